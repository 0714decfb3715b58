// The sun's shadow map (effects/sun_shadow_map/physics.md): a grid of depths
// seen along the sunlight over the box of the surfaces that can cast shadows,
// filled by a grid pass before the shading pass, and the sun's visibility from
// a surface point looked up in it (percentage-closer filtering of the 2 x 2
// nearest texels) instead of tracing a shadow ray. Where the map does not
// cover a point, or without HAS_SUN_SHADOW_MAP, the shadow ray is traced.

// The depth bias, in texels: per unit of the surface's slope to the sun (the
// 2 x 2 filter reaches a texel away), plus a constant; slopes are capped.
CONST float SUN_SHADOW_MAP_SLOPE_BIAS = 1.5f;
CONST float SUN_SHADOW_MAP_CONSTANT_BIAS = 0.5f;
CONST float SUN_SHADOW_MAP_MAX_SLOPE = 10.0f;

// Grid pass: texel (i, j) holds the distance, along -sun from the map's top
// plane, to the first surface (NO_HIT for an empty column).
vec4 sun_shadow_map_pass(int i, int j) {
    SunShadowMapGpu m = frame.sun_shadow_map;
    float texel = m.origin.w;
    vec3 p = vec3(m.origin) + ((float(i) + 0.5f) * texel) * vec3(m.axis_u) + ((float(j) + 0.5f) * texel) * vec3(m.axis_v);
    int hit = -1;
    vec3 n;
    float t = trace_surfaces(p, -vec3(frame.sky.sun_direction), hit, n);
    return vec4(t, 0.0f, 0.0f, 1.0f);
}

// Fraction of the 2 x 2 nearest texels (bilinear weights) from which surface
// point p (normal n, facing the sun) sees it; -1 where the map does not cover p.
// A texel sees p when p is no deeper than the texel's first surface plus a bias
// of the depth change across the filter (slope: tan of the sun's angle to n)
// and the float32 rounding of the depths.
float sun_shadow_map_visibility(vec3 p, vec3 n) {
    SunShadowMapGpu m = frame.sun_shadow_map;
    vec3 s = vec3(frame.sky.sun_direction);
    float texel = m.origin.w;
    vec3 rel = p - vec3(m.origin);
    float fu = dot(rel, vec3(m.axis_u)) / texel - 0.5f;
    float fv = dot(rel, vec3(m.axis_v)) / texel - 0.5f;
    int nu = int(m.axis_u.w);
    int nv = int(m.axis_v.w);
    if (!(fu >= 0.0f && fv >= 0.0f && fu <= float(nu - 1) && fv <= float(nv - 1))) return -1.0f;
    float depth = -dot(rel, s);
    float c = max(dot(n, s), 1.0e-3f);
    float tan_angle = min(sqrt(max(1.0f - c * c, 0.0f)) / c, SUN_SHADOW_MAP_MAX_SLOPE);
    float bias = texel * (SUN_SHADOW_MAP_SLOPE_BIAS * tan_angle + SUN_SHADOW_MAP_CONSTANT_BIAS) + m.depth.y;
    int iu = min(int(fu), nu - 2);
    int iv = min(int(fv), nv - 2);
    float au = fu - float(iu);
    float av = fv - float(iv);
    float l00 = depth <= table_texel(TABLE_SUN_SHADOW_MAP, iu, iv) + bias ? 1.0f : 0.0f;
    float l10 = depth <= table_texel(TABLE_SUN_SHADOW_MAP, iu + 1, iv) + bias ? 1.0f : 0.0f;
    float l01 = depth <= table_texel(TABLE_SUN_SHADOW_MAP, iu, iv + 1) + bias ? 1.0f : 0.0f;
    float l11 = depth <= table_texel(TABLE_SUN_SHADOW_MAP, iu + 1, iv + 1) + bias ? 1.0f : 0.0f;
    return mix(mix(l00, l10, au), mix(l01, l11, au), av);
}

// The sun's visibility from surface point p (normal n, facing the sun): 1 lit,
// 0 in shadow, between at the map's filtered shadow edges. p lies on surface `self`.
float sun_visibility(vec3 p, vec3 n, int self) {
    if (!HAS_SURFACES) return 1.0f;
    if (HAS_SUN_SHADOW_MAP) {
        float v = sun_shadow_map_visibility(p, n);
        if (v >= 0.0f) return v;
    }
    return segment_occluded(p + surface_offset(p) * n, vec3(frame.sky.sun_direction), NO_HIT, self) ? 0.0f : 1.0f;
}
