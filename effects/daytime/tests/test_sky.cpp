// The sky-phase table's quadrature (effects/daytime/sky.cpp) against closed forms for
// the CIE standard overcast sky (exponential integrals E_n), and the species
// and altitude levels built from a scene's atmosphere (issue 6; effects/daytime/docs/daytime.md).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "check.hpp"
#include "numerics.hpp"
#include "sky.hpp"

using namespace airlight;

namespace {

using numerics::kPi;

// E_n(x) for x > 0 by upward recurrence from E1 = -Ei(-x) (stable upward for
// the small n used here), E_n(0) = 1 / (n - 1).
double expn(int n, double x) {
    if (x == 0.0) return 1.0 / (n - 1);
    double e = -std::expint(-x);
    for (int k = 1; k < n; ++k) e = (std::exp(-x) - x * e) / k;
    return e;
}

shader::SkyGpu overcast() {
    Sky sky;
    sky.model = SkyModel::overcast;
    sky.zenith_radiance = glm::vec3(1.0f);
    return make_sky_gpu(sky, Sun{});
}

// Species with given phases: molecules (Rayleigh), aerosol HG g1, rain HG g2.
void species_with(float g1, float g2, shader::SpeciesGpu species[shader::SPECIES_COUNT]) {
    Atmosphere atm;
    atm.molecules.present = true;
    atm.aerosol.present = true;
    atm.aerosol.visibility = 5000.0f;
    atm.aerosol.g = g1;
    atm.rain.present = true;
    atm.rain.rate = 10.0f;
    atm.rain.g = g2;
    make_species_gpu(atm, species);
}

double table_value(const Table2D& t, int column, int row, int kernel) {
    const double c = double(shader::sky_table_column(float(column) / float(t.width - 1)));
    return std::exp(double(t.texels[(size_t(row) * size_t(t.width) + size_t(column)) * 4 + size_t(kernel)]) - c);
}

void check_overcast_closed_forms(bool print) {
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    species_with(0.0f, 0.5f, species);
    const auto table = sky_phase_table(overcast(), species, true);
    const Table2D& t = *table;
    std::printf("overcast sky table %dx%d built in %.3f s\n", t.width, t.height, t.build_seconds);
    double worst_iso = 0.0, worst_ray = 0.0, worst_cos = 0.0;
    for (int i = 0; i < t.width; i += 3) {
        const double c = double(shader::sky_table_column(float(i) / float(t.width - 1)));
        if (c > 60.0) break;  // e^{-C} near float32's end
        for (int row = 0; row < shader::SKY_TABLE_N_ELEVATION; ++row) {
            const double elevation = -kPi / 2.0 + kPi * row / (shader::SKY_TABLE_N_ELEVATION - 1);
            const double mu = std::sin(elevation);
            // Isotropic (aerosol slot, g = 0): (E2 + 2 E3) / 6.
            const double iso = (expn(2, c) + 2.0 * expn(3, c)) / 6.0;
            // Rayleigh: 3/(16 pi) [4/3 A0 + 2/3 P2(mu) A2] (effects/daytime/tests/daytime_reference.py).
            const double f = (expn(2, c) + 2.0 * expn(3, c)) / 3.0, f2 = (expn(4, c) + 2.0 * expn(5, c)) / 3.0;
            const double a0 = 2.0 * kPi * f, a2 = 2.0 * kPi * (1.5 * f2 - 0.5 * f);
            const double ray = 3.0 / (16.0 * kPi) * (4.0 / 3.0 * a0 + 2.0 / 3.0 * (1.5 * mu * mu - 0.5) * a2);
            worst_iso = std::max(worst_iso, std::abs(table_value(t, i, row, 1) / iso - 1.0));
            worst_ray = std::max(worst_ray, std::abs(table_value(t, i, row, 0) / ray - 1.0));
            if (row == shader::SKY_TABLE_N_ELEVATION - 1) {
                // Horizontal irradiance: 2 pi / 3 (E3 + 2 E4); 7 pi / 9 at C = 0.
                const double e = 2.0 * kPi / 3.0 * (expn(3, c) + 2.0 * expn(4, c));
                worst_cos = std::max(worst_cos, std::abs(table_value(t, i, row, 3) / e - 1.0));
            }
        }
    }
    if (print)
        std::printf("table nodes vs closed forms: isotropic %.2e, Rayleigh %.2e, horizontal irradiance %.2e\n",
                    worst_iso, worst_ray, worst_cos);
    CHECK_MSG(worst_iso < 1e-4, std::to_string(worst_iso));
    CHECK_MSG(worst_ray < 1e-4, std::to_string(worst_ray));
    CHECK_MSG(worst_cos < 1e-4, std::to_string(worst_cos));
    const double e0 = table_value(t, 0, shader::SKY_TABLE_N_ELEVATION - 1, 3);
    CHECK_MSG(std::abs(e0 / (7.0 * kPi / 9.0) - 1.0) < 1e-5, std::to_string(e0));
}

// HG phase functions integrate to 1 over the sphere: under a uniform sky
// (CIE type 5 has a = 0: L = Lz) with C = 0 a kernel's integral over the
// upper hemisphere plus the one looking the other way is 1 / (the same by
// symmetry): F(d) + F(-d) = 1 for any d.
void check_uniform_sky_normalisation(bool print) {
    Sky sky;
    sky.model = SkyModel::cie;
    sky.cie_type = 5;
    sky.zenith_radiance = glm::vec3(1.0f);
    const shader::SkyGpu gpu = make_sky_gpu(sky, Sun{});
    double worst = 0.0;
    for (float g : {0.3f, 0.7f, 0.87f, -0.5f}) {
        shader::SpeciesGpu species[shader::SPECIES_COUNT];
        species_with(g, g, species);
        const auto table = sky_phase_table(gpu, species, true);
        const Table2D& t = *table;
        const int ne = shader::SKY_TABLE_N_ELEVATION;
        for (int row = 0; row < ne; ++row) {
            const double sum = table_value(t, 0, row, 1) + table_value(t, 0, ne - 1 - row, 1);
            worst = std::max(worst, std::abs(sum - 1.0));
        }
    }
    if (print) std::printf("uniform sky, HG g in {0.3, 0.7, 0.87, -0.5}: |F(d) + F(-d) - 1| <= %.2e\n", worst);
    CHECK_MSG(worst < 2e-3, std::to_string(worst));
}

// A clear sky with a sun (CIE 12): the table has its azimuth blocks; its
// build time is printed (effects/daytime/docs/daytime.md).
void check_sun_sky_table() {
    Sky sky;
    sky.model = SkyModel::cie;
    sky.cie_type = 12;
    sky.zenith_radiance = glm::vec3(1.0f);
    Sun sun;
    sun.present = true;
    sun.direction = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
    const shader::SkyGpu gpu = make_sky_gpu(sky, sun);
    CHECK(sky_has_azimuth(gpu));
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    species_with(0.7f, 0.87f, species);
    const auto table = sky_phase_table(gpu, species, true);
    const Table2D& t = *table;
    std::printf("CIE 12 sky table %dx%d built in %.3f s\n", t.width, t.height, t.build_seconds);
    CHECK(t.height == shader::SKY_TABLE_N_ELEVATION * shader::SKY_TABLE_N_AZIMUTH);
    // Node values against the same rule evaluated directly at a few directions.
    double worst = 0.0;
    for (int row : {5, 31, 40, 63, 64 * 7 + 33, 64 * 20 + 50, 64 * 31 + 10}) {
        const int ie = row % 64, ia = row / 64;
        const double e = -kPi / 2.0 + kPi * ie / 63.0, a = kPi * ia / 31.0;
        glm::dvec3 along = glm::normalize(glm::dvec3(0.3, 0.0, -0.8));
        glm::dvec3 across = glm::cross(glm::dvec3(0.0, 1.0, 0.0), along);
        glm::dvec3 d = std::cos(e) * (std::cos(a) * along + std::sin(a) * across) + glm::dvec3(0.0, std::sin(e), 0.0);
        for (int k = 0; k < 4; ++k) {
            const double direct = sky_kernel_integral(gpu, species, k, 0.0, d);
            worst = std::max(worst, std::abs(table_value(t, 0, row, k) / (direct + 1e-30) - 1.0));
        }
    }
    CHECK_MSG(worst < 1e-5, std::to_string(worst));
}

void check_species_and_levels() {
    // Rain: pi N0 1e-6 / Lambda^3 (effects/daytime/physics.md).
    const double lambda = 4.1 * std::pow(10.0, -0.21);
    CHECK(std::abs(rain_extinction(10.0) / (kPi * 8000.0e-6 / (lambda * lambda * lambda)) - 1.0) < 1e-12);
    CHECK(rain_extinction(0.0) == 0.0);
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    species_with(0.7f, 0.87f, species);
    // Visibility 5 km: molecules + aerosol give 3.912 / V in green.
    CHECK(std::abs((species[shader::SPECIES_MOLECULES].sigma_t.y + species[shader::SPECIES_AEROSOL].sigma_t.y) *
                       5000.0 / 3.912 -
                   1.0) < 1e-5);
    float top = 0.0f;
    for (int segments : {2, 16, 64}) {
        const std::vector<float> levels = make_altitude_levels(species, segments, top);
        CHECK(levels.front() == 0.0f && levels.back() == top);
        CHECK(int(levels.size()) <= shader::ATMOSPHERE_MAX_LEVELS);
        for (size_t k = 1; k < levels.size(); ++k) CHECK(levels[k] > levels[k - 1]);
        // The profile breaks are levels: rain top and the aerosol's minimum and maximum.
        for (float b : {1500.0f, 2250.0f, 3250.0f}) {
            bool found = false;
            for (float l : levels) found = found || l == b;
            CHECK_MSG(found, std::to_string(b));
        }
    }
    // Molecules reach 1e-5 of their ground density at 8 km x ln(1e5) = 92 km.
    CHECK(std::abs(top - 8000.0f * std::log(1e5f)) < 1.0f);
    // No atmosphere: no levels.
    Atmosphere empty;
    make_species_gpu(empty, species);
    CHECK(make_altitude_levels(species, 16, top).empty());
}

}  // namespace

int main(int argc, char** argv) {
    const bool print = argc > 1 && std::strcmp(argv[1], "--analysis") == 0;
    check_overcast_closed_forms(true);
    check_uniform_sky_normalisation(true);
    check_sun_sky_table();
    check_species_and_levels();
    (void)print;
    return airlight_test::test_result("test_sky");
}
