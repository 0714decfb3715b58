// The multiple-scattering effect's term of the shading pass (effect.cmake
// EFFECT_HOOKS; effects/multiple_scattering/physics.md section 9).

// Hook surface_irradiance: the diffuse light of the daytime atmosphere (light
// scattered at least once, and the ground's reflection) on a surface point;
// like the sky dome's, not occluded by other surfaces. The sun's residual
// forward beam is shadowed with the sun (effects/daytime/daytime_terms.glsl).
vec3 ms_surface_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    if (!HAS_MULTIPLE_SCATTERING) return vec3(0.0f);
    return ms_diffuse_irradiance(p.y, n);
}
