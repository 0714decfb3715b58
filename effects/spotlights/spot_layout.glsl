// The spotlights's frame data and constants (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

// Spot moments (effects/spotlights/docs/spot_table.md): RGBA texel (S, M1/N1, M2/N2, 0) on the
// airlight tail's grid, M1 = <sin 2(xi - v)>, M2 = <sin^2(xi - v)> the local
// moments of the normalised tail weight, N1 = cv/(1 + lam cv/2), N2 = N1^2/2.

// The spotlights' part of FrameUniforms (frame.spot).
struct SpotUniforms {
    float glow_samples;  // quadrature nodes of a spot's surface glow (spot_surface_glow)
    float unused0;
    float unused1;
    float unused2;
};
