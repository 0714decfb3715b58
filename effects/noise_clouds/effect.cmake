# Noise clouds (issue 21; physics.md): a cloud layer between two altitudes
# whose density comes from two tiling 3-D noise textures (Perlin-Worley and
# Worley), lit by the sun with its own shadows and by the sky, marched along
# each view ray. After the daytime effect, whose sun and sky light it uses;
# its view_transfer composes the media around the layer (the atmosphere
# behind, the clouds, the atmosphere in front).
set(EFFECT_SOURCES noise.cpp weather_map.cpp clouds_keys.cpp clouds_frame.cpp)
set(EFFECT_SCENE_KEYS clouds)
set(EFFECT_GLSL_PIXEL clouds.glsl)
set(EFFECT_GLSL_TERMS clouds_terms.glsl)
set(EFFECT_HOOKS
    view_transfer=clouds_view_transfer)
set(EFFECT_FEATURES
    clouds=HAS_CLOUDS             # a cloud layer with some coverage and extinction
    clouds_march=CLOUDS_MARCH     # brute force: fixed steps, no skipping, no early stop (quality.clouds "march")
    clouds_weather_map=CLOUDS_WEATHER_MAP)  # coverage and type from clouds.weather_map
set(EFFECT_TABLES
    cloud_shape    # 128^3 RGBA noise, stacked as 128 x 16384 (noise.hpp)
    cloud_detail   # 32^3 RGBA noise, stacked as 32 x 1024
    cloud_weather) # the weather map's RGBA texels (weather_map.hpp)
set(EFFECT_FRAME 1)
set(EFFECT_GLSL_LAYOUT clouds_layout.glsl)
set(EFFECT_UNIFORMS "CloudsGpu clouds")
set(EFFECT_SCENE_HEADER clouds_scene.hpp)
set(EFFECT_SCENE_MEMBERS "Clouds clouds")
set(EFFECT_QUALITY CloudsQuality)
set(EFFECT_QUALITY_KEYS clouds cloud_steps cloud_light_steps cloud_shadow_steps)
set(EFFECT_LAYERS
    "clouds=the sun's and the sky's light scattered once toward the camera by the cloud layer")
