// The light shafts' term of the shading pass (physics.md), called through the
// integrator's view_transfer hook.

// The homogeneous medium's scattering of the sun toward the camera per unit
// length and unit transmittance: sigma_s p(s . d) E_sun (physics.md eq. 3.1;
// p from the medium's phase, effects/phase, isotropic without one).
vec3 medium_sun_source(vec3 d) {
    vec3 s = vec3(frame.sky.sun_direction);
    float phase = medium_phase_between(s, d) / (4.0f * PI);
    return vec3(frame.sigma_s) * vec3(frame.sky.sun_irradiance) * phase;
}

// The sun's light scattered once toward the camera by the homogeneous medium
// along [a, b] of the view ray (b = NO_HIT: to infinity), without an
// atmosphere (with one, the atmosphere's scattering volumes carry it:
// effects/daytime/sky.glsl): sigma_s p E_sun times int e^{-sigma_t t} dt over
// the lit parts of [a, b] (physics.md eq. 3.2), exact; or, with SHAFTS_MARCH,
// a midpoint march of frame.march_steps steps with a shadow ray each, to b or
// where e^{-sigma_t t} < e^{-30}. The clouds call it on the parts of the ray
// around their layer (effects/noise_clouds/physics.md section 5), the light
// times sun_scale, their transmittance toward the sun there (section 9; 1: none).
vec3 medium_sun_segment_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance, float sun_scale) {
    if (!HAS_MEDIUM_SUN || HAS_ATMOSPHERE || !(b > a)) return radiance;
    vec3 sigma = vec3(frame.sigma_t);
    vec3 light = vec3(0.0f);
    if (SHAFTS_MARCH) {
        float thinnest = NO_HIT;
        for (int c = 0; c < 3; ++c) {
            if (frame.sigma_s[c] > 0.0f) thinnest = min(thinnest, sigma[c]);
        }
        float far = min(b, 30.0f / thinnest);
        int steps = int(frame.march_steps);
        float ds = (far - a) / float(steps);
        for (int k = 0; k < steps && ds > 0.0f; ++k) {
            float t = a + (float(k) + 0.5f) * ds;
            light += sun_visible_from_air(origin + t * dir) * exp(-sigma * t) * ds;
        }
    } else {
        sun_shadow_runs(origin, dir, b);
        float lit_from = a;
        for (int k = 0; k < shadow_runs.count; ++k) {
            vec2 run = shadow_runs.run[k];
            if (run.x > lit_from) light += attenuated_length(sigma, lit_from, run.x);
            lit_from = max(lit_from, run.y);
        }
        if (lit_from < b) light += attenuated_length(sigma, lit_from, b);
    }
    light *= sun_scale * medium_sun_source(dir);
    layer_add(LAYER_MEDIUM_SUN, light);
    return radiance + light;
}

// Hook view_transfer: the homogeneous medium's sunlight along the whole view
// ray [0, t_hit]; with clouds, their transfer calls
// medium_sun_segment_transfer around their layer instead.
vec3 medium_sun_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (HAS_CLOUDS || HAS_PARTICLE_CLOUDS) return radiance;
    return medium_sun_segment_transfer(origin, dir, 0.0f, t_hit, radiance, 1.0f);
}
