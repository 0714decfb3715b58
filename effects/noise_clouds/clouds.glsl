// The noise clouds (physics.md): the density field of two tiling noise
// textures, the layer's interval on a ray, the clouds' transmittance toward a
// light, and the march of a view ray's part inside the layer. Feature
// switches: HAS_CLOUDS, CLOUDS_MARCH. Uses the daytime effect's sun and sky
// light (effects/daytime/sky.glsl).

// Runs of empty samples are crossed in steps this many times the fine step
// (physics.md section 4).
CONST float CLOUD_SKIP_FACTOR = 4.0f;
// The adaptive march's step grows by the near step every this many metres from the camera.
CONST float CLOUD_STEP_GROWTH = 10000.0f;
// Light marches along a nearly horizontal direction end this far away (the
// layer does not end there, but its light is long gone: an optical depth of at
// least the density's mean times this).
CONST float CLOUD_LIGHT_FAR = 100000.0f;
// View rays end this far from the camera inside the layer (a ray grazing the
// layer for longer has met opaque cloud or left the film's resolution long before).
CONST float CLOUD_VIEW_FAR = 200000.0f;
// The light march's last step over its first (the steps grow geometrically
// in between, so that they refine everywhere as their count grows).
CONST float CLOUD_LIGHT_GROWTH = 16.0f;
// Neighbouring pieces of the air in the clouds' shadow whose transmittances
// toward the sun differ by at most this are composed as one (physics.md
// section 9): the atmosphere's walk runs once for a stretch lit alike.
CONST float CLOUD_SHADOW_MERGE = 1.0e-3f;

// The height profile H(h, type) (physics.md section 2): a trapezoid in the
// height fraction h, its corners (rise end a, fall start b, top t) linear in
// type between stratus (0), cumulus (0.5) and cumulonimbus (1).
float cloud_height_profile(float h, float type) {
    vec3 stratus = vec3(0.05f, 0.15f, 0.3f);
    vec3 cumulus = vec3(0.1f, 0.4f, 0.7f);
    vec3 cumulonimbus = vec3(0.05f, 0.7f, 1.0f);
    vec3 k = type < 0.5f ? mix(stratus, cumulus, 2.0f * type) : mix(cumulus, cumulonimbus, 2.0f * type - 1.0f);
    if (!(h > 0.0f) || h >= k.z) return 0.0f;
    return min(h / k.x, 1.0f) * min((k.z - h) / (k.z - k.y), 1.0f);
}

// The shape with its height profile and coverage, s_c of eqs. 2.1-2.3, at p of
// height fraction h: an upper bound of the density d (eq. 2.4 never raises it),
// so s_c = 0 means no cloud at p.
float cloud_coverage_shape(vec3 p, float h) {
    vec3 u = p * frame.clouds.tiles.x - vec3(frame.clouds.offsets.x, 0.0f, frame.clouds.offsets.y);
    float c = frame.clouds.density.x;
    float type = frame.clouds.density.y;
    if (CLOUDS_WEATHER_MAP) {
        // Eq. 8.1: the map's R scales the coverage; its G is the type where the map has colour (B = 1).
        vec2 uv = vec2(p.x, p.z) * vec2(frame.clouds.weather) - vec2(frame.clouds.weather.z, frame.clouds.weather.w);
        vec4 w = table_bilinear4_periodic(TABLE_CLOUD_WEATHER, frame.clouds.weather_texels.x,
                                          frame.clouds.weather_texels.y, uv);
        c *= w.x;
        type = mix(type, w.y, w.z);
        if (!(c > 0.0f)) return 0.0f;
    }
    float profile = cloud_height_profile(h, type);
    if (!(profile > 0.0f)) return 0.0f;
    vec4 s = table_trilinear4_periodic(TABLE_CLOUD_SHAPE, CLOUD_SHAPE_SIZE, u);
    float low = 0.625f * s.y + 0.25f * s.z + 0.125f * s.w;
    float shape = clamp((s.x - (low - 1.0f)) / (2.0f - low), 0.0f, 1.0f);
    float s_h = shape * profile;
    return clamp((s_h - (1.0f - c)) / c, 0.0f, 1.0f) * c;
}

