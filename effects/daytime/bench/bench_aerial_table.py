"""The aerial table against the scattering volumes: frame time and error per distance-node count.

    .venv/bin/python effects/daytime/bench/bench_aerial_table.py [--sizes 640x360] [--nodes 16 24 32]
        [--scenes day_clear day_heavy_rain rainbow_after_heavy_rain] [--backends cpu gl]

Several --sizes show where the table's fixed build per frame is paid back (the film size of
quality.aerial_table "auto", effects/daytime/docs/aerial_table.md section 6).

Per scene: the reference is the CPU backend's exact volumes at 64 altitude levels; for each backend
the volumes at the default 16 levels and the aerial table (effects/daytime/docs/aerial_table.md)
at each node count, built on the same 64 levels (its cost does not grow with them per pixel): the
median of 3 frames after a first one, and the error per pixel (tools/fuzz/compare.py:
error_against_reference), its 99th percentile and maximum.
"""

from __future__ import annotations

import argparse
import copy
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import airlight

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from tools.fuzz.compare import error_against_reference  # noqa: E402


def frame_ms(renderer: airlight.Renderer, scene: dict, frames: int = 3) -> tuple[float, np.ndarray]:
    image = renderer.render(scene)
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        image = renderer.render(scene)
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times), image


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", nargs="+", default=["640x360"])
    parser.add_argument("--nodes", type=int, nargs="+", default=[16, 24, 32])
    parser.add_argument(
        "--scenes", nargs="+", default=["day_clear", "day_heavy_rain", "rainbow_after_heavy_rain"]
    )
    parser.add_argument("--backends", nargs="+", default=["cpu", "gl"])
    args = parser.parse_args()
    print("| scene | size | backend | method | frame ms | x volumes 16 | p99 error | max error |")
    print("|---|---|---|---|---|---|---|---|")
    for size in args.sizes:
        width, height = (int(v) for v in size.split("x"))
        for name in args.scenes:
            bench_scene(name, width, height, args.backends, args.nodes)


def bench_scene(name: str, width: int, height: int, backends: list[str], nodes: list[int]) -> None:
    """One scene at one size: its rows of the table (the volumes pinned with aerial_table 0, which
    "auto" would replace on big films)."""
    scene = airlight.preset(name)
    scene["film"] = {"width": width, "height": height}
    reference = copy.deepcopy(scene)
    reference["quality"] = {**scene.get("quality", {}), "sky_segments": 64, "aerial_table": 0}
    expected = airlight.Renderer("cpu").render(reference)
    for backend in backends:
        renderer = airlight.Renderer(backend)
        methods = [("volumes, 16 levels", {"sky_segments": 16, "aerial_table": 0})]
        methods += [(f"aerial table, {n} nodes", {"sky_segments": 64, "aerial_table": n}) for n in nodes]
        base = None
        for label, quality in methods:
            trial = copy.deepcopy(scene)
            trial["quality"] = {**scene.get("quality", {}), **quality}
            ms, image = frame_ms(renderer, trial)
            base = base or ms
            error = error_against_reference(image, expected)
            print(
                f"| {name} | {width}x{height} | {backend} | {label} | {ms:.0f} | {base / ms:.1f}x faster | "
                f"{np.percentile(error, 99):.1e} | {error.max():.1e} |",
                flush=True,
            )
        renderer.close()

if __name__ == "__main__":
    main()
