// The plane-parallel solver (effects/multiple_scattering/physics.md, design and
// measurements in effects/multiple_scattering/docs/solver.md): per channel and
// azimuth mode, each layer's reflection and transmission by doubling and the
// stack by adding from both ends (effects/multiple_scattering/physics.md
// section 5), the interface fields, then the outputs (sections 6 and 7).
#include "plane_parallel.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "numerics.hpp"
#include "sky.hpp"

namespace airlight {

namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
constexpr double kPi = 3.14159265358979323846;

// Normalised associated Legendre functions Lambda_l^m(x) = sqrt((l-m)!/(l+m)!) P_l^m(x)
// for l = 0..lmax (0 for l < m), by the upward recurrence (effects/multiple_scattering/physics.md section 3).
void normalised_legendre(int m, int lmax, double x, std::vector<double>& out) {
    out.assign(size_t(lmax + 1), 0.0);
    if (m > lmax) return;
    double pmm = 1.0;
    const double s = std::sqrt(std::max(0.0, 1.0 - x * x));
    for (int k = 1; k <= m; ++k) pmm *= std::sqrt((2.0 * k - 1.0) / (2.0 * k)) * s;
    out[size_t(m)] = pmm;
    if (m + 1 <= lmax) out[size_t(m + 1)] = x * std::sqrt(2.0 * m + 1.0) * pmm;
    for (int l = m + 2; l <= lmax; ++l) {
        out[size_t(l)] = ((2.0 * l - 1.0) * x * out[size_t(l - 1)] -
                          std::sqrt(double(l + m - 1) * double(l - m - 1)) * out[size_t(l - 2)]) /
                         std::sqrt(double(l - m) * double(l + m));
    }
}

// A layer's optics in one channel after delta-M scaling (effects/multiple_scattering/physics.md section 4).
struct LayerOptics {
    double depth = 0.0;          // tau (true extinction)
    double scaled_depth = 0.0;   // tau* = (1 - omega f) tau
    double scaled_albedo = 0.0;  // omega* = omega (1 - f) / (1 - omega f)
    std::vector<double> chi;     // chi*_l, l = 0 .. 2N - 1
};

// Reflection R, diffuse transmission Td (T = diag(E) + Td), exact direct
// transmission E, and the sun's diffuse sources per unit beam irradiance at
// the layer's top: U upward at the top, D downward at the bottom; t the
// beam's transmission (effects/multiple_scattering/physics.md section 5).
struct LayerOperators {
    Mat reflection, diffuse_transmission;
    Vec direct;
    Vec sun_up, sun_down;
    double beam = 1.0;
    bool scatters = false;
};

// Phase mode matrices p^m(+mu_i, +-mu_j) and the beam's p^m(+-mu_i, -mu0)
// for moments chi (effects/multiple_scattering/physics.md section 3).
struct ModeKernel {
    Mat same, opposite;    // p^m(mu_i, mu_j), p^m(mu_i, -mu_j)
    Vec sun_up, sun_down;  // p^m(mu_i, -mu0), p^m(-mu_i, -mu0)
};

struct ModeBasis {
    int m = 0, lmax = 0, n = 0;
    std::vector<std::vector<double>> node;  // Lambda_l^m(mu_j)
    std::vector<double> sun;                // Lambda_l^m(-mu0)
};

ModeKernel mode_kernel(const ModeBasis& b, const std::vector<double>& chi, bool sun) {
    const int n = b.n;
    ModeKernel k;
    k.same = Mat::Zero(n, n);
    k.opposite = Mat::Zero(n, n);
    // p^m(x, y) = sum_l (2l+1) chi_l Lambda_l^m(x) Lambda_l^m(y); Lambda(-x) = (-1)^(l+m) Lambda(x).
    for (int l = b.m; l <= b.lmax; ++l) {
        const double c = (2.0 * l + 1.0) * chi[size_t(l)];
        if (c == 0.0) continue;
        const double parity = ((l + b.m) % 2 == 0) ? 1.0 : -1.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double v = c * b.node[size_t(i)][size_t(l)] * b.node[size_t(j)][size_t(l)];
                k.same(i, j) += v;
                k.opposite(i, j) += parity * v;
            }
    }
    if (sun) {
        k.sun_up = Vec::Zero(n);
        k.sun_down = Vec::Zero(n);
        for (int l = b.m; l <= b.lmax; ++l) {
            const double c = (2.0 * l + 1.0) * chi[size_t(l)] * b.sun[size_t(l)];
            const double parity = ((l + b.m) % 2 == 0) ? 1.0 : -1.0;
            for (int i = 0; i < n; ++i) {
                k.sun_up(i) += c * b.node[size_t(i)][size_t(l)];
                k.sun_down(i) += parity * c * b.node[size_t(i)][size_t(l)];
            }
        }
    }
    return k;
}

