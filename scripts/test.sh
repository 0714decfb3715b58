#!/usr/bin/env bash
# Builds everything and runs every test, C++ (ctest) and Python (pytest).
# Calls scripts/setup.sh first, so it also works on a fresh clone.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export PATH="$PWD/.venv/bin:$PATH"
cmake -S . -B build/cpp -G Ninja -DAIRLIGHT_BUILD_TESTS=ON -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/cpp
ctest --test-dir build/cpp --output-on-failure
ruff check python tests benchmarks examples
mypy python/airlight
clang-format --dry-run --Werror cpp/*.cpp cpp/*.hpp include/airlight/*.hpp tests/cpp/*.cpp tests/cpp/*.hpp
python -m pytest tests/python -q
