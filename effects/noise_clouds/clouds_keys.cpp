// The noise clouds' scene key "clouds" and quality keys "clouds",
// "cloud_steps", "cloud_light_steps" (README "Scene format"; physics.md),
// parsed and written back through the registry (EFFECT_SCENE_KEYS,
// EFFECT_QUALITY_KEYS; cpp/scene_keys.hpp).
#include <string>

#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {

const NameTable<CloudsMethod> clouds_methods{{"adaptive", CloudsMethod::adaptive}, {"march", CloudsMethod::march}};

Clouds parse_clouds(const SceneObject& o) {
    o.check_keys({"base", "top", "coverage", "type", "extinction", "albedo", "g", "erosion", "shape_scale",
                  "detail_scale", "wind", "time", "seed"});
    Clouds c;
    c.present = true;
    if (auto v = o.opt("base")) c.base = read_in_range(*v, 0.0, 1e5, " m");
    if (auto v = o.opt("top")) {
        c.top = read_in_range(*v, 0.0, 1e5, " m");
        if (!(c.top > c.base)) fail(Kind::value, v->field, "must be above the base (" + std::to_string(c.base) + " m)");
    } else if (!(c.top > c.base)) {
        fail(Kind::value, join_path(o.path, "base"), "must be below the top (" + std::to_string(c.top) + " m)");
    }
    if (auto v = o.opt("coverage")) c.coverage = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("type")) c.type = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("extinction")) c.extinction = read_in_range(*v, 0.0, 1e3, " 1/m");
    if (auto v = o.opt("albedo")) c.albedo = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("g")) c.g = read_asymmetry(*v);
    if (auto v = o.opt("erosion")) c.erosion = read_in_range(*v, 0.0, 0.95);
    if (auto v = o.opt("shape_scale")) c.shape_scale = read_in_range(*v, 1.0, 1e7, " m");
    if (auto v = o.opt("detail_scale")) c.detail_scale = read_in_range(*v, 0.1, 1e7, " m");
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

void parse_noise_clouds_keys(const SceneObject& top, Scene& s) {
    if (auto v = top.opt("clouds"); v && !v->j.is_null()) s.clouds = parse_clouds(SceneObject(*v));
}

void write_noise_clouds_keys(const Scene& s, json& j) {
    if (!s.clouds.present) {
        j["clouds"] = nullptr;
        return;
    }
    const Clouds& c = s.clouds;
    j["clouds"] = {{"base", json_number(c.base)},
                   {"top", json_number(c.top)},
                   {"coverage", json_number(c.coverage)},
                   {"type", json_number(c.type)},
                   {"extinction", json_number(c.extinction)},
                   {"albedo", json_number(c.albedo)},
                   {"g", json_number(c.g)},
                   {"erosion", json_number(c.erosion)},
                   {"shape_scale", json_number(c.shape_scale)},
                   {"detail_scale", json_number(c.detail_scale)},
                   {"wind", json::array({json_number(c.wind_x), json_number(c.wind_z)})},
                   {"time", json_number(c.time)},
                   {"seed", c.seed}};
}

void parse_noise_clouds_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("clouds")) s.quality.clouds = read_enum(*v, "clouds", clouds_methods);
    if (auto v = quality.opt("cloud_steps")) s.quality.cloud_steps = read_int(*v, 4, 4096);
    if (auto v = quality.opt("cloud_light_steps")) s.quality.cloud_light_steps = read_int(*v, 1, 1024);
}

void write_noise_clouds_quality(const Scene& s, json& quality) {
    quality["clouds"] = name_of(clouds_methods, s.quality.clouds);
    quality["cloud_steps"] = s.quality.cloud_steps;
    quality["cloud_light_steps"] = s.quality.cloud_light_steps;
}

}  // namespace airlight
