// Light scattered inside the particle clouds' reference particle: a
// homogeneous unit sphere of optical radius tau (albedo 1, Henyey-Greenstein
// phase g) lit by the sun, solved order by order by iterating single
// scattering (effects/particle_clouds/physics.md section 2). The frame puts
// the sun on +z: sunlight travels along -z with irradiance 1.
#pragma once

#include <array>
#include <memory>
#include <vector>

namespace airlight {

// Angles from the sun's axis, [0, pi], on `nodes` nodes graded toward the terminator (physics.md
// eq. 2.14): a thick particle's light turns from lit to shadowed within a few mean free paths of it.
// The node index is s(theta) = (G(phi) / G(pi / 2) + 1) (nodes - 1) / 2, phi = theta - pi / 2,
// G(phi) = phi + k w tanh(phi / w): the step at the terminator is the smaller of kStep / tau and the
// uniform step (k = 0 then), w is kWidth of those steps (at most a quarter of the nodes), and the
// nodes are nearly uniform toward the poles. The solver's polar nodes.
class TerminatorNodes {
public:
    static constexpr double kStep = 0.5;     // the step at the terminator, in mean free paths
    static constexpr double kWidth = 8.0;    // w in steps at the terminator
    TerminatorNodes(int nodes, double tau);  // tau = 0: uniform nodes
    double angle(int j) const;               // node j's angle (by bisection: keep it where it is used often)
    double index(double theta) const;        // the fractional node index of the angle theta
    double k() const { return k_; }
    double w() const { return w_; }

private:
    int n_;
    double k_ = 0.0, w_ = 1.0;  // k = 0: uniform
};

// How finely the light field inside the sphere is resolved (physics.md
// section 2.3; the defaults are chosen in effects/particle_clouds/docs/).
struct SphereGrid {
    int radii = 24;  // radial nodes, graded toward the surface in optical depth (eq. 2.7)
    int polar = 32;  // the position's angle from the sun's axis, [0, pi], graded toward the terminator
    // The polar nodes of thick, forward-scattering particles (tau >= kForwardThickTau and g >=
    // kForwardThickG; at least `polar`): their diffuse light, carried forward over many mean free paths,
    // still varies across the graded nodes' coarse steps toward the poles: 32 nodes left the side- and
    // back-lit rays of a tau = 50, g = 0.9 particle 6-9 % dark (physics.md section 2.6). 0: `polar` everywhere.
    int polar_forward_thick = 48;
    static constexpr double kForwardThickTau = 10.0;
    static constexpr double kForwardThickG = 0.7;
    int zenith = 32;       // a direction's angle from the outward normal there, [0, pi]
    int azimuth = 16;      // its azimuth about the normal from the sun's side, [0, pi] (mirror symmetry)
    int march_steps = 16;  // steps of each ray integral, uniform in 1 - transmittance (eq. 2.4)
    int orders = 18;       // scattering orders solved one by one (the source sums 18)
    // The depth of the first radial node under the surface, in mean free paths, where the uniform
    // step would be coarser (eq. 2.7); the radial steps grow from it and level off at twice the uniform step.
    double surface_step = 0.05;
    // Also solve the sum of every order beyond `orders` at once (eq. 2.11): a thick particle's light
    // still inside after 18 orders is 19-60 % of what it scatters (effects/particle_clouds/physics.md
    // section 2.7). Off, the orders stop at `orders`, as in the source.
    bool beyond = false;
    // The polar nodes graded toward the terminator (eq. 2.14); off, uniform (for comparison only).
    bool graded_polar = true;
};

// Throws std::invalid_argument naming the field when a resolution is out of range.
void validate_sphere_grid(const SphereGrid& grid);

// The grid a particle of optical radius tau and asymmetry g is solved on: `grid` with its polar nodes
// raised to polar_forward_thick for thick, forward-scattering particles.
SphereGrid sphere_grid_for(const SphereGrid& grid, double tau, double g);

// The solved light field of one sphere: the source function of every order
// >= 2 on the grid (order 1 is analytic, eq. 2.2).
class SphereScattering {
public:
    // Solves orders 1..grid.orders (about grid.orders - 1 gathers and marches).
    // tau in [1e-4, 1e3], g in [0, 0.99].
    SphereScattering(double tau, double g, const SphereGrid& grid = {});
    ~SphereScattering();
    SphereScattering(const SphereScattering&) = delete;
    SphereScattering& operator=(const SphereScattering&) = delete;

    // The radiance of each order 1..orders that a camera looking along `dir`
    // (unit) from `origin` receives from the sphere (0 for a ray that misses
    // it), the ray integral taken with `steps` steps (eq. 2.4); with
    // grid.beyond one more entry, the radiance of all orders beyond.
    std::vector<double> radiance_orders(const double origin[3], const double dir[3], int steps) const;
    // What the particle table stores for the same ray (physics.md eq. 3.1): order 1 over its phase
    // p_g(sun . v); the ray integrals of orders 2 and 3's peak coefficients (eq. 2.8), whose phases
    // p_{g^2}, p_{g^3} are the same all along the ray; and the rest of orders 2..orders (their R_k and
    // the peaks of orders >= 4) in one march, with every order beyond when grid.beyond is set. Radiance = c0 p_g + c1
    // p_{g^2} + c2 p_{g^3} + c3.
    std::array<double, 4> table_channels(const double origin[3], const double dir[3], int steps) const;

    double tau() const;
    double g() const;
    const SphereGrid& grid() const;  // the grid solved on: sphere_grid_for(grid, tau, g)

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace airlight
