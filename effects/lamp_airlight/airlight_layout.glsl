// The lamp airlight's frame data and constants (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

// ---- Tables -------------------------------------------------------------
// Normalised airlight tail S(X, Y) (effects/lamp_airlight/docs/airlight_table.md):
//   Q(u, xi) = e^{u tan xi} int_xi^{pi/2} e^{-u tan t} dt = N(u, xi) S(X, Y),
//   N = cv / (1 + u sec^2(xi) cv),  cv = pi/2 - xi,
//   X = sqrt(z / (1 + z)), z = u sec xi,   Y = xi / (pi/2).
// X in [0, 1] covers every u >= 0, so no range is left outside the table.
CONST int AIRLIGHT_TAIL_NX = 256;
CONST int AIRLIGHT_TAIL_NY = 64;

// Surface glow G(T, theta_s) = e^{T} G0(T, theta_s) (effects/lamp_airlight/physics.md,
// "surfaces lit through fog"), X = sqrt(T / T_max), Y warped in cos theta_s
// (surface_glow() in airlight.glsl). The factor e^{-T} G underflows float32
// gradually (denormals) from T ~ 90 and is exactly 0 long before T_max, so
// the glow goes continuously to 0 inside the table; past T_max the lookup is
// clamped to the last column (of no consequence: e^{-200} = 0 in float32).
CONST int SURFACE_GLOW_NX = 256;
CONST int SURFACE_GLOW_NY = 128;
CONST float SURFACE_GLOW_T_MAX = 200.0f;
CONST float SURFACE_GLOW_T_SCALE = 0.05f;
// An upper bound of G over all (T, theta_s), for the culling bounds of the
// point lamps' and the spots' glow: G is largest at T = 0, theta_s = 0, where
// G = pi^2/2 + pi = 8.0762 (effects/lamp_airlight/tests/test_tables.cpp checks both).
CONST float SURFACE_GLOW_G_BOUND = 8.08f;
// The floor of the row warp's scale K = max(T, K_min) (surface_glow_log_lookup).
CONST float SURFACE_GLOW_K_MIN = 1.0e-4f;
