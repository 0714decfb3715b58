// The plane-parallel multiple-scattering solver (effects/multiple_scattering/plane_parallel.cpp)
// against references that do not share its discretisation: energy
// conservation, Chandrasekhar's H-function for a semi-infinite atmosphere
// (solved here by iteration), second-order scattering of a thin slab by
// direct quadrature of its defining integral, the bare Lambertian ground; and
// its own convergence, zero output without scattering, finite output over wide
// ranges (effects/multiple_scattering/docs/solver.md lists the measured figures).
// Run with --analysis to print the error tables.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "check.hpp"
#include "plane_parallel.hpp"
#include "sky.hpp"

using namespace airlight;

namespace {

constexpr double kPi = 3.14159265358979323846;
bool g_print = false;

// A homogeneous slab of one species cut into `parts` equal layers.
SlabAtmosphere slab(double tau, double omega, const PhaseFunction& phase, int parts = 1, double height = 1000.0) {
    SlabAtmosphere atm;
    atm.phases = {phase};
    for (int k = 0; k < parts; ++k) {
        SlabLayer l;
        l.bottom = height * k / parts;
        l.top = height * (k + 1) / parts;
        const double t = tau / parts;
        l.extinction_depth.push_back(RgbD{t, t, t});
        l.scattering_depth.push_back(RgbD{t * omega, t * omega, t * omega});
        atm.layers.push_back(l);
    }
    return atm;
}

SlabIllumination sun_only(double mu0, double e = 1.0) {
    SlabIllumination s;
    s.sun_mu = mu0;
    s.sun_irradiance = {e, e, e};
    return s;
}

// Light balance at the top and the ground, relative to what enters:
// (reflected + transmitted + absorbed by the ground) / incident - 1.
double energy_defect(const MultipleScatteringField& f, int c) {
    const int top = int(f.altitudes.size()) - 1;
    const double reflected = f.irradiance_up[size_t(top)][size_t(c)];
    const double down =
        f.irradiance_down[0][size_t(c)] + f.sun_direct_irradiance[0][size_t(c)] + f.sky_direct_irradiance[0][size_t(c)];
    const double ground_absorbed = down - f.irradiance_up[0][size_t(c)];
    return (reflected + ground_absorbed) / f.incident_flux[size_t(c)] - 1.0;
}

bool all_finite(const MultipleScatteringField& f) {
    for (double v : f.phased_radiance)
        if (!std::isfinite(v)) return false;
    for (double v : f.node_radiance)
        if (!std::isfinite(v)) return false;
    for (size_t k = 0; k < f.altitudes.size(); ++k)
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(f.irradiance_down[k][size_t(c)]) || !std::isfinite(f.irradiance_up[k][size_t(c)]) ||
                f.irradiance_down[k][size_t(c)] < -1e-9 * f.incident_flux[size_t(c)] ||
                f.irradiance_up[k][size_t(c)] < -1e-9 * f.incident_flux[size_t(c)])
                return false;
    return true;
}

// Energy: albedo 1 and a black ground conserve light (issue 18's acceptance:
// within 0.5 %), for optical depths 0.01-500, g 0-0.9 and Rayleigh, sun high
// and low, and a sky dome with and without azimuth dependence.
void check_energy_conservation() {
    const PhaseFunction phases[] = {PhaseFunction::henyey_greenstein(0.0), PhaseFunction::henyey_greenstein(0.5),
                                    PhaseFunction::henyey_greenstein(0.9), PhaseFunction::rayleigh()};
    double worst = 0.0;
    for (double tau : {0.01, 0.3, 3.0, 30.0, 500.0})
        for (const PhaseFunction& p : phases)
            for (int light = 0; light < 4; ++light) {
                SlabIllumination s;
                if (light < 2) s = sun_only(light == 0 ? 0.95 : 0.08, 1.7);
                if (light == 2)
                    s.sky_radiance = [](double mu, double) { return RgbD{1 + 2 * mu, 1 + 2 * mu, 1 + 2 * mu}; };
                if (light == 3) {
                    s = sun_only(0.4, 3.0);
                    s.sky_radiance = [](double mu, double phi) {
                        const double v = (1.0 + 0.8 * std::sin(phi) + 0.3 * std::cos(2 * phi)) * (0.5 + mu);
                        return RgbD{v, 0.5 * v, 0.25 * v};
                    };
                }
                const MultipleScatteringField f = solve_plane_parallel(slab(tau, 1.0, p, tau > 10 ? 3 : 1), s);
                for (int c = 0; c < 3; ++c) {
                    worst = std::max(worst, std::abs(energy_defect(f, c)));
                    if (g_print && std::abs(energy_defect(f, c)) > 1e-3)
                        std::printf("  energy tau %g g %g light %d channel %d: %.2e\n", tau, p.moment(1), light, c,
                                    energy_defect(f, c));
                }
                CHECK(all_finite(f));
            }
    if (g_print) std::printf("energy: worst |defect| %.2e over tau 0.01-500, g 0-0.9, Rayleigh, 4 lights\n", worst);
    CHECK_MSG(worst < 5e-3, std::to_string(worst));
}

