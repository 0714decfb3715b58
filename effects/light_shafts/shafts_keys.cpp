// The light shafts' quality key "shafts" (README "Scene format"), parsed and
// written back through the registry (EFFECT_QUALITY_KEYS; cpp/scene_keys.hpp).
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {
const NameTable<ShaftsMethod> shafts_methods{
    {"analytic", ShaftsMethod::analytic}, {"march", ShaftsMethod::march}, {"off", ShaftsMethod::off}};
}

// Every preset keeps the analytic shafts: they are exact (physics.md) and the
// cheapest way to get shadows in the air; "off" is a different image, "march"
// a comparison.
void preset_light_shafts_quality(QualityPreset, Scene&) {}

void parse_light_shafts_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("shafts")) s.quality.shafts = read_enum(*v, "shafts", shafts_methods);
}

void write_light_shafts_quality(const Scene& s, json& quality) {
    quality["shafts"] = name_of(shafts_methods, s.quality.shafts);
}

}  // namespace airlight
