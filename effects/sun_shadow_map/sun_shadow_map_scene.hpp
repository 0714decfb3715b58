// The sun shadow map's quality setting (a base of Quality; sun_shadow_map_keys.cpp parses it).
#pragma once

namespace airlight {

struct SunShadowMapQuality {
    // The sun's shadows on surfaces: 0 traces a shadow ray per point (exact);
    // N in [16, 4096] looks them up in a shadow map of N texels along its
    // longer side, filled by a grid pass (effects/sun_shadow_map/physics.md).
    int sun_shadow_map = 0;
};

}  // namespace airlight
