// The noise clouds' two tiling 3-D noise textures (physics.md section 1),
// built once per process for a seed and shared by both backends.
#pragma once

#include <memory>

#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// Texture (n^3 RGBA texels, each channel in [0, 1], tiling) stored as a
// Table2D of width n and height n * n: texel (i, j, k) (along x, y, z) at
// column i, row k * n + j (shaders/tables.glsl table_trilinear4_periodic).
struct CloudNoise {
    std::shared_ptr<const Table2D> shape;   // R Perlin-Worley, G B A Worley fBm at 4, 8, 16 cells
    std::shared_ptr<const Table2D> detail;  // R G B A Worley at 2, 4, 8, 16 cells
};

// The textures for `seed`, built on first use (about a second for the shape
// texture on two cores) and kept for the last few seeds.
CloudNoise cloud_noise_textures(int seed);

// The noise primitives at a point u in tile units (periodic with period 1),
// for tests: Worley w_f (1 - min(1, F1), F1 in cell units) and the Perlin
// fBm mapped to [0, 1].
double cloud_worley(int seed, int frequency, double ux, double uy, double uz);
double cloud_perlin_fbm(int seed, double ux, double uy, double uz);

}  // namespace airlight
