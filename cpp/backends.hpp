// The two backends behind Renderer. Both consume the same FrameData and run
// the same shared per-pixel code (shaders/*.glsl).
#pragma once

#include <memory>
#include <string>

#include "airlight/renderer.hpp"
#include "frame_data.hpp"

namespace airlight {

class CpuBackend {
public:
    void render(const FrameData& data, Image& out);
    int threads = 0;  // 0: std::thread::hardware_concurrency()
};

class GlBackend {
public:
    GlBackend();  // creates the EGL context; throws BackendUnavailable
    ~GlBackend();
    GlBackend(const GlBackend&) = delete;
    GlBackend& operator=(const GlBackend&) = delete;
    void render(const FrameData& data, Image& out);

    struct State;

private:
    std::unique_ptr<State> state_;
};

// The complete GLSL fragment shader source for one feature set.
std::string fragment_shader_source(const shader::Features& features);

}  // namespace airlight
