// The display effect's scene key: "display" (README "Display"), parsed and
// written back through the registry (EFFECT_SCENE_KEYS; cpp/scene_keys.hpp).
#include <cmath>
#include <optional>
#include <string>

#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {

const NameTable<ToneCurve> tone_curves{{"linear", ToneCurve::linear},
                                       {"loglog", ToneCurve::loglog},
                                       {"reinhard", ToneCurve::reinhard},
                                       {"filmic", ToneCurve::filmic}};

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

// The "display" object (README "Display"): exposure, tone curve, white point,
// the eye's glare (null or absent: no glare) and dithering (default true).
DisplaySettings parse_display(const SceneObject& o) {
    o.check_keys({"exposure", "tonemap", "white", "glare", "dither"});
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
        SceneObject g(*v);
        g.check_keys({"pupil_diameter", "eyelashes"});
        d.glare.enabled = true;
        if (auto p = g.opt("pupil_diameter")) d.glare.pupil_diameter_mm = read_pupil(*p);
        if (auto e = g.opt("eyelashes")) d.glare.eyelashes = read_bool(*e);
    }
    if (auto v = o.opt("dither")) d.dither = read_bool(*v);
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
    j["dither"] = d.dither;
    return j;
}

}  // namespace

// "display" (absent: the defaults; unlike the other keys, null is not accepted).
void parse_display_keys(const SceneObject& top, Scene& s) {
    if (auto v = top.opt("display")) s.display = parse_display(SceneObject(*v));
}

void write_display_keys(const Scene& s, json& j) { j["display"] = display_to_json(s.display); }

}  // namespace airlight
