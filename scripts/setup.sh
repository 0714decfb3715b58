#!/usr/bin/env bash
# Sets up airlight on a fresh Debian 12 machine (run as root): installs the
# missing system packages, creates the virtual environment .venv with the
# Python dependencies, builds and installs the airlight package (which puts
# airlight-demo on .venv/bin). Safe to run again: it only does what is missing.
#   bash scripts/setup.sh            # set up
#   bash scripts/setup.sh --render   # set up, then render the default scene to airlight.png
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake ninja-build pkg-config python3 python3-dev python3-venv
          libegl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri libglm-dev nlohmann-json3-dev libeigen3-dev libglfw3-dev
          libopenexr-dev libpng-dev clang-format)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    "$python" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
# PythonicDISORT: an independent DISORT, the multiple-scattering solver's reference in tests.
# OpenEXR (the official bindings): only the independent reader of tests/python/test_exr.py;
# airlight itself writes and reads EXR through the C++ library (libopenexr-dev).
# pytest-xdist: scripts/test.sh runs the tests in one worker per core.
# ray, pyyaml, tqdm: the batch sweeps (airlight.batch; pyproject's "batch" extra); types-PyYAML for mypy.
.venv/bin/python -m pip install -q numpy pillow pytest pytest-xdist hypothesis scipy matplotlib colour-science \
    "scikit-build-core>=0.10" "pybind11>=2.12" cmake ninja ruff mypy \
    PythonicDISORT "OpenEXR>=3.5,<4" "ray>=2.9" "pyyaml>=6" "tqdm>=4" types-PyYAML types-tqdm
# --no-build-isolation: build with the tools just installed in .venv
# (incremental: the build directory build/python is kept between runs).
.venv/bin/python -m pip install -q --no-build-isolation .
echo "setup: done ($(.venv/bin/python -c 'import airlight; print("backends:", ", ".join(airlight.available_backends()))'))"

if [ "${1:-}" = "--render" ]; then
    .venv/bin/airlight-demo --scene scenes/default.json --out airlight.png --exposure 2
fi
