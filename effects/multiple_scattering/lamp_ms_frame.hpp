// The point lamps' multiple scattering's part of the frame (lamp_ms_frame.cpp).
#pragma once

#include "frame_data.hpp"

namespace airlight {

// Whether the scene's lamps get multiple scattering: the quality switch, a
// scattering medium with lamps, and an optical depth where it is not negligible.
bool lamp_ms_matters(const Scene& scene, const FrameData& data);
void pack_lamp_ms_frame(const Scene& scene, FrameData& data);

}  // namespace airlight
