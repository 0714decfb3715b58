// CPU backend: the shared GLSL per-pixel code compiled as C++ (shader_cpp.hpp),
// run over the image rows by a pool of threads.
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "backends.hpp"

namespace airlight {
namespace shader {

// The shared shader code becomes the member functions of this struct; its
// members play the part of the GL uniforms and storage buffers.
struct CpuShader {
    const FrameUniforms& frame;
    const PointLightGpu* point_lights;
    const SurfaceGpu* surfaces;
    const BvhNodeGpu* bvh_nodes;
    const float* airlight_tail_texels;  // null unless the scene needs the table
    const float* surface_glow_texels;
    const float* spot_moment_texels;
    const SpotLightGpu* spot_lights;
    Features features;

    const float* phase_moment_texels[2];  // per phase lobe (null when unused)
    const float* phase_glow_texels[2];
    const float* sky_texels;  // RGBA, width SKY_TABLE columns (null when unused)
    int sky_table_width;
    const float* rainbow_texels;  // RGBA, RAINBOW_TABLE_N texels (null when unused)

    vec4 rainbow_table_texel(int x) const {
        const float* t = rainbow_texels + size_t(x) * 4;
        return vec4(t[0], t[1], t[2], t[3]);
    }

    vec4 sky_table_texel(int x, int y) const {
        const float* t = sky_texels + (size_t(y) * size_t(sky_table_width) + size_t(x)) * 4;
        return vec4(t[0], t[1], t[2], t[3]);
    }

    float table_texel(int table, int x, int y) const {
        if (table == TABLE_AIRLIGHT_TAIL) return airlight_tail_texels[y * AIRLIGHT_TAIL_NX + x];
        const float* glow = table == TABLE_PHASE_GLOW_0   ? phase_glow_texels[0]
                            : table == TABLE_PHASE_GLOW_1 ? phase_glow_texels[1]
                                                          : surface_glow_texels;
        return glow[y * SURFACE_GLOW_NX + x];
    }
    vec4 table_texel4(int table, int x, int y) const {
        const float* texels = table == TABLE_PHASE_MOMENTS_0   ? phase_moment_texels[0]
                              : table == TABLE_PHASE_MOMENTS_1 ? phase_moment_texels[1]
                                                               : spot_moment_texels;
        const float* t = texels + (size_t(y) * AIRLIGHT_TAIL_NX + size_t(x)) * 4;
        return vec4(t[0], t[1], t[2], t[3]);
    }
    int spot_light_count() const { return frame.light_counts.x; }
    SpotLightGpu spot_light(int i) const { return spot_lights[i]; }
    int point_light_count() const { return frame.film_counts.z; }
    PointLightGpu point_light(int i) const { return point_lights[i]; }
    int surface_count() const { return frame.film_counts.w; }
    SurfaceGpu surface(int i) const { return surfaces[i]; }
    BvhNodeGpu bvh_node(int i) const { return bvh_nodes[i]; }

#define HAS_MEDIUM (features.medium)
#define HAS_POINT_LIGHTS (features.point_lights)
#define HAS_SURFACES (features.surfaces)
#define HAS_AIRLIGHT (features.airlight)
#define AIRLIGHT_MARCH (features.airlight_march)
#define GREY_MEDIUM (features.grey_medium)
#define HAS_SPOT_LIGHTS (features.spot_lights)
#define HAS_SPOT_AIRLIGHT (features.spot_airlight)
#define HAS_PHASE (features.phase)
#define HAS_SKY (features.sky)
#define HAS_SUN (features.sun)
#define HAS_ATMOSPHERE (features.atmosphere)
#define SKY_MARCH (features.sky_march)
#define HAS_RAINBOW (features.rainbow)
// The same order as the GLSL source (gl_backend.cpp).
// clang-format off
#include "geometry.glsl"
#include "airlight.glsl"
#include "phase.glsl"
#include "spot.glsl"
#include "sky.glsl"
#include "shading.glsl"
// clang-format on
#undef HAS_MEDIUM
#undef HAS_POINT_LIGHTS
#undef HAS_SURFACES
#undef HAS_AIRLIGHT
#undef AIRLIGHT_MARCH
#undef GREY_MEDIUM
#undef HAS_SPOT_LIGHTS
#undef HAS_SPOT_AIRLIGHT
#undef HAS_PHASE
#undef HAS_SKY
#undef HAS_SUN
#undef HAS_ATMOSPHERE
#undef SKY_MARCH
#undef HAS_RAINBOW
};

}  // namespace shader

namespace {
const float* texels_of(const Table2D* table) { return table ? table->texels.data() : nullptr; }
}  // namespace

void CpuBackend::render(const FrameData& data, Image& out) {
    const int width = data.frame.film_counts.x;
    const int height = data.frame.film_counts.y;
    out.width = width;
    out.height = height;
    out.rgb.assign(size_t(width) * size_t(height) * 3, 0.0f);

    const shader::CpuShader program{data.frame,
                                    data.point_lights.data(),
                                    data.surfaces.data(),
                                    data.bvh_nodes.data(),
                                    texels_of(data.airlight_tail),
                                    texels_of(data.surface_glow),
                                    texels_of(data.spot_moments),
                                    data.spot_lights.data(),
                                    data.features,
                                    {texels_of(data.phase_moments[0]), texels_of(data.phase_moments[1])},
                                    {texels_of(data.phase_glow[0]), texels_of(data.phase_glow[1])},
                                    texels_of(data.sky_table),
                                    data.sky_table ? data.sky_table->width : 0,
                                    texels_of(data.rainbow_table)};
    std::atomic<int> next_row{0};
    auto worker = [&]() {
        shader::CpuShader local = program;
        for (int row = next_row++; row < height; row = next_row++) {
            float* dst = out.rgb.data() + size_t(row) * size_t(width) * 3;
            for (int x = 0; x < width; ++x) {
                const glm::vec3 radiance = local.render_pixel(x, row);
                dst[3 * x + 0] = radiance.r;
                dst[3 * x + 1] = radiance.g;
                dst[3 * x + 2] = radiance.b;
            }
        }
    };
    int n = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
    n = std::min(n, height);
    std::vector<std::thread> pool;
    for (int i = 1; i < n; ++i) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
}

}  // namespace airlight
