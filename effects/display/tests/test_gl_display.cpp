// The GL display stage (effects/display/display_gl.cpp: GlBackend::display and
// glare_convolve, effects/display/display_pass.comp, effects/display/glare_fft.comp) against
// the CPU: the display bytes equal apply_display's within 1 LSB for HDR
// images with NaN, infinities, negatives, zeros and huge values, every curve;
// the fp32 FFT glare against convolve_glare_fft (double) within the bound
// stated in display_gl.cpp, on non-power-of-two sizes, with and without
// eyelashes, on lines too long for shared memory; energy conservation; the
// kernel spectrum cache; timings at 640x360 and 1920x1080.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "airlight/display.hpp"
#include "airlight/glare.hpp"
#include "backends.hpp"
#include "check.hpp"
#include "glare_shape.hpp"
#include "shader_cpp.hpp"

using namespace airlight;

namespace {

// Bound on the fp32 glare: max |gl - cpu| <= kGlareErrorBound * max |image|
// (effects/display/display_gl.cpp states the measured value).
constexpr double kGlareErrorBound = 1e-6;

struct Curve {
    ToneCurve curve;
    int id;
};
const Curve kCurves[] = {{ToneCurve::linear, shader::TONE_LINEAR},
                         {ToneCurve::loglog, shader::TONE_LOGLOG},
                         {ToneCurve::reinhard, shader::TONE_REINHARD},
                         {ToneCurve::filmic, shader::TONE_FILMIC}};

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Random HDR radiance: log-uniform magnitudes over 1e-6..1e6 with a sprinkle
// of NaN, +-inf, negatives, zeros, denormals and values near FLT_MAX.
Image random_hdr_image(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Image im{w, h, std::vector<float>(size_t(w) * h * 3)};
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              -1.0f,
                              -1e-3f,
                              0.0f,
                              -0.0f,
                              1e-40f,
                              3e38f,
                              1e30f};
    for (float& v : im.rgb) {
        const float p = u(rng);
        if (p < 0.05f) {
            v = specials[size_t(u(rng) * 10.0f) % 10];
        } else {
            v = std::pow(10.0f, -6.0f + 12.0f * u(rng));
        }
    }
    return im;
}

// Point sources of 1e4..1e6 (single pixels and small blobs) over a dim
// background of 1e-3..1; sources stay `margin` pixels from the borders.
Image point_sources_image(int w, int h, int sources, int margin, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Image im{w, h, std::vector<float>(size_t(w) * h * 3)};
    for (float& v : im.rgb) v = float(std::pow(10.0, -3.0 + 3.0 * u(rng)));
    for (int s = 0; s < sources; ++s) {
        const int x = margin + int(u(rng) * std::max(1, w - 2 * margin));
        const int y = margin + int(u(rng) * std::max(1, h - 2 * margin));
        const double level = std::pow(10.0, 4.0 + 2.0 * u(rng));
        const int blob = s % 3 == 0 ? 1 : 0;
        for (int dy = -blob; dy <= blob; ++dy)
            for (int dx = -blob; dx <= blob; ++dx) {
                const int xx = std::min(w - 1, std::max(0, x + dx)), yy = std::min(h - 1, std::max(0, y + dy));
                float* p = &im.rgb[(size_t(yy) * w + xx) * 3];
                p[0] = float(level);
                p[1] = float(level * (0.3 + 0.7 * u(rng)));
                p[2] = float(level * (0.1 + 0.9 * u(rng)));
            }
    }
    return im;
}

double max_abs(const Image& im) {
    double m = 0.0;
    for (float v : im.rgb) m = std::max(m, double(std::fabs(v)));
    return m;
}

