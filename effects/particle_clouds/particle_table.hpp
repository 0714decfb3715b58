// The particle clouds' lighting table (effects/particle_clouds/physics.md
// section 3): the light a camera receives from a particle, per unit sun
// irradiance, indexed by where its ray enters the particle relative to the
// sun, the ray's direction there and the particle's optical radius; built
// from the reference particle solved order by order (sphere_scattering.hpp).
#pragma once

#include <array>
#include <vector>

#include "airlight/scene.hpp"
#include "sphere_scattering.hpp"

namespace airlight {

// The table's nodes (eq. 3.2, particle_table_math.glsl: the entry angle dense across the terminator,
// the view zenith dense near grazing, uniform in the azimuth, log-uniform in the optical radius).
struct ParticleTableShape {
    int entry = 64;         // the entry point's angle from the sun, [0, pi]
    int view_zenith = 32;   // the ray's angle from the inward normal there, [0, pi / 2]
    int view_azimuth = 32;  // its azimuth about the normal from the sun's side, [0, pi]
    int taus = 12;          // optical radii, log-uniform in [tau_min, tau_max]
    double tau_min = 0.1;
    double tau_max = 50.0;
    // Entry angles dense across the terminator (eq. 3.2); false: uniform, for comparisons.
    bool dense_terminator = true;
    int steps = 32;   // ray integral steps of each node (eq. 2.6)
    SphereGrid grid;  // the solver's grid at each optical radius
};

// Throws std::invalid_argument naming the field when a shape is out of range.
void validate_particle_table_shape(const ParticleTableShape& shape);

// The shape the renderer builds for a quality setting (quality.particle_table).
ParticleTableShape particle_table_shape(ParticleTableQuality quality);

class ParticleTable {
public:
    // Solves the reference particle at every optical radius of `shape` (g in [0, 0.99]).
    ParticleTable(double g, const ParticleTableShape& shape = {});

    // The radiance of a ray entering a particle of optical radius tau at a point whose outward normal
    // is `normal`, looking along `view` (unit, view . normal < 0), with the sun toward `sun` (unit), per
    // unit sun irradiance: {order 1, orders 2..N} (eq. 3.1, 3.2).
    std::array<double, 2> lookup(double tau, const double normal[3], const double view[3], const double sun[3]) const;

    double g() const { return g_; }
    const ParticleTableShape& shape() const { return shape_; }
    double build_seconds() const { return build_seconds_; }
    // The optical radius of slice m (log-uniform in [tau_min, tau_max]).
    double slice_tau(int m) const;
    // The stored nodes: [tau][entry][view_zenith][view_azimuth][4], SphereScattering::table_channels.
    const std::vector<float>& nodes() const { return nodes_; }

private:
    double g_;
    ParticleTableShape shape_;
    std::vector<float> nodes_;
    double build_seconds_ = 0.0;
};

}  // namespace airlight
