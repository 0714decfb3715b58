// The daytime effect's scene keys: "sky", "sun" and "atmosphere" (README
// "Scene format"; effects/daytime/docs/daytime.md), parsed and written back
// through the registry (EFFECT_SCENE_KEYS; cpp/scene_keys.hpp).
#include <cmath>
#include <glm/geometric.hpp>
#include <string>

#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {

const NameTable<RainPhase> rain_phases{{"mie", RainPhase::mie}, {"hg", RainPhase::hg}};
const NameTable<SkyModel> sky_models{{"overcast", SkyModel::overcast}, {"cie", SkyModel::cie}};

// CIE general sky types whose indicatrix needs the sun's position (all but
// the indicatrix-group-1 types 1, 3 and 5; ISO 15469).
bool cie_type_needs_sun(int type) { return type != 1 && type != 3 && type != 5; }

Sky parse_sky(const SceneObject& o) {
    Sky sky;
    sky.model = read_enum(o.req("model"), "sky model", sky_models);
    if (sky.model == SkyModel::cie) {
        o.check_keys({"model", "type", "zenith_radiance"});
        sky.cie_type = read_int(o.req("type"), 1, 15);
    } else {
        o.check_keys({"model", "zenith_radiance"});
    }
    sky.zenith_radiance = read_rgb(o.req("zenith_radiance"));
    return sky;
}

// The sun: elevation/azimuth in degrees, or a direction (toward the sun).
Sun parse_sun(const SceneObject& o) {
    o.check_keys({"elevation", "azimuth", "direction", "irradiance"});
    Sun sun;
    sun.present = true;
    const auto direction = o.opt("direction");
    const auto elevation = o.opt("elevation");
    const auto azimuth = o.opt("azimuth");
    if (direction) {
        if (elevation || azimuth)
            fail(Kind::value, direction->field, "give either a direction or elevation and azimuth, not both");
        const glm::dvec3 d(read_vec3(*direction));
        if (!(glm::length(d) > 0.0)) fail(Kind::value, direction->field, "must not have zero length");
        // Stored unit length; a direction already unit to float precision is
        // kept as given, so that a written scene reloads bit for bit.
        sun.direction = std::abs(glm::length(d) - 1.0) < 1e-6 ? glm::vec3(d) : glm::vec3(glm::normalize(d));
    } else {
        if (!elevation && !azimuth)
            fail(Kind::value, join_path(o.path, "elevation"),
                 "missing: give elevation and azimuth (degrees) or a direction");
        const Value el_value = o.req("elevation");
        read_in_range(el_value, -90.0, 90.0, " degrees");
        // In double from the given numbers, stored as float.
        const double el = read_number(el_value) * (M_PI / 180.0);
        const double az = read_number(o.req("azimuth")) * (M_PI / 180.0);
        sun.direction =
            glm::vec3(float(std::sin(az) * std::cos(el)), float(std::sin(el)), float(-std::cos(az) * std::cos(el)));
    }
    if (auto v = o.opt("irradiance")) sun.irradiance = read_rgb(*v);
    return sun;
}

Atmosphere parse_atmosphere(const SceneObject& o) {
    o.check_keys({"molecules", "aerosol", "rain"});
    Atmosphere a;
    if (auto v = o.opt("molecules"); v && !v->j.is_null()) {
        SceneObject m(*v);
        m.check_keys({"density_scale"});
        a.molecules.present = true;
        if (auto d = m.opt("density_scale")) a.molecules.density_scale = read_in_range(*d, 0.0, 1e6);
    }
    if (auto v = o.opt("aerosol"); v && !v->j.is_null()) {
        SceneObject m(*v);
        m.check_keys({"visibility", "coefficient", "scale_height", "g", "albedo"});
        a.aerosol.present = true;
        const Either given = read_either(m, "visibility", "visibility (m)", "coefficient", "coefficient (1/m)");
        if (given.first)
            a.aerosol.visibility = read_visibility(given.value);
        else
            a.aerosol.coefficient = read_in_range(given.value, 0.0, 1e3, " per metre");
        if (auto d = m.opt("scale_height")) a.aerosol.scale_height = read_positive(*d, 1e5, true);
        if (auto d = m.opt("g")) a.aerosol.g = read_asymmetry(*d);
        if (auto d = m.opt("albedo")) a.aerosol.albedo = read_in_range(*d, 0.0, 1.0);
    }
    if (auto v = o.opt("rain"); v && !v->j.is_null()) {
        SceneObject m(*v);
        m.check_keys({"rate", "density_scale", "top", "g", "phase"});
        a.rain.present = true;
        a.rain.rate = read_in_range(m.req("rate"), 0.0, 1000.0, " mm/h");
        if (auto d = m.opt("density_scale")) a.rain.density_scale = read_in_range(*d, 0.0, 1e6);
        if (auto d = m.opt("top")) a.rain.top = read_positive(*d, 1e5, true);
        if (auto d = m.opt("g")) a.rain.g = read_asymmetry(*d);
        if (auto d = m.opt("phase")) a.rain.phase = read_enum(*d, "rain phase", rain_phases);
    }
    return a;
}

