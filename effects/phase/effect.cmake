# Anisotropic phase functions (HG, Rayleigh, two-lobe HG) for the lamps' and
# spots' airlight and glow (physics.md; effects/phase/docs/phase_table.md).
set(EFFECT_SOURCES phase_tables.cpp phase_frame.cpp)
set(EFFECT_GLSL_MATH phase_math.glsl)
set(EFFECT_GLSL_PIXEL phase.glsl)
set(EFFECT_FEATURES
    phase=HAS_PHASE)   # an anisotropic phase function; else isotropic
set(EFFECT_TABLES
    phase_moments_0     # per lobe: (S_p, M1_p/N1_p, M2_p/N2_p, 0)
    phase_moments_1
    phase_glow_0        # per lobe: log G_p
    phase_glow_1)
set(EFFECT_FRAME 1)
set(EFFECT_FRAME_TABLES 1)
set(EFFECT_GLSL_LAYOUT phase_layout.glsl)
set(EFFECT_UNIFORMS "PhaseUniforms phase")
