// Display stage on the CPU (issue 8): the per-pixel math of
// effects/display/display.glsl run over the image rows by a pool of threads, like
// cpp/cpu_backend.cpp. See include/airlight/display.hpp.
#include "airlight/display.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "display_stage.hpp"
#include "numerics.hpp"
#include "shader_cpp.hpp"

namespace airlight {

int tone_curve_shader_id(ToneCurve curve) {
    switch (curve) {
        case ToneCurve::linear:
            return shader::TONE_LINEAR;
        case ToneCurve::loglog:
            return shader::TONE_LOGLOG;
        case ToneCurve::reinhard:
            return shader::TONE_REINHARD;
        case ToneCurve::filmic:
            return shader::TONE_FILMIC;
    }
    return -1;
}

namespace {

void check_image(const Image& image) {
    if (image.width < 0 || image.height < 0 || image.rgb.size() != size_t(image.width) * size_t(image.height) * 3) {
        throw std::invalid_argument("radiance: size does not match width * height * 3");
    }
}

}  // namespace

const char* tone_curve_name(ToneCurve curve) {
    switch (curve) {
        case ToneCurve::linear:
            return "linear";
        case ToneCurve::loglog:
            return "loglog";
        case ToneCurve::reinhard:
            return "reinhard";
        case ToneCurve::filmic:
            return "filmic";
    }
    return "unknown";
}

ToneCurve tone_curve_from_name(const std::string& name, const std::string& field) {
    for (ToneCurve c : {ToneCurve::linear, ToneCurve::loglog, ToneCurve::reinhard, ToneCurve::filmic}) {
        if (name == tone_curve_name(c)) return c;
    }
    throw std::invalid_argument(field + ": unknown tone curve '" + name +
                                "'; expected one of linear, loglog, reinhard, filmic");
}

float default_white(ToneCurve curve) {
    switch (curve) {
        case ToneCurve::linear:
            return 1.0f;
        case ToneCurve::loglog:
            return 100.0f;
        case ToneCurve::reinhard:
            return 16.0f;
        case ToneCurve::filmic:
            return shader::ACES_FIT_WHITE;
    }
    return 1.0f;
}

void validate_display_settings(const DisplaySettings& settings, const std::string& prefix) {
    if (tone_curve_shader_id(settings.curve) < 0) {
        throw std::invalid_argument(prefix + "tonemap: unknown tone curve (enum value " +
                                    std::to_string(int(settings.curve)) + ")");
    }
    if (settings.exposure_mode != ExposureMode::manual && settings.exposure_mode != ExposureMode::automatic) {
        throw std::invalid_argument(prefix + "exposure: unknown exposure mode");
    }
    if (settings.exposure_mode == ExposureMode::manual) {
        if (!std::isfinite(settings.exposure)) throw std::invalid_argument(prefix + "exposure: must be finite");
        if (settings.exposure < 0.0f) throw std::invalid_argument(prefix + "exposure: must be >= 0");
    }
    if (settings.white) {
        if (!std::isfinite(*settings.white)) throw std::invalid_argument(prefix + "white: must be finite");
        if (!(*settings.white > 0.0f)) throw std::invalid_argument(prefix + "white: must be > 0");
    }
}

float auto_exposure(const Image& image, float key, int threads) {
    check_image(image);
    const auto luminance = [](const float* p) {
        return 0.2126 * double(p[0]) + 0.7152 * double(p[1]) + 0.0722 * double(p[2]);
    };
    const size_t pixels = size_t(image.width) * size_t(std::max(image.height, 0));
    // physics.md (5.1): the floor is kAutoExposureFloor times the median luminance of the pixels with a
    // normal (not subnormal) positive float luminance, and never below FLT_MIN: zero and subnormal pixels
    // neither count nor move the floor.
    std::vector<float> normal;
    normal.reserve(pixels);
    for (size_t i = 0; i < pixels; ++i) {
        const double Y = luminance(&image.rgb[3 * i]);
        if (std::isfinite(Y) && Y >= double(kMinNormalFloat)) normal.push_back(float(Y));
    }
    if (normal.empty()) return 1.0f;
    const auto median = normal.begin() + std::ptrdiff_t(normal.size() / 2);
    std::nth_element(normal.begin(), median, normal.end());
    const double floor = std::max(kAutoExposureFloor * double(*median), double(kMinNormalFloat));
    // Per-row sums, added in row order afterwards: the result does not depend
    // on the number of threads.
    std::vector<double> row_sum(size_t(std::max(image.height, 0)), 0.0);
    std::vector<long long> row_count(row_sum.size(), 0);
    const auto sum_row = [&](int row) {
        const float* src = image.rgb.data() + size_t(row) * size_t(image.width) * 3;
        double sum = 0.0;
        long long count = 0;
        for (int x = 0; x < image.width; ++x) {
            const double Y = luminance(src + 3 * x);
            if (Y >= floor && std::isfinite(Y)) {
                sum += std::log(Y);
                ++count;
            }
        }
        row_sum[size_t(row)] = sum;
        row_count[size_t(row)] = count;
    };
    numerics::parallel_for(image.height, sum_row, threads);
    double sum = 0.0;
    long long count = 0;
    for (size_t i = 0; i < row_sum.size(); ++i) {
        sum += row_sum[i];
        count += row_count[i];
    }
    if (count == 0) return 1.0f;
    const double exposure = double(key) / std::exp(sum / double(count));
    return float(std::min(exposure, 1.0e30));
}

float resolve_exposure(const Image& image, const DisplaySettings& settings, int threads) {
    return settings.exposure_mode == ExposureMode::manual ? settings.exposure
                                                          : auto_exposure(image, kAutoExposureKey, threads);
}

float tone_map_luminance(ToneCurve curve, float luminance, float white) {
    return shader::tone_curve(tone_curve_shader_id(curve), luminance, white);
}

std::vector<std::uint8_t> apply_display(const Image& linear, const DisplaySettings& settings, int threads) {
    validate_display_settings(settings);
    check_image(linear);
    const float exposure = resolve_exposure(linear, settings, threads);
    const float white = settings.white ? *settings.white : default_white(settings.curve);
    const int curve = tone_curve_shader_id(settings.curve);
    std::vector<std::uint8_t> out(linear.rgb.size());
    const size_t row_floats = size_t(linear.width) * 3;
    const auto display_row = [&](int row) {
        const float* src = linear.rgb.data() + size_t(row) * row_floats;
        std::uint8_t* dst = out.data() + size_t(row) * row_floats;
        for (int x = 0; x < linear.width; ++x) {
            const glm::vec3 radiance(src[3 * x], src[3 * x + 1], src[3 * x + 2]);
            const glm::vec3 v = shader::display_pixel(radiance, exposure, curve, white);
            const float t = settings.dither ? shader::display_dither_threshold(x, row) : 0.5f;
            for (int c = 0; c < 3; ++c) dst[3 * x + c] = std::uint8_t(shader::display_quantize(v[c], t));
        }
    };
    numerics::parallel_for(linear.height, display_row, threads);
    return out;
}

}  // namespace airlight
