// Daytime light (issue 6; effects/daytime/physics.md; effects/daytime/docs/daytime.md): the sky
// dome seen by escaping rays, the skylight and sunlight on surfaces, and the
// light the atmosphere's particles scatter into view rays, integrated over
// scattering volumes between altitude levels. Feature switches: HAS_SKY,
// HAS_SUN, HAS_ATMOSPHERE, SKY_MARCH (brute-force marching, benchmarks).
// Requires table_texel4(TABLE_SKY_PHASE, x, y) and the pure formulas of sky_math.glsl.

float altitude_level(int k) {
    return frame.atmosphere.levels[k >> 2][k & 3];
}

int altitude_level_count() {
    return int(frame.atmosphere.level_count);
}

bool species_present(int i) {
    return frame.species[i].phase.z != 0.0f;
}

// Radiance of the sky dome in direction d (before attenuation).
vec3 sky_radiance(vec3 d) {
    return vec3(frame.sky.zenith_radiance) * sky_shape(frame.sky, d);
}

// ---- Density profiles ---------------------------------------------------------
// The piece of a species' profile that holds altitude y (y >= 0).
int profile_piece(SpeciesGpu sp, float y) {
    return y < sp.starts.y ? 0 : (y < sp.starts.z ? 1 : (y < sp.starts.w ? 2 : 3));
}

// rho(y) evaluated with piece k's formula (the limit from inside piece k at
// its ends).
float piece_density(SpeciesGpu sp, int k, float y) {
    return sp.values[k] * exp(-(y - sp.starts[k]) * sp.inv_scales[k]);
}

// int_y^inf rho: the species' vertical column above y (the profile's closed
// form piece by piece; the last non-empty piece decays, effects/daytime/sky.cpp).
float species_column(SpeciesGpu sp, float y) {
    float total = 0.0f;
    for (int k = profile_piece(sp, y); k < 4; ++k) {
        if (sp.values[k] == 0.0f) continue;
        float a = max(y, sp.starts[k]);
        float start_density = piece_density(sp, k, a);
        float end = k < 3 ? sp.starts[k + 1] : NO_HIT;
        if (end >= NO_HIT) {
            total += start_density / sp.inv_scales[k];
        } else {
            float len = end - a;
            total += start_density * len * expm1_over_x(-len * sp.inv_scales[k]);
        }
    }
    return total;
}

// C(y): the per-channel vertical optical depth of the atmosphere above y
// (y below the ground counts as the ground).
vec3 atmosphere_column(float y) {
    float h = max(y, 0.0f);
    vec3 c = vec3(0.0f);
    for (int i = 0; i < 3; ++i) {
        if (species_present(i)) c += vec3(frame.species[i].sigma_t) * species_column(frame.species[i], h);
    }
    return c;
}

// ---- The sky-phase table -------------------------------------------------------
// Where a view direction sits in the table: the elevation row and azimuth
// block cells and the weights inside them.
struct SkyTableDirection {
    int row0;   // row of (elevation cell, azimuth cell)
    int row1;   // the same one azimuth block further
    float ae;   // weight of the next elevation row
    float aa;   // weight of the next azimuth block
};

SkyTableDirection sky_table_direction(vec3 d) {
    vec2 angles = sky_table_angles(d, vec3(frame.sky.sun_direction));
    int n_az = int(frame.atmosphere.sky_table_azimuth_blocks);
    float fe = clamp(angles.x / PI + 0.5f, 0.0f, 1.0f) * float(SKY_TABLE_N_ELEVATION - 1);
    int ie = min(int(fe), SKY_TABLE_N_ELEVATION - 2);
    float fa = n_az > 1 ? clamp(angles.y / PI, 0.0f, 1.0f) * float(n_az - 1) : 0.0f;
    int ia = n_az > 1 ? min(int(fa), n_az - 2) : 0;
    SkyTableDirection t;
    t.row0 = ia * SKY_TABLE_N_ELEVATION + ie;
    t.row1 = n_az > 1 ? t.row0 + SKY_TABLE_N_ELEVATION : t.row0;
    t.ae = fe - float(ie);
    t.aa = fa - float(ia);
    return t;
}

