// Scattering tables as both backends read them: a grid of float32 texels,
// built once per process from exact double-precision evaluations (each
// effect builds its own: effects/*/..._tables.cpp), and the process-wide list
// of the tables built (table_stats in Python).
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace airlight {

// A grid of float32 texels, row-major: texels[y * width + x]; node-aligned
// (texel i sits at the normalised coordinate i / (width - 1)).
struct Table2D {
    const char* name = "";
    int width = 0;
    int height = 0;
    int channels = 1;  // texels per grid node (1: R32F, 4: RGBA32F)
    std::vector<float> texels;
    double build_seconds = 0.0;
    long serial = 0;  // distinguishes tables that a cache built at the same address (GL texture cache)
};

// The tables built so far in this process, by name (for tests showing that a
// scene which does not need a table builds none, and for reporting memory).
struct TableInfo {
    std::string name;
    int width = 0;
    int height = 0;
    size_t bytes = 0;
    double build_seconds = 0.0;
};
std::vector<TableInfo> tables_built();
// Records a table in that list (every table builder calls it once per table).
bool register_table(const Table2D& table);

// Runs build() and names the table it returns, with its build time.
template <class Build>
Table2D timed_build(const char* name, Build build) {
    const auto start = std::chrono::steady_clock::now();
    Table2D table = build();
    table.name = name;
    table.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return table;
}

// The table build() makes, built on first use (thread safe: a function-local
// static per call site, each call site's lambda being its own type), named,
// timed, registered and kept for the process.
template <class Build>
const Table2D& table_built_once(const char* name, Build build) {
    static const Table2D table = [&] {
        Table2D t = timed_build(name, build);
        register_table(t);
        return t;
    }();
    return table;
}

}  // namespace airlight
