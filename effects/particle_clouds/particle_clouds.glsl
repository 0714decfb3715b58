// The particle clouds' per-pixel functions (physics.md sections 3 and 6):
// the lighting table's lookup and the compositing of a pixel's particles.

// Texel k of a table laid out in rows of PARTICLE_ROW_TEXELS.
vec4 particle_texel4(int table, int k) {
    return table_texel4(table, k % PARTICLE_ROW_TEXELS, k / PARTICLE_ROW_TEXELS);
}
int particle_index_at(int k) {
    return int(table_texel(TABLE_PARTICLE_TILES, k % PARTICLE_ROW_TEXELS, k / PARTICLE_ROW_TEXELS));
}

// One optical-radius slice m of the lighting table (eq. 3.1): its four
// channels trilinear in the entry angle, view zenith and view azimuth
// (nodes e, z, a and the fractions toward the next in f).
vec4 particle_slice(int m, ivec3 node, vec3 f) {
    ivec4 n = frame.particle_clouds.table_shape;
    vec4 sum = vec4(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        int de = corner & 1;
        int dz = (corner >> 1) & 1;
        int da = (corner >> 2) & 1;
        float w = (de == 1 ? f.x : 1.0f - f.x) * (dz == 1 ? f.y : 1.0f - f.y) * (da == 1 ? f.z : 1.0f - f.z);
        int x = (node.z + da) + n.z * (node.y + dz);
        int y = (node.x + de) + n.x * m;
        sum += w * table_texel4(TABLE_PARTICLE_LIGHT, x, y);
    }
    return sum;
}

// The lower node of a fractional index on n nodes (clamped to [0, n - 2]) and the fraction past it.
int particle_node(float x, int n, OUT(float) f) {
    float c = clamp(x, 0.0f, float(n - 1));
    int i = min(int(c), n - 2);
    f = c - float(i);
    return i;
}

// A Catmull-Rom cubic through b, c at f in [0, 1], a missing end (has_a,
// has_d false) continued linearly (eq. 3.3).
float particle_cubic(float a, float b, float c, float d, bool has_a, bool has_d, float f) {
    if (!has_a) a = 2.0f * b - c;
    if (!has_d) d = 2.0f * c - b;
    float f2 = f * f;
    float f3 = f2 * f;
    return 0.5f * ((-f3 + 2.0f * f2 - f) * a + (3.0f * f3 - 5.0f * f2 + 2.0f) * b + (-3.0f * f3 + 4.0f * f2 + f) * c +
                   (f3 - f2) * d);
}

// Across the slices (eq. 3.3): the cubic of the logarithm where all four are positive, else of the value clamped at 0.
float particle_across_taus(float a, float b, float c, float d, bool has_a, bool has_d, float f) {
    bool positive = b > 0.0f && c > 0.0f && (!has_a || a > 0.0f) && (!has_d || d > 0.0f);
    if (positive)
        return exp(particle_cubic(has_a ? log(a) : 0.0f, log(b), log(c), has_d ? log(d) : 0.0f, has_a, has_d, f));
    return max(0.0f, particle_cubic(a, b, c, d, has_a, has_d, f));
}

