"""A fading rain's daytime multiple scattering with shared solves (issue 18;
effects/multiple_scattering/physics.md eq. 9.3), error and cost in one run:

    .venv/bin/python effects/multiple_scattering/bench/bench_fading_rain.py \\
        [--steps 2 4 8] [--out effects/multiple_scattering/docs/bench_fading_rain.txt]

1. Accuracy: the 9 rain cases of the stored path-tracer reference (rain 3, 40 and 100 mm/h under
   an overcast sky, a sun 10 and 60 degrees high; 14 views of sky and ground each) with the
   rain's ``density_scale`` swept over one octave (1 down to 2^(-15/16), 16 values, so that the
   scene's rain falls everywhere between two rungs), rendered with ``quality.fading_rain_steps``
   N (the field blended between two solves on the ladder) against 0 (the field solved for each
   rain exactly). The relative error per value (view x channel), largest and 99th percentile.
2. Continuity: renders just below and just above a rung (the extinction a factor 1 -+ 1e-6
   from it), whose difference must be that of the rain itself (about 1e-6).
3. Cost: a fade of ``--frames`` frames (default 120: 4 s at 30 frames per second; density_scale 1
   down to 0.05, geometric) of the sun-10 rain-40 weather, a 64 x 36 street view, on the CPU: the
   time of the whole sequence and the number of solves, for N = 0 and each N. A fresh process
   per setting, so that nothing is cached in between.
4. The sun coming out (``--parts sun``; physics.md eq. 9.4): ``--frames`` frames of the same
   weather and view whose sun's irradiance rises from 0 to the scene's along the smoothstep of
   ``airlight-demo --sequence rain-ends`` (over the first 40 % of the frames), the rain fixed; then
   that demo's whole sequence (the rain's density falling 100-fold as well) with N = 0 and each N.
   Solves and time per sequence. Each frame whose sun lights the scene is one solve by source of
   everything but the sun's irradiance, so a brightening sun alone costs one solve.
"""

from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
for folder in ("effects/multiple_scattering/tests", "effects/daytime/tests", "tests/python"):
    sys.path.insert(0, str(ROOT / folder))

import ms_cases  # noqa: E402
from daytime_reference import rain_extinction  # noqa: E402

SCALES = [2.0 ** (-j / 16) for j in range(16)]
FLOOR = airlight._core.MS_RAIN_LADDER_FLOOR  # the ladder's lowest rung (ms_tables.hpp)


def rain_cases() -> dict:
    cases = ms_cases.load_cases("day")["cases"]
    return {name: case for name, case in sorted(cases.items()) if name.startswith("day_rain")}


def views(renderer: airlight.Renderer, case: dict, density_scale: float, steps: int) -> np.ndarray:
    """[view, channel] radiance of a case with its rain's density scaled."""
    out = []
    for i in range(len(case["views"])):
        scene = ms_cases.view_scene(case, i)
        scene["atmosphere"]["rain"]["density_scale"] = density_scale
        scene["quality"] = {**scene.get("quality", {}), "fading_rain_steps": steps}
        out.append(renderer.render(scene)[0, 0, :3])
    return np.array(out, dtype=np.float64)


def accuracy(steps: list[int]) -> list[str]:
    renderer = airlight.Renderer("cpu")
    lines = ["| case | " + " | ".join(f"N = {n}: max / p99" for n in steps) + " |",
             "|---|" + "---|" * len(steps)]
    worst: dict[int, list[float]] = {n: [] for n in steps}
    for name, case in rain_cases().items():
        exact = [views(renderer, case, s, 0) for s in SCALES]
        cells = []
        for n in steps:
            rel = np.concatenate([np.abs(views(renderer, case, s, n) / e - 1).ravel()
                                  for s, e in zip(SCALES, exact)])
            worst[n].extend(rel.tolist())
            cells.append(f"{rel.max():.2e} / {np.percentile(rel, 99):.2e}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines.append("| all | " + " | ".join(f"**{max(worst[n]):.2e}** / {np.percentile(worst[n], 99):.2e}"
                                         for n in steps) + " |")
    return lines


def continuity(steps: list[int]) -> list[str]:
    """The two sides of a rung: density scales whose extinction is a rung times 1 -+ 1e-6."""
    renderer = airlight.Renderer("cpu")
    case = rain_cases()["day_rain40_sun10"]
    extinction = rain_extinction(case["scene"]["atmosphere"]["rain"]["rate"])  # at density_scale 1
    lines = ["| N | rung extinction (1/m) | largest relative difference across it |", "|---|---|---|"]
    for n in steps:
        k = np.ceil(n * np.log2(extinction / FLOOR))
        rung = FLOOR * 2.0 ** (k / n)
        below = views(renderer, case, rung / extinction * (1 - 1e-6), n)
        above = views(renderer, case, rung / extinction * (1 + 1e-6), n)
        lines.append(f"| {n} | {rung:.4e} | {np.max(np.abs(above / below - 1)):.1e} |")
    return lines


