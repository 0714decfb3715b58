"""Error and cost of the renderer's daytime multiple scattering (issue 18), in one run:

    .venv/bin/python effects/multiple_scattering/bench/bench_multiple_scattering.py \\
        [--width 160 --height 90] [--march-steps 64 256 1024] \\
        [--out effects/multiple_scattering/docs/bench_ms.txt] \\
        [--plot docs/images/bench_multiple_scattering.png]

1. Accuracy against the stored Mitsuba reference (effects/multiple_scattering/tests/data/
   day_reference.json: 24 weathers and suns x 14 views x 3 channels; path-traced, unlimited
   depth): per case the share of values within max(3 %, 3 standard errors) and the median and
   largest relative error, for the field's table integrated over the scattering volumes (the
   default), through the aerial table (`quality.aerial_table` 16: effects/daytime/docs/
   aerial_table.md), for brute-force marching of the same field (`"airlight": "march"`: the
   source sampled at every step instead of integrated over scattering volumes), and for single
   scattering alone (`quality.multiple_scattering` false: what the renderer gave before).
2. The solve per weather state: time and table size (a fresh process per state, so that
   nothing is cached), and the solver levels.
3. The per-pixel cost: a frame of the day presets' weathers over open fields (camera 1.7 m up,
   5 degrees up: sky, horizon and ground), with multiple scattering on and off, CPU and GL,
   median of 3 frames after a warm-up that builds the tables. Ratios matter; absolute times on a
   shared 2-core machine are noisy.
"""

from __future__ import annotations

import argparse
import copy
import json
import statistics
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "effects" / "multiple_scattering" / "tests"))

import ms_cases  # noqa: E402


def accuracy(march_steps: list[int]) -> tuple[list[str], dict]:
    cases = ms_cases.load_cases("day")["cases"]
    renderer = airlight.Renderer("cpu")
    methods = [("volumes", {"aerial_table": 0}), ("aerial table 16", {"aerial_table": 16}),
               *[(f"march {n}", {"airlight": "march", "march_steps": n}) for n in march_steps],
               ("single only", {"multiple_scattering": False})]
    lines = ["| case | " + " | ".join(f"{m}: within / median / max" for m, _ in methods) + " |",
             "|---|" + "---|" * len(methods)]
    totals: dict[str, list] = {m: [] for m, _ in methods}
    seconds: dict[str, float] = {m: 0.0 for m, _ in methods}
    for name in sorted(cases):
        case = cases[name]
        want = np.array([v["radiance"] for v in case["views"]])
        err = np.array([v["stderr"] for v in case["views"]])
        cells = []
        for method, quality in methods:
            got = []
            for i in range(len(case["views"])):
                scene = ms_cases.view_scene(case, i)
                scene["quality"] = dict(quality)
                start = time.perf_counter()
                got.append(renderer.render(scene)[0, 0, :3])
                seconds[method] += time.perf_counter() - start
            got_a = np.array(got)
            rel = np.abs(got_a / want - 1.0)
            within = ms_cases.fraction_within(got_a, want, err)
            totals[method].append((got_a, want, err))
            cells.append(f"{within:.2f} / {np.median(rel):.3f} / {rel.max():.3g}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    row = []
    for method, _ in methods:
        got_a = np.concatenate([t[0] for t in totals[method]])
        want = np.concatenate([t[1] for t in totals[method]])
        err = np.concatenate([t[2] for t in totals[method]])
        rel = np.abs(got_a / want - 1.0)
        within = ms_cases.fraction_within(got_a, want, err)
        row.append(f"**{within:.3f}** / {np.median(rel):.3f} / {rel.max():.3g}")
    lines.append("| all | " + " | ".join(row) + " |")
    lines.append("")
    lines.append("CPU seconds for the 336 one-pixel renders (the first of each case includes its solve): " +
                 ", ".join(f"{m} {s:.1f}" for m, s in seconds.items()))
    renderer.close()
    return lines, totals


SOLVE_SCRIPT = textwrap.dedent("""
    import json, sys, time, airlight
    scene = json.loads(sys.argv[1])
    airlight.render(scene, backend="cpu")
    stats = airlight.table_stats()
    # The solve; with a sun it holds the sky's and the sun's parts, summed into ms_field_sunlit (eq. 9.4).
    print(json.dumps({"solve": stats["ms_field"], "table": stats.get("ms_field_sunlit", stats["ms_field"])}))
""")


def solve_costs() -> list[str]:
    lines = ["| weather | sun | solve + tables (s) | levels | table (MB) |", "|---|---|---|---|---|"]
    for weather in ms_cases.WEATHERS:
        for sun in ("sun60", "overcast"):
            scene = ms_cases.day_scene(weather, sun)
            out = subprocess.run([sys.executable, "-c", SOLVE_SCRIPT, json.dumps(scene)], capture_output=True,
                                 text=True, check=True)
            solve, table = json.loads(out.stdout).values()
            lines.append(f"| {weather} | {sun} | {solve['build_seconds']:.2f} | {table['width']} | "
                         f"{table['bytes'] / 1e6:.1f} |")
    return lines


def open_fields(name: str, width: int, height: int) -> dict:
    """A day preset's weather, sky and sun over its ground plane, camera 1.7 m up looking 5 degrees up."""
    scene = airlight.preset(name)
    ground = [s for s in scene["surfaces"] if s["type"] == "plane"][:1]
    scene["surfaces"] = ground
    scene["film"] = {"width": width, "height": height}
    scene["camera"] = {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.7 + np.tan(np.radians(5.0)), -1.0],
                       "up": [0.0, 1.0, 0.0], "fov_y": 60.0}
    scene.pop("display", None)
    return scene


