// Multiple scattering of daylight in a plane-parallel atmosphere (issue 18;
// effects/multiple_scattering/physics.md; effects/multiple_scattering/docs/solver.md).
//
// A standalone solver of the radiative transfer equation in the slab
// 0 <= y <= top over a Lambertian ground, lit at the top by a collimated sun
// and a diffuse sky dome: discrete ordinates in the cosine (double Gauss),
// Fourier series in azimuth, delta-M scaling of the forward peak, each
// homogeneous layer built by doubling from a thin diamond-initialised layer,
// the layers combined by adding. It returns what the renderer lacks besides
// the single scattering it already computes exactly: the light scattered by
// the air at least once (or reflected by the ground) before it meets the
// point being shaded, and the in-scattering source that light produces.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "shader_cpp.hpp"

namespace airlight {

// Per-channel values (R, G, B) in double precision.
using RgbD = std::array<double, 3>;

// A species' phase function p(cos theta), normalised to 4 pi over the sphere,
// and its Legendre moments chi_l (p = sum (2l+1) chi_l P_l; effects/multiple_scattering/physics.md section 2).
struct PhaseFunction {
    enum class Kind { rayleigh, henyey_greenstein, legendre };
    Kind kind = Kind::henyey_greenstein;
    double g = 0.0;               // asymmetry (Henyey-Greenstein)
    std::vector<double> moments;  // chi_0 = 1, chi_1, ... (legendre)

    static PhaseFunction rayleigh();
    static PhaseFunction henyey_greenstein(double g);
    static PhaseFunction legendre(std::vector<double> moments);

    double moment(int l) const;            // chi_l (0 beyond the given ones)
    double value(double cos_theta) const;  // p(cos theta), the full function
};

// One homogeneous layer of the slab: per species (the atmosphere's phases'
// order) and channel, the optical depths of extinction and of scattering.
struct SlabLayer {
    double bottom = 0.0, top = 0.0;      // altitude (m)
    std::vector<RgbD> extinction_depth;  // tau_t of species i
    std::vector<RgbD> scattering_depth;  // tau_s of species i (<= tau_t)
};

// The atmosphere: one phase function per species and the layers from the
// ground up, contiguous (layers[0].bottom = 0, layers[k].top = layers[k+1].bottom).
struct SlabAtmosphere {
    std::vector<PhaseFunction> phases;
    std::vector<SlabLayer> layers;
};

// The light at the top and the ground. Directions are look directions (where
// the light comes from, as in effects/daytime/physics.md): mu = w_y, phi the
// azimuth of w from the sun's azimuth.
struct SlabIllumination {
    double sun_mu = 0.0;    // s_y; no sun when <= 0
    RgbD sun_irradiance{};  // E_sun on a plane facing the sun, at the top
    // Sky radiance entering at the top, for look directions mu > 0 (none when
    // empty); any azimuth dependence (cosine and sine Fourier terms are both kept).
    std::function<RgbD(double mu, double phi)> sky_radiance;
    RgbD ground_albedo{};  // Lambertian, 0 = black
};

struct SolverOptions {
    int streams = 16;                 // N: ordinates per hemisphere (2N in all)
    int max_fourier_mode = -1;        // highest azimuth mode (-1: 2N - 1)
    double azimuth_tolerance = 1e-4;  // stop after two modes below this share of mode 0
    double initial_depth = 1.0 / 16;  // thin layer's depth, in units of the smallest ordinate
    bool delta_m = true;              // delta-M scaling (effects/multiple_scattering/physics.md section 4)
    int sky_azimuth_samples = 96;     // trapezoid nodes of the sky's Fourier transform
    int threads = 1;                  // > 1: the three channels on their own threads
    // The output's view grid (look directions): cosines in [-1, 1] and
    // azimuths from the sun in [0, 2 pi). Empty: 65 cosines (uniform in elevation, 2.8 degrees) x 72 azimuths (5
    // degrees).
    std::vector<double> view_mu, view_phi;
};

// The solution at the layer interfaces, per channel. "Diffuse" light is all
// light but the sun's direct beam and the sky's unscattered light, both
// attenuated with the true optical depth (what the renderer computes itself):
// light scattered by the air at least once, or reflected by the ground
// (effects/multiple_scattering/physics.md section 6).
struct MultipleScatteringField {
    int species_count = 0;
    int streams = 0;                           // N ordinates per hemisphere
    int fourier_modes = 0;                     // modes stored: 0 .. fourier_modes - 1
    int modes_solved = 0;                      // modes computed before azimuth convergence (the rest are 0)
    double sun_mu = 0.0;                       // the sun's s_y (0: no sun)
    std::vector<double> altitudes;             // interfaces, ground (0) up to the top
    std::vector<RgbD> column;                  // vertical extinction optical depth above each altitude
    std::vector<double> view_mu, view_phi;     // the view grid (look directions)
    std::vector<double> node_mu, node_weight;  // the ordinates on (0, 1] and their weights

