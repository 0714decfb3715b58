#!/usr/bin/env bash
# Builds everything and runs every test, C++ (ctest) and Python (pytest).
# Calls scripts/setup.sh first, so it also works on a fresh clone.
#   bash scripts/test.sh           # the full suite (what CI runs)
#   bash scripts/test.sh --quick   # the quick tier for development: the tests not marked slow
# pytest runs one worker per core (pytest-xdist, -n auto): much of the suite is single-threaded
# (Mesa's shader compiler, the numpy and scipy references), so two cores nearly halve it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
# llvmpipe without LLVM's optimisation passes: half the shader compile time, the same images (conftest.py).
export GALLIVM_PERF="${GALLIVM_PERF:-nopt}"
cmake -S . -B build/cpp -G Ninja -DAIRLIGHT_BUILD_TESTS=ON -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/cpp
ctest --test-dir build/cpp --output-on-failure --parallel "$(nproc)"
ruff check python tests benchmarks examples effects tools conftest.py
mypy python/airlight
clang-format --dry-run --Werror cpp/*.cpp cpp/*.hpp include/airlight/*.hpp tests/cpp/*.cpp tests/cpp/*.hpp effects/*/*.cpp effects/*/*.hpp effects/*/tests/*.cpp
if [ "${1:-}" = "--quick" ]; then
    python -m pytest -q -n auto --durations=15 -m "not slow"
else
    python -m pytest -q -n auto --durations=30
fi
