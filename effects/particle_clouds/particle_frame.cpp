// The particle clouds' part of the frame (physics.md sections 3-6): the
// lighting table for the droplets' g (built once per process, kept on disk),
// the frame's particles and the screen tiles' lists, as tables both backends
// read; nothing for a scene without particle clouds.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "frame_data.hpp"
#include "particle_field.hpp"
#include "particle_table.hpp"

namespace airlight {

namespace {

// Bumped whenever the solver or the table's layout changes: older files on disk are ignored.
constexpr int TABLE_FILE_VERSION = 9;  // 2: the orders beyond 18 (physics.md 2.7); 3: cubic between nodes (2.3);
                                       // 4, 5: polar nodes graded toward the terminator (2.14); 6, 7: entry angles
                                       // dense across the terminator (3.2); 8: 24 radii, steps levelled off (2.7);
                                       // 9: 48 polar nodes for thick, forward-scattering slices (2.6)

// Where built tables are kept: $AIRLIGHT_CACHE_DIR, else $XDG_CACHE_HOME/airlight, else
// ~/.cache/airlight; empty (no disk cache) when none can be named.
std::filesystem::path cache_dir() {
    if (const char* d = std::getenv("AIRLIGHT_CACHE_DIR"); d && *d) return d;
    if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::filesystem::path(d) / "airlight";
    if (const char* d = std::getenv("HOME"); d && *d) return std::filesystem::path(d) / ".cache" / "airlight";
    return {};
}

// The lighting table as a texture (eq. 3.1): texel (a + A z, e + E m) holds node
// [m][e][z][a], which is ParticleTable::nodes' order: the texels are the nodes.
Table2D build_light_table(float g, ParticleTableQuality quality) {
    const ParticleTableShape shape = particle_table_shape(quality);
    Table2D t;
    t.width = shape.view_azimuth * shape.view_zenith;
    t.height = shape.entry * shape.taus;
    t.channels = 4;
    const size_t count = size_t(t.width) * t.height * 4;
    char name[96];
    std::snprintf(name, sizeof name, "particle_light_v%d_%s_g%.6f.bin", TABLE_FILE_VERSION,
                  quality == ParticleTableQuality::full ? "full" : "preview", double(g));
    const std::filesystem::path dir = cache_dir();
    auto read_cached = [&] {
        std::ifstream in(dir / name, std::ios::binary);
        t.texels.resize(count);
        return in.read(reinterpret_cast<char*>(t.texels.data()), std::streamsize(count * sizeof(float))) &&
               in.peek() == std::char_traits<char>::eof();
    };
    if (!dir.empty() && read_cached()) return t;
    // One process builds, the others wait for its file: several renderers
    // starting at once (a batch's workers, parallel tests) would otherwise each
    // spend minutes on the same table. The lock goes with its process.
    std::error_code ec;
    int lock = -1;
    if (!dir.empty()) {
        std::filesystem::create_directories(dir, ec);
        lock = ::open((dir / (std::string(name) + ".lock")).c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (lock >= 0 && ::flock(lock, LOCK_EX) == 0 && read_cached()) {
            ::close(lock);
            return t;
        }
    }
    struct CloseLock {
        int fd;
        ~CloseLock() {
            if (fd >= 0) ::close(fd);
        }
    } close_lock{lock};
    const ParticleTable table(g, shape);
    t.texels = table.nodes();
    if (!dir.empty()) {
        // Written to a temporary name and renamed, so that a concurrent reader never sees half a file.
        const std::filesystem::path part = dir / (std::string(name) + ".part" + std::to_string(std::rand()));
        {
            std::ofstream out(part, std::ios::binary);
            out.write(reinterpret_cast<const char*>(t.texels.data()), std::streamsize(count * sizeof(float)));
        }
        std::filesystem::rename(part, dir / name, ec);
        if (ec) std::filesystem::remove(part, ec);
    }
    return t;
}

std::shared_ptr<const Table2D> light_table(float g, ParticleTableQuality quality) {
    static TableCache<std::pair<float, int>> cache(2);
    return cache.get({g, int(quality)},
                     [&] { return timed_build("particle_light", [&] { return build_light_table(g, quality); }); });
}

}  // namespace

ParticleCamera particle_camera(const FrameData& data) {
    ParticleCamera cam;
    cam.position = glm::vec3(data.frame.camera_position);
    cam.right = glm::vec3(data.frame.camera_right);
    cam.up = glm::vec3(data.frame.camera_up);
    cam.forward = glm::vec3(data.frame.camera_forward);
    cam.width = data.frame.film_width;
    cam.height = data.frame.film_height;
    return cam;
}

void pack_particle_clouds_frame(const Scene& scene, FrameData& data) {
    const ParticleClouds& c = scene.particle_clouds;
    data.features.particle_clouds = particle_clouds_visible(c);
    if (!data.features.particle_clouds) return;
    const ParticleCamera cam = particle_camera(data);
    // The shadow map only where surfaces, or air that scatters the sun's light, may lie in the
    // particles' shadow (physics.md section 5).
    // (The light shafts' medium_sun switch is set after every effect's pack: the sun and a scattering medium.)
    const bool sunlit_air = data.features.sun && (data.features.atmosphere || data.scattering);
    const bool air_shadow = scene.quality.cloud_shadow_steps > 0 && sunlit_air;
    const ParticleField field =
        particle_field(c, cam, glm::vec3(data.frame.sky.sun_direction), data.features.surfaces || air_shadow);
    // Brute force ("all"): one tile, the whole film, every pixel testing every particle.
    const int tile_size = scene.quality.particle_compositing == ParticleCompositing::tiles
                              ? shader::PARTICLE_TILE_SIZE
                              : std::max(cam.width, cam.height);
    const ScreenTiles tiles = bin_particles(field.particles, cam, tile_size);
    std::vector<float> particles;
    particles.reserve(field.particles.size() * 8);
    for (const Particle& p : field.particles)
        for (float v :
             {p.center.x, p.center.y, p.center.z, p.radius, p.tau, p.sun_transmittance, p.sky_visibility, 0.0f})
            particles.push_back(v);
    const ParticleTableShape shape = particle_table_shape(scene.quality.particle_table);
    shader::ParticleCloudsGpu& g = data.frame.particle_clouds;
    g.table_shape = glm::ivec4(shape.entry, shape.view_zenith, shape.view_azimuth, shape.taus);
    g.table_taus = glm::vec4(float(shape.tau_min), float(std::log(shape.tau_max / shape.tau_min)), c.g,
                             shape.dense_terminator ? 1.0f : 0.0f);
    g.tiles = glm::ivec4(tiles.tiles_x, tiles.tiles_y, int(field.particles.size()), tile_size);
    if (const ParticleShadowMap& m = field.shadow_map; m.size > 0) {
        auto t = std::make_shared<Table2D>();
        t->name = "particle_shadow";
        t->width = t->height = m.size;
        t->texels = m.transmittance;
        t->serial = next_table_serial();
        data.use_table(shader::TABLE_PARTICLE_SHADOW, std::move(t));
        g.shadow_map = glm::vec4(float(m.x0), float(m.z0), float(1.0 / m.extent), float(m.plane));
        g.shadow_size = glm::ivec4(m.size, 0, 0, 0);
        g.air_shadow = glm::vec4(float(m.top), air_shadow ? float(scene.quality.cloud_shadow_steps) : 0.0f, 0.0f, 0.0f);
    }
    if (particles.empty()) particles.assign(8, 0.0f);
    data.use_table(shader::TABLE_PARTICLES,
                   row_table("particles", 4, shader::PARTICLE_ROW_TEXELS, std::move(particles)));
    data.use_table(shader::TABLE_PARTICLE_TILES,
                   row_table("particle_tiles", 1, shader::PARTICLE_ROW_TEXELS, screen_tile_texels(tiles)));
    data.use_table(shader::TABLE_PARTICLE_LIGHT, light_table(c.g, scene.quality.particle_table));
}

}  // namespace airlight
