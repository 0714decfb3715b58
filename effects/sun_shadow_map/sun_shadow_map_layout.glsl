// The sun's shadow map's frame data and constants (EFFECT_GLSL_LAYOUT: compiled after
// shaders/constants.glsl, before FrameUniforms in shaders/frame.glsl; 4-byte
// scalars in groups of four, vec4, ivec4, so std140 and C++ agree).

// The sun's shadow map (effects/sun_shadow_map): an orthographic grid seen
// along the sunlight; texel (i, j) is centred at origin + (i + 1/2) w axis_u +
// (j + 1/2) w axis_v on the map's top plane (w: the texel size).
struct SunShadowMapGpu {
    vec4 origin;  // xyz: the grid's corner on the top plane, w: texel size (m)
    vec4 axis_u;  // xyz: unit axis across the sunlight, w: texels along it
    vec4 axis_v;  // xyz: the other unit axis, w: texels along it
    vec4 depth;   // x: depth (m) of the casters' box below the top plane, y: float32 rounding bias (m)
};

