// The falling rain's terms (physics.md sections 4 and 5): the grid passes
// that light each drop, and the pixel_cores hook that composites the streaks.

DECLARE(vec3 environment_radiance(vec3 origin, vec3 dir, bool emitters))

// Grid pass rain_environment: the light arriving at the camera from texel
// (x, y)'s direction (eq. 4.5), the lamps' and spots' spheres left out (their
// light reaches the drops directly, rain_light_pass).
vec4 rain_environment_pass(int x, int y) {
    return vec4(environment_radiance(vec3(frame.camera_position), rain_environment_direction(x, y), false), 1.0f);
}

// Grid pass rain_surround: the environment seen through a drop along texel
// (x, y)'s direction (eq. 4.6): the map's light from each direction omega
// through the drop's phase function, summed over the map's solid angles.
vec4 rain_surround_pass(int x, int y) {
    vec3 v = rain_environment_direction(x, y);
    vec3 sum = vec3(0.0f);
    for (int j = 0; j < RAIN_ENV_HEIGHT; ++j)
        for (int i = 0; i < RAIN_ENV_WIDTH; ++i)
            sum += vec3(table_texel4(TABLE_RAIN_ENVIRONMENT, i, j)) * drop_phase(dot(rain_environment_direction(i, j), v));
    return vec4(sum * (4.0f * PI / float(RAIN_ENV_WIDTH * RAIN_ENV_HEIGHT)), 1.0f);
}

// A lamp's or spot's light on the drop at p seen along v (eq. 4.5): its
// intensity (a spot's times its profile toward p: nothing outside its cone)
// over the squared distance, no closer than its radius, through the
// homogeneous medium, times the drop's phase function; 0 where a surface lies
// between the drop and the light's sphere (V_j).
vec3 rain_lamp_light(vec3 p, vec3 v, vec3 position, float radius, vec3 intensity, bool spot, int spot_index) {
    vec3 to_light = position - p;
    float dist = length(to_light);
    if (!(dist > 0.0f)) return vec3(0.0f);
    vec3 l = to_light / dist;
    float profile = spot ? spot_profile_toward(spot_light(spot_index), -l) : 1.0f;
    if (!(profile > 0.0f)) return vec3(0.0f);
    if (segment_occluded(p, l, dist - radius, -1)) return vec3(0.0f);
    return intensity * (profile / max(dist * dist, radius * radius)) * transmittance(dist) * drop_phase(dot(l, v));
}

// Grid pass rain_light: drop k = x + RAIN_ROW_TEXELS y's radiance toward the
// camera at the middle of its streak (eq. 4.5): every lamp's and spot's
// irradiance (inverse square, the homogeneous medium's attenuation, the
// surfaces' shadows), the sun's (as on a surface facing it: shadows, clouds)
// through the drop's phase function, and its surroundings (rain_surround).
vec4 rain_light_pass(int x, int y) {
    int k = x + RAIN_ROW_TEXELS * y;
    if (k >= frame.falling_rain.tiles.z) return vec4(0.0f);
    vec3 q = 0.5f * (vec3(rain_texel4(TABLE_RAIN_DROPS, 2 * k)) + vec3(rain_texel4(TABLE_RAIN_DROPS, 2 * k + 1)));
    vec3 p = vec3(frame.camera_position) + q;
    vec3 v = normalize(q);
    vec3 light = vec3(0.0f);
    if (HAS_POINT_LIGHTS) {
        for (int i = 0; i < point_light_count(); ++i) {
            PointLightGpu lamp = point_light(i);
            light += rain_lamp_light(p, v, vec3(lamp.position_radius), lamp.position_radius.w, vec3(lamp.intensity),
                                     false, 0);
        }
    }
    if (HAS_SPOT_LIGHTS) {
        for (int i = 0; i < spot_light_count(); ++i) {
            SpotLightGpu s = spot_light(i);
            light += rain_lamp_light(p, v, vec3(s.world_position), s.relative_position_radius.w,
                                     vec3(s.intensity_edge), true, i);
        }
    }
    vec3 sun = vec3(frame.sky.sun_direction);
    if (HAS_SUN && sun.y > 0.0f)
        light += sun_surface_irradiance(p, sun, -1, vec3(0.0f)) * drop_phase(dot(sun, v));
    light += rain_surround(v);
    return vec4(light, 1.0f);
}

