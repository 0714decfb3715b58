// The rainbow's part of the frame (effects/rainbow/physics.md): rain lit by
// the sun scatters with the Mie table; a scene without sun or without drops
// builds none.
#include "frame_data.hpp"
#include "rainbow.hpp"

namespace airlight {

void pick_rainbow_tables(const Scene& scene, FrameData& data) {
    const Rain& rain = scene.atmosphere.rain;
    data.features.rainbow =
        data.features.sun && data.frame.species[shader::SPECIES_RAIN].phase.z != 0.0f && rain.phase == RainPhase::mie;
    if (data.features.rainbow)
        data.tables[shader::TABLE_RAINBOW] = &rainbow_phase_table(double(rain.rate), scene.quality.rainbow_wavelengths);
}

}  // namespace airlight
