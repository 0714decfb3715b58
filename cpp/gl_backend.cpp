// GL backend: OpenGL 4.5 core through EGL without a display (surfaceless or
// device platform), one full-screen fragment shader pass into a float FBO,
// read back with glReadPixels. See shared HEADLESS-GL notes in docs/.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include "airlight/display.hpp"
#include "airlight/glare.hpp"
#include "backends.hpp"
#include "shader_sources.hpp"
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
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

// A compute program from one source (display and glare passes).
GLuint link_compute_program(const std::string& source) {
    GLuint cs = compile_shader(GL_COMPUTE_SHADER, source);
    GLuint program = glCreateProgram();
    glAttachShader(program, cs);
    glLinkProgram(program);
    glDeleteShader(cs);
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

// Display stage (issue 8): work-group size of the FFT line passes
// (shaders/glare_fft.comp) and the smallest padded FFT length per axis.
constexpr int kFftLocalSize = 128;
constexpr int kMinFftSize = 16;

int log2_of_pow2(int p) {
    int l = 0;
    while ((1 << l) < p) ++l;
    return l;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Sets a uniform of `program` by name (optimised-out uniforms are ignored).
void set_uniform(GLuint program, const char* name, int v) {
    glProgramUniform1i(program, glGetUniformLocation(program, name), v);
}
void set_uniform(GLuint program, const char* name, float v) {
    glProgramUniform1f(program, glGetUniformLocation(program, name), v);
}

// Grows a buffer object to at least `bytes` (contents are not kept).
void ensure_buffer(GLuint buffer, size_t bytes, size_t& capacity) {
    bytes = std::max<size_t>(bytes, 64);
    if (bytes <= capacity) return;
    glNamedBufferData(buffer, GLsizeiptr(bytes), nullptr, GL_DYNAMIC_COPY);
    capacity = bytes;
}

// A 2-D texture of `format`, re-created when the size changes.
void ensure_texture(GLuint& tex, int& tex_w, int& tex_h, GLenum format, int w, int h) {
    if (tex != 0 && tex_w == w && tex_h == h) return;
    if (tex != 0) glDeleteTextures(1, &tex);
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, format, w, h);
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    tex_w = w;
    tex_h = h;
}

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
    source += std::string("#define HAS_SKY ") + (features.sky ? "true" : "false") + "\n";
    source += std::string("#define HAS_SUN ") + (features.sun ? "true" : "false") + "\n";
    source += std::string("#define HAS_ATMOSPHERE ") + (features.atmosphere ? "true" : "false") + "\n";
    source += std::string("#define SKY_MARCH ") + (features.sky_march ? "true" : "false") + "\n";
    source += std::string("#define HAS_RAINBOW ") + (features.rainbow ? "true" : "false") + "\n";
    for (const char* name :
         {"constants.glsl", "layout.glsl", "phase_math.glsl", "sky_math.glsl", "resources.glsl", "geometry.glsl",
          "airlight.glsl", "phase.glsl", "spot.glsl", "sky.glsl", "shading.glsl", "render.frag"}) {
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

    // ---- Display stage (GlBackend::display, glare_convolve).
    GLuint display_program = 0;
    std::map<int, GLuint> fft_programs;  // by pass * 4 + (shared memory line ? 2 : 0) + (double ? 1 : 0)
    GLuint radiance_tex = 0, glare_tex = 0, display_tex = 0, kernel_tex = 0, addend_tex = 0;
    int radiance_w = 0, radiance_h = 0, glare_w = 0, glare_h = 0, display_w = 0, display_h = 0, kernel_w = 0,
        kernel_h = 0, addend_w = 0, addend_h = 0;
    GLuint scratch_ssbo = 0;
    std::array<GLuint, 2> twiddle_ssbo{};  // [0] float, [1] double
    std::array<GLuint, 3> spectrum_ssbo{}, kernel_ssbo{};
    size_t scratch_capacity = 0;
    std::array<size_t, 2> twiddle_capacity{};
    std::array<size_t, 3> spectrum_capacity{}, kernel_capacity{};
    std::array<int, 2> twiddle_log2{-1, -1};  // the tables hold exp(-2 pi i m / 2^twiddle_log2)
    // The kernel spectrum held in kernel_ssbo: for this padded size, precision and these weights (compared in full).
    bool kernel_valid = false, kernel_double = false;
    int kernel_px = 0, kernel_py = 0, kernel_radius = -1;
    std::array<std::vector<double>, 3> kernel_weights;
    // Driver limits, read on first use.
    GLint max_texture_size = 0, max_shared_bytes = 0, max_groups_x = 0, ssbo_alignment = 0;
    GLint64 max_block_bytes = 0;

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

    void read_limits() {
        if (max_texture_size > 0) return;
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
        glGetIntegerv(GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, &max_shared_bytes);
        glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &max_groups_x);
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &ssbo_alignment);
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block_bytes);
    }

    // Longest FFT line (a power of two) that fits in shared memory with
    // elements of `element_bytes`.
    int shared_line_capacity(int element_bytes) const {
        int n = 1;
        while (2 * n * element_bytes <= max_shared_bytes) n *= 2;
        return n;
    }

    // One pass of shaders/glare_fft.comp (1 rows forward, 2 columns, 3 rows
    // inverse) with its lines in shared memory or in the scratch buffer.
    GLuint fft_program(int pass, bool shared, bool dbl) {
        const int key = pass * 4 + (shared ? 2 : 0) + (dbl ? 1 : 0);
        auto it = fft_programs.find(key);
        if (it != fft_programs.end()) return it->second;
        std::string source = kGlslPrelude;
        source += "#define PASS " + std::to_string(pass) + "\n";
        source += "#define LOCAL_SIZE " + std::to_string(kFftLocalSize) + "\n";
        source += std::string("#define SHARED_LINE ") + (shared ? "1" : "0") + "\n";
        source += std::string("#define FFT_DOUBLE ") + (dbl ? "1" : "0") + "\n";
        source += "#define LINE_CAPACITY " +
                  std::to_string(shared_line_capacity((pass == 2 ? 8 : 16) * (dbl ? 2 : 1))) + "\n";
        source += shader_source("glare_fft.comp");
        GLuint program = link_compute_program(source);
        fft_programs[key] = program;
        return program;
    }

    void check_texture_size(int w, int h) {
        read_limits();
        if (w > max_texture_size || h > max_texture_size) {
            throw std::runtime_error("airlight: display: image of " + std::to_string(w) + "x" + std::to_string(h) +
                                     " exceeds this GL driver's maximum texture size of " +
                                     std::to_string(max_texture_size));
        }
    }

    // The image into radiance_tex (RGBA32F): image row y is texel row y, so
    // every later pass and the read-back keep row 0 on top.
    void upload_radiance(const Image& image) {
        check_texture_size(image.width, image.height);
        ensure_texture(radiance_tex, radiance_w, radiance_h, GL_RGBA32F, image.width, image.height);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glTextureSubImage2D(radiance_tex, 0, 0, 0, image.width, image.height, GL_RGB, GL_FLOAT, image.rgb.data());
    }

    // GlDisplayJob::addend into addend_tex (RGBA32F), like upload_radiance.
    void upload_addend(const Image& image) {
        ensure_texture(addend_tex, addend_w, addend_h, GL_RGBA32F, image.width, image.height);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glTextureSubImage2D(addend_tex, 0, 0, 0, image.width, image.height, GL_RGB, GL_FLOAT, image.rgb.data());
    }

    // Runs `lines` work groups of `program` from line 0 in chunks of at most
    // `chunk` (and the driver's dispatch limit): u_first is set per chunk and
    // bind(first, count) binds what the chunk needs.
    template <class Bind>
    void dispatch_lines(GLuint program, int lines, int chunk, const Bind& bind) {
        chunk = std::max(1, std::min({chunk, lines, int(max_groups_x)}));
        glUseProgram(program);
        for (int first = 0; first < lines; first += chunk) {
            const int count = std::min(chunk, lines - first);
            set_uniform(program, "u_first", first);
            bind(first, count);
            glDispatchCompute(GLuint(count), 1, 1);
            glMemoryBarrier(GL_ALL_BARRIER_BITS);
        }
    }

    // Lines of n elements of element_bytes per dispatch chunk: all of them
    // when the line is in shared memory, else as many as the scratch buffer
    // holds within the storage block limit (the scratch is bound whole).
    int line_chunk(int n, int element_bytes, bool shared) {
        if (shared) return 1 << 30;
        const long long per_line = (long long)n * element_bytes;
        if (per_line > max_block_bytes)
            throw std::runtime_error("airlight: glare: FFT line too long for this GL driver");
        const int chunk = int(std::min<long long>(max_block_bytes / per_line, 1 << 30));
        return chunk;
    }

    void bind_scratch(int count, int n, int element_bytes) {
        const size_t bytes = size_t(count) * size_t(n) * size_t(element_bytes);
        ensure_buffer(scratch_ssbo, bytes, scratch_capacity);
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 7, scratch_ssbo, 0, GLsizeiptr(std::max<size_t>(bytes, 64)));
    }

    // The twiddle table exp(-2 pi i m / 2^l), m < 2^(l-1), computed in double
    // (rounded to float for the fp32 passes), for transforms up to 2^l (a
    // smaller 2^s reads every 2^(l-s)-th entry).
    template <class Real>
    void ensure_twiddles(int log2_n) {
        const int p = sizeof(Real) == sizeof(double) ? 1 : 0;
        if (log2_n <= twiddle_log2[p]) return;
        const size_t half = size_t(1) << (log2_n - 1);
        std::vector<Real> table(2 * half);
        const double pi = 3.14159265358979323846;
        for (size_t m = 0; m < half; ++m) {
            const double a = -2.0 * pi * double(m) / double(2 * half);
            table[2 * m] = Real(std::cos(a));
            table[2 * m + 1] = Real(std::sin(a));
        }
        ensure_buffer(twiddle_ssbo[p], table.size() * sizeof(Real), twiddle_capacity[p]);
        glNamedBufferSubData(twiddle_ssbo[p], 0, GLsizeiptr(table.size() * sizeof(Real)), table.data());
        twiddle_log2[p] = log2_n;
    }

    bool kernel_cached(const GlareKernel& k, int px, int py, bool dbl) const {
        return kernel_valid && kernel_px == px && kernel_py == py && kernel_double == dbl &&
               kernel_radius == k.radius && kernel_weights == k.weights;
    }

    // Zero-padded FFT convolution of radiance_tex (w x h) by the kernel into
    // glare_tex (shaders/glare_fft.comp). The kernel's spectrum is computed by
    // the same passes (rows of the wrapped kernel, then columns in mode 0) and
    // kept for the next call with the same weights, padded size and precision.
    // dbl: the transforms in double precision (FFT_DOUBLE).
    void glare(const GlareKernel& kernel, int w, int h, bool dbl) {
        const int r = kernel.radius, ks = kernel.size();
        const size_t kcount = size_t(ks) * size_t(ks);
        if (r < 0 || kernel.weights[0].size() != kcount || kernel.weights[1].size() != kcount ||
            kernel.weights[2].size() != kcount) {
            throw std::invalid_argument("airlight: glare: kernel weights do not match its radius");
        }
        if (ks > max_texture_size) throw std::runtime_error("airlight: glare: kernel larger than a GL texture");
        // Padded sizes: P >= size + r is enough for no wrap-around (the kernel reaches r pixels each way).
        const int px = std::max(kMinFftSize, detail::next_pow2(w + r));
        const int py = std::max(kMinFftSize, detail::next_pow2(h + r));
        const int lx = log2_of_pow2(px), ly = log2_of_pow2(py);
        const int kx_count = px / 2 + 1;     // stored columns k = 0..P_x/2
        const int stride = std::max(h, ks);  // rows of the per-channel spectrum buffers
        const int complex_bytes = dbl ? 16 : 8, row_element = 2 * complex_bytes;  // column lines: complex_bytes
        const size_t spectrum_bytes = size_t(stride) * size_t(kx_count) * complex_bytes;
        const size_t column_bytes = size_t(py) * complex_bytes;
        if (spectrum_bytes > size_t(max_block_bytes) || column_bytes > size_t(max_block_bytes)) {
            throw std::runtime_error("airlight: glare: an image of " + std::to_string(w) + "x" + std::to_string(h) +
                                     " needs " + std::to_string(spectrum_bytes) +
                                     " bytes per channel spectrum, above this GL driver's shader storage block "
                                     "limit of " +
                                     std::to_string(max_block_bytes) + " bytes");
        }
        if (dbl) {
            ensure_twiddles<double>(std::max(lx, ly));
        } else {
            ensure_twiddles<float>(std::max(lx, ly));
        }
        for (int c = 0; c < 3; ++c) ensure_buffer(spectrum_ssbo[c], spectrum_bytes, spectrum_capacity[c]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, twiddle_ssbo[dbl ? 1 : 0]);

        const bool row_shared = px <= shared_line_capacity(row_element),
                   col_shared = py <= shared_line_capacity(complex_bytes);
        const GLuint rows_fwd = fft_program(1, row_shared, dbl), cols = fft_program(2, col_shared, dbl),
                     rows_inv = fft_program(3, row_shared, dbl);
        const int row_chunk = line_chunk(px, row_element, row_shared);
        // Column chunks also bound the kernel spectrum's range (P_y values per column) to the block limit; a
        // chunk of a power of two columns keeps the offsets aligned when there is more than one.
        int col_chunk =
            std::min(line_chunk(py, complex_bytes, col_shared), int(size_t(max_block_bytes) / column_bytes));
        if (col_chunk < kx_count) {
            int p2 = 1;
            while (2 * p2 <= col_chunk) p2 *= 2;
            col_chunk = p2;
            if ((size_t(col_chunk) * column_bytes) % size_t(std::max(ssbo_alignment, 1)) != 0) {
                throw std::runtime_error("airlight: glare: image too large for this GL driver's storage buffers");
            }
        }
        for (GLuint program : {rows_fwd, cols, rows_inv}) {
            set_uniform(program, "u_tw_log2", twiddle_log2[dbl ? 1 : 0]);
            set_uniform(program, "u_stride", stride);
        }
        set_uniform(rows_fwd, "u_log2n", lx);
        set_uniform(rows_inv, "u_log2n", lx);
        set_uniform(cols, "u_log2n", ly);
        auto bind_spectra = [&]() {
            for (int c = 0; c < 3; ++c) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1 + c, spectrum_ssbo[c]);
        };
        // Column pass over channel c: `mode` 0 stores the kernel spectrum, 1 convolves.
        auto run_columns = [&](int c, int rows, int shift, int mode) {
            set_uniform(cols, "u_rows", rows);
            set_uniform(cols, "u_shift", shift);
            set_uniform(cols, "u_mode", mode);
            set_uniform(cols, "u_scale", float(1.0 / (double(px) * double(py))));
            dispatch_lines(cols, kx_count, col_chunk, [&](int first, int count) {
                glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, spectrum_ssbo[c]);
                glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 2, kernel_ssbo[c], GLintptr(size_t(first) * column_bytes),
                                  GLsizeiptr(size_t(count) * column_bytes));
                if (!col_shared) bind_scratch(count, py, complex_bytes);
            });
        };

        if (!kernel_cached(kernel, px, py, dbl)) {
            kernel_valid = false;
            std::vector<float> texels(kcount * 4, 0.0f);
            for (size_t i = 0; i < kcount; ++i)
                for (int c = 0; c < 3; ++c) texels[4 * i + c] = float(kernel.weights[c][i]);
            ensure_texture(kernel_tex, kernel_w, kernel_h, GL_RGBA32F, ks, ks);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
            glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
            glTextureSubImage2D(kernel_tex, 0, 0, 0, ks, ks, GL_RGBA, GL_FLOAT, texels.data());
            for (int c = 0; c < 3; ++c)
                ensure_buffer(kernel_ssbo[c], size_t(kx_count) * column_bytes, kernel_capacity[c]);
            // Kernel row j, column i sits at ((j - r) mod P_y, (i - r) mod P_x): the wrapped, centred kernel.
            set_uniform(rows_fwd, "u_width", ks);
            set_uniform(rows_fwd, "u_shift", r);
            glBindTextureUnit(0, kernel_tex);
            dispatch_lines(rows_fwd, ks, row_chunk, [&](int, int count) {
                bind_spectra();
                if (!row_shared) bind_scratch(count, px, row_element);
            });
            for (int c = 0; c < 3; ++c) run_columns(c, ks, r, 0);
            kernel_valid = true;
            kernel_px = px;
            kernel_py = py;
            kernel_radius = r;
            kernel_double = dbl;
            kernel_weights = kernel.weights;
        }

        ensure_texture(glare_tex, glare_w, glare_h, GL_RGBA32F, w, h);
        set_uniform(rows_fwd, "u_width", w);
        set_uniform(rows_fwd, "u_shift", 0);
        glBindTextureUnit(0, radiance_tex);
        dispatch_lines(rows_fwd, h, row_chunk, [&](int, int count) {
            bind_spectra();
            if (!row_shared) bind_scratch(count, px, row_element);
        });
        for (int c = 0; c < 3; ++c) run_columns(c, h, 0, 1);
        set_uniform(rows_inv, "u_width", w);
        glBindImageTexture(0, glare_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        dispatch_lines(rows_inv, h, row_chunk, [&](int, int count) {
            bind_spectra();
            if (!row_shared) bind_scratch(count, px, row_element);
        });
    }

    // display_pixel over the w x h texture `source` into display_tex (RGBA8).
    void display_pass(GLuint source, int w, int h, float exposure, int curve, float white, bool has_addend) {
        if (display_program == 0) {
            display_program = link_compute_program(std::string(kGlslPrelude) + shader_source("display.glsl") +
                                                   shader_source("display_pass.comp"));
        }
        ensure_texture(display_tex, display_w, display_h, GL_RGBA8, w, h);
        glUseProgram(display_program);
        glProgramUniform2i(display_program, glGetUniformLocation(display_program, "u_size"), w, h);
        set_uniform(display_program, "u_exposure", exposure);
        set_uniform(display_program, "u_curve", curve);
        set_uniform(display_program, "u_white", white);
        set_uniform(display_program, "u_has_addend", has_addend ? 1 : 0);
        glBindTextureUnit(0, source);
        if (has_addend) glBindTextureUnit(1, addend_tex);
        glBindImageTexture(0, display_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
        glDispatchCompute(GLuint((w + 15) / 16), GLuint((h + 15) / 16), 1);
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
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
    glCreateBuffers(2, state_->twiddle_ssbo.data());
    glCreateBuffers(1, &state_->scratch_ssbo);
    glCreateBuffers(3, state_->spectrum_ssbo.data());
    glCreateBuffers(3, state_->kernel_ssbo.data());
}

GlBackend::~GlBackend() {
    if (state_->egl.context != EGL_NO_CONTEXT) {
        state_->make_current();
        for (auto& entry : state_->programs) glDeleteProgram(entry.second);
        for (auto& entry : state_->table_textures) glDeleteTextures(1, &entry.second.second);
        glDeleteTextures(1, &state_->color);
        if (state_->display_program != 0) glDeleteProgram(state_->display_program);
        for (auto& entry : state_->fft_programs) glDeleteProgram(entry.second);
        GLuint display_textures[] = {state_->radiance_tex, state_->glare_tex, state_->display_tex, state_->kernel_tex,
                                     state_->addend_tex};
        glDeleteTextures(5, display_textures);  // zero names are ignored
        GLuint display_buffers[] = {state_->twiddle_ssbo[0],  state_->twiddle_ssbo[1],  state_->scratch_ssbo,
                                    state_->spectrum_ssbo[0], state_->spectrum_ssbo[1], state_->spectrum_ssbo[2],
                                    state_->kernel_ssbo[0],   state_->kernel_ssbo[1],   state_->kernel_ssbo[2]};
        glDeleteBuffers(9, display_buffers);
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
    if (data.sky_table) glBindTextureUnit(7, s.texture_for(*data.sky_table));
    if (data.rainbow_table) glBindTextureUnit(8, s.texture_for(*data.rainbow_table));

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

namespace {

void check_display_image(const Image* image) {
    if (image == nullptr) throw std::invalid_argument("airlight: display: no image");
    if (image->width < 0 || image->height < 0 ||
        image->rgb.size() != size_t(image->width) * size_t(image->height) * 3) {
        throw std::invalid_argument("radiance: size does not match width * height * 3");
    }
}

// The fp32 glare's measured error bound (see GlBackend::display).
constexpr double kGlareFp32Error = 1e-6;

// Upper bound on the change of a display value (in [0, 1]) per unit change
// of one exposed channel, at any level (DisplayResponse, display.hpp).
double display_slope_bound(int curve_id, float white) {
    // shader::TONE_LINEAR, TONE_LOGLOG, TONE_REINHARD, TONE_FILMIC are 0..3 in ToneCurve's order.
    const ToneCurve curves[] = {ToneCurve::linear, ToneCurve::loglog, ToneCurve::reinhard, ToneCurve::filmic};
    const ToneCurve curve = curve_id >= 1 && curve_id <= 3 ? curves[curve_id] : ToneCurve::linear;
    return DisplayResponse(curve, white).steepest();
}

// True when the fp32 glare's noise, kGlareFp32Error * max |image| spread over
// every pixel, could move a display value by more than 1/8 of an 8-bit step
// after exposure and tone curve: then the transforms run in double.
bool glare_needs_double(const Image& image, float exposure, int curve_id, float white) {
    float vmax = 0.0f;
    for (float v : image.rgb)
        if (std::isfinite(v)) vmax = std::max(vmax, std::fabs(v));
    const double noise = kGlareFp32Error * double(vmax) * double(exposure) * display_slope_bound(curve_id, white);
    return noise > 0.125 / 255.0;
}

void check_gl_error(const char* what) {
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) throw std::runtime_error("airlight: GL error " + std::to_string(err) + " " + what);
}

}  // namespace

// The display stage on the GPU: upload, optional glare (shaders/glare_fft.comp),
// display_pixel (shaders/display_pass.comp), read-back. Timings, each after
// glFinish: glare_ms is the glare convolution alone (the kernel spectrum
// included when it is not cached; the image upload excluded), tone_ms the
// display pass and the read-back of the bytes. The upload is in neither.
//
// Precision of the glare. fp32 error against convolve_glare_fft (double),
// measured by tests/cpp/test_gl_display.cpp on Mesa llvmpipe (point sources
// of 1e4..1e6 over a background of 1e-3..1, uniform random images,
// glare_kernel_rgb with and without eyelashes, r = 1..44, padded sizes from
// 64 x 16 to 4096 x 32 and 32 x 8192 and 2048 x 2048):
//   max |gl - cpu| <= c * max |image|, c = 6.3e-7 measured (worst: a uniform
//   random 0..1e6 image at 1920x1080; point sources give 1.3e-7..2.3e-7);
//   kGlareFp32Error = 1e-6 is the bound used and asserted.
// That noise lands on every pixel, dark ones included: with sources 1e5
// times the background it shows after tone mapping (measured: up to 63 LSB
// at 161x97, auto exposure, loglog). So display() runs the FFT in double
// (FFT_DOUBLE) when glare_needs_double predicts the fp32 noise could exceed
// 1/8 of an 8-bit step, in fp32 otherwise. glare_convolve always uses fp32.
void GlBackend::display(const GlDisplayJob& job, GlDisplayOutput& out) {
    check_display_image(job.linear);
    const Image& image = *job.linear;
    State& s = *state_;
    s.make_current();
    const int w = image.width, h = image.height;
    out.srgb8.assign(size_t(w) * size_t(h) * 3, 0);
    out.glare_ms = 0.0;
    out.tone_ms = 0.0;
    if (w == 0 || h == 0) return;
    s.upload_radiance(image);
    glFinish();
    GLuint source = s.radiance_tex;
    if (job.glare != nullptr) {
        const auto t0 = std::chrono::steady_clock::now();
        s.glare(*job.glare, w, h, glare_needs_double(image, job.exposure, job.curve, job.white));
        glFinish();
        out.glare_ms = ms_since(t0);
        source = s.glare_tex;
    }
    const bool has_addend = job.addend != nullptr;
    if (has_addend) {
        if (job.addend->width != w || job.addend->height != h)
            throw std::invalid_argument("display: the addend's size differs from the radiance's");
        s.upload_addend(*job.addend);
    }
    const auto t1 = std::chrono::steady_clock::now();
    s.display_pass(source, w, h, job.exposure, job.curve, job.white, has_addend);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glGetTextureImage(s.display_tex, 0, GL_RGB, GL_UNSIGNED_BYTE, GLsizei(out.srgb8.size()), out.srgb8.data());
    glFinish();
    out.tone_ms = ms_since(t1);
    check_gl_error("in the display pass");
}

void GlBackend::glare_convolve(const Image& in, const GlareKernel& kernel, Image& out) {
    check_display_image(&in);
    State& s = *state_;
    s.make_current();
    out.width = in.width;
    out.height = in.height;
    out.rgb.assign(in.rgb.size(), 0.0f);
    if (in.width == 0 || in.height == 0) return;
    s.upload_radiance(in);
    s.glare(kernel, in.width, in.height, false);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glGetTextureImage(s.glare_tex, 0, GL_RGB, GL_FLOAT, GLsizei(out.rgb.size() * sizeof(float)), out.rgb.data());
    check_gl_error("in the glare convolution");
}

}  // namespace airlight
