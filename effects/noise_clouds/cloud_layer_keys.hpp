// The keys both cloud methods share (CloudLayer, clouds_scene.hpp): parsed
// and written once, for "clouds" (clouds_keys.cpp) and "particle_clouds"
// (effects/particle_clouds/particle_keys.cpp).
#pragma once

#include "scene_keys.hpp"

namespace airlight {

// The shared keys' names followed by `own`, a method's allowed keys (check_keys).
scene_keys::Names cloud_layer_keys_and(scene_keys::Names own);

// Reads base, top, coverage, extinction, shape_scale, wind, time and seed
// into `layer` (keeping its defaults for those absent); sets present.
void parse_cloud_layer(const scene_keys::SceneObject& o, CloudLayer& layer);
// Writes them into the object `j`.
void write_cloud_layer(const CloudLayer& layer, nlohmann::json& j);

}  // namespace airlight