// The light of a ray entering a particle of optical radius tau where its
// outward normal is n, along unit v (v . n < 0), the sun toward s, per unit
// sun irradiance, all orders (eq. 3.1-3.3; ParticleTable::lookup is the same
// in double).
float particle_table_light(float tau, vec3 n, vec3 v, vec3 s) {
    ivec4 shape = frame.particle_clouds.table_shape;
    vec4 taus = frame.particle_clouds.table_taus;
    float cos_entry = clamp(dot(n, s), -1.0f, 1.0f);
    float cos_view = clamp(-dot(n, v), 0.0f, 1.0f);
    vec3 t = s - cos_entry * n;
    float psi = 0.0f;
    if (dot(t, t) > 1.0e-12f) {
        t = normalize(t);
        psi = atan(abs(dot(v, cross(n, t))), dot(v, t));
    }
    vec3 f;
    ivec3 node;
    node.x = particle_node(particle_entry_index(precise_acos(cos_entry), shape.x, taus.w != 0.0f), shape.x, f.x);
    node.y = particle_node(particle_zenith_coordinate(precise_acos(cos_view)) * float(shape.y - 1), shape.y, f.y);
    node.z = particle_node(psi / PI * float(shape.z - 1), shape.z, f.z);
    float ft;
    int m = particle_node(log(max(tau, 1.0e-30f) / taus.x) / taus.y * float(shape.w - 1), shape.w, ft);
    bool below = m > 0;
    bool above = m + 2 < shape.w;
    // Slices m - 1 (where below) to m + 2 (where above), in one loop with one
    // call so that the shader compiler emits the slice's texel reads once.
    vec4 slices[4];
    slices[0] = vec4(0.0f);
    slices[3] = vec4(0.0f);
    for (int j = below ? 0 : 1; j < (above ? 4 : 3); ++j) slices[j] = particle_slice(m - 1 + j, node, f);
    vec4 vm = slices[0];
    vec4 v0 = slices[1];
    vec4 v1 = slices[2];
    vec4 v2 = slices[3];
    // The channels: order 1 over its phase, orders 2 and 3's peaks over theirs, the rest (eq. 3.1).
    float g = taus.z;
    float mu = dot(s, v);
    vec4 phases = vec4(0.0f, 0.0f, 0.0f, 1.0f);
    phases.x = species_phase(vec4(g, 0.0f, 1.0f, 0.0f), mu);
    phases.y = species_phase(vec4(g * g, 0.0f, 1.0f, 0.0f), mu);
    phases.z = species_phase(vec4(g * g * g, 0.0f, 1.0f, 0.0f), mu);
    float first = particle_across_taus(vm.x * phases.x, v0.x * phases.x, v1.x * phases.x, v2.x * phases.x, below,
                                       above, ft);
    float rest = particle_across_taus(dot(vec3(vm.y, vm.z, vm.w), vec3(phases.y, phases.z, 1.0f)),
                                      dot(vec3(v0.y, v0.z, v0.w), vec3(phases.y, phases.z, 1.0f)),
                                      dot(vec3(v1.y, v1.z, v1.w), vec3(phases.y, phases.z, 1.0f)),
                                      dot(vec3(v2.y, v2.z, v2.w), vec3(phases.y, phases.z, 1.0f)), below, above, ft);
    // Below the smallest slice: order 1 scales with tau, the rest with tau^2 (eq. 3.2).
    float thin = min(1.0f, tau / taus.x);
    return first * thin + rest * thin * thin;
}

// The screen tile holding the pixel whose ray is dir (the inverse of
// camera_ray_direction), -1 off the film.
int particle_tile_of(vec3 dir) {
    int x;
    int row;
    if (!film_pixel_of(dir, x, row)) return -1;
    int size = frame.particle_clouds.tiles.w;
    return (row / size) * frame.particle_clouds.tiles.x + x / size;
}

