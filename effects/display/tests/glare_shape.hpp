// The shape of the glare of one bright pixel (issue 17; effects/display/physics.md section 3,
// "Support"): round (pixels at the same distance from the source agree) and falling off along
// rays from it. Shared by test_glare.cpp (the CPU's FFT and splat paths) and test_gl_display.cpp
// (the GPU's FFT).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "airlight/renderer.hpp"

namespace glare_shape {

struct Shape {
    double asymmetry = 0.0;  // worst (max - min) / max over pixels at the same distance, at least min_distance
    double asymmetry_at = 0.0;
    int rises = 0;         // steps along the 16 rays where the glare grows by more than `zero`
    double support = 0.0;  // the farthest pixel above `zero`
};

// Channel c of `im` around the source at (cx, cy); values at or below `zero` count as 0.
inline Shape measure(const airlight::Image& im, int cx, int cy, int c, int min_distance, double zero) {
    const auto at = [&](int x, int y) { return double(im.rgb[(size_t(y) * im.width + x) * 3 + c]); };
    Shape s;
    std::map<int, std::vector<double>> rings;  // by squared distance
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) {
            const int d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
            const double v = at(x, y) > zero ? at(x, y) : 0.0;
            if (v > 0.0) s.support = std::max(s.support, std::sqrt(double(d2)));
            if (d2 >= min_distance * min_distance) rings[d2].push_back(v);
        }
    for (const auto& [d2, values] : rings) {
        const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
        if (values.size() < 2 || *hi <= 0.0) continue;
        const double a = (*hi - *lo) / *hi;
        if (a > s.asymmetry) {
            s.asymmetry = a;
            s.asymmetry_at = std::sqrt(double(d2));
        }
    }
    const int rays[16][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1},  {1, -1}, {-1, 1},  {-1, -1},
                             {2, 1}, {1, 2}, {-2, 1}, {-1, 2}, {2, -1}, {1, -2}, {-2, -1}, {-1, -2}};
    for (const auto& r : rays) {
        for (int k = 1;; ++k) {
            const int x = cx + k * r[0], y = cy + k * r[1];
            if (x < 0 || y < 0 || x >= im.width || y >= im.height) break;
            if (at(x, y) > at(x - r[0], y - r[1]) + zero) ++s.rises;
        }
    }
    return s;
}

}  // namespace glare_shape
