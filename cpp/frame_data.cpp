#define GLM_ENABLE_EXPERIMENTAL
#include "frame_data.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtx/component_wise.hpp>
#include <limits>

#include "rainbow.hpp"
#include "sky.hpp"

namespace airlight {
namespace {

struct BoundedSurface {
    shader::SurfaceGpu gpu;
    glm::vec3 lo, hi;
};

// Median-split bounding volume hierarchy over items [begin, end) into
// data.bvh_nodes[node] (leaves of at most two surfaces), appending the
// surfaces to data.surfaces in leaf order. Depth <= log2(n) + 1, well inside
// the shader's traversal stack (BVH_STACK_SIZE).
void build_node(std::vector<BoundedSurface>& items, int begin, int end, int node, FrameData& data) {
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    glm::vec3 c_lo = lo, c_hi = hi;
    for (int i = begin; i < end; ++i) {
        lo = glm::min(lo, items[i].lo);
        hi = glm::max(hi, items[i].hi);
        const glm::vec3 c = 0.5f * (items[i].lo + items[i].hi);
        c_lo = glm::min(c_lo, c);
        c_hi = glm::max(c_hi, c);
    }
    data.bvh_nodes[node].lo = glm::vec4(lo, 0.0f);
    data.bvh_nodes[node].hi = glm::vec4(hi, 0.0f);
    if (end - begin <= 2) {
        data.bvh_nodes[node].info = glm::ivec4(int(data.surfaces.size()), end - begin, 0, 0);
        for (int i = begin; i < end; ++i) data.surfaces.push_back(items[i].gpu);
        return;
    }
    const glm::vec3 extent = c_hi - c_lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const int mid = (begin + end) / 2;
    std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                     [axis](const BoundedSurface& a, const BoundedSurface& b) {
                         return a.lo[axis] + a.hi[axis] < b.lo[axis] + b.hi[axis];
                     });
    const int left = int(data.bvh_nodes.size());
    data.bvh_nodes.resize(data.bvh_nodes.size() + 2);
    data.bvh_nodes[node].info = glm::ivec4(left, 0, 0, 0);
    build_node(items, begin, mid, left, data);
    build_node(items, mid, end, left + 1, data);
}

void build_bvh(std::vector<BoundedSurface>& items, FrameData& data) {
    if (items.empty()) return;
    data.bvh_nodes.resize(1);
    build_node(items, 0, int(items.size()), 0, data);
}

// The lobes of an anisotropic phase function with their weights (none for an
// isotropic medium, or an HG one with g = 0: the isotropic tables are exact
// there). |g| is clamped to PHASE_G_LIMIT.
std::vector<std::pair<PhaseLobe, float>> phase_lobes(const Phase& phase) {
    auto hg = [](float g) {
        PhaseLobe l;
        l.g = std::clamp(g, -shader::PHASE_G_LIMIT, shader::PHASE_G_LIMIT);
        return l;
    };
    std::vector<std::pair<PhaseLobe, float>> lobes;
    switch (phase.type) {
        case PhaseType::isotropic:
            break;
        case PhaseType::hg:
            if (phase.g != 0.0f) lobes.push_back({hg(phase.g), 1.0f});
            break;
        case PhaseType::rayleigh: {
            PhaseLobe l;
            l.rayleigh = true;
            lobes.push_back({l, 1.0f});
            break;
        }
        case PhaseType::hg2:
            if (phase.forward_g == 0.0f && phase.backward_g == 0.0f) break;
            if (phase.forward_weight > 0.0f) lobes.push_back({hg(phase.forward_g), phase.forward_weight});
            if (phase.forward_weight < 1.0f) lobes.push_back({hg(phase.backward_g), 1.0f - phase.forward_weight});
            break;
    }
    return lobes;
}

// The daytime part (issue 6; sky.glsl): sky, sun, the atmosphere's species
// and altitude levels, the feature switches and the sky table if needed.
void add_daytime(const Scene& scene, FrameData& data) {
    shader::FrameUniforms& f = data.frame;
    f.sky = make_sky_gpu(scene.sky, scene.sun);
    make_species_gpu(scene.atmosphere, f.species);
    data.features.sky =
        scene.sky.model != SkyModel::none && glm::any(glm::greaterThan(scene.sky.zenith_radiance, glm::vec3(0.0f)));
    data.features.sun = f.sky.sun_direction.w != 0.0f;
    data.features.atmosphere =
        f.species[0].phase.z != 0.0f || f.species[1].phase.z != 0.0f || f.species[2].phase.z != 0.0f;
    data.features.sky_march = data.features.atmosphere && scene.quality.airlight == AirlightMethod::march;
    float top = 0.0f;
    std::vector<float> levels;
    if (data.features.atmosphere) levels = make_altitude_levels(f.species, scene.quality.sky_segments, top);
    for (size_t k = 0; k < levels.size() && k < size_t(shader::ATMOSPHERE_MAX_LEVELS); ++k)
        f.altitude_levels[k / 4][int(k % 4)] = levels[k];
    const bool columns = data.features.sky && data.features.atmosphere;
    if (columns || (data.features.sky && data.features.surfaces))
        data.sky_table = &sky_phase_table(f.sky, f.species, columns);
    // Rainbows (MODELS.md section 4): the rain's phase for sunlight from the Mie
    // table; a scene without sun or without drops builds none.
    const Rain& rain = scene.atmosphere.rain;
    data.features.rainbow = data.features.sun && f.species[2].phase.z != 0.0f && rain.phase == RainPhase::mie;
    if (data.features.rainbow)
        data.rainbow_table = &rainbow_phase_table(double(rain.rate), scene.quality.rainbow_wavelengths);
    f.atmosphere = glm::vec4(top, float(std::min(levels.size(), size_t(shader::ATMOSPHERE_MAX_LEVELS))),
                             data.sky_table ? float(data.sky_table->width) : 1.0f,
                             data.sky_table ? float(data.sky_table->height / shader::SKY_TABLE_N_ELEVATION) : 1.0f);
}

}  // namespace

