# What the eye sees: diffraction glare, exposure and tone curves, sRGB
# (physics.md; effects/display/docs/glare.md). Its passes run after the shading pass
# (display_pass.comp, glare_fft.comp on GL).
set(EFFECT_SOURCES display.cpp glare.cpp display_stage.cpp display_keys.cpp)
# Its GL passes (GlDisplayPasses, which GlBackend::display and glare_convolve forward to).
set(EFFECT_GL_SOURCES display_gl.cpp)
set(EFFECT_SCENE_KEYS display)
set(EFFECT_GLSL_MATH display.glsl)
set(EFFECT_SCENE_HEADER display_settings.hpp)
set(EFFECT_SCENE_MEMBERS "DisplaySettings display")
