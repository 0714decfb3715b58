// The point lamps' terms of the shading pass (effects/lamp_airlight/physics.md),
// called through the integrator's hooks (effect.cmake EFFECT_HOOKS):
// surface_irradiance, emitter_hit, view_glow, pixel_cores.

// Irradiance from the light of a lamp of intensity I scattered once on its way
// to a surface point at distance dist: sigma_s I / (2 pi D) e^{-T} G(T, theta_s)
// (effects/lamp_airlight/physics.md section 3), D held at the lamp radius inside the lamp.
vec3 surface_glow_irradiance(vec3 intensity, float dist, float radius, float cos_theta_s) {
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 scale = vec3(frame.sigma_s) * intensity / (2.0f * PI * max(dist, radius));
    if (GREY_MEDIUM) {
        // sigma equal on all channels: one lookup, the channels differ by I only.
        float peak = max(max(scale.x, scale.y), scale.z);
        return peak > 0.0f ? (scale / peak) * medium_surface_glow(peak, sigma_t.x * dist, cos_theta_s) : vec3(0.0f);
    }
    return vec3(medium_surface_glow(scale.x, sigma_t.x * dist, cos_theta_s),
                medium_surface_glow(scale.y, sigma_t.y * dist, cos_theta_s),
                medium_surface_glow(scale.z, sigma_t.z * dist, cos_theta_s));
}

// Upper bound of the once-scattered irradiance from a lamp of intensity I (or
// a spot of axial intensity I, whose profile is <= 1) at distance dist:
// sigma_s I e^{-T} G / (2 pi D) with G <= SURFACE_GLOW_G_BOUND, for culling.
vec3 surface_glow_bound(vec3 intensity, vec3 attenuation, float dist, float radius) {
    return vec3(frame.sigma_s) * intensity * attenuation * (frame.phase.glow_bound / (2.0f * PI * max(dist, radius)));
}

// Irradiance (W/m^2) at a surface point p with unit normal n from the point
// lamps: inverse-square falloff, Lambert's cosine, attenuation exp(-sigma_t d)
// along the lamp-to-point path and hard shadows from every surface; plus, in
// a scattering medium, the light scattered once on the way (not shadowed).
// Inside a lamp's radius the falloff is held at its value on the lamp's sphere.
// p lies on surface `self`.
// Hook surface_irradiance (so_far unused: the lamps come first).
vec3 point_light_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    vec3 irradiance = vec3(0.0f);
    if (!HAS_POINT_LIGHTS) return irradiance;
    vec3 shadow_origin = p + surface_offset(p) * n;
    for (int i = 0; i < point_light_count(); ++i) {
        PointLightGpu light = point_light(i);
        vec3 to_light = vec3(light.position_radius) - p;
        float dist2 = dot(to_light, to_light);
        float dist = sqrt(dist2);
        float radius = light.position_radius.w;
        if (dist <= 0.0f) continue;
        vec3 l = to_light / dist;
        float cos_theta = dot(n, l);
        vec3 intensity = vec3(light.intensity);
        vec3 attenuation = transmittance(dist);
        vec3 direct = cos_theta > 0.0f ? intensity * (cos_theta / max(dist2, radius * radius)) * attenuation : vec3(0.0f);
        vec3 glow_bound = HAS_AIRLIGHT ? surface_glow_bound(intensity, attenuation, dist, radius) : vec3(0.0f);
        if (negligible(direct + glow_bound, irradiance)) continue;
        if (HAS_AIRLIGHT) irradiance += surface_glow_irradiance(intensity, dist, radius, cos_theta);
        if (cos_theta <= 0.0f) continue;
        if (HAS_SURFACES && segment_occluded(shadow_origin, l, dist - radius, self)) continue;
        irradiance += direct;
    }
    return irradiance;
}

// The airlight integral over the ray segment [x0, x1] of a lamp at closest
// distance h (closest approach at b), times `scale` = sigma_s I / (2 pi h),
// per channel: medium_airlight_segment (the segment integral of airlight.glsl,
// per phase lobe), the scale folded into its exponent (airlight_tail);
// channels without scattering or light have none.
vec3 point_light_segment(vec3 scale, float b, float h, float x0, float x1) {
    vec3 sigma_t = vec3(frame.sigma_t);
    if (GREY_MEDIUM) {
        float peak = max(max(scale.x, scale.y), scale.z);
        return peak > 0.0f ? (scale / peak) * medium_airlight_segment(sigma_t.x, b, h, x0, x1, log(peak)) : vec3(0.0f);
    }
    return vec3(scale.x > 0.0f ? medium_airlight_segment(sigma_t.x, b, h, x0, x1, log(scale.x)) : 0.0f,
                scale.y > 0.0f ? medium_airlight_segment(sigma_t.y, b, h, x0, x1, log(scale.y)) : 0.0f,
                scale.z > 0.0f ? medium_airlight_segment(sigma_t.z, b, h, x0, x1, log(scale.z)) : 0.0f);
}

