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
// is the top row of the image.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;
};

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
    Image render(const Scene& scene, const std::atomic<bool>* cancel = nullptr);

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
