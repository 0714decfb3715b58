// Lorenz-Mie (effects/rainbow/mie.cpp, issue 7 groundwork) against published values,
// limits, energy conservation and values of the independent numpy reference
// (effects/rainbow/tests/mie_reference.py, float64, same series written separately).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "check.hpp"
#include "mie.hpp"
#include "numerics.hpp"

using namespace airlight;

namespace {

using numerics::kPi;

bool near(double a, double b, double rel) { return std::abs(a - b) <= rel * std::abs(b); }

// Bohren & Huffman appendix A: radius 0.525 um, m = 1.55, lambda 0.6328 um.
void check_bhmie_example() {
    const double x = 2.0 * kPi * 0.525 / 0.6328;
    const MieCoefficients c = mie_coefficients({1.55, 0.0}, x);
    const MieEfficiencies q = mie_efficiencies(c);
    CHECK_MSG(near(q.extinction, 3.10543, 2e-6), std::to_string(q.extinction));
    CHECK_MSG(near(q.scattering, 3.10543, 2e-6), std::to_string(q.scattering));
    std::vector<std::complex<double>> s1, s2;
    mie_amplitudes(c, {kPi}, s1, s2);
    const double q_back = 4.0 * std::norm(s1[0]) / (x * x);
    CHECK_MSG(near(q_back, 2.92534, 2e-6), std::to_string(q_back));
}

void check_rayleigh_limit() {
    const std::complex<double> m(1.333, 0.0);
    const double x = 0.01;
    const double k = std::abs((m * m - 1.0) / (m * m + 2.0));
    CHECK(near(mie_efficiencies(mie_coefficients(m, x)).scattering, 8.0 / 3.0 * std::pow(x, 4) * k * k, 1e-4));
    std::vector<double> theta;
    for (int i = 0; i <= 36; ++i) theta.push_back(kPi * i / 36.0);
    const std::vector<double> p = mie_phase_function(m, x, theta);
    for (size_t i = 0; i < theta.size(); ++i) {
        const double c = std::cos(theta[i]);
        CHECK(near(p[i], 3.0 / (16.0 * kPi) * (1.0 + c * c), 1e-4));
    }
}

// int p dOmega = 1 on a grid graded toward the forward peak; Q_ext = Q_sca
// without absorption; Q_ext -> 2 for large drops.
void check_conservation() {
    for (double x : {50.0, 500.0}) {
        std::vector<double> theta;
        for (int i = 0; i <= 4000; ++i) theta.push_back(1e-6 * std::pow(20.0 / x / 1e-6, i / 4000.0));
        for (int i = 1; i <= 20000; ++i) theta.push_back(20.0 / x + (kPi - 20.0 / x) * i / 20000.0);
        const std::vector<double> p = mie_phase_function({1.333, 0.0}, x, theta);
        double sum = 0.0;
        for (size_t i = 1; i < theta.size(); ++i)
            sum += 0.5 * (p[i] * std::sin(theta[i]) + p[i - 1] * std::sin(theta[i - 1])) * (theta[i] - theta[i - 1]);
        CHECK_MSG(std::abs(2.0 * kPi * sum - 1.0) < 1e-4, std::to_string(2.0 * kPi * sum));
        const MieEfficiencies q = mie_efficiencies(mie_coefficients({1.333, 0.0}, x));
        CHECK(near(q.extinction, q.scattering, 1e-10));
    }
    const double q5000 = mie_efficiencies(mie_coefficients({1.333, 0.0}, 5000.0)).extinction;
    CHECK(std::abs(q5000 - 2.0) < 0.01);
}

// A 0.35 mm drop at 550 nm (x = 2000): values of the numpy reference
// (mie_reference.efficiencies / phase_function), at the forward peak, the
// sides, the primary bow (137-139 degrees), the secondary (129) and backward.
void check_against_numpy_reference() {
    const double x = 2000.0;
    const MieEfficiencies q = mie_efficiencies(mie_coefficients({1.333, 0.0}, x));
    CHECK_MSG(near(q.extinction, 2.011466634917105, 1e-10), std::to_string(q.extinction));
    const std::vector<double> degrees = {0.0, 10.0, 90.0, 137.0, 138.0, 139.0, 129.0, 180.0};
    const std::vector<double> expected = {160083.7914,   0.7480012798,  0.001279221012, 0.002153975177,
                                          0.03102018325, 0.04114504829, 0.0065055584,   0.06419039092};
    std::vector<double> theta;
    for (double d : degrees) theta.push_back(d * kPi / 180.0);
    const std::vector<double> p = mie_phase_function({1.333, 0.0}, x, theta);
    double worst = 0.0;
    for (size_t i = 0; i < p.size(); ++i) worst = std::max(worst, std::abs(p[i] / expected[i] - 1.0));
    std::printf("x = 2000 phase function against the numpy reference: worst relative difference %.1e\n", worst);
    CHECK(worst < 1e-8);
    const MieEfficiencies qa = mie_efficiencies(mie_coefficients({1.333, 1e-8}, x));
    CHECK(near(qa.extinction, 2.011467157311673, 1e-10) && near(qa.scattering, 2.0113976452538904, 1e-10));
}

// Analysis for the rainbow design (effects/rainbow/docs/rainbow.md section 2): the Marshall-
// Palmer average of the phase function over n drop sizes (midpoints, uniform
// in D over 0.1-3.5 mm; weight N(D) D^2 Q_sca), 550 nm, 25 mm/h, on 120-145
// degrees every 0.1 degree; how much it changes when n doubles, pointwise
// and in 1-degree bins.
std::vector<double> marshall_palmer_average(int n, double wavelength_nm, double rate, const std::vector<double>& theta,
                                            bool log_sizes = false) {
    const double lambda = 4.1 * std::pow(rate, -0.21);
    std::vector<std::vector<double>> phases(static_cast<size_t>(n), std::vector<double>());
    std::vector<double> weights(static_cast<size_t>(n), 0.0);
    const auto size = [&](int i) {
        // uniform in D, or in log D (then dD = D d(log D))
        const double d = log_sizes ? 0.1 * std::pow(35.0, (i + 0.5) / n) : 0.1 + 3.4 * (i + 0.5) / n;
        const double x = kPi * d * 1e-3 / (wavelength_nm * 1e-9);
        const MieCoefficients c = mie_coefficients({1.333, 0.0}, x);
        weights[size_t(i)] = std::exp(-lambda * d) * mie_efficiencies(c).scattering * d * d * (log_sizes ? d : 1.0);
        phases[size_t(i)] = mie_phase_function({1.333, 0.0}, x, theta);
    };
    numerics::parallel_for(n, size);
    std::vector<double> out(theta.size(), 0.0);
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
        total += weights[size_t(i)];
        for (size_t k = 0; k < theta.size(); ++k) out[k] += weights[size_t(i)] * phases[size_t(i)][k];
    }
    for (double& v : out) v /= total;
    return out;
}

