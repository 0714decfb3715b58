// The sun shadow map's quality key "sun_shadow_map" (README "Scene format"),
// parsed and written back through the registry (EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp).
#include <string>

#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

// Every preset keeps exact shadow rays: the map is no faster on these scenes
// and adds error (physics.md; its benchmark).
void preset_sun_shadow_map_quality(QualityPreset, Scene&) {}

void parse_sun_shadow_map_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("sun_shadow_map")) {
        const int n = read_int(*v, 0, 4096);
        if (n != 0 && n < 16)
            fail(Kind::value, v->field, "must be 0 (shadow rays) or in [16, 4096] (texels), got " + std::to_string(n));
        s.quality.sun_shadow_map = n;
    }
}

void write_sun_shadow_map_quality(const Scene& s, json& quality) {
    quality["sun_shadow_map"] = s.quality.sun_shadow_map;
}

}  // namespace airlight
