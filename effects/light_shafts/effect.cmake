# Light shafts (issue 20; physics.md): the sun's light scattered in the air
# counts only over the parts of each view ray that the surfaces do not shadow,
# in the homogeneous medium (which scatters the sun's light once, into its
# own layer) and in the daytime atmosphere (whose scattering volumes,
# effects/daytime/sky.glsl, integrate the sun's share over the lit parts);
# and lamps and spots with "volumetric_shadows" scatter their light only from
# the parts of each ray they light. The lit parts are exact: every surface is
# convex, so the points of a view ray from which it hides a light form one
# interval, found in closed form (shafts.glsl). First in the registry: the
# lamps', spots' and daytime's code call it.
set(EFFECT_SOURCES shafts_frame.cpp shafts_keys.cpp)
set(EFFECT_GLSL_PIXEL shafts.glsl)
set(EFFECT_GLSL_TERMS shafts_terms.glsl)
set(EFFECT_HOOKS
    view_transfer=medium_sun_view_transfer)
set(EFFECT_FEATURES
    medium_sun=HAS_MEDIUM_SUN  # a sun above the horizon and a homogeneous medium that scatters
    shafts=HAS_SHAFTS          # surfaces shadow the sun's light in the air (quality.shafts not "off")
    shafts_march=SHAFTS_MARCH  # brute force: a shadow ray per marching step (quality.shafts "march")
    lamp_shadows=HAS_LAMP_SHADOWS)  # a lamp or spot with volumetric_shadows, surfaces and a scattering medium
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_SCENE_HEADER shafts_scene.hpp)
set(EFFECT_QUALITY ShaftsQuality)
set(EFFECT_QUALITY_KEYS shafts)
set(EFFECT_LAYERS
    "medium_sun=the sun's light scattered once toward the camera by the homogeneous medium, over the parts of the ray the sun lights")