// The table's four kernels F_k(C, d) (constants.glsl) in units of Lz at
// column C for the direction cell t, by manual trilinear interpolation of
// log(F e^C + floor) (exact float arithmetic, the same on GPU and CPU).
vec4 sky_table_kernels(SkyTableDirection t, float column) {
    int nc = int(frame.atmosphere.sky_table_columns);
    int ix = 0;
    float ax = 0.0f;
    if (nc > 1) {
        float fx = sky_table_x(column) * float(nc - 1);
        ix = min(int(fx), nc - 2);
        ax = fx - float(ix);
    }
    int ix1 = nc > 1 ? ix + 1 : ix;
    vec4 e0 = mix(mix(table_texel4(TABLE_SKY_PHASE, ix, t.row0), table_texel4(TABLE_SKY_PHASE, ix1, t.row0), ax),
                  mix(table_texel4(TABLE_SKY_PHASE, ix, t.row0 + 1), table_texel4(TABLE_SKY_PHASE, ix1, t.row0 + 1), ax), t.ae);
    vec4 e1 = mix(mix(table_texel4(TABLE_SKY_PHASE, ix, t.row1), table_texel4(TABLE_SKY_PHASE, ix1, t.row1), ax),
                  mix(table_texel4(TABLE_SKY_PHASE, ix, t.row1 + 1), table_texel4(TABLE_SKY_PHASE, ix1, t.row1 + 1), ax), t.ae);
    vec4 g = mix(e0, e1, t.aa);
    float c = nc > 1 ? min(column, SKY_TABLE_C_MAX) : 0.0f;
    return max(exp(g - vec4(c)) - vec4(SKY_TABLE_FLOOR * exp(-c)), vec4(0.0f));
}

// ---- Light on surfaces ----------------------------------------------------------
// Irradiance from the attenuated sky dome on a surface at p with normal n:
// Lz int L/Lz exp(-C(p_y) / w_y) max(n . w, 0) dw (the table's A kernel; the
// sky is not occluded by other surfaces: effects/daytime/docs/daytime.md).
vec3 sky_irradiance(vec3 p, vec3 n) {
    SkyTableDirection t = sky_table_direction(n);
    vec3 c = HAS_ATMOSPHERE ? atmosphere_column(p.y) : vec3(0.0f);
    vec3 lz = vec3(frame.sky.zenith_radiance);
    return vec3(lz.x * sky_table_kernels(t, c.x).w, lz.y * sky_table_kernels(t, c.y).w,
                lz.z * sky_table_kernels(t, c.z).w);
}

// Irradiance from the sun on a surface at p with normal n, before shadows:
// E_sun exp(-C(p_y) / s_y) max(n . s, 0).
vec3 sun_irradiance(vec3 p, vec3 n) {
    vec3 s = vec3(frame.sky.sun_direction);
    float cos_n = dot(n, s);
    if (cos_n <= 0.0f) return vec3(0.0f);
    vec3 c = HAS_ATMOSPHERE ? atmosphere_column(p.y) : vec3(0.0f);
    return vec3(frame.sky.sun_irradiance) * exp(-c / s.y) * cos_n;
}

// ---- Light scattered into view rays ---------------------------------------------
// The light each species scatters toward the camera per unit scattering
// coefficient at an altitude whose column is C (effects/daytime/physics.md, with
// the exact sky-phase integral in place of the seed's effective phase
// value): Lz F_i(C, d) (sky) + E_sun exp(-C / s_y) p_i(d . s) (sun), per
// channel; kept apart because they change with C at different rates.
// With multiple scattering (HAS_MULTIPLE_SCATTERING), the light scattered at
// least once before: the diffuse field K_i(y, d) (ms) and the residual beam
// E_res(y) p_i(d . s), which travels along the sun (residual)
// (effects/multiple_scattering/ms_field.glsl).
// medium_sun: the sun's light on the homogeneous medium through its phase
// function (with HAS_MEDIUM_SUN; effects/light_shafts/physics.md section 3).
struct SpeciesLight {
    vec3 sky[3];
    vec3 sun[3];
    vec3 ms[3];
    vec3 residual[3];
    vec3 medium_sun;
};

// Each species' phase function for the sun's light along a view ray, per
// channel (only the rain's depends on wavelength: its rainbow).
// `medium`: the homogeneous medium's (HAS_MEDIUM_SUN).
struct SunPhase {
    vec3 species[SPECIES_COUNT];
    float medium;
};

SunPhase sun_phase_along(vec3 d) {
    SunPhase p;
    float cos_sun = dot(d, vec3(frame.sky.sun_direction));
    for (int i = 0; i < 3; ++i) p.species[i] = vec3(species_phase(frame.species[i].phase, cos_sun));
    if (HAS_RAINBOW) p.species[SPECIES_RAIN] = rainbow_phase(cos_sun);
    p.medium = HAS_MEDIUM_SUN ? medium_phase_between(vec3(frame.sky.sun_direction), d) / (4.0f * PI) : 0.0f;
    return p;
}

SunPhase no_sun_phase() {
    SunPhase p;
    for (int i = 0; i < 3; ++i) p.species[i] = vec3(0.0f);
    p.medium = 0.0f;
    return p;
}

