// The scattering tables: built once per process from exact double-precision
// evaluations and shared, texel for texel, by both backends. Their
// parametrisations, resolutions and measured errors: docs/airlight_table.md.
#pragma once

#include <string>
#include <vector>

#include "shader_cpp.hpp"

namespace airlight {

// A grid of float32 texels, row-major: texels[y * width + x]; node-aligned
// (texel i sits at the normalised coordinate i / (width - 1)).
struct Table2D {
    const char* name = "";
    int width = 0;
    int height = 0;
    int channels = 1;  // texels per grid node (1: R32F, 4: RGBA32F)
    std::vector<float> texels;
    double build_seconds = 0.0;
    long serial = 0;  // distinguishes tables that a cache built at the same address (GL texture cache)
};

// Exact normalised airlight tail (MODELS.md section 1, docs/airlight_table.md)
//   Q(u, v) = e^{u tan v} int_v^{pi/2} e^{-u tan t} dt,   cv = pi/2 - v,
// through the complex exponential integral: Q = Im[e^w E1(w)], w = u (tan v - i).
double airlight_tail_exact(double u, double cv);

// Exact surface glow G(T, theta_s) = e^T G0(T, theta_s) (MODELS.md section 1):
//   G = int_0^pi Q(T sin g, g / 2) Phi(g, theta_s) dg,
// Phi the azimuthal integral of the clamped cosine. `nodes_scale` > 1 refines
// the quadrature (tests use it to check convergence).
double surface_glow_exact(double optical_distance, double theta_s, int nodes_scale = 1);

// Inverse of the glow table's row coordinate (shaders/airlight.glsl):
// cos theta_s at row coordinate Y in [0, 1] and optical distance T.
double surface_glow_cos_theta(double Y, double optical_distance, double k_min = shader::SURFACE_GLOW_K_MIN);

// Builds a surface glow table of any resolution (the production one uses
// SURFACE_GLOW_NX x SURFACE_GLOW_NY; other sizes are for the error analysis).
Table2D build_surface_glow_table(int width, int height);

// The tables, built on first use (thread safe) and kept for the process.
const Table2D& airlight_tail_table();
const Table2D& surface_glow_table();
// Spot local moments (docs/spot_table.md): RGBA (S, M1/N1, M2/N2, 0) on the
// airlight tail's grid.
const Table2D& spot_moment_table();

// ---- Anisotropic phase functions (docs/phase_table.md) ----------------------
// One lobe of the medium's phase function: Henyey-Greenstein with asymmetry g
// (|g| <= PHASE_G_LIMIT), or Rayleigh.
struct PhaseLobe {
    bool rayleigh = false;
    float g = 0.0f;
};

// The lobe's parameters as the shaders read them (layout.glsl), with its
// weight in the mixture.
shader::PhaseLobeGpu phase_lobe_gpu(const PhaseLobe& lobe, float weight);

// The lobe's tail Q_p(u, xi) = e^{u tan xi} int_xi^{pi/2} P(t) e^{-u tan t} dt
// (cv = pi/2 - xi) and its local moments M1_p = <sin 2 Delta>, M2_p =
// <sin^2 Delta> (Delta = t - xi) under the weight P(t) e^{-u (tan t - tan xi)},
// by composite Gauss-Legendre in the lobe's phi (phase_math.glsl). `refine`
// > 1 refines the panels (tests check convergence with it).
void phase_tail_moments(const PhaseLobe& lobe, double u, double cv, double& Q, double& M1, double& M2, int refine = 1);

// Per-lobe tables, built on first use for each distinct lobe and kept for the
// process (thread safe): RGBA (S_p, M1_p/N1_p, M2_p/N2_p, 0) on
// AIRLIGHT_TAIL_NX x AIRLIGHT_TAIL_NY in the lobe's coordinates, and log G_p on
// SURFACE_GLOW_NX x SURFACE_GLOW_NY with the lobe's row-warp floor.
const Table2D& phase_moment_table(const PhaseLobe& lobe);
const Table2D& phase_glow_table(const PhaseLobe& lobe);
// G_p(T, theta_s) for any resolution and the lobe's glow by quadrature (tests, analysis).
Table2D build_phase_glow_table(const PhaseLobe& lobe, int width, int height);
double phase_surface_glow_exact(const PhaseLobe& lobe, double optical_distance, double theta_s);
// int_0^{pi/2} P dt = Q_p(0, 0), the airlight culling bound's factor (pi/2 isotropic).
double phase_airlight_bound(const PhaseLobe& lobe);

// The tables built so far in this process, by name (for tests showing that a
// scene which does not need a table builds none, and for reporting memory).
struct TableInfo {
    std::string name;
    int width = 0;
    int height = 0;
    size_t bytes = 0;
    double build_seconds = 0.0;
};
std::vector<TableInfo> tables_built();
// Records a table in that list (tables built outside cpp/tables.cpp: the sky table).
bool register_table(const Table2D& table);

}  // namespace airlight
