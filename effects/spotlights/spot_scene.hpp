// The spotlights' quality setting (a base of Quality; spot_keys.cpp parses it).
#pragma once

namespace airlight {

struct SpotQuality {
    // Directions per azimuth ring and rings of the quadrature over a spot's
    // beam that gives the light it scatters onto surfaces (a multiple of 4 in
    // [4, 64]; effects/spotlights/docs/spot_table.md section 9 measures its error).
    int spot_glow_samples = 12;
};

}  // namespace airlight
