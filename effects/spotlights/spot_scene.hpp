// The spotlights' quality setting (a base of Quality; spot_keys.cpp parses it).
#pragma once

namespace airlight {

// Which spots a pixel's view ray walks for their airlight (physics.md section 9).
enum class SpotLists {
    tiles,  // those whose beams can meet a ray of its screen tile
    all,    // every spot: for comparisons
};

struct SpotQuality {
    // Directions per azimuth ring and rings of the quadrature over a spot's
    // beam that gives the light it scatters onto surfaces (a multiple of 4 in
    // [4, 64]; effects/spotlights/docs/spot_table.md section 9 measures its error).
    int spot_glow_samples = 12;
    SpotLists spot_lists = SpotLists::tiles;
};

}  // namespace airlight
