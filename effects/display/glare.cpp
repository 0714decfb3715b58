// Eye glare (issue 8): the pupil's Fraunhofer PSF, spectral kernels and FFT
// convolution. See include/airlight/glare.hpp and effects/display/docs/glare.md.
#include "airlight/glare.hpp"

#include <algorithm>
#include <cmath>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "numerics.hpp"

namespace airlight {

namespace {

using numerics::kPi;
constexpr double kLambdaMin = 380e-9;
constexpr double kLambdaMax = 780e-9;

bool is_pow2(int n) { return n > 0 && (n & (n - 1)) == 0; }

// CDF of the unit tent (hat) function centred at 0.
double tent_cdf(double u) {
    if (u <= -1.0) return 0.0;
    if (u <= 0.0) return 0.5 * (1.0 + u) * (1.0 + u);
    if (u <= 1.0) return 1.0 - 0.5 * (1.0 - u) * (1.0 - u);
    return 1.0;
}

// Integrals over axis-aligned rectangles of the bilinear interpolant of a
// sampled function (sample (i, j) at coordinate (i, j), zero outside the
// grid), through a summed-area table: the interpolant's weight on sample i
// over [a, b] is T(b - i) - T(a - i), T the tent's CDF; it is 1 on a run of
// inner samples (a box sum) and fractional on at most two samples each side.
class BilinearIntegrator {
public:
    explicit BilinearIntegrator(const std::vector<double>& values, int n) : n_(n), sat_((n + 1) * size_t(n + 1), 0.0) {
        auto at = [&](int i, int j) { return i < 0 || j < 0 || i >= n || j >= n ? 0.0 : values[size_t(j) * n + i]; };
        for (int j = 0; j < n; ++j) {
            double row = 0.0;
            for (int i = 0; i < n; ++i) {
                // Prefiltered samples q = p - laplacian(p) / 12: the bilinear interpolant of q then has the
                // cell averages of p exactly for quadratic p (the plain interpolant is off by h^2 p'' / 12,
                // about 1% at the Airy peak with 12 cells to the first zero).
                const double lap = at(i + 1, j) + at(i - 1, j) + at(i, j + 1) + at(i, j - 1) - 4.0 * at(i, j);
                row += at(i, j) - lap / 12.0;
                sat_[size_t(j + 1) * (n + 1) + i + 1] = sat_[size_t(j) * (n + 1) + i + 1] + row;
            }
        }
    }

    double integrate(double x0, double x1, double y0, double y1) const {
        Parts px, py;
        parts(x0, x1, px);
        parts(y0, y1, py);
        double sum = 0.0;
        for (int a = 0; a < px.count; ++a)
            for (int b = 0; b < py.count; ++b) sum += px.w[a] * py.w[b] * box(px.lo[a], px.hi[a], py.lo[b], py.hi[b]);
        return sum;
    }

private:
    struct Parts {
        int count = 0;
        int lo[8], hi[8];
        double w[8];
        void add(int l, int h, double weight) {
            lo[count] = l;
            hi[count] = h;
            w[count] = weight;
            ++count;
        }
    };

    static void parts(double a, double b, Parts& out) {
        const int full_lo = static_cast<int>(std::ceil(a + 1.0));
        const int full_hi = static_cast<int>(std::floor(b - 1.0));
        const bool has_full = full_lo <= full_hi;
        if (has_full) out.add(full_lo, full_hi, 1.0);
        const int i0 = static_cast<int>(std::floor(a)), i1 = static_cast<int>(std::ceil(b));
        for (int i = i0; i <= i1; ++i) {
            if (has_full && i >= full_lo && i <= full_hi) {
                i = full_hi;
                continue;
            }
            const double w = tent_cdf(b - i) - tent_cdf(a - i);
            if (w > 0.0 && out.count < 8) out.add(i, i, w);
        }
    }

    double box(int x0, int x1, int y0, int y1) const {
        x0 = std::max(x0, 0);
        y0 = std::max(y0, 0);
        x1 = std::min(x1, n_ - 1);
        y1 = std::min(y1, n_ - 1);
        if (x0 > x1 || y0 > y1) return 0.0;
        const size_t w = size_t(n_) + 1;
        return sat_[size_t(y1 + 1) * w + x1 + 1] - sat_[size_t(y0) * w + x1 + 1] - sat_[size_t(y1 + 1) * w + x0] +
               sat_[size_t(y0) * w + x0];
    }

