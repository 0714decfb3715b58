// Eye glare (issue 8): the pupil's Fraunhofer PSF, spectral kernels and FFT
// convolution. See include/airlight/glare.hpp and docs/glare.md.
#include "airlight/glare.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace airlight {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLambdaMin = 380e-9;
constexpr double kLambdaMax = 780e-9;

int resolve_threads(int threads) {
    if (threads > 0) return threads;
    const unsigned hw = std::thread::hardware_concurrency();
    return hw == 0 ? 1 : static_cast<int>(hw);
}

// Runs body(begin, end) over [0, count) split into contiguous chunks.
template <class F>
void parallel_for(int count, int threads, const F& body) {
    threads = std::max(1, std::min(threads, count));
    if (threads == 1) {
        body(0, count);
        return;
    }
    std::vector<std::thread> pool;
    pool.reserve(threads);
    for (int t = 0; t < threads; ++t) {
        const int begin = static_cast<int>(static_cast<long long>(count) * t / threads);
        const int end = static_cast<int>(static_cast<long long>(count) * (t + 1) / threads);
        pool.emplace_back([&body, begin, end] { body(begin, end); });
    }
    for (std::thread& th : pool) th.join();
}

bool is_pow2(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Wyman, Sloan & Shirley 2013, piecewise Gaussian lobe.
double lobe(double x, double mu, double sigma_lo, double sigma_hi) {
    const double t = (x - mu) / (x < mu ? sigma_lo : sigma_hi);
    return std::exp(-0.5 * t * t);
}

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

// Adds the pixel integrals of the PSF at `lambda` (energy per pixel), times
// weight, into out ((2r + 1)^2 values).
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
            const double x0 = c0 + (u - 0.5) * cells, x1 = c0 + (u + 0.5) * cells;
            // Clamped: the prefiltered interpolant may dip a little below 0 inside a dark ring.
            out[size_t(row) * size + col] += weight * std::max(0.0, integ.integrate(x0, x1, y0, y1));
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

}  // namespace

namespace detail {

int next_pow2(int n) {
    int p = 1;
    while (p < n) p <<= 1;
    return p;
}

void fft(std::vector<std::complex<double>>& data, bool inverse) {
    const size_t n = data.size();
    if (n <= 1) return;
    if ((n & (n - 1)) != 0) throw std::invalid_argument("fft: size must be a power of two");
    for (size_t i = 1, j = 0; i < n; ++i) {
        size_t bit = n >> 1;
        for (; j & bit; bit >>= 1) j ^= bit;
        j ^= bit;
        if (i < j) std::swap(data[i], data[j]);
    }
    const double sign = inverse ? 1.0 : -1.0;
    for (size_t len = 2; len <= n; len <<= 1) {
        const size_t half = len / 2;
        // Twiddles computed directly (not by repeated multiplication) to keep the error near 1e-16.
        std::vector<std::complex<double>> tw(half);
        for (size_t k = 0; k < half; ++k) {
            const double a = sign * 2.0 * kPi * double(k) / double(len);
            tw[k] = {std::cos(a), std::sin(a)};
        }
        for (size_t i = 0; i < n; i += len) {
            for (size_t k = 0; k < half; ++k) {
                const std::complex<double> u = data[i + k];
                const std::complex<double> t = data[i + k + half] * tw[k];
                data[i + k] = u + t;
                data[i + k + half] = u - t;
            }
        }
    }
    if (inverse) {
        const double s = 1.0 / double(n);
        for (auto& z : data) z *= s;
    }
}

void fft2d(std::vector<std::complex<double>>& data, int nx, int ny, bool inverse, int threads) {
    if (!is_pow2(nx) || !is_pow2(ny) || data.size() != size_t(nx) * ny)
        throw std::invalid_argument("fft2d: sizes must be powers of two matching the data");
    threads = resolve_threads(threads);
    parallel_for(ny, threads, [&](int begin, int end) {
        std::vector<std::complex<double>> line(nx);
        for (int y = begin; y < end; ++y) {
            std::copy(data.begin() + size_t(y) * nx, data.begin() + size_t(y + 1) * nx, line.begin());
            fft(line, inverse);
            std::copy(line.begin(), line.end(), data.begin() + size_t(y) * nx);
        }
    });
    parallel_for(nx, threads, [&](int begin, int end) {
        std::vector<std::complex<double>> line(ny);
        for (int x = begin; x < end; ++x) {
            for (int y = 0; y < ny; ++y) line[y] = data[size_t(y) * nx + x];
            fft(line, inverse);
            for (int y = 0; y < ny; ++y) data[size_t(y) * nx + x] = line[y];
        }
    });
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

std::array<double, 3> cie1931_xyz(double nm) {
    const double x =
        1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) - 0.065 * lobe(nm, 501.1, 20.4, 26.2);
    const double y = 0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1);
    const double z = 1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8);
    return {x, y, z};
}

