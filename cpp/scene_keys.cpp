// The scene loader's toolkit (cpp/scene_keys.hpp): objects, value readers and
// JSON number formatting, shared by the core's keys and the effects'.
#include "scene_keys.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <glm/geometric.hpp>

namespace airlight::scene_keys {
namespace {

constexpr double max_coordinate = 1e7;

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

std::string element_prefix(std::size_t i) { return "element " + std::to_string(i) + ": "; }

}  // namespace

// `text` fit for a one-line message: control bytes (NUL included, which
// would end a C string) escaped as \xNN, and cut after kMessagePart bytes
// (at a UTF-8 character boundary) with the length left out: a 100 MB
// unknown key is not echoed whole.
std::string printable(const std::string& text) {
    constexpr std::size_t kMessagePart = 200;
    std::string out;
    std::size_t i = 0;
    for (; i < text.size() && out.size() < kMessagePart; ++i) {
        const unsigned char c = static_cast<unsigned char>(text[i]);
        if (c < 0x20 || c == 0x7f) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
            out += escaped;
        } else {
            out += char(c);
        }
    }
    while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) out += text[i++];
    if (i < text.size()) out += "... (" + std::to_string(text.size() - i) + " more bytes)";
    return out;
}

void fail(Kind kind, const std::string& field, const std::string& message) {
    throw SceneError(kind, printable(field), printable(message));
}

// An empty key (valid JSON) is shown as "" so that the path still names it.
std::string join_path(const std::string& path, const std::string& key) {
    const std::string shown = key.empty() ? std::string("\"\"") : key;
    return path.empty() ? shown : path + "." + shown;
}

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

// --- SceneObject ---------------------------------------------------------------

SceneObject::SceneObject(const Value& v) : j(v.j), path(v.field) {
    if (!j.is_object()) fail(Kind::type, path, "expected an object, got " + type_name(j));
}

std::optional<Value> SceneObject::opt(const char* key) const {
    auto it = j.find(key);
    if (it == j.end()) return std::nullopt;
    return Value{*it, join_path(path, key)};
}

Value SceneObject::req(const char* key) const {
    auto v = opt(key);
    if (!v) fail(Kind::value, join_path(path, key), "missing required key");
    return *v;
}

void SceneObject::check_keys(const Names& allowed) const {
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

// --- value readers -----------------------------------------------------------

double read_number(const Value& v, const std::string& prefix) {
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

float read_positive(const Value& v, double hi, bool hi_inclusive) {
    double x = read_number(v);
    float f = static_cast<float>(x);
    if (!(x > 0 && f > 0)) fail(Kind::value, v.field, "must be > 0");
    if (!std::isfinite(f)) fail(Kind::value, v.field, "out of range for a 32-bit float");
    // The bound holds for the float value too, compared with the bound's own float (float(1e30) > 1e30).
    const float hi_f = static_cast<float>(hi);
    bool ok = hi_inclusive ? (x <= hi && f <= hi_f) : (x < hi && f < hi_f);
    if (!ok) fail(Kind::value, v.field, std::string(hi_inclusive ? "must be <= " : "must be < ") + format_number(hi));
    return f;
}

float read_in_range(const Value& v, double lo, double hi, const char* unit) {
    const double x = read_number(v);
    if (!(x >= lo && x <= hi))
        fail(Kind::value, v.field,
             "must be in [" + format_number(lo) + ", " + format_number(hi) + "]" + unit + " (got " + format_number(x) +
                 ")");
    return static_cast<float>(x);
}

std::string read_string(const Value& v) {
    if (!v.j.is_string()) fail(Kind::type, v.field, "expected a string, got " + type_name(v.j));
    return v.j.get<std::string>();
}

bool read_bool(const Value& v) {
    if (!v.j.is_boolean()) fail(Kind::type, v.field, "expected true or false, got " + type_name(v.j));
    return v.j.get<bool>();
}

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

glm::vec3 read_direction(const Value& v, const char* zero_message) {
    glm::dvec3 d(read_vec3(v));
    double length = glm::length(d);
    if (length < 1e-12) fail(Kind::value, v.field, zero_message);
    return std::abs(length - 1.0) > 1e-6 ? glm::vec3(d / length) : glm::vec3(d);
}

Rgb read_rgb(const Value& v, double hi) {
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

float read_asymmetry(const Value& v) {
    double g = read_number(v);
    if (!(g > -1 && g < 1)) fail(Kind::value, v.field, "must be in (-1, 1)");
    float f = static_cast<float>(g);
    if (std::abs(f) >= 1.0f) f = std::copysign(std::nextafter(1.0f, 0.0f), f);
    return f;
}

float read_visibility(const Value& v) {
    const float visibility = read_positive(v, 1e9, true);
    // Koschmieder's sigma_t stays within max_extinction.
    if (visibility < static_cast<float>(KOSCHMIEDER / max_extinction))
        fail(Kind::value, v.field,
             "must be >= " + format_number(KOSCHMIEDER / max_extinction) + " (sigma_t <= 1000 /m)");
    return visibility;
}

float visibility_extinction(float visibility) { return static_cast<float>(KOSCHMIEDER / double(visibility)); }

Either read_either(const SceneObject& o, const char* a, const char* a_what, const char* b, const char* b_what) {
    const auto va = o.opt(a);
    const auto vb = o.opt(b);
    if (va && vb) fail(Kind::value, vb->field, std::string("give either ") + a_what + " or " + b_what + ", not both");
    if (va) return Either{true, *va};
    if (vb) return Either{false, *vb};
    fail(Kind::value, join_path(o.path, a), std::string("missing required key: give ") + a_what + " or " + b_what);
}

// --- writing -----------------------------------------------------------------

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

}  // namespace airlight::scene_keys
