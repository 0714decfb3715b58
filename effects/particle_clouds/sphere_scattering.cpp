// Light scattered inside the reference particle, order by order
// (effects/particle_clouds/physics.md section 2).
#include "sphere_scattering.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "numerics.hpp"

namespace airlight {
namespace {

using numerics::kPi;

struct Vec {
    double x, y, z;
};
Vec operator+(const Vec& a, const Vec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator*(double s, const Vec& a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(const Vec& a, const Vec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec cross(const Vec& a, const Vec& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

// Distance from p (inside or on the unit sphere) along the unit d to the surface.
double exit_distance(const Vec& p, const Vec& d) {
    const double b = dot(p, d), c = std::min(0.0, dot(p, p) - 1.0);
    const double root = std::sqrt(b * b - c);
    return b > 0.0 ? -c / (b + root) : root - b;  // the larger root of t^2 + 2 b t + c, without cancellation
}

// Radial nodes graded toward the surface (eq. 2.7): the depth u = 1 - r at
// index x (0..1) is (c / a) log1p(k expm1(a x)), k = s (n - 1) / c. The steps
// start at s, `surface_step` optical depths or 0.35 of the uniform step where
// that is smaller, grow geometrically and level off at c times the uniform step.
struct RadialMap {
    static constexpr double kCap = 2.0;  // c: the largest step over the uniform one
    int n = 2;
    double a = 0.0, k = 0.0;

    RadialMap(int nodes, double tau, double surface_step) : n(nodes) {
        const double first = std::min(surface_step / tau, 0.35 / (n - 1));
        k = first * (n - 1) / kCap;
        double lo = 1e-9, hi = 500.0;  // the depth at x = 1 rises with a, from first (n - 1) < 1 to kCap > 1
        for (int it = 0; it < 200; ++it) {
            const double mid = 0.5 * (lo + hi);
            (kCap / mid * std::log1p(k * std::expm1(mid)) < 1.0 ? lo : hi) = mid;
        }
        a = 0.5 * (lo + hi);
    }
    double radius(int i) const {
        if (i >= n - 1) return 0.0;
        return 1.0 - std::min(1.0, kCap / a * std::log1p(k * std::expm1(a * double(i) / (n - 1))));
    }
    double index(double r) const {  // fractional node index of radius r
        const double u = std::clamp(1.0 - r, 0.0, 1.0);
        return std::min(1.0, std::log1p(std::expm1(a * u / kCap) / k) / a) * (n - 1);
    }
};

// A point of the 4-D grid: the lower node and the fraction toward the next, per axis (r, polar, zenith, azimuth).
struct GridPoint {
    std::array<int, 4> node;
    std::array<double, 4> frac;
};

using numerics::node_and_fraction;

}  // namespace

TerminatorNodes::TerminatorNodes(int nodes, double tau) : n_(nodes) {
    if (nodes < 2) throw std::invalid_argument("TerminatorNodes: nodes must be at least 2");
    const double uniform = kPi / (n_ - 1), step = tau > 0.0 ? std::min(uniform, kStep / tau) : uniform;
    w_ = std::min(kWidth, 0.25 * (n_ - 1)) * step;
    // The step at phi = 0 is (2 / (n - 1)) G(pi / 2) / (1 + k), G(pi / 2) = pi / 2 + k w tanh(pi / 2w).
    const double span = w_ * std::tanh(0.5 * kPi / w_);
    k_ = std::max(0.0, (uniform - step) / (step - 2.0 * span / (n_ - 1)));
}

double TerminatorNodes::angle(int j) const {
    if (j <= 0) return 0.0;
    if (j >= n_ - 1) return kPi;
    double lo = 0.0, hi = kPi;  // index() rises with the angle
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (index(mid) < j ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double TerminatorNodes::index(double theta) const {
    auto g = [&](double phi) { return phi + k_ * w_ * std::tanh(phi / w_); };
    return 0.5 * (g(theta - 0.5 * kPi) / g(0.5 * kPi) + 1.0) * (n_ - 1);
}

void validate_sphere_grid(const SphereGrid& grid) {
    auto check = [](const char* name, int value, int lo, int hi) {
        if (value < lo || value > hi)
            throw std::invalid_argument(std::string("grid.") + name + ": must be an integer in [" + std::to_string(lo) +
                                        ", " + std::to_string(hi) + "], got " + std::to_string(value));
    };
    check("radii", grid.radii, 2, 256);
    check("polar", grid.polar, 2, 256);
    if (grid.polar_forward_thick != 0) check("polar_forward_thick", grid.polar_forward_thick, 2, 256);
    check("zenith", grid.zenith, 3, 256);
    check("azimuth", grid.azimuth, 2, 256);
    check("march_steps", grid.march_steps, 1, 4096);
    check("orders", grid.orders, 1, 1000);
    if (!(grid.surface_step >= 1e-3 && grid.surface_step <= 1.0))
        throw std::invalid_argument("grid.surface_step: must be in [0.001, 1] mean free paths, got " +
                                    std::to_string(grid.surface_step));
}

SphereGrid sphere_grid_for(const SphereGrid& grid, double tau, double g) {
    SphereGrid solved = grid;
    if (grid.polar_forward_thick > 0 && tau >= SphereGrid::kForwardThickTau && g >= SphereGrid::kForwardThickG)
        solved.polar = std::max(grid.polar, grid.polar_forward_thick);
    return solved;
}

struct SphereScattering::Impl {
    double tau, g;
    SphereGrid grid;
    RadialMap radial;
    TerminatorNodes polar_nodes;
    std::vector<double> polar_angles;  // polar_nodes.angle(j), once
    int dirs, positions;
    // J_k for k >= 2 (eq. 2.8): peak[p] p_{g^k}(sun . v) + rest[p][direction] at the nodes.
    struct OrderSource {
        std::vector<float> peak;  // e_k at each position node; empty where there is none
        std::vector<float> rest;  // R_k, in the field layout (field_index)
        double peak_g;            // g^k
    };
    std::vector<OrderSource> source;  // source[k - 2]
    // The orders >= 2 summed, for single_and_multiple: sum_k R_k on the grid (the field layout) and e_k by position.
    std::vector<float> rest_sum;
    std::vector<float> peaks;  // [position][k - 2]
    // Every order beyond grid.orders summed (eq. 2.11; its peak 0, on the grid whole), when grid.beyond.
    OrderSource beyond{{}, {}, 0.0};
    int beyond_iterations = 0;
    double beyond_residual = 0.0;
    static constexpr double kBeyondTolerance = 1e-4;
    static constexpr int kBeyondIterations = 200;  // tau = 50 takes 32-48

    Impl(double tau_, double g_, const SphereGrid& grid_)
        : tau(tau_),
          g(g_),
          grid(grid_),
          radial(grid_.radii, tau_, grid_.surface_step),
          polar_nodes(grid_.polar, grid_.graded_polar ? tau_ : 0.0) {
        for (int j = 0; j < grid.polar; ++j) polar_angles.push_back(polar_nodes.angle(j));
        dirs = grid.zenith * grid.azimuth;
        positions = grid.radii * grid.polar;
    }

    static double hg_of(double gk, double c) { return numerics::henyey_greenstein(gk, c); }
    double hg(double c) const { return hg_of(g, c); }
    // Order 1's source (eq. 2.2): the sun's light attenuated to y, scattered toward -w.
    double single_source(const Vec& y, const Vec& w) const {
        return tau * hg(w.z) * std::exp(-tau * exit_distance(y, Vec{0.0, 0.0, 1.0}));
    }
    double polar_angle(int j) const { return polar_angles[size_t(j)]; }
    double zenith_angle(int k) const { return kPi * k / (grid.zenith - 1); }
    double azimuth_angle(int l) const { return kPi * l / (grid.azimuth - 1); }
    // Where a field on the grid (R_k) holds position node `position` (radius * polar + polar node) and
    // direction node `direction`: [radius][direction][polar], so that the polar taps of one lookup
    // (eq. 2.13) lie side by side in memory. The march reads 16 position taps per sample; with the
    // polar node fastest they share cache lines.
    size_t field_index(int position, int direction) const {
        return (size_t(position / grid.polar) * dirs + direction) * grid.polar + position % grid.polar;
    }

    // The local frame at y: outward normal n, t toward the sun in the tangent plane, b = n x t (section 2.3).
    static void frame(const Vec& y, Vec& n, Vec& t, Vec& b) {
        const double r = std::sqrt(dot(y, y));
        n = r > 1e-12 ? (1.0 / r) * y : Vec{0.0, 0.0, 1.0};
        const double st = std::hypot(n.x, n.y);
        t = st > 1e-12 ? Vec{-n.z * n.x / st, -n.z * n.y / st, st} : Vec{-1.0, 0.0, 0.0};
        b = cross(n, t);
    }
    GridPoint locate(const Vec& y, const Vec& w) const {
        Vec n, t, b;
        frame(y, n, t, b);
        GridPoint p;
        node_and_fraction(radial.index(std::sqrt(dot(y, y))), grid.radii, p.node[0], p.frac[0]);
        node_and_fraction(polar_nodes.index(std::atan2(std::hypot(n.x, n.y), n.z)), grid.polar, p.node[1], p.frac[1]);
        node_and_fraction(std::acos(std::clamp(dot(w, n), -1.0, 1.0)) / kPi * (grid.zenith - 1), grid.zenith, p.node[2],
                          p.frac[2]);
        node_and_fraction(std::atan2(std::fabs(dot(w, b)), dot(w, t)) / kPi * (grid.azimuth - 1), grid.azimuth,
                          p.node[3], p.frac[3]);
        return p;
    }
    // Eq. 2.13: the position nodes around a grid point and their weights, a Catmull-Rom cubic in the
    // radial index and in the polar angle. Not linear: a linear interpolant's kinks act as extra
    // diffusion in a thick particle (physics.md section 2.3). Past a pole the mirror node stands in,
    // past the centre the missing node is continued linearly. Always 4 x 4 taps (a tap that the
    // continuation empties keeps weight 0 on a valid node), so that the loops over them unroll.
    struct PositionTaps {
        std::array<int, 4> radial, polar;  // node indices
        std::array<double, 4> radial_weight, polar_weight;
        // Calls visit(position, weight) for every tap (position = radius * polar + polar node).
        template <class Visit>
        void for_each(int polar_nodes, const Visit& visit) const {
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    visit(radial[a] * polar_nodes + polar[b], radial_weight[a] * polar_weight[b]);
        }
    };
    static void cubic_taps(int node, double f, int n, bool mirror, std::array<int, 4>& index,
                           std::array<double, 4>& weight) {
        const double f2 = f * f, f3 = f2 * f;
        std::array<double, 4> w{0.5 * (-f3 + 2 * f2 - f), 0.5 * (3 * f3 - 5 * f2 + 2), 0.5 * (-3 * f3 + 4 * f2 + f),
                                0.5 * (f3 - f2)};
        std::array<int, 4> at{node - 1, node, node + 1, node + 2};
        // A missing end node: the mirror node, or the line through the two nearest (a = 2 b - c).
        auto stand_in = [&](int end, int near, int far, int mirror_node) {
            if (mirror) {
                at[end] = mirror_node;
                return;
            }
            w[near] += 2.0 * w[end];
            w[far] -= w[end];
            w[end] = 0.0;
        };
        if (at[0] < 0) stand_in(0, 1, 2, std::min(1, n - 1));
        if (at[3] > n - 1) stand_in(3, 2, 1, std::max(0, n - 2));
        for (int i = 0; i < 4; ++i) {
            index[i] = std::clamp(at[i], 0, n - 1);  // a continued end's node: weight 0
            weight[i] = w[i];
        }
    }
    PositionTaps position_taps(int node_r, double frac_r, int node_p, double frac_p) const {
        PositionTaps taps;
        cubic_taps(node_r, frac_r, grid.radii, false, taps.radial, taps.radial_weight);
        cubic_taps(node_p, frac_p, grid.polar, true, taps.polar, taps.polar_weight);
        return taps;
    }
    PositionTaps position_taps(const GridPoint& p) const {
        return position_taps(p.node[0], p.frac[0], p.node[1], p.frac[1]);
    }
    // A field on the grid (the field layout) at the taps, bilinear in the direction (zenith, azimuth
    // nodes and fractions).
    double interpolate(const std::vector<float>& field, const PositionTaps& taps, int zenith_node, double zenith_frac,
                       int azimuth_node, double azimuth_frac) const {
        const int d = zenith_node * grid.azimuth + azimuth_node;
        const std::array<int, 4> corner{0, 1, grid.azimuth, grid.azimuth + 1};  // direction nodes around d
        const std::array<double, 4> corner_weight{(1 - zenith_frac) * (1 - azimuth_frac),
                                                  (1 - zenith_frac) * azimuth_frac, zenith_frac * (1 - azimuth_frac),
                                                  zenith_frac * azimuth_frac};
        double sum = 0.0;
        for (int a = 0; a < 4; ++a) {
            const float* at_radius = &field[(size_t(taps.radial[a]) * dirs + d) * grid.polar];
            double by_direction = 0.0;
            for (int c = 0; c < 4; ++c) {
                const float* f = at_radius + size_t(corner[c]) * grid.polar;
                double by_polar = 0.0;
                for (int b = 0; b < 4; ++b) by_polar += taps.polar_weight[b] * f[taps.polar[b]];
                by_direction += corner_weight[c] * by_polar;
            }
            sum += taps.radial_weight[a] * by_direction;
        }
        return sum;
    }
    double interpolate(const std::vector<float>& field, const GridPoint& p) const {
        return interpolate(field, position_taps(p), p.node[2], p.frac[2], p.node[3], p.frac[3]);
    }
    // e_k at the taps; 0 for a source without a peak (the orders beyond, eq. 2.11).
    double peak_at(const OrderSource& o, const PositionTaps& taps) const {
        return o.peak.empty() ? 0.0 : interpolate(o.peak.data(), taps);
    }
    // A field by position only (a peak coefficient) at the taps.
    double interpolate(const float* by_position, const PositionTaps& taps) const {
        double sum = 0.0;
        taps.for_each(grid.polar, [&](int position, double weight) { sum += weight * by_position[position]; });
        return sum;
    }
    // J_k at grid point p toward an observer looking along w, from its grid (eq. 2.8).
    double order_source(const OrderSource& o, const GridPoint& p, const PositionTaps& taps, const Vec& w) const {
        return peak_at(o, taps) * hg_of(o.peak_g, w.z) +
               interpolate(o.rest, taps, p.node[2], p.frac[2], p.node[3], p.frac[3]);
    }
    double order_source(const OrderSource& o, const Vec& x, const Vec& w) const {
        const GridPoint p = locate(x, w);
        return order_source(o, p, position_taps(p), w);
    }
    Vec node_position(int position) const {
        const double r = radial.radius(position / grid.polar), th = polar_angle(position % grid.polar);
        return {r * std::sin(th), 0.0, r * std::cos(th)};
    }
    Vec node_direction(int position, int direction) const {
        Vec n, t, b;
        const double th = polar_angle(position % grid.polar);
        n = {std::sin(th), 0.0, std::cos(th)};
        t = {-std::cos(th), 0.0, std::sin(th)};
        b = cross(n, t);
        const double ze = zenith_angle(direction / grid.azimuth), az = azimuth_angle(direction % grid.azimuth);
        return std::cos(ze) * n + std::sin(ze) * (std::cos(az) * t + std::sin(az) * b);
    }

    // Eq. 2.4: the ray integral from y along w to the surface of a source f(point) times e^{-tau t}. f is
    // sampled at the ends, at `steps` points uniform in u = 1 - e^{-tau t} (crowded where the light gets
    // through) and at `steps` points uniform in t (the far part of the chord, where a back-lit source
    // grows); between samples F = f e^{-tau t} is taken as exponential, whose integral over a step h is
    // h times the logarithmic mean of F at its ends (eq. 2.6). source(x) gives f at x, once per sample.
    // The sample distances of eq. 2.6 along the ray from y along w, in increasing order, through
    // visit(t): t = 0, `steps` points uniform in u and `steps` points uniform in t (the last at the
    // exit distance d); none when d = 0.
    template <class Visit>
    void march_points(const Vec& y, const Vec& w, int steps, const Visit& visit) const {
        const double d = exit_distance(y, w);
        if (!(d > 0.0)) return;
        const double total = -std::expm1(-tau * d);  // U
        visit(0.0);
        int iu = 0, it = 1;  // next u-sample (midpoints) and t-sample (it / steps of d; the last is the end)
        while (iu < steps || it <= steps) {
            const double tu = iu < steps ? -std::log1p(-total * (iu + 0.5) / steps) / tau : 2.0 * d;
            const double tt = d * it / steps;
            if (tu < tt) {
                visit(std::min(tu, d));
                ++iu;
            } else {
                visit(tt);
                ++it;
            }
        }
    }
    template <class Source>
    double march(const Vec& y, const Vec& w, int steps, const Source& source) const {
        double sum = 0.0, t_prev = 0.0, f_prev = 0.0;
        bool first = true;
        march_points(y, w, steps, [&](double t) {
            const double f = source(y + t * w) * std::exp(-tau * t);
            if (!first) sum += (t - t_prev) * log_mean(f_prev, f);
            first = false;
            t_prev = t;
            f_prev = f;
        });
        return sum;
    }
    // march() for `count` sources on the grid at once along the same ray, each sample located on the
    // grid once: source(k, p, taps) is source k at grid point p with its position taps. The sums of
    // march() for each source, in the same order of operations.
    template <class Source>
    std::vector<double> march_located(const Vec& y, const Vec& w, int steps, size_t count, const Source& source) const {
        std::vector<double> sum(count, 0.0), f_prev(count, 0.0);
        double t_prev = 0.0;
        bool first = true;
        march_points(y, w, steps, [&](double t) {
            const GridPoint p = locate(y + t * w, w);
            const PositionTaps taps = position_taps(p);
            const double attenuation = std::exp(-tau * t);
            for (size_t k = 0; k < count; ++k) {
                const double f = source(k, p, taps) * attenuation;
                if (!first) sum[k] += (t - t_prev) * log_mean(f_prev[k], f);
                f_prev[k] = f;
            }
            first = false;
            t_prev = t;
        });
        return sum;
    }
    // The logarithmic mean (b - a) / ln(b / a): the mean of an exponential between the values a and b
    // (eq. 2.6); the arithmetic mean where either is zero (the source has underflowed there).
    static double log_mean(double a, double b) {
        if (!(a > 0.0) || !(b > 0.0)) return 0.5 * (a + b);
        const double l = std::log(b / a);
        return std::fabs(l) < 1e-3 ? 0.5 * (a + b) * (1.0 - l * l / 12.0) : (b - a) / l;
    }

    // Eq. 2.12: the weights of a source's values at t_a and t_b (linear between them) in the integral of
    // source times e^{-tau t} over [t_a, t_b]: e^{-tau t_a} (A - B, B) with x = tau h, A = (1 - e^{-x}) / tau
    // and B = (1 - e^{-x} (1 + x)) / (tau x) (its series below x = 1e-2, where the difference cancels).
    std::array<double, 2> linear_step_weights(double t_a, double t_b) const {
        const double h = t_b - t_a, x = tau * h, e = std::exp(-tau * t_a);
        if (!(h > 0.0)) return {0.0, 0.0};
        const double a = -std::expm1(-x) / tau;
        const double b = x < 1e-2 ? h * (0.5 - x / 3.0 + x * x / 8.0 - x * x * x / 30.0)
                                  : (-std::expm1(-x) - x * std::exp(-x)) / (tau * x);
        return {e * (a - b), e * b};
    }

    // The fraction of the light that a ray from radius r at zenith angle zeta (from the outward normal)
    // meets inside the sphere: U = 1 - e^{-tau d(r, zeta)} (eq. 2.10).
    double meets(double r, double zeta) const {
        return -std::expm1(-tau * exit_distance(Vec{0.0, 0.0, r}, Vec{std::sin(zeta), 0.0, std::cos(zeta)}));
    }

    // Eq. 2.5's and 2.10's quadratures, stored transposed ([j * dirs + i]): plain[i][j] is the integral of
    // p(v_i . w) times node j's hat function (bilinear in zeta and |psi|) over the sphere of directions;
    // by_radius[radius][i][j] the same with the factor U(r, zeta(w)) inside. Both are taken on 8 x 8
    // sub-cells of every cell with their exact solid angles (both signs of the azimuth), and each row of
    // both is divided by plain's row sum, the phase function's normalisation, so that the discrete gather
    // neither creates nor destroys light.
    struct GatherWeights {
        std::vector<float> plain, by_radius;
    };
    GatherWeights gather_weights() const {
        constexpr int kSub = 8;
        const int rows = (grid.zenith - 1) * kSub;  // zenith sub-rows
        const double dpsi = kPi / (grid.azimuth - 1) / kSub;
        // partial[i][row][l]: the row's solid angle times p(v_i . w) times the azimuth hat of node l.
        std::vector<double> partial(size_t(dirs) * rows * grid.azimuth, 0.0);
        auto row_zenith = [&](int row, double f) { return kPi * (row + f) / rows; };
        numerics::parallel_for(dirs, [&](int i) {
            const double zi = zenith_angle(i / grid.azimuth), ai = azimuth_angle(i % grid.azimuth);
            const double cz = std::cos(zi), sz = std::sin(zi);
            for (int row = 0; row < rows; ++row) {
                const double ze = row_zenith(row, 0.5), cs = std::cos(ze), ss = std::sin(ze);
                const double solid = (std::cos(row_zenith(row, 0.0)) - std::cos(row_zenith(row, 1.0))) * dpsi;
                double* out = &partial[(size_t(i) * rows + row) * grid.azimuth];
                for (int l = 0; l + 1 < grid.azimuth; ++l)
                    for (int c = 0; c < kSub; ++c) {
                        const double fa = (c + 0.5) / kSub, az = azimuth_angle(l) + fa * kSub * dpsi;
                        // Both mirror images of the sample (azimuth +az and -az) carry the same field value.
                        const double value = solid * (hg(cz * cs + sz * ss * std::cos(ai - az)) +
                                                      hg(cz * cs + sz * ss * std::cos(ai + az)));
                        out[l] += value * (1.0 - fa);
                        out[l + 1] += value * fa;
                    }
            }
        });
        GatherWeights w{std::vector<float>(size_t(dirs) * dirs), std::vector<float>(size_t(grid.radii) * dirs * dirs)};
        numerics::parallel_for(dirs, [&](int i) {
            std::vector<double> plain(dirs, 0.0), weighted(size_t(grid.radii) * dirs, 0.0);
            for (int row = 0; row < rows; ++row) {
                const int k = row / kSub;
                const double fz = (row % kSub + 0.5) / kSub, ze = row_zenith(row, 0.5);
                const double* in = &partial[(size_t(i) * rows + row) * grid.azimuth];
                for (int l = 0; l < grid.azimuth; ++l) {
                    plain[k * grid.azimuth + l] += in[l] * (1.0 - fz);
                    plain[(k + 1) * grid.azimuth + l] += in[l] * fz;
                }
                for (int ir = 0; ir < grid.radii; ++ir) {
                    const double u = meets(radial.radius(ir), ze);
                    double* out = &weighted[size_t(ir) * dirs];
                    for (int l = 0; l < grid.azimuth; ++l) {
                        out[k * grid.azimuth + l] += u * in[l] * (1.0 - fz);
                        out[(k + 1) * grid.azimuth + l] += u * in[l] * fz;
                    }
                }
            }
            double sum = 0.0;
            for (double x : plain) sum += x;
            for (int j = 0; j < dirs; ++j) w.plain[size_t(j) * dirs + i] = float(plain[j] / sum);
            for (int ir = 0; ir < grid.radii; ++ir)
                for (int j = 0; j < dirs; ++j)
                    w.by_radius[(size_t(ir) * dirs + j) * dirs + i] = float(weighted[size_t(ir) * dirs + j] / sum);
        });
        return w;
    }

    // A sample of a node ray located on the grid once, for every order's march (eq. 2.6): the grid
    // cell (its lower node and the fraction toward the next, 1/65535 steps, per axis r, polar, zenith,
    // azimuth), the distance t along the ray, and the sample's weight in the march that takes the
    // source as linear between samples (eq. 2.12: its share of the two steps it ends and begins).
    struct PlannedSample {
        int16_t node[4];
        uint16_t frac[4];
        float t;
        float linear_weight;
    };
    int samples_per_ray() const { return 2 * grid.march_steps + 1; }
    // Fills the samples of the ray from y along w (all with t = 0 when the ray leaves at once).
    void plan_ray(const Vec& y, const Vec& w, PlannedSample* out) const {
        int n = 0;
        double t_prev = 0.0, weight_prev = 0.0;
        march_points(y, w, grid.march_steps, [&](double t) {
            const GridPoint p = locate(y + t * w, w);
            PlannedSample& s = out[n];
            for (int axis = 0; axis < 4; ++axis) {
                s.node[axis] = int16_t(p.node[axis]);
                s.frac[axis] = uint16_t(std::lround(p.frac[axis] * 65535.0));
            }
            s.t = float(t);
            // Step [t_prev, t] gives its first weight to the sample before and its second to this one.
            const std::array<double, 2> step = n > 0 ? linear_step_weights(t_prev, t) : std::array<double, 2>{0.0, 0.0};
            if (n > 0) out[n - 1].linear_weight = float(weight_prev + step[0]);
            weight_prev = step[1];
            t_prev = t;
            ++n;
        });
        if (n > 0) out[n - 1].linear_weight = float(weight_prev);
        for (; n < samples_per_ray(); ++n) out[n] = PlannedSample{{0, 0, 0, 0}, {0, 0, 0, 0}, 0.0f, 0.0f};
    }
    // Eq. 2.6 over planned samples of the ray whose direction has sun . w = cos_sun. With `linear`, the
    // source is linear between samples instead, its product with the exact exponential integrated
    // (eq. 2.12): linear in the source, as the Krylov solve of the orders beyond needs (eq. 2.11); the
    // logarithmic mean is not additive, and a Krylov vector changes sign.
    double planned_march(const PlannedSample* samples, const OrderSource& o, double cos_sun,
                         bool linear = false) const {
        const double peak_phase = hg_of(o.peak_g, cos_sun);
        double sum = 0.0, f_prev = 0.0, t_prev = 0.0;
        for (int i = 0; i < samples_per_ray(); ++i) {
            const PlannedSample& s = samples[i];
            double frac[4];
            for (int axis = 0; axis < 4; ++axis) frac[axis] = s.frac[axis] / 65535.0;
            const PositionTaps taps = position_taps(s.node[0], frac[0], s.node[1], frac[1]);
            const double j =
                peak_at(o, taps) * peak_phase + interpolate(o.rest, taps, s.node[2], frac[2], s.node[3], frac[3]);
            if (linear) {
                sum += double(s.linear_weight) * j;
                continue;
            }
            const double f = j * std::exp(-tau * double(s.t));
            if (i > 0) sum += (double(s.t) - t_prev) * log_mean(f_prev, f);
            f_prev = f;
            t_prev = s.t;
        }
        return sum;
    }

    // I_k at the nodes ([position][direction]) and toward the sun at each position node.
    struct NodeRadiance {
        std::vector<float> radiance, toward_sun;
    };

    void solve() {
        const GatherWeights weights = gather_weights();
        std::vector<double> node_meets(size_t(grid.radii) * grid.zenith);  // U at each radius and zenith node
        for (int ir = 0; ir < grid.radii; ++ir)
            for (int k = 0; k < grid.zenith; ++k)
                node_meets[size_t(ir) * grid.zenith + k] = meets(radial.radius(ir), zenith_angle(k));
        NodeRadiance light{std::vector<float>(size_t(positions) * dirs), std::vector<float>(positions)};
        const Vec sun{0.0, 0.0, 1.0};
        // Every node ray's samples, located once (rays [position][direction], then one toward the sun
        // per position): the march of orders >= 2 reads them.
        const size_t per_ray = size_t(samples_per_ray()), rays = size_t(positions) * (dirs + 1);
        std::vector<PlannedSample> plan(rays * per_ray);
        numerics::parallel_for(positions, [&](int p) {
            const Vec y = node_position(p);
            for (int d = 0; d < dirs; ++d)
                plan_ray(y, node_direction(p, d), &plan[(size_t(p) * (dirs + 1) + d) * per_ray]);
            plan_ray(y, sun, &plan[(size_t(p) * (dirs + 1) + dirs) * per_ray]);
        });
        // Order 1's radiance at the nodes, from its analytic source.
        numerics::parallel_for(positions, [&](int p) {
            const Vec y = node_position(p);
            for (int d = 0; d < dirs; ++d) {
                const Vec w = node_direction(p, d);
                light.radiance[size_t(p) * dirs + d] =
                    float(march(y, w, grid.march_steps, [&](const Vec& x) { return single_source(x, w); }));
            }
            light.toward_sun[p] =
                float(march(y, sun, grid.march_steps, [&](const Vec& x) { return single_source(x, sun); }));
        });
        // Eq. 2.9: gather the radiance `in` of one order (made by the source `made_by`, order 1's analytic
        // source when null) into the next order's source. With split_peak its peak toward the sun,
        // c p_{g^k} with g^k = peak_g, is taken out and gathered exactly (p * p_{g^k} = p_{g^{k+1}});
        // without, everything goes through the grid (the orders beyond, eq. 2.11).
        auto gather = [&](const NodeRadiance& in, const OrderSource* made_by, double peak_g, bool split_peak) {
            OrderSource next{std::vector<float>(positions), std::vector<float>(size_t(positions) * dirs, 0.0f),
                             split_peak ? peak_g * g : 0.0};
            // By radius: one thread writes all the polar nodes that share its cache lines (field_index).
            numerics::parallel_for(grid.radii, [&](int ir) {
                std::vector<float> out(dirs);
                const float* weighted = &weights.by_radius[size_t(ir) * dirs * dirs];
                for (int p = ir * grid.polar; p < (ir + 1) * grid.polar; ++p) {
                    const double c = split_peak ? in.toward_sun[p] / hg_of(peak_g, 1.0) : 0.0;
                    next.peak[p] = float(tau * c);
                    std::fill(out.begin(), out.end(), 0.0f);
                    const float* radiance = &in.radiance[size_t(p) * dirs];
                    const Vec y = node_position(p);
                    for (int j = 0; j < dirs; ++j) {
                        // Eq. 2.10: I = U S with S smooth (the mean source along the ray; at U = 0 the source at y).
                        const double u = node_meets[size_t(ir) * grid.zenith + j / grid.azimuth];
                        const Vec w = node_direction(p, j);
                        const double mean = u > 1e-7  ? radiance[j] / u
                                            : made_by ? order_source(*made_by, y, w) / tau
                                                      : single_source(y, w) / tau;
                        const float a = float(tau * mean), b = float(-tau * c * hg_of(peak_g, w.z));
                        const float* column = &weighted[size_t(j) * dirs];
                        const float* plain = &weights.plain[size_t(j) * dirs];
                        for (int i = 0; i < dirs; ++i) out[i] += a * column[i] + b * plain[i];
                    }
                    for (int i = 0; i < dirs; ++i) next.rest[field_index(p, i)] = out[i];
                }
            });
            return next;
        };
        // Eq. 2.4: an order's radiance at the nodes, marching its source.
        std::vector<double> node_cos_sun(size_t(grid.polar) * dirs);  // sun . w of each polar and direction node
        for (int pol = 0; pol < grid.polar; ++pol)
            for (int d = 0; d < dirs; ++d) node_cos_sun[size_t(pol) * dirs + d] = node_direction(pol, d).z;
        auto march_nodes = [&](const OrderSource& field, NodeRadiance& out, bool linear) {
            numerics::parallel_for(positions, [&](int p) {
                const PlannedSample* ray = &plan[size_t(p) * (dirs + 1) * per_ray];
                const double* cos_sun = &node_cos_sun[size_t(p % grid.polar) * dirs];
                for (int d = 0; d < dirs; ++d)
                    out.radiance[size_t(p) * dirs + d] =
                        float(planned_march(ray + d * per_ray, field, cos_sun[d], linear));
                out.toward_sun[p] = float(planned_march(ray + dirs * per_ray, field, 1.0, linear));
            });
        };
        double peak_g = g;  // g^k: I_k's forward peak is shaped like p_{g^k} (the k-fold convolution of p)
        for (int order = 2; order <= grid.orders; ++order) {
            OrderSource next = gather(light, order == 2 ? nullptr : &source.back(), peak_g, true);
            peak_g *= g;
            source.push_back(std::move(next));
            if (order == grid.orders && !grid.beyond) break;
            march_nodes(source.back(), light, false);
        }
        rest_sum.assign(size_t(positions) * dirs, 0.0f);
        peaks.assign(size_t(positions) * source.size(), 0.0f);
        for (size_t k = 0; k < source.size(); ++k) {
            for (size_t i = 0; i < rest_sum.size(); ++i) rest_sum[i] += source[k].rest[i];
            for (int p = 0; p < positions; ++p) peaks[size_t(p) * source.size() + k] = source[k].peak[p];
        }
        if (!grid.beyond) return;
        // Eq. 2.11: the orders beyond, B = sum_{k > N} J_k, solve (1 - K) B = J_{N+1}, K one gather of one
        // march on the grid. J_{N+1} comes from order N's radiance with its peak split off as before, then
        // goes onto the grid whole (its lobe p_{g^{N+1}} is broad by then: g^19 <= 0.15 for g <= 0.9).
        const OrderSource first = gather(light, source.empty() ? nullptr : &source.back(), peak_g, true);
        std::vector<double> rhs(size_t(positions) * dirs);
        for (int p = 0; p < positions; ++p)
            for (int d = 0; d < dirs; ++d)
                rhs[field_index(p, d)] =
                    first.rest[field_index(p, d)] + double(first.peak[p]) * hg_of(first.peak_g, node_direction(p, d).z);
        OrderSource field{{}, std::vector<float>(rhs.size()), 0.0};  // no peak: all on the grid
        // x -> (1 - K) x.
        auto apply = [&](const std::vector<double>& x, std::vector<double>& out) {
            for (size_t i = 0; i < x.size(); ++i) field.rest[i] = float(x[i]);
            march_nodes(field, light, true);
            const OrderSource gathered = gather(light, &field, 0.0, false);
            for (size_t i = 0; i < x.size(); ++i) out[i] = x[i] - double(gathered.rest[i]);
        };
        const std::vector<double> solution = gmres(apply, rhs);
        field.rest.assign(solution.begin(), solution.end());
        beyond = std::move(field);
        for (size_t i = 0; i < rest_sum.size(); ++i) rest_sum[i] += beyond.rest[i];
    }

    // GMRES (Saad and Schultz 1986; Arnoldi with modified Gram-Schmidt, Givens rotations) for M x = b,
    // M given by apply(x, out), from x = 0: stops at a residual of kBeyondTolerance |b| or after
    // kBeyondIterations (the basis is kept whole: 3 MiB a vector at the default grid). M = 1 - K has its eigenvalues in
    // (0, 2): K loses a little light each order, least in the slowest modes of a thick sphere (about pi^2 / (3 tau^2 (1
    // - g)) of it, the diffusion limit), which plain iteration would take thousands of orders to sum and a Krylov
    // method about the square root of that (physics.md section 2.7).
    template <class Apply>
    std::vector<double> gmres(const Apply& apply, const std::vector<double>& b) {
        const size_t n = b.size();
        const int m = kBeyondIterations;
        auto norm = [](const std::vector<double>& x) {
            double s = 0.0;
            for (double v : x) s += v * v;
            return std::sqrt(s);
        };
        const double b_norm = norm(b);
        beyond_iterations = 0;
        beyond_residual = 0.0;
        std::vector<double> x(n, 0.0);
        if (!(b_norm > 0.0)) return x;
        std::vector<std::vector<double>> basis;
        std::vector<std::vector<double>> h;  // Hessenberg columns, rotated into R
        std::vector<double> cs, sn, rhs{b_norm};
        basis.emplace_back(n);
        for (size_t i = 0; i < n; ++i) basis[0][i] = b[i] / b_norm;
        std::vector<double> v(n), w(n);
        int k = 0;
        for (; k < m; ++k) {
            for (size_t i = 0; i < n; ++i) v[i] = basis[k][i];
            apply(v, w);
            std::vector<double> col(k + 2, 0.0);
            for (int j = 0; j <= k; ++j) {  // modified Gram-Schmidt
                double d = 0.0;
                for (size_t i = 0; i < n; ++i) d += w[i] * basis[j][i];
                col[j] = d;
                for (size_t i = 0; i < n; ++i) w[i] -= d * basis[j][i];
            }
            col[k + 1] = norm(w);
            for (int j = 0; j < k; ++j) {  // the earlier rotations
                const double a = cs[j] * col[j] + sn[j] * col[j + 1];
                col[j + 1] = -sn[j] * col[j] + cs[j] * col[j + 1];
                col[j] = a;
            }
            const double r = std::hypot(col[k], col[k + 1]);
            cs.push_back(r > 0.0 ? col[k] / r : 1.0);
            sn.push_back(r > 0.0 ? col[k + 1] / r : 0.0);
            const double next_norm = col[k + 1];
            col[k] = r;
            col[k + 1] = 0.0;
            h.push_back(col);
            rhs.push_back(-sn[k] * rhs[k]);
            rhs[k] *= cs[k];
            beyond_residual = std::fabs(rhs[k + 1]) / b_norm;
            if (beyond_residual <= kBeyondTolerance || !(next_norm > 0.0)) {
                ++k;
                break;
            }
            basis.emplace_back(n);
            for (size_t i = 0; i < n; ++i) basis[k + 1][i] = w[i] / next_norm;
        }
        beyond_iterations = std::min(k, m);
        // x = V y, R y = rhs (back substitution).
        std::vector<double> y(beyond_iterations, 0.0);
        for (int j = beyond_iterations - 1; j >= 0; --j) {
            double s = rhs[j];
            for (int l = j + 1; l < beyond_iterations; ++l) s -= h[l][j] * y[l];
            y[j] = s / h[j][j];
        }
        for (int j = 0; j < beyond_iterations; ++j)
            for (size_t i = 0; i < n; ++i) x[i] += y[j] * basis[j][i];
        return x;
    }
};

SphereScattering::SphereScattering(double tau, double g, const SphereGrid& grid) {
    if (!(tau >= 1e-4 && tau <= 1e3)) throw std::invalid_argument("tau: must be in [1e-4, 1000]");
    if (!(g >= 0.0 && g <= 0.99)) throw std::invalid_argument("g: must be in [0, 0.99]");
    validate_sphere_grid(grid);
    impl_ = std::make_unique<Impl>(tau, g, sphere_grid_for(grid, tau, g));
    impl_->solve();
}

SphereScattering::~SphereScattering() = default;

double SphereScattering::tau() const { return impl_->tau; }
double SphereScattering::g() const { return impl_->g; }
const SphereGrid& SphereScattering::grid() const { return impl_->grid; }

// The ray's entry point into the unit sphere (origin outside or on it), false when it misses.
static bool sphere_entry(const Vec& o, const Vec& v, Vec& entry) {
    const double b = dot(o, v), c = dot(o, o) - 1.0, disc = b * b - c;
    if (!(disc > 0.0) || (c > 0.0 && b >= 0.0)) return false;        // misses, or starts outside moving away
    const double t_in = c > 0.0 ? c / (-b + std::sqrt(disc)) : 0.0;  // near root, without cancellation
    entry = o + t_in * v;
    return true;
}

std::array<double, 4> SphereScattering::table_channels(const double origin[3], const double dir[3], int steps) const {
    const Vec o{origin[0], origin[1], origin[2]}, v{dir[0], dir[1], dir[2]};
    Vec entry;
    if (!sphere_entry(o, v, entry)) return {0.0, 0.0, 0.0, 0.0};
    std::array<double, 4> out{0.0, 0.0, 0.0, 0.0};
    // Order 1 over its phase (eq. 2.2: p(sun . v) is the same all along the ray).
    out[0] = impl_->march(entry, v, steps, [&](const Vec& x) { return impl_->single_source(x, v); }) / impl_->hg(v.z);
    const size_t orders = impl_->source.size();
    if (orders == 0 && !impl_->grid.beyond) return out;
    // Located once per sample (march_located): e_2 and e_3 by themselves (eq. 2.8), then the rest of
    // orders >= 2 at once: the rests' sum and the peaks of orders >= 4.
    std::vector<double> peak_phase(orders, 0.0);
    for (size_t k = 2; k < orders; ++k) peak_phase[k] = Impl::hg_of(impl_->source[k].peak_g, v.z);
    const std::vector<double> sums = impl_->march_located(
        entry, v, steps, 3, [&](size_t channel, const GridPoint& p, const Impl::PositionTaps& taps) {
            if (channel < 2)
                return channel < orders ? impl_->interpolate(impl_->source[channel].peak.data(), taps) : 0.0;
            double peak = 0.0;
            taps.for_each(impl_->grid.polar, [&](int position, double weight) {
                const float* e = impl_->peaks.data() + size_t(position) * orders;
                double sum = 0.0;
                for (size_t k = 2; k < orders; ++k) sum += e[k] * peak_phase[k];
                peak += weight * sum;
            });
            return peak + impl_->interpolate(impl_->rest_sum, taps, p.node[2], p.frac[2], p.node[3], p.frac[3]);
        });
    for (int c = 0; c < 3; ++c) out[c + 1] = sums[c];
    return out;
}

std::vector<double> SphereScattering::radiance_orders(const double origin[3], const double dir[3], int steps) const {
    std::vector<double> out(size_t(impl_->grid.orders) + (impl_->grid.beyond ? 1 : 0), 0.0);
    const Vec o{origin[0], origin[1], origin[2]}, v{dir[0], dir[1], dir[2]};
    Vec entry;
    if (!sphere_entry(o, v, entry)) return out;
    out[0] = impl_->march(entry, v, steps, [&](const Vec& x) { return impl_->single_source(x, v); });
    // Orders 2.. (and the orders beyond, when solved), every sample located once.
    const size_t fields = impl_->source.size() + (impl_->grid.beyond ? 1 : 0);
    const std::vector<double> sums = impl_->march_located(
        entry, v, steps, fields, [&](size_t k, const GridPoint& p, const Impl::PositionTaps& taps) {
            return impl_->order_source(k < impl_->source.size() ? impl_->source[k] : impl_->beyond, p, taps, v);
        });
    std::copy(sums.begin(), sums.end(), out.begin() + 1);
    return out;
}

}  // namespace airlight
