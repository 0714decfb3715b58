# Photo: weather on a photograph (issue 26). A backplate (the photo's linear
# radiance and the distance along each pixel's ray to what it shows) ends each
# camera ray in place of the surfaces, so that every medium and lamp term of
# the renderer applies to it unchanged (physics.md); and the atmospheric light,
# Koschmieder's constant airlight A of the homogeneous medium.
set(EFFECT_SOURCES photo_frame.cpp photo_keys.cpp)
set(EFFECT_GLSL_LAYOUT photo_layout.glsl)
set(EFFECT_UNIFORMS "PhotoGpu photo")
set(EFFECT_GLSL_TERMS photo_terms.glsl)
set(EFFECT_HOOKS
    backplate=photo_backplate
    view_transfer=atmospheric_light_view_transfer)
set(EFFECT_FEATURES
    photo=HAS_PHOTO                          # a backplate ends the camera rays
    atmospheric_light=HAS_ATMOSPHERIC_LIGHT) # a constant atmospheric light in a homogeneous medium
set(EFFECT_TABLES
    photo)  # per pixel (row 0 on top): the photo's linear RGB and its depth along the ray (m; NO_HIT: none)
set(EFFECT_FRAME 1)
set(EFFECT_SCENE_HEADER photo_scene.hpp)
set(EFFECT_SCENE_MEMBERS "Backplate backplate" "Rgb atmospheric_light{0.0f}")  # glm vectors are not zeroed by default
set(EFFECT_SCENE_KEYS atmospheric_light)
set(EFFECT_LAYERS
    "atmospheric_light=the constant atmospheric light A of the homogeneous medium (the scene's atmospheric_light) scattered toward the camera: A (1 - exp(-sigma_t depth))")
