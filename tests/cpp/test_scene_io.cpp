// Tests of the scene loader (cpp/scene_io.cpp): every validation rule of the
// README "Scene format", the README example, and exact round trips.
// Self-contained: prints each failure, exits non-zero if any.
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "airlight/scene_io.hpp"
#include "scene_json.hpp"

using airlight::SceneError;
using json = nlohmann::json;
using Kind = SceneError::Kind;

namespace {

int checks = 0;
int failures = 0;

void check(bool ok, const std::string& what, const char* file, int line) {
    ++checks;
    if (!ok) {
        ++failures;
        std::printf("FAIL %s:%d: %s\n", file, line, what.c_str());
    }
}

#define CHECK(cond) check((cond), #cond, __FILE__, __LINE__)
#define CHECK_MSG(cond, msg) check((cond), std::string(#cond) + " [" + (msg) + "]", __FILE__, __LINE__)

const double nan = std::numeric_limits<double>::quiet_NaN();
const double inf = std::numeric_limits<double>::infinity();

// The README example, verbatim.
const char* readme_example =
    R"({"film": {"width": 320, "height": 240}, "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], )"
    R"("up": [0, 1, 0], "fov_y": 60}, "medium": {"sigma_t": 0.05, "albedo": 1.0, "phase": {"type": "isotropic"}}, )"
    R"("lights": [{"type": "point", "position": [3, 5, -20], "intensity": [100, 90, 70]}], "surfaces": [{"type": )"
    R"("plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.3, 0.3, 0.3]}, {"type": "box", "min": )"
    R"([-8, 0, -40], "max": [-4, 12, -25], "albedo": 0.5}], "background": [0, 0, 0]})";

// A spot light with every key given.
json spot_light() {
    return {{"type", "spot"},   {"position", {1, 4, -8}}, {"direction", {0, -1, 0}}, {"intensity", {500, 450, 400}},
            {"cone_angle", 25}, {"edge", 0.15},           {"radius", 0.08}};
}

// The README example plus a sphere (surfaces[2]), a second point light and a
// spot light (lights[2]).
json base_scene() {
    json j = json::parse(readme_example);
    j["surfaces"].push_back({{"type", "sphere"}, {"center", {0, 1, -15}}, {"radius", 1.5}});
    j["lights"].push_back({{"type", "point"}, {"position", {0, 3, -5}}, {"intensity", 10}, {"radius", 0.1}});
    j["lights"].push_back(spot_light());
    return j;
}

