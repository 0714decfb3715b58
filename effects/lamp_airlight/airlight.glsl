// Airlight of isotropic point lights in a homogeneous medium (effects/lamp_airlight/physics.md,
// Sun et al. 2005) and the light they scatter onto surfaces, by
// table lookups. The tables, their parametrisation and their measured errors
// are explained in effects/lamp_airlight/docs/airlight_table.md; effects/lamp_airlight/airlight_tables.cpp builds them from
// these same coordinate definitions; the lookups are shaders/tables.glsl's.

// ---- Airlight along a view ray -------------------------------------------
// Geometry of one light relative to the ray o + x d: b = (S - o).d is the
// distance along the ray to the closest approach, h > 0 the closest distance.

// scale exp(-sigma (x + d(x))) Q(u, xi(x)): the airlight integral from ray
// point x to infinity in units of sigma_s I / (2 pi h) (times `scale`, passed
// as log_scale and folded into the exponential so that a huge intensity times
// a tiny attenuation never passes through a float32 denormal), with d(x) the
// point-light distance and xi(x) = 1/2 atan2(h, b - x) (effects/lamp_airlight/physics.md).
// exp(-sigma (x + d)) <= 1, so nothing overflows however thick the fog.
float airlight_tail(float sigma, float b, float h, float x, float log_scale) {
    float xb = x - b;
    float d = sqrt(h * h + xb * xb);
    float p = xb >= 0.0f ? d + xb : h * h / (d - xb);  // d + x - b, no cancellation
    float tan_xi = p / h;
    float cv = 0.5f * atan(h, xb);                       // pi/2 - xi, accurate near pi/2
    float z = sigma * sqrt(2.0f * d * p);                // u sec xi
    float S = table_bilinear(TABLE_AIRLIGHT_TAIL, AIRLIGHT_TAIL_NX, AIRLIGHT_TAIL_NY, sqrt(z / (1.0f + z)),
                             1.0f - cv * (2.0f / PI));
    float N = cv / (1.0f + 2.0f * sigma * d * tan_xi * cv);  // u sec^2 xi = 2 sigma d tan xi
    return exp(log_scale - sigma * (x + d)) * N * S;
}

// Airlight integral over the ray segment [x0, x1] (x1 = NO_HIT: to infinity)
// in units of sigma_s I / (2 pi h), times exp(log_scale): the difference of
// two tails, or, when that difference would cancel (tail(x1) > tail(x0) / 2),
// 3-point Gauss-Legendre of the integrand exp(-u (tan xi - tan xi0)) in xi.
float airlight_segment(float sigma, float b, float h, float x0, float x1, float log_scale) {
    float tail0 = airlight_tail(sigma, b, h, x0, log_scale);
    if (x1 >= NO_HIT) return tail0;
    float tail1 = airlight_tail(sigma, b, h, x1, log_scale);
    if (tail1 <= 0.5f * tail0) return tail0 - tail1;
    float xb0 = x0 - b;
    float cv0 = 0.5f * atan(h, xb0);
    float dv = 0.5f * atan(h * (x1 - x0), h * h + xb0 * (x1 - b));  // xi(x1) - xi(x0)
    float u = sigma * h;
    float s0 = sin(cv0);
    // tan(xi0 + e) - tan(xi0) = sin e / (sin cv0 sin(cv0 - e)); nodes at (1 +- sqrt(3/5)) / 2.
    float e0 = dv * 0.11270166537925831f;
    float e1 = dv * 0.5f;
    float e2 = dv * 0.88729833462074169f;
    float sum = (5.0f / 18.0f) * exp(-u * sin(e0) / (s0 * sin(cv0 - e0))) +
                (8.0f / 18.0f) * exp(-u * sin(e1) / (s0 * sin(cv0 - e1))) +
                (5.0f / 18.0f) * exp(-u * sin(e2) / (s0 * sin(cv0 - e2)));
    float d0 = sqrt(h * h + xb0 * xb0);
    return exp(log_scale - sigma * (x0 + d0)) * sum * dv;
}

// ---- Light scattered onto surfaces ----------------------------------------
// G(T, theta_s) = e^{T} G0(T, theta_s); the irradiance from light scattered
// once on the way is sigma_s I / (2 pi D) e^{-T} G (effects/lamp_airlight/physics.md).
// Row coordinate: Y = (1 + asinh(K c) / asinh(K)) / 2, c = cos theta_s,
// K = max(T, k_min): linear in c for thin media, logarithmic in c for
// optically distant lights, whose glow turns from lit (c > 0) to unlit
// (c < 0) over a width ~1/T around c = 0 (k_min = 1e-4 isotropic; a forward
// HG lobe's terminator is sharp even in thin fog: k_min = 2 / (1 - g)).
// log G(T, theta_s) from the table (it stores log G: interpolating the
// logarithm keeps the relative error even where G varies like log(T) / T).
float surface_glow_log_lookup(int table, float k_min, float optical_distance, float cos_theta_s, int nx, int ny) {
    float T = min(optical_distance, SURFACE_GLOW_T_MAX);
    float c = clamp(cos_theta_s, -1.0f, 1.0f);
    float k = max(T, k_min);
    float Y = 0.5f + 0.5f * asinh(k * c) / asinh(k);
    float X = sqrt(log(1.0f + T / SURFACE_GLOW_T_SCALE) / log(1.0f + SURFACE_GLOW_T_MAX / SURFACE_GLOW_T_SCALE));
    return table_bilinear(table, nx, ny, X, Y);
}

// scale e^{-T} G(T, theta_s) = scale G0(T, theta_s), for scale >= 0, as one
// exponential: the product stays exact where e^{-T} G alone would be a
// denormal that a GPU flushes to zero (huge intensities at large T).
float scaled_surface_glow(float scale, float optical_distance, float cos_theta_s) {
    if (scale <= 0.0f) return 0.0f;
    return exp(surface_glow_log_lookup(TABLE_SURFACE_GLOW, SURFACE_GLOW_K_MIN, optical_distance, cos_theta_s,
                                       SURFACE_GLOW_NX, SURFACE_GLOW_NY) -
               optical_distance + log(scale));
}
