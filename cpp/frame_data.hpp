// Scene -> the flat arrays both backends consume (shaders/layout.glsl).
#pragma once

#include "airlight/scene.hpp"
#include "shader_cpp.hpp"

#include <vector>

namespace airlight {

struct FrameData {
    shader::FrameUniforms frame{};
    std::vector<shader::PointLightGpu> point_lights;
    std::vector<shader::SurfaceGpu> surfaces;
    shader::Features features;
};

// Builds the per-frame data: camera basis, medium coefficients, lights and
// surfaces, and the feature set that selects the shader variant.
FrameData make_frame_data(const Scene& scene);

}  // namespace airlight