bool same(const glm::vec3& a, const glm::vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// Exact (bitwise-value) equality of two scenes; unused medium fields ignored.
bool same_scene(const airlight::Scene& a, const airlight::Scene& b) {
    bool ok = a.film.width == b.film.width && a.film.height == b.film.height &&
              same(a.camera.position, b.camera.position) && same(a.camera.look_at, b.camera.look_at) &&
              same(a.camera.up, b.camera.up) && a.camera.fov_y_degrees == b.camera.fov_y_degrees &&
              a.has_medium == b.has_medium && same(a.background, b.background) &&
              a.point_lights.size() == b.point_lights.size() && a.spot_lights.size() == b.spot_lights.size() &&
              a.surfaces.size() == b.surfaces.size();
    if (!ok) return false;
    if (a.has_medium && !(same(a.medium.sigma_t, b.medium.sigma_t) && same(a.medium.albedo, b.medium.albedo) &&
                          a.medium.phase.type == b.medium.phase.type && a.medium.phase.g == b.medium.phase.g &&
                          a.medium.phase.forward_g == b.medium.phase.forward_g &&
                          a.medium.phase.backward_g == b.medium.phase.backward_g &&
                          a.medium.phase.forward_weight == b.medium.phase.forward_weight))
        return false;
    for (std::size_t i = 0; i < a.point_lights.size(); ++i) {
        const auto &x = a.point_lights[i], &y = b.point_lights[i];
        if (!(same(x.position, y.position) && same(x.intensity, y.intensity) && x.radius == y.radius &&
              x.volumetric_shadows == y.volumetric_shadows))
            return false;
    }
    for (std::size_t i = 0; i < a.spot_lights.size(); ++i) {
        const auto &x = a.spot_lights[i], &y = b.spot_lights[i];
        if (!(same(x.position, y.position) && same(x.direction, y.direction) && same(x.intensity, y.intensity) &&
              x.cone_angle_degrees == y.cone_angle_degrees && x.edge == y.edge && x.radius == y.radius &&
              x.volumetric_shadows == y.volumetric_shadows))
            return false;
    }
    for (std::size_t i = 0; i < a.surfaces.size(); ++i) {
        const auto &x = a.surfaces[i], &y = b.surfaces[i];
        if (!(x.type == y.type && same(x.point, y.point) && same(x.normal, y.normal) && same(x.box_min, y.box_min) &&
              same(x.box_max, y.box_max) && same(x.center, y.center) && x.radius == y.radius &&
              same(x.albedo, y.albedo)))
            return false;
    }
    const airlight::Atmosphere &aa = a.atmosphere, &ab = b.atmosphere;
    if (!(a.sky.model == b.sky.model && a.sky.cie_type == b.sky.cie_type &&
          same(a.sky.zenith_radiance, b.sky.zenith_radiance) && a.sun.present == b.sun.present &&
          same(a.sun.direction, b.sun.direction) && same(a.sun.irradiance, b.sun.irradiance) &&
          a.quality.sky_segments == b.quality.sky_segments && aa.molecules.present == ab.molecules.present &&
          aa.molecules.density_scale == ab.molecules.density_scale && aa.aerosol.present == ab.aerosol.present &&
          aa.aerosol.visibility == ab.aerosol.visibility && aa.aerosol.coefficient == ab.aerosol.coefficient &&
          aa.aerosol.scale_height == ab.aerosol.scale_height && aa.aerosol.g == ab.aerosol.g &&
          aa.aerosol.albedo == ab.aerosol.albedo && aa.rain.present == ab.rain.present &&
          aa.rain.rate == ab.rain.rate && aa.rain.density_scale == ab.rain.density_scale &&
          aa.rain.top == ab.rain.top && aa.rain.g == ab.rain.g))
        return false;
    const airlight::DisplaySettings &da = a.display, &db = b.display;
    return da.exposure_mode == db.exposure_mode &&
           (da.exposure_mode == airlight::ExposureMode::automatic || da.exposure == db.exposure) &&
           da.curve == db.curve && da.white == db.white && da.glare.enabled == db.glare.enabled &&
           (!da.glare.enabled ||
            (da.glare.pupil_diameter_mm == db.glare.pupil_diameter_mm && da.glare.eyelashes == db.glare.eyelashes));
}

struct BadCase {
    const char* name;
    std::function<void(json&)> mutate;
    Kind kind;
    const char* field;
    const char* message;  // substring of the message
};

const std::vector<BadCase> bad_cases = {
    // Top level.
    {"scene not an object", [](json& j) { j = json::array({1}); }, Kind::type, "", "scene must be a JSON object"},
    {"scene null", [](json& j) { j = nullptr; }, Kind::type, "", "scene must be a JSON object"},
    {"typo key", [](json& j) { j["camra"] = j["camera"]; }, Kind::value, "camra",
     "unknown key; did you mean 'camera'?"},
    {"unknown key", [](json& j) { j["zzzzzzz"] = 1; }, Kind::value, "zzzzzzz", "unknown key"},
    {"typo lights", [](json& j) { j["light"] = json::array(); }, Kind::value, "light", "did you mean 'lights'?"},
    {"missing film", [](json& j) { j.erase("film"); }, Kind::value, "film", "missing required key"},
    {"missing camera", [](json& j) { j.erase("camera"); }, Kind::value, "camera", "missing required key"},
    {"film not object", [](json& j) { j["film"] = 5; }, Kind::type, "film", "expected an object"},
    {"camera null", [](json& j) { j["camera"] = nullptr; }, Kind::type, "camera", "expected an object"},
    // Film.
    {"width 0", [](json& j) { j["film"]["width"] = 0; }, Kind::value, "film.width", "must be in [1, 16384]"},
    {"film beyond 64 megapixels",
     [](json& j) {
         j["film"]["width"] = 16384;
         j["film"]["height"] = 16384;
     },
     Kind::value, "film.height", "film of 16384 x 16384 pixels exceeds 67108864 pixels"},
    {"width negative", [](json& j) { j["film"]["width"] = -5; }, Kind::value, "film.width", "must be in"},
    {"width huge", [](json& j) { j["film"]["width"] = 16385; }, Kind::value, "film.width", "must be in"},
    {"height uint64", [](json& j) { j["film"]["height"] = 18446744073709551615ull; }, Kind::value, "film.height",
     "must be in"},
    {"width float", [](json& j) { j["film"]["width"] = 320.5; }, Kind::value, "film.width", "must be an integer"},
    {"width 1e300", [](json& j) { j["film"]["width"] = 1e300; }, Kind::value, "film.width", "must be in"},
    {"width string", [](json& j) { j["film"]["width"] = "320"; }, Kind::type, "film.width",
     "expected a number, got string"},
    {"width bool", [](json& j) { j["film"]["width"] = true; }, Kind::type, "film.width",
     "expected a number, got boolean"},
    {"width NaN", [](json& j) { j["film"]["width"] = nan; }, Kind::value, "film.width", "must be finite"},
    {"height missing", [](json& j) { j["film"].erase("height"); }, Kind::value, "film.height", "missing required key"},
    {"film extra", [](json& j) { j["film"]["depth"] = 3; }, Kind::value, "film.depth", "unknown key"},
    {"film typo", [](json& j) { j["film"]["widht"] = 3; }, Kind::value, "film.widht", "did you mean 'width'?"},
    // Camera.
    {"fov 0", [](json& j) { j["camera"]["fov_y"] = 0; }, Kind::value, "camera.fov_y", "must be > 0"},
    {"fov negative", [](json& j) { j["camera"]["fov_y"] = -10; }, Kind::value, "camera.fov_y", "must be > 0"},
    {"fov 180", [](json& j) { j["camera"]["fov_y"] = 180; }, Kind::value, "camera.fov_y", "must be < 180"},
    {"fov 180 as float", [](json& j) { j["camera"]["fov_y"] = 179.999999999; }, Kind::value, "camera.fov_y",
     "must be < 180"},
    {"fov NaN", [](json& j) { j["camera"]["fov_y"] = nan; }, Kind::value, "camera.fov_y", "must be finite"},
    {"fov inf", [](json& j) { j["camera"]["fov_y"] = inf; }, Kind::value, "camera.fov_y", "must be finite"},
    {"fov string", [](json& j) { j["camera"]["fov_y"] = "60"; }, Kind::type, "camera.fov_y",
     "expected a number, got string"},
    {"fov bool", [](json& j) { j["camera"]["fov_y"] = false; }, Kind::type, "camera.fov_y", "expected a number"},
    {"fov missing", [](json& j) { j["camera"].erase("fov_y"); }, Kind::value, "camera.fov_y", "missing required key"},
    {"fov typo", [](json& j) { j["camera"]["fovy"] = 60; }, Kind::value, "camera.fovy", "did you mean 'fov_y'?"},
    {"look_at missing", [](json& j) { j["camera"].erase("look_at"); }, Kind::value, "camera.look_at",
     "missing required key"},
    {"position short",
     [](json& j) {
         j["camera"]["position"] = {0, 1};
     },
     Kind::value, "camera.position", "exactly 3"},
    {"position long",
     [](json& j) {
         j["camera"]["position"] = {0, 1, 2, 3};
     },
     Kind::value, "camera.position", "exactly 3"},
    {"position string", [](json& j) { j["camera"]["position"] = "origin"; }, Kind::type, "camera.position",
     "expected a list"},
    {"position scalar", [](json& j) { j["camera"]["position"] = 0; }, Kind::type, "camera.position", "expected a list"},
    {"position null", [](json& j) { j["camera"]["position"] = nullptr; }, Kind::type, "camera.position", "got null"},
    {"position bool elem",
     [](json& j) {
         j["camera"]["position"] = {0, true, 0};
     },
     Kind::type, "camera.position", "expected a number, got boolean"},
    {"position string elem",
     [](json& j) {
         j["camera"]["position"] = {0, "1", 0};
     },
     Kind::type, "camera.position", "expected a number, got string"},
    {"position NaN",
     [](json& j) {
         j["camera"]["position"] = {0, nan, 0};
     },
     Kind::value, "camera.position", "must be finite"},
    {"position -inf",
     [](json& j) {
         j["camera"]["position"] = {-inf, 0, 0};
     },
     Kind::value, "camera.position", "must be finite"},
    {"position absurd",
     [](json& j) {
         j["camera"]["position"] = {0, 2e7, 0};
     },
     Kind::value, "camera.position", "absurd coordinate"},
    {"look_at absurd",
     [](json& j) {
         j["camera"]["look_at"] = {0, 0, -1.5e7};
     },
     Kind::value, "camera.look_at", "absurd coordinate"},
    {"up NaN",
     [](json& j) {
         j["camera"]["up"] = {0, nan, 0};
     },
     Kind::value, "camera.up", "must be finite"},
    {"look_at = position",
     [](json& j) {
         j["camera"]["look_at"] = {0, 1.7, 0};
     },
     Kind::value, "camera.look_at", "look_at equals position"},
    {"look_at ~ position",
     [](json& j) {
         j["camera"]["look_at"] = {0, 1.7, 1e-8};
     },
     Kind::value, "camera.look_at", "closer to position than float32 resolves"},
    {"look_at within rounding far out",
     [](json& j) {
         j["camera"]["position"] = {1e7, 0, 1e7};
         j["camera"]["look_at"] = {1e7, 0, 1e7 - 2};
     },
     Kind::value, "camera.look_at", "closer to position than float32 resolves"},
    {"up zero",
     [](json& j) {
         j["camera"]["up"] = {0, 0, 0};
     },
     Kind::value, "camera.up", "parallel"},
    {"up parallel",
     [](json& j) {
         j["camera"]["up"] = {0, 0, -1};
     },
     Kind::value, "camera.up", "parallel"},
    {"up antiparallel",
     [](json& j) {
         j["camera"]["up"] = {0, 0, 5};
     },
     Kind::value, "camera.up", "parallel"},
    // Medium.
    {"medium scalar", [](json& j) { j["medium"] = 5; }, Kind::type, "medium", "expected an object"},
    {"medium list", [](json& j) { j["medium"] = json::array(); }, Kind::type, "medium", "expected an object"},
    {"sigma_t missing", [](json& j) { j["medium"].erase("sigma_t"); }, Kind::value, "medium.sigma_t",
     "missing required key"},
    {"sigma_t negative", [](json& j) { j["medium"]["sigma_t"] = -1; }, Kind::value, "medium.sigma_t", "must be >= 0"},
    {"sigma_t negative elem",
     [](json& j) {
         j["medium"]["sigma_t"] = {0.1, -0.1, 0};
     },
     Kind::value, "medium.sigma_t", "must be >= 0"},
    {"sigma_t short",
     [](json& j) {
         j["medium"]["sigma_t"] = {0.1, 0.2};
     },
     Kind::value, "medium.sigma_t", "exactly 3"},
    {"sigma_t string", [](json& j) { j["medium"]["sigma_t"] = "thick"; }, Kind::type, "medium.sigma_t", "got string"},
    {"sigma_t bool", [](json& j) { j["medium"]["sigma_t"] = true; }, Kind::type, "medium.sigma_t", "got boolean"},
    {"sigma_t bool elem",
     [](json& j) {
         j["medium"]["sigma_t"] = {0.1, false, 0.1};
     },
     Kind::type, "medium.sigma_t", "expected a number, got boolean"},
    {"sigma_t NaN", [](json& j) { j["medium"]["sigma_t"] = nan; }, Kind::value, "medium.sigma_t", "must be finite"},
    {"sigma_t inf elem",
     [](json& j) {
         j["medium"]["sigma_t"] = {0.1, inf, 0.1};
     },
     Kind::value, "medium.sigma_t", "must be finite"},
    {"sigma_t beyond float", [](json& j) { j["medium"]["sigma_t"] = 1e39; }, Kind::value, "medium.sigma_t",
     "must be <= 1000"},
    {"sigma_t beyond max_extinction", [](json& j) { j["medium"]["sigma_t"] = {0.1, 1001, 0.1}; }, Kind::value,
     "medium.sigma_t", "element 1: must be <= 1000"},
    {"intensity beyond max_radiometric", [](json& j) { j["lights"][0]["intensity"] = 1.5e30; }, Kind::value,
     "lights[0].intensity", "must be <= 1e+30"},
    {"background beyond max_radiometric", [](json& j) { j["background"] = 3e38; }, Kind::value, "background",
     "must be <= 1e+30"},
    {"medium albedo > 1", [](json& j) { j["medium"]["albedo"] = 1.5; }, Kind::value, "medium.albedo", "must be <= 1"},
    {"medium albedo elem > 1",
     [](json& j) {
         j["medium"]["albedo"] = {0.5, 0.5, 1.01};
     },
     Kind::value, "medium.albedo", "must be <= 1"},
    {"medium albedo < 0", [](json& j) { j["medium"]["albedo"] = -0.1; }, Kind::value, "medium.albedo", "must be >= 0"},
    {"medium typo", [](json& j) { j["medium"]["sigma"] = 1; }, Kind::value, "medium.sigma", "did you mean 'sigma_t'?"},
    // A medium given by its visibility (issue 17): exactly one of sigma_t and visibility.
    {"medium both amounts", [](json& j) { j["medium"]["visibility"] = 100; }, Kind::value, "medium.visibility",
     "give either sigma_t (1/m) or visibility (m), not both"},
    {"medium without amount", [](json& j) { j["medium"].erase("sigma_t"); }, Kind::value, "medium.sigma_t",
     "or visibility (m)"},
    {"medium visibility zero",
     [](json& j) {
         j["medium"].erase("sigma_t");
         j["medium"]["visibility"] = 0;
     },
     Kind::value, "medium.visibility", "must be > 0"},
    {"medium visibility negative",
     [](json& j) {
         j["medium"].erase("sigma_t");
         j["medium"]["visibility"] = -50;
     },
     Kind::value, "medium.visibility", "must be > 0"},
    {"medium visibility huge",
     [](json& j) {
         j["medium"].erase("sigma_t");
         j["medium"]["visibility"] = 2e9;
     },
     Kind::value, "medium.visibility", "must be <= 1e+09"},
    {"medium visibility list",
     [](json& j) {
         j["medium"].erase("sigma_t");
         j["medium"]["visibility"] = {100, 100, 100};
     },
     Kind::type, "medium.visibility", "expected a number"},
    {"medium visibility typo", [](json& j) { j["medium"]["visibilty"] = 100; }, Kind::value, "medium.visibilty",
     "did you mean 'visibility'?"},
    {"phase unknown type", [](json& j) { j["medium"]["phase"]["type"] = "mie"; }, Kind::value, "medium.phase.type",
     "isotropic"},
    {"hg without g", [](json& j) { j["medium"]["phase"]["type"] = "hg"; }, Kind::value, "medium.phase.g",
     "missing required key"},
    {"hg g = 1", [](json& j) { j["medium"]["phase"] = {{"type", "hg"}, {"g", 1.0}}; }, Kind::value, "medium.phase.g",
     "(-1, 1)"},
    {"hg g = -1", [](json& j) { j["medium"]["phase"] = {{"type", "hg"}, {"g", -1}}; }, Kind::value, "medium.phase.g",
     "(-1, 1)"},
    {"hg g a string", [](json& j) { j["medium"]["phase"] = {{"type", "hg"}, {"g", "0.8"}}; }, Kind::type,
     "medium.phase.g", "expected a number"},
    {"isotropic with g", [](json& j) { j["medium"]["phase"] = {{"type", "isotropic"}, {"g", 0.5}}; }, Kind::value,
     "medium.phase.g", "unknown key"},
    {"rayleigh with g", [](json& j) { j["medium"]["phase"] = {{"type", "rayleigh"}, {"g", 0.5}}; }, Kind::value,
     "medium.phase.g", "unknown key"},
    {"hg2 weight > 1",
     [](json& j) {
         j["medium"]["phase"] = {{"type", "hg2"}, {"forward_g", 0.8}, {"backward_g", -0.3}, {"forward_weight", 1.5}};
     },
     Kind::value, "medium.phase.forward_weight", "[0, 1]"},
    {"hg2 backward_g missing",
     [](json& j) { j["medium"]["phase"] = {{"type", "hg2"}, {"forward_g", 0.8}, {"forward_weight", 0.5}}; },
     Kind::value, "medium.phase.backward_g", "missing required key"},
    {"hg2 typo",
     [](json& j) {
         j["medium"]["phase"] = {
             {"type", "hg2"}, {"forward_g", 0.8}, {"backward_g", -0.3}, {"forward_weight", 0.5}, {"forward_gg", 1}};
     },
     Kind::value, "medium.phase.forward_gg", "did you mean 'forward_g'?"},
    {"phase type missing", [](json& j) { j["medium"]["phase"] = json::object(); }, Kind::value, "medium.phase.type",
     "missing required key"},
    {"phase type number", [](json& j) { j["medium"]["phase"]["type"] = 3; }, Kind::type, "medium.phase.type",
     "expected a string"},
    {"phase not object", [](json& j) { j["medium"]["phase"] = "isotropic"; }, Kind::type, "medium.phase",
     "expected an object"},
    {"phase extra key", [](json& j) { j["medium"]["phase"]["g"] = 0.5; }, Kind::value, "medium.phase.g", "unknown key"},
    // Lights.
    {"lights object", [](json& j) { j["lights"] = json::object(); }, Kind::type, "lights", "expected a list"},
    {"lights null", [](json& j) { j["lights"] = nullptr; }, Kind::type, "lights", "expected a list"},
    {"light not object", [](json& j) { j["lights"][0] = 5; }, Kind::type, "lights[0]", "expected an object"},
    {"light type missing", [](json& j) { j["lights"][0].erase("type"); }, Kind::value, "lights[0].type",
     "missing required key"},
    {"light type unknown", [](json& j) { j["lights"][0]["type"] = "area"; }, Kind::value, "lights[0].type",
     "unknown light type 'area'; allowed: point, spot"},
    {"light type number", [](json& j) { j["lights"][0]["type"] = 1; }, Kind::type, "lights[0].type",
     "expected a string"},
    {"light position missing", [](json& j) { j["lights"][0].erase("position"); }, Kind::value, "lights[0].position",
     "missing required key"},
    {"light position absurd",
     [](json& j) {
         j["lights"][0]["position"] = {1e8, 0, 0};
     },
     Kind::value, "lights[0].position", "absurd coordinate"},
    {"light intensity missing", [](json& j) { j["lights"][1].erase("intensity"); }, Kind::value, "lights[1].intensity",
     "missing required key"},
    {"light intensity negative", [](json& j) { j["lights"][0]["intensity"] = -1; }, Kind::value, "lights[0].intensity",
     "must be >= 0"},
    {"light intensity long",
     [](json& j) {
         j["lights"][0]["intensity"] = {1, 2, 3, 4};
     },
     Kind::value, "lights[0].intensity", "exactly 3"},
    {"light intensity NaN",
     [](json& j) {
         j["lights"][0]["intensity"] = {1, 2, nan};
     },
     Kind::value, "lights[0].intensity", "must be finite"},
    {"light radius 0", [](json& j) { j["lights"][0]["radius"] = 0; }, Kind::value, "lights[0].radius",
     "must be in [1e-06, 1000] m"},
    {"light radius negative", [](json& j) { j["lights"][0]["radius"] = -1; }, Kind::value, "lights[0].radius",
     "must be in [1e-06, 1000] m"},
    {"light radius tiny", [](json& j) { j["lights"][0]["radius"] = 1e-60; }, Kind::value, "lights[0].radius",
     "must be in [1e-06, 1000] m"},
    {"light radius below 1 micrometre", [](json& j) { j["lights"][0]["radius"] = 9.9e-7; }, Kind::value,
     "lights[0].radius", "must be in [1e-06, 1000] m"},
    {"light core radiance past 1e30",
     [](json& j) {
         j["lights"][0]["intensity"] = 1e30;
         j["lights"][0]["radius"] = 0.5;
     },
     Kind::value, "lights[0].radius", "core radiance intensity / (pi radius^2) = 1.27324e+30 exceeds 1e+30"},
    {"light core radiance past 1e30 at the default radius", [](json& j) { j["lights"][0]["intensity"] = 1e30; },
     Kind::value, "lights[0].intensity", "exceeds 1e+30 (radius 0.05 m by default)"},
    {"light radius huge", [](json& j) { j["lights"][0]["radius"] = 1000.5; }, Kind::value, "lights[0].radius",
     "must be in [1e-06, 1000] m"},
    {"light radius NaN", [](json& j) { j["lights"][1]["radius"] = nan; }, Kind::value, "lights[1].radius",
     "must be finite"},
    {"light radius string", [](json& j) { j["lights"][0]["radius"] = "big"; }, Kind::type, "lights[0].radius",
     "expected a number"},
    {"light extra key", [](json& j) { j["lights"][0]["colour"] = 1; }, Kind::value, "lights[0].colour", "unknown key"},
    {"light typo", [](json& j) { j["lights"][0]["intensty"] = 1; }, Kind::value, "lights[0].intensty",
     "did you mean 'intensity'?"},
    {"fourth light",
     [](json& j) { j["lights"].push_back({{"type", "point"}, {"position", {0, 0, 0}}, {"intensity", {1, -2, 3}}}); },
     Kind::value, "lights[3].intensity", "must be >= 0"},
    {"point with direction",
     [](json& j) {
         j["lights"][0]["direction"] = {0, -1, 0};
     },
     Kind::value, "lights[0].direction", "unknown key"},
    {"point with cone_angle", [](json& j) { j["lights"][1]["cone_angle"] = 30; }, Kind::value, "lights[1].cone_angle",
     "unknown key"},
    {"point with edge", [](json& j) { j["lights"][1]["edge"] = 0.5; }, Kind::value, "lights[1].edge", "unknown key"},
    // Spot lights (lights[2] is a spot).
    {"spot position missing", [](json& j) { j["lights"][2].erase("position"); }, Kind::value, "lights[2].position",
     "missing required key"},
    {"spot direction missing", [](json& j) { j["lights"][2].erase("direction"); }, Kind::value, "lights[2].direction",
     "missing required key"},
    {"spot intensity missing", [](json& j) { j["lights"][2].erase("intensity"); }, Kind::value, "lights[2].intensity",
     "missing required key"},
    {"spot cone_angle missing", [](json& j) { j["lights"][2].erase("cone_angle"); }, Kind::value,
     "lights[2].cone_angle", "missing required key"},
    {"spot direction zero",
     [](json& j) {
         j["lights"][2]["direction"] = {0, 0, 0};
     },
     Kind::value, "lights[2].direction", "must not be zero"},
    {"spot direction tiny",
     [](json& j) {
         j["lights"][2]["direction"] = {0, -1e-13, 0};
     },
     Kind::value, "lights[2].direction", "must not be zero"},
    {"spot direction short",
     [](json& j) {
         j["lights"][2]["direction"] = {0, -1};
     },
     Kind::value, "lights[2].direction", "exactly 3"},
    {"spot direction string", [](json& j) { j["lights"][2]["direction"] = "down"; }, Kind::type, "lights[2].direction",
     "expected a list"},
    {"spot direction NaN",
     [](json& j) {
         j["lights"][2]["direction"] = {0, nan, -1};
     },
     Kind::value, "lights[2].direction", "must be finite"},
    {"spot direction bool elem",
     [](json& j) {
         j["lights"][2]["direction"] = {0, true, 0};
     },
     Kind::type, "lights[2].direction", "expected a number, got boolean"},
    {"spot position absurd",
     [](json& j) {
         j["lights"][2]["position"] = {0, 0, 2e7};
     },
     Kind::value, "lights[2].position", "absurd coordinate"},
    {"spot intensity negative", [](json& j) { j["lights"][2]["intensity"] = -1; }, Kind::value, "lights[2].intensity",
     "must be >= 0"},
    {"spot cone_angle 0", [](json& j) { j["lights"][2]["cone_angle"] = 0; }, Kind::value, "lights[2].cone_angle",
     "must be in [0.001, 90]"},
    {"spot cone_angle negative", [](json& j) { j["lights"][2]["cone_angle"] = -10; }, Kind::value,
     "lights[2].cone_angle", "must be in [0.001, 90]"},
    {"spot cone_angle tiny", [](json& j) { j["lights"][2]["cone_angle"] = 1e-60; }, Kind::value,
     "lights[2].cone_angle", "must be in [0.001, 90]"},
    {"spot cone_angle above 90", [](json& j) { j["lights"][2]["cone_angle"] = 90.5; }, Kind::value,
     "lights[2].cone_angle", "must be in [0.001, 90]"},
    {"spot cone_angle just above 90", [](json& j) { j["lights"][2]["cone_angle"] = 90.000000000001; }, Kind::value,
     "lights[2].cone_angle", "must be in [0.001, 90]"},
    {"spot cone_angle 180", [](json& j) { j["lights"][2]["cone_angle"] = 180; }, Kind::value, "lights[2].cone_angle",
     "must be in [0.001, 90]"},
    {"spot cone_angle NaN", [](json& j) { j["lights"][2]["cone_angle"] = nan; }, Kind::value, "lights[2].cone_angle",
     "must be finite"},
    {"spot cone_angle string", [](json& j) { j["lights"][2]["cone_angle"] = "25"; }, Kind::type,
     "lights[2].cone_angle", "expected a number, got string"},
    {"spot cone_angle list",
     [](json& j) {
         j["lights"][2]["cone_angle"] = {25};
     },
     Kind::type, "lights[2].cone_angle", "expected a number, got list"},
    {"spot edge negative", [](json& j) { j["lights"][2]["edge"] = -0.01; }, Kind::value, "lights[2].edge",
     "must be in [0, 1]"},
    {"spot edge above 1", [](json& j) { j["lights"][2]["edge"] = 1.5; }, Kind::value, "lights[2].edge",
     "must be in [0, 1]"},
    {"spot edge inf", [](json& j) { j["lights"][2]["edge"] = inf; }, Kind::value, "lights[2].edge", "must be finite"},
    {"spot edge bool", [](json& j) { j["lights"][2]["edge"] = true; }, Kind::type, "lights[2].edge",
     "expected a number, got boolean"},
    {"spot edge null", [](json& j) { j["lights"][2]["edge"] = nullptr; }, Kind::type, "lights[2].edge",
     "expected a number, got null"},
    {"spot radius 0", [](json& j) { j["lights"][2]["radius"] = 0; }, Kind::value, "lights[2].radius",
     "must be in [1e-06, 1000] m"},
    {"spot radius huge", [](json& j) { j["lights"][2]["radius"] = 1e4; }, Kind::value, "lights[2].radius",
     "must be in [1e-06, 1000] m"},
    {"spot extra key", [](json& j) { j["lights"][2]["colour"] = 1; }, Kind::value, "lights[2].colour", "unknown key"},
    {"spot with normal",
     [](json& j) {
         j["lights"][2]["normal"] = {0, 1, 0};
     },
     Kind::value, "lights[2].normal", "unknown key"},
    {"spot typo cone_angle", [](json& j) { j["lights"][2]["cone_angel"] = 25; }, Kind::value, "lights[2].cone_angel",
     "did you mean 'cone_angle'?"},
    {"spot typo direction",
     [](json& j) {
         j["lights"][2]["diretion"] = {0, -1, 0};
     },
     Kind::value, "lights[2].diretion", "did you mean 'direction'?"},
    {"fourth light spot",
     [](json& j) {
         json l = spot_light();
         l["cone_angle"] = 120;
         j["lights"].push_back(l);
     },
     Kind::value, "lights[3].cone_angle", "must be in [0.001, 90]"},
    {"spot before points",
     [](json& j) {
         json l = spot_light();
         l["edge"] = 2;
         j["lights"].insert(j["lights"].begin(), l);
     },
     Kind::value, "lights[0].edge", "must be in [0, 1]"},
    // Surfaces.
    {"surfaces string", [](json& j) { j["surfaces"] = "x"; }, Kind::type, "surfaces", "expected a list"},
    {"surface not object", [](json& j) { j["surfaces"][1] = json::array(); }, Kind::type, "surfaces[1]",
     "expected an object"},
    {"surface type missing", [](json& j) { j["surfaces"][0].erase("type"); }, Kind::value, "surfaces[0].type",
     "missing required key"},
    {"surface type unknown", [](json& j) { j["surfaces"][0]["type"] = "disk"; }, Kind::value, "surfaces[0].type",
     "plane, box, sphere"},
    {"surface type bool", [](json& j) { j["surfaces"][0]["type"] = true; }, Kind::type, "surfaces[0].type",
     "expected a string"},
    {"surface albedo > 1", [](json& j) { j["surfaces"][0]["albedo"] = 2; }, Kind::value, "surfaces[0].albedo",
     "must be <= 1"},
    {"surface albedo NaN", [](json& j) { j["surfaces"][1]["albedo"] = nan; }, Kind::value, "surfaces[1].albedo",
     "must be finite"},
    {"surface albedo string", [](json& j) { j["surfaces"][1]["albedo"] = "grey"; }, Kind::type, "surfaces[1].albedo",
     "got string"},
    {"plane normal missing", [](json& j) { j["surfaces"][0].erase("normal"); }, Kind::value, "surfaces[0].normal",
     "missing required key"},
    {"plane point missing", [](json& j) { j["surfaces"][0].erase("point"); }, Kind::value, "surfaces[0].point",
     "missing required key"},
    {"plane normal zero", [](json& j) { j["surfaces"][0]["normal"] = {0, 0, 0}; }, Kind::value, "surfaces[0].normal",
     "nonzero"},
    {"plane normal tiny", [](json& j) { j["surfaces"][0]["normal"] = {1e-14, 0, 0}; }, Kind::value,
     "surfaces[0].normal", "nonzero"},
    {"plane normal short", [](json& j) { j["surfaces"][0]["normal"] = {0, 1}; }, Kind::value, "surfaces[0].normal",
     "exactly 3"},
    {"plane point absurd", [](json& j) { j["surfaces"][0]["point"] = {0, -1e9, 0}; }, Kind::value, "surfaces[0].point",
     "absurd coordinate"},
    {"plane with radius", [](json& j) { j["surfaces"][0]["radius"] = 1; }, Kind::value, "surfaces[0].radius",
     "unknown key"},
    {"plane with min", [](json& j) { j["surfaces"][0]["min"] = {0, 0, 0}; }, Kind::value, "surfaces[0].min",
     "unknown key"},
    {"box min missing", [](json& j) { j["surfaces"][1].erase("min"); }, Kind::value, "surfaces[1].min",
     "missing required key"},
    {"box max missing", [](json& j) { j["surfaces"][1].erase("max"); }, Kind::value, "surfaces[1].max",
     "missing required key"},
    {"box inverted", [](json& j) { j["surfaces"][1]["max"] = {-9, 12, -25}; }, Kind::value, "surfaces[1].max",
     "greater than min"},
    {"box flat", [](json& j) { j["surfaces"][1]["max"] = {-4, 12, -40}; }, Kind::value, "surfaces[1].max",
     "greater than min"},
    {"box with normal", [](json& j) { j["surfaces"][1]["normal"] = {0, 1, 0}; }, Kind::value, "surfaces[1].normal",
     "unknown key"},
    {"box min NaN", [](json& j) { j["surfaces"][1]["min"] = {nan, 0, 0}; }, Kind::value, "surfaces[1].min",
     "must be finite"},
    {"sphere radius 0", [](json& j) { j["surfaces"][2]["radius"] = 0; }, Kind::value, "surfaces[2].radius",
     "must be > 0"},
    {"sphere radius negative", [](json& j) { j["surfaces"][2]["radius"] = -1; }, Kind::value, "surfaces[2].radius",
     "must be > 0"},
    {"sphere radius inf", [](json& j) { j["surfaces"][2]["radius"] = inf; }, Kind::value, "surfaces[2].radius",
     "must be finite"},
    {"sphere radius beyond float", [](json& j) { j["surfaces"][2]["radius"] = 1e300; }, Kind::value,
     "surfaces[2].radius", "32-bit float"},
    {"sphere radius missing", [](json& j) { j["surfaces"][2].erase("radius"); }, Kind::value, "surfaces[2].radius",
     "missing required key"},
    {"sphere center missing", [](json& j) { j["surfaces"][2].erase("center"); }, Kind::value, "surfaces[2].center",
     "missing required key"},
    {"sphere center bool", [](json& j) { j["surfaces"][2]["center"] = true; }, Kind::type, "surfaces[2].center",
     "expected a list"},
    {"sphere typo", [](json& j) { j["surfaces"][2]["centre"] = {0, 0, 0}; }, Kind::value, "surfaces[2].centre",
     "did you mean 'center'?"},
    {"sphere with point", [](json& j) { j["surfaces"][2]["point"] = {0, 0, 0}; }, Kind::value, "surfaces[2].point",
     "unknown key"},
    // Background.
    {"background negative", [](json& j) { j["background"] = -1; }, Kind::value, "background", "must be >= 0"},
    {"background string", [](json& j) { j["background"] = "black"; }, Kind::type, "background", "got string"},
    {"background NaN", [](json& j) { j["background"] = {0, 0, nan}; }, Kind::value, "background", "must be finite"},
    {"background null", [](json& j) { j["background"] = nullptr; }, Kind::type, "background", "got null"},
    // Display (issue 8).
    {"display not an object", [](json& j) { j["display"] = 1; }, Kind::type, "display", "expected an object"},
    {"display unknown key", [](json& j) { j["display"] = {{"gamma", 2.2}}; }, Kind::value, "display.gamma",
     "unknown key"},
    {"exposure negative", [](json& j) { j["display"] = {{"exposure", -1}}; }, Kind::value, "display.exposure",
     "must be >= 0"},
    {"exposure word", [](json& j) { j["display"] = {{"exposure", "manual"}}; }, Kind::value, "display.exposure",
     "\"auto\""},
    {"exposure bool", [](json& j) { j["display"] = {{"exposure", true}}; }, Kind::type, "display.exposure",
     "got bool"},
    {"exposure huge", [](json& j) { j["display"] = {{"exposure", 1e300}}; }, Kind::value, "display.exposure",
     "32-bit float"},
    {"tonemap unknown", [](json& j) { j["display"] = {{"tonemap", "aces"}}; }, Kind::value, "display.tonemap",
     "allowed: linear, loglog, reinhard, filmic"},
    {"tonemap number", [](json& j) { j["display"] = {{"tonemap", 2}}; }, Kind::type, "display.tonemap",
     "expected a string"},
    {"white zero", [](json& j) { j["display"] = {{"white", 0}}; }, Kind::value, "display.white", "must be > 0"},
    {"glare not an object", [](json& j) { j["display"] = {{"glare", true}}; }, Kind::type, "display.glare",
     "expected an object"},
    {"glare unknown key", [](json& j) { j["display"] = {{"glare", {{"pupil", 4}}}}; }, Kind::value,
     "display.glare.pupil", "unknown key"},
    {"pupil too small", [](json& j) { j["display"] = {{"glare", {{"pupil_diameter", 0.5}}}}; }, Kind::value,
     "display.glare.pupil_diameter", "must be in [1, 9] mm"},
    {"pupil too large", [](json& j) { j["display"] = {{"glare", {{"pupil_diameter", 9.5}}}}; }, Kind::value,
     "display.glare.pupil_diameter", "must be in [1, 9] mm"},
    {"pupil word", [](json& j) { j["display"] = {{"glare", {{"pupil_diameter", "dark"}}}}; }, Kind::value,
     "display.glare.pupil_diameter", "\"auto\""},
    {"pupil NaN", [](json& j) { j["display"] = {{"glare", {{"pupil_diameter", nan}}}}; }, Kind::value,
     "display.glare.pupil_diameter", "must be finite"},
    {"eyelashes number", [](json& j) { j["display"] = {{"glare", {{"eyelashes", 1}}}}; }, Kind::type,
     "display.glare.eyelashes", "expected true or false"},
    // Daytime (issue 6).
    {"sky model unknown", [](json& j) { j["sky"] = {{"model", "clear"}, {"zenith_radiance", 1}}; }, Kind::value,
     "sky.model", "allowed: overcast, cie"},
    {"sky type 0", [](json& j) { j["sky"] = {{"model", "cie"}, {"type", 0}, {"zenith_radiance", 1}}; }, Kind::value,
     "sky.type", "must be in [1, 15]"},
    {"sky type 16", [](json& j) { j["sky"] = {{"model", "cie"}, {"type", 16}, {"zenith_radiance", 1}}; },
     Kind::value, "sky.type", "must be in [1, 15]"},
    {"sky type fraction", [](json& j) { j["sky"] = {{"model", "cie"}, {"type", 2.5}, {"zenith_radiance", 1}}; },
     Kind::value, "sky.type", "integer"},
    {"sky type missing", [](json& j) { j["sky"] = {{"model", "cie"}, {"zenith_radiance", 1}}; }, Kind::value,
     "sky.type", "missing"},
    {"sky type on overcast", [](json& j) { j["sky"] = {{"model", "overcast"}, {"type", 3}, {"zenith_radiance", 1}}; },
     Kind::value, "sky.type", "unknown key"},
    {"sky type without sun", [](json& j) { j["sky"] = {{"model", "cie"}, {"type", 12}, {"zenith_radiance", 1}}; },
     Kind::value, "sky.type", "sun"},
    {"zenith radiance negative", [](json& j) { j["sky"] = {{"model", "overcast"}, {"zenith_radiance", -1}}; },
     Kind::value, "sky.zenith_radiance", "must be >= 0"},
    {"zenith radiance missing", [](json& j) { j["sky"] = {{"model", "overcast"}}; }, Kind::value,
     "sky.zenith_radiance", "missing"},
    {"sun zero direction", [](json& j) { j["sun"] = {{"direction", {0, 0, 0}}}; }, Kind::value, "sun.direction",
     "zero length"},
    {"sun direction and angles", [](json& j) { j["sun"] = {{"direction", {0, 1, 0}}, {"elevation", 30}}; },
     Kind::value, "sun.direction", "not both"},
    {"sun elevation 100", [](json& j) { j["sun"] = {{"elevation", 100}, {"azimuth", 0}}; }, Kind::value,
     "sun.elevation", "must be in [-90, 90]"},
    {"sun azimuth missing", [](json& j) { j["sun"] = {{"elevation", 30}}; }, Kind::value, "sun.azimuth", "missing"},
    {"sun irradiance negative", [](json& j) { j["sun"] = {{"elevation", 30}, {"azimuth", 0}, {"irradiance", -2}}; },
     Kind::value, "sun.irradiance", "must be >= 0"},
    {"atmosphere unknown species", [](json& j) { j["atmosphere"] = {{"snow", json::object()}}; }, Kind::value,
     "atmosphere.snow", "unknown key"},
    {"rain rate negative", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", -1}}}}; }, Kind::value,
     "atmosphere.rain.rate", "must be in [0, 1000]"},
    {"rain rate missing", [](json& j) { j["atmosphere"] = {{"rain", json::object()}}; }, Kind::value,
     "atmosphere.rain.rate", "missing"},
    {"rain rate string", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", "heavy"}}}}; }, Kind::type,
     "atmosphere.rain.rate", "expected a number"},
    {"rain top zero", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"top", 0}}}}; }, Kind::value,
     "atmosphere.rain.top", "must be > 0"},
    {"rain g one", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"g", 1}}}}; }, Kind::value,
     "atmosphere.rain.g", "(-1, 1)"},
    {"visibility negative", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", -5000}}}}; }, Kind::value,
     "atmosphere.aerosol.visibility", "must be > 0"},
    {"visibility zero", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 0}}}}; }, Kind::value,
     "atmosphere.aerosol.visibility", "must be > 0"},
    {"aerosol without amount", [](json& j) { j["atmosphere"] = {{"aerosol", {{"g", 0.7}}}}; }, Kind::value,
     "atmosphere.aerosol.visibility", "missing"},
    {"aerosol both amounts",
     [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"coefficient", 0.01}}}}; }, Kind::value,
     "atmosphere.aerosol.coefficient", "not both"},
    {"aerosol coefficient negative", [](json& j) { j["atmosphere"] = {{"aerosol", {{"coefficient", -0.01}}}}; },
     Kind::value, "atmosphere.aerosol.coefficient", "must be in [0, 1000]"},
    {"aerosol scale height zero",
     [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"scale_height", 0}}}}; }, Kind::value,
     "atmosphere.aerosol.scale_height", "must be > 0"},
    {"aerosol albedo 2", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"albedo", 2}}}}; },
     Kind::value, "atmosphere.aerosol.albedo", "must be in [0, 1]"},
    {"molecules negative", [](json& j) { j["atmosphere"] = {{"molecules", {{"density_scale", -1}}}}; }, Kind::value,
     "atmosphere.molecules.density_scale", "must be in [0, 1e+06]"},
    {"sky segments 1", [](json& j) { j["quality"] = {{"sky_segments", 1}}; }, Kind::value, "quality.sky_segments",
     "must be in [2, 64]"},
    {"sky segments 100", [](json& j) { j["quality"] = {{"sky_segments", 100}}; }, Kind::value,
     "quality.sky_segments", "must be in [2, 64]"},
    {"sky segments fraction", [](json& j) { j["quality"] = {{"sky_segments", 8.5}}; }, Kind::value,
     "quality.sky_segments", "integer"},
    {"sky segments string", [](json& j) { j["quality"] = {{"sky_segments", "many"}}; }, Kind::type,
     "quality.sky_segments", "expected a number"},
    {"sky not an object", [](json& j) { j["sky"] = "blue"; }, Kind::type, "sky", "expected an object"},
    {"sky model missing", [](json& j) { j["sky"] = {{"zenith_radiance", 1}}; }, Kind::value, "sky.model", "missing"},
    {"sky unknown key", [](json& j) { j["sky"] = {{"model", "overcast"}, {"zenith_radiance", 1}, {"zenit", 1}}; },
     Kind::value, "sky.zenit", "unknown key"},
    {"sky type 2 without sun", [](json& j) { j["sky"] = {{"model", "cie"}, {"type", 2}, {"zenith_radiance", 1}}; },
     Kind::value, "sky.type", "\"sun\""},
    {"zenith radiance NaN",
     [](json& j) { j["sky"] = {{"model", "overcast"}, {"zenith_radiance", {1, std::nan(""), 1}}}; }, Kind::value,
     "sky.zenith_radiance", "must be finite"},
    {"zenith radiance overflows float", [](json& j) { j["sky"] = {{"model", "overcast"}, {"zenith_radiance", 1e39}}; },
     Kind::value, "sky.zenith_radiance", "must be <= 1e+30"},
    {"sun not an object", [](json& j) { j["sun"] = json::array({0, 1, 0}); }, Kind::type, "sun", "expected an object"},
    {"sun empty", [](json& j) { j["sun"] = json::object(); }, Kind::value, "sun.elevation", "or a direction"},
    {"sun elevation missing", [](json& j) { j["sun"] = {{"azimuth", 30}}; }, Kind::value, "sun.elevation",
     "missing"},
    {"sun direction and azimuth", [](json& j) { j["sun"] = {{"direction", {0, 1, 0}}, {"azimuth", 30}}; },
     Kind::value, "sun.direction", "not both"},
    {"sun direction of 2", [](json& j) { j["sun"] = {{"direction", {0, 1}}}; }, Kind::value, "sun.direction",
     "exactly 3"},
    {"sun elevation -90.5", [](json& j) { j["sun"] = {{"elevation", -90.5}, {"azimuth", 0}}; }, Kind::value,
     "sun.elevation", "must be in [-90, 90]"},
    {"sun azimuth string", [](json& j) { j["sun"] = {{"elevation", 10}, {"azimuth", "north"}}; }, Kind::type,
     "sun.azimuth", "expected a number"},
    {"sun unknown key", [](json& j) { j["sun"] = {{"elevation", 10}, {"azimuth", 0}, {"irradience", 1}}; },
     Kind::value, "sun.irradience", "did you mean 'irradiance'"},
    {"atmosphere not an object", [](json& j) { j["atmosphere"] = 1; }, Kind::type, "atmosphere",
     "expected an object"},
    {"molecules not an object", [](json& j) { j["atmosphere"] = {{"molecules", 1}}; }, Kind::type,
     "atmosphere.molecules", "expected an object"},
    {"molecules unknown key", [](json& j) { j["atmosphere"] = {{"molecules", {{"density", 1}}}}; }, Kind::value,
     "atmosphere.molecules.density", "unknown key"},
    {"molecules density huge", [](json& j) { j["atmosphere"] = {{"molecules", {{"density_scale", 2e6}}}}; },
     Kind::value, "atmosphere.molecules.density_scale", "must be in [0, 1e+06]"},
    {"visibility huge", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 2e9}}}}; }, Kind::value,
     "atmosphere.aerosol.visibility", "must be <= 1e+09"},
    {"visibility string", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", "far"}}}}; }, Kind::type,
     "atmosphere.aerosol.visibility", "expected a number"},
    {"aerosol coefficient huge", [](json& j) { j["atmosphere"] = {{"aerosol", {{"coefficient", 1e4}}}}; },
     Kind::value, "atmosphere.aerosol.coefficient", "must be in [0, 1000]"},
    {"aerosol scale height huge",
     [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"scale_height", 1e6}}}}; }, Kind::value,
     "atmosphere.aerosol.scale_height", "must be <= 100000"},
    {"aerosol g minus one", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"g", -1}}}}; },
     Kind::value, "atmosphere.aerosol.g", "(-1, 1)"},
    {"aerosol albedo negative",
     [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibility", 100}, {"albedo", -0.1}}}}; }, Kind::value,
     "atmosphere.aerosol.albedo", "must be in [0, 1]"},
    {"aerosol unknown key", [](json& j) { j["atmosphere"] = {{"aerosol", {{"visibilty", 100}}}}; }, Kind::value,
     "atmosphere.aerosol.visibilty", "did you mean 'visibility'"},
    {"rain rate huge", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1001}}}}; }, Kind::value,
     "atmosphere.rain.rate", "must be in [0, 1000]"},
    {"rain density negative", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"density_scale", -1}}}}; },
     Kind::value, "atmosphere.rain.density_scale", "must be in [0, 1e+06]"},
    {"rain density huge", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"density_scale", 1e7}}}}; },
     Kind::value, "atmosphere.rain.density_scale", "must be in [0, 1e+06]"},
    {"rain top negative", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"top", -5}}}}; }, Kind::value,
     "atmosphere.rain.top", "must be > 0"},
    {"rain top huge", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"top", 1e6}}}}; }, Kind::value,
     "atmosphere.rain.top", "must be <= 100000"},
    {"rain unknown key", [](json& j) { j["atmosphere"] = {{"rain", {{"rate", 1}, {"intensity", 1}}}}; },
     Kind::value, "atmosphere.rain.intensity", "unknown key"},
};

