// The shadows of the sun and of lamps along a view ray (physics.md). A point x
// is in the sun's shadow when the half-line x + u s (u > 0, s toward the sun)
// meets a surface, in a lamp's when the segment from x to the lamp does. Every
// surface is convex (a box, a sphere, the half-space behind a plane), and so
// is the surface swept away from the light, so the points of a view ray that
// one surface shadows form one interval (physics.md sections 2 and 7): found
// here in closed form, merged into the ray's sorted shadowed runs, whose
// complement is the lit part the scattering integrals count.

// The most separate shadowed runs a ray keeps; a ray that crosses more joins
// the two runs with the narrowest lit gap between them (physics.md section 4).
CONST int SHAFTS_MAX_RUNS = 64;

// The shadowed runs of a ray: disjoint intervals [run[k].x, run[k].y] of the
// ray's distance, sorted.
struct ShadowRuns {
    vec2 run[SHAFTS_MAX_RUNS];
    int count;
};

// The runs of the ray being shaded (sun_shadow_runs fills them): a private
// global on GL, a member of the per-thread CpuShader copy on the CPU, so that
// no function copies the array (on llvmpipe, arrays passed by value made the
// shader take 30 s to compile).
ShadowRuns shadow_runs;

// Shrinks [u0, u1] to the u with a + b u <= 0 (an empty result has u0 >= u1).
void keep_where_nonpositive(float a, float b, INOUT(float) u0, INOUT(float) u1) {
    if (b > 0.0f) {
        u1 = min(u1, -a / b);
    } else if (b < 0.0f) {
        u0 = max(u0, -a / b);
    } else if (a > 0.0f) {
        u0 = NO_HIT;
        u1 = -NO_HIT;
    }
}

// The u for which the half-line o + u d + t s, t >= 0, meets the box
// [lo, hi] (physics.md section 2, eq. 2.2): the slab test of that half-line,
// whose entry and exit distances along s are linear in u, is feasible when
// max(0, near_i) <= min(far_j) for every pair of axes, each pair a half-line
// of u (the divisions by |s_i| multiplied out, so near-zero components are safe).
vec2 box_shadow_run(vec3 lo, vec3 hi, vec3 o, vec3 d, vec3 s) {
    float u0 = -NO_HIT;
    float u1 = NO_HIT;
    vec3 near_a = vec3(0.0f);  // |s_i| near_i(u) = near_a_i + slope_i u
    vec3 far_a = vec3(0.0f);   // |s_i| far_i(u) = far_a_i + slope_i u
    vec3 slope = vec3(0.0f);
    vec3 e = abs(s);
    for (int i = 0; i < 3; ++i) {
        if (s[i] == 0.0f) {  // parallel to the slab: the line itself must lie in it
            keep_where_nonpositive(lo[i] - o[i], -d[i], u0, u1);
            keep_where_nonpositive(o[i] - hi[i], d[i], u0, u1);
            continue;
        }
        float sign_s = s[i] > 0.0f ? 1.0f : -1.0f;
        near_a[i] = sign_s * ((s[i] > 0.0f ? lo[i] : hi[i]) - o[i]);
        far_a[i] = sign_s * ((s[i] > 0.0f ? hi[i] : lo[i]) - o[i]);
        slope[i] = -sign_s * d[i];
    }
    for (int j = 0; j < 3; ++j) {
        if (e[j] == 0.0f) continue;
        keep_where_nonpositive(-far_a[j], -slope[j], u0, u1);  // 0 <= far_j
        for (int i = 0; i < 3; ++i) {
            if (i == j || e[i] == 0.0f) continue;
            // near_i <= far_j, times |s_i| |s_j|
            keep_where_nonpositive(near_a[i] * e[j] - far_a[j] * e[i], slope[i] * e[j] - slope[j] * e[i], u0, u1);
        }
    }
    return vec2(u0, u1);
}

// The u for which the half-line o + u d + t s, t >= 0, meets the sphere
// (centre c, radius r): the ball itself, or the half-cylinder behind it
// (distance to the axis c + t s at most r, on the side away from the sun);
// their union is convex (physics.md section 2, eq. 2.3).
vec2 sphere_shadow_run(vec3 c, float r, vec3 o, vec3 d, vec3 s) {
    vec3 q = o - c;
    float r2 = r * r;
    vec2 run = vec2(NO_HIT, -NO_HIT);
    float b = dot(q, d);
    vec3 closest = q - b * d;
    float h2 = dot(closest, closest);
    if (h2 <= r2) {
        float w = sqrt(r2 - h2);
        run = vec2(-b - w, -b + w);
    }
    vec3 q_perp = q - dot(q, s) * s;
    vec3 d_perp = d - dot(d, s) * s;
    float d_perp2 = dot(d_perp, d_perp);
    float c0 = NO_HIT;
    float c1 = -NO_HIT;
    if (d_perp2 > 0.0f) {
        float bc = dot(q_perp, d_perp) / d_perp2;
        vec3 closest_perp = q_perp - bc * d_perp;
        float hc2 = dot(closest_perp, closest_perp);
        if (hc2 <= r2) {
            float w = sqrt((r2 - hc2) / d_perp2);
            c0 = -bc - w;
            c1 = -bc + w;
        }
    } else if (dot(q_perp, q_perp) <= r2) {  // the ray runs along the sun inside the cylinder
        c0 = -NO_HIT;
        c1 = NO_HIT;
    }
    keep_where_nonpositive(dot(q, s), dot(d, s), c0, c1);  // behind the centre's plane
    if (c0 < c1) run = vec2(min(run.x, c0), max(run.y, c1));
    return run;
}