void size_convergence_analysis() {
    std::vector<double> theta;
    for (int i = 0; i <= 250; ++i) theta.push_back((120.0 + 0.1 * i) * kPi / 180.0);
    std::vector<double> previous;
    std::printf("| sizes | seconds | change pointwise | change in 1-degree bins |\n|---|---|---|---|\n");
    for (int n : {100, 200, 400, 800}) {
        const auto start = std::chrono::steady_clock::now();
        const std::vector<double> p = marshall_palmer_average(n, 550.0, 25.0, theta);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        double pointwise = 0.0, binned = 0.0;
        if (!previous.empty()) {
            for (size_t k = 0; k < p.size(); ++k) pointwise = std::max(pointwise, std::abs(previous[k] / p[k] - 1.0));
            for (size_t k = 0; k + 10 <= p.size(); k += 10) {
                double a = 0.0, b = 0.0;
                for (size_t j = 0; j < 10; ++j) {
                    a += previous[k + j];
                    b += p[k + j];
                }
                binned = std::max(binned, std::abs(a / b - 1.0));
            }
        }
        std::printf("| %d | %.2f | %.3f | %.3f |\n", n, seconds, pointwise, binned);
        previous = p;
    }
}

// The same seen through the sun's disc (0.53 degrees: the 1-D profile of a
// uniform disc of radius 0.2665 degrees convolved in scattering angle), sizes
// uniform in log D, 125-142 degrees every 0.02 degree: the change when n doubles.
void disc_smoothed_convergence_analysis() {
    const double step = 0.02, radius = 0.2665;
    std::vector<double> theta;
    for (int i = 0; i <= 850; ++i) theta.push_back((125.0 + step * i) * kPi / 180.0);
    const int h = int(radius / step);
    std::vector<double> kernel;
    double kernel_sum = 0.0;
    for (int j = -h; j <= h; ++j) {
        const double t = j * step / radius;
        kernel.push_back(std::sqrt(std::max(0.0, 1.0 - t * t)));
        kernel_sum += kernel.back();
    }
    std::vector<double> previous;
    std::printf("\n| sizes (log-uniform) | seconds | change of the disc-smoothed phase |\n|---|---|---|\n");
    for (int n : {200, 400, 800, 1600}) {
        const auto start = std::chrono::steady_clock::now();
        const std::vector<double> p = marshall_palmer_average(n, 550.0, 25.0, theta, true);
        std::vector<double> smooth(p.size(), 0.0);
        for (size_t k = size_t(h); k + size_t(h) < p.size(); ++k) {
            for (int j = -h; j <= h; ++j) smooth[k] += kernel[size_t(j + h)] * p[size_t(int(k) + j)];
            smooth[k] /= kernel_sum;
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        double change = 0.0;
        if (!previous.empty())
            for (size_t k = size_t(h); k + size_t(h) < p.size(); ++k)
                change = std::max(change, std::abs(previous[k] / smooth[k] - 1.0));
        std::printf("| %d | %.1f | %.4f |\n", n, seconds, change);
        previous = smooth;
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::strcmp(argv[1], "--analysis") == 0) {
        size_convergence_analysis();
        disc_smoothed_convergence_analysis();
        return 0;
    }
    check_bhmie_example();
    check_rayleigh_limit();
    check_conservation();
    check_against_numpy_reference();
    return airlight_test::test_result("test_mie");
}
