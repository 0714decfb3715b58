# The core's part of the registry (cmake/effects.cmake): scene loading,
# camera, surfaces and their BVH, the homogeneous medium, the backends.
set(EFFECT_SOURCES scene_io.cpp scene_keys.cpp frame_data.cpp tables.cpp screen_tiles.cpp colour.cpp cpu_backend.cpp renderer.cpp
    render_outputs.cpp image_io.cpp)
# Constants and the core's structs come before every effect's layout (then
# shaders/frame.glsl, FrameUniforms, and every effect's formulas).
set(EFFECT_GLSL_MATH constants.glsl layout.glsl outputs_layout.glsl)
# The render outputs' recording, ray casting against the surfaces, table
# lookups and the light helpers come before every effect's per-pixel code.
set(EFFECT_GLSL_PIXEL outputs.glsl geometry.glsl tables.glsl lights.glsl)
set(EFFECT_FEATURES
    medium=HAS_MEDIUM           # a homogeneous medium with extinction
    surfaces=HAS_SURFACES       # planes, boxes, spheres
    grey_medium=GREY_MEDIUM     # sigma_t and sigma_s equal on all channels: one evaluation, not three
    outputs=RENDER_OUTPUTS)     # the render outputs beside the radiance (shaders/outputs.glsl), when asked for
# The core's layer of the render outputs (the effects add theirs).
set(EFFECT_LAYERS
    "surfaces=the light leaving what each ray ends on (a surface, a lamp's or spot's sphere or its sub-pixel core, the sky dome or the background), attenuated on its way to the camera")
