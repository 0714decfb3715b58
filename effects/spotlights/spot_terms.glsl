// The spotlights' terms of the shading pass (effects/spotlights/physics.md),
// called through the integrator's hooks (effect.cmake EFFECT_HOOKS):
// surface_irradiance, emitter_hit, view_glow, pixel_cores.

// Upper bound of spot_surface_glow, for culling (effects/spotlights/physics.md
// section 5): the point lamp's glow at the same distance and angle
// (surface_glow_irradiance; the spot's integrand is the lamp's times the profile,
// which is <= 1), plus 1e-6 of the lamp's largest glow where the table's relative
// error is not measured, times SPOT_GLOW_BOUND_MARGIN, which covers what
// spot_surface_glow computes above the exact glow (its quadrature's error).
CONST float SPOT_GLOW_BOUND_MARGIN = 1.25f;

vec3 spot_surface_glow_bound(float cos_theta_s, vec3 intensity, vec3 attenuation, float dist, float radius) {
    return SPOT_GLOW_BOUND_MARGIN * (surface_glow_irradiance(intensity, dist, radius, cos_theta_s) +
                                     1.0e-6f * surface_glow_bound(intensity, attenuation, dist, radius));
}

// Irradiance at a surface point p (unit normal n) from the spots: the profile
// in the direction of p, inverse-square falloff, Lambert's cosine, attenuation
// and hard shadows (effects/spotlights/physics.md); plus, in a scattering
// medium, the light each spot scatters once on the way (spot_surface_glow, not
// shadowed). p lies on surface `self`; so_far is the lamps' irradiance at p.
// Two passes (effects/lamp_airlight/docs/culling.md): the direct light of every
// spot first, then the glows, each culled by its bound (spot_surface_glow_bound)
// against everything summed so far, the direct light of all spots included, so
// that a far spot's costly glow is compared with the near spots' light. A spot
// whose direct light and glow bound are negligible together in the first pass
// is skipped in both, so each spot is still at most one skipped term.
// Hook surface_irradiance.
vec3 spot_light_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    vec3 irradiance = vec3(0.0f);
    if (!HAS_SPOT_LIGHTS) return irradiance;
    vec3 shadow_origin = p + surface_offset(p) * n;
    int passes = HAS_SPOT_AIRLIGHT ? 2 : 1;
    for (int pass = 0; pass < passes; ++pass) {
        for (int i = 0; i < spot_light_count(); ++i) {
            SpotLightGpu s = spot_light(i);
            vec3 to_light = vec3(s.world_position) - p;
            float dist2 = dot(to_light, to_light);
            float dist = sqrt(dist2);
            float radius = s.relative_position_radius.w;
            if (dist <= 0.0f) continue;
            vec3 l = to_light / dist;
            vec3 intensity = vec3(s.intensity_edge);
            vec3 attenuation = transmittance(dist);
            float cos_theta = dot(n, l);
            vec3 glow_bound = HAS_SPOT_AIRLIGHT
                                  ? spot_surface_glow_bound(cos_theta, intensity, attenuation, dist, radius)
                                  : vec3(0.0f);
            if (pass == 1) {
                if (negligible(glow_bound, irradiance + so_far)) continue;
                irradiance += spot_surface_glow(s, p, n, int(frame.spot.glow_samples));
                continue;
            }
            float profile = cos_theta > 0.0f ? spot_profile_toward(s, -l) : 0.0f;
            vec3 direct = intensity * (max(profile, 0.0f) * cos_theta / max(dist2, radius * radius)) * attenuation;
            if (profile <= 0.0f) direct = vec3(0.0f);
            if (negligible(direct + glow_bound, irradiance + so_far)) continue;
            if (profile <= 0.0f) continue;
            if (HAS_SURFACES && segment_occluded(shadow_origin, l, dist - radius, self)) continue;
            irradiance += direct;
        }
    }
    return irradiance;
}

// Float k of the spots' tile table (spot_frame.cpp): the tiles' offsets, then their lists.
int spot_tile_entry(int k) {
    return int(table_texel(TABLE_SPOT_TILES, k % SPOT_ROW_TEXELS, k / SPOT_ROW_TEXELS));
}

// Hook view_glow: the airlight of every spot whose beam the ray can meet over [0, t_hit].
vec3 spot_lights_view_glow(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_SPOT_AIRLIGHT) return radiance;
    // The spots whose beams can meet a ray of the pixel's screen tile
    // (physics.md section 9; spot_frame.cpp), in their order; every spot off
    // the film or without lists.
    int x;
    int row;
    ivec4 tiles = frame.spot.tiles;
    bool listed = tiles.w > 0 && film_pixel_of(dir, x, row);
    int tile = listed ? (row / tiles.w) * tiles.x + x / tiles.w : 0;
    int header = tiles.x * tiles.y + 1;
    int begin = listed ? spot_tile_entry(tile) : 0;
    int end = listed ? spot_tile_entry(tile + 1) : spot_light_count();
    for (int k = begin; k < end; ++k) {
        int i = listed ? spot_tile_entry(header + k) : k;
        vec3 airlight = spot_light_airlight(i, dir, t_hit, radiance);
        layer_add(LAYER_SPOTS, airlight);
        radiance += airlight;
    }
    return radiance;
}

// Hook emitter_hit: a spot's sphere nearer than t_hit shows its profile in
// the direction of the camera.
void spot_lights_emitter_hit(vec3 origin, vec3 dir, INOUT(float) t_hit, INOUT(vec3) emitted, INOUT(bool) hit) {
    if (!HAS_SPOT_LIGHTS) return;
    for (int i = 0; i < spot_light_count(); ++i) {
        SpotLightGpu s = spot_light(i);
        if (lamp_is_subpixel(vec3(s.relative_position_radius), s.relative_position_radius.w)) continue;
        PointLightGpu sphere;
        sphere.position_radius = vec4(vec3(s.world_position), s.relative_position_radius.w);
        sphere.intensity = s.intensity_edge;
        float t = intersect_lamp(sphere, origin, dir);
        if (t < t_hit) {
            t_hit = t;
            float r = s.relative_position_radius.w;
            emitted = vec3(s.intensity_edge) *
                      (spot_profile_toward(s, normalize(-vec3(s.relative_position_radius))) / (PI * r * r));
            hit = true;
        }
    }
}

// Hook pixel_cores: the sub-pixel spot cores composited over the pixel
// (composite_lamp_core, effects/lamp_airlight/lamp_terms.glsl), each with its
// profile toward the camera.
vec3 spot_lights_pixel_cores(int x, int row, vec3 radiance) {
    if (!HAS_SPOT_LIGHTS) return radiance;
    for (int i = 0; i < spot_light_count(); ++i) {
        SpotLightGpu s = spot_light(i);
        float r = s.relative_position_radius.w;
        vec3 rel = vec3(s.relative_position_radius);
        float cover = lamp_pixel_weight(rel, r, x, row);
        if (cover <= 0.0f) continue;
        vec3 core = vec3(s.intensity_edge) * (spot_profile_toward(s, -rel / length(rel)) / (PI * r * r));
        radiance = composite_lamp_core(radiance, rel, r, cover, core);
    }
    return radiance;
}
