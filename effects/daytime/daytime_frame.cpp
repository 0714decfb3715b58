// The daytime part of the frame (effects/daytime/physics.md): sky, sun, the
// atmosphere's species and altitude levels, the switches and the sky-phase
// table where the scene needs it.
#include <algorithm>
#include <glm/glm.hpp>
#include <vector>

#include "frame_data.hpp"
#include "sky.hpp"

namespace airlight {

// quality.aerial_table "auto" (effects/daytime/docs/aerial_table.md section 6):
// 16 nodes for a camera near the ground, where the table was measured as close
// to the float64 sweep as the volumes at 16 levels and closer to the march (and
// the path tracer) in rain; the volumes on films smaller than 320 x 180 (the
// table's build, a fixed cost per frame, outweighs their cost per pixel) and
// for higher cameras (1.7 % at 500 m with 16 nodes; 32 nodes cost more per
// frame than the volumes but on big films).
static int auto_aerial_nodes(const Scene& scene) {
    constexpr long min_pixels = 320 * 180;
    constexpr float street_camera = 20.0f;  // m (the sweep's ground cameras: 0 and 1.7 m)
    if (long(scene.film.width) * long(scene.film.height) < min_pixels) return 0;
    return scene.camera.position.y <= street_camera ? 16 : 0;
}

// The aerial table's size and grid passes (aerial_table.glsl), when the
// scene asks for it and has an atmosphere that is not marched.
static void pack_aerial_table(const Scene& scene, FrameData& data) {
    const int nodes =
        scene.quality.aerial_table == AERIAL_TABLE_AUTO ? auto_aerial_nodes(scene) : scene.quality.aerial_table;
    // Clouds walk the volumes over their stretches (effects/daytime/docs/aerial_table.md section 4).
    if (nodes <= 0 || !data.features.atmosphere || data.features.sky_march || clouds_visible(scene.clouds) ||
        particle_clouds_visible(scene.particle_clouds))
        return;
    shader::FrameUniforms& f = data.frame;
    const int rows = 12 * nodes + 1;  // odd: the horizon is a row
    // The diffuse light depends on the azimuth from the sun with a sun (its
    // multiple scattering) or a sky with an indicatrix.
    const bool azimuth = data.features.sun || f.atmosphere.sky_table_azimuth_blocks > 1.0f;
    // (rows x azimuths rows of texels: within GL's 16384)
    const int azimuths = azimuth ? std::min(nodes, shader::AERIAL_MAX_TEXTURE_ROWS / rows) : 1;
    glm::vec2 toward(f.sky.sun_direction.x, f.sky.sun_direction.z);
    const float length = glm::length(toward);
    toward = length > 1e-6f ? toward / length : glm::vec2(1.0f, 0.0f);
    f.aerial.size = glm::vec4(float(rows), float(azimuths), float(nodes), 0.0f);
    f.aerial.sun_axes = glm::vec4(toward.x, toward.y, -toward.y, toward.x);
    data.features.aerial_table = true;
    const int parts_width = shader::AERIAL_GROUPS * nodes;
    data.grid_passes.push_back({shader::TABLE_AERIAL_SEGMENTS, parts_width, rows, 4});
    data.grid_passes.push_back({shader::TABLE_AERIAL_DIFFUSE_SEGMENTS, nodes, rows * azimuths, 4});
    data.grid_passes.push_back({shader::TABLE_AERIAL, parts_width, rows, 4});
    data.grid_passes.push_back({shader::TABLE_AERIAL_DIFFUSE, nodes, rows * azimuths, 4});
}

void pack_daytime_frame(const Scene& scene, FrameData& data) {
    shader::FrameUniforms& f = data.frame;
    f.sky = make_sky_gpu(scene.sky, scene.sun);
    make_species_gpu(scene.atmosphere, f.species);
    data.features.sky =
        scene.sky.model != SkyModel::none && glm::any(glm::greaterThan(scene.sky.zenith_radiance, glm::vec3(0.0f)));
    data.features.sun = f.sky.sun_direction.w != 0.0f;
    data.features.atmosphere = false;
    for (const shader::SpeciesGpu& species : f.species) data.features.atmosphere |= species.phase.z != 0.0f;
    data.features.sky_march = data.features.atmosphere && scene.quality.airlight == AirlightMethod::march;
    float top = 0.0f;
    std::vector<float> levels;
    if (data.features.atmosphere) levels = make_altitude_levels(f.species, scene.quality.sky_segments, top);
    for (size_t k = 0; k < levels.size() && k < size_t(shader::ATMOSPHERE_MAX_LEVELS); ++k)
        f.atmosphere.levels[k / 4][int(k % 4)] = levels[k];
    // The table: with its columns for a sky that lights an atmosphere, C = 0
    // only for one that lights surfaces or clouds (effects/noise_clouds, particle_clouds)
    // through clear air.
    const bool columns = data.features.sky && data.features.atmosphere;
    const Table2D* sky_table = nullptr;
    if (columns || (data.features.sky && (data.features.surfaces || clouds_visible(scene.clouds) ||
                                          particle_clouds_visible(scene.particle_clouds)))) {
        data.use_table(shader::TABLE_SKY_PHASE, sky_phase_table(f.sky, f.species, columns));
        sky_table = data.tables[shader::TABLE_SKY_PHASE];
    }
    f.atmosphere.top = top;
    f.atmosphere.level_count = float(std::min(levels.size(), size_t(shader::ATMOSPHERE_MAX_LEVELS)));
    f.atmosphere.sky_table_columns = sky_table ? float(sky_table->width) : 1.0f;
    f.atmosphere.sky_table_azimuth_blocks = sky_table ? float(sky_table->height / shader::SKY_TABLE_N_ELEVATION) : 1.0f;
    pack_aerial_table(scene, data);
}

}  // namespace airlight
