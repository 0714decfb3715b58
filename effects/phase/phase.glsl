// Airlight and surface glow with an anisotropic phase function (issue 5;
// effects/phase/docs/phase_table.md), by per-lobe tables built for the medium's phase
// (effects/phase/phase_tables.cpp). Used when HAS_PHASE; an isotropic medium takes the
// isotropic code of airlight.glsl. Requires the helpers of airlight.glsl and
// the pure lobe formulas of phase_math.glsl.

int phase_lobe_count() {
    return frame.phase.lobe_count;
}

PhaseLobeGpu phase_lobe(int lobe) {
    return lobe == 0 ? frame.phase.lobe0 : frame.phase.lobe1;
}

// 4 pi p of the medium (docs/conventions.md; 1 when isotropic) at the angle
// theta = 2 xi between the unit directions a (the light's, before scattering)
// and b (after): sin^2 xi = |a - b|^2 / 4 and cos^2 xi = |a + b|^2 / 4, free of
// the cancellation of (1 -+ a.b) / 2 next to a lobe's peak (with g = -0.999
// the march's airlight was 2 % off on GL).
float medium_phase_between(vec3 a, vec3 b) {
    if (!HAS_PHASE) return 1.0f;
    vec3 difference = a - b;
    vec3 sum_ab = a + b;
    float sin2_xi = 0.25f * dot(difference, difference);
    float cos2_xi = 0.25f * dot(sum_ab, sum_ab);
    float sum = 0.0f;
    for (int lobe = 0; lobe < phase_lobe_count(); ++lobe) {
        PhaseLobeGpu l = phase_lobe(lobe);
        sum += l.info.w * lobe_phase_at(l, sin2_xi, cos2_xi);
    }
    return sum;
}

// A lobe's tail at ray position tau = x - b (closest distance h): the table
// texel (S, M1/N1, M2/N2) and the normalisers, with d = |x - light| and
// p = d + tau (no cancellation).
struct LobeEnd {
    vec4 texel;
    float N;
    float N1;
    float d;
    float p;
    float cvp;
    float cv;
};

LobeEnd lobe_end(int lobe, float sigma, float h, float tau) {
    LobeEnd e;
    e.d = sqrt(h * h + tau * tau);
    e.p = tau >= 0.0f ? e.d + tau : h * h / (e.d - tau);
    float X;
    float Y;
    lobe_coordinates(phase_lobe(lobe), sigma, h, e.p, X, Y, e.N, e.N1, e.cvp, e.cv);
    e.texel = table_bilinear4(lobe == 0 ? TABLE_PHASE_MOMENTS_0 : TABLE_PHASE_MOMENTS_1, AIRLIGHT_TAIL_NX,
                              AIRLIGHT_TAIL_NY, X, Y);
    return e;
}

// phi1 - phi0 between ray points tau0 < tau1 (in the lobe's variable):
// tan(cvp0 - cvp1) = k h (p1 - p0) / (k^2 h^2 + p0 p1), p1 - p0 = (tau1 - tau0)
// (p0 + p1) / (d0 + d1) without cancellation; `length` = tau1 - tau0.
float lobe_angle_between(int lobe, float h, LobeEnd e0, LobeEnd e1, float length) {
    float kh = phase_lobe(lobe).shape.x * h;
    float dp = length * (e0.p + e1.p) / (e0.d + e1.d);
    return atan(kh * dp, kh * kh + e0.p * e1.p);
}

// One lobe's airlight over [x0, x1] (x1 = NO_HIT: to infinity) in units of
// sigma_s I / (2 pi h) times exp(log_scale) (effects/lamp_airlight/physics.md, general
// phase function): the difference of two tails, or where that would cancel
// (tail1 > tail0 / 2) 4-point Gauss-Legendre in phi, where the HG peak is gone
// (effects/phase/docs/phase_table.md section 1.6).
float lobe_segment(int lobe, float sigma, float b, float h, float x0, float x1, float log_scale) {
    LobeEnd e0 = lobe_end(lobe, sigma, h, x0 - b);
    float tail0 = exp(log_scale - sigma * (x0 + e0.d)) * e0.N * e0.texel.x;
    if (x1 >= NO_HIT) return tail0;
    LobeEnd e1 = lobe_end(lobe, sigma, h, x1 - b);
    float tail1 = exp(log_scale - sigma * (x1 + e1.d)) * e1.N * e1.texel.x;
    if (tail1 <= 0.5f * tail0) return tail0 - tail1;
    PhaseLobeGpu l = phase_lobe(lobe);
    float dphi = lobe_angle_between(lobe, h, e0, e1, x1 - x0);
    float uk = sigma * h * l.shape.x;
    float s0 = sin(e0.cvp);
    float J = 0.0f;
    for (int j = 0; j < 4; ++j) {
        float D = 0.5f * dphi * (1.0f + gauss4_node(j));
        float c1 = e0.cvp - D;
        // u k (tan phi - tan phi0) = u k sin D / (sin cvp0 sin(cvp0 - D))
        J += 0.5f * gauss4_weight(j) * lobe_density(l, c1) * exp(-uk * sin(D) / (s0 * sin(c1)));
    }
    return exp(log_scale - sigma * (x0 + e0.d)) * J * dphi;
}

// The medium's airlight over [x0, x1]: airlight_segment of airlight.glsl,
// or the weighted sum of its lobes' segments (each with its own rule).
float medium_airlight_segment(float sigma, float b, float h, float x0, float x1, float log_scale) {
    if (!HAS_PHASE) return airlight_segment(sigma, b, h, x0, x1, log_scale);
    float sum = 0.0f;
    for (int lobe = 0; lobe < phase_lobe_count(); ++lobe) {
        float w = phase_lobe(lobe).info.w;
        if (w > 0.0f) sum += lobe_segment(lobe, sigma, b, h, x0, x1, log_scale + log(w));
    }
    return sum;
}

// scale e^{-T} G_p(T, theta_s) for the medium's phase function: the isotropic
// glow table, or the weighted sum of the lobes' glow slices, whose row warp
// has its scale floored at the lobe's K_min (HG's terminator is sharp even in
// thin fog; effects/phase/docs/phase_table.md section 6).
float medium_surface_glow(float scale, float optical_distance, float cos_theta_s) {
    if (!HAS_PHASE) return scaled_surface_glow(scale, optical_distance, cos_theta_s);
    if (scale <= 0.0f) return 0.0f;
    float sum = 0.0f;
    for (int lobe = 0; lobe < phase_lobe_count(); ++lobe) {
        PhaseLobeGpu l = phase_lobe(lobe);
        if (!(l.info.w > 0.0f)) continue;
        float log_g = surface_glow_log_lookup(lobe == 0 ? TABLE_PHASE_GLOW_0 : TABLE_PHASE_GLOW_1, l.info.z,
                                              optical_distance, cos_theta_s, SURFACE_GLOW_NX, SURFACE_GLOW_NY);
        sum += exp(log_g - optical_distance + log(scale * l.info.w));
    }
    return sum;
}