// Albedo 0 (and a black ground): no diffuse light at all, exactly.
void check_no_scattering_no_output() {
    SlabIllumination s = sun_only(0.6, 2.0);
    s.sky_radiance = [](double mu, double phi) { return RgbD{1 + mu, 1 + std::cos(phi), 2.0}; };
    SlabAtmosphere atm;
    atm.phases = {PhaseFunction::rayleigh(), PhaseFunction::henyey_greenstein(0.87)};
    for (int k = 0; k < 4; ++k) {
        SlabLayer l;
        l.bottom = 100.0 * k;
        l.top = 100.0 * (k + 1);
        l.extinction_depth.push_back(RgbD{0.1, 0.2, 0.3});
        l.extinction_depth.push_back(RgbD{5.0 * k, 5.0 * k, 5.0 * k});
        l.scattering_depth.assign(2, RgbD{});
        atm.layers.push_back(l);
    }
    const MultipleScatteringField f = solve_plane_parallel(atm, s);
    bool zero = true;
    for (double v : f.phased_radiance) zero = zero && v == 0.0;
    for (double v : f.node_radiance) zero = zero && v == 0.0;
    for (size_t k = 0; k < f.altitudes.size(); ++k)
        for (int c = 0; c < 3; ++c)
            zero = zero && f.irradiance_down[k][size_t(c)] == 0.0 && f.irradiance_up[k][size_t(c)] == 0.0 &&
                   f.sun_forward_irradiance[k][size_t(c)] == 0.0;
    CHECK(zero);
    // The unscattered light is there (the renderer's part): the sun's direct
    // beam at the ground is E mu0 exp(-tau / mu0).
    const double tau_g = 0.2 * 4 + 5.0 * (0 + 1 + 2 + 3);
    CHECK(std::abs(f.sun_direct_irradiance[0][1] / (2.0 * 0.6 * std::exp(-tau_g / 0.6)) - 1.0) < 1e-12);
}

// Chandrasekhar's H-function of isotropic scattering with albedo omega, by
// iterating 1/H(mu) = sqrt(1 - omega) + omega/2 int_0^1 mu' H(mu') / (mu + mu') dmu'
// on a fine Gauss rule (independent of the solver's ordinates).
struct HFunction {
    double omega;
    std::vector<double> x, w, h;
    explicit HFunction(double om) : omega(om) {
        gauss_legendre_unit(400, x, w);
        h.assign(x.size(), 1.0);
        for (int it = 0; it < 2000; ++it) {
            double change = 0.0;
            std::vector<double> next(h.size());
            for (size_t i = 0; i < x.size(); ++i) next[i] = 1.0 / inverse(x[i]);
            // Damped (the plain iteration does not settle at omega = 1).
            for (size_t i = 0; i < x.size(); ++i) {
                next[i] = 0.5 * (next[i] + h[i]);
                change = std::max(change, std::abs(next[i] - h[i]));
            }
            h = next;
            if (change < 1e-14) break;
        }
    }
    double inverse(double mu) const {
        double s = 0.0;
        for (size_t j = 0; j < x.size(); ++j) s += w[j] * x[j] * h[j] / (mu + x[j]);
        return std::sqrt(std::max(0.0, 1.0 - omega)) + 0.5 * omega * s;
    }
    double operator()(double mu) const { return 1.0 / inverse(mu); }
};

// The semi-infinite isotropic atmosphere reflects
// I(mu) = E omega mu0 H(mu) H(mu0) / (4 pi (mu + mu0)) (Chandrasekhar 1950, section 6.2).
void check_h_function_reflection() {
    for (double omega : {1.0, 0.9, 0.5}) {
        const HFunction h(omega);
        if (omega == 1.0) {
            // Chandrasekhar's table (Radiative Transfer, table XI): H(1) = 2.9078 for omega = 1.
            CHECK_MSG(std::abs(h(1.0) - 2.9078) < 2e-4, std::to_string(h(1.0)));
        }
        for (double mu0 : {1.0, 0.5, 0.15}) {
            const double e = kPi;
            const MultipleScatteringField f =
                solve_plane_parallel(slab(1e5, omega, PhaseFunction::henyey_greenstein(0.0)), sun_only(mu0, e));
            const int top = int(f.altitudes.size()) - 1;
            double worst = 0.0;
            for (int j = 0; j < f.streams; ++j) {
                const double mu = f.node_mu[size_t(j)];
                const double ref = e * omega * mu0 * h(mu) * h(mu0) / (4.0 * kPi * (mu + mu0));
                const double got = f.node_diffuse_radiance(top, 1, f.streams + j, 0.3);
                worst = std::max(worst, std::abs(got / ref - 1.0));
            }
            if (g_print) std::printf("H-function: omega %.1f mu0 %.2f worst relative error %.2e\n", omega, mu0, worst);
            CHECK_MSG(worst < 2e-3, std::to_string(omega) + " " + std::to_string(mu0) + " " + std::to_string(worst));
        }
    }
}

