// The two backends run the same shared shader code: every shader variant
// compiles in GL, GL and CPU agree within 0.5% away from geometric edges, and
// the image conventions (row 0 on top, lamp core radiance) hold on both.
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>

#include "airlight/renderer.hpp"
#include "airlight/scene_io.hpp"
#include "check.hpp"

using namespace airlight;

namespace {

Scene base_scene() {
    return parse_scene(R"({
      "film": {"width": 96, "height": 64},
      "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 60},
      "medium": {"sigma_t": [0.02, 0.05, 0.1]},
      "lights": [{"type": "point", "position": [3, 5, -20], "intensity": [100, 90, 70]},
                 {"type": "point", "position": [0, 1.7, -8], "intensity": 2, "radius": 0.3}],
      "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
                   {"type": "box", "min": [-8, 0, -40], "max": [-4, 12, -25], "albedo": 0.5},
                   {"type": "sphere", "center": [2, 1, -12], "radius": 1, "albedo": [0.7, 0.2, 0.2]}],
      "background": [0.1, 0.2, 0.3]})");
}

bool all_finite_nonnegative(const Image& img) {
    return std::all_of(img.rgb.begin(), img.rgb.end(), [](float v) { return std::isfinite(v) && v >= 0.0f; });
}

// Largest relative difference over pixels whose 3x3 neighbourhood is smooth in
// `a` (no geometric edge) and above 1e-3 of the image's 99th percentile (not
// its maximum: a lamp smaller than a pixel puts its whole energy into a few
// very bright pixels).
double max_relative_difference(const Image& a, const Image& b, int& compared) {
    std::vector<float> sorted = a.rgb;
    auto p99 = sorted.begin() + std::ptrdiff_t(0.99 * double(sorted.size() - 1));
    std::nth_element(sorted.begin(), p99, sorted.end());
    const float peak = *p99;
    double worst = 0.0;
    compared = 0;
    auto at = [&](const Image& img, int x, int y, int c) { return img.rgb[(size_t(y) * img.width + x) * 3 + c]; };
    for (int y = 1; y + 1 < a.height; ++y) {
        for (int x = 1; x + 1 < a.width; ++x) {
            for (int c = 0; c < 3; ++c) {
                const float v = at(a, x, y, c);
                if (v < 1e-3f * peak) continue;
                bool edge = false;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) edge |= std::abs(at(a, x + dx, y + dy, c) - v) > 0.2f * v;
                if (edge) continue;
                ++compared;
                worst = std::max(worst, double(std::abs(at(b, x, y, c) - v)) / v);
            }
        }
    }
    return worst;
}

void test_cpu_conventions() {
    Scene scene = base_scene();
    scene.medium.albedo = glm::vec3(0.0f);  // absorbing fog: no airlight in front of the core
    Renderer cpu(Backend::cpu);
    const Image img = cpu.render(scene);
    CHECK(img.width == 96 && img.height == 64 && img.rgb.size() == size_t(96 * 64 * 3));
    CHECK(all_finite_nonnegative(img));
    // The lamp at the view centre shows its core: I / (pi r^2) attenuated over 8 - 0.3 m.
    const float expected = 2.0f / (3.14159265f * 0.09f) * std::exp(-0.02f * 7.7f);
    const float centre = img.rgb[(size_t(32) * 96 + 48) * 3 + 0];
    CHECK_MSG(std::abs(centre - expected) < 1e-3f * expected,
              std::to_string(centre) + " vs " + std::to_string(expected));
    // Row 0 is the top: looking level at a plane below, the ground is in the bottom rows only.
    scene.point_lights.resize(1);
    scene.surfaces.resize(1);
    scene.has_medium = false;
    const Image ground = cpu.render(scene);
    CHECK(ground.rgb[(size_t(63) * 96 + 48) * 3] > 0.0f);
    CHECK(ground.rgb[(size_t(0) * 96 + 48) * 3 + 2] == 0.3f);  // background on top
}

int test_gl_matches_cpu() {
    std::string reason;
    if (!gl_backend_available(&reason)) {
        std::printf("SKIPPED GL checks: GL backend unavailable: %s\n", reason.c_str());
        return airlight_test::kSkipped;
    }
    Renderer cpu(Backend::cpu);
    Renderer gl(Backend::gl);
    // Every feature combination (shader variant) compiles and agrees:
    // medium, lights, surfaces, grey medium, ray-marched airlight, spotlights.
    for (int mask = 0; mask < 64; ++mask) {
        Scene scene = base_scene();
        if (!(mask & 1)) scene.has_medium = false;
        if (!(mask & 2)) scene.point_lights.clear();
        if (!(mask & 4)) scene.surfaces.clear();
        if (mask & 8) scene.medium.sigma_t = glm::vec3(0.05f);
        if (mask & 16) scene.quality.airlight = AirlightMethod::march;
        if (mask & 32) {
            SpotLight spot;
            spot.position = glm::vec3(-2.0f, 5.0f, -12.0f);
            spot.direction = glm::normalize(glm::vec3(0.3f, -1.0f, -0.2f));
            spot.intensity = glm::vec3(400.0f, 350.0f, 300.0f);
            spot.cone_angle_degrees = 25.0f;
            spot.edge = 0.2f;
            scene.spot_lights.push_back(spot);
        }
        const Image a = cpu.render(scene);
        const Image b = gl.render(scene);
        CHECK(all_finite_nonnegative(b));
        int compared = 0;
        const double diff = max_relative_difference(a, b, compared);
        CHECK_MSG(diff <= 0.005, "variant " + std::to_string(mask) + ": " + std::to_string(diff));
        if (mask == 7 || mask == 15) CHECK_MSG(compared > 1500, std::to_string(compared));
    }
    // Size changes and reuse of one GL renderer.
    Scene scene = base_scene();
    scene.film = {33, 17};
    const Image small = gl.render(scene);
    CHECK(small.width == 33 && small.height == 17 && small.rgb.size() == size_t(33 * 17 * 3));
    // Films larger than one GL tile (2048 pixels) are drawn tile by tile and
    // must come back seamless, in the right place: compare with the CPU on a
    // film two tiles wide, and on one two tiles tall.
    for (Film film : {Film{2100, 20}, Film{20, 2100}}) {
        Scene tiled = base_scene();
        tiled.film = film;
        tiled.camera.fov_y_degrees = 100.0f;
        const Image a = cpu.render(tiled), b = gl.render(tiled);
        int compared = 0;
        const double diff = max_relative_difference(a, b, compared);
        CHECK_MSG(diff <= 0.005 && compared > 10000,
                  std::to_string(film.width) + "x" + std::to_string(film.height) + ": " + std::to_string(diff));
    }
    return 0;
}

}  // namespace

int main() {
    test_cpu_conventions();
    const int gl = test_gl_matches_cpu();
    const int result = airlight_test::test_result("test_backends");
    return result != 0 ? result : gl;
}
