#include "tables.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "shader_cpp.hpp"

namespace airlight {
namespace {

using cdouble = std::complex<double>;
constexpr double PHASE_GLOW_PANEL_RATIO = 2.2;
constexpr double kPi = 3.14159265358979323846;
constexpr double kEulerGamma = 0.57721566490153286061;

std::mutex registry_mutex;
std::vector<TableInfo>& registry() {
    static std::vector<TableInfo> tables;
    return tables;
}

// e^w E1(w) for Re w >= 0: power series for |w| < 3.5, else the even
// continued fraction e^w E1(w) = 1 / (w + 1 - 1^2 / (w + 3 - 2^2 / (w + 5 - ...))).
// Both agree with scipy's exp1 to < 2e-12 over the quarter plane we use.
cdouble scaled_e1(cdouble w) {
    if (std::abs(w) < 3.5) {
        cdouble sum = 0.0, term = 1.0;
        for (int k = 1; k < 80; ++k) {
            term *= -w / double(k);
            sum += term / double(k);
        }
        return std::exp(w) * (-kEulerGamma - std::log(w) - sum);
    }
    cdouble f = 0.0;
    for (int k = 120; k >= 1; --k) f = double(k) * double(k) / (w + double(2 * k + 1) - f);
    return 1.0 / (w + 1.0 - f);
}

// Composite Gauss-Legendre (8 points per panel) nodes and weights.
const double kGl8x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                         0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
const double kGl8w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                         0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

// Azimuthal integral of max(cos theta_s cos g + sin theta_s sin g cos phi, 0)
// over phi in [0, 2 pi): the clamped cosine of directions at angle g from the
// light direction, seen from a surface whose normal is at theta_s from it.
double clamped_cosine_ring(double g, double theta_s) {
    const double a = std::cos(theta_s) * std::cos(g);
    const double b = std::sin(theta_s) * std::sin(g);
    if (b <= std::abs(a)) return a > 0.0 ? 2.0 * kPi * a : 0.0;
    const double phi0 = std::acos(-a / b);
    return 2.0 * (a * phi0 + b * std::sin(phi0));
}

template <class Build>
Table2D timed_build(const char* name, Build build) {
    const auto start = std::chrono::steady_clock::now();
    Table2D table = build();
    table.name = name;
    table.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return table;
}

// Quadrature nodes in g in [0, pi] for the glow integral: panels graded
// geometrically towards g = 0, where Q(T sin g, g/2) has a boundary layer of
// width ~1/T, then uniform. Returns (g, weight) pairs.
// Panel edges also sit at pi/2, where Phi has a kink for theta_s = 0 or pi,
// and at the given extra points (the other places where Phi changes form).
// `backward_width` > 0 also grades them geometrically towards g = pi, where a
// backward phase lobe of that width (~1 - |g|) peaks.
std::vector<std::pair<double, double>> glow_nodes(int scale, std::vector<double> extra_edges = {},
                                                  double backward_width = 0.0) {
    std::vector<double> edges = {0.0, 0.5 * kPi};
    for (double e = 1e-5; e < 0.5; e *= 1.0 + 0.6 / scale) edges.push_back(e);
    if (backward_width > 0.0) {
        for (double e = 1e-2 * backward_width; e < 0.5; e *= 1.0 + 0.6 / scale) edges.push_back(kPi - e);
    }
    const int uniform_panels = 24 * scale;
    const double start = edges.back();
    for (int i = 1; i <= uniform_panels; ++i) edges.push_back(start + (kPi - start) * i / uniform_panels);
    for (double e : extra_edges)
        if (e > 0.0 && e < kPi) edges.push_back(e);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<std::pair<double, double>> nodes;
    for (size_t p = 0; p + 1 < edges.size(); ++p) {
        const double mid = 0.5 * (edges[p] + edges[p + 1]), half = 0.5 * (edges[p + 1] - edges[p]);
        for (int k = 0; k < 8; ++k) nodes.emplace_back(mid + half * kGl8x[k], half * kGl8w[k]);
    }
    return nodes;
}

}  // namespace

bool register_table(const Table2D& table) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    registry().push_back(
        {table.name, table.width, table.height, table.texels.size() * sizeof(float), table.build_seconds});
    return true;
}

