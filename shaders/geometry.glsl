// Ray geometry shared by both backends: camera rays and ray/surface
// intersections. Requires the accessors frame, surface_count(), surface(i),
// bvh_node(i), point_light_count(), point_light(i) (declared per backend).

// Unit direction of the ray through the centre of pixel (x, row), row 0 on top.
vec3 camera_ray_direction(int x, int row) {
    float width = float(frame.film_width);
    float height = float(frame.film_height);
    float sx = 2.0f * (float(x) + 0.5f) / width - 1.0f;
    float sy = 1.0f - 2.0f * (float(row) + 0.5f) / height;
    return normalize(vec3(frame.camera_forward) + sx * vec3(frame.camera_right) +
                     sy * vec3(frame.camera_up));
}

// The pixel (x, row) whose camera ray is dir (the inverse of
// camera_ray_direction); false off the film.
bool film_pixel_of(vec3 dir, OUT(int) x, OUT(int) row) {
    vec3 r = vec3(frame.camera_right);
    vec3 u = vec3(frame.camera_up);
    float z = dot(dir, vec3(frame.camera_forward));
    x = -1;
    row = -1;
    if (!(z > 0.0f)) return false;
    float sx = dot(dir, r) / (dot(r, r) * z);
    float sy = dot(dir, u) / (dot(u, u) * z);
    x = int(floor(0.5f * (sx + 1.0f) * float(frame.film_width)));
    row = int(floor(0.5f * (1.0f - sy) * float(frame.film_height)));
    return x >= 0 && row >= 0 && x < frame.film_width && row < frame.film_height;
}

// 1/x without dividing by zero (slab tests with axis-parallel rays).
float safe_inverse(float x) {
    return 1.0f / (abs(x) > 1.0e-20f ? x : (x >= 0.0f ? 1.0e-20f : -1.0e-20f));
}

// Nearest intersection distance t > t_min of a ray with surface s, or NO_HIT.
// The geometric normal (not yet facing the ray) goes to `normal`.
float intersect_surface(SurfaceGpu s, vec3 origin, vec3 dir, float t_min, OUT(vec3) normal) {
    int type = int(s.albedo_type.w + 0.5f);
    normal = vec3(0.0f, 1.0f, 0.0f);
    if (type == SURFACE_PLANE) {
        vec3 n = vec3(s.p1);
        float denom = dot(n, dir);
        if (abs(denom) < 1.0e-12f) return NO_HIT;
        float t = dot(vec3(s.p0) - origin, n) / denom;
        normal = n;
        return t > t_min ? t : NO_HIT;
    }
    if (type == SURFACE_BOX) {
        vec3 inv = vec3(safe_inverse(dir.x), safe_inverse(dir.y), safe_inverse(dir.z));
        vec3 ta = (vec3(s.p0) - origin) * inv;
        vec3 tb = (vec3(s.p1) - origin) * inv;
        vec3 t_lo = min(ta, tb);
        vec3 t_hi = max(ta, tb);
        float t_near = max(max(t_lo.x, t_lo.y), t_lo.z);
        float t_far = min(min(t_hi.x, t_hi.y), t_hi.z);
        if (t_near > t_far) return NO_HIT;
        // Entering face when the origin is outside, leaving face when inside.
        bool outside = t_near > t_min;
        float t = outside ? t_near : t_far;
        if (t <= t_min) return NO_HIT;
        vec3 t_face = outside ? t_lo : t_hi;
        if (t_face.x == t) normal = vec3(-sign(dir.x), 0.0f, 0.0f);
        else if (t_face.y == t) normal = vec3(0.0f, -sign(dir.y), 0.0f);
        else normal = vec3(0.0f, 0.0f, -sign(dir.z));
        return t;
    }
    // Sphere: |origin + t dir - c|^2 = r^2 with |dir| = 1, roots -b -+ h with
    // h^2 = r^2 - d^2 (d: the ray's distance from the centre), formed as
    // (r - d)(r + d) and square-rooted factor by factor: no cancellation for
    // distant spheres and no overflow of r^2 for huge ones.
    vec3 oc = origin - vec3(s.p0);
    float r = s.p1.x;
    float b = dot(oc, dir);
    float d = length(oc - b * dir);  // component of oc across the ray
    if (d > r) return NO_HIT;
    float h = sqrt(r - d) * sqrt(r + d);
    float t = -b - h;
    if (t <= t_min) t = -b + h;
    if (t <= t_min) return NO_HIT;
    normal = (origin + t * dir - vec3(s.p0)) / r;
    return t;
}

// Distance along a ray from a point of surface s itself (a shadow ray) to
// where it meets s again, or NO_HIT. Every surface is convex: a plane never
// meets the ray again; a ray leaving a sphere neither, one entering it meets
// it where it leaves, at the far root -2 b (exact for an origin on the
// sphere). The general test would meet the sphere again at t ~ 0 wherever
// float rounding, about 6e-8 (|c| + r), puts the origin inside: shadow acne
// that no fixed offset beats on large spheres. Boxes keep the general test
// (their faces are axis-aligned coordinates, which surface_offset covers).
float intersect_own_surface(SurfaceGpu s, vec3 origin, vec3 dir, OUT(vec3) normal) {
    int type = int(s.albedo_type.w + 0.5f);
    normal = vec3(0.0f, 1.0f, 0.0f);
    if (type == SURFACE_PLANE) return NO_HIT;
    if (type == SURFACE_SPHERE) {
        float b = dot(origin - vec3(s.p0), dir);
        return b < 0.0f ? -2.0f * b : NO_HIT;
    }
    return intersect_surface(s, origin, dir, 0.0f, normal);
}

