// The sun's shadow map (effects/sun_shadow_map/physics.md): when the frame
// asks for its grid pass, and what the pass computes, against an independent
// double-precision ray cast of the same boxes and ground.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "airlight/scene_io.hpp"
#include "backends.hpp"
#include "check.hpp"
#include "frame_data.hpp"

using namespace airlight;

namespace {

// Two boxes and a sphere on a ground plane under a sun 35 degrees high.
std::string scene_json(const std::string& quality, const std::string& sun, bool boxes = true) {
    const std::string bounded = boxes ? R"(,
        {"type": "box", "min": [-3, 0, -14], "max": [-1, 3, -10], "albedo": 0.5},
        {"type": "box", "min": [1, 0, -9], "max": [2, 1.5, -7], "albedo": 0.5},
        {"type": "sphere", "center": [0.5, 1, -16], "radius": 1, "albedo": 0.5})"
                                      : "";
    return R"({"film": {"width": 32, "height": 24},
        "camera": {"position": [0, 1.7, 0], "look_at": [0, 1, -10], "up": [0, 1, 0], "fov_y": 60},
        "sky": {"model": "overcast", "zenith_radiance": 0.3},)" +
           sun + R"("quality": )" + quality + R"(,
        "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3})" +
           bounded + "]}";
}
const std::string kSun = R"("sun": {"elevation": 35, "azimuth": 120, "irradiance": 100},)";

// Distance along direction d from o to the first of the scene's surfaces, in double.
double exact_first_hit(const glm::dvec3& o, const glm::dvec3& d) {
    double best = std::numeric_limits<double>::infinity();
    if (d.y < 0.0) best = std::min(best, -o.y / d.y);  // the ground
    auto box = [&](glm::dvec3 lo, glm::dvec3 hi) {
        double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a) {
            double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (t0 <= t1) best = std::min(best, t0);
    };
    box({-3, 0, -14}, {-1, 3, -10});
    box({1, 0, -9}, {2, 1.5, -7});
    const glm::dvec3 oc = o - glm::dvec3(0.5, 1, -16);
    const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - 1.0, disc = b * b - c;
    if (disc >= 0.0 && -b - std::sqrt(disc) > 0.0) best = std::min(best, -b - std::sqrt(disc));
    return best;
}

void check_when_the_pass_runs() {
    CHECK(make_frame_data(parse_scene(scene_json("{}", kSun))).grid_passes.empty());  // default: shadow rays
    CHECK(make_frame_data(parse_scene(scene_json(R"({"sun_shadow_map": 0})", kSun))).grid_passes.empty());
    // No sun, or nothing bounded to cast a shadow: no map.
    CHECK(make_frame_data(parse_scene(scene_json(R"({"sun_shadow_map": 256})", ""))).grid_passes.empty());
    CHECK(make_frame_data(parse_scene(scene_json(R"({"sun_shadow_map": 256})", kSun, false))).grid_passes.empty());
    const FrameData data = make_frame_data(parse_scene(scene_json(R"({"sun_shadow_map": 256})", kSun)));
    CHECK(data.features.sun_shadow_map);
    CHECK(data.grid_passes.size() == 1);
    if (data.grid_passes.size() != 1) return;
    const GridPassJob& job = data.grid_passes[0];
    CHECK(job.slot == shader::TABLE_SUN_SHADOW_MAP);
    CHECK(job.channels == 1);
    // N texels along the longer side, one texel of border each side.
    CHECK(std::max(job.width, job.height) == 256 + 2);
    CHECK(std::min(job.width, job.height) >= 3);
    CHECK(job.width == int(data.frame.sun_shadow_map.axis_u.w) &&
          job.height == int(data.frame.sun_shadow_map.axis_v.w));
}

// Every texel of the CPU pass is the distance to the first surface along the
// sunlight from its centre, within float32 rounding.
void check_pass_against_exact_rays() {
    const FrameData data = make_frame_data(parse_scene(scene_json(R"({"sun_shadow_map": 128})", kSun)));
    CpuBackend cpu;
    const std::vector<Table2D> tables = cpu.grid_passes(data);
    CHECK(tables.size() == 1);
    if (tables.size() != 1) return;
    const Table2D& t = tables[0];
    const shader::SunShadowMapGpu& m = data.frame.sun_shadow_map;
    const glm::dvec3 s = glm::normalize(glm::dvec3(glm::vec3(data.frame.sky.sun_direction)));
    const double w = m.origin.w;
    double worst = 0.0;
    int casters = 0;
    for (int j = 0; j < t.height; ++j) {
        for (int i = 0; i < t.width; ++i) {
            const glm::dvec3 p = glm::dvec3(glm::vec3(m.origin)) + (i + 0.5) * w * glm::dvec3(glm::vec3(m.axis_u)) +
                                 (j + 0.5) * w * glm::dvec3(glm::vec3(m.axis_v));
            const double exact = exact_first_hit(p, -s);
            const double got = t.texels[size_t(j) * size_t(t.width) + size_t(i)];
            if (exact < double(m.depth.x)) ++casters;  // a bounded surface, above the ground's depth range
            // Texels whose centre grazes an edge may hit the other side: compare only clear cases.
            const double near_edge = exact_first_hit(p + 0.02 * w * glm::dvec3(glm::vec3(m.axis_u)), -s);
            if (std::abs(near_edge - exact) > 1e-3 * (exact + 1.0)) continue;
            worst = std::max(worst, std::abs(got - exact) / (exact + 1.0));
        }
    }
    CHECK_MSG(worst < 1e-5, std::to_string(worst));
    CHECK_MSG(casters > 100, std::to_string(casters));  // the map sees the casters
}

}  // namespace

int main() {
    check_when_the_pass_runs();
    check_pass_against_exact_rays();
    return airlight_test::test_result("test_sun_shadow_map");
}
