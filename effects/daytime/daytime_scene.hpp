// The daytime effect's scene data: the sky dome, the sun and the
// height-varying atmosphere ("sky", "sun", "atmosphere" and the quality key
// "sky_segments" of the scene format; daytime_keys.cpp parses them).
#pragma once

#include <glm/vec3.hpp>

#include "airlight/rgb.hpp"

namespace airlight {

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

// quality.aerial_table "auto": the node count is chosen per frame.
constexpr int AERIAL_TABLE_AUTO = -1;

// The daytime effect's quality setting (a base of Quality).
struct DaytimeQuality {
    // Accuracy knob of the daytime scattering volumes (effects/daytime/physics.md):
    // the number of altitude levels that split view rays through the
    // atmosphere (effects/daytime/docs/daytime.md measures error against it), in [2, 64].
    int sky_segments = 16;
    // The aerial table (effects/daytime/docs/aerial_table.md): 0 walks the
    // scattering volumes in every pixel; N in [8, 64] tabulates the light
    // along camera rays once per frame at N distance nodes (12N + 1 elevation
    // rows, N azimuth blocks where the light depends on the azimuth) and
    // interpolates it per pixel; AERIAL_TABLE_AUTO ("auto", the default)
    // chooses by the camera's altitude and the film's size
    // (auto_aerial_nodes, daytime_frame.cpp).
    int aerial_table = AERIAL_TABLE_AUTO;
};

}  // namespace airlight
