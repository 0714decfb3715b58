// The scene description: what is rendered. Plain data, validated on load
// (scene_io.hpp); the README's "Scene format" section documents every key.
#pragma once

#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "airlight/rgb.hpp"
// The effects' scene types (each effect's EFFECT_SCENE_HEADER) and their members of Scene.
#include "airlight_scene_parts.hpp"

namespace airlight {

struct Film {
    int width = 320;
    int height = 240;
};

// Pinhole camera. fov_y is the full vertical field of view in degrees; the
// aspect ratio comes from the film; right-handed, y up.
struct Camera {
    glm::vec3 position{0.0f, 1.7f, 0.0f};
    glm::vec3 look_at{0.0f, 1.7f, -10.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_degrees = 60.0f;
    // The shutter's open time (s) ending at the scene's time: moving falling
    // rain drops leave streaks over it (effects/falling_rain/physics.md section 4).
    float exposure_time = 1.0f / 60.0f;
};

enum class PhaseType { isotropic, hg, rayleigh, hg2 };

// The medium's phase function p(cos theta), normalised to 1 over the sphere,
// theta the angle between the light's directions before and after scattering
// (docs/conventions.md):
//   isotropic  1 / (4 pi)
//   hg         Henyey-Greenstein with asymmetry g in (-1, 1)
//   rayleigh   3 / (16 pi) (1 + cos^2 theta)
//   hg2        forward_weight HG(forward_g) + (1 - forward_weight) HG(backward_g)
// Rendering clamps |g| to PHASE_G_LIMIT (effects/phase/docs/phase_table.md, section 0).
struct Phase {
    PhaseType type = PhaseType::isotropic;
    float g = 0.0f;               // hg
    float forward_g = 0.0f;       // hg2
    float backward_g = 0.0f;      // hg2
    float forward_weight = 1.0f;  // hg2
};

// Koschmieder's law with the 2 % contrast threshold (docs/conventions.md section
// 4): an extinction sigma_t (1/m) has the visibility V = KOSCHMIEDER / sigma_t (m).
inline constexpr double KOSCHMIEDER = 3.912;

// Homogeneous participating medium filling all space (docs/conventions.md):
// sigma_t extinction in 1/m, albedo = sigma_s / sigma_t. A scene may give the
// medium by its visibility V instead (the same on every channel): sigma_t =
// float(KOSCHMIEDER / V); `visibility` then records V, and the medium is
// written back by its visibility while sigma_t still equals that value.
struct Medium {
    Rgb sigma_t{0.0f};
    float visibility = 0.0f;  // m; > 0 when the scene gave the visibility
    Rgb albedo{1.0f};
    Phase phase;

    Rgb sigma_s() const { return sigma_t * albedo; }
};

// Isotropic point light: radiant intensity in W/sr. The lamp is a small
// emitting sphere of the given radius (metres) so that a pixel looking
// straight at it sees a finite radiance I / (pi r^2).
struct PointLight {
    glm::vec3 position{0.0f};
    Rgb intensity{0.0f};
    float radius = 0.05f;
    // Its airlight only from the parts of each view ray it lights, the rest
    // shadowed by the surfaces (effects/light_shafts/physics.md section 7).
    bool volumetric_shadows = false;
};

// Spot light (effects/spotlights/physics.md): a lamp at `position` shining along the unit
// `direction` with intensity (W/sr) I0 on the axis and, at angle theta from it,
//   I(theta) = I0 [(1 - edge) (cos theta - cos A) / (1 - cos A) + edge]
// for theta <= A = cone_angle_degrees (the half-angle, in (0, 90]), else 0.
// The lamp is a small emitting sphere of the given radius, as for PointLight.
struct SpotLight {
    glm::vec3 position{0.0f};
    glm::vec3 direction{0.0f, -1.0f, 0.0f};
    Rgb intensity{0.0f};
    float cone_angle_degrees = 30.0f;
    float edge = 0.0f;
    float radius = 0.05f;
    bool volumetric_shadows = false;  // as PointLight's
};

enum class SurfaceType { plane, box, sphere };

// Lambertian surfaces. Field use by type:
//   plane:  point, normal (unit after loading)
//   box:    box_min, box_max (axis aligned)
//   sphere: center, radius
struct Surface {
    SurfaceType type = SurfaceType::plane;
    glm::vec3 point{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec3 box_min{0.0f};
    glm::vec3 box_max{0.0f};
    glm::vec3 center{0.0f};
    float radius = 0.0f;
    Rgb albedo{0.5f};
};

// How the airlight is computed (effects/lamp_airlight/physics.md).
enum class AirlightMethod {
    analytic,  // the table method: exact up to the tables' measured error
    march,     // brute-force ray marching, for benchmarks and comparison
};

// A named set of the quality knobs (the key "quality.preset"): each effect
// maps it onto its own knobs (preset_<name>_quality, next to its keys) before
// the scene's explicit quality keys, which override it. Its values and their
// measured time and error: docs/quality_presets.md.
enum class QualityPreset {
    fast,       // the knobs that save time at a measured error, inside each effect's stated bound
    default_,   // each knob's default (the struct initialisers below and in the effects)
    reference,  // every knob at its most accurate setting: the images the accuracy tests compare
};

// Accuracy and speed settings (the "quality" object of the scene format):
// the core's here, each effect's in its EFFECT_QUALITY struct, a base of
// Quality (scene.quality.<field> reads either).
struct CoreQuality {
    QualityPreset preset = QualityPreset::default_;
    AirlightMethod airlight = AirlightMethod::analytic;
    int march_steps = 64;  // midpoint-rule steps per light and view ray, for "march"
    // A light is skipped wherever a bound proves its contribution to a pixel
    // below cull_fraction x the scene's reference radiance (effects/lamp_airlight/docs/culling.md);
    // 0 disables culling.
    float cull_fraction = 1e-5f;
};

struct Quality : public CoreQuality AIRLIGHT_EFFECT_QUALITY_BASES {};

struct Scene {
    Film film;
    Camera camera;
    bool has_medium = false;  // false: clear air
    Medium medium;
    std::vector<PointLight> point_lights;
    std::vector<SpotLight> spot_lights;
    std::vector<Surface> surfaces;
    Rgb background{0.0f};  // radiance of rays that hit nothing (seen through the medium), added to the sky's
    Quality quality;
    // The effects' parts (EFFECT_SCENE_MEMBERS): the daytime effect's sky,
    // sun and atmosphere; the display effect's display settings (how the demo
    // and Renderer::display turn the radiance into an image; render() itself
    // always returns linear radiance).
    AIRLIGHT_EFFECT_SCENE_MEMBERS
};

}  // namespace airlight
