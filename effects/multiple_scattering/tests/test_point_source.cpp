// The point lamp's multiple-scattering builder (effects/multiple_scattering/point_source.cpp,
// physics.md sections 10 to 12): the azimuthal phase mean against brute-force
// quadrature and its normalisation, energy conservation of the Monte Carlo
// source (every order >= 2 scattering of an infinite medium: 4 pi a^2 / (1 - a)), the far field's
// decay rate and its seam with the bins,
// results independent of the thread count, the seed noise of the table, and
// its build time. Run with --analysis to print the timings and noise.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "check.hpp"
#include "point_source.hpp"
#include "shader_cpp.hpp"

using namespace airlight;

namespace {

constexpr double kPi = 3.14159265358979323846;
bool g_print = false;

PointSourcePhase hg(double g) {
    PointSourcePhase p;
    p.hg.push_back({g, 1.0});
    return p;
}

double hg_value(double g, double mu) { return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5)); }

void check_azimuthal_phase() {
    for (double g : {0.0, 0.5, 0.9, -0.7}) {
        for (double ci : {0.99, 0.3, -0.6}) {
            for (double co : {0.95, 0.1, -0.9}) {
                const double si = std::sqrt(1 - ci * ci), so = std::sqrt(1 - co * co);
                double brute = 0.0;
                const int n = 200000;
                for (int k = 0; k < n; ++k) {
                    const double phi = 2.0 * kPi * (k + 0.5) / n;
                    brute += hg_value(g, ci * co + si * so * std::cos(phi)) / n;
                }
                const double got = azimuthal_phase(hg(g), ci, co);
                CHECK_MSG(std::abs(got - brute) <= 1e-9 + 1e-7 * brute, std::to_string(g));
            }
        }
        // Normalised: int pbar(ci, co) 2 pi dco = 1.
        double sum = 0.0;
        const int n = 400000;
        for (int k = 0; k < n; ++k) {
            const double co = -1.0 + 2.0 * (k + 0.5) / n;
            sum += azimuthal_phase(hg(g), 0.2, co) * 2.0 * kPi * 2.0 / n;
        }
        CHECK_MSG(std::abs(sum - 1.0) < 1e-4, std::to_string(sum));
    }
    PointSourcePhase rayleigh;
    rayleigh.rayleigh_weight = 1.0;
    CHECK(std::abs(azimuthal_phase(rayleigh, 1.0, 1.0) - 3.0 / (8.0 * kPi)) < 1e-12);
}

// Sum over the field of J dV dOmega: the power scattered at orders >= 2.
double field_power(const PointSourceField& f, int c) {
    double total = 0.0;
    for (int j = 0; j < f.nt; ++j) {
        const double x0 = double(j) / f.nt, x1 = double(j + 1) / f.nt;
        const double omega = 2.0 * kPi * (std::cos(kPi * x0 * x0) - std::cos(kPi * x1 * x1));
        total += f.core[size_t(c)][size_t(j)] * 2.0 * kPi * f.r_core * f.r_core * omega;
        for (int i = 0; i < f.nr; ++i) {
            const double r0 = f.bin_edge(i), r1 = f.bin_edge(i + 1);
            total += f.source[size_t(c)][size_t(i) * size_t(f.nt) + size_t(j)] * 4.0 / 3.0 * kPi *
                     (r1 * r1 * r1 - r0 * r0 * r0) * omega;
        }
    }
    return total;
}

void check_energy() {
    PointSourceSettings s;
    s.collision_budget = 2e6;
    for (double g : {0.0, 0.9}) {
        const std::array<double, 3> albedo = {0.5, 0.8, 0.0};
        const PointSourceField f = point_source_field(hg(g), albedo, s);
        for (int c = 0; c < 3; ++c) {
            const double a = albedo[size_t(c)], want = 4.0 * kPi * a * a / (1.0 - a), got = field_power(f, c);
            if (g_print) std::printf("energy g %.2f a %.2f: %.5f want %.5f\n", g, a, got, want);
            CHECK_MSG(a == 0.0 ? got == 0.0 : std::abs(got / want - 1.0) < 0.01, std::to_string(got));
        }
    }
}

