# Spotlights and headlights: direct light, cores, airlight and glow
# (physics.md; effects/spotlights/docs/spot_table.md).
set(EFFECT_SOURCES spot_tables.cpp spot_frame.cpp spot_keys.cpp)
set(EFFECT_GLSL_PIXEL spot.glsl)
set(EFFECT_FEATURES
    spot_lights=HAS_SPOT_LIGHTS       # spotlights: direct light and cores
    spot_airlight=HAS_SPOT_AIRLIGHT)  # spotlights in a scattering medium
set(EFFECT_TABLES
    spot_moments  # (S, M1/N1, M2/N2, 0) on the airlight tail's grid
    spot_tiles)   # the screen tiles' offsets, then their lists of the spots whose beams can meet their rays
set(EFFECT_FRAME 1)
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_GLSL_LAYOUT spot_layout.glsl)
set(EFFECT_UNIFORMS "SpotUniforms spot")
set(EFFECT_GLSL_TERMS spot_terms.glsl)
set(EFFECT_HOOKS
    surface_irradiance=spot_light_irradiance
    emitter_hit=spot_lights_emitter_hit
    view_glow=spot_lights_view_glow
    pixel_cores=spot_lights_pixel_cores)
set(EFFECT_LAYERS
    "spots=the spotlights' and headlights' light scattered toward the camera by the homogeneous medium")
set(EFFECT_SCENE_HEADER spot_scene.hpp)
set(EFFECT_QUALITY SpotQuality)
set(EFFECT_QUALITY_KEYS spot_glow_samples spot_lists)