// One homogeneous layer: a thin layer of depth tau* / 2^n by the diamond
// scheme, then n doublings (effects/multiple_scattering/physics.md section 5).
LayerOperators layer_operators(const LayerOptics& lo, const ModeBasis& b, const std::vector<double>& mu,
                               const std::vector<double>& w, double sun_mu, double initial_depth) {
    const int n = b.n;
    LayerOperators op;
    op.reflection = Mat::Zero(n, n);
    op.diffuse_transmission = Mat::Zero(n, n);
    op.direct = Vec::Ones(n);
    const bool sun = sun_mu > 0.0;
    if (sun) {
        op.sun_up = Vec::Zero(n);
        op.sun_down = Vec::Zero(n);
    }
    const double tau = lo.scaled_depth;
    for (int i = 0; i < n; ++i) op.direct(i) = std::exp(-tau / mu[size_t(i)]);
    op.beam = sun ? std::exp(-tau / sun_mu) : 0.0;
    bool any = lo.scaled_albedo > 0.0 && tau > 0.0;
    if (any) {
        any = false;
        for (int l = b.m; l <= b.lmax; ++l) any = any || lo.chi[size_t(l)] != 0.0;
    }
    if (!any) return op;  // no scattering in this mode: exactly nothing diffuse
    op.scatters = true;
    const ModeKernel k = mode_kernel(b, lo.chi, sun);
    int doublings = 0;
    const double thin = std::max(initial_depth * mu[0], 1e-300);
    if (tau > thin) doublings = int(std::ceil(std::log2(tau / thin)));
    const double delta = std::ldexp(tau, -doublings);
    // Thin layer, diamond scheme (effects/multiple_scattering/physics.md section 5.2): a = delta/2 M^-1 (1 - c P++ W),
    // b = delta/2 M^-1 c P+- W with c = omega*/2.
    const double c = 0.5 * lo.scaled_albedo;
    Mat a(n, n), bm(n, n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double s = 0.5 * delta / mu[size_t(i)];
            a(i, j) = s * ((i == j ? 1.0 : 0.0) - c * k.same(i, j) * w[size_t(j)]);
            bm(i, j) = s * c * k.opposite(i, j) * w[size_t(j)];
        }
    const Mat id = Mat::Identity(n, n);
    Mat lhs(2 * n, 2 * n), rhs(2 * n, 2 * n);
    lhs << -(id + a), bm, -bm, id + a;
    rhs << -bm, -(id - a), id - a, bm;
    Eigen::PartialPivLU<Mat> lu(lhs);
    const Mat x = lu.solve(rhs);
    Mat r = x.topLeftCorner(n, n), td = x.bottomLeftCorner(n, n);
    Vec e(n);
    for (int i = 0; i < n; ++i) {
        // The direct part is what the scheme gives without scattering,
        // (1 - s)/(1 + s) ~ exp(-2 s): kept (not the exact exponential) so
        // that the thin layer conserves energy exactly (effects/multiple_scattering/physics.md section 5.2).
        const double s = 0.5 * delta / mu[size_t(i)];
        e(i) = (1.0 - s) / (1.0 + s);
        td(i, i) -= e(i);
    }
    Vec u, d;
    double t = 0.0;
    if (sun) {
        // Beam source q+- = omega*/(4 pi) (2 - delta_m0) p^m(+-mu_i, -mu0), its
        // mean over the thin layer exact.
        const double mode = b.m == 0 ? 1.0 : 2.0;
        const double mean = -std::expm1(-delta / sun_mu) * sun_mu / delta;
        Vec src(2 * n);
        for (int i = 0; i < n; ++i) {
            const double scale = delta / mu[size_t(i)] * lo.scaled_albedo / (4.0 * kPi) * mode * mean;
            src(i) = -scale * k.sun_up(i);
            src(n + i) = scale * k.sun_down(i);
        }
        const Vec y = lu.solve(src);
        u = y.head(n);
        d = y.tail(n);
        t = std::exp(-delta / sun_mu);
    }
    // Doubling (effects/multiple_scattering/physics.md section 5.3).
    for (int it = 0; it < doublings; ++it) {
        const Mat rr = r * r;
        Eigen::PartialPivLU<Mat> q(id - rr);
        Mat tfull = td;
        tfull.diagonal() += e;
        const Mat qt = q.solve(tfull);
        const Mat r2 = r + tfull * r * qt;
        Mat td2 = e.asDiagonal() * td + td * e.asDiagonal() + td * td + tfull * rr * qt;
        if (sun) {
            const Vec up_mid = q.solve(r * d + u * t);
            const Vec down_mid = q.solve(d + r * u * t);
            u = u + tfull * up_mid;
            d = tfull * down_mid + d * t;
            t = t * t;
        }
        r = r2;
        td = std::move(td2);
        e = e.cwiseProduct(e);
    }
    op.reflection = r;
    op.diffuse_transmission = td;
    if (sun) {
        op.sun_up = u;
        op.sun_down = d;
    }
    return op;
}

double hg_value(double g, double c) {
    const double den = 1.0 + g * g - 2.0 * g * c;
    return (1.0 - g * g) / (den * std::sqrt(den));
}

}  // namespace

PhaseFunction PhaseFunction::rayleigh() {
    PhaseFunction p;
    p.kind = Kind::rayleigh;
    return p;
}

PhaseFunction PhaseFunction::henyey_greenstein(double g) {
    PhaseFunction p;
    p.kind = Kind::henyey_greenstein;
    p.g = g;
    return p;
}

PhaseFunction PhaseFunction::legendre(std::vector<double> moments) {
    PhaseFunction p;
    p.kind = Kind::legendre;
    p.moments = std::move(moments);
    if (p.moments.empty()) p.moments.push_back(1.0);
    return p;
}

double PhaseFunction::moment(int l) const {
    switch (kind) {
        case Kind::rayleigh:
            return l == 0
                       ? 1.0
                       : (l == 2 ? 0.1 : 0.0);  // p = 3/4 (1 + c^2) (effects/multiple_scattering/physics.md section 2)
        case Kind::henyey_greenstein:
            return std::pow(g, l);
        case Kind::legendre:
            return l < int(moments.size()) ? moments[size_t(l)] : 0.0;
    }
    return 0.0;
}

double PhaseFunction::value(double c) const {
    switch (kind) {
        case Kind::rayleigh:
            return 0.75 * (1.0 + c * c);
        case Kind::henyey_greenstein:
            return hg_value(g, c);
        case Kind::legendre: {
            double sum = 0.0, p0 = 1.0, p1 = c;
            for (size_t l = 0; l < moments.size(); ++l) {
                const double pl = l == 0 ? 1.0 : (l == 1 ? c : p1);
                sum += (2.0 * double(l) + 1.0) * moments[l] * pl;
                if (l >= 1) {
                    const double next = ((2.0 * double(l) + 1.0) * c * p1 - double(l) * p0) / double(l + 1);
                    p0 = p1;
                    p1 = next;
                }
            }
            return sum;
        }
    }
    return 0.0;
}

