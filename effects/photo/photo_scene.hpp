// The photo effect's scene data: a backplate (not a scene key: handed to the
// renderer with the scene, e.g. by airlight.photo.apply_weather) and the
// homogeneous medium's constant atmospheric light (the key "atmospheric_light").
#pragma once

#include <memory>
#include <vector>

#include "airlight/rgb.hpp"

namespace airlight {

// A photograph with its depth, ending each camera ray in place of the
// surfaces: `rgbd` holds width * height texels (row 0 on top) of 4 floats, the
// pixel's linear radiance (W/(m^2 sr)) and its depth in metres (+inf: the ray
// escapes), along the ray or, with depth_along_axis, along the camera's optical
// axis. Its size must be the film's. With `intrinsics` (fx, fy, cx, cy in pixels,
// OpenCV's convention: pixel x's centre at x, row 0 on top), pixel (x, row)'s
// ray goes through ((x - cx) / fx, -(row - cy) / fy, -1) in the camera's frame
// instead of the film's pinhole (fx, fy, cx, cy all 0: the film's).
struct Backplate {
    std::shared_ptr<const std::vector<float>> rgbd;
    int width = 0;
    int height = 0;
    bool depth_along_axis = false;
    float intrinsics[4] = {0.0f, 0.0f, 0.0f, 0.0f};
};

}  // namespace airlight
