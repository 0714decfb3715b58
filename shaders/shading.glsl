// Radiance along camera rays, shared by both backends. Feature switches
// (HAS_MEDIUM, HAS_POINT_LIGHTS, HAS_SURFACES, HAS_AIRLIGHT, AIRLIGHT_MARCH,
// GREY_MEDIUM) are compile-time constants in a GL shader variant and cheap
// runtime flags on the CPU.

// Beer-Lambert transmittance exp(-sigma_t t) of the homogeneous medium.
// t = NO_HIT (escaping ray) gives 0 on every channel with sigma_t > 0.
vec3 transmittance(float t) {
    if (!HAS_MEDIUM) return vec3(1.0f);
    vec3 sigma_t = vec3(frame.sigma_t);
    if (t >= NO_HIT) {  // explicit: exp(-0 * inf) may be NaN once a compiler reassociates
        return vec3(sigma_t.x > 0.0f ? 0.0f : 1.0f, sigma_t.y > 0.0f ? 0.0f : 1.0f, sigma_t.z > 0.0f ? 0.0f : 1.0f);
    }
    return exp(-sigma_t * t);
}

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
    return vec3(frame.sigma_s) * intensity * attenuation * (frame.phase_glow_bound / (2.0f * PI * max(dist, radius)));
}

