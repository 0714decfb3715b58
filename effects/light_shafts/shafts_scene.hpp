// The light shafts' quality setting (a base of Quality; shafts_keys.cpp parses it).
#pragma once

namespace airlight {

// How the sun's shadows in the air are found (physics.md).
enum class ShaftsMethod {
    analytic,  // each surface's shadow on a view ray in closed form: exact
    march,     // a shadow ray at every marching step (quality.march_steps): brute force, for comparison
    off,       // the air is never shadowed (the look before issue 20)
};

struct ShaftsQuality {
    ShaftsMethod shafts = ShaftsMethod::analytic;
};

}  // namespace airlight