// Airlight of point light `light` over the visible part [0, x_end] of the
// view ray (effects/lamp_airlight/physics.md): sigma_s I / (2 pi h) times the segment
// integral of airlight.glsl. A camera inside the lamp's sphere sees fog from
// where the ray leaves the sphere. Skipped when its bound
// sigma_s I e^{-sigma_t (D - r)} (pi / 2) / (2 pi h) is negligible against
// `so_far` (the pixel's radiance found so far). A lamp with volumetric shadows
// (intensity.w; HAS_LAMP_SHADOWS) sums the segment integral over the parts of
// [x0, x_end] it lights (effects/light_shafts/physics.md section 7), exact.
vec3 point_light_airlight(PointLightGpu light, vec3 origin, vec3 dir, float x_end, vec3 so_far) {
    vec3 to_light = vec3(light.position_radius) - origin;
    float radius = light.position_radius.w;
    float dist = length(to_light);
    float b = dot(to_light, dir);
    float h = max(length(to_light - b * dir), 1.0e-6f * max(dist, radius));
    float x0 = 0.0f;
    if (dist < radius) x0 = b + sqrt(max(radius * radius - h * h, 0.0f));
    if (x0 >= x_end) return vec3(0.0f);
    vec3 scale = vec3(frame.sigma_s) * vec3(light.intensity) / (2.0f * PI * h);
    if (negligible(scale * frame.phase.airlight_bound * transmittance(max(dist - radius, 0.0f)), so_far)) return vec3(0.0f);
    bool shadowed = HAS_LAMP_SHADOWS && light.intensity.w != 0.0f;
    if (AIRLIGHT_MARCH)
        return airlight_march(vec3(light.position_radius), vec3(light.intensity), -1, shadowed, origin, dir, x0, x_end);
    if (shadowed) find_shadow_runs(origin, dir, x_end, vec4(vec3(light.position_radius), 1.0f));
    int runs = shadowed ? shadow_runs.count : 0;
    // The lit parts: before each shadowed run, and after the last (k == runs);
    // one call site, so that GL compiles the segment integral once
    // (docs/architecture.md, "GL compile time").
    vec3 airlight = vec3(0.0f);
    float lit_from = x0;
    for (int k = 0; k <= runs; ++k) {
        vec2 run = k < runs ? shadow_runs.run[k] : vec2(x_end);
        if (run.x > lit_from) airlight += point_light_segment(scale, b, h, lit_from, run.x);
        lit_from = max(lit_from, run.y);
    }
    return airlight;
}

// Hook view_glow: the airlight of every point lamp over [0, t_hit], each
// culled against the pixel's radiance so far.
vec3 point_lights_view_glow(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_AIRLIGHT) return radiance;
    for (int i = 0; i < point_light_count(); ++i) {
        vec3 airlight = point_light_airlight(point_light(i), origin, dir, t_hit, radiance);
        layer_add(LAYER_LAMPS, airlight);
        radiance += airlight;
    }
    return radiance;
}

// Hook emitter_hit: the nearest lamp sphere in front of t_hit (lamps drawn by
// point_lights_pixel_cores excepted) shows radiance I / (pi r^2).
void point_lights_emitter_hit(vec3 origin, vec3 dir, INOUT(float) t_hit, INOUT(vec3) emitted, INOUT(bool) hit) {
    if (!HAS_POINT_LIGHTS) return;
    for (int i = 0; i < point_light_count(); ++i) {
        PointLightGpu lamp = point_light(i);
        if (lamp_is_subpixel(vec3(lamp.position_radius) - origin, lamp.position_radius.w)) continue;
        float t = intersect_lamp(lamp, origin, dir);
        if (t < t_hit) {
            t_hit = t;
            float r = lamp.position_radius.w;
            emitted = vec3(lamp.intensity) / (PI * r * r);
            hit = true;
        }
    }
}

// `radiance` with a sub-pixel lamp core composited over it: the core
// (radiance `core` at the lamp, centre `rel` from the camera, radius r)
// covers `cover` of the pixel (lamp_pixel_weight, shaders/lights.glsl) with
// its attenuated radiance, unless a surface hides its centre. The weight can
// exceed 1 by the solid-angle ratio: the core's part stays exact, the hidden
// background's never goes negative.
vec3 composite_lamp_core(vec3 radiance, vec3 rel, float r, float cover, vec3 core) {
    vec3 origin = vec3(frame.camera_position);
    float d = length(rel);
    int hit = -1;
    vec3 n;
    if (HAS_SURFACES && trace_surfaces(origin, rel / d, hit, n) < d - r) return radiance;
    core *= transmittance(d) * atmosphere_transmittance(origin, rel / d, d);
    outputs_cover(max(1.0f - cover, 0.0f));
    layer_add(LAYER_SURFACES, core * cover);
    return radiance * max(1.0f - cover, 0.0f) + core * cover;
}

// Hook pixel_cores: pixel (x, row)'s radiance with the sub-pixel lamp cores
// composited over it.
vec3 point_lights_pixel_cores(int x, int row, vec3 radiance) {
    if (!HAS_POINT_LIGHTS) return radiance;
    for (int i = 0; i < point_light_count(); ++i) {
        PointLightGpu lamp = point_light(i);
        float r = lamp.position_radius.w;
        vec3 rel = vec3(lamp.position_radius) - vec3(frame.camera_position);
        float cover = lamp_pixel_weight(rel, r, x, row);
        if (cover > 0.0f) radiance = composite_lamp_core(radiance, rel, r, cover, vec3(lamp.intensity) / (PI * r * r));
    }
    return radiance;
}
