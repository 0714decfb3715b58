#include "airlight/renderer.hpp"

#include "backends.hpp"
#include "display_stage.hpp"

namespace airlight {

const char* backend_name(Backend backend) { return backend == Backend::gl ? "gl" : "cpu"; }

struct Renderer::Impl {
    Backend backend;
    CpuBackend cpu;
    std::unique_ptr<GlBackend> gl;
};

Renderer::Renderer(Backend backend) : impl_(std::make_unique<Impl>()) {
    impl_->backend = backend;
    if (backend == Backend::gl) impl_->gl = std::make_unique<GlBackend>();
}

Renderer::~Renderer() = default;

Backend Renderer::backend() const { return impl_->backend; }

void Renderer::set_cpu_threads(int threads) { impl_->cpu.threads = threads; }

DisplayImage Renderer::display(const Image& linear, const DisplaySettings& settings, double fov_y_degrees) {
    return run_display_stage(linear, settings, fov_y_degrees, impl_->cpu.threads, impl_->gl.get());
}

Image Renderer::render(const Scene& scene) {
    const FrameData data = make_frame_data(scene);
    Image image;
    if (impl_->gl) {
        impl_->gl->render(data, image);
    } else {
        impl_->cpu.render(data, image);
    }
    return image;
}

}  // namespace airlight
