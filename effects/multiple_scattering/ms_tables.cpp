// The multiple-scattering field as the shading pass reads it
// (effects/multiple_scattering/physics.md section 9; ms_layout.glsl): the
// plane-parallel solution of the scene's atmosphere, sky, sun and ground,
// solved once per weather state and tabulated over the solver's levels.
#include "ms_tables.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <string>

#include "frame_data.hpp"
#include "numerics.hpp"
#include "sky.hpp"

namespace airlight {

using numerics::kPi;

bool sky_lights_atmosphere(const shader::SkyGpu& sky) {
    const bool dome = int(sky.zenith_radiance.w) != shader::SKY_NONE &&
                      (sky.zenith_radiance.x > 0.0f || sky.zenith_radiance.y > 0.0f || sky.zenith_radiance.z > 0.0f);
    return dome || sky.sun_direction.w != 0.0f;
}

double atmosphere_scattering_depth(const shader::SpeciesGpu species[shader::SPECIES_COUNT]) {
    float top = 0.0f;
    const std::vector<float> levels = make_altitude_levels(species, 2, top);
    if (!(top > 0.0f)) return 0.0;
    const SlabAtmosphere atm = slab_from_species(species, {0.0, double(top)});
    double depth = 0.0;
    for (int c = 0; c < 3; ++c) {
        double d = 0.0;
        for (const RgbD& s : atm.layers[0].scattering_depth) d += s[size_t(c)];
        depth = std::max(depth, d);
    }
    return depth;
}

RgbD ground_albedo(const Scene& scene) {
    for (const Surface& s : scene.surfaces) {
        if (s.type != SurfaceType::plane) continue;
        const glm::vec3 n = glm::normalize(s.normal);
        if (n.y > 0.9999f && std::abs(s.point.y) <= MS_GROUND_TOLERANCE)
            return {double(s.albedo.x), double(s.albedo.y), double(s.albedo.z)};
    }
    return {0.0, 0.0, 0.0};
}

// C_m(mu_n, mu) = int_0^{2 pi} cos(m psi) max(mu_n mu + s_n s cos psi, 0) dpsi
// in closed form (effects/multiple_scattering/physics.md section 9): the
// azimuthal weight of Fourier mode m of the radiance at cosine mu in the
// irradiance of a surface whose normal has cosine mu_n.
double clamped_cosine_mode(int m, double mu_n, double mu) {
    const double a = mu_n * mu;
    const double b = std::sqrt(std::max(0.0, 1.0 - mu_n * mu_n)) * std::sqrt(std::max(0.0, 1.0 - mu * mu));
    if (b <= std::abs(a)) {
        if (a <= 0.0) return 0.0;
        return m == 0 ? 2.0 * kPi * a : (m == 1 ? kPi * b : 0.0);
    }
    const double psi0 = std::acos(std::clamp(-a / b, -1.0, 1.0));  // where the cosine turns negative
    if (m == 0) return 2.0 * (a * psi0 + b * std::sin(psi0));
    if (m == 1) return 2.0 * (a * std::sin(psi0) + 0.5 * b * (psi0 + 0.5 * std::sin(2.0 * psi0)));
    return 2.0 * (a * std::sin(m * psi0) / m +
                  0.5 * b * (std::sin((m - 1) * psi0) / (m - 1) + std::sin((m + 1) * psi0) / (m + 1)));
}

namespace {

// The table's layout (ms_layout.glsl) for a field.
struct FieldLayout {
    int levels = 0;
    int view_azimuths = 1;
    int normal_azimuths = 1;
    int irradiance_row = 0;
    int residual_row = 0;
    int altitude_row = 0;
    int rows = 0;
};

FieldLayout field_layout(int levels, bool azimuth) {
    FieldLayout l;
    l.levels = levels;
    l.view_azimuths = azimuth ? shader::MS_VIEW_AZIMUTHS : 1;
    l.normal_azimuths = azimuth ? shader::MS_NORMAL_AZIMUTHS : 1;
    l.irradiance_row = shader::SPECIES_COUNT * shader::MS_VIEW_ELEVATIONS * l.view_azimuths;
    l.residual_row = l.irradiance_row + shader::MS_NORMAL_ELEVATIONS * l.normal_azimuths;
    l.altitude_row = l.residual_row + 1;
    l.rows = l.altitude_row + 1;
    return l;
}

// Uniform nodes over [a, b] (n >= 2; one node at a when n = 1).
std::vector<double> uniform_nodes(double a, double b, int n) {
    std::vector<double> v(size_t(n), a);
    for (int k = 1; k < n; ++k) v[size_t(k)] = a + (b - a) * k / (n - 1);
    return v;
}

std::string field_key(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                      const RgbD& ground, int segments) {
    std::string key(reinterpret_cast<const char*>(&sky), sizeof(sky));
    key.append(reinterpret_cast<const char*>(species), sizeof(shader::SpeciesGpu) * shader::SPECIES_COUNT);
    key.append(reinterpret_cast<const char*>(ground.data()), sizeof(double) * 3);
    key.append(reinterpret_cast<const char*>(&segments), sizeof(segments));
    return key;
}

// The table of a solved field (ms_layout.glsl's rows).
Table2D field_table(const MultipleScatteringField& field, const SlabAtmosphere& atm,
                    const shader::SpeciesGpu species[shader::SPECIES_COUNT], const FieldLayout& layout);

// The solve of one weather state and its table. With `by_source` the sun is
// solved at unit irradiance in its own part (solve_plane_parallel_by_source):
// the table holds the sky's part in its first layout.rows rows, the sun's in
// the next (sunlit_table adds them, eq. 9.4).
Table2D build_field_table(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                          const RgbD& ground, int segments, bool by_source) {
    const auto start = std::chrono::steady_clock::now();
    // Levels: the solver's (slab_levels), at most MS_MAX_LEVELS (thicker
    // layers where a very dense atmosphere needs more).
    double depth = MS_LAYER_DEPTH;
    std::vector<double> levels = slab_levels(species, segments, depth);
    while (levels.size() > size_t(shader::MS_MAX_LEVELS)) {
        depth *= 2.0;
        levels = slab_levels(species, segments, depth);
    }
    const SlabAtmosphere atm = slab_from_species(species, levels);
    SlabIllumination light = slab_illumination(sky, ground);
    if (by_source) light.sun_irradiance = {1.0, 1.0, 1.0};
    const bool azimuth = sky.sun_direction.w != 0.0f || sky_has_azimuth(sky);
    const FieldLayout layout = field_layout(int(levels.size()), azimuth);
    SolverOptions options;
    options.streams = MS_STREAMS;
    options.threads = numerics::worker_count(3);
    for (int k = 0; k < shader::MS_VIEW_ELEVATIONS; ++k)
        options.view_mu.push_back(std::sin(-0.5 * kPi + kPi * k / (shader::MS_VIEW_ELEVATIONS - 1)));
    options.view_phi = uniform_nodes(0.0, kPi, layout.view_azimuths);
    Table2D t;
    if (by_source) {
        const FieldBySource parts = solve_plane_parallel_by_source(atm, light, options);
        t = field_table(parts.sky, atm, species, layout);
        const Table2D sun = field_table(parts.sun, atm, species, layout);
        t.height += sun.height;
        t.texels.insert(t.texels.end(), sun.texels.begin(), sun.texels.end());
    } else {
        t = field_table(solve_plane_parallel(atm, light, options), atm, species, layout);
    }
    t.name = "ms_field";
    t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

Table2D field_table(const MultipleScatteringField& field, const SlabAtmosphere& atm,
                    const shader::SpeciesGpu species[shader::SPECIES_COUNT], const FieldLayout& layout) {
    Table2D t;
    t.width = layout.levels;
    t.height = layout.rows;
    t.channels = 4;
    t.texels.assign(size_t(t.width) * size_t(t.height) * 4, 0.0f);
    auto texel = [&](int level, int row) { return &t.texels[(size_t(row) * size_t(t.width) + size_t(level)) * 4]; };
    const std::array<double, 3> sun = look_direction(field.sun_mu, 0.0);
    // K_i without the residual beam (ms_field.glsl adds E_res p_i(d . s) with the renderer's own sun phase).
    int solver_species = 0;
    for (int i = 0; i < shader::SPECIES_COUNT; ++i) {
        if (species[i].phase.z == 0.0f) continue;
        const PhaseFunction& phase = atm.phases[size_t(solver_species)];
        for (int ia = 0; ia < layout.view_azimuths; ++ia)
            for (int ie = 0; ie < shader::MS_VIEW_ELEVATIONS; ++ie) {
                const std::array<double, 3> d = look_direction(field.view_mu[size_t(ie)], field.view_phi[size_t(ia)]);
                const double p_sun =
                    field.sun_mu > 0.0 ? phase.value(d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]) / (4.0 * kPi) : 0.0;
                const int row = (i * layout.view_azimuths + ia) * shader::MS_VIEW_ELEVATIONS + ie;
                for (int lev = 0; lev < layout.levels; ++lev)
                    for (int c = 0; c < 3; ++c)
                        texel(lev, row)[c] = float(field.phased(lev, solver_species, c, ie, ia) -
                                                   p_sun * field.sun_forward_irradiance[size_t(lev)][size_t(c)]);
            }
        ++solver_species;
    }
    // E(y, n) from the ordinates' Fourier modes, the azimuth integrated in
    // closed form (clamped_cosine_mode): sum_j w_j sum_m (a_m cos m phi_n +
    // b_m sin m phi_n) C_m(mu_n, mu_j) over both hemispheres.
    const int n = field.streams, modes = field.modes_solved;
    const std::vector<double> normal_phi = uniform_nodes(0.0, kPi, layout.normal_azimuths);
    for (int ie = 0; ie < shader::MS_NORMAL_ELEVATIONS; ++ie) {
        const double mu_n = std::sin(-0.5 * kPi + kPi * ie / (shader::MS_NORMAL_ELEVATIONS - 1));
        std::vector<double> weight(size_t(2 * n) * size_t(modes));  // w_j C_m(mu_n, mu_node)
        for (int node = 0; node < 2 * n; ++node) {
            const int j = node % n;
            const double mu = node < n ? field.node_mu[size_t(j)] : -field.node_mu[size_t(j)];
            for (int m = 0; m < modes; ++m)
                weight[size_t(node) * size_t(modes) + size_t(m)] =
                    field.node_weight[size_t(j)] * clamped_cosine_mode(m, mu_n, mu);
        }
        for (int ia = 0; ia < layout.normal_azimuths; ++ia) {
            const double phi_n = normal_phi[size_t(ia)];
            const int row = layout.irradiance_row + ia * shader::MS_NORMAL_ELEVATIONS + ie;
            for (int lev = 0; lev < layout.levels; ++lev)
                for (int c = 0; c < 3; ++c) {
                    double e = 0.0;
                    for (int node = 0; node < 2 * n; ++node)
                        for (int m = 0; m < modes; ++m)
                            e += weight[size_t(node) * size_t(modes) + size_t(m)] *
                                 (field.node_radiance[field.node_index(lev, c, m, node, 0)] * std::cos(m * phi_n) +
                                  field.node_radiance[field.node_index(lev, c, m, node, 1)] * std::sin(m * phi_n));
                    texel(lev, row)[c] = float(e);
                }
        }
    }
    for (int lev = 0; lev < layout.levels; ++lev) {
        for (int c = 0; c < 3; ++c)
            texel(lev, layout.residual_row)[c] = float(field.sun_forward_irradiance[size_t(lev)][size_t(c)]);
        texel(lev, layout.altitude_row)[0] = float(field.altitudes[size_t(lev)]);
    }
    return t;
}

// The layout of a field table, from its size (with or without azimuths).
FieldLayout layout_of(const Table2D& t) {
    for (const bool azimuth : {false, true})
        if (const FieldLayout l = field_layout(t.width, azimuth); l.rows == t.height) return l;
    throw std::logic_error("ms field table: " + std::to_string(t.height) + " rows match no field layout");
}

// Eq. 9.4: the field under a sun of irradiance e (per channel), from a
// by-source table: sky part + e x sun part at unit irradiance, row by row (the
// altitudes as they are).
Table2D sunlit_table(const Table2D& parts, const glm::vec3& e) {
    const auto start = std::chrono::steady_clock::now();
    Table2D t;
    t.width = parts.width;
    t.height = parts.height / 2;
    t.channels = 4;
    const size_t half = size_t(t.width) * size_t(t.height) * 4;
    t.texels.assign(parts.texels.begin(), parts.texels.begin() + std::ptrdiff_t(half));
    const int altitude_row = layout_of(t).altitude_row;
    const size_t row_texels = size_t(t.width) * 4;
    for (int row = 0; row < t.height; ++row) {
        if (row == altitude_row) continue;  // the levels' altitudes, the same in both parts
        for (size_t i = size_t(row) * row_texels; i < size_t(row + 1) * row_texels; i += 4)
            for (int c = 0; c < 3; ++c) t.texels[i + size_t(c)] += e[c] * parts.texels[half + i + size_t(c)];
    }
    t.name = "ms_field_sunlit";
    t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

}  // namespace

std::shared_ptr<const Table2D> multiple_scattering_table(const shader::SkyGpu& sky,
                                                         const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                         const RgbD& ground, int segments) {
    static TableCache<std::string> solves(4);  // the last 4 weather states
    if (sky.sun_direction.w == 0.0f)           // no sun: the sky's field alone
        return solves.get(field_key(sky, species, ground, segments),
                          [&] { return build_field_table(sky, species, ground, segments, false); });
    // With a sun, one solve by source per state of everything but the sun's
    // irradiance, so that a sun brightening or dimming re-uses it (eq. 9.4).
    shader::SkyGpu unlit = sky;
    unlit.sun_irradiance = glm::vec4(0.0f);
    const std::shared_ptr<const Table2D> parts = solves.get(field_key(unlit, species, ground, segments), [&] {
        return build_field_table(sky, species, ground, segments, true);
    });
    static TableCache<std::string> lit(4);
    return lit.get(field_key(sky, species, ground, segments),
                   [&] { return sunlit_table(*parts, glm::vec3(sky.sun_irradiance)); });
}

namespace {

// The species with the rain's extinction (grey, albedo 1: make_species_gpu) set
// to exactly `extinction`, so that every frame's rung has the same key.
void species_with_rain(const shader::SpeciesGpu species[shader::SPECIES_COUNT], double extinction,
                       shader::SpeciesGpu out[shader::SPECIES_COUNT]) {
    std::copy(species, species + shader::SPECIES_COUNT, out);
    shader::SpeciesGpu& rain = out[shader::SPECIES_RAIN];
    rain.sigma_t = rain.sigma_s = glm::vec4(glm::vec3(float(extinction)), 0.0f);
}

// The altitudes of a field table's levels.
std::vector<float> table_altitudes(const Table2D& t) {
    const int row = layout_of(t).altitude_row;
    std::vector<float> y(size_t(t.width));
    for (int k = 0; k < t.width; ++k) y[size_t(k)] = t.texels[(size_t(row) * size_t(t.width) + size_t(k)) * 4];
    return y;
}

// Row `row` of field table t at altitude y, linear between its levels as ms_row reads it (ms_field.glsl).
glm::vec4 field_row_at(const Table2D& t, const std::vector<float>& levels, int row, float y) {
    const size_t hi = size_t(std::upper_bound(levels.begin(), levels.end(), y) - levels.begin());
    const size_t k0 = hi == 0 ? 0 : hi - 1, k1 = std::min(k0 + 1, levels.size() - 1);
    const float a = k1 > k0 ? std::clamp((y - levels[k0]) / (levels[k1] - levels[k0]), 0.0f, 1.0f) : 0.0f;
    const float* v0 = &t.texels[(size_t(row) * size_t(t.width) + k0) * 4];
    const float* v1 = &t.texels[(size_t(row) * size_t(t.width) + k1) * 4];
    return glm::mix(glm::vec4(v0[0], v0[1], v0[2], v0[3]), glm::vec4(v1[0], v1[1], v1[2], v1[3]), a);
}

// (1 - w) lo + w hi on y, the union of their levels (eq. 9.3). Each table is
// piecewise linear in altitude, so it is reproduced exactly on the union: at
// w = 0 or 1 the blend is the rung itself, whichever pair it belongs to.
Table2D blend_field_tables(const Table2D& lo, const Table2D& hi, const std::vector<float>& y, float w) {
    const std::vector<float> y_lo = table_altitudes(lo), y_hi = table_altitudes(hi);
    Table2D t;
    t.width = int(y.size());
    t.height = lo.height;
    t.channels = 4;
    t.texels.resize(size_t(t.width) * size_t(t.height) * 4);
    const int altitude_row = layout_of(lo).altitude_row;
    for (int row = 0; row < t.height; ++row)
        for (int k = 0; k < t.width && row != altitude_row; ++k) {
            const glm::vec4 v =
                glm::mix(field_row_at(lo, y_lo, row, y[size_t(k)]), field_row_at(hi, y_hi, row, y[size_t(k)]), w);
            std::memcpy(&t.texels[(size_t(row) * size_t(t.width) + size_t(k)) * 4], &v[0], sizeof(v));
        }
    for (int k = 0; k < t.width; ++k) t.texels[(size_t(altitude_row) * size_t(t.width) + size_t(k)) * 4] = y[size_t(k)];
    t.name = "ms_field_rain_blend";
    return t;
}

}  // namespace

std::shared_ptr<const Table2D> fading_rain_table(const shader::SkyGpu& sky,
                                                 const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                 const RgbD& ground, int segments, int steps) {
    const shader::SpeciesGpu& rain = species[shader::SPECIES_RAIN];
    const double extinction = double(rain.sigma_t.x);
    const bool grey_rain = rain.phase.z != 0.0f && rain.sigma_t == rain.sigma_s && rain.sigma_t.x == rain.sigma_t.y &&
                           rain.sigma_t.x == rain.sigma_t.z;
    if (steps <= 0 || !grey_rain || !(extinction >= MS_RAIN_LADDER_FLOOR))
        return multiple_scattering_table(sky, species, ground, segments);
    // Eq. 9.3: rung k at MS_RAIN_LADDER_FLOOR 2^(k / steps); the scene's rain between k and k + 1.
    const double x = steps * std::log2(extinction / MS_RAIN_LADDER_FLOOR);
    const double k = std::floor(x);
    const float w = float(x - k);
    shader::SpeciesGpu lo[shader::SPECIES_COUNT], hi[shader::SPECIES_COUNT];
    species_with_rain(species, MS_RAIN_LADDER_FLOOR * std::exp2(k / steps), lo);
    species_with_rain(species, MS_RAIN_LADDER_FLOOR * std::exp2((k + 1.0) / steps), hi);
    const std::shared_ptr<const Table2D> table_lo = multiple_scattering_table(sky, lo, ground, segments);
    const std::shared_ptr<const Table2D> table_hi = multiple_scattering_table(sky, hi, ground, segments);
    const std::vector<float> y_lo = table_altitudes(*table_lo), y_hi = table_altitudes(*table_hi);
    std::vector<float> y;
    std::set_union(y_lo.begin(), y_lo.end(), y_hi.begin(), y_hi.end(), std::back_inserter(y));
    y.erase(std::unique(y.begin(), y.end()), y.end());
    if (y.size() > size_t(shader::MS_MAX_LEVELS)) return multiple_scattering_table(sky, species, ground, segments);
    static TableCache<std::string> cache(4);  // the last 4 blends
    std::string key = field_key(sky, species, ground, segments);
    key.append(reinterpret_cast<const char*>(&steps), sizeof(steps));
    return cache.get(key, [&] {
        const auto start = std::chrono::steady_clock::now();
        Table2D t = blend_field_tables(*table_lo, *table_hi, y, w);
        t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return t;
    });
}

namespace {

// The ground's reflection alone (effects/multiple_scattering/physics.md
// section 9): in an atmosphere too thin to scatter, the diffuse light is the
// ground's Lambertian radiance rho E_0 / pi from below the horizon, so a
// surface of normal n receives rho E_0 (1 - n_y) / 2, E_0 the sun's and the
// sky's unscattered irradiance on the ground (through the column C(0)).
Table2D build_ground_bounce_table(const shader::SkyGpu& sky, const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                  const RgbD& ground, const glm::dvec3& column) {
    const auto start = std::chrono::steady_clock::now();
    const FieldLayout layout = field_layout(2, false);
    Table2D t;
    t.width = layout.levels;
    t.height = layout.rows;
    t.channels = 4;
    t.texels.assign(size_t(t.width) * size_t(t.height) * 4, 0.0f);
    RgbD e0{};
    const double sun_y = double(sky.sun_direction.y);
    for (int c = 0; c < 3; ++c) {
        double e = 0.0;
        if (sky.sun_direction.w != 0.0f && sun_y > 0.0)
            e += double(sky.sun_irradiance[c]) * sun_y * std::exp(-column[c] / sun_y);
        if (int(sky.zenith_radiance.w) != shader::SKY_NONE)
            e += double(sky.zenith_radiance[c]) * sky_kernel_integral(sky, species, 3, column[c], glm::dvec3(0, 1, 0));
        e0[size_t(c)] = e;
    }
    for (int ie = 0; ie < shader::MS_NORMAL_ELEVATIONS; ++ie) {
        const double n_y = std::sin(-0.5 * kPi + kPi * ie / (shader::MS_NORMAL_ELEVATIONS - 1));
        for (int lev = 0; lev < layout.levels; ++lev)
            for (int c = 0; c < 3; ++c)
                t.texels[(size_t(layout.irradiance_row + ie) * size_t(t.width) + size_t(lev)) * 4 + size_t(c)] =
                    float(ground[size_t(c)] * e0[size_t(c)] * 0.5 * (1.0 - n_y));
    }
    // Levels at the ground and far above: the same light at every altitude.
    t.texels[(size_t(layout.altitude_row) * size_t(t.width) + 1) * 4] = MS_GROUND_BOUNCE_TOP;
    t.name = "ms_ground_bounce";
    t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return t;
}

}  // namespace

std::shared_ptr<const Table2D> ground_bounce_table(const shader::SkyGpu& sky,
                                                   const shader::SpeciesGpu species[shader::SPECIES_COUNT],
                                                   const RgbD& ground, const glm::dvec3& column) {
    static TableCache<std::string> cache(4);
    std::string key = field_key(sky, species, ground, 0);
    key.append(reinterpret_cast<const char*>(&column), sizeof(column));
    return cache.get(key, [&] { return build_ground_bounce_table(sky, species, ground, column); });
}

bool has_surface_besides_ground(const Scene& scene) {
    for (const Surface& s : scene.surfaces) {
        const bool ground = s.type == SurfaceType::plane && glm::normalize(s.normal).y > 0.9999f &&
                            std::abs(s.point.y) <= MS_GROUND_TOLERANCE;
        if (!ground) return true;
    }
    return false;
}

void pick_multiple_scattering_tables(const Scene& scene, FrameData& data) {
    data.features.multiple_scattering = false;
    shader::FrameUniforms& f = data.frame;
    f.multiple_scattering = shader::MultipleScatteringGpu{};
    if (!scene.quality.multiple_scattering || !sky_lights_atmosphere(f.sky)) return;
    // The air's scattering is skipped where it cannot matter: no atmosphere,
    // or one whose vertical optical depth of scattering is below
    // MS_MIN_SCATTERING_DEPTH in every channel. The ground's reflection onto
    // other surfaces is kept (ground_bounce_table) where a surface can see it.
    const bool air = data.features.atmosphere && atmosphere_scattering_depth(f.species) >= MS_MIN_SCATTERING_DEPTH;
    const RgbD ground = ground_albedo(scene);
    const bool bounce = (ground[0] > 0.0 || ground[1] > 0.0 || ground[2] > 0.0) && has_surface_besides_ground(scene);
    if (!air && !bounce) return;
    std::shared_ptr<const Table2D> table;
    if (air) {
        table =
            fading_rain_table(f.sky, f.species, ground, scene.quality.sky_segments, scene.quality.fading_rain_steps);
    } else {
        glm::dvec3 column(0.0);
        if (data.features.atmosphere) {
            const SlabAtmosphere slab = slab_from_species(f.species, {0.0, 1e30});
            for (const RgbD& t : slab.layers[0].extinction_depth)
                for (int c = 0; c < 3; ++c) column[c] += t[size_t(c)];
        }
        table = ground_bounce_table(f.sky, f.species, ground, column);
    }
    data.features.multiple_scattering = true;
    const FieldLayout layout = layout_of(*table);
    f.multiple_scattering.air_scattering = air ? 1.0f : 0.0f;
    f.multiple_scattering.level_count = float(layout.levels);
    f.multiple_scattering.view_azimuths = float(layout.view_azimuths);
    f.multiple_scattering.normal_azimuths = float(layout.normal_azimuths);
    f.multiple_scattering.irradiance_row = float(layout.irradiance_row);
    f.multiple_scattering.residual_row = float(layout.residual_row);
    for (int k = 0; k < layout.levels; ++k)
        f.multiple_scattering.levels[k / 4][k % 4] =
            table->texels[(size_t(layout.altitude_row) * size_t(table->width) + size_t(k)) * 4];
    data.use_table(shader::TABLE_MS_FIELD, table);
}

}  // namespace airlight
