// The render outputs of the pixel being shaded (outputs_layout.glsl): the
// integrator (shading.glsl) and the effects' terms record into them as they
// compose the radiance, keeping the invariant that the layers sum to the
// radiance so far. Without RENDER_OUTPUTS (a compile-time constant in a GL
// variant) every function here returns at once: a frame that asks only for
// the radiance pays nothing.

struct PixelOutputs {
    float depth;
    float distance_z;
    vec3 normal;
    vec3 transmittance;
    vec3 layers[LAYER_COUNT];
};

// The pixel's outputs: a private global on GL, a member of the per-thread
// CpuShader copy on the CPU.
PixelOutputs pixel_outputs;

void outputs_begin() {
    if (!RENDER_OUTPUTS) return;
    pixel_outputs.depth = NO_HIT;
    pixel_outputs.distance_z = NO_HIT;
    pixel_outputs.normal = vec3(0.0f);
    pixel_outputs.transmittance = vec3(1.0f);
    for (int k = 0; k < LAYER_COUNT; ++k) pixel_outputs.layers[k] = vec3(0.0f);
}

// Where the camera ray ends: at distance t (NO_HIT: it escapes) along dir, on
// a surface of unit normal n facing the camera (vec3(0): an emitter or nothing).
void outputs_ray_end(vec3 dir, float t, vec3 n) {
    if (!RENDER_OUTPUTS) return;
    pixel_outputs.depth = t;
    pixel_outputs.distance_z = t >= NO_HIT ? NO_HIT : t * dot(dir, vec3(frame.camera_forward));
    pixel_outputs.normal = n;
}

// Light `v` joins layer `layer` (LAYER_*), as it joins the radiance.
void layer_add(int layer, vec3 v) {
    if (!RENDER_OUTPUTS) return;
    pixel_outputs.layers[layer] += v;
}

// A medium along the view ray of transmittance t: everything behind it (every
// layer so far) reaches the camera times t.
void outputs_attenuate(vec3 t) {
    if (!RENDER_OUTPUTS) return;
    pixel_outputs.transmittance *= t;
    for (int k = 0; k < LAYER_COUNT; ++k) pixel_outputs.layers[k] *= t;
}

// Something covers 1 - keep of the pixel (a sub-pixel lamp core composited
// over it): every layer so far keeps that share; the transmittance, which is
// the ray's, stays.
void outputs_cover(float keep) {
    if (!RENDER_OUTPUTS) return;
    for (int k = 0; k < LAYER_COUNT; ++k) pixel_outputs.layers[k] *= keep;
}

// Float k (0 <= k < OUTPUT_FLOATS) of the packed outputs (outputs_layout.glsl),
// as both backends store them.
float pixel_output_value(int k) {
    if (k == OUTPUT_DEPTH) return pixel_outputs.depth;
    if (k == OUTPUT_DISTANCE_Z) return pixel_outputs.distance_z;
    if (k < OUTPUT_TRANSMITTANCE) return pixel_outputs.normal[k - OUTPUT_NORMAL];
    if (k < OUTPUT_LAYERS) return pixel_outputs.transmittance[k - OUTPUT_TRANSMITTANCE];
    int j = k - OUTPUT_LAYERS;
    return pixel_outputs.layers[j / 3][j % 3];
}
