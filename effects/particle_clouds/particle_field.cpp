// The particle clouds' particles for one frame (physics.md sections 4-6).
#include "particle_field.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>

#include "noise.hpp"
#include "numerics.hpp"

namespace airlight {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The cross-fade band of a ring (eq. 4.2): the outer quarter of its half-width.
constexpr double RING_FADE = 0.25;

double smoothstep01(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

// A well-mixed 32-bit hash of a voxel's integer coordinates (its fixed jitter).
uint32_t voxel_hash(int seed, int level, long long i, long long j, int k) {
    uint64_t h = 0x9E3779B97F4A7C15ull ^ uint64_t(uint32_t(seed));
    for (uint64_t v : {uint64_t(level), uint64_t(i), uint64_t(j), uint64_t(k)}) {
        h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    return uint32_t(h >> 16);
}

// The density texture at a point of the ground (eq. 4.1): Perlin fBm and
// Worley cells in equal parts, tiling with period shape_scale, drifting with
// the wind; in [0, 1].
double ground_density(const ParticleClouds& c, double x, double z) {
    const double u = (x - double(c.wind_x) * c.time) / c.shape_scale;
    const double v = (z - double(c.wind_z) * c.time) / c.shape_scale;
    return 0.5 * cloud_perlin_fbm(c.seed, u, 0.5, v) + 0.5 * cloud_worley(c.seed, 4, u, 0.5, v);
}

// A cell's column strength (eq. 4.1): the texture remapped by the coverage,
// above the threshold, in [0, 1]; 0 is no cloud.
double column_strength(const ParticleClouds& c, double density) {
    const double covered = std::clamp((density - (1.0 - c.coverage)) / std::max(double(c.coverage), 1e-3), 0.0, 1.0);
    return std::max(0.0, (covered - c.threshold) / (1.0 - c.threshold));
}

struct Cell {
    int level;
    long long i, j;  // the cell's index on its ring's lattice (edge cell_size 2^level)
    float weight;    // the ring's cross-fade weight (eq. 4.2)
    float strength;  // the column strength (eq. 4.1)
};

// A coarse grid of the field's extinction over the particles' bounding box (section 5).
struct Lattice {
    glm::dvec3 origin{0.0}, cell{1.0};
    int nx = 1, ny = 1, nz = 1;
    std::vector<float> sigma;  // 1/m at cell centres, x fastest

    std::vector<float> above;  // optical depth from each cell centre straight up to the top (the sky's)

    float at(int x, int y, int z) const { return sigma[(size_t(z) * ny + y) * nx + x]; }
    // Fills `above` by summing each column from the top (midpoint rule, half of a cell's own).
    void integrate_columns() {
        above.assign(sigma.size(), 0.0f);
        for (int z = 0; z < nz; ++z)
            for (int x = 0; x < nx; ++x) {
                double sum = 0.0;
                for (int y = ny - 1; y >= 0; --y) {
                    const size_t i = (size_t(z) * ny + y) * nx + x;
                    above[i] = float(sum + 0.5 * sigma[i] * cell.y);
                    sum += sigma[i] * cell.y;
                }
            }
    }
    // The optical depth straight up from p: `above` trilinear (continuous in p); 0 above the box.
    double depth_above(const glm::dvec3& p) const {
        const glm::dvec3 f = (p - origin) / cell - 0.5;
        const double fy = std::clamp(f.y, 0.0, double(ny - 1));
        const int x0 = int(std::floor(f.x)), z0 = int(std::floor(f.z));
        const int y0 = std::min(int(fy), ny - 2 < 0 ? 0 : ny - 2);
        const double ax = f.x - x0, az = f.z - z0, ay = ny > 1 ? fy - y0 : 0.0;
        double sum = 0.0;
        for (int c = 0; c < 8; ++c) {
            const int x = x0 + (c & 1), y = std::min(y0 + ((c >> 1) & 1), ny - 1), z = z0 + ((c >> 2) & 1);
            if (x < 0 || z < 0 || x >= nx || z >= nz) continue;
            sum += ((c & 1) ? ax : 1 - ax) * (((c >> 1) & 1) ? ay : 1 - ay) * (((c >> 2) & 1) ? az : 1 - az) *
                   above[(size_t(z) * ny + y) * nx + x];
        }
        // Above the top cell's centre the column's depth falls linearly to 0 at the box's top.
        if (f.y > ny - 1) sum *= std::max(0.0, 1.0 - 2.0 * (f.y - (ny - 1)));
        return sum;
    }
    // Trilinear at p (cell-centred), 0 outside.
    double sample(const glm::dvec3& p) const {
        const glm::dvec3 f = (p - origin) / cell - 0.5;
        const int x0 = int(std::floor(f.x)), y0 = int(std::floor(f.y)), z0 = int(std::floor(f.z));
        const double ax = f.x - x0, ay = f.y - y0, az = f.z - z0;
        double sum = 0.0;
        for (int c = 0; c < 8; ++c) {
            const int x = x0 + (c & 1), y = y0 + ((c >> 1) & 1), z = z0 + ((c >> 2) & 1);
            if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) continue;
            sum +=
                ((c & 1) ? ax : 1 - ax) * (((c >> 1) & 1) ? ay : 1 - ay) * (((c >> 2) & 1) ? az : 1 - az) * at(x, y, z);
        }
        return sum;
    }
    // Optical depth from p along unit d to the box's exit (eq. 5.2): steps of half a cell from
    // p, the last one cut at the exit, so that the sum moves continuously with p.
    double optical_depth(glm::dvec3 p, const glm::dvec3& d) const {
        const glm::dvec3 lo = origin, hi = origin + cell * glm::dvec3(nx, ny, nz);
        double t_exit = 1e300;
        for (int a = 0; a < 3; ++a) {
            if (d[a] > 1e-12)
                t_exit = std::min(t_exit, (hi[a] - p[a]) / d[a]);
            else if (d[a] < -1e-12)
                t_exit = std::min(t_exit, (lo[a] - p[a]) / d[a]);
        }
        if (!(t_exit > 0.0)) return 0.0;
        // Half a cell along the axis the ray crosses cells fastest.
        const double step = 0.5 / std::max({std::fabs(d.x) / cell.x, std::fabs(d.y) / cell.y, std::fabs(d.z) / cell.z});
        double sum = 0.0;
        for (double t = 0.0; t < t_exit; t += step) {
            const double h = std::min(step, t_exit - t);
            sum += sample(p + (t + 0.5 * h) * d) * h;
        }
        return sum;
    }
};

// The lattice of the particles' extinction, each particle's mass sigma V
// spread over the cells its sphere covers (eq. 5.1), mass conserved. Its
// cells lie on a world grid whose size follows from the keys alone (the
// rings' extent over LATTICE_CELLS_XZ, at least cell_size; the layer and the
// largest particle's radius over LATTICE_CELLS_Y), so that a point's value
// changes continuously as the viewer moves (section 5).
constexpr int LATTICE_CELLS_XZ = 160, LATTICE_CELLS_Y = 48;  // 4.9 MiB at most
Lattice build_lattice(const std::vector<Particle>& ps, const ParticleClouds& c, const glm::dvec3& viewer) {
    Lattice L;
    const double outer = double(c.cell_size) * std::ldexp(1.0, c.rings - 1);  // the outermost ring's cell
    const double reach = c.ring_cells * outer + double(c.particle_size) * outer + outer;
    const double xz = std::max(double(c.cell_size), 2.0 * reach / (LATTICE_CELLS_XZ - 2));
    const double y_lo = double(c.base) - double(c.particle_size) * outer;
    const double y_hi = double(c.top) + double(c.particle_size) * outer;
    L.cell = glm::dvec3(xz, (y_hi - y_lo) / LATTICE_CELLS_Y, xz);
    L.nx = L.nz = std::min(LATTICE_CELLS_XZ, int(std::ceil(2.0 * reach / xz)) + 2);
    L.ny = LATTICE_CELLS_Y;
    L.origin = glm::dvec3(std::floor((viewer.x - reach) / xz) * xz, y_lo, std::floor((viewer.z - reach) / xz) * xz);
    L.sigma.assign(size_t(L.nx) * L.ny * L.nz, 0.0f);
    const double cell_volume = L.cell.x * L.cell.y * L.cell.z;
    const double half_diagonal = 0.5 * glm::length(L.cell);
    for (const Particle& p : ps) {
        const double R = p.radius, mass = double(p.tau) / R * (4.0 / 3.0) * numerics::kPi * R * R * R;
        if (!(mass > 0.0)) continue;
        const glm::dvec3 q(p.center);
        const glm::ivec3 a = glm::clamp(glm::ivec3(glm::floor((q - R - half_diagonal - L.origin) / L.cell)),
                                        glm::ivec3(0), glm::ivec3(L.nx - 1, L.ny - 1, L.nz - 1));
        const glm::ivec3 b = glm::clamp(glm::ivec3(glm::floor((q + R + half_diagonal - L.origin) / L.cell)),
                                        glm::ivec3(0), glm::ivec3(L.nx - 1, L.ny - 1, L.nz - 1));
        // A cell's share: 1 inside the sphere, 0 outside, linear across a band of one cell
        // half-diagonal about its surface; normalised so the shares sum to the mass.
        auto share = [&](int x, int y, int z) {
            const glm::dvec3 m = L.origin + (glm::dvec3(x, y, z) + 0.5) * L.cell;
            return std::clamp(0.5 + (R - glm::length(m - q)) / (2.0 * half_diagonal), 0.0, 1.0);
        };
        double total = 0.0;
        for (int z = a.z; z <= b.z; ++z)
            for (int y = a.y; y <= b.y; ++y)
                for (int x = a.x; x <= b.x; ++x) total += share(x, y, z);
        if (!(total > 0.0)) continue;
        const double scale = mass / (total * cell_volume);
        for (int z = a.z; z <= b.z; ++z)
            for (int y = a.y; y <= b.y; ++y)
                for (int x = a.x; x <= b.x; ++x)
                    L.sigma[(size_t(z) * L.ny + y) * L.nx + x] += float(scale * share(x, y, z));
    }
    return L;
}

// The conservative screen rectangle of a sphere, in pixels [x0, x1] x [y0, y1]
// (rows down); false when it is behind the camera or off the film.
bool screen_rectangle(const Particle& p, const ParticleCamera& cam, int& x0, int& x1, int& y0, int& y1) {
    const glm::vec3 v = p.center - cam.position;
    const float right_length = glm::length(cam.right), up_length = glm::length(cam.up);
    const float z = glm::dot(v, cam.forward), R = p.radius;
    if (z < -R) return false;
    float sx0 = -1.0f, sx1 = 1.0f, sy0 = -1.0f, sy1 = 1.0f;
    if (z > 1.0001f * R) {
        // X / Z over the sphere lies within the extremes of (x -+ R) / (z -+ R) (Z > 0 throughout).
        const float x = glm::dot(v, cam.right) / right_length, y = glm::dot(v, cam.up) / up_length;
        const float near = z - R, far = z + R;
        sx0 = std::min((x - R) / near, (x - R) / far) / right_length;
        sx1 = std::max((x + R) / near, (x + R) / far) / right_length;
        sy0 = std::min((y - R) / near, (y - R) / far) / up_length;
        sy1 = std::max((y + R) / near, (y + R) / far) / up_length;
        if (sx1 < -1.0f || sx0 > 1.0f || sy1 < -1.0f || sy0 > 1.0f) return false;
    }
    const float W = float(cam.width), H = float(cam.height);
    x0 = std::clamp(int(std::floor(0.5f * (sx0 + 1.0f) * W)) - 1, 0, cam.width - 1);
    x1 = std::clamp(int(std::floor(0.5f * (sx1 + 1.0f) * W)) + 1, 0, cam.width - 1);
    y0 = std::clamp(int(std::floor(0.5f * (1.0f - sy1) * H)) - 1, 0, cam.height - 1);
    y1 = std::clamp(int(std::floor(0.5f * (1.0f - sy0) * H)) + 1, 0, cam.height - 1);
    return true;
}

}  // namespace

std::vector<Particle> model_particles(const ParticleClouds& c, const glm::vec3& camera, const glm::vec3& sun,
                                      ParticleFieldStats* stats, ParticleShadowMap* shadow_map) {
    auto start = Clock::now();
    std::vector<Particle> out;
    if (!particle_clouds_visible(c)) return out;
    // Eq. 4.2: ring k spans the Chebyshev distance from the viewer [0.75 H_{k-1}, H_k], H_k its
    // ring_cells cells of edge cell_size 2^k; its cells fade in and out across the outer quarters.
    std::vector<Cell> cells;
    const double cx = camera.x, cz = camera.z;
    for (int level = 0; level < c.rings; ++level) {
        const double a = double(c.cell_size) * std::ldexp(1.0, level), H = c.ring_cells * a;
        const double H_inner = level == 0 ? 0.0 : 0.5 * H;
        const long long i0 = (long long)std::floor((cx - H) / a) - 1, i1 = (long long)std::floor((cx + H) / a) + 1;
        const long long j0 = (long long)std::floor((cz - H) / a) - 1, j1 = (long long)std::floor((cz + H) / a) + 1;
        for (long long j = j0; j <= j1; ++j)
            for (long long i = i0; i <= i1; ++i) {
                const double x = (i + 0.5) * a, z = (j + 0.5) * a;
                const double rho = std::max(std::fabs(x - cx), std::fabs(z - cz));
                const double out_w = smoothstep01((H - rho) / (RING_FADE * H));
                const double in_w =
                    level == 0 ? 1.0 : smoothstep01((rho - (1.0 - RING_FADE) * H_inner) / (RING_FADE * H_inner));
                const double w = out_w * in_w;
                if (w > 0.0) cells.push_back({level, i, j, float(w), 0.0f});
            }
    }
    numerics::parallel_for(int(cells.size()), [&](int k) {
        Cell& cell = cells[size_t(k)];
        const double a = double(c.cell_size) * std::ldexp(1.0, cell.level);
        cell.strength = float(column_strength(c, ground_density(c, (cell.i + 0.5) * a, (cell.j + 0.5) * a)));
    });
    cells.erase(std::remove_if(cells.begin(), cells.end(), [](const Cell& k) { return !(k.strength > 0.0f); }),
                cells.end());
    size_t voxels = 0;
    for (const Cell& cell : cells)
        voxels += size_t(std::max(
            1L, std::lround((double(c.top) - double(c.base)) / (double(c.cell_size) * std::ldexp(1.0, cell.level)))));
    if (voxels > PARTICLE_MAX_VOXELS)
        throw std::runtime_error("particle_clouds: the cloudy columns around the viewer hold " +
                                 std::to_string(voxels) + " voxels, more than the bound of " +
                                 std::to_string(PARTICLE_MAX_VOXELS) +
                                 "; raise cell_size or lower ring_cells, rings or top - base");
    // Eq. 4.3: each column's voxels, density falling with height to zero at sqrt(strength) of the
    // layer, perturbed by a drifting noise; one particle per voxel of positive density.
    const double thickness = double(c.top) - double(c.base);
    std::vector<std::vector<Particle>> per_cell(cells.size());
    numerics::parallel_for(int(cells.size()), [&](int k) {
        const Cell& cell = cells[size_t(k)];
        const double a = double(c.cell_size) * std::ldexp(1.0, cell.level);
        const int n = std::max(1, int(std::lround(thickness / a)));
        const double h = thickness / n, top_fraction = std::sqrt(double(cell.strength));
        for (int v = 0; v < n; ++v) {
            const double eta = (v + 0.5) / n;
            if (eta >= top_fraction) break;
            const uint32_t hash = voxel_hash(c.seed, cell.level, cell.i, cell.j, v);
            const double jx = ((hash & 0xFF) / 255.0 - 0.5) * 0.5 * a,
                         jz = (((hash >> 8) & 0xFF) / 255.0 - 0.5) * 0.5 * a;
            const double jy = (((hash >> 16) & 0xFF) / 255.0 - 0.5) * 0.25 * h;
            const double x = (cell.i + 0.5) * a + jx, y = c.base + (v + 0.5) * h + jy, z = (cell.j + 0.5) * a + jz;
            const double u = (x - double(c.wind_x) * c.time) / c.detail_scale;
            const double w = (z - double(c.wind_z) * c.time) / c.detail_scale;
            const double perturb = cloud_perlin_fbm(c.seed + 1, u, (y - c.base) / c.detail_scale, w);
            const double density = cell.strength * (1.0 - eta / top_fraction) * (0.4 + 1.2 * perturb);
            if (!(density > 0.0)) continue;
            Particle p;
            p.center = glm::vec3(float(x), float(y), float(z));
            p.radius = float(c.particle_size * a);
            p.tau = float(double(c.extinction) * density * cell.weight * p.radius);
            per_cell[size_t(k)].push_back(p);
        }
    });
    for (auto& list : per_cell) out.insert(out.end(), list.begin(), list.end());
    if (stats) {
        stats->columns = cells.size();
        stats->particles = out.size();
        stats->model_seconds = seconds_since(start);
    }
    // Section 5: the sun's and the sky's transmittance through the lattice.
    start = Clock::now();
    Lattice lattice = build_lattice(out, c, glm::dvec3(camera));
    lattice.integrate_columns();
    const glm::dvec3 s(sun), up(0.0, 1.0, 0.0);
    const bool sun_up = sun.y > 0.0f;
    numerics::parallel_for_chunks(int(out.size()), [&](int begin, int end) {
        for (int k = begin; k < end; ++k) {
            Particle& p = out[size_t(k)];
            const glm::dvec3 q(p.center);
            p.sun_transmittance = sun_up ? float(std::exp(-lattice.optical_depth(q + double(p.radius) * s, s))) : 0.0f;
            p.sky_visibility = float(std::exp(-lattice.depth_above(q + double(p.radius) * up)));
        }
    });
    // The shadow below (eq. 5.3): each sphere's chord along the sun's ray from every node of the map
    // its shadow covers (within R / s_y of its centre's projection), summed exactly.
    if (shadow_map && sun_up && !out.empty()) {
        ParticleShadowMap& m = *shadow_map;
        m.size = PARTICLE_SHADOW_MAP_SIZE;
        m.x0 = lattice.origin.x;
        m.z0 = lattice.origin.z;
        m.extent = lattice.cell.x * lattice.nx;
        m.plane = lattice.origin.y;
        std::vector<double> depth(size_t(m.size) * m.size, 0.0);
        const double texel = m.extent / (m.size - 1);
        m.top = m.plane;
        for (const Particle& p : out) {
            const glm::dvec3 c(p.center);
            const double R = p.radius, sigma = double(p.tau) / R;
            m.top = std::max(m.top, c.y + R);
            const glm::dvec3 foot = c - ((c.y - m.plane) / s.y) * s;  // the centre's projection along the sun
            const double reach = R / s.y;
            const int i0 = std::max(0, int(std::ceil((foot.x - reach - m.x0) / texel)));
            const int i1 = std::min(m.size - 1, int(std::floor((foot.x + reach - m.x0) / texel)));
            const int j0 = std::max(0, int(std::ceil((foot.z - reach - m.z0) / texel)));
            const int j1 = std::min(m.size - 1, int(std::floor((foot.z + reach - m.z0) / texel)));
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    const glm::dvec3 oc = c - glm::dvec3(m.x0 + i * texel, m.plane, m.z0 + j * texel);
                    const double b = glm::dot(oc, s), h2 = R * R - (glm::dot(oc, oc) - b * b);
                    if (h2 > 0.0) depth[size_t(j) * m.size + i] += sigma * 2.0 * std::sqrt(h2);
                }
        }
        m.transmittance.resize(depth.size());
        for (size_t k = 0; k < depth.size(); ++k) m.transmittance[k] = float(std::exp(-depth[k]));
    }
    if (stats) stats->shadow_seconds = seconds_since(start);
    return out;
}

