// CPU backend: the shared GLSL per-pixel code compiled as C++ (shader_cpp.hpp),
// run over the image rows by a pool of threads.
#include "backends.hpp"
#include "numerics.hpp"

namespace airlight {
namespace shader {

// The shared shader code becomes the member functions of this struct; its
// members play the part of the GL uniforms, storage buffers and samplers, and
// the features' switches (AIRLIGHT_FEATURES) are members named as the GL
// variant's macros.
struct CpuShader {
    const FrameData& data;
    const FrameUniforms& frame;
    // The tables the code reads: the frame's, and the outputs of its grid passes.
    std::array<const Table2D*, TABLE_COUNT> tables;

#define AIRLIGHT_X(name, macro) bool macro;
    AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X

    explicit CpuShader(const FrameData& d)
        : data(d),
          frame(d.frame),
          tables(d.tables)
#define AIRLIGHT_X(name, macro) , macro(d.features.name)
              AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X
    {
    }

    // Texel (x, y) of table slot `table` (a single-channel texel as (r, 0, 0, 1), as GL's texelFetch).
    vec4 table_texel4(int table, int x, int y) const {
        const Table2D& t = *tables[size_t(table)];
        const float* p = t.texels.data() + (size_t(y) * size_t(t.width) + size_t(x)) * size_t(t.channels);
        return t.channels == 4 ? vec4(p[0], p[1], p[2], p[3]) : vec4(p[0], 0.0f, 0.0f, 1.0f);
    }
    int spot_light_count() const { return frame.spot_light_count; }
    SpotLightGpu spot_light(int i) const { return data.spot_lights[size_t(i)]; }
    int point_light_count() const { return frame.point_light_count; }
    PointLightGpu point_light(int i) const { return data.point_lights[size_t(i)]; }
    int surface_count() const { return frame.surface_count; }
    SurfaceGpu surface(int i) const { return data.surfaces[size_t(i)]; }
    BvhNodeGpu bvh_node(int i) const { return data.bvh_nodes[size_t(i)]; }

// The shading pass's functions: the core's and every effect's, in registry order.
#include "airlight_glsl_pixel.inc"

    // Texel (x, y) of the grid pass that fills table slot `slot` (AIRLIGHT_GRID_PASSES).
    vec4 run_grid_pass(int slot, int x, int y) {
#define AIRLIGHT_X(name, table) \
    if (slot == table) return name##_pass(x, y);
        AIRLIGHT_GRID_PASSES(AIRLIGHT_X)
#undef AIRLIGHT_X
        (void)slot, (void)x, (void)y;
        return vec4(0.0f);
    }
};

}  // namespace shader

namespace {

// Runs data.grid_passes in order into `tables` (one per pass), pointing
// program's table slots at them as they are filled.
void run_grid_passes(const FrameData& data, shader::CpuShader& program, std::vector<Table2D>& tables, int threads) {
    tables.assign(data.grid_passes.size(), Table2D{});
    for (size_t k = 0; k < data.grid_passes.size(); ++k) {
        const GridPassJob& job = data.grid_passes[k];
        Table2D& t = tables[k];
        t.name = "grid pass";
        t.width = job.width;
        t.height = job.height;
        t.channels = job.channels;
        t.texels.assign(size_t(job.width) * size_t(job.height) * size_t(job.channels), 0.0f);
        numerics::parallel_for(
            job.height,
            [&](int y) {
                shader::CpuShader local = program;
                for (int x = 0; x < job.width; ++x) {
                    const glm::vec4 v = local.run_grid_pass(job.slot, x, y);
                    float* dst = t.texels.data() + (size_t(y) * size_t(job.width) + size_t(x)) * size_t(job.channels);
                    for (int c = 0; c < job.channels; ++c) dst[c] = v[c];
                }
            },
            threads);
        program.tables[size_t(job.slot)] = &t;
    }
}

}  // namespace

std::vector<Table2D> CpuBackend::grid_passes(const FrameData& data) {
    shader::CpuShader program(data);
    std::vector<Table2D> tables;
    run_grid_passes(data, program, tables, threads);
    return tables;
}

void CpuBackend::render(const FrameData& data, Image& out) {
    const int width = data.frame.film_width;
    const int height = data.frame.film_height;
    out.width = width;
    out.height = height;
    out.rgb.assign(size_t(width) * size_t(height) * 3, 0.0f);

    shader::CpuShader program(data);
    // The grid passes first (FrameData::grid_passes), each into a table the
    // passes after it and the shading pass read.
    std::vector<Table2D> pass_tables;
    run_grid_passes(data, program, pass_tables, threads);
    numerics::parallel_for(
        height,
        [&](int row) {
            shader::CpuShader local = program;  // the shared code's functions are non-const members
            float* dst = out.rgb.data() + size_t(row) * size_t(width) * 3;
            for (int x = 0; x < width; ++x) {
                const glm::vec3 radiance = local.render_pixel(x, row);
                dst[3 * x + 0] = radiance.r;
                dst[3 * x + 1] = radiance.g;
                dst[3 * x + 2] = radiance.b;
            }
        },
        threads);
}

}  // namespace airlight
