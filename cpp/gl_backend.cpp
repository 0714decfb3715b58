// GL backend: OpenGL 4.5 core through EGL without a display (surfaceless or
// device platform), one full-screen fragment shader pass into a float FBO,
// read back with glReadPixels. See shared HEADLESS-GL notes in docs/.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "backends.hpp"
#include "shader_sources.hpp"
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace airlight {
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

// Tries each display until one gives a 4.5 core context; returns false with
// the reason otherwise.
bool create_context(EglContext& out, std::string& reason) {
    const char* disable = std::getenv("AIRLIGHT_DISABLE_GL");
    if (disable != nullptr && std::strcmp(disable, "") != 0 && std::strcmp(disable, "0") != 0) {
        reason = "disabled by AIRLIGHT_DISABLE_GL";
        return false;
    }
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

GLuint compile_shader(GLenum stage, const std::string& source) {
    GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetShaderInfoLog(shader, len, nullptr, log.data());
        glDeleteShader(shader);
        throw std::runtime_error("airlight: GLSL compilation failed (a bug in airlight): " + log);
    }
    return shader;
}

GLuint link_program(const std::string& vertex, const std::string& fragment) {
    GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex);
    GLuint fs = compile_shader(GL_FRAGMENT_SHADER, fragment);
    GLuint program = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetProgramInfoLog(program, len, nullptr, log.data());
        glDeleteProgram(program);
        throw std::runtime_error("airlight: GLSL link failed (a bug in airlight): " + log);
    }
    return program;
}

// Uploads `bytes` into a buffer object, growing it when needed. Storage
// buffers are never empty (GL forbids binding a zero-sized range).
void upload(GLuint buffer, GLenum target, const void* bytes, size_t size, size_t& capacity) {
    const size_t needed = std::max<size_t>(size, 64);
    glBindBuffer(target, buffer);
    if (needed > capacity) {
        glBufferData(target, GLsizeiptr(needed), nullptr, GL_DYNAMIC_DRAW);
        capacity = needed;
    }
    if (size > 0) glBufferSubData(target, 0, GLsizeiptr(size), bytes);
}

constexpr int kTile = 2048;  // largest tile drawn at once (GlBackend::render)

const char* kGlslPrelude =
    "#version 450 core\n"
    "#define CONST const\n"
    "#define OUT(T) out T\n"
    "#define INOUT(T) inout T\n"
    "#define INLINE\n";

}  // namespace

std::string fragment_shader_source(const shader::Features& features) {
    std::string source = kGlslPrelude;
    source += std::string("#define HAS_MEDIUM ") + (features.medium ? "true" : "false") + "\n";
    source += std::string("#define HAS_POINT_LIGHTS ") + (features.point_lights ? "true" : "false") + "\n";
    source += std::string("#define HAS_SURFACES ") + (features.surfaces ? "true" : "false") + "\n";
    source += std::string("#define HAS_AIRLIGHT ") + (features.airlight ? "true" : "false") + "\n";
    source += std::string("#define AIRLIGHT_MARCH ") + (features.airlight_march ? "true" : "false") + "\n";
    source += std::string("#define GREY_MEDIUM ") + (features.grey_medium ? "true" : "false") + "\n";
    source += std::string("#define HAS_SPOT_LIGHTS ") + (features.spot_lights ? "true" : "false") + "\n";
    source += std::string("#define HAS_SPOT_AIRLIGHT ") + (features.spot_airlight ? "true" : "false") + "\n";
    source += std::string("#define HAS_PHASE ") + (features.phase ? "true" : "false") + "\n";
    for (const char* name : {"constants.glsl", "layout.glsl", "phase_math.glsl", "resources.glsl", "geometry.glsl",
                             "airlight.glsl", "phase.glsl", "spot.glsl", "shading.glsl", "render.frag"}) {
        source += "// ---- " + std::string(name) + "\n";
        source += shader_source(name);
    }
    return source;
}

struct GlBackend::State {
    EglContext egl;
    std::map<int, GLuint> programs;  // by Features::key()
    GLuint vao = 0, fbo = 0, color = 0;
    GLuint frame_ubo = 0, light_ssbo = 0, surface_ssbo = 0, bvh_ssbo = 0, spot_ssbo = 0;
    size_t frame_capacity = 0, light_capacity = 0, surface_capacity = 0, bvh_capacity = 0, spot_capacity = 0;
    int fbo_width = 0, fbo_height = 0;
    std::map<const Table2D*, GLuint> table_textures;  // uploaded once per context

