// The multiple-scattering effect's quality setting (a base of Quality; the
// key "multiple_scattering" of the scene format's "quality" object, parsed
// by ms_keys.cpp; effects/multiple_scattering/physics.md section 9).
#pragma once

namespace airlight {

struct MultipleScatteringQuality {
    // true (default): the daytime atmosphere's light scattered more than once
    // is added to the single scattering; false: single scattering only (the
    // source paper's look, for comparison).
    bool multiple_scattering = true;
};

}  // namespace airlight