void test_bad_cases() {
    for (const auto& c : bad_cases) {
        json j = base_scene();
        c.mutate(j);
        bool thrown = false;
        try {
            airlight::parse_scene_json(j);
        } catch (const SceneError& e) {
            thrown = true;
            std::string got = std::string("field '") + e.field() + "', message '" + e.what() + "'";
            CHECK_MSG(e.kind() == c.kind, std::string(c.name) + ": " + got);
            CHECK_MSG(e.field() == c.field, std::string(c.name) + ": expected field '" + c.field + "', " + got);
            CHECK_MSG(std::string(e.what()).find(c.message) != std::string::npos,
                      std::string(c.name) + ": expected '" + c.message + "' in " + got);
        }
        CHECK_MSG(thrown, std::string(c.name) + ": no SceneError");
    }
}

// Expects parse_scene(text) to throw a SceneError of the given kind and field.
void check_text_error(const std::string& text, Kind kind, const std::string& field, const std::string& message) {
    try {
        airlight::parse_scene(text);
        CHECK_MSG(false, "no SceneError for: " + text);
    } catch (const SceneError& e) {
        CHECK_MSG(e.kind() == kind, text);
        CHECK_MSG(e.field() == field, text + " -> field '" + e.field() + "'");
        CHECK_MSG(std::string(e.what()).find(message) != std::string::npos, text + " -> " + e.what());
    }
}

