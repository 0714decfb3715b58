// Scene -> the flat arrays both backends consume (shaders/layout.glsl).
#pragma once

#include <vector>

#include "airlight/scene.hpp"
#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

struct FrameData {
    shader::FrameUniforms frame{};
    std::vector<shader::PointLightGpu> point_lights;
    std::vector<shader::SurfaceGpu> surfaces;   // planes first, then the rest in BVH leaf order
    std::vector<shader::BvhNodeGpu> bvh_nodes;  // over the bounded surfaces (boxes, spheres)
    std::vector<shader::SpotLightGpu> spot_lights;
    shader::Features features;
    // Tables the shader variant reads (null when the scene does not need them:
    // they are then never built).
    const Table2D* airlight_tail = nullptr;
    const Table2D* surface_glow = nullptr;
    const Table2D* spot_moments = nullptr;
    // Per phase lobe (anisotropic media; docs/phase_table.md).
    const Table2D* phase_moments[2] = {nullptr, nullptr};
    const Table2D* phase_glow[2] = {nullptr, nullptr};
    // The sky-phase table (sky.glsl; cpp/sky.hpp): only for a sky that lights
    // an atmosphere (then with its columns) or surfaces (C = 0 only when
    // there is no atmosphere).
    const Table2D* sky_table = nullptr;
    // The rainbow table (cpp/rainbow.hpp): only for rain lit by the sun with
    // the "mie" phase.
    const Table2D* rainbow_table = nullptr;
};

// Builds the per-frame data: camera basis, medium coefficients, lights and
// surfaces, the feature set that selects the shader variant, and the tables
// that variant needs. Lights are sorted brightest first for the culling.
FrameData make_frame_data(const Scene& scene);

}  // namespace airlight
