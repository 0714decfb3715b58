// The photo effect's terms (physics.md).

// Hook backplate: pixel (x, row)'s ray ends at the backplate's depth with its
// radiance; with the backplate's own intrinsics, `dir` becomes its camera's ray.
bool photo_backplate(int x, int row, INOUT(vec3) dir, INOUT(float) t_end, INOUT(vec3) radiance) {
    if (!HAS_PHOTO) return false;
    vec4 intrinsics = frame.photo.intrinsics;
    if (intrinsics.x > 0.0f) {  // physics.md section 2
        vec3 right = normalize(vec3(frame.camera_right));
        vec3 up = normalize(vec3(frame.camera_up));
        dir = normalize(vec3(frame.camera_forward) + ((float(x) - intrinsics.z) / intrinsics.x) * right -
                        ((float(row) - intrinsics.w) / intrinsics.y) * up);
    }
    vec4 texel = table_texel4(TABLE_PHOTO, x, row);
    radiance = vec3(texel);
    float depth = texel.w;
    if (depth >= NO_HIT) {
        t_end = NO_HIT;
    } else {
        t_end = frame.photo.depth_along_axis != 0 ? depth / dot(dir, vec3(frame.camera_forward)) : depth;
        t_end = min(t_end, NO_HIT);
    }
    return true;
}

// Hook view_transfer: the homogeneous medium lit by a uniform ambient light
// whose in-scattering is the constant atmospheric light A per unit optical
// depth: A (1 - exp(-sigma_t t)) along [0, t] (physics.md section 3).
vec3 atmospheric_light_view_transfer(vec3 origin, vec3 dir, float t_hit, vec3 radiance) {
    if (!HAS_ATMOSPHERIC_LIGHT) return radiance;
    vec3 light = vec3(frame.photo.atmospheric_light) * (vec3(1.0f) - transmittance(t_hit));
    layer_add(LAYER_ATMOSPHERIC_LIGHT, light);
    return radiance + light;
}
