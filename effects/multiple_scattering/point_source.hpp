// Multiple scattering of an isotropic point lamp in an infinite homogeneous
// medium (effects/multiple_scattering/physics.md sections 10 to 13): the
// radiance field of the light scattered at least twice, built by a seeded
// Monte Carlo of the in-scattering source and a line integral per table entry,
// and the table the shading pass reads (effects/multiple_scattering/lamp_ms_math.glsl).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "airlight/scene.hpp"
#include "tables.hpp"

namespace airlight {

// The medium's phase function as a mixture of Henyey-Greenstein lobes and a
// Rayleigh part (weights summing to 1; isotropic: one HG lobe with g = 0).
struct PointSourcePhase {
    struct Lobe {
        double g = 0.0;
        double weight = 1.0;
    };
    std::vector<Lobe> hg;
    double rayleigh_weight = 0.0;
    double mean_cosine() const;
};
PointSourcePhase point_source_phase(const Phase& phase);

// The Monte Carlo's settings: it traces batches of photons until it has
// counted `collision_budget` collisions (or `max_photons` photons); the result
// depends on seed and budget only, not on the number of threads.
struct PointSourceSettings {
    double collision_budget = 2.0e7;
    long max_photons = 4000000;
    uint64_t seed = 18;
    int threads = 0;
};

// The in-scattering source of order >= 2, J(R, theta) (section 11), in optical
// units (sigma_t = 1) for a lamp of unit intensity, per albedo channel: bins
// over log R (R_core to R_switch), then R (to R_kill) and x = sqrt(theta / pi), theta the angle
// between the light's propagation direction and the outward radial. Inside
// R_core J = f(theta) / R (section 11); beyond r_far the diffusion mode (eq. 11.10).
struct PointSourceField {
    int nr = 0;
    int nt = 0;
    double r_core = 0.0;
    double r_kill = 0.0;
    double dlog_r = 0.0;  // log bins from r_core to r_switch ...
    int n_log = 0;
    double r_switch = 0.0;  // ... then bins of width dr (J falls exponentially there)
    double dr = 0.0;
    long photons = 0;
    double collisions = 0.0;
    double seconds = 0.0;
    std::array<std::vector<double>, 3> source;      // [channel][ir * nt + it]
    std::array<std::vector<double>, 3> log_source;  // log J, -inf where J = 0
    std::array<std::vector<double>, 3> core;        // [channel][it]: f = R J inside R_core
    // Beyond r_far[c] channel c's bins are too sparse (or too near R_kill) to hold J, and J
    // continues as the diffusion mode, its amplitude from the bins before (section 11, eq. 11.10):
    // J = far_profile(theta) (r_far / R) e^{-kappa (R - r_far)}, kappa the mode's rate kappa_0
    // (eq. 11.11). r_far = r_kill where the bins hold J to R_kill (albedo 1, or too few bins).
    std::array<double, 3> r_far{};
    std::array<double, 3> kappa{};
    std::array<std::vector<double>, 3> far_profile;  // [channel][it]: J at r_far
    // The continuous bin coordinate of radius r >= r_core (bin i is [i, i + 1)) and bin i's inner edge.
    double bin_coordinate(double r) const;
    double bin_edge(int i) const;
    // J at distance R (optical) and cos theta, channel c (bilinear between bin centres).
    double at(int c, double r, double cos_theta) const;
    // The distance beyond which J is 0 on every channel (infinite where a channel has a far field).
    double reach() const;
};

// kappa_0 of the diffusion mode e^{-kappa_0 R} (section 11, eq. 11.11): the decay rate of the
// slowest plane-wave solution of the transport equation in the homogeneous medium, 0 for albedo 1,
// 1 for albedo 0 (and where kappa_0 is within 1e-9 of 1).
double diffusion_mode_rate(const PointSourcePhase& phase, double albedo);

PointSourceField point_source_field(const PointSourcePhase& phase, const std::array<double, 3>& albedo,
                                    const PointSourceSettings& settings = {});

// The multiply scattered radiance (optical units, unit intensity) seen from a
// point at optical distance tau from the lamp, looking at angle gamma from
// the direction to the lamp: L = int_0^inf e^{-s} J(R(s), theta(s)) ds (section 11),
// per channel.
std::array<double, 3> point_source_radiance(const PointSourceField& field, double tau, double gamma);

// The azimuthal integral of the cosine factor (section 13): int_0^{2 pi}
// max(cos beta cos gamma + sin beta sin gamma cos phi, 0) dphi, the weight of
// the radiance arriving from angle gamma off the lamp's direction on a surface
// whose normal is beta off it.
double hemisphere_kernel(double beta, double gamma);

// The irradiance of the light scattered at least twice (optical units, unit
// intensity) on a surface element at optical distance tau from the lamp, its
// normal at angle beta from the lamp's direction: E = int L(tau, gamma) sin gamma
// K(beta, gamma) dgamma (section 13), for each of `betas`, by `steps` line
// integrals (11.4) in gamma: the direct quadrature the table's rows are checked against.
std::vector<std::array<double, 3>> point_source_irradiance(const PointSourceField& field, double tau,
                                                           const std::vector<double>& betas, int steps);

// The table of log L over (tau, gamma) (lamp_ms_math.glsl's coordinates),
// RGBA texels: one albedo per channel; then the rows of log E(tau, beta)
// (section 13), computed from the same column's log L rows.
Table2D build_lamp_ms_table(const PointSourcePhase& phase, const std::array<double, 3>& albedo,
                            const PointSourceSettings& settings = {});

// The same, cached for the last 8 (phase, albedo) keys.
std::shared_ptr<const Table2D> lamp_ms_table(const PointSourcePhase& phase, const std::array<double, 3>& albedo);

// The azimuthal mean of the phase function, (1 / 2 pi) int p(cos theta_i cos theta_o +
// sin theta_i sin theta_o cos phi) dphi (section 11; HG through the complete elliptic integral).
double azimuthal_phase(const PointSourcePhase& phase, double cos_i, double cos_o);

}  // namespace airlight
