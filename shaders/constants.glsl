// Constants shared by every shader file, the table builder (effects/lamp_airlight/airlight_tables.cpp)
// and the CPU backend.

CONST float PI = 3.14159265358979f;
CONST float NO_HIT = 3.0e38f;  // "infinitely far" distance along a ray
// Lamp cores whose projected radius is below this many pixels are
// box-filtered onto the film instead of being hit by pixel rays
// (the pixel_cores hooks; shaders/lights.glsl).
CONST float LAMP_SUBPIXEL_RADIUS = 1.0f;

// Each effect's own constants are in its EFFECT_GLSL_LAYOUT file (effects/<name>/*_layout.glsl).
