// Turning linear radiance into display values and writing image files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "airlight/renderer.hpp"

namespace airlight {

// sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
float linear_to_srgb(float linear);

// 8-bit sRGB of radiance * exposure, clipped to [0, 1]; NaN maps to 0.
// Output: width * height RGB bytes, row 0 on top.
std::vector<std::uint8_t> to_srgb8(const Image& image, float exposure);

// 8-bit RGB PNG (uncompressed deflate blocks; no external library).
void write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

// Portable float map (little-endian, linear radiance) for HDR output.
void write_pfm(const std::string& path, const Image& image);

}  // namespace airlight
