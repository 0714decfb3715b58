#include "spot_tables.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "airlight_tables.hpp"
#include "numerics.hpp"

namespace airlight {
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
            const double D = mid + half * numerics::kGaussLegendre8Nodes[k];
            const double w =
                half * numerics::kGaussLegendre8Weights[k] * std::exp(-u * std::sin(D) / (s0 * std::sin(cv - D)));
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
    return table_built_once("spot_moments", [] {
        using namespace shader;
        Table2D t;
        t.width = AIRLIGHT_TAIL_NX;
        t.height = AIRLIGHT_TAIL_NY;
        t.channels = 4;
        t.texels.resize(size_t(t.width) * t.height * 4);
        const Table2D& tail = airlight_tail_table();
        for (int iy = 0; iy < t.height; ++iy) {
            // The xi = pi/2 row is evaluated just below it (its limit is continuous).
            const double cv = std::max((1.0 - double(iy) / (t.height - 1)) * 0.5 * numerics::kPi, 1e-6);
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
}

}  // namespace airlight
