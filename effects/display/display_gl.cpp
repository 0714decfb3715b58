// The display stage's GL passes (display_gl.hpp): glare_fft.comp, display_pass.comp.
#include "display_gl.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "airlight/display.hpp"
#include "airlight/glare.hpp"
#include "numerics.hpp"
#include "shader_sources.hpp"

namespace airlight {

using gl::ensure_buffer;
using gl::ensure_texture;
using gl::kGlslPrelude;
using gl::link_compute_program;
using gl::log2_of_pow2;
using gl::ms_since;
using gl::set_uniform;

namespace {

// Display stage (issue 8): work-group size of the FFT line passes
// (effects/display/glare_fft.comp) and the smallest padded FFT length per axis.
constexpr int kFftLocalSize = 128;
constexpr int kMinFftSize = 16;

// The fp32 glare's measured error bound (see GlDisplayPasses::display).
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

void check_display_image(const Image* image) {
    if (image == nullptr) throw std::invalid_argument("airlight: display: no image");
    if (image->width < 0 || image->height < 0 ||
        image->rgb.size() != size_t(image->width) * size_t(image->height) * 3) {
        throw std::invalid_argument("radiance: size does not match width * height * 3");
    }
}

GlDisplayPasses::GlDisplayPasses() {
    glCreateBuffers(2, twiddle_ssbo.data());
    glCreateBuffers(1, &scratch_ssbo);
    glCreateBuffers(3, spectrum_ssbo.data());
    glCreateBuffers(3, kernel_ssbo.data());
}

GlDisplayPasses::~GlDisplayPasses() {
    if (display_program != 0) glDeleteProgram(display_program);
    for (auto& entry : fft_programs) glDeleteProgram(entry.second);
    GLuint display_textures[] = {radiance_tex, glare_tex, display_tex, kernel_tex, addend_tex};
    glDeleteTextures(5, display_textures);  // zero names are ignored
    GLuint display_buffers[] = {twiddle_ssbo[0],  twiddle_ssbo[1], scratch_ssbo,   spectrum_ssbo[0], spectrum_ssbo[1],
                                spectrum_ssbo[2], kernel_ssbo[0],  kernel_ssbo[1], kernel_ssbo[2]};
    glDeleteBuffers(9, display_buffers);
}

void GlDisplayPasses::read_limits() {
    if (max_texture_size > 0) return;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
    glGetIntegerv(GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, &max_shared_bytes);
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &max_groups_x);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &ssbo_alignment);
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block_bytes);
}

// Longest FFT line (a power of two) that fits in shared memory with
// elements of `element_bytes`.
int GlDisplayPasses::shared_line_capacity(int element_bytes) const {
    int n = 1;
    while (2 * n * element_bytes <= max_shared_bytes) n *= 2;
    return n;
}

// One pass of effects/display/glare_fft.comp (1 rows forward, 2 columns, 3 rows
// inverse) with its lines in shared memory or in the scratch buffer.
GLuint GlDisplayPasses::fft_program(int pass, bool shared, bool dbl) {
    const int key = pass * 4 + (shared ? 2 : 0) + (dbl ? 1 : 0);
    auto it = fft_programs.find(key);
    if (it != fft_programs.end()) return it->second;
    std::string source = kGlslPrelude;
    source += "#define PASS " + std::to_string(pass) + "\n";
    source += "#define LOCAL_SIZE " + std::to_string(kFftLocalSize) + "\n";
    source += std::string("#define SHARED_LINE ") + (shared ? "1" : "0") + "\n";
    source += std::string("#define FFT_DOUBLE ") + (dbl ? "1" : "0") + "\n";
    source +=
        "#define LINE_CAPACITY " + std::to_string(shared_line_capacity((pass == 2 ? 8 : 16) * (dbl ? 2 : 1))) + "\n";
    source += shader_source("glare_fft.comp");
    GLuint program = link_compute_program(source);
    fft_programs[key] = program;
    return program;
}

