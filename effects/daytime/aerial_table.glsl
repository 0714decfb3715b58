// The aerial table (issue 24; effects/daytime/docs/aerial_table.md): the
// atmosphere's light along view rays from the camera, tabulated once per frame
// by view direction and distance, so that a pixel interpolates it instead of
// walking the scattering volumes (atmosphere_light, sky.glsl, which builds it).
//
// The atmosphere depends on altitude only, so from one camera the light over
// [0, s] of a ray depends on the ray's elevation, its azimuth from the sun's
// and s. Each species' sunlight and residual beam is tabulated without its
// phase function, which is constant along the ray (the sun is a direction):
// a pixel multiplies by p_i(d . s) itself, so the rainbow and the forward
// lobes stay exact and need no azimuth; only the diffuse part (sky and
// multiple scattering) is tabulated by azimuth too. Cumulative values from the
// camera let any stretch [a, b] be a difference: the sun's shadows in the air
// (effects/light_shafts) are the sun's parts over the shadowed runs,
// subtracted.
//
// Grid: rows of elevation e = sign(x) (pi / 2) x^2, x uniform in [-1, 1]
// (dense at the horizon, which is a row), azimuth blocks uniform in [0, pi]
// from the sun's, distance nodes s_k = AERIAL_NEAR expm1(k w / (N - 2)),
// w = log1p(AERIAL_FAR / AERIAL_NEAR), k < N - 1, and node N - 1 the whole ray.
// Built in two grid passes per table: each segment [s_{k-1}, s_k] on its own,
// then the sums from the camera.


int aerial_rows() { return int(frame.aerial.size.x); }
int aerial_azimuths() { return int(frame.aerial.size.y); }
int aerial_nodes() { return int(frame.aerial.size.z); }

float aerial_expm1(float x) { return x * expm1_over_x(x); }

// Distance of node k < N - 1 from the camera (m).
float aerial_node_distance(int k) {
    float w = log(1.0f + AERIAL_FAR / AERIAL_NEAR);
    return AERIAL_NEAR * aerial_expm1(w * float(k) / float(aerial_nodes() - 2));
}

// The view direction of row `row`, azimuth block `az` (from the sun's).
vec3 aerial_direction(int row, int az) {
    float x = 2.0f * float(row) / float(aerial_rows() - 1) - 1.0f;
    float e = (x < 0.0f ? -0.5f : 0.5f) * PI * x * x;
    float a = aerial_azimuths() > 1 ? PI * float(az) / float(aerial_azimuths() - 1) : 0.0f;
    vec2 h = cos(a) * vec2(frame.aerial.sun_axes.x, frame.aerial.sun_axes.y) +
             sin(a) * vec2(frame.aerial.sun_axes.z, frame.aerial.sun_axes.w);
    return vec3(cos(e) * h.x, sin(e), cos(e) * h.y);
}

// `first` then `second` (which starts where first ends, after `first_length`
// metres): one stretch.
AtmosphereLight aerial_join(AtmosphereLight first, AtmosphereLight second, float first_length) {
    vec3 sigma_medium = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
    vec3 through = exp(-(first.optical_depth + sigma_medium * first_length));
    first.diffuse += through * second.diffuse;
    for (int i = 0; i < SPECIES_COUNT; ++i) {
        first.sun[i] += through * second.sun[i];
        first.residual[i] += through * second.residual[i];
    }
    first.medium_sun += through * second.medium_sun;
    first.optical_depth += second.optical_depth;
    return first;
}

