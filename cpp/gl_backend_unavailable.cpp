// Built instead of gl_backend.cpp when EGL/OpenGL were not found at configure
// time: the CPU backend still works and "auto" falls back to it.
#include "backends.hpp"

namespace airlight {

struct GlBackend::State {};

bool gl_backend_available(std::string* reason, std::string*) {
    if (reason != nullptr) *reason = "airlight was built without EGL/OpenGL";
    return false;
}

GlBackend::GlBackend() { throw BackendUnavailable("airlight: GL backend unavailable: built without EGL/OpenGL"); }
GlBackend::~GlBackend() = default;
void GlBackend::render(const FrameData&, Image&, std::vector<size_t>*, const std::atomic<bool>*) {}
int GlBackend::max_texture_size() { return 0; }
void GlBackend::display(const GlDisplayJob&, GlDisplayOutput&) {}
void GlBackend::glare_convolve(const Image&, const GlareKernel&, Image&, bool) {}

}  // namespace airlight
