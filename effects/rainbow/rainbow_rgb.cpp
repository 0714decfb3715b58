// Stage 2 of the rainbow tables (effects/rainbow/rainbow.hpp): the renderer's linear-sRGB
// table from the embedded spectral table, per scene.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <list>
#include <mutex>
#include <stdexcept>
#include <string>

#include "airlight/colour.hpp"
#include "rainbow.hpp"
#include "shader_cpp.hpp"

namespace airlight {

// ---- Stage 2 ---------------------------------------------------------------
namespace {
// Node j's weight (hat function of the nodes' spacing) at a wavelength.
double hat(double wavelength, double node, double spacing) {
    return std::max(0.0, 1.0 - std::abs(wavelength - node) / spacing);
}

void check_wavelength_count(int count) {
    if (!is_rainbow_wavelength_count(count))
        throw std::invalid_argument(std::string("rainbow: the wavelength count must be ") + RAINBOW_WAVELENGTH_COUNTS +
                                    ", got " + std::to_string(count));
}

// Channels R, G, B, then Y (luminance) per node, each normalised to sum 1.
std::vector<double> spectral_weights(int count) {
    check_wavelength_count(count);
    // Sums over the CIE tables' 1-nm rows within the table's 380-720 nm.
    const double spacing = 340.0 / (count - 1);
    std::vector<double> w(size_t(count) * 4, 0.0);
    for (int j = 0; j < count; ++j) {
        const double node = 380.0 + spacing * j;
        for (int nm = 380; nm <= 720; ++nm) {
            const double h = hat(nm, node, spacing) * cie_d65(nm);
            if (h == 0.0) continue;
            const std::array<double, 3> xyz = cie1931_xyz(nm);
            const std::array<double, 3> rgb = xyz_to_linear_srgb(xyz);
            for (int c = 0; c < 3; ++c) w[size_t(j) * 4 + size_t(c)] += h * rgb[size_t(c)];
            w[size_t(j) * 4 + 3] += h * xyz[1];
        }
    }
    for (int c = 0; c < 4; ++c) {
        double total = 0.0;
        for (int j = 0; j < count; ++j) total += w[size_t(j) * 4 + size_t(c)];
        for (int j = 0; j < count; ++j) w[size_t(j) * 4 + size_t(c)] /= total;
    }
    return w;
}

// The embedded table's index of the node that is node j of `count`.
int spectral_node(int j, int count) { return j * ((RAINBOW_WAVELENGTHS - 1) / (count - 1)); }
}  // namespace

bool is_rainbow_wavelength_count(int count) {
    static_assert(RAINBOW_WAVELENGTHS == 33, "the supported counts are the evenly spaced subsets of 33 nodes");
    for (int n : {3, 5, 9, 17, 33})
        if (count == n) return true;
    return false;
}

std::vector<float> rainbow_rgb_weights(int count) {
    const std::vector<double> w = spectral_weights(count);
    std::vector<float> out(size_t(count) * 3);
    for (int j = 0; j < count; ++j)
        for (int c = 0; c < 3; ++c) out[size_t(j) * 3 + size_t(c)] = float(w[size_t(j) * 4 + size_t(c)]);
    return out;
}

std::vector<double> rainbow_spectral_phase(double rate, int wavelength) {
    const RainbowSpectralTable& t = rainbow_spectral_table();
    if (wavelength < 0 || size_t(wavelength) >= t.wavelengths_nm.size())
        throw std::invalid_argument("rainbow: no wavelength node " + std::to_string(wavelength));
    if (!(rate > 0.0)) throw std::invalid_argument("rainbow: the rain rate must be positive");
    // Linear in log rate between the table's rates (0.1 * 2^k), clamped at the ends.
    const double kf = std::clamp(std::log2(rate / t.rates.front()), 0.0, double(t.rates.size() - 1));
    const int k0 = std::min(int(kf), int(t.rates.size()) - 2);
    const double f = kf - k0;
    std::vector<double> p(t.angles_deg.size());
    for (size_t a = 0; a < p.size(); ++a)
        p[a] = (1.0 - f) * t.at(k0, wavelength, int(a)) + f * t.at(k0 + 1, wavelength, int(a));
    return p;
}

const Table2D& rainbow_phase_table(double rate, int count) {
    check_wavelength_count(count);
    static std::mutex mutex;
    struct Cached {
        double rate;
        int count;
        Table2D table;
    };
    static std::list<Cached> cache;  // most recent first; addresses stay valid while cached
    static long serial = 0;
    std::lock_guard<std::mutex> lock(mutex);
    for (auto it = cache.begin(); it != cache.end(); ++it) {
        if (it->rate == rate && it->count == count) {
            cache.splice(cache.begin(), cache, it);
            return cache.front().table;
        }
    }
    const auto start = std::chrono::steady_clock::now();
    const RainbowSpectralTable& spectral = rainbow_spectral_table();
    const std::vector<double> w = spectral_weights(count);
    std::vector<std::vector<double>> phases;
    for (int j = 0; j < count; ++j) phases.push_back(rainbow_spectral_phase(rate, spectral_node(j, count)));
    const std::vector<double>& grid = spectral.angles_deg;

    Table2D t;
    t.name = "rainbow_phase";
    t.width = shader::RAINBOW_TABLE_N;
    t.height = 1;
    t.channels = 4;
    t.texels.assign(size_t(t.width) * 4, 0.0f);
    for (int u = 0; u < t.width; ++u) {
        const double deg = 180.0 * u / (t.width - 1);
        const size_t hi = std::clamp<size_t>(size_t(std::upper_bound(grid.begin(), grid.end(), deg) - grid.begin()), 1,
                                             grid.size() - 1);
        const size_t lo = hi - 1;
        const double f = std::clamp((deg - grid[lo]) / (grid[hi] - grid[lo]), 0.0, 1.0);
        double rgby[4] = {0.0, 0.0, 0.0, 0.0};
        for (int j = 0; j < count; ++j) {
            const double p = (1.0 - f) * phases[size_t(j)][lo] + f * phases[size_t(j)][hi];
            for (int c = 0; c < 4; ++c) rgby[c] += w[size_t(j) * 4 + size_t(c)] * p;
        }
        // Colours outside the sRGB gamut (a channel below 0) are desaturated
        // toward the luminance, keeping it, until the smallest channel is 0
        // (the max only removes rounding below 0).
        double s = 1.0;
        for (int c = 0; c < 3; ++c)
            if (rgby[c] < 0.0) s = std::min(s, rgby[3] / (rgby[3] - rgby[c]));
        for (int c = 0; c < 3; ++c)
            t.texels[size_t(u) * 4 + size_t(c)] = float(std::max(0.0, rgby[3] + s * (rgby[c] - rgby[3])));
        t.texels[size_t(u) * 4 + 3] = float(rgby[3]);
    }
    t.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    t.serial = ++serial;
    register_table(t);
    cache.push_front({rate, count, std::move(t)});
    if (cache.size() > 8) cache.pop_back();
    return cache.front().table;
}

}  // namespace airlight
