"""Noise clouds: the adaptive march against fixed-step marching, time and error, both backends.

    .venv/bin/python effects/noise_clouds/bench/bench_clouds.py [--width 160 --height 90]
        [--adaptive 96/32 200/64] [--march 1024/32 2048/64]
        [--error-width 48 --error-height 27] [--frames 1] [--backends cpu gl]
        [--out effects/noise_clouds/docs/bench_clouds.txt] [--plot effects/noise_clouds/docs/bench_clouds.png]

Four parts (--parts to choose):

1. For each camera (below, inside and above the layer: the tests' scenes, single scattering), each
   setting of the adaptive march (`quality.cloud_steps`, `quality.cloud_light_steps`) and of the
   brute force (`quality.clouds: "march"`, `march_steps` equal steps, equal light steps): the frame
   time at --width x --height on each backend, and the error of the clouds layer against the float64
   reference (effects/noise_clouds/tests/clouds_reference.py) at --error-width x --error-height on
   the CPU: the median and 99th percentile of the relative error over the pixels above 1e-3 of the
   maximum (the issue's measure). The speed-up at equal error is read off the table (and the plot).
2. The noise textures: build time (a fresh process) and memory.
3. What a scene without clouds pays: the same scene with `"clouds": null` against coverage 0
   (nothing built, no cloud code: HAS_CLOUDS off) and against the clouds.
4. The clouds' shadow in the air (physics.md section 9), for each `quality.cloud_shadow_steps`: the
   error of the fraction of the fog's sunlight the clouds let through against the float64 reference
   (the tests' fog scene at 24x14, CPU: median and maximum absolute error) and the frame time of
   the preset clouds_cumulus_town (atmosphere, default quality otherwise) at --width x --height.

Absolute times on a shared 2-core machine are noisy; compare ratios. GL is Mesa's llvmpipe; its
loop limiter cuts long marches, whose pixels the renderer recomputes on the CPU.
"""

from __future__ import annotations

import argparse
import copy
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE.parents[2] / "tests" / "python"))  # shared_results, which the tests import
import clouds_reference  # noqa: E402
import test_clouds_against_reference as cases  # noqa: E402

ADAPTIVE = [(48, 8), (96, 16), (96, 32), (200, 64)]
MARCH = [(256, 16), (1024, 32), (2048, 64)]


def settings(method: str, steps: int, light: int) -> dict[str, Any]:
    if method == "adaptive":
        return {"multiple_scattering": False, "cloud_steps": steps, "cloud_light_steps": light}
    return {"multiple_scattering": False, "clouds": "march", "march_steps": steps, "cloud_light_steps": light}


def frame_time(renderer: airlight.Renderer, scene: dict, frames: int) -> float:
    renderer.render(scene)  # warm-up: programs compiled, textures built
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        renderer.render(scene)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def error_stats(image: np.ndarray, exact: np.ndarray) -> tuple[float, float]:
    mask = exact.max(axis=-1) > 1e-3 * exact.max()
    rel = np.abs(image - exact)[mask] / exact[mask]
    return float(np.median(rel)), float(np.percentile(rel, 99))


BUILD = """
import json, time, airlight
t = time.perf_counter()
shape, detail = airlight._core.cloud_noise_textures(11)
print(json.dumps({"seconds": time.perf_counter() - t, "bytes": shape.nbytes + detail.nbytes}))
"""


SHADOW_STEPS = [0, 4, 16, 64]


