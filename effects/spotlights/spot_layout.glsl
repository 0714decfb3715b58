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
    ivec4 tiles;  // the spots' screen tiles (physics.md section 9): x, y: tiles along x and down,
                  // z: unused, w: a tile's edge in pixels (0: no lists, every ray walks every spot)
};

// The spots' screen tiles' edge in pixels, and texels per row of their table.
CONST int SPOT_TILE_SIZE = 16;
CONST int SPOT_ROW_TEXELS = 2048;
