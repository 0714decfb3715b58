// The rainbow's spectral table data/rainbow_phase.bin (cpp/rainbow.hpp,
// written by build/cpp/make_rainbow_table), embedded into the library with the
// assembler's .incbin so that installed binaries need no data files.
#include "rainbow.hpp"

#ifndef AIRLIGHT_RAINBOW_DATA
#error "AIRLIGHT_RAINBOW_DATA must name data/rainbow_phase.bin (CMakeLists.txt)"
#endif

asm(".section .rodata\n"
    ".balign 16\n"
    "airlight_rainbow_phase_begin:\n"
    ".incbin \"" AIRLIGHT_RAINBOW_DATA "\"\n"
    "airlight_rainbow_phase_end:\n"
    ".previous\n");
extern "C" const char airlight_rainbow_phase_begin[];
extern "C" const char airlight_rainbow_phase_end[];

namespace airlight {

const RainbowSpectralTable& rainbow_spectral_table() {
    static const RainbowSpectralTable table =
        parse_rainbow_table(std::vector<char>(airlight_rainbow_phase_begin, airlight_rainbow_phase_end));
    return table;
}

}  // namespace airlight
