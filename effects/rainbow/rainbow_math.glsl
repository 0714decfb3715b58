// The rainbow's constants, shared by its table builder (rainbow_rgb.cpp) and
// the shading pass (rainbow.glsl).

// Rainbow table (effects/rainbow/rainbow_rgb.cpp, rainbow.glsl): the raindrops' linear-sRGB phase
// function seen through the sun's disc, at scattering angles a * 180 / (N - 1)
// degrees: 0.05 degree, the spectral table's finest step (its bows are smooth
// on that scale after the 0.53-degree disc; effects/rainbow/docs/rainbow.md).
CONST int RAINBOW_TABLE_N = 3601;
