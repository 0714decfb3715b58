// Data layout shared by the GL backend (uniform and storage buffers) and the
// CPU backend (the same structs compiled as C++ against GLM). Only vec4/ivec4
// members, so std140/std430 and C++ agree byte for byte.

// Buffer bindings of the frame's data (resources.glsl on GL; the CPU reads FrameData).
CONST int BINDING_FRAME = 0;        // uniform block: FrameUniforms
CONST int BINDING_POINT_LIGHTS = 1;  // storage blocks: PointLightGpu[], SurfaceGpu[], BvhNodeGpu[], SpotLightGpu[]
CONST int BINDING_SURFACES = 2;
CONST int BINDING_BVH_NODES = 3;
CONST int BINDING_SPOT_LIGHTS = 4;
CONST int BINDING_OUTPUTS = 5;       // storage block written by the shading pass: the render outputs (outputs_layout.glsl)

// An isotropic point lamp (effects/lamp_airlight/physics.md): a sphere of radius r emitting
// radiant intensity I (W/sr), hence radiance I / (pi r^2) on its disc.
struct PointLightGpu {
    vec4 position_radius;  // xyz: centre, w: radius (m)
    vec4 intensity;        // rgb: W/sr, w: 1 with volumetric shadows (effects/light_shafts/physics.md section 7)
};

// A spotlight (effects/spotlights/physics.md): profile I(theta) = I0 [(1 - q)(cos theta -
// cos A)/(1 - cos A) + q] for theta <= A, theta measured from the axis; a
// sphere of radius r like a point lamp. Quantities that lose precision in
// float32 (position relative to the camera, sin^2 A, 1 - cos A) are formed in
// double on the CPU (effects/spotlights/docs/spot_table.md, section 4).
struct SpotLightGpu {
    vec4 relative_position_radius;  // xyz: S - camera position, w: radius (m)
    vec4 world_position;            // xyz: S
    vec4 axis_cos;                  // xyz: unit axis a, w: cos A
    vec4 intensity_edge;            // rgb: I0 (W/sr on the axis), w: edge softness q
    vec4 cone;                      // x: sin^2 A, y: 1 - cos A, z: beta = (1 - q) / (1 - cos A), w: 1 with volumetric shadows
};

// A Lambertian surface. type (albedo_type.w, exact small integer):
//   0 plane:  p0 = point, p1 = unit normal
//   1 box:    p0 = min corner, p1 = max corner
//   2 sphere: p0 = centre, p1.x = radius
struct SurfaceGpu {
    vec4 p0;
    vec4 p1;
    vec4 albedo_type;
};

// A node of the bounding volume hierarchy over the bounded surfaces (boxes,
// spheres), built by cpp/frame_data.cpp. Inner node: children first and
// first + 1; leaf: surfaces [first, first + count).
struct BvhNodeGpu {
    vec4 lo;     // xyz: box min
    vec4 hi;     // xyz: box max
    ivec4 info;  // x: first, y: count (0 for an inner node)
};

CONST int BVH_STACK_SIZE = 32;  // depth bound of a median-split tree of < 2^31 surfaces

CONST int SURFACE_PLANE = 0;
CONST int SURFACE_BOX = 1;
CONST int SURFACE_SPHERE = 2;