    int n_;
    std::vector<double> sat_;
};

struct GridChoice {
    double dx;
    int radius;
};

// Aperture sampling dx for an N grid and the kernel radius it supports:
// N dx >= 2 D (the PSF, band-limited to the aperture's autocorrelation of
// width 2 D, is sampled at least at its Nyquist rate, so sums over cells are
// its integrals), and lambda_max / (N dx) <= pixel / 2 (cells no larger than
// half a pixel, so the bilinear interpolant resolves the PSF inside a pixel).
// The angular range lambda_min / (2 dx) then bounds the kernel's radius.
GridChoice choose_grid(const GlareOptions& options, double pixel_angle, double lambda_lo, double lambda_hi) {
    const int n = options.grid_size;
    const double d = options.pupil_diameter_mm * 1e-3;
    const double cell = std::max(pixel_angle / 8.0, 1.22 * lambda_hi / (12.0 * d));
    const double dx = std::max(2.0 * d / n, lambda_hi / (n * cell));
    if (d / dx < 24.0) {
        std::ostringstream msg;
        msg << "glare: grid_size " << n << " samples the pupil with only " << d / dx
            << " cells across at this pixel angle; use a larger grid_size";
        throw std::invalid_argument(msg.str());
    }
    // Kernel edge (r + 0.5) pixels must stay inside the sampled range (n/2 - 1 cells) at lambda_lo.
    const double cells_per_pixel = pixel_angle * n * dx / lambda_lo;
    const int r_max = static_cast<int>(std::floor((n / 2 - 1) / cells_per_pixel - 0.5));
    return {dx, std::max(0, std::min(options.max_kernel_radius, r_max))};
}

void check_options(const GlareOptions& options, double pixel_angle) {
    validate_pupil_diameter(options.pupil_diameter_mm);
    if (!is_pow2(options.grid_size) || options.grid_size < 64)
        throw std::invalid_argument("glare: grid_size must be a power of two >= 64");
    if (!(pixel_angle > 0.0) || !std::isfinite(pixel_angle))
        throw std::invalid_argument("glare: pixel_angle must be finite and > 0");
    if (options.max_kernel_radius < 0) throw std::invalid_argument("glare: max_kernel_radius must be >= 0");
    if (!(options.wavelength_step_nm > 0.0) || options.wavelength_step_nm > 100.0)
        throw std::invalid_argument("glare: wavelength_step_nm must be in (0, 100]");
    if (options.eyelashes && (options.eyelash_count < 0 || !(options.eyelash_width_mm > 0.0)))
        throw std::invalid_argument("glare: eyelash_count must be >= 0 and eyelash_width_mm > 0");
}

}  // namespace

double glare_support_window(double rho, int radius) {
    // physics.md section 3, "Support": 1 inside half the rim, a cos^2 fall to 0 at the rim radius + 1/2.
    const double rim = radius + 0.5, start = 0.5 * rim;
    if (rho <= start) return 1.0;
    if (rho >= rim) return 0.0;
    const double c = std::cos(0.5 * kPi * (rho - start) / (rim - start));
    return c * c;
}

namespace {

// Adds the pixel integrals of the PSF at `lambda` (energy per pixel), times weight and the round support's
// window (glare_support_window of the pixel centre's distance), into out ((2r + 1)^2 values): the kernel is
// round, never the (2r + 1)^2 square, whose corners reach sqrt(2) r along the diagonals but only r along the
// axes (a square halo with a hard edge).
void accumulate_pixel_integrals(const BilinearIntegrator& integ, int n, double dx, int radius, double pixel_angle,
                                double lambda, double weight, std::vector<double>& out) {
    const int size = 2 * radius + 1;
    const double cells = pixel_angle * n * dx / lambda;  // frequency cells per pixel
    const double c0 = n / 2;
    for (int row = 0; row < size; ++row) {
        // Row 0 on top: angle up = (radius - row) pixels. The PSF is centrosymmetric, so the sign convention of
        // the aperture's y axis does not matter.
        const double v = radius - row;
        const double y0 = c0 + (v - 0.5) * cells, y1 = c0 + (v + 0.5) * cells;
        for (int col = 0; col < size; ++col) {
            const double u = col - radius;
            const double window = glare_support_window(std::hypot(u, v), radius);
            if (window <= 0.0) continue;
            const double x0 = c0 + (u - 0.5) * cells, x1 = c0 + (u + 0.5) * cells;
            // Clamped: the prefiltered interpolant may dip a little below 0 inside a dark ring.
            out[size_t(row) * size + col] += weight * window * std::max(0.0, integ.integrate(x0, x1, y0, y1));
        }
    }
}

// Makes a kernel of pixel energies (fractions of the whole PSF) sum to 1: the energy the kernel misses
// (diffracted beyond its radius or the grid's range) is light that leaves the central pixel, so the centre
// keeps its exact integral and the off-centre weights are scaled up to absorb it. Returns the sum before.
double conserve_energy(std::vector<double>& w, int radius) {
    const int size = 2 * radius + 1;
    const size_t centre = size_t(radius) * size + radius;
    double sum = 0.0, off = 0.0;
    for (size_t i = 0; i < w.size(); ++i) {
        sum += w[i];
        if (i != centre) off += w[i];
    }
    const double c = std::min(w[centre], 1.0);
    if (off > 0.0) {
        for (size_t i = 0; i < w.size(); ++i)
            if (i != centre) w[i] *= (1.0 - c) / off;
        w[centre] = c;
    } else {
        w[centre] = 1.0;  // a 1x1 kernel: all the light stays
    }
    return sum;
}

// ---------------------------------------------------------------------------
// FFT: mixed-radix (4, 2, 3, 5) Stockham autosort, decimation in frequency
// (Stockham 1966; formulation of Van Loan, "Computational Frameworks for the
// Fast Fourier Transform", 1992, section 1.7). A stage of radix p on a
// sub-transform of length L = p m with stride s maps x to y by
//   y[q + s (p j + t)] = w^(j t) sum_r x[q + s (j + r m)] e^(-2 pi i r t / p),  w = e^(-2 pi i / L),
// for j < m, q < s, then recurses on length m with stride s p (x, y swapped).
// No bit reversal; the loop over q is contiguous. Batched: every element is
// a run of `batch` complex values (several columns transformed together).
// Twiddles are precomputed per stage with cos/sin of the exact angle.
// ---------------------------------------------------------------------------

using cd = std::complex<double>;

struct FftStage {
    int radix, m, s;    // sub-length radix * m, stride s
    size_t twiddle_at;  // w^(j t) at twiddle_at + j (radix - 1) + t - 1
};

struct FftPlan {
    int n = 1;
    std::vector<FftStage> stages;
    std::vector<cd> twiddles;
};

// The product without std::complex's NaN recovery (which blocks vectorisation).
inline cd cmul(cd a, cd b) {
    return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}
template <bool Inv>
inline cd twiddle(cd w) {
    return Inv ? std::conj(w) : w;
}
// Multiplies by -i (forward) or +i (inverse).
template <bool Inv>
inline cd rot(cd a) {
    return Inv ? cd(-a.imag(), a.real()) : cd(a.imag(), -a.real());
}

template <bool Inv>
void stage2(const cd* x, cd* y, int m, size_t run, const cd* tw) {
    for (int j = 0; j < m; ++j) {
        const cd w1 = twiddle<Inv>(tw[j]);
        const cd *x0 = x + run * j, *x1 = x + run * (j + m);
        cd *y0 = y + run * (2 * j), *y1 = y0 + run;
        for (size_t q = 0; q < run; ++q) {
            const cd a = x0[q], b = x1[q];
            y0[q] = a + b;
            y1[q] = cmul(a - b, w1);
        }
    }
}

template <bool Inv>
void stage4(const cd* x, cd* y, int m, size_t run, const cd* tw) {
    for (int j = 0; j < m; ++j) {
        const cd w1 = twiddle<Inv>(tw[3 * j]), w2 = twiddle<Inv>(tw[3 * j + 1]), w3 = twiddle<Inv>(tw[3 * j + 2]);
        const cd *x0 = x + run * j, *x1 = x + run * (j + m), *x2 = x + run * (j + 2 * m), *x3 = x + run * (j + 3 * m);
        cd *y0 = y + run * (4 * j), *y1 = y0 + run, *y2 = y1 + run, *y3 = y2 + run;
        for (size_t q = 0; q < run; ++q) {
            const cd b0 = x0[q] + x2[q], b1 = x0[q] - x2[q], b2 = x1[q] + x3[q], b3 = rot<Inv>(x1[q] - x3[q]);
            y0[q] = b0 + b2;
            y1[q] = cmul(b1 + b3, w1);
            y2[q] = cmul(b0 - b2, w2);
            y3[q] = cmul(b1 - b3, w3);
        }
    }
}

template <bool Inv>
void stage3(const cd* x, cd* y, int m, size_t run, const cd* tw) {
    const double s3 = (Inv ? 1.0 : -1.0) * 0.86602540378443864676;  // sin(+-2 pi / 3)
    for (int j = 0; j < m; ++j) {
        const cd w1 = twiddle<Inv>(tw[2 * j]), w2 = twiddle<Inv>(tw[2 * j + 1]);
        const cd *x0 = x + run * j, *x1 = x + run * (j + m), *x2 = x + run * (j + 2 * m);
        cd *y0 = y + run * (3 * j), *y1 = y0 + run, *y2 = y1 + run;
        for (size_t q = 0; q < run; ++q) {
            const cd a0 = x0[q], s = x1[q] + x2[q], d = x1[q] - x2[q];
            const cd c = a0 - 0.5 * s, e(-s3 * d.imag(), s3 * d.real());  // e = i sin d
            y0[q] = a0 + s;
            y1[q] = cmul(c + e, w1);
            y2[q] = cmul(c - e, w2);
        }
    }
}

template <bool Inv>
void stage5(const cd* x, cd* y, int m, size_t run, const cd* tw) {
    const double c1 = 0.30901699437494742410, c2 = -0.80901699437494742410;  // cos(2 pi / 5), cos(4 pi / 5)
    const double sg = Inv ? 1.0 : -1.0;
    const double s1 = sg * 0.95105651629515357212, s2 = sg * 0.58778525229247312917;  // sin(2 pi / 5), sin(4 pi / 5)
    for (int j = 0; j < m; ++j) {
        const cd* w = tw + 4 * j;
        const cd w1 = twiddle<Inv>(w[0]), w2 = twiddle<Inv>(w[1]), w3 = twiddle<Inv>(w[2]), w4 = twiddle<Inv>(w[3]);
        const cd *x0 = x + run * j, *x1 = x + run * (j + m), *x2 = x + run * (j + 2 * m), *x3 = x + run * (j + 3 * m),
                 *x4 = x + run * (j + 4 * m);
        cd *y0 = y + run * (5 * j), *y1 = y0 + run, *y2 = y1 + run, *y3 = y2 + run, *y4 = y3 + run;
        for (size_t q = 0; q < run; ++q) {
            const cd a0 = x0[q], t1 = x1[q] + x4[q], t2 = x2[q] + x3[q], t3 = x1[q] - x4[q], t4 = x2[q] - x3[q];
            const cd b1 = a0 + c1 * t1 + c2 * t2, b2 = a0 + c2 * t1 + c1 * t2;
            const cd u1 = s1 * t3 + s2 * t4, u2 = s2 * t3 - s1 * t4;  // times i below
            const cd e1(-u1.imag(), u1.real()), e2(-u2.imag(), u2.real());
            y0[q] = a0 + t1 + t2;
            y1[q] = cmul(b1 + e1, w1);
            y4[q] = cmul(b1 - e1, w4);
            y2[q] = cmul(b2 + e2, w2);
            y3[q] = cmul(b2 - e2, w3);
        }
    }
}

FftPlan make_plan(int n) {
    FftPlan plan;
    plan.n = n;
    int rest = n, s = 1;
    while (rest > 1) {
        int p = 0;
        if (rest % 4 == 0) {
            p = 4;
        } else if (rest % 2 == 0) {
            p = 2;
        } else if (rest % 3 == 0) {
            p = 3;
        } else if (rest % 5 == 0) {
            p = 5;
        } else {
            throw std::invalid_argument("fft: size must be a product of 2, 3 and 5 (got " + std::to_string(n) + ")");
        }
        const int m = rest / p;
        plan.stages.push_back({p, m, s, plan.twiddles.size()});
        for (int j = 0; j < m; ++j)
            for (int t = 1; t < p; ++t) {
                const long long e = (static_cast<long long>(j) * t) % rest;
                const double a = -2.0 * kPi * double(e) / double(rest);
                plan.twiddles.emplace_back(std::cos(a), std::sin(a));
            }
        rest = m;
        s *= p;
    }
    return plan;
}

// Plans are built once per size and kept (a few kB each); the map is only touched under the mutex.
const FftPlan& get_plan(int n) {
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<FftPlan>> plans;
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<FftPlan>& slot = plans[n];
    if (!slot) {
        try {
            slot = std::make_unique<FftPlan>(make_plan(n));
        } catch (...) {
            plans.erase(n);
            throw;
        }
    }
    return *slot;
}

// Unnormalised transform of `batch` interleaved sequences: element k of sequence b at data[k * batch + b].
// work holds n * batch values. The result is left in data.
template <bool Inv>
void run_plan(const FftPlan& plan, cd* data, cd* work, size_t batch) {
    cd *x = data, *y = work;
    for (const FftStage& st : plan.stages) {
        const size_t run = size_t(st.s) * batch;
        const cd* tw = plan.twiddles.data() + st.twiddle_at;
        switch (st.radix) {
            case 4:
                stage4<Inv>(x, y, st.m, run, tw);
                break;
            case 2:
                stage2<Inv>(x, y, st.m, run, tw);
                break;
            case 3:
                stage3<Inv>(x, y, st.m, run, tw);
                break;
            default:
                stage5<Inv>(x, y, st.m, run, tw);
                break;
        }
        std::swap(x, y);
    }
    if (x != data) std::copy(x, x + size_t(plan.n) * batch, data);
}

void run_plan(const FftPlan& plan, cd* data, cd* work, size_t batch, bool inverse) {
    if (inverse) {
        run_plan<true>(plan, data, work, batch);
    } else {
        run_plan<false>(plan, data, work, batch);
    }
}

// Columns transformed together: a block of kColumnBlock columns (py x 8 x 16 bytes, ~150 kB for 1125 rows,
// twice with the work buffer) stays in L2 through all the stages.
constexpr int kColumnBlock = 8;

// Transforms columns [x0, x1) of a row-major ny x nx array, kColumnBlock at a time.
void fft_column_range(std::complex<double>* data, int nx, int ny, int x0, int x1, bool inverse) {
    const FftPlan& plan = get_plan(ny);
    std::vector<cd> block(size_t(ny) * kColumnBlock), work(block.size());
    for (int xb = x0; xb < x1; xb += kColumnBlock) {
        const int bw = std::min(kColumnBlock, x1 - xb);
        for (int y = 0; y < ny; ++y) std::copy_n(data + size_t(y) * nx + xb, bw, block.data() + size_t(y) * bw);
        run_plan(plan, block.data(), work.data(), size_t(bw), inverse);
        for (int y = 0; y < ny; ++y) std::copy_n(block.data() + size_t(y) * bw, bw, data + size_t(y) * nx + xb);
    }
}

}  // namespace

namespace detail {

int next_pow2(int n) {
    int p = 1;
    while (p < n) p <<= 1;
    return p;
}

bool is_fft_size(int n) {
    if (n < 1) return false;
    for (int p : {2, 3, 5})
        while (n % p == 0) n /= p;
    return n == 1;
}

int next_fft_size(int n) {
    if (n <= 1) return 1;
    // Smallest 2^a 3^b 5^c >= n: enumerate the products of powers of 5 and 3, then double up to n.
    long long best = static_cast<long long>(next_pow2(n));
    for (long long p5 = 1; p5 < 2LL * n; p5 *= 5)
        for (long long p35 = p5; p35 < 2LL * n; p35 *= 3) {
            long long v = p35;
            while (v < n) v *= 2;
            best = std::min(best, v);
        }
    return static_cast<int>(best);
}

void fft(std::vector<std::complex<double>>& data, bool inverse) {
    const size_t n = data.size();
    if (n <= 1) return;
    if (n > size_t(1) << 30) throw std::invalid_argument("fft: size too large");
    const FftPlan& plan = get_plan(static_cast<int>(n));
    std::vector<cd> work(n);
    run_plan(plan, data.data(), work.data(), 1, inverse);
    if (inverse) {
        const double s = 1.0 / double(n);
        for (auto& z : data) z *= s;
    }
}

void fft2d(std::vector<std::complex<double>>& data, int nx, int ny, bool inverse, int threads) {
    if (!is_fft_size(nx) || !is_fft_size(ny) || data.size() != size_t(nx) * ny)
        throw std::invalid_argument("fft2d: sizes must be products of 2, 3 and 5 matching the data");
    threads = numerics::thread_count(threads);
    const FftPlan& row_plan = get_plan(nx);
    const auto row_chunk = [&](int begin, int end) {
        std::vector<cd> work(nx);
        for (int y = begin; y < end; ++y) run_plan(row_plan, data.data() + size_t(y) * nx, work.data(), 1, inverse);
    };
    numerics::parallel_for_chunks(ny, row_chunk, threads);
    const int blocks = (nx + kColumnBlock - 1) / kColumnBlock;
    const auto column_chunk = [&](int begin, int end) {
        fft_column_range(data.data(), nx, ny, begin * kColumnBlock, std::min(nx, end * kColumnBlock), inverse);
    };
    numerics::parallel_for_chunks(blocks, column_chunk, threads);
    if (inverse) {
        const double s = 1.0 / (double(nx) * ny);
        for (auto& z : data) z *= s;
    }
}

}  // namespace detail

void validate_pupil_diameter(double diameter_mm) {
    if (!(diameter_mm >= 1.0 && diameter_mm <= 9.0)) {
        std::ostringstream msg;
        msg << kPupilDiameterField << ": must be in [1, 9] mm (got " << diameter_mm << ")";
        throw std::invalid_argument(msg.str());
    }
}

double pupil_diameter_from_luminance(double luminance_cd_m2) {
    if (!(luminance_cd_m2 > 0.0) || !std::isfinite(luminance_cd_m2)) {
        std::ostringstream msg;
        msg << "display.glare.adaptation_luminance: must be finite and > 0 cd/m^2 (got " << luminance_cd_m2 << ")";
        throw std::invalid_argument(msg.str());
    }
    const double millilamberts = luminance_cd_m2 * kPi / 10.0;
    return 4.9 - 3.0 * std::tanh(0.4 * std::log10(millilamberts));
}

double camera_pixel_angle(double fov_y_deg, int height) {
    if (!(fov_y_deg > 0.0 && fov_y_deg < 180.0) || height < 1)
        throw std::invalid_argument("glare: fov_y must be in (0, 180) degrees and height >= 1");
    return 2.0 * std::tan(0.5 * fov_y_deg * kPi / 180.0) / height;
}

PupilAperture make_pupil_aperture(const GlareOptions& options, int n, double dx) {
    validate_pupil_diameter(options.pupil_diameter_mm);
    if (n < 2 || !(dx > 0.0)) throw std::invalid_argument("glare: aperture grid must have n >= 2 and dx > 0");
    const double radius = 0.5e-3 * options.pupil_diameter_mm;
    // Eyelashes (effects/display/docs/glare.md): straight opaque strips hanging from above the pupil, anchored on its
    // top edge at x evenly spread over [-0.6 R, 0.6 R], fanned outwards up to 20 degrees from vertical, reaching down
    // to tips at heights alternating between 0.2 R and 0.45 R above the centre.
    struct Lash {
        double ax, ay, dx_, dy_, t_tip;
    };
    std::vector<Lash> lashes;
    const double half_w = 0.5e-3 * options.eyelash_width_mm;
    if (options.eyelashes) {
        const int count = options.eyelash_count;
        for (int i = 0; i < count; ++i) {
            const double s = count == 1 ? 0.0 : -1.0 + 2.0 * i / (count - 1);
            const double phi = s * 20.0 * kPi / 180.0;
            const double tip_y = (i % 2 == 0 ? 0.2 : 0.45) * radius;
            const double ax = 0.6 * radius * s, ay = radius;
            const double ddx = std::sin(phi), ddy = -std::cos(phi);  // pointing down
            lashes.push_back({ax, ay, ddx, ddy, (ay - tip_y) / std::cos(phi)});
        }
    }
    auto opaque_lash = [&](double x, double y) {
        for (const Lash& l : lashes) {
            const double px = x - l.ax, py = y - l.ay;
            const double t = px * l.dx_ + py * l.dy_;
            const double perp = px * l.dy_ - py * l.dx_;
            if (std::abs(perp) <= half_w && t <= l.t_tip) return true;
        }
        return false;
    };
    auto near_lash = [&](double x, double y, double margin) {
        for (const Lash& l : lashes) {
            const double px = x - l.ax, py = y - l.ay;
            const double t = px * l.dx_ + py * l.dy_;
            const double perp = px * l.dy_ - py * l.dx_;
            if (std::abs(perp) <= half_w + margin && t <= l.t_tip + margin) return true;
        }
        return false;
    };

    PupilAperture ap;
    ap.n = n;
    ap.dx = dx;
    ap.disc_radius = radius;
    ap.transmission.assign(size_t(n) * n, 0.0);
    if (!lashes.empty()) ap.lashes.assign(size_t(n) * n, 0.0);
    const double half_diag = dx * std::sqrt(0.5);
    constexpr int kSub = 16;  // supersampling of cells cut by an edge
    for (int iy = 0; iy < n; ++iy) {
        const double y = (iy - n / 2) * dx;
        for (int ix = 0; ix < n; ++ix) {
            const double x = (ix - n / 2) * dx;
            const double r = std::hypot(x, y);
            if (r > radius + half_diag) continue;
            const bool edge = r > radius - half_diag || near_lash(x, y, half_diag);
            double t, shade = 0.0;
            if (!edge) {
                t = 1.0;
            } else {
                int inside = 0, shaded = 0;
                for (int sy = 0; sy < kSub; ++sy) {
                    const double yy = y + ((sy + 0.5) / kSub - 0.5) * dx;
                    for (int sx = 0; sx < kSub; ++sx) {
                        const double xx = x + ((sx + 0.5) / kSub - 0.5) * dx;
                        if (xx * xx + yy * yy > radius * radius) continue;
                        ++(opaque_lash(xx, yy) ? shaded : inside);
                    }
                }
                t = double(inside) / (kSub * kSub);
                shade = double(shaded) / (kSub * kSub);
            }
            ap.transmission[size_t(iy) * n + ix] = t;
            if (!ap.lashes.empty()) ap.lashes[size_t(iy) * n + ix] = shade;
        }
    }
    return ap;
}

PupilSpectrum pupil_power_spectrum(const PupilAperture& aperture) {
    const int n = aperture.n;
    if (!is_pow2(n)) throw std::invalid_argument("glare: aperture grid size must be a power of two");
    const bool disc = aperture.disc_radius > 0.0;
    const bool lashes = disc && aperture.lashes.size() == size_t(n) * n;
    std::vector<std::complex<double>> field(size_t(n) * n, cd(0.0, 0.0));
    if (!disc || lashes) {
        // The sampled part: the whole aperture, or only the lashes' shade inside a clear disc.
        const std::vector<double>& sampled = disc ? aperture.lashes : aperture.transmission;
        std::copy(sampled.begin(), sampled.end(), field.begin());
        detail::fft2d(field, n, n, false, 0);
        if (disc)
            for (auto& z : field) z = -z;
    }
    // Light through the pupil in cells (dx^2): Parseval's total for the true 0/1 aperture.
    double area = 0.0;
    if (disc) {
        // The clear disc's transform is exact (physics.md section 3, "PSF", equation 3.1):
        //   A(f) = pi R^2 2 J1(2 pi R f) / (2 pi R f),
        // in cells at frequency index k (f = (k - n/2) / (n dx)), times (-1)^(kx + ky): the DFT's phase for a grid
        // whose cell n/2 is the origin. The DFT of the sampled disc instead sums the copies of A shifted by
        // multiples of 1 / dx (aliasing of its f^-3/2 tail), which interfere destructively along the axes:
        // 17 % too little glare there at 0.7 of the grid's range, a square-looking halo.
        const double r = aperture.disc_radius, inv_cell_area = 1.0 / (aperture.dx * aperture.dx);
        // A depends on |f| only: evaluated once per (|kx|, |ky|) with |kx| <= |ky| (an eighth of the grid).
        const int h = n / 2;
        std::vector<double> airy(size_t(h + 1) * (h + 1));
        for (int b = 0; b <= h; ++b)
            for (int a = 0; a <= b; ++a) {
                const double z = 2.0 * kPi * r * std::hypot(double(a), double(b)) / (n * aperture.dx);
                const double value = z < 1e-8 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, z) / z;
                airy[size_t(b) * (h + 1) + a] = airy[size_t(a) * (h + 1) + b] = value;
            }
        const double peak = kPi * r * r * inv_cell_area;
        for (int ky = 0; ky < n; ++ky) {
            const int b = std::abs((ky + h) % n - h);
            for (int kx = 0; kx < n; ++kx) {
                const int a = std::abs((kx + h) % n - h);
                const double sign = ((kx + ky) & 1) ? -1.0 : 1.0;
                field[size_t(ky) * n + kx] += sign * peak * airy[size_t(b) * (h + 1) + a];
            }
        }
        area = kPi * r * r * inv_cell_area;
        if (lashes)
            for (double t : aperture.lashes) area -= t;
    } else {
        // Normalised by the light through the pupil, n^2 sum(t) (Parseval, for the true 0/1 aperture), not by
        // the grid's own total n^2 sum(t^2): the anti-aliased edge cells (0 < t < 1) stand for the box-filtered
        // aperture, whose missing energy sum(t) - sum(t^2) is light diffracted beyond the grid's angular range
        // (about (2/3) dx / D of the total). Normalising by the grid total would push it into the core.
        for (double t : aperture.transmission) area += t;
    }
    PupilSpectrum spec;
    spec.n = n;
    spec.dx = aperture.dx;
    spec.power.assign(size_t(n) * n, 0.0);
    if (!(area > 0.0)) throw std::invalid_argument("glare: the aperture lets no light through");
    const double scale = 1.0 / (double(n) * n * area);
    for (int ky = 0; ky < n; ++ky) {
        for (int kx = 0; kx < n; ++kx) {
            // fftshift: zero frequency to (n/2, n/2).
            spec.power[size_t((ky + n / 2) % n) * n + (kx + n / 2) % n] = scale * std::norm(field[size_t(ky) * n + kx]);
        }
    }
    return spec;
}

