// Scene JSON loading, validation and writing (format: README "Scene format").
// Numbers are validated as doubles; bounds that must survive the conversion to
// float (strict inequalities, camera and box degeneracy) are checked on the
// float values, so that parse(write(scene)) reproduces the scene exactly.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rainbow.hpp"
#include "scene_json.hpp"

namespace airlight {
namespace {

using json = nlohmann::json;
using Kind = SceneError::Kind;
using Names = std::vector<std::string>;

constexpr double max_coordinate = 1e7;
constexpr int max_film_size = 16384;
constexpr double max_light_radius = 1e3;
constexpr double default_light_radius = 0.05;
constexpr double infinity = std::numeric_limits<double>::infinity();

enum class LightType { point, spot };

template <class E>
using NameTable = std::vector<std::pair<const char*, E>>;

const NameTable<PhaseType> phase_types{{"isotropic", PhaseType::isotropic},
                                       {"hg", PhaseType::hg},
                                       {"rayleigh", PhaseType::rayleigh},
                                       {"hg2", PhaseType::hg2}};
const NameTable<LightType> light_types{{"point", LightType::point}, {"spot", LightType::spot}};
const NameTable<AirlightMethod> airlight_methods{{"analytic", AirlightMethod::analytic},
                                                 {"march", AirlightMethod::march}};
const NameTable<ToneCurve> tone_curves{{"linear", ToneCurve::linear},
                                       {"loglog", ToneCurve::loglog},
                                       {"reinhard", ToneCurve::reinhard},
                                       {"filmic", ToneCurve::filmic}};
const NameTable<RainPhase> rain_phases{{"mie", RainPhase::mie}, {"hg", RainPhase::hg}};
const NameTable<SkyModel> sky_models{{"overcast", SkyModel::overcast}, {"cie", SkyModel::cie}};
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

[[noreturn]] void fail(Kind kind, const std::string& field, const std::string& message) {
    throw SceneError(kind, field, message);
}

std::string join_path(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

std::string index_path(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

std::string join_names(const Names& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

std::string format_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// JSON type names in the vocabulary of the Python API.
std::string type_name(const json& j) {
    switch (j.type()) {
        case json::value_t::null:
            return "null";
        case json::value_t::boolean:
            return "boolean";
        case json::value_t::string:
            return "string";
        case json::value_t::array:
            return "list";
        case json::value_t::object:
            return "object";
        case json::value_t::number_integer:
        case json::value_t::number_unsigned:
        case json::value_t::number_float:
            return "number";
        default:
            return "unsupported value";
    }
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1] ? 1 : 0)});
            diag = above;
        }
    }
    return row[b.size()];
}

// A JSON value with the dotted path it was found at.
struct Value {
    const json& j;
    std::string field;
};

// An object being parsed.
struct Obj {
    const json& j;
    std::string path;

    explicit Obj(const Value& v) : j(v.j), path(v.field) {
        if (!j.is_object()) fail(Kind::type, path, "expected an object, got " + type_name(j));
    }

    std::optional<Value> opt(const char* key) const {
        auto it = j.find(key);
        if (it == j.end()) return std::nullopt;
        return Value{*it, join_path(path, key)};
    }

    Value req(const char* key) const {
        auto v = opt(key);
        if (!v) fail(Kind::value, join_path(path, key), "missing required key");
        return *v;
    }

    // Rejects keys not in `allowed`, suggesting a known key within edit distance 2.
    void check_keys(const Names& allowed) const {
        for (const auto& item : j.items()) {
            const std::string& key = item.key();
            if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
            std::size_t best = 3;
            std::string message = "unknown key (allowed: " + join_names(allowed) + ")";
            for (const auto& known : allowed) {
                std::size_t d = edit_distance(key, known);
                if (d < best) {
                    best = d;
                    message = "unknown key; did you mean '" + known + "'?";
                }
            }
            fail(Kind::value, join_path(path, key), message);
        }
    }
};

// --- value readers -----------------------------------------------------------

// A finite number (JSON integer or float; never a bool). `prefix` names the
// element of a list ("element 1: ").
double read_number(const Value& v, const std::string& prefix = "") {
    if (!v.j.is_number()) fail(Kind::type, v.field, prefix + "expected a number, got " + type_name(v.j));
    double x = v.j.get<double>();
    if (!std::isfinite(x)) fail(Kind::value, v.field, prefix + "must be finite");
    return x;
}