// The layer's height fraction of altitude y (0 at the base, 1 at the top).
float cloud_height_fraction(float y) {
    return (y - frame.clouds.layer.x) * frame.clouds.layer.z;
}

// The density d(p) in [0, 1] (physics.md eqs. 2.1-2.4): the shape eroded at
// its edges by the detail noise; 0 outside the layer.
float cloud_density(vec3 p) {
    float h = cloud_height_fraction(p.y);
    if (!(h > 0.0f && h < 1.0f)) return 0.0f;
    float s_c = cloud_coverage_shape(p, h);
    if (s_c <= 0.0f) return 0.0f;
    vec3 u = p * frame.clouds.tiles.y - vec3(frame.clouds.offsets.z, 0.0f, frame.clouds.offsets.w);
    vec4 q = table_trilinear4_periodic(TABLE_CLOUD_DETAIL, CLOUD_DETAIL_SIZE, u);
    float high = 0.625f * q.x + 0.25f * q.y + 0.125f * q.z;
    float m = mix(high, 1.0f - high, clamp(10.0f * h, 0.0f, 1.0f));
    float em = frame.clouds.density.z * m;
    return clamp((s_c - em) / (1.0f - em), 0.0f, 1.0f);
}

// The interval [t0, t1] of o + t d, t in [0, min(t_end, CLOUD_VIEW_FAR)], inside
// the layer's slab base <= y <= top; false when the ray misses it.
bool cloud_layer_interval(vec3 o, vec3 d, float t_end, OUT(float) t0, OUT(float) t1) {
    float base = frame.clouds.layer.x;
    float top = frame.clouds.layer.y;
    t0 = 0.0f;
    t1 = min(t_end, CLOUD_VIEW_FAR);
    if (d.y == 0.0f) return o.y > base && o.y < top && t1 > 0.0f;
    float a = (base - o.y) / d.y;
    float b = (top - o.y) / d.y;
    t0 = max(t0, min(a, b));
    t1 = min(t1, max(a, b));
    return t0 < t1;
}

// The distance from p (inside the slab) along w to where w leaves the layer,
// at most CLOUD_LIGHT_FAR.
float cloud_exit_distance(vec3 p, vec3 w) {
    float boundary = w.y > 0.0f ? frame.clouds.layer.y : frame.clouds.layer.x;
    float s = w.y != 0.0f ? (boundary - p.y) / w.y : CLOUD_LIGHT_FAR;
    return clamp(s, 0.0f, CLOUD_LIGHT_FAR);
}

// The clouds' optical depth from p along w out of the layer, the exponent of
// T_c of eq. 3.2: frame.clouds.lighting.z midpoint steps growing geometrically,
// the last CLOUD_LIGHT_GROWTH times the first (CLOUDS_MARCH: equal steps).
float cloud_optical_depth_toward(vec3 p, vec3 w) {
    float length_out = cloud_exit_distance(p, w);
    if (!(length_out > 0.0f)) return 0.0f;
    int steps = int(frame.clouds.lighting.z);
    // The ratio r of consecutive steps and the first, length_out (r - 1) / (r^n - 1) (equal steps for r = 1).
    float r = CLOUDS_MARCH || steps < 2 ? 1.0f : pow(CLOUD_LIGHT_GROWTH, 1.0f / float(steps - 1));
    float ds = r == 1.0f ? length_out / float(steps) : length_out * (r - 1.0f) / (pow(r, float(steps)) - 1.0f);
    float s = 0.0f;
    float depth = 0.0f;
    for (int k = 0; k < steps; ++k) {
        depth += cloud_density(p + (s + 0.5f * ds) * w) * ds;
        s += ds;
        ds *= r;
    }
    return frame.clouds.layer.w * depth;
}

