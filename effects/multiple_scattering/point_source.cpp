// Multiple scattering of a point lamp in an infinite homogeneous medium
// (effects/multiple_scattering/physics.md sections 10 to 13; measurements:
// effects/multiple_scattering/docs/lamps.md).
#include "point_source.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "numerics.hpp"
#include "plane_parallel.hpp"
#include "shader_cpp.hpp"

namespace airlight {
namespace {

using numerics::kPi;

// xoshiro256+ seeded through splitmix64: a stream per (seed, batch).
struct Rng {
    uint64_t s[4];
    Rng(uint64_t seed, uint64_t stream) {
        uint64_t x = seed * 0x9E3779B97F4A7C15ull + stream * 0xD1B54A32D192ED03ull + 1;
        for (uint64_t& v : s) {
            x += 0x9E3779B97F4A7C15ull;
            uint64_t z = x;
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            v = z ^ (z >> 31);
        }
    }
    static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    // Uniform in [0, 1).
    double uniform() {
        const uint64_t result = s[0] + s[3];
        const uint64_t t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = rotl(s[3], 45);
        return double(result >> 11) * 0x1.0p-53;
    }
};

struct Vec {
    double x, y, z;
};

// The cosine of the scattering angle drawn from the phase function.
double sample_cos(const PointSourcePhase& phase, Rng& rng) {
    double pick = rng.uniform();
    if (pick < phase.rayleigh_weight) {
        // Rayleigh: rejection from uniform cos theta against (1 + mu^2) / 2.
        for (;;) {
            const double mu = 2.0 * rng.uniform() - 1.0;
            if (2.0 * rng.uniform() <= 1.0 + mu * mu) return mu;
        }
    }
    pick -= phase.rayleigh_weight;
    double g = phase.hg.empty() ? 0.0 : phase.hg.back().g;
    for (const auto& lobe : phase.hg) {
        if (pick < lobe.weight) {
            g = lobe.g;
            break;
        }
        pick -= lobe.weight;
    }
    const double xi = rng.uniform();
    if (std::abs(g) < 1e-6) return 2.0 * xi - 1.0;
    const double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
    return std::clamp((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0);
}

// `dir` turned by the scattering angle acos(mu) at azimuth phi.
Vec scatter(const Vec& d, double mu, double phi) {
    const double st = std::sqrt(std::max(0.0, 1.0 - mu * mu)), cp = std::cos(phi), sp = std::sin(phi);
    if (std::abs(d.z) > 0.99999) {
        const double sign = d.z > 0.0 ? 1.0 : -1.0;
        return {st * cp, st * sp, sign * mu};
    }
    const double t = std::sqrt(1.0 - d.z * d.z);
    return {st * (d.x * d.z * cp - d.y * sp) / t + d.x * mu, st * (d.y * d.z * cp + d.x * sp) / t + d.y * mu,
            -st * cp * t + d.z * mu};
}

// The bins of the source: R from r_core (pooled below) to r_switch, 12 per
// decade, then of width kLinearBin to r_kill (where J falls as e^{-R / L_d}, a bin
// is 0.1 to 0.2 e-folds); theta by x = sqrt(theta / pi), fine towards the radial direction.
constexpr int kBinsPerDecade = 12;
constexpr int kThetaBins = 128;
constexpr double kCoreRadius = 0.02;   // optical: the pooled core, J = f / R (section 11)
constexpr double kSwitchRadius = 1.0;  // log bins below, linear above
constexpr double kLinearBin = 0.2;
constexpr double kWeightFloor = 1.0e-3;
constexpr double kSurvival = 0.1;  // Russian roulette below the weight floor
// The far field (eq. 11.10): a bin of width kLinearBin holds J while its scores' relative
// standard error is below kFarNoise and it lies kFarBoundary diffusion lengths inside R_kill (the
// photons killed there take away the light that would come back: a bias of about
// e^{-2 kFarBoundary}); beyond it J follows the mode (eq. 11.11), its amplitude from the bins before.
constexpr double kFarNoise = 0.02;
constexpr double kFarBoundary = 2.6;
constexpr int kFarFitBins = 15;
constexpr double kFarFitLengths = 2.0;
constexpr double kFarFitStart = 3.0;  // transport mean free paths 1 / (1 - a g)
constexpr int kModeNodes = 64;        // Gauss-Legendre cosines per hemisphere for the mode's rate
constexpr int kBatchPhotons = 1024;   // a group of 8 batches between budget checks: an albedo-1 walk
constexpr int kGroupBatches = 8;      // of ~3000 collisions per photon overshoots the budget little

int theta_bin(double cos_theta, int nt) {
    const double theta = std::acos(std::clamp(cos_theta, -1.0, 1.0));
    return std::min(int(std::sqrt(theta / kPi) * nt), nt - 1);
}

// The bin-averaged azimuthal phase P[k][j] (incoming bin k, outgoing bin j),
// rows normalised so that sum_j P[k][j] Omega_j = 1 (section 11).
std::vector<double> phase_matrix(const PointSourcePhase& phase, int nt) {
    std::vector<double> cos_at(size_t(nt) * 8), weight_at(size_t(nt) * 8), omega(static_cast<size_t>(nt));
    for (int k = 0; k < nt; ++k) {
        const double x0 = double(k) / nt, x1 = double(k + 1) / nt;
        omega[size_t(k)] = 2.0 * kPi * (std::cos(kPi * x0 * x0) - std::cos(kPi * x1 * x1));
        double sum = 0.0;
        for (int n = 0; n < 8; ++n) {
            const double x = 0.5 * (x0 + x1) + 0.5 * (x1 - x0) * numerics::kGaussLegendre8Nodes[n];
            const double theta = kPi * x * x;
            cos_at[size_t(k) * 8 + size_t(n)] = std::cos(theta);
            const double w = numerics::kGaussLegendre8Weights[n] * std::sin(theta) * x;
            weight_at[size_t(k) * 8 + size_t(n)] = w;
            sum += w;
        }
        for (int n = 0; n < 8; ++n) weight_at[size_t(k) * 8 + size_t(n)] /= sum;
    }
    std::vector<double> p(size_t(nt) * size_t(nt));
    for (int k = 0; k < nt; ++k) {
        double norm = 0.0;
        for (int j = 0; j < nt; ++j) {
            double v = 0.0;
            for (int a = 0; a < 8; ++a)
                for (int b = 0; b < 8; ++b)
                    v += weight_at[size_t(k) * 8 + size_t(a)] * weight_at[size_t(j) * 8 + size_t(b)] *
                         azimuthal_phase(phase, cos_at[size_t(k) * 8 + size_t(a)], cos_at[size_t(j) * 8 + size_t(b)]);
            p[size_t(k) * size_t(nt) + size_t(j)] = v;
            norm += v * omega[size_t(j)];
        }
        for (int j = 0; j < nt; ++j) p[size_t(k) * size_t(nt) + size_t(j)] /= norm;
    }
    return p;
}

// The scores of one batch: collision weights by (channel, R bin, theta bin);
// the R bin nr is the core.
struct BatchScores {
    std::vector<double> h;   // [c][ir][it], ir in [0, nr]
    std::vector<double> h2;  // [c][ir]: the squared scores (the bins' noise, eq. 11.10)
    long photons = 0;
    double collisions = 0.0;
};

}  // namespace

double PointSourcePhase::mean_cosine() const {
    double g = 0.0;
    for (const Lobe& l : hg) g += l.weight * l.g;
    return g;
}

PointSourcePhase point_source_phase(const Phase& phase) {
    PointSourcePhase p;
    auto clamp_g = [](float g) { return double(std::clamp(g, -0.999f, 0.999f)); };
    switch (phase.type) {
        case PhaseType::isotropic:
            p.hg.push_back({0.0, 1.0});
            break;
        case PhaseType::hg:
            p.hg.push_back({clamp_g(phase.g), 1.0});
            break;
        case PhaseType::rayleigh:
            p.rayleigh_weight = 1.0;
            break;
        case PhaseType::hg2:
            if (phase.forward_weight > 0.0f) p.hg.push_back({clamp_g(phase.forward_g), double(phase.forward_weight)});
            if (phase.forward_weight < 1.0f)
                p.hg.push_back({clamp_g(phase.backward_g), 1.0 - double(phase.forward_weight)});
            break;
    }
    return p;
}

double azimuthal_phase(const PointSourcePhase& phase, double cos_i, double cos_o) {
    const double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
    const double sin_o = std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o));
    const double a = cos_i * cos_o, b = sin_i * sin_o;
    // Rayleigh 3 / (16 pi) (1 + mu^2): the azimuthal mean of mu^2 is a^2 + b^2 / 2.
    double value = phase.rayleigh_weight * 3.0 / (16.0 * kPi) * (1.0 + a * a + 0.5 * b * b);
    for (const auto& lobe : phase.hg) {
        const double g = lobe.g;
        if (g == 0.0) {
            value += lobe.weight / (4.0 * kPi);
            continue;
        }
        // (1 / 2 pi) int (1 - g^2) / (4 pi) (A - B cos phi)^{-3/2} dphi
        //   = (1 - g^2) / (4 pi) (2 / pi) E(m) / ((A - B) sqrt(A + B)),  m = 2B / (A + B) (section 11).
        const double A = 1.0 + g * g - 2.0 * g * a, B = 2.0 * std::abs(g) * b;
        const double m = std::clamp(2.0 * B / (A + B), 0.0, 1.0);
        const double e = std::comp_ellint_2(std::sqrt(m));
        value += lobe.weight * (1.0 - g * g) / (4.0 * kPi) * (2.0 / kPi) * e / ((A - B) * std::sqrt(A + B));
    }
    return value;
}

