// A weather map for the noise clouds (physics.md section 8): an image whose
// red channel scales the layer's coverage and whose green channel is its
// type, laid over the ground and repeating.
#pragma once

#include <memory>
#include <string>

#include "tables.hpp"

namespace airlight {

// Reads a PNG (grey or colour, 8 or 16 bit) or an OpenEXR file into an RGBA
// table of the image's size (column i along +x, row j along +z, row 0 the
// image's top row): R the coverage factor, G the type, B 1 where the image has
// colour (G is the type) and 0 where it is grey (the layer's `type` holds),
// A 0. Values are the file's as stored: 8- and 16-bit PNG codes over 255 or
// 65535 (data, not sRGB-decoded), EXR's R, G (or its one channel) as they are;
// each must lie in [0, 1]. Kept for the last few files (read again when a file
// changes). Throws std::runtime_error naming the path and what is wrong
// (missing, not PNG or EXR, too small, values outside [0, 1]).
std::shared_ptr<const Table2D> load_weather_map(const std::string& path);

}  // namespace airlight
