// GL backend: OpenGL 4.5 core through EGL without a display (surfaceless or
// device platform), one full-screen fragment shader pass into a float FBO,
// read back with glReadPixels. See shared HEADLESS-GL notes in docs/.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <pthread.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends.hpp"
#include "display_gl.hpp"
#include "gl_util.hpp"
#include "shader_sources.hpp"

namespace airlight {

using gl::kGlslPrelude;
using gl::link_program;
using gl::upload;

namespace {

bool has_extension(const char* list, const char* name) {
    if (list == nullptr) return false;
    const size_t len = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += len) {
        if ((p == list || p[-1] == ' ') && (p[len] == ' ' || p[len] == '\0')) return true;
    }
    return false;
}

// Candidate EGL displays, best first: GPU devices, then Mesa's surfaceless
// platform (llvmpipe on machines without a GPU).
std::vector<EGLDisplay> candidate_displays() {
    std::vector<EGLDisplay> displays;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) return displays;
    if (has_extension(client, "EGL_EXT_platform_device")) {
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (query_devices != nullptr && query_devices(16, devices, &count)) {
            for (EGLint i = 0; i < count; ++i) {
                EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                if (d != EGL_NO_DISPLAY) displays.push_back(d);
            }
        }
    }
    if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY) displays.push_back(d);
    }
    return displays;
}

struct EglContext {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
};

// ---- Fork safety. EGL and the GL driver keep per-process state (Mesa's
// llvmpipe: a pool of rasteriser threads) that a forked child inherits
// without the threads: any GL call there waits forever. So once this process
// has initialised EGL, a child forked from it refuses GL with this message
// (gl_backend_available is false there, Renderer("gl") and the parent's GL
// renderers throw) instead of hanging.
std::atomic<bool> forked_after_egl{false};

constexpr const char* kForkedReason =
    "this process was forked after its parent had initialised GL, whose driver state does not survive "
    "a fork; start worker processes with the 'spawn' or 'forkserver' method (multiprocessing), or "
    "use the GL backend only in the children";

void note_egl_initialised() {
    static std::once_flag once;
    std::call_once(once, [] { pthread_atfork(nullptr, nullptr, [] { forked_after_egl = true; }); });
}

// Tries each display until one gives a 4.5 core context; returns false with
// the reason otherwise.
bool create_context(EglContext& out, std::string& reason) {
    const char* disable = std::getenv("AIRLIGHT_DISABLE_GL");
    if (disable != nullptr && std::strcmp(disable, "") != 0 && std::strcmp(disable, "0") != 0) {
        reason = "disabled by AIRLIGHT_DISABLE_GL";
        return false;
    }
    if (forked_after_egl) {
        reason = kForkedReason;
        return false;
    }
    note_egl_initialised();
    std::vector<EGLDisplay> displays = candidate_displays();
    if (displays.empty()) {
        reason = "no EGL display (no device or surfaceless platform)";
        return false;
    }
    reason = "no EGL display offers an OpenGL 4.5 core context";
    for (EGLDisplay d : displays) {
        EGLint major = 0, minor = 0;
        if (!eglInitialize(d, &major, &minor)) continue;
        if (!eglBindAPI(EGL_OPENGL_API)) {
            eglTerminate(d);
            continue;
        }
        const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                         EGL_NONE};
        EGLConfig config;
        EGLint n_configs = 0;
        const bool have_config = eglChooseConfig(d, config_attribs, &config, 1, &n_configs) && n_configs > 0;
        const EGLint context_attribs[] = {
            EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        EGLContext ctx = eglCreateContext(d, have_config ? config : EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attribs);
        if (ctx == EGL_NO_CONTEXT) {
            eglTerminate(d);
            continue;
        }
        if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
            eglDestroyContext(d, ctx);
            eglTerminate(d);
            continue;
        }
        out.display = d;
        out.context = ctx;
        return true;
    }
    return false;
}

void destroy_context(EglContext& c) {
    if (c.context != EGL_NO_CONTEXT) {
        eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c.display, c.context);
    }
    // eglTerminate is not called: displays are shared per process and other
    // renderers may still use this one.
    c = EglContext{};
}

