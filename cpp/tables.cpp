#include "tables.hpp"

#include <mutex>
#include <vector>

namespace airlight {
namespace {

std::mutex registry_mutex;
std::vector<TableInfo>& registry() {
    static std::vector<TableInfo> tables;
    return tables;
}

}  // namespace

bool register_table(const Table2D& table) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    registry().push_back(
        {table.name, table.width, table.height, table.texels.size() * sizeof(float), table.build_seconds});
    return true;
}

std::vector<TableInfo> tables_built() {
    std::lock_guard<std::mutex> lock(registry_mutex);
    return registry();
}

}  // namespace airlight
