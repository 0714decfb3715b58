// Internal: the toolkit of the scene loader (cpp/scene_io.cpp), shared with the
// effects that parse and write their own top-level scene keys (EFFECT_SCENE_KEYS
// in cmake/effects.cmake): an effect defines
//   void parse_<name>_keys(const SceneObject& top, Scene& s);
//   void write_<name>_keys(const Scene& s, nlohmann::json& j);
// in namespace airlight, called in registry order after the core's keys.
// Errors are SceneError with the dotted field path (include/airlight/scene_io.hpp).
#pragma once

#include <glm/vec3.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "airlight/scene_io.hpp"

namespace airlight::scene_keys {

using json = nlohmann::json;
using Kind = SceneError::Kind;
using Names = std::vector<std::string>;

constexpr double infinity = std::numeric_limits<double>::infinity();
// The largest intensity (W/sr), radiance (W/(m^2 sr)) or irradiance (W/m^2) a
// scene may give: 1e30 keeps every sum and product the renderer forms of them
// below float32's 3.4e38 (values near that limit gave NaN and Inf).
constexpr double max_radiometric = 1e30;
// The largest extinction coefficient (1/m): a visibility of 3.9 mm. Beyond
// it nothing is visible at all, and sigma_t near 1e37 gave NaN.
constexpr double max_extinction = 1e3;

template <class E>
using NameTable = std::vector<std::pair<const char*, E>>;

[[noreturn]] void fail(Kind kind, const std::string& field, const std::string& message);

std::string join_path(const std::string& path, const std::string& key);
std::string index_path(const std::string& path, std::size_t i);
std::string join_names(const Names& names);
// A number as "%g".
std::string format_number(double v);
// JSON type names in the vocabulary of the Python API.
std::string type_name(const json& j);

// A JSON value with the dotted path it was found at.
struct Value {
    const json& j;
    std::string field;
};

// An object being parsed.
struct SceneObject {
    const json& j;
    std::string path;

    // Throws unless the value is an object.
    explicit SceneObject(const Value& v);

    std::optional<Value> opt(const char* key) const;
    // Throws "missing required key" when absent.
    Value req(const char* key) const;
    // Rejects keys not in `allowed`, suggesting a known key within edit distance 2.
    void check_keys(const Names& allowed) const;
};

// --- value readers -----------------------------------------------------------

// A finite number (JSON integer or float; never a bool). `prefix` names the
// element of a list ("element 1: ").
double read_number(const Value& v, const std::string& prefix = "");
// An integer in [lo, hi].
int read_int(const Value& v, int lo, int hi);
// A scalar in (0, hi) or (0, hi], the bounds holding for the float value too.
float read_positive(const Value& v, double hi, bool hi_inclusive);
// A number in [lo, hi], as a float; `unit` follows the bounds in the message.
float read_in_range(const Value& v, double lo, double hi, const char* unit = "");
std::string read_string(const Value& v);
bool read_bool(const Value& v);
// A point or direction: a list of exactly 3 finite numbers, |x| <= 1e7.
glm::vec3 read_vec3(const Value& v);
// A direction: nonzero, stored unit. Directions already unit to float
// precision are kept as given, so that reloading a written scene gives the
// same bits.
glm::vec3 read_direction(const Value& v, const char* zero_message);
// An RGB value: a number (all channels) or a list of exactly 3, each in [0, hi]
// (by default a radiometric quantity, at most max_radiometric).
Rgb read_rgb(const Value& v, double hi = max_radiometric);
// A Henyey-Greenstein asymmetry: a number in (-1, 1). One that rounds to
// +-1 in float32 is kept as the float just inside (rendering clamps |g| to
// PHASE_G_LIMIT anyway), so that the written scene reloads.
float read_asymmetry(const Value& v);

// A visibility in metres, in [3.912e-3, 1e9] (Koschmieder, docs/conventions.md section 4; the
// lower bound keeps sigma_t within max_extinction).
float read_visibility(const Value& v);
// The extinction (1/m, float) of a visibility read by read_visibility: KOSCHMIEDER / V.
float visibility_extinction(float visibility);

// The one given of two alternative keys of `o`, `a` or `b`; `a_what` and
// `b_what` name them with their units in the messages ("visibility (m)").
// Fails on b's field when both are given, on a's when neither is. `first` is
// true when the key given is `a`.
struct Either {
    bool first;
    Value value;
};
Either read_either(const SceneObject& o, const char* a, const char* a_what, const char* b, const char* b_what);

// A name of `table`; `what` names the kind in the error ("unknown <what> type").
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

// A list of objects, each parsed by `parse_item`; absent means empty.
template <class T, class F>
std::vector<T> read_list(const std::optional<Value>& v, F parse_item) {
    std::vector<T> out;
    if (!v) return out;
    if (!v->j.is_array()) fail(Kind::type, v->field, "expected a list, got " + type_name(v->j));
    for (std::size_t i = 0; i < v->j.size(); ++i)
        out.push_back(parse_item(SceneObject(Value{v->j[i], index_path(v->field, i)})));
    return out;
}

// --- writing -----------------------------------------------------------------

// The shortest decimal that reads back as `f`, as a double (so that the JSON
// text shows "0.05", not "0.05000000074505806").
double json_number(float f);
json json_vec3(const glm::vec3& v);

}  // namespace airlight::scene_keys
