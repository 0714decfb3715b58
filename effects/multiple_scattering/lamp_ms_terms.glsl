// The point lamps' multiple scattering in the homogeneous medium
// (effects/multiple_scattering/physics.md sections 10 to 13), added to their
// exact single scattering (effects/lamp_airlight/lamp_terms.glsl): hooks
// view_glow (the fog's glow) and surface_irradiance (the diffuse light on surfaces).

// One channel of the field: exp(log_scale) L(tau, gamma) with the table's log L
// (lamp_ms_math.glsl); no light at or beyond LAMP_MS_TAU_MAX (section 12).
float lamp_ms_channel(int channel, float log_scale, float tau, float y) {
    if (tau >= LAMP_MS_TAU_MAX) return 0.0f;
    vec4 t = table_bilinear4(TABLE_LAMP_MS_GLOW, LAMP_MS_NX, LAMP_MS_NY, lamp_ms_x(tau), y);
    float log_l = channel == 0 ? t.x : (channel == 1 ? t.y : t.z);
    return exp(log_scale + log_l);
}

// The radiance of lamp `light`'s light scattered at least twice arriving at
// a point q from direction dir (looking along dir), times exp(-sigma_t t):
// I sigma_t^2 e^{-sigma_t t} L(sigma_t R, gamma) per channel (section 11); v is
// the vector from q to the lamp (relative, so that far from the origin it
// keeps its precision), R its length, gamma its angle from dir.
vec3 lamp_ms_field(PointLightGpu light, vec3 v, vec3 dir, float t) {
    float dist = length(v);
    float gamma = atan(length(cross(dir, v)), dot(dir, v));
    float y = lamp_ms_y(gamma);
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 intensity = vec3(light.intensity);
    if (GREY_MEDIUM) {
        // One lookup; the channels differ by I only (the table's channels hold one albedo).
        float peak = max(max(intensity.x, intensity.y), intensity.z);
        if (peak <= 0.0f || sigma_t.x <= 0.0f) return vec3(0.0f);
        float log_scale = log(peak) + 2.0f * log(sigma_t.x) - sigma_t.x * t;
        return (intensity / peak) * lamp_ms_channel(0, log_scale, sigma_t.x * dist, y);
    }
    vec3 field = vec3(0.0f);
    for (int c = 0; c < 3; ++c) {
        if (intensity[c] <= 0.0f || sigma_t[c] <= 0.0f) continue;
        field[c] = lamp_ms_channel(c, log(intensity[c]) + 2.0f * log(sigma_t[c]) - sigma_t[c] * t, sigma_t[c] * dist, y);
    }
    return field;
}

// Hook view_glow: every lamp's multiply scattered light over [0, t_hit]: the
// field at the camera less the field beyond the hit point seen through the
// segment (section 11; surfaces neither block nor reflect the diffuse light).
vec3 lamp_ms_view_glow(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!LAMP_MULTIPLE_SCATTERING) return radiance;
    vec3 sum = vec3(0.0f);
    for (int i = 0; i < point_light_count(); ++i) {
        PointLightGpu light = point_light(i);
        vec3 v = vec3(light.position_radius) - origin;
        // A camera inside the lamp's sphere sees the fog from where the ray
        // leaves the sphere, as for the single scattering (lamp_terms.glsl).
        float radius = light.position_radius.w;
        float x0 = 0.0f;
        if (dot(v, v) < radius * radius) {
            float b = dot(v, dir);
            x0 = b + sqrt(max(radius * radius - (dot(v, v) - b * b), 0.0f));
        }
        if (x0 >= t_hit) continue;
        vec3 glow = lamp_ms_field(light, v - x0 * dir, dir, x0);
        if (t_hit < NO_HIT) glow -= lamp_ms_field(light, v - t_hit * dir, dir, t_hit);
        sum += max(glow, vec3(0.0f));
    }
    layer_add(LAYER_LAMPS, sum);
    return radiance + sum;
}