void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights) {
    // Golub-Welsch: the Jacobi matrix of the Legendre recurrence.
    Mat j = Mat::Zero(n, n);
    for (int k = 1; k < n; ++k) {
        const double beta = k / std::sqrt(4.0 * k * k - 1.0);
        j(k, k - 1) = j(k - 1, k) = beta;
    }
    Eigen::SelfAdjointEigenSolver<Mat> es(j);
    nodes.resize(size_t(n));
    weights.resize(size_t(n));
    for (int k = 0; k < n; ++k) {
        const double v = es.eigenvectors()(0, k);
        nodes[size_t(k)] = 0.5 * (es.eigenvalues()(k) + 1.0);
        weights[size_t(k)] = v * v;  // 2 v0^2 on [-1, 1], halved on [0, 1]
    }
}

std::array<double, 3> look_direction(double mu, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    return {s * std::cos(phi), mu, s * std::sin(phi)};
}

std::array<double, 9> sh_basis(const std::array<double, 3>& w) {
    const double x = w[0], y = w[1], z = w[2];
    return {0.28209479177387814,
            0.4886025119029199 * y,
            0.4886025119029199 * z,
            0.4886025119029199 * x,
            1.0925484305920792 * x * y,
            1.0925484305920792 * y * z,
            0.31539156525252005 * (3.0 * z * z - 1.0),
            1.0925484305920792 * x * z,
            0.5462742152960396 * (x * x - y * y)};
}

double MultipleScatteringField::node_diffuse_radiance(int level, int channel, int node, double phi) const {
    double v = 0.0;
    for (int m = 0; m < fourier_modes; ++m)
        v += node_radiance[node_index(level, channel, m, node, 0)] * std::cos(m * phi) +
             node_radiance[node_index(level, channel, m, node, 1)] * std::sin(m * phi);
    return v;
}

double MultipleScatteringField::tilted_irradiance_sh(int level, int channel, const std::array<double, 3>& n) const {
    // Clamped-cosine convolution: A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (effects/multiple_scattering/physics.md
    // section 7).
    const std::array<double, 9> y = sh_basis(n);
    const double a[9] = {kPi,       2.0 * kPi / 3.0, 2.0 * kPi / 3.0, 2.0 * kPi / 3.0, kPi / 4.0,
                         kPi / 4.0, kPi / 4.0,       kPi / 4.0,       kPi / 4.0};
    double e = 0.0;
    for (int k = 0; k < 9; ++k) e += a[k] * radiance_sh[size_t(level)][size_t(channel)][size_t(k)] * y[size_t(k)];
    return e;
}

double MultipleScatteringField::tilted_irradiance_nodes(int level, int channel, const std::array<double, 3>& n) const {
    const int az = 256;
    double e = 0.0;
    for (int node = 0; node < 2 * streams; ++node) {
        const int j = node % streams;
        const double mu = node < streams ? node_mu[size_t(j)] : -node_mu[size_t(j)];
        for (int s = 0; s < az; ++s) {
            const double phi = 2.0 * kPi * (s + 0.5) / az;
            const std::array<double, 3> d = look_direction(mu, phi);
            const double c = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
            if (c > 0.0)
                e += node_weight[size_t(j)] * 2.0 * kPi / az * c * node_diffuse_radiance(level, channel, node, phi);
        }
    }
    // The forward peak's residual beam (effects/multiple_scattering/physics.md section 6) along the sun.
    const std::array<double, 3> s = look_direction(sun_mu, 0.0);
    const double c = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];
    if (sun_mu > 0.0 && c > 0.0) e += sun_forward_irradiance[size_t(level)][size_t(channel)] * c;
    return e;
}