// Irradiance (W/m^2) at a surface point p with unit normal n from the point
// lamps: inverse-square falloff, Lambert's cosine, attenuation exp(-sigma_t d)
// along the lamp-to-point path and hard shadows from every surface; plus, in
// a scattering medium, the light scattered once on the way (not shadowed).
// Inside a lamp's radius the falloff is held at its value on the lamp's sphere.
// p lies on surface `self`.
vec3 point_light_irradiance(vec3 p, vec3 n, int self) {
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

// Irradiance at p (normal n) from the spotlights: the profile in the direction
// of p, inverse-square falloff, Lambert's cosine, attenuation and hard shadows
// (effects/spotlights/physics.md); plus, in a scattering medium, the light each spot
// scatters once on the way (spot_surface_glow, not shadowed), bounded for
// culling by the glow of a point lamp of intensity I0 (the profile is <= 1).
// p lies on surface `self`.
vec3 spot_light_irradiance(vec3 p, vec3 n, int self, vec3 so_far) {
    vec3 irradiance = vec3(0.0f);
    vec3 shadow_origin = p + surface_offset(p) * n;
    for (int i = 0; i < spot_light_count(); ++i) {
        SpotLightGpu s = spot_light(i);
        vec3 to_light = vec3(s.world_position) - p;
        float dist2 = dot(to_light, to_light);
        float dist = sqrt(dist2);
        float radius = s.relative_position_radius.w;
        if (dist <= 0.0f) continue;
        vec3 l = to_light / dist;
        float cos_theta = dot(n, l);
        float profile = cos_theta > 0.0f ? spot_profile_toward(s, -l) : 0.0f;
        vec3 intensity = vec3(s.intensity_edge);
        vec3 attenuation = transmittance(dist);
        vec3 direct = intensity * (max(profile, 0.0f) * cos_theta / max(dist2, radius * radius)) * attenuation;
        if (profile <= 0.0f) direct = vec3(0.0f);
        vec3 glow_bound = HAS_SPOT_AIRLIGHT ? surface_glow_bound(intensity, attenuation, dist, radius) : vec3(0.0f);
        if (negligible(direct + glow_bound, irradiance + so_far)) continue;
        if (HAS_SPOT_AIRLIGHT) irradiance += spot_surface_glow(s, p, n, int(frame.spot_glow_samples));
        if (profile <= 0.0f) continue;
        if (HAS_SURFACES && segment_occluded(shadow_origin, l, dist - radius, self)) continue;
        irradiance += direct;
    }
    return irradiance;
}

// Airlight of point light `light` over the visible part [0, x_end] of the
// view ray (effects/lamp_airlight/physics.md): sigma_s I / (2 pi h) times the segment
// integral of airlight.glsl. A camera inside the lamp's sphere sees fog from
// where the ray leaves the sphere. Skipped when its bound
// sigma_s I e^{-sigma_t (D - r)} (pi / 2) / (2 pi h) is negligible against
// `so_far` (the pixel's radiance found so far).
vec3 point_light_airlight(PointLightGpu light, vec3 origin, vec3 dir, float x_end, vec3 so_far) {
    vec3 to_light = vec3(light.position_radius) - origin;
    float radius = light.position_radius.w;
    float dist = length(to_light);
    float b = dot(to_light, dir);
    float h = max(length(to_light - b * dir), 1.0e-6f * max(dist, radius));
    float x0 = 0.0f;
    if (dist < radius) x0 = b + sqrt(max(radius * radius - h * h, 0.0f));
    if (x0 >= x_end) return vec3(0.0f);
    vec3 sigma_t = vec3(frame.sigma_t);
    vec3 scale = vec3(frame.sigma_s) * vec3(light.intensity) / (2.0f * PI * h);
    if (negligible(scale * frame.phase_airlight_bound * transmittance(max(dist - radius, 0.0f)), so_far)) return vec3(0.0f);
    if (AIRLIGHT_MARCH) return airlight_march(vec3(light.position_radius), vec3(light.intensity), -1, origin, dir, x0, x_end);
    // The scale goes into the exponent (airlight_tail); channels without
    // scattering or light have none.
    if (GREY_MEDIUM) {
        float peak = max(max(scale.x, scale.y), scale.z);
        return peak > 0.0f ? (scale / peak) * medium_airlight_segment(sigma_t.x, b, h, x0, x_end, log(peak)) : vec3(0.0f);
    }
    return vec3(scale.x > 0.0f ? medium_airlight_segment(sigma_t.x, b, h, x0, x_end, log(scale.x)) : 0.0f,
                scale.y > 0.0f ? medium_airlight_segment(sigma_t.y, b, h, x0, x_end, log(scale.y)) : 0.0f,
                scale.z > 0.0f ? medium_airlight_segment(sigma_t.z, b, h, x0, x_end, log(scale.z)) : 0.0f);
}

// ---- Lamp cores smaller than a pixel ---------------------------------------
// A lamp's disc that projects smaller than LAMP_SUBPIXEL_RADIUS pixels is
// missed or hit at random by one ray through the pixel's centre (a distant
// headlight would flicker or vanish). Such cores are box-filtered instead:
// the disc becomes the square of the same area on the image plane, and each
// pixel gets the lamp's radiance times the fraction of its area that square
// covers. The square's area is the disc's projected area, pi r^2 / (d^2
// cos^3 theta) at distance d and off-axis angle theta (a solid angle Omega
// projects to Omega / cos^3 theta on the plane at distance 1), so the energy
// over all pixels is exactly the lamp's, L pi r^2 / d^2 (issue 8: the
// glare's point sources must carry their true energy).

// Position of `rel` (a point relative to the camera) on the film in
// continuous pixel units (x right, row down; pixel (x, row) spans
// [x, x + 1] x [row, row + 1]) in .xy, the projected square's half side in
// pixels in .z; .z = NO_HIT for points not in front of the camera.
vec3 lamp_film_square(vec3 rel, float r) {
    vec3 forward = vec3(frame.camera_forward);
    vec3 right = vec3(frame.camera_right);
    vec3 up = vec3(frame.camera_up);
    float z = dot(rel, forward);
    float d = length(rel);
    if (z <= r || d <= r) return vec3(0.0f, 0.0f, NO_HIT);
    float sx = dot(rel, right) / (z * dot(right, right));
    float sy = dot(rel, up) / (z * dot(up, up));
    float width = float(frame.film_width);
    float height = float(frame.film_height);
    float pixel = 2.0f * length(up) / height;  // pixel side on the plane at distance 1
    float cos_theta = z / d;
    float disc_radius = r / (d * cos_theta * sqrt(cos_theta));  // equal projected area
    float half_side = 0.5f * sqrt(PI) * disc_radius / pixel;
    return vec3(0.5f * (sx + 1.0f) * width, 0.5f * (1.0f - sy) * height, half_side);
}

// True when the lamp (centre relative to the camera, radius r) is drawn by
// lamp_subpixel_cores, not by the pixel's ray.
bool lamp_is_subpixel(vec3 rel, float r) {
    float half_side = lamp_film_square(rel, r).z;
    return half_side < 0.5f * sqrt(PI) * LAMP_SUBPIXEL_RADIUS;
}

// Length of [c - h, c + h] inside the pixel [i, i + 1]: min(2 h, u + h,
// 1 - u + h, 1) with u = c - i, never below 0. Not min(i + 1, c + h) -
// max(i, c - h), whose c +- h round to c when h is below the float spacing
// of c (a 5 mm lamp 100 km away is 3e-6 pixel wide): an interval inside the
// pixel keeps its exact width 2 h, whatever h.
float pixel_interval_overlap(float c, float h, int i) {
    float u = c - float(i);
    return max(min(min(2.0f * h, 1.0f), min(u + h, (1.0f - u) + h)), 0.0f);
}

// Fraction of pixel (x, row) covered by the lamp's film square (0 when the
// lamp is resolved: the ray draws it).
float lamp_pixel_coverage(vec3 rel, float r, int x, int row) {
    vec3 sq = lamp_film_square(rel, r);
    if (!(sq.z < 0.5f * sqrt(PI) * LAMP_SUBPIXEL_RADIUS)) return 0.0f;
    return pixel_interval_overlap(sq.x, sq.z, x) * pixel_interval_overlap(sq.y, sq.z, row);
}

// Weight of a sub-pixel core in pixel (x, row): its coverage times the
// ratio of the solid angle of a pixel at the lamp's centre to this pixel's,
// (cos theta_lamp / cos theta_pixel)^3, so that the energy the pixels get,
// sum of radiance x pixel solid angle, is the lamp's whatever the pixel.
float lamp_pixel_weight(vec3 rel, float r, int x, int row) {
    float cover = lamp_pixel_coverage(rel, r, x, row);
    if (cover <= 0.0f) return 0.0f;
    vec3 forward = vec3(frame.camera_forward);
    float ratio = (dot(rel, forward) / length(rel)) / dot(camera_ray_direction(x, row), forward);
    return cover * ratio * ratio * ratio;
}

// Radiance of pixel (x, row) with its sub-pixel lamp cores composited over
// `radiance` (the pixel's ray without them): each covers its share of the
// pixel (lamp_pixel_weight) with its attenuated core radiance, unless a
// surface hides its centre.
vec3 lamp_subpixel_cores(int x, int row, vec3 radiance) {
    vec3 origin = vec3(frame.camera_position);
    if (HAS_POINT_LIGHTS) {
        for (int i = 0; i < point_light_count(); ++i) {
            PointLightGpu lamp = point_light(i);
            float r = lamp.position_radius.w;
            vec3 rel = vec3(lamp.position_radius) - origin;
            float cover = lamp_pixel_weight(rel, r, x, row);
            if (cover <= 0.0f) continue;
            float d = length(rel);
            int hit = -1;
            vec3 n;
            if (HAS_SURFACES && trace_surfaces(origin, rel / d, hit, n) < d - r) continue;
            // The weight can exceed 1 by the solid-angle ratio: the core's part stays exact, the
            // hidden background's never goes negative.
            vec3 core = vec3(lamp.intensity) / (PI * r * r) * transmittance(d) * atmosphere_transmittance(origin, rel / d, d);
            radiance = radiance * max(1.0f - cover, 0.0f) + core * cover;
        }
    }
    if (HAS_SPOT_LIGHTS) {
        for (int i = 0; i < spot_light_count(); ++i) {
            SpotLightGpu s = spot_light(i);
            float r = s.relative_position_radius.w;
            vec3 rel = vec3(s.relative_position_radius);
            float cover = lamp_pixel_weight(rel, r, x, row);
            if (cover <= 0.0f) continue;
            float d = length(rel);
            int hit = -1;
            vec3 n;
            if (HAS_SURFACES && trace_surfaces(origin, rel / d, hit, n) < d - r) continue;
            vec3 core = vec3(s.intensity_edge) * (spot_profile_toward(s, -rel / d) / (PI * r * r));
            core *= transmittance(d) * atmosphere_transmittance(origin, rel / d, d);
            radiance = radiance * max(1.0f - cover, 0.0f) + core * cover;
        }
    }
    return radiance;
}

// Radiance arriving at the camera along the ray origin + t dir (lamp cores
// smaller than a pixel excepted: lamp_subpixel_cores).
vec3 ray_radiance(vec3 origin, vec3 dir) {
    int hit_index = -1;
    vec3 normal = vec3(0.0f, 1.0f, 0.0f);
    float t_hit = NO_HIT;
    if (HAS_SURFACES) t_hit = trace_surfaces(origin, dir, hit_index, normal);

    // Lamp cores: the nearest lamp sphere in front of the first surface. A
    // spot's core shows its profile in the direction of the camera.
    int lamp_index = -1;
    int spot_index = -1;
    if (HAS_POINT_LIGHTS) {
        for (int i = 0; i < point_light_count(); ++i) {
            PointLightGpu lamp = point_light(i);
            if (lamp_is_subpixel(vec3(lamp.position_radius) - origin, lamp.position_radius.w)) continue;
            float t = intersect_lamp(lamp, origin, dir);
            if (t < t_hit) {
                t_hit = t;
                lamp_index = i;
            }
        }
    }

    if (HAS_SPOT_LIGHTS) {
        for (int i = 0; i < spot_light_count(); ++i) {
            SpotLightGpu s = spot_light(i);
            if (lamp_is_subpixel(vec3(s.relative_position_radius), s.relative_position_radius.w)) continue;
            PointLightGpu sphere;
            sphere.position_radius = vec4(vec3(s.world_position), s.relative_position_radius.w);
            sphere.intensity = s.intensity_edge;
            float t = intersect_lamp(sphere, origin, dir);
            if (t < t_hit) {
                t_hit = t;
                spot_index = i;
                lamp_index = -1;
            }
        }
    }

    vec3 radiance;
    if (spot_index >= 0) {
        SpotLightGpu s = spot_light(spot_index);
        float r = s.relative_position_radius.w;
        radiance = vec3(s.intensity_edge) * (spot_profile_toward(s, normalize(-vec3(s.relative_position_radius))) / (PI * r * r));
    } else if (lamp_index >= 0) {
        PointLightGpu lamp = point_light(lamp_index);
        float r = lamp.position_radius.w;
        radiance = vec3(lamp.intensity) / (PI * r * r);
    } else if (hit_index >= 0) {
        vec3 p = origin + t_hit * dir;
        vec3 albedo = vec3(surface(hit_index).albedo_type);
        vec3 irradiance = vec3(0.0f);
        // A black surface reflects nothing: skip its lighting (and shadow rays).
        bool black = albedo.x == 0.0f && albedo.y == 0.0f && albedo.z == 0.0f;
        if (HAS_POINT_LIGHTS && !black) irradiance += point_light_irradiance(p, normal, hit_index);
        if (HAS_SPOT_LIGHTS && !black) irradiance += spot_light_irradiance(p, normal, hit_index, irradiance);
        if (HAS_SKY && !black) irradiance += sky_irradiance(p, normal);
        if (HAS_SUN && !black && dot(normal, vec3(frame.sky.sun_direction)) > 0.0f) {
            float visible = sun_visibility(p, normal, hit_index);  // effects/sun_shadow_map
            if (visible > 0.0f) irradiance += visible * sun_irradiance(p, normal);
        }
        radiance = albedo / PI * irradiance;
    } else {
        radiance = vec3(frame.background);
        if (HAS_SKY) radiance += sky_radiance(dir);
    }
    // Everything behind the medium reaches the camera attenuated; the fog in
    // front of it adds its glow.
    radiance *= transmittance(t_hit);
    // The atmosphere (daytime, sky.glsl): aerial perspective on whatever the
    // ray ends at, plus the sky and sun light its particles scatter.
    if (HAS_ATMOSPHERE) {
        vec3 sigma_medium = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
        vec3 inscatter;
        vec3 through_atmosphere;
        if (SKY_MARCH) {
            atmosphere_scattering_march(origin, dir, t_hit, sigma_medium, int(frame.march_steps), inscatter,
                                        through_atmosphere);
        } else {
            atmosphere_scattering(origin, dir, t_hit, sigma_medium, inscatter, through_atmosphere);
        }
        radiance = radiance * through_atmosphere + inscatter;
    }
    if (HAS_AIRLIGHT) {
        for (int i = 0; i < point_light_count(); ++i) {
            radiance += point_light_airlight(point_light(i), origin, dir, t_hit, radiance);
        }
    }
    if (HAS_SPOT_AIRLIGHT) {
        for (int i = 0; i < spot_light_count(); ++i) radiance += spot_light_airlight(i, dir, t_hit, radiance);
    }
    return radiance;
}

// The smallest normal float32 (FLT_MIN): below it a float is subnormal (denormal).
CONST float RADIANCE_MIN_NORMAL = 1.17549435e-38f;
// The largest float32 (FLT_MAX).
CONST float RADIANCE_MAX = 3.40282347e38f;

// A radiance channel with subnormal magnitude flushed to 0. Terms that underflow
// (exp(-T) of a far lamp, a cone's edge) leave values of 1e-45..1e-38 that the CPU
// keeps and a GPU flushes, so the backends' images would differ in those pixels;
// radiance never carries them (effects/display/physics.md section 8). Written as a
// comparison, so that a GPU which flushes subnormal inputs gives 0 as well.
float flush_subnormal(float v) { return abs(v) < RADIANCE_MIN_NORMAL ? 0.0f : v; }

// Linear radiance of pixel (x, row), row 0 on top: the per-pixel entry point.
vec3 render_pixel(int x, int row) {
    vec3 radiance = ray_radiance(vec3(frame.camera_position), camera_ray_direction(x, row));
    if (HAS_POINT_LIGHTS || HAS_SPOT_LIGHTS) radiance = lamp_subpixel_cores(x, row, radiance);
    radiance = vec3(flush_subnormal(radiance.r), flush_subnormal(radiance.g), flush_subnormal(radiance.b));
    // Saturated at the largest float, never Inf: the scene keys' bounds
    // (max_radiometric, max_extinction in cpp/scene_keys.hpp) keep valid scenes
    // below it; this is the net for sums of many lamps near those bounds.
    return min(radiance, vec3(RADIANCE_MAX));
}
