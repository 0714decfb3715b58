// The particle clouds' term of the shading pass (physics.md section 6),
// called through the integrator's view_transfer hook.

// Hook view_transfer: with particle clouds, the other media along [0, t_hit]
// composed around the particles (as the noise clouds do, section 6): those
// behind t_half, where the particles in front pass less than half the light,
// then the particles (their light in the `particle_clouds` layer), then those
// in front of t_half; the air in the particles' shadow (section 5, through
// the noise clouds' cloud_shadowed_media_transfer). One loop with one call of
// the media's transfer, so that the shader compiler inlines the atmosphere's
// walk once.
vec3 particle_clouds_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_PARTICLE_CLOUDS) return radiance;
    vec3 light;
    float through;
    float t_half;
    particle_composite(origin, dir, t_hit, light, through, t_half);
    bool behind_particles = t_half >= 0.0f;  // else one stretch, [0, t_hit]
    t_half = behind_particles ? min(t_half, t_hit) : 0.0f;
    for (int i = 0; i < (behind_particles ? 2 : 1); ++i) {
        if (i == 1) {
            outputs_attenuate(vec3(through));
            layer_add(LAYER_PARTICLE_CLOUDS, light);
            radiance = radiance * through + light;
        }
        float a = i == 0 ? t_half : 0.0f;
        float b = i == 0 ? t_hit : t_half;
        radiance = cloud_shadowed_media_transfer(origin, dir, a, b, radiance);
    }
    return radiance;
}
