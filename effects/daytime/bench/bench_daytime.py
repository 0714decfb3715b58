"""Run time against error for daytime scenes (issue 6): scattering volumes versus brute-force
ray marching of the same atmosphere, both backends, in one run.

    .venv/bin/python effects/daytime/bench/bench_daytime.py [--width 320 --height 180] [--samples 120]
        [--segments 2 4 8 16 32 64] [--steps 16 64 256 1024 4096] [--gl-max-steps 1024]
        [--out effects/daytime/docs/bench_daytime.txt] [--plot docs/images/bench_daytime.png]

Scenes: the three weathers of the daytime presets (scenes/day_clear.json, day_heavy_rain.json,
day_light_rain.json: a CIE 12 sky with the sun over haze; heavy rain 40 mm/h in 3 km haze under
the overcast sky; light rain 3 mm/h in 10 km haze) seen over open fields (the presets' ground
plane, without their buildings, so that every sampled pixel has an exact reference) by a camera
1.7 m above the ground looking 5 degrees up: sky, horizon and ground in one frame.

Error: against effects/daytime/tests/daytime_reference.py (float64; the exact sky-phase integral by a
hemisphere rule at every point, the view ray by Gauss-Legendre on graded panels; it shares none
of the renderer's table, altitude levels or source approximation), on sampled pixels (half
uniformly random, half in the rows around the horizon, where the rays are longest); the largest
relative error over sampled pixels above 1e-3 of the largest sampled value.

Methods: the analytic scattering volumes at several `quality.sky_segments` (altitude levels),
and ray marching (`"airlight": "march"`) at several step counts: midpoint steps of equal length
over each ray's part in the atmosphere, up to where its optical depth passes 30 (upward rays:
up to the top of the atmosphere, 92 km). GL marching is limited to --gl-max-steps: llvmpipe cuts
longer shader loops short. Time: median of 3 frames (1 for frames over 5 s), after a warm-up
frame that builds the sky table; the same scene without its atmosphere is what both methods
share (its time is reported, and the atmosphere's part is the difference).

Speed-up at an error target: the time of marching at that error (log-log interpolation between
the step counts that bracket it; a lower bound, marked >, when no step count reaches it) over
the time of the fewest segments that reach it. Timings on a shared 2-core machine are noisy:
compare ratios.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(ROOT / "tests" / "python"), *(str(d) for d in sorted(ROOT.glob("effects/*/tests")))]

import daytime_reference as ref  # noqa: E402
import reference  # noqa: E402

SCENES = ("day_clear", "day_heavy_rain", "day_light_rain")
TARGETS = (0.01, 0.005)


def open_fields(name: str, width: int, height: int) -> dict:
    """The preset's weather over its ground plane only, camera 1.7 m up looking 5 degrees up."""
    scene = airlight.preset(name)
    scene["surfaces"] = scene["surfaces"][:1]
    scene["film"] = {"width": width, "height": height}
    p = math.radians(5.0)
    scene["camera"] = {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.7 + math.sin(p), -math.cos(p)],
                       "up": [0.0, 1.0, 0.0], "fov_y": 60.0}
    scene.pop("display", None)
    return scene


def reference_of(scene: dict):
    """(atmosphere, sky, ground albedo) of the reference for a scene of this script."""
    sky, sun, atm = scene["sky"], scene.get("sun", {}), scene["atmosphere"]
    cie = 0 if sky["model"] == "overcast" else sky["type"]
    r_sky = ref.Sky(cie, tuple(sky["zenith_radiance"]), sun.get("azimuth", 0.0), sun.get("elevation", 30.0),
                    tuple(sun.get("irradiance", (0.0, 0.0, 0.0))))
    aerosol = atm.get("aerosol")
    r_atm = ref.make_atmosphere(rain_rate=atm.get("rain", {}).get("rate", 0.0),
                                visibility=aerosol["visibility"] if aerosol else None,
                                molecules="molecules" in atm,
                                aerosol_g=aerosol.get("g", ref.AEROSOL_G) if aerosol else ref.AEROSOL_G,
                                aerosol_albedo=aerosol.get("albedo", ref.AEROSOL_ALBEDO) if aerosol
                                else ref.AEROSOL_ALBEDO,
                                aerosol_scale_height=aerosol.get("scale_height", ref.AEROSOL_SCALE_HEIGHT)
                                if aerosol else ref.AEROSOL_SCALE_HEIGHT)
    albedo = np.asarray(scene["surfaces"][0]["albedo"], dtype=float)
    return r_atm, r_sky, albedo


