// The rainbow's part of the shading pass: the rain's phase function for
// sunlight from the rainbow table (effects/rainbow/physics.md section 5), which
// the daytime atmosphere uses for the rain's sun light (sun_phase_along,
// effects/daytime/sky.glsl) when HAS_RAINBOW.

// The rain's phase for sunlight at scattering angle acos(cos_theta) from the
// rainbow table (effects/rainbow/physics.md; effects/rainbow/rainbow.hpp): linear in angle
// between texels 0.05 degree apart.
vec3 rainbow_phase(float cos_theta) {
    float x = precise_acos(cos_theta) * (float(RAINBOW_TABLE_N - 1) / PI);
    int i = min(int(x), RAINBOW_TABLE_N - 2);
    float f = clamp(x - float(i), 0.0f, 1.0f);
    return mix(vec3(table_texel4(TABLE_RAINBOW, i, 0)), vec3(table_texel4(TABLE_RAINBOW, i + 1, 0)), f);
}

