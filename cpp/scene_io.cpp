// Scene JSON loading, validation and writing (format: README "Scene format").
// Numbers are validated as doubles; bounds that must survive the conversion to
// float (strict inequalities, camera and box degeneracy) are checked on the
// float values, so that parse(write(scene)) reproduces the scene exactly.
// The core's keys are here; an effect's top-level keys are parsed and written
// by the effect (EFFECT_SCENE_KEYS, cpp/scene_keys.hpp), called through the
// registry after the core's, in registry order.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "airlight_registry.hpp"
#include "numerics.hpp"
#include "scene_json.hpp"
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

// The effects' scene keys (effects/<name>/, EFFECT_SCENE_KEYS).
#define AIRLIGHT_X(e)                                        \
    void parse_##e##_keys(const SceneObject& top, Scene& s); \
    void write_##e##_keys(const Scene& s, json& j);
AIRLIGHT_SCENE_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
// ... and their keys of the "quality" object (EFFECT_QUALITY_KEYS).
#define AIRLIGHT_X(e)                                               \
    void preset_##e##_quality(QualityPreset preset, Scene& s);      \
    void parse_##e##_quality(const SceneObject& quality, Scene& s); \
    void write_##e##_quality(const Scene& s, json& quality);
AIRLIGHT_QUALITY_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X

