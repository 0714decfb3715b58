// CPU backend: the shared GLSL per-pixel code compiled as C++ (shader_cpp.hpp),
// run over the image rows by a pool of threads.
#include <algorithm>
#include <stdexcept>

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
    // The tables the code reads (the frame's, and the outputs of its grid
    // passes): texels and row length per slot, read directly in the hot loops.
    std::array<const float*, TABLE_COUNT> table_texels{};
    std::array<size_t, TABLE_COUNT> table_widths{};

    void set_table(int slot, const Table2D* t) {
        table_texels[size_t(slot)] = t ? t->texels.data() : nullptr;
        table_widths[size_t(slot)] = t ? size_t(t->width) : 0;
    }

#define AIRLIGHT_X(name, macro) bool macro;
    AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X

    explicit CpuShader(const FrameData& d)
        : data(d),
          frame(d.frame)
#define AIRLIGHT_X(name, macro) , macro(d.features.name)
              AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X
    {
        for (int slot = 0; slot < TABLE_COUNT; ++slot) set_table(slot, d.tables[size_t(slot)]);
    }

    // Texel (x, y) of table slot `table`: a single-channel table's (table_texel)
    // or an RGBA one's (table_texel4), as GL's texelFetch reads them.
    float table_texel(int table, int x, int y) const {
        return table_texels[size_t(table)][size_t(y) * table_widths[size_t(table)] + size_t(x)];
    }
    vec4 table_texel4(int table, int x, int y) const {
        const float* t = table_texels[size_t(table)] + (size_t(y) * table_widths[size_t(table)] + size_t(x)) * 4;
        return vec4(t[0], t[1], t[2], t[3]);
    }
    // The storage buffers' arrays (pointers kept: the accessors sit in the innermost loops).
    const PointLightGpu* point_lights = data.point_lights.data();
    const SurfaceGpu* surfaces = data.surfaces.data();
    const BvhNodeGpu* bvh_nodes = data.bvh_nodes.data();
    const SpotLightGpu* spot_lights = data.spot_lights.data();
    int spot_light_count() const { return frame.spot_light_count; }
    SpotLightGpu spot_light(int i) const { return spot_lights[i]; }
    int point_light_count() const { return frame.point_light_count; }
    PointLightGpu point_light(int i) const { return point_lights[i]; }
    int surface_count() const { return frame.surface_count; }
    SurfaceGpu surface(int i) const { return surfaces[i]; }
    BvhNodeGpu bvh_node(int i) const { return bvh_nodes[i]; }

// The shading pass's functions: the core's and every effect's, in registry order.
// A hook has its kind's signature (cmake/effects.cmake), whose arguments not
// every effect needs.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "airlight_glsl_pixel.inc"
#pragma GCC diagnostic pop

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
        program.set_table(job.slot, &t);
    }
}

}  // namespace

std::vector<Table2D> CpuBackend::grid_passes(const FrameData& data) {
    shader::CpuShader program(data);
    std::vector<Table2D> tables;
    run_grid_passes(data, program, tables, threads);
    return tables;
}

namespace {

bool cancelled(const std::atomic<bool>* cancel) { return cancel != nullptr && cancel->load(std::memory_order_relaxed); }

// Shades pixel (x, row) into out (index row * width + x): its radiance, and
// its render outputs when the frame asks for them (out.outputs sized for them).
void shade_pixel(shader::CpuShader& shader, int x, int row, Image& out) {
    const size_t pixel = size_t(row) * size_t(out.width) + size_t(x);
    const glm::vec3 radiance = shader.render_pixel(x, row);
    out.rgb[3 * pixel + 0] = radiance.r;
    out.rgb[3 * pixel + 1] = radiance.g;
    out.rgb[3 * pixel + 2] = radiance.b;
    if (!shader.RENDER_OUTPUTS) return;
    float* dst = out.outputs.data() + pixel * size_t(shader::OUTPUT_FLOATS);
    for (int k = 0; k < shader::OUTPUT_FLOATS; ++k) dst[k] = shader.pixel_output_value(k);
}

// Sizes out.outputs for the frame's render outputs (none when not asked for).
void prepare_outputs(const FrameData& data, Image& out) {
    if (!data.features.outputs) {
        out.output_floats = 0;
        out.outputs.clear();
        return;
    }
    const size_t size = size_t(out.width) * size_t(out.height) * size_t(shader::OUTPUT_FLOATS);
    if (out.output_floats != shader::OUTPUT_FLOATS || out.outputs.size() != size) out.outputs.assign(size, 0.0f);
    out.output_floats = shader::OUTPUT_FLOATS;
}

}  // namespace

void CpuBackend::render_pixels(const FrameData& data, const std::vector<size_t>& pixels, Image& out,
                               const std::atomic<bool>* cancel) {
    const size_t width = size_t(data.frame.film_width);
    if (out.width != data.frame.film_width || out.height != data.frame.film_height)
        throw std::logic_error("airlight: render_pixels needs a frame of the film's size");
    prepare_outputs(data, out);
    shader::CpuShader program(data);
    std::vector<Table2D> pass_tables;
    run_grid_passes(data, program, pass_tables, threads);
    constexpr int kBatch = 256;  // pixels per task
    const int batches = int((pixels.size() + kBatch - 1) / kBatch);
    numerics::parallel_for(
        batches,
        [&](int b) {
            if (cancelled(cancel)) return;
            shader::CpuShader local = program;
            const size_t end = std::min(pixels.size(), size_t(b + 1) * kBatch);
            for (size_t k = size_t(b) * kBatch; k < end; ++k) {
                shade_pixel(local, int(pixels[k] % width), int(pixels[k] / width), out);
            }
        },
        threads);
    if (cancelled(cancel)) throw RenderCancelled();
}

void CpuBackend::render(const FrameData& data, Image& out, const std::atomic<bool>* cancel) {
    const int width = data.frame.film_width;
    const int height = data.frame.film_height;
    out.width = width;
    out.height = height;
    out.rgb.assign(size_t(width) * size_t(height) * 3, 0.0f);
    prepare_outputs(data, out);

    shader::CpuShader program(data);
    // The grid passes first (FrameData::grid_passes), each into a table the
    // passes after it and the shading pass read.
    std::vector<Table2D> pass_tables;
    run_grid_passes(data, program, pass_tables, threads);
    numerics::parallel_for(
        height,
        [&](int row) {
            if (cancelled(cancel)) return;
            // A copy per task: the shared code's functions are non-const
            // members, and the pixel's outputs (pixel_outputs) are a member.
            shader::CpuShader local = program;
            for (int x = 0; x < width; ++x) shade_pixel(local, x, row, out);
        },
        threads);
    if (cancelled(cancel)) throw RenderCancelled();
}

}  // namespace airlight
