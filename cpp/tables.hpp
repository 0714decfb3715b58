// Scattering tables as both backends read them: a grid of float32 texels,
// built once per process from exact double-precision evaluations (each
// effect builds its own: effects/*/..._tables.cpp), and the process-wide list
// of the tables built (table_stats in Python).
#pragma once

#include <chrono>
#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace airlight {

// A grid of float32 texels, row-major: texels[y * width + x]; node-aligned
// (texel i sits at the normalised coordinate i / (width - 1)).
struct Table2D {
    std::string name;
    int width = 0;
    int height = 0;
    int channels = 1;  // texels per grid node (1: R32F, 4: RGBA32F)
    std::vector<float> texels;
    double build_seconds = 0.0;
    long serial = 0;  // distinguishes tables that a TableCache built at the same address (GL texture cache)
};

// The tables built so far in this process, by name (for tests showing that a
// scene which does not need a table builds none, and for reporting memory).
struct TableInfo {
    std::string name;
    int width = 0;
    int height = 0;
    size_t bytes = 0;
    double build_seconds = 0.0;
    bool resident = true;  // still in memory (false: a TableCache evicted it and no frame holds it)
};
std::vector<TableInfo> tables_built();
// Records a table in that list (every table builder calls it once per table):
// one kept for the process, or one a TableCache holds (resident while alive).
bool register_table(const Table2D& table);
void register_table(const std::shared_ptr<const Table2D>& table);
// A new Table2D::serial for each table a TableCache builds.
long next_table_serial();

// Runs build() and names the table it returns, with its build time.
template <class Build>
Table2D timed_build(const std::string& name, Build build) {
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

// The tables built for the last `capacity` keys, the least recently used
// evicted first: for tables that depend on a scene parameter that may animate
// (a phase lobe's g, the sky), so that memory stays bounded. Tables are
// shared: a frame that uses one keeps it alive (FrameData::table_owners)
// after its eviction. Thread safe; a table is built under the cache's lock.
template <class Key>
class TableCache {
public:
    explicit TableCache(size_t capacity) : capacity_(capacity) {}

    // The table for `key`, made by build() (returning a named Table2D) on a miss.
    template <class Build>
    std::shared_ptr<const Table2D> get(const Key& key, Build build) {
        std::lock_guard<std::mutex> lock(mutex_);
        for (auto it = entries_.begin(); it != entries_.end(); ++it) {
            if (it->first == key) {
                entries_.splice(entries_.begin(), entries_, it);
                return entries_.front().second;
            }
        }
        auto table = std::make_shared<Table2D>(build());
        table->serial = next_table_serial();
        std::shared_ptr<const Table2D> shared = std::move(table);
        register_table(shared);
        entries_.emplace_front(key, shared);
        if (entries_.size() > capacity_) entries_.pop_back();
        return shared;
    }

    size_t size() const {
        std::lock_guard<std::mutex> lock(mutex_);
        return entries_.size();
    }

private:
    size_t capacity_;
    mutable std::mutex mutex_;
    std::list<std::pair<Key, std::shared_ptr<const Table2D>>> entries_;  // most recent first
};

}  // namespace airlight
