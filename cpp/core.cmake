# The core's part of the registry (cmake/effects.cmake): scene loading,
# camera, surfaces and their BVH, the homogeneous medium, the backends.
set(EFFECT_SOURCES scene_io.cpp scene_keys.cpp frame_data.cpp tables.cpp colour.cpp cpu_backend.cpp renderer.cpp image_io.cpp)
# Constants and the core's structs come before every effect's layout (then
# shaders/frame.glsl, FrameUniforms, and every effect's formulas).
set(EFFECT_GLSL_MATH constants.glsl layout.glsl)
# Ray casting against the surfaces, table lookups and the light helpers come
# before every effect's per-pixel code.
set(EFFECT_GLSL_PIXEL geometry.glsl tables.glsl lights.glsl)
set(EFFECT_FEATURES
    medium=HAS_MEDIUM           # a homogeneous medium with extinction
    surfaces=HAS_SURFACES       # planes, boxes, spheres
    grey_medium=GREY_MEDIUM)    # sigma_t and sigma_s equal on all channels: one evaluation, not three