// Segment k of the ray in direction d: [s_{k-1}, s_k] (k = N - 1: to its
// end; k = 0: empty), its light attenuated to its start, phase-free. A ray
// going down is continued past the ground along it (horizontally, at altitude
// 0, with the sky and diffuse light of its own direction), so that a row's values go on beyond its own ground distance: a pixel
// whose ray meets the ground between two rows' then interpolates between
// values at its own distance (nearly its own ray) rather than at theirs.
AtmosphereLight aerial_segment_light(vec3 d, int k) {
    SunPhase ones;
    for (int i = 0; i < SPECIES_COUNT; ++i) ones.species[i] = vec3(1.0f);
    ones.medium = 1.0f;
    float s0 = k > 0 ? aerial_node_distance(k - 1) : 0.0f;
    float s1 = k == aerial_nodes() - 1 ? NO_HIT : (k > 0 ? aerial_node_distance(k) : 0.0f);
    vec3 sigma_medium = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
    vec3 camera = vec3(frame.camera_position);
    float ground = d.y < 0.0f && camera.y > 0.0f ? camera.y / -d.y : NO_HIT;  // distance to the ground
    if (!(s1 > ground))
        return atmosphere_light(camera + s0 * d, d, s1 >= NO_HIT ? NO_HIT : s1 - s0, sigma_medium, false, 1.0f, ones,
                                true, d);
    vec2 h = vec2(d.x, d.z);
    h = length(h) > 0.0f ? normalize(h) : vec2(frame.aerial.sun_axes.x, frame.aerial.sun_axes.y);
    vec3 along = vec3(h.x, 0.0f, h.y);
    vec3 landing = vec3(camera.x + ground * d.x, 0.0f, camera.z + ground * d.z);
    float after_len = s1 >= NO_HIT ? NO_HIT : s1 - max(s0, ground);
    if (s0 >= ground)
        return atmosphere_light(landing + (s0 - ground) * along, along, after_len, sigma_medium, false, 1.0f, ones,
                                true, d);
    AtmosphereLight before = atmosphere_light(camera + s0 * d, d, ground - s0, sigma_medium, false, 1.0f, ones, true, d);
    AtmosphereLight after = atmosphere_light(landing, along, after_len, sigma_medium, false, 1.0f, ones, true, d);
    return aerial_join(before, after, ground - s0);
}

vec3 aerial_part(AtmosphereLight l, int group) {
    if (group == AERIAL_OPTICAL_DEPTH) return l.optical_depth;
    if (group == AERIAL_MEDIUM_SUN) return l.medium_sun;
    if (group < AERIAL_MEDIUM_SUN) return l.sun[group - AERIAL_SUN];
    return l.residual[group - AERIAL_RESIDUAL];
}

// Grid pass: texel (g N + k, row) holds part g of segment k.
vec4 aerial_segments_pass(int x, int y) {
    int group = x / aerial_nodes();
    return vec4(aerial_part(aerial_segment_light(aerial_direction(y, 0), x - group * aerial_nodes()), group), 0.0f);
}

// Grid pass: texel (k, az R + row) holds the diffuse part of segment k.
vec4 aerial_diffuse_segments_pass(int x, int y) {
    int az = y / aerial_rows();
    return vec4(aerial_segment_light(aerial_direction(y - az * aerial_rows(), az), x).diffuse, 0.0f);
}

// The sum over segments 1..k of column group `group` of `table` (row y; its
// elevation row `row`), each attenuated from the camera to its start
// (`attenuated` false: summed as they are, the optical depth).
vec3 aerial_prefix(int table, int group, int k, int y, int row, bool attenuated) {
    vec3 sigma_medium = HAS_MEDIUM ? vec3(frame.sigma_t) : vec3(0.0f);
    vec3 tau = vec3(0.0f);
    vec3 sum = vec3(0.0f);
    for (int j = 1; j <= k; ++j) {
        vec3 segment_tau = vec3(table_texel4(TABLE_AERIAL_SEGMENTS, j, row));
        if (!attenuated) {
            sum += segment_tau;
        } else {
            vec3 before = exp(-(tau + sigma_medium * aerial_node_distance(j - 1)));
            sum += before * vec3(table_texel4(table, group * aerial_nodes() + j, y));
        }
        tau += segment_tau;
    }
    return sum;
}

