# The sun's shadow map: a grid pass before the shading pass casts rays from
# the sun over the surfaces that can cast shadows; surfaces then look up
# whether they see the sun instead of tracing a shadow ray each (physics.md).
# The first of the passes the light shafts will use.
set(EFFECT_SOURCES sun_shadow_map_frame.cpp sun_shadow_map_keys.cpp)
set(EFFECT_GLSL_PIXEL sun_shadow_map.glsl)
set(EFFECT_FEATURES
    sun_shadow_map=HAS_SUN_SHADOW_MAP)  # the sun's visibility from the map where it covers a point
set(EFFECT_TABLES
    sun_shadow_map)  # per texel: distance from the map's top plane to the first surface along the sunlight
set(EFFECT_PASSES
    sun_shadow_map)  # filled by sun_shadow_map_pass(x, y) before the shading pass
set(EFFECT_FRAME 1)
set(EFFECT_GLSL_LAYOUT sun_shadow_map_layout.glsl)
set(EFFECT_UNIFORMS "SunShadowMapGpu sun_shadow_map")
set(EFFECT_SCENE_HEADER sun_shadow_map_scene.hpp)
set(EFFECT_QUALITY SunShadowMapQuality)
set(EFFECT_QUALITY_KEYS sun_shadow_map)
