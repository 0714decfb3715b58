// The falling rain's drops (physics.md sections 1-3).
#include "drops.hpp"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>

#include "airlight/scene_io.hpp"
#include "numerics.hpp"
#include "rainbow.hpp"
#include "sky.hpp"

namespace airlight {

namespace {

// Atlas, Srivastava and Sekhon's fit to Gunn and Kinzer (eq. 1.2, D >= 0.51 mm).
double atlas_speed(double d_mm) { return 9.65 - 10.3 * std::exp(-0.6 * d_mm); }

// A water sphere's terminal speed under the Schiller-Naumann drag law (eq. 1.2,
// small drops): v (1 + 0.15 Re^0.687) = v_Stokes with Re = rho_a v D / eta,
// solved by Newton's method from v_Stokes (the left side is convex and
// increasing in v, so the iterates fall monotonically to the root).
double schiller_naumann_speed(double d_mm) {
    constexpr double rho_air = 1.204, eta = 1.813e-5, rho_water = 998.2, g = 9.80665;  // 20 C, 1013 hPa
    const double d = 1e-3 * d_mm;
    const double v_stokes = g * d * d * (rho_water - rho_air) / (18.0 * eta);
    const double a = 0.15 * std::pow(rho_air * d / eta, 0.687);
    double v = v_stokes;
    for (int i = 0; i < 60 && v > 0.0; ++i) {
        const double v_0687 = std::pow(v, 0.687);  // one pow per step: v^1.687 = v v^0.687
        const double step = (v + a * v * v_0687 - v_stokes) / (1.0 + 1.687 * a * v_0687);
        v -= step;
        if (!(std::abs(step) > 1e-13 * v)) break;
    }
    return v;
}

}  // namespace

double rain_speed_crossing_mm() {
    // Where the drag law meets the fit, by bisection (the drag law is above the fit below it).
    static const double crossing = [] {
        double lo = 0.2, hi = 0.9;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (schiller_naumann_speed(mid) > atlas_speed(mid) ? lo : hi) = mid;
        }
        return 0.5 * (lo + hi);
    }();
    return crossing;
}

double terminal_speed(double d_mm) {
    if (!(d_mm > 0.0)) return 0.0;
    return d_mm >= rain_speed_crossing_mm() ? atlas_speed(d_mm) : schiller_naumann_speed(d_mm);
}

namespace {

// Integral over [lo, hi] mm of N(D) D^power (N0 exp(-Lambda D)), Gauss-Legendre on
// 64 panels (the integrands are smooth; exact to ~1e-12 relative).
template <class F>
double integrate(double lo, double hi, const F& f) {
    const int panels = 64;
    double sum = 0.0;
    for (int p = 0; p < panels; ++p) {
        const double a = lo + (hi - lo) * p / panels, b = lo + (hi - lo) * (p + 1) / panels;
        for (int k = 0; k < 8; ++k) {
            const double x = 0.5 * (a + b) + 0.5 * (b - a) * numerics::kGaussLegendre8Nodes[k];
            sum += 0.5 * (b - a) * numerics::kGaussLegendre8Weights[k] * f(x);
        }
    }
    return sum;
}

// splitmix64: the rain field's hash and random stream (section 3).
std::uint64_t mix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}
struct Stream {
    std::uint64_t state;
    double uniform() {  // in [0, 1)
        state = mix(state);
        return double(state >> 11) * (1.0 / 9007199254740992.0);
    }
};

// A Poisson count of the given mean (Knuth's product of uniforms; means here are ~4).
int poisson(Stream& s, double mean) {
    const double limit = std::exp(-mean);
    int n = 0;
    for (double p = s.uniform(); p > limit; p *= s.uniform()) ++n;
    return n;
}

double class_edge(int k) {
    return RAIN_DROP_MIN_MM * std::pow(RAIN_DROP_MAX_MM / RAIN_DROP_MIN_MM, double(k) / RAIN_DROP_CLASSES);
}

}  // namespace

double rain_number_density(double rate, double lo, double hi) {
    const double lam = marshall_palmer_slope(rate);
    // Closed form of the exponential's integral (eq. 1.3).
    return MARSHALL_PALMER_N0 / lam * (std::exp(-lam * lo) - std::exp(-lam * hi));
}

double rain_water_content(double rate, double lo, double hi) {
    const double lam = marshall_palmer_slope(rate);
    // pi/6 D^3 mm^3 of water at 1e-3 g/mm^3 per drop (eq. 1.3).
    return integrate(lo, hi, [&](double d) {
        return MARSHALL_PALMER_N0 * std::exp(-lam * d) * numerics::kPi / 6.0 * d * d * d * 1e-3;
    });
}

double rain_draw_distance(const FallingRain& rain, double d_mm) {
    return double(rain.radius) * std::min(1.0, d_mm / double(rain.full_diameter));
}

