// The spotlights' part of the frame: the spots as the shaders read them,
// their switches and, in an isotropic medium, their table.
#include "spot_frame.hpp"

#include <cmath>

#include "spot_tables.hpp"

namespace airlight {

void pack_spotlights_frame(const Scene& scene, FrameData& data) {
    data.frame.spot.glow_samples = float(scene.quality.spot_glow_samples);
    // What loses precision in float32 (the position relative to the camera,
    // sin^2 A, 1 - cos A) is formed in double (effects/spotlights/docs/spot_table.md).
    for (const SpotLight& spot : scene.spot_lights) {
        const glm::dvec3 relative = glm::dvec3(spot.position) - glm::dvec3(scene.camera.position);
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
                           float((1.0 - q) / one_minus_cos), spot.volumetric_shadows ? 1.0f : 0.0f);
        data.spot_lights.push_back(g);
    }
    data.frame.spot_light_count = int(data.spot_lights.size());
    data.features.spot_lights = !data.spot_lights.empty();
    data.features.spot_airlight = data.scattering && !data.spot_lights.empty();
}

void pick_spotlights_tables(const Scene&, FrameData& data) {
    if (data.features.phase) return;  // the phase effect's per-lobe tables take its place
    if (needs_spot_moments(data)) data.tables[shader::TABLE_SPOT_MOMENTS] = &spot_moment_table();
}

}  // namespace airlight
