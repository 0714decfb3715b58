// The scattering tables: built once per process from exact double-precision
// evaluations and shared, texel for texel, by both backends. Their
// parametrisations, resolutions and measured errors: docs/airlight_table.md.
#pragma once

#include <vector>

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
double surface_glow_cos_theta(double Y, double optical_distance);

// Builds a surface glow table of any resolution (the production one uses
// SURFACE_GLOW_NX x SURFACE_GLOW_NY; other sizes are for the error analysis).
Table2D build_surface_glow_table(int width, int height);

// The tables, built on first use (thread safe) and kept for the process.
const Table2D& airlight_tail_table();
const Table2D& surface_glow_table();
// Spot local moments (docs/spot_table.md): RGBA (S, M1/N1, M2/N2, 0) on the
// airlight tail's grid.
const Table2D& spot_moment_table();

// The tables built so far in this process, by name (for tests showing that a
// scene which does not need a table builds none, and for reporting memory).
struct TableInfo {
    const char* name;
    const Table2D* table;
};
std::vector<TableInfo> tables_built();

}  // namespace airlight
