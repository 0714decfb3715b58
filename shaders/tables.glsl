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

