// The daytime sky and atmosphere's frame data and constants (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

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

// The sky dome and the sun (effects/daytime/physics.md; sky.glsl).
struct SkyGpu {
    vec4 zenith_radiance;  // rgb: Lz; w: model (SKY_NONE, SKY_OVERCAST, SKY_CIE)
    vec4 gradation;        // x: a, y: b, z: 1 / (phi(0) f(Z_s)) (CIE normaliser)
    vec4 indicatrix;       // x: c, y: d, z: e, w: exp(d pi / 2)
    vec4 sun_direction;    // xyz: unit vector toward the sun; w: 1 when the sun lights the scene (above the horizon)
    vec4 sun_irradiance;   // rgb: irradiance on a plane facing the sun at the top of the atmosphere (W/m^2)
};

// One particle species of the atmosphere (sky.glsl): extinction and
// scattering at relative density 1 times a piecewise exponential relative
// density rho(y) = value_k exp(-(y - start_k) inv_scale_k) on [start_k,
// start_{k+1}) (4 pieces; unused pieces start at NO_HIT).
struct SpeciesGpu {
    vec4 sigma_t;      // rgb: extinction (1/m) at rho = 1
    vec4 sigma_s;      // rgb: scattering (1/m) at rho = 1
    vec4 phase;        // x: HG g, y: 1 for Rayleigh, z: 1 when present
    vec4 starts;       // altitudes where the pieces start (x = 0)
    vec4 values;       // rho at each piece's start
    vec4 inv_scales;   // 1 / scale height of each piece (0: constant, < 0: growing)
};

// The atmosphere's particle species, FrameUniforms::species's indices.
CONST int SPECIES_MOLECULES = 0;
CONST int SPECIES_AEROSOL = 1;
CONST int SPECIES_RAIN = 2;
CONST int SPECIES_COUNT = 3;

// The atmosphere's altitude levels and sky-phase table size (frame.atmosphere).
struct AtmosphereGpu {
    float top;                       // top altitude (m): empty above
    float level_count;               // levels in use
    float sky_table_columns;         // columns of the sky-phase table (1: C = 0 only)
    float sky_table_azimuth_blocks;  // its blocks of rows by azimuth (1: no sun)
    vec4 levels[ATMOSPHERE_MAX_LEVELS / 4];  // sorted level altitudes, 4 per vec4 (sky.glsl)
};

// The aerial table (aerial_table.glsl; effects/daytime/docs/aerial_table.md):
// distance nodes from AERIAL_NEAR expm1(0) = 0 to AERIAL_FAR (m), log-spaced, and the whole ray.
CONST float AERIAL_NEAR = 1.0f;
CONST float AERIAL_FAR = 1.0e6f;
// The parts of the aerial table's texels: optical depth, then each species'
// sunlight, the medium's sunlight, each species' residual beam (column
// group g holds nodes g N .. g N + N - 1).
CONST int AERIAL_OPTICAL_DEPTH = 0;
CONST int AERIAL_SUN = 1;       // + species
CONST int AERIAL_MEDIUM_SUN = 4;
CONST int AERIAL_RESIDUAL = 5;  // + species
CONST int AERIAL_GROUPS = 8;
CONST int AERIAL_MAX_TEXTURE_ROWS = 16384;  // the diffuse table's rows x azimuth blocks, at most
struct AerialGpu {
    vec4 size;      // x: elevation rows, y: azimuth blocks, z: distance nodes (the last: the whole ray)
    vec4 sun_axes;  // xy: horizontal unit vector (x, z) toward the sun's azimuth, zw: the one across
};