def median_time(renderer: airlight.Renderer, scene: dict) -> float:
    renderer.render(scene)  # warm-up: tables, shader variant
    times = []
    for _ in range(3):
        start = time.perf_counter()
        renderer.render(scene)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def frame_costs(width: int, height: int) -> list[str]:
    lines = ["| scene | backend | off (ms) | on (ms) | on / off |", "|---|---|---|---|---|"]
    for backend in ("cpu", "gl"):
        if backend == "gl" and airlight.gl_unavailable_reason() is not None:
            lines.append(f"| (all) | gl | unavailable: {airlight.gl_unavailable_reason()} | | |")
            continue
        renderer = airlight.Renderer(backend)
        for name in ("day_clear", "day_light_rain", "day_heavy_rain"):
            scene = open_fields(name, width, height)
            on = median_time(renderer, scene)
            off_scene = copy.deepcopy(scene)
            off_scene["quality"] = {"multiple_scattering": False}
            off = median_time(renderer, off_scene)
            lines.append(f"| {name} | {backend} | {1e3 * off:.0f} | {1e3 * on:.0f} | {on / off:.2f} |")
        renderer.close()
    return lines


def plot(totals: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.0))
    for method in ("volumes", "aerial table 16", "single only"):
        got = np.concatenate([t[0] for t in totals[method]]).ravel()
        want = np.concatenate([t[1] for t in totals[method]]).ravel()
        ax.loglog(want, got, ".", ms=3, label=f"airlight, {method}")
    lo, hi = 1e-7, 20.0
    ax.loglog([lo, hi], [lo, hi], "k-", lw=0.8, label="equal")
    ax.set_xlabel("Mitsuba 3 path tracer (radiance)")
    ax.set_ylabel("airlight (radiance)")
    ax.set_title("Daytime views: 24 weathers and suns x 14 views x RGB")
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--width", type=int, default=160)
    p.add_argument("--height", type=int, default=90)
    p.add_argument("--march-steps", type=int, nargs="*", default=[64, 256, 1024])
    p.add_argument("--out", type=Path)
    p.add_argument("--plot", type=Path)
    args = p.parse_args()
    acc, totals = accuracy(args.march_steps)
    text = ["## Accuracy against the path tracer (within 3 % or 3 sigma / median / max relative error)", "",
            *acc, "", "## The solve per weather state", "", *solve_costs(), "",
            f"## Frame cost, {args.width} x {args.height}", "", *frame_costs(args.width, args.height)]
    print("\n".join(text))
    if args.out:
        args.out.write_text("\n".join(text) + "\n")
    if args.plot:
        plot(totals, args.plot)


if __name__ == "__main__":
    main()
