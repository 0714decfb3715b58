// The particle clouds' term of the shading pass (physics.md section 6),
// called through the integrator's view_transfer hook.

// Hook view_transfer: with particle clouds, the other media along [0, t_hit]
// composed around the particles (as the noise clouds do, section 6): those
// behind t_half, where the particles in front pass less than half the light,
// then the particles (their light in the `particle_clouds` layer), then those
// in front of t_half.
vec3 particle_clouds_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_PARTICLE_CLOUDS) return radiance;
    vec3 light;
    float through;
    float t_half;
    particle_composite(origin, dir, t_hit, light, through, t_half);
    if (t_half < 0.0f) return media_segment_transfer(origin, dir, 0.0f, t_hit, radiance, 1.0f);
    t_half = min(t_half, t_hit);
    radiance = media_segment_transfer(origin, dir, t_half, t_hit, radiance, 1.0f);
    outputs_attenuate(vec3(through));
    layer_add(LAYER_PARTICLE_CLOUDS, light);
    radiance = radiance * through + light;
    return media_segment_transfer(origin, dir, 0.0f, t_half, radiance, 1.0f);
}
