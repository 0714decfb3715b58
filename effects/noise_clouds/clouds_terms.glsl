// The noise clouds' term of the shading pass (physics.md), called through the
// integrator's view_transfer hook.

// The media other than the clouds over [a, b] of the view ray: the
// homogeneous medium's sunlight (effects/light_shafts) or the atmosphere
// (effects/daytime), each a no-op where absent.
vec3 media_segment_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance) {
    radiance = medium_sun_segment_transfer(origin, dir, a, b, radiance);
    return atmosphere_segment_transfer(origin, dir, a, b, radiance);
}

// Hook view_transfer: with clouds, the media along [0, t_hit] composed around
// the layer's part [t0, t1] of the ray (physics.md section 5): the other media
// behind it, the clouds (their light in the `clouds` layer), the other media
// in front. The homogeneous medium's own transmittance was applied by the
// integrator; it attenuates the clouds' light from the camera on.
vec3 clouds_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_CLOUDS) return radiance;
    float t0;
    float t1;
    if (!cloud_layer_interval(origin, dir, t_hit, t0, t1)) return media_segment_transfer(origin, dir, 0.0f, t_hit, radiance);
    radiance = media_segment_transfer(origin, dir, t1, t_hit, radiance);
    vec3 light;
    float through_clouds;
    cloud_march(origin, dir, t0, t1, light, through_clouds);
    outputs_attenuate(vec3(through_clouds));
    layer_add(LAYER_CLOUDS, light);
    radiance = radiance * through_clouds + light;
    return media_segment_transfer(origin, dir, 0.0f, t0, radiance);
}
