// Anisotropic phase functions (issue 5): the pure per-lobe formulas shared by
// the shaders (phase.glsl) and the table builder (effects/phase/phase_tables.cpp). Nothing
// here reads the frame or a table. Derivations and measured errors:
// effects/phase/docs/phase_table.md.
//
// The medium's phase function is a weighted sum of at most two lobes, each a
// Henyey-Greenstein lobe of asymmetry g or the Rayleigh function. A lobe is
// described by PhaseLobeGpu (phase_layout.glsl):
//   shape = (k, sqrt k, c, 1 / (1 - g)),  k = (1 - g) / (1 + g),  c = min(k, sqrt k)
//   info  = (g, 1 for Rayleigh else 0, glow row-warp floor K_min, weight)
// Rayleigh is tabulated in the isotropic variables: shape = (1, 1, 1, 1), g = 0.
//
// Along a view ray the scattering angle is 2 xi (effects/lamp_airlight/physics.md), and
// P = 4 pi p(cos 2 xi). For HG the substitution tan t = k tan phi turns the
// tail Q_p(u, xi) = e^{u tan xi} int_xi^{pi/2} P(t) e^{-u tan t} dt into
//   Q_p = int_{phi0}^{pi/2} rho(phi) exp(-u k (tan phi - tan phi0)) dphi,
//   rho = sqrt(cos^2 phi + k^2 sin^2 phi) / (1 - g)        (effects/phase/docs/phase_table.md 1.1)
// which has no forward peak; for Rayleigh phi = t and rho = P(t).

// P at scattering angle 2 xi from sin^2 xi and cos^2 xi (each formed without
// cancellation by the caller): HG's 1 + g^2 - 2 g cos 2 xi is
// (1 - g)^2 + 4 g sin^2 xi = (1 + g)^2 - 4 g cos^2 xi, the form without
// cancellation chosen by the sign of g.
INLINE float lobe_phase_at(PhaseLobeGpu lobe, float sin2_xi, float cos2_xi) {
    if (lobe.info.y != 0.0f) {
        float cos_2xi = cos2_xi - sin2_xi;
        return 0.75f * (1.0f + cos_2xi * cos_2xi);
    }
    float g = lobe.info.x;
    float base = g >= 0.0f ? (1.0f - g) * (1.0f - g) + 4.0f * g * sin2_xi : (1.0f + g) * (1.0f + g) - 4.0f * g * cos2_xi;
    return (1.0f - g * g) / (base * sqrt(base));
}

// The integrand's weight rho in the substituted variable at phi = pi/2 - cp.
INLINE float lobe_density(PhaseLobeGpu lobe, float cp) {
    if (lobe.info.y != 0.0f) {
        float c2 = cos(2.0f * cp);  // cos 2t = -cos 2 cp
        return 0.75f * (1.0f + c2 * c2);
    }
    float k = lobe.shape.x;
    float s = sin(cp);
    float c = cos(cp);
    return sqrt(s * s + k * k * c * c) * lobe.shape.w;
}

// Table coordinates and normalisers of a lobe's tail at the ray point whose
// closest-point distance is h and whose p = d + x - b (effects/phase/docs/phase_table.md
// sections 1.3-1.5 and 7):
//   X = sqrt(z / (1 + z)),  z = sigma sqrt(c^2 h^2 + p^2)
//   Y = 1 - 2 / (3 pi) [atan(h, p) + atan(sqrt(k) h, p) + atan(k h, p)]
//   N  = Ct / (1 + lam' Ct / rho(phi_e)) / (1 - g)  (Q_p = N S)
//   N1 = 2 eps / (1 + eps / cv), eps = N / P(xi)     (spot moment M1 = N1 (M1/N1);
//                                                     eps = N for Rayleigh)
// At g = 0 each is the isotropic formula of constants.glsl. cvp = pi/2 - phi0
// and cv = pi/2 - xi are returned for the short-segment rules.
INLINE void lobe_coordinates(PhaseLobeGpu lobe, float sigma, float h, float p, OUT(float) X, OUT(float) Y,
                             OUT(float) N, OUT(float) N1, OUT(float) cvp, OUT(float) cv) {
    float k = lobe.shape.x;
    float kh = k * h;
    cvp = atan(kh, p);
    cv = atan(h, p);
    Y = 1.0f - (cv + atan(lobe.shape.y * h, p) + cvp) * (2.0f / (3.0f * PI));
    float c = lobe.shape.z;
    float z = min(sigma * sqrt(c * c * h * h + p * p), 1.0e20f);
    X = sqrt(z / (1.0f + z));
    float R2 = kh * kh + p * p;
    float tau = kh / (sqrt(R2) + p);  // tan(cvp / 2)
    float Ct = cvp * (tau + k) / (tau + 1.0f);
    float lam = min(sigma * R2 / kh, 1.0e30f);  // u k sec^2 phi0
    float ce = cvp - cvp / (2.0f + lam * cvp);
    float se = sin(ce);
    float ke = k * cos(ce);
    float rho_e = lobe.info.y != 0.0f ? 1.0f : sqrt(se * se + ke * ke);  // Rayleigh: the isotropic N
    N = Ct / (1.0f + lam * Ct / rho_e) * lobe.shape.w;
    // eps, the tail's width: N / P(xi) for HG, whose N carries the peak; the
    // isotropic width N for Rayleigh, whose N is the isotropic one.
    float d2 = h * h + p * p;
    float eps = lobe.info.y != 0.0f ? N : N / lobe_phase_at(lobe, p * p / d2, h * h / d2);
    N1 = 2.0f * eps / (1.0f + eps / max(cv, 1.0e-30f));
}
