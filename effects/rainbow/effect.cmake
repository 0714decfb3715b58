# Rainbows: the raindrops' Lorenz-Mie phase function for sunlight, averaged
# over drop sizes (physics.md; effects/rainbow/docs/rainbow.md).
set(EFFECT_SOURCES mie.cpp rainbow.cpp rainbow_rgb.cpp rainbow_data.cpp rainbow_frame.cpp rainbow_keys.cpp)
set(EFFECT_FEATURES
    rainbow=HAS_RAINBOW)  # rain lit by the sun scatters with the Mie table
set(EFFECT_TABLES
    rainbow)  # RGBA phase against the scattering angle (one row)
set(EFFECT_LAYERS
    "rainbow=sunlight scattered once by the rain's drops through their Mie phase function toward the camera (the bows, Alexander's dark band, the drops' glow around the sun)")
set(EFFECT_GLSL_MATH rainbow_math.glsl)
set(EFFECT_GLSL_PIXEL rainbow.glsl)
# Its switch depends on the daytime effect's sun (registered before it, since
# the daytime GLSL calls rainbow_phase): it is set when tables are picked.
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_SCENE_HEADER rainbow_scene.hpp)
set(EFFECT_QUALITY RainbowQuality)
set(EFFECT_QUALITY_KEYS rainbow_wavelengths)