def sample_pixels(width: int, height: int, count: int, horizon_row: int, rng) -> list[tuple[int, int]]:
    """Half uniformly random pixels, half within 4 % of the height of the horizon's row."""
    band = max(1, int(0.04 * height))
    picks = set()
    while len(picks) < count // 2:
        picks.add((int(rng.integers(height)), int(rng.integers(width))))
    while len(picks) < count:
        row = int(np.clip(horizon_row + rng.integers(-band, band + 1), 0, height - 1))
        picks.add((row, int(rng.integers(width))))
    return sorted(picks)


def reference_values(scene: dict, pixels: list[tuple[int, int]]) -> np.ndarray:
    r_atm, r_sky, albedo = reference_of(scene)
    _o, dirs = reference.camera_rays(scene["camera"], scene["film"]["width"], scene["film"]["height"])
    out = []
    for row, col in pixels:
        d = dirs[row, col]
        # The ground's albedo is per channel: the reference takes one number, so run it per channel
        # only for ground pixels whose albedo differs between channels.
        if d[1] < 0.0:
            per = [ref.view_ray_gauss(r_atm, r_sky, 1.7, d, ground_albedo=float(a)) for a in albedo]
            out.append([per[c][c] for c in range(3)])
        else:
            out.append(ref.view_ray_gauss(r_atm, r_sky, 1.7, d))
    return np.asarray(out)


def error_of(image: np.ndarray, pixels, expected: np.ndarray) -> tuple[float, float]:
    got = np.asarray([image[r, c] for r, c in pixels], dtype=float)
    mask = expected > 1e-3 * expected.max()
    rel = np.abs(got - expected)[mask] / expected[mask]
    return float(rel.max()), float(np.percentile(rel, 95))


def timed(renderer: airlight.Renderer, scene: dict) -> tuple[float, np.ndarray]:
    t0 = time.perf_counter()
    image = renderer.render(scene)
    first = time.perf_counter() - t0
    times = [first]
    if first < 5.0:
        for _ in range(2):
            t0 = time.perf_counter()
            image = renderer.render(scene)
            times.append(time.perf_counter() - t0)
    return statistics.median(times), image


def speedup(analytic: list[dict], marched: list[dict], target: float) -> str:
    fast = [m for m in analytic if m["error"] <= target]
    if not fast:
        return "n/a"
    t_fast = min(m["seconds"] for m in fast)
    pts = sorted((m["error"], m["seconds"]) for m in marched)
    for (e1, t1), (e2, t2) in zip(pts, pts[1:]):
        if e1 <= target <= e2 and e1 > 0:
            f = (math.log(target) - math.log(e2)) / (math.log(e1) - math.log(e2))
            t = math.exp(math.log(t2) + f * (math.log(t1) - math.log(t2)))
            return f"{t / t_fast:.0f}x"
    if pts and pts[0][0] <= target:
        return f"{pts[0][1] / t_fast:.0f}x"
    slowest = max(m["seconds"] for m in marched)
    return f">{slowest / t_fast:.0f}x"


def sweep(renderer: airlight.Renderer, scene: dict, pixels, expected: np.ndarray, segments, steps,
          gl_max_steps: int) -> dict:
    """Frame time and error of the scattering volumes at each count of altitude levels
    (``analytic``) and of ray marching at each step count (``march``; GL only up to
    ``gl_max_steps``, llvmpipe's loop limit)."""
    rows: dict = {"analytic": [], "march": []}
    runs = [("analytic", n, {"sky_segments": n}) for n in segments]
    runs += [("march", n, {"airlight": "march", "march_steps": n}) for n in steps
             if renderer.backend != "gl" or n <= gl_max_steps]
    for method, n, quality in runs:
        s = copy.deepcopy(scene)
        s["quality"] = quality
        t, image = timed(renderer, s)
        e, e95 = error_of(image, pixels, expected)
        rows[method].append({"param": n, "seconds": t, "error": e, "error95": e95})
    return rows


def sweep_table(rows: dict, baseline: float | None = None) -> list[str]:
    """The sweep's rows as a Markdown table; with ``baseline`` (the frame time without the
    atmosphere) also the atmosphere's part of each frame."""
    part = " atmosphere part (ms) |" if baseline is not None else ""
    out = [f"| method | parameter | frame (ms) |{part} max error | 95th pct error |",
           "|---|---|---|" + ("---|" if baseline is not None else "") + "---|---|"]
    for method, label in (("analytic", "segments"), ("march", "steps")):
        for m in rows[method]:
            cell = f" {(m['seconds'] - baseline) * 1e3:.1f} |" if baseline is not None else ""
            out.append(f"| {method} | {label} {m['param']} | {m['seconds'] * 1e3:.1f} |{cell} "
                       f"{m['error']:.2e} | {m['error95']:.2e} |")
    return out


