"""What the spots' screen tiles save (physics.md section 9): the frame with each pixel walking only the
spots its tile's rays can meet (`quality.spot_lists: "tiles"`, the default) against every pixel
walking every spot (`"all"`), on both backends, with the check that the two images are identical.

    .venv/bin/python effects/spotlights/bench/bench_spot_tiles.py [--width 320 --height 180]
        [--frames 3] [--out effects/spotlights/docs/bench_spot_tiles.txt]

Scenes: bench_airlight's street of 32 cars' headlights (black surfaces: the airlight alone), the
spot presets. Median of `--frames` frames after a warm one; absolute times on a shared 2-core
machine are noisy, compare the ratios.
"""

from __future__ import annotations

import argparse
import copy
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))
from effects.lamp_airlight.bench.bench_airlight import street_scene  # noqa: E402


def headlight_street(width: int, height: int) -> dict[str, Any]:
    """bench_airlight's street of 32 cars' headlights over black surfaces."""
    return street_scene(64, width, height, 0.0, "headlights")


def frame(renderer: airlight.Renderer, scene: dict[str, Any], frames: int) -> tuple[np.ndarray, float]:
    image = renderer.render(scene)
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        image = renderer.render(scene)
        times.append(time.perf_counter() - start)
    return image, statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=180)
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    scenes = {"headlights64 (street, black surfaces)": headlight_street(args.width, args.height)}
    for name in ("spotlights_crossing_002", "crane_searchlight", "approaching_car"):
        scenes[name] = airlight.preset(name)
        scenes[name]["film"] = {"width": args.width, "height": args.height}
    size = f"{args.width}x{args.height}"
    lines = [f"Spots' screen tiles against every spot, {size}, median of {args.frames} frames",
             "", "| scene | backend | tiles s | all s | all / tiles | images |", "|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    for backend in airlight.available_backends():
        renderer = airlight.Renderer(backend)
        for name, scene in scenes.items():
            results = {}
            for lists in ("tiles", "all"):
                s = copy.deepcopy(scene)
                s["quality"] = {**s.get("quality", {}), "spot_lists": lists}
                results[lists] = frame(renderer, s, args.frames)
            same = "identical" if np.array_equal(results["tiles"][0], results["all"][0]) else "DIFFER"
            row = (f"| {name} | {backend} | {results['tiles'][1]:.3f} | {results['all'][1]:.3f} | "
                   f"{results['all'][1] / results['tiles'][1]:.2f} | {same} |")
            print(row, flush=True)
            lines.append(row)
    if args.out:
        command = "`.venv/bin/python effects/spotlights/bench/bench_spot_tiles.py`"
        args.out.write_text(command + "\n\n" + "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
