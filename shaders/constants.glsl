// Constants shared by every shader file, the table builder (effects/lamp_airlight/airlight_tables.cpp)
// and the CPU backend.

CONST float PI = 3.14159265358979f;
CONST float NO_HIT = 3.0e38f;  // "infinitely far" distance along a ray
// Lamp cores whose projected radius is below this many pixels are
// box-filtered onto the film instead of being hit by pixel rays
// (lamp_subpixel_cores in shading.glsl).
CONST float LAMP_SUBPIXEL_RADIUS = 1.0f;

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


// Spot moments (effects/spotlights/docs/spot_table.md): RGBA texel (S, M1/N1, M2/N2, 0) on the
// airlight tail's grid, M1 = <sin 2(xi - v)>, M2 = <sin^2(xi - v)> the local
// moments of the normalised tail weight, N1 = cv/(1 + lam cv/2), N2 = N1^2/2.

// Anisotropic phase functions (effects/phase/docs/phase_table.md): per lobe, an RGBA slice
// (S_p, M1_p/N1_p, M2_p/N2_p, 0) on the airlight tail's size in the lobe's
// coordinates (phase_math.glsl), and a log G slice of the surface glow's size.
// |g| is clamped here for rendering: past it the tables' error grows
// (1.6e-3 at 0.9999, 6.4e-3 at -0.999; effects/phase/docs/phase_table.md section 0).
CONST float PHASE_G_LIMIT = 0.999f;

// ---- Daytime sky and atmosphere (effects/daytime/physics.md; effects/daytime/docs/daytime.md) ----
CONST int SKY_NONE = 0;
CONST int SKY_OVERCAST = 1;
CONST int SKY_CIE = 2;
// The altitude levels that split view rays into scattering volumes: the
// quality knob's levels plus the profiles' breaks, the ground and the top.
CONST int ATMOSPHERE_MAX_LEVELS = 80;
// A volume whose species' shares change fast is cut into at most this many
// parts (sky.glsl, volume_parts); the walk along a ray is bounded by
// ATMOSPHERE_MAX_VOLUMES steps, enough for every level crossed cut this finely.
CONST int VOLUME_MAX_PARTS = 16;
CONST int ATMOSPHERE_MAX_VOLUMES = (ATMOSPHERE_MAX_LEVELS + 2) * VOLUME_MAX_PARTS;
// Sky-phase table (effects/daytime/sky.cpp, sky.glsl): per kernel k (RGB: the three
// species' phase functions, A: the clamped cosine of irradiance)
//   F_k(C, d) = int_{w_y > 0} shape(w) exp(-C / w_y) k(d . w) dw,
// stored as log(F e^C + SKY_TABLE_FLOOR) on a node-aligned grid:
//   X = sqrt(log(1 + C / C0) / log(1 + C_MAX / C0))   (NC columns),
//   elevation of d uniform in [-pi/2, pi/2]            (N_ELEVATION rows),
//   azimuth of d from the sun's, uniform in [0, pi]    (N_AZIMUTH blocks of rows; 1 for skies without a sun).
CONST int SKY_TABLE_NC = 64;
CONST int SKY_TABLE_N_ELEVATION = 64;
CONST int SKY_TABLE_N_AZIMUTH = 32;
CONST float SKY_TABLE_C0 = 0.01f;
CONST float SKY_TABLE_C_MAX = 100.0f;
CONST float SKY_TABLE_FLOOR = 1.0e-12f;
