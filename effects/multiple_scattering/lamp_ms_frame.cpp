// The point lamps' multiple scattering: its switch and table
// (effects/multiple_scattering/physics.md section 12).
#include "lamp_ms_frame.hpp"

#include <algorithm>
#include <cmath>

#include "point_source.hpp"

namespace airlight {

// Below this sigma_s D (D the farthest lamp's distance from the camera) the
// light scattered twice or more is under about 1e-3 of the single scattering
// at every angle (section 12): no table.
constexpr float kNegligibleScatteringDepth = 1.0e-4f;

bool lamp_ms_matters(const Scene& scene, const FrameData& data) {
    if (!data.features.airlight || !scene.quality.multiple_scattering) return false;
    const glm::vec3 sigma_t = glm::vec3(data.frame.sigma_t), sigma_s = glm::vec3(data.frame.sigma_s);
    const float s_max = std::max({sigma_s.x, sigma_s.y, sigma_s.z});
    const float t_min = std::min({sigma_t.x, sigma_t.y, sigma_t.z});
    float far = 0.0f, near = 3.0e38f;
    for (const PointLight& l : scene.point_lights) {
        const float d = glm::length(l.position - scene.camera.position);
        far = std::max(far, d);
        near = std::min(near, d);
    }
    if (s_max * far < kNegligibleScatteringDepth) return false;
    // Every lamp beyond the table's optical distance on every channel: nothing to add.
    return t_min * near < shader::LAMP_MS_TAU_MAX;
}

void pack_lamp_ms_frame(const Scene& scene, FrameData& data) {
    data.features.lamp_multiple_scattering = lamp_ms_matters(scene, data);
    if (!data.features.lamp_multiple_scattering) return;
    const glm::vec3 sigma_t = glm::vec3(data.frame.sigma_t), sigma_s = glm::vec3(data.frame.sigma_s);
    std::array<double, 3> albedo{};
    for (int c = 0; c < 3; ++c) albedo[size_t(c)] = sigma_t[c] > 0.0f ? double(sigma_s[c] / sigma_t[c]) : 0.0;
    data.use_table(shader::TABLE_LAMP_MS_GLOW, lamp_ms_table(point_source_phase(scene.medium.phase), albedo));
}

}  // namespace airlight
