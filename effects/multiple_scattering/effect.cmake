# Multiple scattering: the daytime atmosphere's light scattered more than once,
# from the plane-parallel radiative transfer solver (physics.md;
# effects/multiple_scattering/docs/solver.md), tabulated per weather state and
# added to the daytime effect's single scattering. Registered before daytime,
# whose scattering volumes read its field (ms_field.glsl).
set(EFFECT_SOURCES plane_parallel.cpp ms_tables.cpp ms_keys.cpp)
set(EFFECT_SCENE_HEADER ms_scene.hpp)
set(EFFECT_QUALITY MultipleScatteringQuality)
set(EFFECT_QUALITY_KEYS multiple_scattering fading_rain_steps)
set(EFFECT_FEATURES
    multiple_scattering=HAS_MULTIPLE_SCATTERING)  # the daytime atmosphere's multiple scattering
set(EFFECT_TABLES
    ms_field)  # K_i(y, d), E(y, n), E_res(y) (ms_layout.glsl)
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_GLSL_LAYOUT ms_layout.glsl)
set(EFFECT_UNIFORMS "MultipleScatteringGpu multiple_scattering")
set(EFFECT_GLSL_PIXEL ms_field.glsl)
set(EFFECT_GLSL_TERMS ms_terms.glsl)
set(EFFECT_HOOKS
    surface_irradiance=ms_surface_irradiance)  # the diffuse sky light on surfaces

# ---- Night (issue 18): point lamps' multiple scattering in the homogeneous
# medium (physics.md sections 10 to 13; effects/multiple_scattering/docs/lamps.md),
# switched by the same quality.multiple_scattering.
list(APPEND EFFECT_SOURCES point_source.cpp lamp_ms_frame.cpp ms_frame.cpp)
list(APPEND EFFECT_GLSL_MATH lamp_ms_math.glsl)
list(APPEND EFFECT_GLSL_TERMS lamp_ms_terms.glsl)
list(APPEND EFFECT_FEATURES
    lamp_multiple_scattering=LAMP_MULTIPLE_SCATTERING)  # point lamps: light scattered twice or more
list(APPEND EFFECT_TABLES
    lamp_ms_glow)  # log L(tau, gamma), then log E(tau, beta), per albedo channel (lamp_ms_math.glsl)
list(APPEND EFFECT_HOOKS
    view_glow=lamp_ms_view_glow
    surface_irradiance=lamp_ms_surface_irradiance)  # the lamps' diffuse light on surfaces (physics.md section 13)
set(EFFECT_FRAME 1)  # ms_frame.cpp: pack_multiple_scattering_frame (the lamps' switch and table)