void test_text_errors() {
    check_text_error("{\"film\": ", Kind::value, "", "invalid JSON");
    check_text_error("", Kind::value, "", "invalid JSON");
    check_text_error("{\"film\": {\"width\": NaN}}", Kind::value, "", "invalid JSON");
    // Without the parser library's prefix, one line that says where (issue 17).
    for (const char* text : {"{\"film\": {\"width\": 10,\n\n \"height\": }", "{\"film\" 1}", "", "[1, 2"}) {
        try {
            airlight::parse_scene(text);
            CHECK_MSG(false, std::string("no SceneError for: ") + text);
        } catch (const SceneError& e) {
            const std::string what = e.what();
            CHECK_MSG(what.rfind("invalid JSON at line ", 0) == 0, what);
            CHECK_MSG(what.find("json.exception") == std::string::npos && what.find('\n') == std::string::npos, what);
        }
    }
    check_text_error("{\"film\": {\"width\": 10,\n\n \"height\": }", Kind::value, "",
                     "invalid JSON at line 3, column 12: syntax error while parsing value");
    check_text_error("[1, 2, 3]", Kind::type, "", "scene must be a JSON object");
    check_text_error("\"scene\"", Kind::type, "", "scene must be a JSON object");
    check_text_error("{}", Kind::value, "film", "missing required key");
}

