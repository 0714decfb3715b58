// OpenEXR output and input (cpp/image_io.cpp): write_exr / read_exr round
// trips (float32 bit-exact, half within half precision), the channel naming,
// and the errors for bad input and for files that cannot be written or read.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "airlight/image_io.hpp"
#include "check.hpp"

using airlight::NamedImage;

namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("airlight_test_image_io_" + std::to_string(getpid()));
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

std::uint32_t bits(float v) {
    std::uint32_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
}

float from_bits(std::uint32_t b) {
    float v;
    std::memcpy(&v, &b, sizeof v);
    return v;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (bits(a[i]) != bits(b[i])) return false;
    return true;
}

// Deterministic values of every kind: ordinary, negative, tiny, subnormal,
// signed zero, +-inf (escaping rays' depth) and NaNs with payloads.
std::vector<float> test_values(std::size_t n, std::uint32_t seed) {
    const float specials[] = {0.0f,
                              -0.0f,
                              1e-40f,  // subnormal
                              -3.5e-38f,
                              std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::quiet_NaN(),
                              from_bits(0x7fc00123u),  // a quiet NaN with a payload
                              from_bits(0xffc00000u),  // a negative NaN
                              3.4e38f,
                              1e-7f};
    std::vector<float> v(n);
    std::uint32_t state = seed;
    for (std::size_t i = 0; i < n; ++i) {
        state = state * 1664525u + 1013904223u;
        v[i] = i % 3 == 0 && i / 3 < std::size(specials) ? specials[i / 3]
                                                         : (float(state >> 8) / float(1 << 24) - 0.25f) * 100.0f;
    }
    return v;
}

void test_float_round_trip_is_bit_exact_with_names_and_order() {
    const int w = 7, h = 5;  // odd sizes
    const std::size_t n = std::size_t(w) * h;
    const std::vector<NamedImage> written = {
        {"depth", 1, test_values(n, 1)},
        {"radiance", 3, test_values(3 * n, 2)},
        {"normal", 3, test_values(3 * n, 3)},
        {"albedo", 3, test_values(3 * n, 4)},
    };
    const std::string path = (temp_dir() / "round_trip.exr").string();
    airlight::write_exr(path, w, h, written);
    int rw = 0, rh = 0;
    const std::vector<NamedImage> back = airlight::read_exr(path, rw, rh);
    CHECK(rw == w && rh == h);
    // radiance first, then the file's channel order (sorted): albedo.*, depth, normal.*.
    const char* expected_order[] = {"radiance", "albedo", "depth", "normal"};
    CHECK(back.size() == 4);
    for (std::size_t i = 0; i < back.size() && i < 4; ++i) CHECK_MSG(back[i].name == expected_order[i], back[i].name);
    for (const NamedImage& im : written) {
        bool found = false;
        for (const NamedImage& b : back) {
            if (b.name != im.name) continue;
            found = true;
            CHECK_MSG(b.components == im.components, im.name);
            CHECK_MSG(same_bits(b.values, im.values), im.name);
        }
        CHECK_MSG(found, im.name);
    }
}

void test_one_pixel_and_plain_radiance_round_trip() {
    airlight::Image image;
    image.width = image.height = 1;
    image.rgb = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), -1e-30f};
    const std::string path = (temp_dir() / "one_pixel.exr").string();
    airlight::write_exr(path, image);
    int w = 0, h = 0;
    const std::vector<NamedImage> back = airlight::read_exr(path, w, h);
    CHECK(w == 1 && h == 1);
    CHECK(back.size() == 1 && back[0].name == "radiance" && back[0].components == 3);
    CHECK(!back.empty() && same_bits(back[0].values, image.rgb));
}

void test_half_is_within_half_precision_and_overflows_to_inf() {
    const int w = 9, h = 3;
    const std::size_t n = std::size_t(w) * h;
    std::vector<float> rgb(3 * n), depth(n);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = 1e-3f * std::pow(1.7f, float(i % 40));  // 1e-3 .. 1e6
    for (std::size_t i = 0; i < n; ++i) depth[i] = -0.37f * float(i + 1);
    depth[0] = 65504.0f;  // the largest half
    depth[1] = 70000.0f;
    depth[2] = -1e5f;
    depth[3] = std::numeric_limits<float>::infinity();
    depth[4] = std::numeric_limits<float>::quiet_NaN();
    const std::string path = (temp_dir() / "half.exr").string();
    airlight::write_exr(path, w, h, {{"radiance", 3, rgb}, {"depth", 1, depth}}, true);
    int rw = 0, rh = 0;
    const std::vector<NamedImage> back = airlight::read_exr(path, rw, rh);
    CHECK(back.size() == 2 && back[0].name == "radiance" && back[1].name == "depth");
    if (back.size() != 2) return;
    const float inf = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        const float expected = rgb[i] > 65504.0f ? inf : rgb[i];
        const float got = back[0].values[i];
        CHECK_MSG(got == expected || std::fabs(got - expected) <= std::ldexp(std::fabs(expected), -11),
                  std::to_string(rgb[i]) + " -> " + std::to_string(got));
    }
    CHECK(back[1].values[0] == 65504.0f);
    CHECK(back[1].values[1] == inf);
    CHECK(back[1].values[2] == -inf);
    CHECK(back[1].values[3] == inf);
    CHECK(std::isnan(back[1].values[4]));
    for (std::size_t i = 5; i < n; ++i)
        CHECK(std::fabs(back[1].values[i] - depth[i]) <= std::ldexp(std::fabs(depth[i]), -11));
}

