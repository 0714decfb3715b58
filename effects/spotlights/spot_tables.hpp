// The spotlights' table (effects/spotlights/physics.md; effects/spotlights/docs/spot_table.md).
#pragma once

#include "tables.hpp"

namespace airlight {

// Spot local moments (effects/spotlights/docs/spot_table.md): RGBA (S, M1/N1, M2/N2, 0) on the
// airlight tail's grid.
const Table2D& spot_moment_table();

}  // namespace airlight
