// Display stage (issue 8): linear radiance -> 8-bit sRGB as a person would see
// it: exposure (manual, or automatic from the image's log-average luminance),
// a tone curve on luminance, then the sRGB OETF. The per-pixel math is
// shaders/display.glsl, shared with the GL display pass; this is the CPU
// implementation, multithreaded over rows.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "airlight/display_settings.hpp"
#include "airlight/glare.hpp"
#include "airlight/renderer.hpp"

namespace airlight {

// Reinhard et al. 2002's key: the exposed log-average luminance of a scene.
constexpr float kAutoExposureKey = 0.18f;

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

// The tone stage alone (exposure, curve, sRGB; settings.glare is ignored):
// width * height RGB bytes, row 0 on top, round(255 * display_pixel(...)).
// Validates `settings` first. threads <= 0: one per hardware thread.
std::vector<std::uint8_t> apply_display(const Image& linear, const DisplaySettings& settings, int threads = 0);

// Luminous efficacy used to read the renderer's luminance Y (Rec. 709
// weights of the linear channels, W / (m^2 sr)) as cd/m^2 for the pupil's
// adaptation: 683 lm/W, the photopic maximum (an equal-weight assumption:
// the channels are taken as already photometrically weighted).
constexpr double kLuminousEfficacy = 683.0;

// The steepest response of a grey pixel's display value (in [0, 1], before
// 8-bit rounding) to its exposed value, from `exposed` up: max over
// y >= exposed of d/dy srgb_oetf(f(y)), f the tone curve (non-increasing in
// `exposed`, so it bounds the slope over any interval starting there).
// Tabulated on a log grid over [1e-8, 1e3] x white (display_stage.cpp).
class DisplaySlope {
public:
    DisplaySlope(ToneCurve curve, float white);
    double at_least(double exposed) const;

private:
    double log_lo_ = 0.0, step_ = 0.0;
    std::vector<double> envelope_;
};

// How the glare of one display run is done (plan_glare; docs/glare.md
// "Skipping what does not show").
//
// The exact glare is K * v (K the kernel, centre weight k_c). Split v into a
// clipped part B = min(v, T) and the excess E = v - B, with a threshold T per
// tile of the image (tiles of the kernel's radius), and show B + K * E. The
// error at pixel p is (K * B - B)(p) = sum_d K(d) (B_{p+d} - B_p). The
// kernel's window around p lies inside the 3 x 3 tiles around p's tile; over
// them let R be the range of B (max - min, worst channel) and s the largest
// step between neighbouring pixels. Then |B_{p+d} - B_p| <= min(s |d|_1, R),
// and e_t = sum_d K(d) min(s |d|_1, R) (max over channels; with any value
// clipped, s is not known and e_t = (1 - k_c) R) bounds the error on all of
// the tile's pixels: smooth fog gets a small bound from s, a lamp's core a
// large one from R. The thresholds are the largest with
// e_t * exposure * DisplaySlope(exposure * (min B in the tile - e_t)) <= 1/2
// of an 8-bit step on every tile: the dropped glare moves no grey pixel's
// 8-bit value by more than one step. A tile whose neighbourhood passes
// unclipped keeps no threshold (nothing spread there); a lamp's core gets a
// threshold just above the fog around it and its excess is spread exactly;
// with nothing above any threshold the glare is skipped.
struct GlarePlan {
    bool enabled = false;                       // settings.glare.enabled and exposure > 0
    double pupil_diameter_mm = 0.0;             // given or from the adaptation luminance
    double pixel_angle = 0.0;                   // camera_pixel_angle(fov_y, height)
    std::shared_ptr<const GlareKernel> kernel;  // cached per (pupil, eyelashes, pixel angle)
    int tile = 1, tiles_x = 0;                  // tile side (pixels), tiles per row
    std::vector<float> tile_threshold;          // T per tile, radiance (every channel)
    double error_bound = 0.0;                   // max over tiles of e_t, radiance
    long long sources = 0;                      // pixels with a channel above their tile's T; 0: glare skipped
    float threshold_at(int x, int y) const {
        return tile_threshold[size_t(y / tile) * size_t(tiles_x) + size_t(x / tile)];
    }
};

// The eye's glare as shown by the display stage: the image extended by
// copies of its edge pixels (extend_edges: the world goes on past the frame,
// so the border gathers glare from outside as it loses glare to it; a uniform
// image is unchanged), convolved with the kernel (convolve_glare_fft),
// cropped. NaN and negative radiance count as 0.
Image glare_exact(const Image& linear, const GlareKernel& kernel, int threads = 0);
// `image` with `margin` copies of its edge rows and columns on every side.
Image extend_edges(const Image& image, int margin);
// The width x height window of `image` whose top-left pixel is (x0, y0).
Image crop(const Image& image, int x0, int y0, int width, int height);

// The glare plan for `linear` shown with `exposure` and the curve. Throws
// std::invalid_argument naming display.glare.pupil_diameter for a pupil
// outside [1, 9] mm, or camera.fov_y for a field of view outside (0, 180).
GlarePlan plan_glare(const Image& linear, const DisplaySettings& settings, float exposure, double fov_y_degrees,
                     int threads = 0);

// The glare of `plan` on the CPU: nothing when plan.sources == 0; else
// B + K * E (see GlarePlan) by splatting the sources' excess when they are
// few, or the exact convolution K * v (glare_exact) when splatting would
// cost more; both over the edge-extended image. `method` (if given) says which: "off", "skipped",
// "sparse" or "fft".
Image apply_glare_plan(const Image& linear, const GlarePlan& plan, int threads = 0, std::string* method = nullptr);

// What a display run did.
struct DisplayReport {
    float exposure = 1.0f;
    float white = 1.0f;
    std::string glare = "off";  // "off", "skipped", "sparse", "fft" (CPU) or "gl-fft"
    double pupil_diameter_mm = 0.0;
    int glare_kernel_radius = 0;
    double glare_threshold = 0.0;    // radiance; see GlarePlan
    double glare_error_bound = 0.0;  // radiance; see GlarePlan
    long long glare_sources = 0;
    double glare_ms = 0.0;  // kernel (first use of a pupil / pixel angle) and convolution
    double tone_ms = 0.0;
};

struct DisplayImage {
    int width = 0, height = 0;
    std::vector<std::uint8_t> srgb8;  // width * height RGB bytes, row 0 on top
    DisplayReport report;
};

// The whole display stage on the CPU: exposure (from the linear image before
// glare), glare (settings.glare; its angular scale from fov_y and the image's
// height), tone curve, sRGB. Renderer::display runs the same on either backend.
DisplayImage display_image(const Image& linear, const DisplaySettings& settings, double fov_y_degrees, int threads = 0);

}  // namespace airlight
