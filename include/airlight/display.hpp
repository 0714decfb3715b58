// Display stage (issue 8): linear radiance -> 8-bit sRGB as a person would see
// it: exposure (manual, or automatic from the image's log-average luminance),
// a tone curve on luminance, then the sRGB OETF. The per-pixel math is
// shaders/display.glsl, shared with the GL display pass; this is the CPU
// implementation, multithreaded over rows.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "airlight/renderer.hpp"

namespace airlight {

enum class ExposureMode {
    manual,     // DisplaySettings::exposure multiplies the radiance
    automatic,  // exposure = key / log-average luminance (auto_exposure)
};

// The tone curves of shaders/display.glsl (their ids there: TONE_*).
enum class ToneCurve {
    linear,    // L / W, clipped
    loglog,    // the source paper's double logarithm: ln(1 + ln(1 + L)) / ln(1 + ln(1 + W))
    reinhard,  // extended Reinhard (2002) with white point W
    filmic,    // ACES fit of Narkowicz (2015), white point W
};

// Reinhard et al. 2002's key: the exposed log-average luminance of a scene.
constexpr float kAutoExposureKey = 0.18f;

struct DisplaySettings {
    ExposureMode exposure_mode = ExposureMode::automatic;
    float exposure = 1.0f;  // used when exposure_mode is manual; finite, >= 0
    ToneCurve curve = ToneCurve::loglog;
    // The exposed luminance that maps to display value 1; empty: the curve's
    // default (default_white). Finite and > 0.
    std::optional<float> white;
};

// "linear", "loglog", "reinhard", "filmic".
const char* tone_curve_name(ToneCurve curve);
// The inverse; an unknown name throws std::invalid_argument naming `field`.
ToneCurve tone_curve_from_name(const std::string& name, const std::string& field = "display.tonemap");

// The white point used when DisplaySettings::white is empty: linear 1,
// loglog 100 (about 9 stops above the key), reinhard 16, filmic 7.2439 (where
// the published ACES fit reaches 1).
float default_white(ToneCurve curve);

// Throws std::invalid_argument naming the field (prefix + "exposure",
// prefix + "white", prefix + "tonemap") for a manual exposure that is negative
// or not finite, a white point that is <= 0 or not finite, or a curve that is
// not one of the enum's values.
void validate_display_settings(const DisplaySettings& settings, const std::string& prefix = "display.");

// key / exp(mean ln Y) over the pixels whose Rec. 709 luminance Y is finite
// and > 0 (zero, negative, NaN and infinite pixels are ignored: a black sky
// must not drag the exposure to infinity). 1 when no pixel counts. Capped at
// 1e30. Accumulated in double.
float auto_exposure(const Image& image, float key = kAutoExposureKey, int threads = 0);

// The exposure `settings` give for `image` (manual value or auto_exposure).
float resolve_exposure(const Image& image, const DisplaySettings& settings, int threads = 0);

// Tone curve `curve` of exposed luminance L (display.glsl's tone_curve), in
// [0, 1], before sRGB encoding.
float tone_map_luminance(ToneCurve curve, float luminance, float white);

// The whole display stage: width * height RGB bytes, row 0 on top,
// round(255 * display_pixel(...)). Validates `settings` first. threads <= 0:
// one per hardware thread.
std::vector<std::uint8_t> apply_display(const Image& linear, const DisplaySettings& settings, int threads = 0);

}  // namespace airlight
