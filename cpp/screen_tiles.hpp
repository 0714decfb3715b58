// Screen tiles for effects that composite many small objects per pixel (the
// particle clouds' particles, the falling rain's streaks; docs/architecture.md
// "Passes"): each object's pixel rectangle binned into square tiles, the
// lists stored as one table the shading pass reads; and per-frame tables laid
// out in rows.
#pragma once

#include <glm/vec4.hpp>
#include <memory>
#include <string>
#include <vector>

#include "tables.hpp"

namespace airlight {

struct ScreenTiles {
    int tiles_x = 0, tiles_y = 0;
    std::vector<int> offsets;  // tiles + 1: tile t's entries are [offsets[t], offsets[t + 1])
    std::vector<int> entries;  // object indices, in the objects' order within each tile
};

// Bins objects by their inclusive pixel rectangles (x0, x1, y0, y1; x1 < x0:
// off the film) on a width x height film into tiles of tile_size pixels.
// Throws std::runtime_error(too_many) beyond max_entries entries.
ScreenTiles bin_screen_rectangles(const std::vector<glm::ivec4>& rects, int width, int height, int tile_size,
                                  size_t max_entries, const std::string& too_many);

// The tiles as one table's floats: the offsets, then the entries (indices
// exact in float32 below 2^24).
std::vector<float> screen_tile_texels(const ScreenTiles& tiles);

// A per-frame table of `texels` floats (`channels` per texel) in rows of
// row_texels texels, at least one row.
std::shared_ptr<const Table2D> row_table(const char* name, int channels, int row_texels, std::vector<float> texels);

}  // namespace airlight
