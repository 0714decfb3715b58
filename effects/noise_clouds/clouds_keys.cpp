// The noise clouds' scene key "clouds" and quality keys "clouds",
// "cloud_steps", "cloud_light_steps", "cloud_shadow_steps" (README "Scene format"; physics.md),
// parsed and written back through the registry (EFFECT_SCENE_KEYS,
// EFFECT_QUALITY_KEYS; cpp/scene_keys.hpp).
#include <algorithm>
#include <stdexcept>
#include <string>

#include "cloud_layer_keys.hpp"
#include "scene_keys.hpp"
#include "weather_map.hpp"

namespace airlight {

using namespace scene_keys;

namespace {

const NameTable<CloudsMethod> clouds_methods{{"adaptive", CloudsMethod::adaptive}, {"march", CloudsMethod::march}};

// [a, b] (m) of a two-number array key.
void read_pair(const Value& v, double lo, double hi, float& a, float& b) {
    if (!v.j.is_array() || v.j.size() != 2) fail(Kind::type, v.field, "expected [x, z] (m), got " + type_name(v.j));
    a = read_in_range(Value{v.j[0], index_path(v.field, 0)}, lo, hi, " m");
    b = read_in_range(Value{v.j[1], index_path(v.field, 1)}, lo, hi, " m");
}

// "weather_map": {"image": path, "size": [x, z], "center": [x, z]}; the image is read here, so that a
// missing or bad file is reported against the key.
WeatherMap parse_weather_map(const SceneObject& o) {
    o.check_keys({"image", "size", "center"});
    WeatherMap m;
    const Value image = o.req("image");
    if (!image.j.is_string()) fail(Kind::type, image.field, "expected a file path, got " + type_name(image.j));
    m.image = image.j.get<std::string>();
    read_pair(o.req("size"), 1.0, 1e7, m.size_x, m.size_z);
    if (auto v = o.opt("center")) read_pair(*v, -1e7, 1e7, m.center_x, m.center_z);
    try {
        m.texels = load_weather_map(m.image);
        m.max_coverage = 0.0f;
        for (size_t i = 0; i < m.texels->texels.size(); i += size_t(m.texels->channels))
            m.max_coverage = std::max(m.max_coverage, m.texels->texels[i]);
    } catch (const std::runtime_error& e) {
        fail(Kind::value, image.field, e.what());
    }
    return m;
}

Clouds parse_clouds(const SceneObject& o) {
    o.check_keys(cloud_layer_keys_and(
        {"type", "albedo", "g", "second_g", "second_weight", "powder", "erosion", "detail_scale", "weather_map"}));
    Clouds c;
    parse_cloud_layer(o, c);
    if (auto v = o.opt("type")) c.type = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("albedo")) c.albedo = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("g")) c.g = read_asymmetry(*v);
    if (auto v = o.opt("second_g")) c.second_g = read_asymmetry(*v);
    if (auto v = o.opt("second_weight")) c.second_weight = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("powder")) c.powder = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("erosion")) c.erosion = read_in_range(*v, 0.0, 0.95);
    if (auto v = o.opt("detail_scale")) c.detail_scale = read_in_range(*v, 0.1, 1e7, " m");
    if (auto v = o.opt("weather_map"); v && !v->j.is_null()) c.weather_map = parse_weather_map(SceneObject(*v));
    return c;
}

}  // namespace

Names cloud_layer_keys_and(Names own) {
    Names keys{"base", "top", "coverage", "extinction", "shape_scale", "wind", "time", "seed"};
    keys.insert(keys.end(), own.begin(), own.end());
    return keys;
}

void parse_cloud_layer(const SceneObject& o, CloudLayer& c) {
    c.present = true;
    if (auto v = o.opt("base")) c.base = read_in_range(*v, 0.0, 1e5, " m");
    if (auto v = o.opt("top")) {
        c.top = read_in_range(*v, 0.0, 1e5, " m");
        if (!(c.top > c.base)) fail(Kind::value, v->field, "must be above the base (" + std::to_string(c.base) + " m)");
    } else if (!(c.top > c.base)) {
        fail(Kind::value, join_path(o.path, "base"), "must be below the top (" + std::to_string(c.top) + " m)");
    }
    if (auto v = o.opt("coverage")) c.coverage = read_in_range(*v, 0.0, 1.0);
    if (auto v = o.opt("extinction")) c.extinction = read_in_range(*v, 0.0, 1e3, " 1/m");
    if (auto v = o.opt("shape_scale")) c.shape_scale = read_in_range(*v, 1.0, 1e7, " m");
    if (auto v = o.opt("wind")) {
        if (!v->j.is_array() || v->j.size() != 2)
            fail(Kind::type, v->field, "expected [vx, vz] (m/s), got " + type_name(v->j));
        c.wind_x = read_in_range(Value{v->j[0], index_path(v->field, 0)}, -1e3, 1e3, " m/s");
        c.wind_z = read_in_range(Value{v->j[1], index_path(v->field, 1)}, -1e3, 1e3, " m/s");
    }
    if (auto v = o.opt("time")) c.time = read_in_range(*v, -1e7, 1e7, " s");
    if (auto v = o.opt("seed")) c.seed = read_int(*v, 0, 1 << 30);
}

