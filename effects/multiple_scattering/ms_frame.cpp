// The multiple-scattering effect's part of the frame (EFFECT_FRAME): the night
// part (point lamps, lamp_ms_frame.cpp). The daytime part joins it here.
#include "lamp_ms_frame.hpp"

namespace airlight {

void pack_multiple_scattering_frame(const Scene& scene, FrameData& data) { pack_lamp_ms_frame(scene, data); }

}  // namespace airlight
