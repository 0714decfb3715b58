// The shading pass's integrator, shared by both backends: the radiance along
// a camera ray composed from the effects' terms, which it calls through the
// hooks of the generated airlight_hooks.glsl (each effect's EFFECT_HOOKS,
// cmake/effects.cmake lists the kinds); it names no effect. Feature switches
// are compile-time constants in a GL shader variant and cheap runtime flags
// on the CPU.

// Light `radiance` leaving the end of the ray origin + t dir at t_hit (NO_HIT:
// it escapes), on a surface of unit normal n facing the camera (vec3(0): none),
// as it reaches the camera: everything behind the homogeneous medium reaches
// the camera attenuated; then the effects' media along the ray (view_transfer:
// attenuation and in-scattering; view_glow: the lamps' light scattered toward
// the camera). The render outputs (outputs.glsl): where the ray ends, and this
// light as the first layer, attenuated with it.
vec3 view_ray(vec3 origin, vec3 dir, float t_hit, vec3 n, vec3 radiance) {
    outputs_ray_end(dir, t_hit, n);
    layer_add(LAYER_SURFACES, radiance);
    vec3 through_medium = transmittance(t_hit);
    outputs_attenuate(through_medium);
    radiance *= through_medium;
    return hooks_view_segment(origin, dir, t_hit, radiance);
}

// Radiance arriving at `origin` along the ray origin + t dir (lamp cores
// smaller than a pixel excepted: hooks_pixel_cores); with `emitters` false,
// the lamps' and spots' own spheres are left out (the light an effect sums
// from the lamps directly: the falling rain's environment).
vec3 environment_radiance(vec3 origin, vec3 dir, bool emitters) {
    int hit_index = -1;
    vec3 normal = vec3(0.0f, 1.0f, 0.0f);
    float t_hit = NO_HIT;
    if (HAS_SURFACES) t_hit = trace_surfaces(origin, dir, hit_index, normal);

    // An emitter (a lamp's sphere) in front of the first surface shows its own radiance.
    bool emitter = false;
    vec3 emitted = vec3(0.0f);
    if (emitters) hooks_emitter_hit(origin, dir, t_hit, emitted, emitter);

    vec3 radiance;
    if (emitter) {
        radiance = emitted;
    } else if (hit_index >= 0) {
        vec3 p = origin + t_hit * dir;
        vec3 albedo = vec3(surface(hit_index).albedo_type);
        // A black surface reflects nothing: skip its lighting (and shadow rays).
        bool black = albedo.x == 0.0f && albedo.y == 0.0f && albedo.z == 0.0f;
        vec3 irradiance = black ? vec3(0.0f) : hooks_surface_irradiance(p, normal, hit_index);
        radiance = albedo / PI * irradiance;
    } else {
        radiance = vec3(frame.background) + hooks_escaping_radiance(dir);
    }
    return view_ray(origin, dir, t_hit, hit_index >= 0 && !emitter ? normal : vec3(0.0f), radiance);
}

// Radiance arriving at the camera along the ray origin + t dir.
vec3 ray_radiance(vec3 origin, vec3 dir) { return environment_radiance(origin, dir, true); }

// The smallest normal float32 (FLT_MIN): below it a float is subnormal (denormal).
CONST float RADIANCE_MIN_NORMAL = 1.17549435e-38f;
// The largest float32 (FLT_MAX).
CONST float RADIANCE_MAX = 3.40282347e38f;

// A radiance channel with subnormal magnitude flushed to 0. Terms that underflow
// (exp(-T) of a far lamp, a cone's edge) leave values of 1e-45..1e-38 that the CPU
// keeps and a GPU flushes, so the backends' images would differ in those pixels;
// radiance never carries them (effects/display/physics.md section 8). Written as a
// comparison, so that a GPU which flushes subnormal inputs gives 0 as well.
float flush_subnormal(float v) { return abs(v) < RADIANCE_MIN_NORMAL ? 0.0f : v; }

// Linear radiance of pixel (x, row), row 0 on top: the per-pixel entry point;
// with RENDER_OUTPUTS, its render outputs in pixel_outputs (outputs.glsl).
vec3 render_pixel(int x, int row) {
    outputs_begin();
    vec3 origin = vec3(frame.camera_position);
    vec3 dir = camera_ray_direction(x, row);
    float t_end = NO_HIT;
    vec3 at_end = vec3(0.0f);
    vec3 radiance;
    if (hooks_backplate(x, row, dir, t_end, at_end)) {
        // An image ends the ray (a photo and its depth): it already shows
        // whatever surfaces, emitters and cores the pixel sees.
        radiance = view_ray(origin, dir, t_end, vec3(0.0f), at_end);
    } else {
        radiance = ray_radiance(origin, dir);
        radiance = hooks_pixel_cores(x, row, radiance);
    }
    radiance = vec3(flush_subnormal(radiance.r), flush_subnormal(radiance.g), flush_subnormal(radiance.b));
    // Saturated at the largest float, never Inf: the scene keys' bounds
    // (max_radiometric, max_extinction in cpp/scene_keys.hpp) keep valid scenes
    // below it; this is the net for sums of many lamps near those bounds.
    return min(radiance, vec3(RADIANCE_MAX));
}

