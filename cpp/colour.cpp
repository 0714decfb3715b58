// Colour science (include/airlight/colour.hpp) from the CIE tables.
#include "airlight/colour.hpp"

#include <algorithm>

namespace airlight {
namespace {

struct CieRow {
    double wavelength, x, y, z, d65;
};
constexpr CieRow kCie[] = {
#include "cie_tables.inc"
};
constexpr int kRows = int(sizeof(kCie) / sizeof(kCie[0]));

// Row i and the weight of row i + 1 at a wavelength; false outside the table.
bool locate(double nm, int& i, double& t) {
    const double u = nm - kCie[0].wavelength;
    if (!(u >= 0.0) || u > double(kRows - 1)) return false;
    i = std::min(int(u), kRows - 2);
    t = u - double(i);
    return true;
}

}  // namespace

std::array<double, 3> cie1931_xyz(double nm) {
    int i = 0;
    double t = 0.0;
    if (!locate(nm, i, t)) return {0.0, 0.0, 0.0};
    const CieRow &a = kCie[i], &b = kCie[i + 1];
    return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)};
}

double cie_d65(double nm) {
    int i = 0;
    double t = 0.0;
    if (!locate(nm, i, t)) return 0.0;
    return kCie[i].d65 + t * (kCie[i + 1].d65 - kCie[i].d65);
}

std::array<double, 3> xyz_to_linear_srgb(const std::array<double, 3>& c) {
    return {3.2404542 * c[0] - 1.5371385 * c[1] - 0.4985314 * c[2],
            -0.9692660 * c[0] + 1.8760108 * c[1] + 0.0415560 * c[2],
            0.0556434 * c[0] - 0.2040259 * c[1] + 1.0572252 * c[2]};
}

}  // namespace airlight