// The first two orders of scattering of a slab of depth tau0 (black ground)
// lit by a unit beam from (-mu0, 0), in propagation directions.
struct LowOrders {
    PhaseFunction phase;
    double tau0, mu0;
    std::vector<double> tn, tw;  // Gauss rule in depth
    std::vector<double> un, uw;  // panels in mu' over (-1, 1), graded towards 0
    LowOrders(const PhaseFunction& p, double t, double m) : phase(p), tau0(t), mu0(m) {
        gauss_legendre_unit(48, tn, tw);
        for (double& x : tn) x *= tau0;
        for (double& x : tw) x *= tau0;
        std::vector<double> gx, gw;
        gauss_legendre_unit(16, gx, gw);
        std::vector<double> edges = {0.0};
        for (int k = 14; k >= 0; --k) edges.push_back(std::pow(0.5, k));
        std::vector<double> cuts;
        for (double e : edges) cuts.push_back(e);
        // Downward directions: the same panels mirrored, plus a cut at -mu0.
        std::vector<double> all;
        for (double e : cuts) {
            all.push_back(e);
            all.push_back(-e);
        }
        all.push_back(-mu0);
        std::sort(all.begin(), all.end());
        all.erase(std::unique(all.begin(), all.end()), all.end());
        for (size_t k = 0; k + 1 < all.size(); ++k)
            for (size_t q = 0; q < gx.size(); ++q) {
                un.push_back(all[k] + (all[k + 1] - all[k]) * gx[q]);
                uw.push_back((all[k + 1] - all[k]) * gw[q]);
            }
    }
    static double phi1(double x) { return std::abs(x) < 1e-8 ? 1.0 + 0.5 * x : std::expm1(x) / x; }
    // I1(tau, mu') / (p / (4 pi)): the first-order radiance's depth factor.
    double depth_factor(double tau, double mu) const {
        if (mu > 0.0) {
            const double k = 1.0 / mu0 + 1.0 / mu;
            return std::exp(-tau / mu0) * -std::expm1(-(tau0 - tau) * k) / k / mu;
        }
        // (1/nu) int_0^tau exp(-t/mu0) exp(-(tau - t)/nu) dt, x = tau (1/nu - 1/mu0).
        const double nu = -mu, x = tau * (1.0 / nu - 1.0 / mu0);
        if (std::abs(x) < 0.5) return std::exp(-tau / nu) * tau * phi1(x) / nu;
        return tau * (std::exp(-tau / mu0) - std::exp(-tau / nu)) / x / nu;
    }
    double cosine(double mu1, double phi1v, double mu2, double phi2) const {
        return mu1 * mu2 + std::sqrt(std::max(0.0, 1 - mu1 * mu1)) * std::sqrt(std::max(0.0, 1 - mu2 * mu2)) *
                               std::cos(phi1v - phi2);
    }
    double first(double mu, double phi) const {  // upward radiance at the top, omega = 1
        return phase.value(cosine(mu, phi, -mu0, 0.0)) / (4.0 * kPi) * depth_factor(0.0, mu);
    }
    double second(double mu, double phi) const {  // upward at the top, coefficient of omega^2
        const int az = 128;
        double sum = 0.0;
        for (size_t q = 0; q < un.size(); ++q) {
            const double mp = un[q];
            double h = 0.0;  // (1/mu) int_0^tau0 exp(-tau/mu) depth_factor(tau, mu') dtau
            for (size_t t = 0; t < tn.size(); ++t) h += tw[t] * std::exp(-tn[t] / mu) * depth_factor(tn[t], mp);
            h /= mu;
            double ang = 0.0;
            for (int s = 0; s < az; ++s) {
                const double pp = 2.0 * kPi * s / az;
                ang += phase.value(cosine(mu, phi, mp, pp)) * phase.value(cosine(mp, pp, -mu0, 0.0));
            }
            sum += uw[q] * h * ang * 2.0 * kPi / az;
        }
        return sum / (16.0 * kPi * kPi);
    }
};

// Second order: the solver's omega^2 coefficient of the reflected radiance
// (Richardson in omega, the first order removed by its closed form) against
// the double integral by quadrature.
void check_second_order() {
    struct Case {
        PhaseFunction phase;
        double tau0, mu0;
    };
    const Case cases[] = {{PhaseFunction::henyey_greenstein(0.5), 0.3, 0.6},
                          {PhaseFunction::rayleigh(), 0.5, 0.3},
                          {PhaseFunction::henyey_greenstein(0.0), 0.1, 0.9}};
    for (const Case& cs : cases) {
        const LowOrders ref(cs.phase, cs.tau0, cs.mu0);
        const double om = 0.02;
        const MultipleScatteringField fa = solve_plane_parallel(slab(cs.tau0, om, cs.phase), sun_only(cs.mu0));
        const MultipleScatteringField fb = solve_plane_parallel(slab(cs.tau0, om / 2, cs.phase), sun_only(cs.mu0));
        const int top = int(fa.altitudes.size()) - 1;
        double worst = 0.0, worst_first = 0.0;
        for (int j = 0; j < fa.streams; j += 3)
            for (double phi : {0.0, 1.2, kPi}) {
                const double mu = fa.node_mu[size_t(j)];
                const double i1 = ref.first(mu, phi);
                const double ia = fa.node_diffuse_radiance(top, 1, fa.streams + j, phi);
                const double ib = fb.node_diffuse_radiance(top, 1, fb.streams + j, phi);
                const double ra = (ia - om * i1) / (om * om), rb = (ib - om / 2 * i1) / (om * om / 4);
                const double i2 = 2.0 * rb - ra;
                const double want = ref.second(mu, phi);
                if (g_print && j == 0)
                    std::printf("  mu %.3f phi %.2f: solver %.6e quadrature %.6e\n", mu, phi, i2, want);
                worst = std::max(worst, std::abs(i2 / want - 1.0));
                worst_first = std::max(worst_first, std::abs(ia / (om * i1) - 1.0));
            }
        if (g_print)
            std::printf("second order: tau0 %.2f mu0 %.2f worst relative error %.2e (first order %.2e)\n", cs.tau0,
                        cs.mu0, worst, worst_first);
        CHECK_MSG(worst < 5e-3, std::to_string(worst));
        CHECK_MSG(worst_first < 0.05, std::to_string(worst_first));
    }
}

