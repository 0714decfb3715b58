// Spotlights in a homogeneous medium (effects/spotlights/physics.md): the profile, the
// exact ray-cone intersection and the airlight over the lit part of a view
// ray, by the local-moment tail table (effects/spotlights/docs/spot_table.md). Requires
// table_texel4(table, x, y) and the helpers of airlight.glsl.

// The profile formula I(theta) / I0 = (1 - q)(cos theta - cos A) / (1 - cos A)
// + q (effects/spotlights/physics.md) for cos theta = ct and sin^2 theta = st2, the
// first term clamped at 0. For narrow cones (cos A >= 1/2) the difference of
// two close cosines is formed as (sin^2 A - sin^2 theta) / (cos theta + cos A)
// without cancellation; for wide cones ct - cos A is well conditioned against
// 1 - cos A >= 1/2, and the sine form would be 0/0 along a 90 degree cone's
// wall (a surface lit by a spot that lies on it).
float spot_profile_formula(SpotLightGpu s, float ct, float st2) {
    float c = s.axis_cos.w;
    float q = s.intensity_edge.w;
    float cos_difference = c >= 0.5f ? (s.cone.x - st2) / (ct + c) : ct - c;
    return max((1.0f - q) * cos_difference / s.cone.y, 0.0f) + q;
}

// I(theta) / I0 for cos theta = ct and sin^2 theta = st2, 0 outside the cone:
// inside is ct >= 0 and sin^2 theta <= sin^2 A (A <= 90 degrees), not ct >=
// cos A, which float32 rounds to ct >= 1 for cones below about 0.02 degree.
float spot_profile(SpotLightGpu s, float ct, float st2) {
    // Wide cones (cos A < 1/2) keep ct >= cos A, well conditioned there; sin^2 theta of a
    // direction along a 90 degree cone's wall may round above sin^2 A = 1.
    bool inside = s.axis_cos.w >= 0.5f ? ct >= 0.0f && st2 <= s.cone.x : ct >= s.axis_cos.w;
    return inside ? spot_profile_formula(s, ct, st2) : 0.0f;
}

// I(theta) / I0 in the emission direction `dir` (unit) from the spot.
float spot_profile_toward(SpotLightGpu s, vec3 dir) {
    vec3 axis = vec3(s.axis_cos);
    vec3 across = cross(dir, axis);
    return spot_profile(s, dot(dir, axis), dot(across, across));
}

// a * b - c * d with one rounding (Kahan's difference of products).
float difference_of_products(float a, float b, float c, float d) {
    float w = c * d;
    float e = fma(-c, d, w);
    float f = fma(a, b, -w);
    return f + e;
}

vec3 cross_accurate(vec3 u, vec3 v) {
    return vec3(difference_of_products(u.y, v.z, u.z, v.y), difference_of_products(u.z, v.x, u.x, v.z),
                difference_of_products(u.x, v.y, u.y, v.x));
}

// A spot seen from a view ray, in the ray's closest-point frame: tau = x - b,
// h the closest distance, and the axis components along d, m (towards the
// spot from the closest point) and n = d x m.
struct SpotRay {
    float b;
    float h;
    float da;
    float ma;
    float na;
};

// The closest-point frame of the ray origin + x dir (unit) seen from a spot
// at origin + rel with unit axis `axis` (effects/spotlights/docs/spot_table.md section 4):
// m = d x c1 / |c1| points from the closest ray point to the spot, n = -c1 / |c1|,
// c1 = rel x d. A ray through the spot's centre (c1 = 0) takes any unit m
// across the ray; h is floored at h_floor (> 0) for the 1/h scale only.
SpotRay spot_ray_frame(vec3 rel, vec3 axis, vec3 dir, float h_floor) {
    SpotRay r;
    r.b = dot(rel, dir);
    vec3 c1 = cross_accurate(rel, dir);
    float closest = length(c1);
    vec3 m;
    if (closest > 0.0f) {
        m = cross(dir, c1) / closest;
    } else {
        vec3 across = cross(dir, abs(dir.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f));
        m = normalize(across);
    }
    vec3 n = cross(dir, m);
    r.h = max(closest, h_floor);
    r.da = dot(dir, axis);
    r.ma = dot(m, axis);
    r.na = dot(n, axis);
    return r;
}

