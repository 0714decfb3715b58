// Rainbows (issue 7; effects/rainbow/physics.md): the raindrops' phase function seen
// through the sun's disc, averaged over the Marshall-Palmer drop sizes, per
// wavelength, and turned into the linear-sRGB table the renderer reads.
//
// Two stages (effects/rainbow/docs/rainbow.md explains the choices and the measured errors):
//  1. The spectral table (rainbow_spectral_table): for 33 wavelengths, 14
//     rainfall rates and an angle grid refined near the bows, computed from the
//     Lorenz-Mie series (mie.cpp) by Monte-Carlo integration over drop size and
//     the sun's disc. It takes minutes, so it is computed once
//     (build/cpp/make_rainbow_table) into effects/rainbow/rainbow_phase.bin, which is
//     embedded into the library; the sampling's standard error is stored too.
//  2. The renderer's table (rainbow_phase_table): per scene, interpolated in
//     log rate, converted to linear sRGB through the CIE 1931 colour-matching
//     functions (airlight/colour.hpp) and resampled uniformly in angle: milliseconds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tables.hpp"

namespace airlight {

// ---- The spectral table's grids ------------------------------------------
// Wavelengths 380 + 10.625 i nm (i = 0..32): 33 nodes, so that 17, 9, 5 and 3
// of them are also evenly spaced (the colour-convergence measurement: each
// halving of the spacing cuts the colour error about fourfold; 33 nodes are
// within about 3 % of the converged bow, effects/rainbow/docs/rainbow.md).
constexpr int RAINBOW_WAVELENGTHS = 33;
double rainbow_wavelength_nm(int i);
// Rates 0.1 * 2^k mm/h (k = 0..13, up to 819.2); others are interpolated in
// log rate, and clamped to the ends.
constexpr int RAINBOW_RATES = 14;
double rainbow_rate(int k);
// Scattering angles in degrees: every 0.05 degree in [0, 3] (the aureole) and
// [118, 146] (both bows and the dark band) and [178, 180] (the glory), every
// 0.5 degree elsewhere.
std::vector<double> rainbow_angles_deg();

// Drop diameters in mm (effects/daytime/physics.md: raindrops of 0.1 to 3.5 mm).
constexpr double RAINDROP_D_MIN_MM = 0.1;
constexpr double RAINDROP_D_MAX_MM = 3.5;
// The sun's mean angular radius, degrees.
constexpr double SUN_ANGULAR_RADIUS_DEG = 0.2665;

// Marshall-Palmer slope Lambda = 4.1 R^-0.21 per mm (effects/daytime/physics.md).
double marshall_palmer_slope(double rate_mm_per_h);

// Refractive index of fresh water at 20 C (Quan & Fry 1995, Appl. Opt. 34,
// 3477; fitted over 400-700 nm, used here over 380-720 nm).
double water_refractive_index(double wavelength_nm);

// ---- Stage 1: the spectral table ------------------------------------------
struct RainbowSpectralTable {
    std::vector<double> wavelengths_nm, rates, angles_deg;
    int samples_per_wavelength = 0;
    // phase[(k * n_wavelengths + i) * n_angles + a]: sr^-1, normalised to 1
    // over the sphere (as a Monte-Carlo estimate); rel_error: its standard
    // error relative to the value (batch means).
    std::vector<float> phase, rel_error;
    float at(int rate, int wavelength, int angle) const {
        return phase[(size_t(rate) * wavelengths_nm.size() + size_t(wavelength)) * angles_deg.size() + size_t(angle)];
    }
};

struct RainbowSampling {
    int samples_per_wavelength = 4096;  // drop-size and sun-disc samples
    std::uint64_t seed = 1;
    int threads = 0;               // 0: all hardware threads
    std::vector<int> wavelengths;  // indices to compute (empty: all)
    // Only the grid's angles in this range (degrees), for refining a table.
    double angle_min_deg = 0.0, angle_max_deg = 180.0;
};
RainbowSpectralTable compute_rainbow_spectral_table(const RainbowSampling& sampling);
// Rescales the forward aureole (below 1 degree) of each rate and wavelength so
// that the phase integrates to exactly 1 over the sphere: the sampling's noise
// in that integral is almost all there (compute_rainbow_spectral_table calls it).
// A table that does not span 0-180 degrees is left as it is.
void normalise_rainbow_aureole(RainbowSpectralTable& table);

std::vector<char> serialize_rainbow_table(const RainbowSpectralTable& table);
RainbowSpectralTable parse_rainbow_table(const std::vector<char>& bytes);  // throws std::runtime_error
// The table embedded into the library (effects/rainbow/rainbow_phase.bin).
const RainbowSpectralTable& rainbow_spectral_table();

// One drop's phase function seen through the sun's disc, by a deterministic
// product rule over the disc (n_radial x 4 n_radial points): for tests and the
// convergence analysis.
std::vector<double> mie_sun_disc_phase(double refractive_index, double diameter_mm, double wavelength_nm,
                                       const std::vector<double>& angles_deg, int n_radial = 12);

// The phase function of drops with N(D) ~ exp(-slope D) on [d_min, d_max]
// (mm; Marshall-Palmer: slope = marshall_palmer_slope(rate) on [RAINDROP_D_MIN_MM,
// RAINDROP_D_MAX_MM]) at a point (no sun disc), by a deterministic rule
// independent of the table's Monte Carlo: midpoint rule with n_sizes
// diameters evenly spaced in log D (tests and effects/rainbow/docs/rainbow.md).
struct DropSizes {
    double slope_per_mm = 0.0, d_min_mm = RAINDROP_D_MIN_MM, d_max_mm = RAINDROP_D_MAX_MM;
};
std::vector<double> mie_size_average_phase(const DropSizes& sizes, double wavelength_nm,
                                           const std::vector<double>& angles_deg, int n_sizes);

// ---- Stage 2: the renderer's table ----------------------------------------
// Linear-sRGB weights of each spectral node (CIE 1931 2-degree observer, D65
// sun spectrum, band integrals of the node's hat function), normalised so
// that each channel's weights sum to 1: a phase function that does not depend
// on wavelength gives the same value in R, G and B. `count`: 33, 17, 9, 5 or 3
// nodes (every 32 / (count - 1)-th).
std::vector<float> rainbow_rgb_weights(int count);
// The node counts the table supports: 3, 5, 9, 17 and 33 (evenly spaced
// subsets of the 33 nodes).
bool is_rainbow_wavelength_count(int count);
constexpr const char* RAINBOW_WAVELENGTH_COUNTS = "3, 5, 9, 17 or 33";

// Uniform angle axis of the renderer's table (constants.glsl).
// Texel a holds the phase at a * 180 / (RAINBOW_TABLE_N - 1) degrees, RGB in
// the first three channels of RGBA.
const Table2D& rainbow_phase_table(double rate_mm_per_h, int wavelength_count);

// The spectral phase at a rate (interpolated in log rate) for wavelength node i.
std::vector<double> rainbow_spectral_phase(double rate_mm_per_h, int wavelength);

}  // namespace airlight
