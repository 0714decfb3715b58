// Screen tiles (screen_tiles.hpp).
#include "screen_tiles.hpp"

#include <algorithm>
#include <stdexcept>

namespace airlight {

ScreenTiles bin_screen_rectangles(const std::vector<glm::ivec4>& rects, int width, int height, int tile_size,
                                  size_t max_entries, const std::string& too_many) {
    ScreenTiles t;
    t.tiles_x = (width + tile_size - 1) / tile_size;
    t.tiles_y = (height + tile_size - 1) / tile_size;
    const size_t tiles = size_t(t.tiles_x) * t.tiles_y;
    // Each rectangle in tiles, clamped to the film.
    std::vector<glm::ivec4> in_tiles(rects.size(), glm::ivec4(0, -1, 0, -1));
    std::vector<size_t> counts(tiles + 1, 0);
    for (size_t i = 0; i < rects.size(); ++i) {
        const glm::ivec4 r = rects[i];
        if (r.y < r.x || r.w < r.z || r.y < 0 || r.w < 0 || r.x >= width || r.z >= height) continue;
        in_tiles[i] = glm::ivec4(std::max(r.x, 0) / tile_size, std::min(r.y, width - 1) / tile_size,
                                 std::max(r.z, 0) / tile_size, std::min(r.w, height - 1) / tile_size);
        for (int y = in_tiles[i].z; y <= in_tiles[i].w; ++y)
            for (int x = in_tiles[i].x; x <= in_tiles[i].y; ++x) ++counts[size_t(y) * t.tiles_x + x + 1];
    }
    t.offsets.assign(tiles + 1, 0);
    size_t total = 0;
    for (size_t k = 0; k < tiles; ++k) {
        total += counts[k + 1];
        if (total > max_entries) throw std::runtime_error(too_many);
        t.offsets[k + 1] = int(total);
    }
    t.entries.assign(total, 0);
    std::vector<int> fill(t.offsets.begin(), t.offsets.end() - 1);
    for (size_t i = 0; i < rects.size(); ++i)
        for (int y = in_tiles[i].z; y <= in_tiles[i].w; ++y)
            for (int x = in_tiles[i].x; x <= in_tiles[i].y; ++x)
                t.entries[size_t(fill[size_t(y) * t.tiles_x + x]++)] = int(i);
    return t;
}

std::vector<float> screen_tile_texels(const ScreenTiles& tiles) {
    std::vector<float> lists;
    lists.reserve(tiles.offsets.size() + tiles.entries.size());
    for (int v : tiles.offsets) lists.push_back(float(v));
    for (int v : tiles.entries) lists.push_back(float(v));
    return lists;
}

std::shared_ptr<const Table2D> row_table(const char* name, int channels, int row_texels, std::vector<float> texels) {
    auto t = std::make_shared<Table2D>();
    t->name = name;
    t->channels = channels;
    const size_t n = texels.size() / size_t(channels);
    t->width = row_texels;
    t->height = int(std::max<size_t>(1, (n + size_t(row_texels) - 1) / size_t(row_texels)));
    texels.resize(size_t(t->width) * t->height * channels, 0.0f);
    t->texels = std::move(texels);
    t->serial = next_table_serial();
    return t;
}

}  // namespace airlight
