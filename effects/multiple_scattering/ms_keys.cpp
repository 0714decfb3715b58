// The quality keys "multiple_scattering" and "fading_rain_steps" (EFFECT_QUALITY_KEYS; README "Scene format").
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

// Every preset keeps multiple scattering on: turning it off is not a saving at
// a bounded error but a different physics (rainy days 10^5 times too dark,
// physics.md section 9).
void preset_multiple_scattering_quality(QualityPreset, Scene&) {}

void parse_multiple_scattering_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("multiple_scattering")) s.quality.multiple_scattering = read_bool(*v);
    if (auto v = quality.opt("fading_rain_steps")) s.quality.fading_rain_steps = read_int(*v, 0, 16);
}

void write_multiple_scattering_quality(const Scene& s, json& quality) {
    quality["multiple_scattering"] = s.quality.multiple_scattering;
    quality["fading_rain_steps"] = s.quality.fading_rain_steps;
}

}  // namespace airlight
