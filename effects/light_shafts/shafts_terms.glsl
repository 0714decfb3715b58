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
// along [0, t_hit], without an atmosphere (with one, the atmosphere's
// scattering volumes carry it: effects/daytime/sky.glsl): sigma_s p E_sun
// times int e^{-sigma_t t} dt over the lit parts of the ray (physics.md
// eq. 3.2), exact; or, with SHAFTS_MARCH, a midpoint march of frame.march_steps
// steps with a shadow ray each, to t_hit or where e^{-sigma_t t} < e^{-30}.
vec3 medium_sun_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_MEDIUM_SUN || HAS_ATMOSPHERE) return radiance;
    vec3 sigma = vec3(frame.sigma_t);
    vec3 light = vec3(0.0f);
    if (SHAFTS_MARCH) {
        float thinnest = NO_HIT;
        for (int c = 0; c < 3; ++c) {
            if (frame.sigma_s[c] > 0.0f) thinnest = min(thinnest, sigma[c]);
        }
        float far = min(t_hit, 30.0f / thinnest);
        int steps = int(frame.march_steps);
        float ds = far / float(steps);
        for (int k = 0; k < steps; ++k) {
            float t = (float(k) + 0.5f) * ds;
            light += sun_visible_from_air(origin + t * dir) * exp(-sigma * t) * ds;
        }
    } else {
        sun_shadow_runs(origin, dir, t_hit);
        float lit_from = 0.0f;
        for (int k = 0; k < shadow_runs.count; ++k) {
            light += attenuated_length(sigma, lit_from, shadow_runs.run[k].x);
            lit_from = shadow_runs.run[k].y;
        }
        if (lit_from < t_hit) light += attenuated_length(sigma, lit_from, t_hit);
    }
    light *= medium_sun_source(dir);
    layer_add(LAYER_MEDIUM_SUN, light);
    return radiance + light;
}