namespace {

// The pupil's power spectrum on the grid chosen for wavelengths [lambda_lo,
// lambda_hi], and an empty kernel of that grid's radius.
struct KernelStart {
    PupilSpectrum spec;
    GlareKernel kernel;
};

KernelStart start_kernel(const GlareOptions& options, double pixel_angle, double lambda_lo, double lambda_hi) {
    const GridChoice grid = choose_grid(options, pixel_angle, lambda_lo, lambda_hi);
    KernelStart start{pupil_power_spectrum(make_pupil_aperture(options, options.grid_size, grid.dx)), GlareKernel{}};
    start.kernel.radius = grid.radius;
    start.kernel.pixel_angle = pixel_angle;
    start.kernel.grid_dx = grid.dx;
    return start;
}

}  // namespace

GlareKernel glare_kernel_mono(const GlareOptions& options, double pixel_angle, double wavelength_m) {
    check_options(options, pixel_angle);
    if (!(wavelength_m >= 300e-9 && wavelength_m <= 1000e-9))
        throw std::invalid_argument("glare: wavelength must be in [300, 1000] nm");
    KernelStart start = start_kernel(options, pixel_angle, wavelength_m, wavelength_m);
    const PupilSpectrum& spec = start.spec;
    const BilinearIntegrator integ(spec.power, spec.n);
    GlareKernel& k = start.kernel;
    const int size = k.size();
    std::vector<double> w(size_t(size) * size, 0.0);
    accumulate_pixel_integrals(integ, spec.n, spec.dx, k.radius, pixel_angle, wavelength_m, 1.0, w);
    const double captured = conserve_energy(w, k.radius);
    for (int c = 0; c < 3; ++c) {
        k.weights[c] = w;
        k.captured[c] = captured;
        k.negative_clamped[c] = 0.0;
    }
    return std::move(k);
}