double surface_glow_cos_theta(double Y, double optical_distance, double k_min) {
    // K = max(T, k_min) as the shader forms it in float32
    const double s = 2.0 * Y - 1.0, k = double(std::max(float(optical_distance), float(k_min)));
    return std::clamp(std::sinh(s * std::asinh(k)) / k, -1.0, 1.0);
}

double airlight_tail_exact(double u, double cv) {
    if (cv <= 0.0) return 0.0;
    if (u <= 0.0) return cv;
    const cdouble w(u * std::cos(cv) / std::sin(cv), -u);
    return scaled_e1(w).imag();
}

double surface_glow_exact(double optical_distance, double theta_s, int nodes_scale) {
    double sum = 0.0;
    const double h = 0.5 * kPi;
    for (const auto& [g, w] : glow_nodes(nodes_scale, {h - theta_s, theta_s - h, h + theta_s, 3.0 * h - theta_s})) {
        const double ring = clamped_cosine_ring(g, theta_s);
        if (ring == 0.0) continue;
        sum += w * ring * airlight_tail_exact(optical_distance * std::sin(g), 0.5 * (kPi - g));
    }
    return sum;
}

const Table2D& airlight_tail_table() {
    static const Table2D table = timed_build("airlight_tail", [] {
        using namespace shader;
        Table2D t;
        t.width = AIRLIGHT_TAIL_NX;
        t.height = AIRLIGHT_TAIL_NY;
        t.texels.resize(size_t(t.width) * t.height);
        for (int iy = 0; iy < t.height; ++iy) {
            const double cv = (1.0 - double(iy) / (t.height - 1)) * 0.5 * kPi;
            for (int ix = 0; ix < t.width; ++ix) {
                const double X = double(ix) / (t.width - 1);
                double S = 1.0;  // exact at u = 0 (X = 0) and u = infinity (X = 1)
                if (ix > 0 && ix + 1 < t.width) {
                    const double r = X * X, z = r / (1.0 - r);
                    if (iy + 1 == t.height) {
                        // xi = pi/2 at fixed z = u sec xi: S = (1 - z e^z E1(z)) (1 + z).
                        S = (1.0 - z * scaled_e1(cdouble(z, 0.0)).real()) * (1.0 + z);
                    } else {
                        const double s = std::sin(cv), u = z * s;
                        const double N = cv / (1.0 + u * cv / (s * s));
                        S = airlight_tail_exact(u, cv) / N;
                    }
                }
                t.texels[size_t(iy) * t.width + ix] = float(S);
            }
        }
        return t;
    });
    static const bool registered = register_table(table);
    (void)registered;
    return table;
}

const Table2D& surface_glow_table() {
    static const Table2D table = timed_build(
        "surface_glow", [] { return build_surface_glow_table(shader::SURFACE_GLOW_NX, shader::SURFACE_GLOW_NY); });
    static const bool registered = register_table(table);
    (void)registered;
    return table;
}

