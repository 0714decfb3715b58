// The sun's shadow map's part of the frame: where the sun lights surfaces that
// can cast shadows and the scene asks for a map (quality.sun_shadow_map), the
// map's grid over the casters' box seen along the sunlight, and its grid pass.
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

#include "frame_data.hpp"

namespace airlight {

void pack_sun_shadow_map_frame(const Scene& scene, FrameData& data) {
    const int size = scene.quality.sun_shadow_map;
    // Casters: the bounded surfaces, in the BVH's root box (planes cast no
    // shadows on a map's footprint that a shadow ray would not find: points
    // outside the footprint trace the ray).
    if (size <= 0 || !data.features.sun || !data.features.surfaces || data.bvh_nodes.empty()) return;
    const glm::dvec3 s = glm::normalize(glm::dvec3(glm::vec3(data.frame.sky.sun_direction)));
    const glm::dvec3 helper = std::abs(s.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, s)), v = glm::cross(s, u);
    const glm::dvec3 lo(glm::vec3(data.bvh_nodes[0].lo)), hi(glm::vec3(data.bvh_nodes[0].hi));
    glm::dvec3 min_p(1e300), max_p(-1e300);  // the box's corners in (u, v, s)
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 c((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
        const glm::dvec3 q(glm::dot(c, u), glm::dot(c, v), glm::dot(c, s));
        min_p = glm::min(min_p, q);
        max_p = glm::max(max_p, q);
    }
    const glm::dvec3 extent = max_p - min_p;
    const double longer = std::max({extent.x, extent.y, 1e-6 * (std::abs(max_p.x) + std::abs(max_p.y) + 1.0)});
    const double texel = longer / double(size);
    // One texel of border each side: the 2 x 2 filter covers the whole box.
    const int nu = std::clamp(int(std::ceil(extent.x / texel)), 1, size) + 2;
    const int nv = std::clamp(int(std::ceil(extent.y / texel)), 1, size) + 2;
    const double margin = 0.01 * std::max(extent.z, longer) + 1e-3;
    const double top = max_p.z + margin;
    const glm::dvec3 origin = (min_p.x - texel) * u + (min_p.y - texel) * v + top * s;
    shader::SunShadowMapGpu& m = data.frame.sun_shadow_map;
    m.origin = glm::vec4(glm::vec3(origin), float(texel));
    m.axis_u = glm::vec4(glm::vec3(u), float(nu));
    m.axis_v = glm::vec4(glm::vec3(v), float(nv));
    // Depths are differences of float32 coordinates of size ~|origin| + depth.
    const double depth = top - min_p.z;
    const double scale = std::max({std::abs(origin.x), std::abs(origin.y), std::abs(origin.z)}) + depth;
    m.depth = glm::vec4(float(depth), float(4e-6 * scale), 0.0f, 0.0f);
    data.features.sun_shadow_map = true;
    data.grid_passes.push_back({shader::TABLE_SUN_SHADOW_MAP, nu, nv, 1});
}

}  // namespace airlight
