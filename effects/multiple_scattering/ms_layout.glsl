// The multiple-scattering field's frame data and constants (EFFECT_GLSL_LAYOUT;
// effects/multiple_scattering/physics.md section 9). 4-byte scalars in groups
// of four and vec4, so std140 and C++ agree.

// The table TABLE_MS_FIELD (ms_tables.cpp builds it from the plane-parallel
// solution; ms_field.glsl reads it): one column per solver level (altitude
// frame.multiple_scattering.levels[k]), and blocks of rows:
//   K_i(y, d), species i = 0..2: MS_VIEW_ELEVATIONS rows (elevation of the
//     look direction d uniform in [-pi/2, pi/2]) per azimuth block (azimuth
//     from the sun's uniform in [0, pi]; view_azimuths blocks, 1 without a
//     sun or an azimuth-dependent sky), rgb per channel;
//   E(y, n): the diffuse irradiance on a surface of normal n, MS_NORMAL_ELEVATIONS
//     rows per azimuth block (normal_azimuths blocks), starting at irradiance_row;
//   E_res(y): the sun's forward-scattered residual beam, one row at residual_row.
CONST int MS_MAX_LEVELS = 192;
CONST int MS_VIEW_ELEVATIONS = 65;
CONST int MS_VIEW_AZIMUTHS = 37;
CONST int MS_NORMAL_ELEVATIONS = 17;
CONST int MS_NORMAL_AZIMUTHS = 13;

struct MultipleScatteringGpu {
    float level_count;     // solver levels in use (the table's width)
    float view_azimuths;   // azimuth blocks of K (1 or MS_VIEW_AZIMUTHS)
    float normal_azimuths; // azimuth blocks of E (1 or MS_NORMAL_AZIMUTHS)
    float irradiance_row;  // first row of E
    float residual_row;    // the row of E_res
    float air_scattering;  // 1: the air scatters (K, E_res); 0: the ground's reflection only (E)
    float pad1;
    float pad2;
    vec4 levels[MS_MAX_LEVELS / 4];  // the levels' altitudes (m), ascending from 0, 4 per vec4
};
