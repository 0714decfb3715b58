// The noise clouds' frame data (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

// Texels per side of the two tiling noise textures (physics.md section 1).
CONST int CLOUD_SHAPE_SIZE = 128;
CONST int CLOUD_DETAIL_SIZE = 32;

// The cloud layer (physics.md): its extent, density parameters and march.
struct CloudsGpu {
    vec4 layer;     // x: base (m), y: top (m), z: 1 / (top - base), w: extinction at density 1 (1/m)
    vec4 tiles;     // x: 1 / shape_scale, y: 1 / detail_scale (tiles per metre), z, w: unused
    vec4 offsets;   // the wind's drift in tile units, fract(wind time / scale): x, y shape (along x, z), z, w detail
    vec4 density;   // x: coverage, y: type, z: erosion, w: albedo
    vec4 lighting;  // x: Henyey-Greenstein g, y: view steps across the layer, z: light steps,
                    // w: pieces of the air in the clouds' shadow (quality.cloud_shadow_steps; 0: unshadowed)
    vec4 octaves;   // multiple scattering's octaves (physics.md eq. 6.1): x: a, y: b, z: c, w: their count (1: single)
    vec4 weather;   // the weather map (CLOUDS_WEATHER_MAP; section 8): x, y: 1 / size along x, z (1/m),
                    // z, w: fract(the map's corner + wind time, over the size) along x, z
    ivec4 weather_texels;  // x, y: the map's width and height in texels, z, w: unused
    vec4 phase;     // x: the second lobe's g, y: its weight (eq. 3.4), z: the powder term's strength (eq. 3.5), w: unused
};