void test_display_matches_cpu(GlBackend& gl) {
    const int sizes[][2] = {{67, 43}, {256, 128}, {1, 1}, {3, 200}};
    const float exposures[] = {0.0f, 1e-3f, 0.37f, 1.0f, 50.0f};
    long long compared = 0, differ = 0, worst = 0;
    unsigned seed = 1;
    for (const auto& size : sizes) {
        const Image im = random_hdr_image(size[0], size[1], seed++);
        for (const Curve& c : kCurves) {
            for (float exposure : exposures) {
                for (int wi = 0; wi < 2; ++wi) {
                    DisplaySettings settings;
                    settings.exposure_mode = ExposureMode::manual;
                    settings.exposure = exposure;
                    settings.curve = c.curve;
                    const float white = wi == 0 ? default_white(c.curve) : 0.25f * default_white(c.curve) + 0.5f;
                    settings.white = white;
                    const std::vector<std::uint8_t> cpu = apply_display(im, settings, 2);
                    GlDisplayJob job;
                    job.linear = &im;
                    job.exposure = exposure;
                    job.curve = c.id;
                    job.white = white;
                    GlDisplayOutput out;
                    gl.display(job, out);
                    CHECK(out.srgb8.size() == cpu.size());
                    if (out.srgb8.size() != cpu.size()) continue;
                    long long bad = 0;
                    for (size_t i = 0; i < cpu.size(); ++i) {
                        const int d = std::abs(int(out.srgb8[i]) - int(cpu[i]));
                        worst = std::max<long long>(worst, d);
                        if (d != 0) ++differ;
                        if (d > 1) ++bad;
                    }
                    compared += (long long)cpu.size();
                    CHECK_MSG(bad == 0, std::string(tone_curve_name(c.curve)) + " exposure " +
                                            std::to_string(exposure) + " " + std::to_string(size[0]) + "x" +
                                            std::to_string(size[1]) + ": " + std::to_string(bad) +
                                            " bytes differ by more than 1");
                }
            }
        }
    }
    std::printf("display pass: %lld bytes compared with apply_display, %lld differ by 1 LSB, max difference %lld\n",
                compared, differ, worst);
    // An empty image gives no bytes.
    Image empty;
    GlDisplayJob job;
    job.linear = &empty;
    GlDisplayOutput out;
    gl.display(job, out);
    CHECK(out.srgb8.empty());
}

// GL glare against convolve_glare_fft; returns max |gl - cpu| / max |image|.
double glare_error(GlBackend& gl, const Image& im, const GlareKernel& k, const char* what) {
    Image out;
    gl.glare_convolve(im, k, out);
    const Image ref = convolve_glare_fft(im, k, 2);
    double err = 0.0;
    for (size_t i = 0; i < ref.rgb.size(); ++i) err = std::max(err, std::fabs(double(out.rgb[i]) - ref.rgb[i]));
    const double rel = err / max_abs(im);
    std::printf("glare %-28s %4dx%-4d r=%2d: max |gl - cpu| = %.3e = %.2e * max(image)\n", what, im.width, im.height,
                k.radius, err, rel);
    CHECK_MSG(out.width == im.width && out.height == im.height, what);
    CHECK_MSG(rel <= kGlareErrorBound, what);
    return rel;
}

// Uniform random radiance in [0, scale).
Image uniform_image(int w, int h, float scale, unsigned seed) {
    Image im{w, h, std::vector<float>(size_t(w) * h * 3)};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, scale);
    for (float& v : im.rgb) v = u(rng);
    return im;
}

