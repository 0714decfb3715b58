// Computes the rainbow's spectral phase table (effects/rainbow/rainbow.hpp, stage 1) and
// writes it for embedding: build/cpp/make_rainbow_table --out effects/rainbow/rainbow_phase.bin
// Prints, per rate, the largest Monte-Carlo standard error in the bow region.
// --merge FILE adds the wavelengths of an existing table (same rates, angles
// and samples) to the ones computed, for refining the wavelength grid;
// --angles LO HI computes only the grid's angles in [LO, HI] and takes the
// others from the --merge table (same wavelengths), for refining the angles.
// --renormalise FILE rescales an existing table's forward aureole in place
// (normalise_rainbow_aureole; tables computed since do it themselves).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rainbow.hpp"

namespace {

airlight::RainbowSpectralTable read_table(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read");
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return airlight::parse_rainbow_table(bytes);
}

// The computed table's angles (all within [lo, hi]) completed with the other
// angles of this build's grid from an earlier table of the same wavelengths.
airlight::RainbowSpectralTable with_angles_from(const airlight::RainbowSpectralTable& computed,
                                                const airlight::RainbowSpectralTable& earlier, double lo, double hi) {
    if (computed.wavelengths_nm != earlier.wavelengths_nm || computed.rates != earlier.rates ||
        computed.samples_per_wavelength != earlier.samples_per_wavelength)
        throw std::runtime_error("wavelengths, rates or samples differ from the computed table's");
    airlight::RainbowSpectralTable m = computed;
    m.angles_deg = airlight::rainbow_angles_deg();
    const size_t rows = m.rates.size() * m.wavelengths_nm.size(), na = m.angles_deg.size();
    m.phase.assign(rows * na, 0.0f);
    m.rel_error.assign(rows * na, 0.0f);
    size_t from_computed = 0;
    for (size_t a = 0; a < na; ++a) {
        const double deg = m.angles_deg[a];
        const airlight::RainbowSpectralTable* src = &computed;
        size_t at = from_computed;
        if (deg >= lo && deg <= hi) {
            ++from_computed;
        } else {
            const auto it = std::find(earlier.angles_deg.begin(), earlier.angles_deg.end(), deg);
            if (it == earlier.angles_deg.end())
                throw std::runtime_error("the earlier table lacks the angle " + std::to_string(deg));
            src = &earlier;
            at = size_t(it - earlier.angles_deg.begin());
        }
        const size_t src_na = src->angles_deg.size();
        for (size_t r = 0; r < rows; ++r) {
            m.phase[r * na + a] = src->phase[r * src_na + at];
            m.rel_error[r * na + a] = src->rel_error[r * src_na + at];
        }
    }
    airlight::normalise_rainbow_aureole(m);
    return m;
}

// The union of two tables' wavelengths, in increasing order.
airlight::RainbowSpectralTable merged(const airlight::RainbowSpectralTable& a,
                                      const airlight::RainbowSpectralTable& b) {
    if (a.rates != b.rates || a.angles_deg != b.angles_deg || a.samples_per_wavelength != b.samples_per_wavelength)
        throw std::runtime_error("rates, angles or samples differ from the computed table's");
    airlight::RainbowSpectralTable m = a;
    m.wavelengths_nm.clear();
    std::vector<std::pair<double, std::pair<const airlight::RainbowSpectralTable*, size_t>>> order;
    for (size_t i = 0; i < a.wavelengths_nm.size(); ++i) order.push_back({a.wavelengths_nm[i], {&a, i}});
    for (size_t i = 0; i < b.wavelengths_nm.size(); ++i) order.push_back({b.wavelengths_nm[i], {&b, i}});
    std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (size_t i = 0; i + 1 < order.size(); ++i)
        if (order[i].first == order[i + 1].first) throw std::runtime_error("both tables hold a wavelength");
    const size_t nw = order.size(), na = a.angles_deg.size();
    m.phase.assign(a.rates.size() * nw * na, 0.0f);
    m.rel_error.assign(m.phase.size(), 0.0f);
    for (size_t w = 0; w < nw; ++w) {
        m.wavelengths_nm.push_back(order[w].first);
        const airlight::RainbowSpectralTable& src = *order[w].second.first;
        const size_t sw = order[w].second.second, snw = src.wavelengths_nm.size();
        for (size_t k = 0; k < a.rates.size(); ++k)
            for (size_t x = 0; x < na; ++x) {
                m.phase[(k * nw + w) * na + x] = src.phase[(k * snw + sw) * na + x];
                m.rel_error[(k * nw + w) * na + x] = src.rel_error[(k * snw + sw) * na + x];
            }
    }
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    airlight::RainbowSampling sampling;
    std::string out = "effects/rainbow/rainbow_phase.bin", renormalise, merge;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "make_rainbow_table: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--samples")
            sampling.samples_per_wavelength = std::stoi(value());
        else if (a == "--seed")
            sampling.seed = std::stoull(value());
        else if (a == "--threads")
            sampling.threads = std::stoi(value());
        else if (a == "--wavelength")
            sampling.wavelengths.push_back(std::stoi(value()));
        else if (a == "--out")
            out = value();
        else if (a == "--renormalise")
            renormalise = value();
        else if (a == "--merge")
            merge = value();
        else if (a == "--angles") {
            sampling.angle_min_deg = std::stod(value());
            sampling.angle_max_deg = std::stod(value());
        } else {
            std::fprintf(stderr,
                         "make_rainbow_table: unknown option %s (--samples N --seed S --threads T "
                         "--wavelength I (repeatable) --angles LO HI --out FILE --merge FILE | --renormalise FILE)\n",
                         a.c_str());
            return 2;
        }
    }
    if (!renormalise.empty()) {
        try {
            airlight::RainbowSpectralTable t = read_table(renormalise);
            airlight::normalise_rainbow_aureole(t);
            const std::vector<char> fixed = airlight::serialize_rainbow_table(t);
            std::ofstream f(renormalise, std::ios::binary);
            f.write(fixed.data(), std::streamsize(fixed.size()));
            if (!f) throw std::runtime_error("cannot write " + renormalise);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_rainbow_table: %s: %s\n", renormalise.c_str(), e.what());
            return 1;
        }
        std::printf("renormalised %s\n", renormalise.c_str());
        return 0;
    }
    const auto start = std::chrono::steady_clock::now();
    // Read before computing: a bad file is reported at once, not after minutes.
    airlight::RainbowSpectralTable earlier;
    try {
        if (!merge.empty()) earlier = read_table(merge);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_rainbow_table: %s: %s\n", merge.c_str(), e.what());
        return 1;
    }
    airlight::RainbowSpectralTable t = airlight::compute_rainbow_spectral_table(sampling);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!merge.empty()) {
        try {
            const bool some_angles = sampling.angle_min_deg > 0.0 || sampling.angle_max_deg < 180.0;
            t = some_angles ? with_angles_from(t, earlier, sampling.angle_min_deg, sampling.angle_max_deg)
                            : merged(t, earlier);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "make_rainbow_table: %s: %s\n", merge.c_str(), e.what());
            return 1;
        }
    }
    std::printf("%zu wavelengths x %d samples in %.1f s\n", t.wavelengths_nm.size(), t.samples_per_wavelength, seconds);
    std::printf("rate mm/h | largest relative standard error, 120-145 deg (over wavelengths) | at the primary max\n");
    const size_t nw = t.wavelengths_nm.size(), na = t.angles_deg.size();
    for (size_t k = 0; k < t.rates.size(); ++k) {
        double worst = 0.0, at_peak = 0.0;
        for (size_t w = 0; w < nw; ++w) {
            size_t peak = 0;  // the primary's maximum at this wavelength
            for (size_t a = 0; a < na; ++a) {
                const double deg = t.angles_deg[a];
                if (deg < 120.0 || deg > 145.0) continue;
                const size_t i = (k * nw + w) * na + a;
                worst = std::max(worst, double(t.rel_error[i]));
                if (deg > 134.0 && (peak == 0 || t.phase[i] > t.phase[peak])) peak = i;
            }
            if (peak != 0) at_peak = std::max(at_peak, double(t.rel_error[peak]));
        }
        std::printf("%8.1f | %.4f | %.4f\n", t.rates[k], worst, at_peak);
    }
    const std::vector<char> bytes = airlight::serialize_rainbow_table(t);
    std::ofstream f(out, std::ios::binary);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    if (!f) {
        std::fprintf(stderr, "make_rainbow_table: cannot write %s\n", out.c_str());
        return 1;
    }
    std::printf("wrote %s (%zu bytes)\n", out.c_str(), bytes.size());
    return 0;
}
