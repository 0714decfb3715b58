// Display stage (issue 8): the per-pixel math that turns linear radiance into
// display values, shared by the CPU implementation (effects/display/display.cpp, through
// cpp/shader_cpp.hpp) and the GL display pass. Pure functions, no globals:
// compiles as GLSL 4.50 and as C++ against GLM.
//
// Pipeline of one pixel (display_pixel):
//   1. c = exposure * radiance per channel; NaN, negative and non-finite
//      values become 0 and values are capped at DISPLAY_BIG (1e30), so that
//      every later step is finite.
//   2. Y = display_luminance(c): Rec. 709 / sRGB luminance weights
//      (0.2126, 0.7152, 0.0722; they sum to 1, so a grey pixel has Y = c).
//   3. The tone curve is applied to LUMINANCE, not per channel: the pixel is
//      scaled by f(Y) / Y, which keeps the chromaticity of the linear colour
//      (a sodium lamp's halo stays orange instead of turning white). Channels
//      that the scaling pushes above 1 are clipped to 1 at step 4.
//   4. Clamp to [0, 1] and encode with the sRGB OETF (IEC 61966-2-1).
//   5. 8 bits (display_quantize): floor(255 v + t) with the pixel's ordered
//      dither threshold t in [0, 1) (display_dither_threshold), or t = 1/2
//      (plain rounding) with dithering off (physics.md section 5, "Dithering").
//
// Every curve f(L) takes the exposed luminance L >= 0 and a white point W > 0,
// the exposed luminance that maps to display value 1, and satisfies: f(0) = 0,
// f non-decreasing, f(W) = 1 (up to rounding), output clamped to [0, 1], finite
// and NaN-free for every input (NaN and negative inputs give 0, +inf gives 1).
// Each curve returns 0 for L <= 0 before anything else, so that a tiny white
// (W^2 or 1 / W out of range) cannot make 0 * inf.
// With automatic exposure the scene's log-average luminance is mapped to
// L = 0.18 (the "key", Reinhard et al. 2002) before the curve.

CONST int TONE_LINEAR = 0;
CONST int TONE_LOGLOG = 1;
CONST int TONE_REINHARD = 2;
CONST int TONE_FILMIC = 3;

// Cap on exposed values: far below float overflow, so that products such as
// L * L / W^2 or c * f(Y) / Y stay finite; every curve is saturated long before.
CONST float DISPLAY_BIG = 1.0e30f;

// The exposed luminance at which the ACES fit below reaches 1: the positive
// root of (c - a) x^2 + (d - b) x + e = 0 with the constants of tone_filmic,
// x = (0.56 + sqrt(0.56^2 + 4 * 0.08 * 0.14)) / 0.16 = 7.2439.
CONST float ACES_FIT_WHITE = 7.2439203f;

// Rec. 709 luminance of linear sRGB (ITU-R BT.709 / IEC 61966-2-1 primaries).
INLINE float display_luminance(vec3 rgb) { return dot(rgb, vec3(0.2126f, 0.7152f, 0.0722f)); }

// A value as a safe curve input: NaN, negative and -inf give 0, +inf and huge
// values give DISPLAY_BIG. (The comparison is false for NaN.)
INLINE float display_sanitize(float x) { return x > 0.0f ? min(x, DISPLAY_BIG) : 0.0f; }

// linear: f(L) = L / W, clipped at 1. With W = 1 this is the plain clipping of
// to_srgb8.
INLINE float tone_linear(float L, float white) {
    float x = display_sanitize(L);
    if (x <= 0.0f) return 0.0f;
    return clamp(x / white, 0.0f, 1.0f);
}

// loglog, the double-logarithmic curve of the source paper (its section 3;
// the paper only says energy is mapped through a double logarithm). Defined
// here as
//   f(L) = ln(1 + ln(1 + L)) / ln(1 + ln(1 + W)),  clipped to [0, 1].
// Properties: f(0) = 0; strictly increasing (a composition of increasing
// functions); concave; f(W) = 1; slope 1 / ln(1 + ln(1 + W)) at 0, so the
// darkest tones are linear (no infinite slope amplifying noise, unlike a
// plain logarithm or power law); grows only like ln ln L, so L = 1e30 gives
// ln(1 + 69.1) = 4.25 before normalisation: ten decades of highlights fit in
// the top part of the range. The inner ln(1 + L) is the Weber-Fechner
// response; the outer ln(1 + .) compresses the highlights further. Rounding
// in float keeps it non-decreasing (1 + x and ln are monotone after rounding);
// ln(1 + x) is 0 below x = 6e-8 (no log1p in GLSL), far below 1/2 LSB at 8
// bits. For W < 6e-8 the denominator rounds to 0 and is floored at 1e-30, so
// any L that registers maps to 1.
INLINE float tone_loglog(float L, float white) {
    float x = display_sanitize(L);
    if (x <= 0.0f) return 0.0f;
    float num = log(1.0f + log(1.0f + x));
    float den = max(log(1.0f + log(1.0f + white)), 1.0e-30f);  // 0 when 1 + W rounds to 1 (W < 6e-8)
    return clamp(num / den, 0.0f, 1.0f);
}