std::array<double, 3> xyz_to_linear_srgb(const std::array<double, 3>& c) {
    return {3.2404542 * c[0] - 1.5371385 * c[1] - 0.4985314 * c[2],
            -0.9692660 * c[0] + 1.8760108 * c[1] + 0.0415560 * c[2],
            0.0556434 * c[0] - 0.2040259 * c[1] + 1.0572252 * c[2]};
}

PupilAperture make_pupil_aperture(const GlareOptions& options, int n, double dx) {
    validate_pupil_diameter(options.pupil_diameter_mm);
    if (n < 2 || !(dx > 0.0)) throw std::invalid_argument("glare: aperture grid must have n >= 2 and dx > 0");
    const double radius = 0.5e-3 * options.pupil_diameter_mm;
    // Eyelashes (docs/glare.md): straight opaque strips hanging from above the pupil, anchored on its top edge
    // at x evenly spread over [-0.6 R, 0.6 R], fanned outwards up to 20 degrees from vertical, reaching down
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
    ap.transmission.assign(size_t(n) * n, 0.0);
    const double half_diag = dx * std::sqrt(0.5);
    constexpr int kSub = 16;  // supersampling of cells cut by an edge
    for (int iy = 0; iy < n; ++iy) {
        const double y = (iy - n / 2) * dx;
        for (int ix = 0; ix < n; ++ix) {
            const double x = (ix - n / 2) * dx;
            const double r = std::hypot(x, y);
            if (r > radius + half_diag) continue;
            const bool edge = r > radius - half_diag || near_lash(x, y, half_diag);
            double t;
            if (!edge) {
                t = 1.0;
            } else {
                int inside = 0;
                for (int sy = 0; sy < kSub; ++sy) {
                    const double yy = y + ((sy + 0.5) / kSub - 0.5) * dx;
                    for (int sx = 0; sx < kSub; ++sx) {
                        const double xx = x + ((sx + 0.5) / kSub - 0.5) * dx;
                        if (xx * xx + yy * yy <= radius * radius && !opaque_lash(xx, yy)) ++inside;
                    }
                }
                t = double(inside) / (kSub * kSub);
            }
            ap.transmission[size_t(iy) * n + ix] = t;
        }
    }
    return ap;
}