// A bare Lambertian ground (no air): every upward ordinate carries
// A / pi x the incident flux, and an isotropic species would see the mean
// K = A F / (2 pi) of it.
void check_bare_ground() {
    SlabIllumination s = sun_only(0.5, 2.0);
    s.sky_radiance = [](double mu, double) { return RgbD{1 + 2 * mu, 1 + 2 * mu, 1 + 2 * mu}; };
    s.ground_albedo = {0.3, 0.6, 0.9};
    const MultipleScatteringField f = solve_plane_parallel(slab(1e-12, 1.0, PhaseFunction::henyey_greenstein(0.0)), s);
    double worst = 0.0, worst_k = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double want = s.ground_albedo[size_t(c)] * f.incident_flux[size_t(c)] / kPi;
        for (int j = 0; j < f.streams; ++j)
            worst = std::max(worst, std::abs(f.node_diffuse_radiance(0, c, f.streams + j, 0.7) / want - 1.0));
        for (size_t a = 0; a < f.view_mu.size(); ++a)
            worst_k = std::max(worst_k, std::abs(f.phased(0, 0, c, int(a), 3) / (want / 2.0) - 1.0));
    }
    // The sky's flux by the solver's quadrature against 7 pi / 9 x 9/7... (2 pi int (1 + 2mu) mu = 2 pi (1/2 + 2/3)).
    CHECK(std::abs(f.incident_flux[0] - (2.0 * 0.5 + 2.0 * kPi * (0.5 + 2.0 / 3.0))) < 1e-9);
    CHECK_MSG(worst < 1e-9, std::to_string(worst));
    CHECK_MSG(worst_k < 1e-9, std::to_string(worst_k));
}

// Mirror symmetry: the sky mirrored in the sun's plane (phi -> -phi)
// mirrors the field; this guards the sine terms.
void check_azimuth_mirror() {
    SlabIllumination a = sun_only(0.5), b = sun_only(0.5);
    a.sky_radiance = [](double mu, double phi) {
        double v = (1.0 + 0.9 * std::sin(phi)) * mu;
        return RgbD{v, v, v};
    };
    b.sky_radiance = [](double mu, double phi) {
        double v = (1.0 - 0.9 * std::sin(phi)) * mu;
        return RgbD{v, v, v};
    };
    const SlabAtmosphere atm = slab(2.0, 0.95, PhaseFunction::henyey_greenstein(0.7), 2);
    const MultipleScatteringField fa = solve_plane_parallel(atm, a), fb = solve_plane_parallel(atm, b);
    const int np = int(fa.view_phi.size());
    double worst = 0.0, asym = 0.0;
    for (size_t lev = 0; lev < fa.altitudes.size(); ++lev)
        for (int m = 0; m < int(fa.view_mu.size()); ++m)
            for (int p = 0; p < np; ++p) {
                const double va = fa.phased(int(lev), 0, 1, m, p), vb = fb.phased(int(lev), 0, 1, m, (np - p) % np);
                worst = std::max(worst, std::abs(va - vb) / std::abs(va));
                asym = std::max(asym, std::abs(va - fa.phased(int(lev), 0, 1, m, (np - p) % np)) / std::abs(va));
            }
    CHECK_MSG(worst < 1e-10, std::to_string(worst));
    CHECK_MSG(asym > 0.05, std::to_string(asym));  // the sky's asymmetry is there to mirror
    // And the orientation: sky a is brightest at phi = 90 degrees, so the
    // forward-scattering species' K at the ground looking up that way exceeds
    // K looking up at phi = 270 degrees (view_phi is uniform from 0).
    const int up = int(fa.view_mu.size()) * 3 / 4;
    const int east = np / 4, west = 3 * np / 4;
    CHECK_MSG(fa.phased(0, 0, 1, up, east) > 1.2 * fa.phased(0, 0, 1, up, west),
              std::to_string(fa.phased(0, 0, 1, up, east)) + " " + std::to_string(fa.phased(0, 0, 1, up, west)));
}

// Convergence: in the streams (against 48) and in the thin layer's depth.
void check_convergence() {
    const SlabAtmosphere atm = slab(20.0, 1.0, PhaseFunction::henyey_greenstein(0.87), 2);
    SlabIllumination s = sun_only(0.5, 1.0);
    s.sky_radiance = [](double mu, double) { return RgbD{0.1 * (1 + 2 * mu), 0.1, 0.1}; };
    auto run = [&](int n, double initial) {
        SolverOptions o;
        o.streams = n;
        o.initial_depth = initial;
        return solve_plane_parallel(atm, s, o);
    };
    auto difference = [](const MultipleScatteringField& a, const MultipleScatteringField& b) {
        double d = 0.0, scale = 0.0;
        for (size_t lev = 0; lev < a.altitudes.size(); ++lev) {
            d = std::max(d, std::abs(a.irradiance_down[lev][1] / b.irradiance_down[lev][1] - 1.0));
            for (size_t m = 0; m < a.view_mu.size(); m += 2)
                for (size_t p = 0; p < a.view_phi.size(); p += 3)
                    scale = std::max(scale, b.phased(int(lev), 0, 1, int(m), int(p)));
        }
        for (size_t lev = 0; lev < a.altitudes.size(); ++lev)
            for (size_t m = 0; m < a.view_mu.size(); m += 2)
                for (size_t p = 0; p < a.view_phi.size(); p += 3)
                    d = std::max(d, std::abs(a.phased(int(lev), 0, 1, int(m), int(p)) -
                                             b.phased(int(lev), 0, 1, int(m), int(p))) /
                                        scale);
        return d;
    };
    const double default_depth = SolverOptions{}.initial_depth;
    const MultipleScatteringField ref = run(48, default_depth);
    double previous = 1e30;
    for (int n : {8, 16, 32}) {
        const double d = difference(run(n, default_depth), ref);
        if (g_print) std::printf("streams %2d: largest difference to 48 streams %.2e (flux, K / max K)\n", n, d);
        CHECK_MSG(d < previous, std::to_string(n));
        previous = d;
        if (n == 16) CHECK_MSG(d < 0.02, std::to_string(d));
    }
    const MultipleScatteringField fine = run(16, 1.0 / 1024);
    const double d_default = difference(run(16, default_depth), fine), d_coarse = difference(run(16, 4.0), fine);
    if (g_print)
        std::printf("thin layer default (mu_min x %.3g) vs mu_min / 1024: %.2e; 4 mu_min: %.2e\n", default_depth,
                    d_default, d_coarse);
    CHECK_MSG(d_default < 1e-4, std::to_string(d_default));
    CHECK(d_default < d_coarse);
}

