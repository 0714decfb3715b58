// The spotlights' quality key "spot_glow_samples" (README "Scene format"),
// parsed and written back through the registry (EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp). The spot lights themselves are entries of the core's
// "lights" list.
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

void parse_spotlights_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("spot_glow_samples")) {
        s.quality.spot_glow_samples = read_int(*v, 4, 64);
        if (s.quality.spot_glow_samples % 4 != 0) fail(Kind::value, v->field, "must be a multiple of 4");
    }
}

void write_spotlights_quality(const Scene& s, json& quality) {
    quality["spot_glow_samples"] = s.quality.spot_glow_samples;
}

}  // namespace airlight
