// The noise clouds' term of the shading pass (physics.md), called through the
// integrator's view_transfer hook.

// The media other than the clouds over [a, b] of the view ray: the
// homogeneous medium's sunlight (effects/light_shafts) or the atmosphere
// (effects/daytime), each a no-op where absent; their sunlight times
// sun_scale.
vec3 media_segment_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance, float sun_scale) {
    radiance = medium_sun_segment_transfer(origin, dir, a, b, radiance, sun_scale);
    return atmosphere_segment_transfer(origin, dir, a, b, radiance, sun_scale);
}

// True when no point of [a, b] (b = NO_HIT: the ray's end at infinity) can
// be in the clouds' shadow: all of it above the layer's top with the sun
// above the horizon.
bool cloud_shadow_free(vec3 origin, vec3 dir, float a, float b) {
    float top = frame.clouds.layer.y;
    float y_a = origin.y + a * dir.y;
    float y_b = b >= NO_HIT ? (dir.y >= 0.0f ? y_a : -NO_HIT) : origin.y + b * dir.y;
    return frame.sky.sun_direction.y >= 0.0f && min(y_a, y_b) >= top;
}

// The media over [a, b], a part of the ray outside the layer, in the clouds'
// shadow (physics.md section 9): cut into quality.cloud_shadow_steps pieces
// growing geometrically from a (the last CLOUD_LIGHT_GROWTH times the first;
// equal with CLOUDS_MARCH), each lit through the clouds' transmittance toward
// the sun at its middle; beyond CLOUD_VIEW_FAR from a, lit as there. Composed
// from the far piece to the near one.
vec3 cloud_shadowed_media_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance) {
    int pieces = int(frame.clouds.lighting.w);
    if (pieces == 0 || !HAS_SUN || !(b > a) || cloud_shadow_free(origin, dir, a, b))
        return media_segment_transfer(origin, dir, a, b, radiance, 1.0f);
    vec3 s = vec3(frame.sky.sun_direction);
    float far = min(b, a + CLOUD_VIEW_FAR);
    if (b > far)
        radiance = media_segment_transfer(origin, dir, far, b, radiance, cloud_transmittance_from(origin + far * dir, s));
    // Piece k spans the sums of r^i over i < k and i <= k, over their total, of [a, far].
    float r = CLOUDS_MARCH || pieces < 2 ? 1.0f : pow(CLOUD_LIGHT_GROWTH, 1.0f / float(pieces - 1));
    float total = r == 1.0f ? float(pieces) : (pow(r, float(pieces)) - 1.0f) / (r - 1.0f);
    float t_end = far;
    for (int k = pieces - 1; k >= 0; --k) {
        float before = r == 1.0f ? float(k) : (pow(r, float(k)) - 1.0f) / (r - 1.0f);
        float t_start = k == 0 ? a : a + (far - a) * (before / total);
        float lit = cloud_transmittance_from(origin + (0.5f * (t_start + t_end)) * dir, s);
        radiance = media_segment_transfer(origin, dir, t_start, t_end, radiance, lit);
        t_end = t_start;
    }
    return radiance;
}

// Hook view_transfer: with clouds, the media along [0, t_hit] composed around
// the layer's part [t0, t1] of the ray (physics.md section 5): the other media
// behind the layer, those of the layer's part behind t_half (where the
// clouds' transmittance falls below 1/2), the clouds (their light in the
// `clouds` layer), the other media of the layer's part in front of t_half,
// those in front of the layer; all of them in the clouds' shadow (section 9).
// The homogeneous medium's own transmittance was applied by the integrator; it
// attenuates the clouds' light from the camera on.
vec3 clouds_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_CLOUDS) return radiance;
    float t0;
    float t1;
    if (!cloud_layer_interval(origin, dir, t_hit, t0, t1))
        return cloud_shadowed_media_transfer(origin, dir, 0.0f, t_hit, radiance);
    vec3 light;
    float through_clouds;
    float t_half;
    cloud_march(origin, dir, t0, t1, light, through_clouds, t_half);
    radiance = cloud_shadowed_media_transfer(origin, dir, t1, t_hit, radiance);
    radiance = cloud_shadowed_media_transfer(origin, dir, t_half, t1, radiance);
    outputs_attenuate(vec3(through_clouds));
    layer_add(LAYER_CLOUDS, light);
    radiance = radiance * through_clouds + light;
    radiance = cloud_shadowed_media_transfer(origin, dir, t0, t_half, radiance);
    return cloud_shadowed_media_transfer(origin, dir, 0.0f, t0, radiance);
}