// kappa_0 of the diffusion mode (eq. 11.11): for isotropic scattering the root of
// a artanh(kappa) / kappa = 1 (eq. 11.8); 0 for albedo 1, 1 for albedo 0; smaller for a forward
// phase; and the diffusion limit sqrt(3 (1 - a)(1 - a g)) as the albedo tends to 1.
void check_diffusion_mode_rate() {
    for (double a : {0.3, 0.5, 0.9, 0.99, 0.999}) {
        double lo = 1e-12, hi = 1.0 - 1e-15;
        for (int k = 0; k < 200; ++k) {
            const double mid = 0.5 * (lo + hi);
            (a * std::atanh(mid) / mid > 1.0 ? hi : lo) = mid;
        }
        const double got = diffusion_mode_rate(hg(0.0), a);
        if (g_print) std::printf("kappa_0 isotropic a %.3f: %.12f exact %.12f\n", a, got, lo);
        CHECK_MSG(std::abs(got - lo) < 1e-7, std::to_string(got) + " " + std::to_string(lo));
    }
    CHECK(diffusion_mode_rate(hg(0.5), 1.0) == 0.0 && diffusion_mode_rate(hg(0.5), 0.0) == 1.0);
    double previous = 1.0;
    for (double g : {0.0, 0.5, 0.9, 0.95}) {
        const double k = diffusion_mode_rate(hg(g), 0.9);
        CHECK_MSG(k < previous && k > 0.0, std::to_string(g));
        previous = k;
        const double a = 0.99999, diffusion = std::sqrt(3.0 * (1.0 - a) * (1.0 - a * g));
        const double near_one = diffusion_mode_rate(hg(g), a);
        CHECK_MSG(std::abs(near_one / diffusion - 1.0) < 0.02,
                  std::to_string(near_one) + " " + std::to_string(diffusion));
    }
}

// The far field (eq. 11.10) takes over from the bins without a jump: the scalar J (integrated over
// directions) just inside and just beyond r_far agree within the bins' noise.
void check_far_field_continues_the_bins() {
    for (double a : {0.5, 0.9}) {
        const PointSourceField f = point_source_field(hg(0.0), {a, a, a});
        CHECK_MSG(f.r_far[0] < f.r_kill, std::to_string(a));
        auto scalar = [&](double r) {
            double sum = 0.0;
            for (int j = 0; j < 400; ++j) sum += f.at(0, r, -1.0 + (j + 0.5) / 200.0) / 200.0;
            return sum;
        };
        const double inside = scalar(f.r_far[0] - 0.3), beyond = scalar(f.r_far[0] + 0.3);
        const double mode = std::exp(-0.6 * f.kappa[0]) * (f.r_far[0] - 0.3) / (f.r_far[0] + 0.3);
        if (g_print)
            std::printf("far field a %.2f: r_far %.2f, J beyond / inside %.4f, the mode %.4f\n", a, f.r_far[0],
                        beyond / inside, mode);
        CHECK_MSG(std::abs(beyond / inside / mode - 1.0) < 0.05, std::to_string(beyond / inside / mode));
    }
}

void check_threads_do_not_matter() {
    PointSourceSettings one, two;
    one.collision_budget = two.collision_budget = 1e6;
    one.threads = 1;
    two.threads = 2;
    const PointSourceField a = point_source_field(hg(0.5), {0.9, 0.9, 0.9}, one);
    const PointSourceField b = point_source_field(hg(0.5), {0.9, 0.9, 0.9}, two);
    CHECK(a.photons == b.photons && a.source[0] == b.source[0] && a.core[1] == b.core[1]);
}

// Two seeds: the radiance at a few (tau, gamma) differs by the table's noise (printed).
void check_seed_noise() {
    for (double g : {0.0, 0.95}) {
        PointSourceSettings s1, s2;
        s2.seed = 1234;
        const auto t0 = std::chrono::steady_clock::now();
        const PointSourceField f1 = point_source_field(hg(g), {0.9, 0.9, 0.9}, s1);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const PointSourceField f2 = point_source_field(hg(g), {0.9, 0.9, 0.9}, s2);
        double worst = 0.0;
        for (double tau : {0.5, 2.0, 5.0, 20.0})
            for (double deg : {0.5, 5.0, 30.0, 90.0, 180.0}) {
                const double a = point_source_radiance(f1, tau, deg * kPi / 180.0)[0];
                const double b = point_source_radiance(f2, tau, deg * kPi / 180.0)[0];
                worst = std::max(worst, std::abs(a - b) / (0.5 * (a + b)));
                if (g_print)
                    std::printf("  tau %5.1f gamma %5.1f: %.5g %.5g (%+.4f)\n", tau, deg, a, b,
                                (a - b) / (0.5 * (a + b)));
            }
        if (g_print)
            std::printf("g %.2f: %ld photons, %.3g collisions, MC %.2f s, worst seed difference %.4f\n", g, f1.photons,
                        f1.collisions, seconds, worst);
    }
}

