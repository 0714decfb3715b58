// Daytime sky and atmosphere (issue 6; effects/daytime/physics.md): the pure
// formulas shared by the shaders (sky.glsl) and the sky table builder
// (effects/daytime/sky.cpp). Nothing here reads the frame or a table. Design and
// measured errors: effects/daytime/docs/daytime.md.

// expm1(x) / x, 1 at x = 0, without cancellation for small |x| (GLSL has no
// expm1): the length factor of an exponential profile's integral.
INLINE float expm1_over_x(float x) {
    if (abs(x) < 1.0e-3f) return 1.0f + x * (0.5f + x * (1.0f / 6.0f));
    return (exp(x) - 1.0f) / x;
}

// L / Lz of the sky dome in the unit direction w (effects/daytime/physics.md), 0
// below the horizon:
//   overcast  (1 + 2 cos Z) / 3, the CIE standard overcast sky;
//   cie       phi(Z) f(chi) / (phi(0) f(Z_s)), phi(Z) = 1 + a exp(b / cos Z),
//             f(chi) = 1 + c [exp(d chi) - exp(d pi / 2)] + e cos^2 chi,
//             chi the angle between w and the sun (ISO 15469).
// b < 0 for every type, so phi -> 1 at the horizon without a division by 0.
INLINE float sky_shape(SkyGpu sky, vec3 w) {
    if (w.y < 0.0f) return 0.0f;
    int model = int(sky.zenith_radiance.w);
    if (model == SKY_OVERCAST) return (1.0f + 2.0f * w.y) / 3.0f;
    if (model != SKY_CIE) return 0.0f;
    float gradation = 1.0f + sky.gradation.x * exp(sky.gradation.y / max(w.y, 1.0e-30f));
    float cos_chi = clamp(dot(w, vec3(sky.sun_direction)), -1.0f, 1.0f);
    float indicatrix = 1.0f + sky.indicatrix.x * (exp(sky.indicatrix.y * acos(cos_chi)) - sky.indicatrix.w) +
                       sky.indicatrix.z * cos_chi * cos_chi;
    return gradation * indicatrix * sky.gradation.z;
}

// A species' phase function p(cos theta) (normalised to 1 over the sphere),
// theta between the light's directions before and after scattering; `info`
// is SpeciesGpu.phase: Rayleigh 3 (1 + cos^2) / (16 pi) or HG with g.
INLINE float species_phase(vec4 info, float cos_theta) {
    if (info.y != 0.0f) return (3.0f / (16.0f * PI)) * (1.0f + cos_theta * cos_theta);
    float g = info.x;
    float base = max(1.0f + g * g - 2.0f * g * cos_theta, 1.0e-12f);
    return (1.0f - g * g) / (4.0f * PI * base * sqrt(base));
}

// arccos with an absolute error below 1e-7 rad from multiplications, additions
// and a square root only (Abramowitz & Stegun 4.4.46), so that GL and the CPU
// agree: the rainbow table changes by up to 20 % between texels 0.05 degree
// apart, and llvmpipe's acos is off by about 1e-4 rad.
INLINE float precise_acos(float x) {
    float a = min(abs(x), 1.0f);
    float p = -0.0012624911f;
    p = p * a + 0.0066700901f;
    p = p * a - 0.0170881256f;
    p = p * a + 0.0308918810f;
    p = p * a - 0.0501743046f;
    p = p * a + 0.0889789874f;
    p = p * a - 0.2145988016f;
    p = p * a + 1.5707963050f;
    float r = sqrt(1.0f - a) * p;
    return x < 0.0f ? PI - r : r;
}

// ---- The sky-phase table's coordinates (constants.glsl) ----------------------
// Column coordinate X in [0, 1] of the vertical optical depth C >= 0
// (clamped at SKY_TABLE_C_MAX, where e^{-C} is below float32's range).
INLINE float sky_table_x(float column) {
    float c = clamp(column, 0.0f, SKY_TABLE_C_MAX);
    return sqrt(log(1.0f + c / SKY_TABLE_C0) / log(1.0f + SKY_TABLE_C_MAX / SKY_TABLE_C0));
}

// Its inverse: the column at coordinate X.
INLINE float sky_table_column(float X) {
    return SKY_TABLE_C0 * (exp(X * X * log(1.0f + SKY_TABLE_C_MAX / SKY_TABLE_C0)) - 1.0f);
}

// Elevation in [-pi/2, pi/2] and azimuth from the sun's in [0, pi] of the
// unit direction d (azimuth 0 where d or the sun is vertical).
INLINE vec2 sky_table_angles(vec3 d, vec3 sun) {
    float elevation = asin(clamp(d.y, -1.0f, 1.0f));
    float dh = d.x * d.x + d.z * d.z;
    float sh = sun.x * sun.x + sun.z * sun.z;
    float azimuth = 0.0f;
    if (dh > 1.0e-12f && sh > 1.0e-12f) {
        azimuth = acos(clamp((d.x * sun.x + d.z * sun.z) / sqrt(dh * sh), -1.0f, 1.0f));
    }
    return vec2(elevation, azimuth);
}
