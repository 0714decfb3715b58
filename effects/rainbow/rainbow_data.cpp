// The rainbow's spectral table effects/rainbow/rainbow_phase.bin (effects/rainbow/rainbow.hpp,
// written by build/cpp/make_rainbow_table), embedded into the library with the
// assembler's .incbin so that installed binaries need no data files.
#include <stdexcept>

#include "rainbow.hpp"

#ifndef AIRLIGHT_RAINBOW_DATA
#error "AIRLIGHT_RAINBOW_DATA must name effects/rainbow/rainbow_phase.bin (CMakeLists.txt)"
#endif

asm(".section .rodata\n"
    ".balign 16\n"
    "airlight_rainbow_phase_begin:\n"
    ".incbin \"" AIRLIGHT_RAINBOW_DATA
    "\"\n"
    "airlight_rainbow_phase_end:\n"
    ".previous\n");
extern "C" const char airlight_rainbow_phase_begin[];
extern "C" const char airlight_rainbow_phase_end[];

namespace airlight {

namespace {
// The renderer indexes the table by this build's grids (rainbow.hpp).
RainbowSpectralTable checked(RainbowSpectralTable t) {
    bool same = t.wavelengths_nm.size() == size_t(RAINBOW_WAVELENGTHS) && t.rates.size() == size_t(RAINBOW_RATES) &&
                t.angles_deg == rainbow_angles_deg();
    for (size_t i = 0; same && i < t.wavelengths_nm.size(); ++i)
        same = t.wavelengths_nm[i] == rainbow_wavelength_nm(int(i));
    for (size_t k = 0; same && k < t.rates.size(); ++k) same = t.rates[k] == rainbow_rate(int(k));
    if (!same)
        throw std::runtime_error(
            "rainbow table: effects/rainbow/rainbow_phase.bin does not match the grids of effects/rainbow/rainbow.hpp "
            "(recompute it with make_rainbow_table)");
    return t;
}
}  // namespace

const RainbowSpectralTable& rainbow_spectral_table() {
    static const RainbowSpectralTable table =
        checked(parse_rainbow_table(std::vector<char>(airlight_rainbow_phase_begin, airlight_rainbow_phase_end)));
    return table;
}

}  // namespace airlight
