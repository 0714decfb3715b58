// The daytime sky's and atmosphere's terms of the shading pass
// (effects/daytime/physics.md), called through the integrator's hooks
// (effect.cmake EFFECT_HOOKS): surface_irradiance (sky, then sun),
// escaping_radiance, view_transfer.

// Hook surface_irradiance: the sky dome's light on a surface point (sky.glsl).
vec3 sky_surface_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    if (!HAS_SKY) return vec3(0.0f);
    return sky_irradiance(p, n);
}

// Hook surface_irradiance: the sun's, where the point sees it (sun_visibility:
// a shadow ray, or the map of effects/sun_shadow_map) through the clouds; with multiple
// scattering, its forward-scattered residual beam E_res too, which travels
// nearly along the sun and is shadowed with it
// (effects/multiple_scattering/physics.md section 9).
vec3 sun_surface_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    float cos_n = dot(n, vec3(frame.sky.sun_direction));
    if (!HAS_SUN || cos_n <= 0.0f) return vec3(0.0f);
    float visible = sun_visibility(p, n, self);
    if (visible <= 0.0f) return vec3(0.0f);
    vec3 e = sun_irradiance(p, n);
    if (HAS_MULTIPLE_SCATTERING && frame.multiple_scattering.air_scattering != 0.0f) e += ms_sun_residual(ms_level(max(p.y, 0.0f))) * cos_n;
    // The clouds' shadow (effects/noise_clouds/physics.md section 5).
    if (HAS_CLOUDS) visible *= cloud_transmittance_from(p, vec3(frame.sky.sun_direction));
    // The particle clouds' (effects/particle_clouds/physics.md section 5).
    if (HAS_PARTICLE_CLOUDS) visible *= particle_sun_transmittance(p);
    return visible * e;
}

// Hook escaping_radiance: the sky dome seen by a ray that meets nothing.
vec3 sky_escaping_radiance(vec3 dir) {
    if (!HAS_SKY) return vec3(0.0f);
    return sky_radiance(dir);
}

// The atmosphere's transfer over [a, b] of the view ray (b = NO_HIT: to
// infinity): aerial perspective on `radiance` arriving at b, plus the sky and
// sun light the atmosphere's particles scatter toward the camera (and the
// homogeneous medium's sunlight, which varies with the atmosphere's
// transmittance to each altitude), the sun's over the lit parts of the ray;
// the light from beyond a reaches the camera through the homogeneous medium
// before a. The clouds call it on the parts of the ray around their layer
// (effects/noise_clouds/physics.md section 5), the sun's light times
// sun_scale, their transmittance toward the sun there (section 9; 1: none).
vec3 atmosphere_segment_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance, float sun_scale) {
    if (!HAS_ATMOSPHERE || !(b > a)) return radiance;
    vec3 start = origin + a * dir;
    float length_ = b >= NO_HIT ? NO_HIT : b - a;
    vec3 sigma_medium = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
    vec3 inscatter;
    vec3 rainbow;  // the rain's sunlight, kept apart only for the render outputs (rainbow_layer_apart)
    vec3 medium_sun;  // the homogeneous medium's sunlight (HAS_MEDIUM_SUN; effects/light_shafts)
    vec3 through_atmosphere;
    if (SKY_MARCH) {
        atmosphere_scattering_march(start, dir, length_, sigma_medium, int(frame.march_steps), sun_scale, inscatter,
                                    rainbow, medium_sun, through_atmosphere);
    } else {
        // The sun's shadows along the ray (effects/light_shafts): counted by the volumes.
        sun_shadow_runs(start, dir, length_);
        // The camera's rays look the light up in the aerial table (aerial_table.glsl);
        // not the clouds' stretches (effects/daytime/docs/aerial_table.md, section 4).
        bool looked_up = HAS_AERIAL_TABLE && !HAS_CLOUDS && !HAS_PARTICLE_CLOUDS && origin == vec3(frame.camera_position) &&
                         aerial_scattering(dir, a, b, sun_scale, true, inscatter, rainbow, medium_sun,
                                           through_atmosphere);
        if (!looked_up)
            atmosphere_scattering(start, dir, length_, sigma_medium, true, sun_scale, inscatter, rainbow, medium_sun,
                                  through_atmosphere);
    }
    if (a > 0.0f) {
        vec3 before = exp(-sigma_medium * a);
        inscatter *= before;
        rainbow *= before;
        medium_sun *= before;
    }
    outputs_attenuate(through_atmosphere);
    layer_add(LAYER_SKY, inscatter);
    layer_add(LAYER_RAINBOW, rainbow);
    layer_add(LAYER_MEDIUM_SUN, medium_sun);
    return radiance * through_atmosphere + inscatter + rainbow + medium_sun;
}

// Hook view_transfer: the atmosphere along the whole view ray [0, t_hit]; with
// clouds, their transfer calls atmosphere_segment_transfer around their layer instead.
vec3 atmosphere_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (HAS_CLOUDS || HAS_PARTICLE_CLOUDS) return radiance;
    return atmosphere_segment_transfer(origin, dir, 0.0f, t_hit, radiance, 1.0f);
}