double rain_draw_weight(const FallingRain& rain, double d_mm, double dist) {
    const double r = rain_draw_distance(rain, d_mm);
    const double x = std::clamp((r - dist) / (FALLING_RAIN_FADE * r), 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

double rain_drawn_cross_section(const FallingRain& rain, double dist) {
    if (!(rain.rate > 0.0f)) return 0.0;
    const double lam = marshall_palmer_slope(rain.rate);
    // w(D, dist) has kinks where dist = r(D) and 0.75 r(D): many panels (eq. 2.3).
    return integrate(RAIN_DROP_MIN_MM, RAIN_DROP_MAX_MM, [&](double d) {
        return MARSHALL_PALMER_N0 * std::exp(-lam * d) * rain_draw_weight(rain, d, dist) * numerics::kPi / 4.0 * d * d *
               1e-6;
    });
}

std::vector<RainDrop> rain_drops(const FallingRain& rain, const glm::dvec3& camera, double exposure,
                                 const std::function<bool(const RainDrop&)>& keep) {
    std::vector<RainDrop> drops;
    if (!rain.present || !(rain.rate > 0.0f)) return drops;
    const double lam = marshall_palmer_slope(rain.rate);
    const double t_mid = rain.time - 0.5 * exposure;
    const glm::dvec3 wind(rain.wind);
    // The drops within their draw distances, expected (eq. 1.3 per class): beyond FALLING_RAIN_MAX_SPHERE
    // the frame's drops are not even counted (the bound on the time spent drawing them).
    double expected = 0.0;
    for (int k = 0; k < RAIN_DROP_CLASSES; ++k) {
        const double reach = rain_draw_distance(rain, class_edge(k + 1));
        expected += rain_number_density(rain.rate, class_edge(k), class_edge(k + 1)) * 4.0 / 3.0 * numerics::kPi *
                    reach * reach * reach;
    }
    if (expected > double(FALLING_RAIN_MAX_SPHERE))
        throw SceneError(SceneError::Kind::value, "falling_rain.radius",
                         "about " + std::to_string(std::llround(expected)) +
                             " drops within their draw distances, more than " +
                             std::to_string(FALLING_RAIN_MAX_SPHERE) +
                             " (the bound on the time spent drawing them); lower it or raise "
                             "falling_rain.full_diameter");
    for (int k = 0; k < RAIN_DROP_CLASSES; ++k) {
        const double d_lo = class_edge(k), d_hi = class_edge(k + 1);
        const double v_lo = terminal_speed(d_lo), v_hi = terminal_speed(d_hi);
        const double reach = rain_draw_distance(rain, d_hi);
        // Drops crossing the plane y = 0 per m^2 per s (eq. 3.1).
        const double flux = integrate(
            d_lo, d_hi, [&](double d) { return MARSHALL_PALMER_N0 * std::exp(-lam * d) * terminal_speed(d); });
        if (!(flux > 0.0)) continue;
        // Cells of (xi_x, xi_z, t0) holding 4 drops on average, xi = crossing point - wind t0 (eq. 3.2).
        const double cell = std::max(0.5 * reach, 1e-3);
        const double cell_t = 4.0 / (flux * cell * cell);
        // Crossing times of the drops within `reach` of the camera's height at t_mid (eq. 3.3).
        const double ya = camera.y - reach, yb = camera.y + reach;
        const double t0_lo = t_mid + std::min(ya / v_lo, ya / v_hi), t0_hi = t_mid + std::max(yb / v_lo, yb / v_hi);
        const double xi_x = camera.x - wind.x * t_mid, xi_z = camera.z - wind.z * t_mid;
        const auto first = [](double lo, double size) { return (long long)std::floor(lo / size); };
        for (long long n = first(t0_lo, cell_t); double(n) * cell_t <= t0_hi; ++n)
            for (long long j = first(xi_z - reach, cell); double(j) * cell <= xi_z + reach; ++j)
                for (long long i = first(xi_x - reach, cell); double(i) * cell <= xi_x + reach; ++i) {
                    std::uint64_t h = mix(std::uint64_t(rain.seed) * 0x100000001B3ull + std::uint64_t(k));
                    h = mix(h ^ std::uint64_t(n));
                    h = mix(h ^ std::uint64_t(j));
                    h = mix(h ^ std::uint64_t(i));
                    Stream s{h};
                    const int count = poisson(s, flux * cell * cell * cell_t);
                    for (int m = 0; m < count; ++m) {
                        const double px = (double(i) + s.uniform()) * cell;
                        const double pz = (double(j) + s.uniform()) * cell;
                        const double t0 = (double(n) + s.uniform()) * cell_t;
                        // D with density proportional to N(D) v(D) on the class (eq. 3.4): the
                        // truncated exponential by its inverse, kept with probability v / v_hi.
                        double d = d_lo;
                        for (;;) {
                            const double u = s.uniform();
                            d = d_lo - std::log1p(-u * (1.0 - std::exp(-lam * (d_hi - d_lo)))) / lam;
                            if (s.uniform() * v_hi <= terminal_speed(d)) break;
                        }
                        RainDrop drop;
                        drop.diameter = d;
                        drop.velocity = glm::dvec3(wind.x, -terminal_speed(d), wind.z);
                        drop.position =
                            glm::dvec3(px + wind.x * t_mid, -terminal_speed(d) * (t_mid - t0), pz + wind.z * t_mid);
                        const double dist = glm::length(drop.position - camera);
                        if (dist > rain_draw_distance(rain, d)) continue;
                        drop.weight = rain_draw_weight(rain, d, dist);
                        drop.id = mix(h ^ std::uint64_t(m));
                        if (keep && !keep(drop)) continue;
                        if (drops.size() >= FALLING_RAIN_MAX_DROPS)
                            throw SceneError(SceneError::Kind::value, "falling_rain.radius",
                                             "more than " + std::to_string(FALLING_RAIN_MAX_DROPS) +
                                                 " drops in view (the drop tables' memory bound); lower it "
                                                 "or raise falling_rain.full_diameter");
                        drops.push_back(drop);
                    }
                }
    }
    return drops;
}

}  // namespace airlight
