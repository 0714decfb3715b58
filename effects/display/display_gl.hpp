// The display stage's GL passes (built only with the GL backend:
// EFFECT_GL_SOURCES): the eye's glare as a zero-padded FFT convolution
// (glare_fft.comp) and the tone curve and sRGB encoding (display_pass.comp).
// GlBackend (cpp/gl_backend.cpp) holds one GlDisplayPasses and forwards
// GlBackend::display and GlBackend::glare_convolve to it with its context
// current.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <vector>

#include "backends.hpp"
#include "gl_util.hpp"

namespace airlight {

struct GlareKernel;  // include/airlight/glare.hpp

// Throws std::invalid_argument unless `image` is an image whose rgb holds
// width * height * 3 values: the check of GlBackend::display and
// glare_convolve, before anything touches the GL context.
void check_display_image(const Image* image);

// The GL objects of the display stage and the passes that use them. Every
// member needs the GL context current, the constructor and destructor
// included (they create and delete the buffers, textures and programs).
class GlDisplayPasses {
public:
    GlDisplayPasses();
    ~GlDisplayPasses();
    GlDisplayPasses(const GlDisplayPasses&) = delete;
    GlDisplayPasses& operator=(const GlDisplayPasses&) = delete;

    // GlBackend::display: job.linear already checked (check_display_image).
    void display(const GlDisplayJob& job, GlDisplayOutput& out);
    // GlBackend::glare_convolve: `in` already checked (check_display_image).
    void glare_convolve(const Image& in, const GlareKernel& kernel, Image& out, bool double_precision);

private:
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

    void read_limits();
    int shared_line_capacity(int element_bytes) const;
    GLuint fft_program(int pass, bool shared, bool dbl);
    void check_texture_size(int w, int h);
    void upload_radiance(const Image& image);
    void upload_addend(const Image& image);
    template <class Bind>
    void dispatch_lines(GLuint program, int lines, int chunk, const Bind& bind);
    int line_chunk(int n, int element_bytes, bool shared);
    void bind_scratch(int count, int n, int element_bytes);
    template <class Real>
    void ensure_twiddles(int log2_n);
    bool kernel_cached(const GlareKernel& k, int px, int py, bool dbl) const;
    void glare(const GlareKernel& kernel, int w, int h, bool dbl);
    void display_pass(GLuint source, int w, int h, const GlDisplayJob& job, bool has_addend);
};

}  // namespace airlight
