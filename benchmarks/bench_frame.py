"""Frame time of both backends at 640x360 and the set-up cost a Renderer saves.

    .venv/bin/python benchmarks/bench_frame.py [--scene scenes/default.json] [--frames 10]
        [--width 640 --height 360] [--set quality.spot_glow_samples=8 ...] [--backends gl cpu]

Prints, per backend: the one-off set-up (context creation, shader compilation)
paid by a new Renderer's first frame, the median and the best time of later
frames (the best also per megapixel: on a shared machine the least disturbed),
and the time of the one-shot airlight.render() which pays the set-up every call.
``--set KEY=VALUE`` changes one scene key first (a dotted path, the value as
JSON), e.g. a quality knob.
Absolute times on a shared 2-core machine are noisy; compare ratios.
"""

from __future__ import annotations

import argparse
import json
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
    return {"first": first, "frame": frame, "best": min(times), "setup": first - frame, "one_shot": one_shot}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    default_scene = Path(__file__).resolve().parents[1] / "scenes" / "default.json"
    parser.add_argument("--scene", default=str(default_scene))
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="set a scene key (dotted path, JSON value) before timing")
    parser.add_argument("--backends", nargs="+", choices=("gl", "cpu"), default=None,
                        help="the backends to time (default: every available one)")
    args = parser.parse_args()
    scene = airlight.load_scene(args.scene)
    scene["film"] = {"width": args.width, "height": args.height}
    for item in args.set:
        key, sep, value = item.partition("=")
        if not sep:
            parser.error(f"--set: expected KEY=VALUE, got {item!r}")
        *parents, last = key.split(".")
        node = scene
        for name in parents:
            node = node.setdefault(name, {})
        node[last] = json.loads(value)
    scene = airlight.load_scene(scene)
    megapixels = args.width * args.height / 1e6
    settings = "".join(f", {item}" for item in args.set)
    print(f"scene {args.scene} at {args.width}x{args.height}{settings}, median of {args.frames} frames")
    print(f"{'backend':8} {'frame ms':>9} {'best ms':>8} {'best/MP':>8} {'set-up ms':>10} "
          f"{'one-shot ms':>12} {'saved by Renderer':>18}")
    backends = args.backends or airlight.available_backends()
    for backend in backends:
        r = time_backend(backend, scene, args.frames)
        best_per_mp = 1e3 * r["best"] / megapixels
        print(f"{backend:8} {1e3 * r['frame']:9.1f} {1e3 * r['best']:8.1f} {best_per_mp:8.0f} "
              f"{1e3 * r['setup']:10.1f} {1e3 * r['one_shot']:12.1f} {r['one_shot'] / r['frame']:17.1f}x")
    if "gl" not in airlight.available_backends():
        print(f"gl: skipped ({airlight.gl_unavailable_reason()})")


if __name__ == "__main__":
    main()