void GlDisplayPasses::check_texture_size(int w, int h) {
    read_limits();
    if (w > max_texture_size || h > max_texture_size) {
        throw std::runtime_error("airlight: display: image of " + std::to_string(w) + "x" + std::to_string(h) +
                                 " exceeds this GL driver's maximum texture size of " +
                                 std::to_string(max_texture_size));
    }
}

// The image into radiance_tex (RGBA32F): image row y is texel row y, so
// every later pass and the read-back keep row 0 on top.
void GlDisplayPasses::upload_radiance(const Image& image) {
    check_texture_size(image.width, image.height);
    ensure_texture(radiance_tex, radiance_w, radiance_h, GL_RGBA32F, image.width, image.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTextureSubImage2D(radiance_tex, 0, 0, 0, image.width, image.height, GL_RGB, GL_FLOAT, image.rgb.data());
}

// GlDisplayJob::addend into addend_tex (RGBA32F), like upload_radiance.
void GlDisplayPasses::upload_addend(const Image& image) {
    ensure_texture(addend_tex, addend_w, addend_h, GL_RGBA32F, image.width, image.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTextureSubImage2D(addend_tex, 0, 0, 0, image.width, image.height, GL_RGB, GL_FLOAT, image.rgb.data());
}

// Runs `lines` work groups of `program` from line 0 in chunks of at most
// `chunk` (and the driver's dispatch limit): u_first is set per chunk and
// bind(first, count) binds what the chunk needs.
template <class Bind>
void GlDisplayPasses::dispatch_lines(GLuint program, int lines, int chunk, const Bind& bind) {
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
int GlDisplayPasses::line_chunk(int n, int element_bytes, bool shared) {
    if (shared) return 1 << 30;
    const long long per_line = (long long)n * element_bytes;
    if (per_line > max_block_bytes) throw std::runtime_error("airlight: glare: FFT line too long for this GL driver");
    const int chunk = int(std::min<long long>(max_block_bytes / per_line, 1 << 30));
    return chunk;
}

void GlDisplayPasses::bind_scratch(int count, int n, int element_bytes) {
    const size_t bytes = size_t(count) * size_t(n) * size_t(element_bytes);
    ensure_buffer(scratch_ssbo, bytes, scratch_capacity);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 7, scratch_ssbo, 0, GLsizeiptr(std::max<size_t>(bytes, 64)));
}

// The twiddle table exp(-2 pi i m / 2^l), m < 2^(l-1), computed in double
// (rounded to float for the fp32 passes), for transforms up to 2^l (a
// smaller 2^s reads every 2^(l-s)-th entry).
template <class Real>
void GlDisplayPasses::ensure_twiddles(int log2_n) {
    const int p = sizeof(Real) == sizeof(double) ? 1 : 0;
    if (log2_n <= twiddle_log2[p]) return;
    const size_t half = size_t(1) << (log2_n - 1);
    std::vector<Real> table(2 * half);
    const double pi = numerics::kPi;
    for (size_t m = 0; m < half; ++m) {
        const double a = -2.0 * pi * double(m) / double(2 * half);
        table[2 * m] = Real(std::cos(a));
        table[2 * m + 1] = Real(std::sin(a));
    }
    ensure_buffer(twiddle_ssbo[p], table.size() * sizeof(Real), twiddle_capacity[p]);
    glNamedBufferSubData(twiddle_ssbo[p], 0, GLsizeiptr(table.size() * sizeof(Real)), table.data());
    twiddle_log2[p] = log2_n;
}

bool GlDisplayPasses::kernel_cached(const GlareKernel& k, int px, int py, bool dbl) const {
    return kernel_valid && kernel_px == px && kernel_py == py && kernel_double == dbl && kernel_radius == k.radius &&
           kernel_weights == k.weights;
}

// Zero-padded FFT convolution of radiance_tex (w x h) by the kernel into
// glare_tex (effects/display/glare_fft.comp). The kernel's spectrum is computed by
// the same passes (rows of the wrapped kernel, then columns in mode 0) and
// kept for the next call with the same weights, padded size and precision.
// dbl: the transforms in double precision (FFT_DOUBLE).
void GlDisplayPasses::glare(const GlareKernel& kernel, int w, int h, bool dbl) {
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
    int col_chunk = std::min(line_chunk(py, complex_bytes, col_shared), int(size_t(max_block_bytes) / column_bytes));
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
        for (int c = 0; c < 3; ++c) ensure_buffer(kernel_ssbo[c], size_t(kx_count) * column_bytes, kernel_capacity[c]);
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
void GlDisplayPasses::display_pass(GLuint source, int w, int h, const GlDisplayJob& job, bool has_addend) {
    if (display_program == 0) {
        display_program = link_compute_program(std::string(kGlslPrelude) + shader_source("display.glsl") +
                                               shader_source("display_pass.comp"));
    }
    ensure_texture(display_tex, display_w, display_h, GL_RGBA8, w, h);
    glUseProgram(display_program);
    glProgramUniform2i(display_program, glGetUniformLocation(display_program, "u_size"), w, h);
    set_uniform(display_program, "u_exposure", job.exposure);
    set_uniform(display_program, "u_curve", job.curve);
    set_uniform(display_program, "u_white", job.white);
    set_uniform(display_program, "u_has_addend", has_addend ? 1 : 0);
    set_uniform(display_program, "u_dither", job.dither ? 1 : 0);
    set_uniform(display_program, "u_origin", job.origin);
    glBindTextureUnit(0, source);
    if (has_addend) glBindTextureUnit(1, addend_tex);
    glBindImageTexture(0, display_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
    glDispatchCompute(GLuint((w + 15) / 16), GLuint((h + 15) / 16), 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
}

// The display stage on the GPU: upload, optional glare (effects/display/glare_fft.comp),
// display_pixel (effects/display/display_pass.comp), read-back. Timings, each after
// glFinish: glare_ms is the glare convolution alone (the kernel spectrum
// included when it is not cached; the image upload excluded), tone_ms the
// display pass and the read-back of the bytes. The upload is in neither.
//
// Precision of the glare. fp32 error against convolve_glare_fft (double),
// measured by effects/display/tests/test_gl_display.cpp on Mesa llvmpipe (point sources
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
// 1/8 of an 8-bit step, in fp32 otherwise. glare_convolve uses fp32 unless asked for fp64.
void GlDisplayPasses::display(const GlDisplayJob& job, GlDisplayOutput& out) {
    const Image& image = *job.linear;
    const int w = image.width, h = image.height;
    out.srgb8.assign(size_t(w) * size_t(h) * 3, 0);
    out.glare_ms = 0.0;
    out.tone_ms = 0.0;
    if (w == 0 || h == 0) return;
    upload_radiance(image);
    glFinish();
    GLuint source = radiance_tex;
    if (job.glare != nullptr) {
        const auto t0 = std::chrono::steady_clock::now();
        glare(*job.glare, w, h, glare_needs_double(image, job.exposure, job.curve, job.white));
        glFinish();
        out.glare_ms = ms_since(t0);
        source = glare_tex;
    }
    const bool has_addend = job.addend != nullptr;
    if (has_addend) {
        if (job.addend->width != w || job.addend->height != h)
            throw std::invalid_argument("display: the addend's size differs from the radiance's");
        upload_addend(*job.addend);
    }
    const auto t1 = std::chrono::steady_clock::now();
    display_pass(source, w, h, job, has_addend);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glGetTextureImage(display_tex, 0, GL_RGB, GL_UNSIGNED_BYTE, GLsizei(out.srgb8.size()), out.srgb8.data());
    glFinish();
    out.tone_ms = ms_since(t1);
    check_gl_error("in the display pass");
}

void GlDisplayPasses::glare_convolve(const Image& in, const GlareKernel& kernel, Image& out, bool double_precision) {
    out.width = in.width;
    out.height = in.height;
    out.rgb.assign(in.rgb.size(), 0.0f);
    if (in.width == 0 || in.height == 0) return;
    upload_radiance(in);
    glare(kernel, in.width, in.height, double_precision);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glGetTextureImage(glare_tex, 0, GL_RGB, GL_FLOAT, GLsizei(out.rgb.size() * sizeof(float)), out.rgb.data());
    check_gl_error("in the glare convolution");
}

}  // namespace airlight
