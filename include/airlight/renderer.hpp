// Rendering a scene to linear radiance with the GL or the CPU backend.
#pragma once

#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "airlight/scene.hpp"

namespace airlight {

enum class Backend { cpu, gl };

struct DisplaySettings;  // effects/display/display_settings.hpp
struct DisplayImage;     // airlight/display.hpp

const char* backend_name(Backend backend);

// Thrown when the GL backend cannot run here (no EGL, no OpenGL 4.5 context,
// or a build without EGL); the message says why.
class BackendUnavailable : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Thrown by Renderer::render when its cancel flag was set (Ctrl-C in Python
// and in the demo): the frame is abandoned, the renderer stays usable.
class RenderCancelled : public std::runtime_error {
public:
    RenderCancelled() : std::runtime_error("airlight: render interrupted") {}
};

// Linear radiance, W/(m^2 sr): `rgb` holds width * height RGB triples, row 0
// is the top row of the image. `outputs`: the render outputs beside the
// radiance when the render asked for them (Renderer::render's with_outputs),
// packed `output_floats` per pixel; read them with output_values. Empty otherwise.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;
    int output_floats = 0;
    std::vector<float> outputs{};
};

// One of the outputs a render can give (README "Render outputs"): its name,
// components per pixel (1 or 3) and what it holds, with its unit.
struct RenderOutput {
    std::string name;
    int components = 3;
    std::string description;
    bool layer = false;  // one of the layers that sum to the radiance
};

// Every output, in a fixed order: radiance, depth, distance_z, normal,
// transmittance, then the layers (the core's and each effect's EFFECT_LAYERS,
// in registry order).
const std::vector<RenderOutput>& render_outputs();

// Output `name` of an image rendered with its outputs: width * height *
// components floats, row 0 on top; depth and distance_z are +inf where the ray
// escapes. "radiance" is the image's rgb. Throws std::invalid_argument for an
// unknown name, or for any other name when the image has no outputs.
std::vector<float> output_values(const Image& image, const std::string& name);

// True when an OpenGL 4.5 core context can be created through EGL here; on
// false, `reason` (if given) says why; on true, `gl_renderer` (if given) is the
// context's GL_RENDERER string. Setting AIRLIGHT_DISABLE_GL=1 makes it false,
// to exercise the CPU fallback.
bool gl_backend_available(std::string* reason = nullptr, std::string* gl_renderer = nullptr);

// True for the GL_RENDERER of a software rasteriser: Mesa's llvmpipe, softpipe
// or swrast (case-insensitive), which run on the CPU's cores.
bool is_software_gl_renderer(const std::string& gl_renderer);

// What Backend "auto" (Python's backend="auto", the demo's --backend auto)
// picks here, and why: GL where a hardware OpenGL 4.5 context works; the CPU
// where GL cannot run, and also where the only GL is a software rasteriser
// (llvmpipe on a machine without a GPU), which shares the CPU backend's cores
// and pays a 40 times larger set-up (README "Measurements"). Backend::gl stays
// available explicitly.
struct AutoBackend {
    Backend backend = Backend::cpu;
    bool gl_available = false;
    std::string gl_renderer;            // GL_RENDERER where GL is available, else empty
    bool gl_software = false;           // gl_renderer is a software rasteriser
    std::string gl_unavailable_reason;  // why GL cannot run, else empty
};
AutoBackend choose_auto_backend();

// Keeps what is expensive to set up (the GL context, compiled shader variants,
// and later the scattering tables) across frames, so that animations pay the
// set-up once. Usable from any thread, one call at a time (concurrent calls
// wait their turn); a GL renderer not in a child forked after GL was
// initialised (it throws BackendUnavailable there).
class Renderer {
public:
    // Throws BackendUnavailable for Backend::gl when GL cannot run here.
    explicit Renderer(Backend backend);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    Backend backend() const;
    // `cancel` (optional) is polled while rendering (per row on the CPU, per
    // tile on GL): once it is true, render throws RenderCancelled.
    // `with_outputs`: compute the render outputs (render_outputs()) in the same
    // pass, into Image::outputs; without them the frame pays nothing for them.
    Image render(const Scene& scene, const std::atomic<bool>* cancel = nullptr, bool with_outputs = false);

    // The display stage (include/airlight/display.hpp, display_image) on this
    // renderer's backend: the GL backend runs the glare convolution and the
    // tone curve on the GPU. fov_y_degrees: the camera's vertical field of
    // view (the glare's angular scale). Include airlight/display.hpp to call.
    DisplayImage display(const Image& linear, const DisplaySettings& settings, double fov_y_degrees);

    // Pixels of the last frame that the GL backend could not finish within
    // its driver's loop limit (Mesa llvmpipe: 65535 loop iterations per
    // invocation, e.g. thousands of lamps) and that were recomputed on the
    // CPU; 0 on the CPU backend and for most scenes.
    size_t cpu_fallback_pixels() const;

    // Number of CPU threads used by the CPU backend (default: all cores).
    void set_cpu_threads(int threads);

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace airlight
