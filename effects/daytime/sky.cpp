#include "sky.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "numerics.hpp"

namespace airlight {
namespace {

using numerics::kPi;

// CIE general sky (ISO 15469:2004 / CIE S 011/E:2003): six gradation groups
// (a, b) and six indicatrix groups (c, d, e) combined into the 15 types.
constexpr double kGradation[6][2] = {{4.0, -0.70},  {1.1, -0.8},   {0.0, -1.0},
                                     {-1.0, -0.55}, {-1.0, -0.32}, {-1.0, -0.15}};
constexpr double kIndicatrix[6][3] = {{0.0, -1.0, 0.0},   {2.0, -1.5, 0.15},  {5.0, -2.5, 0.30},
                                      {10.0, -3.0, 0.45}, {16.0, -3.0, 0.30}, {24.0, -2.8, 0.15}};
// Type t (1..15): {gradation group, indicatrix group}, 1-based.
constexpr int kTypeGroups[15][2] = {{1, 1}, {1, 2}, {2, 1}, {2, 2}, {3, 1}, {3, 2}, {3, 3}, {3, 4},
                                    {4, 2}, {4, 3}, {4, 4}, {5, 4}, {5, 5}, {6, 5}, {6, 6}};

}  // namespace

double rain_extinction(double rate) {
    if (!(rate > 0.0)) return 0.0;
    const double lambda = 4.1 * std::pow(rate, -0.21);  // per mm
    return kPi * MARSHALL_PALMER_N0 * 1e-6 / (lambda * lambda * lambda);
}

shader::SkyGpu make_sky_gpu(const Sky& sky, const Sun& sun) {
    shader::SkyGpu g{};
    const int model = sky.model == SkyModel::overcast ? shader::SKY_OVERCAST
                      : sky.model == SkyModel::cie    ? shader::SKY_CIE
                                                      : shader::SKY_NONE;
    g.zenith_radiance = glm::vec4(sky.zenith_radiance, float(model));
    const glm::dvec3 s = sun.present ? glm::normalize(glm::dvec3(sun.direction)) : glm::dvec3(0.0, 1.0, 0.0);
    g.sun_direction = glm::vec4(
        glm::vec3(s),
        sun.present && s.y > 0.0 && glm::any(glm::greaterThan(sun.irradiance, glm::vec3(0.0f))) ? 1.0f : 0.0f);
    g.sun_irradiance = glm::vec4(sun.present ? sun.irradiance : glm::vec3(0.0f), 0.0f);
    if (model == shader::SKY_CIE) {
        const int t = std::clamp(sky.cie_type, 1, 15) - 1;
        const double* ab = kGradation[kTypeGroups[t][0] - 1];
        const double* cde = kIndicatrix[kTypeGroups[t][1] - 1];
        // Normaliser 1 / (phi(0) f(Z_s)): L = Lz at the zenith.
        const double zs = std::acos(std::clamp(s.y, -1.0, 1.0));
        const double phi0 = 1.0 + ab[0] * std::exp(ab[1]);
        const double f_zs = 1.0 + cde[0] * (std::exp(cde[1] * zs) - std::exp(cde[1] * kPi / 2.0)) +
                            cde[2] * std::cos(zs) * std::cos(zs);
        g.gradation = glm::vec4(float(ab[0]), float(ab[1]), float(1.0 / (phi0 * f_zs)), 0.0f);
        g.indicatrix = glm::vec4(float(cde[0]), float(cde[1]), float(cde[2]), float(std::exp(cde[1] * kPi / 2.0)));
    }
    return g;
}

bool sky_has_azimuth(const shader::SkyGpu& sky) {
    return int(sky.zenith_radiance.w) == shader::SKY_CIE && (sky.indicatrix.x != 0.0f || sky.indicatrix.z != 0.0f);
}

void make_species_gpu(const Atmosphere& atm, shader::SpeciesGpu species[shader::SPECIES_COUNT]) {
    const float none = shader::NO_HIT;
    for (int i = 0; i < 3; ++i) {
        species[i] = shader::SpeciesGpu{};
        species[i].starts = glm::vec4(0.0f, none, none, none);
    }
    // Molecules: Rayleigh, exp(-y / 8 km).
    if (atm.molecules.present && atm.molecules.density_scale > 0.0f) {
        shader::SpeciesGpu& m = species[shader::SPECIES_MOLECULES];
        const glm::vec3 sigma =
            glm::vec3(float(RAYLEIGH_SIGMA_S0[0]), float(RAYLEIGH_SIGMA_S0[1]), float(RAYLEIGH_SIGMA_S0[2])) *
            atm.molecules.density_scale;
        m.sigma_t = m.sigma_s = glm::vec4(sigma, 0.0f);
        m.phase = glm::vec4(0.0f, 1.0f, 1.0f, 0.0f);
        m.values = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
        m.inv_scales = glm::vec4(float(1.0 / RAYLEIGH_SCALE_HEIGHT), 0.0f, 0.0f, 0.0f);
    }
    // Aerosol: grey, the seed's profile with its minimum and rise.
    if (atm.aerosol.present) {
        double ext = atm.aerosol.coefficient;
        if (atm.aerosol.visibility > 0.0f) {
            const double molecules =
                atm.molecules.present ? RAYLEIGH_SIGMA_S0[1] * double(atm.molecules.density_scale) : 0.0;
            ext = std::max(KOSCHMIEDER / double(atm.aerosol.visibility) - molecules, 0.0);
        }
        if (ext > 0.0) {
            shader::SpeciesGpu& a = species[shader::SPECIES_AEROSOL];
            const double h = atm.aerosol.scale_height;
            const double v1 = std::exp(-AEROSOL_MIN_ALTITUDE / h);
            a.sigma_t = glm::vec4(glm::vec3(float(ext)), 0.0f);
            a.sigma_s = glm::vec4(glm::vec3(float(ext * atm.aerosol.albedo)), 0.0f);
            a.phase = glm::vec4(atm.aerosol.g, 0.0f, 1.0f, 0.0f);
            a.starts = glm::vec4(0.0f, float(AEROSOL_MIN_ALTITUDE), float(AEROSOL_MAX_ALTITUDE), none);
            a.values = glm::vec4(1.0f, float(v1), float(v1 * AEROSOL_RISE), 0.0f);
            a.inv_scales = glm::vec4(float(1.0 / h),
                                     float(-std::log(AEROSOL_RISE) / (AEROSOL_MAX_ALTITUDE - AEROSOL_MIN_ALTITUDE)),
                                     float(1.0 / h), 0.0f);
        }
    }
    // Rain: constant below the cloud base.
    if (atm.rain.present) {
        const double ext = rain_extinction(atm.rain.rate) * double(atm.rain.density_scale);
        if (ext > 0.0) {
            shader::SpeciesGpu& r = species[shader::SPECIES_RAIN];
            r.sigma_t = r.sigma_s = glm::vec4(glm::vec3(float(ext)), 0.0f);
            r.phase = glm::vec4(atm.rain.g, 0.0f, 1.0f, 0.0f);
            r.starts = glm::vec4(0.0f, atm.rain.top, none, none);
            r.values = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
            r.inv_scales = glm::vec4(0.0f);
        }
    }
}

namespace {

// Piece k of a profile holding y, and rho(y) (double precision, CPU side).
int piece_of(const shader::SpeciesGpu& sp, double y) {
    return y < sp.starts.y ? 0 : (y < sp.starts.z ? 1 : (y < sp.starts.w ? 2 : 3));
}

double density(const shader::SpeciesGpu& sp, double y) {
    const int k = piece_of(sp, y);
    return sp.values[k] * std::exp(-(y - sp.starts[k]) * sp.inv_scales[k]);
}

}  // namespace

// The weights of the levels' measure (make_altitude_levels; effects/daytime/docs/daytime.md).
constexpr double LEVEL_COLUMN_STEP = 0.3;
constexpr double LEVEL_MIX_STEP = 0.5;

std::vector<float> make_altitude_levels(const shader::SpeciesGpu species[shader::SPECIES_COUNT], int segments,
                                        float& top) {
    // The top: where every species' density has fallen below
    // ATMOSPHERE_TOP_DENSITY (or its profile ends).
    double y_top = 0.0;
    std::vector<double> breaks;
    for (int i = 0; i < 3; ++i) {
        const shader::SpeciesGpu& sp = species[i];
        if (sp.phase.z == 0.0f) continue;
        int last = 0;
        for (int k = 1; k < 4; ++k)
            if (sp.starts[k] < shader::NO_HIT) {
                breaks.push_back(sp.starts[k]);
                if (sp.values[k] != 0.0f) last = k;
            }
        double end;
        if (last + 1 < 4 && sp.starts[last + 1] < shader::NO_HIT) {
            end = sp.starts[last + 1];  // the profile ends (rain: the cloud base)
        } else {
            end = sp.starts[last] + std::log(std::max(double(sp.values[last]), 1e-30) / ATMOSPHERE_TOP_DENSITY) /
                                        double(sp.inv_scales[last]);
        }
        y_top = std::max(y_top, end);
    }
    top = float(y_top);
    std::vector<float> levels;
    if (!(y_top > 0.0)) return levels;
    // How fast the source function S = J / sigma_t changes with altitude
    // (effects/daytime/docs/daytime.md): along a ray of direction cosine mu the optical depth
    // is (C(y0) - C(y)) / mu, so a source that depends on y only through the
    // column C is as smooth in optical depth as in C: one part of the measure
    // is the column of the densest channel per LEVEL_COLUMN_STEP; the other
    // is the change of the species' shares of the extinction (whose phases
    // differ) per LEVEL_MIX_STEP. Levels are spread evenly in its integral.
    const int n = 4096;
    std::vector<double> ys(n + 1), v(n + 1, 0.0);
    auto shares = [&](double y, double& sigma_max, double f[3]) {
        double total = 0.0;
        sigma_max = 0.0;
        for (int i = 0; i < 3; ++i) {
            const shader::SpeciesGpu& sp = species[i];
            const double rho = sp.phase.z == 0.0f ? 0.0 : density(sp, y);
            f[i] = rho * double(sp.sigma_t.y);
            total += f[i];
            sigma_max += rho * double(std::max({sp.sigma_t.x, sp.sigma_t.y, sp.sigma_t.z}));
        }
        for (int i = 0; i < 3; ++i) f[i] = total > 0.0 ? f[i] / total : 0.0;
    };
    // A grid uniform in log(1 + y / 10 m): fine near the ground.
    const double u_top = std::log1p(y_top / 10.0);
    for (int k = 0; k <= n; ++k) ys[k] = 10.0 * std::expm1(u_top * k / n);
    ys[n] = y_top;
    std::vector<double> column_part(n + 1, 0.0), mix_part(n + 1, 0.0);
    double sigma0, f0[3];
    shares(0.0, sigma0, f0);
    for (int k = 1; k <= n; ++k) {
        double sigma1, f1[3];
        shares(ys[k], sigma1, f1);
        double mix = 0.0;
        for (int i = 0; i < 3; ++i) mix += std::abs(f1[i] - f0[i]);
        column_part[k] = column_part[k - 1] + 0.5 * (sigma0 + sigma1) * (ys[k] - ys[k - 1]) / LEVEL_COLUMN_STEP;
        mix_part[k] = mix_part[k - 1] + mix / LEVEL_MIX_STEP;
        sigma0 = sigma1;
        std::copy(f1, f1 + 3, f0);
    }
    // The two parts share the levels: each gets at least a third of them
    // whatever the other's total (a dense ground fog's column must not
    // starve the mixture's change higher up, nor the reverse).
    const double column_total = column_part[n], mix_total = mix_part[n];
    const double total = column_total + mix_total;
    const double column_weight = total > 0.0 ? std::clamp(column_total / total, 1.0 / 3.0, 2.0 / 3.0) : 0.5;
    for (int k = 0; k <= n; ++k)
        v[k] = (column_total > 0.0 ? column_weight * column_part[k] / column_total : 0.0) +
               (mix_total > 0.0 ? (1.0 - column_weight) * mix_part[k] / mix_total : 0.0);
    levels.push_back(0.0f);
    for (int j = 1; j < segments; ++j) {
        const double target = v[n] * j / segments;
        const int k = int(std::lower_bound(v.begin(), v.end(), target) - v.begin());
        if (k <= 0 || k > n) continue;
        const double f = (target - v[k - 1]) / std::max(v[k] - v[k - 1], 1e-300);
        levels.push_back(float(ys[k - 1] + f * (ys[k] - ys[k - 1])));
    }
    for (double b : breaks)
        if (b > 0.0 && b < y_top) levels.push_back(float(b));
    levels.push_back(top);
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    return levels;
}

// ---- The sky-phase table --------------------------------------------------------

namespace {

// Hemisphere rule over the sky (w_y > 0): Gauss-Legendre rings in mu = w_y
// on panels graded toward the horizon (where exp(-C / mu) is not smooth) and
// 0.1 wide above 0.2 (a forward HG lobe, g <= 0.9, spans >= 0.1 in mu), times
// RULE_AZIMUTHS equal azimuth steps in the sun's frame, which include every
// table azimuth as a node (the lobe's peak on a node).
constexpr int RULE_NODES = 8;
constexpr int RULE_AZIMUTHS = 6 * (shader::SKY_TABLE_N_AZIMUTH - 1) * 2;

struct HemisphereRule {
    std::vector<double> mu, mu_weight;
};

HemisphereRule hemisphere_rule() {
    static const double x8[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                                 0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
    static const double w8[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                 0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    std::vector<double> cuts = {0.0, 0.002, 0.01, 0.05, 0.2};
    for (int k = 3; k <= 10; ++k) cuts.push_back(k / 10.0);
    HemisphereRule r;
    for (size_t p = 0; p + 1 < cuts.size(); ++p) {
        const double a = cuts[p], b = cuts[p + 1];
        for (int i = 0; i < RULE_NODES; ++i) {
            r.mu.push_back(0.5 * (b - a) * x8[i] + 0.5 * (b + a));
            r.mu_weight.push_back(0.5 * (b - a) * w8[i]);
        }
    }
    return r;
}

// The sun's horizontal frame: unit vectors along and across its azimuth.
void sun_frame(const shader::SkyGpu& sky, glm::dvec3& along, glm::dvec3& across) {
    glm::dvec3 s(sky.sun_direction);
    glm::dvec3 h(s.x, 0.0, s.z);
    along = glm::length(h) > 1e-9 ? glm::normalize(h) : glm::dvec3(0.0, 0.0, -1.0);
    across = glm::cross(glm::dvec3(0.0, 1.0, 0.0), along);
}

double kernel_value(const shader::SpeciesGpu species[shader::SPECIES_COUNT], int kernel, double cos_theta) {
    if (kernel == 3) return std::max(cos_theta, 0.0);
    return shader::species_phase(species[kernel].phase, float(cos_theta));
}

// The rule's directions w and their sky shape times the azimuth step.
struct RuleSamples {
    std::vector<glm::dvec3> w;
    std::vector<double> shape;  // L / Lz dpsi
};

RuleSamples rule_samples(const shader::SkyGpu& sky, const HemisphereRule& rule, const glm::dvec3& along,
                         const glm::dvec3& across) {
    RuleSamples s;
    const double dpsi = 2.0 * kPi / RULE_AZIMUTHS;
    for (size_t r = 0; r < rule.mu.size(); ++r) {
        const double mu = rule.mu[r], st = std::sqrt(std::max(1.0 - mu * mu, 0.0));
        for (int q = 0; q < RULE_AZIMUTHS; ++q) {
            const glm::dvec3 w =
                st * (std::cos(q * dpsi) * along + std::sin(q * dpsi) * across) + glm::dvec3(0.0, mu, 0.0);
            s.w.push_back(w);
            s.shape.push_back(double(shader::sky_shape(sky, glm::vec3(w))) * dpsi);
        }
    }
    return s;
}

// For one direction d: per ring r and kernel k, the azimuthal sums
// G_k(r) = sum_psi shape(w) k(d . w) dpsi (the ring's mu weight excluded).
void ring_sums(const shader::SpeciesGpu species[shader::SPECIES_COUNT], const RuleSamples& samples, int rings,
               const glm::dvec3& d, const bool kernels[4], std::vector<double>& sums) {
    sums.assign(size_t(rings) * 4, 0.0);
    for (int r = 0; r < rings; ++r) {
        double acc[4] = {0.0, 0.0, 0.0, 0.0};
        for (int q = 0; q < RULE_AZIMUTHS; ++q) {
            const size_t i = size_t(r) * RULE_AZIMUTHS + size_t(q);
            const double L = samples.shape[i];
            if (L == 0.0) continue;
            const double c = glm::dot(d, samples.w[i]);
            for (int k = 0; k < 4; ++k)
                if (kernels[k]) acc[k] += L * kernel_value(species, k, c);
        }
        for (int k = 0; k < 4; ++k) sums[size_t(r) * 4 + size_t(k)] = acc[k];
    }
}

std::string table_key(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                      bool columns) {
    std::string key = std::to_string(int(sky.zenith_radiance.w)) + "|" + std::to_string(columns);
    auto add = [&](float f) { key += "|" + std::to_string(double(f)); };
    if (int(sky.zenith_radiance.w) == shader::SKY_CIE) {
        for (int i = 0; i < 3; ++i) add(sky.gradation[i]);
        for (int i = 0; i < 4; ++i) add(sky.indicatrix[i]);
        if (sky_has_azimuth(sky))
            for (int i = 0; i < 3; ++i) add(sky.sun_direction[i]);
    }
    if (columns)
        for (int i = 0; i < 3; ++i) {
            add(species[i].phase.x);
            add(species[i].phase.y);
            add(species[i].phase.z);
        }
    return key;
}

}  // namespace

double sky_kernel_integral(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                           int kernel, double column, const glm::dvec3& direction) {
    const HemisphereRule rule = hemisphere_rule();
    glm::dvec3 along, across;
    sun_frame(sky, along, across);
    const RuleSamples samples = rule_samples(sky, rule, along, across);
    bool kernels[4] = {false, false, false, false};
    kernels[kernel] = true;
    std::vector<double> sums;
    ring_sums(species, samples, int(rule.mu.size()), glm::normalize(direction), kernels, sums);
    double total = 0.0;
    for (size_t r = 0; r < rule.mu.size(); ++r)
        total += rule.mu_weight[r] * std::exp(-column / rule.mu[r]) * sums[r * 4 + size_t(kernel)];
    return total;
}

static Table2D build_sky_phase_table(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                     bool columns);

std::shared_ptr<const Table2D> sky_phase_table(const shader::SkyGpu& sky,
                                               const shader::SpeciesGpu species[shader::SPECIES_COUNT], bool columns) {
    static TableCache<std::string> cache(8);  // the last 8 skies
    return cache.get(table_key(sky, species, columns), [&] { return build_sky_phase_table(sky, species, columns); });
}

static Table2D build_sky_phase_table(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                     bool columns) {
    const auto start = std::chrono::steady_clock::now();
    const bool azimuth = sky_has_azimuth(sky);
    const int nc = columns ? shader::SKY_TABLE_NC : 1;
    const int ne = shader::SKY_TABLE_N_ELEVATION;
    const int na = azimuth ? shader::SKY_TABLE_N_AZIMUTH : 1;
    bool kernels[4] = {false, false, false, true};
    if (columns)
        for (int i = 0; i < 3; ++i) kernels[i] = species[i].phase.z != 0.0f;

    Table2D t;
    t.name = "sky_phase";
    t.width = nc;
    t.height = ne * na;
    t.channels = 4;
    t.texels.assign(size_t(nc) * size_t(ne * na) * 4, 0.0f);
    const HemisphereRule rule = hemisphere_rule();
    glm::dvec3 along, across;
    sun_frame(sky, along, across);
    const RuleSamples samples = rule_samples(sky, rule, along, across);
    std::vector<double> columns_at(nc);
    for (int i = 0; i < nc; ++i)
        columns_at[i] = nc > 1 ? double(shader::sky_table_column(float(i) / float(nc - 1))) : 0.0;

    auto build_row = [&](int row, std::vector<double>& sums) {
        const int ie = row % ne, ia = row / ne;
        const double elevation = -kPi / 2.0 + kPi * ie / (ne - 1);
        const double azimuth = na > 1 ? kPi * ia / (na - 1) : 0.0;
        const glm::dvec3 d = std::cos(elevation) * (std::cos(azimuth) * along + std::sin(azimuth) * across) +
                             glm::dvec3(0.0, std::sin(elevation), 0.0);
        ring_sums(species, samples, int(rule.mu.size()), d, kernels, sums);
        for (int i = 0; i < nc; ++i) {
            // F e^C = sum_r w_r exp(-C (1 / mu_r - 1)) G(r): no underflow at large C.
            double f[4] = {0.0, 0.0, 0.0, 0.0};
            for (size_t r = 0; r < rule.mu.size(); ++r) {
                const double e = rule.mu_weight[r] * std::exp(-columns_at[i] * (1.0 / rule.mu[r] - 1.0));
                for (int k = 0; k < 4; ++k) f[k] += e * sums[r * 4 + size_t(k)];
            }
            float* texel = &t.texels[(size_t(row) * size_t(nc) + size_t(i)) * 4];
            for (int k = 0; k < 4; ++k) texel[k] = float(std::log(f[k] + double(shader::SKY_TABLE_FLOOR)));
        }
    };
    // Rows handed out one at a time; each worker keeps its own scratch sums.
    const int rows = ne * na;
    const size_t workers = size_t(numerics::worker_count(rows));
    std::vector<std::vector<double>> sums(workers);
    const auto build = [&](int row, int worker) { build_row(row, sums[size_t(worker)]); };
    numerics::parallel_for_worker(rows, build, int(workers));
    t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

}  // namespace airlight
