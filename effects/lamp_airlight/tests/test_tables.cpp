// The scattering tables (effects/lamp_airlight/airlight_tables.cpp) against independent evaluations, and
// the error analysis that chose their resolutions (effects/lamp_airlight/docs/airlight_table.md):
// run `build/cpp/test_tables --analysis` for the full tables of numbers.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "airlight_tables.hpp"
#include "check.hpp"
#include "numerics.hpp"
#include "shader_cpp.hpp"

using namespace airlight;

namespace airlight::shader {
// The production sampling code (airlight.glsl) over an arbitrary table.
struct TableSampler {
    const Table2D* tail = nullptr;
    const Table2D* glow = nullptr;
    FrameUniforms frame{};  // unused here (culling)
    vec4 table_texel4(int table, int x, int y) const {
        const Table2D& t = table == TABLE_AIRLIGHT_TAIL ? *tail : *glow;
        return vec4(t.texels[size_t(y) * t.width + x], 0.0f, 0.0f, 1.0f);
    }
#include "airlight.glsl"
    float table_texel(int table, int x, int y) const { return table_texel4(table, x, y).x; }
#include "tables.glsl"
};
}  // namespace airlight::shader

namespace {

using numerics::kPi;

template <class F>
double adaptive_simpson(const F& f, double a, double b, double fa, double fm, double fb, double whole, double tol,
                        int depth) {
    const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    const double flm = f(lm), frm = f(rm);
    const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm), right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    if (depth <= 0 || std::abs(left + right - whole) <= 15.0 * tol) return left + right + (left + right - whole) / 15.0;
    return adaptive_simpson(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
           adaptive_simpson(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
}

// Q(u, v) = e^{u tan v} int_v^{pi/2} e^{-u tan t} dt by adaptive Simpson in
// y, with pi/2 - t = cv e^{-y} (graded towards t = pi/2, where e^{-u tan t}
// vanishes): independent of the exponential-integral route of tables.cpp.
double tail_by_quadrature(double u, double cv) {
    const double y_max = std::log(cv / 1e-300);
    auto f = [&](double y) {
        const double psi = cv * std::exp(-y);  // pi/2 - t
        return std::exp(-u * std::sin(-cv * std::expm1(-y)) / (std::sin(psi) * std::sin(cv))) * psi;
    };
    // Start from pieces graded geometrically from the width cv / u of the
    // boundary layer at y = 0, so that the adaptive rule cannot miss it.
    std::vector<double> edges = {0.0};
    for (double e = 1e-3 * std::min(1.0, cv / std::max(u, 1e-300)); e < y_max; e *= 1.5) edges.push_back(e);
    edges.push_back(y_max);
    const int pieces = int(edges.size()) - 1;
    const double tol = 1e-13 * cv / (1.0 + u * cv / (std::sin(cv) * std::sin(cv))) / pieces;  // ~1e-13 Q
    double total = 0.0;
    for (int i = 0; i < pieces; ++i) {
        const double a = edges[i], b = edges[i + 1];
        const double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
        total += adaptive_simpson(f, a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), tol, 40);
    }
    return total;
}

void test_tail_exact_matches_quadrature() {
    double worst = 0.0;
    for (double u : {1e-6, 1e-3, 0.1, 1.0, 3.0, 10.0, 100.0, 1e4}) {
        for (double cv : {1e-6, 1e-3, 0.1, 0.5, 1.0, 1.5, 1.5707}) {
            const double a = airlight_tail_exact(u, cv), b = tail_by_quadrature(u, cv);
            worst = std::max(worst, std::abs(a / b - 1.0));
        }
    }
    CHECK_MSG(worst < 1e-9, std::to_string(worst));
    CHECK(airlight_tail_exact(0.0, 0.7) == 0.7);  // F(0, v) = v
}

// Max relative error of the sampled tail N * S against Q, at random points.
double tail_table_error(const Table2D& table, int samples, std::mt19937& rng) {
    shader::TableSampler sampler;
    sampler.tail = &table;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worst = 0.0;
    for (int i = 0; i < samples; ++i) {
        const double u = std::pow(10.0, -6.0 + 10.0 * unit(rng));
        const double cv = unit(rng) < 0.5 ? 0.5 * kPi * unit(rng) : std::pow(10.0, -6.0 + 6.0 * unit(rng)) * 1.5;
        const float s = float(std::sin(cv)), z = float(u / std::sin(cv));
        const float X = std::sqrt(z / (1.0f + z)), Y = 1.0f - float(cv) * float(2.0 / kPi);
        const float S = sampler.table_bilinear(shader::TABLE_AIRLIGHT_TAIL, table.width, table.height, X, Y);
        const double N = cv / (1.0 + u * cv / (double(s) * s));
        const double exact = airlight_tail_exact(u, cv);
        if (exact > 0) worst = std::max(worst, std::abs(N * S / exact - 1.0));
    }
    return worst;
}

// Max relative error of the sampled glow table against the exact glow, over
// random (T, theta_s) with T < T_max; glows below 1e-6 of G(0, 0) are skipped
// (a lit surface's glow there is below float precision of its direct light).
double glow_table_error(const Table2D& table, int samples, std::mt19937& rng, double T_lo, double T_hi) {
    shader::TableSampler sampler;
    sampler.glow = &table;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double g00 = std::exp(*std::max_element(table.texels.begin(), table.texels.end()));
    double worst = 0.0;
    for (int i = 0; i < samples; ++i) {
        const double T =
            T_lo == 0.0 && unit(rng) < 0.5 ? T_hi * std::pow(10.0, -6.0 * unit(rng)) : T_lo + (T_hi - T_lo) * unit(rng);
        const double theta = kPi * unit(rng);
        const double exact = surface_glow_exact(T, theta);
        if (exact < 1e-6 * g00) continue;
        const float G =
            std::exp(sampler.surface_glow_log_lookup(shader::TABLE_SURFACE_GLOW, shader::SURFACE_GLOW_K_MIN, float(T),
                                                     float(std::cos(theta)), table.width, table.height));
        worst = std::max(worst, std::abs(G / exact - 1.0));
    }
    return worst;
}

void test_tables_within_budget() {
    std::mt19937 rng(7);
    const double tail = tail_table_error(airlight_tail_table(), 20000, rng);
    CHECK_MSG(tail < 1e-4, "tail table " + std::to_string(tail));
    const double glow = glow_table_error(surface_glow_table(), 3000, rng, 0.0, 88.0);
    CHECK_MSG(glow < 1e-3, "glow table " + std::to_string(glow));
}

void test_glow_quadrature_converged() {
    double worst = 0.0;
    for (double T : {0.0, 1e-3, 0.1, 1.0, 10.0, 99.0}) {
        for (double theta : {0.0, 0.7, 1.5707963, 2.2, 3.1}) {
            const double a = surface_glow_exact(T, theta, 1), b = surface_glow_exact(T, theta, 4);
            if (b > 0) worst = std::max(worst, std::abs(a / b - 1.0));
        }
    }
    CHECK_MSG(worst < 1e-6, std::to_string(worst));
}

void test_glow_limits() {
    // T = 0, light straight above: G = pi int_0^{pi/2} (pi - g) cos g dg
    // = pi [(pi - g) sin g - cos g]_0^{pi/2} = pi (pi/2 + 1) = pi^2/2 + pi.
    const double closed_form = kPi * (kPi / 2.0 + 1.0);
    CHECK_MSG(std::abs(surface_glow_exact(0.0, 0.0) / closed_form - 1.0) < 1e-9,
              std::to_string(surface_glow_exact(0.0, 0.0)) + " vs " + std::to_string(closed_form));
    // The table holds log G; its largest texel is G(0, theta_s = 0) (row Y = 1),
    // and G(0, 0) exceeds G anywhere, so SURFACE_GLOW_G_BOUND bounds every
    // lookup (bilinear interpolation never exceeds the largest texel): the
    // culling bounds of the lamps' and spots' glow rely on it.
    const Table2D& t = surface_glow_table();
    const float top_left = t.texels[size_t(t.height - 1) * t.width];
    CHECK(*std::max_element(t.texels.begin(), t.texels.end()) == top_left);
    CHECK(std::exp(double(top_left)) <= double(shader::SURFACE_GLOW_G_BOUND));
    CHECK(closed_form <= double(shader::SURFACE_GLOW_G_BOUND));
    CHECK_MSG(std::abs(std::exp(double(top_left)) / surface_glow_exact(0.0, 0.0) - 1.0) < 1e-6,
              std::to_string(top_left));
    CHECK(std::all_of(t.texels.begin(), t.texels.end(), [](float v) { return std::isfinite(v); }));
}

void print_analysis() {
    std::mt19937 rng(11);
    std::printf("airlight tail table: max relative error of N*S vs exact Q (20000 random (u, xi))\n");
    for (auto [nx, ny] : {std::pair{64, 64}, {128, 64}, {256, 32}, {256, 64}, {512, 128}}) {
        // Rebuild at other sizes by sampling the exact function on the same grid definition.
        Table2D t;
        t.width = nx;
        t.height = ny;
        t.texels.resize(size_t(nx) * ny);
        for (int iy = 0; iy < ny; ++iy) {
            const double cv = (1.0 - double(iy) / (ny - 1)) * 0.5 * kPi;
            for (int ix = 0; ix < nx; ++ix) {
                const double X = double(ix) / (nx - 1), r = X * X, z = r / (1.0 - r);
                double S = 1.0;
                if (ix > 0 && ix + 1 < nx) {
                    if (iy + 1 == ny) {
                        // Y = 1 row: use a point just below pi/2 (the limit is continuous).
                        const double c = 1e-9, s = std::sin(c), u = z * s;
                        S = airlight_tail_exact(u, c) / (c / (1.0 + u * c / (s * s)));
                    } else {
                        const double s = std::sin(cv), u = z * s;
                        S = airlight_tail_exact(u, cv) / (cv / (1.0 + u * cv / (s * s)));
                    }
                }
                t.texels[size_t(iy) * nx + ix] = float(S);
            }
        }
        std::printf("  %4d x %-4d %9.1e\n", nx, ny, tail_table_error(t, 20000, rng));
    }
    std::printf("surface glow table: max relative error vs exact G by optical distance T (4000 random (T, theta_s))\n");
    std::printf("  %-11s %10s %10s %10s %10s %10s\n", "size", "T<1", "1-10", "10-30", "30-60", "60-88");
    for (auto [nx, ny] : {std::pair{64, 48}, {96, 96}, {128, 96}, {192, 96}, {256, 128}}) {
        const Table2D t = build_surface_glow_table(nx, ny);
        std::printf("  %4d x %-4d", nx, ny);
        const double bands[6] = {0.0, 1.0, 10.0, 30.0, 60.0, 88.0};
        for (int b = 0; b < 5; ++b) {
            std::printf(" %10.1e", glow_table_error(t, 1500, rng, bands[b], bands[b + 1]));
        }
        std::printf("\n");
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::strcmp(argv[1], "--analysis") == 0) {
        print_analysis();
        std::printf("build time: tail %.3f s, glow %.3f s (%zu KiB and %zu KiB of float32)\n",
                    airlight_tail_table().build_seconds, surface_glow_table().build_seconds,
                    airlight_tail_table().texels.size() * 4 / 1024, surface_glow_table().texels.size() * 4 / 1024);
        return 0;
    }
    test_tail_exact_matches_quadrature();
    test_tables_within_budget();
    test_glow_quadrature_converged();
    test_glow_limits();
    return airlight_test::test_result("test_tables");
}
