"""The sun's shadow map against shadow rays: frame time and error on the daytime town, both backends.

    .venv/bin/python effects/sun_shadow_map/bench/bench_sun_shadow_map.py
        [--scene scenes/day_clear.json] [--width 320 --height 180] [--sizes 128 256 512 1024 2048]
        [--frames 3] [--out effects/sun_shadow_map/docs/bench_sun_shadow_map.txt]

For each backend: the median frame time with exact shadow rays (quality.sun_shadow_map 0) and with
maps of each size (the grid pass included), their ratio to the rays' time, and the error of the map's
image against the rays' image: the fraction of pixels off by more than 2 % and the mean relative
error over the image. Absolute times on a shared 2-core machine are noisy; compare the ratios.
"""

from __future__ import annotations

import argparse
import copy
import statistics
import time
from pathlib import Path

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]


def frame_time(renderer: airlight.Renderer, scene: dict, frames: int) -> tuple[float, np.ndarray]:
    image = renderer.render(scene)  # warm-up: programs compiled, tables built
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        image = renderer.render(scene)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), image


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=str(ROOT / "scenes" / "day_clear.json"))
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=180)
    ap.add_argument("--sizes", type=int, nargs="+", default=[128, 256, 512, 1024, 2048])
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--backends", nargs="+", default=airlight.available_backends())
    ap.add_argument("--out", default=None, help="also write the table to this file")
    args = ap.parse_args()
    scene = airlight.load_scene(args.scene)
    scene["film"] = {"width": args.width, "height": args.height}
    lines = [f"scene {Path(args.scene).name} at {args.width}x{args.height}, "
             f"{len(scene['surfaces'])} surfaces, median of {args.frames} frames",
             f"{'backend':8} {'shadows':>10} {'frame ms':>9} {'vs rays':>8} {'pixels off >2%':>15} "
             f"{'mean rel err':>13}"]
    for backend in args.backends:
        with airlight.Renderer(backend) as r:
            t_rays, ref = frame_time(r, scene, args.frames)
            lines.append(f"{backend:8} {'rays':>10} {1e3 * t_rays:9.1f} {1.0:8.2f} {'-':>15} {'-':>13}")
            for n in args.sizes:
                s = copy.deepcopy(scene)
                s["quality"]["sun_shadow_map"] = n
                t, img = frame_time(r, s, args.frames)
                scale = np.maximum(np.maximum(img, ref), 1e-3)
                off = float(np.mean(np.any(np.abs(img - ref) > 0.02 * scale, axis=-1)))
                rel = float(np.mean(np.abs(img - ref) / scale))
                label = f"map {n}"
                lines.append(f"{backend:8} {label:>10} {1e3 * t:9.1f} {t / t_rays:8.2f} {100 * off:14.2f}% "
                             f"{rel:13.2e}")
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
