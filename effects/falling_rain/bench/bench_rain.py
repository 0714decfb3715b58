"""Falling rain: frame time against the rain rate on both backends, what a scene pays for the key when
no drop is drawn, and the per-frame tables' memory against their stated bound.

    .venv/bin/python effects/falling_rain/bench/bench_rain.py [--width 640 --height 360]
        [--backends cpu,gl] [--repeats 3] [--quick]
        [--out effects/falling_rain/docs/bench_rain.txt]
        [--plot effects/falling_rain/docs/bench_rain.png]

The scene is the preset crane_searchlight (a night street with 16 lamps and a crane's searchlight in
a homogeneous fog) with falling_rain {rate, time 10 s, seed 1} added, the other keys at their
defaults (radius 8 m, full_diameter 2 mm, no wind, camera.exposure_time 1/60 s). Each scene is
rendered once to warm the renderer (tables built, shader variants compiled), then the scenes of a
table are rendered in turn, `--repeats` rounds (three times as many for the cheap frames of "no drop
drawn"). Each frame is timed twice: wall-clock seconds, and the process's CPU seconds (all threads:
the CPU backend's and llvmpipe's), which another job on the machine barely changes where it can
double the wall time. A time is the median over the rounds; a ratio is the median of the rounds'
ratios of CPU seconds (drift hits both sides alike).

"Drops in the field" is len(airlight._core.rain_drops(scene)): every drop within its draw distance,
in any direction. No output or table statistic of the renderer tells how many of them it drew
(airlight.table_stats lists the tables built once, not the per-frame rain_drops/rain_tiles), so
"drops in view", the tile entries and the tables' bytes are computed here by the frame's own test
(rain_frame.cpp: a streak is kept when its pixel rectangle meets the film and its weight is
positive), checked against the falling_rain layer of a sparse field's render. "Where the time goes"
renders the 25 mm/h frame without the street's surfaces (no shadow test per drop and lamp) and
without its lamps (drops lit by a dim background alone). GL is Mesa's llvmpipe here: a software
rasteriser on the same CPU cores, no GPU. Absolute times on a shared 2-core machine are noisy (the
load average is printed at the start and the end); compare the CPU-time ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

RATES = [0.5, 2, 10, 25, 50, 100]  # mm/h
QUICK_RATES = [2, 25]
RAIN_TIME = 10.0  # s
SEED = 1
# The frame's layout (effects/falling_rain/rain_layout.glsl, drops.hpp, rain_frame.cpp).
ROW_TEXELS = 2048  # texels per row of the drop, tile and light tables
TILE = 16  # a screen tile's edge, pixels
NEAR = 0.05  # m: streaks are cut there in front of the camera
DROP_FLOATS = 8  # two RGBA texels a drop: streak start, diameter; streak end, weight
LIGHT_FLOATS = 4  # one RGBA texel a drop: its radiance toward the camera (grid pass)
MAX_DROPS = 2**21  # FALLING_RAIN_MAX_DROPS: drops a frame
MAX_TILE_ENTRIES = 2**24  # the tile lists' bound (4-byte entries)
ENV_BYTES = 2 * 64 * 32 * 4 * 4  # rain_environment and rain_surround: 64x32 RGBA float maps
MIB = 2.0**20


def street(width: int, height: int, rate: float | None = None, lights: bool = True) -> dict[str, Any]:
    """crane_searchlight at width x height, with falling_rain at `rate` mm/h (None: no key), and
    with no light at all when `lights` is False (its background is already black)."""
    scene = airlight.preset("crane_searchlight")
    scene["film"] = {"width": width, "height": height}
    if not lights:
        scene["lights"] = []
        scene["background"] = [0, 0, 0]
    if rate is not None:
        scene["falling_rain"] = {"rate": rate, "time": RAIN_TIME, "seed": SEED}
    return scene


FALLBACK: dict[str, int] = {}  # backend -> the most pixels llvmpipe's loop limiter sent back to the CPU
TOTAL = np.zeros(2)  # wall and CPU seconds of every timed frame


WALL, CPU = 0, 1  # the last axis of rounds()'s times


def timed(renderer: airlight.Renderer, scene: dict[str, Any]) -> tuple[float, float]:
    """One frame's wall-clock seconds and the process's CPU seconds (all its threads)."""
    wall, cpu = time.perf_counter(), time.process_time()
    renderer.render(scene)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    FALLBACK[renderer.backend] = max(FALLBACK.get(renderer.backend, 0), renderer.cpu_fallback_pixels)
    TOTAL[:] += (wall, cpu)
    return wall, cpu


def rounds(renderer: airlight.Renderer, scenes: list[dict[str, Any]], repeats: int, label: str) -> np.ndarray:
    """Times (repeats x scenes x [wall, CPU]): each scene rendered once to warm, then all of them in
    turn per round."""
    for scene in scenes:
        renderer.render(scene)
    times = np.zeros((repeats, len(scenes), 2))
    for k in range(repeats):
        for i, scene in enumerate(scenes):
            times[k, i] = timed(renderer, scene)
        print(f"  {label}: round {k + 1}/{repeats} (wall/CPU s): "
              + " ".join(f"{w:.2f}/{c:.2f}" for w, c in times[k]), file=sys.stderr, flush=True)
    return times


def ratio(times: np.ndarray, i: int, ref: int) -> float:
    """The median over the rounds of scene i's CPU seconds over scene ref's."""
    return float(np.median(times[:, i, CPU] / times[:, ref, CPU]))


def camera_basis(scene: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Position and the frame's right, up (scaled by the film's half extents) and forward, in float32
    as cpp/frame_data.cpp makes them."""
    cam = scene["camera"]
    f32 = np.float32
    position = np.asarray(cam["position"], f32)
    forward = np.asarray(cam["look_at"], f32) - position
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(cam.get("up", [0, 1, 0]), f32))
    right = right / np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_half = f32(np.tan(0.5 * np.radians(cam["fov_y"])))
    aspect = f32(scene["film"]["width"]) / f32(scene["film"]["height"])
    return (position.astype(float), (right * (tan_half * aspect)).astype(float),
            (up * tan_half).astype(float), forward.astype(float))


