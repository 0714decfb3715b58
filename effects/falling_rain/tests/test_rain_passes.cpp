// The falling rain's grid passes (physics.md section 4) on both backends: the
// GL passes' tables, read back, agree with the CPU's texel by texel, in the
// night street (lamps and spots over boxes: the drops' shadow rays) and where
// a drop's light needs more loop iterations than llvmpipe runs (its texels
// are cut and the frame's grid passes recomputed on the CPU).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "airlight/scene_io.hpp"
#include "backends.hpp"
#include "check.hpp"
#include "frame_data.hpp"

using namespace airlight;

namespace {

// The largest relative difference between the backends' tables, pass by pass.
double worst_difference(const std::vector<Table2D>& cpu, const std::vector<Table2D>& gl) {
    CHECK(cpu.size() == gl.size());
    double worst = 0.0;
    for (size_t k = 0; k < cpu.size() && k < gl.size(); ++k) {
        CHECK(cpu[k].texels.size() == gl[k].texels.size());
        for (size_t i = 0; i < cpu[k].texels.size() && i < gl[k].texels.size(); ++i) {
            const double a = cpu[k].texels[i], b = gl[k].texels[i];
            worst = std::max(worst, std::abs(a - b) / (std::abs(a) + 1e-6));
        }
    }
    return worst;
}

Scene night_street() {
    const char* root = std::getenv("AIRLIGHT_SOURCE_DIR");
    Scene scene = load_scene_file(std::string(root != nullptr ? root : ".") + "/scenes/falling_rain_night_light.json");
    scene.film.width = 16;
    scene.film.height = 9;
    return scene;
}

// Thousands of drops near the camera whose shadow rays to the lamps miss every
// box: the GL traversal once kept its loop running after all its lanes had
// left it, the loop limiter then cut the remaining lamps (a third of the
// drops lost lamps' light) - now no texel is cut.
void check_night_street_passes_agree() {
    const Scene scene = night_street();
    const FrameData data = make_frame_data(scene);
    CHECK(data.grid_passes.size() == 3);
    CpuBackend cpu;
    GlBackend gl;
    const std::vector<Table2D> a = cpu.grid_passes(data), b = gl.grid_passes(data);
    CHECK(data.frame.falling_rain.tiles.z > 2000);
    const double worst = worst_difference(a, b);
    CHECK_MSG(worst < 1e-4, std::to_string(worst));
    CHECK_MSG(gl.grid_pass_cut_texels() == 0, std::to_string(gl.grid_pass_cut_texels()));
}

// 3000 lamps: a drop's rain_light texel needs more than llvmpipe's 65535 loop
// iterations; its cut texels are found and the passes computed on the CPU.
void check_cut_texels_fall_back_to_the_cpu() {
    Scene scene = night_street();
    scene.falling_rain.radius = 1.0f;
    const PointLight lamp = scene.point_lights.at(0);
    scene.point_lights.clear();
    scene.spot_lights.clear();
    for (int i = 0; i < 3000; ++i) {
        PointLight l = lamp;
        l.position = glm::vec3(-5.0f + 10.0f * float(i % 2), 6.0f, -8.0f - 0.05f * float(i));
        l.intensity *= 0.01f;
        scene.point_lights.push_back(l);
    }
    const FrameData data = make_frame_data(scene);
    CpuBackend cpu;
    GlBackend gl;
    const std::vector<Table2D> a = cpu.grid_passes(data), b = gl.grid_passes(data);
    const int cut = gl.grid_pass_cut_texels();
    CHECK_MSG(cut > 0, "no texel was cut: the test no longer reaches the loop limit");
    const double worst = worst_difference(a, b);
    CHECK_MSG(worst < 1e-4, std::to_string(worst) + " with " + std::to_string(cut) + " texels cut");
}

}  // namespace

int main() {
    std::string reason;
    if (!gl_backend_available(&reason)) {
        std::printf("SKIPPED GL checks: GL backend unavailable: %s\n", reason.c_str());
        return airlight_test::kSkipped;
    }
    check_night_street_passes_agree();
    check_cut_texels_fall_back_to_the_cpu();
    return airlight_test::test_result("test_rain_passes");
}
