// The light shafts' switches. Run after every effect's pack (EFFECT_FRAME_TABLES:
// pick_light_shafts_tables), because they depend on the daytime effect's sun
// and atmosphere, which pack after this effect's GLSL position in the registry.
#include <glm/glm.hpp>

#include "frame_data.hpp"

namespace airlight {

void pick_light_shafts_tables(const Scene& scene, FrameData& data) {
    shader::Features& f = data.features;
    // The homogeneous medium scatters the sun's light where both exist.
    f.medium_sun = f.sun && f.medium && glm::any(glm::greaterThan(glm::vec3(data.frame.sigma_s), glm::vec3(0.0f)));
    // Shadows in the air: something that scatters the sun, and surfaces to cast them.
    f.shafts = scene.quality.shafts != ShaftsMethod::off && f.surfaces && (f.medium_sun || (f.sun && f.atmosphere));
    f.shafts_march = f.shafts && scene.quality.shafts == ShaftsMethod::march;
    // Lamps and spots that shadow their own airlight.
    bool lamp_shadows = false;
    for (const PointLight& light : scene.point_lights) lamp_shadows |= light.volumetric_shadows;
    for (const SpotLight& spot : scene.spot_lights) lamp_shadows |= spot.volumetric_shadows;
    f.lamp_shadows = lamp_shadows && f.surfaces && data.scattering && scene.quality.shafts != ShaftsMethod::off;
    // Marching the shadowed integral marches the atmosphere too (its brute force).
    f.sky_march = f.sky_march || (f.shafts_march && f.atmosphere);
}

}  // namespace airlight
