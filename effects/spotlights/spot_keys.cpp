// The spotlights' quality keys "spot_glow_samples" and "spot_lists" (README "Scene format"),
// parsed and written back through the registry (EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp). The spot lights themselves are entries of the core's
// "lights" list.
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

namespace {
const NameTable<SpotLists> spot_lists_names{{"tiles", SpotLists::tiles}, {"all", SpotLists::all}};
}  // namespace

// Samples of a spot's glow quadrature under each preset (effects/spotlights/docs/spot_table.md
// section 9: 8 about 5e-3, 12 about 8e-4, 16 about 5e-4 relative).
void preset_spotlights_quality(QualityPreset preset, Scene& s) {
    if (preset == QualityPreset::fast) s.quality.spot_glow_samples = 8;
    if (preset == QualityPreset::reference) s.quality.spot_glow_samples = 32;
}

void parse_spotlights_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("spot_glow_samples")) {
        s.quality.spot_glow_samples = read_int(*v, 4, 64);
        if (s.quality.spot_glow_samples % 4 != 0) fail(Kind::value, v->field, "must be a multiple of 4");
    }
    if (auto v = quality.opt("spot_lists")) s.quality.spot_lists = read_enum(*v, "spot_lists", spot_lists_names);
}

void write_spotlights_quality(const Scene& s, json& quality) {
    quality["spot_glow_samples"] = s.quality.spot_glow_samples;
    quality["spot_lists"] = name_of(spot_lists_names, s.quality.spot_lists);
}

}  // namespace airlight