constexpr int kTile = 512;  // largest tile drawn at once (GlBackend::render; a cancel is seen between tiles)

// Iterations of render.frag's last loop, which finishes only where the
// driver's loop limiter has not cut the pixel's loops.
constexpr int kLoopGuardIterations = 2;

}  // namespace

std::string fragment_shader_source(const shader::Features& features, int grid_pass_slot) {
    std::string source = kGlslPrelude;
    // The variant's switches (AIRLIGHT_FEATURES), the CPU shader's members of the same names.
#define AIRLIGHT_X(name, macro) \
    source += std::string("#define " #macro " ") + (features.name ? "true" : "false") + "\n";
    AIRLIGHT_FEATURES(AIRLIGHT_X)
#undef AIRLIGHT_X
    // The formulas, the GL resources, the shading pass's functions (registry order).
    std::vector<const char*> files = {AIRLIGHT_GLSL_MATH_FILES "resources.glsl", AIRLIGHT_GLSL_PIXEL_FILES};
    for (const char* name : files) {
        source += "// ---- " + std::string(name) + "\n";
        source += shader_source(name);
    }
    if (grid_pass_slot < 0) return source + "// ---- render.frag\n" + shader_source("render.frag");
    // A grid pass: one fragment per texel of its table.
    std::string entry;
#define AIRLIGHT_X(name, table) \
    if (grid_pass_slot == shader::table) entry = #name "_pass";
    AIRLIGHT_GRID_PASSES(AIRLIGHT_X)
#undef AIRLIGHT_X
    if (entry.empty())
        throw std::logic_error("airlight: no grid pass fills table slot " + std::to_string(grid_pass_slot));
    return source +
           "// ---- grid pass\n"
           "layout(location = 0) out vec4 out_texel;\n"
           "layout(location = 1) out float out_finished;  // 0 where the loop limiter cut the texel (render.frag)\n"
           "void main() {\n"
           "    ivec2 texel = ivec2(gl_FragCoord.xy);\n"
           "    out_texel = " +
           entry +
           "(texel.x, texel.y);\n"
           "    int guard = 0;\n"
           "    while (guard < frame.loop_guard_iterations) ++guard;\n"
           "    out_finished = guard == frame.loop_guard_iterations ? 1.0f : 0.0f;\n"
           "}\n";
}

struct GlBackend::State {
    EglContext egl;
    std::map<std::pair<unsigned long long, int>, GLuint> programs;  // by (Features::key(), grid pass slot or -1)
    GLuint vao = 0, fbo = 0, color = 0;
    GLuint frame_ubo = 0, light_ssbo = 0, surface_ssbo = 0, bvh_ssbo = 0, spot_ssbo = 0;
    size_t frame_capacity = 0, light_capacity = 0, surface_capacity = 0, bvh_capacity = 0, spot_capacity = 0;
    GLuint outputs_ssbo = 0;  // a tile's render outputs (RENDER_OUTPUTS), made on first use
    size_t outputs_capacity = 0;
    int fbo_width = 0, fbo_height = 0;
    std::map<const Table2D*, std::pair<long, GLuint>> table_textures;  // by address: (serial, texture)

    // The texture holding `table`, uploaded on first use (again when a cache
    // reused the address for another table: the serial differs).
    GLuint texture_for(const Table2D& table) {
        auto it = table_textures.find(&table);
        if (it != table_textures.end()) {
            if (it->second.first == table.serial) return it->second.second;
            glDeleteTextures(1, &it->second.second);
            table_textures.erase(it);
        }
        GLuint tex = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, table.channels == 4 ? GL_RGBA32F : GL_R32F, table.width, table.height);
        glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTextureSubImage2D(tex, 0, 0, 0, table.width, table.height, table.channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT,
                            table.texels.data());
        table_textures[&table] = {table.serial, tex};
        return tex;
    }

    // Deletes the textures of tables this frame does not use once more than
    // kMaxTableTextures are kept: a TableCache's evicted tables (an animated
    // phase g, a moving sun) would otherwise keep theirs for the renderer's life.
    static constexpr size_t kMaxTableTextures = 32;
    void prune_table_textures(const FrameData& data) {
        if (table_textures.size() <= kMaxTableTextures) return;
        for (auto it = table_textures.begin(); it != table_textures.end();) {
            if (std::find(data.tables.begin(), data.tables.end(), it->first) == data.tables.end()) {
                glDeleteTextures(1, &it->second.second);
                it = table_textures.erase(it);
            } else {
                ++it;
            }
        }
    }

    // ---- The display stage (effects/display/display_gl.cpp: GlBackend::display, glare_convolve).
    std::unique_ptr<GlDisplayPasses> display_passes;

    // One call at a time, from any thread: each call holds the lock and has
    // the context current on its thread for its duration only (Current).
    std::mutex mutex;

    class Current {
    public:
        explicit Current(State& s) : lock_(s.mutex), display_(s.egl.display) {
            if (forked_after_egl)
                throw BackendUnavailable(std::string("airlight: this GL renderer cannot be used here: ") +
                                         kForkedReason);
            if (!eglMakeCurrent(s.egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, s.egl.context))
                throw BackendUnavailable("airlight: eglMakeCurrent failed (EGL error " + std::to_string(eglGetError()) +
                                         ")");
        }
        ~Current() { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }
        Current(const Current&) = delete;
        Current& operator=(const Current&) = delete;

    private:
        std::lock_guard<std::mutex> lock_;
        EGLDisplay display_;
    };

    // The shading pass's program for `features` (grid_pass_slot -1), or that of
    // the grid pass filling that table slot.
    GLuint program_for(const shader::Features& features, int grid_pass_slot = -1) {
        const auto key = std::make_pair(features.key(), grid_pass_slot);
        auto it = programs.find(key);
        if (it != programs.end()) return it->second;
        std::string vertex = std::string(kGlslPrelude) + shader_source("fullscreen.vert");
        GLuint program = link_program(vertex, fragment_shader_source(features, grid_pass_slot));
        programs[key] = program;
        return program;
    }

    // The grid passes' textures and their framebuffer, kept between frames (by table slot).
    GLuint pass_fbo = 0;
    struct PassTexture {
        GLuint texture = 0;
        GLuint finished = 0;  // R8: 0 where the driver cut the texel's loops
        int width = 0, height = 0, channels = 0;
    };
    int grid_pass_cut_texels = 0;  // of the last frame's grid passes (GlBackend::grid_pass_cut_texels)
    std::array<PassTexture, shader::TABLE_COUNT> pass_textures{};

    // Uploads the frame's uniforms, lights, surfaces, BVH and tables, binds
    // them, then runs the grid passes in order, each into its slot (read by
    // the passes after it and the shading pass).
    void upload_frame(const FrameData& data, const shader::FrameUniforms& frame) {
        upload(frame_ubo, GL_UNIFORM_BUFFER, &frame, sizeof(frame), frame_capacity);
        upload(light_ssbo, GL_SHADER_STORAGE_BUFFER, data.point_lights.data(),
               data.point_lights.size() * sizeof(shader::PointLightGpu), light_capacity);
        upload(surface_ssbo, GL_SHADER_STORAGE_BUFFER, data.surfaces.data(),
               data.surfaces.size() * sizeof(shader::SurfaceGpu), surface_capacity);
        upload(bvh_ssbo, GL_SHADER_STORAGE_BUFFER, data.bvh_nodes.data(),
               data.bvh_nodes.size() * sizeof(shader::BvhNodeGpu), bvh_capacity);
        glBindBufferBase(GL_UNIFORM_BUFFER, shader::BINDING_FRAME, frame_ubo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shader::BINDING_POINT_LIGHTS, light_ssbo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shader::BINDING_SURFACES, surface_ssbo);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shader::BINDING_BVH_NODES, bvh_ssbo);
        upload(spot_ssbo, GL_SHADER_STORAGE_BUFFER, data.spot_lights.data(),
               data.spot_lights.size() * sizeof(shader::SpotLightGpu), spot_capacity);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shader::BINDING_SPOT_LIGHTS, spot_ssbo);
        // Table slot i on texture unit i (resources.glsl's table_samplers[i]).
        for (int slot = 0; slot < shader::TABLE_COUNT; ++slot) {
            const Table2D* table = data.tables[size_t(slot)];
            if (table != nullptr) glBindTextureUnit(GLuint(slot), texture_for(*table));
        }
        prune_table_textures(data);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        grid_pass_cut_texels = 0;
        for (const GridPassJob& job : data.grid_passes) grid_pass_cut_texels += run_grid_pass(data.features, job);
        // Where the driver cut a texel's loops (the GL loop limit), the grid
        // passes are computed again on the CPU (the later passes read the
        // earlier ones) and replace the textures.
        if (grid_pass_cut_texels == 0) return;
        CpuBackend cpu;
        const std::vector<Table2D> tables = cpu.grid_passes(data);
        for (size_t k = 0; k < data.grid_passes.size(); ++k) {
            const GridPassJob& job = data.grid_passes[k];
            glTextureSubImage2D(pass_textures[size_t(job.slot)].texture, 0, 0, 0, job.width, job.height,
                                job.channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT, tables[k].texels.data());
        }
    }

    // Runs `job` (FrameData::grid_passes) into its texture, bound to its table
    // slot's unit; returns the number of texels whose loops the driver cut.
    int run_grid_pass(const shader::Features& features, const GridPassJob& job) {
        PassTexture& t = pass_textures[size_t(job.slot)];
        if (t.texture == 0 || t.width != job.width || t.height != job.height || t.channels != job.channels) {
            if (t.texture != 0) glDeleteTextures(1, &t.texture);
            if (t.finished != 0) glDeleteTextures(1, &t.finished);
            glCreateTextures(GL_TEXTURE_2D, 1, &t.texture);
            glTextureStorage2D(t.texture, 1, job.channels == 4 ? GL_RGBA32F : GL_R32F, job.width, job.height);
            glTextureParameteri(t.texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(t.texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glCreateTextures(GL_TEXTURE_2D, 1, &t.finished);
            glTextureStorage2D(t.finished, 1, GL_R8, job.width, job.height);
            t = {t.texture, t.finished, job.width, job.height, job.channels};
        }
        if (pass_fbo == 0) glCreateFramebuffers(1, &pass_fbo);
        glNamedFramebufferTexture(pass_fbo, GL_COLOR_ATTACHMENT0, t.texture, 0);
        glNamedFramebufferTexture(pass_fbo, GL_COLOR_ATTACHMENT1, t.finished, 0);
        const GLenum attachments[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        glNamedFramebufferDrawBuffers(pass_fbo, 2, attachments);
        if (glCheckNamedFramebufferStatus(pass_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error("airlight: a grid pass's float framebuffer is not supported by this GL driver");
        glBindFramebuffer(GL_FRAMEBUFFER, pass_fbo);
        glViewport(0, 0, job.width, job.height);
        glUseProgram(program_for(features, job.slot));
        glBindVertexArray(vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindTextureUnit(GLuint(job.slot), t.texture);
        std::vector<std::uint8_t> finished(size_t(job.width) * size_t(job.height));
        glPixelStorei(GL_PACK_ALIGNMENT, 1);  // rows of bytes, unpadded
        glGetTextureImage(t.finished, 0, GL_RED, GL_UNSIGNED_BYTE, GLsizei(finished.size()), finished.data());
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        return int(std::count(finished.begin(), finished.end(), std::uint8_t(0)));
    }

    void ensure_target(int width, int height) {
        if (width == fbo_width && height == fbo_height) return;
        if (color != 0) glDeleteTextures(1, &color);
        glCreateTextures(GL_TEXTURE_2D, 1, &color);
        glTextureStorage2D(color, 1, GL_RGBA32F, width, height);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
        if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            throw std::runtime_error("airlight: float framebuffer of " + std::to_string(width) + "x" +
                                     std::to_string(height) + " is not supported by this GL driver");
        }
        fbo_width = width;
        fbo_height = height;
    }
};

bool gl_backend_available(std::string* reason, std::string* gl_renderer) {
    EglContext ctx;
    std::string why;
    const bool ok = create_context(ctx, why);
    if (ok && gl_renderer != nullptr) {
        const GLubyte* name = glGetString(GL_RENDERER);
        *gl_renderer = name != nullptr ? reinterpret_cast<const char*>(name) : "";
    }
    if (ok) destroy_context(ctx);
    if (!ok && reason != nullptr) *reason = why;
    return ok;
}

GlBackend::GlBackend() : state_(std::make_unique<State>()) {
    std::string reason;
    if (!create_context(state_->egl, reason)) throw BackendUnavailable("airlight: GL backend unavailable: " + reason);
    glCreateVertexArrays(1, &state_->vao);
    glCreateFramebuffers(1, &state_->fbo);
    glCreateBuffers(1, &state_->frame_ubo);
    glCreateBuffers(1, &state_->light_ssbo);
    glCreateBuffers(1, &state_->surface_ssbo);
    glCreateBuffers(1, &state_->bvh_ssbo);
    glCreateBuffers(1, &state_->spot_ssbo);
    state_->display_passes = std::make_unique<GlDisplayPasses>();
    // Released: the next call makes it current on its own thread (State::Current).
    eglMakeCurrent(state_->egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

GlBackend::~GlBackend() {
    // In a child forked after GL was initialised, the driver is unusable: its
    // objects are left to the process's end.
    if (state_->egl.context != EGL_NO_CONTEXT && !forked_after_egl) {
        State::Current current(*state_);
        for (auto& entry : state_->programs) glDeleteProgram(entry.second);
        for (auto& entry : state_->table_textures) glDeleteTextures(1, &entry.second.second);
        glDeleteTextures(1, &state_->color);
        state_->display_passes.reset();  // deletes the display stage's GL objects while the context is current
        glDeleteFramebuffers(1, &state_->fbo);
        if (state_->pass_fbo != 0) glDeleteFramebuffers(1, &state_->pass_fbo);
        for (auto& t : state_->pass_textures) {
            if (t.texture != 0) glDeleteTextures(1, &t.texture);
            if (t.finished != 0) glDeleteTextures(1, &t.finished);
        }
        glDeleteVertexArrays(1, &state_->vao);
        GLuint buffers[] = {state_->frame_ubo, state_->light_ssbo, state_->surface_ssbo, state_->bvh_ssbo,
                            state_->spot_ssbo};
        glDeleteBuffers(5, buffers);
        if (state_->outputs_ssbo != 0) glDeleteBuffers(1, &state_->outputs_ssbo);
    }
    if (!forked_after_egl) destroy_context(state_->egl);
}

void GlBackend::render(const FrameData& data, Image& out, std::vector<size_t>* cut_pixels,
                       const std::atomic<bool>* cancel) {
    State& s = *state_;
    State::Current current(s);
    const int width = data.frame.film_width;
    const int height = data.frame.film_height;
    // The film is drawn in tiles (at most kTile x kTile pixels each): any film
    // size fits the driver's texture limits, and no single draw runs long
    // enough to trip a GPU watchdog.
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    const int tile = std::min(kTile, int(max_size));
    const int tile_w = std::min(width, tile), tile_h = std::min(height, tile);
    s.ensure_target(tile_w, tile_h);
    const GLuint program = s.program_for(data.features);

    shader::FrameUniforms frame = data.frame;
    frame.loop_guard_iterations = kLoopGuardIterations;
    frame.tile_width = tile_w;  // row length of a tile's render outputs (render.frag)
    s.upload_frame(data, frame);

    glBindFramebuffer(GL_FRAMEBUFFER, s.fbo);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(program);
    glBindVertexArray(s.vao);

    out.width = width;
    out.height = height;
    out.rgb.resize(size_t(width) * size_t(height) * 3);
    if (cut_pixels != nullptr) cut_pixels->clear();
    // The render outputs (shaders/outputs_layout.glsl), when asked for: the
    // shading pass writes a tile's into a storage buffer, read back per tile.
    const bool outputs = data.features.outputs;
    const size_t floats = size_t(shader::OUTPUT_FLOATS);
    std::vector<float> tile_outputs;
    out.output_floats = outputs ? shader::OUTPUT_FLOATS : 0;
    out.outputs.assign(outputs ? size_t(width) * size_t(height) * floats : 0, 0.0f);
    if (outputs) {
        tile_outputs.resize(size_t(tile_w) * size_t(tile_h) * floats);
        if (s.outputs_ssbo == 0) glCreateBuffers(1, &s.outputs_ssbo);
        if (s.outputs_capacity < tile_outputs.size() * sizeof(float)) {
            s.outputs_capacity = tile_outputs.size() * sizeof(float);
            glNamedBufferData(s.outputs_ssbo, GLsizeiptr(s.outputs_capacity), nullptr, GL_DYNAMIC_READ);
        }
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, shader::BINDING_OUTPUTS, s.outputs_ssbo);
    }
    // Each tile is read back as RGBA: alpha 0 marks a pixel whose loops the driver cut (render.frag).
    std::vector<float> rgba(size_t(tile_w) * size_t(tile_h) * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    for (int y0 = 0; y0 < height; y0 += tile_h) {
        for (int x0 = 0; x0 < width; x0 += tile_w) {
            if (cancel != nullptr && cancel->load()) throw RenderCancelled();
            const int w = std::min(tile_w, width - x0), h = std::min(tile_h, height - y0);
            if (x0 > 0 || y0 > 0 || frame.tile_width != w) {
                frame.tile_origin_x = x0;  // pixel offset of this tile (render.frag)
                frame.tile_origin_y = y0;
                frame.tile_width = w;  // row length of its outputs
                glNamedBufferSubData(s.frame_ubo, 0, sizeof(frame), &frame);
            }
            glViewport(0, 0, w, h);
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, rgba.data());
            if (outputs) {
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glGetNamedBufferSubData(s.outputs_ssbo, 0, GLsizeiptr(size_t(w) * size_t(h) * floats * sizeof(float)),
                                        tile_outputs.data());
                for (int y = 0; y < h; ++y) {
                    const float* src = tile_outputs.data() + size_t(y) * size_t(w) * floats;
                    std::copy(src, src + size_t(w) * floats,
                              out.outputs.data() + (size_t(y0 + y) * size_t(width) + size_t(x0)) * floats);
                }
            }
            for (int y = 0; y < h; ++y) {
                for (int x = 0; x < w; ++x) {
                    const float* src = rgba.data() + (size_t(y) * size_t(w) + size_t(x)) * 4;
                    const size_t pixel = size_t(y0 + y) * size_t(width) + size_t(x0 + x);
                    std::copy(src, src + 3, out.rgb.data() + pixel * 3);
                    if (src[3] < 0.5f && cut_pixels != nullptr) cut_pixels->push_back(pixel);
                }
            }
        }
    }
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) throw std::runtime_error("airlight: GL error " + std::to_string(err) + " while rendering");
}

std::vector<Table2D> GlBackend::grid_passes(const FrameData& data) {
    State& s = *state_;
    State::Current current(s);
    shader::FrameUniforms frame = data.frame;
    frame.loop_guard_iterations = kLoopGuardIterations;
    s.upload_frame(data, frame);
    std::vector<Table2D> tables;
    for (const GridPassJob& job : data.grid_passes) {
        Table2D t;
        t.width = job.width;
        t.height = job.height;
        t.channels = job.channels;
        t.texels.resize(size_t(job.width) * size_t(job.height) * size_t(job.channels));
        glGetTextureImage(s.pass_textures[size_t(job.slot)].texture, 0, job.channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT,
                          GLsizei(t.texels.size() * sizeof(float)), t.texels.data());
        tables.push_back(std::move(t));
    }
    return tables;
}

int GlBackend::grid_pass_cut_texels() const { return state_->grid_pass_cut_texels; }

int GlBackend::max_texture_size() {
    State::Current current(*state_);
    GLint size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &size);
    return int(size);
}

// The display stage: effects/display/display_gl.cpp (GlDisplayPasses), with the context current.
void GlBackend::display(const GlDisplayJob& job, GlDisplayOutput& out) {
    check_display_image(job.linear);
    State::Current current(*state_);
    state_->display_passes->display(job, out);
}

void GlBackend::glare_convolve(const Image& in, const GlareKernel& kernel, Image& out, bool double_precision) {
    check_display_image(&in);
    State::Current current(*state_);
    state_->display_passes->glare_convolve(in, kernel, out, double_precision);
}

}  // namespace airlight
