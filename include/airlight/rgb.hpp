// The colour triple of the scene data (the core's and the effects' scene types).
#pragma once

#include <glm/vec3.hpp>

namespace airlight {

// Linear RGB triple (radiance, intensity, coefficients, albedo), per channel.
using Rgb = glm::vec3;

}  // namespace airlight
