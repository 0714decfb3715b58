#include "tables.hpp"

#include <atomic>
#include <mutex>
#include <vector>

namespace airlight {
namespace {

struct Registered {
    TableInfo info;
    std::weak_ptr<const Table2D> cached;  // empty for tables kept for the process
    bool permanent = true;
};

std::mutex registry_mutex;
std::vector<Registered>& registry() {
    static std::vector<Registered> tables;
    return tables;
}

TableInfo info_of(const Table2D& table) {
    return {table.name, table.width, table.height, table.texels.size() * sizeof(float), table.build_seconds, true};
}

}  // namespace

bool register_table(const Table2D& table) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    registry().push_back({info_of(table), {}, true});
    return true;
}

void register_table(const std::shared_ptr<const Table2D>& table) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    registry().push_back({info_of(*table), table, false});
}

long next_table_serial() {
    static std::atomic<long> serial{0};
    return ++serial;
}

std::vector<TableInfo> tables_built() {
    std::lock_guard<std::mutex> lock(registry_mutex);
    std::vector<TableInfo> out;
    for (const Registered& r : registry()) {
        out.push_back(r.info);
        out.back().resident = r.permanent || !r.cached.expired();
    }
    return out;
}

}  // namespace airlight
