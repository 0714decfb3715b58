// The scene description: what is rendered. Plain data, validated on load
// (scene_io.hpp); the README's "Scene format" section documents every key.
#pragma once

#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "airlight/display_settings.hpp"

namespace airlight {

// Linear RGB triple (radiance, intensity, coefficients, albedo), per channel.
using Rgb = glm::vec3;

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

// ---- Daytime: sky dome, sun and a height-varying atmosphere (effects/daytime/physics.md;
// issue 6; effects/daytime/docs/daytime.md). Altitude is y in metres above the
// ground plane y = 0; the atmosphere exists for y >= 0.

enum class SkyModel {
    none,      // no sky: escaping rays see `background` only
    overcast,  // the classic CIE standard overcast sky L = Lz (1 + 2 cos Z) / 3
    cie,       // the CIE general sky, ISO 15469 type 1..15 (needs a sun position for types with an indicatrix)
};

// The sky dome: the radiance entering the atmosphere at its top, L(w) =
// zenith_radiance x shape(w) for directions above the horizon, 0 below.
struct Sky {
    SkyModel model = SkyModel::none;
    int cie_type = 1;  // 1..15, for SkyModel::cie
    Rgb zenith_radiance{0.0f};
};

// A directional sun: `direction` is the unit vector toward the sun (scene
// keys elevation/azimuth in degrees give (sin az cos el, sin el, -cos az cos el)),
// `irradiance` the irradiance on a plane facing it at the top of the
// atmosphere (W/m^2 per channel). Below the horizon it lights nothing; it
// still sets the CIE sky's sun position.
struct Sun {
    bool present = false;
    glm::vec3 direction{0.0f, 1.0f, 0.0f};
    Rgb irradiance{0.0f};
};

// Air molecules: Rayleigh scattering, sea-level coefficients times
// density_scale, scale height 8 km (effects/daytime/physics.md).
struct Molecules {
    bool present = false;
    float density_scale = 1.0f;
};

// Aerosol (haze, fog): Henyey-Greenstein g, single-scattering albedo, grey
// extinction at the ground given either by the visibility (Koschmieder,
// 3.912 / V for the clear air, molecules included) or directly by the
// coefficient; exponential decay with scale_height up to the minimum at
// 2250 m, a 25 % rise to 3250 m, decay above (effects/daytime/physics.md).
struct Aerosol {
    bool present = false;
    float visibility = 0.0f;   // m; > 0 when given
    float coefficient = 0.0f;  // 1/m at the ground; used when visibility == 0
    float scale_height = 1000.0f;
    float g = 0.7f;
    float albedo = 0.9f;
};

// Raindrops: Marshall-Palmer drop sizes for the rainfall rate (mm/h), whose
// extinction is pi N0 / Lambda^3 (extinction efficiency 2) times
// density_scale; constant density from the ground to `top` (the cloud base,
// m); Henyey-Greenstein g of large drops.
// How rain scatters the sun (effects/rainbow/physics.md): "mie", the drops'
// Lorenz-Mie phase function averaged over the rate's drop sizes, per
// wavelength (rainbows; effects/rainbow/rainbow.hpp); or "hg", Henyey-Greenstein with g.
// Sky light is always scattered with HG g (the sky is smooth; effects/rainbow/docs/rainbow.md).
enum class RainPhase { mie, hg };

struct Rain {
    bool present = false;
    float rate = 0.0f;
    float density_scale = 1.0f;  // drop density relative to the rate's (the fading rain of a rainbow)
    float top = 1500.0f;
    float g = 0.87f;
    RainPhase phase = RainPhase::mie;
};

struct Atmosphere {
    Molecules molecules;
    Aerosol aerosol;
    Rain rain;
    bool any() const { return molecules.present || aerosol.present || rain.present; }
};

// How the airlight is computed (effects/lamp_airlight/physics.md).
enum class AirlightMethod {
    analytic,  // the table method: exact up to the tables' measured error
    march,     // brute-force ray marching, for benchmarks and comparison
};

// Accuracy and speed settings (the "quality" object of the scene format).
struct Quality {
    AirlightMethod airlight = AirlightMethod::analytic;
    int march_steps = 64;  // midpoint-rule steps per light and view ray, for "march"
    // A light is skipped wherever a bound proves its contribution to a pixel
    // below cull_fraction x the scene's reference radiance (effects/lamp_airlight/docs/culling.md);
    // 0 disables culling.
    float cull_fraction = 1e-5f;
    // Directions per azimuth ring and rings of the quadrature over a spot's
    // beam that gives the light it scatters onto surfaces (a multiple of 4 in
    // [4, 64]; effects/spotlights/docs/spot_table.md section 9 measures its error).
    int spot_glow_samples = 12;
    // Accuracy knob of the daytime scattering volumes (effects/daytime/physics.md):
    // the number of altitude levels that split view rays through the
    // atmosphere (effects/daytime/docs/daytime.md measures error against it), in [2, 64].
    int sky_segments = 16;
    // Wavelength nodes (3, 5, 9, 17 or 33, 380-720 nm) of the rainbow's
    // spectral phase function turned into RGB (effects/rainbow/docs/rainbow.md measures the
    // colour error of fewer).
    int rainbow_wavelengths = 33;
    // The sun's shadows on surfaces: 0 traces a shadow ray per point (exact);
    // N in [16, 4096] looks them up in a shadow map of N texels along its
    // longer side, filled by a grid pass (effects/sun_shadow_map/physics.md).
    int sun_shadow_map = 0;
};

struct Scene {
    Film film;
    Camera camera;
    bool has_medium = false;  // false: clear air
    Medium medium;
    std::vector<PointLight> point_lights;
    std::vector<SpotLight> spot_lights;
    std::vector<Surface> surfaces;
    Rgb background{0.0f};  // radiance of rays that hit nothing (seen through the medium), added to the sky's
    Sky sky;
    Sun sun;
    Atmosphere atmosphere;
    Quality quality;
    // How the demo and Renderer::display turn the radiance into an image
    // (issue 8); render() itself always returns linear radiance.
    DisplaySettings display;
};

}  // namespace airlight
