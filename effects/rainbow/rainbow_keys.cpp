// The rainbow's quality key "rainbow_wavelengths" (README "Scene format"),
// parsed and written back through the registry (EFFECT_QUALITY_KEYS;
// cpp/scene_keys.hpp).
#include <string>

#include "rainbow.hpp"
#include "scene_keys.hpp"

namespace airlight {

using namespace scene_keys;

// Wavelength nodes under each preset (effects/rainbow/docs/rainbow.md measures the colour
// error of fewer): the default is already the finest table.
void preset_rainbow_quality(QualityPreset preset, Scene& s) {
    if (preset == QualityPreset::fast) s.quality.rainbow_wavelengths = 9;
}

void parse_rainbow_quality(const SceneObject& quality, Scene& s) {
    if (auto v = quality.opt("rainbow_wavelengths")) {
        const int n = read_int(*v, 3, RAINBOW_WAVELENGTHS);
        if (!is_rainbow_wavelength_count(n))
            fail(Kind::value, v->field,
                 std::string("must be ") + RAINBOW_WAVELENGTH_COUNTS + " (wavelength nodes), got " + std::to_string(n));
        s.quality.rainbow_wavelengths = n;
    }
}

void write_rainbow_quality(const Scene& s, json& quality) {
    quality["rainbow_wavelengths"] = s.quality.rainbow_wavelengths;
}

}  // namespace airlight
