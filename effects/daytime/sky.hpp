// Daytime sky and atmosphere on the CPU side (issue 6; effects/daytime/physics.md;
// effects/daytime/docs/daytime.md): the species of the scene's atmosphere in the form the
// shaders read (sky.glsl), the altitude levels that cut view rays into
// scattering volumes, and the sky-phase table.
#pragma once

#include <memory>
#include <vector>

#include "airlight/scene.hpp"
#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// Sea-level Rayleigh scattering of air at 680 / 550 / 440 nm (1/m; the
// values of the source paper (effects/daytime/physics.md), as in Bruneton's precomputed atmosphere), scale height.
inline constexpr double RAYLEIGH_SIGMA_S0[3] = {5.802e-6, 13.558e-6, 33.1e-6};
inline constexpr double RAYLEIGH_SCALE_HEIGHT = 8000.0;
// The aerosol's low-altitude profile (seed section 1.1.1): exponential decay
// to a minimum at 2250 m, a rise by 25 % up to 3250 m, decay above.
inline constexpr double AEROSOL_MIN_ALTITUDE = 2250.0;
inline constexpr double AEROSOL_MAX_ALTITUDE = 3250.0;
inline constexpr double AEROSOL_RISE = 1.25;
// Marshall-Palmer N(D) = N0 exp(-Lambda D), N0 per m^3 per mm.
inline constexpr double MARSHALL_PALMER_N0 = 8000.0;
// Species whose relative density falls below this are cut off at the
// atmosphere's top (the column above is below this fraction of the total).
inline constexpr double ATMOSPHERE_TOP_DENSITY = 1.0e-5;

// Rain extinction (1/m) for rainfall rate R (mm/h): int N(D) 2 pi D^2 / 4 dD
// = pi N0 1e-6 / Lambda^3, Lambda = 4.1 R^-0.21 per mm (effects/daytime/physics.md).
double rain_extinction(double rate_mm_per_h);

// The sky and sun as the shaders read them.
shader::SkyGpu make_sky_gpu(const Sky& sky, const Sun& sun);

// The atmosphere's species (0 molecules, 1 aerosol, 2 rain; phase.z = 0
// where absent or of zero extinction).
void make_species_gpu(const Atmosphere& atmosphere, shader::SpeciesGpu species[shader::SPECIES_COUNT]);

// The altitude where the atmosphere ends (empty above) and the sorted
// altitude levels from 0 to it: the profile breaks plus `segments` levels
// spread evenly in a measure of how fast the light and the species' mixture
// change with altitude (effects/daytime/docs/daytime.md).
std::vector<float> make_altitude_levels(const shader::SpeciesGpu species[shader::SPECIES_COUNT], int segments,
                                        float& top);

// True when the CIE sky depends on the azimuth (an indicatrix: every type
// but 1, 3 and 5).
bool sky_has_azimuth(const shader::SkyGpu& sky);

// The sky-phase table F_k(C, d) (constants.glsl) for this sky and these
// species' phase functions: RGBA, SKY_TABLE_NC (or 1 when `columns` is false:
// C = 0 only) texels wide, SKY_TABLE_N_ELEVATION x (SKY_TABLE_N_AZIMUTH or 1)
// rows. Built on first use and cached for the last 8 skies (thread safe;
// TableCache).
std::shared_ptr<const Table2D> sky_phase_table(const shader::SkyGpu& sky,
                                               const shader::SpeciesGpu species[shader::SPECIES_COUNT], bool columns);

// The exact kernel integral by the same hemisphere rule (tests, analysis):
// F_k(C, d) for kernel k (0..2 species phase, 3 clamped cosine).
double sky_kernel_integral(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                           int kernel, double column, const glm::dvec3& direction);

}  // namespace airlight
