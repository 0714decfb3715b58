// GL-only: the resources behind the accessors that the shared code uses.
// (The CPU backend defines the same accessors over its own arrays.)
layout(std140, binding = BINDING_FRAME) uniform FrameBlock { FrameUniforms frame; };
layout(std430, binding = BINDING_POINT_LIGHTS) readonly buffer PointLightBlock { PointLightGpu point_lights[]; };
layout(std430, binding = BINDING_SURFACES) readonly buffer SurfaceBlock { SurfaceGpu surfaces[]; };

int point_light_count() { return frame.point_light_count; }
PointLightGpu point_light(int i) { return point_lights[i]; }
int surface_count() { return frame.surface_count; }
SurfaceGpu surface(int i) { return surfaces[i]; }
layout(std430, binding = BINDING_BVH_NODES) readonly buffer BvhBlock { BvhNodeGpu bvh_nodes[]; };
layout(std430, binding = BINDING_SPOT_LIGHTS) readonly buffer SpotLightBlock { SpotLightGpu spot_lights[]; };
int spot_light_count() { return frame.spot_light_count; }
SpotLightGpu spot_light(int i) { return spot_lights[i]; }
BvhNodeGpu bvh_node(int i) { return bvh_nodes[i]; }
// The render outputs of the tile being drawn (RENDER_OUTPUTS): OUTPUT_FLOATS per
// pixel, pixels in rows of the tile's width (render.frag).
layout(std430, binding = BINDING_OUTPUTS) writeonly buffer OutputBlock { float tile_outputs[]; };

// The tables of the shading pass (effects/lamp_airlight/airlight_tables.hpp), one sampler per slot of
// the registry (TABLE_*, generated from the effects' EFFECT_TABLES), read
// texel by texel: the shared code interpolates them itself so that GPU and CPU
// results agree exactly. Binding i holds slot i (gl_backend.cpp).
layout(binding = 0) uniform sampler2D table_samplers[TABLE_COUNT];

float table_texel(int table, int x, int y) {
    return texelFetch(table_samplers[table], ivec2(x, y), 0).x;
}

vec4 table_texel4(int table, int x, int y) {
    return texelFetch(table_samplers[table], ivec2(x, y), 0);
}