namespace {

// The solve (effects/multiple_scattering/physics.md sections 3-7). With `split`
// the sky's light and the sun's travel in their own columns of the adding
// method's source matrices (sky: 0 and 1, the cosine and sine of each azimuth
// mode; sun: 2 and 3) and land in `sun_part`; otherwise both share columns 0
// and 1 and everything lands in the returned field. The operators, the
// costly part, are the same either way.
MultipleScatteringField solve_sources(const SlabAtmosphere& atm, const SlabIllumination& light,
                                      const SolverOptions& opt, MultipleScatteringField* sun_part) {
    const auto start = std::chrono::steady_clock::now();
    const int n = opt.streams;
    if (n < 2 || n > 128) throw std::invalid_argument("solve_plane_parallel: streams must be in [2, 128]");
    const int species = int(atm.phases.size());
    const int layers = int(atm.layers.size());
    const int lmax = 2 * n - 1;
    const int modes = opt.max_fourier_mode < 0 ? 2 * n : std::min(opt.max_fourier_mode + 1, 2 * n);
    const double sun_mu = light.sun_mu > 0.0 ? std::min(light.sun_mu, 1.0) : 0.0;
    const bool sun = sun_mu > 0.0 &&
                     (light.sun_irradiance[0] > 0.0 || light.sun_irradiance[1] > 0.0 || light.sun_irradiance[2] > 0.0);

    const bool split = sun_part != nullptr;
    const int groups = split ? 2 : 1;  // column pairs: (sky and sun) or (sky), (sun)
    const int cols = 2 * groups;
    const int sun_col = split ? 2 : 0;
    MultipleScatteringField out;
    out.species_count = species;
    out.streams = n;
    out.fourier_modes = modes;
    out.sun_mu = sun ? sun_mu : 0.0;
    gauss_legendre_unit(n, out.node_mu, out.node_weight);
    const std::vector<double>& mu = out.node_mu;
    const std::vector<double>& w = out.node_weight;
    out.view_mu = opt.view_mu;
    out.view_phi = opt.view_phi;
    if (out.view_mu.empty())
        for (int k = 0; k <= 64; ++k) out.view_mu.push_back(std::sin(-0.5 * kPi + kPi * k / 64.0));
    if (out.view_phi.empty())
        for (int k = 0; k < 72; ++k) out.view_phi.push_back(2.0 * kPi * k / 72.0);
    const int nv = int(out.view_mu.size()), np = int(out.view_phi.size());

    // Interfaces from the top (k = 0) down to the ground (k = layers); layer
    // l (1-based from the top) lies between interfaces l - 1 and l.
    const int levels = layers + 1;
    auto layer_of = [&](int l) -> const SlabLayer& { return atm.layers[size_t(layers - l)]; };
    std::vector<double> altitude_top_down(static_cast<size_t>(levels));
    altitude_top_down[0] = layers > 0 ? atm.layers.back().top : 0.0;
    for (int l = 1; l <= layers; ++l) altitude_top_down[size_t(l)] = layer_of(l).bottom;

    // Optics per layer and channel (effects/multiple_scattering/physics.md section 4).
    std::vector<std::array<LayerOptics, 3>> optics(static_cast<size_t>(layers + 1));
    std::vector<RgbD> depth_true(size_t(levels), RgbD{}), depth_scaled(size_t(levels), RgbD{});
    for (int l = 1; l <= layers; ++l) {
        const SlabLayer& sl = layer_of(l);
        for (int c = 0; c < 3; ++c) {
            double tt = 0.0, ts = 0.0;
            std::vector<double> chi(size_t(2 * n + 1), 0.0);
            for (int i = 0; i < species; ++i) {
                const double ti = sl.extinction_depth[size_t(i)][size_t(c)];
                const double si = std::min(sl.scattering_depth[size_t(i)][size_t(c)], ti);
                tt += ti;
                ts += si;
                if (si > 0.0)
                    for (int k = 0; k <= 2 * n; ++k) chi[size_t(k)] += si * atm.phases[size_t(i)].moment(k);
            }
            LayerOptics& lo = optics[size_t(l)][size_t(c)];
            lo.depth = tt;
            const double omega = tt > 0.0 ? std::min(ts / tt, 1.0) : 0.0;
            if (ts > 0.0)
                for (double& x : chi) x /= ts;
            const double f = (opt.delta_m && ts > 0.0) ? std::clamp(chi[size_t(2 * n)], 0.0, 1.0 - 1e-9) : 0.0;
            lo.scaled_depth = tt * (1.0 - omega * f);
            lo.scaled_albedo = omega * (1.0 - f) / (1.0 - omega * f);
            lo.chi.assign(size_t(lmax + 1), 0.0);
            for (int k = 0; k <= lmax; ++k) lo.chi[size_t(k)] = ts > 0.0 ? (chi[size_t(k)] - f) / (1.0 - f) : 0.0;
            depth_true[size_t(l)][size_t(c)] = depth_true[size_t(l - 1)][size_t(c)] + lo.depth;
            depth_scaled[size_t(l)][size_t(c)] = depth_scaled[size_t(l - 1)][size_t(c)] + lo.scaled_depth;
        }
    }

    // The sky's Fourier coefficients at the downward ordinates (look mu = mu_j).
    std::vector<std::array<Mat, 3>> sky(static_cast<size_t>(modes));
    for (int m = 0; m < modes; ++m)
        for (int c = 0; c < 3; ++c) sky[size_t(m)][size_t(c)] = Mat::Zero(n, cols);
    bool has_sky = bool(light.sky_radiance);
    if (has_sky) {
        const int ns = std::max(opt.sky_azimuth_samples, 2 * modes + 2);
        for (int j = 0; j < n; ++j)
            for (int s = 0; s < ns; ++s) {
                const double phi = 2.0 * kPi * s / ns;
                const RgbD l = light.sky_radiance(mu[size_t(j)], phi);
                for (int m = 0; m < modes; ++m) {
                    const double norm = (m == 0 ? 1.0 : 2.0) / ns;
                    for (int c = 0; c < 3; ++c) {
                        sky[size_t(m)][size_t(c)](j, 0) += norm * l[size_t(c)] * std::cos(m * phi);
                        sky[size_t(m)][size_t(c)](j, 1) += norm * l[size_t(c)] * std::sin(m * phi);
                    }
                }
            }
    }

    // Outputs (bottom-up altitude order in the struct: level index = layers - k).
    out.altitudes.resize(size_t(levels));
    out.column.resize(size_t(levels));
    for (int k = 0; k < levels; ++k) {
        out.altitudes[size_t(layers - k)] = altitude_top_down[size_t(k)];
        out.column[size_t(layers - k)] = depth_true[size_t(k)];
    }
    out.phased_radiance.assign(size_t(levels) * size_t(species) * 3 * size_t(nv) * size_t(np), 0.0);
    out.node_radiance.assign(size_t(levels) * 3 * size_t(modes) * size_t(2 * n) * 2, 0.0);
    out.irradiance_down.assign(size_t(levels), RgbD{});
    out.irradiance_up.assign(size_t(levels), RgbD{});
    out.sun_direct_irradiance.assign(size_t(levels), RgbD{});
    out.sky_direct_irradiance.assign(size_t(levels), RgbD{});
    out.sun_forward_irradiance.assign(size_t(levels), RgbD{});
    out.radiance_sh.assign(size_t(levels), {});
    if (split) *sun_part = out;  // the same grids, its own zeroed outputs
    // Where each column pair's outputs go, and the sun's own terms.
    MultipleScatteringField* const target[2] = {&out, split ? sun_part : &out};
    MultipleScatteringField& sun_out = *target[1];

    // The forward peak's residual beam (effects/multiple_scattering/physics.md section 6) and the unscattered light.
    for (int k = 0; k < levels; ++k)
        for (int c = 0; c < 3; ++c) {
            const int lev = layers - k;
            const double tt = depth_true[size_t(k)][size_t(c)], ts = depth_scaled[size_t(k)][size_t(c)];
            if (sun) {
                const double e = light.sun_irradiance[size_t(c)];
                sun_out.sun_direct_irradiance[size_t(lev)][size_t(c)] = e * sun_mu * std::exp(-tt / sun_mu);
                sun_out.sun_forward_irradiance[size_t(lev)][size_t(c)] =
                    e * std::exp(-ts / sun_mu) * -std::expm1(-(tt - ts) / sun_mu);
            }
            double sky_flux = 0.0;
            for (int j = 0; j < n; ++j)
                sky_flux +=
                    2.0 * kPi * w[size_t(j)] * mu[size_t(j)] * sky[0][size_t(c)](j, 0) * std::exp(-tt / mu[size_t(j)]);
            out.sky_direct_irradiance[size_t(lev)][size_t(c)] = sky_flux;
        }
    for (int c = 0; c < 3; ++c) {
        sun_out.incident_flux[size_t(c)] = sun ? light.sun_irradiance[size_t(c)] * sun_mu : 0.0;
        for (int j = 0; j < n; ++j)
            out.incident_flux[size_t(c)] += 2.0 * kPi * w[size_t(j)] * mu[size_t(j)] * sky[0][size_t(c)](j, 0);
    }

    // Per-species view kernels need Lambda at the view cosines (propagation u = -mu_view).
    std::vector<double> tmp;
    // Azimuth convergence per column pair, so that each part of a split solve
    // is the solve of its source alone.
    double mode0_scale[2] = {0.0, 0.0};
    int quiet_modes[2] = {0, 0};
    int modes_solved[2] = {0, 0};
    bool converged[2] = {false, !split};
    const Mat id = Mat::Identity(n, n);
    for (int m = 0; m < modes; ++m) {
        ModeBasis basis;
        basis.m = m;
        basis.lmax = lmax;
        basis.n = n;
        basis.node.resize(size_t(n));
        for (int j = 0; j < n; ++j) normalised_legendre(m, lmax, mu[size_t(j)], basis.node[size_t(j)]);
        if (sun) normalised_legendre(m, lmax, -sun_mu, basis.sun);
        // View kernels p_i^m(u_a, +-mu_j) with the species' own moments (effects/multiple_scattering/physics.md section
        // 6).
        std::vector<Mat> view_same(static_cast<size_t>(species)), view_opposite(static_cast<size_t>(species));
        std::vector<std::vector<double>> view_lambda(static_cast<size_t>(nv));
        for (int a = 0; a < nv; ++a) normalised_legendre(m, lmax, -out.view_mu[size_t(a)], view_lambda[size_t(a)]);
        for (int i = 0; i < species; ++i) {
            view_same[size_t(i)] = Mat::Zero(nv, n);
            view_opposite[size_t(i)] = Mat::Zero(nv, n);
            for (int l = m; l <= lmax; ++l) {
                const double cl = (2.0 * l + 1.0) * atm.phases[size_t(i)].moment(l);
                if (cl == 0.0) continue;
                const double parity = ((l + m) % 2 == 0) ? 1.0 : -1.0;
                for (int a = 0; a < nv; ++a)
                    for (int j = 0; j < n; ++j) {
                        const double v = cl * view_lambda[size_t(a)][size_t(l)] * basis.node[size_t(j)][size_t(l)];
                        view_same[size_t(i)](a, j) += v;
                        view_opposite[size_t(i)](a, j) += parity * v;
                    }
            }
        }
        std::vector<double> cos_m(static_cast<size_t>(np)), sin_m(static_cast<size_t>(np));
        for (int b = 0; b < np; ++b) {
            cos_m[size_t(b)] = std::cos(m * out.view_phi[size_t(b)]);
            sin_m[size_t(b)] = std::sin(m * out.view_phi[size_t(b)]);
        }
        // The channels are independent: one thread each when allowed, each
        // writing only its own channel's outputs.
        using Cache = std::vector<std::pair<const LayerOptics*, LayerOperators>>;
        double channel_scale[3][2] = {};
        auto solve_channel = [&](int c, Cache& cache) {
            double* mode_scale = channel_scale[c];
            // Layer operators.
            std::vector<LayerOperators> ops(static_cast<size_t>(layers + 1));
            bool any_scatter = false;
            for (int l = 1; l <= layers; ++l) {
                // Layers of equal optics (equal parts of a uniform species, grey
                // channels) share their operators (cache of this mode).
                const LayerOptics& lo = optics[size_t(l)][size_t(c)];
                const LayerOperators* same = nullptr;
                for (const auto& entry : cache)
                    if (entry.first->scaled_depth == lo.scaled_depth &&
                        entry.first->scaled_albedo == lo.scaled_albedo && entry.first->chi == lo.chi) {
                        same = &entry.second;
                        break;
                    }
                if (same) {
                    ops[size_t(l)] = *same;
                } else {
                    ops[size_t(l)] = layer_operators(lo, basis, mu, w, sun ? sun_mu : 0.0, opt.initial_depth);
                    cache.emplace_back(&lo, ops[size_t(l)]);
                }
                any_scatter = any_scatter || ops[size_t(l)].scatters;
            }
            const double albedo = m == 0 ? light.ground_albedo[size_t(c)] : 0.0;
            const bool sky_mode = sky[size_t(m)][size_t(c)].cwiseAbs().maxCoeff() > 0.0;
            const bool residual = depth_true[size_t(layers)][size_t(c)] > depth_scaled[size_t(layers)][size_t(c)];
            if (!any_scatter && albedo == 0.0 && !(residual && sky_mode)) return;  // nothing diffuse in this mode
            if (!any_scatter && !sky_mode && !sun) return;
            const double e_sun = sun ? light.sun_irradiance[size_t(c)] : 0.0;
            std::vector<double> beta(size_t(levels), 0.0);  // beam irradiance (normal) at interface k, scaled depth
            for (int k = 0; k < levels; ++k)
                beta[size_t(k)] = e_sun * std::exp(-depth_scaled[size_t(k)][size_t(c)] / std::max(sun_mu, 1e-300));
            // Top-down adding (effects/multiple_scattering/physics.md section 5.4): Rb reflection of the stack above
            // for light from below; Sdown the downward light with nothing from
            // below, its unscattered part unsc and its diffuse part sd.
            std::vector<Mat> rb(static_cast<size_t>(levels)), sdown(static_cast<size_t>(levels)),
                sd(static_cast<size_t>(levels)), unsc(static_cast<size_t>(levels));
            rb[0] = Mat::Zero(n, n);
            sdown[0] = sky[size_t(m)][size_t(c)];
            unsc[0] = sdown[0];
            sd[0] = Mat::Zero(n, cols);
            for (int k = 0; k < layers; ++k) {
                const LayerOperators& op = ops[size_t(k + 1)];
                Mat t = op.diffuse_transmission;
                t.diagonal() += op.direct;
                Eigen::PartialPivLU<Mat> g(id - rb[size_t(k)] * op.reflection);
                Mat src = sdown[size_t(k)];
                Mat refl = op.reflection * sdown[size_t(k)];
                if (sun) {
                    src.col(sun_col) += rb[size_t(k)] * op.sun_up * beta[size_t(k)];
                    refl.col(sun_col) += op.sun_up * beta[size_t(k)];
                }
                const Mat down = g.solve(src);
                const Mat diffuse = sd[size_t(k)] + g.solve(rb[size_t(k)] * refl);
                sdown[size_t(k + 1)] = t * down;
                sd[size_t(k + 1)] = op.diffuse_transmission * down + op.direct.asDiagonal() * diffuse;
                if (sun) {
                    sdown[size_t(k + 1)].col(sun_col) += op.sun_down * beta[size_t(k)];
                    sd[size_t(k + 1)].col(sun_col) += op.sun_down * beta[size_t(k)];
                }
                unsc[size_t(k + 1)] = op.direct.asDiagonal() * unsc[size_t(k)];
                rb[size_t(k + 1)] = op.reflection + t * g.solve(rb[size_t(k)] * t);
            }
            // Bottom-up adding: Ru reflection of everything below (ground
            // included) for light from above; Sup the upward light with
            // nothing from above.
            std::vector<Mat> ru(static_cast<size_t>(levels)), sup(static_cast<size_t>(levels));
            ru[size_t(layers)] = Mat::Zero(n, n);
            sup[size_t(layers)] = Mat::Zero(n, cols);
            if (albedo > 0.0) {
                // Lambert: I+ = A / pi x (2 pi sum_j w_j mu_j I-_j + mu0 beam) (effects/multiple_scattering/physics.md
                // section 5.1).
                for (int i = 0; i < n; ++i)
                    for (int j = 0; j < n; ++j) ru[size_t(layers)](i, j) = 2.0 * albedo * w[size_t(j)] * mu[size_t(j)];
                if (sun) sup[size_t(layers)].col(sun_col).setConstant(albedo / kPi * sun_mu * beta[size_t(layers)]);
            }
            for (int k = layers; k >= 1; --k) {
                const LayerOperators& op = ops[size_t(k)];
                Mat t = op.diffuse_transmission;
                t.diagonal() += op.direct;
                Eigen::PartialPivLU<Mat> h(id - ru[size_t(k)] * op.reflection);
                ru[size_t(k - 1)] = op.reflection + t * h.solve(ru[size_t(k)] * t);
                Mat src = sup[size_t(k)];
                if (sun) src.col(sun_col) += ru[size_t(k)] * op.sun_down * beta[size_t(k - 1)];
                sup[size_t(k - 1)] = t * h.solve(src);
                if (sun) sup[size_t(k - 1)].col(sun_col) += op.sun_up * beta[size_t(k - 1)];
            }
            // Interface fields (effects/multiple_scattering/physics.md section 5.4) and the outputs.
            for (int k = 0; k < levels; ++k) {
                const int lev = layers - k;
                Eigen::PartialPivLU<Mat> f(id - rb[size_t(k)] * ru[size_t(k)]);
                const Mat down = f.solve(sdown[size_t(k)] + rb[size_t(k)] * sup[size_t(k)]);
                const Mat up = ru[size_t(k)] * down + sup[size_t(k)];
                Mat diffuse_down =
                    sd[size_t(k)] + f.solve(rb[size_t(k)] * (ru[size_t(k)] * sdown[size_t(k)] + sup[size_t(k)]));
                // The sky's forward-peak residual (effects/multiple_scattering/physics.md section 6).
                const double tt = depth_true[size_t(k)][size_t(c)], ts = depth_scaled[size_t(k)][size_t(c)];
                if (tt > ts)
                    for (int j = 0; j < n; ++j)
                        diffuse_down.row(j) += sky[size_t(m)][size_t(c)].row(j) * std::exp(-ts / mu[size_t(j)]) *
                                               -std::expm1(-(tt - ts) / mu[size_t(j)]);
                for (int g = 0; g < groups; ++g) {
                    if (converged[g]) continue;
                    for (int j = 0; j < n; ++j)
                        for (int s = 0; s < 2; ++s) {
                            MultipleScatteringField& o = *target[g];
                            o.node_radiance[o.node_index(lev, c, m, j, s)] = diffuse_down(j, 2 * g + s);
                            o.node_radiance[o.node_index(lev, c, m, n + j, s)] = up(j, 2 * g + s);
                        }
                    mode_scale[g] = std::max({mode_scale[g], diffuse_down.middleCols(2 * g, 2).cwiseAbs().maxCoeff(),
                                              up.middleCols(2 * g, 2).cwiseAbs().maxCoeff()});
                }
                if (m == 0) {
                    for (int g = 0; g < groups; ++g) {
                        double fd = 0.0, fu = 0.0;
                        for (int j = 0; j < n; ++j) {
                            fd += 2.0 * kPi * w[size_t(j)] * mu[size_t(j)] * diffuse_down(j, 2 * g);
                            fu += 2.0 * kPi * w[size_t(j)] * mu[size_t(j)] * up(j, 2 * g);
                        }
                        target[g]->irradiance_down[size_t(lev)][size_t(c)] = fd;
                        target[g]->irradiance_up[size_t(lev)][size_t(c)] = fu;
                    }
                    sun_out.irradiance_down[size_t(lev)][size_t(c)] +=
                        sun_mu * sun_out.sun_forward_irradiance[size_t(lev)][size_t(c)];
                }
                // K_i^m(u_a) = 1/2 sum_j w_j [p^m(u, mu_j) I+_j + p^m(u, -mu_j) I-_j]
                // (effects/multiple_scattering/physics.md section 6).
                const Mat wu = Eigen::Map<const Vec>(w.data(), n).asDiagonal() * up;
                const Mat wd = Eigen::Map<const Vec>(w.data(), n).asDiagonal() * diffuse_down;
                for (int i = 0; i < species; ++i) {
                    const Mat kv = 0.5 * (view_same[size_t(i)] * wu + view_opposite[size_t(i)] * wd);
                    for (int g = 0; g < groups; ++g) {
                        if (converged[g]) continue;
                        double* dst = &target[g]->phased_radiance[out.phased_index(lev, i, c, 0, 0)];
                        for (int a = 0; a < nv; ++a)
                            for (int b = 0; b < np; ++b)
                                dst[size_t(a) * size_t(np) + size_t(b)] +=
                                    kv(a, 2 * g) * cos_m[size_t(b)] + kv(a, 2 * g + 1) * sin_m[size_t(b)];
                    }
                }
            }
        };
        if (opt.threads > 1) {
            Cache caches[3];
            numerics::parallel_for(
                3, [&](int c) { solve_channel(c, caches[c]); }, opt.threads);
        } else {
            Cache cache;  // shared: grey channels reuse each other's layers
            for (int c = 0; c < 3; ++c) solve_channel(c, cache);
        }
        // Azimuth convergence (effects/multiple_scattering/physics.md section 3): two modes in a row below the
        // tolerance.
        for (int g = 0; g < groups; ++g) {
            if (converged[g]) continue;
            const double mode_scale = std::max({channel_scale[0][g], channel_scale[1][g], channel_scale[2][g]});
            modes_solved[g] = m + 1;
            if (m == 0)
                mode0_scale[g] = mode_scale;
            else {
                quiet_modes[g] = mode_scale <= opt.azimuth_tolerance * mode0_scale[g] ? quiet_modes[g] + 1 : 0;
                converged[g] = quiet_modes[g] >= 2;
            }
        }
        if (converged[0] && converged[1]) break;
    }
    out.modes_solved = modes_solved[0];
    if (split) sun_part->modes_solved = modes_solved[1];

    // The sun's forward-peak residual scattered by each species' full phase (effects/multiple_scattering/physics.md
    // section 6).
    if (sun) {
        // p_i(d . s) / (4 pi) on the view grid, once per species.
        const std::array<double, 3> s = look_direction(sun_mu, 0.0);
        std::vector<double> phase_sun(size_t(nv) * size_t(np));
        for (int i = 0; i < species; ++i) {
            for (int a = 0; a < nv; ++a)
                for (int b = 0; b < np; ++b) {
                    const std::array<double, 3> d = look_direction(out.view_mu[size_t(a)], out.view_phi[size_t(b)]);
                    phase_sun[size_t(a) * size_t(np) + size_t(b)] =
                        atm.phases[size_t(i)].value(d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) / (4.0 * kPi);
                }
            for (int lev = 0; lev < levels; ++lev)
                for (int c = 0; c < 3; ++c) {
                    const double res = sun_out.sun_forward_irradiance[size_t(lev)][size_t(c)];
                    if (res == 0.0) continue;
                    double* dst = &sun_out.phased_radiance[out.phased_index(lev, i, c, 0, 0)];
                    for (size_t k = 0; k < phase_sun.size(); ++k) dst[k] += phase_sun[k] * res;
                }
        }
    }

    // Spherical harmonics l <= 2 of the diffuse radiance (effects/multiple_scattering/physics.md section 7): modes 0..2
    // are the only ones they see; 16 azimuths integrate them exactly.
    const int az = 16;
    for (int g = 0; g < groups; ++g)
        for (int lev = 0; lev < levels; ++lev)
            for (int c = 0; c < 3; ++c) {
                MultipleScatteringField& o = *target[g];
                std::array<double, 9> sh{};
                for (int node = 0; node < 2 * n; ++node) {
                    const int j = node % n;
                    const double mv = node < n ? mu[size_t(j)] : -mu[size_t(j)];
                    for (int s = 0; s < az; ++s) {
                        const double phi = 2.0 * kPi * s / az;
                        double l = 0.0;
                        for (int m = 0; m < std::min(3, modes); ++m)
                            l += o.node_radiance[o.node_index(lev, c, m, node, 0)] * std::cos(m * phi) +
                                 o.node_radiance[o.node_index(lev, c, m, node, 1)] * std::sin(m * phi);
                        const std::array<double, 9> y = sh_basis(look_direction(mv, phi));
                        for (int k = 0; k < 9; ++k) sh[size_t(k)] += w[size_t(j)] * 2.0 * kPi / az * l * y[size_t(k)];
                    }
                }
                if (sun && target[g] == &sun_out) {
                    const std::array<double, 9> y = sh_basis(look_direction(sun_mu, 0.0));
                    for (int k = 0; k < 9; ++k)
                        sh[size_t(k)] += o.sun_forward_irradiance[size_t(lev)][size_t(c)] * y[size_t(k)];
                }
                o.radiance_sh[size_t(lev)][size_t(c)] = sh;
            }
    out.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    sun_out.solve_seconds = out.solve_seconds;
    return out;
}

}  // namespace

