// The photo effect's frame data (EFFECT_GLSL_LAYOUT: 4-byte scalars in groups
// of four, vec4, ivec4, so std140 and C++ agree).
struct PhotoGpu {
    vec4 atmospheric_light;  // rgb: the homogeneous medium's atmospheric light A (W/(m^2 sr))
    vec4 intrinsics;         // fx, fy, cx, cy (pixels) of the backplate's camera; fx = 0: the film's pinhole
    int depth_along_axis;    // 1: the backplate's depth is along the optical axis (a z-buffer), 0: along the ray
    int unused_int0;
    int unused_int1;
    int unused_int2;
};
