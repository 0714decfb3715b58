// Glare convolution on the GPU (issue 8): the eye's glare kernel applied to
// linear radiance by FFT, zero padded to P_x x P_y (powers of two, P >= size
// + kernel radius, so no light wraps around), fp32. The same result as
// convolve_glare_fft (effects/display/glare.cpp, double); error bound in cpp/gl_backend.cpp.
//
// Three passes, chosen by PASS (cpp/gl_backend.cpp, GlBackend::State::glare):
//   PASS 1, rows forward: one work group per image row. The row's R + iG and
//     B + i0 are transformed together as a vec4 line (radix-2 decimation in
//     time, Cooley-Tukey), then split into the three real rows' spectra by
//     conjugate symmetry (the "two real FFTs for one" of Numerical Recipes
//     12.3): R_k = (Z_k + conj Z_{P-k}) / 2, G_k = (Z_k - conj Z_{P-k}) / 2i.
//     Only k = 0..P_x/2 is stored (the rest is Hermitian), one buffer per
//     channel, laid out [k][row] with row stride u_stride.
//   PASS 2, columns: one work group per stored column k of one channel. The
//     column (rows past the data are the zero padding) is transformed by
//     decimation in frequency (Gentleman-Sande: natural order in, bit-reversed
//     out), then either stored as the kernel's spectrum (u_mode 0, scaled by
//     u_scale = 1 / (P_x P_y), the inverse transform's normalisation) or
//     multiplied by the stored kernel spectrum (same bit-reversed order) and
//     transformed back by decimation in time (bit-reversed in, natural out),
//     keeping the first u_rows rows (u_mode 1).
//   PASS 3, rows inverse: one work group per image row. The row's full
//     spectrum is rebuilt from k = 0..P_x/2 (X_{P-k} = conj X_k), R + iG and
//     B are transformed back together and the first u_width values are
//     written to the output image.
// Every line lives either in shared memory (SHARED_LINE 1, LINE_CAPACITY
// elements) or, for lines too long for it, in a scratch storage buffer, one
// slice per work group (SHARED_LINE 0); the FFT code is the same.
// FFT_DOUBLE 1 runs the transforms in double precision (dvec2 complex numbers,
// chosen by gl_backend.cpp when fp32's noise would show after tone mapping).
// Twiddles come from a table computed in double on the CPU:
// twiddle[m] = exp(-2 pi i m / 2^u_tw_log2), m < 2^(u_tw_log2 - 1).

layout(local_size_x = LOCAL_SIZE) in;

#if FFT_DOUBLE
#define C2 dvec2
#define C4 dvec4
#else
#define C2 vec2
#define C4 vec4
#endif

#if PASS == 2
#define LINE_T C2
#else
#define LINE_T C4
#endif

layout(std430, binding = 0) readonly buffer Twiddles { C2 twiddle[]; };

#if SHARED_LINE
shared LINE_T line_data[LINE_CAPACITY];
#define LINE(i) line_data[i]
#define LINE_SYNC() \
    memoryBarrierShared(); \
    barrier()
#else
layout(std430, binding = 7) coherent buffer Scratch { LINE_T scratch[]; };
#define LINE(i) scratch[line_base + (i)]
#define LINE_SYNC() \
    memoryBarrierBuffer(); \
    barrier()
#endif

uniform int u_log2n;    // line length n = 2^u_log2n (P_x for rows, P_y for columns)
uniform int u_tw_log2;  // log2 of the twiddle table's transform size (>= u_log2n)
uniform int u_first;    // first row (PASS 1, 3) or column (PASS 2) of this dispatch
uniform int u_stride;   // row stride of the per-channel spectrum buffers (elements)

uint line_base;  // start of this work group's slice of the scratch buffer

C2 cmul(C2 a, C2 b) { return C2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }
C4 cmul(C4 a, C2 b) { return C4(cmul(a.xy, b), cmul(a.zw, b)); }
C2 conj2(C2 a) { return C2(a.x, -a.y); }

uint bit_reverse(uint i) { return bitfieldReverse(i) >> (32u - uint(u_log2n)); }

// exp(-+2 pi i k / 2^s) (the sign + for the inverse transform).
C2 twiddle_at(uint k, int s, bool inverse) {
    C2 w = twiddle[k << uint(u_tw_log2 - s)];
    return inverse ? conj2(w) : w;
}

// Radix-2 decimation in time, in place: bit-reversed input, natural output.
void fft_dit(bool inverse) {
    uint n = 1u << uint(u_log2n);
    for (int s = 1; s <= u_log2n; ++s) {
        uint half_len = 1u << uint(s - 1);
        for (uint j = gl_LocalInvocationID.x; j < n / 2u; j += uint(LOCAL_SIZE)) {
            uint k = j & (half_len - 1u);
            uint i0 = ((j >> uint(s - 1)) << uint(s)) + k;
            uint i1 = i0 + half_len;
            LINE_T u = LINE(i0);
            LINE_T t = cmul(LINE(i1), twiddle_at(k, s, inverse));
            LINE(i0) = u + t;
            LINE(i1) = u - t;
        }
        LINE_SYNC();
    }
}