SpeciesLight species_light(SkyTableDirection t, MsDirection ms_dir, float y, vec3 column, SunPhase sun_phase) {
    SpeciesLight out_light;
    vec4 k0 = vec4(0.0f);
    vec4 k1 = vec4(0.0f);
    vec4 k2 = vec4(0.0f);
    if (HAS_SKY) {
        k0 = sky_table_kernels(t, column.x);
        k1 = sky_table_kernels(t, column.y);
        k2 = sky_table_kernels(t, column.z);
    }
    vec3 lz = vec3(frame.sky.zenith_radiance);
    vec3 sun = vec3(0.0f);
    if (HAS_SUN) sun = vec3(frame.sky.sun_irradiance) * exp(-column / frame.sky.sun_direction.y);
    out_light.sky[0] = lz * vec3(k0.x, k1.x, k2.x);
    out_light.sky[1] = lz * vec3(k0.y, k1.y, k2.y);
    out_light.sky[2] = lz * vec3(k0.z, k1.z, k2.z);
    out_light.sun[0] = sun * sun_phase.species[SPECIES_MOLECULES];
    out_light.sun[1] = sun * sun_phase.species[SPECIES_AEROSOL];
    out_light.sun[2] = sun * sun_phase.species[SPECIES_RAIN];
    out_light.medium_sun = sun * sun_phase.medium;
    for (int i = 0; i < 3; ++i) {
        out_light.ms[i] = vec3(0.0f);
        out_light.residual[i] = vec3(0.0f);
    }
    if (HAS_MULTIPLE_SCATTERING && frame.multiple_scattering.air_scattering != 0.0f) {
        MsLevel level = ms_level(y);
        vec3 residual = HAS_SUN ? ms_sun_residual(level) : vec3(0.0f);
        for (int i = 0; i < 3; ++i) {
            if (!species_present(i)) continue;
            out_light.ms[i] = ms_phased_radiance(i, ms_dir, level);
            out_light.residual[i] = residual * sun_phase.species[i];
        }
    }
    return out_light;
}

// True when the rain's once-scattered sunlight goes to the render outputs'
// rainbow layer (shaders/outputs.glsl) instead of being summed with the rest.
bool rainbow_layer_apart(int species) { return RENDER_OUTPUTS && HAS_RAINBOW && species == SPECIES_RAIN; }

// Extinction (rgb) and in-scattering J (rgb, per unit length) at altitude y,
// with each species' profile piece chosen at altitude y_piece (so that the
// ends of a scattering volume use the volume's own pieces); j_rainbow: the
// rain's sunlight, when kept apart (rainbow_layer_apart), else 0.
void atmosphere_point(float y, float y_piece, SpeciesLight light, OUT(vec3) sigma_t, OUT(vec3) j,
                      OUT(vec3) j_rainbow) {
    sigma_t = vec3(0.0f);
    j = vec3(0.0f);
    j_rainbow = vec3(0.0f);
    for (int i = 0; i < 3; ++i) {
        if (!species_present(i)) continue;
        SpeciesGpu sp = frame.species[i];
        float rho = piece_density(sp, profile_piece(sp, y_piece), y);
        sigma_t += vec3(sp.sigma_t) * rho;
        if (rainbow_layer_apart(i)) {
            j += vec3(sp.sigma_s) * rho * (light.sky[i] + light.ms[i] + light.residual[i]);
            j_rainbow = vec3(sp.sigma_s) * rho * light.sun[i];
        } else {
            j += vec3(sp.sigma_s) * rho * (light.sky[i] + light.sun[i] + light.ms[i] + light.residual[i]);
        }
    }
}

// The part [s_in, s_out] of the ray o + s d (s_out <= s_end) inside the
// atmosphere's slab 0 <= y <= top; false when the ray misses it.
bool atmosphere_interval(vec3 o, vec3 d, float s_end, OUT(float) s_in, OUT(float) s_out) {
    float top = frame.atmosphere.top;
    if (d.y > 0.0f) {
        s_in = max(0.0f, -o.y / d.y);
        s_out = (top - o.y) / d.y;
    } else if (d.y < 0.0f) {
        s_in = max(0.0f, (top - o.y) / d.y);
        s_out = o.y / -d.y;
    } else {
        s_in = 0.0f;
        s_out = o.y >= 0.0f && o.y < top ? NO_HIT : 0.0f;
    }
    s_out = min(s_out, s_end);
    return s_out > s_in;
}