void test_readme_example() {
    airlight::Scene s = airlight::parse_scene(readme_example);
    CHECK(s.film.width == 320 && s.film.height == 240);
    CHECK(same(s.camera.position, {0.0f, 1.7f, 0.0f}));
    CHECK(same(s.camera.look_at, {0.0f, 1.7f, -10.0f}));
    CHECK(same(s.camera.up, {0.0f, 1.0f, 0.0f}));
    CHECK(s.camera.fov_y_degrees == 60.0f);
    CHECK(s.has_medium);
    CHECK(same(s.medium.sigma_t, glm::vec3(0.05f)));
    CHECK(same(s.medium.albedo, glm::vec3(1.0f)));
    CHECK(s.medium.phase.type == airlight::PhaseType::isotropic);
    CHECK(s.point_lights.size() == 1);
    CHECK(same(s.point_lights.at(0).position, {3.0f, 5.0f, -20.0f}));
    CHECK(same(s.point_lights.at(0).intensity, {100.0f, 90.0f, 70.0f}));
    CHECK(s.point_lights.at(0).radius == 0.05f);
    CHECK(s.spot_lights.empty());
    CHECK(s.surfaces.size() == 2);
    CHECK(s.surfaces.at(0).type == airlight::SurfaceType::plane);
    CHECK(same(s.surfaces.at(0).point, glm::vec3(0.0f)));
    CHECK(same(s.surfaces.at(0).normal, {0.0f, 1.0f, 0.0f}));
    CHECK(same(s.surfaces.at(0).albedo, glm::vec3(0.3f)));
    CHECK(s.surfaces.at(1).type == airlight::SurfaceType::box);
    CHECK(same(s.surfaces.at(1).box_min, {-8.0f, 0.0f, -40.0f}));
    CHECK(same(s.surfaces.at(1).box_max, {-4.0f, 12.0f, -25.0f}));
    CHECK(same(s.surfaces.at(1).albedo, glm::vec3(0.5f)));
    CHECK(same(s.background, glm::vec3(0.0f)));
}

