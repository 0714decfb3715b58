// Loading, validating and writing scenes in the JSON format of the README.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "airlight/scene.hpp"

namespace airlight {

// Bounds of the scene format that the README states and Python checks before
// calling in (the native module exports them as `scene_limits`).
namespace scene_limits {
// The largest film side and film, in pixels.
constexpr int max_film_size = 16384;
constexpr long max_film_pixels = 8192L * 8192L;
// The largest scene file read (a scene of 10^5 lamps is about 10 MiB).
constexpr std::size_t max_scene_file_bytes = std::size_t(64) << 20;
// A lamp's radius, in metres: at least 1 micrometre (pi r^2 stays a normal
// float32), and its core radiance I / (pi r^2) is a radiance, at most 1e30
// like every other (a 1e-7 m lamp of 1e30 W/sr gave Inf, and NaN behind
// dense rain).
constexpr double min_light_radius = 1e-6;
constexpr double max_light_radius = 1e3;
constexpr double default_light_radius = 0.05;
// The narrowest spot, in degrees (1.7 cm wide at 1 km): below, float32 cannot
// resolve the beam's glow on surfaces (at 1e-4 degree GL's was 31 % low, the
// CPU's 0.5 %; at 1e-3 both are within 0.3 % of the reference).
constexpr double min_cone_angle = 1e-3;
}  // namespace scene_limits

// Raised for any invalid scene. `field` is the dotted path of the offending
// value ("camera.fov_y", "lights[2].intensity"); `kind` says whether the value
// had the wrong JSON type (Python TypeError) or a bad value (ValueError).
class SceneError : public std::runtime_error {
public:
    enum class Kind { type, value };
    SceneError(Kind kind, std::string field, const std::string& message)
        : std::runtime_error(field.empty() ? message : field + ": " + message), kind_(kind), field_(std::move(field)) {}
    Kind kind() const { return kind_; }
    const std::string& field() const { return field_; }

private:
    Kind kind_;
    std::string field_;
};

// A scene file that cannot be opened or read (a value error with no field):
// "scene file not found: PATH" or "cannot read scene file PATH: REASON".
class SceneFileError : public SceneError {
public:
    explicit SceneFileError(const std::string& message) : SceneError(Kind::value, "", message) {}
};

// Parses and validates a scene from JSON text. Throws SceneError; text that is
// not JSON is a value error with no field, "invalid JSON at line L, column C:
// what the parser expected".
Scene parse_scene(const std::string& json_text);

// Reads a JSON file and parses it. Throws SceneFileError for a missing or
// unreadable file, SceneError for its contents.
Scene load_scene_file(const std::string& path);

// The film size asked for by a width and/or a height, 0 meaning not given (the
// demo's --width/--height, Python's render(width=, height=)): both given, that
// size; one alone keeps the film's aspect ratio, the other side rounded to the
// nearest integer (halves up) and at least 1; neither, the film unchanged.
Film resize_film(const Film& film, int width, int height);

// Writes a scene back as JSON with every default filled in and every RGB
// value expanded to a triple; parse_scene(scene_to_json(s)) == s.
std::string scene_to_json(const Scene& scene, int indent = 2);

}  // namespace airlight
