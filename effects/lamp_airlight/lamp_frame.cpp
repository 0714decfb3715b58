// The point lamps' part of the frame: the lamps brightest first, their
// switches and, in an isotropic medium, their tables.
#define GLM_ENABLE_EXPERIMENTAL
#include "lamp_frame.hpp"

#include <algorithm>
#include <glm/gtx/component_wise.hpp>

#include "airlight_tables.hpp"

namespace airlight {

void pack_lamp_airlight_frame(const Scene& scene, FrameData& data) {
    // Lamps in order of decreasing brightness seen from the camera, so that the
    // per-pixel culling (effects/lamp_airlight/docs/culling.md) meets the bright ones first.
    const glm::vec3 camera = scene.camera.position;
    const glm::vec3 sigma_t = glm::vec3(data.frame.sigma_t);
    std::vector<PointLight> lights = scene.point_lights;
    auto brightness = [&](const PointLight& l) {
        const float dist = glm::length(l.position - camera);
        return glm::compMax(l.intensity * glm::exp(-sigma_t * dist)) / std::max(dist * dist, l.radius * l.radius);
    };
    std::stable_sort(lights.begin(), lights.end(),
                     [&](const PointLight& a, const PointLight& b) { return brightness(a) > brightness(b); });
    for (const PointLight& light : lights)
        data.point_lights.push_back({glm::vec4(light.position, light.radius),
                                     glm::vec4(light.intensity, light.volumetric_shadows ? 1.0f : 0.0f)});
    data.frame.point_light_count = int(data.point_lights.size());

    data.features.point_lights = !data.point_lights.empty();
    data.features.airlight = data.scattering && !data.point_lights.empty();
    // Brute-force marching (benchmarks) replaces the tables for every light's airlight, the spots' too.
    data.features.airlight_march = data.scattering && (!scene.point_lights.empty() || !scene.spot_lights.empty()) &&
                                   scene.quality.airlight == AirlightMethod::march;
}

void pick_lamp_airlight_tables(const Scene&, FrameData& data) {
    if (data.features.phase) return;  // the phase effect's per-lobe tables take their place
    if (needs_surface_glow(data)) data.tables[shader::TABLE_SURFACE_GLOW] = &surface_glow_table();
    if (needs_airlight_tail(data)) data.tables[shader::TABLE_AIRLIGHT_TAIL] = &airlight_tail_table();
}

}  // namespace airlight