// Grid pass: texel (g N + k, row): part g over [0, s_k] from the camera.
vec4 aerial_pass(int x, int y) {
    int group = x / aerial_nodes();
    return vec4(aerial_prefix(TABLE_AERIAL_SEGMENTS, group, x - group * aerial_nodes(), y, y,
                              group != AERIAL_OPTICAL_DEPTH),
                0.0f);
}

// Grid pass: texel (k, az R + row): the diffuse part over [0, s_k].
vec4 aerial_diffuse_pass(int x, int y) {
    int az = y / aerial_rows();
    return vec4(aerial_prefix(TABLE_AERIAL_DIFFUSE_SEGMENTS, 0, x, y, y - az * aerial_rows(), true), 0.0f);
}

// One row's values at distance s between nodes k and k + 1 (fraction a_s in
// distance): the optical depth linear in distance, each part weighted by the
// attenuation, (1 - e^{-(tau(s) - tau_k)}) / (1 - e^{-(tau_{k+1} - tau_k)})
// per channel (exact for a source constant over the cell), medium included.
vec3 aerial_weight(int row, int k, float a_s, vec3 medium_k, vec3 medium_k1, OUT(vec3) tau) {
    vec3 tau_k = vec3(table_texel4(TABLE_AERIAL, k, row));
    vec3 tau_k1 = vec3(table_texel4(TABLE_AERIAL, k + 1, row));
    tau = mix(tau_k, tau_k1, a_s);
    vec3 cell = tau_k1 - tau_k + medium_k1 - medium_k;
    vec3 part = (tau - tau_k) + a_s * (medium_k1 - medium_k);
    vec3 w;
    w.x = cell.x > 1.0e-4f ? aerial_expm1(-part.x) / aerial_expm1(-cell.x) : a_s;
    w.y = cell.y > 1.0e-4f ? aerial_expm1(-part.y) / aerial_expm1(-cell.y) : a_s;
    w.z = cell.z > 1.0e-4f ? aerial_expm1(-part.z) / aerial_expm1(-cell.z) : a_s;
    return w;
}

vec3 aerial_value(int table, int column, int row, vec3 w, bool at_end) {
    vec3 v0 = vec3(table_texel4(table, column, row));
    if (at_end) return v0;
    return v0 + w * (vec3(table_texel4(table, column + 1, row)) - v0);
}

