"""Where a lamp-pixel's time goes: the lamp airlight kernel's cost per lamp and pixel on both
backends, and (with ``--perf``) the CPU backend's profile by function.

    .venv/bin/python effects/lamp_airlight/bench/profile_lamp_kernel.py [--width 640 --height 360]
        [--frames 5] [--perf] [--out effects/lamp_airlight/docs/profile_lamp_kernel.txt]

The scene is `foggy_street`'s 16 point lamps in its fog (sigma_t 0.04/m, isotropic, grey) with
no surfaces, so that every camera ray escapes and each lamp-pixel is one closed-form tail of the
airlight integral (effects/lamp_airlight/physics.md); culling off (`quality.cull_fraction` 0),
so that every lamp is evaluated in every pixel; multiple scattering off. A lamp-pixel's time is
(frame with the lamps - frame without) / (pixels x lamps), in the process's CPU seconds (all its
threads: the CPU backend's and llvmpipe's), the median of `--frames` frames after a warm one. The
CPU backend is timed with one thread and with all; GL is Mesa's llvmpipe here (the same cores).

``--perf`` records the one-thread CPU frames with Linux `perf` (when it is installed and allowed)
and prints the functions with the largest shares of the samples.
"""

from __future__ import annotations

import argparse
import copy
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import airlight


def kernel_scene(width: int, height: int, lamps: bool) -> dict[str, Any]:
    scene = copy.deepcopy(airlight.preset("foggy_street"))
    scene["film"] = {"width": width, "height": height}
    scene["surfaces"] = []
    scene["lights"] = [light for light in scene["lights"] if light["type"] == "point"] if lamps else []
    scene["quality"] = {**scene.get("quality", {}), "cull_fraction": 0.0, "multiple_scattering": False}
    return scene


def frame_seconds(backend: str, threads: int, scene: dict[str, Any], frames: int) -> tuple[float, float]:
    """Median CPU seconds of the process and wall seconds per frame, after one warm frame."""
    renderer = airlight.Renderer(backend, cpu_threads=threads)
    renderer.render(scene)
    cpu, wall = [], []
    for _ in range(frames):
        start, start_wall = time.process_time(), time.perf_counter()
        renderer.render(scene)
        cpu.append(time.process_time() - start)
        wall.append(time.perf_counter() - start_wall)
    renderer.close()
    return statistics.median(cpu), statistics.median(wall)


def perf_profile(args: argparse.Namespace, top: int = 15) -> list[str]:
    """The one-thread CPU frames under `perf record`; the `top` functions by share of samples."""
    if shutil.which("perf") is None:
        return ["perf: not installed (Debian: apt-get install linux-perf)"]
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "perf.data"
        command = [sys.executable, __file__, "--inner", "--width", str(args.width), "--height",
                   str(args.height), "--frames", str(args.frames)]
        record = subprocess.run(["perf", "record", "-F", "999", "-o", str(data), "--", *command],
                                capture_output=True, text=True)
        if record.returncode != 0:
            return [f"perf record failed: {record.stderr.strip().splitlines()[-1:]}"]
        report = subprocess.run(["perf", "report", "-i", str(data), "--no-children", "--sort", "symbol",
                                 "--stdio"], capture_output=True, text=True)
    rows = [line.strip() for line in report.stdout.splitlines() if "%" in line and not line.startswith("#")]
    # A row: share, [.] or [k], the symbol, then "-" columns perf leaves empty.
    return [f"| {row.split()[0]} | `{' '.join(row.split()[2:]).rstrip(' -')}` |" for row in rows[:top]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--perf", action="store_true", help="profile the one-thread CPU frames with perf")
    parser.add_argument("--out", type=Path, help="also write the report to this file")
    parser.add_argument("--inner", action="store_true", help=argparse.SUPPRESS)  # the process perf records
    args = parser.parse_args()
    with_lamps = kernel_scene(args.width, args.height, True)
    if args.inner:
        frame_seconds("cpu", 1, with_lamps, args.frames)
        return
    without = kernel_scene(args.width, args.height, False)
    lamp_pixels = args.width * args.height * len(with_lamps["lights"])
    lines = [
        "# The lamp airlight kernel: time per lamp-pixel",
        "",
        "`.venv/bin/python effects/lamp_airlight/bench/profile_lamp_kernel.py"
        + (" --perf" if args.perf else "")
        + (f" --out {args.out}" if args.out else "") + "`",
        "",
        f"Machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}; "
        f"GL: {airlight.backend_info().get('gl_renderer') or 'unavailable'}.",
        f"Scene: foggy_street's {len(with_lamps['lights'])} point lamps, no surfaces, culling off, "
        f"{args.width}x{args.height}; median CPU seconds of {args.frames} frames after a warm one.",
        "",
        "| backend | threads | frame with lamps (CPU s) | without (CPU s) | ns per lamp-pixel (CPU time) "
        "| ns per lamp-pixel (wall) |",
        "|---|---|---|---|---|---|",
    ]
    runs = [("cpu", 1), ("cpu", 0)] + ([("gl", 0)] if "gl" in airlight.available_backends() else [])
    for backend, threads in runs:
        lit, lit_wall = frame_seconds(backend, threads, with_lamps, args.frames)
        dark, dark_wall = frame_seconds(backend, threads, without, args.frames)
        per = 1e9 * (lit - dark) / lamp_pixels
        per_wall = 1e9 * (lit_wall - dark_wall) / lamp_pixels
        lines.append(f"| {backend} | {threads or 'all'} | {lit:.3f} | {dark:.3f} | {per:.1f} "
                     f"| {per_wall:.1f} |")
        print(lines[-1], flush=True)
    if args.perf:
        lines += ["", "CPU backend, one thread, share of perf samples by function (the whole process, "
                  "warm-up and Python included):", "", "| share | function |", "|---|---|"]
        lines += perf_profile(args)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
