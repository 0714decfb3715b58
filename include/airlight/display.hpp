// Display stage (issue 8): linear radiance -> 8-bit sRGB as a person would see
// it: exposure (manual, or automatic from the image's log-average luminance),
// a tone curve on luminance, then the sRGB OETF. The per-pixel math is
// effects/display/display.glsl, shared with the GL display pass; this is the CPU
// implementation, multithreaded over rows.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "airlight/glare.hpp"
#include "airlight/renderer.hpp"
#include "display_settings.hpp"

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

// Automatic exposure's floor (effects/display/physics.md section 5, equation 5.1):
// only pixels with Y >= max(kAutoExposureFloor * Y_median, kMinNormalFloat) count,
// Y_median the median luminance of the pixels whose luminance is a normal positive
// float. Six decades below the median pixel: darker than the black level of any
// curve with the median shown below white (an 8-bit sRGB step near black is
// 3e-4 of white), so such pixels show as black yet would pull the log-average.
constexpr double kAutoExposureFloor = 1e-6;
// FLT_MIN: below it a float32 is subnormal (or zero).
constexpr float kMinNormalFloat = 1.17549435e-38f;

// key / exp(mean ln Y) over the pixels whose Rec. 709 luminance Y is finite
// and at least the floor above (zero, negative, NaN, infinite, subnormal and
// near-zero pixels are ignored: a black sky must not drag the exposure to
// infinity, nor 1e-40 radiance left by underflow pull it up; adding zero or
// subnormal pixels never changes the exposure). 1 when no pixel counts.
// Capped at 1e30. Accumulated in double.
float auto_exposure(const Image& image, float key = kAutoExposureKey, int threads = 0);

// The exposure `settings` give for `image` (manual value or auto_exposure).
float resolve_exposure(const Image& image, const DisplaySettings& settings, int threads = 0);

// Tone curve `curve` of exposed luminance L (display.glsl's tone_curve), in
// [0, 1], before sRGB encoding.
float tone_map_luminance(ToneCurve curve, float luminance, float white);

// The tone stage alone (exposure, curve, sRGB; settings.glare is ignored):
// width * height RGB bytes, row 0 on top, display_quantize(display_pixel(...))
// with pixel (x, y)'s dither threshold (settings.dither; off: round(255 v)).
// Validates `settings` first. threads <= 0: one per hardware thread.
std::vector<std::uint8_t> apply_display(const Image& linear, const DisplaySettings& settings, int threads = 0);

// Luminous efficacy used to read the renderer's luminance Y (Rec. 709
// weights of the linear channels, W / (m^2 sr)) as cd/m^2 for the pupil's
// adaptation: 683 lm/W, the photopic maximum (an equal-weight assumption:
// the channels are taken as already photometrically weighted).
constexpr double kLuminousEfficacy = 683.0;

// How much a display value (in [0, 1], before 8-bit rounding) can move when
// every exposed channel of a pixel moves by at most delta. display_pixel
// shows channel i as u_i = c_i g(Y), g(Y) = f(Y) / Y (f the tone curve, Y the
// luminance), then sRGB. With |dc_j| <= delta, |dY| <= delta (the weights sum
// to 1) and g' = (f' - g) / Y,
//   |du_i| <= delta (g + c_i |g'|) = delta (g + (c_i / Y) |f' - g|),
// and |dv_i| <= srgb'(u) |du_i| with srgb' decreasing in u. So for a tile
// whose exposed values after the change stay in [c_lo, ...], luminance in
// [Y_lo, Y_hi] and chroma c_i / Y <= chroma:
//   |dv| <= delta * srgb'(c_lo g(Y_hi)) * (G(Y_lo) + chroma H(Y_lo)),
// G(y) = max over y' >= y of g(y'), H likewise of |f' - g| (envelopes: the
// filmic toe is convex, g is not monotonic there). Tabulated on 64 points per
// decade over [1e-8, 1e3] x white (f' by central differences), with a 5 %
// margin for the grid (display_stage.cpp).
class DisplayResponse {
public:
    DisplayResponse(ToneCurve curve, float white);
    // Bound on |dv| / delta for the tile described above (exposed units).
    double sensitivity(double c_lo, double y_lo, double y_hi, double chroma) const;
    // The largest sensitivity at any level and colour of chroma <= 1 (a grey pixel at 0).
    double steepest() const { return sensitivity(0.0, 0.0, 0.0, 1.0); }

private:
    double gain(double y) const;  // g(y) = f(y) / y (f'(0) at 0)
    double envelope(const std::vector<double>& table, double y) const;
    int curve_id_ = 0;
    float white_ = 1.0f;
    double log_lo_ = 0.0, step_ = 0.0;
    std::vector<double> gain_envelope_, bend_envelope_;  // G, H
};

// How the glare of one display run is done (plan_glare; effects/display/docs/glare.md
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
// image is unchanged), convolved with the kernel, cropped. NaN and negative
// radiance count as 0, +inf as 1e30 (as display_pixel takes them). The
// convolution is split_for_fft's: the FFT's roundoff is about 1e-16 of its
// input's maximum (6e-7 on the GPU in fp32), which a lamp 1e16 times its
// surroundings (or an infinite pixel) would spread over the whole image, so
// the FFT sees the image clipped at C = 1e4 times the median of its positive
// values and the excess of the few pixels above (lamp cores) is splatted
// exactly: the FFT's noise stays below 1e-12 (double) or 6e-3 (fp32) of the
// median, and the GPU's fp32 path suffices unless the exposure makes the
// median far brighter than white.
Image glare_exact(const Image& linear, const GlareKernel& kernel, int threads = 0);

// `image` (sanitised as above) clipped at C = 1e4 x the median of its
// positive channel values, and the glare of the excess above it (splatted with
// `kernel`, zero padding; empty when nothing is above): K * image =
// K * clipped + excess.
struct GlareSplit {
    Image clipped;
    Image excess;
};
GlareSplit split_for_fft(Image image, const GlareKernel& kernel);
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

// True when splatting the plan's sources costs fewer operations than the
// exact convolution's FFT (the choice apply_glare_plan makes; the GL backend
// makes it too, splatting on the CPU and tone-mapping on the GPU).
bool glare_prefers_sparse(const Image& linear, const GlarePlan& plan);

// What a display run did.
struct DisplayReport {
    float exposure = 1.0f;
    float white = 1.0f;
    std::string glare = "off";  // "off", "skipped", "sparse" (CPU splats), "fft" (CPU) or "gl-fft"
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