namespace {

using namespace scene_limits;

enum class LightType { point, spot };

const NameTable<PhaseType> phase_types{{"isotropic", PhaseType::isotropic},
                                       {"hg", PhaseType::hg},
                                       {"rayleigh", PhaseType::rayleigh},
                                       {"hg2", PhaseType::hg2}};
const NameTable<LightType> light_types{{"point", LightType::point}, {"spot", LightType::spot}};
const NameTable<AirlightMethod> airlight_methods{{"analytic", AirlightMethod::analytic},
                                                 {"march", AirlightMethod::march}};
const NameTable<QualityPreset> quality_presets{
    {"fast", QualityPreset::fast}, {"default", QualityPreset::default_}, {"reference", QualityPreset::reference}};
const NameTable<SurfaceType> surface_types{
    {"plane", SurfaceType::plane}, {"box", SurfaceType::box}, {"sphere", SurfaceType::sphere}};

// Keys allowed in a surface object of each type.
Names surface_keys(SurfaceType type) {
    switch (type) {
        case SurfaceType::plane:
            return {"type", "albedo", "point", "normal"};
        case SurfaceType::box:
            return {"type", "albedo", "min", "max"};
        case SurfaceType::sphere:
            return {"type", "albedo", "center", "radius"};
    }
    return {};
}

// --- objects -----------------------------------------------------------------

Film parse_film(const SceneObject& o) {
    o.check_keys({"width", "height"});
    Film f;
    f.width = read_int(o.req("width"), 1, max_film_size);
    f.height = read_int(o.req("height"), 1, max_film_size);
    // 64 megapixels at most (8192 x 8192: 768 MiB of float RGB), refused before anything is allocated.
    if (long(f.width) * long(f.height) > max_film_pixels)
        fail(Kind::value, join_path(o.path, "height"),
             "film of " + std::to_string(f.width) + " x " + std::to_string(f.height) + " pixels exceeds " +
                 std::to_string(max_film_pixels) + " pixels (8192 x 8192)");
    return f;
}

Camera parse_camera(const SceneObject& o) {
    o.check_keys({"position", "look_at", "up", "fov_y", "exposure_time"});
    Camera c;
    c.position = read_vec3(o.req("position"));
    c.look_at = read_vec3(o.req("look_at"));
    c.up = read_vec3(o.req("up"));
    c.fov_y_degrees = read_positive(o.req("fov_y"), 180.0, false);
    if (auto v = o.opt("exposure_time")) c.exposure_time = read_in_range(*v, 0.0, 10.0, " s");
    // Degeneracy, on the stored float values.
    glm::dvec3 position(c.position), view = glm::dvec3(c.look_at) - position, up(c.up);
    // The view direction must stand above the float32 rounding of the two
    // points' coordinates (a few units in the last place of the largest).
    const double coordinate =
        std::max({1.0, std::abs(position.x), std::abs(position.y), std::abs(position.z), double(std::abs(c.look_at.x)),
                  double(std::abs(c.look_at.y)), double(std::abs(c.look_at.z))});
    const double resolution = 4.0 * double(std::numeric_limits<float>::epsilon()) * coordinate;
    if (glm::length(view) == 0.0) fail(Kind::value, join_path(o.path, "look_at"), "look_at equals position");
    if (glm::length(view) < resolution)
        fail(Kind::value, join_path(o.path, "look_at"),
             "look_at is closer to position than float32 resolves at these coordinates (" + format_number(resolution) +
                 " m); move it further away");
    double up_length = glm::length(up);
    if (up_length == 0 || glm::length(glm::cross(glm::normalize(view), up)) < 1e-6 * up_length)
        fail(Kind::value, join_path(o.path, "up"), "up is zero or parallel to the view direction");
    return c;
}

Phase parse_phase(const SceneObject& o) {
    Phase p;
    p.type = read_enum(o.req("type"), "phase", phase_types);
    switch (p.type) {
        case PhaseType::isotropic:
        case PhaseType::rayleigh:
            o.check_keys({"type"});
            break;
        case PhaseType::hg:
            o.check_keys({"type", "g"});
            p.g = read_asymmetry(o.req("g"));
            break;
        case PhaseType::hg2: {
            o.check_keys({"type", "forward_g", "backward_g", "forward_weight"});
            p.forward_g = read_asymmetry(o.req("forward_g"));
            p.backward_g = read_asymmetry(o.req("backward_g"));
            Value w = o.req("forward_weight");
            double weight = read_number(w);
            if (weight < 0 || weight > 1) fail(Kind::value, w.field, "must be in [0, 1]");
            p.forward_weight = static_cast<float>(weight);
            break;
        }
    }
    return p;
}

Medium parse_medium(const SceneObject& o) {
    o.check_keys({"sigma_t", "visibility", "albedo", "phase"});
    Medium m;
    // Exactly one of sigma_t and the visibility (Koschmieder, as the aerosol's).
    const Either given = read_either(o, "sigma_t", "sigma_t (1/m)", "visibility", "visibility (m)");
    if (given.first) {
        m.sigma_t = read_rgb(given.value, max_extinction);
    } else {
        m.visibility = read_visibility(given.value);
        m.sigma_t = Rgb(visibility_extinction(m.visibility));
    }
    if (auto v = o.opt("albedo")) m.albedo = read_rgb(*v, 1.0);
    if (auto v = o.opt("phase")) m.phase = parse_phase(SceneObject(*v));
    return m;
}

// A lamp's radius in [min_light_radius, max_light_radius], and its core
// radiance I / (pi r^2) (the largest channel of the intensity, on a spot's
// axis) at most max_radiometric, like every radiance of the scene.
float read_light_radius(const SceneObject& o, const Rgb& intensity) {
    std::optional<Value> given = o.opt("radius");
    const float r =
        given ? read_in_range(*given, min_light_radius, max_light_radius, " m") : float(default_light_radius);
    const double peak = std::max({double(intensity.x), double(intensity.y), double(intensity.z)});
    const double radiance = peak / (numerics::kPi * double(r) * double(r));
    if (radiance > max_radiometric) {
        const std::string field = given ? given->field : o.req("intensity").field;
        fail(Kind::value, field,
             "the lamp's core radiance intensity / (pi radius^2) = " + format_number(radiance) + " exceeds " +
                 format_number(max_radiometric) + (given ? "" : " (radius 0.05 m by default)") +
                 ": give a larger radius or a smaller intensity");
    }
    return r;
}

PointLight parse_point_light(const SceneObject& o) {
    o.check_keys({"type", "position", "intensity", "radius", "volumetric_shadows"});
    PointLight l;
    l.position = read_vec3(o.req("position"));
    l.intensity = read_rgb(o.req("intensity"));
    l.radius = read_light_radius(o, l.intensity);
    if (auto v = o.opt("volumetric_shadows")) l.volumetric_shadows = read_bool(*v);
    return l;
}

// Spot light (effects/spotlights/physics.md): cone_angle is the half-angle in degrees,
// in [min_cone_angle, 90] (checked on the float value too); edge in [0, 1].
SpotLight parse_spot_light(const SceneObject& o) {
    o.check_keys({"type", "position", "direction", "intensity", "cone_angle", "edge", "radius", "volumetric_shadows"});
    SpotLight l;
    l.position = read_vec3(o.req("position"));
    l.direction = read_direction(o.req("direction"), "must not be zero");
    l.intensity = read_rgb(o.req("intensity"));
    Value cone = o.req("cone_angle");
    double angle = read_number(cone);
    float angle_f = static_cast<float>(angle);
    if (!(angle >= min_cone_angle && angle_f >= float(min_cone_angle) && angle <= 90 && angle_f <= 90))
        fail(Kind::value, cone.field, "must be in [0.001, 90]");
    l.cone_angle_degrees = angle_f;
    if (auto v = o.opt("edge")) {
        double edge = read_number(*v);
        if (edge < 0 || edge > 1) fail(Kind::value, v->field, "must be in [0, 1]");
        l.edge = static_cast<float>(edge);
    }
    l.radius = read_light_radius(o, l.intensity);
    if (auto v = o.opt("volumetric_shadows")) l.volumetric_shadows = read_bool(*v);
    return l;
}

// The "lights" list: point entries go to point_lights, spot entries to
// spot_lights; field paths keep the index in the list.
void parse_lights(const std::optional<Value>& v, Scene& s) {
    if (!v) return;
    if (!v->j.is_array()) fail(Kind::type, v->field, "expected a list, got " + type_name(v->j));
    for (std::size_t i = 0; i < v->j.size(); ++i) {
        SceneObject o(Value{v->j[i], index_path(v->field, i)});
        switch (read_enum(o.req("type"), "light", light_types)) {
            case LightType::point:
                s.point_lights.push_back(parse_point_light(o));
                break;
            case LightType::spot:
                s.spot_lights.push_back(parse_spot_light(o));
                break;
        }
    }
}

Surface parse_surface(const SceneObject& o) {
    Surface s;
    s.type = read_enum(o.req("type"), "surface", surface_types);
    o.check_keys(surface_keys(s.type));
    if (auto v = o.opt("albedo")) s.albedo = read_rgb(*v, 1.0);
    switch (s.type) {
        case SurfaceType::plane: {
            s.point = read_vec3(o.req("point"));
            s.normal = read_direction(o.req("normal"), "normal must be nonzero");
            break;
        }
        case SurfaceType::box: {
            s.box_min = read_vec3(o.req("min"));
            Value max = o.req("max");
            s.box_max = read_vec3(max);
            if (!(s.box_min.x < s.box_max.x && s.box_min.y < s.box_max.y && s.box_min.z < s.box_max.z))
                fail(Kind::value, max.field, "max must be greater than min on every axis");
            break;
        }
        case SurfaceType::sphere:
            s.center = read_vec3(o.req("center"));
            s.radius = read_positive(o.req("radius"), infinity, false);
            break;
    }
    return s;
}

// The "quality" object: the core's keys here, each effect's in its
// parse_<name>_quality (EFFECT_QUALITY_KEYS).
// The core's knobs under a preset: culling (effects/lamp_airlight/docs/culling.md
// bounds its error by cull_fraction per skipped lamp; docs/quality_presets.md
// measures the time it saves).
void preset_core_quality(QualityPreset preset, Scene& s) {
    if (preset == QualityPreset::fast) s.quality.cull_fraction = 1e-4f;
    if (preset == QualityPreset::reference) s.quality.cull_fraction = 0.0f;
}

void parse_quality(const SceneObject& o, Scene& s) {
    o.check_keys({"preset", "airlight", "march_steps", "cull_fraction", AIRLIGHT_EFFECT_QUALITY_KEYS});
    Quality& q = s.quality;
    // The preset first, so that every explicit key below overrides it.
    if (auto v = o.opt("preset")) q.preset = read_enum(*v, "preset", quality_presets);
    preset_core_quality(q.preset, s);
#define AIRLIGHT_X(e) preset_##e##_quality(q.preset, s);
    AIRLIGHT_QUALITY_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
    if (auto v = o.opt("airlight")) q.airlight = read_enum(*v, "airlight", airlight_methods);
    if (auto v = o.opt("march_steps")) q.march_steps = read_int(*v, 1, 65536);
    if (auto v = o.opt("cull_fraction")) {
        double x = read_number(*v);
        if (x < 0 || x > 0.01) fail(Kind::value, v->field, "must be in [0, 0.01]");
        q.cull_fraction = static_cast<float>(x);
    }
#define AIRLIGHT_X(e) parse_##e##_quality(o, s);
    AIRLIGHT_QUALITY_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
}

}  // namespace

