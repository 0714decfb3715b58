// The particle clouds' frame data (EFFECT_GLSL_LAYOUT; physics.md sections
// 3 and 6): the lighting table's shape and the screen tiles' grid. The
// particles and the tiles' lists are tables (particle_frame.cpp).

// Texels per row of the particle and tile tables (two RGBA texels a particle).
CONST int PARTICLE_ROW_TEXELS = 2048;
// The screen tiles' edge in pixels (section 6; quality.particle_compositing "tiles").
CONST int PARTICLE_TILE_SIZE = 16;
// A pixel's compositing stops once the particles in front pass less than
// this fraction of the light behind them (section 6).
CONST float PARTICLE_OPAQUE = 1.0e-4f;

struct ParticleCloudsGpu {
    ivec4 table_shape;  // the lighting table's nodes: x entry angles, y view zeniths, z view azimuths, w optical radii
    vec4 table_taus;    // x: the smallest optical radius, y: ln(largest / smallest), z: the droplets' g,
                        // w: 1 where the entry angles are dense across the terminator (particle_table_math.glsl)
    ivec4 tiles;        // x, y: screen tiles along x and down, z: particles, w: a tile's edge in pixels
    vec4 shadow_map;    // the shadow below (physics.md section 5): x, y: its corner's x, z (m), z: 1 / its extent (1/m),
                        // w: the plane's height (m)
    ivec4 shadow_size;  // x: the map's nodes per side (0: no shadow), y, z, w: unused
    vec4 air_shadow;    // the particles' shadow in the air (physics.md section 5): x: the highest sphere's top (m),
                        // y: pieces of the air (quality.cloud_shadow_steps; 0: unshadowed), z, w: unused
};