def streak_rectangles(scene: dict[str, Any], drops: dict[str, np.ndarray]) -> np.ndarray:
    """The drops' pixel rectangles (x0, x1, y0, y1) as rain_frame.cpp computes them, for the drops the
    frame keeps (rectangle on the film, weight > 0)."""
    width, height = scene["film"]["width"], scene["film"]["height"]
    exposure = scene["camera"].get("exposure_time", 1.0 / 60.0)
    camera, right, up, forward = camera_basis(scene)
    a = drops["position"] - 0.5 * exposure * drops["velocity"] - camera
    b = drops["position"] + 0.5 * exposure * drops["velocity"] - camera
    za, zb = a @ forward, b @ forward
    seen = (za >= NEAR) | (zb >= NEAR)
    with np.errstate(divide="ignore", invalid="ignore"):
        cut_a = seen & (za < NEAR)
        a[cut_a] += (b - a)[cut_a] * ((NEAR - za) / (zb - za))[cut_a, None]
        cut_b = seen & (zb < NEAR)
        b[cut_b] += (a - b)[cut_b] * ((NEAR - zb) / (za - zb))[cut_b, None]
        ends = []
        for q in (a, b):
            z = q @ forward
            x = 0.5 * (q @ right / (right @ right * z) + 1.0) * width
            y = 0.5 * (1.0 - q @ up / (up @ up * z)) * height
            ends.append((x, y, z))
    (xa, ya, za), (xb, yb, zb) = ends
    z_min = np.minimum(za, zb)
    grow = 0.5e-3 * drops["diameter"] / (z_min * 2.0 * np.linalg.norm(up) / height) + 1.0
    x_lo, x_hi = np.minimum(xa, xb) - grow, np.maximum(xa, xb) + grow
    y_lo, y_hi = np.minimum(ya, yb) - grow, np.maximum(ya, yb) + grow
    keep = seen & ~((x_hi < 0) | (y_hi < 0) | (x_lo >= width) | (y_lo >= height)) & (drops["weight"] > 0)
    rects = np.stack([np.maximum(x_lo, 0), np.minimum(x_hi, width - 1.0),
                      np.maximum(y_lo, 0), np.minimum(y_hi, height - 1.0)], axis=1)[keep]
    return rects.astype(np.int64)