void test_defaults_and_accepted_forms() {
    json j = base_scene();
    j.erase("medium");
    j.erase("background");
    j["surfaces"][0].erase("albedo");
    j["film"]["width"] = 320.0;                 // integral float
    j["film"]["height"] = 16384u;               // unsigned, upper bound
    j["lights"][0]["radius"] = 1000;            // upper bound inclusive
    j["surfaces"][0]["normal"] = {0, 2, 0};     // normalised on load
    j["surfaces"][1]["albedo"] = {0, 1, 0.25};  // albedo bounds inclusive
    j["camera"]["fov_y"] = 179.5;
    j["camera"]["up"] = {0.5, 3, 0.1};  // need not be orthogonal
    airlight::Scene s = airlight::parse_scene_json(j);
    CHECK(!s.has_medium);
    CHECK(same(s.background, glm::vec3(0.0f)));
    CHECK(same(s.surfaces.at(0).albedo, glm::vec3(0.5f)));
    CHECK(s.film.width == 320 && s.film.height == 16384);
    CHECK(s.point_lights.at(0).radius == 1000.0f);
    CHECK(s.point_lights.at(1).radius == 0.1f);
    CHECK(same(s.point_lights.at(1).intensity, glm::vec3(10.0f)));  // scalar broadcast
    CHECK(same(s.surfaces.at(0).normal, {0.0f, 1.0f, 0.0f}));
    CHECK(same(s.surfaces.at(1).albedo, {0.0f, 1.0f, 0.25f}));
    CHECK(s.surfaces.at(2).type == airlight::SurfaceType::sphere);
    CHECK(same(s.surfaces.at(2).center, {0.0f, 1.0f, -15.0f}));
    CHECK(s.surfaces.at(2).radius == 1.5f);
    CHECK(s.camera.fov_y_degrees == 179.5f);

    j["medium"] = nullptr;  // null medium: clear air
    j["lights"] = json::array();
    j.erase("surfaces");
    s = airlight::parse_scene_json(j);
    CHECK(!s.has_medium && s.point_lights.empty() && s.surfaces.empty());

    j = json::parse(readme_example);
    j["medium"] = {{"sigma_t", {0.1, 0.2, 0.3}}};  // albedo and phase default
    j["background"] = 0.25;
    s = airlight::parse_scene_json(j);
    CHECK(s.has_medium && same(s.medium.sigma_t, {0.1f, 0.2f, 0.3f}) && same(s.medium.albedo, glm::vec3(1.0f)));
    CHECK(s.medium.phase.type == airlight::PhaseType::isotropic);
    CHECK(same(s.background, glm::vec3(0.25f)));
    j["camera"]["position"] = {1e7, -1e7, 0};  // coordinate bound inclusive
    j["camera"]["look_at"] = {0, 0, 0};
    CHECK(airlight::parse_scene_json(j).camera.position.x == 1e7f);
}