// Optical depth (rgb) of the atmosphere over a stretch of the ray of length
// len (< NO_HIT: capped) starting at altitude y_a with direction cosine mu,
// the stretch lying inside one profile piece of every species (chosen at
// y_piece): sigma_t rho(y_a) len expm1(-mu len / H) / (-mu len / H), exact.
// (rho(y_a) e^x = rho(y_b): the same from the denser end.)
vec3 stretch_optical_depth(float y_a, float y_piece, float mu, float len) {
    float l = min(len, 1.0e30f);
    vec3 tau = vec3(0.0f);
    for (int i = 0; i < 3; ++i) {
        if (!species_present(i)) continue;
        SpeciesGpu sp = frame.species[i];
        int k = profile_piece(sp, y_piece);
        // Integrated from the denser end, so the factor expm1(x) / x has x <= 0
        // and cannot overflow (a descent through many scale heights).
        float x = -mu * l * sp.inv_scales[k];
        float y_dense = x > 0.0f ? y_a + mu * l : y_a;
        tau += vec3(sp.sigma_t) * (piece_density(sp, k, y_dense) * l * expm1_over_x(-abs(x)));
    }
    return tau;
}

// The first altitude level the ray meets after altitude y going up (mu > 0)
// or down (mu < 0), as an index; -1 when there is none.
int next_altitude_level(float y, float mu) {
    int n = altitude_level_count();
    if (mu > 0.0f) {
        for (int k = 0; k < n; ++k) {
            if (altitude_level(k) > y) return k;
        }
    } else if (mu < 0.0f) {
        for (int k = n - 1; k >= 0; --k) {
            if (altitude_level(k) < y) return k;
        }
    }
    return -1;
}

// How many equal parts in altitude the volume [y_a, y_b] needs so that the
// density ratio of any two species that matter there (a share of the
// extinction above 1e-3 at an end) changes by at most e^{0.5} in each:
// |y_b - y_a| (max 1/H - min 1/H) / 0.5 over those species, at most
// VOLUME_MAX_PARTS.
int volume_parts(float y_a, float y_b) {
    float y_piece = 0.5f * (y_a + y_b);
    vec3 at_a = vec3(0.0f);
    vec3 at_b = vec3(0.0f);
    vec3 inv_scale = vec3(0.0f);
    for (int i = 0; i < 3; ++i) {
        if (!species_present(i)) continue;
        SpeciesGpu sp = frame.species[i];
        int k = profile_piece(sp, y_piece);
        at_a[i] = sp.sigma_t.y * piece_density(sp, k, y_a);
        at_b[i] = sp.sigma_t.y * piece_density(sp, k, y_b);
        inv_scale[i] = sp.inv_scales[k];
    }
    float sum_a = at_a.x + at_a.y + at_a.z;
    float sum_b = at_b.x + at_b.y + at_b.z;
    float lo = 1.0e30f;
    float hi = -1.0e30f;
    for (int i = 0; i < 3; ++i) {
        if (at_a[i] > 1.0e-3f * sum_a || at_b[i] > 1.0e-3f * sum_b) {
            lo = min(lo, inv_scale[i]);
            hi = max(hi, inv_scale[i]);
        }
    }
    if (hi <= lo) return 1;
    float parts = ceil(abs(y_b - y_a) * (hi - lo) / 0.5f);
    return int(clamp(parts, 1.0f, float(VOLUME_MAX_PARTS)));
}

// The end (distance s_b, altitude y_b) of the scattering volume that starts
// at altitude y_a on the ray o + s d (d_y = mu) inside [s_in, s_out]: the next
// altitude level, or s_out.
void volume_end(vec3 o, float mu, float s_in, float s_out, float y_a, OUT(float) s_b, OUT(float) y_b) {
    int k = next_altitude_level(y_a, mu);
    s_b = s_out;
    y_b = y_a;
    if (k >= 0) {
        float s_level = s_in + (altitude_level(k) - o.y - mu * s_in) / mu;
        if (s_level < s_out) {
            s_b = s_level;
            y_b = altitude_level(k);
        }
    }
    if (s_b == s_out && mu != 0.0f) y_b = clamp(o.y + mu * s_out, 0.0f, frame.atmosphere.top);
}

// int_0^dtau e^{-t} S(t) dt for a source S that varies exponentially in
// optical depth from s_a to s_b (exact when the light reaching the volume is
// attenuated along one direction, nearly so for the dome): with r = ln(s_b /
// s_a), s_a dtau expm1(r - dtau) / (r - dtau). (Both ends 0: 0 through the
// linear form s_a (A - B) + s_b B, A = 1 - e^{-dtau}, B = A / dtau - e^{-dtau}.)
float source_integral(float dtau, float s_a, float s_b) {
    // Within a volume every species stays in one profile piece, so an end at
    // 0 beside a positive one is an underflow (a species or light fading by
    // more than float32's range), not a species ending: floor it relative to
    // the other end and keep the exponential form.
    float floor_value = 1.0e-30f * max(s_a, s_b);
    if (floor_value > 0.0f) {
        s_a = max(s_a, floor_value);
        s_b = max(s_b, floor_value);
    }
    if (s_a > 0.0f && s_b > 0.0f) {
        float t = min(dtau, 1.0e30f);
        float x = log(s_b / s_a) - t;
        // s_a e^x = s_b e^{-dtau}: for x > 1 that form cannot overflow (the
        // ends may differ by any factor: a species fading out).
        if (x > 1.0f) return t * (s_b * exp(-t) - s_a) / x;
        return s_a * t * expm1_over_x(x);
    }
    float e = exp(-dtau);
    float a;
    float b;
    if (dtau < 1.0e-2f) {
        a = dtau * (1.0f - dtau * (0.5f - dtau * (1.0f / 6.0f)));
        b = dtau * (0.5f - dtau * ((1.0f / 3.0f) - dtau * 0.125f));
    } else {
        a = 1.0f - e;
        b = a / dtau - e;
    }
    return s_a * (a - b) + s_b * b;
}

