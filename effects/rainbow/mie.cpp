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
    // The angular functions pi_n, tau_n (BH 4.46-4.47) by upward recurrence, with
    // the terms outermost and the angles innermost so that the angle loop runs
    // over plain arrays (vectorised); this is where a rainbow table spends its time.
    const size_t count = theta.size();
    std::vector<double> mu(count), pi_prev(count, 0.0), pi_n(count, 1.0);
    std::vector<double> s1_re(count, 0.0), s1_im(count, 0.0), s2_re(count, 0.0), s2_im(count, 0.0);
    for (size_t k = 0; k < count; ++k) mu[k] = std::cos(theta[k]);
    for (size_t i = 0; i < c.a.size(); ++i) {
        const double n = double(i + 1);
        const double f = (2.0 * n + 1.0) / (n * (n + 1.0));
        const double ar = f * c.a[i].real(), ai = f * c.a[i].imag();
        const double br = f * c.b[i].real(), bi = f * c.b[i].imag();
        const double up = (2.0 * n + 1.0) / n, down = (n + 1.0) / n;
        double* __restrict p = pi_n.data();
        double* __restrict q = pi_prev.data();
        const double* __restrict m = mu.data();
        double* __restrict x1 = s1_re.data();
        double* __restrict y1 = s1_im.data();
        double* __restrict x2 = s2_re.data();
        double* __restrict y2 = s2_im.data();
        for (size_t k = 0; k < count; ++k) {
            const double pik = p[k];
            const double tau = n * m[k] * pik - (n + 1.0) * q[k];
            x1[k] += ar * pik + br * tau;  // BH 4.74
            y1[k] += ai * pik + bi * tau;
            x2[k] += ar * tau + br * pik;
            y2[k] += ai * tau + bi * pik;
            p[k] = up * m[k] * pik - down * q[k];
            q[k] = pik;
        }
    }
    s1.resize(count);
    s2.resize(count);
    for (size_t k = 0; k < count; ++k) {
        s1[k] = {s1_re[k], s1_im[k]};
        s2[k] = {s2_re[k], s2_im[k]};
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
