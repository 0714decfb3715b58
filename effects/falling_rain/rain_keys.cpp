// The falling rain's scene key "falling_rain" (README "Scene format";
// physics.md), parsed and written back through the registry
// (EFFECT_SCENE_KEYS; cpp/scene_keys.hpp).
#include <cmath>
#include <string>

#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

// After the daytime effect (effects/registry.cmake): the rate defaults to the atmosphere's rain.
void parse_falling_rain_keys(const SceneObject& top, Scene& s) {
    auto v = top.opt("falling_rain");
    if (!v || v->j.is_null()) return;
    SceneObject o(*v);
    o.check_keys({"rate", "radius", "full_diameter", "wind", "time", "seed"});
    FallingRain& r = s.falling_rain;
    r.present = true;
    if (auto x = o.opt("rate")) {
        r.rate = read_in_range(*x, 0.0, 2000.0, " mm/h");  // the 1-minute world record is ~1900 mm/h
    } else if (s.atmosphere.rain.present) {
        r.rate = s.atmosphere.rain.rate * s.atmosphere.rain.density_scale;
    } else {
        fail(Kind::value, join_path(o.path, "rate"),
             "missing: give the rain rate (mm/h) or an atmosphere with rain, whose rate it then takes");
    }
    if (auto x = o.opt("radius")) r.radius = read_in_range(*x, 0.1, 200.0, " m");
    if (auto x = o.opt("full_diameter")) r.full_diameter = read_in_range(*x, 0.1, 6.0, " mm");
    if (auto x = o.opt("wind")) {
        r.wind = read_vec3(*x);
        if (r.wind.y != 0.0f) fail(Kind::value, x->field, "the wind is horizontal: give y = 0");
        if (std::hypot(r.wind.x, r.wind.z) > 100.0f) fail(Kind::value, x->field, "must be at most 100 m/s");
    }
    if (auto x = o.opt("time")) {
        r.time = read_number(*x);
        if (std::abs(r.time) > 1e7) fail(Kind::value, x->field, "must be within 1e7 s of 0");
    }
    if (auto x = o.opt("seed")) r.seed = std::uint32_t(read_int(*x, 0, 2147483647));
}

void write_falling_rain_keys(const Scene& s, json& j) {
    if (!s.falling_rain.present) {
        j["falling_rain"] = nullptr;
        return;
    }
    const FallingRain& r = s.falling_rain;
    j["falling_rain"] = {{"rate", json_number(r.rate)},
                         {"radius", json_number(r.radius)},
                         {"full_diameter", json_number(r.full_diameter)},
                         {"wind", json_vec3(r.wind)},
                         {"time", r.time},
                         {"seed", r.seed}};
}

}  // namespace airlight