// Hook pixel_cores: the streaks crossing pixel (x, row) composited over its
// radiance (eq. 5.2): each covers the share alpha of the pixel that its
// drop's solid angle times its time in the pixel gives, in front of what the
// pixel's centre ray meets, seen through the media to it.
vec3 falling_rain_pixel_cores(int x, int row, vec3 radiance) {
    if (!HAS_FALLING_RAIN) return radiance;
    int size = frame.falling_rain.tiles.w;
    int tile = (row / size) * frame.falling_rain.tiles.x + x / size;
    int begin = rain_index_at(tile);
    int end = rain_index_at(tile + 1);
    bool compensated = frame.falling_rain.near_depth.y > 0.0f;
    if (begin == end && !compensated) return radiance;
    vec3 origin = vec3(frame.camera_position);
    vec3 dir = camera_ray_direction(x, row);
    float t_hit = NO_HIT;
    if (HAS_SURFACES) {
        int hit = -1;
        vec3 n;
        t_hit = trace_surfaces(origin, dir, hit, n);
    }
    if (compensated) {
        // The medium's rain that the drawn drops stand for, given back (eq. 2.4): on average over the
        // drops the streaks take exactly this away again.
        float back = exp(rain_near_optical_depth(t_hit));
        outputs_attenuate(vec3(back));
        radiance *= back;
    }
    vec3 f = vec3(frame.camera_forward);
    vec3 u = vec3(frame.camera_up);
    vec3 r = vec3(frame.camera_right);
    // The pixel's solid angle: its area on the plane at distance 1, times cos^3 of its centre ray.
    float cos_pixel = dot(dir, f);
    float pixel_area = (2.0f * length(r) / float(frame.film_width)) * (2.0f * length(u) / float(frame.film_height));
    float pixel_solid_angle = pixel_area * cos_pixel * cos_pixel * cos_pixel;
    float pixel_side = 2.0f * length(u) / float(frame.film_height);
    int header = frame.falling_rain.tiles.x * frame.falling_rain.tiles.y + 1;
    for (int j = begin; j < end; ++j) {
        int k = rain_index_at(header + j);
        vec4 start = rain_texel4(TABLE_RAIN_DROPS, 2 * k);
        vec4 stop = rain_texel4(TABLE_RAIN_DROPS, 2 * k + 1);
        vec3 s = vec3(start);
        vec3 e = vec3(stop);
        // The drop's width in pixels at the streak's middle (eq. 5.1), its footprint no narrower than 1e-3 px.
        float z_mid = max(dot(0.5f * (s + e), f), RAIN_NEAR);
        float w = max(start.w / (z_mid * pixel_side), 1e-3f);
        vec2 coverage = rain_pixel_coverage(s, e, x, row, w, 0.5f * start.w);
        if (!(coverage.x > 0.0f)) continue;
        vec3 q = s + coverage.y * (e - s);
        float d = length(q);
        if (d >= t_hit) continue;
        float alpha = min(stop.w * coverage.x / pixel_solid_angle, 1.0f);
        vec3 seen = vec3(rain_texel4(TABLE_RAIN_LIGHT, k)) * transmittance(d) * atmosphere_transmittance(origin, q / d, d);
        outputs_cover(1.0f - alpha);
        layer_add(LAYER_FALLING_RAIN, seen * alpha);
        radiance = radiance * (1.0f - alpha) + seen * alpha;
    }
    return radiance;
}