namespace {

// Runs body(i) for i in [0, n) on the machine's cores.
template <class Body>
void parallel_for(int n, const Body& body) {
    std::atomic<int> next{0};
    auto worker = [&]() {
        for (int i = next++; i < n; i = next++) body(i);
    };
    const int threads = std::max(1, std::min(n, int(std::thread::hardware_concurrency())));
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
    worker();
    for (std::thread& th : pool) th.join();
}

// A glow table (log G) of width x height: column X holds the optical
// distance T (SURFACE_GLOW_T_SCALE / T_MAX warp), row Y the cos theta_s of
// surface_glow_cos_theta(Y, T, k_min); tail(u, cv) is the airlight tail of
// the medium's phase function. G = int_0^pi Q(T sin g, g / 2) Phi(g, theta_s) dg
// (MODELS.md section 1; docs/airlight_table.md section 7).
template <class Tail>
Table2D build_glow_table(int width, int height, double k_min, double backward_width, const Tail& tail) {
    using namespace shader;
    Table2D t;
    t.width = width;
    t.height = height;
    t.texels.resize(size_t(t.width) * t.height);
    const auto nodes = glow_nodes(1, {}, backward_width);
    parallel_for(t.width, [&](int ix) {
        const double X = double(ix) / (t.width - 1);
        const double t0 = double(SURFACE_GLOW_T_SCALE);
        const double T = t0 * std::expm1(X * X * std::log1p(double(SURFACE_GLOW_T_MAX) / t0));
        // Q depends on T and g only: evaluate once per column, reuse for every theta_s.
        std::vector<double> q(nodes.size());
        for (size_t n = 0; n < nodes.size(); ++n) {
            const double g = nodes[n].first;
            q[n] = tail(T * std::sin(g), 0.5 * (kPi - g));
        }
        for (int iy = 0; iy < t.height; ++iy) {
            const double c = surface_glow_cos_theta(double(iy) / (t.height - 1), T, k_min);
            const double theta_s = std::acos(c);
            // Phi(g, theta_s) kinks at g = |pi/2 - theta_s| and pi - |pi/2 - theta_s|:
            // a panel holding a kink is split there, with Q at the new nodes from
            // the panel's degree-7 interpolant (Q is smooth within a panel).
            const double off = std::abs(0.5 * kPi - theta_s);
            const double kinks[2] = {off, kPi - off};
            double sum = 0.0;
            for (size_t p = 0; p < nodes.size() / 8; ++p) {
                const std::pair<double, double>* panel = &nodes[8 * p];
                const double* qp = &q[8 * p];
                const double mid = panel[0].first - kGl8x[0] * panel[0].second / kGl8w[0];
                const double half = panel[0].second / kGl8w[0];
                double cuts[4] = {mid - half, 0.0, 0.0, mid + half};
                int count = 1;
                for (double k : kinks)
                    if (k > cuts[0] + 1e-12 * half && k < cuts[3] - 1e-12 * half) cuts[count++] = k;
                if (count == 1) {
                    for (int j = 0; j < 8; ++j)
                        sum += panel[j].second * qp[j] * clamped_cosine_ring(panel[j].first, theta_s);
                    continue;
                }
                cuts[count] = cuts[3];
                if (count == 3 && cuts[1] > cuts[2]) std::swap(cuts[1], cuts[2]);
                for (int piece = 0; piece < count; ++piece) {
                    const double pm = 0.5 * (cuts[piece] + cuts[piece + 1]), ph = 0.5 * (cuts[piece + 1] - cuts[piece]);
                    for (int j = 0; j < 8; ++j) {
                        const double g = pm + ph * kGl8x[j];
                        double value = 0.0;  // Lagrange interpolation through the panel's nodes
                        for (int a = 0; a < 8; ++a) {
                            double basis = 1.0;
                            for (int b = 0; b < 8; ++b)
                                if (b != a) basis *= (g - panel[b].first) / (panel[a].first - panel[b].first);
                            value += basis * qp[a];
                        }
                        sum += ph * kGl8w[j] * value * clamped_cosine_ring(g, theta_s);
                    }
                }
            }
            t.texels[size_t(iy) * t.width + ix] = float(std::log(sum));
        }
    });
    return t;
}

}  // namespace

Table2D build_surface_glow_table(int width, int height) {
    return build_glow_table(width, height, shader::SURFACE_GLOW_K_MIN, 0.0, airlight_tail_exact);
}

namespace {

// Local moments of the normalised tail weight w = exp(-u (tan xi - tan v)) on
// [v, pi/2], in Delta = xi - v in [0, cv]: Q = int w, M1 = int sin 2 Delta w / Q,
// M2 = int sin^2 Delta w / Q. Composite 8-point Gauss-Legendre on panels
// graded geometrically from both ends (the weight's boundary layer of width
// 1/lam at Delta = 0, and its decay at xi -> pi/2).
void spot_moments(double u, double cv, double& Q, double& M1, double& M2) {
    std::vector<double> edges = {0.0, 0.5 * cv, cv};
    const double lam = u / (std::sin(cv) * std::sin(cv));
    for (double e = std::min(1e-3 / std::max(lam, 1e-300), 1e-3) * cv; e < 0.5 * cv; e *= 1.6) {
        edges.push_back(e);
        edges.push_back(cv - e);
    }
    std::sort(edges.begin(), edges.end());
    double q = 0.0, m1 = 0.0, m2 = 0.0;
    const double s0 = std::sin(cv);
    for (size_t p = 0; p + 1 < edges.size(); ++p) {
        const double mid = 0.5 * (edges[p] + edges[p + 1]), half = 0.5 * (edges[p + 1] - edges[p]);
        for (int k = 0; k < 8; ++k) {
            const double D = mid + half * kGl8x[k];
            const double w = half * kGl8w[k] * std::exp(-u * std::sin(D) / (s0 * std::sin(cv - D)));
            q += w;
            m1 += w * std::sin(2.0 * D);
            m2 += w * std::sin(D) * std::sin(D);
        }
    }
    Q = q;
    M1 = q > 0.0 ? m1 / q : 0.0;
    M2 = q > 0.0 ? m2 / q : 0.0;
}

}  // namespace

