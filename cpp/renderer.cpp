#include "airlight/renderer.hpp"

#include <algorithm>
#include <cctype>
#include <mutex>
#include <vector>

#include "backends.hpp"
#include "display_stage.hpp"

namespace airlight {

const char* backend_name(Backend backend) { return backend == Backend::gl ? "gl" : "cpu"; }

bool is_software_gl_renderer(const std::string& gl_renderer) {
    std::string name = gl_renderer;
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* software : {"llvmpipe", "softpipe", "swrast"})
        if (name.find(software) != std::string::npos) return true;
    return false;
}

AutoBackend choose_auto_backend() {
    AutoBackend a;
    a.gl_available = gl_backend_available(&a.gl_unavailable_reason, &a.gl_renderer);
    if (a.gl_available) a.gl_unavailable_reason.clear();
    a.gl_software = a.gl_available && is_software_gl_renderer(a.gl_renderer);
    a.backend = a.gl_available && !a.gl_software ? Backend::gl : Backend::cpu;
    return a;
}

struct Renderer::Impl {
    Backend backend;
    CpuBackend cpu;
    std::unique_ptr<GlBackend> gl;
    size_t cpu_fallback_pixels = 0;  // of the last frame
    std::mutex mutex;                // one call at a time, from any thread
};

Renderer::Renderer(Backend backend) : impl_(std::make_unique<Impl>()) {
    impl_->backend = backend;
    if (backend == Backend::gl) impl_->gl = std::make_unique<GlBackend>();
}

Renderer::~Renderer() = default;

Backend Renderer::backend() const { return impl_->backend; }

size_t Renderer::cpu_fallback_pixels() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->cpu_fallback_pixels;
}

void Renderer::set_cpu_threads(int threads) { impl_->cpu.threads = threads; }

DisplayImage Renderer::display(const Image& linear, const DisplaySettings& settings, double fov_y_degrees) {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return run_display_stage(linear, settings, fov_y_degrees, impl_->cpu.threads, impl_->gl.get());
}

Image Renderer::render(const Scene& scene, const std::atomic<bool>* cancel, bool with_outputs) {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    FrameData data = make_frame_data(scene);
    data.features.outputs = with_outputs;
    Image image;
    impl_->cpu_fallback_pixels = 0;
    if (impl_->gl) {
        // Pixels the GL driver could not finish (its loop limit) are recomputed
        // exactly on the CPU, so every scene is right on every backend.
        std::vector<size_t> cut;
        impl_->gl->render(data, image, &cut, cancel);
        if (!cut.empty()) impl_->cpu.render_pixels(data, cut, image, cancel);
        impl_->cpu_fallback_pixels = cut.size();
    } else {
        impl_->cpu.render(data, image, cancel);
    }
    return image;
}

}  // namespace airlight
