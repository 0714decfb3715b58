// The medium's phase function's frame data and constants (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

// Anisotropic phase functions (effects/phase/docs/phase_table.md): per lobe, an RGBA slice
// (S_p, M1_p/N1_p, M2_p/N2_p, 0) on the airlight tail's size in the lobe's
// coordinates (phase_math.glsl), and a log G slice of the surface glow's size.
// |g| is clamped here for rendering: past it the tables' error grows
// (1.6e-3 at 0.9999, 6.4e-3 at -0.999; effects/phase/docs/phase_table.md section 0).
CONST float PHASE_G_LIMIT = 0.999f;

// One lobe of an anisotropic phase function (phase_math.glsl).
struct PhaseLobeGpu {
    vec4 shape;  // k = (1 - g) / (1 + g), sqrt k, c = min(k, sqrt k), 1 / (1 - g)
    vec4 info;   // x: g, y: 1 for Rayleigh, z: glow row-warp floor K_min, w: weight in the mixture
};

// The phase function's part of FrameUniforms (frame.phase).
struct PhaseUniforms {
    PhaseLobeGpu lobe0;
    PhaseLobeGpu lobe1;
    int lobe_count;        // lobes of the medium's phase function (0: isotropic)
    float airlight_bound;  // int_0^{pi/2} P dt (airlight culling; pi/2 isotropic)
    float glow_bound;      // max G (glow culling)
    float unused;
};
