// The falling rain's frame data (EFFECT_GLSL_LAYOUT; physics.md sections 4
// and 5): the screen tiles' grid and the optics table's shape. The drops and
// the tiles' lists are tables (rain_frame.cpp).

// Texels per row of the drop, tile and light tables.
CONST int RAIN_ROW_TEXELS = 2048;
// The screen tiles' edge in pixels, halved on small films (section 5).
CONST int RAIN_TILE_SIZE = 16;
// Bins of the drop's phase function over theta in [0, pi] (section 4).
CONST int DROP_OPTICS_BINS = 720;
// The environment map's texels: longitude, and the direction's y in equal steps (equal solid angles).
CONST int RAIN_ENV_WIDTH = 64;
CONST int RAIN_ENV_HEIGHT = 32;
// Streaks are cut at this distance in front of the camera (m).
CONST float RAIN_NEAR = 0.05f;

// Texels of the near rain's compensated optical depth over [0, radius] (section 2).
CONST int RAIN_NEAR_DEPTH_TEXELS = 256;

struct FallingRainGpu {
    ivec4 tiles;      // x, y: screen tiles along x and down, z: drops, w: a tile's edge in pixels
    vec4 near_depth;  // x: the rain_near_depth table's reach (m); y: 1 where the medium's rain is compensated
};
