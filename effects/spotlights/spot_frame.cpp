// The spotlights' part of the frame: the spots as the shaders read them,
// their switches and, in an isotropic medium, their table.
#include "spot_frame.hpp"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

#include "numerics.hpp"
#include "screen_tiles.hpp"
#include "spot_tables.hpp"

namespace airlight {

namespace {

// The spots each screen tile's view rays can meet (physics.md section 9): a
// spot is left out of a tile's list when one of the planes through the camera
// that bound the tile's rays (its four sides, and the plane of the camera
// facing away from the view) leaves the spot's whole beam (its cone, apex
// widened to the lamp's sphere) strictly outside, with a margin: n . (S - C)
// > r + margin and n . a >= sin(A + margin), n the plane's outward unit
// normal. Such a beam meets no ray of the tile, whose spot_lit_interval would
// find no lit part: the skip changes nothing.
ScreenTiles spot_tiles(const Scene& scene, const FrameData& data, int tile_size) {
    const shader::FrameUniforms& f = data.frame;
    const int width = f.film_width, height = f.film_height;
    ScreenTiles tiles;
    tiles.tiles_x = (width + tile_size - 1) / tile_size;
    tiles.tiles_y = (height + tile_size - 1) / tile_size;
    const glm::dvec3 forward(f.camera_forward), right(f.camera_right), up(f.camera_up);
    // The (unnormalised) ray through film point (x, row) in pixels, at a pixel's corner.
    auto ray = [&](int x, int row) {
        return forward + (2.0 * x / width - 1.0) * right + (1.0 - 2.0 * row / height) * up;
    };
    constexpr double margin = 1e-4;  // radians, and relative to the spot's distance
    tiles.offsets.push_back(0);
    for (int ty = 0; ty < tiles.tiles_y; ++ty)
        for (int tx = 0; tx < tiles.tiles_x; ++tx) {
            const int x0 = tx * tile_size, x1 = std::min(x0 + tile_size, width);
            const int y0 = ty * tile_size, y1 = std::min(y0 + tile_size, height);
            const glm::dvec3 top_left = ray(x0, y0), top_right = ray(x1, y0), bottom_left = ray(x0, y1),
                             bottom_right = ray(x1, y1);
            // Outward normals: each side's two corner rays crossed, away from the tile's middle ray.
            const glm::dvec3 middle = top_left + top_right + bottom_left + bottom_right;
            glm::dvec3 planes[5] = {glm::cross(top_left, bottom_left), glm::cross(bottom_right, top_right),
                                    glm::cross(top_right, top_left), glm::cross(bottom_left, bottom_right), -forward};
            for (glm::dvec3& n : planes) {
                n = glm::normalize(n);
                if (glm::dot(n, middle) > 0.0) n = -n;
            }
            for (int i = 0; i < int(scene.spot_lights.size()); ++i) {
                const SpotLight& spot = scene.spot_lights[size_t(i)];
                const glm::dvec3 apex = glm::dvec3(spot.position) - glm::dvec3(scene.camera.position);
                const glm::dvec3 axis = glm::normalize(glm::dvec3(spot.direction));
                const double reach =
                    std::sin(std::min(glm::radians(double(spot.cone_angle_degrees)) + margin, 0.5 * numerics::kPi));
                bool outside = false;
                for (const glm::dvec3& n : planes)
                    outside |= glm::dot(n, apex) > double(spot.radius) + margin * glm::length(apex) &&
                               glm::dot(n, axis) >= reach;
                if (!outside) tiles.entries.push_back(i);
            }
            tiles.offsets.push_back(int(tiles.entries.size()));
        }
    return tiles;
}

}  // namespace

void pack_spotlights_frame(const Scene& scene, FrameData& data) {
    data.frame.spot.glow_samples = float(scene.quality.spot_glow_samples);
    // What loses precision in float32 (the position relative to the camera,
    // sin^2 A, 1 - cos A) is formed in double (effects/spotlights/docs/spot_table.md).
    for (const SpotLight& spot : scene.spot_lights) {
        const glm::dvec3 relative = glm::dvec3(spot.position) - glm::dvec3(scene.camera.position);
        const glm::dvec3 axis = glm::normalize(glm::dvec3(spot.direction));
        const double angle = glm::radians(double(spot.cone_angle_degrees));
        const double sin_half = std::sin(0.5 * angle), one_minus_cos = 2.0 * sin_half * sin_half;
        const double q = spot.edge;
        shader::SpotLightGpu g{};
        g.relative_position_radius = glm::vec4(glm::vec3(relative), spot.radius);
        g.world_position = glm::vec4(spot.position, 0.0f);
        g.axis_cos = glm::vec4(glm::vec3(axis), float(std::cos(angle)));
        g.intensity_edge = glm::vec4(spot.intensity, float(q));
        g.cone = glm::vec4(float(std::sin(angle) * std::sin(angle)), float(one_minus_cos),
                           float((1.0 - q) / one_minus_cos), spot.volumetric_shadows ? 1.0f : 0.0f);
        data.spot_lights.push_back(g);
    }
    data.frame.spot_light_count = int(data.spot_lights.size());
    data.features.spot_lights = !data.spot_lights.empty();
    data.features.spot_airlight = data.scattering && !data.spot_lights.empty();
    data.frame.spot.tiles = glm::ivec4(0);
    if (data.features.spot_airlight && scene.quality.spot_lists == SpotLists::tiles) {
        const ScreenTiles tiles = spot_tiles(scene, data, shader::SPOT_TILE_SIZE);
        data.frame.spot.tiles = glm::ivec4(tiles.tiles_x, tiles.tiles_y, 0, shader::SPOT_TILE_SIZE);
        data.use_table(shader::TABLE_SPOT_TILES,
                       row_table("spot_tiles", 1, shader::SPOT_ROW_TEXELS, screen_tile_texels(tiles)));
    }
}

void pick_spotlights_tables(const Scene&, FrameData& data) {
    if (data.features.phase) return;  // the phase effect's per-lobe tables take its place
    if (needs_spot_moments(data)) data.tables[shader::TABLE_SPOT_MOMENTS] = &spot_moment_table();
}

}  // namespace airlight
