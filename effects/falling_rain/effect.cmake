# Falling rain (issue 23; physics.md): the drops around the camera for the
# scene's rain rate, with Marshall-Palmer sizes, terminal speeds and the
# wind, drawn as streaks over the camera's exposure. The drops are drawn per
# frame on the CPU from a stationary rain field, binned into screen tiles; a
# grid pass lights each drop once (lamps, spots, sun and its surroundings
# through its optics)
# and the pixel_cores hook composites the streaks crossing each pixel.
set(EFFECT_SOURCES drops.cpp drop_optics.cpp rain_keys.cpp rain_frame.cpp)
set(EFFECT_SCENE_KEYS falling_rain)
set(EFFECT_GLSL_PIXEL falling_rain.glsl)
set(EFFECT_GLSL_TERMS rain_terms.glsl)
set(EFFECT_HOOKS
    pixel_cores=falling_rain_pixel_cores)
set(EFFECT_FEATURES
    falling_rain=HAS_FALLING_RAIN)  # drops in view
set(EFFECT_TABLES
    drop_optics       # the drop's phase function over theta, RGB
    rain_drops        # the frame's drops, two RGBA texels each (streak start, diameter; streak end, weight)
    rain_tiles        # the screen tiles' offsets, then their lists of drop indices
    rain_near_depth   # the optical depth of the medium's rain the drawn drops stand for, against distance
    rain_environment  # the light arriving at the camera from each direction, lamps' spheres left out (grid pass)
    rain_surround     # that light seen through a drop along each view direction (grid pass)
    rain_light)       # each drop's radiance toward the camera (grid pass)
set(EFFECT_PASSES
    rain_environment  # rain_environment_pass(x, y): an equal-area map of directions
    rain_surround     # rain_surround_pass(x, y): the map convolved with the drop's phase function
    rain_light)       # rain_light_pass(x, y): one texel per drop
set(EFFECT_FRAME 1)
set(EFFECT_GLSL_LAYOUT rain_layout.glsl)
set(EFFECT_UNIFORMS "FallingRainGpu falling_rain")
set(EFFECT_SCENE_HEADER falling_rain_scene.hpp)
set(EFFECT_SCENE_MEMBERS "FallingRain falling_rain")
set(EFFECT_LAYERS
    "falling_rain=the light of the falling drops' streaks (lamps, spots, sun and sky through each drop)")