int read_int(const Value& v, int lo, int hi) {
    double x = read_number(v);
    if (x != std::floor(x)) fail(Kind::value, v.field, "must be an integer");
    if (x < lo || x > hi)
        fail(Kind::value, v.field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(x);
}

// A scalar in (0, hi) or (0, hi], the bounds holding for the float value too.
float read_positive(const Value& v, double hi, bool hi_inclusive) {
    double x = read_number(v);
    float f = static_cast<float>(x);
    if (!(x > 0 && f > 0)) fail(Kind::value, v.field, "must be > 0");
    if (!std::isfinite(f)) fail(Kind::value, v.field, "out of range for a 32-bit float");
    bool ok = hi_inclusive ? (x <= hi && f <= hi) : (x < hi && f < hi);
    if (!ok) fail(Kind::value, v.field, std::string(hi_inclusive ? "must be <= " : "must be < ") + format_number(hi));
    return f;
}

std::string read_string(const Value& v) {
    if (!v.j.is_string()) fail(Kind::type, v.field, "expected a string, got " + type_name(v.j));
    return v.j.get<std::string>();
}

template <class E>
E read_enum(const Value& v, const char* what, const NameTable<E>& table) {
    std::string name = read_string(v);
    Names allowed;
    for (const auto& [n, e] : table) {
        if (name == n) return e;
        allowed.emplace_back(n);
    }
    fail(Kind::value, v.field,
         "unknown " + std::string(what) + " type '" + name + "'; allowed: " + join_names(allowed));
}

template <class E>
const char* name_of(const NameTable<E>& table, E e) {
    for (const auto& [n, x] : table)
        if (x == e) return n;
    return "?";
}

std::string element_prefix(std::size_t i) { return "element " + std::to_string(i) + ": "; }

// A point or direction: a list of exactly 3 finite numbers, |x| <= 1e7.
glm::vec3 read_vec3(const Value& v) {
    if (!v.j.is_array()) fail(Kind::type, v.field, "expected a list of 3 numbers, got " + type_name(v.j));
    if (v.j.size() != 3)
        fail(Kind::value, v.field, "expected a list of exactly 3 numbers, got " + std::to_string(v.j.size()));
    glm::vec3 out;
    for (std::size_t i = 0; i < 3; ++i) {
        double x = read_number(Value{v.j[i], v.field}, element_prefix(i));
        if (std::abs(x) > max_coordinate)
            fail(Kind::value, v.field, element_prefix(i) + "absurd coordinate (|x| > 1e7)");
        out[static_cast<glm::length_t>(i)] = static_cast<float>(x);
    }
    return out;
}

// An RGB value: a number (all channels) or a list of exactly 3, each in [0, hi].
Rgb read_rgb(const Value& v, double hi = infinity) {
    double c[3];
    bool list = v.j.is_array();
    if (list) {
        if (v.j.size() != 3)
            fail(Kind::value, v.field,
                 "expected a number or a list of exactly 3 numbers, got " + std::to_string(v.j.size()));
        for (std::size_t i = 0; i < 3; ++i) c[i] = read_number(Value{v.j[i], v.field}, element_prefix(i));
    } else if (v.j.is_number()) {
        c[0] = c[1] = c[2] = read_number(v);
    } else {
        fail(Kind::type, v.field, "expected a number or a list of 3 numbers, got " + type_name(v.j));
    }
    Rgb out;
    for (std::size_t i = 0; i < 3; ++i) {
        std::string prefix = list ? element_prefix(i) : "";
        if (c[i] < 0) fail(Kind::value, v.field, prefix + "must be >= 0");
        if (c[i] > hi) fail(Kind::value, v.field, prefix + "must be <= " + format_number(hi));
        float f = static_cast<float>(c[i]);
        if (!std::isfinite(f)) fail(Kind::value, v.field, prefix + "out of range for a 32-bit float");
        out[static_cast<glm::length_t>(i)] = f;
    }
    return out;
}

// A list of objects, each parsed by `parse_item`; absent means empty.
template <class T, class F>
std::vector<T> read_list(const std::optional<Value>& v, F parse_item) {
    std::vector<T> out;
    if (!v) return out;
    if (!v->j.is_array()) fail(Kind::type, v->field, "expected a list, got " + type_name(v->j));
    for (std::size_t i = 0; i < v->j.size(); ++i)
        out.push_back(parse_item(Obj(Value{v->j[i], index_path(v->field, i)})));
    return out;
}

// --- objects -----------------------------------------------------------------

Film parse_film(const Obj& o) {
    o.check_keys({"width", "height"});
    Film f;
    f.width = read_int(o.req("width"), 1, max_film_size);
    f.height = read_int(o.req("height"), 1, max_film_size);
    return f;
}

Camera parse_camera(const Obj& o) {
    o.check_keys({"position", "look_at", "up", "fov_y"});
    Camera c;
    c.position = read_vec3(o.req("position"));
    c.look_at = read_vec3(o.req("look_at"));
    c.up = read_vec3(o.req("up"));
    c.fov_y_degrees = read_positive(o.req("fov_y"), 180.0, false);
    // Degeneracy, on the stored float values.
    glm::dvec3 position(c.position), view = glm::dvec3(c.look_at) - position, up(c.up);
    if (glm::length(view) < 1e-6 * std::max(1.0, glm::length(position)))
        fail(Kind::value, join_path(o.path, "look_at"), "look_at equals position");
    double up_length = glm::length(up);
    if (up_length == 0 || glm::length(glm::cross(glm::normalize(view), up)) < 1e-6 * up_length)
        fail(Kind::value, join_path(o.path, "up"), "up is zero or parallel to the view direction");
    return c;
}

// A Henyey-Greenstein asymmetry: a number in (-1, 1). One that rounds to
// +-1 in float32 is kept as the float just inside (rendering clamps |g| to
// PHASE_G_LIMIT anyway), so that the written scene reloads.
float read_asymmetry(const Value& v) {
    double g = read_number(v);
    if (!(g > -1 && g < 1)) fail(Kind::value, v.field, "must be in (-1, 1)");
    float f = static_cast<float>(g);
    if (std::abs(f) >= 1.0f) f = std::copysign(std::nextafter(1.0f, 0.0f), f);
    return f;
}

Phase parse_phase(const Obj& o) {
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

Medium parse_medium(const Obj& o) {
    o.check_keys({"sigma_t", "albedo", "phase"});
    Medium m;
    m.sigma_t = read_rgb(o.req("sigma_t"));
    if (auto v = o.opt("albedo")) m.albedo = read_rgb(*v, 1.0);
    if (auto v = o.opt("phase")) m.phase = parse_phase(Obj(*v));
    return m;
}

// A direction: nonzero, stored unit. Directions already unit to float
// precision are kept as given, so that reloading a written scene gives the
// same bits.
glm::vec3 read_direction(const Value& v, const char* zero_message) {
    glm::dvec3 d(read_vec3(v));
    double length = glm::length(d);
    if (length < 1e-12) fail(Kind::value, v.field, zero_message);
    return std::abs(length - 1.0) > 1e-6 ? glm::vec3(d / length) : glm::vec3(d);
}

float read_light_radius(const Obj& o) {
    if (auto v = o.opt("radius")) return read_positive(*v, max_light_radius, true);
    return static_cast<float>(default_light_radius);
}

PointLight parse_point_light(const Obj& o) {
    o.check_keys({"type", "position", "intensity", "radius"});
    PointLight l;
    l.position = read_vec3(o.req("position"));
    l.intensity = read_rgb(o.req("intensity"));
    l.radius = read_light_radius(o);
    return l;
}

// Spot light (MODELS.md section 2): cone_angle is the half-angle in degrees,
// in (0, 90] (checked on the float value too); edge in [0, 1].
SpotLight parse_spot_light(const Obj& o) {
    o.check_keys({"type", "position", "direction", "intensity", "cone_angle", "edge", "radius"});
    SpotLight l;
    l.position = read_vec3(o.req("position"));
    l.direction = read_direction(o.req("direction"), "must not be zero");
    l.intensity = read_rgb(o.req("intensity"));
    Value cone = o.req("cone_angle");
    double angle = read_number(cone);
    float angle_f = static_cast<float>(angle);
    if (!(angle > 0 && angle_f > 0 && angle <= 90 && angle_f <= 90))
        fail(Kind::value, cone.field, "must be in (0, 90]");
    l.cone_angle_degrees = angle_f;
    if (auto v = o.opt("edge")) {
        double edge = read_number(*v);
        if (edge < 0 || edge > 1) fail(Kind::value, v->field, "must be in [0, 1]");
        l.edge = static_cast<float>(edge);
    }
    l.radius = read_light_radius(o);
    return l;
}

// The "lights" list: point entries go to point_lights, spot entries to
// spot_lights; field paths keep the index in the list.
void parse_lights(const std::optional<Value>& v, Scene& s) {
    if (!v) return;
    if (!v->j.is_array()) fail(Kind::type, v->field, "expected a list, got " + type_name(v->j));
    for (std::size_t i = 0; i < v->j.size(); ++i) {
        Obj o(Value{v->j[i], index_path(v->field, i)});
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

Surface parse_surface(const Obj& o) {
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

// --- writing -----------------------------------------------------------------

// The shortest decimal that reads back as `f`, as a double (so that the JSON
// text shows "0.05", not "0.05000000074505806").
double json_number(float f) {
    char buf[32];
    for (int digits = 6; digits <= 9; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, static_cast<double>(f));
        double d = std::strtod(buf, nullptr);
        if (static_cast<float>(d) == f) return d;
    }
    return static_cast<double>(f);  // unreachable: 9 digits always round-trip
}

json json_vec3(const glm::vec3& v) { return json::array({json_number(v.x), json_number(v.y), json_number(v.z)}); }

Quality parse_quality(const Obj& o) {
    o.check_keys(
        {"airlight", "march_steps", "cull_fraction", "spot_glow_samples", "sky_segments", "rainbow_wavelengths"});
    Quality q;
    if (auto v = o.opt("airlight")) q.airlight = read_enum(*v, "airlight", airlight_methods);
    if (auto v = o.opt("march_steps")) q.march_steps = read_int(*v, 1, 65536);
    if (auto v = o.opt("cull_fraction")) {
        double x = read_number(*v);
        if (x < 0 || x > 0.01) fail(Kind::value, v->field, "must be in [0, 0.01]");
        q.cull_fraction = static_cast<float>(x);
    }
    if (auto v = o.opt("spot_glow_samples")) {
        q.spot_glow_samples = read_int(*v, 4, 64);
        if (q.spot_glow_samples % 4 != 0) fail(Kind::value, v->field, "must be a multiple of 4");
    }
    if (auto v = o.opt("sky_segments")) q.sky_segments = read_int(*v, 2, 64);
    if (auto v = o.opt("rainbow_wavelengths")) {
        q.rainbow_wavelengths = read_int(*v, 3, RAINBOW_WAVELENGTHS);
        if (!is_rainbow_wavelength_count(q.rainbow_wavelengths))
            fail(Kind::value, v->field,
                 std::string("must be ") + RAINBOW_WAVELENGTH_COUNTS + " (wavelength nodes), got " +
                     std::to_string(q.rainbow_wavelengths));
    }
    return q;
}

// ---- Daytime (issue 6; README "Scene format"; docs/daytime.md) ----------------

// A number in [lo, hi], as a float.
float read_in_range(const Value& v, double lo, double hi, const char* unit = "") {
    const double x = read_number(v);
    if (!(x >= lo && x <= hi))
        fail(Kind::value, v.field,
             "must be in [" + format_number(lo) + ", " + format_number(hi) + "]" + unit + " (got " + format_number(x) +
                 ")");
    return static_cast<float>(x);
}

// CIE general sky types whose indicatrix needs the sun's position (all but
// the indicatrix-group-1 types 1, 3 and 5; ISO 15469).
bool cie_type_needs_sun(int type) { return type != 1 && type != 3 && type != 5; }

Sky parse_sky(const Obj& o) {
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
Sun parse_sun(const Obj& o) {
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

Atmosphere parse_atmosphere(const Obj& o) {
    o.check_keys({"molecules", "aerosol", "rain"});
    Atmosphere a;
    if (auto v = o.opt("molecules"); v && !v->j.is_null()) {
        Obj m(*v);
        m.check_keys({"density_scale"});
        a.molecules.present = true;
        if (auto d = m.opt("density_scale")) a.molecules.density_scale = read_in_range(*d, 0.0, 1e6);
    }
    if (auto v = o.opt("aerosol"); v && !v->j.is_null()) {
        Obj m(*v);
        m.check_keys({"visibility", "coefficient", "scale_height", "g", "albedo"});
        a.aerosol.present = true;
        const auto visibility = m.opt("visibility");
        const auto coefficient = m.opt("coefficient");
        if (visibility && coefficient)
            fail(Kind::value, coefficient->field, "give either a visibility or a coefficient, not both");
        if (visibility) {
            a.aerosol.visibility = read_positive(*visibility, 1e9, true);
        } else if (coefficient) {
            a.aerosol.coefficient = read_in_range(*coefficient, 0.0, 1e3, " per metre");
        } else {
            fail(Kind::value, join_path(m.path, "visibility"), "missing: give a visibility (m) or a coefficient (1/m)");
        }
        if (auto d = m.opt("scale_height")) a.aerosol.scale_height = read_positive(*d, 1e5, true);
        if (auto d = m.opt("g")) a.aerosol.g = read_asymmetry(*d);
        if (auto d = m.opt("albedo")) a.aerosol.albedo = read_in_range(*d, 0.0, 1.0);
    }
    if (auto v = o.opt("rain"); v && !v->j.is_null()) {
        Obj m(*v);
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

// The pupil of display.glare: a diameter in [1, 9] mm or "auto" (from the
// adaptation luminance; include/airlight/glare.hpp).
std::optional<double> read_pupil(const Value& v) {
    if (v.j.is_string()) {
        if (v.j.get<std::string>() == "auto") return std::nullopt;
        fail(Kind::value, v.field, "expected a diameter in mm or \"auto\", got '" + v.j.get<std::string>() + "'");
    }
    if (!v.j.is_number()) fail(Kind::type, v.field, "expected a diameter in mm or \"auto\", got " + type_name(v.j));
    const double d = read_number(v);
    if (!(d >= 1.0 && d <= 9.0)) fail(Kind::value, v.field, "must be in [1, 9] mm (got " + format_number(d) + ")");
    return d;
}

bool read_bool(const Value& v) {
    if (!v.j.is_boolean()) fail(Kind::type, v.field, "expected true or false, got " + type_name(v.j));
    return v.j.get<bool>();
}

// The "display" object (README "Display"): exposure, tone curve, white point
// and the eye's glare (null or absent: no glare).
DisplaySettings parse_display(const Obj& o) {
    o.check_keys({"exposure", "tonemap", "white", "glare"});
    DisplaySettings d;
    if (auto v = o.opt("exposure")) {
        if (v->j.is_string()) {
            if (v->j.get<std::string>() != "auto")
                fail(Kind::value, v->field,
                     "expected a number >= 0 or \"auto\", got '" + v->j.get<std::string>() + "'");
            d.exposure_mode = ExposureMode::automatic;
        } else {
            if (!v->j.is_number())
                fail(Kind::type, v->field, "expected a number >= 0 or \"auto\", got " + type_name(v->j));
            const double e = read_number(*v);
            if (e < 0) fail(Kind::value, v->field, "must be >= 0");
            if (!std::isfinite(static_cast<float>(e))) fail(Kind::value, v->field, "out of range for a 32-bit float");
            d.exposure_mode = ExposureMode::manual;
            d.exposure = static_cast<float>(e);
        }
    }
    if (auto v = o.opt("tonemap")) d.curve = read_enum(*v, "tone curve", tone_curves);
    if (auto v = o.opt("white")) d.white = read_positive(*v, 1e30, true);
    if (auto v = o.opt("glare"); v && !v->j.is_null()) {
        Obj g(*v);
        g.check_keys({"pupil_diameter", "eyelashes"});
        d.glare.enabled = true;
        if (auto p = g.opt("pupil_diameter")) d.glare.pupil_diameter_mm = read_pupil(*p);
        if (auto e = g.opt("eyelashes")) d.glare.eyelashes = read_bool(*e);
    }
    return d;
}

json display_to_json(const DisplaySettings& d) {
    json j;
    if (d.exposure_mode == ExposureMode::automatic)
        j["exposure"] = "auto";
    else
        j["exposure"] = json_number(d.exposure);
    j["tonemap"] = name_of(tone_curves, d.curve);
    if (d.white) j["white"] = json_number(*d.white);
    if (d.glare.enabled) {
        json g;
        if (d.glare.pupil_diameter_mm)
            g["pupil_diameter"] = *d.glare.pupil_diameter_mm;
        else
            g["pupil_diameter"] = "auto";
        g["eyelashes"] = d.glare.eyelashes;
        j["glare"] = g;
    } else {
        j["glare"] = nullptr;
    }
    return j;
}

}  // namespace

Scene parse_scene_json(const json& j) {
    if (!j.is_object()) fail(Kind::type, "", "scene must be a JSON object");
    Obj top(Value{j, ""});
    top.check_keys({"film", "camera", "medium", "lights", "surfaces", "background", "quality", "display", "sky", "sun",
                    "atmosphere"});
    Scene s;
    s.film = parse_film(Obj(top.req("film")));
    s.camera = parse_camera(Obj(top.req("camera")));
    if (auto v = top.opt("medium"); v && !v->j.is_null()) {
        s.has_medium = true;
        s.medium = parse_medium(Obj(*v));
    }
    parse_lights(top.opt("lights"), s);
    s.surfaces = read_list<Surface>(top.opt("surfaces"), parse_surface);
    if (auto v = top.opt("background")) s.background = read_rgb(*v);
    if (auto v = top.opt("quality")) s.quality = parse_quality(Obj(*v));
    if (auto v = top.opt("sky"); v && !v->j.is_null()) s.sky = parse_sky(Obj(*v));
    if (auto v = top.opt("sun"); v && !v->j.is_null()) s.sun = parse_sun(Obj(*v));
    if (auto v = top.opt("atmosphere"); v && !v->j.is_null()) s.atmosphere = parse_atmosphere(Obj(*v));
    if (s.sky.model == SkyModel::cie && cie_type_needs_sun(s.sky.cie_type) && !s.sun.present)
        fail(Kind::value, "sky.type",
             "CIE sky type " + std::to_string(s.sky.cie_type) +
                 " depends on the sun's position: add a \"sun\" (its irradiance may be 0)");
    if (auto v = top.opt("display")) s.display = parse_display(Obj(*v));
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
                   {"fov_y", json_number(s.camera.fov_y_degrees)}};
    if (s.has_medium) {
        j["medium"] = {{"sigma_t", json_vec3(s.medium.sigma_t)},
                       {"albedo", json_vec3(s.medium.albedo)},
                       {"phase", phase_to_json(s.medium.phase)}};
    } else {
        j["medium"] = nullptr;
    }
    j["lights"] = json::array();
    for (const auto& l : s.point_lights) {
        j["lights"].push_back({{"type", name_of(light_types, LightType::point)},
                               {"position", json_vec3(l.position)},
                               {"intensity", json_vec3(l.intensity)},
                               {"radius", json_number(l.radius)}});
    }
    for (const auto& l : s.spot_lights) {
        j["lights"].push_back({{"type", name_of(light_types, LightType::spot)},
                               {"position", json_vec3(l.position)},
                               {"direction", json_vec3(l.direction)},
                               {"intensity", json_vec3(l.intensity)},
                               {"cone_angle", json_number(l.cone_angle_degrees)},
                               {"edge", json_number(l.edge)},
                               {"radius", json_number(l.radius)}});
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
    j["quality"] = {{"airlight", name_of(airlight_methods, s.quality.airlight)},
                    {"march_steps", s.quality.march_steps},
                    {"cull_fraction", json_number(s.quality.cull_fraction)},
                    {"spot_glow_samples", s.quality.spot_glow_samples},
                    {"sky_segments", s.quality.sky_segments},
                    {"rainbow_wavelengths", s.quality.rainbow_wavelengths}};
    j["sky"] = sky_to_json(s.sky);
    j["sun"] = sun_to_json(s.sun);
    j["atmosphere"] = atmosphere_to_json(s.atmosphere);
    j["display"] = display_to_json(s.display);
    return j;
}

Scene parse_scene(const std::string& json_text) {
    json j;
    try {
        j = json::parse(json_text);
    } catch (const json::exception& e) {
        fail(Kind::value, "", std::string("invalid JSON: ") + e.what());
    }
    return parse_scene_json(j);
}

Scene load_scene_file(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) fail(Kind::value, "path", "cannot open '" + path + "': " + std::strerror(errno));
    std::string text;
    char buf[1 << 16];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
    int error = std::ferror(f) ? errno : 0;
    std::fclose(f);
    if (error) fail(Kind::value, "path", "cannot read '" + path + "': " + std::strerror(error));
    return parse_scene(text);
}

std::string scene_to_json(const Scene& scene, int indent) { return scene_to_json_value(scene).dump(indent); }

}  // namespace airlight
