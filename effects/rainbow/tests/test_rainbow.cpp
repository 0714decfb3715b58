// The rainbow tables (effects/rainbow/rainbow.hpp, issue 7): the embedded spectral table's
// grids and file format, the colour weights, the renderer's RGB table and its
// cache, and the features a scene switches on.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "airlight/scene_io.hpp"
#include "check.hpp"
#include "frame_data.hpp"
#include "rainbow.hpp"

using namespace airlight;

namespace {

void check_embedded_table() {
    const RainbowSpectralTable& t = rainbow_spectral_table();
    CHECK(t.wavelengths_nm.size() == size_t(RAINBOW_WAVELENGTHS));
    CHECK(t.rates.size() == size_t(RAINBOW_RATES));
    CHECK(t.angles_deg == rainbow_angles_deg());
    for (int i = 0; i < RAINBOW_WAVELENGTHS; ++i) CHECK(t.wavelengths_nm[size_t(i)] == rainbow_wavelength_nm(i));
    bool finite_positive = true;
    for (float p : t.phase) finite_positive = finite_positive && std::isfinite(p) && p > 0.0f;
    CHECK(finite_positive);
    CHECK(t.samples_per_wavelength >= 1024);
}

void check_file_format() {
    const RainbowSpectralTable& t = rainbow_spectral_table();
    std::vector<char> bytes = serialize_rainbow_table(t);
    const RainbowSpectralTable back = parse_rainbow_table(bytes);
    CHECK(back.phase == t.phase && back.rel_error == t.rel_error && back.rates == t.rates);
    auto throws = [](std::vector<char> b, const char* expected) {
        try {
            parse_rainbow_table(b);
        } catch (const std::runtime_error& e) {
            CHECK_MSG(std::string(e.what()).find(expected) != std::string::npos, e.what());
            return;
        }
        CHECK_MSG(false, std::string("no error for ") + expected);
    };
    std::vector<char> bad = bytes;
    bad[0] = 'X';
    throws(bad, "bad magic");
    throws(std::vector<char>(bytes.begin(), bytes.end() - 7), "truncated");
    std::vector<char> longer = bytes;
    longer.push_back(0);
    throws(longer, "trailing");
    std::vector<char> huge = bytes;
    const int32_t n = -3;
    std::memcpy(huge.data() + 8, &n, 4);
    throws(huge, "grid size");
}

// The aureole's rescaling makes a table integrate to 1 and leaves the phase
// beyond 1 degree alone, whatever the forward error was.
void check_aureole_normalisation() {
    RainbowSpectralTable t = rainbow_spectral_table();
    const size_t na = t.angles_deg.size();
    for (size_t a = 0; a < na; ++a)
        if (t.angles_deg[a] < 0.7) t.phase[a] *= 1.3f;  // rate 0, wavelength 0: 30 % too bright
    const std::vector<float> before(t.phase.begin(), t.phase.begin() + long(na));
    normalise_rainbow_aureole(t);
    double total = 0.0;
    for (size_t a = 0; a + 1 < na; ++a) {
        const double t0 = t.angles_deg[a] * M_PI / 180.0, t1 = t.angles_deg[a + 1] * M_PI / 180.0;
        total += M_PI * (t.phase[a] * std::sin(t0) + t.phase[a + 1] * std::sin(t1)) * (t1 - t0);
    }
    CHECK_MSG(std::abs(total - 1.0) < 1e-5, std::to_string(total));
    bool beyond_unchanged = true, forward_dimmed = true;
    for (size_t a = 0; a < na; ++a) {
        if (t.angles_deg[a] >= 1.0) beyond_unchanged = beyond_unchanged && t.phase[a] == before[a];
        if (t.angles_deg[a] <= 0.5) forward_dimmed = forward_dimmed && t.phase[a] < 0.85f * before[a];
    }
    CHECK(beyond_unchanged);
    CHECK(forward_dimmed);
}

// Part of the angle grid (for refining a table) computes only those angles,
// finite and positive, and is not rescaled (it does not span the sphere).
void check_partial_angle_range() {
    RainbowSampling s;
    s.samples_per_wavelength = 64;
    s.wavelengths = {16};
    s.angle_min_deg = 178.0;
    s.angle_max_deg = 180.0;
    const RainbowSpectralTable t = compute_rainbow_spectral_table(s);
    CHECK(t.angles_deg.size() == 41 && t.angles_deg.front() == 178.0 && t.angles_deg.back() == 180.0);
    bool finite_positive = true;
    for (float p : t.phase) finite_positive = finite_positive && std::isfinite(p) && p > 0.0f;
    CHECK(finite_positive);
    s.angle_min_deg = 180.5;
    s.angle_max_deg = 181.0;
    bool threw = false;
    try {
        compute_rainbow_spectral_table(s);
    } catch (const std::invalid_argument&) {
        threw = true;
    }
    CHECK(threw);
}

void check_colour_weights() {
    for (int count : {3, 5, 9, 17}) {
        const std::vector<float> w = rainbow_rgb_weights(count);
        CHECK(w.size() == size_t(count) * 3);
        for (int c = 0; c < 3; ++c) {
            double sum = 0.0;
            for (int j = 0; j < count; ++j) sum += w[size_t(j) * 3 + size_t(c)];
            CHECK_MSG(std::abs(sum - 1.0) < 1e-5, std::to_string(sum));
        }
    }
    // Red weighs long wavelengths, blue short ones.
    const std::vector<float> w = rainbow_rgb_weights(17);
    CHECK(w[14 * 3 + 0] > w[2 * 3 + 0] && w[2 * 3 + 2] > w[14 * 3 + 2]);
    bool threw = false;
    try {
        rainbow_rgb_weights(4);
    } catch (const std::invalid_argument&) {
        threw = true;
    }
    CHECK(threw);
}

void check_rgb_table_and_cache() {
    const Table2D& a = rainbow_phase_table(25.0, 17);
    const Table2D& b = rainbow_phase_table(25.0, 17);
    CHECK(&a == &b);  // cached
    CHECK(a.width == 3601 && a.height == 1 && a.channels == 4);
    bool ok = true;
    for (float v : a.texels) ok = ok && std::isfinite(v) && v >= 0.0f;
    CHECK(ok);
    // Out-of-table rates are clamped to the ends, not extrapolated.
    const std::vector<double> lo = rainbow_spectral_phase(1e-4, 8), first = rainbow_spectral_phase(0.1, 8);
    const std::vector<double> hi = rainbow_spectral_phase(1000.0, 8), last = rainbow_spectral_phase(819.2, 8);
    CHECK(lo == first && hi == last);
}

Scene rain_scene(const std::string& rain) {
    return parse_scene(R"({"film": {"width": 4, "height": 4},
        "camera": {"position": [0, 2, 0], "look_at": [0, 2, -1], "up": [0, 1, 0], "fov_y": 60},
        "sun": {"elevation": 20, "azimuth": 180, "irradiance": [10, 10, 10]},
        "atmosphere": {"rain": )" +
                       rain + "}}");
}

void check_features() {
    CHECK(make_frame_data(rain_scene(R"({"rate": 25})")).features.rainbow);
    CHECK(make_frame_data(rain_scene(R"({"rate": 25})")).tables[shader::TABLE_RAINBOW] != nullptr);
    CHECK(!make_frame_data(rain_scene(R"({"rate": 25, "phase": "hg"})")).features.rainbow);
    CHECK(!make_frame_data(rain_scene(R"({"rate": 25, "density_scale": 0})")).features.rainbow);
    CHECK(!make_frame_data(rain_scene(R"({"rate": 0})")).tables[shader::TABLE_RAINBOW]);
    Scene round = parse_scene(scene_to_json(rain_scene(R"({"rate": 5, "phase": "hg"})")));
    CHECK(round.atmosphere.rain.phase == RainPhase::hg);
}

}  // namespace

int main() {
    check_embedded_table();
    check_file_format();
    check_aureole_normalisation();
    check_partial_angle_range();
    check_colour_weights();
    check_rgb_table_and_cache();
    check_features();
    return airlight_test::test_result("test_rainbow");
}