// Two species: Rayleigh over HG rain, both conservative, black ground.
void check_two_species() {
    SlabAtmosphere atm;
    atm.phases = {PhaseFunction::rayleigh(), PhaseFunction::henyey_greenstein(0.87)};
    const double ray[3] = {0.06, 0.13, 0.32};  // total Rayleigh depth per channel
    for (int k = 0; k < 10; ++k) {
        SlabLayer l;
        l.bottom = 500.0 * k;
        l.top = 500.0 * (k + 1);
        RgbD t{};
        for (int c = 0; c < 3; ++c)
            t[size_t(c)] = ray[c] * (std::exp(-l.bottom / 8000.0) - std::exp(-l.top / 8000.0)) /
                           (1.0 - std::exp(-5000.0 / 8000.0));
        const double rain = k < 3 ? 4.0 : 0.0;
        l.extinction_depth.push_back(t);
        l.extinction_depth.push_back(RgbD{rain, rain, rain});
        l.scattering_depth = l.extinction_depth;
        atm.layers.push_back(l);
    }
    SlabIllumination s = sun_only(0.3, 1.5);
    s.sky_radiance = [](double mu, double phi) {
        double v = 0.2 * (1 + 2 * mu) * (1 + 0.3 * std::cos(phi));
        return RgbD{v, v, v};
    };
    const MultipleScatteringField f = solve_plane_parallel(atm, s);
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(energy_defect(f, c)));
    if (g_print) std::printf("two species: energy defect %.2e, solve %.3f s\n", worst, f.solve_seconds);
    CHECK_MSG(worst < 5e-3, std::to_string(worst));
    CHECK(all_finite(f));
    // Above the rain the molecules' K is bluer than below... the source is positive everywhere.
    double lowest = 1e30;
    for (double v : f.phased_radiance) lowest = std::min(lowest, v);
    CHECK_MSG(lowest > 0.0, std::to_string(lowest));
}

// The renderer's own atmosphere (molecules + 40 mm/h rain) through
// slab_from_species: energy conserved; halving the layers changes the
// ground's diffuse irradiance little.
void check_renderer_atmosphere() {
    Atmosphere atm;
    atm.molecules.present = true;
    atm.rain.present = true;
    atm.rain.rate = 40.0f;
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    make_species_gpu(atm, species);
    SlabIllumination s = sun_only(0.5, 1.0);
    s.sky_radiance = [](double mu, double) {
        return RgbD{0.05 * (1 + 2 * mu), 0.05 * (1 + 2 * mu), 0.05 * (1 + 2 * mu)};
    };
    const std::vector<double> coarse = slab_levels(species, 16, 2.0), fine = slab_levels(species, 16, 0.5);
    CHECK(coarse.size() < fine.size());
    const SlabAtmosphere a = slab_from_species(species, coarse), b = slab_from_species(species, fine);
    // The column is the profile's exact integral whatever the layering.
    double ca = 0.0, cb = 0.0;
    for (const SlabLayer& l : a.layers) ca += l.extinction_depth[1][1];
    for (const SlabLayer& l : b.layers) cb += l.extinction_depth[1][1];
    CHECK(std::abs(ca / cb - 1.0) < 1e-9);
    const MultipleScatteringField fa = solve_plane_parallel(a, s), fb = solve_plane_parallel(b, s);
    double worst = 0.0;
    for (int c = 0; c < 3; ++c)
        worst = std::max({worst, std::abs(energy_defect(fa, c)), std::abs(energy_defect(fb, c))});
    const double layering = std::abs(fa.irradiance_down[0][1] / fb.irradiance_down[0][1] - 1.0);
    if (g_print) {
        const FieldBySource parts = solve_plane_parallel_by_source(a, s);  // eq. 9.4's cost: the same operators
        std::printf(
            "40 mm/h rain: rain depth %.2f, %zu / %zu layers, energy %.2e, layering %.2e, solve %.3f s, "
            "by source %.3f s\n",
            ca, a.layers.size(), b.layers.size(), worst, layering, fa.solve_seconds, parts.sky.solve_seconds);
    }
    CHECK_MSG(worst < 5e-3, std::to_string(worst));
    CHECK_MSG(layering < 2e-3, std::to_string(layering));
    // Threads over the channels give the same numbers.
    SolverOptions threaded;
    threaded.threads = 3;
    const MultipleScatteringField ft = solve_plane_parallel(a, s, threaded);
    CHECK(ft.phased_radiance == fa.phased_radiance && ft.node_radiance == fa.node_radiance);
}