ParticleField particle_field(const ParticleClouds& clouds, const ParticleCamera& camera, const glm::vec3& sun,
                             bool shadow_map) {
    ParticleField field;
    std::vector<Particle> all =
        model_particles(clouds, camera.position, sun, &field.stats, shadow_map ? &field.shadow_map : nullptr);
    const auto start = Clock::now();
    int x0, x1, y0, y1;
    for (Particle& p : all) {
        if (!(p.tau > 0.0f) || !screen_rectangle(p, camera, x0, x1, y0, y1)) continue;
        p.distance = glm::length(p.center - camera.position);
        field.particles.push_back(p);
    }
    // Nearest first; ties (none in practice) by position, so the order never depends on the modelling's.
    std::sort(field.particles.begin(), field.particles.end(), [](const Particle& a, const Particle& b) {
        if (a.distance != b.distance) return a.distance < b.distance;
        if (a.center.x != b.center.x) return a.center.x < b.center.x;
        if (a.center.y != b.center.y) return a.center.y < b.center.y;
        return a.center.z < b.center.z;
    });
    field.stats.drawn = field.particles.size();
    field.stats.sort_seconds = seconds_since(start);
    return field;
}

ScreenTiles bin_particles(const std::vector<Particle>& particles, const ParticleCamera& camera, int tile_size) {
    std::vector<glm::ivec4> rects(particles.size(), glm::ivec4(0, -1, 0, -1));
    for (size_t i = 0; i < particles.size(); ++i) {
        int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
        if (screen_rectangle(particles[i], camera, x0, x1, y0, y1)) rects[i] = glm::ivec4(x0, x1, y0, y1);
    }
    return bin_screen_rectangles(
        rects, camera.width, camera.height, tile_size, PARTICLE_MAX_TILE_ENTRIES,
        "particle_clouds: the particles in view cover more than 2^24 screen-tile entries (the tile lists' "
        "memory bound); use fewer or larger particles (cell_size, ring_cells, rings) or a smaller film");
}

}  // namespace airlight
