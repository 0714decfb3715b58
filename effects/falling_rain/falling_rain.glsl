// The falling rain's per-pixel functions (physics.md sections 4 and 5): the
// drop's optics from its table, and the share of the exposure a streak
// spends in a pixel.

// Texel k of a table laid out in rows of RAIN_ROW_TEXELS.
vec4 rain_texel4(int table, int k) { return table_texel4(table, k % RAIN_ROW_TEXELS, k / RAIN_ROW_TEXELS); }
int rain_index_at(int k) {
    return int(table_texel(TABLE_RAIN_TILES, k % RAIN_ROW_TEXELS, k / RAIN_ROW_TEXELS));
}

// The drop's phase function f(theta) per channel (eq. 4.3): the light it
// sends per steradian along theta from the light's direction of travel, per
// unit irradiance on its cross-section; linear between bin centres. cos_theta
// = omega . v for light from direction omega seen along the view direction v
// (camera to drop).
vec3 drop_phase(float cos_theta) {
    float x = precise_acos(clamp(cos_theta, -1.0f, 1.0f)) / PI;
    float c = clamp(x * float(DROP_OPTICS_BINS) - 0.5f, 0.0f, float(DROP_OPTICS_BINS - 1));
    int i = min(int(c), DROP_OPTICS_BINS - 2);
    return mix(vec3(table_texel4(TABLE_DROP_OPTICS, i, 0)), vec3(table_texel4(TABLE_DROP_OPTICS, i + 1, 0)),
               c - float(i));
}

// The direction of the environment map's texel (i, j) (eq. 4.5): longitude
// 2 pi (i + 1/2) / W, y = 1 - 2 (j + 1/2) / H, each texel 4 pi / (W H) sr.
vec3 rain_environment_direction(int i, int j) {
    float phi = 2.0f * PI * (float(i) + 0.5f) / float(RAIN_ENV_WIDTH);
    float y = 1.0f - 2.0f * (float(j) + 0.5f) / float(RAIN_ENV_HEIGHT);
    float s = sqrt(max(1.0f - y * y, 0.0f));
    return vec3(s * cos(phi), y, s * sin(phi));
}

// The surroundings seen through a drop along view direction v (eq. 4.6):
// the rain_surround map, bilinear, wrapping in longitude.
vec3 rain_surround(vec3 v) {
    float u = atan(v.z, v.x) / (2.0f * PI);
    float w = clamp(0.5f * (1.0f - v.y), 0.5f / float(RAIN_ENV_HEIGHT), 1.0f - 0.5f / float(RAIN_ENV_HEIGHT));
    return vec3(table_bilinear4_periodic(TABLE_RAIN_SURROUND, RAIN_ENV_WIDTH, RAIN_ENV_HEIGHT, vec2(u, w)));
}

// Clips [lo, hi] of the streak parameter to where a + tau b >= 0.
void rain_clip(float a, float b, INOUT(float) lo, INOUT(float) hi) {
    if (b > 0.0f) lo = max(lo, -a / b);
    else if (b < 0.0f) hi = min(hi, -a / b);
    else if (a < 0.0f) hi = lo - 1.0f;
}

// The part [lo, hi] of the exposure (tau in [0, 1] along the streak from
// start s to end e, relative to the camera) during which the drop's centre
// projects into pixel (x, row) grown by `grow` pixels on each side (eq. 5.1):
// each film edge is a plane through the camera, linear in tau. Empty: hi <= lo.
vec2 rain_pixel_interval(vec3 s, vec3 e, int x, int row, float grow) {
    vec3 r = vec3(frame.camera_right);
    vec3 u = vec3(frame.camera_up);
    vec3 f = vec3(frame.camera_forward);
    float width = float(frame.film_width);
    float height = float(frame.film_height);
    // Film coordinates sx = (q . r) / (|r|^2 z), sy = (q . u) / (|u|^2 z), z = q . f.
    float sx_lo = 2.0f * (float(x) - grow) / width - 1.0f;
    float sx_hi = 2.0f * (float(x) + 1.0f + grow) / width - 1.0f;
    float sy_hi = 1.0f - 2.0f * (float(row) - grow) / height;
    float sy_lo = 1.0f - 2.0f * (float(row) + 1.0f + grow) / height;
    vec3 d = e - s;
    float xs = dot(s, r) / dot(r, r), xd = dot(d, r) / dot(r, r);
    float ys = dot(s, u) / dot(u, u), yd = dot(d, u) / dot(u, u);
    float zs = dot(s, f), zd = dot(d, f);
    float lo = 0.0f;
    float hi = 1.0f;
    rain_clip(zs - RAIN_NEAR, zd, lo, hi);
    rain_clip(xs - sx_lo * zs, xd - sx_lo * zd, lo, hi);
    rain_clip(sx_hi * zs - xs, sx_hi * zd - xd, lo, hi);
    rain_clip(ys - sy_lo * zs, yd - sy_lo * zd, lo, hi);
    rain_clip(sy_hi * zs - ys, sy_hi * zd - yd, lo, hi);
    return vec2(lo, hi);
}