// True when tau lies in the forward nappe of the cone (the mirror nappe of
// the quadratic is rejected here). The point v = tau d - h m from the spot
// has axial part ax and squared distance from the axis |v x a|^2 =
// h^2 na^2 + tau^2 na^2 + (tau ma + h da)^2, lit when that is <= sin^2 A |v|^2:
// free of the cancellation of ax^2 >= cos^2 A |v|^2, whose cos A rounds to 1
// in float32 for cones below about 0.02 degree (no light at all).
bool spot_lit_at(SpotLightGpu s, SpotRay r, float tau) {
    float ax = tau * r.da - r.h * r.ma;
    float c = s.axis_cos.w;
    if (c < 0.5f) return ax >= 0.0f && ax * ax >= c * c * (tau * tau + r.h * r.h);  // wide: well conditioned
    float across = tau * r.ma + r.h * r.da;
    float off_axis2 = (tau * tau + r.h * r.h) * (r.na * r.na) + across * across;
    return ax >= 0.0f && off_axis2 <= s.cone.x * (tau * tau + r.h * r.h);
}

// The lit part [lo, hi] (in tau) of the ray segment [tau_start, tau_end]
// (tau_end may be NO_HIT): exact ray-cone intersection in the sin^2 A form of
// effects/spotlights/docs/spot_table.md section 4. The forward nappe is convex, so the lit part
// is one interval; returns false when it is empty. wall_lo / wall_hi tell
// whether an end lies on the cone wall (else it is a clipping end).
bool spot_lit_interval(SpotLightGpu s, SpotRay r, float tau_start, float tau_end, OUT(float) lo, OUT(float) hi,
                       OUT(bool) wall_lo, OUT(bool) wall_hi) {
    float c = s.axis_cos.w;
    float s2 = s.cone.x;
    float A = s2 - r.ma * r.ma - r.na * r.na;  // (d.a)^2 - cos^2 A
    float C0 = r.h * r.h * (s2 - r.da * r.da - r.na * r.na);
    float rad = s2 - r.na * r.na;
    // Break points: the segment's ends and the finite roots inside it, sorted.
    float p0 = tau_start;
    float p1 = NO_HIT;
    float p2 = NO_HIT;
    if (rad >= 0.0f) {
        float hb = r.h * r.da * r.ma;
        float qq = hb + (hb >= 0.0f ? 1.0f : -1.0f) * c * r.h * sqrt(rad);
        float r1 = qq / A;
        float r2 = C0 / qq;
        bool ok1 = abs(r1) < NO_HIT && r1 > tau_start && r1 < tau_end;  // false for inf and NaN
        bool ok2 = abs(r2) < NO_HIT && r2 > tau_start && r2 < tau_end;
        if (ok1 && ok2) {
            p1 = min(r1, r2);
            p2 = max(r1, r2);
        } else if (ok1) {
            p1 = r1;
        } else if (ok2) {
            p1 = r2;
        }
    }
    // Sub-intervals [p0, p1], [p1, p2], [p2, end] (those that exist); the lit
    // ones are contiguous.
    bool found = false;
    lo = 0.0f;
    hi = 0.0f;
    wall_lo = false;
    wall_hi = false;
    for (int k = 0; k < 3; ++k) {
        float a = k == 0 ? p0 : (k == 1 ? p1 : p2);
        float e = k == 0 ? (p1 < NO_HIT ? p1 : tau_end) : (k == 1 ? (p2 < NO_HIT ? p2 : tau_end) : tau_end);
        if (a >= NO_HIT || !(e > a)) continue;
        float mid = e >= NO_HIT ? a + max(r.h, abs(a)) : 0.5f * (a + e);
        if (!spot_lit_at(s, r, mid)) continue;
        if (!found) {
            lo = a;
            wall_lo = k > 0;
            found = true;
        }
        hi = e;
        wall_hi = e < tau_end;
    }
    return found;
}