// The clouds' transmittance from any point p along w (w.y != 0 for a point
// outside the layer): from where w enters the layer, 1 where it never does.
// The clouds' shadow on surfaces (the sun's light, effects/daytime/daytime_terms.glsl).
float cloud_transmittance_from(vec3 p, vec3 w) {
    float base = frame.clouds.layer.x;
    float top = frame.clouds.layer.y;
    if (p.y < base) {
        if (!(w.y > 0.0f)) return 1.0f;
        p += ((base - p.y) / w.y) * w;
        p.y = base;
    } else if (p.y > top) {
        if (!(w.y < 0.0f)) return 1.0f;
        p += ((top - p.y) / w.y) * w;
        p.y = top;
    }
    return exp(-cloud_optical_depth_toward(p, w));
}

// The droplets' phase function (physics.md eq. 3.4): Henyey-Greenstein of g,
// mixed with a second lobe of frame.clouds.phase.x by its weight phase.y,
// both asymmetries scaled by g_scale (the octaves' c^i).
float cloud_phase(float mu, float g_scale) {
    float first = species_phase(vec4(g_scale * frame.clouds.lighting.x, 0.0f, 1.0f, 0.0f), mu);
    float w = frame.clouds.phase.y;
    if (w == 0.0f) return first;
    return mix(first, species_phase(vec4(g_scale * frame.clouds.phase.x, 0.0f, 1.0f, 0.0f), mu), w);
}

// Multiple scattering's octaves (eq. 6.1) for the sun: sum over i of a^i
// e^{-b^i depth} p(mu, c^i g); octave 0 alone is single scattering.
float cloud_sun_octaves(float depth, float mu) {
    vec4 oct = frame.clouds.octaves;
    float sum = 0.0f;
    float weight = 1.0f;
    float depth_scale = 1.0f;
    float g_scale = 1.0f;
    for (int i = 0; i < int(oct.w); ++i) {
        sum += weight * exp(-depth_scale * depth) * cloud_phase(mu, g_scale);
        weight *= oct.x;
        depth_scale *= oct.y;
        g_scale *= oct.z;
    }
    return sum;
}

// The powder term (eq. 3.5): 1 - strength e^{-2 depth}, at most 1, so that
// cloud_source_bound's value without it stays a bound.
float cloud_powder(float depth) {
    return 1.0f - frame.clouds.phase.z * exp(-2.0f * depth);
}

// The same for the sky's light (no phase: its mean over the hemisphere).
float cloud_sky_octaves(float depth) {
    vec4 oct = frame.clouds.octaves;
    float sum = 0.0f;
    float weight = 1.0f;
    float depth_scale = 1.0f;
    for (int i = 0; i < int(oct.w); ++i) {
        sum += weight * exp(-depth_scale * depth);
        weight *= oct.x;
        depth_scale *= oct.y;
    }
    return sum;
}

// The light a unit of cloud density scatters toward the camera at p (view
// direction d), per unit extinction: J / sigma_t of eq. 3.1, the sun's (with the
// clouds' shadow) and the sky's (attenuated straight up), each through the
// octaves of eq. 6.1.
vec3 cloud_source_function(vec3 p, vec3 d) {
    vec3 source = vec3(0.0f);
    if (HAS_SUN) {
        vec3 s = vec3(frame.sky.sun_direction);
        float depth = cloud_optical_depth_toward(p, s);
        source += sun_irradiance(p, s) * (cloud_sun_octaves(depth, dot(s, d)) * cloud_powder(depth));
    }
    if (HAS_SKY) {
        vec3 up = vec3(0.0f, 1.0f, 0.0f);
        source += sky_irradiance(p, up) * (cloud_sky_octaves(cloud_optical_depth_toward(p, up)) / (2.0f * PI));
    }
    return frame.clouds.density.w * source;
}

// An upper bound of cloud_source_function anywhere along the view direction d
// (no cloud shadow, the sun's irradiance above the atmosphere, the sky's at
// the layer's top): what the rest of a march can add per unit transmittance.
vec3 cloud_source_bound(vec3 d) {
    vec3 bound = vec3(0.0f);
    if (HAS_SUN) {
        vec3 s = vec3(frame.sky.sun_direction);
        bound += vec3(frame.sky.sun_irradiance) * cloud_sun_octaves(0.0f, dot(s, d));
    }
    if (HAS_SKY) {
        vec3 top = vec3(0.0f, frame.clouds.layer.y, 0.0f);
        bound += sky_irradiance(top, vec3(0.0f, 1.0f, 0.0f)) * (cloud_sky_octaves(0.0f) / (2.0f * PI));
    }
    return frame.clouds.density.w * bound;
}

