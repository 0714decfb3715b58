// PLACEHOLDER (branch ms-night) for the quality key "multiple_scattering" that
// the daytime part of issue 18 adds to this effect on main: removed when main
// is merged, which then provides the same C++ field scene.quality.multiple_scattering.
#pragma once

namespace airlight {

struct MultipleScatteringQuality {
    // Multiple scattering on (default) or off (false: single scattering only, as before issue 18).
    bool multiple_scattering = true;
};

}  // namespace airlight