MultipleScatteringField solve_plane_parallel(const SlabAtmosphere& atm, const SlabIllumination& light,
                                             const SolverOptions& opt) {
    return solve_sources(atm, light, opt, nullptr);
}

FieldBySource solve_plane_parallel_by_source(const SlabAtmosphere& atm, const SlabIllumination& light,
                                             const SolverOptions& opt) {
    FieldBySource parts;
    parts.sky = solve_sources(atm, light, opt, &parts.sun);
    return parts;
}

namespace {

// integral_a^b of a profile piece rho = v exp(-(y - s) k) (effects/multiple_scattering/physics.md section 8).
double piece_integral(double v, double s, double k, double a, double b) {
    if (!(b > a) || v == 0.0) return 0.0;
    if (k == 0.0) return v * (b - a);
    // v exp(-(a - s) k) (1 - exp(-(b - a) k)) / k, stable for either sign of k.
    return v * std::exp(-(a - s) * k) * (b - a) * (-std::expm1(-(b - a) * k) / ((b - a) * k));
}

double column_between(const shader::SpeciesGpu& sp, double a, double b) {
    double sum = 0.0;
    for (int k = 0; k < 4; ++k) {
        const double s = sp.starts[k];
        if (s >= shader::NO_HIT) break;
        const double e = (k + 1 < 4 && sp.starts[k + 1] < shader::NO_HIT) ? double(sp.starts[k + 1]) : 1e300;
        sum += piece_integral(sp.values[k], s, sp.inv_scales[k], std::max(a, s), std::min(b, e));
    }
    return sum;
}

}  // namespace

