#include "mie.hpp"

#include <cmath>

namespace airlight {

int mie_term_count(double x) { return int(x + 4.05 * std::cbrt(x) + 2.0); }

MieCoefficients mie_coefficients(std::complex<double> m, double x) {
    MieCoefficients c;
    c.x = x;
    const int n_max = mie_term_count(x);
    const std::complex<double> mx = m * x;
    // D_n(mx) = psi_n'(mx) / psi_n(mx) by downward recurrence (stable for any m),
    // started far enough above max(N, |mx|) that the starting value is forgotten.
    const int n_start = std::max(n_max, int(std::abs(mx))) + 16;
    std::vector<std::complex<double>> d(size_t(n_start) + 1, 0.0);
    for (int n = n_start; n > 0; --n) d[size_t(n) - 1] = double(n) / mx - 1.0 / (d[size_t(n)] + double(n) / mx);
    // Riccati-Bessel psi_n(x) and chi_n(x) upward from n = -1, 0 (BH 4.89).
    double psi_prev = std::cos(x), psi = std::sin(x);
    double chi_prev = -std::sin(x), chi = std::cos(x);
    c.a.resize(size_t(n_max));
    c.b.resize(size_t(n_max));
    for (int n = 1; n <= n_max; ++n) {
        const double psi_n = (2.0 * n - 1.0) / x * psi - psi_prev;
        const double chi_n = (2.0 * n - 1.0) / x * chi - chi_prev;
        const std::complex<double> xi_n(psi_n, -chi_n), xi(psi, -chi);
        const std::complex<double> da = d[size_t(n)] / m + double(n) / x;
        const std::complex<double> db = m * d[size_t(n)] + double(n) / x;
        c.a[size_t(n) - 1] = (da * psi_n - psi) / (da * xi_n - xi);  // BH 4.88
        c.b[size_t(n) - 1] = (db * psi_n - psi) / (db * xi_n - xi);
        psi_prev = psi;
        psi = psi_n;
        chi_prev = chi;
        chi = chi_n;
    }
    return c;
}

MieEfficiencies mie_efficiencies(const MieCoefficients& c) {
    MieEfficiencies q;
    for (size_t i = 0; i < c.a.size(); ++i) {
        const double w = 2.0 * double(i + 1) + 1.0;
        q.extinction += w * (c.a[i] + c.b[i]).real();                 // BH 4.62
        q.scattering += w * (std::norm(c.a[i]) + std::norm(c.b[i]));  // BH 4.61
    }
    q.extinction *= 2.0 / (c.x * c.x);
    q.scattering *= 2.0 / (c.x * c.x);
    return q;
}

void mie_amplitudes(const MieCoefficients& c, const std::vector<double>& theta, std::vector<std::complex<double>>& s1,
                    std::vector<std::complex<double>>& s2) {
    s1.assign(theta.size(), 0.0);
    s2.assign(theta.size(), 0.0);
    for (size_t k = 0; k < theta.size(); ++k) {
        const double mu = std::cos(theta[k]);
        double pi_prev = 0.0, pi_n = 1.0;  // pi_0, pi_1 (BH 4.47)
        std::complex<double> sum1 = 0.0, sum2 = 0.0;
        for (size_t i = 0; i < c.a.size(); ++i) {
            const double n = double(i + 1);
            const double tau_n = n * mu * pi_n - (n + 1.0) * pi_prev;
            const double f = (2.0 * n + 1.0) / (n * (n + 1.0));
            sum1 += f * (c.a[i] * pi_n + c.b[i] * tau_n);  // BH 4.74
            sum2 += f * (c.a[i] * tau_n + c.b[i] * pi_n);
            const double pi_next = ((2.0 * n + 1.0) * mu * pi_n - (n + 1.0) * pi_prev) / n;
            pi_prev = pi_n;
            pi_n = pi_next;
        }
        s1[k] = sum1;
        s2[k] = sum2;
    }
}

std::vector<double> mie_phase_function(std::complex<double> m, double x, const std::vector<double>& theta) {
    const MieCoefficients c = mie_coefficients(m, x);
    const double q_sca = mie_efficiencies(c).scattering;
    std::vector<std::complex<double>> s1, s2;
    mie_amplitudes(c, theta, s1, s2);
    std::vector<double> p(theta.size());
    const double norm = 2.0 * 3.14159265358979323846 * x * x * q_sca;
    for (size_t k = 0; k < theta.size(); ++k) p[k] = (std::norm(s1[k]) + std::norm(s2[k])) / norm;
    return p;
}

}  // namespace airlight