const Table2D& spot_moment_table() {
    static const Table2D table = timed_build("spot_moments", [] {
        using namespace shader;
        Table2D t;
        t.width = AIRLIGHT_TAIL_NX;
        t.height = AIRLIGHT_TAIL_NY;
        t.channels = 4;
        t.texels.resize(size_t(t.width) * t.height * 4);
        const Table2D& tail = airlight_tail_table();
        for (int iy = 0; iy < t.height; ++iy) {
            // The xi = pi/2 row is evaluated just below it (its limit is continuous).
            const double cv = std::max((1.0 - double(iy) / (t.height - 1)) * 0.5 * kPi, 1e-6);
            for (int ix = 0; ix < t.width; ++ix) {
                const double X = double(ix) / (t.width - 1);
                double r1 = 1.0, r2 = 1.0;  // exact at u = infinity (X = 1)
                if (ix + 1 < t.width) {
                    const double r = X * X, z = r / (1.0 - r), s = std::sin(cv), u = z * s;
                    const double lam = u / (s * s);
                    double Q, M1, M2;
                    spot_moments(u, cv, Q, M1, M2);
                    const double N1 = cv / (1.0 + 0.5 * lam * cv), N2 = 0.5 * N1 * N1;
                    r1 = M1 / N1;
                    r2 = M2 / N2;
                }
                float* texel = &t.texels[(size_t(iy) * t.width + ix) * 4];
                texel[0] = tail.texels[size_t(iy) * t.width + ix];  // S, the point-light tail
                texel[1] = float(r1);
                texel[2] = float(r2);
                texel[3] = 0.0f;
            }
        }
        return t;
    });
    static const bool registered = register_table(table);
    (void)registered;
    return table;
}

// ---- Anisotropic phase functions -----------------------------------------------

shader::PhaseLobeGpu phase_lobe_gpu(const PhaseLobe& lobe, float weight) {
    shader::PhaseLobeGpu gpu{};
    if (lobe.rayleigh) {
        gpu.shape = glm::vec4(1.0f);
        gpu.info = glm::vec4(0.0f, 1.0f, shader::SURFACE_GLOW_K_MIN, weight);
        return gpu;
    }
    const double g = lobe.g, k = (1.0 - g) / (1.0 + g), root_k = std::sqrt(k);
    gpu.shape = glm::vec4(float(k), float(root_k), float(std::min(k, root_k)), float(1.0 / (1.0 - g)));
    // The glow's row warp: an HG lobe's glow turns over a width ~(1 - |g|) in
    // cos theta_s however thin the fog (docs/phase_table.md sections 6, 9):
    // the forward lobe's terminator, and for g < 0 the back-scattered light
    // arriving from just behind the surface's plane.
    const double k_min = g != 0.0 ? 2.0 / (1.0 - std::abs(g)) : double(shader::SURFACE_GLOW_K_MIN);
    gpu.info = glm::vec4(float(g), 0.0f, float(k_min), weight);
    return gpu;
}

