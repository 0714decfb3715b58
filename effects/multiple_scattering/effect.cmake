# Multiple scattering: the plane-parallel radiative transfer solver of the
# daytime atmosphere (physics.md; effects/multiple_scattering/docs/solver.md).
# A standalone unit for now: no shader features or tables yet.
set(EFFECT_SOURCES plane_parallel.cpp)

# ---- Night (issue 18, branch ms-night): point lamps' multiple scattering in
# the homogeneous medium (physics.md sections 10 to 12; effects/multiple_scattering/docs/lamps.md).
list(APPEND EFFECT_SOURCES point_source.cpp lamp_ms_frame.cpp ms_frame.cpp)
list(APPEND EFFECT_GLSL_MATH lamp_ms_math.glsl)
list(APPEND EFFECT_GLSL_TERMS lamp_ms_terms.glsl)
list(APPEND EFFECT_FEATURES
    lamp_multiple_scattering=LAMP_MULTIPLE_SCATTERING)  # point lamps: light scattered twice or more
list(APPEND EFFECT_TABLES
    lamp_ms_glow)  # log L(tau, gamma) per albedo channel (lamp_ms_math.glsl)
list(APPEND EFFECT_HOOKS
    view_glow=lamp_ms_view_glow)
set(EFFECT_FRAME 1)  # ms_frame.cpp: pack_multiple_scattering_frame
# PLACEHOLDER until main's quality.multiple_scattering is merged (ms_quality_placeholder.hpp).
list(APPEND EFFECT_SOURCES ms_quality_placeholder.cpp)
set(EFFECT_SCENE_HEADER ms_quality_placeholder.hpp)
set(EFFECT_QUALITY MultipleScatteringQuality)
set(EFFECT_QUALITY_KEYS multiple_scattering)
