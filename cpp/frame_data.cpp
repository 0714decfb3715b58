#define GLM_ENABLE_EXPERIMENTAL
#include "frame_data.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtx/component_wise.hpp>
#include <limits>

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

    // The farthest light, for the marching distance below.
    float farthest = 0.0f;
    for (const PointLight& light : scene.point_lights)
        farthest = std::max(farthest, glm::length(light.position - cam.position));
    for (const SpotLight& spot : scene.spot_lights)
        farthest = std::max(farthest, float(glm::length(glm::dvec3(spot.position) - glm::dvec3(cam.position))));

    // Ray marching (benchmarks): escaping rays are cut where the transmittance
    // of the thinnest scattering channel has fallen below e^{-16}.
    float thinnest = std::numeric_limits<float>::infinity();
    for (int c = 0; c < 3; ++c)
        if (sigma_s[c] > 0.0f) thinnest = std::min(thinnest, sigma_t[c]);
    const float march_far = scattering ? farthest + 16.0f / thinnest : 0.0f;
    f.cull_fraction = scene.quality.cull_fraction;
    f.march_steps = float(scene.quality.march_steps);
    f.march_far = march_far;
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
    f.plane_count = planes;
    f.bvh_node_count = int(data.bvh_nodes.size());

    f.film_width = scene.film.width;
    f.film_height = scene.film.height;
    f.surface_count = int(data.surfaces.size());
    data.features.medium = medium;
    data.features.surfaces = !data.surfaces.empty();
    data.features.grey_medium =
        sigma_t.x == sigma_t.y && sigma_t.y == sigma_t.z && sigma_s.x == sigma_s.y && sigma_s.y == sigma_s.z;
    data.scattering = scattering;

    // Each effect's part (effects/<name>/*_frame.cpp, registry order), then the
    // tables of those whose tables depend on other effects' features.
#define AIRLIGHT_X(effect) pack_##effect##_frame(scene, data);
    AIRLIGHT_FRAME_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
#define AIRLIGHT_X(effect) pick_##effect##_tables(scene, data);
    AIRLIGHT_FRAME_TABLE_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
    return data;
}

}  // namespace airlight