namespace {

// phase_tail_moments with panels growing by `ratio`; without `moments` only Q
// is formed (the glow build), and Delta's steps need no panels.
void phase_tail_quadrature(const PhaseLobe& lobe, double u, double cv, double ratio, bool moments, double& Q,
                           double& M1, double& M2) {
    const double g = lobe.rayleigh ? 0.0 : double(lobe.g), k = (1.0 - g) / (1.0 + g);
    // tan phi0 = tan xi / k: cvp = pi/2 - phi0
    const double cvp = std::atan2(k * std::sin(cv), std::cos(cv));
    Q = M1 = M2 = 0.0;
    if (!(cvp > 0.0)) return;
    const double s0 = std::sin(cvp), c0 = std::cos(cvp);
    // Panels graded geometrically from both ends: the weight's boundary layer
    // of width 1 / lam at D = 0, its decay towards phi = pi/2, and the steps of
    // Delta(phi) (the moments' arguments) of width ~min(k, 1/k) at either end.
    const double lam = u * k / (s0 * s0);
    std::vector<double> edges = {0.0, 0.5 * cvp, cvp};
    double first = std::min(1e-3 / std::max(lam, 1e-300), 1e-3);
    if (moments) first = std::min(first, 1e-2 * std::min(k, 1.0 / k)) / (ratio < 1.5 ? 2.0 : 1.0);
    for (double e = first * cvp; e < 0.5 * cvp; e *= ratio) {
        edges.push_back(e);
        edges.push_back(cvp - e);
    }
    std::sort(edges.begin(), edges.end());
    double q = 0.0, m1 = 0.0, m2 = 0.0;
    for (size_t p = 0; p + 1 < edges.size(); ++p) {
        const double mid = 0.5 * (edges[p] + edges[p + 1]), half = 0.5 * (edges[p + 1] - edges[p]);
        for (int j = 0; j < 8; ++j) {
            const double D = mid + half * kGl8x[j], c1 = cvp - D;
            const double s1 = std::sin(c1), co1 = std::cos(c1);
            double density;
            if (lobe.rayleigh) {
                const double c2 = std::cos(2.0 * c1);
                density = 0.75 * (1.0 + c2 * c2);
            } else {
                density = std::sqrt(s1 * s1 + k * k * co1 * co1) / (1.0 - g);
            }
            const double w = half * kGl8w[j] * density * std::exp(-u * k * std::sin(D) / (s0 * s1));
            q += w;
            if (!moments) continue;
            const double delta = std::atan2(k * std::sin(D), s1 * s0 + k * k * co1 * c0);  // xi - xi0
            m1 += w * std::sin(2.0 * delta);
            m2 += w * std::sin(delta) * std::sin(delta);
        }
    }
    Q = q;
    M1 = q > 0.0 ? m1 / q : 0.0;
    M2 = q > 0.0 ? m2 / q : 0.0;
}

}  // namespace

void phase_tail_moments(const PhaseLobe& lobe, double u, double cv, double& Q, double& M1, double& M2, int refine) {
    phase_tail_quadrature(lobe, u, cv, 1.0 + 0.6 / refine, true, Q, M1, M2);
}

