// Minimal test support for the C++ tests: CHECK counts and prints failures;
// a test's main returns test_result() (77 = skipped, see CMakeLists.txt).
#pragma once

#include <cstdio>
#include <string>

namespace airlight_test {

inline int checks = 0;
inline int failures = 0;

inline void check(bool ok, const std::string& what, const char* file, int line) {
    ++checks;
    if (!ok) {
        ++failures;
        std::printf("FAIL %s:%d: %s\n", file, line, what.c_str());
    }
}

inline int test_result(const char* name) {
    std::printf("%s: %d checks, %d failures\n", name, checks, failures);
    return failures == 0 ? 0 : 1;
}

constexpr int kSkipped = 77;

}  // namespace airlight_test

#define CHECK(cond) airlight_test::check((cond), #cond, __FILE__, __LINE__)
#define CHECK_MSG(cond, msg) airlight_test::check((cond), std::string(#cond) + " [" + (msg) + "]", __FILE__, __LINE__)
