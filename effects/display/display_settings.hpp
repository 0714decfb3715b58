// The display stage's settings (issue 8): the "display" object of the scene
// format (cpp/scene_io.cpp parses and validates it) and the argument of
// airlight::display_image / Renderer::display (include/airlight/display.hpp).
// Plain data, no dependencies, so that scene.hpp can hold one.
#pragma once

#include <optional>

namespace airlight {

enum class ExposureMode {
    manual,     // DisplaySettings::exposure multiplies the radiance
    automatic,  // exposure = key / log-average luminance (auto_exposure)
};

// The tone curves of effects/display/display.glsl (their ids there: TONE_*).
enum class ToneCurve {
    linear,    // L / W, clipped
    loglog,    // the source paper's double logarithm: ln(1 + ln(1 + L)) / ln(1 + ln(1 + W))
    reinhard,  // extended Reinhard (2002) with white point W
    filmic,    // ACES fit of Narkowicz (2015), white point W
};

// The eye's diffraction glare (include/airlight/glare.hpp, effects/display/docs/glare.md).
struct GlareSettings {
    bool enabled = false;
    // Pupil diameter in mm, in [1, 9]; empty: from the adaptation luminance
    // (pupil_diameter_from_luminance of the image's log-average luminance
    // times kLuminousEfficacy, see display.hpp), rounded to 0.05 mm.
    std::optional<double> pupil_diameter_mm;
    bool eyelashes = false;
};

struct DisplaySettings {
    ExposureMode exposure_mode = ExposureMode::automatic;
    float exposure = 1.0f;  // used when exposure_mode is manual; finite, >= 0
    ToneCurve curve = ToneCurve::loglog;
    // The exposed luminance that maps to display value 1; empty: the curve's
    // default (default_white). Finite and > 0.
    std::optional<float> white;
    GlareSettings glare;
    // Ordered dithering of the 8-bit output (effects/display/physics.md section 5,
    // "Dithering"): on by default; off: plain rounding (bands on smooth gradients).
    bool dither = true;
};

}  // namespace airlight