// True when the ray segment origin + t dir, t in [0, t_max), meets the box;
// inv_dir = 1 / dir (safe_inverse), so there is no division by zero.
bool ray_meets_box(vec3 origin, vec3 inv_dir, vec3 lo, vec3 hi, float t_max) {
    vec3 ta = (lo - origin) * inv_dir;
    vec3 tb = (hi - origin) * inv_dir;
    vec3 t_lo = min(ta, tb);
    vec3 t_hi = max(ta, tb);
    float t_near = max(max(t_lo.x, t_lo.y), max(t_lo.z, 0.0f));
    float t_far = min(min(t_hi.x, t_hi.y), min(t_hi.z, t_max));
    return t_near <= t_far;
}

// The distance to surface i along the ray, from a point of surface self
// (-1: from anywhere else).
float intersect_surface_from(int i, int self, vec3 origin, vec3 dir, OUT(vec3) normal) {
    if (i == self) return intersect_own_surface(surface(i), origin, dir, normal);
    return intersect_surface(surface(i), origin, dir, 0.0f, normal);
}

// Nearest surface hit along the ray closer than t_max, or any hit when
// `any_hit` (shadow rays): planes one by one, the bounded surfaces through the
// BVH. `self`: the surface the ray starts on (-1: none). Returns the distance
// (NO_HIT if none) with its surface index and geometric normal.
float trace_surfaces_below(vec3 origin, vec3 dir, float t_max, bool any_hit, int self, OUT(int) hit_index,
                           OUT(vec3) hit_normal) {
    float best = t_max;
    hit_index = -1;
    hit_normal = vec3(0.0f, 1.0f, 0.0f);
    for (int i = 0; i < frame.plane_count; ++i) {
        vec3 n;
        float t = intersect_surface_from(i, self, origin, dir, n);
        if (t < best) {
            best = t;
            hit_index = i;
            hit_normal = n;
            if (any_hit) return best;
        }
    }
    if (frame.bvh_node_count == 0) return hit_index >= 0 ? best : NO_HIT;
    vec3 inv_dir = vec3(safe_inverse(dir.x), safe_inverse(dir.y), safe_inverse(dir.z));
    int stack[BVH_STACK_SIZE];
    int top = 0;
    stack[top++] = 0;
    // A traversal visits each node at most once. The bound is also needed on
    // GL: llvmpipe can keep a `while (top > 0)` loop running after every lane
    // has left it, until its loop limiter (docs/architecture.md, "GL loop
    // limit") ends all of the invocation's loops (seen in grid passes).
    for (int visits = 0; visits < frame.bvh_node_count && top > 0; ++visits) {
        BvhNodeGpu node = bvh_node(stack[--top]);
        if (!ray_meets_box(origin, inv_dir, vec3(node.lo), vec3(node.hi), best)) continue;
        if (node.info.y == 0) {
            if (top + 2 <= BVH_STACK_SIZE) {
                stack[top++] = node.info.x + 1;
                stack[top++] = node.info.x;
            }
            continue;
        }
        for (int i = node.info.x; i < node.info.x + node.info.y; ++i) {
            vec3 n;
            float t = intersect_surface_from(i, self, origin, dir, n);
            if (t < best) {
                best = t;
                hit_index = i;
                hit_normal = n;
                if (any_hit) return best;
            }
        }
    }
    return hit_index >= 0 ? best : NO_HIT;
}

// Closest surface along the ray: returns its distance (NO_HIT if none), its
// index and its normal turned to face the ray origin.
float trace_surfaces(vec3 origin, vec3 dir, OUT(int) hit_index, OUT(vec3) hit_normal) {
    float best = trace_surfaces_below(origin, dir, NO_HIT, false, -1, hit_index, hit_normal);
    if (dot(hit_normal, dir) > 0.0f) hit_normal = -hit_normal;
    return best;
}

// True when any surface blocks the segment origin + t dir, 0 < t < max_t,
// which starts on surface `self` (-1: on none).
bool segment_occluded(vec3 origin, vec3 dir, float max_t, int self) {
    int index;
    vec3 n;
    return trace_surfaces_below(origin, dir, max_t, true, self, index, n) < max_t;
}

// Distance to the near side of lamp `i`'s sphere along the ray, or NO_HIT.
// A camera inside the sphere does not see that lamp's core.
float intersect_lamp(PointLightGpu light, vec3 origin, vec3 dir) {
    vec3 oc = origin - vec3(light.position_radius);
    float r = light.position_radius.w;
    float b = dot(oc, dir);
    if (dot(oc, oc) <= r * r || b >= 0.0f) return NO_HIT;
    vec3 perp = oc - b * dir;
    float disc = r * r - dot(perp, perp);
    if (disc < 0.0f) return NO_HIT;
    return -b - sqrt(disc);
}

// Offset that lifts a hit point off its surface before tracing shadow rays:
// a multiple of the float rounding of p (relative to its coordinates and to
// the camera's, which p was computed from), so it works at any scale.
float surface_offset(vec3 p) {
    vec3 o = vec3(frame.camera_position);
    float scale = max(max(abs(p.x), abs(p.y)), abs(p.z)) + max(max(abs(o.x), abs(o.y)), abs(o.z));
    return 1.0e-5f * scale + 1.0e-30f;
}