Scene parse_scene_json(const json& j) {
    if (!j.is_object()) fail(Kind::type, "", "scene must be a JSON object");
    SceneObject top(Value{j, ""});
    top.check_keys(
        {"film", "camera", "medium", "lights", "surfaces", "background", "quality", AIRLIGHT_EFFECT_SCENE_KEYS});
    Scene s;
    s.film = parse_film(SceneObject(top.req("film")));
    s.camera = parse_camera(SceneObject(top.req("camera")));
    if (auto v = top.opt("medium"); v && !v->j.is_null()) {
        s.has_medium = true;
        s.medium = parse_medium(SceneObject(*v));
    }
    parse_lights(top.opt("lights"), s);
    s.surfaces = read_list<Surface>(top.opt("surfaces"), parse_surface);
    if (auto v = top.opt("background")) s.background = read_rgb(*v);
    if (auto v = top.opt("quality")) parse_quality(SceneObject(*v), s);
#define AIRLIGHT_X(e) parse_##e##_keys(top, s);
    AIRLIGHT_SCENE_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
    return s;
}

json phase_to_json(const Phase& p) {
    json j = {{"type", name_of(phase_types, p.type)}};
    if (p.type == PhaseType::hg) j["g"] = json_number(p.g);
    if (p.type == PhaseType::hg2) {
        j["forward_g"] = json_number(p.forward_g);
        j["backward_g"] = json_number(p.backward_g);
        j["forward_weight"] = json_number(p.forward_weight);
    }
    return j;
}