PupilSpectrum pupil_power_spectrum(const PupilAperture& aperture) {
    const int n = aperture.n;
    if (!is_pow2(n)) throw std::invalid_argument("glare: aperture grid size must be a power of two");
    std::vector<std::complex<double>> field(aperture.transmission.begin(), aperture.transmission.end());
    detail::fft2d(field, n, n, false, 0);
    PupilSpectrum spec;
    spec.n = n;
    spec.dx = aperture.dx;
    spec.power.assign(size_t(n) * n, 0.0);
    // Normalised by the light through the pupil, n^2 sum(t) (Parseval, for the true 0/1 aperture), not by the
    // grid's own total n^2 sum(t^2): the anti-aliased edge cells (0 < t < 1) stand for the box-filtered
    // aperture, whose missing energy sum(t) - sum(t^2) is light diffracted beyond the grid's angular range
    // (about (2/3) dx / D of the total). Normalising by the grid total would push it into the core.
    double area = 0.0;
    for (double t : aperture.transmission) area += t;
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

Image convolve_glare_fft(const Image& image, const GlareKernel& kernel, int threads) {
    const int w = image.width, h = image.height, r = kernel.radius, ks = kernel.size();
    if (w < 1 || h < 1 || image.rgb.size() != size_t(w) * h * 3)
        throw std::invalid_argument("glare: image size does not match its data");
    threads = resolve_threads(threads);
    const int px = detail::next_pow2(w + 2 * r), py = detail::next_pow2(h + 2 * r);
    const size_t total = size_t(px) * py;
    Image out{w, h, std::vector<float>(size_t(w) * h * 3, 0.0f)};
    // Two real channels per complex transform: z = a + i b. With the spectra A, B of a, b recovered from Z by
    // conjugate symmetry, the product A Ka + i B Kb transforms back to conv(a, ka) + i conv(b, kb).
    // Kernels: ka + i kb likewise, with ka centred at index (0, 0) (wrapped).
    const int pairs[2][2] = {{0, 1}, {2, -1}};
    std::vector<std::complex<double>> z(total), kz(total);
    for (const auto& pair : pairs) {
        const int ca = pair[0], cb = pair[1];
        std::fill(z.begin(), z.end(), std::complex<double>(0.0, 0.0));
        std::fill(kz.begin(), kz.end(), std::complex<double>(0.0, 0.0));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float* p = &image.rgb[(size_t(y) * w + x) * 3];
                z[size_t(y) * px + x] = {double(p[ca]), cb >= 0 ? double(p[cb]) : 0.0};
            }
        for (int row = 0; row < ks; ++row)
            for (int col = 0; col < ks; ++col) {
                const int yy = (row - r + py) % py, xx = (col - r + px) % px;
                kz[size_t(yy) * px + xx] = {kernel.at(ca, row, col), cb >= 0 ? kernel.at(cb, row, col) : 0.0};
            }
        detail::fft2d(z, px, py, false, threads);
        detail::fft2d(kz, px, py, false, threads);
        std::vector<std::complex<double>> prod(total);
        parallel_for(py, threads, [&](int begin, int end) {
            const std::complex<double> half(0.5, 0.0), minus_half_i(0.0, -0.5), i_unit(0.0, 1.0);
            for (int ky = begin; ky < end; ++ky) {
                const int my = (py - ky) % py;
                for (int kx = 0; kx < px; ++kx) {
                    const int mx = (px - kx) % px;
                    const size_t idx = size_t(ky) * px + kx, midx = size_t(my) * px + mx;
                    const std::complex<double> zc = std::conj(z[midx]), kc = std::conj(kz[midx]);
                    const std::complex<double> a = half * (z[idx] + zc), b = minus_half_i * (z[idx] - zc);
                    const std::complex<double> ka = half * (kz[idx] + kc), kb = minus_half_i * (kz[idx] - kc);
                    prod[idx] = a * ka + i_unit * (b * kb);
                }
            }
        });
        detail::fft2d(prod, px, py, true, threads);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::complex<double> v = prod[size_t(y) * px + x];
                float* o = &out.rgb[(size_t(y) * w + x) * 3];
                o[ca] = static_cast<float>(v.real());
                if (cb >= 0) o[cb] = static_cast<float>(v.imag());
            }
    }
    return out;
}

Image convolve_glare_direct(const Image& image, const GlareKernel& kernel, int threads) {
    const int w = image.width, h = image.height, r = kernel.radius, ks = kernel.size();
    if (w < 1 || h < 1 || image.rgb.size() != size_t(w) * h * 3)
        throw std::invalid_argument("glare: image size does not match its data");
    Image out{w, h, std::vector<float>(size_t(w) * h * 3, 0.0f)};
    parallel_for(h, resolve_threads(threads), [&](int begin, int end) {
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
    });
    return out;
}

double glare_change_bound(const Image& image, const GlareKernel& kernel) {
    std::array<double, 3> vmax{0.0, 0.0, 0.0};
    for (size_t i = 0; i < image.rgb.size(); ++i) vmax[i % 3] = std::max(vmax[i % 3], std::abs(double(image.rgb[i])));
    double bound = 0.0;
    for (int c = 0; c < 3; ++c) bound = std::max(bound, vmax[c] * (1.0 - kernel.centre(c)));
    return bound;
}

bool glare_needed(const Image& image, const GlareKernel& kernel, double display_white, double tolerance) {
    return glare_change_bound(image, kernel) > tolerance * display_white;
}

}  // namespace airlight