// The issue's example of the daytime keys (issue 6).
void test_daytime_example() {
    json j = json::parse(readme_example);
    j["sky"] = {{"model", "cie"}, {"type", 12}, {"zenith_radiance", {1, 1, 1}}};
    j["sun"] = {{"elevation", 30}, {"azimuth", 0}, {"irradiance", {5, 5, 5}}};
    j["atmosphere"] = {{"molecules", {{"density_scale", 1}}},
                       {"aerosol", {{"visibility", 5000}, {"scale_height", 1200}, {"g", 0.7}}},
                       {"rain", {{"rate", 10}}}};
    const airlight::Scene s = airlight::parse_scene_json(j);
    CHECK(s.sky.model == airlight::SkyModel::cie && s.sky.cie_type == 12);
    CHECK(std::abs(s.sun.direction.x) < 1e-7f && std::abs(s.sun.direction.y - 0.5f) < 1e-6f &&
          std::abs(s.sun.direction.z + 0.8660254f) < 1e-6f);
    CHECK(s.atmosphere.molecules.present && s.atmosphere.aerosol.present && s.atmosphere.rain.present);
    CHECK(s.atmosphere.aerosol.visibility == 5000.0f && s.atmosphere.aerosol.scale_height == 1200.0f);
    CHECK(s.atmosphere.rain.rate == 10.0f && s.atmosphere.rain.top == 1500.0f && s.atmosphere.rain.g == 0.87f);
    CHECK(same_scene(s, airlight::parse_scene(airlight::scene_to_json(s))));
    // Azimuth 90 puts the sun along +x; null keys are absent.
    j["sun"] = {{"elevation", 0}, {"azimuth", 90}};
    j["atmosphere"] = nullptr;
    const airlight::Scene t = airlight::parse_scene_json(j);
    CHECK(std::abs(t.sun.direction.x - 1.0f) < 1e-6f && !t.atmosphere.any());
    j["sky"] = {{"model", "overcast"}, {"zenith_radiance", 2}};
    j["sun"] = nullptr;
    const airlight::Scene u = airlight::parse_scene_json(j);
    CHECK(u.sky.model == airlight::SkyModel::overcast && !u.sun.present);

    // The sunless CIE types (indicatrix group 1) need no sun; the others do.
    for (int type = 1; type <= 15; ++type) {
        json k = json::parse(readme_example);
        k["sky"] = {{"model", "cie"}, {"type", type}, {"zenith_radiance", 1}};
        bool ok = true;
        try {
            airlight::parse_scene_json(k);
        } catch (const SceneError& e) {
            ok = false;
            CHECK(e.field() == "sky.type");
        }
        CHECK_MSG(ok == (type == 1 || type == 3 || type == 5), "CIE type " + std::to_string(type));
    }

    // Bounds accepted; a direction is normalised; null sky and sun are absent.
    json k = json::parse(readme_example);
    k["sky"] = nullptr;
    k["sun"] = {{"direction", {0, 3, -4}}};
    k["atmosphere"] = json::object();
    airlight::Scene v = airlight::parse_scene_json(k);
    CHECK(v.sky.model == airlight::SkyModel::none && v.sun.present && !v.atmosphere.any());
    CHECK(same(v.sun.direction, {0.0f, 0.6f, -0.8f}) && same(v.sun.irradiance, glm::vec3(0.0f)));
    CHECK(v.quality.sky_segments == 16);
    k["sun"] = {{"elevation", -90}, {"azimuth", 1e6}, {"irradiance", 0}};
    k["atmosphere"] = {{"molecules", {{"density_scale", 0}}},
                       {"aerosol", {{"coefficient", 0}, {"g", -0.5}, {"albedo", 1}}},
                       {"rain", {{"rate", 1000}, {"density_scale", 1e6}, {"top", 1e5}}}};
    k["quality"] = {{"sky_segments", 64}};
    v = airlight::parse_scene_json(k);
    CHECK(std::abs(v.sun.direction.y + 1.0f) < 1e-7f && glm::length(v.sun.direction) > 0.999999f);
    CHECK(v.atmosphere.molecules.density_scale == 0.0f && v.atmosphere.aerosol.coefficient == 0.0f &&
          v.atmosphere.aerosol.visibility == 0.0f && v.atmosphere.aerosol.scale_height == 1000.0f &&
          v.atmosphere.aerosol.albedo == 1.0f && v.atmosphere.aerosol.g == -0.5f);
    CHECK(v.atmosphere.rain.rate == 1000.0f && v.atmosphere.rain.density_scale == 1e6f &&
          v.atmosphere.rain.top == 1e5f && v.quality.sky_segments == 64);
    k["atmosphere"] = {{"molecules", nullptr}, {"aerosol", {{"visibility", 1e9}}}, {"rain", nullptr}};
    k["quality"] = {{"sky_segments", 2}};
    v = airlight::parse_scene_json(k);
    CHECK(!v.atmosphere.molecules.present && !v.atmosphere.rain.present && v.atmosphere.aerosol.present &&
          v.atmosphere.aerosol.visibility == 1e9f && v.quality.sky_segments == 2);

    // Writing: null sky, sun and atmosphere when absent; the sun as its unit
    // direction; only the present species; the aerosol's amount as given.
    json w = airlight::scene_to_json_value(airlight::parse_scene(readme_example));
    CHECK(w["sky"].is_null() && w["sun"].is_null() && w["atmosphere"].is_null());
    CHECK(w["quality"]["sky_segments"] == 16);
    w = airlight::scene_to_json_value(s);  // the issue's example
    CHECK(w["sky"]["model"] == "cie" && w["sky"]["type"] == 12 && w["sky"]["zenith_radiance"].size() == 3);
    CHECK(w["sun"].size() == 2 && w["sun"]["direction"].size() == 3 && w["sun"]["irradiance"][0] == 5.0);
    CHECK(w["atmosphere"]["aerosol"]["visibility"] == 5000.0 && !w["atmosphere"]["aerosol"].contains("coefficient"));
    CHECK(w["atmosphere"]["rain"]["top"] == 1500.0 && w["atmosphere"]["molecules"]["density_scale"] == 1.0);
    k["sky"] = {{"model", "overcast"}, {"zenith_radiance", {1, 2, 3}}};
    k["atmosphere"] = {{"aerosol", {{"coefficient", 1e-4}}}};
    v = airlight::parse_scene_json(k);
    w = airlight::scene_to_json_value(v);
    CHECK(w["sky"].size() == 2 && !w["sky"].contains("type"));
    CHECK(w["atmosphere"].size() == 1 && w["atmosphere"]["aerosol"]["coefficient"] == 1e-4 &&
          !w["atmosphere"]["aerosol"].contains("visibility"));
    CHECK(same_scene(v, airlight::parse_scene_json(w)));
}

void test_spot_lights() {
    // The base scene's spot, every key given.
    airlight::Scene s = airlight::parse_scene_json(base_scene());
    CHECK(s.point_lights.size() == 2 && s.spot_lights.size() == 1);
    const airlight::SpotLight& given = s.spot_lights.at(0);
    CHECK(same(given.position, {1.0f, 4.0f, -8.0f}));
    CHECK(same(given.direction, {0.0f, -1.0f, 0.0f}));
    CHECK(same(given.intensity, {500.0f, 450.0f, 400.0f}));
    CHECK(given.cone_angle_degrees == 25.0f && given.edge == 0.15f && given.radius == 0.08f);

    // Defaults: edge 0, radius 0.05; scalar intensity broadcast; direction
    // normalised; the bounds cone_angle 90 and edge 0 and 1 accepted.
    json j = json::parse(readme_example);
    j["lights"] = json::array();
    j["lights"].push_back(
        {{"type", "spot"}, {"position", {0, 5, 0}}, {"direction", {0, -2, 0}}, {"intensity", 7}, {"cone_angle", 90}});
    j["lights"].push_back({{"type", "point"}, {"position", {0, 1, 0}}, {"intensity", 1}});
    j["lights"].push_back({{"type", "spot"},
                           {"position", {1, 2, 3}},
                           {"direction", {3, 0, -4}},
                           {"intensity", {1, 2, 3}},
                           {"cone_angle", 1e-3},
                           {"edge", 1},
                           {"volumetric_shadows", true}});
    j["lights"].push_back({{"type", "spot"},
                           {"position", {0, 0, 0}},
                           {"direction", {0.6, 0.8, 0}},
                           {"intensity", 0},
                           {"cone_angle", 45.5},
                           {"edge", 0}});
    s = airlight::parse_scene_json(j);
    CHECK(s.point_lights.size() == 1 && s.spot_lights.size() == 3);
    CHECK(same(s.point_lights.at(0).position, {0.0f, 1.0f, 0.0f}));
    const airlight::SpotLight &a = s.spot_lights.at(0), &b = s.spot_lights.at(1), &c = s.spot_lights.at(2);
    CHECK(same(a.position, {0.0f, 5.0f, 0.0f}));
    CHECK(same(a.direction, {0.0f, -1.0f, 0.0f}));
    CHECK(same(a.intensity, glm::vec3(7.0f)));
    CHECK(a.cone_angle_degrees == 90.0f && a.edge == 0.0f && a.radius == 0.05f);
    CHECK(std::abs(b.direction.x - 0.6f) < 1e-7f && b.direction.y == 0.0f && std::abs(b.direction.z + 0.8f) < 1e-7f);
    CHECK(std::abs(glm::length(b.direction) - 1.0f) < 1e-6f);
    CHECK(same(b.intensity, {1.0f, 2.0f, 3.0f}));
    CHECK(b.cone_angle_degrees == 1e-3f && b.edge == 1.0f && b.radius == 0.05f);
    CHECK(b.volumetric_shadows && !a.volumetric_shadows && !c.volumetric_shadows);
    CHECK(same(c.direction, {0.6f, 0.8f, 0.0f}));  // unit to float precision: kept as given
    CHECK(c.cone_angle_degrees == 45.5f && c.edge == 0.0f);

    // Written with every default filled in, points first, then spots.
    json v = airlight::scene_to_json_value(s);
    CHECK(v["lights"].size() == 4);
    CHECK(v["lights"][0]["type"] == "point");
    CHECK(v["lights"][1]["type"] == "spot" && v["lights"][2]["type"] == "spot" && v["lights"][3]["type"] == "spot");
    const json& w = v["lights"][1];
    CHECK(w.size() == 8);
    CHECK(w["volumetric_shadows"] == false);
    CHECK(w["position"] == json::array({0.0, 5.0, 0.0}));
    CHECK(w["direction"] == json::array({0.0, -1.0, 0.0}));
    CHECK(w["intensity"] == json::array({7.0, 7.0, 7.0}));
    CHECK(w["cone_angle"] == 90.0 && w["edge"] == 0.0 && w["radius"] == 0.05);
    CHECK(v["lights"][2]["edge"] == 1.0 && v["lights"][2]["cone_angle"] == 0.001);
    CHECK(v["lights"][2]["volumetric_shadows"] == true);
    CHECK(!v["lights"][0].contains("direction") && !v["lights"][0].contains("cone_angle"));
    airlight::Scene r = airlight::parse_scene_json(v);
    CHECK(same_scene(s, r));
    CHECK(airlight::scene_to_json_value(r) == v);

    // A scene of spots only.
    j["lights"] = json::array({spot_light()});
    s = airlight::parse_scene_json(j);
    CHECK(s.point_lights.empty() && s.spot_lights.size() == 1);
    CHECK(same_scene(s, airlight::parse_scene(airlight::scene_to_json(s))));
}

