// Physically based glare of the eye (issue 8, effects/display/physics.md): the
// Fraunhofer point spread function of the pupil (optionally obstructed by
// eyelashes), per wavelength, combined through the CIE 1931 colour matching
// functions into one kernel per linear sRGB channel, resampled onto the
// image's angular pixel grid by integrating the PSF over each pixel, and
// applied to linear radiance by FFT convolution. Derivation and measured
// numbers: effects/display/docs/glare.md.
#pragma once

#include <array>
#include <complex>
#include <vector>

#include "airlight/colour.hpp"
#include "airlight/renderer.hpp"

namespace airlight {

// The field that names the pupil diameter in error messages.
inline constexpr const char* kPupilDiameterField = "display.glare.pupil_diameter";

// Throws std::invalid_argument("display.glare.pupil_diameter: must be in [1, 9] mm (got X)")
// unless 1 <= diameter_mm <= 9 (NaN included).
void validate_pupil_diameter(double diameter_mm);

// Light-adapted pupil diameter (mm) from the adaptation luminance (cd/m^2),
// Moon & Spencer 1944 (JOSA 34, 319): D = 4.9 - 3 tanh(0.4 log10 B) with B in
// millilamberts (B = L pi / 10 for L in cd/m^2); ranges over 1.9 to 7.9 mm.
// Throws std::invalid_argument naming "display.glare.adaptation_luminance"
// unless the luminance is finite and > 0.
double pupil_diameter_from_luminance(double luminance_cd_m2);

// Angle (radians) subtended by the central pixel of a pinhole camera with the
// full vertical field of view fov_y_deg over `height` rows:
// 2 tan(fov_y / 2) / height (fov_y / height is a few percent smaller at wide fovs).
double camera_pixel_angle(double fov_y_deg, int height);

struct GlareOptions {
    double pupil_diameter_mm = 4.0;  // [1, 9]
    bool eyelashes = false;
    int eyelash_count = 5;            // thin opaque strips across the upper pupil
    double eyelash_width_mm = 0.08;   // strip width in the pupil plane
    int grid_size = 1024;             // aperture / FFT grid N (power of two, >= 64)
    int max_kernel_radius = 64;       // the kernel is (2r + 1)^2 pixels, r <= this
    double wavelength_step_nm = 5.0;  // spectral integration step over 380-780 nm
};

// The pupil's transmission on an N x N grid of spacing dx (m): cell (ix, iy)
// is centred at ((ix - N/2) dx, (iy - N/2) dx), y up; values are the covered
// fraction of each cell (anti-aliased edges), 0 under an eyelash.
// disc_radius > 0 (make_pupil_aperture): the aperture is that clear disc minus `lashes` (the fraction of each
// cell inside the disc that eyelashes shade; empty without lashes), and pupil_power_spectrum takes the disc's
// transform exactly (effects/display/physics.md section 3) and only the lashes' by FFT. disc_radius 0: the
// transmission alone, by FFT.
struct PupilAperture {
    int n = 0;
    double dx = 0.0;
    std::vector<double> transmission;  // n * n, row iy, column ix
    double disc_radius = 0.0;          // m
    std::vector<double> lashes;        // n * n or empty
};
PupilAperture make_pupil_aperture(const GlareOptions& options, int n, double dx);

// |FT(aperture)|^2 on the FFT's frequency grid, zero frequency at index
// (n/2, n/2), each value the fraction of the light through the pupil that
// falls in its cell (normalised by the pupil's area, so the grid holds a
// little less than 1: the rest, about (2/3) dx / D, is diffracted beyond the
// grid's angular range lambda / (2 dx)). At wavelength lambda cell k sits
// at angle theta = lambda (k - n/2) / (n dx): the same array serves every
// wavelength (Fraunhofer diffraction of a wavelength-independent aperture).
struct PupilSpectrum {
    int n = 0;
    double dx = 0.0;
    std::vector<double> power;  // n * n
    double angle_step(double wavelength_m) const { return wavelength_m / (n * dx); }
};
PupilSpectrum pupil_power_spectrum(const PupilAperture& aperture);

// The window of the kernel's round support at distance rho (pixels) from its centre (physics.md section 3,
// "Support"): 1 up to half the rim radius + 1/2, then cos^2 down to 0 at the rim; 0 beyond. The kernel's
// values are the PSF's pixel integrals times this window, so the glare is round and fades out smoothly.
double glare_support_window(double rho, int radius);

// One kernel per linear sRGB channel, (2 radius + 1)^2 values each, row 0 on
// top, the centre at (radius, radius); each channel sums to 1. Only the pixels
// whose centres lie within radius + 1/2 of the centre are nonzero (a disc).
struct GlareKernel {
    int radius = 0;
    double pixel_angle = 0.0;  // radians
    std::array<std::vector<double>, 3> weights;
    // PSF energy inside the kernel (through its window) before normalising (1 - truncation). Normalising keeps the
    // central pixel's exact integral and scales the off-centre weights up by the missing energy, which leaves the
    // centre.
    std::array<double, 3> captured{};
    std::array<double, 3> negative_clamped{};  // |negative weight| removed (XYZ->RGB), relative to the sum
    double grid_dx = 0.0;                      // aperture sampling used (m)
    int size() const { return 2 * radius + 1; }
    double at(int c, int row, int col) const { return weights[c][static_cast<size_t>(row) * size() + col]; }
    double centre(int c) const { return at(c, radius, radius); }
};

// Monochromatic kernel at wavelength_m (all three channels equal). Each
// kernel value is the integral of the PSF over the pixel's angular square
// (pixel_angle radians on a side), so when the Airy core is smaller than a
// pixel the central pixel holds the core's energy.
GlareKernel glare_kernel_mono(const GlareOptions& options, double pixel_angle, double wavelength_m);

// Spectral kernel: the PSF of an equal-energy white point source, integrated
// over 380-780 nm weighted by the CIE 1931 functions, converted to linear
// sRGB, negative weights clamped to 0, each channel normalised to sum 1.
GlareKernel glare_kernel_rgb(const GlareOptions& options, double pixel_angle);

// Convolution of linear RGB radiance by the kernel, per channel, with zero
// padding (light falling beyond the border is lost, none wraps around).
// threads <= 0: hardware concurrency. The FFT version works in double
// precision on a (w + r) x (h + r) grid rounded up to 2^a 3^b 5^c, and keeps
// the last few kernel spectra (keyed by kernel and grid) for the next call.
Image convolve_glare_fft(const Image& image, const GlareKernel& kernel, int threads = 0);
Image convolve_glare_direct(const Image& image, const GlareKernel& kernel, int threads = 0);

// Internal pieces, exposed for the tests.
namespace detail {
// In-place mixed-radix FFT (Stockham autosort, radices 4, 2, 3, 5); the size
// must be a product of 2, 3 and 5 (std::invalid_argument otherwise). Forward:
// X_k = sum_n x_n exp(-2 pi i k n / N); inverse includes the 1/N.
void fft(std::vector<std::complex<double>>& data, bool inverse);
// 2-D FFT of a row-major ny x nx array (both products of 2, 3 and 5), rows then columns.
void fft2d(std::vector<std::complex<double>>& data, int nx, int ny, bool inverse, int threads = 1);
int next_pow2(int n);
// n > 0 with no prime factor other than 2, 3 and 5.
bool is_fft_size(int n);
// Smallest 2^a 3^b 5^c >= n.
int next_fft_size(int n);
// The padded grid {px, py} of convolve_glare_fft: next_fft_size(width + radius), next_fft_size(height + radius).
std::array<int, 2> glare_fft_grid(int width, int height, int radius);
// convolve_glare_fft on interleaved RGB doubles (width * height * 3), output in double.
std::vector<double> convolve_glare_fft_rgb(const std::vector<double>& rgb, int width, int height,
                                           const GlareKernel& kernel, int threads = 0);
// Kernel spectrum cache counters since the start of the process.
struct GlareSpectrumCacheStats {
    long long hits = 0, misses = 0;
    int entries = 0;
};
GlareSpectrumCacheStats glare_spectrum_cache_stats();
}  // namespace detail

}  // namespace airlight