// Radix-2 decimation in frequency, in place: natural input, bit-reversed output.
void fft_dif(bool inverse) {
    uint n = 1u << uint(u_log2n);
    for (int s = u_log2n; s >= 1; --s) {
        uint half_len = 1u << uint(s - 1);
        for (uint j = gl_LocalInvocationID.x; j < n / 2u; j += uint(LOCAL_SIZE)) {
            uint k = j & (half_len - 1u);
            uint i0 = ((j >> uint(s - 1)) << uint(s)) + k;
            uint i1 = i0 + half_len;
            LINE_T u = LINE(i0);
            LINE_T v = LINE(i1);
            LINE(i0) = u + v;
            LINE(i1) = cmul(u - v, twiddle_at(k, s, inverse));
        }
        LINE_SYNC();
    }
}

#if PASS == 1 || PASS == 3
layout(std430, binding = 1) buffer SpectrumR { C2 spectrum_r[]; };
layout(std430, binding = 2) buffer SpectrumG { C2 spectrum_g[]; };
layout(std430, binding = 3) buffer SpectrumB { C2 spectrum_b[]; };
#endif

#if PASS == 1
layout(binding = 0) uniform sampler2D u_source;  // RGBA32F, texel row = image row
uniform int u_width;  // columns of the source holding data
uniform int u_shift;  // line index i reads source column (i + u_shift) mod n: 0 for the image, r for the kernel

void main() {
    uint n = 1u << uint(u_log2n);
    uint row = uint(u_first) + gl_WorkGroupID.x;
    line_base = gl_WorkGroupID.x * n;
    for (uint i = gl_LocalInvocationID.x; i < n; i += uint(LOCAL_SIZE)) {
        uint c = (i + uint(u_shift)) & (n - 1u);
        vec3 v = c < uint(u_width) ? texelFetch(u_source, ivec2(c, row), 0).rgb : vec3(0.0);
        LINE(bit_reverse(i)) = C4(v, 0.0);
    }
    LINE_SYNC();
    fft_dit(false);
    for (uint k = gl_LocalInvocationID.x; k <= n / 2u; k += uint(LOCAL_SIZE)) {
        C4 a = LINE(k);
        C2 zc = conj2(LINE((n - k) & (n - 1u)).xy);
        C2 d = a.xy - zc;  // 2i G_k
        uint idx = k * uint(u_stride) + row;
        spectrum_r[idx] = 0.5 * (a.xy + zc);
        spectrum_g[idx] = C2(0.5 * d.y, -0.5 * d.x);
        spectrum_b[idx] = a.zw;
    }
}
#endif

#if PASS == 2
layout(std430, binding = 1) buffer Spectrum { C2 spectrum[]; };              // one channel, [k][row]
layout(std430, binding = 2) buffer KernelSpectrum { C2 kernel_spectrum[]; };  // [k - u_first][ky], bit-reversed ky
uniform int u_rows;      // rows holding data
uniform int u_shift;     // line index i reads row (i + u_shift) mod n: 0 for the image, r for the kernel
uniform int u_mode;      // 0: store the kernel's spectrum; 1: convolve
uniform float u_scale;   // mode 0: 1 / (P_x P_y)

void main() {
    uint n = 1u << uint(u_log2n);
    uint k = uint(u_first) + gl_WorkGroupID.x;
    uint kbase = gl_WorkGroupID.x * n;
    line_base = gl_WorkGroupID.x * n;
    for (uint i = gl_LocalInvocationID.x; i < n; i += uint(LOCAL_SIZE)) {
        uint y = (i + uint(u_shift)) & (n - 1u);
        LINE(i) = y < uint(u_rows) ? spectrum[k * uint(u_stride) + y] : C2(0.0);
    }
    LINE_SYNC();
    fft_dif(false);
    if (u_mode == 0) {
        for (uint i = gl_LocalInvocationID.x; i < n; i += uint(LOCAL_SIZE)) kernel_spectrum[kbase + i] = u_scale * LINE(i);
        return;
    }
    for (uint i = gl_LocalInvocationID.x; i < n; i += uint(LOCAL_SIZE)) LINE(i) = cmul(LINE(i), kernel_spectrum[kbase + i]);
    LINE_SYNC();
    fft_dit(true);
    for (uint y = gl_LocalInvocationID.x; y < uint(u_rows); y += uint(LOCAL_SIZE)) spectrum[k * uint(u_stride) + y] = LINE(y);
}
#endif

#if PASS == 3
layout(rgba32f, binding = 0) writeonly uniform image2D u_result;
uniform int u_width;  // columns written

void main() {
    uint n = 1u << uint(u_log2n);
    uint row = uint(u_first) + gl_WorkGroupID.x;
    line_base = gl_WorkGroupID.x * n;
    for (uint i = gl_LocalInvocationID.x; i < n; i += uint(LOCAL_SIZE)) {
        bool mirrored = i > n / 2u;
        uint idx = (mirrored ? n - i : i) * uint(u_stride) + row;
        C2 r = spectrum_r[idx], g = spectrum_g[idx], b = spectrum_b[idx];
        if (mirrored) {
            r = conj2(r);
            g = conj2(g);
            b = conj2(b);
        }
        LINE(bit_reverse(i)) = C4(r.x - g.y, r.y + g.x, b);  // R + iG, B
    }
    LINE_SYNC();
    fft_dit(true);
    for (uint x = gl_LocalInvocationID.x; x < uint(u_width); x += uint(LOCAL_SIZE)) {
        C4 v = LINE(x);
        imageStore(u_result, ivec2(x, row), vec4(v.x, v.y, v.z, 1.0));
    }
}
#endif