// One step of the view march (physics.md eq. 4.1): the sample at the step's
// middle t_mid of density `density`, the step [t_mid - dt / 2, t_mid + dt / 2];
// adds T e^{-sigma_m t_start} J (1 - e^{-sigma dt}) / sigma to `light` (sigma the
// clouds' and the medium's extinction) and multiplies the clouds' transmittance.
void cloud_step(vec3 origin, vec3 dir, float t_mid, float dt, float density, INOUT(float) through_clouds,
                INOUT(vec3) light) {
    float sigma_c = frame.clouds.layer.w * density;
    vec3 sigma_m = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
    vec3 sigma = vec3(sigma_c) + sigma_m;
    float t_start = t_mid - 0.5f * dt;
    vec3 in_step = vec3(dt * expm1_over_x(-sigma.x * dt), dt * expm1_over_x(-sigma.y * dt),
                        dt * expm1_over_x(-sigma.z * dt));  // (1 - e^{-sigma dt}) / sigma
    vec3 j = sigma_c * cloud_source_function(origin + t_mid * dir, dir);
    light += through_clouds * exp(-sigma_m * t_start) * j * in_step;
    through_clouds *= exp(-sigma_c * dt);
}

// The clouds along [t0, t1] of the view ray (inside the layer): the light they
// scatter toward the camera (attenuated by the clouds and the homogeneous
// medium before it) and their transmittance, by the march of physics.md
// section 4; t_half, where their transmittance from t0 first falls below 1/2
// (t1 if it never does: where the other media of the layer split, section 5).
void cloud_march(vec3 origin, vec3 dir, float t0, float t1, OUT(vec3) light, OUT(float) through_clouds,
                 OUT(float) t_half) {
    light = vec3(0.0f);
    through_clouds = 1.0f;
    t_half = t1;
    if (CLOUDS_MARCH) {
        int steps = int(frame.march_steps);
        float dt = (t1 - t0) / float(steps);
        for (int k = 0; k < steps; ++k) {
            float t = t0 + (float(k) + 0.5f) * dt;
            float density = cloud_density(origin + t * dir);
            if (density > 0.0f) cloud_step(origin, dir, t, dt, density, through_clouds, light);
            if (t_half == t1 && through_clouds < 0.5f) t_half = t + 0.5f * dt;
        }
        return;
    }
    float near_step = (frame.clouds.layer.y - frame.clouds.layer.x) / frame.clouds.lighting.y;
    vec3 bound = cloud_source_bound(dir);
    float t = t0;
    // The rest of the ray adds at most through_clouds x bound: stop once that
    // is below the culling fraction of the light found so far.
    while (t < t1 && through_clouds > 0.0f && !negligible(through_clouds * bound, light)) {
        float dt = near_step * (1.0f + t / CLOUD_STEP_GROWTH);
        float long_step = min(CLOUD_SKIP_FACTOR * dt, t1 - t);
        // A long step whose middle has no cloud shape is crossed at once.
        vec3 middle = origin + (t + 0.5f * long_step) * dir;
        float h = cloud_height_fraction(middle.y);
        if (!(h > 0.0f && h < 1.0f) || cloud_coverage_shape(middle, h) <= 0.0f) {
            t += long_step;
            continue;
        }
        int fine = max(int(ceil(long_step / dt)), 1);
        float fine_step = long_step / float(fine);
        for (int k = 0; k < fine; ++k) {
            float tk = t + (float(k) + 0.5f) * fine_step;
            float density = cloud_density(origin + tk * dir);
            if (density > 0.0f) cloud_step(origin, dir, tk, fine_step, density, through_clouds, light);
            if (t_half == t1 && through_clouds < 0.5f) t_half = tk + 0.5f * fine_step;
        }
        t += long_step;
    }
}
