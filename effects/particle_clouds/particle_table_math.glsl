// The particle lighting table's node coordinates (physics.md section 3,
// eq. 3.2): where its nodes lie in the entry angle and the view zenith. One
// source for the build and the lookup on the CPU (particle_table.cpp, through
// shader_cpp.hpp) and the lookup on GL (particle_clouds.glsl). Nothing here
// reads the frame or a table.

// Eq. 3.2: the entry angle's nodes are uniform within four spans of the
// angle from the sun, with these relative densities: 1 on the lit side, 3
// across the terminator, where a thick particle's light falls steeply and
// order 1 peaks on the grazing rays, 2 into the shadow and 1 on the far side
// (effects/particle_clouds/docs/table_resolution.txt). Each span holds a
// whole number of node intervals, so that a node lies on every span's edge
// and the interpolation between two nodes is linear in the angle.
CONST float PARTICLE_TERMINATOR_FROM = 1.3962634f;  // 80 degrees
CONST float PARTICLE_TERMINATOR_TO = 1.7453293f;    // 100 degrees
CONST float PARTICLE_SHADOW_TO = 2.4434610f;        // 140 degrees
CONST float PARTICLE_TERMINATOR_DENSITY = 3.0f;
CONST float PARTICLE_SHADOW_DENSITY = 2.0f;
// The fewest entry nodes of the dense layout (an interval per span).
CONST int PARTICLE_DENSE_ENTRY_MIN = 5;

// The node indices at the spans' edges 80, 100 and 140 degrees for n entry
// nodes (the last node, n - 1, is at pi): each span's share of the n - 1
// intervals in proportion to its length times its density, rounded, at least one.
INLINE vec3 particle_entry_edges(int n) {
    float lit = PARTICLE_TERMINATOR_FROM;
    float terminator = PARTICLE_TERMINATOR_DENSITY * (PARTICLE_TERMINATOR_TO - PARTICLE_TERMINATOR_FROM);
    float shadow = PARTICLE_SHADOW_DENSITY * (PARTICLE_SHADOW_TO - PARTICLE_TERMINATOR_TO);
    float per_weight = float(n - 1) / (lit + terminator + shadow + (PI - PARTICLE_SHADOW_TO));
    float a = max(1.0f, floor(lit * per_weight + 0.5f));
    float b = a + max(1.0f, floor(terminator * per_weight + 0.5f));
    float c = min(b + max(1.0f, floor(shadow * per_weight + 0.5f)), float(n - 2));
    return vec3(a, b, c);
}

// The entry angle (radians from the sun, [0, pi]) as a fractional node index
// in [0, n - 1]. Uniform in the angle without dense_terminator
// (ParticleTableShape::dense_terminator, for comparisons).
INLINE float particle_entry_index(float angle, int n, bool dense_terminator) {
    float x = clamp(angle, 0.0f, PI);
    if (!dense_terminator) return x / PI * float(n - 1);
    vec3 edge = particle_entry_edges(n);
    if (x <= PARTICLE_TERMINATOR_FROM) return x / PARTICLE_TERMINATOR_FROM * edge.x;
    if (x <= PARTICLE_TERMINATOR_TO)
        return mix(edge.x, edge.y, (x - PARTICLE_TERMINATOR_FROM) / (PARTICLE_TERMINATOR_TO - PARTICLE_TERMINATOR_FROM));
    if (x <= PARTICLE_SHADOW_TO)
        return mix(edge.y, edge.z, (x - PARTICLE_TERMINATOR_TO) / (PARTICLE_SHADOW_TO - PARTICLE_TERMINATOR_TO));
    return mix(edge.z, float(n - 1), (x - PARTICLE_SHADOW_TO) / (PI - PARTICLE_SHADOW_TO));
}

// The inverse: the entry angle of node i (or of a fractional index).
INLINE float particle_entry_angle(float i, int n, bool dense_terminator) {
    float x = clamp(i, 0.0f, float(n - 1));
    if (!dense_terminator) return x / float(n - 1) * PI;
    vec3 edge = particle_entry_edges(n);
    if (x <= edge.x) return x / edge.x * PARTICLE_TERMINATOR_FROM;
    if (x <= edge.y) return mix(PARTICLE_TERMINATOR_FROM, PARTICLE_TERMINATOR_TO, (x - edge.x) / (edge.y - edge.x));
    if (x <= edge.z) return mix(PARTICLE_TERMINATOR_TO, PARTICLE_SHADOW_TO, (x - edge.y) / (edge.z - edge.y));
    return mix(PARTICLE_SHADOW_TO, PI, (x - edge.z) / (float(n - 1) - edge.z));
}

// Eq. 3.2: the view's zenith (from the inward normal, [0, pi / 2]) at a
// coordinate s in [0, 1] is (pi / 2) (1 - (1 - s)^1.5): dense near grazing,
// where the chord 2 cos(zenith) and the light along it change fastest.
INLINE float particle_zenith_angle(float coordinate) {
    return 0.5f * PI * (1.0f - pow(1.0f - clamp(coordinate, 0.0f, 1.0f), 1.5f));
}

// The inverse: the coordinate of a zenith angle.
INLINE float particle_zenith_coordinate(float zenith) {
    return 1.0f - pow(max(1.0f - zenith / (0.5f * PI), 0.0f), 1.0f / 1.5f);
}
