// Radiance along camera rays, shared by both backends. Feature switches
// (HAS_MEDIUM, HAS_POINT_LIGHTS, HAS_SURFACES) are compile-time constants in
// a GL shader variant and cheap runtime flags on the CPU.

// Beer-Lambert transmittance exp(-sigma_t t) of the homogeneous medium.
// t = NO_HIT (escaping ray) gives 0 on every channel with sigma_t > 0.
vec3 transmittance(float t) {
    if (!HAS_MEDIUM) return vec3(1.0f);
    return exp(-vec3(frame.sigma_t) * t);
}

// Offset that lifts a hit point off its surface before tracing shadow rays;
// relative to the coordinates' magnitude so it outgrows float rounding.
float surface_offset(vec3 p) {
    return 1.0e-4f * (1.0f + max(max(abs(p.x), abs(p.y)), abs(p.z)));
}

// Irradiance (W/m^2) at a surface point p with unit normal n from the point
// lamps: inverse-square falloff, Lambert's cosine, attenuation exp(-sigma_t d)
// along the lamp-to-point path and hard shadows from every surface. Inside a
// lamp's radius the falloff is held at its value on the lamp's sphere.
vec3 point_light_irradiance(vec3 p, vec3 n) {
    vec3 irradiance = vec3(0.0f);
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
        if (cos_theta <= 0.0f) continue;
        if (HAS_SURFACES && segment_occluded(shadow_origin, l, dist - radius)) continue;
        irradiance += vec3(light.intensity) * (cos_theta / max(dist2, radius * radius)) *
                      transmittance(dist);
    }
    return irradiance;
}

// Radiance arriving at the camera along the ray origin + t dir.
vec3 ray_radiance(vec3 origin, vec3 dir) {
    int hit_index = -1;
    vec3 normal = vec3(0.0f, 1.0f, 0.0f);
    float t_hit = NO_HIT;
    if (HAS_SURFACES) t_hit = trace_surfaces(origin, dir, hit_index, normal);

    // Lamp cores: the nearest lamp sphere in front of the first surface.
    int lamp_index = -1;
    if (HAS_POINT_LIGHTS) {
        for (int i = 0; i < point_light_count(); ++i) {
            float t = intersect_lamp(point_light(i), origin, dir);
            if (t < t_hit) {
                t_hit = t;
                lamp_index = i;
            }
        }
    }

    vec3 radiance;
    if (lamp_index >= 0) {
        PointLightGpu lamp = point_light(lamp_index);
        float r = lamp.position_radius.w;
        radiance = vec3(lamp.intensity) / (PI * r * r);
    } else if (hit_index >= 0) {
        vec3 p = origin + t_hit * dir;
        vec3 albedo = vec3(surface(hit_index).albedo_type);
        vec3 irradiance = vec3(0.0f);
        if (HAS_POINT_LIGHTS) irradiance += point_light_irradiance(p, normal);
        radiance = albedo / PI * irradiance;
    } else {
        radiance = vec3(frame.background);
    }
    // Everything behind the medium reaches the camera attenuated.
    return radiance * transmittance(t_hit);
}

// Linear radiance of pixel (x, row), row 0 on top: the per-pixel entry point.
vec3 render_pixel(int x, int row) {
    return ray_radiance(vec3(frame.camera_position), camera_ray_direction(x, row));
}