// The table's bilinear interpolation of log L (as the shader does it, lamp_ms_math.glsl's coordinates)
// against the field's own line integral at points between the nodes.
void check_table_interpolation() {
    using namespace shader;
    PointSourceSettings s;
    s.collision_budget = 4e6;
    for (double g : {0.0, 0.9}) {
        const PointSourcePhase phase = hg(g);
        const PointSourceField field = point_source_field(phase, {0.9, 0.9, 0.9}, s);
        const Table2D t = build_lamp_ms_table(phase, {0.9, 0.9, 0.9}, s);
        double worst = 0.0, sum = 0.0;
        int count = 0;
        for (double tau : {0.013, 0.37, 1.7, 4.3, 11.0, 27.0})
            for (double deg : {0.7, 3.3, 13.0, 41.0, 97.0, 163.0}) {
                const double gamma = deg * kPi / 180.0;
                const double fx = double(lamp_ms_x(float(tau))) * (t.width - 1);
                const double fy = double(lamp_ms_y(float(gamma))) * (LAMP_MS_NY - 1);
                const int ix = std::min(int(fx), t.width - 2), iy = std::min(int(fy), LAMP_MS_NY - 2);
                const double ax = fx - ix, ay = fy - iy;
                auto texel = [&](int x, int y) {
                    return double(t.texels[(size_t(y) * size_t(t.width) + size_t(x)) * 4]);
                };
                const double log_l = (1 - ay) * ((1 - ax) * texel(ix, iy) + ax * texel(ix + 1, iy)) +
                                     ay * ((1 - ax) * texel(ix, iy + 1) + ax * texel(ix + 1, iy + 1));
                const double want = point_source_radiance(field, tau, gamma)[0];
                const double err = std::abs(std::exp(log_l) / want - 1.0);
                if (g_print && err > 0.01) std::printf("  interp tau %g deg %g: %.4f\n", tau, deg, err);
                worst = std::max(worst, err);
                sum += err;
                ++count;
            }
        if (g_print) std::printf("table interpolation g %.2f: mean %.4f worst %.4f\n", g, sum / count, worst);
        CHECK_MSG(worst < 0.05 && sum / count < 0.01, std::to_string(worst));
    }
}

// The azimuthal integral of the cosine factor (physics.md section 13, eq. 13.3) against brute force,
// and its hemisphere integral: a uniform radiance 1 gives the irradiance pi at every tilt.
void check_hemisphere_kernel() {
    for (double beta : {0.0, 0.3, 1.2, kPi / 2, 2.0, 2.9, kPi}) {
        for (double gamma : {0.0, 0.1, 0.7, 1.5, 2.2, 3.0, kPi}) {
            double brute = 0.0;
            const int n = 100000;
            for (int k = 0; k < n; ++k) {
                const double phi = 2.0 * kPi * (k + 0.5) / n;
                brute +=
                    std::max(std::cos(beta) * std::cos(gamma) + std::sin(beta) * std::sin(gamma) * std::cos(phi), 0.0) *
                    2.0 * kPi / n;
            }
            CHECK_MSG(std::abs(hemisphere_kernel(beta, gamma) - brute) < 1e-8, std::to_string(beta));
        }
        double total = 0.0;
        const int n = 200000;
        for (int k = 0; k < n; ++k) {
            const double gamma = kPi * (k + 0.5) / n;
            total += hemisphere_kernel(beta, gamma) * std::sin(gamma) * kPi / n;
        }
        CHECK_MSG(std::abs(total - kPi) < 1e-6, std::to_string(total));
    }
}

