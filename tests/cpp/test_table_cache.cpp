// TableCache (cpp/tables.hpp): the bounded, least-recently-used cache of the
// tables that depend on animatable scene parameters (issue 27, item 10: each
// distinct HG g used to add two tables for the process's life).
#include <memory>
#include <string>
#include <vector>

#include "check.hpp"
#include "tables.hpp"

using airlight::Table2D;
using airlight::TableCache;

namespace {

int builds = 0;

Table2D make_table(int key) {
    ++builds;
    Table2D t;
    t.name = "test_cache " + std::to_string(key);
    t.width = t.height = 2;
    t.texels.assign(4, float(key));
    return t;
}

bool resident(const std::string& name) {
    bool found = false, alive = false;
    for (const airlight::TableInfo& info : airlight::tables_built())
        if (info.name == name) found = true, alive = info.resident;
    CHECK_MSG(found, name);
    return alive;
}

void test_cache_keeps_the_most_recent_keys_and_builds_each_once() {
    TableCache<int> cache(3);
    builds = 0;
    for (int k = 0; k < 3; ++k) CHECK(cache.get(k, [k] { return make_table(k); })->texels[0] == float(k));
    CHECK(builds == 3);
    CHECK(cache.get(0, [] { return make_table(0); })->texels[0] == 0.0f);  // a hit: 0 is now the most recent
    CHECK(builds == 3);
    cache.get(3, [] { return make_table(3); });  // evicts 1, the least recently used
    CHECK(cache.size() == 3);
    CHECK(!resident("test_cache 1"));
    CHECK(resident("test_cache 0") && resident("test_cache 2") && resident("test_cache 3"));
    cache.get(1, [] { return make_table(1); });  // rebuilt
    CHECK(builds == 5);
}

void test_animating_a_key_keeps_memory_bounded() {
    TableCache<int> cache(4);
    for (int k = 100; k < 140; ++k) cache.get(k, [k] { return make_table(k); });
    CHECK(cache.size() == 4);
    int alive = 0;
    for (const airlight::TableInfo& info : airlight::tables_built())
        if (info.name.rfind("test_cache 1", 0) == 0 && info.name.size() == 14 && info.resident) ++alive;
    CHECK_MSG(alive == 4, std::to_string(alive));
}

void test_a_held_table_outlives_its_eviction_and_serials_differ() {
    TableCache<int> cache(1);
    const std::shared_ptr<const Table2D> held = cache.get(7, [] { return make_table(7); });
    const long serial = held->serial;
    const std::shared_ptr<const Table2D> other = cache.get(8, [] { return make_table(8); });  // evicts 7
    CHECK(resident("test_cache 7"));                                                          // still held by a frame
    CHECK(held->texels[0] == 7.0f);
    CHECK(other->serial != serial && serial > 0);
}

}  // namespace

int main() {
    test_cache_keeps_the_most_recent_keys_and_builds_each_once();
    test_animating_a_key_keeps_memory_bounded();
    test_a_held_table_outlives_its_eviction_and_serials_differ();
    return airlight_test::test_result("test_table_cache");
}
