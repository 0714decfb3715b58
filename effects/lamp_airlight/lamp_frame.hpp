// The point lamps' part of the frame (effects/lamp_airlight/lamp_frame.cpp).
#pragma once

#include "frame_data.hpp"

namespace airlight {

// The tables the lamps' airlight and glow read, once the features are known
// (the phase effect reads the same for its per-lobe tables): the tail for the
// view-ray airlight unless it is marched, the glow where surfaces receive it
// (the spots' too: a point lamp's glow bounds a spot's, spot_surface_glow_bound).
inline bool needs_airlight_tail(const FrameData& data) {
    return data.features.airlight && !data.features.airlight_march;
}
inline bool needs_surface_glow(const FrameData& data) {
    return (data.features.airlight || data.features.spot_airlight) && data.features.surfaces;
}

}  // namespace airlight