// The u for which o + u d lies behind the plane (point p, unit normal n) as
// seen from the sun: the half-line toward the sun crosses it (eq. 2.4).
vec2 plane_shadow_run(vec3 p, vec3 n, vec3 o, vec3 d, vec3 s) {
    float u0 = -NO_HIT;
    float u1 = NO_HIT;
    float side = dot(s, n);
    if (side == 0.0f) return vec2(NO_HIT, -NO_HIT);
    float sign_side = side > 0.0f ? 1.0f : -1.0f;
    keep_where_nonpositive(sign_side * dot(o - p, n), sign_side * dot(d, n), u0, u1);
    return vec2(u0, u1);
}

// The u for which the segment from o + u d to the lamp at l meets the box
// [lo, hi] (physics.md section 7, eq. 7.2): the line clipped to the box's
// shadow volume, bounded by the planes of the faces that face the lamp (the
// point is behind each) and by the planes through the lamp and each
// silhouette edge (an edge between a face that faces the lamp and one that
// does not). A lamp inside the box shadows everything.
vec2 box_lamp_shadow_run(vec3 lo, vec3 hi, vec3 l, vec3 o, vec3 d) {
    float u0 = -NO_HIT;
    float u1 = NO_HIT;
    vec3 facing = vec3(0.0f);  // per axis: -1 the lo face faces the lamp, +1 the hi face, 0 neither
    for (int i = 0; i < 3; ++i) {
        if (l[i] < lo[i]) {
            facing[i] = -1.0f;
            keep_where_nonpositive(lo[i] - o[i], -d[i], u0, u1);  // x_i >= lo_i
        } else if (l[i] > hi[i]) {
            facing[i] = 1.0f;
            keep_where_nonpositive(o[i] - hi[i], d[i], u0, u1);  // x_i <= hi_i
        }
    }
    if (facing == vec3(0.0f)) return vec2(-NO_HIT, NO_HIT);
    vec3 centre = 0.5f * (lo + hi);
    for (int k = 0; k < 3; ++k) {
        int i = (k + 1) % 3;
        int j = (k + 2) % 3;
        vec3 axis = vec3(0.0f);
        axis[k] = 1.0f;
        for (int corner = 0; corner < 4; ++corner) {
            float side_i = (corner & 1) != 0 ? 1.0f : -1.0f;
            float side_j = (corner & 2) != 0 ? 1.0f : -1.0f;
            if ((facing[i] == side_i) == (facing[j] == side_j)) continue;  // not on the silhouette
            vec3 p = lo;
            p[i] = side_i > 0.0f ? hi[i] : lo[i];
            p[j] = side_j > 0.0f ? hi[j] : lo[j];
            vec3 n = cross(p - l, axis);
            if (dot(n, centre - l) > 0.0f) n = -n;  // the box on the inner side
            keep_where_nonpositive(dot(n, o - l), dot(n, d), u0, u1);
        }
    }
    return vec2(u0, u1);
}

