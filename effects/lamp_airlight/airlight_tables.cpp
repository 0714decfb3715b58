#include "airlight_tables.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "numerics.hpp"

namespace airlight {
namespace {

using cdouble = std::complex<double>;

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
        return std::exp(w) * (-numerics::kEulerGamma - std::log(w) - sum);
    }
    cdouble f = 0.0;
    for (int k = 120; k >= 1; --k) f = double(k) * double(k) / (w + double(2 * k + 1) - f);
    return 1.0 / (w + 1.0 - f);
}

}  // namespace

// Azimuthal integral of max(cos theta_s cos g + sin theta_s sin g cos phi, 0)
// over phi in [0, 2 pi): the clamped cosine of directions at angle g from the
// light direction, seen from a surface whose normal is at theta_s from it.
double clamped_cosine_ring(double g, double theta_s) {
    const double a = std::cos(theta_s) * std::cos(g);
    const double b = std::sin(theta_s) * std::sin(g);
    if (b <= std::abs(a)) return a > 0.0 ? 2.0 * numerics::kPi * a : 0.0;
    const double phi0 = std::acos(-a / b);
    return 2.0 * (a * phi0 + b * std::sin(phi0));
}

// Quadrature nodes in g in [0, pi] for the glow integral: panels graded
// geometrically towards g = 0, where Q(T sin g, g/2) has a boundary layer of
// width ~1/T, then uniform. Returns (g, weight) pairs.
// Panel edges also sit at pi/2, where Phi has a kink for theta_s = 0 or pi,
// and at the given extra points (the other places where Phi changes form).
// `backward_width` > 0 also grades them geometrically towards g = pi, where a
// backward phase lobe of that width (~1 - |g|) peaks.
std::vector<std::pair<double, double>> glow_nodes(int scale, std::vector<double> extra_edges, double backward_width) {
    std::vector<double> edges = {0.0, 0.5 * numerics::kPi};
    for (double e = 1e-5; e < 0.5; e *= 1.0 + 0.6 / scale) edges.push_back(e);
    if (backward_width > 0.0) {
        for (double e = 1e-2 * backward_width; e < 0.5; e *= 1.0 + 0.6 / scale) edges.push_back(numerics::kPi - e);
    }
    const int uniform_panels = 24 * scale;
    const double start = edges.back();
    for (int i = 1; i <= uniform_panels; ++i) edges.push_back(start + (numerics::kPi - start) * i / uniform_panels);
    for (double e : extra_edges)
        if (e > 0.0 && e < numerics::kPi) edges.push_back(e);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<std::pair<double, double>> nodes;
    for (size_t p = 0; p + 1 < edges.size(); ++p) {
        const double mid = 0.5 * (edges[p] + edges[p + 1]), half = 0.5 * (edges[p + 1] - edges[p]);
        for (int k = 0; k < 8; ++k)
            nodes.emplace_back(mid + half * numerics::kGaussLegendre8Nodes[k],
                               half * numerics::kGaussLegendre8Weights[k]);
    }
    return nodes;
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
    const double h = 0.5 * numerics::kPi;
    for (const auto& [g, w] : glow_nodes(nodes_scale, {h - theta_s, theta_s - h, h + theta_s, 3.0 * h - theta_s})) {
        const double ring = clamped_cosine_ring(g, theta_s);
        if (ring == 0.0) continue;
        sum += w * ring * airlight_tail_exact(optical_distance * std::sin(g), 0.5 * (numerics::kPi - g));
    }
    return sum;
}

const Table2D& airlight_tail_table() {
    return table_built_once("airlight_tail", [] {
        using namespace shader;
        Table2D t;
        t.width = AIRLIGHT_TAIL_NX;
        t.height = AIRLIGHT_TAIL_NY;
        t.texels.resize(size_t(t.width) * t.height);
        for (int iy = 0; iy < t.height; ++iy) {
            const double cv = (1.0 - double(iy) / (t.height - 1)) * 0.5 * numerics::kPi;
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
}

const Table2D& surface_glow_table() {
    return table_built_once("surface_glow",
                            [] { return build_surface_glow_table(shader::SURFACE_GLOW_NX, shader::SURFACE_GLOW_NY); });
}

// A glow table (log G) of width x height: column X holds the optical
// distance T (SURFACE_GLOW_T_SCALE / T_MAX warp), row Y the cos theta_s of
// surface_glow_cos_theta(Y, T, k_min); tail(u, cv) is the airlight tail of
// the medium's phase function. G = int_0^pi Q(T sin g, g / 2) Phi(g, theta_s) dg
// (effects/lamp_airlight/physics.md; effects/lamp_airlight/docs/airlight_table.md section 7).
Table2D build_glow_table(int width, int height, double k_min, double backward_width,
                         const std::function<double(double, double)>& tail) {
    using namespace shader;
    Table2D t;
    t.width = width;
    t.height = height;
    t.texels.resize(size_t(t.width) * t.height);
    const auto nodes = glow_nodes(1, {}, backward_width);
    numerics::parallel_for(t.width, [&](int ix) {
        const double X = double(ix) / (t.width - 1);
        const double t0 = double(SURFACE_GLOW_T_SCALE);
        const double T = t0 * std::expm1(X * X * std::log1p(double(SURFACE_GLOW_T_MAX) / t0));
        // Q depends on T and g only: evaluate once per column, reuse for every theta_s.
        std::vector<double> q(nodes.size());
        for (size_t n = 0; n < nodes.size(); ++n) {
            const double g = nodes[n].first;
            q[n] = tail(T * std::sin(g), 0.5 * (numerics::kPi - g));
        }
        for (int iy = 0; iy < t.height; ++iy) {
            const double c = surface_glow_cos_theta(double(iy) / (t.height - 1), T, k_min);
            const double theta_s = std::acos(c);
            // Phi(g, theta_s) kinks at g = |pi/2 - theta_s| and pi - |pi/2 - theta_s|:
            // a panel holding a kink is split there, with Q at the new nodes from
            // the panel's degree-7 interpolant (Q is smooth within a panel).
            const double off = std::abs(0.5 * numerics::kPi - theta_s);
            const double kinks[2] = {off, numerics::kPi - off};
            double sum = 0.0;
            for (size_t p = 0; p < nodes.size() / 8; ++p) {
                const std::pair<double, double>* panel = &nodes[8 * p];
                const double* qp = &q[8 * p];
                const double mid = panel[0].first - numerics::kGaussLegendre8Nodes[0] * panel[0].second /
                                                        numerics::kGaussLegendre8Weights[0];
                const double half = panel[0].second / numerics::kGaussLegendre8Weights[0];
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
                        const double g = pm + ph * numerics::kGaussLegendre8Nodes[j];
                        double value = 0.0;  // Lagrange interpolation through the panel's nodes
                        for (int a = 0; a < 8; ++a) {
                            double basis = 1.0;
                            for (int b = 0; b < 8; ++b)
                                if (b != a) basis *= (g - panel[b].first) / (panel[a].first - panel[b].first);
                            value += basis * qp[a];
                        }
                        sum += ph * numerics::kGaussLegendre8Weights[j] * value * clamped_cosine_ring(g, theta_s);
                    }
                }
            }
            t.texels[size_t(iy) * t.width + ix] = float(std::log(sum));
        }
    });
    return t;
}

Table2D build_surface_glow_table(int width, int height) {
    return build_glow_table(width, height, shader::SURFACE_GLOW_K_MIN, 0.0, airlight_tail_exact);
}

}  // namespace airlight