// The table's light over [0, s] of the camera's ray in direction d (s >=
// NO_HIT: to its end), phase-free (AtmosphereLight's parts).
AtmosphereLight aerial_light(vec3 d, float s) {
    int rows = aerial_rows();
    int n = aerial_nodes();
    // Elevation row and weight.
    float e = asin(clamp(d.y, -1.0f, 1.0f));
    float x = sqrt(abs(e) / (0.5f * PI));
    float fr = (0.5f + (e < 0.0f ? -0.5f : 0.5f) * x) * float(rows - 1);
    int r0 = clamp(int(fr), 0, rows - 2);
    float ar = clamp(fr - float(r0), 0.0f, 1.0f);
    // Azimuth block from the sun's.
    int az0 = 0;
    float aa = 0.0f;
    int n_az = aerial_azimuths();
    if (n_az > 1) {
        vec2 h = vec2(d.x, d.z);
        float u = dot(h, vec2(frame.aerial.sun_axes.x, frame.aerial.sun_axes.y));
        float v = abs(dot(h, vec2(frame.aerial.sun_axes.z, frame.aerial.sun_axes.w)));
        float a = (u == 0.0f && v == 0.0f) ? 0.0f : atan(v, u);
        float fa = clamp(a / PI, 0.0f, 1.0f) * float(n_az - 1);
        az0 = min(int(fa), n_az - 2);
        aa = fa - float(az0);
    }
    // Distance cell.
    bool at_end = s >= NO_HIT;
    int k = n - 1;
    float a_s = 0.0f;
    vec3 medium_k = vec3(0.0f);
    vec3 medium_k1 = vec3(0.0f);
    if (!at_end) {
        float w = log(1.0f + AERIAL_FAR / AERIAL_NEAR);
        float fk = clamp(log(1.0f + max(s, 0.0f) / AERIAL_NEAR) / w, 0.0f, 1.0f) * float(n - 2);
        k = min(int(fk), n - 3);
        float s_k = aerial_node_distance(k);
        float s_k1 = aerial_node_distance(k + 1);
        a_s = clamp((s - s_k) / (s_k1 - s_k), 0.0f, 1.0f);
        if (HAS_MEDIUM) {
            medium_k = vec3(frame.sigma_t) * s_k;
            medium_k1 = vec3(frame.sigma_t) * s_k1;
        }
    }
    AtmosphereLight light = no_atmosphere_light();
    bool residual = HAS_MULTIPLE_SCATTERING && HAS_SUN && frame.multiple_scattering.air_scattering != 0.0f;
    for (int corner = 0; corner < 2; ++corner) {
        int row = r0 + corner;
        float row_weight = corner == 0 ? 1.0f - ar : ar;
        vec3 tau = vec3(table_texel4(TABLE_AERIAL, k, row));
        vec3 w = vec3(0.0f);
        if (!at_end) w = aerial_weight(row, k, a_s, medium_k, medium_k1, tau);
        light.optical_depth += row_weight * tau;
        for (int i = 0; i < SPECIES_COUNT; ++i) {
            if (!species_present(i)) continue;
            if (HAS_SUN) light.sun[i] += row_weight * aerial_value(TABLE_AERIAL, (AERIAL_SUN + i) * n + k, row, w, at_end);
            if (residual)
                light.residual[i] +=
                    row_weight * aerial_value(TABLE_AERIAL, (AERIAL_RESIDUAL + i) * n + k, row, w, at_end);
        }
        if (HAS_MEDIUM_SUN)
            light.medium_sun += row_weight * aerial_value(TABLE_AERIAL, AERIAL_MEDIUM_SUN * n + k, row, w, at_end);
        vec3 diffuse = aerial_value(TABLE_AERIAL_DIFFUSE, k, az0 * rows + row, w, at_end);
        if (n_az > 1)
            diffuse = mix(diffuse, aerial_value(TABLE_AERIAL_DIFFUSE, k, (az0 + 1) * rows + row, w, at_end), aa);
        light.diffuse += row_weight * diffuse;
    }
    return light;
}

// The sun's parts of the camera's ray in direction d between distances s0 <
// s1, times the phases (the light a shadowed run takes away).
vec3 aerial_sun_between(vec3 d, float s0, float s1, SunPhase phase, OUT(vec3) medium_sun, OUT(vec3) rainbow) {
    AtmosphereLight l0 = aerial_light(d, s0);
    AtmosphereLight l1 = aerial_light(d, s1);
    vec3 sun = vec3(0.0f);
    rainbow = vec3(0.0f);
    for (int i = 0; i < SPECIES_COUNT; ++i) {
        vec3 part = phase.species[i] * (l1.sun[i] - l0.sun[i]);
        if (rainbow_layer_apart(i)) {
            rainbow += part;
        } else {
            sun += part;
        }
    }
    medium_sun = phase.medium * (l1.medium_sun - l0.medium_sun);
    return sun;
}

// The atmosphere's optical depth over [0, s] of the camera's ray in direction
// d (s >= NO_HIT: to its end), exact: the difference of the vertical columns
// at its ends over |mu| (mu = 0: the density at the camera times s). Not
// interpolated: near the horizon the transmittance changes as e^{-C / mu}.
vec3 aerial_optical_depth(vec3 d, float s) {
    float top = frame.atmosphere.top;
    float y0 = clamp(frame.camera_position.y, 0.0f, top);
    if (d.y == 0.0f) {
        vec3 sigma = vec3(0.0f);
        for (int i = 0; i < SPECIES_COUNT; ++i) {
            SpeciesGpu sp = frame.species[i];
            if (species_present(i)) sigma += vec3(sp.sigma_t) * piece_density(sp, profile_piece(sp, y0), y0);
        }
        return sigma * min(s, 1.0e30f);
    }
    float y1 = s >= NO_HIT ? (d.y > 0.0f ? top : 0.0f) : clamp(frame.camera_position.y + d.y * s, 0.0f, top);
    return abs(atmosphere_column(y0) - atmosphere_column(y1)) / abs(d.y);
}