GlareKernel glare_kernel_rgb(const GlareOptions& options, double pixel_angle) {
    check_options(options, pixel_angle);
    KernelStart start = start_kernel(options, pixel_angle, kLambdaMin, kLambdaMax);
    const PupilSpectrum& spec = start.spec;
    const BilinearIntegrator integ(spec.power, spec.n);
    GlareKernel& k = start.kernel;
    const int size = k.size();
    const size_t count = size_t(size) * size;
    // XYZ kernels of an equal-energy spectrum (trapezoid rule over 380-780 nm); the per-wavelength pixel
    // integrals are each unit-energy PSFs (before truncation), so their weighted sums carry the CMF integrals.
    std::array<std::vector<double>, 3> xyz;
    for (auto& v : xyz) v.assign(count, 0.0);
    std::array<double, 3> xyz_total{0.0, 0.0, 0.0};
    const int steps = std::max(1, static_cast<int>(std::lround(400.0 / options.wavelength_step_nm)));
    std::vector<double> mono(count);
    for (int s = 0; s <= steps; ++s) {
        const double nm = 380.0 + 400.0 * s / steps;
        const double trap = (s == 0 || s == steps) ? 0.5 : 1.0;
        const std::array<double, 3> cmf = cie1931_xyz(nm);
        std::fill(mono.begin(), mono.end(), 0.0);
        accumulate_pixel_integrals(integ, spec.n, spec.dx, k.radius, pixel_angle, nm * 1e-9, 1.0, mono);
        for (int c = 0; c < 3; ++c) {
            const double w = trap * cmf[c];
            xyz_total[c] += w;
            for (size_t i = 0; i < count; ++i) xyz[c][i] += w * mono[i];
        }
    }
    // The full (untruncated) PSF at every wavelength has unit energy: the RGB of the whole pattern is
    // M * xyz_total. The captured fraction per channel compares the kernel's RGB with it.
    const std::array<double, 3> rgb_total = xyz_to_linear_srgb(xyz_total);
    for (int c = 0; c < 3; ++c) k.weights[c].assign(count, 0.0);
    std::array<double, 3> negative{0.0, 0.0, 0.0}, raw_sum{0.0, 0.0, 0.0};
    for (size_t i = 0; i < count; ++i) {
        const std::array<double, 3> rgb = xyz_to_linear_srgb({xyz[0][i], xyz[1][i], xyz[2][i]});
        for (int c = 0; c < 3; ++c) {
            raw_sum[c] += rgb[c];
            if (rgb[c] < 0.0) {
                negative[c] -= rgb[c];
            } else {
                k.weights[c][i] = rgb[c];
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        for (double& v : k.weights[c]) v /= rgb_total[c];
        k.negative_clamped[c] = negative[c] / rgb_total[c];
        conserve_energy(k.weights[c], k.radius);
        k.captured[c] = raw_sum[c] / rgb_total[c];
    }
    return std::move(k);
}

namespace {

// The kernel's spectrum on a px x py grid, per channel py rows x (px / 2 + 1) columns (the other columns follow
// by the conjugate symmetry of a real kernel's transform), scaled by 1 / (px py): the inverse transforms of the
// convolution are left unnormalised.
struct KernelSpectrum {
    int px = 0, py = 0, radius = 0;
    std::array<std::vector<double>, 3> weights;  // the kernel it was made from (the cache key)
    std::array<std::vector<cd>, 3> spectrum;
    size_t bytes() const { return 3 * spectrum[0].size() * sizeof(cd); }
};

// Forward FFTs of `count` real rows of length px, two per complex transform (real-input trick, e.g. Press et
// al., Numerical Recipes, section 12.3): with Z = FFT(a + i b), the half spectra of the real rows a and b are
// A_k = (Z_k + conj Z_(px-k)) / 2 and B_k = (Z_k - conj Z_(px-k)) / (2 i), k = 0 .. px / 2.
// fill(t, dst) writes real row t at dst[0], dst[2], ... (zeroed beforehand); dest(t) is where its
// px / 2 + 1 coefficients go.
template <class Fill, class Dest>
void forward_real_rows(int count, int px, int threads, const Fill& fill, const Dest& dest) {
    const FftPlan& plan = get_plan(px);
    const int hx = px / 2 + 1;
    const auto pairs = [&](int begin, int end) {
        std::vector<cd> z(px), work(px);
        double* line = reinterpret_cast<double*>(z.data());  // std::complex<double> is an array of two doubles
        for (int pair = begin; pair < end; ++pair) {
            const int ta = 2 * pair, tb = ta + 1;
            std::fill(z.begin(), z.end(), cd(0.0, 0.0));
            fill(ta, line);
            if (tb < count) fill(tb, line + 1);
            run_plan<false>(plan, z.data(), work.data(), 1);
            cd* a = dest(ta);
            cd* b = tb < count ? dest(tb) : nullptr;
            for (int k = 0; k < hx; ++k) {
                const cd zk = z[k], zm = std::conj(z[k == 0 ? 0 : px - k]);
                a[k] = 0.5 * (zk + zm);
                if (b) b[k] = cd(0.5 * (zk.imag() - zm.imag()), -0.5 * (zk.real() - zm.real()));  // (zk - zm) / 2i
            }
        }
    };
    numerics::parallel_for_chunks((count + 1) / 2, pairs, threads);
}

// Inverse of forward_real_rows (unnormalised): row t's half spectrum at src(t), its px real values handed to
// sink(t, src, 2) as values src[0], src[2], ...; two rows per transform, Z_k = A_k + i B_k with
// A_(px-k) = conj A_k.
template <class Src, class Sink>
void inverse_real_rows(int count, int px, int threads, const Src& src, const Sink& sink) {
    const FftPlan& plan = get_plan(px);
    const int hx = px / 2 + 1;
    const auto pairs = [&](int begin, int end) {
        std::vector<cd> z(px), work(px), zero(hx);
        const double* line = reinterpret_cast<const double*>(z.data());
        for (int pair = begin; pair < end; ++pair) {
            const int ta = 2 * pair, tb = ta + 1;
            const cd* a = src(ta);
            const cd* b = tb < count ? src(tb) : zero.data();
            for (int k = 0; k < hx; ++k) z[k] = cd(a[k].real() - b[k].imag(), a[k].imag() + b[k].real());
            for (int k = hx; k < px; ++k) {
                const int m = px - k;
                z[k] = cd(a[m].real() + b[m].imag(), b[m].real() - a[m].imag());
            }
            run_plan<true>(plan, z.data(), work.data(), 1);
            sink(ta, line);
            if (tb < count) sink(tb, line + 1);
        }
    };
    numerics::parallel_for_chunks((count + 1) / 2, pairs, threads);
}

// Per channel, the wrapped kernel K[(dy mod py), (dx mod px)] = sum of the taps k(dy, dx) falling there
// (taps collide only when 2 r + 1 > px or py; see convolve_fft_impl for why that is harmless), transformed.
std::shared_ptr<KernelSpectrum> compute_kernel_spectrum(const GlareKernel& kernel, int px, int py, int threads) {
    auto ks = std::make_shared<KernelSpectrum>();
    ks->px = px;
    ks->py = py;
    ks->radius = kernel.radius;
    ks->weights = kernel.weights;
    const int r = kernel.radius, size = kernel.size(), hx = px / 2 + 1;
    // The distinct padded rows the taps land on.
    std::vector<int> slot(py, -1), rows;
    for (int row = 0; row < size; ++row) {
        const int yy = ((row - r) % py + py) % py;
        if (slot[yy] < 0) {
            slot[yy] = static_cast<int>(rows.size());
            rows.push_back(yy);
        }
    }
    const int nrows = static_cast<int>(rows.size());
    // Wrapped real rows, per channel nrows x px.
    std::array<std::vector<double>, 3> wrapped;
    for (int c = 0; c < 3; ++c) {
        wrapped[c].assign(size_t(nrows) * px, 0.0);
        for (int row = 0; row < size; ++row) {
            double* dst = wrapped[c].data() + size_t(slot[((row - r) % py + py) % py]) * px;
            for (int col = 0; col < size; ++col) dst[((col - r) % px + px) % px] += kernel.at(c, row, col);
        }
        ks->spectrum[c].assign(size_t(py) * hx, cd(0.0, 0.0));
    }
    forward_real_rows(
        3 * nrows, px, threads,
        [&](int t, double* dst) {
            const double* s = wrapped[t / nrows].data() + size_t(t % nrows) * px;
            for (int x = 0; x < px; ++x) dst[2 * x] = s[x];
        },
        [&](int t) { return ks->spectrum[t / nrows].data() + size_t(rows[t % nrows]) * hx; });
    const FftPlan& plan = get_plan(py);
    const int blocks = (hx + kColumnBlock - 1) / kColumnBlock;
    const double scale = 1.0 / (double(px) * py);
    const auto column_blocks = [&](int begin, int end) {
        std::vector<cd> block(size_t(py) * kColumnBlock), work(block.size());
        for (int item = begin; item < end; ++item) {
            cd* s = ks->spectrum[item / blocks].data();
            const int xb = (item % blocks) * kColumnBlock, bw = std::min(kColumnBlock, hx - xb);
            for (int y = 0; y < py; ++y) std::copy_n(s + size_t(y) * hx + xb, bw, block.data() + size_t(y) * bw);
            run_plan<false>(plan, block.data(), work.data(), size_t(bw));
            for (int y = 0; y < py; ++y)
                for (int i = 0; i < bw; ++i) s[size_t(y) * hx + xb + i] = scale * block[size_t(y) * bw + i];
        }
    };
    numerics::parallel_for_chunks(3 * blocks, column_blocks, threads);
    return ks;
}

// A few recent kernel spectra (kernel content and padded size as the key), most recent first, under a mutex.
// The newest is always kept; older ones are dropped beyond 4 entries or 512 MB.
struct SpectrumCache {
    std::mutex mutex;
    std::list<std::shared_ptr<const KernelSpectrum>> entries;
    long long hits = 0, misses = 0;
};

SpectrumCache& spectrum_cache() {
    static SpectrumCache cache;
    return cache;
}

std::shared_ptr<const KernelSpectrum> kernel_spectrum(const GlareKernel& kernel, int px, int py, int threads) {
    SpectrumCache& cache = spectrum_cache();
    {
        std::lock_guard<std::mutex> lock(cache.mutex);
        for (auto it = cache.entries.begin(); it != cache.entries.end(); ++it) {
            const KernelSpectrum& e = **it;
            if (e.px == px && e.py == py && e.radius == kernel.radius && e.weights == kernel.weights) {
                ++cache.hits;
                cache.entries.splice(cache.entries.begin(), cache.entries, it);
                return cache.entries.front();
            }
        }
        ++cache.misses;
    }
    // Built outside the lock (two threads missing together both build it; both results are equal).
    std::shared_ptr<const KernelSpectrum> fresh = compute_kernel_spectrum(kernel, px, py, threads);
    std::lock_guard<std::mutex> lock(cache.mutex);
    cache.entries.push_front(fresh);
    size_t bytes = 0;
    for (const auto& e : cache.entries) bytes += e->bytes();
    while (cache.entries.size() > 1 && (cache.entries.size() > 4 || bytes > (size_t(512) << 20))) {
        bytes -= cache.entries.back()->bytes();
        cache.entries.pop_back();
    }
    return fresh;
}

// Linear convolution by circular convolution on a px x py grid, px >= w + r and py >= h + r (1-D argument,
// per axis, n the image size, P the padded size): the circular result at y in [0, n) is
//   sum over x in [0, n) and taps |d| <= r with d = y - x (mod P) of k(d) in(x).
// A term with d = y - x + j P, j != 0, needs |d| >= P - |y - x| >= P - (n - 1) >= r + 1 > r: no such tap.
// So only d = y - x contributes, the linear convolution with zero padding. This also holds when taps collide
// in the wrapped kernel (2 r + 1 > P): they are summed there, and only the one with d = y - x can pair with
// an in-image x. Output rows y >= h are never formed (only h rows are inverse-transformed).
// Steps: real rows of the 3 channels -> half spectra (two per complex FFT); per block of columns, forward
// column FFT, product with the cached kernel spectrum, inverse column FFT (kept in L2); inverse rows.
template <class T>
void convolve_fft_impl(const T* in, int w, int h, const GlareKernel& kernel, int threads, T* out) {
    const std::array<int, 2> grid = detail::glare_fft_grid(w, h, kernel.radius);
    const int px = grid[0], py = grid[1], hx = px / 2 + 1;
    const std::shared_ptr<const KernelSpectrum> ks = kernel_spectrum(kernel, px, py, threads);
    // Half spectra of the image rows, per channel h x hx (the padded rows h .. py - 1 are zero).
    std::array<std::vector<cd>, 3> spec;
    for (auto& s : spec) s.resize(size_t(h) * hx);
    forward_real_rows(
        3 * h, px, threads,
        [&](int t, double* dst) {
            const T* src = in + size_t(t % h) * w * 3 + t / h;
            for (int x = 0; x < w; ++x) dst[2 * x] = double(src[size_t(x) * 3]);
        },
        [&](int t) { return spec[t / h].data() + size_t(t % h) * hx; });
    const FftPlan& plan = get_plan(py);
    const int blocks = (hx + kColumnBlock - 1) / kColumnBlock;
    const auto column_blocks = [&](int begin, int end) {
        std::vector<cd> block(size_t(py) * kColumnBlock), work(block.size());
        for (int item = begin; item < end; ++item) {
            const int c = item / blocks, xb = (item % blocks) * kColumnBlock, bw = std::min(kColumnBlock, hx - xb);
            cd* s = spec[c].data();
            const cd* k = ks->spectrum[c].data();
            for (int y = 0; y < h; ++y) std::copy_n(s + size_t(y) * hx + xb, bw, block.data() + size_t(y) * bw);
            std::fill(block.begin() + size_t(h) * bw, block.begin() + size_t(py) * bw, cd(0.0, 0.0));
            run_plan<false>(plan, block.data(), work.data(), size_t(bw));
            for (int y = 0; y < py; ++y)
                for (int i = 0; i < bw; ++i) {
                    cd& v = block[size_t(y) * bw + i];
                    v = cmul(v, k[size_t(y) * hx + xb + i]);
                }
            run_plan<true>(plan, block.data(), work.data(), size_t(bw));
            for (int y = 0; y < h; ++y) std::copy_n(block.data() + size_t(y) * bw, bw, s + size_t(y) * hx + xb);
        }
    };
    numerics::parallel_for_chunks(3 * blocks, column_blocks, threads);
    inverse_real_rows(
        3 * h, px, threads, [&](int t) -> const cd* { return spec[t / h].data() + size_t(t % h) * hx; },
        [&](int t, const double* src) {
            T* dst = out + size_t(t % h) * w * 3 + t / h;
            for (int x = 0; x < w; ++x) dst[size_t(x) * 3] = static_cast<T>(src[2 * x]);
        });
}

void check_convolution_input(int w, int h, size_t values, const GlareKernel& kernel) {
    if (w < 1 || h < 1 || values != size_t(w) * h * 3)
        throw std::invalid_argument("glare: image size does not match its data");
    const size_t taps = size_t(kernel.size()) * kernel.size();
    if (kernel.radius < 0 || kernel.weights[0].size() != taps || kernel.weights[1].size() != taps ||
        kernel.weights[2].size() != taps)
        throw std::invalid_argument("glare: kernel weights do not match its radius");
}

}  // namespace

namespace detail {

std::array<int, 2> glare_fft_grid(int width, int height, int radius) {
    return {next_fft_size(width + radius), next_fft_size(height + radius)};
}

std::vector<double> convolve_glare_fft_rgb(const std::vector<double>& rgb, int width, int height,
                                           const GlareKernel& kernel, int threads) {
    check_convolution_input(width, height, rgb.size(), kernel);
    std::vector<double> out(rgb.size());
    convolve_fft_impl(rgb.data(), width, height, kernel, numerics::thread_count(threads), out.data());
    return out;
}

GlareSpectrumCacheStats glare_spectrum_cache_stats() {
    SpectrumCache& cache = spectrum_cache();
    std::lock_guard<std::mutex> lock(cache.mutex);
    return {cache.hits, cache.misses, static_cast<int>(cache.entries.size())};
}

}  // namespace detail

Image convolve_glare_fft(const Image& image, const GlareKernel& kernel, int threads) {
    check_convolution_input(image.width, image.height, image.rgb.size(), kernel);
    Image out{image.width, image.height, std::vector<float>(image.rgb.size())};
    convolve_fft_impl(image.rgb.data(), image.width, image.height, kernel, numerics::thread_count(threads),
                      out.rgb.data());
    return out;
}

Image convolve_glare_direct(const Image& image, const GlareKernel& kernel, int threads) {
    const int w = image.width, h = image.height, r = kernel.radius, ks = kernel.size();
    if (w < 1 || h < 1 || image.rgb.size() != size_t(w) * h * 3)
        throw std::invalid_argument("glare: image size does not match its data");
    Image out{w, h, std::vector<float>(size_t(w) * h * 3, 0.0f)};
    const auto rows = [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < 3; ++c) {
                    double sum = 0.0;
                    for (int row = 0; row < ks; ++row) {
                        const int sy = y - (row - r);
                        if (sy < 0 || sy >= h) continue;
                        for (int col = 0; col < ks; ++col) {
                            const int sx = x - (col - r);
                            if (sx < 0 || sx >= w) continue;
                            sum += kernel.at(c, row, col) * image.rgb[(size_t(sy) * w + sx) * 3 + c];
                        }
                    }
                    out.rgb[(size_t(y) * w + x) * 3 + c] = static_cast<float>(sum);
                }
    };
    numerics::parallel_for_chunks(h, rows, numerics::thread_count(threads));
    return out;
}

}  // namespace airlight
