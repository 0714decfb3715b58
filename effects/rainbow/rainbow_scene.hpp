// The rainbow's quality setting (a base of Quality; rainbow_keys.cpp parses it).
#pragma once

namespace airlight {

struct RainbowQuality {
    // Wavelength nodes (3, 5, 9, 17 or 33, 380-720 nm) of the rainbow's
    // spectral phase function turned into RGB (effects/rainbow/docs/rainbow.md measures the
    // colour error of fewer).
    int rainbow_wavelengths = 33;
};

}  // namespace airlight
