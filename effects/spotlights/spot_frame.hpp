// The spotlights' part of the frame (effects/spotlights/spot_frame.cpp).
#pragma once

#include "frame_data.hpp"

namespace airlight {

// The spots' moment tables serve their view-ray airlight unless it is marched,
// and their surface glow (the phase effect reads the same for its per-lobe tables).
inline bool needs_spot_moments(const FrameData& data) {
    return data.features.spot_airlight && (!data.features.airlight_march || data.features.surfaces);
}

}  // namespace airlight