vec3 source_integral3(vec3 dtau, vec3 s_a, vec3 s_b) {
    return vec3(source_integral(dtau.x, s_a.x, s_b.x), source_integral(dtau.y, s_a.y, s_b.y),
                source_integral(dtau.z, s_a.z, s_b.z));
}

// int_{t0}^{t1} e^{-t} S(t) dt over part [t0, t1] of a volume of optical
// depth dtau whose source S is exponential in optical depth from s_a at 0 to
// s_b at dtau (source_integral's model; its ends at t0 and t1 interpolated
// geometrically): e^{-t0} times source_integral of the part. The whole volume
// gives source_integral itself, so a ray no shadow reaches is unchanged.
float source_integral_part(float dtau, float s_a, float s_b, float t0, float t1) {
    if (t0 == 0.0f && t1 == dtau) return source_integral(dtau, s_a, s_b);
    float floor_value = 1.0e-30f * max(s_a, s_b);
    if (!(floor_value > 0.0f) || !(t1 > t0)) return 0.0f;
    s_a = max(s_a, floor_value);
    s_b = max(s_b, floor_value);
    float r = log(s_b / s_a);
    float f0 = dtau > 0.0f ? clamp(t0 / dtau, 0.0f, 1.0f) : 0.0f;
    float f1 = dtau > 0.0f ? clamp(t1 / dtau, 0.0f, 1.0f) : 0.0f;
    return exp(-t0) * source_integral(t1 - t0, s_a * exp(r * f0), s_a * exp(r * f1));
}

vec3 source_integral_part3(vec3 dtau, vec3 s_a, vec3 s_b, vec3 t0, vec3 t1) {
    return vec3(source_integral_part(dtau.x, s_a.x, s_b.x, t0.x, t1.x),
                source_integral_part(dtau.y, s_a.y, s_b.y, t0.y, t1.y),
                source_integral_part(dtau.z, s_a.z, s_b.z, t0.z, t1.z));
}

// What atmosphere_light returns: the light scattered toward the camera over a
// stretch of a view ray, attenuated to the stretch's start (by the
// homogeneous medium too), part by part, and the stretch's optical depth.
struct AtmosphereLight {
    vec3 diffuse;                  // the sky's light and the diffuse field's (multiple scattering), every species
    vec3 sun[SPECIES_COUNT];       // each species' sunlight over the lit parts, times its phase (sun_phase) and sun_scale
    vec3 residual[SPECIES_COUNT];  // each species' residual beam times its phase, when kept apart; else in diffuse
    vec3 medium_sun;               // the homogeneous medium's sunlight over the lit parts, times sun_scale
    vec3 optical_depth;            // the atmosphere's (not the medium's)
};

// No light and no optical depth: a stretch outside the atmosphere.
AtmosphereLight no_atmosphere_light() {
    AtmosphereLight light;
    light.diffuse = vec3(0.0f);
    for (int i = 0; i < SPECIES_COUNT; ++i) {
        light.sun[i] = vec3(0.0f);
        light.residual[i] = vec3(0.0f);
    }
    light.medium_sun = vec3(0.0f);
    light.optical_depth = vec3(0.0f);
    return light;
}

// The sun's light of a lit part [t0, t1] (optical depth from the volume's
// start, per channel) of a volume: each species' share (sun_a, sun_b: its
// source functions at the volume's ends; index SPECIES_COUNT: the homogeneous
// medium's) into `light`; `weight`: the transmittance from the stretch's
// start to the volume.
void add_sun_part(vec3 weight, vec3 dtau, vec3 t0, vec3 t1, vec3 sun_a[SPECIES_COUNT + 1],
                  vec3 sun_b[SPECIES_COUNT + 1], INOUT(AtmosphereLight) light) {
    for (int i = 0; i < 3; ++i) {
        if (species_present(i)) light.sun[i] += weight * source_integral_part3(dtau, sun_a[i], sun_b[i], t0, t1);
    }
    if (HAS_MEDIUM_SUN)
        light.medium_sun += weight * source_integral_part3(dtau, sun_a[SPECIES_COUNT], sun_b[SPECIES_COUNT], t0, t1);
}

