#include "frame_data.hpp"

#include <cmath>

namespace airlight {

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
    if (medium) {
        f.sigma_t = glm::vec4(scene.medium.sigma_t, 0.0f);
        f.sigma_s = glm::vec4(scene.medium.sigma_s(), 0.0f);
    }
    f.background = glm::vec4(scene.background, 0.0f);

    for (const PointLight& light : scene.point_lights) {
        data.point_lights.push_back({glm::vec4(light.position, light.radius), glm::vec4(light.intensity, 0.0f)});
    }
    for (const Surface& s : scene.surfaces) {
        shader::SurfaceGpu g{};
        switch (s.type) {
        case SurfaceType::plane:
            g.p0 = glm::vec4(s.point, 0.0f);
            g.p1 = glm::vec4(glm::normalize(s.normal), 0.0f);
            g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_PLANE));
            break;
        case SurfaceType::box:
            g.p0 = glm::vec4(s.box_min, 0.0f);
            g.p1 = glm::vec4(s.box_max, 0.0f);
            g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_BOX));
            break;
        case SurfaceType::sphere:
            g.p0 = glm::vec4(s.center, 0.0f);
            g.p1 = glm::vec4(s.radius, 0.0f, 0.0f, 0.0f);
            g.albedo_type = glm::vec4(s.albedo, float(shader::SURFACE_SPHERE));
            break;
        }
        data.surfaces.push_back(g);
    }

    f.film_counts = glm::ivec4(scene.film.width, scene.film.height, int(data.point_lights.size()),
                               int(data.surfaces.size()));
    data.features.medium = medium;
    data.features.point_lights = !data.point_lights.empty();
    data.features.surfaces = !data.surfaces.empty();
    return data;
}

}  // namespace airlight