// The largest difference between two fields' outputs, relative to the largest
// value of `b` in each output; `sum` adds field c to a first (a + c against b).
double field_difference(const MultipleScatteringField& a, const MultipleScatteringField& b,
                        const MultipleScatteringField* c = nullptr) {
    double worst = 0.0;
    auto compare = [&](const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>* z) {
        CHECK(x.size() == y.size());
        double scale = 1e-300, diff = 0.0;
        for (size_t k = 0; k < y.size(); ++k) {
            scale = std::max(scale, std::abs(y[k]));
            diff = std::max(diff, std::abs(x[k] + (z ? (*z)[k] : 0.0) - y[k]));
        }
        worst = std::max(worst, diff / scale);
    };
    auto flat = [](const std::vector<RgbD>& v) {
        std::vector<double> out;
        for (const RgbD& x : v) out.insert(out.end(), x.begin(), x.end());
        return out;
    };
    auto flat_sh = [](const MultipleScatteringField& f) {
        std::vector<double> out;
        for (const auto& level : f.radiance_sh)
            for (const auto& channel : level) out.insert(out.end(), channel.begin(), channel.end());
        return out;
    };
    auto vec = [](const RgbD& x) { return std::vector<double>(x.begin(), x.end()); };
    compare(a.phased_radiance, b.phased_radiance, c ? &c->phased_radiance : nullptr);
    compare(a.node_radiance, b.node_radiance, c ? &c->node_radiance : nullptr);
    for (auto member :
         {&MultipleScatteringField::irradiance_down, &MultipleScatteringField::irradiance_up,
          &MultipleScatteringField::sun_direct_irradiance, &MultipleScatteringField::sky_direct_irradiance,
          &MultipleScatteringField::sun_forward_irradiance}) {
        const std::vector<double> cz = c ? flat(c->*member) : std::vector<double>();
        compare(flat(a.*member), flat(b.*member), c ? &cz : nullptr);
    }
    const std::vector<double> csh = c ? flat_sh(*c) : std::vector<double>(), cf = c ? vec(c->incident_flux) : cf;
    compare(flat_sh(a), flat_sh(b), c ? &csh : nullptr);
    compare(vec(a.incident_flux), vec(b.incident_flux), c ? &cf : nullptr);
    return worst;
}

// The field by source (solve_plane_parallel_by_source): the sky's part is the
// solve without the sun, the sun's the solve without the sky (each stops its
// azimuth modes on its own light), and the sun's part scales with each
// channel's irradiance, all to rounding; their sum is the solve with both up to
// where that solve stopped its modes (the azimuth tolerance, 1e-4 of mode 0).
void check_field_by_source() {
    SlabIllumination both = sun_only(0.4);
    both.sun_irradiance = {1.0, 0.7, 0.4};
    both.ground_albedo = {0.3, 0.2, 0.1};
    both.sky_radiance = [](double mu, double phi) {
        const double v = (1.0 + 2.0 * mu) * (1.0 + 0.5 * std::cos(phi) + 0.3 * std::sin(phi));
        return RgbD{0.05 * v, 0.08 * v, 0.1 * v};
    };
    SlabAtmosphere atm = slab(3.0, 0.9, PhaseFunction::henyey_greenstein(0.75), 3);
    atm.phases.push_back(PhaseFunction::rayleigh());
    for (SlabLayer& l : atm.layers) {
        l.extinction_depth.push_back(RgbD{0.3, 0.2, 0.1});
        l.scattering_depth.push_back(RgbD{0.3, 0.2, 0.1});
    }
    SlabIllumination sky_only = both, sun_alone = both, brighter = both;
    sky_only.sun_irradiance = {0.0, 0.0, 0.0};
    sun_alone.sky_radiance = nullptr;
    brighter.sun_irradiance = {2.0, 1.4, 0.8};
    const FieldBySource parts = solve_plane_parallel_by_source(atm, both);
    const FieldBySource doubled = solve_plane_parallel_by_source(atm, brighter);
    const double sum = field_difference(parts.sky, solve_plane_parallel(atm, both), &parts.sun);
    const double sky = field_difference(parts.sky, solve_plane_parallel(atm, sky_only));
    const double sun = field_difference(parts.sun, solve_plane_parallel(atm, sun_alone));
    const double scale = field_difference(parts.sun, doubled.sun, &parts.sun);
    const double same_sky = field_difference(doubled.sky, parts.sky);
    if (g_print)
        std::printf("by source: sum %.1e, sky %.1e, sun %.1e, sun scaling %.1e, sky unchanged %.1e\n", sum, sky, sun,
                    scale, same_sky);
    CHECK_MSG(sum < 1e-4, std::to_string(sum));
    CHECK_MSG(sky < 1e-12, std::to_string(sky));
    CHECK_MSG(sun < 1e-12, std::to_string(sun));
    CHECK_MSG(scale < 1e-12, std::to_string(scale));
    CHECK_MSG(same_sky == 0.0, std::to_string(same_sky));
    // Each part has light of its own.
    CHECK(parts.sky.irradiance_down[0][1] > 0.0 && parts.sun.irradiance_down[0][1] > 0.0);
}

