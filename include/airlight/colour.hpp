// Colour science shared by the glare kernels and the rainbow's colours: the
// CIE 1931 2-degree colour-matching functions and the D65 illuminant (the CIE
// tables at 1 nm, 380-780 nm, as the colour-science package holds them:
// cpp/cie_tables.inc, written by tools/make_cmf_table.py), and the XYZ to
// linear sRGB matrix.
#pragma once

#include <array>

namespace airlight {

// xbar, ybar, zbar at a wavelength (nm): linear between the 1-nm table rows,
// 0 outside 380-780 nm.
std::array<double, 3> cie1931_xyz(double wavelength_nm);

// The CIE D65 illuminant's relative spectral power (100 at 560 nm), linear
// between the 1-nm rows, 0 outside 380-780 nm.
double cie_d65(double wavelength_nm);

// Linear sRGB (D65) from CIE XYZ (IEC 61966-2-1 matrix).
std::array<double, 3> xyz_to_linear_srgb(const std::array<double, 3>& xyz);

}  // namespace airlight