double diffusion_mode_rate(const PointSourcePhase& phase, double albedo) {
    if (!(albedo > 0.0)) return 1.0;
    if (albedo >= 1.0) return 0.0;
    // Cosines mu_i on (-1, 1) with weights w_i; K_ij = 4 pi pbar(mu_i, mu_j), rows normalised so
    // that (1/2) sum_j K_ij w_j = 1 (the scattering conserves energy on the nodes, as eq. 11.2's P).
    std::vector<double> half_nodes, half_weights;
    gauss_legendre_unit(kModeNodes, half_nodes, half_weights);
    const int n = 2 * kModeNodes;
    std::vector<double> mu(static_cast<size_t>(n)), w(static_cast<size_t>(n));
    for (int i = 0; i < kModeNodes; ++i) {
        mu[size_t(kModeNodes - 1 - i)] = -half_nodes[size_t(i)];
        mu[size_t(kModeNodes + i)] = half_nodes[size_t(i)];
        w[size_t(kModeNodes - 1 - i)] = w[size_t(kModeNodes + i)] = half_weights[size_t(i)];
    }
    std::vector<double> kw(size_t(n) * size_t(n));  // (a / 2) K_ij w_j
    for (int i = 0; i < n; ++i) {
        double norm = 0.0;
        for (int j = 0; j < n; ++j) {
            const double v = 4.0 * kPi * azimuthal_phase(phase, mu[size_t(i)], mu[size_t(j)]) * w[size_t(j)];
            kw[size_t(i) * size_t(n) + size_t(j)] = v;
            norm += 0.5 * v;
        }
        for (int j = 0; j < n; ++j) kw[size_t(i) * size_t(n) + size_t(j)] *= 0.5 * albedo / norm;
    }
    // Whether the Perron root of B(kappa) = diag(1 / (1 - kappa mu_i)) (a / 2) K W exceeds 1, by
    // power iteration from the last vector until the Collatz-Wielandt bounds min_i and max_i of
    // (B v)_i / v_i lie on one side of 1 (the root only grows with kappa).
    std::vector<double> v(static_cast<size_t>(n), 1.0), bv(static_cast<size_t>(n));
    auto root_above_one = [&](double kappa) {
        for (int iteration = 0; iteration < 2000; ++iteration) {
            double lo = std::numeric_limits<double>::infinity(), hi = 0.0, sum = 0.0;
            for (int i = 0; i < n; ++i) {
                double x = 0.0;
                for (int j = 0; j < n; ++j) x += kw[size_t(i) * size_t(n) + size_t(j)] * v[size_t(j)];
                x /= 1.0 - kappa * mu[size_t(i)];
                lo = std::min(lo, x / v[size_t(i)]);
                hi = std::max(hi, x / v[size_t(i)]);
                bv[size_t(i)] = x;
                sum += x;
            }
            for (int i = 0; i < n; ++i) v[size_t(i)] = bv[size_t(i)] / sum;
            if (lo > 1.0) return true;
            if (hi < 1.0) return false;
            if (hi - lo < 1e-13) return 0.5 * (lo + hi) > 1.0;
        }
        return false;
    };
    if (!root_above_one(1.0 - 1e-9)) return 1.0;  // the mode lies closer to 1 than the nodes resolve
    double lo = 0.0, hi = 1.0 - 1e-9;
    for (int step = 0; step < 60 && hi - lo > 1e-13; ++step) {
        const double mid = 0.5 * (lo + hi);
        (root_above_one(mid) ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
}

PointSourceField point_source_field(const PointSourcePhase& phase, const std::array<double, 3>& albedo,
                                    const PointSourceSettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    PointSourceField f;
    const int nt = kThetaBins;
    const double a_max = std::max({albedo[0], albedo[1], albedo[2]});
    // The diffusion length of the most scattering channel (section 12): the
    // light beyond 25 of them is below e^{-25} of the lamp's; capped at 80.
    const double g_mean = phase.mean_cosine();
    const double absorb = std::max(3.0 * (1.0 - a_max) * (1.0 - a_max * g_mean), 0.0);
    const double diffusion = absorb > 0.0 ? 1.0 / std::sqrt(absorb) : 1e30;
    f.r_kill = std::min(80.0, 5.0 + 25.0 * diffusion);
    f.r_core = kCoreRadius;
    f.dlog_r = std::log(10.0) / kBinsPerDecade;
    f.n_log = int(std::ceil(std::log(kSwitchRadius / f.r_core) / f.dlog_r));
    f.r_switch = f.r_core * std::exp(f.n_log * f.dlog_r);
    f.dr = kLinearBin;
    f.nr = f.n_log + int(std::ceil((f.r_kill - f.r_switch) / f.dr));
    f.nt = nt;
    const int nr = f.nr;
    const size_t plane = size_t(nr + 1) * size_t(nt);
    const double r_kill2 = f.r_kill * f.r_kill, r_core2 = f.r_core * f.r_core;

    auto run_batch = [&](uint64_t batch, BatchScores& out) {
        out.h.assign(3 * plane, 0.0);
        out.h2.assign(3 * size_t(nr + 1), 0.0);
        out.photons = 0;
        out.collisions = 0.0;
        Rng rng(settings.seed, batch);
        for (int p = 0; p < kBatchPhotons; ++p) {
            const double mu0 = 2.0 * rng.uniform() - 1.0, phi0 = 2.0 * kPi * rng.uniform();
            const double st0 = std::sqrt(std::max(0.0, 1.0 - mu0 * mu0));
            Vec dir{st0 * std::cos(phi0), st0 * std::sin(phi0), mu0};
            Vec pos{0.0, 0.0, 0.0};
            double w[3] = {1.0, 1.0, 1.0};
            bool scattered = false;
            long count = 0;
            for (;;) {
                const double s = -std::log(1.0 - rng.uniform());
                pos = {pos.x + s * dir.x, pos.y + s * dir.y, pos.z + s * dir.z};
                const double r2 = pos.x * pos.x + pos.y * pos.y + pos.z * pos.z;
                if (r2 > r_kill2) break;
                ++count;
                if (scattered) {
                    // A collision of light already scattered: its in-scattering
                    // is of order >= 2 (section 11): score albedo x weight.
                    const double r = std::sqrt(r2);
                    const double mu = (dir.x * pos.x + dir.y * pos.y + dir.z * pos.z) / r;
                    const int ir = r2 < r_core2 ? nr : std::min(int(f.bin_coordinate(r)), nr - 1);
                    const size_t cell = size_t(ir) * size_t(nt) + size_t(theta_bin(mu, nt));
                    for (int c = 0; c < 3; ++c) {
                        const double score = w[c] * albedo[size_t(c)];
                        out.h[size_t(c) * plane + cell] += score;
                        out.h2[size_t(c) * size_t(nr + 1) + size_t(ir)] += score * score;
                    }
                }
                for (int c = 0; c < 3; ++c) w[c] *= albedo[size_t(c)];
                scattered = true;
                const double wmax = std::max({w[0], w[1], w[2]});
                if (wmax <= 0.0) break;
                if (wmax < kWeightFloor) {
                    if (rng.uniform() >= kSurvival) break;
                    for (double& v : w) v /= kSurvival;
                }
                const double mu = sample_cos(phase, rng);
                dir = scatter(dir, mu, 2.0 * kPi * rng.uniform());
            }
            out.photons += 1;
            out.collisions += double(count);
        }
    };

    std::vector<double> h(3 * plane, 0.0), h2(3 * size_t(nr + 1), 0.0);
    std::vector<BatchScores> group(kGroupBatches);
    uint64_t next_batch = 0;
    while (f.collisions < settings.collision_budget && f.photons < settings.max_photons) {
        numerics::parallel_for(
            kGroupBatches, [&](int i) { run_batch(next_batch + uint64_t(i), group[size_t(i)]); }, settings.threads);
        next_batch += kGroupBatches;
        for (const BatchScores& b : group) {  // in batch order: the sums do not depend on the schedule
            for (size_t i = 0; i < h.size(); ++i) h[i] += b.h[i];
            for (size_t i = 0; i < h2.size(); ++i) h2[i] += b.h2[i];
            f.photons += b.photons;
            f.collisions += b.collisions;
        }
    }

    // J = (4 pi / (N V)) sum_k H_k P_kj (section 11); the core: f = R J.
    const std::vector<double> pm = phase_matrix(phase, nt);
    const double per_photon = 4.0 * kPi / double(f.photons);
    for (int c = 0; c < 3; ++c) {
        f.source[size_t(c)].assign(size_t(nr) * size_t(nt), 0.0);
        f.core[size_t(c)].assign(size_t(nt), 0.0);
        for (int ir = 0; ir <= nr; ++ir) {
            double scale;
            if (ir == nr) {
                scale = per_photon / (2.0 * kPi * r_core2);
            } else {
                const double r0 = f.bin_edge(ir), r1 = f.bin_edge(ir + 1);
                scale = per_photon / (4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0));
            }
            const double* hk = &h[size_t(c) * plane + size_t(ir) * size_t(nt)];
            double* out = ir == nr ? f.core[size_t(c)].data() : &f.source[size_t(c)][size_t(ir) * size_t(nt)];
            for (int j = 0; j < nt; ++j) {
                double v = 0.0;
                for (int k = 0; k < nt; ++k) v += hk[k] * pm[size_t(k) * size_t(nt) + size_t(j)];
                out[j] = v * scale;
            }
        }
    }
    // The far field (eq. 11.10), per channel: the last bin that holds J, the mode's rate kappa_0
    // (eq. 11.11), and J at r_far as the mean of the bins' J carried to r_far along the mode, over
    // the kFarFitLengths diffusion lengths before it (at least kFarFitBins bins; none nearer the
    // lamp than kFarFitStart transport mean free paths or r_far / 2, where the mode may not yet
    // hold), weighted by the bins' inverse variances.
    for (int c = 0; c < 3; ++c) {
        f.r_far[size_t(c)] = f.r_kill;
        f.far_profile[size_t(c)].assign(size_t(nt), 0.0);
        const double a = albedo[size_t(c)];
        const double ac = std::max(3.0 * (1.0 - a) * (1.0 - a * g_mean), 0.0);
        if (!(ac > 0.0)) continue;
        const double length = 1.0 / std::sqrt(ac);  // the channel's diffusion length
        const double r_limit = f.r_kill - kFarBoundary * length;
        std::vector<double> weight(size_t(nr), 0.0);
        int end = f.n_log;
        for (; end < nr; ++end) {
            double sum = 0.0;
            for (int j = 0; j < nt; ++j) sum += h[size_t(c) * plane + size_t(end) * size_t(nt) + size_t(j)];
            const double noise = sum > 0.0 ? std::sqrt(h2[size_t(c) * size_t(nr + 1) + size_t(end)]) / sum : 1.0;
            if (noise > kFarNoise || f.bin_edge(end + 1) > r_limit) break;
            weight[size_t(end)] = 1.0 / std::max(noise * noise, 1e-12);
        }
        const double transport = 1.0 / (1.0 - a * g_mean);  // the transport mean free path
        const int first = int(std::ceil(f.bin_coordinate(kFarFitStart * transport)));
        const int span = std::max(kFarFitBins, int(std::lround(kFarFitLengths * length / f.dr)));
        const int begin = std::max({end - span, first, int(std::ceil(f.bin_coordinate(0.5 * f.bin_edge(end))))});
        if (end >= nr || end - begin < kFarFitBins) continue;  // J held to R_kill, or too few bins
        const double kappa =
            c > 0 && a == albedo[size_t(c - 1)] ? f.kappa[size_t(c - 1)] : diffusion_mode_rate(phase, a);
        const double r_far = f.bin_edge(end);
        double total = 0.0;
        for (int i = begin; i < end; ++i) total += weight[size_t(i)];
        for (int i = begin; i < end; ++i) {
            const double r = 0.5 * (f.bin_edge(i) + f.bin_edge(i + 1));
            const double carry = weight[size_t(i)] / total * r / r_far * std::exp(kappa * (r - r_far));
            for (int j = 0; j < nt; ++j)
                f.far_profile[size_t(c)][size_t(j)] += carry * f.source[size_t(c)][size_t(i) * size_t(nt) + size_t(j)];
        }
        f.r_far[size_t(c)] = r_far;
        f.kappa[size_t(c)] = kappa;
    }
    for (int c = 0; c < 3; ++c) {
        f.log_source[size_t(c)].resize(f.source[size_t(c)].size());
        for (size_t i = 0; i < f.source[size_t(c)].size(); ++i) {
            const double v = f.source[size_t(c)][i];
            f.log_source[size_t(c)][i] = v > 0.0 ? std::log(v) : -std::numeric_limits<double>::infinity();
        }
    }
    f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return f;
}

double PointSourceField::bin_coordinate(double r) const {
    return r < r_switch ? std::log(r / r_core) / dlog_r : n_log + (r - r_switch) / dr;
}

double PointSourceField::bin_edge(int i) const {
    return i <= n_log ? r_core * std::exp(i * dlog_r) : r_switch + (i - n_log) * dr;
}

double PointSourceField::reach() const {
    for (int c = 0; c < 3; ++c)
        if (r_far[size_t(c)] < r_kill) return std::numeric_limits<double>::infinity();
    return r_kill;
}

double PointSourceField::at(int c, double r, double cos_theta) const {
    const double theta = std::acos(std::clamp(cos_theta, -1.0, 1.0));
    const double ft = std::clamp(std::sqrt(theta / kPi) * nt - 0.5, 0.0, double(nt - 1));
    const int j0 = std::min(int(ft), nt - 2);
    const double wt = ft - j0;
    const double rf = r_far[size_t(c)];
    if (r > rf && rf < r_kill) {  // the diffusion mode (eq. 11.10)
        const std::vector<double>& p = far_profile[size_t(c)];
        return (p[size_t(j0)] * (1.0 - wt) + p[size_t(j0 + 1)] * wt) * rf / r * std::exp(-kappa[size_t(c)] * (r - rf));
    }
    if (r >= r_kill) return 0.0;
    if (r < r_core) {
        const std::vector<double>& k = core[size_t(c)];
        return (k[size_t(j0)] * (1.0 - wt) + k[size_t(j0 + 1)] * wt) / r;
    }
    const double fr = std::clamp(bin_coordinate(r) - 0.5, 0.0, double(nr - 1));
    const int i0 = std::min(int(fr), nr - 2);
    const double ar = fr - i0;
    const double* s0 = &source[size_t(c)][size_t(i0) * size_t(nt)];
    const double* s1 = s0 + nt;
    const double* l0 = &log_source[size_t(c)][size_t(i0) * size_t(nt)];
    const double* l1 = l0 + nt;
    const double m = std::min({l0[j0], l0[j0 + 1], l1[j0], l1[j0 + 1]});
    if (m > -std::numeric_limits<double>::infinity()) {
        // Geometric interpolation: J is close to exponential in R and in theta (section 11).
        const double lo = l0[j0] * (1.0 - wt) + l0[j0 + 1] * wt, hi = l1[j0] * (1.0 - wt) + l1[j0 + 1] * wt;
        return std::exp(lo * (1.0 - ar) + hi * ar);
    }
    const double v00 = s0[j0], v01 = s0[j0 + 1], v10 = s1[j0], v11 = s1[j0 + 1];
    const double lo = v00 * (1.0 - wt) + v01 * wt, hi = v10 * (1.0 - wt) + v11 * wt;
    return lo * (1.0 - ar) + hi * ar;
}

std::array<double, 3> point_source_radiance(const PointSourceField& field, double tau, double gamma) {
    // The view ray from the point at tau: s = b + h sinh u, R = h cosh u,
    // cos theta = -tanh u (section 11); midpoint rule in u, steps du <= 0.04
    // (theta and log R change by less) and ds <= 0.15 (e^{-s} by 15 %: 0.1 % error).
    const double b = tau * std::cos(gamma), h = std::max(tau * std::sin(gamma), tau * 1e-9);
    const double s_end = std::max(b, 0.0) + 60.0, reach = field.reach();
    std::array<double, 3> sum = {0.0, 0.0, 0.0};
    double u = std::asinh(-b / h);
    for (int step = 0; step < 200000; ++step) {
        const double r_here = h * std::cosh(u);
        const double du = std::min(0.04, 0.15 / r_here);
        const double um = u + 0.5 * du;
        const double s = b + h * std::sinh(um), r = h * std::cosh(um);
        if (s > s_end || (r > reach && s > b)) break;
        const double weight = std::exp(-s) * r * du, cos_theta = -std::tanh(um);
        for (int c = 0; c < 3; ++c) sum[size_t(c)] += weight * field.at(c, r, cos_theta);
        u += du;
    }
    return sum;
}

double hemisphere_kernel(double beta, double gamma) {
    // a + b cos phi with b >= 0: positive for every phi, for none, or for |phi| < phi0 = acos(-a / b),
    // where the integral is 2 (a phi0 + b sin phi0) (section 13, eq. 13.3).
    const double a = std::cos(beta) * std::cos(gamma), b = std::abs(std::sin(beta) * std::sin(gamma));
    if (b <= std::abs(a)) return a > 0.0 ? 2.0 * kPi * a : 0.0;
    const double c = -a / b, phi0 = std::acos(c);
    return 2.0 * (a * phi0 + b * std::sqrt(std::max(0.0, 1.0 - c * c)));
}

namespace {

// The angle gamma of the glow rows' coordinate Y (the inverse of lamp_ms_y, without the first
// row's clamp) and d gamma / dY.
double gamma_of_y(double Y) {
    const double c = std::log(1.0 + kPi / double(shader::LAMP_MS_GAMMA0));
    return double(shader::LAMP_MS_GAMMA0) * std::expm1(c * Y);
}
double dgamma_dy(double Y) {
    const double c = std::log(1.0 + kPi / double(shader::LAMP_MS_GAMMA0));
    return c * (double(shader::LAMP_MS_GAMMA0) + gamma_of_y(Y));
}

// Sub-steps of the surface rows' quadrature per interval of the glow rows (section 13).
constexpr int kSurfaceSubsteps = 16;

}  // namespace

std::vector<std::array<double, 3>> point_source_irradiance(const PointSourceField& field, double tau,
                                                           const std::vector<double>& betas, int steps) {
    // Midpoint rule in the glow rows' coordinate Y (fine near the lamp's direction, where L grows
    // as log 1 / gamma), L from the line integral (11.4) at every point.
    std::vector<std::array<double, 3>> out(betas.size(), {0.0, 0.0, 0.0});
    for (int k = 0; k < steps; ++k) {
        const double Y = (k + 0.5) / steps, gamma = gamma_of_y(Y);
        const std::array<double, 3> l = point_source_radiance(field, tau, gamma);
        const double w = std::sin(gamma) * dgamma_dy(Y) / steps;
        for (size_t i = 0; i < betas.size(); ++i) {
            const double kw = w * hemisphere_kernel(betas[i], gamma);
            for (int c = 0; c < 3; ++c) out[i][size_t(c)] += kw * l[size_t(c)];
        }
    }
    return out;
}

Table2D build_lamp_ms_table(const PointSourcePhase& phase, const std::array<double, 3>& albedo,
                            const PointSourceSettings& settings) {
    using namespace shader;
    const PointSourceField field = point_source_field(phase, albedo, settings);
    Table2D t;
    t.width = LAMP_MS_NX;
    t.height = LAMP_MS_NY + LAMP_MS_NB;
    t.channels = 4;
    t.texels.assign(size_t(t.width) * size_t(t.height) * 4, 0.0f);
    const double tau_min = double(LAMP_MS_TAU_MIN), tau_lin = double(LAMP_MS_TAU_LIN);
    const double w_max = std::log(double(LAMP_MS_TAU_MAX) / tau_min) + double(LAMP_MS_TAU_MAX) / tau_lin;
    // The inverse of lamp_ms_x: w(tau) = log(tau / tau_min) + tau / tau_lin by Newton's method.
    auto tau_at = [&](double X) {
        const double w = X * w_max;
        double tau = std::min(tau_min * std::exp(w), tau_lin * w);
        for (int k = 0; k < 60; ++k)
            tau =
                std::max(tau - (std::log(tau / tau_min) + tau / tau_lin - w) / (1.0 / tau + 1.0 / tau_lin), 0.5 * tau);
        return tau;
    };
    const double log_floor = double(LAMP_MS_LOG_FLOOR);
    const double log_gamma = std::log(1.0 + kPi / double(LAMP_MS_GAMMA0));
    std::vector<std::array<double, 3>> log_l(size_t(LAMP_MS_NX) * size_t(LAMP_MS_NY));
    numerics::parallel_for(
        LAMP_MS_NX * LAMP_MS_NY,
        [&](int i) {
            const int ix = i % t.width, iy = i / t.width;
            // The inverses of lamp_ms_x and lamp_ms_y (lamp_ms_math.glsl).
            const double tau = ix == 0 ? tau_min : tau_at(double(ix) / (t.width - 1));
            const double gamma = std::clamp(double(LAMP_MS_GAMMA0) * std::expm1(log_gamma * iy / (LAMP_MS_NY - 1)),
                                            double(LAMP_MS_GAMMA_MIN), kPi);
            const std::array<double, 3> l = point_source_radiance(field, tau, gamma);
            float* texel = &t.texels[size_t(i) * 4];
            for (int c = 0; c < 3; ++c) {
                log_l[size_t(i)][size_t(c)] = std::max(l[size_t(c)] > 0.0 ? std::log(l[size_t(c)]) : -1e30, log_floor);
                texel[c] = float(log_l[size_t(i)][size_t(c)]);
            }
            texel[3] = 0.0f;
        },
        settings.threads);
    // The surface rows (section 13): E(tau, beta) = int L sin gamma K(beta, gamma) dgamma over the
    // column's own rows, log L linear in Y between them as the shader reads it; kSurfaceSubsteps
    // midpoints per interval.
    constexpr int nsub = (LAMP_MS_NY - 1) * kSurfaceSubsteps;
    std::vector<double> sub_gamma(nsub), sub_weight(nsub);
    for (int k = 0; k < nsub; ++k) {
        const double Y = (k + 0.5) / nsub;
        sub_gamma[size_t(k)] = gamma_of_y(Y);
        sub_weight[size_t(k)] = std::sin(sub_gamma[size_t(k)]) * dgamma_dy(Y) / nsub;
    }
    std::vector<double> log_e(size_t(LAMP_MS_NX) * size_t(LAMP_MS_NB) * 3);
    numerics::parallel_for(
        LAMP_MS_NX * LAMP_MS_NB,
        [&](int i) {
            const int ix = i % LAMP_MS_NX, ib = i / LAMP_MS_NX;
            const double beta = kPi * ib / (LAMP_MS_NB - 1);
            double e[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < nsub; ++k) {
                const double kw = sub_weight[size_t(k)] * hemisphere_kernel(beta, sub_gamma[size_t(k)]);
                if (kw <= 0.0) continue;
                const int iy = k / kSurfaceSubsteps;
                const double a = ((k % kSurfaceSubsteps) + 0.5) / kSurfaceSubsteps;
                const auto& l0 = log_l[size_t(iy) * size_t(LAMP_MS_NX) + size_t(ix)];
                const auto& l1 = log_l[size_t(iy + 1) * size_t(LAMP_MS_NX) + size_t(ix)];
                for (int c = 0; c < 3; ++c)
                    if (l0[size_t(c)] > log_floor || l1[size_t(c)] > log_floor)
                        e[c] += kw * std::exp(l0[size_t(c)] * (1.0 - a) + l1[size_t(c)] * a);
            }
            for (int c = 0; c < 3; ++c)
                log_e[size_t(i) * 3 + size_t(c)] = e[c] > 0.0 ? std::max(std::log(e[c]), log_floor) : log_floor;
        },
        settings.threads);
    for (int ix = 0; ix < LAMP_MS_NX; ++ix) {
        double bound = log_floor;
        for (int ib = 0; ib < LAMP_MS_NB; ++ib)
            for (int c = 0; c < 3; ++c)
                bound = std::max(bound, log_e[(size_t(ib) * size_t(LAMP_MS_NX) + size_t(ix)) * 3 + size_t(c)]);
        for (int ib = 0; ib < LAMP_MS_NB; ++ib) {
            float* texel = &t.texels[(size_t(LAMP_MS_NY + ib) * size_t(t.width) + size_t(ix)) * 4];
            for (int c = 0; c < 3; ++c)
                texel[c] = float(log_e[(size_t(ib) * size_t(LAMP_MS_NX) + size_t(ix)) * 3 + size_t(c)]);
            texel[3] = float(bound);  // the culling bound (rounding is monotone: no row's float exceeds it)
        }
    }
    return t;
}

std::shared_ptr<const Table2D> lamp_ms_table(const PointSourcePhase& phase, const std::array<double, 3>& albedo) {
    static TableCache<std::string> cache(8);
    std::string key;
    char buf[160];
    for (const auto& l : phase.hg) {
        std::snprintf(buf, sizeof buf, "hg %.9g %.9g;", l.g, l.weight);
        key += buf;
    }
    std::snprintf(buf, sizeof buf, "ray %.9g; a %.9g %.9g %.9g", phase.rayleigh_weight, albedo[0], albedo[1],
                  albedo[2]);
    key += buf;
    return cache.get(key,
                     [&] { return timed_build("lamp_ms_glow", [&] { return build_lamp_ms_table(phase, albedo); }); });
}

}  // namespace airlight
