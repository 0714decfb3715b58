// The particle clouds' scene key "particle_clouds" and quality keys
// "particle_table", "particle_compositing" (README "Scene format"; physics.md section 4), parsed and
// written back through the registry (EFFECT_SCENE_KEYS, EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp).
#include <string>

#include "cloud_layer_keys.hpp"
#include "particle_field.hpp"
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {

const NameTable<ParticleTableQuality> table_qualities{{"full", ParticleTableQuality::full},
                                                      {"preview", ParticleTableQuality::preview}};
const NameTable<ParticleCompositing> compositings{{"tiles", ParticleCompositing::tiles},
                                                  {"all", ParticleCompositing::all}};

ParticleClouds parse_particle_clouds(const SceneObject& o) {
    o.check_keys(
        cloud_layer_keys_and({"threshold", "g", "cell_size", "ring_cells", "rings", "particle_size", "detail_scale"}));
    ParticleClouds c;
    parse_cloud_layer(o, c);
    if (auto v = o.opt("threshold")) c.threshold = read_in_range(*v, 0.0, 0.99);
    if (auto v = o.opt("g")) c.g = read_in_range(*v, 0.0, 0.95);
    if (auto v = o.opt("cell_size")) c.cell_size = read_in_range(*v, 1.0, 1e5, " m");
    if (auto v = o.opt("ring_cells")) c.ring_cells = read_int(*v, 2, 512);
    if (auto v = o.opt("rings")) c.rings = read_int(*v, 1, 12);
    // The rings' cells (PARTICLE_MAX_CELLS bounds the modelling's memory).
    const size_t cells = size_t(c.rings) * size_t(2 * c.ring_cells + 3) * size_t(2 * c.ring_cells + 3);
    if (cells > PARTICLE_MAX_CELLS)
        fail(Kind::value, join_path(o.path, "ring_cells"),
             "rings x (2 ring_cells + 3)^2 = " + std::to_string(cells) + " cells, more than " +
                 std::to_string(PARTICLE_MAX_CELLS) + "; lower ring_cells or rings");
    if (auto v = o.opt("particle_size")) c.particle_size = read_in_range(*v, 0.1, 4.0);
    if (auto v = o.opt("detail_scale")) c.detail_scale = read_in_range(*v, 1.0, 1e7, " m");
    return c;
}

}  // namespace

// After the noise clouds (effects/registry.cmake): a scene has one cloud method.
void parse_particle_clouds_keys(const SceneObject& top, Scene& s) {
    auto v = top.opt("particle_clouds");
    if (!v || v->j.is_null()) return;
    if (s.clouds.present)
        fail(Kind::value, v->field,
             "a scene has one cloud method: give either \"clouds\" (noise clouds) or \"particle_clouds\"");
    s.particle_clouds = parse_particle_clouds(SceneObject(*v));
}

void write_particle_clouds_keys(const Scene& s, json& j) {
    if (!s.particle_clouds.present) {
        j["particle_clouds"] = nullptr;
        return;
    }
    const ParticleClouds& c = s.particle_clouds;
    j["particle_clouds"] = {{"threshold", json_number(c.threshold)},
                            {"g", json_number(c.g)},
                            {"cell_size", json_number(c.cell_size)},
                            {"ring_cells", c.ring_cells},
                            {"rings", c.rings},
                            {"particle_size", json_number(c.particle_size)},
                            {"detail_scale", json_number(c.detail_scale)}};
    write_cloud_layer(c, j["particle_clouds"]);
}

// Every preset keeps the full table and the tiles: the preview table is not
// accurate for thick particles (physics.md section 3), and the tiles give the
// same image as testing every particle, faster.
void preset_particle_clouds_quality(QualityPreset, Scene&) {}

void parse_particle_clouds_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("particle_table"))
        s.quality.particle_table = read_enum(*v, "particle_table", table_qualities);
    if (auto v = quality.opt("particle_compositing"))
        s.quality.particle_compositing = read_enum(*v, "particle_compositing", compositings);
}

void write_particle_clouds_quality(const Scene& s, json& quality) {
    quality["particle_table"] = name_of(table_qualities, s.quality.particle_table);
    quality["particle_compositing"] = name_of(compositings, s.quality.particle_compositing);
}

}  // namespace airlight
