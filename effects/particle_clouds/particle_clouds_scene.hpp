// The particle clouds' scene data: "particle_clouds" in the scene format
// (particle_keys.cpp parses it; physics.md section 4 defines every field).
#pragma once

namespace airlight {

// Cumulus built from spherical particles (physics.md section 4): a density
// texture tiled over nested square rings of cells around the viewer, each
// ring's cells twice the size of the one inside it; the cells above a
// threshold extruded upward into voxels whose density falls with height;
// one particle per occupied voxel. The keys shared with "clouds" (CloudLayer,
// effects/noise_clouds/clouds_scene.hpp) mean the same.
struct ParticleClouds : CloudLayer {
    ParticleClouds() { top = 3500.0f; }  // the tallest column reaches the top
    float threshold = 0.1f;              // [0, 1): a column is cloud where its density exceeds this
    float g = 0.85f;                     // Henyey-Greenstein asymmetry of the droplets (the table's)
    float cell_size = 200.0f;            // m: the innermost ring's cells (and voxels)
    int ring_cells = 16;                 // cells from the viewer to the edge of each ring (in that ring's cells)
    int rings = 4;                       // nested rings; ring k's cells are cell_size 2^k
    float particle_size = 0.75f;         // a particle's radius over its voxel's edge
    float detail_scale = 1500.0f;        // m: the tile of the noise that perturbs the voxels' density
};

// Particle clouds that can be seen: some coverage and extinction (a scene
// without builds no table and runs no particle code).
inline bool particle_clouds_visible(const ParticleClouds& c) {
    return c.present && c.coverage > 0.0f && c.extinction > 0.0f;
}

// The lighting table's resolution (physics.md section 3; effects/particle_clouds/docs/table_resolution.txt).
enum class ParticleTableQuality {
    full,     // 64 x 32 x 32 angles (entry dense across the terminator), 12 optical radii
    preview,  // 16 x 8 x 16 angles, 8 optical radii, a coarser solver grid: for tests and previews
};

// How a pixel finds its particles (physics.md section 6).
enum class ParticleCompositing {
    tiles,  // the lists of its screen tile
    all,    // every particle in view: brute force, for comparisons
};

// The particle clouds' quality settings (a base of Quality).
struct ParticleCloudsQuality {
    ParticleTableQuality particle_table = ParticleTableQuality::full;
    ParticleCompositing particle_compositing = ParticleCompositing::tiles;
};

}  // namespace airlight
