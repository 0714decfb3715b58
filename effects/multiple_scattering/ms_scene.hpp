// The multiple-scattering effect's quality settings (a base of Quality; the
// keys "multiple_scattering" and "fading_rain_steps" of the scene format's
// "quality" object, parsed by ms_keys.cpp; effects/multiple_scattering/physics.md
// section 9).
#pragma once

namespace airlight {

struct MultipleScatteringQuality {
    // true (default): the daytime atmosphere's light scattered more than once
    // is added to the single scattering; false: single scattering only (the
    // source paper's look, for comparison).
    bool multiple_scattering = true;
    // 0 (default): the daytime field is solved for the scene's rain exactly;
    // N > 0: solved at rain extinctions 2^(1/N) apart and interpolated between
    // the two around the scene's (physics.md eq. 9.3), so that the frames of a
    // fading rain share their solves.
    int fading_rain_steps = 0;
};

}  // namespace airlight
