// A falling drop's optics (physics.md section 4).
#include "drop_optics.hpp"

#include <algorithm>
#include <cmath>

#include "numerics.hpp"

namespace airlight {

double drop_order_energy(double n, int p, double incidence) {
    const double ci = std::cos(incidence), si = std::sin(incidence);
    const double sr = si / n, cr = std::sqrt(std::max(0.0, 1.0 - sr * sr));
    // Fresnel reflectances of the two polarisations (eq. 4.1).
    const double rs_amp = (ci - n * cr) / (ci + n * cr), rp_amp = (n * ci - cr) / (n * ci + cr);
    double sum = 0.0;
    for (double r : {rs_amp * rs_amp, rp_amp * rp_amp})
        sum += p == 0 ? r : (1.0 - r) * (1.0 - r) * std::pow(r, double(p - 1));
    return 0.5 * sum;
}

double drop_order_angle(double n, int p, double incidence) {
    const double r = std::asin(std::sin(incidence) / n);
    // Deviation from the forward direction (eq. 4.2), folded into [0, pi].
    const double deviation =
        p == 0 ? numerics::kPi - 2.0 * incidence : 2.0 * (incidence - r) + double(p - 1) * (numerics::kPi - 2.0 * r);
    return std::acos(std::cos(deviation));
}

std::vector<double> drop_phase_order(double n, int p, int bins, int samples) {
    std::vector<double> f(size_t(bins), 0.0);
    // u = b^2 uniform over the cross-section; each sample carries 1 / samples of its light.
    for (int k = 0; k < samples; ++k) {
        const double u = (k + 0.5) / samples;
        const double i = std::asin(std::sqrt(u));
        const double theta = drop_order_angle(n, p, i);
        const int bin = std::min(bins - 1, int(theta / numerics::kPi * bins));
        f[size_t(bin)] += drop_order_energy(n, p, i) / samples;
    }
    // Per steradian: over each bin's solid angle 2 pi (cos a - cos b) (eq. 4.3).
    for (int b = 0; b < bins; ++b) {
        const double a = numerics::kPi * b / bins, c = numerics::kPi * (b + 1) / bins;
        f[size_t(b)] /= 2.0 * numerics::kPi * (std::cos(a) - std::cos(c));
    }
    return f;
}

}  // namespace airlight