FADE_SCRIPT = textwrap.dedent("""
    import json, sys, time
    import airlight
    scene, frames, steps = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    renderer = airlight.Renderer("cpu")
    start = time.perf_counter()
    for f in range(frames):
        scene["atmosphere"]["rain"]["density_scale"] = 0.05 ** (f / (frames - 1))
        scene["quality"]["fading_rain_steps"] = steps
        renderer.render(scene)
    stats = airlight.table_stats()
    print(json.dumps({"seconds": time.perf_counter() - start,
                      "solves": stats.get("ms_field", {}).get("builds", 0)}))
""")


def street_view() -> dict:
    """The sun-10 rain-40 weather seen along a street, 64 x 36 (the sequences' scene)."""
    scene = copy.deepcopy(rain_cases()["day_rain40_sun10"]["scene"])
    scene["film"] = {"width": 64, "height": 36}
    scene["camera"] = {"position": [0, 1.7, 0], "look_at": [0, 1.7 + 0.087, -1], "up": [0, 1, 0], "fov_y": 40}
    scene.setdefault("quality", {})
    return scene


def fade_cost(steps: list[int], frames: int) -> list[str]:
    scene = street_view()
    lines = ["| N | frames | solves | sequence time (s) | per frame (ms) | speed-up against N = 0 |",
             "|---|---|---|---|---|---|"]
    exact = 0.0
    for n in [0, *steps]:
        out = subprocess.run([sys.executable, "-c", FADE_SCRIPT, json.dumps(scene), str(frames), str(n)],
                             capture_output=True, text=True, check=True)
        r = json.loads(out.stdout)
        exact = exact or r["seconds"]
        lines.append(f"| {n} | {frames} | {r['solves']} | {r['seconds']:.1f} | "
                     f"{1e3 * r['seconds'] / frames:.0f} | {exact / r['seconds']:.1f}x |")
    return lines


SUN_SCRIPT = textwrap.dedent("""
    import json, sys, time
    import airlight
    scene, frames, steps = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    fade = sys.argv[4] == "1"
    sun = list(scene["sun"]["irradiance"])
    renderer = airlight.Renderer("cpu")
    start = time.perf_counter()
    for f in range(frames):
        t = f / (frames - 1)
        s = min(1.0, t / 0.4)  # cpp/demo.cpp run_rain_ends: smoothstep over the first 40 %
        scene["sun"]["irradiance"] = [e * s * s * (3 - 2 * s) for e in sun]
        scene["atmosphere"]["rain"]["density_scale"] = 0.01 ** t if fade else 1.0
        scene["quality"]["fading_rain_steps"] = steps
        renderer.render(scene)
    stats = airlight.table_stats()
    print(json.dumps({"seconds": time.perf_counter() - start,
                      "solves": stats.get("ms_field", {}).get("builds", 0)}))
""")


def sun_cost(steps: list[int], frames: int) -> list[str]:
    scene = street_view()
    lines = ["| sequence | N | frames | solves | sequence time (s) | per frame (ms) |",
             "|---|---|---|---|---|---|"]
    for fade, ns in ((False, [0]), (True, [0, *steps])):
        for n in ns:
            out = subprocess.run([sys.executable, "-c", SUN_SCRIPT, json.dumps(scene), str(frames), str(n),
                                  "1" if fade else "0"], capture_output=True, text=True, check=True)
            r = json.loads(out.stdout)
            name = "sun comes out, rain fades 100-fold" if fade else "sun comes out, rain fixed"
            lines.append(f"| {name} | {n} | {frames} | {r['solves']} | {r['seconds']:.1f} | "
                         f"{1e3 * r['seconds'] / frames:.0f} |")
    return lines


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--steps", type=int, nargs="*", default=[2, 4, 8])
    p.add_argument("--frames", type=int, default=120)
    p.add_argument("--parts", nargs="*", default=["accuracy", "continuity", "cost"])
    p.add_argument("--out", type=Path)
    args = p.parse_args()
    report = [f"# {' '.join(sys.argv)}", ""]
    if "accuracy" in args.parts:
        report += ["## Accuracy: ladder against the exact solve per rain (relative error per value)", "",
                   *accuracy(args.steps), ""]
    if "continuity" in args.parts:
        report += ["## Continuity across a rung (day_rain40_sun10)", "", *continuity(args.steps), ""]
    if "cost" in args.parts:
        report += [f"## Cost of a fade of {args.frames} frames (day_rain40_sun10 weather, 64 x 36, CPU)", "",
                   *fade_cost(args.steps, args.frames), ""]
    if "sun" in args.parts:
        title = f"## The sun coming out, {args.frames} frames (day_rain40_sun10 weather, 64 x 36, CPU)"
        report += [title, "", *sun_cost(args.steps, args.frames), ""]
    text = "\n".join(report)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
