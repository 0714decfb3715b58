// Anisotropic phase functions' tables (effects/phase/physics.md;
// effects/phase/docs/phase_table.md).
#pragma once

#include <memory>

#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// One lobe of the medium's phase function: Henyey-Greenstein with asymmetry g
// (|g| <= PHASE_G_LIMIT), or Rayleigh.
struct PhaseLobe {
    bool rayleigh = false;
    float g = 0.0f;
};

// The lobe's parameters as the shaders read them (phase_layout.glsl), with its
// weight in the mixture.
shader::PhaseLobeGpu phase_lobe_gpu(const PhaseLobe& lobe, float weight);

// The lobe's tail Q_p(u, xi) = e^{u tan xi} int_xi^{pi/2} P(t) e^{-u tan t} dt
// (cv = pi/2 - xi) and its local moments M1_p = <sin 2 Delta>, M2_p =
// <sin^2 Delta> (Delta = t - xi) under the weight P(t) e^{-u (tan t - tan xi)},
// by composite Gauss-Legendre in the lobe's phi (phase_math.glsl). `refine`
// > 1 refines the panels (tests check convergence with it).
void phase_tail_moments(const PhaseLobe& lobe, double u, double cv, double& Q, double& M1, double& M2, int refine = 1);

// Per-lobe tables, built on first use for each distinct lobe and cached for
// the last 8 lobes (thread safe; TableCache): RGBA (S_p, M1_p/N1_p, M2_p/N2_p,
// 0) on AIRLIGHT_TAIL_NX x AIRLIGHT_TAIL_NY in the lobe's coordinates, and
// log G_p on SURFACE_GLOW_NX x SURFACE_GLOW_NY with the lobe's row-warp floor.
std::shared_ptr<const Table2D> phase_moment_table(const PhaseLobe& lobe);
std::shared_ptr<const Table2D> phase_glow_table(const PhaseLobe& lobe);
// G_p(T, theta_s) for any resolution and the lobe's glow by quadrature (tests, analysis).
Table2D build_phase_glow_table(const PhaseLobe& lobe, int width, int height);
double phase_surface_glow_exact(const PhaseLobe& lobe, double optical_distance, double theta_s);
// int_0^{pi/2} P dt = Q_p(0, 0), the airlight culling bound's factor (pi/2 isotropic).
double phase_airlight_bound(const PhaseLobe& lobe);

}  // namespace airlight