// Tilted surfaces: the l <= 2 harmonics against quadrature of the ordinates.
void check_tilted_irradiance() {
    SlabIllumination s = sun_only(0.4, 1.0);
    s.ground_albedo = {0.2, 0.2, 0.2};
    s.sky_radiance = [](double mu, double) { return RgbD{0.1 * (1 + 2 * mu), 0.1, 0.1}; };
    for (double tau : {0.3, 5.0, 50.0}) {
        const MultipleScatteringField f =
            solve_plane_parallel(slab(tau, 1.0, PhaseFunction::henyey_greenstein(0.8), 2), s);
        double worst = 0.0, scale = 0.0;
        for (size_t lev = 0; lev < f.altitudes.size(); ++lev) {
            // Horizontal: the harmonics' up irradiance matches the exact flux sum.
            const double e_up = f.tilted_irradiance_sh(int(lev), 1, {0.0, 1.0, 0.0});
            scale = std::max(scale, f.irradiance_down[lev][1]);
            worst = std::max(worst, std::abs(e_up - f.irradiance_down[lev][1]));
            for (double th : {0.5, 1.2, 1.57, 2.4})
                for (double ph : {0.0, 1.5, 3.1}) {
                    const std::array<double, 3> n = look_direction(std::cos(th), ph);
                    worst = std::max(worst, std::abs(f.tilted_irradiance_sh(int(lev), 1, n) -
                                                     f.tilted_irradiance_nodes(int(lev), 1, n)));
                }
        }
        if (g_print)
            std::printf("tilted irradiance, tau %.1f: harmonics' worst error %.2e of the largest flux\n", tau,
                        worst / scale);
        CHECK_MSG(worst / scale < 0.1, std::to_string(worst / scale));
    }
}

// No NaN or Inf, non-negative fluxes over wide ranges (8 streams for speed).
void check_finite_sweep() {
    int bad = 0, runs = 0;
    SolverOptions o;
    o.streams = 8;
    for (double tau : {0.0, 1e-9, 1e-3, 1.0, 60.0, 1e4})
        for (double omega : {0.0, 0.4, 0.999999, 1.0})
            for (const PhaseFunction& p :
                 {PhaseFunction::henyey_greenstein(0.0), PhaseFunction::henyey_greenstein(0.97),
                  PhaseFunction::henyey_greenstein(-0.6), PhaseFunction::rayleigh()})
                for (double mu0 : {1e-4, 0.3, 1.0})
                    for (double albedo : {0.0, 1.0}) {
                        SlabIllumination s = sun_only(mu0, 1e3);
                        s.ground_albedo = {albedo, albedo, albedo};
                        if (mu0 == 0.3)
                            s.sky_radiance = [](double mu, double phi) { return RgbD{mu, std::cos(phi) + 1, 1e-20}; };
                        const MultipleScatteringField f = solve_plane_parallel(slab(tau, omega, p, 2), s, o);
                        ++runs;
                        if (!all_finite(f)) {
                            ++bad;
                            if (g_print && bad < 12)
                                std::printf("  not finite: tau %g omega %g g %g mu0 %g albedo %g\n", tau, omega,
                                            p.moment(1), mu0, albedo);
                        }
                    }
    CHECK_MSG(bad == 0, std::to_string(bad) + " of " + std::to_string(runs));
}

// Interpolation in altitude: the solver's own levels (slab_levels) against a
// solve with a level added at the middle (in optical depth) of every layer:
// K there against linear interpolation in the column between the two ends.
double altitude_interpolation_error(const Atmosphere& atm, double max_depth, bool print_it, const char* name) {
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    make_species_gpu(atm, species);
    const std::vector<double> levels = slab_levels(species, 16, max_depth);
    auto green_depth = [&](double a, double b) {
        const SlabAtmosphere one = slab_from_species(species, {a, b});
        double d = 0.0;
        for (const RgbD& t : one.layers[0].extinction_depth) d += t[1];
        return d;
    };
    std::vector<double> refined;
    for (size_t k = 0; k + 1 < levels.size(); ++k) {
        refined.push_back(levels[k]);
        const double half = 0.5 * green_depth(levels[k], levels[k + 1]);
        double lo = levels[k], hi = levels[k + 1];
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            (green_depth(levels[k], mid) < half ? lo : hi) = mid;
        }
        refined.push_back(0.5 * (lo + hi));
    }
    refined.push_back(levels.back());
    SlabIllumination s = sun_only(0.6, 1.0);
    s.ground_albedo = {0.2, 0.2, 0.2};
    s.sky_radiance = [](double mu, double) { return RgbD{0.1 * (1 + 2 * mu), 0.1 * (1 + 2 * mu), 0.1 * (1 + 2 * mu)}; };
    SolverOptions o;
    o.streams = 12;
    const MultipleScatteringField f = solve_plane_parallel(slab_from_species(species, refined), s, o);
    double worst = 0.0, worst_altitude = 0.0, worst_mu = 0.0, worst_depth = 0.0;
    for (int i = 0; i < f.species_count; ++i) {
        double scale = 0.0;
        for (size_t lev = 0; lev < f.altitudes.size(); ++lev)
            for (size_t a = 0; a < f.view_mu.size(); ++a)
                for (size_t p = 0; p < f.view_phi.size(); ++p)
                    scale = std::max(scale, f.phased(int(lev), i, 1, int(a), int(p)));
        for (size_t lev = 1; lev + 1 < f.altitudes.size(); lev += 2) {
            const double c0 = f.column[lev - 1][1], c1 = f.column[lev][1], c2 = f.column[lev + 1][1];
            const double t = (c1 - c0) / (c2 - c0);
            for (size_t a = 0; a < f.view_mu.size(); ++a)
                for (size_t p = 0; p < f.view_phi.size(); ++p) {
                    const double guess = (1 - t) * f.phased(int(lev - 1), i, 1, int(a), int(p)) +
                                         t * f.phased(int(lev + 1), i, 1, int(a), int(p));
                    const double e = std::abs(guess - f.phased(int(lev), i, 1, int(a), int(p))) / scale;
                    if (e > worst) {
                        worst = e;
                        worst_altitude = f.altitudes[lev];
                        worst_mu = f.view_mu[a];
                        worst_depth = c0 - c2;
                    }
                }
        }
    }
    if (print_it)
        std::printf(
            "altitude interpolation, %s, layers <= %.2f deep (%zu levels): worst %.2e of the largest K "
            "(at %.0f m, view mu %.2f, layer depth %.3f)\n",
            name, max_depth, levels.size(), worst, worst_altitude, worst_mu, worst_depth);
    return worst;
}

