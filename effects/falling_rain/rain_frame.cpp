// The falling rain's part of the frame (physics.md sections 3-5): the drops
// in view for the frame's exposure, their streaks binned into screen tiles,
// the drop's optics table and the grid pass that lights each drop; nothing
// for a scene without falling rain.
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <stdexcept>
#include <string>

#include "drop_optics.hpp"
#include "drops.hpp"
#include "frame_data.hpp"
#include "numerics.hpp"
#include "rainbow.hpp"
#include "screen_tiles.hpp"
#include "sky.hpp"

namespace airlight {

namespace {

// The mean screen-tile list length above which the tiles are made finer (section 5).
constexpr int RAIN_TILE_LIST = 64;

// The optics table (eq. 4.3): the phase function f(theta) over
// DROP_OPTICS_BINS bins of theta; RGB for water at 610, 550 and 465 nm.
Table2D build_drop_optics() {
    constexpr int bins = shader::DROP_OPTICS_BINS;
    Table2D t;
    t.width = bins;
    t.height = 1;
    t.channels = 4;
    t.texels.assign(size_t(bins) * 4, 0.0f);
    const double wavelengths[3] = {610.0, 550.0, 465.0};
    for (int c = 0; c < 3; ++c) {
        const double n = water_refractive_index(wavelengths[c]);
        std::vector<double> f(bins, 0.0);
        for (int p = 0; p < DROP_ORDERS; ++p) {
            const std::vector<double> fp = drop_phase_order(n, p, bins, 1 << 20);
            for (int b = 0; b < bins; ++b) f[size_t(b)] += fp[size_t(b)];
        }
        for (int b = 0; b < bins; ++b) t.texels[size_t(b) * 4 + c] = float(f[size_t(b)]);
    }
    return t;
}

// Whether any light can reach a drop (section 5): a lamp, a spot, the sun
// above the horizon, a sky, a background or the medium's constant light. A
// scene with none sees no drop and pays nothing for them.
bool light_can_show_a_drop(const Scene& scene) {
    const auto positive = [](const Rgb& c) { return glm::any(glm::greaterThan(c, Rgb(0.0f))); };
    const bool sun = scene.sun.present && scene.sun.direction.y > 0.0f && positive(scene.sun.irradiance);
    const bool sky = scene.sky.model != SkyModel::none && positive(scene.sky.zenith_radiance);
    return !scene.point_lights.empty() || !scene.spot_lights.empty() || sun || sky || positive(scene.background) ||
           positive(scene.atmospheric_light);
}

}  // namespace

void pack_falling_rain_frame(const Scene& scene, FrameData& data) {
    const FallingRain& rain = scene.falling_rain;
    // Not yet drawn over a photograph (a backplate ends the ray before the pixel_cores hook; section 6).
    if (!rain.present || !(rain.rate > 0.0f) || !light_can_show_a_drop(scene) || scene.backplate.rgbd) return;
    const glm::dvec3 camera(scene.camera.position);
    const glm::dvec3 right(glm::vec3(data.frame.camera_right)), up(glm::vec3(data.frame.camera_up)),
        forward(glm::vec3(data.frame.camera_forward));
    const int width = data.frame.film_width, height = data.frame.film_height;
    const double exposure = scene.camera.exposure_time;
    // A streak's pixel rectangle (section 5): its ends cut at RAIN_NEAR, projected, grown by the
    // drop's half width and a pixel; x1 < x0 when it misses the film.
    const auto rectangle = [&](const RainDrop& d) {
        glm::dvec3 a = d.position - 0.5 * exposure * d.velocity - camera;
        glm::dvec3 b = d.position + 0.5 * exposure * d.velocity - camera;
        const double near = double(shader::RAIN_NEAR);
        const double za = glm::dot(a, forward), zb = glm::dot(b, forward);
        if (za < near && zb < near) return glm::ivec4(0, -1, 0, -1);
        if (za < near) a += (b - a) * ((near - za) / (zb - za));
        if (zb < near) b += (a - b) * ((near - zb) / (za - zb));
        double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300, z_min = 1e300;
        for (const glm::dvec3& q : {a, b}) {
            const double z = glm::dot(q, forward);
            const double x = 0.5 * (glm::dot(q, right) / (glm::dot(right, right) * z) + 1.0) * width;
            const double y = 0.5 * (1.0 - glm::dot(q, up) / (glm::dot(up, up) * z)) * height;
            x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x), y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
            z_min = std::min(z_min, z);
        }
        const double grow = 0.5e-3 * d.diameter / (z_min * 2.0 * glm::length(up) / height) + 1.0;
        x_lo -= grow, x_hi += grow, y_lo -= grow, y_hi += grow;
        if (x_hi < 0.0 || y_hi < 0.0 || x_lo >= width || y_lo >= height) return glm::ivec4(0, -1, 0, -1);
        return glm::ivec4(int(std::max(x_lo, 0.0)), int(std::min(x_hi, width - 1.0)), int(std::max(y_lo, 0.0)),
                          int(std::min(y_hi, height - 1.0)));
    };
    const std::vector<RainDrop> drops = rain_drops(rain, camera, exposure, [&](const RainDrop& d) {
        const glm::ivec4 r = rectangle(d);
        return r.y >= r.x && d.weight > 0.0;
    });
    if (drops.empty()) return;
    std::vector<glm::ivec4> rects;
    rects.reserve(drops.size());
    std::vector<float> texels;
    texels.reserve(drops.size() * 8);
    for (const RainDrop& d : drops) {
        rects.push_back(rectangle(d));
        const glm::dvec3 a = d.position - 0.5 * exposure * d.velocity - camera;
        const glm::dvec3 b = d.position + 0.5 * exposure * d.velocity - camera;
        for (double v : {a.x, a.y, a.z, 1e-3 * d.diameter, b.x, b.y, b.z, d.weight}) texels.push_back(float(v));
    }
    // Tiles of RAIN_TILE_SIZE pixels, halved while a tile's list averages more than RAIN_TILE_LIST
    // streaks (a small film sees many streaks a pixel; section 5), as long as the lists' bound holds.
    const std::string too_many =
        "falling_rain: the streaks in view cover more than 2^24 screen-tile entries (the tile lists' memory bound); "
        "lower falling_rain.radius or camera.exposure_time, or use a smaller film";
    int tile_size = shader::RAIN_TILE_SIZE;
    ScreenTiles tiles = bin_screen_rectangles(rects, width, height, tile_size, size_t(1) << 24, too_many);
    while (tile_size > 1 && tiles.entries.size() > size_t(RAIN_TILE_LIST) * tiles.offsets.size()) {
        try {
            ScreenTiles finer = bin_screen_rectangles(rects, width, height, tile_size / 2, size_t(1) << 24, too_many);
            tiles = std::move(finer);
            tile_size /= 2;
        } catch (const std::runtime_error&) {
            break;
        }
    }
    const int count = int(drops.size());
    data.features.falling_rain = true;
    data.frame.falling_rain.tiles = glm::ivec4(tiles.tiles_x, tiles.tiles_y, count, tile_size);
    data.use_table(shader::TABLE_RAIN_DROPS, row_table("rain_drops", 4, shader::RAIN_ROW_TEXELS, std::move(texels)));
    data.use_table(shader::TABLE_RAIN_TILES,
                   row_table("rain_tiles", 1, shader::RAIN_ROW_TEXELS, screen_tile_texels(tiles)));
    // The drops drawn stand for the medium's rain near the camera (eq. 2.4): its optical depth from the
    // camera to each distance, which the streaks' occlusion replaces, tabulated over [0, radius].
    const Atmosphere& atmosphere = scene.atmosphere;
    if (atmosphere.rain.present && camera.y < double(atmosphere.rain.top)) {
        const double sigma_medium = rain_extinction(atmosphere.rain.rate) * double(atmosphere.rain.density_scale);
        const int n = shader::RAIN_NEAR_DEPTH_TEXELS;
        const double step = double(rain.radius) / (n - 1);
        std::vector<float> depth(size_t(n), 0.0f);
        double tau = 0.0, before = 0.0;
        for (int i = 1; i < n; ++i) {
            // Trapezoids in distance; nothing is drawn nearer than RAIN_NEAR.
            const double r = i * step;
            const double here =
                r < double(shader::RAIN_NEAR) ? 0.0 : std::min(rain_drawn_cross_section(rain, r), sigma_medium);
            tau += 0.5 * (before + here) * step;
            before = here;
            depth[size_t(i)] = float(tau);
        }
        data.use_table(shader::TABLE_RAIN_NEAR_DEPTH, row_table("rain_near_depth", 1, n, std::move(depth)));
        data.frame.falling_rain.near_depth = glm::vec4(rain.radius, 1.0f, 0.0f, 0.0f);
    }
    data.tables[size_t(shader::TABLE_DROP_OPTICS)] = &table_built_once("drop_optics", build_drop_optics);
    data.grid_passes.push_back({shader::TABLE_RAIN_ENVIRONMENT, shader::RAIN_ENV_WIDTH, shader::RAIN_ENV_HEIGHT, 4});
    data.grid_passes.push_back({shader::TABLE_RAIN_SURROUND, shader::RAIN_ENV_WIDTH, shader::RAIN_ENV_HEIGHT, 4});
    data.grid_passes.push_back({shader::TABLE_RAIN_LIGHT, std::min(count, shader::RAIN_ROW_TEXELS),
                                (count + shader::RAIN_ROW_TEXELS - 1) / shader::RAIN_ROW_TEXELS, 4});
}

}  // namespace airlight