// The source function J / sigma (0 where sigma = 0).
vec3 source_function(vec3 j, vec3 sigma) {
    return vec3(sigma.x > 0.0f ? j.x / sigma.x : 0.0f, sigma.y > 0.0f ? j.y / sigma.y : 0.0f,
                sigma.z > 0.0f ? j.z / sigma.z : 0.0f);
}

// Light scattered into the ray o + s d over [0, s_end] by the atmosphere, by
// part (AtmosphereLight: attenuated on its way to o, by the homogeneous
// medium too), and the atmosphere's optical depth over it. Scattering
// volumes (effects/daytime/physics.md, seed equations 3 to 6, corrected): the ray
// is cut where it crosses the altitude levels (which include every profile
// break), and in each volume each species' sky and sun shares of the source
// function J / sigma_t are taken exponential in optical depth between its
// ends, integrated exactly against e^{-tau} (source_integral; the seed's
// constant-source form is the case r = 0). sigma_medium: the
// homogeneous medium's extinction, which attenuates and (HAS_MEDIUM_SUN)
// scatters the sun's light into `medium_sun`, but no sky light. The sun's
// shares count only over the lit parts of each volume, the complement of the
// shadowed runs (`shadowed`: those of shadow_runs, effects/light_shafts/physics.md
// section 5; false: none), times sun_scale (the clouds' transmittance toward
// the sun over this part of the ray, effects/noise_clouds/physics.md section 9; 1: none).
// sun_phase: each species' phase for the sun's light (sun_phase_along(d); all
// 1 gives the phase-free integrals of the aerial table, aerial_table.glsl);
// residual_apart: the residual beam in `residual` rather than in `diffuse`.
// light_direction: the direction whose sky and diffuse light the volumes
// scatter (d; another only for the aerial table's rays continued past the
// ground, aerial_table.glsl).
AtmosphereLight atmosphere_light(vec3 o, vec3 d, float s_end, vec3 sigma_medium, bool shadowed, float sun_scale,
                                 SunPhase sun_phase, bool residual_apart, vec3 light_direction) {
    AtmosphereLight light = no_atmosphere_light();
    float s_in;
    float s_out;
    if (!atmosphere_interval(o, d, s_end, s_in, s_out)) return light;
    SkyTableDirection t = sky_table_direction(light_direction);
    MsDirection ms_dir = ms_view_direction(light_direction);  // (cheap; unused without multiple scattering)
    int run_index = 0;  // the first shadowed run that may reach the volume
    int run_count = shadowed ? shadow_runs.count : 0;
    float mu = d.y;
    float y_a = o.y + mu * s_in;
    if (mu != 0.0f) y_a = clamp(y_a, 0.0f, frame.atmosphere.top);
    float s_a = s_in;
    vec3 weight = exp(-sigma_medium * s_in);  // transmittance from the camera to s_a, medium included
    SpeciesLight light_a = species_light(t, ms_dir, y_a, atmosphere_column(y_a), sun_phase);
    for (int step = 0; step < ATMOSPHERE_MAX_VOLUMES && s_a < s_out; ++step) {
        float s_b;
        float y_b;
        volume_end(o, mu, s_in, s_out, y_a, s_b, y_b);
        // Where the species' density ratios change by more than e^{0.5}
        // across the volume (a dense, shallow layer far below the camera), it
        // is cut into equal parts in altitude (effects/daytime/docs/daytime.md).
        int parts = volume_parts(y_a, y_b);
        if (parts > 1) {
            y_b = y_a + (y_b - y_a) / float(parts);
            s_b = s_a + (y_b - y_a) / mu;
        }
        float len = s_b - s_a;
        float y_piece = 0.5f * (y_a + y_b);
        vec3 tau = stretch_optical_depth(y_a, y_piece, mu, len);
        vec3 dtau = tau + sigma_medium * min(len, 1.0e30f);
        SpeciesLight light_b = light_a;
        if (y_b != y_a) light_b = species_light(t, ms_dir, y_b, atmosphere_column(y_b), sun_phase);
        // Each species' share of the source, sigma_s,i rho_i L_i / sigma_t,
        // its sky and sun parts each taken exponential in optical depth on
        // their own (effects/daytime/docs/daytime.md).
        vec3 sigma_a = sigma_medium;
        vec3 sigma_b = sigma_medium;
        for (int i = 0; i < 3; ++i) {
            if (!species_present(i)) continue;
            int piece = profile_piece(frame.species[i], y_piece);
            sigma_a += vec3(frame.species[i].sigma_t) * piece_density(frame.species[i], piece, y_a);
            sigma_b += vec3(frame.species[i].sigma_t) * piece_density(frame.species[i], piece, y_b);
        }
        // The sun's source functions at the ends: each species', then the medium's.
        vec3 sun_a[SPECIES_COUNT + 1];
        vec3 sun_b[SPECIES_COUNT + 1];
        for (int i = 0; i < SPECIES_COUNT + 1; ++i) {
            sun_a[i] = vec3(0.0f);
            sun_b[i] = vec3(0.0f);
        }
        for (int i = 0; i < 3; ++i) {
            if (!species_present(i)) continue;
            SpeciesGpu sp = frame.species[i];
            int piece = profile_piece(sp, y_piece);
            vec3 scale_a = vec3(sp.sigma_s) * piece_density(sp, piece, y_a);
            vec3 scale_b = vec3(sp.sigma_s) * piece_density(sp, piece, y_b);
            light.diffuse += weight * source_integral3(dtau, source_function(scale_a * light_a.sky[i], sigma_a),
                                                       source_function(scale_b * light_b.sky[i], sigma_b));
            if (HAS_SUN) {
                sun_a[i] = source_function(scale_a * light_a.sun[i], sigma_a);
                sun_b[i] = source_function(scale_b * light_b.sun[i], sigma_b);
            }
            if (HAS_MULTIPLE_SCATTERING && frame.multiple_scattering.air_scattering != 0.0f) {
                if (residual_apart) {
                    light.diffuse += weight * source_integral3(dtau, source_function(scale_a * light_a.ms[i], sigma_a),
                                                               source_function(scale_b * light_b.ms[i], sigma_b));
                    light.residual[i] +=
                        weight * source_integral3(dtau, source_function(scale_a * light_a.residual[i], sigma_a),
                                                  source_function(scale_b * light_b.residual[i], sigma_b));
                } else {
                    vec3 ms_a = light_a.ms[i] + light_a.residual[i];
                    vec3 ms_b = light_b.ms[i] + light_b.residual[i];
                    light.diffuse += weight * source_integral3(dtau, source_function(scale_a * ms_a, sigma_a),
                                                               source_function(scale_b * ms_b, sigma_b));
                }
            }
        }
        if (HAS_MEDIUM_SUN) {
            sun_a[SPECIES_COUNT] = source_function(vec3(frame.sigma_s) * light_a.medium_sun, sigma_a);
            sun_b[SPECIES_COUNT] = source_function(vec3(frame.sigma_s) * light_b.medium_sun, sigma_b);
        }
        if (HAS_SUN) {
            // The lit parts [t0, t1] of the volume in optical depth from s_a
            // (all of it, [0, dtau], where no shadowed run reaches it).
            float lit_from = s_a;
            vec3 tau_from = vec3(0.0f);
            while (run_index < run_count && shadow_runs.run[run_index].x < s_b) {
                vec2 run = shadow_runs.run[run_index];
                if (run.x > lit_from) {
                    vec3 tau_to = stretch_optical_depth(y_a, y_piece, mu, run.x - s_a) + sigma_medium * (run.x - s_a);
                    add_sun_part(weight * sun_scale, dtau, tau_from, tau_to, sun_a, sun_b, light);
                }
                if (run.y >= s_b) {  // shadowed to the volume's end: the run may reach the next volume
                    lit_from = s_b;
                    break;
                }
                if (run.y > lit_from) {
                    lit_from = run.y;
                    tau_from = stretch_optical_depth(y_a, y_piece, mu, run.y - s_a) + sigma_medium * (run.y - s_a);
                }
                ++run_index;
            }
            if (lit_from < s_b)
                add_sun_part(weight * sun_scale, dtau, tau_from, dtau, sun_a, sun_b, light);
        }
        weight *= exp(-dtau);
        light.optical_depth += tau;
        s_a = s_b;
        y_a = y_b;
        light_a = light_b;
    }
    return light;
}

