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

// One named image of a render's outputs: `components` (1 or 3) float32 values
// per pixel, width * height pixels, row 0 on top.
struct NamedImage {
    std::string name;
    int components = 3;
    std::vector<float> values;
};

// OpenEXR files (through the OpenEXR library): one single-part scanline file
// holding every image as channels, linear, float32 (or half with `half`), ZIP
// compression. Channel naming (cpp/image_io.cpp, README "Python API"): the
// image `radiance` is the channels R, G, B (what every EXR viewer shows);
// `normal` is normal.X, normal.Y, normal.Z; any other 3-component image <name>
// is <name>.R, <name>.G, <name>.B; a 1-component image <name> is the channel
// <name>. Values are written as they are (inf, NaN). Bad input (an empty or
// duplicate name, a name with '.', components not 1 or 3, a wrong number of
// values, width or height < 1, `radiance` with 1 component, a 1-component R, G
// or B) throws std::invalid_argument naming the field; a file that cannot be
// written std::runtime_error with the path and the library's reason.
void write_exr(const std::string& path, int width, int height, const std::vector<NamedImage>& images,
               bool half = false);

// Plain radiance: the image `radiance` alone (channels R, G, B).
void write_exr(const std::string& path, const Image& image, bool half = false);

// Reads an EXR file (single-part or the first part; scanline or tiled; float,
// half or uint channels, not subsampled) into float32 images, the naming above
// reversed: R, G, B -> `radiance`; x.R, x.G, x.B -> `x` (3 components); x.X,
// x.Y, x.Z -> `x`; any other channel (a lone A, x.R without x.G) -> a
// 1-component image named by the full channel name. `radiance` comes first,
// then the others in the file's channel order (sorted by name). `width` and
// `height` are the data window's. A missing, unreadable or malformed file
// throws std::runtime_error with the path and the library's reason.
std::vector<NamedImage> read_exr(const std::string& path, int& width, int& height);

}  // namespace airlight
