// The noise clouds' part of the frame (physics.md): the layer's parameters,
// the wind's drift as a fraction of each texture's tile (formed in double, so
// that long times keep their precision), and the two noise textures, built
// only when a scene has clouds that can be seen.
#include <cmath>

#include "frame_data.hpp"
#include "noise.hpp"

namespace airlight {

namespace {

// fract(x) of a drift in tile units, in double.
float tile_fraction(double x) { return float(x - std::floor(x)); }

}  // namespace

void pack_noise_clouds_frame(const Scene& scene, FrameData& data) {
    const Clouds& c = scene.clouds;
    data.features.clouds = c.present && c.coverage > 0.0f && c.extinction > 0.0f;
    if (!data.features.clouds) return;
    data.features.clouds_march = scene.quality.clouds == CloudsMethod::march;
    shader::CloudsGpu& g = data.frame.clouds;
    g.layer = glm::vec4(c.base, c.top, float(1.0 / (double(c.top) - double(c.base))), c.extinction);
    g.tiles = glm::vec4(float(1.0 / double(c.shape_scale)), float(1.0 / double(c.detail_scale)), 0.0f, 0.0f);
    const double dx = double(c.wind_x) * double(c.time), dz = double(c.wind_z) * double(c.time);
    g.offsets = glm::vec4(tile_fraction(dx / c.shape_scale), tile_fraction(dz / c.shape_scale),
                          tile_fraction(dx / c.detail_scale), tile_fraction(dz / c.detail_scale));
    g.density = glm::vec4(c.coverage, c.type, c.erosion, c.albedo);
    g.lighting = glm::vec4(c.g, float(scene.quality.cloud_steps), float(scene.quality.cloud_light_steps), 0.0f);
    const CloudNoise noise = cloud_noise_textures(c.seed);
    data.use_table(shader::TABLE_CLOUD_SHAPE, noise.shape);
    data.use_table(shader::TABLE_CLOUD_DETAIL, noise.detail);
}

}  // namespace airlight