// atmosphere_scattering's sums over [a, b] of the camera's ray in direction d
// from the table (b >= NO_HIT: to its end): the light attenuated to a by the
// medium only, as atmosphere_scattering returns it; `shadowed`: the sun's
// shadowed runs (shadow_runs, relative to a) taken away. False where the
// table cannot stand for the walk: the atmosphere before a too thick to
// divide its attenuation out (the caller walks the volumes instead).
bool aerial_scattering(vec3 d, float a, float b, float sun_scale, bool shadowed, OUT(vec3) inscatter,
                       OUT(vec3) rainbow, OUT(vec3) medium_sun, OUT(vec3) transmittance) {
    inscatter = vec3(0.0f);
    rainbow = vec3(0.0f);
    medium_sun = vec3(0.0f);
    transmittance = vec3(1.0f);
    // A ray going down ends on the ground (the table goes on past it).
    if (d.y < 0.0f && frame.camera_position.y > 0.0f) b = min(b, frame.camera_position.y / -d.y);
    if (!(b > a)) return false;
    AtmosphereLight l1 = aerial_light(d, b);
    l1.optical_depth = aerial_optical_depth(d, b);
    vec3 undo = vec3(1.0f);  // 1 / the attenuation over [0, a]
    if (a > 0.0f) {
        AtmosphereLight l0 = aerial_light(d, a);
        l0.optical_depth = aerial_optical_depth(d, a);
        vec3 before = l0.optical_depth + (HAS_MEDIUM ? vec3(frame.sigma_t) * a : vec3(0.0f));
        if (max(before.x, max(before.y, before.z)) > 20.0f) return false;
        undo = exp(before);
        l1.diffuse -= l0.diffuse;
        for (int i = 0; i < SPECIES_COUNT; ++i) {
            l1.sun[i] -= l0.sun[i];
            l1.residual[i] -= l0.residual[i];
        }
        l1.medium_sun -= l0.medium_sun;
        l1.optical_depth -= l0.optical_depth;
    }
    SunPhase phase = no_sun_phase();
    if (HAS_SUN) phase = sun_phase_along(d);
    inscatter = l1.diffuse;
    for (int i = 0; i < SPECIES_COUNT; ++i) {
        inscatter += phase.species[i] * l1.residual[i];
        vec3 sun = sun_scale * phase.species[i] * l1.sun[i];
        if (rainbow_layer_apart(i)) {
            rainbow += sun;
        } else {
            inscatter += sun;
        }
    }
    medium_sun = sun_scale * phase.medium * l1.medium_sun;
    if (HAS_SUN && shadowed) {
        for (int r = 0; r < shadow_runs.count; ++r) {
            vec2 run = shadow_runs.run[r];
            float s0 = a + run.x;
            float s1 = b >= NO_HIT ? a + run.y : min(a + run.y, b);
            if (!(s1 > s0)) continue;
            vec3 run_medium;
            vec3 run_rainbow;
            inscatter -= sun_scale * aerial_sun_between(d, s0, s1, phase, run_medium, run_rainbow);
            rainbow -= sun_scale * run_rainbow;
            medium_sun -= sun_scale * run_medium;
        }
        inscatter = max(inscatter, vec3(0.0f));
        rainbow = max(rainbow, vec3(0.0f));
        medium_sun = max(medium_sun, vec3(0.0f));
    }
    inscatter *= undo;
    rainbow *= undo;
    medium_sun *= undo;
    transmittance = exp(-max(l1.optical_depth, vec3(0.0f)));
    return true;
}
