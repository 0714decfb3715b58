// Scene -> the flat arrays both backends consume (shaders/layout.glsl).
#pragma once

#include <array>
#include <vector>

#include "airlight/scene.hpp"
#include "shader_cpp.hpp"
#include "tables.hpp"

namespace airlight {

// A grid pass to run before the shading pass (an effect's EFFECT_PASSES): it
// fills table slot `slot` (shader::TABLE_*) with width x height texels of
// `channels` (1 or 4) floats from the GLSL function <name>_pass(x, y); the
// backend owns the result for the frame.
struct GridPassJob {
    int slot = 0;
    int width = 0;
    int height = 0;
    int channels = 1;
};

struct FrameData {
    shader::FrameUniforms frame{};
    std::vector<shader::PointLightGpu> point_lights;
    std::vector<shader::SurfaceGpu> surfaces;   // planes first, then the rest in BVH leaf order
    std::vector<shader::BvhNodeGpu> bvh_nodes;  // over the bounded surfaces (boxes, spheres)
    std::vector<shader::SpotLightGpu> spot_lights;
    shader::Features features;
    bool scattering = false;  // the homogeneous medium scatters light (some sigma_s > 0)
    // The tables the shader variant reads, by slot (shader::TABLE_*, the
    // effects' EFFECT_TABLES); null where the scene does not need one: it is
    // then never built.
    std::array<const Table2D*, shader::TABLE_COUNT> tables{};
    // The tables of `tables` that a TableCache holds, kept alive for the frame
    // (the cache may evict them meanwhile); use_table sets both.
    std::vector<std::shared_ptr<const Table2D>> table_owners;
    // Puts a cached table in slot `slot` (shader::TABLE_*) for this frame.
    void use_table(int slot, std::shared_ptr<const Table2D> table) {
        tables[size_t(slot)] = table.get();
        table_owners.push_back(std::move(table));
    }
    // Grid passes to run first, in order (a pass may read the tables of those before it).
    std::vector<GridPassJob> grid_passes;
};

// Each effect's part of the frame (registry: EFFECT_FRAME, EFFECT_FRAME_TABLES):
// pack_<name>_frame fills its data and features after the core's part, in
// registry order; pick_<name>_tables then chooses its tables, once every
// effect's features are known.
#define AIRLIGHT_X(effect) void pack_##effect##_frame(const Scene& scene, FrameData& data);
AIRLIGHT_FRAME_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X
#define AIRLIGHT_X(effect) void pick_##effect##_tables(const Scene& scene, FrameData& data);
AIRLIGHT_FRAME_TABLE_EFFECTS(AIRLIGHT_X)
#undef AIRLIGHT_X

// Builds the per-frame data: camera basis, medium coefficients, lights and
// surfaces, the feature set that selects the shader variant, and the tables
// that variant needs. Lights are sorted brightest first for the culling.
FrameData make_frame_data(const Scene& scene);

}  // namespace airlight
