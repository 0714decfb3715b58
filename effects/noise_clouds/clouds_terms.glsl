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

// The sun's transmittance through the scene's clouds from p toward s: the
// noise clouds' light march (physics.md eq. 3.2) or the particle clouds'
// shadow map (effects/particle_clouds/physics.md section 5); a scene has one
// of the two.
float clouds_sun_transmittance(vec3 p, vec3 s) {
    if (HAS_PARTICLE_CLOUDS) return particle_sun_transmittance(p);
    return cloud_transmittance_from(p, s);
}

// The highest altitude the clouds' shadow casters reach, and the pieces the
// air in their shadow is cut into (quality.cloud_shadow_steps; 0: none).
float clouds_top() { return HAS_PARTICLE_CLOUDS ? frame.particle_clouds.air_shadow.x : frame.clouds.layer.y; }
int cloud_shadow_pieces() {
    return int(HAS_PARTICLE_CLOUDS ? frame.particle_clouds.air_shadow.y : frame.clouds.lighting.w);
}

// Where the ray's part from a stops being cut into shadowed pieces: beyond
// it the light is lit as there (physics.md section 9). CLOUD_VIEW_FAR from
// a, and for the particle clouds no farther than where the ray leaves their
// shadow map for good (effects/particle_clouds/physics.md section 5).
float clouds_shadow_far(vec3 origin, vec3 dir, float a, float b) {
    float far = min(b, a + CLOUD_VIEW_FAR);
    return HAS_PARTICLE_CLOUDS ? min(far, max(particle_shadow_exit(origin, dir), a)) : far;
}

// True when no point of [a, b] (b = NO_HIT: the ray's end at infinity) can
// be in the clouds' shadow: all of it above the clouds' top with the sun
// above the horizon.
bool cloud_shadow_free(vec3 origin, vec3 dir, float a, float b) {
    float y_a = origin.y + a * dir.y;
    float y_b = b >= NO_HIT ? (dir.y >= 0.0f ? y_a : -NO_HIT) : origin.y + b * dir.y;
    return frame.sky.sun_direction.y >= 0.0f && min(y_a, y_b) >= clouds_top();
}

// The media over [a, b], a part of the ray outside the layer (or outside the
// particles), in the clouds' shadow (physics.md section 9): cut into
// quality.cloud_shadow_steps pieces growing geometrically from a (the last
// CLOUD_LIGHT_GROWTH times the first; equal with CLOUDS_MARCH), each lit
// through the clouds' transmittance toward the sun at its middle
// (clouds_sun_transmittance); beyond clouds_shadow_far, lit as there.
// Composed from the far piece to the near one; neighbouring pieces whose
// transmittances differ by at most CLOUD_SHADOW_MERGE are composed as one,
// lit as the farthest of them (an error of at most that fraction of their
// sunlight, where whole stretches are lit or shadowed alike). One loop with
// one call of each transfer, so that the shader compiler inlines the
// atmosphere's walk once.
vec3 cloud_shadowed_media_transfer(vec3 origin, vec3 dir, float a, float b, vec3 radiance) {
    int pieces = cloud_shadow_pieces();
    float far = clouds_shadow_far(origin, dir, a, b);
    bool unshadowed = pieces == 0 || !HAS_SUN || !(far > a) || cloud_shadow_free(origin, dir, a, b);
    vec3 s = vec3(frame.sky.sun_direction);
    bool beyond_far = !unshadowed && b > far;  // [far, b] first, lit as at far
    // Piece k spans the sums of r^i over i < k and i <= k, over their total, of [a, far].
    float r = CLOUDS_MARCH || pieces < 2 ? 1.0f : pow(CLOUD_LIGHT_GROWTH, 1.0f / float(pieces - 1));
    float total = r == 1.0f ? float(pieces) : (pow(r, float(pieces)) - 1.0f) / (r - 1.0f);
    int count = unshadowed ? 1 : pieces + (beyond_far ? 1 : 0);
    // Neighbouring pieces lit alike (within CLOUD_SHADOW_MERGE of the first
    // of them) go through one transfer: the run [run_start, run_end] lit by
    // run_lit; iteration `count` only hands over the last run.
    float run_start = 0.0f;
    float run_end = 0.0f;
    float run_lit = -1.0f;  // < 0: no run
    float t_end = far;
    for (int i = 0; i <= count; ++i) {
        float t_start = a;
        float lit = 1.0f;
        if (i == count) {
            lit = -2.0f;  // joins no run
        } else if (unshadowed) {
            t_end = b;
        } else if (beyond_far && i == 0) {
            t_start = far;
            t_end = b;
        } else {
            int k = pieces - 1 - (i - (beyond_far ? 1 : 0));
            if (k == pieces - 1) t_end = far;
            float before = r == 1.0f ? float(k) : (pow(r, float(k)) - 1.0f) / (r - 1.0f);
            if (k > 0) t_start = a + (far - a) * (before / total);
        }
        if (!unshadowed && i < count) {
            float lit_at = beyond_far && i == 0 ? far : 0.5f * (t_start + t_end);
            lit = clouds_sun_transmittance(origin + lit_at * dir, s);
        }
        if (run_lit >= 0.0f && abs(lit - run_lit) <= CLOUD_SHADOW_MERGE) {
            run_start = t_start;
        } else {
            if (run_lit >= 0.0f) radiance = media_segment_transfer(origin, dir, run_start, run_end, radiance, run_lit);
            run_start = t_start;
            run_end = t_end;
            run_lit = lit;
        }
        t_end = t_start;
    }
    return radiance;
}

// The ends of the view ray's stretches outside the clouds, far to near
// (physics.md section 5): end i and end i + 1 bound stretch i ([t1, t_hit],
// [t_half, t1], [t0, t_half], [0, t0]).
float cloud_stretch_end(int i, float t_hit, float t1, float t_half, float t0) {
    return i == 0 ? t_hit : i == 1 ? t1 : i == 2 ? t_half : i == 3 ? t0 : 0.0f;
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
    float t0 = 0.0f;
    float t1 = 0.0f;
    vec3 light = vec3(0.0f);
    float through_clouds = 1.0f;
    float t_half = 0.0f;
    bool through_layer = cloud_layer_interval(origin, dir, t_hit, t0, t1);
    if (through_layer) cloud_march(origin, dir, t0, t1, light, through_clouds, t_half);
    else t0 = t1 = t_half = 0.0f;  // one stretch, [0, t_hit]
    int stretches = through_layer ? 4 : 1;
    for (int i = 0; i < stretches; ++i) {
        if (i == 2) {
            outputs_attenuate(vec3(through_clouds));
            layer_add(LAYER_CLOUDS, light);
            radiance = radiance * through_clouds + light;
        }
        float b = cloud_stretch_end(i, t_hit, t1, t_half, t0);
        float a = cloud_stretch_end(i + 1, t_hit, t1, t_half, t0);
        radiance = cloud_shadowed_media_transfer(origin, dir, a, b, radiance);
    }
    return radiance;
}