namespace {

// Q_p alone, for the glow build: panels growing by 2.2 (measured: within
// 2e-7 of the finer rule, test_phase_tables).
double phase_tail(const PhaseLobe& lobe, double u, double cv) {
    double Q, M1, M2;
    phase_tail_quadrature(lobe, u, cv, PHASE_GLOW_PANEL_RATIO, false, Q, M1, M2);
    return Q;
}

std::string lobe_name(const char* what, const PhaseLobe& lobe) {
    if (lobe.rayleigh) return std::string(what) + " rayleigh";
    char g[32];
    std::snprintf(g, sizeof g, " g=%.6g", double(lobe.g));
    return std::string(what) + g;
}

// Per-lobe tables, kept for the process (their addresses key the GL textures).
struct LobeTables {
    std::unique_ptr<Table2D> moments;
    std::unique_ptr<Table2D> glow;
};
std::mutex lobe_mutex;
std::map<std::pair<bool, float>, LobeTables>& lobe_tables() {
    static std::map<std::pair<bool, float>, LobeTables> tables;
    return tables;
}
std::deque<std::string>& table_names() {
    static std::deque<std::string> names;
    return names;
}

Table2D build_phase_moment_table(const PhaseLobe& lobe) {
    using namespace shader;
    const PhaseLobeGpu gpu = phase_lobe_gpu(lobe, 1.0f);
    Table2D t;
    t.width = AIRLIGHT_TAIL_NX;
    t.height = AIRLIGHT_TAIL_NY;
    t.channels = 4;
    t.texels.resize(size_t(t.width) * t.height * 4);
    parallel_for(t.height, [&](int iy) {
        // The row's cv = pi/2 - xi: Y(cv) (phase_math.glsl) decreases from 1 at
        // cv = 0 to 0 at cv = pi/2; inverted by bisection. The Y = 1 row is
        // evaluated just below xi = pi/2 (its limit is continuous).
        const double Y_row = double(iy) / (t.height - 1);
        double lo = 1e-7, hi = 0.5 * kPi;
        for (int i = 0; i < 60 && iy > 0 && iy + 1 < t.height; ++i) {
            const double mid = 0.5 * (lo + hi);
            float X, Y, N, N1, cvp, cv;
            lobe_coordinates(gpu, 0.0f, float(std::sin(mid)), float(std::cos(mid)), X, Y, N, N1, cvp, cv);
            (Y > Y_row ? lo : hi) = mid;
        }
        const double cv = iy == 0 ? 0.5 * kPi : (iy + 1 == t.height ? 1e-7 : 0.5 * (lo + hi));
        const double h = std::sin(cv), p = std::cos(cv), c = gpu.shape.z;
        for (int ix = 0; ix < t.width; ++ix) {
            const double X = double(ix) / (t.width - 1);
            // u = infinity (X = 1): Watson's limit, S = 1 for HG, P(xi) for
            // Rayleigh (isotropic normaliser); M1/N1 = M2/N2 = 1.
            const double c2 = std::cos(2.0 * cv);
            double S = lobe.rayleigh ? 0.75 * (1.0 + c2 * c2) : 1.0, r1 = 1.0, r2 = 1.0;
            if (ix + 1 < t.width) {
                const double r = X * X, z = r / (1.0 - r), sigma = z / std::sqrt(c * c * h * h + p * p);
                double Q, M1, M2;
                phase_tail_moments(lobe, sigma * h, cv, Q, M1, M2);
                float Xf, Yf, N, N1, cvp, cvf;
                lobe_coordinates(gpu, float(sigma), float(h), float(p), Xf, Yf, N, N1, cvp, cvf);
                S = Q / N;
                r1 = M1 / N1;
                r2 = M2 / (0.5 * double(N1) * N1);
            }
            float* texel = &t.texels[(size_t(iy) * t.width + ix) * 4];
            texel[0] = float(S);
            texel[1] = float(r1);
            texel[2] = float(r2);
            texel[3] = 0.0f;
        }
    });
    return t;
}

const Table2D& lobe_table(const PhaseLobe& lobe, bool glow) {
    std::lock_guard<std::mutex> lock(lobe_mutex);
    LobeTables& entry = lobe_tables()[{lobe.rayleigh, lobe.rayleigh ? 0.0f : lobe.g}];
    std::unique_ptr<Table2D>& slot = glow ? entry.glow : entry.moments;
    if (!slot) {
        table_names().push_back(lobe_name(glow ? "phase_glow" : "phase_moments", lobe));
        const char* name = table_names().back().c_str();
        slot = std::make_unique<Table2D>(timed_build(name, [&] {
            return glow ? build_phase_glow_table(lobe, shader::SURFACE_GLOW_NX, shader::SURFACE_GLOW_NY)
                        : build_phase_moment_table(lobe);
        }));
        register_table(*slot);
    }
    return *slot;
}

}  // namespace

Table2D build_phase_glow_table(const PhaseLobe& lobe, int width, int height) {
    const double k_min = phase_lobe_gpu(lobe, 1.0f).info.z;
    const double backward_width = !lobe.rayleigh && lobe.g < 0.0f ? 1.0 + double(lobe.g) : 0.0;
    return build_glow_table(width, height, k_min, backward_width,
                            [&](double u, double cv) { return phase_tail(lobe, u, cv); });
}

double phase_surface_glow_exact(const PhaseLobe& lobe, double optical_distance, double theta_s) {
    double sum = 0.0;
    const double h = 0.5 * kPi;
    const double backward_width = lobe.rayleigh ? 0.0 : std::max(1.0 - std::abs(double(lobe.g)), 1e-3);
    for (const auto& [g, w] :
         glow_nodes(2, {h - theta_s, theta_s - h, h + theta_s, 3.0 * h - theta_s}, backward_width)) {
        const double ring = clamped_cosine_ring(g, theta_s);
        if (ring == 0.0) continue;
        double Q, M1, M2;
        phase_tail_moments(lobe, optical_distance * std::sin(g), 0.5 * (kPi - g), Q, M1, M2, 2);
        sum += w * ring * Q;
    }
    return sum;
}

const Table2D& phase_moment_table(const PhaseLobe& lobe) { return lobe_table(lobe, false); }
const Table2D& phase_glow_table(const PhaseLobe& lobe) { return lobe_table(lobe, true); }

double phase_airlight_bound(const PhaseLobe& lobe) { return phase_tail(lobe, 0.0, 0.5 * kPi); }

std::vector<TableInfo> tables_built() {
    std::lock_guard<std::mutex> lock(registry_mutex);
    return registry();
}

}  // namespace airlight