// The particles along [0, t_hit] of the ray origin + t dir, nearest centre
// first (section 6): their light reaching the camera (light) and the
// fraction of the light behind them they pass (through); t_half, the middle
// of the visible chord of the particle where that fraction falls below 1/2
// (of the last one where it never does; -1 where the ray meets none).
void particle_composite(vec3 origin, vec3 dir, float t_hit, OUT(vec3) light, OUT(float) through,
                        OUT(float) t_half) {
    light = vec3(0.0f);
    through = 1.0f;
    t_half = -1.0f;
    int tile = particle_tile_of(dir);
    if (tile < 0) return;
    int begin = particle_index_at(tile);
    int end = particle_index_at(tile + 1);
    int header = frame.particle_clouds.tiles.x * frame.particle_clouds.tiles.y + 1;
    vec3 s = vec3(frame.sky.sun_direction);
    bool sun = HAS_SUN && s.y > 0.0f;
    bool crossed_half = false;
    for (int k = begin; k < end; ++k) {
        int i = particle_index_at(header + k);
        vec4 sphere = particle_texel4(TABLE_PARTICLES, 2 * i);
        vec4 lit = particle_texel4(TABLE_PARTICLES, 2 * i + 1);
        // Eq. 6.1: the chord [t0, t1] and its visible part [a, e] (the camera inside, a surface cutting it).
        vec3 oc = vec3(sphere) - origin;
        float b = dot(oc, dir);
        float R = sphere.w;
        float h2 = R * R - dot(oc - b * dir, oc - b * dir);
        if (!(h2 > 0.0f)) continue;
        float h = sqrt(h2);
        float a = max(b - h, 0.0f);
        float e = min(b + h, t_hit);
        if (!(e > a)) continue;
        float sigma = lit.x / R;
        float opacity = 1.0f - exp(-sigma * (e - a));
        float chord_opacity = 1.0f - exp(-sigma * 2.0f * h);
        // The chord's light scaled by the visible part's share of its opacity (eq. 6.2).
        float share = chord_opacity > 1.0e-6f ? opacity / chord_opacity : (e - a) / (2.0f * h);
        vec3 c = vec3(sphere);
        vec3 own = vec3(0.0f);
        if (sun && lit.y > 0.0f) {
            vec3 n = (origin + (b - h) * dir - c) / R;
            own += sun_irradiance(c, s) * (lit.y * share * particle_table_light(lit.x, n, dir, s));
        }
        // The sky's light (eq. 6.3): the mean radiance of the sky over the sphere of directions, seen
        // through the others above, scattered in proportion to the opacity.
        if (HAS_SKY) own += sky_irradiance(c, vec3(0.0f, 1.0f, 0.0f)) * (lit.z * opacity / (2.0f * PI));
        light += through * own;
        through *= 1.0f - opacity;
        // The chord's middle, within its visible part (a camera inside the particle may be past it).
        if (!crossed_half) t_half = clamp(b, a, e);
        crossed_half = crossed_half || through < 0.5f;
        if (through < PARTICLE_OPAQUE) {
            through = 0.0f;
            break;
        }
    }
}

// The distance along the segment of a 2-D point q + t v after which it lies
// outside the square [lo, hi] for good (0: outside from the start on).
float square_exit(vec2 q, vec2 v, vec2 lo, vec2 hi) {
    float t = NO_HIT;
    for (int k = 0; k < 2; ++k) {
        if (v[k] > 0.0f) t = min(t, (hi[k] - q[k]) / v[k]);
        else if (v[k] < 0.0f) t = min(t, (lo[k] - q[k]) / v[k]);
        else if (q[k] < lo[k] || q[k] > hi[k]) t = 0.0f;
    }
    return max(t, 0.0f);
}

// The distance along the ray o + t d after which every point's read of the
// shadow map (particle_sun_transmittance: along the sun below the map's
// plane, straight below above it) lies off the map, where the sun passes
// freely (section 5): the later of the two reads' exits from the map's
// square, each moving linearly with t. NO_HIT without a map.
float particle_shadow_exit(vec3 o, vec3 d) {
    vec3 s = vec3(frame.sky.sun_direction);
    if (frame.particle_clouds.shadow_size.x == 0 || !(s.y > 0.0f)) return NO_HIT;
    vec4 map = frame.particle_clouds.shadow_map;
    vec2 lo = vec2(map.x, map.y);
    vec2 hi = lo + vec2(1.0f / map.z);
    vec2 slope = vec2(s.x, s.z) / s.y;
    float below = square_exit(vec2(o.x, o.z) + (map.w - o.y) * slope, vec2(d.x, d.z) - d.y * slope, lo, hi);
    float above = square_exit(vec2(o.x, o.z), vec2(d.x, d.z), lo, hi);
    return max(below, above);
}

// The sun's transmittance through the particles from p (section 5): the
// shadow map on the plane below them, read where the ray from p toward the
// sun crosses it (p above the plane: straight below p, the shadow of what
// lies above the plane taken for all); 1 off the map.
float particle_sun_transmittance(vec3 p) {
    int n = frame.particle_clouds.shadow_size.x;
    vec3 s = vec3(frame.sky.sun_direction);
    if (n == 0 || !(s.y > 0.0f)) return 1.0f;
    vec4 map = frame.particle_clouds.shadow_map;
    float t = max((map.w - p.y) / s.y, 0.0f);
    float u = (p.x + t * s.x - map.x) * map.z;
    float v = (p.z + t * s.z - map.y) * map.z;
    if (u < 0.0f || v < 0.0f || u > 1.0f || v > 1.0f) return 1.0f;
    return table_bilinear(TABLE_PARTICLE_SHADOW, n, n, u, v);
}
