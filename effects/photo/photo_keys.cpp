// The photo effect's scene key "atmospheric_light" (README "Scene format"),
// parsed and written back through the registry (EFFECT_SCENE_KEYS).
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

void parse_photo_keys(const SceneObject& top, Scene& s) {
    if (auto v = top.opt("atmospheric_light")) s.atmospheric_light = read_rgb(*v);
}

void write_photo_keys(const Scene& s, json& j) { j["atmospheric_light"] = json_vec3(s.atmospheric_light); }

}  // namespace airlight
