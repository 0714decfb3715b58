// The particle clouds' particles for one frame (physics.md section 4): the
// rings of cells around the viewer, the voxels extruded from them, one
// sphere per occupied voxel, the sun's transmittance to each through a
// coarse lattice of the field's density (section 5), culled to the view and
// sorted from the camera outward; and the screen tiles' lists of the
// particles each may show (section 6).
#pragma once

#include <cstddef>
#include <vector>

#include "airlight/scene.hpp"
#include "screen_tiles.hpp"
#include "shader_cpp.hpp"

namespace airlight {

struct Particle {
    glm::vec3 center{0.0f};
    float radius = 0.0f;             // m
    float tau = 0.0f;                // optical radius: extinction x density x radius
    float sun_transmittance = 1.0f;  // through the other particles toward the sun (section 5)
    float sky_visibility = 1.0f;     // through the other particles straight up (section 5)
    float distance = 0.0f;           // m: from the camera to the centre (the sort key)
};

// A pinhole camera as the shading pass sees it (shaders/geometry.glsl
// camera_ray_direction): right and up scaled by the half-angle tangents.
struct ParticleCamera {
    glm::vec3 position{0.0f}, right{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f}, forward{0.0f, 0.0f, -1.0f};
    int width = 1, height = 1;
};

struct ParticleFieldStats {
    size_t columns = 0;       // cells above the threshold, every ring
    size_t particles = 0;     // occupied voxels (every ring, before culling): the shadow casters
    size_t drawn = 0;         // those in the view
    size_t tile_entries = 0;  // sum over the screen tiles of their list lengths
    size_t bytes = 0;         // the particle and tile arrays handed to the shader
    double model_seconds = 0.0, shadow_seconds = 0.0, sort_seconds = 0.0, bin_seconds = 0.0;
};

// The particles' shadow below them (section 5): the sun's transmittance
// through the lattice from each node of a square grid on the horizontal
// plane y = plane (the lattice's bottom), node (i, j) at
// (x0 + i extent / (size - 1), z0 + j extent / (size - 1)); empty when the
// sun is below the horizon or there are no particles.
struct ParticleShadowMap {
    int size = 0;
    double x0 = 0.0, z0 = 0.0, extent = 1.0, plane = 0.0;
    double top = 0.0;                  // the highest sphere's top (m): the sun lights the air above it
    std::vector<float> transmittance;  // size x size, row j at [j size, (j + 1) size)
};
constexpr int PARTICLE_SHADOW_MAP_SIZE = 256;

struct ParticleField {
    std::vector<Particle> particles;  // the drawn ones, nearest centre first
    ParticleShadowMap shadow_map;
    ParticleFieldStats stats;
};

// Every particle of the field around `camera` (none culled), unsorted, with
// the sun's and the sky's transmittance through the others (sun: unit, toward
// the sun; below the horizon the sun's is 0).
std::vector<Particle> model_particles(const ParticleClouds& clouds, const glm::vec3& camera, const glm::vec3& sun,
                                      ParticleFieldStats* stats = nullptr, ParticleShadowMap* shadow_map = nullptr);

// The frame's particles: modelled, shadowed, culled to the view, sorted; with
// the shadow map where `shadow_map` (a scene with surfaces that could be in
// their shadow).
ParticleField particle_field(const ParticleClouds& clouds, const ParticleCamera& camera, const glm::vec3& sun,
                             bool shadow_map = true);

// Screen tiles of PARTICLE_TILE_SIZE pixels: for tile k (row-major), its list
// of particle indices (into the sorted array, ascending: nearest first) in
// entries[offsets[k] .. offsets[k + 1]). A particle is listed in every tile
// its conservative screen rectangle overlaps.
ScreenTiles bin_particles(const std::vector<Particle>& particles, const ParticleCamera& camera, int tile_size);

struct FrameData;
// The camera of a frame's shading pass (frame_data's camera and film).
ParticleCamera particle_camera(const FrameData& data);

// The most entries the tile lists may hold (physics.md section 6: the memory
// bound; beyond it the frame fails with a message naming the keys to change).
constexpr size_t PARTICLE_MAX_TILE_ENTRIES = size_t(1) << 24;
// The most voxels the occupied columns may hold (their particles: 32 bytes each, 256 MiB), and the
// most cells the rings may hold (particle_keys.cpp rejects more).
constexpr size_t PARTICLE_MAX_VOXELS = size_t(1) << 23;
constexpr size_t PARTICLE_MAX_CELLS = size_t(1) << 22;

}  // namespace airlight