    // K_i(y, d) = 1/(4 pi) int p_i(d . w) L_diffuse(y, w) dw for look
    // direction d (effects/multiple_scattering/physics.md section 6): the renderer's multiple-scattering
    // source is J_ms = sum_i sigma_s,i rho_i(y) K_i (radiance per metre).
    // Index: phased_index(level, species, channel, mu, phi).
    std::vector<double> phased_radiance;
    // Horizontal diffuse irradiance (W/m^2): onto a surface facing up (light
    // from the sky side) and facing down (from the ground side).
    std::vector<RgbD> irradiance_down, irradiance_up;
    // The unscattered light the renderer adds itself, onto a surface facing up.
    std::vector<RgbD> sun_direct_irradiance, sky_direct_irradiance;
    // The forward-peak residual beam along the sun (effects/multiple_scattering/physics.md section 6):
    // E_sun (exp(-tau*/mu0) - exp(-tau/mu0)), irradiance on a plane facing the
    // sun; part of the diffuse light (in irradiance_down, radiance_sh and
    // phased_radiance, not in node_radiance).
    std::vector<RgbD> sun_forward_irradiance;
    // Real spherical harmonics (l <= 2, index l (l + 1) + m: the standard real
    // basis in the x, y, z of look_direction's frame, sh_basis) of the diffuse
    // radiance over look directions, the residual beam included:
    // [level][channel][9]. Irradiance of any normal: tilted_irradiance_sh.
    std::vector<std::array<std::array<double, 9>, 3>> radiance_sh;
    // The diffuse radiance at the ordinates, Fourier coefficients in azimuth:
    // index node_index(level, channel, mode, node, sine); node 0..N-1 look
    // up at mu = node_mu[j], N..2N-1 look down at mu = -node_mu[j - N].
    std::vector<double> node_radiance;
    RgbD incident_flux{};  // onto the top: sun + sky (the sky by the solver's quadrature)
    double solve_seconds = 0.0;

    size_t phased_index(int level, int species, int channel, int mu, int phi) const {
        return (((size_t(level) * size_t(species_count) + size_t(species)) * 3 + size_t(channel)) * view_mu.size() +
                size_t(mu)) *
                   view_phi.size() +
               size_t(phi);
    }
    size_t node_index(int level, int channel, int mode, int node, int sine) const {
        return (((size_t(level) * 3 + size_t(channel)) * size_t(fourier_modes) + size_t(mode)) * size_t(2 * streams) +
                size_t(node)) *
                   2 +
               size_t(sine);
    }
    double phased(int level, int species, int channel, int mu, int phi) const {
        return phased_radiance[phased_index(level, species, channel, mu, phi)];
    }
    // The diffuse radiance at ordinate `node` (see node_radiance) and azimuth phi.
    double node_diffuse_radiance(int level, int channel, int node, double phi) const;
    // Diffuse irradiance onto a surface of unit normal n (frame of radiance_sh)
    // from the l <= 2 harmonics (effects/multiple_scattering/physics.md section 7).
    double tilted_irradiance_sh(int level, int channel, const std::array<double, 3>& normal) const;
    // The same by quadrature of the ordinates' radiance over 256 azimuths (the
    // reference for the harmonics' error; exact up to the ordinates).
    double tilted_irradiance_nodes(int level, int channel, const std::array<double, 3>& normal) const;
};

// The look direction of (mu, phi) in the harmonics' frame: y up, x the
// horizontal towards the sun's azimuth, z the horizontal at phi = 90 degrees:
// (sqrt(1 - mu^2) cos phi, mu, sqrt(1 - mu^2) sin phi).
std::array<double, 3> look_direction(double mu, double phi);
// Real spherical harmonics up to l = 2 at a unit direction.
std::array<double, 9> sh_basis(const std::array<double, 3>& w);

MultipleScatteringField solve_plane_parallel(const SlabAtmosphere& atmosphere, const SlabIllumination& light,
                                             const SolverOptions& options = {});

// The field in two parts by source, in one solve (the layers' operators are
// shared): `sky` the sky dome's light (and the ground's reflection of it),
// `sun` the sun's. The transfer is linear in its sources, so their sum is
// solve_plane_parallel's field (up to rounding), and the sun's part scales
// with each channel's sun_irradiance: a sun that brightens or dims re-uses it
// (effects/multiple_scattering/physics.md eq. 9.4).
struct FieldBySource {
    MultipleScatteringField sky, sun;
};
FieldBySource solve_plane_parallel_by_source(const SlabAtmosphere& atmosphere, const SlabIllumination& light,
                                             const SolverOptions& options = {});

// The renderer's atmosphere (make_species_gpu) as slab layers between the
// given altitudes: optical depths integrated exactly over each profile piece;
// phases Rayleigh for molecules, HG for aerosol and rain (the HG that
// lights rain by the sky; the rainbow's Mie phase is not carried).
SlabAtmosphere slab_from_species(const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                 const std::vector<double>& levels);

// Levels for the solver: the renderer's altitude levels (make_altitude_levels
// with `segments`), plus levels at optical depths max_depth / 2^k (k = 1..10)
// from the ground and the top, each layer then split into equal parts so that
// none is optically thicker than max_depth (max_depth / 8 in the top 4
// optical depths) in its densest channel (effects/multiple_scattering/physics.md section 8).
std::vector<double> slab_levels(const shader::SpeciesGpu species[shader::SPECIES_COUNT], int segments,
                                double max_depth);

// The renderer's sky dome and sun (make_sky_gpu) as the solver's light at
// the top: the sun's s_y and irradiance (when it lights the scene), the sky
// Lz shape(w) (effects/daytime/sky_math.glsl) with w rebuilt from (mu, phi)
// about the sun's azimuth; the ground's albedo as given.
SlabIllumination slab_illumination(const shader::SkyGpu& sky, const RgbD& ground_albedo);

// Gauss-Legendre nodes and weights on (0, 1) (Golub-Welsch, Eigen's
// symmetric eigensolver); ascending.
void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace airlight