// The table's surface rows (log E, bilinear as the shader reads them) against the direct quadrature
// of the field's line integrals (point_source_irradiance, 1500 directions), between the nodes and on them.
// Asserted on the albedo-0.9 channel (as the glow's interpolation above); the albedo-0.5 channel is
// printed: beyond tau ~ 10 its field (E below e^-15 of the lamp's) is the Monte Carlo's noise, which
// the rows and the direct quadrature sample at different angles.
void check_surface_rows() {
    using namespace shader;
    PointSourceSettings s;
    s.collision_budget = 4e6;
    for (double g : {0.0, 0.9}) {
        const PointSourcePhase phase = hg(g);
        const std::array<double, 3> albedo = {0.9, 0.5, 0.0};
        const PointSourceField field = point_source_field(phase, albedo, s);
        const Table2D t = build_lamp_ms_table(phase, albedo, s);
        CHECK(t.height == LAMP_MS_NY + LAMP_MS_NB);
        double worst = 0.0, sum = 0.0;
        int count = 0;
        const std::vector<double> degs = {0.0, 17.0, 61.0, 90.0, 119.0, 151.0, 180.0};
        std::vector<double> betas;
        for (double d : degs) betas.push_back(d * kPi / 180.0);
        for (double tau : {0.001, 0.013, 0.37, 1.7, 4.3, 11.0, 27.0}) {
            const std::vector<std::array<double, 3>> want = point_source_irradiance(field, tau, betas, 1500);
            for (size_t b = 0; b < betas.size(); ++b) {
                const double fx = double(lamp_ms_x(float(tau))) * (t.width - 1);
                const double fy = double(lamp_ms_surface_y(float(std::cos(betas[b])))) * (LAMP_MS_NB - 1);
                const int ix = std::min(int(fx), t.width - 2), iy = std::min(int(fy), LAMP_MS_NB - 2);
                const double ax = fx - ix, ay = fy - iy;
                auto texel = [&](int x, int y, int c) {
                    return double(t.texels[(size_t(LAMP_MS_NY + y) * size_t(t.width) + size_t(x)) * 4 + size_t(c)]);
                };
                for (int c = 0; c < 2; ++c) {
                    const double log_e = (1 - ay) * ((1 - ax) * texel(ix, iy, c) + ax * texel(ix + 1, iy, c)) +
                                         ay * ((1 - ax) * texel(ix, iy + 1, c) + ax * texel(ix + 1, iy + 1, c));
                    const double err = std::abs(std::exp(log_e) / want[b][size_t(c)] - 1.0);
                    if (g_print && err > 0.01)
                        std::printf("  surface tau %g beta %g a %.1f: %.4f\n", tau, degs[b], albedo[size_t(c)], err);
                    if (c == 0) {
                        worst = std::max(worst, err);
                        sum += err;
                        ++count;
                    }
                    // The culling bound is above every value at this tau.
                    CHECK(texel(ix, 0, 3) >= texel(ix, iy, c) && texel(ix + 1, 0, 3) >= texel(ix + 1, iy, c));
                }
                // Albedo 0: the channel's rows are empty.
                CHECK(texel(ix, iy, 2) == double(LAMP_MS_LOG_FLOOR));
            }
        }
        if (g_print) std::printf("surface rows g %.2f albedo 0.9: mean %.4f worst %.4f\n", g, sum / count, worst);
        CHECK_MSG(worst < 0.06 && sum / count < 0.015, std::to_string(worst));
    }
}

void print_build_times() {
    for (double g : {0.0, 0.5, 0.9, 0.95})
        for (double a : {0.5, 0.9, 0.99}) {
            const auto t0 = std::chrono::steady_clock::now();
            const Table2D t = build_lamp_ms_table(hg(g), {a, a, a});
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::printf("build g %.2f albedo %.2f: %.2f s (%dx%d)\n", g, a, seconds, t.width, t.height);
        }
}

}  // namespace

int main(int argc, char** argv) {
    g_print = argc > 1 && std::strcmp(argv[1], "--analysis") == 0;
    check_azimuthal_phase();
    check_energy();
    check_diffusion_mode_rate();
    check_far_field_continues_the_bins();
    check_threads_do_not_matter();
    check_table_interpolation();
    check_hemisphere_kernel();
    check_surface_rows();
    if (g_print) {
        check_seed_noise();
        if (argc > 2) print_build_times();
    }
    return airlight_test::test_result("test_point_source");
}
