// Computes the rainbow's spectral phase table (cpp/rainbow.hpp, stage 1) and
// writes it for embedding: build/cpp/make_rainbow_table --out data/rainbow_phase.bin
// Prints, per rate, the largest Monte-Carlo standard error in the bow region.
// --renormalise FILE rescales an existing table's forward aureole in place
// (normalise_rainbow_aureole; tables computed since do it themselves).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "rainbow.hpp"

int main(int argc, char** argv) {
    airlight::RainbowSampling sampling;
    std::string out = "data/rainbow_phase.bin", renormalise;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "make_rainbow_table: %s needs a value\n", a.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--samples") sampling.samples_per_wavelength = std::stoi(value());
        else if (a == "--seed") sampling.seed = std::stoull(value());
        else if (a == "--threads") sampling.threads = std::stoi(value());
        else if (a == "--wavelength") sampling.wavelengths.push_back(std::stoi(value()));
        else if (a == "--out") out = value();
        else if (a == "--renormalise") renormalise = value();
        else {
            std::fprintf(stderr, "make_rainbow_table: unknown option %s (--samples N --seed S --threads T "
                                 "--wavelength I (repeatable) --out FILE | --renormalise FILE)\n", a.c_str());
            return 2;
        }
    }
    if (!renormalise.empty()) {
        std::ifstream in(renormalise, std::ios::binary);
        const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        try {
            airlight::RainbowSpectralTable t = airlight::parse_rainbow_table(bytes);
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
    const airlight::RainbowSpectralTable t = airlight::compute_rainbow_spectral_table(sampling);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%zu wavelengths x %d samples in %.1f s\n", t.wavelengths_nm.size(), t.samples_per_wavelength, seconds);
    std::printf("rate mm/h | largest relative standard error, 120-145 deg (over wavelengths) | at the primary max\n");
    const size_t nw = t.wavelengths_nm.size(), na = t.angles_deg.size();
    for (size_t k = 0; k < t.rates.size(); ++k) {
        double worst = 0.0, at_peak = 0.0;
        for (size_t w = 0; w < nw; ++w) {
            double peak = 0.0;
            for (size_t a = 0; a < na; ++a) {
                const double deg = t.angles_deg[a];
                if (deg < 120.0 || deg > 145.0) continue;
                const size_t i = (k * nw + w) * na + a;
                worst = std::max(worst, double(t.rel_error[i]));
                if (deg > 134.0 && t.phase[i] > peak) {
                    peak = t.phase[i];
                    at_peak = std::max(at_peak, double(t.rel_error[i]));
                }
            }
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