// The surface rows of the table (lamp_ms_math.glsl): log E per albedo channel
// (xyz) and the culling bound (w), bilinear at (X, Y).
vec4 lamp_ms_surface_texels(float X, float Y) {
    int ix;
    int iy;
    float ax;
    float ay;
    table_cell(LAMP_MS_NX, LAMP_MS_NB, X, Y, ix, iy, ax, ay);
    int row = LAMP_MS_NY + iy;
    vec4 bottom = mix(table_texel4(TABLE_LAMP_MS_GLOW, ix, row), table_texel4(TABLE_LAMP_MS_GLOW, ix + 1, row), ax);
    vec4 top = mix(table_texel4(TABLE_LAMP_MS_GLOW, ix, row + 1), table_texel4(TABLE_LAMP_MS_GLOW, ix + 1, row + 1), ax);
    return mix(bottom, top, ay);
}

// An upper bound of log E(tau, beta) over beta and the channels, for the
// interpolated table at X: the larger of the two columns' bounds (physics.md
// section 13; a bilinear value never exceeds its largest node).
float lamp_ms_surface_log_bound(float X) {
    int ix;
    int iy;
    float ax;
    float ay;
    table_cell(LAMP_MS_NX, LAMP_MS_NB, X, 0.0f, ix, iy, ax, ay);
    return max(table_texel4(TABLE_LAMP_MS_GLOW, ix, LAMP_MS_NY).w, table_texel4(TABLE_LAMP_MS_GLOW, ix + 1, LAMP_MS_NY).w);
}

// Hook surface_irradiance: the light of every point lamp scattered at least
// twice, arriving on the surface point p with unit normal n:
// I sigma_t^2 E(sigma_t R, beta) per channel (physics.md section 13, eq. 13.2),
// R the distance to the lamp (held at its radius inside it), beta the normal's
// angle from the lamp's direction. Not shadowed (the medium is taken as
// infinite: surfaces neither block nor reflect the diffuse field). A lamp whose
// bound is negligible against the irradiance so far is skipped, as
// point_light_irradiance skips its direct light and glow.
vec3 lamp_ms_surface_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    vec3 sum = vec3(0.0f);
    if (!LAMP_MULTIPLE_SCATTERING) return sum;
    vec3 sigma_t = vec3(frame.sigma_t);
    for (int i = 0; i < point_light_count(); ++i) {
        PointLightGpu light = point_light(i);
        vec3 v = vec3(light.position_radius) - p;
        float dist = length(v);
        if (dist <= 0.0f) continue;
        float r = max(dist, light.position_radius.w);
        float y = lamp_ms_surface_y(dot(n, v) / dist);
        vec3 intensity = vec3(light.intensity);
        if (GREY_MEDIUM) {
            // One lookup; the channels differ by I only (the table's channels hold one albedo).
            float peak = max(max(intensity.x, intensity.y), intensity.z);
            float tau = sigma_t.x * r;
            if (peak <= 0.0f || sigma_t.x <= 0.0f || tau >= LAMP_MS_TAU_MAX) continue;
            float x = lamp_ms_x(tau);
            float log_scale = log(peak) + 2.0f * log(sigma_t.x);
            vec3 share = intensity / peak;
            if (negligible(share * exp(log_scale + lamp_ms_surface_log_bound(x)), so_far + sum)) continue;
            sum += share * exp(log_scale + lamp_ms_surface_texels(x, y).x);
            continue;
        }
        vec3 bound = vec3(0.0f);
        vec3 log_scale = vec3(0.0f);
        vec3 x = vec3(0.0f);
        for (int c = 0; c < 3; ++c) {
            float tau = sigma_t[c] * r;
            if (intensity[c] <= 0.0f || sigma_t[c] <= 0.0f || tau >= LAMP_MS_TAU_MAX) continue;
            x[c] = lamp_ms_x(tau);
            log_scale[c] = log(intensity[c]) + 2.0f * log(sigma_t[c]);
            bound[c] = exp(log_scale[c] + lamp_ms_surface_log_bound(x[c]));
        }
        if (negligible(bound, so_far + sum)) continue;
        for (int c = 0; c < 3; ++c) {
            if (bound[c] <= 0.0f) continue;
            vec4 t = lamp_ms_surface_texels(x[c], y);
            float log_e = c == 0 ? t.x : (c == 1 ? t.y : t.z);
            sum[c] += exp(log_scale[c] + log_e);
        }
    }
    return sum;
}