// The u for which the segment from o + u d to the lamp at l meets the sphere
// (centre c, radius r; eq. 7.3): the ball itself, or the part of the cone
// from l tangent to it that lies beyond the plane of the tangent circle,
// (x - l) . q >= |q|^2 - r^2 with q = c - l. A lamp inside the sphere
// shadows everything.
vec2 sphere_lamp_shadow_run(vec3 c, float r, vec3 l, vec3 o, vec3 d) {
    vec3 q = c - l;
    float r2 = r * r;
    float k = dot(q, q) - r2;
    if (!(k > 0.0f)) return vec2(-NO_HIT, NO_HIT);
    vec2 run = vec2(NO_HIT, -NO_HIT);
    vec3 oc = o - c;
    float b = dot(oc, d);
    vec3 closest = oc - b * d;
    float h2 = dot(closest, closest);
    if (h2 <= r2) {
        float w = sqrt(r2 - h2);
        run = vec2(-b - w, -b + w);
    }
    // The cone: ((x - l) . q)^2 >= k |x - l|^2 with x - l = a0 + u d, a
    // quadratic A u^2 + B u + C >= 0; the tangent plane keeps its forward nappe.
    vec3 a0 = o - l;
    float aq = dot(a0, q);
    float dq = dot(d, q);
    float qa = dq * dq - k;  // |d| = 1
    float qb = 2.0f * (aq * dq - k * dot(a0, d));
    float qc = aq * aq - k * dot(a0, a0);
    float c0 = NO_HIT;
    float c1 = -NO_HIT;
    float disc = qb * qb - 4.0f * qa * qc;
    if (qa != 0.0f && disc >= 0.0f) {
        float root = -0.5f * (qb + (qb >= 0.0f ? sqrt(disc) : -sqrt(disc)));
        float r0 = root / qa;
        float r1 = root != 0.0f ? qc / root : r0;
        if (qa < 0.0f) {  // d outside the cone: the line is in it between the roots
            c0 = min(r0, r1);
            c1 = max(r0, r1);
        } else {  // d inside: outside the roots, one side in each nappe; the plane keeps the forward one
            float b0 = -NO_HIT;
            float b1 = min(r0, r1);
            keep_where_nonpositive(k - aq, -dq, b0, b1);
            if (b0 < b1) {
                c0 = b0;
                c1 = b1;
            } else {
                c0 = max(r0, r1);
                c1 = NO_HIT;
            }
        }
    } else if (qa == 0.0f) {  // d along the cone's side: a half-line, B u + C >= 0
        c0 = -NO_HIT;
        c1 = NO_HIT;
        keep_where_nonpositive(-qc, -qb, c0, c1);
    }
    keep_where_nonpositive(k - aq, -dq, c0, c1);  // beyond the tangent circle's plane
    if (c0 < c1) run = vec2(min(run.x, c0), max(run.y, c1));
    return run;
}

// The u for which o + u d lies on the other side of the plane (point p, unit
// normal n) from the lamp at l (eq. 7.4).
vec2 plane_lamp_shadow_run(vec3 p, vec3 n, vec3 l, vec3 o, vec3 d) {
    float u0 = -NO_HIT;
    float u1 = NO_HIT;
    float side = dot(l - p, n);
    if (side == 0.0f) return vec2(NO_HIT, -NO_HIT);
    float sign_side = side > 0.0f ? 1.0f : -1.0f;
    keep_where_nonpositive(sign_side * dot(o - p, n), sign_side * dot(d, n), u0, u1);
    return vec2(u0, u1);
}

// Sorts the runs by start and merges those that overlap or touch.
void merge_shadow_runs() {
    for (int i = 1; i < shadow_runs.count; ++i) {  // insertion sort: a few runs, mostly in order
        vec2 v = shadow_runs.run[i];
        int j = i - 1;
        while (j >= 0 && shadow_runs.run[j].x > v.x) {
            shadow_runs.run[j + 1] = shadow_runs.run[j];
            --j;
        }
        shadow_runs.run[j + 1] = v;
    }
    int n = 0;
    for (int i = 0; i < shadow_runs.count; ++i) {
        if (n > 0 && shadow_runs.run[i].x <= shadow_runs.run[n - 1].y) {
            shadow_runs.run[n - 1].y = max(shadow_runs.run[n - 1].y, shadow_runs.run[i].y);
        } else {
            shadow_runs.run[n] = shadow_runs.run[i];
            ++n;
        }
    }
    shadow_runs.count = n;
}

// Adds run r, clipped to [0, t_end], to the runs (merge_shadow_runs sorts
// them once all are in). When SHAFTS_MAX_RUNS separate runs are already kept,
// the two with the narrowest lit gap between them become one (the gap is lost).
void add_shadow_run(vec2 r, float t_end) {
    r = vec2(max(r.x, 0.0f), min(r.y, t_end));
    if (!(r.x < r.y)) return;
    if (shadow_runs.count == SHAFTS_MAX_RUNS) merge_shadow_runs();
    if (shadow_runs.count == SHAFTS_MAX_RUNS) {
        int narrowest = 0;
        for (int i = 1; i + 1 < shadow_runs.count; ++i) {
            if (shadow_runs.run[i + 1].x - shadow_runs.run[i].y < shadow_runs.run[narrowest + 1].x - shadow_runs.run[narrowest].y) narrowest = i;
        }
        shadow_runs.run[narrowest].y = shadow_runs.run[narrowest + 1].y;
        for (int i = narrowest + 1; i + 1 < shadow_runs.count; ++i) shadow_runs.run[i] = shadow_runs.run[i + 1];
        shadow_runs.count -= 1;
    }
    shadow_runs.run[shadow_runs.count] = r;
    shadow_runs.count += 1;
}