void test_glare_matches_cpu(GlBackend& gl, const GlareKernel& k97, const GlareKernel& k97_lashes,
                            const GlareKernel& k360, const GlareKernel& k1080, const GlareKernel& k_wide) {
    double worst = 0.0;
    worst = std::max(worst, glare_error(gl, point_sources_image(161, 97, 6, 0, 11), k97, "point sources"));
    worst = std::max(worst, glare_error(gl, point_sources_image(161, 97, 6, 0, 12), k97_lashes, "eyelashes"));
    worst = std::max(worst, glare_error(gl, uniform_image(161, 97, 1.0f, 5), k97_lashes, "uniform random 0..1"));
    worst = std::max(worst, glare_error(gl, point_sources_image(161, 97, 6, 0, 17), k1080, "point sources"));
    worst = std::max(worst, glare_error(gl, point_sources_image(640, 360, 20, 0, 13), k360, "point sources"));
    worst = std::max(worst, glare_error(gl, point_sources_image(640, 360, 20, 0, 18), k_wide, "eyelashes, grid 2048"));
    // The largest error measured: a uniformly bright image at the largest padded size (2048 x 2048).
    worst = std::max(worst, glare_error(gl, uniform_image(1920, 1080, 1e6f, 19), k1080, "uniform random 0..1e6"));
    worst = std::max(worst, glare_error(gl, point_sources_image(40, 3, 2, 0, 14), k97, "tiny"));
    // Lines longer than shared memory holds: rows (P_x = 4096) and columns (P_y = 8192) in the scratch buffer.
    worst = std::max(worst, glare_error(gl, point_sources_image(4000, 20, 8, 0, 15), k97, "long rows (scratch)"));
    worst = std::max(worst, glare_error(gl, point_sources_image(20, 4100, 8, 0, 16), k97, "long columns (scratch)"));
    std::printf("glare: worst max |gl - cpu| / max(image) = %.2e (bound %.1e)\n", worst, kGlareErrorBound);
}

void test_glare_energy(GlBackend& gl, const GlareKernel& k) {
    // Only the sources, at least r + 1 pixels from the borders (the background near the borders loses light).
    Image sources = point_sources_image(161, 97, 4, k.radius + 1, 21);
    for (float& v : sources.rgb)
        if (v < 1e3f) v = 0.0f;
    Image out;
    gl.glare_convolve(sources, k, out);
    for (int c = 0; c < 3; ++c) {
        double in_sum = 0.0, out_sum = 0.0;
        for (size_t i = size_t(c); i < sources.rgb.size(); i += 3) {
            in_sum += sources.rgb[i];
            out_sum += out.rgb[i];
        }
        const double rel = std::fabs(out_sum - in_sum) / in_sum;
        std::printf("glare energy, r=%d, channel %d: in %.6e out %.6e, relative change %.2e\n", k.radius, c, in_sum,
                    out_sum, rel);
        CHECK(rel <= 1e-4);
    }
}

// Display with glare end to end: GL bytes against apply_display of the CPU
// convolution, for a moderate image (max 10) where display() keeps the fp32
// FFT, its noise far below 1 LSB.
void test_display_with_glare(GlBackend& gl, const GlareKernel& k) {
    Image im = point_sources_image(161, 97, 5, 0, 31);
    for (float& v : im.rgb) v = std::min(v, 10.0f);
    const Image glared = convolve_glare_fft(im, k, 2);
    DisplaySettings settings;
    settings.exposure_mode = ExposureMode::manual;
    settings.exposure = 0.8f;
    settings.curve = ToneCurve::loglog;
    settings.white = 50.0f;
    const std::vector<std::uint8_t> cpu = apply_display(glared, settings, 2);
    GlDisplayJob job;
    job.linear = &im;
    job.exposure = 0.8f;
    job.curve = shader::TONE_LOGLOG;
    job.white = 50.0f;
    job.glare = &k;
    GlDisplayOutput out;
    gl.display(job, out);
    long long differ = 0, bad = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        const int d = std::abs(int(out.srgb8[i]) - int(cpu[i]));
        if (d != 0) ++differ;
        if (d > 1) ++bad;
    }
    std::printf("display with glare: %lld of %zu bytes differ by 1 LSB from the CPU\n", differ, cpu.size());
    CHECK(out.srgb8.size() == cpu.size());
    CHECK(bad == 0);
}