// The spot tail at tau, per unit I0 and in units of sigma_s I0 / (2 pi h)
// exp(-sigma (x + d)): Q (I_v - 2 beta cos(theta_v) M2 + beta g_v M1), and the
// sum of the magnitudes of its terms (for the cancellation test). Q, M1 and M2
// are those of the isotropic medium (lobe < 0), or of phase lobe `lobe`, whose
// moments are taken under its phase-weighted tail (effects/phase/docs/phase_table.md
// section 7: the identity holds for any phase function).
float spot_tail(SpotLightGpu s, SpotRay r, float sigma, float tau, bool wall, int lobe, OUT(float) magnitude,
                OUT(float) ct, OUT(float) g, OUT(float) profile) {
    float h = r.h;
    float dd;
    float Q;
    float M1;
    float M2;
    if (lobe >= 0) {
        LobeEnd e = lobe_end(lobe, sigma, h, tau);
        dd = e.d;
        Q = e.N * e.texel.x;
        M1 = e.N1 * e.texel.y;
        M2 = 0.5f * e.N1 * e.N1 * e.texel.z;
    } else {
        dd = sqrt(h * h + tau * tau);
        float p = tau >= 0.0f ? dd + tau : h * h / (dd - tau);  // d + x - b
        float t = p / h;
        float cv = 0.5f * atan(h, tau);
        float z = min(sigma * sqrt(2.0f * dd * p), 1.0e20f);
        float lam = 2.0f * sigma * dd * t;
        vec4 T = table_bilinear4(TABLE_SPOT_MOMENTS, AIRLIGHT_TAIL_NX, AIRLIGHT_TAIL_NY, sqrt(z / (1.0f + z)),
                                 1.0f - cv * (2.0f / PI));
        float N = cv / (1.0f + lam * cv);
        float N1 = cv / (1.0f + 0.5f * lam * cv);
        Q = N * T.x;
        M1 = N1 * T.y;
        M2 = 0.5f * N1 * N1 * T.z;
    }
    ct = (tau * r.da - h * r.ma) / dd;
    g = (h * r.da + tau * r.ma) / dd;
    profile = wall ? s.intensity_edge.w : spot_profile_formula(s, ct, r.na * r.na + g * g);
    float beta = s.cone.z;
    magnitude = Q * (abs(profile) + 2.0f * beta * abs(ct) * M2 + beta * abs(g) * M1);
    return Q * (profile - 2.0f * beta * ct * M2 + beta * g * M1);
}

// The fallback of spot_lobe_airlight in an isotropic medium: 4-point
// Gauss-Legendre in xi over [xi(lo), xi(hi)] of exp(-u (tan xi - tan xi0))
// times the profile's local expansion about lo at Delta = xi - xi0
// (effects/spotlights/docs/spot_table.md section 3). length_lit = hi - lo, formed by the caller
// without cancellation.
float spot_isotropic_quadrature(SpotLightGpu s, SpotRay r, float sigma, float lo, float hi, float length_lit,
                                float profile0, float ct0, float g0) {
    float h = r.h;
    float cv0 = 0.5f * atan(h, lo);
    float dv = hi >= NO_HIT ? cv0 : 0.5f * atan(h * length_lit, h * h + lo * hi);
    float u = sigma * h;
    float s0 = sin(cv0);
    float beta = s.cone.z;
    float J = 0.0f;
    for (int k = 0; k < 4; ++k) {
        float D = dv * 0.5f * (1.0f + gauss4_node(k));
        float sD = sin(D);
        float I = max(profile0 - 2.0f * beta * ct0 * sD * sD + beta * g0 * sin(2.0f * D), 0.0f);
        float w = D < cv0 ? exp(-u * sD / (s0 * sin(cv0 - D))) : 0.0f;
        J += 0.5f * gauss4_weight(k) * I * w;
    }
    return J * dv;
}

// The fallback of spot_lobe_airlight for phase lobe `lobe`: 4-point
// Gauss-Legendre in phi over [phi(lo), phi(hi)] of rho(phi)
// exp(-u k (tan phi - tan phi0)) times the profile's local expansion about lo
// at Delta = xi - xi0, tan xi = k tan phi (effects/phase/docs/phase_table.md section 7).
// length_lit = hi - lo, formed by the caller without cancellation.
float spot_lobe_quadrature(SpotLightGpu s, SpotRay r, float sigma, float lo, float hi, float length_lit, int lobe,
                           float profile0, float ct0, float g0) {
    PhaseLobeGpu l = phase_lobe(lobe);
    float k = l.shape.x;
    float h = r.h;
    LobeEnd e0 = lobe_end(lobe, sigma, h, lo);
    float dphi = e0.cvp;
    if (hi < NO_HIT) dphi = lobe_angle_between(lobe, h, e0, lobe_end(lobe, sigma, h, hi), length_lit);
    float uk = sigma * h * k;
    float s0 = sin(e0.cvp);
    float c0 = cos(e0.cvp);
    float beta = s.cone.z;
    float J = 0.0f;
    for (int j = 0; j < 4; ++j) {
        float D = 0.5f * dphi * (1.0f + gauss4_node(j));
        float c1 = e0.cvp - D;
        if (!(c1 > 0.0f)) continue;
        float s1 = sin(c1);
        // tan(xi) = k tan(phi): Delta = xi - xi0 from phi - phi0 = D
        float delta = atan(k * sin(D), s1 * s0 + k * k * cos(c1) * c0);
        float sd = sin(delta);
        float I = max(profile0 - 2.0f * beta * ct0 * sd * sd + beta * g0 * sin(2.0f * delta), 0.0f);
        J += 0.5f * gauss4_weight(j) * I * lobe_density(l, c1) * exp(-uk * sin(D) / (s0 * s1));
    }
    return J * dphi;
}

