"""Light shafts: the closed-form lit intervals against brute-force marching, time and error, both backends.

    .venv/bin/python effects/light_shafts/bench/bench_shafts.py [--width 640 --height 360]
        [--steps 64 256 1024] [--frames 3] [--backends cpu gl]
        [--out effects/light_shafts/docs/bench_shafts.txt] [--plot effects/light_shafts/docs/bench_shafts.png]

Three parts, each a table:

1. The fog street (the test scene of effects/light_shafts/tests: a sun, boxes and a sphere in a
   homogeneous fog): `quality.shafts` "analytic" (physics.md section 2) and "march" at each step
   count (a shadow ray per step), frame time and error against the exact float64 reference
   (shafts_reference.py): the median and 99th percentile of the relative error over the pixels
   above 1e-3 of the maximum (the issue's measure), and each method's time as a multiple of the
   analytic one. Also "off" (no shadows): the error the shadows remove.
2. The low-sun preset (scenes/shafts_low_sun.json: the atmosphere, a hazy fog and 30 buildings):
   frame time of "off", "analytic" and "march" (which also marches the atmosphere).
3. What a scene that needs no shafts pays: the same preset without its buildings, "analytic"
   against "off" (no shadow runs are sought: HAS_SHAFTS is off), and the daytime town
   (scenes/day_clear.json: 40 buildings, no fog) with and without shafts.
4. A lamp's volumetric shadows (the tests' alley, at --lamp-width): the lamps layer shadowed
   (closed-form segments between the shadows), unshadowed, and marched with a shadow ray per
   step, against the exact float64 reference.

Absolute times on a shared 2-core machine are noisy; compare the ratios. GL is Mesa's llvmpipe;
its loop limiter cuts marches of many steps, whose pixels the renderer then recomputes on the CPU.
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

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(HERE.parent / "tests"))
import shafts_reference  # noqa: E402
import test_light_shafts  # noqa: E402


def frame_time(renderer: airlight.Renderer, scene: dict, frames: int,
               outputs: list[str]) -> tuple[float, dict]:
    out = renderer.render(scene, outputs=outputs)  # warm-up: programs compiled, tables built
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        out = renderer.render(scene, outputs=outputs)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def row(backend: str, label: str, seconds: float, ratio: float, med: float, p99: float) -> str:
    return f"{backend:8} {label:>14} {1e3 * seconds:10.1f} {ratio:10.2f} {med:11.2e} {p99:9.2e}"


def with_quality(scene: dict, **quality: object) -> dict:
    s = copy.deepcopy(scene)
    s.setdefault("quality", {}).update(quality)
    return s


def error_stats(image: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    rel, _ = test_light_shafts.relative_errors(image, ref)
    return float(np.median(rel)), float(np.percentile(rel, 99))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--steps", type=int, nargs="+", default=[64, 256, 1024])
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--lamp-width", type=int, default=160, help="part 4's film width (slow reference)")
    ap.add_argument("--backends", nargs="+", default=airlight.available_backends())
    ap.add_argument("--out", default=None, help="also write the tables to this file")
    ap.add_argument("--plot", default=None, help="write a plot of time against error (PNG)")
    args = ap.parse_args()
    film = {"width": args.width, "height": args.height}

    street = test_light_shafts.street_with_sun("on_screen")
    street["film"] = film
    ref = shafts_reference.medium_sun_radiance(street, args.width, args.height)
    lines = [f"1. fog street at {args.width}x{args.height}, {len(street['surfaces'])} surfaces: medium_sun "
             f"against the float64 reference (median of {args.frames} frames; march: 1 frame)",
             f"{'backend':8} {'method':>14} {'frame ms':>10} {'x analytic':>10} {'median err':>11} "
             f"{'p99 err':>9}"]
    points: dict[str, list[tuple[float, float, str]]] = {}
    for backend in args.backends:
        with airlight.Renderer(backend) as r:
            t_exact, out = frame_time(r, with_quality(street, shafts="analytic"), args.frames, ["medium_sun"])
            med, p99 = error_stats(out["medium_sun"], ref)
            lines.append(f"{backend:8} {'analytic':>14} {1e3 * t_exact:10.1f} {1.0:10.2f} {med:11.2e} "
                         f"{p99:9.2e}")
            points.setdefault(backend, []).append((t_exact, p99, "analytic"))
            t_off, out = frame_time(r, with_quality(street, shafts="off"), args.frames, ["medium_sun"])
            med, p99 = error_stats(out["medium_sun"], ref)
            lines.append(f"{backend:8} {'off':>14} {1e3 * t_off:10.1f} {t_off / t_exact:10.2f} {med:11.2e} "
                         f"{p99:9.2e}")
            for steps in args.steps:
                marching = with_quality(street, shafts="march", march_steps=steps)
                t, out = frame_time(r, marching, 1, ["medium_sun"])
                med, p99 = error_stats(out["medium_sun"], ref)
                label = f"march {steps}"
                lines.append(f"{backend:8} {label:>14} {1e3 * t:10.1f} {t / t_exact:10.2f} {med:11.2e} "
                             f"{p99:9.2e}")
                points[backend].append((t, p99, label))

    low = airlight.load_scene(ROOT / "scenes" / "shafts_low_sun.json")
    low["film"] = film
    lines += ["", f"2. scenes/shafts_low_sun.json at {args.width}x{args.height}, "
              f"{len(low['surfaces'])} surfaces, atmosphere and fog",
              f"{'backend':8} {'method':>14} {'frame ms':>10} {'x off':>10}"]
    for backend in args.backends:
        with airlight.Renderer(backend) as r:
            t_off, _ = frame_time(r, with_quality(low, shafts="off"), args.frames, ["radiance"])
            lines.append(f"{backend:8} {'off':>14} {1e3 * t_off:10.1f} {1.0:10.2f}")
            t, _ = frame_time(r, with_quality(low, shafts="analytic"), args.frames, ["radiance"])
            lines.append(f"{backend:8} {'analytic':>14} {1e3 * t:10.1f} {t / t_off:10.2f}")
            steps = args.steps[0]
            t, _ = frame_time(r, with_quality(low, shafts="march", march_steps=steps), 1, ["radiance"])
            label = f"march {steps}"
            lines.append(f"{backend:8} {label:>14} {1e3 * t:10.1f} {t / t_off:10.2f}")

    bare = copy.deepcopy(low)
    bare["surfaces"] = []
    town = airlight.load_scene(ROOT / "scenes" / "day_clear.json")
    town["film"] = film
    lines += ["", "3. what shafts cost where nothing, or little, needs them",
              f"{'backend':8} {'scene':>24} {'off ms':>10} {'analytic ms':>12} {'ratio':>7}"]
    for backend in args.backends:
        with airlight.Renderer(backend) as r:
            for name, scene in (("low sun, no buildings", bare), ("day_clear town", town)):
                t_off, _ = frame_time(r, with_quality(scene, shafts="off"), args.frames, ["radiance"])
                t_on, _ = frame_time(r, with_quality(scene, shafts="analytic"), args.frames, ["radiance"])
                lines.append(f"{backend:8} {name:>24} {1e3 * t_off:10.1f} {1e3 * t_on:12.1f} "
                             f"{t_on / t_off:7.2f}")

    # 4. A lamp's volumetric shadows (physics.md section 7): the alley of the tests.
    w4, h4 = args.lamp_width, args.lamp_width * 9 // 16
    alley = copy.deepcopy(test_light_shafts.ALLEY)
    alley["film"] = {"width": w4, "height": h4}
    lamp_ref = shafts_reference.lamp_airlight_radiance(alley, w4, h4)
    lines += ["", f"4. a lamp between buildings at {w4}x{h4} (the tests' alley): the lamps layer against the "
              "float64 reference",
              f"{'backend':8} {'method':>14} {'frame ms':>10} {'x shadowed':>10} {'median err':>11} "
              f"{'p99 err':>9}"]
    for backend in args.backends:
        with airlight.Renderer(backend) as r:
            t_on, out = frame_time(r, alley, args.frames, ["lamps"])
            med, p99 = error_stats(out["lamps"], lamp_ref)
            lines.append(row(backend, "shadowed", t_on, 1.0, med, p99))
            unshadowed = copy.deepcopy(alley)
            unshadowed["lights"][0]["volumetric_shadows"] = False
            t, out = frame_time(r, unshadowed, args.frames, ["lamps"])
            med, p99 = error_stats(out["lamps"], lamp_ref)
            lines.append(row(backend, "unshadowed", t, t / t_on, med, p99))
            for steps in args.steps:
                t, out = frame_time(r, with_quality(alley, airlight="march", march_steps=steps), 1, ["lamps"])
                med, p99 = error_stats(out["lamps"], lamp_ref)
                lines.append(row(backend, f"march {steps}", t, t / t_on, med, p99))

    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        for backend, pts in points.items():
            march = [p for p in pts if p[2] != "analytic"]
            ax.plot([1e3 * p[0] for p in march], [p[1] for p in march], "o-", label=f"{backend} march")
            exact = [p for p in pts if p[2] == "analytic"][0]
            ax.plot([1e3 * exact[0]], [max(exact[1], 1e-8)], "*", markersize=12, label=f"{backend} analytic")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("frame time (ms)")
        ax.set_ylabel("99th percentile relative error")
        ax.set_title(f"light shafts, fog street {args.width}x{args.height}")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)


if __name__ == "__main__":
    main()