json scene_to_json_value(const Scene& s) {
    json j;
    j["film"] = {{"width", s.film.width}, {"height", s.film.height}};
    j["camera"] = {{"position", json_vec3(s.camera.position)},
                   {"look_at", json_vec3(s.camera.look_at)},
                   {"up", json_vec3(s.camera.up)},
                   {"fov_y", json_number(s.camera.fov_y_degrees)},
                   {"exposure_time", json_number(s.camera.exposure_time)}};
    if (s.has_medium) {
        // By its visibility where the scene gave one and sigma_t is still its value.
        const bool by_visibility =
            s.medium.visibility > 0.0f && s.medium.sigma_t == Rgb(visibility_extinction(s.medium.visibility));
        j["medium"] = {{"albedo", json_vec3(s.medium.albedo)}, {"phase", phase_to_json(s.medium.phase)}};
        if (by_visibility)
            j["medium"]["visibility"] = json_number(s.medium.visibility);
        else
            j["medium"]["sigma_t"] = json_vec3(s.medium.sigma_t);
    } else {
        j["medium"] = nullptr;
    }
    j["lights"] = json::array();
    for (const auto& l : s.point_lights) {
        j["lights"].push_back({{"type", name_of(light_types, LightType::point)},
                               {"position", json_vec3(l.position)},
                               {"intensity", json_vec3(l.intensity)},
                               {"radius", json_number(l.radius)},
                               {"volumetric_shadows", l.volumetric_shadows}});
    }
    for (const auto& l : s.spot_lights) {
        j["lights"].push_back({{"type", name_of(light_types, LightType::spot)},
                               {"position", json_vec3(l.position)},
                               {"direction", json_vec3(l.direction)},
                               {"intensity", json_vec3(l.intensity)},
                               {"cone_angle", json_number(l.cone_angle_degrees)},
                               {"edge", json_number(l.edge)},
                               {"radius", json_number(l.radius)},
                               {"volumetric_shadows", l.volumetric_shadows}});
    }
    j["surfaces"] = json::array();
    for (const auto& sf : s.surfaces) {
        json o = {{"type", name_of(surface_types, sf.type)}, {"albedo", json_vec3(sf.albedo)}};
        switch (sf.type) {
            case SurfaceType::plane:
                o["point"] = json_vec3(sf.point);
                o["normal"] = json_vec3(sf.normal);
                break;
            case SurfaceType::box:
                o["min"] = json_vec3(sf.box_min);
                o["max"] = json_vec3(sf.box_max);
                break;
            case SurfaceType::sphere:
                o["center"] = json_vec3(sf.center);
                o["radius"] = json_number(sf.radius);
                break;
        }
        j["surfaces"].push_back(std::move(o));
    }
    j["background"] = json_vec3(s.background);
    j["quality"] = {{"preset", name_of(quality_presets, s.quality.preset)},
                    {"airlight", name_of(airlight_methods, s.quality.airlight)},
                    {"march_steps", s.quality.march_steps},
                    {"cull_fraction", json_number(s.quality.cull_fraction)}};
#define AIRLIGHT_X(e) write_##e##_quality(s, j["quality"]);
    AIRLIGHT_QUALITY_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
#define AIRLIGHT_X(e) write_##e##_keys(s, j);
    AIRLIGHT_SCENE_KEY_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
    return j;
}

