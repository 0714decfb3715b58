// The noise clouds' scene data: the cloud layer ("clouds" in the scene format)
// and its quality settings (clouds_keys.cpp parses them; physics.md defines
// every field's meaning).
#pragma once

#include <memory>
#include <string>

namespace airlight {

struct Table2D;

// A weather map (physics.md section 8): an image laid over the ground, `size`
// metres along x and z centred on `center`, repeating, drifting with the
// wind: its red channel scales the coverage, its green channel (a colour
// image) is the type (weather_map.hpp reads it).
struct WeatherMap {
    std::string image;  // the PNG or EXR file's path, as given
    float size_x = 0.0f, size_z = 0.0f;
    float center_x = 0.0f, center_z = 0.0f;
    std::shared_ptr<const Table2D> texels;  // null: no weather map
    float max_coverage = 1.0f;              // the largest red texel: 0 means the map clears the sky
};

// What both cloud methods' keys share ("clouds" here, "particle_clouds" in
// effects/particle_clouds): a layer between two altitudes, how much of the
// sky it covers, its extinction, its density texture's tile, its drift with
// the wind and its seed, read and written by one function
// (cloud_layer_keys.hpp).
struct CloudLayer {
    bool present = false;
    float base = 1500.0f;         // m: the layer's bottom
    float top = 4000.0f;          // m: its top
    float coverage = 0.5f;        // [0, 1]: the fraction of the sky the layer covers (0: none)
    float extinction = 0.05f;     // 1/m: sigma_t at density 1
    float shape_scale = 8000.0f;  // m: the shape (density) texture's tile
    float wind_x = 0.0f;          // m/s: the field's drift along x
    float wind_z = 0.0f;          // m/s: along z
    float time = 0.0f;            // s: the field has drifted by wind * time
    int seed = 0;                 // the noise textures' seed
};

// A layer of cloud between two altitudes whose density comes from two tiling
// noise textures (physics.md sections 1 and 2); its coverage is scaled by the
// weather map's R where there is one.
struct Clouds : CloudLayer {
    float type = 0.5f;            // [0, 1]: the height profile, 0 stratus, 0.5 cumulus, 1 cumulonimbus (or the map's G)
    float albedo = 1.0f;          // single-scattering albedo (water droplets: 1)
    float g = 0.2f;               // Henyey-Greenstein asymmetry of the droplets' lobe
    float second_g = -0.3f;       // an optional second lobe's asymmetry (physics.md eq. 3.4)
    float second_weight = 0.0f;   // [0, 1]: that lobe's share of the phase function (0: one lobe)
    float powder = 0.0f;          // [0, 1]: the powder term's strength (eq. 3.5; 0: physical)
    float erosion = 0.35f;        // [0, 1]: how far the detail noise eats into the edges (eq. 2.4)
    float detail_scale = 600.0f;  // m: the detail texture's tile
    WeatherMap weather_map;       // optional: coverage and type varying over the ground
};

// Clouds that can be seen or cast shadows: some coverage (after the weather
// map's) and extinction (a scene without builds no texture and runs no cloud
// code).
inline bool clouds_visible(const Clouds& c) {
    const float map = c.weather_map.texels ? c.weather_map.max_coverage : 1.0f;
    return c.present && c.coverage * map > 0.0f && c.extinction > 0.0f;
}

enum class CloudsMethod {
    adaptive,  // steps growing with distance, empty space crossed in long steps, early stop (physics.md section 4)
    march,     // fixed steps over the layer's part of the ray (quality.march_steps): brute force, for comparison
};

// The noise clouds' quality settings (a base of Quality).
struct CloudsQuality {
    CloudsMethod clouds = CloudsMethod::adaptive;
    int cloud_steps = 96;         // view-ray steps across the layer's thickness near the camera
    int cloud_light_steps = 32;   // steps of each march toward the sun and upward (eq. 3.2)
    int cloud_shadow_steps = 16;  // pieces of the air outside the layer lit through it (section 9; 0: unshadowed)
};

}  // namespace airlight
