// The two backends behind Renderer. Both consume the same FrameData and run
// the same shared per-pixel code (shaders/*.glsl).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "airlight/renderer.hpp"
#include "frame_data.hpp"

namespace airlight {

struct GlareKernel;  // include/airlight/glare.hpp

// One run of the GL display pass (issue 8). effects/display/display_stage.cpp resolves
// the exposure and decides whether glare is needed (the same decisions as on
// the CPU); the GPU does the glare convolution, the tone curve and the sRGB
// encoding (effects/display/display.glsl's display_pixel).
struct GlDisplayJob {
    const Image* linear = nullptr;       // linear radiance, row 0 on top
    float exposure = 1.0f;               // resolved exposure, >= 0
    int curve = 0;                       // shader::TONE_*
    float white = 1.0f;                  // > 0
    const GlareKernel* glare = nullptr;  // null: no glare
    // Optional radiance of the same size added after the glare convolution,
    // before display_pixel (the splatted glare of the few extreme pixels that
    // the FFT does not see; glare_exact_split in display_stage.cpp).
    const Image* addend = nullptr;
    // Ordered dithering of the bytes (display.glsl's display_quantize), with the
    // thresholds of image pixel (x - origin, y - origin): `linear` may be the
    // image extended by `origin` pixels on each side (the FFT glare's margin).
    bool dither = true;
    int origin = 0;
};

// What the GL display pass returns: RGB bytes, row 0 on top, as
// apply_display; and the time of each part (after glFinish), in ms.
struct GlDisplayOutput {
    std::vector<std::uint8_t> srgb8;
    double glare_ms = 0.0;
    double tone_ms = 0.0;
};

class CpuBackend {
public:
    // `cancel` (optional): polled per row (per batch of pixels); once true, throws RenderCancelled.
    void render(const FrameData& data, Image& out, const std::atomic<bool>* cancel = nullptr);
    // Recomputes the listed pixels (indices row * width + x) of `out`, a
    // frame of data's film size (the GL backend's cut pixels).
    void render_pixels(const FrameData& data, const std::vector<size_t>& pixels, Image& out,
                       const std::atomic<bool>* cancel = nullptr);
    // The outputs of data.grid_passes alone, in order (tests).
    std::vector<Table2D> grid_passes(const FrameData& data);
    int threads = 0;  // 0: std::thread::hardware_concurrency()
};

class GlBackend {
public:
    GlBackend();  // creates the EGL context; throws BackendUnavailable
    ~GlBackend();
    GlBackend(const GlBackend&) = delete;
    GlBackend& operator=(const GlBackend&) = delete;
    // Renders the frame; `cut_pixels` (if given) receives the pixels whose
    // shader loops the driver cut short (Mesa llvmpipe's loop limiter: see
    // render.frag), which are wrong and must be recomputed (Renderer::render
    // does it on the CPU).
    // `cancel` (optional): polled per tile; once true, throws RenderCancelled.
    void render(const FrameData& data, Image& out, std::vector<size_t>* cut_pixels = nullptr,
                const std::atomic<bool>* cancel = nullptr);
    // The outputs of data.grid_passes alone, in order, read back (tests).
    std::vector<Table2D> grid_passes(const FrameData& data);
    // The texels of the last frame's grid passes whose loops the driver cut
    // (the GL loop limit, render.frag): then every grid pass of that frame was
    // computed again on the CPU.
    int grid_pass_cut_texels() const;
    // GL_MAX_TEXTURE_SIZE: the display stage's images must fit it on each side.
    int max_texture_size();
    // The display stage on the GPU (see GlDisplayJob).
    void display(const GlDisplayJob& job, GlDisplayOutput& out);
    // The glare convolution of the display pass alone (FFT on the GPU, fp32, or
    // fp64 with double_precision), read back as linear radiance: compare with
    // convolve_glare_fft.
    void glare_convolve(const Image& in, const GlareKernel& kernel, Image& out, bool double_precision = false);

    struct State;

private:
    std::unique_ptr<State> state_;
};

// The complete GLSL fragment shader source for one feature set: the shading
// pass's (grid_pass_slot -1) or that of the grid pass filling that table slot.
std::string fragment_shader_source(const shader::Features& features, int grid_pass_slot = -1);

}  // namespace airlight
