// The daytime multiple-scattering field as the renderer uses it (issue 18;
// effects/multiple_scattering/physics.md section 9): the plane-parallel
// solution (plane_parallel.hpp) of the scene's atmosphere under its sky and
// sun over its ground, tabulated for the shading pass (ms_layout.glsl).
#pragma once

#include <memory>

#include "airlight/scene.hpp"
#include "plane_parallel.hpp"
#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// The solver's settings for the renderer (effects/multiple_scattering/docs/solver.md
// measures their error): ordinates per hemisphere, and the thickest layer
// (optical depth of the densest channel) between levels.
inline constexpr int MS_STREAMS = 16;
inline constexpr double MS_LAYER_DEPTH = 1.0;
// Below this vertical optical depth of scattering (every channel) the
// atmosphere scatters too little for a second order to matter: no solve
// (effects/multiple_scattering/docs/renderer.md measures what it leaves out).
inline constexpr double MS_MIN_SCATTERING_DEPTH = 1e-3;
// The upper level of the ground-bounce table (m): its light is the same at every altitude.
inline constexpr float MS_GROUND_BOUNCE_TOP = 1e9f;
// A plane facing up within this distance (m) of y = 0 is the ground.
inline constexpr float MS_GROUND_TOLERANCE = 1e-3f;

// The fading rain's ladder (physics.md eq. 9.3): the rain extinction (1/m) of
// its lowest rung. Rain thinner than this is solved exactly, per state.
inline constexpr double MS_RAIN_LADDER_FLOOR = 1e-6;

// True when the sky dome or the sun lights the atmosphere.
bool sky_lights_atmosphere(const shader::SkyGpu& sky);

// The largest over channels of the atmosphere's vertical optical depth of
// scattering, sum_i sigma_s,i int rho_i dy.
double atmosphere_scattering_depth(const shader::SpeciesGpu species[shader::SPECIES_COUNT]);

// The ground's albedo for the solver: the first plane facing up at y = 0
// (within MS_GROUND_TOLERANCE), else black.
RgbD ground_albedo(const Scene& scene);

// C_m(mu_n, mu) = int_0^{2 pi} cos(m psi) max(mu_n mu + sqrt(1 - mu_n^2)
// sqrt(1 - mu^2) cos psi, 0) dpsi, in closed form.
double clamped_cosine_mode(int m, double mu_n, double mu);

// The table TABLE_MS_FIELD for this sky, sun, atmosphere and ground, solved
// over slab_levels(segments, MS_LAYER_DEPTH); cached for the last 4 weather
// states (thread safe; TableCache).
std::shared_ptr<const Table2D> multiple_scattering_table(const shader::SkyGpu& sky,
                                                         const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                         const RgbD& ground, int segments);

// The table for a rain that may fade (quality.fading_rain_steps = steps > 0;
// physics.md eq. 9.3): the fields solved at the two rain extinctions of the
// ladder MS_RAIN_LADDER_FLOOR 2^(k / steps) around the scene's, each on its own
// levels, blended linearly in log extinction on the union of their levels, so
// that the frames of a fading rain share their solves and the blend is
// continuous across rungs. Falls back to multiple_scattering_table where there
// is no rain, rain thinner than the floor, or more levels than MS_MAX_LEVELS.
std::shared_ptr<const Table2D> fading_rain_table(const shader::SkyGpu& sky,
                                                 const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                 const RgbD& ground, int segments, int steps);

// The ground's reflection alone, for an atmosphere too thin to scatter (or
// none): E(y, n) = rho E_0 (1 - n_y) / 2, E_0 the unscattered irradiance on the
// ground through the vertical column `column` (per channel); K and E_res 0.
std::shared_ptr<const Table2D> ground_bounce_table(const shader::SkyGpu& sky,
                                                   const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                   const RgbD& ground, const glm::dvec3& column);

// True when the scene has a surface that is not the ground (which can see the ground's reflection).
bool has_surface_besides_ground(const Scene& scene);

}  // namespace airlight
