// The falling rain's drops (effects/falling_rain/physics.md sections 1-3):
// the Marshall-Palmer size distribution, the terminal fall speed, and the
// drops around the camera at a time, each a fixed member of a stationary
// rain field that keeps its identity from frame to frame.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <vector>

#include "falling_rain_scene.hpp"

namespace airlight {

// The diameters drawn (mm): Marshall-Palmer's exponential is cut at these
// (section 1; below 0.1 mm drops are drizzle, above 6 mm they break up).
constexpr double RAIN_DROP_MIN_MM = 0.1;
constexpr double RAIN_DROP_MAX_MM = 6.0;
// Size classes of the rain field (section 3), geometric in D over [min, max].
constexpr int RAIN_DROP_CLASSES = 24;
// Drops fade out over the outer share of their distance limit (section 2).
constexpr double FALLING_RAIN_FADE = 0.25;
// At most this many drops a frame (the tables' memory bound, section 5).
constexpr std::size_t FALLING_RAIN_MAX_DROPS = std::size_t(1) << 21;
// At most this many drops, expected, within their draw distances (the time bound, section 3).
constexpr std::size_t FALLING_RAIN_MAX_SPHERE = std::size_t(1) << 24;

// Marshall-Palmer N(D) = N0 exp(-Lambda D) (eq. 1.1): N0 is MARSHALL_PALMER_N0
// (effects/daytime/sky.hpp), Lambda marshall_palmer_slope (effects/rainbow/rainbow.hpp).
// Terminal fall speed (m/s) of a drop of diameter d_mm (eq. 1.2): a rigid sphere
// under the Schiller-Naumann drag law in air at 20 C and 1013 hPa below
// rain_speed_crossing_mm(), Atlas et al.'s fit to Gunn and Kinzer,
// 9.65 - 10.3 exp(-0.6 D), above it (where the two meet, about 0.51 mm).
double terminal_speed(double d_mm);
double rain_speed_crossing_mm();
// Drops per m^3 with diameters in [lo, hi] mm, and their water (g/m^3), eq. 1.3.
double rain_number_density(double rate, double lo_mm, double hi_mm);
double rain_water_content(double rate, double lo_mm, double hi_mm);

// The distance out to which a drop of diameter d_mm is drawn (eq. 2.1) and its
// weight at distance `dist` (1 inside, a smoothstep to 0 over the fade, eq. 2.2).
double rain_draw_distance(const FallingRain& rain, double d_mm);
double rain_draw_weight(const FallingRain& rain, double d_mm, double dist);

// The drawn drops' geometric cross-section per m^3 at distance `dist` from the
// camera (1/m; eq. 2.3): integral of N(D) w(D, dist) pi D^2 / 4 over the drawn
// diameters, the expected share of a ray's length they cover.
double rain_drawn_cross_section(const FallingRain& rain, double dist);

struct RainDrop {
    glm::dvec3 position;   // m, world, at the middle of the exposure
    glm::dvec3 velocity;   // m/s
    double diameter = 0;   // mm
    double weight = 0;     // eq. 2.2 at the middle of the exposure
    std::uint64_t id = 0;  // the same drop keeps its id in every frame
};

// The drops whose distance from `camera` at the middle of the exposure
// [rain.time - exposure, rain.time] is within their draw distance (section 3)
// and that `keep` (when given) keeps; throws std::runtime_error naming the
// keys once more than FALLING_RAIN_MAX_DROPS would be drawn.
std::vector<RainDrop> rain_drops(const FallingRain& rain, const glm::dvec3& camera, double exposure,
                                 const std::function<bool(const RainDrop&)>& keep = {});

}  // namespace airlight
