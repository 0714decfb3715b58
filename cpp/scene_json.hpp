// Internal: the scene loader on parsed JSON values, shared by scene_io.cpp and
// the Python module (which converts a dict straight into nlohmann::json, so
// values may hold NaN/Inf; they are rejected as "must be finite").
#pragma once

#include <nlohmann/json.hpp>

#include "airlight/scene_io.hpp"

namespace airlight {

// Validates a JSON value and builds the scene. Throws SceneError.
Scene parse_scene_json(const nlohmann::json& j);

// The scene as a JSON value: every default filled in, every RGB a triple,
// surfaces with only the keys of their type, a missing medium as null.
nlohmann::json scene_to_json_value(const Scene& s);

}  // namespace airlight
