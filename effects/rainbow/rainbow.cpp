#include "rainbow.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <list>
#include <mutex>
#include <random>
#include <stdexcept>

#include "mie.hpp"
#include "numerics.hpp"

namespace airlight {

namespace {
using numerics::kPi;
constexpr double kDeg = kPi / 180.0;
}  // namespace

double rainbow_wavelength_nm(int i) { return 380.0 + 10.625 * double(i); }

double rainbow_rate(int k) { return 0.1 * std::ldexp(1.0, k); }

std::vector<double> rainbow_angles_deg() {
    // Every 0.05 degree where the phase changes within the sun's disc (the
    // forward aureole, the bows and the glory around the antisolar point),
    // 0.5 degree where it is smooth: interpolating the 0.5-degree nodes from
    // 1-degree ones is off by 0.2 % in the median and 3.6 % at worst there
    // (effects/rainbow/docs/rainbow_analysis.txt section 5), so about a quarter of that at
    // 0.5 degree; in the glory it was off by 52 %, hence the fine nodes.
    std::vector<double> a;
    auto fine = [&](double from, double to) {
        for (int i = int(std::lround(from / 0.05)); i * 0.05 <= to + 1e-9; ++i) a.push_back(i * 0.05);
    };
    auto coarse = [&](double from, double to) {
        for (int i = int(std::lround(from / 0.5)) + 1; i * 0.5 < to - 1e-9; ++i) a.push_back(i * 0.5);
    };
    fine(0.0, 3.0);
    coarse(3.0, 118.0);
    fine(118.0, 146.0);
    coarse(146.0, 178.0);
    fine(178.0, 180.0);
    return a;
}

double marshall_palmer_slope(double rate) { return 4.1 * std::pow(rate, -0.21); }

double water_refractive_index(double wavelength_nm) {
    // Quan & Fry (1995) with salinity S = 0 and temperature T = 20 C.
    const double t = 20.0, l = wavelength_nm;
    return 1.31405 - 2.02e-6 * t * t + (15.868 - 0.00423 * t) / l - 4382.0 / (l * l) + 1.1455e6 / (l * l * l);
}

namespace {

// Differential scattering cross-section dC/dOmega = (|S1|^2 + |S2|^2) / (2 k^2)
// (mm^2 / sr, unpolarised light) at the angles, and C_sca (mm^2) of one drop.
void drop_scattering(double diameter_mm, double wavelength_nm, const std::vector<double>& theta,
                     std::vector<double>& dc_domega, double& c_sca) {
    const double m = water_refractive_index(wavelength_nm);
    const double lambda_mm = wavelength_nm * 1e-6;
    const double x = kPi * diameter_mm / lambda_mm;
    const MieCoefficients c = mie_coefficients({m, 0.0}, x);
    const double k = 2.0 * kPi / lambda_mm;
    c_sca = mie_efficiencies(c).scattering * kPi * diameter_mm * diameter_mm / 4.0;
    std::vector<std::complex<double>> s1, s2;
    mie_amplitudes(c, theta, s1, s2);
    dc_domega.resize(theta.size());
    for (size_t a = 0; a < theta.size(); ++a) dc_domega[a] = (std::norm(s1[a]) + std::norm(s2[a])) / (2.0 * k * k);
}

// Scattering angle (radians) between a view at angle theta from the sun's
// centre and a point of the disc at angular radius r and azimuth phi.
double angle_to_disc_point(double theta, double r, double phi) {
    const double c = std::cos(theta) * std::cos(r) + std::sin(theta) * std::sin(r) * std::cos(phi);
    return std::acos(std::clamp(c, -1.0, 1.0));
}

// The proposal density of drop diameters: the mixture, over the table's
// rates, of D^2 exp(-Lambda D) on [D_MIN, D_MAX] (each normalised), tabulated
// with its cumulative distribution for inversion.
struct SizeProposal {
    std::vector<double> d, pdf, cdf;
    SizeProposal() {
        const int n = 20001;
        d.resize(n);
        pdf.assign(n, 0.0);
        for (int i = 0; i < n; ++i)
            d[size_t(i)] = RAINDROP_D_MIN_MM + (RAINDROP_D_MAX_MM - RAINDROP_D_MIN_MM) * i / (n - 1);
        const double h = d[1] - d[0];
        for (int k = 0; k < RAINBOW_RATES; ++k) {
            const double lam = marshall_palmer_slope(rainbow_rate(k));
            std::vector<double> g(n);
            double total = 0.0;
            for (int i = 0; i < n; ++i) {
                g[size_t(i)] = d[size_t(i)] * d[size_t(i)] * std::exp(-lam * d[size_t(i)]);
                total += (i == 0 || i == n - 1 ? 0.5 : 1.0) * g[size_t(i)] * h;
            }
            for (int i = 0; i < n; ++i) pdf[size_t(i)] += g[size_t(i)] / total / RAINBOW_RATES;
        }
        cdf.assign(n, 0.0);
        for (int i = 1; i < n; ++i)
            cdf[size_t(i)] = cdf[size_t(i) - 1] + 0.5 * (pdf[size_t(i)] + pdf[size_t(i) - 1]) * h;
        for (double& c : cdf) c /= cdf.back();
    }
    // Diameter at cumulative probability u, and the density there.
    void sample(double u, double& diameter, double& density) const {
        const size_t i = size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
        const size_t hi = std::clamp<size_t>(i, 1, cdf.size() - 1), lo = hi - 1;
        const double t = cdf[hi] > cdf[lo] ? (u - cdf[lo]) / (cdf[hi] - cdf[lo]) : 0.0;
        diameter = d[lo] + t * (d[hi] - d[lo]);
        density = pdf[lo] + t * (pdf[hi] - pdf[lo]);
    }
};

}  // namespace

RainbowSpectralTable compute_rainbow_spectral_table(const RainbowSampling& sampling) {
    if (sampling.samples_per_wavelength < 64) throw std::invalid_argument("rainbow table: need at least 64 samples");
    RainbowSpectralTable table;
    std::vector<int> wavelengths = sampling.wavelengths;
    if (wavelengths.empty())
        for (int i = 0; i < RAINBOW_WAVELENGTHS; ++i) wavelengths.push_back(i);
    for (int i : wavelengths) table.wavelengths_nm.push_back(rainbow_wavelength_nm(i));
    for (int k = 0; k < RAINBOW_RATES; ++k) table.rates.push_back(rainbow_rate(k));
    for (double a : rainbow_angles_deg())
        if (a >= sampling.angle_min_deg && a <= sampling.angle_max_deg) table.angles_deg.push_back(a);
    if (table.angles_deg.empty()) throw std::invalid_argument("rainbow table: no angle in the requested range");
    table.samples_per_wavelength = sampling.samples_per_wavelength;
    const size_t nw = wavelengths.size(), nr = table.rates.size(), na = table.angles_deg.size();
    table.phase.assign(nr * nw * na, 0.0f);
    table.rel_error.assign(nr * nw * na, 0.0f);

    const SizeProposal proposal;
    const int n_samples = sampling.samples_per_wavelength;
    constexpr int kBatches = 16;  // batch means for the standard error
    // Samples handed out one at a time to the workers, each with its own partial sums.
    const size_t workers = size_t(numerics::worker_count(n_samples, sampling.threads));
    std::vector<double> theta(na);
    for (size_t a = 0; a < na; ++a) theta[a] = table.angles_deg[a] * kDeg;
    const double rho = SUN_ANGULAR_RADIUS_DEG * kDeg;

    for (size_t wi = 0; wi < nw; ++wi) {
        const double wavelength = table.wavelengths_nm[wi];
        // Latin hypercube over (size, disc radius^2, disc azimuth): each
        // coordinate stratified into n_samples strata.
        std::mt19937_64 rng(sampling.seed * 1000003u + uint64_t(wavelengths[wi]));
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        std::vector<int> perm_r(static_cast<size_t>(n_samples)), perm_phi(static_cast<size_t>(n_samples));
        for (int j = 0; j < n_samples; ++j) perm_r[size_t(j)] = perm_phi[size_t(j)] = j;
        std::shuffle(perm_r.begin(), perm_r.end(), rng);
        std::shuffle(perm_phi.begin(), perm_phi.end(), rng);
        struct Sample {
            double diameter, density, r, phi;
        };
        std::vector<Sample> samples(static_cast<size_t>(n_samples));
        for (int j = 0; j < n_samples; ++j) {
            Sample& s = samples[size_t(j)];
            proposal.sample((j + uniform(rng)) / n_samples, s.diameter, s.density);
            s.r = rho * std::sqrt((perm_r[size_t(j)] + uniform(rng)) / n_samples);
            s.phi = 2.0 * kPi * (perm_phi[size_t(j)] + uniform(rng)) / n_samples;
        }
        // Largest drops first, so that the threads finish together.
        std::vector<int> order(static_cast<size_t>(n_samples));
        for (int j = 0; j < n_samples; ++j) order[size_t(j)] = n_samples - 1 - j;

        // Per worker: numerators [batch][rate][angle] and denominators [batch][rate], and scratch.
        std::vector<std::vector<double>> num(workers, std::vector<double>(kBatches * nr * na, 0.0));
        std::vector<std::vector<double>> den(workers, std::vector<double>(kBatches * nr, 0.0));
        std::vector<std::vector<double>> shifted_of(workers, std::vector<double>(na)), dc_of(workers);
        const auto add_sample = [&](int idx, int t) {
            std::vector<double>& shifted = shifted_of[size_t(t)];
            std::vector<double>& dc = dc_of[size_t(t)];
            const int j = order[size_t(idx)];
            const Sample& s = samples[size_t(j)];
            for (size_t a = 0; a < na; ++a) shifted[a] = angle_to_disc_point(theta[a], s.r, s.phi);
            double c_sca = 0.0;
            drop_scattering(s.diameter, wavelength, shifted, dc, c_sca);
            const size_t b = size_t(j % kBatches);
            for (size_t k = 0; k < nr; ++k) {
                // Marshall-Palmer number density (N0 cancels) over the proposal.
                const double w = std::exp(-marshall_palmer_slope(table.rates[k]) * s.diameter) / s.density;
                den[size_t(t)][b * nr + k] += w * c_sca;
                double* row = &num[size_t(t)][(b * nr + k) * na];
                for (size_t a = 0; a < na; ++a) row[a] += w * dc[a];
            }
        };
        numerics::parallel_for_worker(n_samples, add_sample, int(workers));

        for (size_t k = 0; k < nr; ++k) {
            double den_all = 0.0;
            std::vector<double> den_b(kBatches, 0.0);
            for (size_t t = 0; t < workers; ++t)
                for (int b = 0; b < kBatches; ++b) den_b[size_t(b)] += den[t][size_t(b) * nr + k];
            for (double v : den_b) den_all += v;
            for (size_t a = 0; a < na; ++a) {
                double num_all = 0.0;
                double batch[kBatches];
                for (int b = 0; b < kBatches; ++b) {
                    double v = 0.0;
                    for (size_t t = 0; t < workers; ++t) v += num[t][(size_t(b) * nr + k) * na + a];
                    num_all += v;
                    batch[b] = v / den_b[size_t(b)];
                }
                const double p = num_all / den_all;
                double var = 0.0;
                for (double v : batch) var += (v - p) * (v - p);
                const double se = std::sqrt(var / (kBatches * (kBatches - 1.0)));
                table.phase[(k * nw + wi) * na + a] = float(p);
                table.rel_error[(k * nw + wi) * na + a] = float(p > 0.0 ? se / p : 0.0);
            }
        }
    }
    normalise_rainbow_aureole(table);
    return table;
}

void normalise_rainbow_aureole(RainbowSpectralTable& table) {
    // The sampled phase integrates to 1 only in expectation; nearly all of the
    // noise in that integral comes from the diffraction peak within 0.3
    // degree, where a few large drops carry everything (standard errors up to
    // 40 % per angle), while the rest of the sphere (about half of the light)
    // is known to 0.3 %. So the aureole is rescaled: weight w = 1 up to 0.5
    // degree, falling linearly to 0 at 1 degree, and P -> P (1 + c w) with c
    // chosen so that the trapezoid integral over the table's grid is 1.
    const size_t nw = table.wavelengths_nm.size(), na = table.angles_deg.size();
    // Only a table of the whole sphere can be normalised (a part computed
    // for refining a table is, once merged into it).
    if (na < 2 || table.angles_deg.front() != 0.0 || table.angles_deg.back() != 180.0) return;
    std::vector<double> theta(na), weight(na);
    for (size_t a = 0; a < na; ++a) {
        theta[a] = table.angles_deg[a] * kPi / 180.0;
        weight[a] = std::clamp((1.0 - table.angles_deg[a]) / 0.5, 0.0, 1.0);
    }
    auto integral = [&](const float* p, bool weighted) {
        double sum = 0.0;
        for (size_t a = 0; a + 1 < na; ++a) {
            auto f = [&](size_t i) { return 2.0 * kPi * p[i] * std::sin(theta[i]) * (weighted ? weight[i] : 1.0); };
            sum += 0.5 * (f(a) + f(a + 1)) * (theta[a + 1] - theta[a]);
        }
        return sum;
    };
    for (size_t row = 0; row < table.rates.size() * nw; ++row) {
        float* p = table.phase.data() + row * na;
        const double c = (1.0 - integral(p, false)) / integral(p, true);
        for (size_t a = 0; a < na; ++a) p[a] = float(p[a] * (1.0 + c * weight[a]));
    }
}

std::vector<double> mie_sun_disc_phase(double refractive_index, double diameter_mm, double wavelength_nm,
                                       const std::vector<double>& angles_deg, int n_radial) {
    // Midpoint rule in r^2 (uniform over the disc's area) and in azimuth.
    const double rho = SUN_ANGULAR_RADIUS_DEG * kDeg;
    const int n_phi = 4 * n_radial;
    const double lambda_mm = wavelength_nm * 1e-6;
    const double x = kPi * diameter_mm / lambda_mm;
    const MieCoefficients c = mie_coefficients({refractive_index, 0.0}, x);
    const double norm = 2.0 * kPi * x * x * mie_efficiencies(c).scattering;
    std::vector<double> theta;
    theta.reserve(angles_deg.size() * size_t(n_radial * n_phi));
    for (double a : angles_deg)
        for (int i = 0; i < n_radial; ++i)
            for (int j = 0; j < n_phi; ++j)
                theta.push_back(angle_to_disc_point(a * kDeg, rho * std::sqrt((i + 0.5) / n_radial),
                                                    2.0 * kPi * (j + 0.5) / n_phi));
    std::vector<std::complex<double>> s1, s2;
    mie_amplitudes(c, theta, s1, s2);
    std::vector<double> p(angles_deg.size(), 0.0);
    const size_t per = size_t(n_radial * n_phi);
    for (size_t a = 0; a < angles_deg.size(); ++a) {
        for (size_t q = 0; q < per; ++q) p[a] += std::norm(s1[a * per + q]) + std::norm(s2[a * per + q]);
        p[a] /= norm * double(per);
    }
    return p;
}

std::vector<double> mie_size_average_phase(const DropSizes& sizes, double wavelength_nm,
                                           const std::vector<double>& angles_deg, int n_sizes) {
    // Midpoint rule in log D over [d_min, d_max] with the weight
    // N(D) dD = N0 exp(-slope D) D dlnD (N0 cancels in the ratio); the sizes
    // are shared out between threads, each with its own sums.
    const double slope = sizes.slope_per_mm;
    const double lo = std::log(sizes.d_min_mm), hi = std::log(sizes.d_max_mm);
    std::vector<double> theta(angles_deg.size());
    for (size_t a = 0; a < theta.size(); ++a) theta[a] = angles_deg[a] * kDeg;
    const size_t workers = size_t(numerics::worker_count(n_sizes));
    std::vector<std::vector<double>> num(workers, std::vector<double>(theta.size(), 0.0));
    std::vector<double> den(workers, 0.0);
    std::vector<std::vector<double>> dc_of(workers);
    const auto add_size = [&](int i, int t) {
        std::vector<double>& dc = dc_of[size_t(t)];
        double c_sca = 0.0;
        const double d = std::exp(lo + (hi - lo) * (n_sizes - 1 - i + 0.5) / n_sizes);  // largest first
        const double weight = std::exp(-slope * d) * d;
        drop_scattering(d, wavelength_nm, theta, dc, c_sca);
        for (size_t a = 0; a < theta.size(); ++a) num[size_t(t)][a] += weight * dc[a];
        den[size_t(t)] += weight * c_sca;
    };
    numerics::parallel_for_worker(n_sizes, add_size, int(workers));
    std::vector<double> p(theta.size(), 0.0);
    double total = 0.0;
    for (size_t t = 0; t < workers; ++t) total += den[t];
    for (size_t t = 0; t < workers; ++t)
        for (size_t a = 0; a < theta.size(); ++a) p[a] += num[t][a] / total;
    return p;
}

// ---- File format (little-endian): "ALRBOW01", int32 counts (wavelengths,
// rates, angles, samples), float64 grids, float32 phase then rel_error.
namespace {
constexpr char kMagic[8] = {'A', 'L', 'R', 'B', 'O', 'W', '0', '1'};
template <class T>
void put(std::vector<char>& out, const T* v, size_t n) {
    const char* p = reinterpret_cast<const char*>(v);
    out.insert(out.end(), p, p + n * sizeof(T));
}
template <class T>
void get(const std::vector<char>& in, size_t& pos, T* v, size_t n) {
    if (pos + n * sizeof(T) > in.size()) throw std::runtime_error("rainbow table: file is truncated");
    std::memcpy(v, in.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
}
}  // namespace

std::vector<char> serialize_rainbow_table(const RainbowSpectralTable& t) {
    std::vector<char> out(kMagic, kMagic + 8);
    const int32_t counts[4] = {int32_t(t.wavelengths_nm.size()), int32_t(t.rates.size()), int32_t(t.angles_deg.size()),
                               int32_t(t.samples_per_wavelength)};
    put(out, counts, 4);
    put(out, t.wavelengths_nm.data(), t.wavelengths_nm.size());
    put(out, t.rates.data(), t.rates.size());
    put(out, t.angles_deg.data(), t.angles_deg.size());
    put(out, t.phase.data(), t.phase.size());
    put(out, t.rel_error.data(), t.rel_error.size());
    return out;
}

RainbowSpectralTable parse_rainbow_table(const std::vector<char>& in) {
    if (in.size() < 8 || std::memcmp(in.data(), kMagic, 8) != 0)
        throw std::runtime_error("rainbow table: not a rainbow phase table (bad magic)");
    size_t pos = 8;
    int32_t counts[4];
    get(in, pos, counts, 4);
    for (int32_t c : counts)
        if (c <= 0 || c > 1000000) throw std::runtime_error("rainbow table: bad grid size");
    RainbowSpectralTable t;
    t.wavelengths_nm.resize(size_t(counts[0]));
    t.rates.resize(size_t(counts[1]));
    t.angles_deg.resize(size_t(counts[2]));
    t.samples_per_wavelength = counts[3];
    get(in, pos, t.wavelengths_nm.data(), t.wavelengths_nm.size());
    get(in, pos, t.rates.data(), t.rates.size());
    get(in, pos, t.angles_deg.data(), t.angles_deg.size());
    const size_t n = t.wavelengths_nm.size() * t.rates.size() * t.angles_deg.size();
    t.phase.resize(n);
    t.rel_error.resize(n);
    get(in, pos, t.phase.data(), n);
    get(in, pos, t.rel_error.data(), n);
    if (pos != in.size()) throw std::runtime_error("rainbow table: trailing bytes");
    return t;
}

}  // namespace airlight