void write_cloud_layer(const CloudLayer& c, json& j) {
    j["base"] = json_number(c.base);
    j["top"] = json_number(c.top);
    j["coverage"] = json_number(c.coverage);
    j["extinction"] = json_number(c.extinction);
    j["shape_scale"] = json_number(c.shape_scale);
    j["wind"] = json::array({json_number(c.wind_x), json_number(c.wind_z)});
    j["time"] = json_number(c.time);
    j["seed"] = c.seed;
}

// Rain falls from the cloud base (physics.md section 7): an atmosphere's rain
// without its own "top" reaches up to the layer's base. Runs after the daytime
// effect has parsed the atmosphere (effects/registry.cmake).
void parse_noise_clouds_keys(const SceneObject& top, Scene& s) {
    auto v = top.opt("clouds");
    if (!v || v->j.is_null()) return;
    s.clouds = parse_clouds(SceneObject(*v));
    const json& atmosphere = top.j.contains("atmosphere") ? top.j["atmosphere"] : json();
    const bool rain_top_given = atmosphere.is_object() && atmosphere.contains("rain") &&
                                atmosphere["rain"].is_object() && atmosphere["rain"].contains("top");
    if (!s.atmosphere.rain.present || rain_top_given) return;
    if (!(s.clouds.base > 0.0f))
        fail(Kind::value, "atmosphere.rain.top",
             "missing: the rain would fall from the clouds' base, which is at the ground; give the rain a top");
    s.atmosphere.rain.top = s.clouds.base;
}

void write_noise_clouds_keys(const Scene& s, json& j) {
    if (!s.clouds.present) {
        j["clouds"] = nullptr;
        return;
    }
    const Clouds& c = s.clouds;
    j["clouds"] = {{"type", json_number(c.type)},
                   {"albedo", json_number(c.albedo)},
                   {"g", json_number(c.g)},
                   {"second_g", json_number(c.second_g)},
                   {"second_weight", json_number(c.second_weight)},
                   {"powder", json_number(c.powder)},
                   {"erosion", json_number(c.erosion)},
                   {"detail_scale", json_number(c.detail_scale)}};
    write_cloud_layer(c, j["clouds"]);
    if (c.weather_map.texels) {
        const WeatherMap& m = c.weather_map;
        j["clouds"]["weather_map"] = {{"image", m.image},
                                      {"size", json::array({json_number(m.size_x), json_number(m.size_z)})},
                                      {"center", json::array({json_number(m.center_x), json_number(m.center_z)})}};
    }
}

// The clouds' marches under each preset (physics.md section 4; their error
// against the step counts: docs/quality_presets.md). "march" stays a
// comparison, never a preset.
void preset_noise_clouds_quality(QualityPreset preset, Scene& s) {
    if (preset == QualityPreset::fast) {
        s.quality.cloud_steps = 48;
        s.quality.cloud_light_steps = 16;
        s.quality.cloud_shadow_steps = 8;
    }
    if (preset == QualityPreset::reference) {
        s.quality.cloud_steps = 192;
        s.quality.cloud_light_steps = 64;
        s.quality.cloud_shadow_steps = 32;
    }
}

void parse_noise_clouds_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("clouds")) s.quality.clouds = read_enum(*v, "clouds", clouds_methods);
    if (auto v = quality.opt("cloud_steps")) s.quality.cloud_steps = read_int(*v, 4, 4096);
    if (auto v = quality.opt("cloud_light_steps")) s.quality.cloud_light_steps = read_int(*v, 1, 1024);
    if (auto v = quality.opt("cloud_shadow_steps")) s.quality.cloud_shadow_steps = read_int(*v, 0, 1024);
}

void write_noise_clouds_quality(const Scene& s, json& quality) {
    quality["clouds"] = name_of(clouds_methods, s.quality.clouds);
    quality["cloud_steps"] = s.quality.cloud_steps;
    quality["cloud_light_steps"] = s.quality.cloud_light_steps;
    quality["cloud_shadow_steps"] = s.quality.cloud_shadow_steps;
}

}  // namespace airlight
