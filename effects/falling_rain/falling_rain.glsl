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

// The film's pixel coordinate of the streak point s + tau d (relative to the
// camera) along film axis `axis` (r or u, with sign +1 for x and -1 for
// rows), and the tau at which it equals pixel coordinate c: each is a plane
// through the camera, linear in tau (eq. 5.1).
float rain_film_coordinate(float a, float b, float z0, float z1, float pixels, float sign_, float tau) {
    return 0.5f * pixels * (1.0f + sign_ * (a + b * tau) / (z0 + z1 * tau));
}
float rain_film_crossing(float a, float b, float z0, float z1, float pixels, float sign_, float c) {
    float k = sign_ * (2.0f * c / pixels - 1.0f);
    float den = b - k * z1;
    return abs(den) > 1e-30f ? (k * z0 - a) / den : -1.0f;
}

// The share of a box footprint of side w pixels centred at c that lies over
// the pixel [p, p + 1] along one axis (eq. 5.1): summed over the pixels it is 1.
float rain_footprint_share(float c, float p, float w) {
    return max(min(c + 0.5f * w, p + 1.0f) - max(c - 0.5f * w, p), 0.0f) / w;
}

// The drop's solid angle times the share of its footprint over pixel (x, row),
// integrated over the exposure (tau in [0, 1]) of the streak from s to e
// relative to the camera (eq. 5.1): the footprint is a square of side w
// pixels (the drop's width at the streak's middle); the integrand is a
// product of two ramps, so Simpson's rule between its breakpoints (where a
// footprint edge crosses a pixel edge) is exact up to the perspective's
// curvature. Returns (integral, tau at the middle of the time in the pixel).
vec2 rain_pixel_coverage(vec3 s, vec3 e, int x, int row, float w, float drop_radius) {
    vec3 r = vec3(frame.camera_right);
    vec3 u = vec3(frame.camera_up);
    vec3 f = vec3(frame.camera_forward);
    float width = float(frame.film_width);
    float height = float(frame.film_height);
    vec3 d = e - s;
    float xs = dot(s, r) / dot(r, r), xd = dot(d, r) / dot(r, r);
    float ys = dot(s, u) / dot(u, u), yd = dot(d, u) / dot(u, u);
    float zs = dot(s, f), zd = dot(d, f);
    float lo = 0.0f;
    float hi = 1.0f;
    rain_clip(zs - RAIN_NEAR, zd, lo, hi);
    // The times the footprint overlaps the pixel at all: the pixel grown by w / 2.
    float px = float(x);
    float py = float(row);
    float h = 0.5f * w;
    float x_lo = 2.0f * (px - h) / width - 1.0f, x_hi = 2.0f * (px + 1.0f + h) / width - 1.0f;
    float y_hi = 1.0f - 2.0f * (py - h) / height, y_lo = 1.0f - 2.0f * (py + 1.0f + h) / height;
    rain_clip(xs - x_lo * zs, xd - x_lo * zd, lo, hi);
    rain_clip(x_hi * zs - xs, x_hi * zd - xd, lo, hi);
    rain_clip(ys - y_lo * zs, yd - y_lo * zd, lo, hi);
    rain_clip(y_hi * zs - ys, y_hi * zd - yd, lo, hi);
    if (!(hi > lo)) return vec2(0.0f, -1.0f);
    // Breakpoints: a footprint edge on a pixel edge, in x (sign +1) and in rows (sign -1).
    float cuts[10];
    int n = 0;
    cuts[n++] = lo;
    for (int k = 0; k < 4; ++k) {
        float c = (k < 2 ? px : px + 1.0f) + (k % 2 == 0 ? -h : h);
        float tx = rain_film_crossing(xs, xd, zs, zd, width, 1.0f, c);
        if (tx > lo && tx < hi) cuts[n++] = tx;
        float cy = (k < 2 ? py : py + 1.0f) + (k % 2 == 0 ? -h : h);
        float ty = rain_film_crossing(ys, yd, zs, zd, height, -1.0f, cy);
        if (ty > lo && ty < hi) cuts[n++] = ty;
    }
    cuts[n++] = hi;
    for (int i = 1; i < n; ++i)  // insertion sort
        for (int j = i; j > 0 && cuts[j - 1] > cuts[j]; --j) {
            float t = cuts[j];
            cuts[j] = cuts[j - 1];
            cuts[j - 1] = t;
        }
    float total = 0.0f;
    for (int i = 0; i + 1 < n; ++i) {
        float a = cuts[i];
        float b = cuts[i + 1];
        if (!(b > a)) continue;
        float g[3];
        for (int k = 0; k < 3; ++k) {
            float t = a + 0.5f * float(k) * (b - a);
            vec3 q = s + t * d;
            float cx = rain_film_coordinate(xs, xd, zs, zd, width, 1.0f, t);
            float cy = rain_film_coordinate(ys, yd, zs, zd, height, -1.0f, t);
            g[k] = rain_footprint_share(cx, px, w) * rain_footprint_share(cy, py, w) * PI * drop_radius *
                   drop_radius / dot(q, q);
        }
        total += (b - a) / 6.0f * (g[0] + 4.0f * g[1] + g[2]);
    }
    return vec2(total, 0.5f * (lo + hi));
}

// The optical depth of the medium's rain between the camera and distance t
// that the drawn drops stand for (eq. 2.4), linear between the table's texels.
float rain_near_optical_depth(float t) {
    float reach = frame.falling_rain.near_depth.x;
    float c = clamp(t / reach, 0.0f, 1.0f) * float(RAIN_NEAR_DEPTH_TEXELS - 1);
    int i = min(int(c), RAIN_NEAR_DEPTH_TEXELS - 2);
    return mix(table_texel(TABLE_RAIN_NEAR_DEPTH, i, 0), table_texel(TABLE_RAIN_NEAR_DEPTH, i + 1, 0), c - float(i));
}
