// Per-frame constants (std140 uniform block on the GPU; FrameData::frame on
// the CPU): the core's fields, then each effect's members, declared in its
// effect.cmake (EFFECT_UNIFORMS) with their structs in its EFFECT_GLSL_LAYOUT
// file; AIRLIGHT_EFFECT_UNIFORMS (generated, airlight_registry.glsl) lists them.
struct FrameUniforms {
    vec4 camera_position;  // xyz: pinhole position
    vec4 camera_right;     // xyz: right vector scaled by tan(fov_y / 2) * aspect
    vec4 camera_up;        // xyz: up vector scaled by tan(fov_y / 2)
    vec4 camera_forward;   // xyz: unit view direction
    vec4 sigma_t;          // rgb: medium extinction (1/m); 0 in clear air
    vec4 sigma_s;          // rgb: medium scattering (1/m) = albedo * sigma_t
    vec4 background;       // rgb: radiance of escaping rays, before attenuation
    // Scalars in groups of four (std140 packs them as C++ does; a vec4 after a full group stays aligned).
    int film_width;           // pixels
    int film_height;
    int point_light_count;    // point_lights[0, n)
    int surface_count;        // surfaces[0, n): the planes, then the bounded surfaces in BVH leaf order
    int plane_count;          // surfaces[0, n) are planes (tested one by one)
    int bvh_node_count;       // BVH nodes over the bounded surfaces (0: none)
    int tile_origin_x;        // pixel origin of the tile being drawn (GL backend; 0 on the CPU)
    int tile_origin_y;
    int spot_light_count;     // spot_lights[0, n)
    int loop_guard_iterations;  // GL: iterations of render.frag's loop-limit guard (2); 0 on the CPU
    int tile_width;           // GL: width of the tile being drawn (its render outputs' rows)
    int unused_int1;
    float cull_fraction;      // contributions provably below this fraction of the pixel are skipped
    float march_steps;        // brute-force ray marching (quality.airlight "march"): steps per ray
    float march_far;          // ... and the distance (m) where escaping rays are cut
    float unused_float0;
    AIRLIGHT_EFFECT_UNIFORMS
};