// Airlight of a spot over its lit interval [lo, hi] of the view ray, one
// channel and one phase lobe (lobe < 0: isotropic medium): scale
// exp(-sigma (x_lo + d_lo)) J (effects/spotlights/docs/spot_table.md section 3), scale =
// sigma_s I0 / (2 pi h) > 0 folded into the exponent. J is the difference of
// two spot tails, or, where that difference would amplify the table error
// more than 4 times, 4-point Gauss-Legendre on the exact integrand written
// about lo: in xi when isotropic, in the lobe's phi (effects/phase/docs/phase_table.md
// section 7) otherwise.
float spot_lobe_airlight(SpotLightGpu s, SpotRay r, float sigma, float lo, float hi, bool wall_lo, bool wall_hi,
                         float clip_length, int lobe, float scale) {
    float mag0;
    float ct0;
    float g0;
    float profile0;
    float tail0 = spot_tail(s, r, sigma, lo, wall_lo, lobe, mag0, ct0, g0, profile0);
    float arg0 = -sigma * (r.b + lo + sqrt(r.h * r.h + lo * lo));
    bool escapes = hi >= NO_HIT;
    float J = tail0;
    float mag = mag0;
    if (!escapes) {
        float mag1;
        float ct1;
        float g1;
        float profile1;
        float tail1 = spot_tail(s, r, sigma, hi, wall_hi, lobe, mag1, ct1, g1, profile1);
        float arg1 = -sigma * (r.b + hi + sqrt(r.h * r.h + hi * hi));
        float ratio = exp(arg1 - arg0);
        J = tail0 - ratio * tail1;
        mag = mag0 + ratio * mag1;
    }
    if (!(mag <= 4.0f * abs(J))) {
        float length_lit = (wall_lo || wall_hi) ? hi - lo : clip_length;
        J = lobe >= 0 ? spot_lobe_quadrature(s, r, sigma, lo, hi, length_lit, lobe, profile0, ct0, g0)
                      : spot_isotropic_quadrature(s, r, sigma, lo, hi, length_lit, profile0, ct0, g0);
    }
    return max(J, 0.0f) * exp(arg0 + log(scale));
}

// spot_lobe_airlight for the medium's phase function: isotropic, or the
// weighted sum over its lobes.
float spot_airlight_channel(SpotLightGpu s, SpotRay r, float sigma, float lo, float hi, bool wall_lo, bool wall_hi,
                            float clip_length, float scale) {
    if (!HAS_PHASE) return spot_lobe_airlight(s, r, sigma, lo, hi, wall_lo, wall_hi, clip_length, -1, scale);
    float sum = 0.0f;
    for (int lobe = 0; lobe < phase_lobe_count(); ++lobe) {
        float w = phase_lobe(lobe).info.w;
        if (w > 0.0f) sum += spot_lobe_airlight(s, r, sigma, lo, hi, wall_lo, wall_hi, clip_length, lobe, scale * w);
    }
    return sum;
}