namespace {

// nlohmann's "[json.exception.parse_error.101] parse error at line 1, column 2: syntax
// error ..." without the library's prefix: "invalid JSON at line 1, column 2: syntax ...".
std::string json_error_message(const nlohmann::json::exception& e) {
    std::string m = e.what();
    if (m.rfind("[json.exception.", 0) == 0) {
        const auto end = m.find("] ");
        if (end != std::string::npos) m.erase(0, end + 2);
    }
    if (m.rfind("parse error", 0) == 0) m.erase(0, std::strlen("parse error"));
    if (m.rfind(": ", 0) == 0) m.erase(0, 2);
    if (m.rfind(" at ", 0) == 0) return "invalid JSON" + m;
    return "invalid JSON: " + m;
}

}  // namespace

Scene parse_scene(const std::string& json_text) {
    // JSON lets an object repeat a key and the parser keeps the last one: a
    // scene that does is refused, naming the key (a stale copy would win silently).
    std::vector<std::set<std::string>> keys_of_open_objects;
    std::string duplicate;
    const auto check_keys = [&](int, json::parse_event_t event, json& parsed) {
        if (event == json::parse_event_t::object_start) {
            keys_of_open_objects.emplace_back();
        } else if (event == json::parse_event_t::object_end) {
            if (!keys_of_open_objects.empty()) keys_of_open_objects.pop_back();
        } else if (event == json::parse_event_t::key && !keys_of_open_objects.empty()) {
            const std::string key = parsed.get<std::string>();
            if (!keys_of_open_objects.back().insert(key).second && duplicate.empty()) duplicate = key;
        }
        return true;
    };
    json j;
    try {
        j = json::parse(json_text, check_keys);
    } catch (const json::exception& e) {
        fail(Kind::value, "", json_error_message(e));
    }
    if (!duplicate.empty()) fail(Kind::value, duplicate, "duplicate key (JSON gives each key once per object)");
    return parse_scene_json(j);
}

Scene load_scene_file(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) {
        if (errno == ENOENT) throw SceneFileError("scene file not found: " + path);
        throw SceneFileError("cannot read scene file " + path + ": " + std::strerror(errno));
    }
    // Read at most max_scene_file_bytes: '/dev/zero' or a huge file is refused,
    // not read until memory runs out.
    std::string text;
    char buf[1 << 16];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0 && text.size() <= max_scene_file_bytes) text.append(buf, n);
    int error = std::ferror(f) ? errno : 0;
    std::fclose(f);
    if (error) throw SceneFileError("cannot read scene file " + path + ": " + std::strerror(error));
    if (text.size() > max_scene_file_bytes)
        throw SceneFileError("scene file " + path + " is larger than " + std::to_string(max_scene_file_bytes >> 20) +
                             " MiB");
    return parse_scene(text);
}

Film resize_film(const Film& film, int width, int height) {
    Film out = film;
    if (width > 0 && height > 0) {
        out.width = width;
        out.height = height;
    } else if (width > 0) {
        out.width = width;
        out.height = std::max(1, int(std::floor(double(width) * film.height / film.width + 0.5)));
    } else if (height > 0) {
        out.height = height;
        out.width = std::max(1, int(std::floor(double(height) * film.width / film.height + 0.5)));
    }
    return out;
}

std::string scene_to_json(const Scene& scene, int indent) { return scene_to_json_value(scene).dump(indent); }

}  // namespace airlight