def write_outputs(lines: list[str], results: dict, scenes, backends, out: Path | None,
                  plot: Path | None) -> None:
    """The table as text, and the time-against-error plot (one panel a scene) with its data."""
    if out:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    if not plot:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4), sharey=True)
    for ax, name in zip(np.atleast_1d(axes), scenes):
        for backend, style in zip(backends, ("-", "--")):
            data = results[name][backend]
            for method, marker in (("analytic", "o"), ("march", "s")):
                pts = sorted((m["error"], m["seconds"]) for m in data[method])
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, marker=marker,
                          label=f"{method} ({backend})")
        ax.axvline(0.01, color="grey", lw=0.5)
        ax.set_title(name)
        ax.set_xlabel("max relative error")
    np.atleast_1d(axes)[0].set_ylabel("frame time (s)")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    fig.tight_layout()
    plot.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(plot, dpi=90)
    plot.with_suffix(".json").write_text(json.dumps(results, indent=1), encoding="utf-8")


def sweep_arguments(doc: str | None, height: int, segments: list[int]) -> argparse.Namespace:
    """The command line shared by the daytime and rainbow benchmarks."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=height)
    ap.add_argument("--samples", type=int, default=120)
    ap.add_argument("--segments", type=int, nargs="+", default=segments)
    ap.add_argument("--steps", type=int, nargs="+", default=[16, 64, 256, 1024, 4096])
    ap.add_argument("--gl-max-steps", type=int, default=1024)
    ap.add_argument("--backends", nargs="+", default=["cpu", "gl"])
    ap.add_argument("--out", type=Path)
    ap.add_argument("--plot", type=Path)
    return ap.parse_args()


def main() -> None:
    args = sweep_arguments(__doc__, 180, [2, 4, 8, 16, 32, 64])
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    backends = [b for b in args.backends if b in airlight.available_backends()]
    rng = np.random.default_rng(6)
    results: dict = {}
    say(f"# Daytime scattering volumes against ray marching ({args.width}x{args.height}, "
        f"{args.samples} sampled pixels, 2 cores, GL = llvmpipe)")
    for name in SCENES:
        scene = open_fields(name, args.width, args.height)
        tilt = math.tan(math.radians(5.0)) / math.tan(math.radians(30.0))
        horizon = int(round(args.height / 2 * (1.0 + tilt)))
        pixels = sample_pixels(args.width, args.height, args.samples, horizon, rng)
        t0 = time.perf_counter()
        expected = reference_values(scene, pixels)
        say(f"\n## {name}: {json.dumps(scene['atmosphere'])}\n")
        say(f"reference: {len(pixels)} pixels in {time.perf_counter() - t0:.1f} s")
        for backend in backends:
            with airlight.Renderer(backend) as r:
                r.render(scene)  # warm-up: shader variant and sky table
                bare = copy.deepcopy(scene)
                bare.pop("atmosphere")
                t_bare, _ = timed(r, bare)
                rows = sweep(r, scene, pixels, expected, args.segments, args.steps, args.gl_max_steps)
            results.setdefault(name, {})[backend] = {"no_atmosphere_seconds": t_bare, **rows}
            say(f"\n### {backend}: frame without the atmosphere {t_bare * 1e3:.1f} ms\n")
            for line in sweep_table(rows, t_bare):
                say(line)
            ups = ", ".join(f"{t:.1%}: {speedup(rows['analytic'], rows['march'], t)}" for t in TARGETS)
            say(f"\nspeed-up of the scattering volumes over marching at equal error (whole frames): {ups}")
            part, part_m = ([{"error": m["error"], "seconds": max(m["seconds"] - t_bare, 1e-4)}
                             for m in rows[k]] for k in ("analytic", "march"))
            ups = ", ".join(f"{t:.1%}: {speedup(part, part_m, t)}" for t in TARGETS)
            say(f"the same on the atmosphere's part alone: {ups}")
    stats = airlight.table_stats().get("sky_phase")
    if stats:
        say(f"\nsky table: {stats['builds']} builds in this run, the last {stats['width']}x{stats['height']} "
            f"RGBA ({stats['bytes'] / 2**20:.1f} MiB) in {stats['build_seconds']:.3f} s")
    write_outputs(lines, results, SCENES, backends, args.out, args.plot)

if __name__ == "__main__":
    main()