// High dynamic range on screen: sources of 1e4..1e6 over a background of
// 1e-3..1, automatic exposure, loglog. fp32's noise (c * max(image) on every
// pixel) would show in the background here (up to 63 LSB measured), so
// display() must switch to the double-precision FFT: every byte within 1 LSB
// of the CPU.
void test_hdr_display_with_glare(GlBackend& gl, const GlareKernel& k) {
    const Image im = point_sources_image(161, 97, 6, 0, 41);
    DisplaySettings settings;
    settings.exposure_mode = ExposureMode::automatic;
    settings.curve = ToneCurve::loglog;
    const float exposure = resolve_exposure(im, settings, 2);
    settings.exposure_mode = ExposureMode::manual;
    settings.exposure = exposure;
    const std::vector<std::uint8_t> cpu = apply_display(convolve_glare_fft(im, k, 2), settings, 2);
    GlDisplayJob job;
    job.linear = &im;
    job.exposure = exposure;
    job.curve = shader::TONE_LOGLOG;
    job.white = default_white(ToneCurve::loglog);
    job.glare = &k;
    GlDisplayOutput out;
    gl.display(job, out);
    long long differ = 0, over1 = 0;
    int worst = 0;
    for (size_t i = 0; i < cpu.size(); ++i) {
        const int d = std::abs(int(out.srgb8[i]) - int(cpu[i]));
        worst = std::max(worst, d);
        if (d != 0) ++differ;
        if (d > 1) ++over1;
    }
    std::printf(
        "HDR display with glare (max %.1e, exposure %.3g, loglog, fp32 noise would be %.1e after exposure): %lld of "
        "%zu bytes differ from the CPU, %lld by more than 1 LSB, max %d\n",
        max_abs(im), double(exposure), kGlareErrorBound * max_abs(im) * exposure, differ, cpu.size(), over1, worst);
    CHECK(cpu.size() == out.srgb8.size());
    CHECK(over1 == 0);
}

// Timings (printed, not asserted). A moderate image (max 10, exposure 1,
// loglog) takes the fp32 FFT; an HDR one (sources of 1e4..1e6) the double
// one; each glare is timed first with the kernel's spectrum, then cached.
void print_timings(GlBackend& gl, int w, int h, const GlareKernel& k) {
    Image moderate = point_sources_image(w, h, 30, 0, unsigned(w));
    for (float& v : moderate.rgb) v = std::min(v, 10.0f);
    const Image hdr = point_sources_image(w, h, 30, 0, unsigned(w) + 1);
    GlDisplayJob job;
    job.linear = &moderate;
    job.exposure = 1.0f;
    job.curve = shader::TONE_LOGLOG;
    job.white = 100.0f;
    GlDisplayOutput out;
    const auto t0 = std::chrono::steady_clock::now();
    gl.display(job, out);
    const double plain_call = ms_since(t0);
    const double tone = out.tone_ms;
    double glare_ms[2][2];
    for (int precision = 0; precision < 2; ++precision) {
        job.linear = precision == 0 ? &moderate : &hdr;
        job.glare = &k;
        for (int pass = 0; pass < 2; ++pass) {
            gl.display(job, out);
            glare_ms[precision][pass] = out.glare_ms;
        }
    }
    std::printf(
        "timing %dx%d (r=%d): display pass %.1f ms (whole call without glare %.1f ms, upload included); glare fp32 "
        "%.1f ms (%.1f ms with the kernel spectrum), glare fp64 %.1f ms (%.1f ms with the kernel spectrum)\n",
        w, h, k.radius, tone, plain_call, glare_ms[0][1], glare_ms[0][0], glare_ms[1][1], glare_ms[1][0]);
    CHECK(out.srgb8.size() == size_t(w) * h * 3);
}

