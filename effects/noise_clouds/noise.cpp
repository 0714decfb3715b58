// The noise clouds' textures (physics.md section 1): periodic Perlin gradient
// noise and Worley cellular noise from a fixed integer hash of the seed and
// the lattice cell, so that a seed gives the same clouds on every machine.
#include "noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "numerics.hpp"

namespace airlight {

namespace {

// A 32-bit integer hash (the "lowbias32" finaliser) of a running state.
uint32_t mix32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

uint32_t cell_hash(int seed, int salt, int x, int y, int z) {
    uint32_t h = mix32(uint32_t(seed) * 0x9e3779b9U + uint32_t(salt));
    h = mix32(h ^ uint32_t(x));
    h = mix32(h ^ (uint32_t(y) * 0x85ebca6bU));
    h = mix32(h ^ (uint32_t(z) * 0xc2b2ae35U));
    return h;
}

double unit_from_hash(uint32_t h) { return double(h) / 4294967296.0; }

int wrap(int i, int n) { return ((i % n) + n) % n; }

// Worley noise at frequency f: F1, the distance (in cells) from u f to the
// nearest of one hashed feature point per cell, the cells wrapping with period f.
double worley_f1(int seed, int f, double ux, double uy, double uz) {
    const double qx = ux * f, qy = uy * f, qz = uz * f;
    const int cx = int(std::floor(qx)), cy = int(std::floor(qy)), cz = int(std::floor(qz));
    double best = 1e30;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int x = cx + dx, y = cy + dy, z = cz + dz;
                const uint32_t h = cell_hash(seed, f, wrap(x, f), wrap(y, f), wrap(z, f));
                const double px = x + unit_from_hash(mix32(h ^ 0x1U));
                const double py = y + unit_from_hash(mix32(h ^ 0x2U));
                const double pz = z + unit_from_hash(mix32(h ^ 0x3U));
                const double d2 = (px - qx) * (px - qx) + (py - qy) * (py - qy) + (pz - qz) * (pz - qz);
                best = std::min(best, d2);
            }
    return std::sqrt(best);
}

double quintic(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Perlin gradient noise with lattice period p (cells per tile), in about [-1, 1].
double perlin(int seed, int p, double ux, double uy, double uz) {
    static const std::array<std::array<double, 3>, 12> gradients{{{1, 1, 0},
                                                                  {-1, 1, 0},
                                                                  {1, -1, 0},
                                                                  {-1, -1, 0},
                                                                  {1, 0, 1},
                                                                  {-1, 0, 1},
                                                                  {1, 0, -1},
                                                                  {-1, 0, -1},
                                                                  {0, 1, 1},
                                                                  {0, -1, 1},
                                                                  {0, 1, -1},
                                                                  {0, -1, -1}}};
    const double qx = ux * p, qy = uy * p, qz = uz * p;
    const int cx = int(std::floor(qx)), cy = int(std::floor(qy)), cz = int(std::floor(qz));
    const double fx = qx - cx, fy = qy - cy, fz = qz - cz;
    double corner[8];
    for (int c = 0; c < 8; ++c) {
        const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
        const uint32_t h = cell_hash(seed, 1000 + p, wrap(cx + ox, p), wrap(cy + oy, p), wrap(cz + oz, p));
        const auto& g = gradients[h % 12];
        corner[c] = g[0] * (fx - ox) + g[1] * (fy - oy) + g[2] * (fz - oz);
    }
    const double sx = quintic(fx), sy = quintic(fy), sz = quintic(fz);
    auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
    const double x00 = lerp(corner[0], corner[1], sx), x10 = lerp(corner[2], corner[3], sx);
    const double x01 = lerp(corner[4], corner[5], sx), x11 = lerp(corner[6], corner[7], sx);
    return lerp(lerp(x00, x10, sy), lerp(x01, x11, sy), sz);
}

double clamp01(double x) { return std::clamp(x, 0.0, 1.0); }

// Texel (i, j, k) of an n^3 texture, filled by texel(u) at its centre, as a
// stacked Table2D (noise.hpp).
template <class Texel>
Table2D build_texture(const std::string& name, int n, Texel texel) {
    return timed_build(name, [&] {
        Table2D t;
        t.width = n;
        t.height = n * n;
        t.channels = 4;
        t.texels.resize(size_t(n) * n * n * 4);
        numerics::parallel_for(n, [&](int k) {
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const std::array<double, 4> v = texel((i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n);
                    float* out = &t.texels[((size_t(k) * n + j) * n + i) * 4];
                    for (int c = 0; c < 4; ++c) out[c] = float(v[c]);
                }
        });
        return t;
    });
}

}  // namespace

double cloud_worley(int seed, int frequency, double ux, double uy, double uz) {
    return 1.0 - std::min(1.0, worley_f1(seed, frequency, ux, uy, uz));
}

double cloud_perlin_fbm(int seed, double ux, double uy, double uz) {
    const double n =
        perlin(seed, 4, ux, uy, uz) + 0.5 * perlin(seed, 8, ux, uy, uz) + 0.25 * perlin(seed, 16, ux, uy, uz);
    return clamp01(0.5 + 0.5 * n / 1.75);
}

CloudNoise cloud_noise_textures(int seed) {
    static TableCache<int> shape_cache(4), detail_cache(4);
    CloudNoise noise;
    noise.shape = shape_cache.get(seed, [&] {
        return build_texture("cloud_shape", shader::CLOUD_SHAPE_SIZE, [&](double x, double y, double z) {
            double w[5];  // w_f for f = 4, 8, ..., 64 (2 texels per cell at 64)
            for (int o = 0; o < 5; ++o) w[o] = cloud_worley(seed, 4 << o, x, y, z);
            auto fbm = [&](int o) { return 0.625 * w[o] + 0.25 * w[o + 1] + 0.125 * w[o + 2]; };
            const double p = cloud_perlin_fbm(seed, x, y, z), w4 = fbm(0);
            return std::array<double, 4>{clamp01((p - (w4 - 1.0)) / (2.0 - w4)), w4, fbm(1), fbm(2)};
        });
    });
    noise.detail = detail_cache.get(seed, [&] {
        return build_texture("cloud_detail", shader::CLOUD_DETAIL_SIZE, [&](double x, double y, double z) {
            return std::array<double, 4>{cloud_worley(seed + 1, 2, x, y, z), cloud_worley(seed + 1, 4, x, y, z),
                                         cloud_worley(seed + 1, 8, x, y, z), cloud_worley(seed + 1, 16, x, y, z)};
        });
    });
    return noise;
}

}  // namespace airlight
