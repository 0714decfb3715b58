// A falling drop's optics (effects/falling_rain/physics.md section 4): the
// geometric-optics phase function of a water sphere (Fresnel reflection,
// refraction and internal reflections, the Debye series), order by order.
#pragma once

#include <vector>

namespace airlight {

// Debye orders summed (p = 0 reflection, 1 refraction, p >= 2 with p - 1
// internal reflections); the rest carry about 3e-4 of the light (physics.md section 4).
constexpr int DROP_ORDERS = 8;

// The energy fraction of Debye order p for a ray entering at incidence angle
// i (radians) on a sphere of relative index n, averaged over the two
// polarisations (eq. 4.1).
double drop_order_energy(double n, int p, double incidence);
// The scattering angle (radians, in [0, pi]) of order p for incidence i (eq. 4.2).
double drop_order_angle(double n, int p, double incidence);
// f_p(theta) of order p in `bins` equal bins of theta over [0, pi]: the
// share of the light intercepted by the drop's cross-section that leaves
// per steradian (eq. 4.3), by sampling the cross-section (`samples` rays,
// stratified in b^2). Summed over every p it integrates to 1 over the sphere.
std::vector<double> drop_phase_order(double n, int p, int bins, int samples);

}  // namespace airlight
