// The falling rain's scene data: the "falling_rain" key of the scene format
// (rain_keys.cpp parses it; effects/falling_rain/physics.md).
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

namespace airlight {

// Drops falling around the camera: Marshall-Palmer diameters for `rate`, the
// Gunn-Kinzer terminal speed (Atlas's fit) plus the wind, drawn as streaks
// over the camera's exposure time (physics.md sections 1-4). A drop of
// diameter D is drawn out to the distance radius x min(1, D / full_diameter)
// from the camera, fading out over the last FALLING_RAIN_FADE of it
// (section 2: the split with the continuous medium).
struct FallingRain {
    bool present = false;
    float rate = 0.0f;           // mm/h (0: no drops); the key's default is the atmosphere's rain rate
    float radius = 8.0f;         // m: the largest distance at which drops are drawn
    float full_diameter = 2.0f;  // mm: drops at least this large are drawn out to `radius`
    glm::vec3 wind{0.0f};        // m/s, horizontal (y = 0)
    double time = 0.0;           // s: the end of the exposure
    std::uint32_t seed = 1;
};

}  // namespace airlight