json sky_to_json(const Sky& sky) {
    if (sky.model == SkyModel::none) return nullptr;
    json j = {{"model", name_of(sky_models, sky.model)}, {"zenith_radiance", json_vec3(sky.zenith_radiance)}};
    if (sky.model == SkyModel::cie) j["type"] = sky.cie_type;
    return j;
}

json sun_to_json(const Sun& sun) {
    if (!sun.present) return nullptr;
    return {{"direction", json_vec3(sun.direction)}, {"irradiance", json_vec3(sun.irradiance)}};
}

json atmosphere_to_json(const Atmosphere& a) {
    if (!a.any()) return nullptr;
    json j = json::object();
    if (a.molecules.present) j["molecules"] = {{"density_scale", json_number(a.molecules.density_scale)}};
    if (a.aerosol.present) {
        json m = {{"scale_height", json_number(a.aerosol.scale_height)},
                  {"g", json_number(a.aerosol.g)},
                  {"albedo", json_number(a.aerosol.albedo)}};
        if (a.aerosol.visibility > 0.0f)
            m["visibility"] = json_number(a.aerosol.visibility);
        else
            m["coefficient"] = json_number(a.aerosol.coefficient);
        j["aerosol"] = m;
    }
    if (a.rain.present)
        j["rain"] = {{"rate", json_number(a.rain.rate)},
                     {"density_scale", json_number(a.rain.density_scale)},
                     {"top", json_number(a.rain.top)},
                     {"g", json_number(a.rain.g)},
                     {"phase", name_of(rain_phases, a.rain.phase)}};
    return j;
}

}  // namespace

// "sky", "sun", "atmosphere" (null or absent: none), then the check that a
// CIE sky type whose indicatrix needs the sun has one.
void parse_daytime_keys(const SceneObject& top, Scene& s) {
    if (auto v = top.opt("sky"); v && !v->j.is_null()) s.sky = parse_sky(SceneObject(*v));
    if (auto v = top.opt("sun"); v && !v->j.is_null()) s.sun = parse_sun(SceneObject(*v));
    if (auto v = top.opt("atmosphere"); v && !v->j.is_null()) s.atmosphere = parse_atmosphere(SceneObject(*v));
    if (s.sky.model == SkyModel::cie && cie_type_needs_sun(s.sky.cie_type) && !s.sun.present)
        fail(Kind::value, "sky.type",
             "CIE sky type " + std::to_string(s.sky.cie_type) +
                 " depends on the sun's position: add a \"sun\" (its irradiance may be 0)");
}

void write_daytime_keys(const Scene& s, json& j) {
    j["sky"] = sky_to_json(s.sky);
    j["sun"] = sun_to_json(s.sun);
    j["atmosphere"] = atmosphere_to_json(s.atmosphere);
}

}  // namespace airlight

namespace airlight {

// The altitude levels under each preset (effects/daytime/docs/daytime.md section 3 measures
// the error against the number of levels; docs/quality_presets.md the time).
// The reference walks the volumes in every pixel (no aerial table).
void preset_daytime_quality(QualityPreset preset, Scene& s) {
    if (preset == QualityPreset::fast) s.quality.sky_segments = 8;
    if (preset == QualityPreset::reference) {
        s.quality.sky_segments = 64;
        s.quality.aerial_table = 0;
    }
}

// The quality keys "sky_segments" and "aerial_table" (EFFECT_QUALITY_KEYS).
void parse_daytime_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("sky_segments")) s.quality.sky_segments = read_int(*v, 2, 64);
    if (auto v = quality.opt("aerial_table")) {
        const auto bad = [](const std::string& got) {
            throw SceneError(SceneError::Kind::value, "quality.aerial_table",
                             "\"auto\", 0 (off) or 8 to 64 distance nodes, got " + got);
        };
        if (v->j.is_string()) {
            if (v->j.get<std::string>() != "auto") bad("\"" + v->j.get<std::string>() + "\"");
            s.quality.aerial_table = AERIAL_TABLE_AUTO;
        } else {
            s.quality.aerial_table = read_int(*v, 0, 64);
            if (s.quality.aerial_table != 0 && s.quality.aerial_table < 8) bad(std::to_string(s.quality.aerial_table));
        }
    }
}

void write_daytime_quality(const Scene& s, json& quality) {
    quality["sky_segments"] = s.quality.sky_segments;
    if (s.quality.aerial_table == AERIAL_TABLE_AUTO)
        quality["aerial_table"] = "auto";
    else
        quality["aerial_table"] = s.quality.aerial_table;
}

}  // namespace airlight
