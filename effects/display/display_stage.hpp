// The display stage's driver shared by display_image (CPU) and
// Renderer::display (either backend). See include/airlight/display.hpp.
#pragma once

#include "airlight/display.hpp"

namespace airlight {

class GlBackend;

// The id of `curve` in effects/display/display.glsl (TONE_*); -1 for a value outside the enum.
int tone_curve_shader_id(ToneCurve curve);

// Exposure and glare plan on the CPU (cheap passes over the image), then the
// glare and the tone stage on `gl` when given, else on the CPU.
DisplayImage run_display_stage(const Image& linear, const DisplaySettings& settings, double fov_y_degrees, int threads,
                               GlBackend* gl);

}  // namespace airlight