void test_round_trip() {
    airlight::Scene s = airlight::parse_scene_json(base_scene());
    s.medium.sigma_t = {0.1f, 1.0f / 3.0f, 2e-7f};
    s.background = {0.01f, 0.02f, 1e5f};
    std::string text = airlight::scene_to_json(s);
    airlight::Scene r = airlight::parse_scene(text);
    CHECK(same_scene(s, r));
    CHECK(airlight::scene_to_json(r) == text);
    CHECK(text.find("0.05") != std::string::npos);  // shortest float digits
    CHECK(text.find("0.0500000") == std::string::npos);

    // Every default written; surfaces carry only their own keys.
    json v = airlight::scene_to_json_value(airlight::parse_scene(readme_example));
    CHECK(v["lights"][0]["radius"].is_number());
    CHECK(v["lights"].size() == 1);
    CHECK(v["medium"]["albedo"].is_array() && v["medium"]["albedo"].size() == 3);
    CHECK(v["medium"]["phase"]["type"] == "isotropic");
    CHECK(v["surfaces"][1]["albedo"].is_array());
    CHECK(v["background"].is_array() && v["background"].size() == 3);
    CHECK(!v["surfaces"][0].contains("radius") && !v["surfaces"][0].contains("min"));
    CHECK(v["surfaces"][1].contains("min") && !v["surfaces"][1].contains("normal"));
    CHECK(v["film"]["width"].is_number_integer());

    // A g just inside (-1, 1) that rounds to 1 in float32 is kept just inside, and reloads.
    json near_one = base_scene();
    near_one["medium"]["phase"] = {{"type", "hg"}, {"g", 0.99999999999}};
    airlight::Scene g_scene = airlight::parse_scene_json(near_one);
    CHECK(g_scene.medium.phase.g < 1.0f && g_scene.medium.phase.g > 0.9999f);
    CHECK(same_scene(g_scene, airlight::parse_scene(airlight::scene_to_json(g_scene))));

    // A medium given by its visibility (issue 17): sigma_t = 3.912 / V on every channel,
    // written back by its visibility (not sigma_t: the two together are refused), and reloaded
    // bit for bit; once sigma_t is changed it is written as sigma_t.
    json foggy = base_scene();
    foggy["medium"].erase("sigma_t");
    foggy["medium"]["visibility"] = 97.8;
    airlight::Scene fog = airlight::parse_scene_json(foggy);
    CHECK(fog.has_medium && fog.medium.visibility == 97.8f);
    CHECK(same(fog.medium.sigma_t, glm::vec3(float(3.912 / double(97.8f)))));
    CHECK(std::abs(fog.medium.sigma_t.y - 0.04f) < 1e-6f);
    json fog_json = airlight::scene_to_json_value(fog);
    CHECK(fog_json["medium"]["visibility"] == 97.8 && !fog_json["medium"].contains("sigma_t"));
    const airlight::Scene fog_again = airlight::parse_scene(airlight::scene_to_json(fog));
    CHECK(same_scene(fog, fog_again) && fog_again.medium.visibility == fog.medium.visibility);
    fog.medium.sigma_t.x = 0.5f;
    json edited = airlight::scene_to_json_value(fog);
    CHECK(!edited["medium"].contains("visibility") && edited["medium"]["sigma_t"][0] == 0.5);

    // No medium: written as null.
    airlight::Scene clear = s;
    clear.has_medium = false;
    v = airlight::scene_to_json_value(clear);
    CHECK(v.contains("medium") && v["medium"].is_null());
    CHECK(same_scene(clear, airlight::parse_scene_json(v)));

    // Random scenes: parse -> write -> parse gives identical floats.
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> coord(-1e3, 1e3), unit(0.0, 1.0), expo(-8.0, 4.0);
    auto vec = [&] { return json::array({coord(rng), coord(rng), coord(rng)}); };
    int mismatches = 0, rejected = 0;
    for (int i = 0; i < 2000; ++i) {
        json j = json::parse(readme_example);
        j["camera"] = {{"position", vec()}, {"look_at", vec()}, {"up", vec()}, {"fov_y", 0.01 + 179.98 * unit(rng)}};
        j["medium"] = {{"sigma_t", std::pow(10.0, expo(rng) - 1.0)}, {"albedo", {unit(rng), unit(rng), unit(rng)}}};
        switch (i % 4) {  // every phase type, with random parameters
            case 0:
                j["medium"]["phase"] = {{"type", "isotropic"}};
                break;
            case 1:
                j["medium"]["phase"] = {{"type", "hg"}, {"g", 2.0 * unit(rng) - 1.0}};
                break;
            case 2:
                j["medium"]["phase"] = {{"type", "rayleigh"}};
                break;
            default:
                j["medium"]["phase"] = {{"type", "hg2"},
                                        {"forward_g", unit(rng)},
                                        {"backward_g", -unit(rng)},
                                        {"forward_weight", unit(rng)}};
        }
        j["lights"][0]["radius"] = 1e-3 + unit(rng);
        json spot = {{"type", "spot"},
                     {"position", vec()},
                     {"direction", vec()},
                     {"intensity", {std::pow(10.0, expo(rng)), unit(rng), 0}},
                     {"cone_angle", 90.0 * (1.0 - unit(rng))},
                     {"edge", unit(rng)}};
        if (i % 2) spot["radius"] = 1e-3 + unit(rng);
        j["lights"].insert(j["lights"].begin(), spot);  // written after the point light
        j["surfaces"][0]["normal"] = vec();
        j["surfaces"].push_back({{"type", "sphere"}, {"center", vec()}, {"radius", std::pow(10.0, expo(rng))}});
        const char* curves[] = {"linear", "loglog", "reinhard", "filmic"};
        j["display"] = {{"exposure", i % 3 == 0 ? json("auto") : json(std::pow(10.0, expo(rng)))},
                        {"tonemap", curves[i % 4]}};
        if (i % 5 == 0) j["display"]["white"] = std::pow(10.0, expo(rng));
        if (i % 2 == 0)
            j["display"]["glare"] = {{"pupil_diameter", i % 6 == 0 ? json("auto") : json(1.0 + 8.0 * unit(rng))},
                                     {"eyelashes", i % 4 == 0}};
        if (i % 3 != 2) {  // daytime keys, every kind
            const int type = 1 + i % 15;
            j["sky"] = i % 2 ? json{{"model", "overcast"}, {"zenith_radiance", unit(rng)}}
                             : json{{"model", "cie"}, {"type", type}, {"zenith_radiance", {unit(rng), 1, 2}}};
            j["sun"] = i % 4 < 2 ? json{{"elevation", 180.0 * unit(rng) - 90.0}, {"azimuth", coord(rng)}}
                                 : json{{"direction", vec()}, {"irradiance", std::pow(10.0, expo(rng))}};
            j["atmosphere"] = {
                {"molecules", {{"density_scale", unit(rng)}}},
                {"aerosol",
                 {i % 5 ? json::array({"visibility", std::pow(10.0, 0.5 * expo(rng) + 2.0)})  // 1 cm to 10 km
                        : json::array({"coefficient", std::pow(10.0, expo(rng) - 1.0)}),
                  {"scale_height", 1e4 * unit(rng) + 1.0},
                  {"g", 2.0 * unit(rng) - 1.0},
                  {"albedo", unit(rng)}}},
                {"rain", {{"rate", 100.0 * unit(rng)}, {"top", 1.0 + 3e3 * unit(rng)}}}};
            if (i % 7 == 0) j["atmosphere"].erase("aerosol");
            j["quality"] = {{"sky_segments", 2 + i % 63}};
        }
        airlight::Scene a;
        try {
            a = airlight::parse_scene_json(j);
        } catch (const SceneError&) {
            ++rejected;
            continue;
        }
        airlight::Scene b = airlight::parse_scene(airlight::scene_to_json(a, -1));
        if (!same_scene(a, b)) ++mismatches;
        float len = glm::length(a.surfaces[0].normal);
        if (std::abs(len - 1.0f) > 2e-6f) ++mismatches;
        if (a.spot_lights.size() != 1 || std::abs(glm::length(a.spot_lights[0].direction) - 1.0f) > 2e-6f) ++mismatches;
    }
    CHECK_MSG(mismatches == 0, std::to_string(mismatches) + " mismatches");
    CHECK(rejected < 10);
}

void test_files() {
    // A missing or unreadable file says so, with the path (issue 17: no bare "path:" label).
    try {
        airlight::load_scene_file("/nonexistent/scene.json");
        CHECK(false);
    } catch (const airlight::SceneFileError& e) {
        CHECK(e.kind() == Kind::value && e.field().empty());
        CHECK_MSG(std::string(e.what()) == "scene file not found: /nonexistent/scene.json", e.what());
    }
    try {
        airlight::load_scene_file("/tmp");  // a directory
        CHECK(false);
    } catch (const airlight::SceneFileError& e) {
        CHECK(e.kind() == Kind::value && e.field().empty());
        CHECK_MSG(std::string(e.what()) == "cannot read scene file /tmp: Is a directory", e.what());
    }
    std::string path = "/tmp/airlight_test_scene_" + std::to_string(std::random_device{}()) + ".json";
    if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
        std::fputs(readme_example, f);
        std::fclose(f);
        airlight::Scene s = airlight::load_scene_file(path);
        CHECK(s.film.width == 320 && s.surfaces.size() == 2);
        std::remove(path.c_str());
    } else {
        CHECK(false);
    }
}

}  // namespace

int main() {
    test_daytime_example();
    test_bad_cases();
    test_text_errors();
    test_readme_example();
    test_defaults_and_accepted_forms();
    test_spot_lights();
    test_round_trip();
    test_files();
    std::printf("%d bad-input cases, %d checks, %d failures\n", static_cast<int>(bad_cases.size()), checks, failures);
    return failures == 0 ? 0 : 1;
}
