// Lorenz-Mie scattering by a homogeneous sphere (issue 7 groundwork;
// effects/rainbow/physics.md section 2): the series of Bohren & Huffman (1983, chapter 4 and BHMIE) with
// Wiscombe's (1980) number of terms and the downward recurrence of the
// logarithmic derivative, in double precision. The raindrop phase tables of
// the rainbow issue are to be built from it; effects/rainbow/tests/test_mie.cpp checks it
// against published values, limits and the independent numpy reference
// (effects/rainbow/tests/mie_reference.py).
#pragma once

#include <complex>
#include <vector>

namespace airlight {

// The external-field coefficients a_n, b_n (n = 1..N) of a sphere of relative
// refractive index m (Im m >= 0 absorbs) and size parameter x = pi D / lambda.
struct MieCoefficients {
    double x = 0.0;
    std::vector<std::complex<double>> a, b;
};

// N = x + 4.05 x^(1/3) + 2 (Wiscombe).
int mie_term_count(double x);

MieCoefficients mie_coefficients(std::complex<double> m, double x);

// Efficiencies for extinction and scattering (cross-section / pi r^2).
struct MieEfficiencies {
    double extinction = 0.0;
    double scattering = 0.0;
};
MieEfficiencies mie_efficiencies(const MieCoefficients& c);

// The amplitudes S1, S2 at the scattering angles theta (radians, 0 forward).
void mie_amplitudes(const MieCoefficients& c, const std::vector<double>& theta, std::vector<std::complex<double>>& s1,
                    std::vector<std::complex<double>>& s2);

// The phase function for unpolarised light, normalised to 1 over the sphere:
// (|S1|^2 + |S2|^2) / (2 pi x^2 Q_sca).
std::vector<double> mie_phase_function(std::complex<double> m, double x, const std::vector<double>& theta);

}  // namespace airlight
