// The lamps' multiple-scattering table's coordinates (EFFECT_GLSL_MATH: the
// shading pass and effects/multiple_scattering/point_source.cpp, which builds
// the table, share them). Texel (ix, iy) holds log L(tau, gamma) per albedo
// channel (RGB), L the radiance of the light scattered at least twice seen from
// optical distance tau from a lamp of unit intensity in a medium of unit
// extinction, at angle gamma from the lamp's direction
// (effects/multiple_scattering/physics.md section 11). Rows LAMP_MS_NY to
// LAMP_MS_NY + LAMP_MS_NB - 1 hold log E(tau, beta) per albedo channel, E the
// irradiance of that light on a surface element whose normal makes the angle
// beta with the direction to the lamp, and in alpha the largest log E over
// beta and the channels at that tau (the culling bound; physics.md section 13).
CONST int LAMP_MS_NX = 160;  // optical distance: X = w(tau) / w(TAU_MAX), w = log(tau / TAU_MIN) + tau / TAU_LIN
CONST int LAMP_MS_NY = 80;   // angle: Y = log(1 + gamma / GAMMA0) / log(1 + pi / GAMMA0)
CONST float LAMP_MS_TAU_MIN = 1.0e-3f;  // below: L held (it grows only as log(1 / tau))
CONST float LAMP_MS_TAU_MAX = 64.0f;    // beyond: no multiple scattering (section 12)
CONST float LAMP_MS_TAU_LIN = 4.0f;     // logarithmic in tau below, linear above (L ~ e^{-tau / L_d} there)
CONST float LAMP_MS_GAMMA0 = 0.02f;     // radians: rows fine near the lamp's direction
CONST float LAMP_MS_GAMMA_MIN = 1.0e-4f;  // the first row is built at this angle (L diverges as log 1 / gamma)
CONST float LAMP_MS_LOG_FLOOR = -700.0f;  // log of an empty texel
CONST int LAMP_MS_NB = 33;  // surface rows: Y = beta / pi, beta the normal's angle from the lamp's direction

INLINE float lamp_ms_x(float tau) {
    float t = max(tau, LAMP_MS_TAU_MIN);
    return (log(t / LAMP_MS_TAU_MIN) + t / LAMP_MS_TAU_LIN) /
           (log(LAMP_MS_TAU_MAX / LAMP_MS_TAU_MIN) + LAMP_MS_TAU_MAX / LAMP_MS_TAU_LIN);
}

INLINE float lamp_ms_y(float gamma) { return log(1.0f + gamma / LAMP_MS_GAMMA0) / log(1.0f + PI / LAMP_MS_GAMMA0); }

// The surface rows' coordinate of cos beta (rows uniform in beta: E is even
// and smooth in beta, physics.md section 13).
INLINE float lamp_ms_surface_y(float cos_beta) { return acos(clamp(cos_beta, -1.0f, 1.0f)) / PI; }