    // The texture holding `table`, uploaded on first use.
    GLuint texture_for(const Table2D& table) {
        auto it = table_textures.find(&table);
        if (it != table_textures.end()) return it->second;
        GLuint tex = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, table.channels == 4 ? GL_RGBA32F : GL_R32F, table.width, table.height);
        glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTextureSubImage2D(tex, 0, 0, 0, table.width, table.height, table.channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT,
                            table.texels.data());
        table_textures[&table] = tex;
        return tex;
    }

    void make_current() {
        if (!eglMakeCurrent(egl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl.context)) {
            throw BackendUnavailable("airlight: eglMakeCurrent failed");
        }
    }

    GLuint program_for(const shader::Features& features) {
        auto it = programs.find(features.key());
        if (it != programs.end()) return it->second;
        std::string vertex = std::string(kGlslPrelude) + shader_source("fullscreen.vert");
        GLuint program = link_program(vertex, fragment_shader_source(features));
        programs[features.key()] = program;
        return program;
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

bool gl_backend_available(std::string* reason) {
    EglContext ctx;
    std::string why;
    const bool ok = create_context(ctx, why);
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
}

GlBackend::~GlBackend() {
    if (state_->egl.context != EGL_NO_CONTEXT) {
        state_->make_current();
        for (auto& entry : state_->programs) glDeleteProgram(entry.second);
        for (auto& entry : state_->table_textures) glDeleteTextures(1, &entry.second);
        glDeleteTextures(1, &state_->color);
        glDeleteFramebuffers(1, &state_->fbo);
        glDeleteVertexArrays(1, &state_->vao);
        GLuint buffers[] = {state_->frame_ubo, state_->light_ssbo, state_->surface_ssbo, state_->bvh_ssbo,
                            state_->spot_ssbo};
        glDeleteBuffers(5, buffers);
        destroy_context(state_->egl);
    }
}

void GlBackend::render(const FrameData& data, Image& out) {
    State& s = *state_;
    s.make_current();
    const int width = data.frame.film_counts.x;
    const int height = data.frame.film_counts.y;
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
    upload(s.frame_ubo, GL_UNIFORM_BUFFER, &frame, sizeof(frame), s.frame_capacity);
    upload(s.light_ssbo, GL_SHADER_STORAGE_BUFFER, data.point_lights.data(),
           data.point_lights.size() * sizeof(shader::PointLightGpu), s.light_capacity);
    upload(s.surface_ssbo, GL_SHADER_STORAGE_BUFFER, data.surfaces.data(),
           data.surfaces.size() * sizeof(shader::SurfaceGpu), s.surface_capacity);
    upload(s.bvh_ssbo, GL_SHADER_STORAGE_BUFFER, data.bvh_nodes.data(),
           data.bvh_nodes.size() * sizeof(shader::BvhNodeGpu), s.bvh_capacity);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, s.frame_ubo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s.light_ssbo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s.surface_ssbo);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s.bvh_ssbo);
    upload(s.spot_ssbo, GL_SHADER_STORAGE_BUFFER, data.spot_lights.data(),
           data.spot_lights.size() * sizeof(shader::SpotLightGpu), s.spot_capacity);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, s.spot_ssbo);
    if (data.airlight_tail) glBindTextureUnit(0, s.texture_for(*data.airlight_tail));
    if (data.surface_glow) glBindTextureUnit(1, s.texture_for(*data.surface_glow));
    if (data.spot_moments) glBindTextureUnit(2, s.texture_for(*data.spot_moments));
    for (int lobe = 0; lobe < 2; ++lobe) {
        if (data.phase_moments[lobe]) glBindTextureUnit(3 + lobe, s.texture_for(*data.phase_moments[lobe]));
        if (data.phase_glow[lobe]) glBindTextureUnit(5 + lobe, s.texture_for(*data.phase_glow[lobe]));
    }

    glBindFramebuffer(GL_FRAMEBUFFER, s.fbo);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(program);
    glBindVertexArray(s.vao);

    out.width = width;
    out.height = height;
    out.rgb.resize(size_t(width) * size_t(height) * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, width);
    for (int y0 = 0; y0 < height; y0 += tile_h) {
        for (int x0 = 0; x0 < width; x0 += tile_w) {
            const int w = std::min(tile_w, width - x0), h = std::min(tile_h, height - y0);
            if (x0 > 0 || y0 > 0) {
                frame.geometry_counts.z = x0;  // pixel offset of this tile (render.frag)
                frame.geometry_counts.w = y0;
                glNamedBufferSubData(s.frame_ubo, 0, sizeof(frame), &frame);
            }
            glViewport(0, 0, w, h);
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glReadPixels(0, 0, w, h, GL_RGB, GL_FLOAT, out.rgb.data() + (size_t(y0) * width + x0) * 3);
        }
    }
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) throw std::runtime_error("airlight: GL error " + std::to_string(err) + " while rendering");
}

}  // namespace airlight
