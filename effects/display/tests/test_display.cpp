// The display stage (effects/display/display.glsl, effects/display/display.cpp): tone curves
// monotonic on a dense log grid, 0 -> 0, white -> 1, finite on huge, zero,
// NaN and infinite input; the sRGB OETF at known points; automatic exposure
// mapping a uniform image to the key; apply_display against a double
// precision evaluation of the same formulas; bad settings naming the field.
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "airlight/display.hpp"
#include "check.hpp"
#include "shader_cpp.hpp"

using namespace airlight;

namespace {

const ToneCurve kCurves[] = {ToneCurve::linear, ToneCurve::loglog, ToneCurve::reinhard, ToneCurve::filmic};

// The curves in double, written from their definitions (display.glsl's comments).
double reference_curve(ToneCurve curve, double L, double W) {
    if (!(L > 0.0)) return 0.0;
    double v = 0.0;
    switch (curve) {
        case ToneCurve::linear:
            v = L / W;
            break;
        case ToneCurve::loglog:
            v = std::log1p(std::log1p(L)) / std::log1p(std::log1p(W));
            break;
        case ToneCurve::reinhard:
            v = L * (1.0 + L / (W * W)) / (1.0 + L);
            break;
        case ToneCurve::filmic: {
            const double x = L * 7.2439203 / W;
            v = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
            break;
        }
    }
    return std::min(std::max(v, 0.0), 1.0);
}

double reference_oetf(double v) {
    v = std::min(std::max(v, 0.0), 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

bool throws_naming(const std::string& field, void (*fn)()) {
    try {
        fn();
    } catch (const std::invalid_argument& e) {
        return std::string(e.what()).rfind(field + ":", 0) == 0;
    }
    return false;
}

Image uniform_image(int w, int h, float r, float g, float b) {
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.resize(size_t(w) * size_t(h) * 3);
    for (size_t i = 0; i < img.rgb.size(); i += 3) {
        img.rgb[i] = r;
        img.rgb[i + 1] = g;
        img.rgb[i + 2] = b;
    }
    return img;
}

void test_curves() {
    for (ToneCurve curve : kCurves) {
        const std::string name = tone_curve_name(curve);
        const float W = default_white(curve);
        CHECK_MSG(tone_map_luminance(curve, 0.0f, W) == 0.0f, name);
        CHECK_MSG(std::fabs(tone_map_luminance(curve, W, W) - 1.0f) < 1e-5f, name);
        CHECK_MSG(std::fabs(tone_map_luminance(curve, 3.0f, 3.0f) - 1.0f) < 1e-5f, name + " white 3");
        // Monotonic non-decreasing on a dense log grid, 1e-6 .. 1e6, for several whites.
        for (float white : {W, 0.5f, 3.0f, 1000.0f}) {
            float prev = 0.0f;
            bool monotonic = true, in_range = true;
            double max_err = 0.0;
            for (int i = 0; i <= 120000; ++i) {
                const float L = float(std::pow(10.0, -6.0 + 12.0 * i / 120000.0));
                const float v = tone_map_luminance(curve, L, white);
                if (v < prev) monotonic = false;
                if (!(v >= 0.0f && v <= 1.0f)) in_range = false;
                max_err = std::max(max_err, std::fabs(v - reference_curve(curve, L, white)));
                prev = v;
            }
            const std::string what = name + " white " + std::to_string(white);
            CHECK_MSG(monotonic, what);
            CHECK_MSG(in_range, what);
            CHECK_MSG(max_err < 2e-6, what + " max error " + std::to_string(max_err));
        }
        // Huge, infinite, NaN and negative inputs; extreme white points.
        const float inf = std::numeric_limits<float>::infinity();
        const float nan = std::numeric_limits<float>::quiet_NaN();
        CHECK_MSG(tone_map_luminance(curve, 1e30f, W) == 1.0f, name);
        CHECK_MSG(tone_map_luminance(curve, 3e38f, W) == 1.0f, name);
        CHECK_MSG(tone_map_luminance(curve, inf, W) == 1.0f, name);
        CHECK_MSG(tone_map_luminance(curve, nan, W) == 0.0f, name);
        CHECK_MSG(tone_map_luminance(curve, -5.0f, W) == 0.0f, name);
        for (float white : {1e-38f, 1e-20f, 1e30f, 3e38f}) {
            for (float L : {0.0f, 1e-30f, 0.18f, 1e30f}) {
                const float v = tone_map_luminance(curve, L, white);
                CHECK_MSG(v >= 0.0f && v <= 1.0f, name + " L " + std::to_string(L) + " white " + std::to_string(white));
            }
        }
    }
    // Known values: Reinhard at L = 1, W = 2: 1 * 1.25 / 2; the loglog at e - 1.
    CHECK(std::fabs(tone_map_luminance(ToneCurve::reinhard, 1.0f, 2.0f) - 0.625f) < 1e-6f);
    const float e1 = float(std::exp(1.0) - 1.0);
    CHECK(std::fabs(tone_map_luminance(ToneCurve::loglog, e1, 100.0f) -
                    float(std::log(2.0) / std::log1p(std::log1p(100.0)))) < 1e-6f);
    // Narkowicz's curve at 1: 2.54 / 3.16.
    CHECK(std::fabs(tone_map_luminance(ToneCurve::filmic, 1.0f, shader::ACES_FIT_WHITE) - 2.54f / 3.16f) < 1e-6f);
}

void test_oetf() {
    using shader::srgb_oetf;
    CHECK(srgb_oetf(0.0f) == 0.0f);
    CHECK(srgb_oetf(1.0f) == 1.0f);
    CHECK(std::fabs(srgb_oetf(0.5f) - 0.7353569f) < 1e-6f);
    CHECK(std::fabs(srgb_oetf(0.18f) - 0.4613561f) < 1e-6f);
    CHECK(std::fabs(srgb_oetf(0.001f) - 0.01292f) < 1e-7f);
    // Continuity at the break 0.0031308: both pieces give 0.04045 there.
    CHECK(std::fabs(srgb_oetf(0.0031308f) - 0.04045f) < 1e-6f);
    CHECK(std::fabs(srgb_oetf(0.00313081f) - 0.04045f) < 1e-5f);
    CHECK(srgb_oetf(2.0f) == 1.0f && srgb_oetf(-1.0f) == 0.0f);
    CHECK(srgb_oetf(std::numeric_limits<float>::quiet_NaN()) == 0.0f);
    double max_err = 0.0;
    for (int i = 0; i <= 1000; ++i)
        max_err = std::max(max_err, std::fabs(srgb_oetf(i / 1000.0f) - reference_oetf(i / 1000.0)));
    CHECK_MSG(max_err < 1e-6, std::to_string(max_err));
    CHECK(std::fabs(shader::display_luminance(glm::vec3(1.0f)) - 1.0f) < 1e-7f);
}

void test_auto_exposure() {
    // A uniform image of luminance L: exposure * L = 0.18.
    for (float L : {1e-4f, 0.05f, 1.0f, 300.0f}) {
        const Image img = uniform_image(7, 5, 0.5f * L, 1.2f * L, 0.8f * L);
        const double Y = 0.2126 * 0.5 * L + 0.7152 * 1.2 * L + 0.0722 * 0.8 * L;
        const float e = auto_exposure(img);
        CHECK_MSG(std::fabs(e * Y - 0.18) < 1e-5, std::to_string(L));
        // Before the curve: with the linear curve and white 1, grey maps to sRGB(0.18) = 118.
        DisplaySettings s;
        s.curve = ToneCurve::linear;
        s.dither = false;
        const std::vector<std::uint8_t> out = apply_display(uniform_image(3, 2, L, L, L), s);
        CHECK_MSG(out[0] == 118 && out[1] == 118 && out[2] == 118, std::to_string(out[0]));
        // Dithered: 117.65 shows as 117 or 118.
        s.dither = true;
        for (std::uint8_t v : apply_display(uniform_image(3, 2, L, L, L), s)) CHECK(v == 117 || v == 118);
    }
    // Zero, negative, NaN and infinite pixels are ignored; an all-black image gets 1.
    Image img = uniform_image(4, 4, 2.0f, 2.0f, 2.0f);
    img.rgb[0] = img.rgb[1] = img.rgb[2] = 0.0f;
    img.rgb[3] = img.rgb[4] = img.rgb[5] = std::numeric_limits<float>::quiet_NaN();
    img.rgb[6] = img.rgb[7] = img.rgb[8] = std::numeric_limits<float>::infinity();
    img.rgb[9] = img.rgb[10] = img.rgb[11] = -3.0f;
    CHECK(std::fabs(auto_exposure(img) - 0.09f) < 1e-7f);
    CHECK(auto_exposure(uniform_image(3, 3, 0.0f, 0.0f, 0.0f)) == 1.0f);
    CHECK(auto_exposure(uniform_image(0, 0, 0.0f, 0.0f, 0.0f)) == 1.0f);
    // Independent of the thread count.
    Image ramp = uniform_image(9, 37, 1.0f, 1.0f, 1.0f);
    for (size_t i = 0; i < ramp.rgb.size(); ++i) ramp.rgb[i] = float(std::exp(0.01 * double(i % 997)) - 1.0);
    CHECK(auto_exposure(ramp, 0.18f, 1) == auto_exposure(ramp, 0.18f, 8));
}

void test_apply_display() {
    // A 1 x N image of assorted colours over 14 decades, against the formulas in double.
    Image img;
    img.width = 600;
    img.height = 3;
    for (int i = 0; i < img.width * img.height; ++i) {
        const double L = std::pow(10.0, -7.0 + 14.0 * (i % img.width) / img.width);
        img.rgb.insert(img.rgb.end(), {float(L * (0.2 + 0.8 * ((i * 7) % 5) / 4.0)), float(L),
                                       float(L * (0.1 + 0.9 * ((i * 3) % 7) / 6.0))});
    }
    img.rgb[5] = std::numeric_limits<float>::quiet_NaN();
    img.rgb[9] = std::numeric_limits<float>::infinity();
    img.rgb[13] = -1.0f;
    for (ToneCurve curve : kCurves) {
        for (int automatic = 0; automatic < 2; ++automatic) {
            DisplaySettings s;
            s.curve = curve;
            s.exposure_mode = automatic ? ExposureMode::automatic : ExposureMode::manual;
            s.exposure = 2.5f;
            const double exposure = resolve_exposure(img, s);
            const double W = default_white(curve);
            const std::vector<std::uint8_t> out = apply_display(img, s, 4);
            CHECK(out == apply_display(img, s, 1));
            int worst = 0;
            for (size_t p = 0; p < img.rgb.size() / 3; ++p) {
                double c[3];
                for (int k = 0; k < 3; ++k) {
                    const double v = double(img.rgb[3 * p + k]) * exposure;
                    c[k] = v > 0.0 ? std::min(v, 1e30) : 0.0;
                }
                const double Y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                const double scale = Y > 0.0 ? reference_curve(curve, Y, W) / Y : 0.0;
                for (int k = 0; k < 3; ++k) {
                    const int expected = int(std::lround(255.0 * reference_oetf(c[k] * scale)));
                    worst = std::max(worst, std::abs(expected - int(out[3 * p + k])));
                }
            }
            CHECK_MSG(worst <= 1, std::string(tone_curve_name(curve)) + " worst LSB " + std::to_string(worst));
        }
    }
    // Linear, white 1, manual exposure: the same bytes as to_srgb8's clipping.
    DisplaySettings lin;
    lin.curve = ToneCurve::linear;
    lin.exposure_mode = ExposureMode::manual;
    lin.exposure = 1.0f;
    lin.dither = false;
    const Image grey = uniform_image(2, 2, 0.5f, 0.5f, 0.5f);
    CHECK(apply_display(grey, lin)[0] == 188);  // round(255 * 0.7353569)
    CHECK(apply_display(uniform_image(0, 0, 0, 0, 0), lin).empty());
}

void test_errors() {
    CHECK(throws_naming("display.exposure", [] {
        DisplaySettings s;
        s.exposure_mode = ExposureMode::manual;
        s.exposure = -1.0f;
        apply_display(uniform_image(1, 1, 1, 1, 1), s);
    }));
    CHECK(throws_naming("display.exposure", [] {
        DisplaySettings s;
        s.exposure_mode = ExposureMode::manual;
        s.exposure = std::numeric_limits<float>::infinity();
        validate_display_settings(s);
    }));
    CHECK(throws_naming("display.white", [] {
        DisplaySettings s;
        s.white = 0.0f;
        validate_display_settings(s);
    }));
    CHECK(throws_naming("display.white", [] {
        DisplaySettings s;
        s.white = std::numeric_limits<float>::quiet_NaN();
        validate_display_settings(s);
    }));
    CHECK(throws_naming("display.tonemap", [] { tone_curve_from_name("aces"); }));
    CHECK(throws_naming("display.tonemap", [] {
        DisplaySettings s;
        s.curve = ToneCurve(17);
        validate_display_settings(s);
    }));
    CHECK(throws_naming("white", [] {
        DisplaySettings s;
        s.white = -2.0f;
        validate_display_settings(s, "");
    }));
    CHECK(throws_naming("radiance", [] {
        Image img;
        img.width = 2;
        img.height = 2;
        img.rgb.assign(11, 1.0f);
        apply_display(img, DisplaySettings{});
    }));
    for (ToneCurve c : kCurves) CHECK(tone_curve_from_name(tone_curve_name(c)) == c);
}

}  // namespace

int main() {
    test_curves();
    test_oetf();
    test_auto_exposure();
    test_apply_display();
    test_errors();
    return airlight_test::test_result("test_display");
}
