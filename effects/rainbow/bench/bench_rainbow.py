"""Rainbows (issue 7): the tables' cost, render time with and without the rainbow term, and run
time against error versus brute-force ray marching, both backends, in one run.

    .venv/bin/python effects/rainbow/bench/bench_rainbow.py [--width 320 --height 200] [--samples 120]
        [--segments 4 8 16 32] [--steps 16 64 256 1024 4096] [--gl-max-steps 1024]
        [--out effects/rainbow/docs/bench_rainbow.txt] [--plot docs/images/bench_rainbow.png]

Scenes: the figure-7 presets (scenes/rainbow_after_heavy_rain.json, rainbow_after_light_rain.json)
over their ground plane only (so that every sampled pixel has an exact reference), the camera
looking at both bows.

Error: against the float64 reference of effects/daytime/tests/daytime_reference.py (view rays by
Gauss-Legendre on graded panels, the sky integral by a hemisphere rule), given the same rainbow
phase table (an input, like the scene: its own accuracy is tested in effects/rainbow/tests/test_rainbow.py
and measured in effects/rainbow/docs/rainbow.md); the largest relative error over sampled pixels (half
random, half
on the bows) above 1e-3 of the largest sampled value.

"Without the rainbow term": the same scene with "phase": "hg" (the rain scatters the sun with
Henyey-Greenstein g = 0.87 instead of the table): the integration is identical, so the difference
is the table lookup's cost. Time: median of 3 frames after a warm-up frame. Timings on a shared
2-core machine are noisy: compare ratios.
"""

from __future__ import annotations

import copy
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(ROOT / "tests" / "python"), *(str(d) for d in sorted(ROOT.glob("effects/*/tests")))]
sys.path.insert(0, str(ROOT / "effects" / "daytime" / "bench"))

import daytime_reference as ref  # noqa: E402
import reference  # noqa: E402
from bench_daytime import speedup, sweep, sweep_arguments, sweep_table, timed, write_outputs  # noqa: E402
from daytime_scenes import reference_atmosphere, reference_sky  # noqa: E402

SCENES = ("rainbow_after_heavy_rain", "rainbow_after_light_rain")
TARGETS = (0.01, 0.005)


def open_fields(name: str, width: int, height: int) -> dict:
    scene = airlight.preset(name)
    scene["surfaces"] = scene["surfaces"][:1]
    scene["film"] = {"width": width, "height": height}
    scene.pop("display", None)
    return scene


def sample_pixels(scene: dict, count: int, rng) -> list[tuple[int, int]]:
    """Half uniformly random pixels, half where the scattering angle is in 125-142 degrees."""
    w, h = scene["film"]["width"], scene["film"]["height"]
    _o, dirs = reference.camera_rays(scene["camera"], w, h)
    el, az = math.radians(scene["sun"]["elevation"]), math.radians(scene["sun"]["azimuth"])
    s = np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])
    angle = np.degrees(np.arccos(np.clip(dirs @ s, -1.0, 1.0)))
    bow = np.argwhere((angle > 125.0) & (angle < 142.0) & (dirs[..., 1] > 0.0))
    picks = set()
    while len(picks) < count // 2:
        picks.add((int(rng.integers(h)), int(rng.integers(w))))
    while len(picks) < count and len(bow):
        r, c = bow[rng.integers(len(bow))]
        picks.add((int(r), int(c)))
    return sorted(picks)


def reference_values(scene: dict, pixels) -> np.ndarray:
    atm, sky = reference_atmosphere(scene), reference_sky(scene)
    albedo = np.asarray(scene["surfaces"][0]["albedo"], dtype=float)
    y0 = float(scene["camera"]["position"][1])
    _o, dirs = reference.camera_rays(scene["camera"], scene["film"]["width"], scene["film"]["height"])
    out = []
    for row, col in pixels:
        d = dirs[row, col]
        if d[1] < 0.0:
            per = [ref.view_ray_gauss(atm, sky, y0, d, ground_albedo=float(a)) for a in albedo]
            out.append([per[c][c] for c in range(3)])
        else:
            out.append(ref.view_ray_gauss(atm, sky, y0, d))
    return np.asarray(out)


def main() -> None:
    args = sweep_arguments(__doc__, 200, [4, 8, 16, 32])
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    backends = [b for b in args.backends if b in airlight.available_backends()]
    spectral = airlight._core.rainbow_spectral_table()
    data_file = ROOT / "effects" / "rainbow" / "rainbow_phase.bin"
    say(f"# Rainbows: tables, the rainbow term's cost, and scattering volumes against ray marching "
        f"({args.width}x{args.height}, {args.samples} sampled pixels, 2 cores, GL = llvmpipe)\n")
    say(f"spectral table (embedded, computed once by build/cpp/make_rainbow_table): "
        f"{len(spectral['rates'])} rates x {len(spectral['wavelengths_nm'])} wavelengths x "
        f"{len(spectral['angles_deg'])} angles, {spectral['samples_per_wavelength']} samples per wavelength, "
        f"{data_file.stat().st_size / 2**20:.2f} MiB "
        "(generation time: effects/rainbow/docs/rainbow_table.txt)")
    t0 = time.perf_counter()
    for rate in (0.3, 3.0, 30.0, 300.0):
        airlight.rainbow_phase(rate)
    per_table = (time.perf_counter() - t0) / 4
    say(f"renderer's RGB table per scene (interpolation in rate, 33 wavelengths to sRGB, 3601 texels, "
        f"{3601 * 16 / 1024:.0f} KiB): {per_table * 1e3:.2f} ms\n")
    rng = np.random.default_rng(7)
    results: dict = {}
    for name in SCENES:
        scene = open_fields(name, args.width, args.height)
        pixels = sample_pixels(scene, args.samples, rng)
        t0 = time.perf_counter()
        expected = reference_values(scene, pixels)
        say(f"\n## {name}: {json.dumps(scene['atmosphere']['rain'])}\n")
        say(f"reference: {len(pixels)} pixels in {time.perf_counter() - t0:.1f} s")
        for backend in backends:
            with airlight.Renderer(backend) as r:
                r.render(scene)
                hg = copy.deepcopy(scene)
                hg["atmosphere"]["rain"]["phase"] = "hg"
                r.render(hg)
                t_mie, _ = timed(r, scene)
                t_hg, _ = timed(r, hg)
                rows = sweep(r, scene, pixels, expected, args.segments, args.steps, args.gl_max_steps)
            results.setdefault(name, {})[backend] = {"rainbow_seconds": t_mie, "hg_seconds": t_hg, **rows}
            say(f"\n### {backend}: frame with the rainbow term {t_mie * 1e3:.1f} ms, without (HG rain) "
                f"{t_hg * 1e3:.1f} ms (ratio {t_mie / t_hg:.2f})\n")
            for line in sweep_table(rows):
                say(line)
            ups = ", ".join(f"{t:.1%}: {speedup(rows['analytic'], rows['march'], t)}" for t in TARGETS)
            say(f"\nspeed-up of the scattering volumes over marching at equal error: {ups}")
    write_outputs(lines, results, SCENES, backends, args.out, args.plot)

if __name__ == "__main__":
    main()