// Calls `f`, expecting exception E whose message contains every one of `needles`.
template <class E>
void check_throws(const std::function<void()>& f, const std::vector<std::string>& needles, const std::string& what) {
    try {
        f();
        CHECK_MSG(false, what + ": no exception");
    } catch (const E& e) {
        for (const std::string& needle : needles)
            CHECK_MSG(std::string(e.what()).find(needle) != std::string::npos,
                      what + ": '" + needle + "' not in '" + e.what() + "'");
    } catch (const std::exception& e) {
        CHECK_MSG(false, what + ": wrong exception type: " + e.what());
    }
}

void test_bad_input_is_rejected_naming_the_field() {
    const std::string path = (temp_dir() / "bad.exr").string();
    const std::vector<float> rgb(2 * 3 * 3, 1.0f), grey(2 * 3, 1.0f);
    auto bad = [&](int w, int h, std::vector<NamedImage> images, std::vector<std::string> needles) {
        check_throws<std::invalid_argument>([&] { airlight::write_exr(path, w, h, images); }, needles,
                                            needles.empty() ? "" : needles[0]);
    };
    bad(0, 3, {{"radiance", 3, {}}}, {"width"});
    bad(2, -1, {{"radiance", 3, rgb}}, {"height"});
    bad(2, 3, {}, {"images"});
    bad(2, 3, {{"", 3, rgb}}, {"images[0].name", "empty"});
    bad(2, 3, {{"radiance", 3, rgb}, {"depth", 2, grey}}, {"images[1].components", "1 or 3"});
    bad(2, 3, {{"radiance", 3, grey}}, {"images[0].values", "18", "got 6"});
    bad(2, 3, {{"depth", 1, grey}, {"depth", 1, grey}}, {"images[1].name", "duplicate", "depth"});
    bad(2, 3, {{"a.b", 1, grey}}, {"images[0].name", "'.'"});
    bad(2, 3, {{"radiance", 1, grey}}, {"images[0].components", "radiance"});
    bad(2, 3, {{"radiance", 3, rgb}, {"G", 1, grey}}, {"images[1].name", "'G'"});
    bad(2, 3, {{std::string(254, 'n'), 1, grey}}, {"images[0].name", "253"});
    CHECK(!fs::exists(path));
}

void test_io_failures_name_the_path() {
    const std::string missing = (temp_dir() / "no_such.exr").string();
    int w = 0, h = 0;
    check_throws<std::runtime_error>([&] { airlight::read_exr(missing, w, h); }, {missing}, "missing file");
    const std::string text = (temp_dir() / "not_exr.exr").string();
    std::ofstream(text) << "this is not an OpenEXR file\n";
    check_throws<std::runtime_error>([&] { airlight::read_exr(text, w, h); }, {text}, "not an EXR file");
    // A truncated EXR file: the header read, the pixels not.
    const std::string whole = (temp_dir() / "whole.exr").string();
    airlight::write_exr(whole, 64, 64, {{"radiance", 3, test_values(64 * 64 * 3, 5)}});
    const std::string cut = (temp_dir() / "truncated.exr").string();
    fs::copy_file(whole, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, fs::file_size(whole) / 2);
    check_throws<std::runtime_error>([&] { airlight::read_exr(cut, w, h); }, {cut}, "truncated file");
    const std::string unwritable = (temp_dir() / "no_such_dir" / "x.exr").string();
    check_throws<std::runtime_error>(
        [&] {
            airlight::write_exr(unwritable, 1, 1, {{"depth", 1, {1.0f}}});
        },
        {unwritable}, "unwritable path");
}

}  // namespace

int main() {
    test_float_round_trip_is_bit_exact_with_names_and_order();
    test_one_pixel_and_plain_radiance_round_trip();
    test_half_is_within_half_precision_and_overflows_to_inf();
    test_bad_input_is_rejected_naming_the_field();
    test_io_failures_name_the_path();
    fs::remove_all(temp_dir());
    return airlight_test::test_result("test_image_io");
}