SlabAtmosphere slab_from_species(const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                 const std::vector<double>& levels) {
    SlabAtmosphere atm;
    std::vector<int> used;
    for (int i = 0; i < shader::SPECIES_COUNT; ++i) {
        if (species[i].phase.z == 0.0f) continue;
        used.push_back(i);
        atm.phases.push_back(species[i].phase.y != 0.0f ? PhaseFunction::rayleigh()
                                                        : PhaseFunction::henyey_greenstein(species[i].phase.x));
    }
    for (size_t k = 0; k + 1 < levels.size(); ++k) {
        SlabLayer layer;
        layer.bottom = levels[k];
        layer.top = levels[k + 1];
        for (int i : used) {
            const double col = column_between(species[i], layer.bottom, layer.top);
            RgbD t{}, s{};
            for (int c = 0; c < 3; ++c) {
                t[size_t(c)] = double(species[i].sigma_t[c]) * col;
                s[size_t(c)] = double(species[i].sigma_s[c]) * col;
            }
            layer.extinction_depth.push_back(t);
            layer.scattering_depth.push_back(s);
        }
        atm.layers.push_back(layer);
    }
    return atm;
}

SlabIllumination slab_illumination(const shader::SkyGpu& sky, const RgbD& ground_albedo) {
    SlabIllumination light;
    light.ground_albedo = ground_albedo;
    const glm::dvec3 s = glm::dvec3(sky.sun_direction);
    if (sky.sun_direction.w > 0.0f && s.y > 0.0) {
        light.sun_mu = s.y;
        light.sun_irradiance = {sky.sun_irradiance.x, sky.sun_irradiance.y, sky.sun_irradiance.z};
    }
    if (int(sky.zenith_radiance.w) == shader::SKY_NONE) return light;
    // phi is measured from the sun's horizontal direction (x when it is at the zenith).
    glm::dvec3 along(s.x, 0.0, s.z);
    along = glm::length(along) > 1e-9 ? glm::normalize(along) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 across = glm::cross(along, glm::dvec3(0.0, 1.0, 0.0));
    light.sky_radiance = [sky, along, across](double mu, double phi) {
        const double h = std::sqrt(std::max(0.0, 1.0 - mu * mu));
        const glm::dvec3 w = h * (std::cos(phi) * along + std::sin(phi) * across) + glm::dvec3(0.0, mu, 0.0);
        const double shape = double(shader::sky_shape(sky, glm::vec3(w)));
        return RgbD{shape * sky.zenith_radiance.x, shape * sky.zenith_radiance.y, shape * sky.zenith_radiance.z};
    };
    return light;
}

