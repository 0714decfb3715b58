// The particle clouds' scene key "particle_clouds" and quality keys
// "particle_table", "particle_compositing" (README "Scene format"; physics.md section 4), parsed and
// written back through the registry (EFFECT_SCENE_KEYS, EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp).
#include <string>

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
    o.check_keys({"base", "top", "coverage", "threshold", "extinction", "g", "cell_size", "ring_cells", "rings",
                  "particle_size", "shape_scale", "detail_scale", "wind", "time", "seed"});
    ParticleClouds c;
    c.present = true;
    if (auto v = o.opt("base")) c.base = read_in_range(*v, 0.0, 1e5, " m");
    if (auto v = o.opt("top")) {
        c.top = read_in_range(*v, 0.0, 1e5, " m");
        if (!(c.top > c.base)) fail(Kind::value, v->field, "must be above the base (" + std::to_string(c.base) + " m)");
    } else if (!(c.top > c.base)) {
        fail(Kind::value, join_path(o.path, "base"), "must be below the top (" + std::to_string(c.top) + " m)");
    }
    if (auto v = o.opt("coverage")) c.coverage = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("threshold")) c.threshold = read_in_range(*v, 0.0, 0.99);
    if (auto v = o.opt("extinction")) c.extinction = read_in_range(*v, 0.0, 1e3, " 1/m");
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
    if (auto v = o.opt("shape_scale")) c.shape_scale = read_in_range(*v, 1.0, 1e7, " m");
    if (auto v = o.opt("detail_scale")) c.detail_scale = read_in_range(*v, 1.0, 1e7, " m");
    if (auto v = o.opt("wind")) {
        if (!v->j.is_array() || v->j.size() != 2)
            fail(Kind::type, v->field, "expected [vx, vz] (m/s), got " + type_name(v->j));
        c.wind_x = read_in_range(Value{v->j[0], index_path(v->field, 0)}, -1e3, 1e3, " m/s");
        c.wind_z = read_in_range(Value{v->j[1], index_path(v->field, 1)}, -1e3, 1e3, " m/s");
    }
    if (auto v = o.opt("time")) c.time = read_in_range(*v, -1e7, 1e7, " s");
    if (auto v = o.opt("seed")) c.seed = read_int(*v, 0, 1 << 30);
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
    j["particle_clouds"] = {{"base", json_number(c.base)},
                            {"top", json_number(c.top)},
                            {"coverage", json_number(c.coverage)},
                            {"threshold", json_number(c.threshold)},
                            {"extinction", json_number(c.extinction)},
                            {"g", json_number(c.g)},
                            {"cell_size", json_number(c.cell_size)},
                            {"ring_cells", c.ring_cells},
                            {"rings", c.rings},
                            {"particle_size", json_number(c.particle_size)},
                            {"shape_scale", json_number(c.shape_scale)},
                            {"detail_scale", json_number(c.detail_scale)},
                            {"wind", json::array({json_number(c.wind_x), json_number(c.wind_z)})},
                            {"time", json_number(c.time)},
                            {"seed", c.seed}};
}

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
