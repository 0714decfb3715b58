// Data layout shared by the GL backend (uniform and storage buffers) and the
// CPU backend (the same structs compiled as C++ against GLM). Only vec4/ivec4
// members, so std140/std430 and C++ agree byte for byte.

// One lobe of an anisotropic phase function (phase_math.glsl).
struct PhaseLobeGpu {
    vec4 shape;  // k = (1 - g) / (1 + g), sqrt k, c = min(k, sqrt k), 1 / (1 - g)
    vec4 info;   // x: g, y: 1 for Rayleigh, z: glow row-warp floor K_min, w: weight in the mixture
};

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

// Buffer bindings of the frame's data (resources.glsl on GL; the CPU reads FrameData).
CONST int BINDING_FRAME = 0;        // uniform block: FrameUniforms
CONST int BINDING_POINT_LIGHTS = 1;  // storage blocks: PointLightGpu[], SurfaceGpu[], BvhNodeGpu[], SpotLightGpu[]
CONST int BINDING_SURFACES = 2;
CONST int BINDING_BVH_NODES = 3;
CONST int BINDING_SPOT_LIGHTS = 4;

// The atmosphere's particle species, FrameUniforms::species's indices.
CONST int SPECIES_MOLECULES = 0;
CONST int SPECIES_AEROSOL = 1;
CONST int SPECIES_RAIN = 2;
CONST int SPECIES_COUNT = 3;

// The sun's shadow map (effects/sun_shadow_map): an orthographic grid seen
// along the sunlight; texel (i, j) is centred at origin + (i + 1/2) w axis_u +
// (j + 1/2) w axis_v on the map's top plane (w: the texel size).
struct SunShadowMapGpu {
    vec4 origin;  // xyz: the grid's corner on the top plane, w: texel size (m)
    vec4 axis_u;  // xyz: unit axis across the sunlight, w: texels along it
    vec4 axis_v;  // xyz: the other unit axis, w: texels along it
    vec4 depth;   // x: depth (m) of the casters' box below the top plane, y: float32 rounding bias (m)
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
    int phase_lobe_count;     // lobes of the medium's phase function (0: isotropic)
    int loop_guard_iterations;  // GL: iterations of render.frag's loop-limit guard (2); 0 on the CPU
    int unused_int1;
    float cull_fraction;      // contributions provably below this fraction of the pixel are skipped
    float march_steps;        // brute-force ray marching (quality.airlight "march"): steps per ray
    float march_far;          // ... and the distance (m) where escaping rays are cut
    float spot_glow_samples;  // quadrature nodes of a spot's surface glow (spot_surface_glow)
    float phase_airlight_bound;  // int_0^{pi/2} P dt (airlight culling; pi/2 isotropic)
    float phase_glow_bound;      // max G (glow culling)
    float unused_float0;
    float unused_float1;
    PhaseLobeGpu phase_lobe0;
    PhaseLobeGpu phase_lobe1;
    SkyGpu sky;
    SpeciesGpu species[SPECIES_COUNT];  // SPECIES_MOLECULES, SPECIES_AEROSOL, SPECIES_RAIN (phase.z = 0 when absent)
    float atmosphere_top;            // top altitude (m): empty above
    float altitude_level_count;      // altitude_levels in use
    float sky_table_columns;         // columns of the sky-phase table (1: C = 0 only)
    float sky_table_azimuth_blocks;  // its blocks of rows by azimuth (1: no sun)
    vec4 altitude_levels[ATMOSPHERE_MAX_LEVELS / 4];  // sorted level altitudes, 4 per vec4 (sky.glsl)
    SunShadowMapGpu sun_shadow_map;
};

// An isotropic point lamp (effects/lamp_airlight/physics.md): a sphere of radius r emitting
// radiant intensity I (W/sr), hence radiance I / (pi r^2) on its disc.
struct PointLightGpu {
    vec4 position_radius;  // xyz: centre, w: radius (m)
    vec4 intensity;        // rgb: W/sr
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