// reinhard: the extended Reinhard operator with a white point (Reinhard,
// Stark, Shirley, Ferwerda, "Photographic Tone Reproduction for Digital
// Images", SIGGRAPH 2002, equation 4):
//   f(L) = L (1 + L / W^2) / (1 + L),  clipped to [0, 1].
// f(0) = 0, f(W) = 1, strictly increasing for L >= 0. Evaluated as
// (L / (1 + L)) (1 + L / W^2) so that nothing overflows; L = 0 returns first
// (0 * inf if W^2 underflows).
INLINE float tone_reinhard(float L, float white) {
    float x = display_sanitize(L);
    if (x <= 0.0f) return 0.0f;
    float v = (x / (1.0f + x)) * (1.0f + x / (white * white));
    return clamp(v, 0.0f, 1.0f);
}

// filmic: the ACES filmic curve as fitted by Krzysztof Narkowicz ("ACES
// Filmic Tone Mapping Curve", 2015, knarkowicz.wordpress.com):
//   g(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),  clipped to [0, 1],
// applied to x = L * ACES_FIT_WHITE / W, so that the published curve is the
// default (W = ACES_FIT_WHITE = 7.244, where g reaches 1) and W moves its
// white point like the other curves'. g(0) = 0; g' has the numerator
// 1.408 x^2 + 0.7028 x + 0.0042 > 0, so g is strictly increasing; its toe
// (slope 0.21 at 0) darkens the shadows, its shoulder rolls off highlights.
INLINE float tone_filmic(float L, float white) {
    float x = display_sanitize(L);
    if (x <= 0.0f) return 0.0f;
    x = min(x * (ACES_FIT_WHITE / white), 100.0f);  // g(100) > 1 already
    float v = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    return clamp(v, 0.0f, 1.0f);
}

// The tone curve `curve` (TONE_*) of exposed luminance L; unknown ids: linear.
INLINE float tone_curve(int curve, float L, float white) {
    if (curve == TONE_LOGLOG) return tone_loglog(L, white);
    if (curve == TONE_REINHARD) return tone_reinhard(L, white);
    if (curve == TONE_FILMIC) return tone_filmic(L, white);
    return tone_linear(L, white);
}

// sRGB OETF (IEC 61966-2-1:1999, piecewise): linear [0, 1] -> encoded [0, 1].
// The input is clamped to [0, 1] first (NaN gives 0).
INLINE float srgb_oetf(float v) {
    float x = v > 0.0f ? min(v, 1.0f) : 0.0f;
    if (x >= 1.0f) return 1.0f;  // 1.055 - 0.055 rounds to 0.99999994 in float
    return x <= 0.0031308f ? 12.92f * x : 1.055f * pow(x, 1.0f / 2.4f) - 0.055f;
}

// One pixel: linear radiance -> sRGB-encoded display value in [0, 1] per
// channel (steps 1-4 above). 8-bit output is round(255 * value).
INLINE vec3 display_pixel(vec3 radiance, float exposure, int curve, float white) {
    vec3 c = vec3(display_sanitize(radiance.r * exposure), display_sanitize(radiance.g * exposure),
                  display_sanitize(radiance.b * exposure));
    float Y = display_luminance(c);
    float scale = Y > 0.0f ? tone_curve(curve, Y, white) / Y : 0.0f;
    return vec3(srgb_oetf(c.r * scale), srgb_oetf(c.g * scale), srgb_oetf(c.b * scale));
}

// The ordered dither threshold of image pixel (x, y), in [0, 1) (physics.md section 5, "Dithering"): the
// two-dimensional R2 low-discrepancy sequence of Roberts (2018), t = frac(a1 x + a2 y) with a1 = 1 / phi2 and
// a2 = 1 / phi2^2 (phi2 = 1.3247..., the plastic number), in 32-bit fixed point so that both backends compute
// the same bits: a1 = 3242174889 / 2^32, a2 = 2447445413 / 2^32; unsigned products wrap mod 2^32 in GLSL and
// C++ alike. The top 24 bits give t exactly as a float. Along any row or column the thresholds of n
// consecutive pixels are spread over [0, 1) with gaps below 3 / n (the three-distance theorem), so a smooth
// ramp alternates between its two nearest 8-bit values within a few pixels instead of showing bands.
INLINE float display_dither_threshold(int x, int y) {
    uint h = uint(x) * 3242174889u + uint(y) * 2447445413u;
    return float(h >> 8u) * (1.0f / 16777216.0f);
}

// One encoded channel v in [0, 1] as an 8-bit value q in 0..255 (as a float): q = floor(255 v + t), written
// as floor(255 v) + (frac >= 1 - t) so that no sum is rounded (1 - t is exact for t = k / 2^24). t = 1/2 is
// rounding half up (std::lround for v >= 0); a t in [0, 1) keeps 0 at 0 and 1 at 255, and the mean of q over
// thresholds spread evenly over [0, 1) is 255 v: dithering adds no bias.
INLINE float display_quantize(float v, float threshold) {
    PRECISE float t = 255.0f * v;
    PRECISE float q = floor(t);
    PRECISE float frac = t - q;  // exact
    return frac >= 1.0f - threshold ? q + 1.0f : q;
}