void test_too_large(GlBackend& gl) {
    Image im{1, 1, {1.0f, 1.0f, 1.0f}};
    im.width = 1 << 20;  // wider than any GL texture; the size check comes first
    im.rgb.assign(size_t(im.width) * 3, 0.0f);
    GlDisplayJob job;
    job.linear = &im;
    GlDisplayOutput out;
    bool threw = false;
    try {
        gl.display(job, out);
    } catch (const std::runtime_error& e) {
        threw = std::string(e.what()).find("maximum texture size") != std::string::npos;
    }
    CHECK(threw);
}

}  // namespace

// Issue 17 on the GPU: the FFT glare (fp64, so that its roundoff stays far below the faint rim) of one
// bright pixel is round and falls off along rays, like the CPU's (test_glare.cpp,
// test_glare_of_a_pixel_is_round; the same cases).
void test_glare_of_a_pixel_is_round(GlBackend& gl) {
    struct Case {
        double pupil_mm, fov_y;
        int rows, min_distance;
    };
    for (const Case& cs : {Case{1.0, 14.0, 360, 6}, Case{4.0, 60.0, 360, 1}}) {
        GlareOptions options;
        options.pupil_diameter_mm = cs.pupil_mm;
        const GlareKernel k = glare_kernel_rgb(options, camera_pixel_angle(cs.fov_y, cs.rows));
        const int r = k.radius, n = 2 * r + 9, c0 = n / 2;
        Image one{n, n, std::vector<float>(size_t(n) * n * 3, 0.0f)};
        for (int c = 0; c < 3; ++c) one.rgb[(size_t(c0) * n + c0) * 3 + c] = 1.0f;
        Image out;
        gl.glare_convolve(one, k, out, true);
        for (int c = 0; c < 3; ++c) {
            const double peak = out.rgb[(size_t(c0) * n + c0) * 3 + c];
            const glare_shape::Shape s = glare_shape::measure(out, c0, c0, c, cs.min_distance, 1e-10 * peak);
            std::printf(
                "round glare (GPU FFT, fp64), %.0f mm, channel %d: asymmetry %.2e at %.1f px, %d rises, "
                "support %.1f px (radius %d)\n",
                cs.pupil_mm, c, s.asymmetry, s.asymmetry_at, s.rises, s.support, r);
            CHECK(s.asymmetry <= 0.01);
            CHECK(s.rises == 0);
            CHECK(s.support <= r + 0.5);
        }
    }
}

int main() {
    std::string reason;
    if (!gl_backend_available(&reason)) {
        std::printf("SKIP: no EGL device (%s)\n", reason.c_str());
        return 0;
    }
    GlBackend gl;
    test_display_matches_cpu(gl);
    test_too_large(gl);

    const auto t0 = std::chrono::steady_clock::now();
    const GlareKernel k97 = glare_kernel_rgb(GlareOptions{}, camera_pixel_angle(60, 97));
    GlareOptions lashes;
    lashes.eyelashes = true;
    const GlareKernel k97_lashes = glare_kernel_rgb(lashes, camera_pixel_angle(60, 97));
    const GlareKernel k360 = glare_kernel_rgb(GlareOptions{}, camera_pixel_angle(60, 360));
    const GlareKernel k1080 = glare_kernel_rgb(GlareOptions{}, camera_pixel_angle(60, 1080));
    GlareOptions wide = lashes;
    wide.grid_size = 2048;
    const GlareKernel k_wide = glare_kernel_rgb(wide, camera_pixel_angle(60, 1080));
    std::printf("kernels (CPU): %.0f ms\n", ms_since(t0));

    print_timings(gl, 640, 360, k360);
    print_timings(gl, 1920, 1080, k1080);
    test_glare_matches_cpu(gl, k97, k97_lashes, k360, k1080, k_wide);
    test_glare_energy(gl, k97);
    test_glare_energy(gl, k1080);
    test_display_with_glare(gl, k97);
    test_hdr_display_with_glare(gl, k97);
    test_hdr_display_with_glare(gl, k1080);
    test_glare_of_a_pixel_is_round(gl);
    return airlight_test::test_result("test_gl_display");
}
