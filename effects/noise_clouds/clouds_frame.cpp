// The noise clouds' part of the frame (physics.md): the layer's parameters,
// the wind's drift as a fraction of each texture's tile (formed in double, so
// that long times keep their precision), and the two noise textures, built
// only when a scene has clouds that can be seen.
#include <cmath>

#include "frame_data.hpp"
#include "noise.hpp"
#include "weather_map.hpp"

namespace airlight {

namespace {

// Multiple scattering's octaves (physics.md eq. 6.1): each octave's weight,
// optical-depth and asymmetry factors and their count, fitted to Mitsuba 3's
// path tracer with a <= b (effects/noise_clouds/docs/multiple_scattering.md,
// effects/noise_clouds/docs/fit_octaves.txt:
// median error 47 % where single scattering's is 90 %; thick clouds stay far
// too dark).
constexpr float OCTAVE_WEIGHT = 0.5434f;
constexpr float OCTAVE_DEPTH = 0.5434f;
constexpr float OCTAVE_ASYMMETRY = 0.6092f;
constexpr int OCTAVE_COUNT = 8;

// fract(x) of a drift in tile units, in double.
float tile_fraction(double x) { return float(x - std::floor(x)); }

}  // namespace

void pack_noise_clouds_frame(const Scene& scene, FrameData& data) {
    const Clouds& c = scene.clouds;
    data.features.clouds = clouds_visible(c);
    if (!data.features.clouds) return;
    data.features.clouds_march = scene.quality.clouds == CloudsMethod::march;
    shader::CloudsGpu& g = data.frame.clouds;
    g.layer = glm::vec4(c.base, c.top, float(1.0 / (double(c.top) - double(c.base))), c.extinction);
    g.tiles = glm::vec4(float(1.0 / double(c.shape_scale)), float(1.0 / double(c.detail_scale)), 0.0f, 0.0f);
    const double dx = double(c.wind_x) * double(c.time), dz = double(c.wind_z) * double(c.time);
    g.offsets = glm::vec4(tile_fraction(dx / c.shape_scale), tile_fraction(dz / c.shape_scale),
                          tile_fraction(dx / c.detail_scale), tile_fraction(dz / c.detail_scale));
    g.density = glm::vec4(c.coverage, c.type, c.erosion, c.albedo);
    g.phase = glm::vec4(c.second_g, c.second_weight, c.powder, 0.0f);
    g.lighting = glm::vec4(c.g, float(scene.quality.cloud_steps), float(scene.quality.cloud_light_steps),
                           float(scene.quality.cloud_shadow_steps));
    g.octaves = scene.quality.multiple_scattering
                    ? glm::vec4(OCTAVE_WEIGHT, OCTAVE_DEPTH, OCTAVE_ASYMMETRY, float(OCTAVE_COUNT))
                    : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    if (const WeatherMap& m = c.weather_map; m.texels) {
        // The map's corner (centre - size / 2) drifts with the wind like the noise.
        data.features.clouds_weather_map = true;
        g.weather = glm::vec4(float(1.0 / double(m.size_x)), float(1.0 / double(m.size_z)),
                              tile_fraction((double(m.center_x) - 0.5 * m.size_x + dx) / m.size_x),
                              tile_fraction((double(m.center_z) - 0.5 * m.size_z + dz) / m.size_z));
        g.weather_texels = glm::ivec4(m.texels->width, m.texels->height, 0, 0);
        data.use_table(shader::TABLE_CLOUD_WEATHER, m.texels);
    }
    const CloudNoise noise = cloud_noise_textures(c.seed);
    data.use_table(shader::TABLE_CLOUD_SHAPE, noise.shape);
    data.use_table(shader::TABLE_CLOUD_DETAIL, noise.detail);
}

}  // namespace airlight