// The top optical depth whose layers are refined (slab_levels).
constexpr double SUNLIT_DEPTH = 4.0;

std::vector<double> slab_levels(const shader::SpeciesGpu species[shader::SPECIES_COUNT], int segments,
                                double max_depth) {
    float top = 0.0f;
    const std::vector<float> base = make_altitude_levels(species, segments, top);
    std::vector<double> levels;
    if (base.empty()) return levels;
    // The densest channel's optical depth between two altitudes.
    auto depth_between = [&](double a, double b) {
        double depth = 0.0;
        for (int c = 0; c < 3; ++c) {
            double d = 0.0;
            for (int i = 0; i < shader::SPECIES_COUNT; ++i)
                if (species[i].phase.z != 0.0f) d += double(species[i].sigma_t[c]) * column_between(species[i], a, b);
            depth = std::max(depth, d);
        }
        return depth;
    };
    // The altitude in [a, b] at optical depth `target` above a (bisection).
    auto altitude_at = [&](double a, double b, double target) {
        double lo = a, hi = b;
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            (depth_between(a, mid) < target ? lo : hi) = mid;
        }
        return 0.5 * (lo + hi);
    };
    std::vector<double> cuts(base.begin(), base.end());
    // Grading at both boundaries (effects/multiple_scattering/docs/solver.md section 6): grazing radiance
    // changes over optical depths of the order of its cosine next to the
    // ground and the top, so levels are added at depths max_depth / 2^k
    // (k = 1..10) from each.
    const double total = depth_between(0.0, double(top));
    for (int k = 1; k <= 10; ++k) {
        const double d = max_depth * std::ldexp(1.0, -k);
        if (d >= 0.5 * total) continue;
        cuts.push_back(altitude_at(0.0, double(top), d));
        cuts.push_back(altitude_at(0.0, double(top), total - d));
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    levels.push_back(cuts[0]);
    for (size_t k = 1; k < cuts.size(); ++k) {
        const double a = cuts[k - 1], b = cuts[k];
        if (!(b > a)) continue;
        const double depth = depth_between(a, b);
        // Where the sun's beam is still strong (the top SUNLIT_DEPTH of the
        // column), the aureole it scatters varies like C exp(-C / mu0):
        // layers there are 8 times thinner (effects/multiple_scattering/docs/solver.md section 6).
        const double from_top = depth_between(b, double(top));
        const double limit = from_top < SUNLIT_DEPTH ? max_depth / 8.0 : max_depth;
        const int parts = std::max(1, int(std::ceil(depth / limit)));
        // Equal parts in optical depth.
        for (int p = 1; p < parts; ++p) levels.push_back(altitude_at(a, b, depth * p / parts));
        levels.push_back(b);
    }
    return levels;
}

}  // namespace airlight