FrameData make_frame_data(const Scene& scene) {
    FrameData data;
    shader::FrameUniforms& f = data.frame;

    // Pinhole camera basis (validated non-degenerate on load).
    const Camera& cam = scene.camera;
    const glm::vec3 forward = glm::normalize(cam.look_at - cam.position);
    const glm::vec3 right = glm::normalize(glm::cross(forward, cam.up));
    const glm::vec3 up = glm::cross(right, forward);
    const float tan_half = static_cast<float>(std::tan(0.5 * glm::radians(double(cam.fov_y_degrees))));
    const float aspect = float(scene.film.width) / float(scene.film.height);
    f.camera_position = glm::vec4(cam.position, 0.0f);
    f.camera_right = glm::vec4(right * (tan_half * aspect), 0.0f);
    f.camera_up = glm::vec4(up * tan_half, 0.0f);
    f.camera_forward = glm::vec4(forward, 0.0f);

    const bool medium = scene.has_medium && glm::any(glm::greaterThan(scene.medium.sigma_t, glm::vec3(0.0f)));
    const glm::vec3 sigma_t = medium ? scene.medium.sigma_t : glm::vec3(0.0f);
    const glm::vec3 sigma_s = medium ? scene.medium.sigma_s() : glm::vec3(0.0f);
    const bool scattering = glm::any(glm::greaterThan(sigma_s, glm::vec3(0.0f)));
    f.sigma_t = glm::vec4(sigma_t, 0.0f);
    f.sigma_s = glm::vec4(sigma_s, 0.0f);
    f.background = glm::vec4(scene.background, 0.0f);

    // Lights in order of decreasing brightness seen from the camera, so that
    // the per-pixel culling (docs/culling.md) meets the bright ones first.
    std::vector<PointLight> lights = scene.point_lights;
    auto brightness = [&](const PointLight& l) {
        const float dist = glm::length(l.position - cam.position);
        return glm::compMax(l.intensity * glm::exp(-sigma_t * dist)) / std::max(dist * dist, l.radius * l.radius);
    };
    std::stable_sort(lights.begin(), lights.end(),
                     [&](const PointLight& a, const PointLight& b) { return brightness(a) > brightness(b); });
    float farthest = 0.0f;
    for (const PointLight& light : lights) {
        farthest = std::max(farthest, glm::length(light.position - cam.position));
        data.point_lights.push_back({glm::vec4(light.position, light.radius), glm::vec4(light.intensity, 0.0f)});
    }
    // Spotlights: what loses precision in float32 (the position relative to
    // the camera, sin^2 A, 1 - cos A) is formed in double (docs/spot_table.md).
    for (const SpotLight& spot : scene.spot_lights) {
        const glm::dvec3 relative = glm::dvec3(spot.position) - glm::dvec3(cam.position);
        const glm::dvec3 axis = glm::normalize(glm::dvec3(spot.direction));
        const double angle = glm::radians(double(spot.cone_angle_degrees));
        const double sin_half = std::sin(0.5 * angle), one_minus_cos = 2.0 * sin_half * sin_half;
        const double q = spot.edge;
        shader::SpotLightGpu g{};
        g.relative_position_radius = glm::vec4(glm::vec3(relative), spot.radius);
        g.world_position = glm::vec4(spot.position, 0.0f);
        g.axis_cos = glm::vec4(glm::vec3(axis), float(std::cos(angle)));
        g.intensity_edge = glm::vec4(spot.intensity, float(q));
        g.cone = glm::vec4(float(std::sin(angle) * std::sin(angle)), float(one_minus_cos),
                           float((1.0 - q) / one_minus_cos), 0.0f);
        data.spot_lights.push_back(g);
        farthest = std::max(farthest, float(glm::length(relative)));
    }
    f.light_counts = glm::ivec4(int(data.spot_lights.size()), 0, 0, 0);

    // Ray marching (benchmarks): escaping rays are cut where the transmittance
    // of the thinnest scattering channel has fallen below e^{-16}.
    float thinnest = std::numeric_limits<float>::infinity();
    for (int c = 0; c < 3; ++c)
        if (sigma_s[c] > 0.0f) thinnest = std::min(thinnest, sigma_t[c]);
    const float march_far = scattering ? farthest + 16.0f / thinnest : 0.0f;
    f.quality = glm::vec4(scene.quality.cull_fraction, float(scene.quality.march_steps), march_far,
                          float(scene.quality.spot_glow_samples));
    // Surfaces: the planes (unbounded, tested one by one), then the bounded
    // surfaces ordered by the leaves of a BVH built over them.
    std::vector<BoundedSurface> bounded;
    for (const Surface& s : scene.surfaces) {
        shader::SurfaceGpu g{};
        switch (s.type) {
            case SurfaceType::plane:
                g.p0 = glm::vec4(s.point, 0.0f);
                g.p1 = glm::vec4(glm::normalize(s.normal), 0.0f);
                g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_PLANE));
                data.surfaces.push_back(g);
                break;
            case SurfaceType::box:
                g.p0 = glm::vec4(s.box_min, 0.0f);
                g.p1 = glm::vec4(s.box_max, 0.0f);
                g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_BOX));
                bounded.push_back({g, s.box_min, s.box_max});
                break;
            case SurfaceType::sphere:
                g.p0 = glm::vec4(s.center, 0.0f);
                g.p1 = glm::vec4(s.radius, 0.0f, 0.0f, 0.0f);
                g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_SPHERE));
                bounded.push_back({g, s.center - glm::vec3(s.radius), s.center + glm::vec3(s.radius)});
                break;
        }
    }
    const int planes = int(data.surfaces.size());
    build_bvh(bounded, data);
    f.geometry_counts = glm::ivec4(planes, int(data.bvh_nodes.size()), 0, 0);

    f.film_counts =
        glm::ivec4(scene.film.width, scene.film.height, int(data.point_lights.size()), int(data.surfaces.size()));
    data.features.medium = medium;
    data.features.point_lights = !data.point_lights.empty();
    data.features.surfaces = !data.surfaces.empty();
    data.features.airlight = scattering && !data.point_lights.empty();
    data.features.airlight_march = data.features.airlight && scene.quality.airlight == AirlightMethod::march;
    data.features.grey_medium =
        sigma_t.x == sigma_t.y && sigma_t.y == sigma_t.z && sigma_s.x == sigma_s.y && sigma_s.y == sigma_s.z;
    data.features.spot_lights = !data.spot_lights.empty();
    data.features.spot_airlight = scattering && !data.spot_lights.empty();
    data.features.airlight_march =
        (data.features.airlight || data.features.spot_airlight) && scene.quality.airlight == AirlightMethod::march;
    // Which tables the variant reads: the tail (or per-lobe moments) for the
    // view-ray airlight unless marched, the spot moments also for the spots'
    // surface glow, the glow table only where surfaces receive it.
    const bool spot_tables = data.features.spot_airlight && (!data.features.airlight_march || data.features.surfaces);
    const bool point_tail = data.features.airlight && !data.features.airlight_march;
    const bool point_glow = data.features.airlight && data.features.surfaces;
    const auto lobes = scattering ? phase_lobes(scene.medium.phase) : std::vector<std::pair<PhaseLobe, float>>{};
    data.features.phase = !lobes.empty();
    f.phase_bounds = glm::vec4(0.5f * shader::PI, shader::SURFACE_GLOW_G_BOUND, 0.0f, 0.0f);
    f.light_counts.y = int(lobes.size());
    if (data.features.phase) {
        double airlight_bound = 0.0, glow_bound = 0.0;
        for (size_t i = 0; i < lobes.size(); ++i) {
            const auto& [lobe, weight] = lobes[i];
            (i == 0 ? f.phase_lobe0 : f.phase_lobe1) = phase_lobe_gpu(lobe, weight);
            airlight_bound += weight * phase_airlight_bound(lobe);
            if (spot_tables || point_tail) data.phase_moments[i] = &phase_moment_table(lobe);
            if (point_glow) data.phase_glow[i] = &phase_glow_table(lobe);
            // The glow culling bound (a spot's glow is at most a lamp's): the
            // slice's maximum of G (for g < 0 above the isotropic 8.08: 63 at
            // g = -0.9); without a slice (spots only) G <= 2 pi^2 int_0^{pi/2} P dt,
            // from Q_p(u, xi) <= int_xi^{pi/2} P dt and Phi <= 2 pi.
            const double pi = double(shader::PI);
            glow_bound +=
                weight * (data.phase_glow[i] ? std::exp(double(*std::max_element(data.phase_glow[i]->texels.begin(),
                                                                                 data.phase_glow[i]->texels.end())))
                                             : 2.0 * pi * pi * phase_airlight_bound(lobe));
        }
        f.phase_bounds = glm::vec4(float(airlight_bound * 1.0001), float(glow_bound * 1.001), 0.0f, 0.0f);
    } else {
        if (spot_tables) data.spot_moments = &spot_moment_table();
        if (point_glow) data.surface_glow = &surface_glow_table();
        if (point_tail) data.airlight_tail = &airlight_tail_table();
    }
    add_daytime(scene, data);
    return data;
}

}  // namespace airlight
