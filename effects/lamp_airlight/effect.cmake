# Point lamps in fog: direct light, cores, the analytic airlight of Sun et al.
# 2005 and the surface glow (physics.md; effects/lamp_airlight/docs/airlight_table.md).
set(EFFECT_SOURCES airlight_tables.cpp lamp_frame.cpp)
set(EFFECT_GLSL_PIXEL airlight.glsl)
set(EFFECT_FEATURES
    point_lights=HAS_POINT_LIGHTS  # point lamps: direct light and cores
    airlight=HAS_AIRLIGHT          # point lamps in a scattering medium: airlight and surface glow
    airlight_march=AIRLIGHT_MARCH) # brute-force ray marching instead of the tables (benchmarks)
set(EFFECT_TABLES
    airlight_tail   # normalised airlight tail S(X, Y)
    surface_glow)   # log G(T, theta_s)
set(EFFECT_FRAME 1)
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_GLSL_LAYOUT airlight_layout.glsl)  # the tables' sizes and ranges
set(EFFECT_GLSL_TERMS lamp_terms.glsl)
set(EFFECT_HOOKS
    surface_irradiance=point_light_irradiance  # direct light and glow on surfaces
    emitter_hit=point_lights_emitter_hit       # the lamps' spheres
    view_glow=point_lights_view_glow           # the airlight
    pixel_cores=point_lights_pixel_cores)      # lamps smaller than a pixel
set(EFFECT_LAYERS
    "lamps=the point lamps' light scattered toward the camera by the homogeneous medium (once, and more often where multiple scattering is on)")
