#include "phase_tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "airlight_tables.hpp"
#include "numerics.hpp"

namespace airlight {
namespace {
constexpr double PHASE_GLOW_PANEL_RATIO = 2.2;
}  // namespace

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
    // cos theta_s however thin the fog (effects/phase/docs/phase_table.md sections 6, 9):
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
            const double D = mid + half * numerics::kGaussLegendre8Nodes[j], c1 = cvp - D;
            const double s1 = std::sin(c1), co1 = std::cos(c1);
            double density;
            if (lobe.rayleigh) {
                const double c2 = std::cos(2.0 * c1);
                density = 0.75 * (1.0 + c2 * c2);
            } else {
                density = std::sqrt(s1 * s1 + k * k * co1 * co1) / (1.0 - g);
            }
            const double w =
                half * numerics::kGaussLegendre8Weights[j] * density * std::exp(-u * k * std::sin(D) / (s0 * s1));
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

// Per-lobe tables for the last kPhaseLobeCacheSize lobes: animating g builds
// new ones and drops the oldest (issue 27, item 10: they used to pile up).
constexpr size_t kPhaseLobeCacheSize = 8;
using LobeKey = std::pair<bool, float>;  // (rayleigh, g)
TableCache<LobeKey>& lobe_cache(bool glow) {
    static TableCache<LobeKey> moments(kPhaseLobeCacheSize), glows(kPhaseLobeCacheSize);
    return glow ? glows : moments;
}

Table2D build_phase_moment_table(const PhaseLobe& lobe) {
    using namespace shader;
    const PhaseLobeGpu gpu = phase_lobe_gpu(lobe, 1.0f);
    Table2D t;
    t.width = AIRLIGHT_TAIL_NX;
    t.height = AIRLIGHT_TAIL_NY;
    t.channels = 4;
    t.texels.resize(size_t(t.width) * t.height * 4);
    numerics::parallel_for(t.height, [&](int iy) {
        // The row's cv = pi/2 - xi: Y(cv) (phase_math.glsl) decreases from 1 at
        // cv = 0 to 0 at cv = pi/2; inverted by bisection. The Y = 1 row is
        // evaluated just below xi = pi/2 (its limit is continuous).
        const double Y_row = double(iy) / (t.height - 1);
        double lo = 1e-7, hi = 0.5 * numerics::kPi;
        for (int i = 0; i < 60 && iy > 0 && iy + 1 < t.height; ++i) {
            const double mid = 0.5 * (lo + hi);
            float X, Y, N, N1, cvp, cv;
            lobe_coordinates(gpu, 0.0f, float(std::sin(mid)), float(std::cos(mid)), X, Y, N, N1, cvp, cv);
            (Y > Y_row ? lo : hi) = mid;
        }
        const double cv = iy == 0 ? 0.5 * numerics::kPi : (iy + 1 == t.height ? 1e-7 : 0.5 * (lo + hi));
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

std::shared_ptr<const Table2D> lobe_table(const PhaseLobe& lobe, bool glow) {
    const LobeKey key{lobe.rayleigh, lobe.rayleigh ? 0.0f : lobe.g};
    return lobe_cache(glow).get(key, [&] {
        return timed_build(lobe_name(glow ? "phase_glow" : "phase_moments", lobe), [&] {
            return glow ? build_phase_glow_table(lobe, shader::SURFACE_GLOW_NX, shader::SURFACE_GLOW_NY)
                        : build_phase_moment_table(lobe);
        });
    });
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
    const double h = 0.5 * numerics::kPi;
    const double backward_width = lobe.rayleigh ? 0.0 : std::max(1.0 - std::abs(double(lobe.g)), 1e-3);
    for (const auto& [g, w] :
         glow_nodes(2, {h - theta_s, theta_s - h, h + theta_s, 3.0 * h - theta_s}, backward_width)) {
        const double ring = clamped_cosine_ring(g, theta_s);
        if (ring == 0.0) continue;
        double Q, M1, M2;
        phase_tail_moments(lobe, optical_distance * std::sin(g), 0.5 * (numerics::kPi - g), Q, M1, M2, 2);
        sum += w * ring * Q;
    }
    return sum;
}

std::shared_ptr<const Table2D> phase_moment_table(const PhaseLobe& lobe) { return lobe_table(lobe, false); }
std::shared_ptr<const Table2D> phase_glow_table(const PhaseLobe& lobe) { return lobe_table(lobe, true); }

double phase_airlight_bound(const PhaseLobe& lobe) { return phase_tail(lobe, 0.0, 0.5 * numerics::kPi); }

}  // namespace airlight