// The same summed as the view ray's terms want them: `inscatter` (the rain's
// once-scattered sunlight apart in `rainbow` when the render outputs keep it
// apart, rainbow_layer_apart), the medium's sunlight and the atmosphere's
// transmittance (the medium's is applied by the caller).
void atmosphere_scattering(vec3 o, vec3 d, float s_end, vec3 sigma_medium, bool shadowed, float sun_scale,
                           OUT(vec3) inscatter, OUT(vec3) rainbow, OUT(vec3) medium_sun, OUT(vec3) transmittance) {
    SunPhase sun_phase = no_sun_phase();
    if (HAS_SUN) sun_phase = sun_phase_along(d);
    AtmosphereLight light = atmosphere_light(o, d, s_end, sigma_medium, shadowed, sun_scale, sun_phase, false, d);
    inscatter = light.diffuse;
    rainbow = vec3(0.0f);
    for (int i = 0; i < SPECIES_COUNT; ++i) {
        if (rainbow_layer_apart(i)) {
            rainbow += light.sun[i];
        } else {
            inscatter += light.sun[i];
        }
    }
    medium_sun = light.medium_sun;
    transmittance = exp(-light.optical_depth);
}

// The atmosphere's transmittance along o + s d over [0, s_end] (1 without
// an atmosphere): lamp cores smaller than a pixel (shading.glsl).
vec3 atmosphere_transmittance(vec3 o, vec3 d, float s_end) {
    if (!HAS_ATMOSPHERE) return vec3(1.0f);
    vec3 inscatter;
    vec3 rainbow;
    vec3 medium_sun;
    vec3 t;
    atmosphere_scattering(o, d, s_end, vec3(0.0f), false, 1.0f, inscatter, rainbow, medium_sun, t);
    return t;
}