def frame_tables(scene: dict[str, Any], rects: np.ndarray) -> dict[str, float]:
    """Drops in view, tile entries and the per-frame tables' bytes (row tables padded to full rows)."""
    width, height = scene["film"]["width"], scene["film"]["height"]
    n = len(rects)
    tiles = -(-width // TILE) * -(-height // TILE)
    entries = int(((rects[:, 1] // TILE - rects[:, 0] // TILE + 1)
                   * (rects[:, 3] // TILE - rects[:, 2] // TILE + 1)).sum())
    rows = lambda texels: max(1, -(-texels // ROW_TEXELS))  # noqa: E731
    drop_bytes = rows(n * DROP_FLOATS // 4) * ROW_TEXELS * 16
    tile_bytes = rows(tiles + 1 + entries) * ROW_TEXELS * 4
    light_bytes = min(n, ROW_TEXELS) * rows(n) * 16
    return {"in_view": n, "tile_entries": entries, "drop_bytes": drop_bytes, "tile_bytes": tile_bytes,
            "light_bytes": light_bytes, "bytes": drop_bytes + tile_bytes + light_bytes + ENV_BYTES}


def header(args: argparse.Namespace, renderers: dict[str, airlight.Renderer]) -> list[str]:
    info = airlight.backend_info()
    cpu = platform.processor() or platform.machine()
    try:
        model = [line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                 if line.startswith("model name")]
        cpu = model[0] if model else cpu
    except OSError:
        pass
    names = {"cpu": f"CPU backend ({os.cpu_count()} threads)",
             "gl": f"GL: {info['gl_renderer']}" + (" (software, on the same CPU cores)" if info["gl_software"]
                                                  else "")}
    lines = ["# Falling rain benchmark\n", f"`{' '.join(sys.argv)}`\n",
             f"Machine: {os.cpu_count()} cores (nproc), {cpu}; airlight {airlight.__version__}, "
             f"Python {platform.python_version()}.",
             "Backends: " + "; ".join(names[b] for b in renderers) + ".",
             f"Scene: crane_searchlight at {args.width}x{args.height}, falling_rain "
             f"{{rate, time {RAIN_TIME:g}, seed {SEED}}} (radius 8 m, full_diameter 2 mm, "
             f"exposure 1/60 s). Times: median of {args.repeats} rounds after one warm frame per scene, "
             "wall-clock and CPU (the process's CPU seconds, all threads); ratios: median of the rounds' "
             "ratios of CPU seconds.\n"]
    return lines


def sweep(args: argparse.Namespace, renderers: dict[str, airlight.Renderer], lines: list[str]) -> list[dict]:
    lines.append(f"## Frame time against the rain rate ({args.width}x{args.height})\n")
    rows: list[dict[str, Any]] = [{"rate": r} for r in args.rates]
    for row in rows:
        scene = street(args.width, args.height, row["rate"])
        field = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            drops = airlight._core.rain_drops(scene)
            field.append(time.perf_counter() - start)
        row["field_seconds"] = float(np.median(field))
        row["field"] = len(drops["id"])
        row.update(frame_tables(scene, streak_rectangles(scene, drops)))
    scenes = [street(args.width, args.height)] + [street(args.width, args.height, r) for r in args.rates]
    tiles = -(-args.width // TILE) * -(-args.height // TILE)
    none: dict[str, tuple[float, float]] = {}
    for b, renderer in renderers.items():
        t = rounds(renderer, scenes, args.repeats, f"{b} {args.width}x{args.height}")
        none[b] = (float(np.median(t[:, 0, WALL])), float(np.median(t[:, 0, CPU])))
        for i, row in enumerate(rows, start=1):
            row[b] = (float(np.median(t[:, i, WALL])), float(np.median(t[:, i, CPU])))
            row[b + "_ratio"] = ratio(t, i, 0)
    head = ("| rate mm/h | drops in the field | drops in view | tile entries (mean per tile) | tables MiB "
            "| field s |")
    for b in renderers:
        head += f" {b} wall s | {b} CPU s | {b} / no rain | {b} CPU us per drop |"
    lines.append(head)
    lines.append("|" + "---|" * (head.count("|") - 1))
    text = "| no falling_rain | - | - | - | - | - |"
    for b in renderers:
        text += f" {none[b][WALL]:.2f} | {none[b][CPU]:.2f} | 1 | - |"
    lines.append(text)
    for row in rows:
        text = (f"| {row['rate']:g} | {row['field']} | {row['in_view']} "
                f"| {row['tile_entries']} ({row['tile_entries'] / tiles:.0f}) "
                f"| {row['bytes'] / MIB:.2f} | {row['field_seconds']:.3f} |")
        for b in renderers:
            per_drop = (row[b][CPU] - none[b][CPU]) / max(row["in_view"], 1) * 1e6
            text += f" {row[b][WALL]:.2f} | {row[b][CPU]:.2f} | {row[b + '_ratio']:.2f} | {per_drop:.0f} |"
        lines.append(text)
    lines.append(f"\nTiles: {TILE}x{TILE} pixels, {tiles} on the film; each pixel tests every streak of its "
                 "tile's list. \"field s\": airlight._core.rain_drops alone (every drop within its "
                 "distance, one thread), which each rain frame also draws before keeping those in view. "
                 "\"CPU us per drop\": (CPU s - no rain's) / drops in view.")
    if "cpu" in renderers and "gl" in renderers:
        def compare(k: int) -> str:
            return f"no rain {none['gl'][k] / none['cpu'][k]:.2f}; " + ", ".join(
                f"{r['rate']:g} mm/h {r['gl'][k] / r['cpu'][k]:.2f}" for r in rows)
        slower = [r["rate"] for r in rows if r["gl"][WALL] > r["cpu"][WALL]]
        verdict = ("slower than the CPU backend at every rain rate" if len(slower) == len(rows) else
                   f"slower than the CPU backend at {len(slower)} of {len(rows)} rain rates")
        lines.append(f"GL (llvmpipe) / CPU backend, wall time: {compare(WALL)}; CPU time: {compare(CPU)}. "
                     f"llvmpipe runs on the same {os.cpu_count()} cores as the CPU backend (no GPU here): "
                     f"in wall time GL is {verdict}.")
    if "gl" in renderers:
        lines.append(f"GL pixels cut by llvmpipe's loop limiter and recomputed on the CPU "
                     f"(Renderer.cpu_fallback_pixels), most in any frame so far: {FALLBACK.get('gl', 0)}.")
    for r in rows:
        r["none"] = none
    lines.append("")
    return rows


def layer_check(args: argparse.Namespace, lines: list[str]) -> None:
    """The computed streak rectangles against the falling_rain layer of one CPU frame of a sparse field
    (25 mm/h within 1 m, so that the rectangles leave most of the film): no lit pixel outside them, and
    a lit pixel in each (none drawn that the count misses, none counted that the frame left out)."""
    scene = street(args.width, args.height, 25)
    scene["falling_rain"]["radius"] = 1.0
    rects = streak_rectangles(scene, airlight._core.rain_drops(scene))
    with airlight.Renderer("cpu") as r:
        layer = r.render(scene, outputs=["falling_rain"])["falling_rain"]
    lit = np.any(layer != 0, axis=2)
    covered = np.zeros_like(lit)
    holding = 0
    for x0, x1, y0, y1 in rects:
        covered[y0:y1 + 1, x0:x1 + 1] = True
        holding += bool(lit[y0:y1 + 1, x0:x1 + 1].any())
    outside = int((lit & ~covered).sum())
    lines.append(f"Check of the drops-in-view count (25 mm/h within radius 1 m, CPU, falling_rain layer): "
                 f"{len(rects)} computed streak rectangles covering {int(covered.sum())} of {lit.size} "
                 "pixels; "
                 f"{int(lit.sum())} pixels lit by the layer, {outside} of them outside the rectangles; "
                 f"{holding} of the {len(rects)} rectangles hold a lit pixel.\n")


def time_split(args: argparse.Namespace, renderers: dict[str, airlight.Renderer], lines: list[str]) -> None:
    """The 25 mm/h frame's extra time over no rain, with the drops' lamp and shadow work taken away."""
    w, h = args.width, args.height
    lines.append(f"## Where the time goes (25 mm/h, {w}x{h})\n")
    cases = []
    for name in ("crane_searchlight (16 lamps, a spot, 26 surfaces)", "surfaces [] (no shadow tests)",
                 "lights [], background 0.01 (no lamp loop)"):
        pair = [street(w, h), street(w, h, 25)]
        for s in pair:
            if name.startswith("surfaces"):
                s["surfaces"] = []
            elif name.startswith("lights"):
                s["lights"], s["background"] = [], [0.01, 0.01, 0.01]
        cases.append((name, pair))
    head = "| scene (CPU seconds) | " + " | ".join(f"{b} no rain | {b} rain | {b} rain - no rain"
                                                   for b in renderers) + " |"
    lines.append(head)
    lines.append("|" + "---|" * (head.count("|") - 1))
    scenes = [s for _, pair in cases for s in pair]
    results = {b: rounds(r, scenes, args.repeats, f"{b} time split") for b, r in renderers.items()}
    for i, (name, _) in enumerate(cases):
        text = f"| {name} |"
        for b in renderers:
            t = results[b][:, :, CPU]
            text += (f" {np.median(t[:, 2 * i]):.2f} | {np.median(t[:, 2 * i + 1]):.2f} "
                     f"| {np.median(t[:, 2 * i + 1] - t[:, 2 * i]):.2f} |")
        lines.append(text)
    lines.append("")


def costs_nothing(args: argparse.Namespace, renderers: dict[str, airlight.Renderer],
                  lines: list[str]) -> None:
    lines.append(f"## What a frame pays when no drop is drawn ({args.width}x{args.height})\n")
    w, h = args.width, args.height
    zero = street(w, h)
    zero["falling_rain"] = {"rate": 0, "time": RAIN_TIME, "seed": SEED}
    few = street(w, h, 25)
    few["falling_rain"]["radius"] = 0.3
    in_view = len(streak_rectangles(few, airlight._core.rain_drops(few)))
    cases = [("crane_searchlight, no falling_rain", street(w, h), None),
             ("falling_rain rate 0", zero, 0),
             (f"falling_rain 25 mm/h within radius 0.3 m ({in_view} drops in view: the effect's "
              "fixed passes)", few, 0),
             ("lights [] (no light), no falling_rain", street(w, h, lights=False), None),
             ("lights [] (no light), falling_rain 25 mm/h", street(w, h, 25, lights=False), 3)]
    head = "| scene | " + " | ".join(f"{b} wall s | {b} CPU s | {b} / no rain" for b in renderers) + " |"
    lines.append(head)
    lines.append("|" + "---|" * (head.count("|") - 1))
    results = {b: rounds(r, [c[1] for c in cases], 3 * args.repeats, f"{b} no drops")
               for b, r in renderers.items()}
    for i, (name, _, ref) in enumerate(cases):
        text = f"| {name} |"
        for b in renderers:
            t = results[b]
            r = "1" if ref is None else f"{ratio(t, i, ref):.3f}"
            text += f" {np.median(t[:, i, WALL]):.3f} | {np.median(t[:, i, CPU]):.3f} | {r} |"
        lines.append(text)
    probe = ("import json, sys, airlight; airlight.render(json.loads(sys.argv[1]), backend='cpu', width=64, "
             "height=36); print(json.dumps(sorted(airlight.table_stats())))")
    lines.append("")
    for name, s in [("no falling_rain", street(w, h)), ("falling_rain rate 0", zero),
                    ("no light, falling_rain 25 mm/h", street(w, h, 25, lights=False)),
                    ("falling_rain 25 mm/h", street(w, h, 25))]:
        out = subprocess.run([sys.executable, "-c", probe, json.dumps(s)], capture_output=True, text=True,
                             check=True)
        built = [t for t in json.loads(out.stdout) if "rain" in t or "drop" in t]
        lines.append(f"Rain tables built by a fresh process rendering {name}: {built or 'none'}")
    lines.append("")


def memory(rows: list[dict], lines: list[str]) -> None:
    lines.append("## Memory\n")
    big = max(rows, key=lambda r: r["bytes"])
    lines.append(f"Largest per-frame tables over the sweep: {big['bytes'] / MIB:.2f} MiB at "
                 f"{big['rate']:g} mm/h "
                 f"({big['in_view']} drops in view: drops {big['drop_bytes'] / MIB:.2f} MiB, light "
                 f"{big['light_bytes'] / MIB:.2f} MiB; {big['tile_entries']} tile entries: "
                 f"{big['tile_bytes'] / MIB:.2f} MiB; environment maps {ENV_BYTES / MIB:.2f} MiB), "
                 "row tables counted to full rows of 2048 texels, float32.")
    drops = MAX_DROPS * (DROP_FLOATS + LIGHT_FLOATS) * 4
    tiles = MAX_TILE_ENTRIES * 4
    lines.append(f"Bound: at most 2^21 drops a frame x ({DROP_FLOATS} + {LIGHT_FLOATS}) floats x 4 bytes = "
                 f"{drops / MIB:.0f} MiB, and 2^24 tile entries x 4 bytes = {tiles / MIB:.0f} MiB: "
                 f"{(drops + tiles) / MIB:.0f} MiB in all (beyond either, the frame refuses, naming the keys "
                 f"to change). The sweep's largest frame uses {big['bytes'] / (drops + tiles) * 100:.1f} % "
                 "of it.\n")


def plot(rows: list[dict], backends: list[str], path: str, size: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    rates = [r["rate"] for r in rows]
    for ax, k, what in zip(axes, (WALL, CPU), ("wall-clock seconds per frame",
                                               "CPU seconds per frame (all threads)")):
        for b, color in zip(backends, ["C0", "C1"]):
            ax.plot(rates, [r[b][k] for r in rows], "o-", color=color, label=f"{b}: with falling rain")
            ax.axhline(rows[0]["none"][b][k], color=color, ls="--", lw=1, label=f"{b}: no falling_rain")
        ax.set_xscale("log")
        ax.set_ylim(bottom=0)
        ax.set_xlabel("rain rate (mm/h)")
        ax.set_ylabel(what)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"crane_searchlight + falling_rain, {size}, {os.cpu_count()} cores "
                 "(gl: Mesa llvmpipe, on the CPU)", fontsize=9)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--backends", default="cpu,gl", help="comma-separated: cpu,gl")
    ap.add_argument("--repeats", type=int, default=3, help="timed rounds after the warm frame")
    ap.add_argument("--quick", action="store_true", help="smoke test: 160x90, rates 2 and 25, 1 repeat")
    ap.add_argument("--out")
    ap.add_argument("--plot")
    args = ap.parse_args()
    args.rates = RATES
    if args.quick:
        args.width, args.height, args.rates, args.repeats = 160, 90, QUICK_RATES, 1
    wanted = [b.strip() for b in args.backends.replace(" ", ",").split(",") if b.strip()]
    backends = [b for b in wanted if b in airlight.available_backends()]
    renderers = {b: airlight.Renderer(b) for b in backends}
    start, load = time.perf_counter(), os.getloadavg()[0]
    lines = header(args, renderers)
    rows = sweep(args, renderers, lines)
    layer_check(args, lines)
    time_split(args, renderers, lines)
    costs_nothing(args, renderers, lines)
    memory(rows, lines)
    if args.plot:
        plot(rows, backends, args.plot, f"{args.width}x{args.height}")
        lines.append(f"Plot: {args.plot}\n")
    lines.append(f"Benchmark wall time: {time.perf_counter() - start:.0f} s; load average (1 min) "
                 f"{load:.2f} at the start, {os.getloadavg()[0]:.2f} at the end; CPU / wall seconds over "
                 f"all timed frames {TOTAL[CPU] / TOTAL[WALL]:.2f} (the cores this process had on average: "
                 f"{os.cpu_count()} when it has the machine to itself).")
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