// Brute-force airlight of a point light, or of spot number spot_index (>= 0),
// on [x0, x1]: the midpoint rule with frame.march_steps steps on the defining
// integral (effects/lamp_airlight/physics.md and effects/spotlights/physics.md), escaping rays cut at frame.march_far
// metres; `shadowed`: a step counts only where a shadow ray reaches the lamp
// (volumetric shadows, effects/light_shafts/physics.md section 7). For benchmarks only.
vec3 airlight_march(vec3 light_position, vec3 intensity, int spot_index, bool shadowed, vec3 origin, vec3 dir,
                    float x0, float x1) {
    bool spot = spot_index >= 0;
    SpotLightGpu s;
    if (spot) s = spot_light(spot_index);
    float x_end = min(x1, frame.march_far);
    int steps = int(frame.march_steps);
    float dx = (x_end - x0) / float(steps);
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 sum = vec3(0.0f);
    for (int k = 0; k < steps; ++k) {
        float x = x0 + (float(k) + 0.5f) * dx;
        vec3 from_light = origin + x * dir - light_position;
        float d2 = dot(from_light, from_light);
        float d = sqrt(d2);
        float profile = spot ? spot_profile_toward(s, from_light / d) : 1.0f;
        if (shadowed && segment_occluded(origin + x * dir, -from_light / d, d, -1)) continue;
        sum += profile * medium_phase_between(from_light / d, -dir) * exp(-sigma_t * (x + d)) / d2;
    }
    return vec3(frame.sigma_s) * intensity * sum * (dx / (4.0f * PI));
}

// A spot's airlight over the part [lo, hi] (closest-point coordinates tau) of
// the view ray inside its beam, per channel (spot_airlight_channel; wall_lo,
// wall_hi: an end on the cone's wall; clip_length: hi - lo formed without
// cancellation).
vec3 spot_airlight_part(SpotLightGpu s, SpotRay r, vec3 scale, float lo, float hi, bool wall_lo, bool wall_hi,
                        float clip_length) {
    vec3 sigma_t = vec3(frame.sigma_t);
    if (GREY_MEDIUM) {
        float peak = max(max(scale.x, scale.y), scale.z);
        if (!(peak > 0.0f)) return vec3(0.0f);
        return (scale / peak) * spot_airlight_channel(s, r, sigma_t.x, lo, hi, wall_lo, wall_hi, clip_length, peak);
    }
    return vec3(
        scale.x > 0.0f ? spot_airlight_channel(s, r, sigma_t.x, lo, hi, wall_lo, wall_hi, clip_length, scale.x) : 0.0f,
        scale.y > 0.0f ? spot_airlight_channel(s, r, sigma_t.y, lo, hi, wall_lo, wall_hi, clip_length, scale.y) : 0.0f,
        scale.z > 0.0f ? spot_airlight_channel(s, r, sigma_t.z, lo, hi, wall_lo, wall_hi, clip_length, scale.z) : 0.0f);
}

// Airlight of spot number spot_index over the visible part [0, x_end] of the view ray from
// the camera (effects/spotlights/physics.md): only the lit part of the ray scatters. A
// camera inside the lamp's sphere sees fog from where the ray leaves it.
// Skipped when the point-light bound (the profile is <= 1) is negligible
// against `so_far`.
vec3 spot_light_airlight(int spot_index, vec3 dir, float x_end, vec3 so_far) {
    SpotLightGpu s = spot_light(spot_index);
    vec3 Sr = vec3(s.relative_position_radius);
    float radius = s.relative_position_radius.w;
    float dist = length(Sr);
    SpotRay r = spot_ray_frame(Sr, vec3(s.axis_cos), dir, 1.0e-6f * max(dist, radius));
    float x0 = 0.0f;
    if (dist < radius) x0 = r.b + sqrt(max(radius * radius - r.h * r.h, 0.0f));
    if (x0 >= x_end) return vec3(0.0f);
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 scale = vec3(frame.sigma_s) * vec3(s.intensity_edge) / (2.0f * PI * r.h);
    float min_sigma_t = min(min(sigma_t.x, sigma_t.y), sigma_t.z);
    if (negligible(scale * (frame.phase.airlight_bound * exp(-min_sigma_t * max(dist - radius, 0.0f))), so_far)) return vec3(0.0f);
    float lo;
    float hi;
    bool wall_lo;
    bool wall_hi;
    float tau_end = x_end >= NO_HIT ? NO_HIT : x_end - r.b;
    if (!spot_lit_interval(s, r, x0 - r.b, tau_end, lo, hi, wall_lo, wall_hi)) return vec3(0.0f);
    bool shadowed = HAS_LAMP_SHADOWS && s.cone.w != 0.0f;
    if (AIRLIGHT_MARCH) {
        return airlight_march(vec3(s.world_position), vec3(s.intensity_edge), spot_index, shadowed,
                              vec3(frame.camera_position), dir, lo + r.b, hi >= NO_HIT ? NO_HIT : hi + r.b);
    }
    // The beam's lit part [lo, hi] less the surfaces' shadows with volumetric
    // shadows (effects/light_shafts/physics.md section 7); a part's end at a
    // shadow's edge is no wall of the cone. The parts before each shadowed run
    // and after the last (k == runs) go through one call site, so that GL
    // compiles the beam's integral once (docs/architecture.md, "GL compile time").
    float x_hi = hi >= NO_HIT ? NO_HIT : hi + r.b;
    if (shadowed) find_shadow_runs(vec3(frame.camera_position), dir, x_hi, vec4(vec3(s.world_position), 1.0f));
    int runs = shadowed ? shadow_runs.count : 0;
    vec3 airlight = vec3(0.0f);
    float lit_from = lo + r.b;
    float part_lo = shadowed ? lit_from - r.b : lo;
    bool wall_from = wall_lo;
    for (int k = 0; k <= runs; ++k) {
        bool last = k == runs;
        vec2 run = last ? vec2(x_hi) : shadow_runs.run[k];
        if (!last && run.y <= lit_from) continue;
        bool lit = last ? (!shadowed || lit_from < x_hi) : run.x > lit_from;
        if (lit) {
            float part_hi = last ? hi : run.x - r.b;
            float clip = !last ? run.x - lit_from
                               : (!shadowed ? x_end - x0 : (x_hi >= NO_HIT ? NO_HIT : x_hi - lit_from));
            airlight += spot_airlight_part(s, r, scale, part_lo, part_hi, wall_from, last && wall_hi, clip);
        }
        lit_from = run.y;
        part_lo = lit_from - r.b;
        wall_from = false;
    }
    return airlight;
}

