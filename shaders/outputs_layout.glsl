// The render outputs beside the radiance (README "Render outputs"): what the
// shading pass records of a pixel when they are asked for (RENDER_OUTPUTS),
// packed as OUTPUT_FLOATS floats per pixel in this order; the host unpacks them
// by these offsets (cpp/render_outputs.cpp).
CONST int OUTPUT_DEPTH = 0;          // m along the ray to the first surface or emitter (NO_HIT: none)
CONST int OUTPUT_DISTANCE_Z = 1;     // the same along the camera's optical axis
CONST int OUTPUT_NORMAL = 2;         // xyz: unit world normal of the surface hit, facing the camera (0: none)
CONST int OUTPUT_TRANSMITTANCE = 5;  // rgb: from the camera to the ray's end
CONST int OUTPUT_LAYERS = 8;         // rgb per layer (LAYER_*, generated from the effects' EFFECT_LAYERS)
CONST int OUTPUT_FLOATS = OUTPUT_LAYERS + 3 * LAYER_COUNT;
