// GL-only: the resources behind the accessors that the shared code uses.
// (The CPU backend defines the same accessors over its own arrays.)
layout(std140, binding = 0) uniform FrameBlock { FrameUniforms frame; };
layout(std430, binding = 1) readonly buffer PointLightBlock { PointLightGpu point_lights[]; };
layout(std430, binding = 2) readonly buffer SurfaceBlock { SurfaceGpu surfaces[]; };

int point_light_count() { return frame.film_counts.z; }
PointLightGpu point_light(int i) { return point_lights[i]; }
int surface_count() { return frame.film_counts.w; }
SurfaceGpu surface(int i) { return surfaces[i]; }
layout(std430, binding = 3) readonly buffer BvhBlock { BvhNodeGpu bvh_nodes[]; };
layout(std430, binding = 4) readonly buffer SpotLightBlock { SpotLightGpu spot_lights[]; };
int spot_light_count() { return frame.light_counts.x; }
SpotLightGpu spot_light(int i) { return spot_lights[i]; }
BvhNodeGpu bvh_node(int i) { return bvh_nodes[i]; }

// Scattering tables (cpp/tables.cpp), read texel by texel: the shared code
// interpolates them itself so that GPU and CPU results agree exactly.
layout(binding = 0) uniform sampler2D airlight_tail_texels;
layout(binding = 1) uniform sampler2D surface_glow_texels;
layout(binding = 2) uniform sampler2D spot_moment_texels;
layout(binding = 3) uniform sampler2D phase_moment_texels0;  // per phase lobe (phase.glsl)
layout(binding = 4) uniform sampler2D phase_moment_texels1;
layout(binding = 5) uniform sampler2D phase_glow_texels0;
layout(binding = 6) uniform sampler2D phase_glow_texels1;
layout(binding = 7) uniform sampler2D sky_texels;  // the sky-phase table (sky.glsl)

vec4 sky_table_texel(int x, int y) {
    return texelFetch(sky_texels, ivec2(x, y), 0);
}

layout(binding = 8) uniform sampler2D rainbow_texels;  // the rainbow table (sky.glsl)

vec4 rainbow_table_texel(int x) {
    return texelFetch(rainbow_texels, ivec2(x, 0), 0);
}

float table_texel(int table, int x, int y) {
    if (table == TABLE_AIRLIGHT_TAIL) return texelFetch(airlight_tail_texels, ivec2(x, y), 0).r;
    if (table == TABLE_PHASE_GLOW_0) return texelFetch(phase_glow_texels0, ivec2(x, y), 0).r;
    if (table == TABLE_PHASE_GLOW_1) return texelFetch(phase_glow_texels1, ivec2(x, y), 0).r;
    return texelFetch(surface_glow_texels, ivec2(x, y), 0).r;
}

vec4 table_texel4(int table, int x, int y) {
    if (table == TABLE_PHASE_MOMENTS_0) return texelFetch(phase_moment_texels0, ivec2(x, y), 0);
    if (table == TABLE_PHASE_MOMENTS_1) return texelFetch(phase_moment_texels1, ivec2(x, y), 0);
    return texelFetch(spot_moment_texels, ivec2(x, y), 0);
}