// spot_lit_interval for a receiver "spot" (cone angle 90 degrees: the half-
// space in front of a surface) on [tau_start, infinity): lit where
// tau da - h ma >= 0, i.e. on one side of tau = h ma / da, the crossing of the
// surface's plane, formed in the closest-point frame without cancellation.
bool receiver_lit_interval(SpotRay r, float tau_start, OUT(float) lo, OUT(float) hi, OUT(bool) wall_lo,
                           OUT(bool) wall_hi) {
    lo = tau_start;
    hi = NO_HIT;
    wall_lo = false;
    wall_hi = false;
    if (r.da == 0.0f) return r.ma <= 0.0f;
    float crossing = r.h * r.ma / r.da;
    if (r.da > 0.0f) {
        if (crossing > tau_start) {
            lo = crossing;
            wall_lo = true;
        }
        return true;
    }
    hi = crossing;
    wall_hi = true;
    return crossing > tau_start;
}

// ---- Light a spot scatters onto surfaces (its glow) ------------------------
// Irradiance at a surface point p (unit normal n) from the light of spot s
// scattered once in the medium, unshadowed like the point lamps' glow
// (effects/lamp_airlight/physics.md and effects/spotlights/physics.md; effects/spotlights/docs/spot_table.md section 9):
//   E = int over the beam's directions w of I(theta_w) / I0 * A(w) dw,
// where A(w) is the airlight seen from the spot along w of a "spot" at p with
// axis n, cone angle 90 degrees, q = 0 and intensity I0: a Lambertian receiver
// weights the light arriving from y by max(cos psi, 0) / |y - p|^2 exactly as
// a cosine-profile emitter would, so spot_airlight_channel gives A exactly.
// The outer integral is done in polar coordinates (alpha, phi) about the
// direction from the spot to p, where A ~ 1 / sin(alpha) is cancelled by the
// Jacobian sin(alpha). Along each phi the beam is an exact arc alpha in
// [a0, a1], integrated by 4-point Gauss-Legendre panels in w =
// log(alpha + alpha_c) (one per 24 / samples of w's range, at least one), alpha_c = min(1 / sqrt(1 + sigma_t D), |n.(p - S)| / D):
// dense where the light scattered near p gives a plateau (alpha < alpha_c) and
// geometric along the 1 / alpha tail of the light scattered near the spot.
// phi: the circle (p inside the beam or its mirror cone), or the wedge
// [-phi_m, phi_m] of the directions that meet the beam with
// phi = phi_m sin(pi sv / 2) absorbing its square-root ends, is cut where the
// integrand kinks (the directions along the receiver's plane, phi_n +- pi/2),
// and each piece gets samples / 4 panels of 4-point Gauss-Legendre.
// Measured error: effects/spotlights/docs/spot_table.md section 9.
vec3 spot_surface_glow(SpotLightGpu s, vec3 p, vec3 n, int samples) {
    vec3 v = p - vec3(s.world_position);
    float D = length(v);
    if (!(D > 0.0f)) return vec3(0.0f);
    vec3 to_p = v / D;
    float radius = s.relative_position_radius.w;
    if (D < radius) {  // inside the lamp's sphere: held at its value on the sphere
        D = radius;
        v = to_p * D;
    }
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 numerator = vec3(frame.sigma_s) * vec3(s.intensity_edge) / (2.0f * PI);  // scale = numerator / h
    float peak = max(max(numerator.x, numerator.y), numerator.z);
    if (!(peak > 0.0f)) return vec3(0.0f);
    // The receiver as a spot at p seen from the spot's centre.
    SpotLightGpu receiver;
    receiver.relative_position_radius = vec4(v, 0.0f);
    receiver.world_position = vec4(p, 0.0f);
    receiver.axis_cos = vec4(n, 0.0f);
    receiver.intensity_edge = vec4(vec3(s.intensity_edge), 0.0f);
    receiver.cone = vec4(1.0f, 1.0f, 1.0f, 0.0f);
    // The frame (to_p, e1, e2), e1 towards the axis: a.w = cos(alpha) ct + sin(alpha) st cos(phi).
    vec3 axis = vec3(s.axis_cos);
    float cos_a = s.axis_cos.w;
    float ct = dot(axis, to_p);
    vec3 toward_axis = axis - ct * to_p;
    float st = length(toward_axis);
    vec3 e1 = st > 1.0e-7f ? toward_axis / st
                           : normalize(cross(to_p, abs(to_p.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f)));
    vec3 e2 = cross(to_p, e1);
    float sigma_max = max(max(sigma_t.x, sigma_t.y), sigma_t.z);
    float n_to_p = dot(n, to_p);
    float alpha_c = min(1.0f / sqrt(1.0f + sigma_max * D), max(abs(n_to_p), 1.0e-4f));
    // Azimuth of the receiver's normal about to_p: at phi_n +- pi/2 the
    // directions cross the receiver's plane near p, where A jumps (the near
    // part of the ray is lit or not); the midpoint rule puts cell edges there.
    vec3 n_across = n - n_to_p * to_p;
    float phi_n = dot(n_across, n_across) > 1.0e-12f ? atan(dot(n_across, e2), dot(n_across, e1)) : 0.0f;
    // Inside the cone (or its mirror): sin^2 theta = st^2 <= sin^2 A. Outside,
    // the half great circles at azimuth phi meet the cone for |sin phi| <
    // sin A / st: phi_m = atan(sin A, sqrt(st^2 - sin^2 A)), accurate for any
    // cone (acos(sqrt(cos^2 A - ct^2) / st) loses the narrowest cones' phi_m
    // to the rounding of its argument near 1, and cos A rounds to 1 there).
    bool narrow = cos_a >= 0.5f;  // wide cones keep the cosine forms, well conditioned there
    bool within = st * st <= s.cone.x;
    bool inside = narrow ? ct >= 0.0f && within : ct >= cos_a;
    bool every_phi = narrow ? within : inside || ct <= -cos_a;
    float phi_m = every_phi ? PI
                            : (narrow ? atan(sqrt(s.cone.x), sqrt(max(st * st - s.cone.x, 0.0f)))
                                      : acos(min(sqrt(max(cos_a * cos_a - ct * ct, 0.0f)) / st, 1.0f)));
    // phi pieces, split where the receiver's plane makes the integrand kink
    // (phi_n +- pi/2), in the variable sv: phi = sv over the whole circle,
    // phi = phi_m sin(pi sv / 2) over the wedge sv in [-1, 1].
    float edges[4];
    int pieces = 0;
    if (every_phi) {
        edges[0] = phi_n - 0.5f * PI;
        edges[1] = phi_n + 0.5f * PI;
        edges[2] = phi_n + 1.5f * PI;
        pieces = 2;
    } else {
        float k0 = phi_n - 0.5f * PI;  // in (-3 pi / 2, pi / 2]
        float k1 = phi_n + 0.5f * PI;  // in (-pi / 2, 3 pi / 2]
        if (k0 <= -PI) k0 += 2.0f * PI;
        if (k1 > PI) k1 -= 2.0f * PI;
        float lo_k = min(k0, k1);
        float hi_k = max(k0, k1);
        edges[0] = -1.0f;
        pieces = 1;
        if (abs(lo_k) < phi_m) edges[pieces++] = (2.0f / PI) * asin(lo_k / phi_m);
        if (abs(hi_k) < phi_m) edges[pieces++] = (2.0f / PI) * asin(hi_k / phi_m);
        edges[pieces] = 1.0f;
    }
    int phi_panels = max(samples / 4, 1);
    vec3 E = vec3(0.0f);
    for (int j = 0; j < 4 * phi_panels * pieces; ++j) {
        int piece = j / (4 * phi_panels);
        float width = (edges[piece + 1] - edges[piece]) / float(phi_panels);
        float sv = edges[piece] + width * (float((j / 4) % phi_panels) + 0.5f * (1.0f + gauss4_node(j % 4)));
        float phi = every_phi ? sv : phi_m * sin(0.5f * PI * sv);
        float w_phi = 0.5f * width * gauss4_weight(j % 4) * (every_phi ? 1.0f : phi_m * (0.5f * PI) * cos(0.5f * PI * sv));
        vec3 e = cos(phi) * e1 + sin(phi) * e2;
        // The beam's arc on this half great circle: R cos(alpha - beta) >= cos A.
        float x = ct;
        float y = st * cos(phi);
        float R = sqrt(x * x + y * y);
        // R > cos A is 1 - R^2 = st^2 sin^2 phi < sin^2 A, and the arc's half
        // width gamma (cos gamma = cos A / R) is atan(sqrt(sin^2 A - (1 - R^2)),
        // cos A): free of the cancellation of acos(cos A / R) near 1, where
        // float32 rounds cos A to 1 for cones below about 0.02 degree.
        float sin_phi = sin(phi);
        float off_circle2 = st * st * sin_phi * sin_phi;
        if (narrow ? !(off_circle2 < s.cone.x) || !(R > 0.0f) : !(R > cos_a) || !(R > 0.0f)) continue;
        float beta = atan(y, x);
        float gamma = narrow ? atan(sqrt(s.cone.x - off_circle2), cos_a) : acos(min(cos_a / R, 1.0f));
        float a0 = inside ? 0.0f : max(beta - gamma, 0.0f);
        float a1 = min(beta + gamma, PI);
        if (!(a1 > a0)) {  // beta < 0: the arc is the one about beta + 2 pi
            a0 = max(beta + 2.0f * PI - gamma, 0.0f);
            a1 = PI;
        }
        if (!(a1 > a0)) continue;
        float w0 = log(a0 + alpha_c);
        // Panels in proportion to the arc's length in w (e-folds of alpha + alpha_c).
        float w_length = log(a1 + alpha_c) - w0;
        int alpha_panels = clamp(int(ceil(w_length * float(samples) / 24.0f)), 1, 16);
        float dw = w_length / float(alpha_panels);
        for (int k = 0; k < 4 * alpha_panels; ++k) {
            float w = w0 + dw * (float(k / 4) + 0.5f * (1.0f + gauss4_node(k % 4)));
            float alpha = exp(w) - alpha_c;
            vec3 dir = cos(alpha) * to_p + sin(alpha) * e;
            float profile = spot_profile_toward(s, dir);
            if (!(profile > 0.0f)) continue;
            SpotRay r = spot_ray_frame(v, n, dir, 1.0e-6f * D);
            float lo;
            float hi;
            bool wall_lo;
            bool wall_hi;
            if (!receiver_lit_interval(r, -r.b, lo, hi, wall_lo, wall_hi)) continue;
            float weight = w_phi * 0.5f * dw * gauss4_weight(k % 4) * (alpha + alpha_c) * sin(alpha) * profile;
            if (GREY_MEDIUM) {
                E += (weight * spot_airlight_channel(receiver, r, sigma_t.x, lo, hi, wall_lo, wall_hi, NO_HIT,
                                                     peak / r.h)) * (numerator / peak);
            } else {
                for (int c = 0; c < 3; ++c) {
                    if (numerator[c] > 0.0f)
                        E[c] += weight * spot_airlight_channel(receiver, r, sigma_t[c], lo, hi, wall_lo, wall_hi,
                                                               NO_HIT, numerator[c] / r.h);
                }
            }
        }
    }
    return E;
}
