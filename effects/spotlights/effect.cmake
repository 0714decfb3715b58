# Spotlights and headlights: direct light, cores, airlight and glow
# (physics.md; effects/spotlights/docs/spot_table.md).
set(EFFECT_SOURCES spot_tables.cpp spot_frame.cpp)
set(EFFECT_GLSL_PIXEL spot.glsl)
set(EFFECT_FEATURES
    spot_lights=HAS_SPOT_LIGHTS       # spotlights: direct light and cores
    spot_airlight=HAS_SPOT_AIRLIGHT)  # spotlights in a scattering medium
set(EFFECT_TABLES
    spot_moments)  # (S, M1/N1, M2/N2, 0) on the airlight tail's grid
set(EFFECT_FRAME 1)
set(EFFECT_FRAME_TABLES 1)