def shadow_in_the_air(args: argparse.Namespace, renderers: dict[str, airlight.Renderer],
                      cpu: airlight.Renderer, shape: np.ndarray, detail: np.ndarray) -> list[str]:
    """Part 4: the error and cost of the clouds' shadow in the air by quality.cloud_shadow_steps."""
    fog = cases.FOG_UNDER_CLOUDS
    width, height = fog["film"]["width"], fog["film"]["height"]
    through = clouds_reference.medium_sun_through_clouds(fog, width, height, shape, detail, steps=1024,
                                                         light_steps=96)
    # the pixels whose fog below the layer hides the rest (the tests' mask)
    origin, dirs, _ = clouds_reference.view_rays(fog, width, height)
    t0 = (fog["clouds"]["base"] - origin[1]) / np.maximum(dirs[:, 1], 1e-9)
    sigma = float(clouds_reference.medium_sigma_t(fog)[0])
    below = (np.exp(-sigma * t0) < 0.01).reshape(height, width)
    town = airlight.preset("clouds_cumulus_town")
    town["film"] = {"width": args.width, "height": args.height}
    lines = ["", f"4. the clouds' shadow in the air: error of the fraction of the fog's sunlight let through "
             f"({below.sum()} of {width}x{height} pixels, CPU; reference from {through[below].min():.2f} to "
             f"{through[below].max():.2f}); "
             f"frame time of clouds_cumulus_town at {args.width}x{args.height}",
             f"{'pieces':>6} {'median err':>11} {'max err':>9} "
             + " ".join(f"{b + ' ms':>10}" for b in renderers)]
    for steps in SHADOW_STEPS:
        scene = copy.deepcopy(fog)
        scene["quality"] = {"cloud_shadow_steps": steps, "cloud_light_steps": 96}
        shadowed = cpu.render(scene, outputs=["medium_sun"])["medium_sun"][..., 1]
        scene["quality"]["cloud_shadow_steps"] = 0
        free = cpu.render(scene, outputs=["medium_sun"])["medium_sun"][..., 1]
        err = np.abs(shadowed / free - through)[below]
        town["quality"] = {**town.get("quality", {}), "cloud_shadow_steps": steps}
        times = {b: frame_time(r, town, args.frames) for b, r in renderers.items()}
        lines.append(f"{steps:6d} {np.median(err):11.2e} {np.max(err):9.2e} "
                     + " ".join(f"{1e3 * times[b]:10.1f}" for b in renderers))
        print(lines[-1], file=sys.stderr)
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=90)
    ap.add_argument("--error-width", type=int, default=48)
    ap.add_argument("--error-height", type=int, default=27)
    ap.add_argument("--frames", type=int, default=1)
    ap.add_argument("--cameras", nargs="+", default=list(cases.CAMERAS))
    ap.add_argument("--backends", nargs="+", default=airlight.available_backends())
    ap.add_argument("--out", default=None, help="also write the tables to this file")
    ap.add_argument("--plot", default=None, help="write a plot of time against error (PNG)")
    ap.add_argument("--parts", type=int, nargs="+", default=[1, 2, 3, 4], help="which parts to run")
    ap.add_argument("--adaptive", nargs="+", default=[f"{view}/{light}" for view, light in ADAPTIVE],
                    help="part 1's adaptive settings, view/light steps")
    ap.add_argument("--march", nargs="+", default=[f"{view}/{light}" for view, light in MARCH],
                    help="part 1's fixed-step settings, view/light steps")
    args = ap.parse_args()

    shape, detail = airlight._core.cloud_noise_textures(0)
    lines = [] if 1 not in args.parts else [
        f"1. frame time at {args.width}x{args.height} (median of {args.frames}); error of the clouds "
        f"layer at {args.error_width}x{args.error_height} against the float64 reference (CPU)",
        f"{'camera':8} {'method':>9} {'steps':>6} {'light':>6} {'median err':>11} {'p99 err':>9} "
        + " ".join(f"{b + ' ms':>10}" for b in args.backends)]
    points: dict[str, list[tuple[float, float, str]]] = {}
    cpu = airlight.Renderer("cpu")
    renderers = {b: (cpu if b == "cpu" else airlight.Renderer(b)) for b in args.backends}
    for camera in args.cameras if 1 in args.parts else []:
        scene = cases.scene_for(camera)
        small = copy.deepcopy(scene)
        small["film"] = {"width": args.error_width, "height": args.error_height}
        t0 = time.perf_counter()
        exact = clouds_reference.clouds_layer_radiance(small, args.error_width, args.error_height, shape,
                                                       detail)
        print(f"{camera}: reference in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
        for method, table in (("adaptive", args.adaptive), ("march", args.march)):
            for steps, light in (map(int, pair.split("/")) for pair in table):
                quality = settings(method, steps, light)
                small["quality"] = quality
                med, p99 = error_stats(cpu.render(small, outputs=["clouds"])["clouds"], exact)
                big = copy.deepcopy(scene)
                big["film"] = {"width": args.width, "height": args.height}
                big["quality"] = quality
                times = {b: frame_time(r, big, args.frames if method == "adaptive" else 1)
                         for b, r in renderers.items()}
                lines.append(f"{camera:8} {method:>9} {steps:6d} {light:6d} {med:11.2e} {p99:9.2e} "
                             + " ".join(f"{1e3 * times[b]:10.1f}" for b in args.backends))
                for b in args.backends:
                    points.setdefault(f"{camera} {b} {method}", []).append(
                        (times[b], p99, f"{steps}/{light}"))
                print(lines[-1], file=sys.stderr)

    if 2 in args.parts:
        build = json.loads(subprocess.run([sys.executable, "-c", BUILD], capture_output=True, text=True,
                                          check=True).stdout)
        lines += ["", "2. the noise textures (seed 11, a fresh process)",
                  f"build {build['seconds']:.2f} s, {build['bytes'] / 2**20:.1f} MiB "
                  "(128^3 and 32^3 RGBA float32)"]

    if 3 in args.parts:
        lines += ["", f"3. what clouds cost ({args.width}x{args.height}, camera below, default quality)",
                  f"{'backend':8} {'no clouds':>10} {'coverage 0':>11} {'clouds':>10}"]
        base = cases.scene_for("below")
        base["film"] = {"width": args.width, "height": args.height}
        base["surfaces"] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.2}]
        for b, r in renderers.items():
            none = frame_time(r, {**base, "clouds": None}, args.frames)
            zero = frame_time(r, {**base, "clouds": {**base["clouds"], "coverage": 0}}, args.frames)
            full = frame_time(r, base, args.frames)
            lines.append(f"{b:8} {1e3 * none:10.1f} {1e3 * zero:11.1f} {1e3 * full:10.1f}")

    if 4 in args.parts:
        lines += shadow_in_the_air(args, renderers, cpu, shape, detail)

    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4.5))
        for label, pts in sorted(points.items()):
            pts.sort()
            ax.plot([1e3 * p[0] for p in pts], [p[1] for p in pts], "o-" if "adaptive" in label else "s--",
                    label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"frame time at {args.width}x{args.height} (ms)")
        ax.set_ylabel("99th percentile relative error")
        ax.set_title("noise clouds: adaptive march against fixed steps")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
    for r in renderers.values():
        r.close()


if __name__ == "__main__":
    main()