// One surface's shadow run on the ray o + u d from the light (xyz: the
// direction toward the sun, w = 0; or the lamp's position, w = 1).
vec2 caster_shadow_run(int type, vec3 p0, vec3 p1, vec4 light, vec3 o, vec3 d) {
    vec3 l = vec3(light);
    bool lamp = light.w != 0.0f;
    if (type == SURFACE_BOX)
        return lamp ? box_lamp_shadow_run(p0, p1, l, o, d) : box_shadow_run(p0, p1, o, d, l);
    if (type == SURFACE_SPHERE)
        return lamp ? sphere_lamp_shadow_run(p0, p1.x, l, o, d) : sphere_shadow_run(p0, p1.x, o, d, l);
    return lamp ? plane_lamp_shadow_run(p0, p1, l, o, d) : plane_shadow_run(p0, p1, o, d, l);
}

// The runs of the ray o + t d, t in [0, t_end], that the surfaces shadow from
// the light (caster_shadow_run's), into shadow_runs: the planes one by one,
// the bounded surfaces through the BVH, a node's subtree skipped when the
// node's box, swept away from the light, misses the ray's part [0, t_end];
// sorted, disjoint. One loop tests one caster per iteration (a plane, a BVH
// node's box or a leaf's surface) through one call of caster_shadow_run, so
// that the GL compiler inlines the six shadow-run functions once
// (docs/architecture.md, "GL compile time").
void find_shadow_runs(vec3 o, vec3 d, float t_end, vec4 light) {
    shadow_runs.count = 0;
    if (!HAS_SURFACES) return;
    int stack[BVH_STACK_SIZE];
    int top = 0;
    if (frame.bvh_node_count > 0) stack[top++] = 0;
    int plane = 0;
    int leaf_next = 0;  // the leaf's surfaces still to test: [leaf_next, leaf_end)
    int leaf_end = 0;
    // Each plane, node and surface at most once; bounded for llvmpipe (geometry.glsl, trace_surfaces_below).
    int most = frame.plane_count + frame.bvh_node_count + surface_count();
    for (int visits = 0; visits < most; ++visits) {
        int type;
        vec3 p0;
        vec3 p1;
        ivec4 node_info = ivec4(-1);  // x, y: a node's first child or surface, its surface count
        if (plane < frame.plane_count || leaf_next < leaf_end) {
            SurfaceGpu surf = surface(plane < frame.plane_count ? plane++ : leaf_next++);
            type = int(surf.albedo_type.w);
            p0 = vec3(surf.p0);
            p1 = vec3(surf.p1);
        } else if (top > 0) {
            BvhNodeGpu node = bvh_node(stack[--top]);
            node_info = node.info;
            type = SURFACE_BOX;
            p0 = vec3(node.lo);
            p1 = vec3(node.hi);
        } else {
            break;
        }
        vec2 run = caster_shadow_run(type, p0, p1, light, o, d);
        if (node_info.x < 0) {
            add_shadow_run(run, t_end);
            continue;
        }
        if (!(max(run.x, 0.0f) < min(run.y, t_end))) continue;
        if (node_info.y == 0) {
            if (top + 2 <= BVH_STACK_SIZE) {
                stack[top++] = node_info.x + 1;
                stack[top++] = node_info.x;
            }
        } else {
            leaf_next = node_info.x;
            leaf_end = node_info.x + node_info.y;
        }
    }
    merge_shadow_runs();
}

// The runs that the surfaces shadow from the sun (none without HAS_SHAFTS).
void sun_shadow_runs(vec3 o, vec3 d, float t_end) {
    shadow_runs.count = 0;
    if (HAS_SHAFTS) find_shadow_runs(o, d, t_end, vec4(vec3(frame.sky.sun_direction), 0.0f));
}

// 1 where the sun lights point p of the air, 0 where a surface shadows it:
// a shadow ray (the brute-force march, SHAFTS_MARCH).
float sun_visible_from_air(vec3 p) {
    if (!HAS_SHAFTS) return 1.0f;
    return segment_occluded(p, vec3(frame.sky.sun_direction), NO_HIT, -1) ? 0.0f : 1.0f;
}

// int_a^b e^{-sigma t} dt per channel, b < NO_HIT or NO_HIT (to infinity);
// 0 on a channel with sigma = 0 (which scatters nothing).
vec3 attenuated_length(vec3 sigma, float a, float b) {
    vec3 out_length = vec3(0.0f);
    for (int c = 0; c < 3; ++c) {
        if (sigma[c] <= 0.0f) continue;
        float e = exp(-sigma[c] * a);
        out_length[c] = b >= NO_HIT ? e / sigma[c] : e * (b - a) * expm1_over_x(-sigma[c] * (b - a));
    }
    return out_length;
}