// Where marching stops: s_out, or sooner where the optical depth from the
// camera of the thinnest channel passes 30 (e^{-30}: nothing further shows),
// found volume by volume (linear in optical depth inside the last one).
float march_far_distance(vec3 o, vec3 d, float s_in, float s_out, vec3 sigma_medium) {
    float mu = d.y;
    float y_a = o.y + mu * s_in;
    if (mu != 0.0f) y_a = clamp(y_a, 0.0f, frame.atmosphere.top);
    float s_a = s_in;
    vec3 tau = sigma_medium * s_in;
    for (int step = 0; step < ATMOSPHERE_MAX_LEVELS + 2 && s_a < s_out; ++step) {
        float s_b;
        float y_b;
        volume_end(o, mu, s_in, s_out, y_a, s_b, y_b);
        float len = s_b - s_a;
        vec3 dtau = stretch_optical_depth(y_a, 0.5f * (y_a + y_b), mu, len) + sigma_medium * min(len, 1.0e30f);
        float before = min(min(tau.x, tau.y), tau.z);
        tau += dtau;
        float after = min(min(tau.x, tau.y), tau.z);
        if (after > 30.0f) return s_a + min(len, 1.0e30f) * (30.0f - before) / (after - before);
        s_a = s_b;
        y_a = y_b;
    }
    return s_out;
}

// The same by brute force (benchmarks, SKY_MARCH): `steps` midpoint steps of
// equal length over [s_in, s_far] (march_far_distance: rays end where they
// have become opaque); transmittance accumulated step by step; the sun's
// light at each step only where a shadow ray finds it (HAS_SHAFTS), times sun_scale.
void atmosphere_scattering_march(vec3 o, vec3 d, float s_end, vec3 sigma_medium, int steps, float sun_scale,
                                 OUT(vec3) inscatter, OUT(vec3) rainbow, OUT(vec3) medium_sun,
                                 OUT(vec3) transmittance) {
    inscatter = vec3(0.0f);
    rainbow = vec3(0.0f);
    medium_sun = vec3(0.0f);
    transmittance = vec3(1.0f);
    float s_in;
    float s_out;
    if (!atmosphere_interval(o, d, s_end, s_in, s_out)) return;
    float s_far = march_far_distance(o, d, s_in, s_out, sigma_medium);
    SkyTableDirection t = sky_table_direction(d);
    MsDirection ms_dir = ms_view_direction(d);  // (cheap; unused without multiple scattering)
    SunPhase sun_phase = no_sun_phase();
    if (HAS_SUN) sun_phase = sun_phase_along(d);
    float ds = (s_far - s_in) / float(steps);
    vec3 tau_medium = sigma_medium * s_in;
    vec3 tau = vec3(0.0f);  // the atmosphere's, from s_in (summed, not multiplied: no drift in float32)
    for (int step = 0; step < steps; ++step) {
        float s = s_in + (float(step) + 0.5f) * ds;
        float y = clamp(o.y + d.y * s, 0.0f, frame.atmosphere.top);
        vec3 sigma;
        vec3 j;
        vec3 j_rainbow;
        SpeciesLight light = species_light(t, ms_dir, y, atmosphere_column(y), sun_phase);
        if (HAS_SUN) {
            float lit = sun_visible_from_air(o + s * d) * sun_scale;
            for (int i = 0; i < 3; ++i) light.sun[i] *= lit;
            light.medium_sun *= lit;
        }
        atmosphere_point(y, y, light, sigma, j, j_rainbow);
        vec3 reaching = exp(-(tau + sigma * (0.5f * ds)) - (tau_medium + sigma_medium * (float(step) + 0.5f) * ds));
        inscatter += reaching * j * ds;
        rainbow += reaching * j_rainbow * ds;
        if (HAS_MEDIUM_SUN) medium_sun += reaching * vec3(frame.sigma_s) * light.medium_sun * ds;
        tau += sigma * ds;
    }
    transmittance = exp(-tau);
    if (s_far < s_out) transmittance = vec3(0.0f);
}
