// The daytime atmosphere's multiply scattered light (effects/multiple_scattering/physics.md
// section 9), read from the table TABLE_MS_FIELD (ms_layout.glsl) that the
// plane-parallel solution fills: per species the phased diffuse radiance
// K_i(y, d), the diffuse irradiance E(y, n) on surfaces and the sun's residual
// forward beam E_res(y). Linear in altitude between the solver's levels,
// bilinear in direction. Compiled before the daytime effect's sky.glsl, which
// adds sigma_s,i rho_i (K_i + E_res p_i(d . s)) to its source function.

// Where altitude y sits among the solver's levels: level k and the weight of k + 1.
struct MsLevel {
    int k;
    float a;
};

float ms_level_altitude(int k) {
    return frame.multiple_scattering.levels[k >> 2][k & 3];
}

MsLevel ms_level(float y) {
    int n = int(frame.multiple_scattering.level_count);
    MsLevel l;
    // Binary search for the last level <= y (levels[0] = 0).
    int lo = 0;
    int hi = n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (ms_level_altitude(mid) <= y) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    float y0 = ms_level_altitude(lo);
    float y1 = ms_level_altitude(hi);
    l.k = lo;
    l.a = hi > lo && y1 > y0 ? clamp((y - y0) / (y1 - y0), 0.0f, 1.0f) : 0.0f;
    return l;
}

// rgb of row `row` at altitude l (linear between the two levels).
vec3 ms_row(int row, MsLevel l) {
    int k1 = min(l.k + 1, int(frame.multiple_scattering.level_count) - 1);
    return mix(vec3(table_texel4(TABLE_MS_FIELD, l.k, row)), vec3(table_texel4(TABLE_MS_FIELD, k1, row)), l.a);
}

// A direction's cell in a block of `elevations` rows per azimuth block
// (`azimuths` blocks over [0, pi] from the sun's azimuth).
struct MsDirection {
    int row0;  // (elevation cell, azimuth cell)
    int row1;  // the same one azimuth block further
    float ae;  // weight of the next elevation row
    float aa;  // weight of the next azimuth block
};

MsDirection ms_direction(vec3 d, int elevations, int azimuths) {
    vec2 angles = sky_table_angles(d, vec3(frame.sky.sun_direction));
    float fe = clamp(angles.x / PI + 0.5f, 0.0f, 1.0f) * float(elevations - 1);
    int ie = min(int(fe), elevations - 2);
    float fa = azimuths > 1 ? clamp(angles.y / PI, 0.0f, 1.0f) * float(azimuths - 1) : 0.0f;
    int ia = azimuths > 1 ? min(int(fa), azimuths - 2) : 0;
    MsDirection t;
    t.row0 = ia * elevations + ie;
    t.row1 = azimuths > 1 ? t.row0 + elevations : t.row0;
    t.ae = fe - float(ie);
    t.aa = fa - float(ia);
    return t;
}

// The look direction d's cell among K's rows.
MsDirection ms_view_direction(vec3 d) {
    return ms_direction(d, MS_VIEW_ELEVATIONS, int(frame.multiple_scattering.view_azimuths));
}

vec3 ms_block_value(int base, MsDirection t, MsLevel l) {
    vec3 e0 = mix(ms_row(base + t.row0, l), ms_row(base + t.row0 + 1, l), t.ae);
    vec3 e1 = mix(ms_row(base + t.row1, l), ms_row(base + t.row1 + 1, l), t.ae);
    return mix(e0, e1, t.aa);
}

// K_i(y, d) = int p_i(d . w) L_diffuse(y, w) dw (p normalised to 1; the
// residual beam excluded): radiance, per channel.
vec3 ms_phased_radiance(int species, MsDirection t, MsLevel l) {
    int block = species * MS_VIEW_ELEVATIONS * int(frame.multiple_scattering.view_azimuths);
    return max(ms_block_value(block, t, l), vec3(0.0f));
}

// E_res(y): the sun's residual forward beam, irradiance on a plane facing the sun.
vec3 ms_sun_residual(MsLevel l) {
    return max(ms_row(int(frame.multiple_scattering.residual_row), l), vec3(0.0f));
}

// E(y, n): the diffuse irradiance (the residual beam excluded) on a surface of unit normal n at altitude y.
vec3 ms_diffuse_irradiance(float y, vec3 n) {
    MsDirection t = ms_direction(n, MS_NORMAL_ELEVATIONS, int(frame.multiple_scattering.normal_azimuths));
    return max(ms_block_value(int(frame.multiple_scattering.irradiance_row), t, ms_level(max(y, 0.0f))), vec3(0.0f));
}
