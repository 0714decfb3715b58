// The particle clouds' lighting table (effects/particle_clouds/physics.md section 3).
#include "particle_table.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "numerics.hpp"
#include "shader_cpp.hpp"

namespace airlight {
namespace {

using numerics::kPi;

using numerics::node_and_fraction;
double hg(double g, double mu) { return numerics::henyey_greenstein(g, mu); }

}  // namespace

void validate_particle_table_shape(const ParticleTableShape& shape) {
    auto check = [](const char* name, int value, int lo, int hi) {
        if (value < lo || value > hi)
            throw std::invalid_argument(std::string("shape.") + name + ": must be an integer in [" +
                                        std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                                        std::to_string(value));
    };
    check("entry", shape.entry, shape.dense_terminator ? shader::PARTICLE_DENSE_ENTRY_MIN : 2, 512);
    check("view_zenith", shape.view_zenith, 2, 512);
    check("view_azimuth", shape.view_azimuth, 2, 512);
    check("taus", shape.taus, 2, 256);
    check("steps", shape.steps, 1, 4096);
    if (!(shape.tau_min >= 1e-3 && shape.tau_max <= 1e3 && shape.tau_min < shape.tau_max))
        throw std::invalid_argument("shape.tau_min, shape.tau_max: must satisfy 1e-3 <= tau_min < tau_max <= 1000");
    validate_sphere_grid(shape.grid);
}

ParticleTable::ParticleTable(double g, const ParticleTableShape& shape) : g_(g), shape_(shape) {
    if (!(g >= 0.0 && g <= 0.99)) throw std::invalid_argument("g: must be in [0, 0.99]");
    validate_particle_table_shape(shape);
    const auto start = std::chrono::steady_clock::now();
    const int E = shape.entry, Z = shape.view_zenith, A = shape.view_azimuth;
    const size_t slice = size_t(E) * Z * A * 4;
    nodes_.assign(slice * shape.taus, 0.0f);
    for (int m = 0; m < shape.taus; ++m) {
        const double tau = slice_tau(m);
        const SphereScattering sphere(tau, g, shape.grid);
        numerics::parallel_for(E * Z, [&](int ez) {
            // Eq. 3.1: the node's ray in the solver's frame (sun on +z), entering at P = n, at the entry
            // angle and view zenith of eq. 3.2's nodes (particle_table_math.glsl).
            const double th = shader::particle_entry_angle(float(ez / Z), E, shape.dense_terminator);
            const double ze = shader::particle_zenith_angle(float(ez % Z) / float(Z - 1));
            const double n[3] = {std::sin(th), 0.0, std::cos(th)}, t[3] = {-std::cos(th), 0.0, std::sin(th)};
            for (int a = 0; a < A; ++a) {
                const double ps = kPi * a / (A - 1);
                // v = cos(ze) (-n) + sin(ze) (cos(ps) t + sin(ps) b), b = n x t = (0, -1, 0)
                const double v[3] = {-std::cos(ze) * n[0] + std::sin(ze) * std::cos(ps) * t[0],
                                     -std::sin(ze) * std::sin(ps),
                                     -std::cos(ze) * n[2] + std::sin(ze) * std::cos(ps) * t[2]};
                const std::array<double, 4> r = sphere.table_channels(n, v, shape.steps);
                float* out = &nodes_[m * slice + (size_t(ez) * A + a) * 4];
                for (int c = 0; c < 4; ++c) out[c] = float(r[c]);
            }
        });
    }
    build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

ParticleTableShape particle_table_shape(ParticleTableQuality quality) {
    ParticleTableShape shape;  // full (effects/particle_clouds/docs/table_resolution.txt)
    shape.grid.beyond = true;  // every order, not the source's 18 (physics.md section 2.7)
    if (quality == ParticleTableQuality::preview) {
        shape.entry = 16;
        shape.view_zenith = 8;
        shape.view_azimuth = 16;
        shape.taus = 8;
        shape.steps = 16;
        shape.grid.radii = 8;
        shape.grid.polar = 12;
        shape.grid.polar_forward_thick = 0;  // a preview keeps its 12
        shape.grid.zenith = 12;
        shape.grid.azimuth = 8;
        shape.grid.march_steps = 8;
    }
    return shape;
}

double ParticleTable::slice_tau(int m) const {
    return shape_.tau_min * std::pow(shape_.tau_max / shape_.tau_min, double(m) / (shape_.taus - 1));
}

std::array<double, 2> ParticleTable::lookup(double tau, const double normal[3], const double view[3],
                                            const double sun[3]) const {
    // Eq. 3.1: the angles of the entry point and the ray in the frame of the normal and the sun.
    const double cos_entry = std::clamp(normal[0] * sun[0] + normal[1] * sun[1] + normal[2] * sun[2], -1.0, 1.0);
    const double cos_view = std::clamp(-(normal[0] * view[0] + normal[1] * view[1] + normal[2] * view[2]), 0.0, 1.0);
    double t[3] = {sun[0] - cos_entry * normal[0], sun[1] - cos_entry * normal[1], sun[2] - cos_entry * normal[2]};
    const double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    double psi = 0.0;
    if (tl > 1e-12) {
        for (double& x : t) x /= tl;
        const double b[3] = {normal[1] * t[2] - normal[2] * t[1], normal[2] * t[0] - normal[0] * t[2],
                             normal[0] * t[1] - normal[1] * t[0]};
        psi = std::atan2(std::fabs(view[0] * b[0] + view[1] * b[1] + view[2] * b[2]),
                         view[0] * t[0] + view[1] * t[1] + view[2] * t[2]);
    }
    const int E = shape_.entry, Z = shape_.view_zenith, A = shape_.view_azimuth;
    int node[4];
    double frac[4];
    // Eq. 3.2: the nodes' coordinates (particle_table_math.glsl).
    node_and_fraction(shader::particle_entry_index(float(std::acos(cos_entry)), E, shape_.dense_terminator), E, node[0],
                      frac[0]);
    node_and_fraction(shader::particle_zenith_coordinate(float(std::acos(cos_view))) * (Z - 1), Z, node[1], frac[1]);
    node_and_fraction(psi / kPi * (A - 1), A, node[2], frac[2]);
    // Eq. 3.2: the optical radius, log-uniform; below tau_min order 1 scales with tau and the rest with
    // tau^2 (thin particles), above tau_max the thickest slice stands.
    const double x = std::log(std::max(tau, 1e-30) / shape_.tau_min) / std::log(shape_.tau_max / shape_.tau_min);
    node_and_fraction(x * (shape_.taus - 1), shape_.taus, node[3], frac[3]);
    const double thin = std::min(1.0, tau / shape_.tau_min);
    const size_t stride[3] = {size_t(Z) * A * 4, size_t(A) * 4, 4};
    // Eq. 3.1: a slice's order 1 and orders 2..N, trilinear in the angles, with the phases of order 1
    // and of orders 2 and 3's peaks exact for the ray.
    const double mu = sun[0] * view[0] + sun[1] * view[1] + sun[2] * view[2];
    const double p1 = hg(g_, mu), p2 = hg(g_ * g_, mu), p3 = hg(g_ * g_ * g_, mu);
    auto slice_light = [&](int m) {
        double v[4] = {0.0, 0.0, 0.0, 0.0};
        const size_t slice = size_t(m) * E * Z * A * 4;
        for (int corner = 0; corner < 8; ++corner) {
            double weight = 1.0;
            size_t index = slice;
            for (int axis = 0; axis < 3; ++axis) {
                const bool upper = (corner >> axis) & 1;
                weight *= upper ? frac[axis] : 1.0 - frac[axis];
                index += (node[axis] + (upper ? 1 : 0)) * stride[axis];
            }
            for (int k = 0; k < 4; ++k) v[k] += weight * nodes_[index + k];
        }
        return std::array<double, 2>{v[0] * p1, v[1] * p2 + v[2] * p3 + v[3]};
    };
    // Eq. 3.3: across the slices a Catmull-Rom cubic in log tau through the four around it (a missing
    // end continued linearly), of the logarithm of the light where all four are positive (a ray into
    // a thick particle's shadow dims exponentially with tau), of the light itself clamped at zero
    // otherwise. The light of a ray is not monotonic in tau (single scattering falls where multiple
    // rises), which linear interpolation between slices a factor 2 apart misses by 5-8 %.
    const int m = node[3];
    const std::array<double, 2> v0 = slice_light(m), v1 = slice_light(m + 1);
    const bool below = m > 0, above = m + 2 < shape_.taus;
    const std::array<double, 2> vm = below ? slice_light(m - 1) : std::array<double, 2>{0.0, 0.0};
    const std::array<double, 2> v2 = above ? slice_light(m + 2) : std::array<double, 2>{0.0, 0.0};
    const double f = frac[3], f2 = f * f, f3 = f2 * f;
    const double w[4] = {0.5 * (-f3 + 2 * f2 - f), 0.5 * (3 * f3 - 5 * f2 + 2), 0.5 * (-3 * f3 + 4 * f2 + f),
                         0.5 * (f3 - f2)};
    auto cubic = [&](double a, double b, double c, double d, bool has_a, bool has_d) {
        if (!has_a) a = 2 * b - c;
        if (!has_d) d = 2 * c - b;
        return w[0] * a + w[1] * b + w[2] * c + w[3] * d;
    };
    std::array<double, 2> out;
    for (int k = 0; k < 2; ++k) {
        const bool positive = v0[k] > 0.0 && v1[k] > 0.0 && (!below || vm[k] > 0.0) && (!above || v2[k] > 0.0);
        out[k] = positive ? std::exp(cubic(below ? std::log(vm[k]) : 0.0, std::log(v0[k]), std::log(v1[k]),
                                           above ? std::log(v2[k]) : 0.0, below, above))
                          : std::max(0.0, cubic(vm[k], v0[k], v1[k], v2[k], below, above));
    }
    return {out[0] * thin, out[1] * thin * thin};
}

}  // namespace airlight
