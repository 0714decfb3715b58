#!/usr/bin/env bash
# What each feature costs per megapixel, and the quality knobs that trade time
# for error, on both backends (README "Measurements", "Cost per feature"):
# benchmarks/bench_frame.py on a preset per feature at 640x360, best of 5 frames.
#   bash benchmarks/bench_features.sh > docs/bench_features.txt
set -euo pipefail
cd "$(dirname "$0")/.."
bench() { .venv/bin/python benchmarks/bench_frame.py --frames 5 "$@"; }
uptime
bench --scene scenes/default.json
bench --scene scenes/foggy_street.json
bench --scene scenes/foggy_street.json --set quality.cull_fraction=0
bench --scene scenes/foggy_street_hg.json
bench --scene scenes/crane_searchlight.json --set quality.spot_glow_samples=8
bench --scene scenes/crane_searchlight.json
bench --scene scenes/crane_searchlight.json --set quality.spot_glow_samples=16
bench --scene scenes/day_clear.json --set quality.sky_segments=4
bench --scene scenes/day_clear.json
bench --scene scenes/day_clear.json --set quality.sun_shadow_map=1024
bench --scene scenes/rainbow_after_heavy_rain.json
uptime
