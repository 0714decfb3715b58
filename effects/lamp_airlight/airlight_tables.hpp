// The point lamps' scattering tables (effects/lamp_airlight/physics.md;
// parametrisations, resolutions and measured errors: effects/lamp_airlight/docs/airlight_table.md):
// the normalised airlight tail and the surface glow, with their exact
// evaluations.
#pragma once

#include <functional>
#include <utility>
#include <vector>

#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// Exact normalised airlight tail (effects/lamp_airlight/physics.md, effects/lamp_airlight/docs/airlight_table.md)
//   Q(u, v) = e^{u tan v} int_v^{pi/2} e^{-u tan t} dt,   cv = pi/2 - v,
// through the complex exponential integral: Q = Im[e^w E1(w)], w = u (tan v - i).
double airlight_tail_exact(double u, double cv);

// Exact surface glow G(T, theta_s) = e^T G0(T, theta_s) (effects/lamp_airlight/physics.md):
//   G = int_0^pi Q(T sin g, g / 2) Phi(g, theta_s) dg,
// Phi the azimuthal integral of the clamped cosine. `nodes_scale` > 1 refines
// the quadrature (tests use it to check convergence).
double surface_glow_exact(double optical_distance, double theta_s, int nodes_scale = 1);

// Inverse of the glow table's row coordinate (effects/lamp_airlight/airlight.glsl):
// cos theta_s at row coordinate Y in [0, 1] and optical distance T.
double surface_glow_cos_theta(double Y, double optical_distance, double k_min = shader::SURFACE_GLOW_K_MIN);

// Builds a surface glow table of any resolution (the production one uses
// SURFACE_GLOW_NX x SURFACE_GLOW_NY; other sizes are for the error analysis).
Table2D build_surface_glow_table(int width, int height);

// The tables, built on first use (thread safe) and kept for the process.
const Table2D& airlight_tail_table();
const Table2D& surface_glow_table();

// A glow table (log G) of width x height: column X holds the optical
// distance T, row Y the cos theta_s of surface_glow_cos_theta(Y, T, k_min);
// tail(u, cv) is the airlight tail of the medium's phase function (the phase
// effect builds its per-lobe glow tables with it). backward_width > 0 grades
// the quadrature towards g = pi for a backward lobe of that width.
Table2D build_glow_table(int width, int height, double k_min, double backward_width,
                         const std::function<double(double, double)>& tail);

// Quadrature nodes (g, weight) in g in [0, pi] for the glow integral, graded
// towards g = 0 (and towards pi with backward_width > 0), with panel edges at
// extra_edges; `scale` > 1 refines.
std::vector<std::pair<double, double>> glow_nodes(int scale, std::vector<double> extra_edges = {},
                                                  double backward_width = 0.0);

// Azimuthal integral of the clamped cosine over the ring of directions at
// angle g from the light, for a surface normal at theta_s from it.
double clamped_cosine_ring(double g, double theta_s);

}  // namespace airlight
