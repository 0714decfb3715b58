// Data layout shared by the GL backend (uniform and storage buffers) and the
// CPU backend (the same structs compiled as C++ against GLM). Only vec4/ivec4
// members, so std140/std430 and C++ agree byte for byte.

// One lobe of an anisotropic phase function (phase_math.glsl).
struct PhaseLobeGpu {
    vec4 shape;  // k = (1 - g) / (1 + g), sqrt k, c = min(k, sqrt k), 1 / (1 - g)
    vec4 info;   // x: g, y: 1 for Rayleigh, z: glow row-warp floor K_min, w: weight in the mixture
};

// The sky dome and the sun (MODELS.md section 3; sky.glsl).
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

// Per-frame constants (std140 uniform block on the GPU).
struct FrameUniforms {
    vec4 camera_position;  // xyz: pinhole position
    vec4 camera_right;     // xyz: right vector scaled by tan(fov_y / 2) * aspect
    vec4 camera_up;        // xyz: up vector scaled by tan(fov_y / 2)
    vec4 camera_forward;   // xyz: unit view direction
    vec4 sigma_t;          // rgb: medium extinction (1/m); 0 in clear air
    vec4 sigma_s;          // rgb: medium scattering (1/m) = albedo * sigma_t
    vec4 background;       // rgb: radiance of escaping rays, before attenuation
    ivec4 film_counts;     // x: width, y: height, z: point lights, w: surfaces
    vec4 quality;          // x: cull fraction, y: march steps, z: march far distance (m), w: spot glow samples (spot_surface_glow)
    ivec4 geometry_counts; // x: planes (surfaces [0, x)), y: BVH nodes over the other surfaces,
                           // zw: pixel origin of the tile being drawn (GL backend; 0 on the CPU)
    ivec4 light_counts;    // x: spot lights, y: phase lobes (0: isotropic medium)
    vec4 phase_bounds;     // x: int_0^{pi/2} P dt (airlight culling; pi/2 isotropic), y: max G (glow culling)
    PhaseLobeGpu phase_lobe0;
    PhaseLobeGpu phase_lobe1;
    SkyGpu sky;
    SpeciesGpu species[3];  // molecules, aerosol, rain (phase.z = 0 when absent)
    vec4 atmosphere;        // x: top altitude (empty above), y: altitude levels, z: sky table columns (1: C = 0 only), w: its azimuth blocks
    vec4 altitude_levels[ATMOSPHERE_MAX_LEVELS / 4];  // sorted level altitudes, 4 per vec4 (sky.glsl)
};

// An isotropic point lamp (MODELS.md section 1): a sphere of radius r emitting
// radiant intensity I (W/sr), hence radiance I / (pi r^2) on its disc.
struct PointLightGpu {
    vec4 position_radius;  // xyz: centre, w: radius (m)
    vec4 intensity;        // rgb: W/sr
};

// A spotlight (MODELS.md section 2): profile I(theta) = I0 [(1 - q)(cos theta -
// cos A)/(1 - cos A) + q] for theta <= A, theta measured from the axis; a
// sphere of radius r like a point lamp. Quantities that lose precision in
// float32 (position relative to the camera, sin^2 A, 1 - cos A) are formed in
// double on the CPU (docs/spot_table.md, section 4).
struct SpotLightGpu {
    vec4 relative_position_radius;  // xyz: S - camera position, w: radius (m)
    vec4 world_position;            // xyz: S
    vec4 axis_cos;                  // xyz: unit axis a, w: cos A
    vec4 intensity_edge;            // rgb: I0 (W/sr on the axis), w: edge softness q
    vec4 cone;                      // x: sin^2 A, y: 1 - cos A, z: beta = (1 - q) / (1 - cos A)
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