void check_altitude_interpolation() {
    Atmosphere clear, rain, fog;
    clear.molecules.present = rain.molecules.present = fog.molecules.present = true;
    clear.aerosol.present = rain.aerosol.present = fog.aerosol.present = true;
    clear.aerosol.visibility = 30000.0f;
    rain.aerosol.visibility = 3000.0f;
    rain.rain.present = true;
    rain.rain.rate = 40.0f;
    fog.aerosol.visibility = 50.0f;
    double previous = 1e30;
    for (double d : {4.0, 2.0, 1.0}) {
        const double e = std::max({altitude_interpolation_error(clear, d, g_print, "clear"),
                                   altitude_interpolation_error(rain, d, g_print, "40 mm/h rain"),
                                   altitude_interpolation_error(fog, d, g_print, "50 m fog")});
        CHECK_MSG(e < previous, std::to_string(d));
        previous = e;
        if (d == 2.0) CHECK_MSG(e < 0.05, std::to_string(e));
        if (d == 1.0) CHECK_MSG(e < 0.015, std::to_string(e));
    }
}

// Interpolation in direction: K on a grid of ne cosines (uniform in
// elevation) x np azimuths, bilinear in (elevation, phi), against K solved at
// the cells' centres; for the renderer's 40 mm/h rain under a sun 37 degrees
// up (the aureole of rain's g = 0.87 is the sharpest feature).
double direction_interpolation_error(int ne, int np) {
    Atmosphere atm;
    atm.molecules.present = atm.aerosol.present = atm.rain.present = true;
    atm.aerosol.visibility = 3000.0f;
    atm.rain.rate = 40.0f;
    shader::SpeciesGpu species[shader::SPECIES_COUNT];
    make_species_gpu(atm, species);
    const SlabAtmosphere slab_atm = slab_from_species(species, slab_levels(species, 16, 2.0));
    SlabIllumination s = sun_only(0.6, 1.0);
    s.sky_radiance = [](double mu, double) { return RgbD{0.1 * (1 + 2 * mu), 0.1 * (1 + 2 * mu), 0.1 * (1 + 2 * mu)}; };
    SolverOptions corners, centres;
    for (int a = 0; a < ne; ++a) corners.view_mu.push_back(std::sin(-0.5 * kPi + kPi * a / (ne - 1)));
    for (int b = 0; b < np; ++b) corners.view_phi.push_back(2.0 * kPi * b / np);
    for (int a = 0; a + 1 < ne; ++a) centres.view_mu.push_back(std::sin(-0.5 * kPi + kPi * (a + 0.5) / (ne - 1)));
    for (int b = 0; b < np; ++b) centres.view_phi.push_back(2.0 * kPi * (b + 0.5) / np);
    const MultipleScatteringField grid = solve_plane_parallel(slab_atm, s, corners);
    const MultipleScatteringField mid = solve_plane_parallel(slab_atm, s, centres);
    double worst = 0.0;
    for (int i = 0; i < grid.species_count; ++i) {
        double scale = 0.0;
        for (size_t lev = 0; lev < grid.altitudes.size(); ++lev)
            for (int a = 0; a < ne; ++a)
                for (int b = 0; b < np; ++b) scale = std::max(scale, grid.phased(int(lev), i, 1, a, b));
        for (size_t lev = 0; lev < grid.altitudes.size(); lev += 3)
            for (int a = 0; a + 1 < ne; ++a)
                for (int b = 0; b < np; ++b) {
                    const double bilinear =
                        0.25 * (grid.phased(int(lev), i, 1, a, b) + grid.phased(int(lev), i, 1, a + 1, b) +
                                grid.phased(int(lev), i, 1, a, (b + 1) % np) +
                                grid.phased(int(lev), i, 1, a + 1, (b + 1) % np));
                    worst = std::max(worst, std::abs(bilinear - mid.phased(int(lev), i, 1, a, b)) / scale);
                }
    }
    if (g_print)
        std::printf("direction interpolation (bilinear, %d x %d grid): worst %.2e of the largest K\n", ne, np, worst);
    return worst;
}

void check_direction_interpolation() {
    const double fine = direction_interpolation_error(65, 72);  // the default grid
    CHECK_MSG(fine < 0.02, std::to_string(fine));
    if (g_print) {
        const double coarse = direction_interpolation_error(33, 36);
        CHECK(fine < coarse);
    }
}

}  // namespace

int main(int argc, char** argv) {
    g_print = argc > 1 && std::strcmp(argv[1], "--analysis") == 0;
    check_no_scattering_no_output();
    check_bare_ground();
    check_h_function_reflection();
    check_second_order();
    check_energy_conservation();
    check_azimuth_mirror();
    check_two_species();
    check_renderer_atmosphere();
    check_field_by_source();
    check_tilted_irradiance();
    check_convergence();
    check_altitude_interpolation();
    check_direction_interpolation();
    check_finite_sweep();
    return airlight_test::test_result("test_plane_parallel");
}
