// The particle lighting table's node coordinates (physics.md section 3,
// eq. 3.2): where its nodes lie in the entry angle and the view zenith. One
// source for the build and the lookup on the CPU (particle_table.cpp, through
// shader_cpp.hpp) and the lookup on GL (particle_clouds.glsl). Nothing here
// reads the frame or a table.

// Eq. 3.2: the entry angle's nodes are uniform within four spans of the
// angle from the sun, with these relative densities: 1 on the lit side, 3
// across the terminator, where a thick particle's light falls steeply and
// order 1 peaks on the grazing rays, 2 into the shadow and 1 on the far side
// (effects/particle_clouds/docs/table_resolution.txt).
CONST float PARTICLE_TERMINATOR_FROM = 1.3962634f;  // 80 degrees
CONST float PARTICLE_TERMINATOR_TO = 1.7453293f;    // 100 degrees
CONST float PARTICLE_SHADOW_TO = 2.4434610f;        // 140 degrees
CONST float PARTICLE_TERMINATOR_DENSITY = 3.0f;
CONST float PARTICLE_SHADOW_DENSITY = 2.0f;

// The number of nodes' worth of density from 0 to the entry angle (radians
// weighted by the spans' densities).
INLINE float particle_entry_weight(float angle) {
    float lit = min(angle, PARTICLE_TERMINATOR_FROM);
    float terminator = clamp(angle, PARTICLE_TERMINATOR_FROM, PARTICLE_TERMINATOR_TO) - PARTICLE_TERMINATOR_FROM;
    float shadow = clamp(angle, PARTICLE_TERMINATOR_TO, PARTICLE_SHADOW_TO) - PARTICLE_TERMINATOR_TO;
    float far_side = max(angle, PARTICLE_SHADOW_TO) - PARTICLE_SHADOW_TO;
    return lit + PARTICLE_TERMINATOR_DENSITY * terminator + PARTICLE_SHADOW_DENSITY * shadow + far_side;
}

// The entry angle (radians from the sun, [0, pi]) as a coordinate in [0, 1]:
// node i of n lies at coordinate i / (n - 1). Uniform in the angle without
// dense_terminator (ParticleTableShape::dense_terminator, for comparisons).
INLINE float particle_entry_coordinate(float angle, bool dense_terminator) {
    if (!dense_terminator) return clamp(angle / PI, 0.0f, 1.0f);
    return particle_entry_weight(angle) / particle_entry_weight(PI);
}

// The inverse: the entry angle at a coordinate in [0, 1].
INLINE float particle_entry_angle(float coordinate, bool dense_terminator) {
    if (!dense_terminator) return clamp(coordinate, 0.0f, 1.0f) * PI;
    float w = clamp(coordinate, 0.0f, 1.0f) * particle_entry_weight(PI);
    float at_from = PARTICLE_TERMINATOR_FROM;
    float at_to = particle_entry_weight(PARTICLE_TERMINATOR_TO);
    float at_shadow = particle_entry_weight(PARTICLE_SHADOW_TO);
    if (w <= at_from) return w;
    if (w <= at_to) return PARTICLE_TERMINATOR_FROM + (w - at_from) / PARTICLE_TERMINATOR_DENSITY;
    if (w <= at_shadow) return PARTICLE_TERMINATOR_TO + (w - at_to) / PARTICLE_SHADOW_DENSITY;
    return PARTICLE_SHADOW_TO + (w - at_shadow);
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
