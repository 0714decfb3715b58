"""Frame time of both backends at 640x360 and the set-up cost a Renderer saves.

    .venv/bin/python benchmarks/bench_frame.py [--scene scenes/default.json] [--frames 10]

Prints, per backend: the one-off set-up (context creation, shader compilation)
paid by a new Renderer's first frame, the median time of later frames, and the
time of the one-shot airlight.render() which pays the set-up every call.
Absolute times on a shared 2-core machine are noisy; compare ratios.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import airlight


def time_backend(backend: str, scene: dict, frames: int) -> dict[str, float]:
    start = time.perf_counter()
    renderer = airlight.Renderer(backend)
    renderer.render(scene)
    first = time.perf_counter() - start
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        renderer.render(scene)
        times.append(time.perf_counter() - t0)
    renderer.close()
    t0 = time.perf_counter()
    airlight.render(scene, backend=backend)
    one_shot = time.perf_counter() - t0
    frame = statistics.median(times)
    return {"first": first, "frame": frame, "setup": first - frame, "one_shot": one_shot}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    default_scene = Path(__file__).resolve().parents[1] / "scenes" / "default.json"
    parser.add_argument("--scene", default=str(default_scene))
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    args = parser.parse_args()
    scene = airlight.load_scene(args.scene)
    scene["film"] = {"width": args.width, "height": args.height}
    print(f"scene {args.scene} at {args.width}x{args.height}, median of {args.frames} frames")
    print(f"{'backend':8} {'frame ms':>9} {'set-up ms':>10} {'one-shot ms':>12} {'saved by Renderer':>18}")
    for backend in airlight.available_backends():
        r = time_backend(backend, scene, args.frames)
        print(f"{backend:8} {1e3 * r['frame']:9.1f} {1e3 * r['setup']:10.1f} {1e3 * r['one_shot']:12.1f} "
              f"{r['one_shot'] / r['frame']:17.1f}x")
    if "gl" not in airlight.available_backends():
        print(f"gl: skipped ({airlight.gl_unavailable_reason()})")


if __name__ == "__main__":
    main()
