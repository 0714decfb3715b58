// Table lookups shared by every effect (both backends): the texels come from
// table_texel(TABLE_*, x, y) for a single-channel table and table_texel4 for
// an RGBA one (a sampler per slot on GL, resources.glsl; the texel arrays of
// FrameData::tables on the CPU, cpu_backend.cpp), the interpolation
// is done here in float32 so that GPU and CPU agree exactly; and the
// culling test and quadrature rules the effects' per-pixel code shares.

// Manual bilinear interpolation on a node-aligned grid (texel i at
// X = i / (n - 1)): exact float32 arithmetic, identical on GPU and CPU (GL's
// fixed-point texture filtering would not be).
// The cell (ix, iy) of an nx x ny node-aligned grid holding (X, Y) in [0, 1]^2,
// clamped to the grid, and the position (ax, ay) in [0, 1]^2 inside it.
// A NaN coordinate is taken as 0 (comparisons with NaN are false): a table
// index never comes from int(NaN).
void table_cell(int nx, int ny, float X, float Y, OUT(int) ix, OUT(int) iy, OUT(float) ax, OUT(float) ay) {
    float fx = (X > 0.0f ? min(X, 1.0f) : 0.0f) * float(nx - 1);
    float fy = (Y > 0.0f ? min(Y, 1.0f) : 0.0f) * float(ny - 1);
    ix = min(int(fx), nx - 2);
    iy = min(int(fy), ny - 2);
    ax = fx - float(ix);
    ay = fy - float(iy);
}

float table_bilinear(int table, int nx, int ny, float X, float Y) {
    int ix;
    int iy;
    float ax;
    float ay;
    table_cell(nx, ny, X, Y, ix, iy, ax, ay);
    float bottom = mix(table_texel(table, ix, iy), table_texel(table, ix + 1, iy), ax);
    float top = mix(table_texel(table, ix, iy + 1), table_texel(table, ix + 1, iy + 1), ax);
    return mix(bottom, top, ay);
}

// True when a contribution bounded by `bound` is provably below the culling
// fraction of `so_far`, a lower bound of the final value, on every channel
// (effects/lamp_airlight/docs/culling.md): skipping it changes the result by less than that fraction.
bool negligible(vec3 bound, vec3 so_far) {
    vec3 limit = frame.cull_fraction * so_far;
    return bound.x < limit.x && bound.y < limit.y && bound.z < limit.z;
}

// The same for a table of four channels (RGBA texels, table_texel4).
vec4 table_bilinear4(int table, int nx, int ny, float X, float Y) {
    int ix;
    int iy;
    float ax;
    float ay;
    table_cell(nx, ny, X, Y, ix, iy, ax, ay);
    vec4 bottom = mix(table_texel4(table, ix, iy), table_texel4(table, ix + 1, iy), ax);
    vec4 top = mix(table_texel4(table, ix, iy + 1), table_texel4(table, ix + 1, iy + 1), ax);
    return mix(bottom, top, ay);
}

// The 4-point Gauss-Legendre rule on [-1, 1]: node and weight k (0..3).
float gauss4_node(int k) {
    return k == 0 ? -0.8611363115940526f
                  : (k == 1 ? -0.3399810435848563f : (k == 2 ? 0.3399810435848563f : 0.8611363115940526f));
}

float gauss4_weight(int k) {
    return (k == 0 || k == 3) ? 0.3478548451374538f : 0.6521451548625461f;
}


// Manual trilinear interpolation of a tiling n^3 RGBA texture stored as a
// stacked table (width n, height n^2: texel (i, j, k) at column i, row
// k n + j; effects/noise_clouds/noise.hpp) at u in tile units, texel centres at
// (i + 1/2) / n, wrapping (effects/noise_clouds/physics.md eq. 1.1).
vec4 table_trilinear4_periodic(int table, int n, vec3 u) {
    vec3 f = float(n) * (u - floor(u)) - vec3(0.5f);
    vec3 corner = floor(f);
    vec3 a = f - corner;
    int i0 = (int(corner.x) + n) % n;
    int j0 = (int(corner.y) + n) % n;
    int k0 = (int(corner.z) + n) % n;
    int i1 = (i0 + 1) % n;
    int row00 = k0 * n + j0;
    int row10 = k0 * n + (j0 + 1) % n;
    int row01 = ((k0 + 1) % n) * n + j0;
    int row11 = ((k0 + 1) % n) * n + (j0 + 1) % n;
    vec4 near = mix(mix(table_texel4(table, i0, row00), table_texel4(table, i1, row00), a.x),
                    mix(table_texel4(table, i0, row10), table_texel4(table, i1, row10), a.x), a.y);
    vec4 far = mix(mix(table_texel4(table, i0, row01), table_texel4(table, i1, row01), a.x),
                   mix(table_texel4(table, i0, row11), table_texel4(table, i1, row11), a.x), a.y);
    return mix(near, far, a.z);
}

// Manual bilinear interpolation of a tiling nx x ny RGBA table at u in tile
// units, texel (i, j) centred at ((i + 1/2) / nx, (j + 1/2) / ny), wrapping
// (the clouds' weather map, effects/noise_clouds/physics.md eq. 8.1).
vec4 table_bilinear4_periodic(int table, int nx, int ny, vec2 u) {
    vec2 f = vec2(float(nx), float(ny)) * (u - floor(u)) - vec2(0.5f);
    vec2 corner = floor(f);
    vec2 a = f - corner;
    int i0 = (int(corner.x) + nx) % nx;
    int j0 = (int(corner.y) + ny) % ny;
    int i1 = (i0 + 1) % nx;
    int j1 = (j0 + 1) % ny;
    return mix(mix(table_texel4(table, i0, j0), table_texel4(table, i1, j0), a.x),
               mix(table_texel4(table, i0, j1), table_texel4(table, i1, j1), a.x), a.y);
}
