"""Display-stage time (issue 8): exposure, the eye's glare, tone curve and sRGB,
on both backends, at 640x360 and 1920x1080, with and without glare.

    .venv/bin/python effects/display/bench/bench_display.py [--repeats 3] [--out
    effects/display/docs/bench_display.txt]

Scenes: ``foggy_street`` (street lamps in view: bright sources) and
``dense_fog_lamps_behind``, the same street in denser fog (sigma_t 0.15/m)
with its lamps moved behind the camera: the fog they light fills the view,
smooth, with no lamp core and only faint building edges (a scene without
bright sources).
Each radiance image is rendered once on the CPU; then each backend's display
stage runs ``--repeats`` times after one warm-up call (which builds the glare
kernel and, on GL, compiles the programs and caches the kernel's spectrum) and
the median is printed, with the glare method the run chose ("skipped",
"sparse": splats on the CPU, on either backend; "fft" on the CPU, "gl-fft" on
GL), the number of pixels above their tile's threshold (whose excess is
spread exactly; the FFT convolves the whole image) and the kernel's radius (``display_report``,
effects/display/docs/glare.md: what is not spread moves no 8-bit value by more than one
step). Times are wall-clock on whatever machine runs it (llvmpipe for GL
without a GPU): compare ratios.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

SIZES = ((640, 360), (1920, 1080))
GLARE = {"pupil_diameter": 4.0, "eyelashes": True}


def scenes() -> dict[str, dict[str, Any]]:
    street = airlight.preset("foggy_street")
    behind = airlight.preset("foggy_street")
    behind["medium"]["sigma_t"] = 0.15
    for light in behind["lights"]:
        light["position"][2] = 6.0 + abs(light["position"][2]) * 0.1  # behind the camera (it looks down -z)
    return {"foggy_street": street, "dense_fog_lamps_behind": behind}


def time_display(radiance: np.ndarray, fov: float, glare: Any, renderer: airlight.Renderer | None,
                 repeats: int) -> tuple[float, dict[str, Any]]:
    airlight.display_report(radiance, glare=glare, fov_y=fov, renderer=renderer)  # warm-up
    times, report = [], {}
    for _ in range(repeats):
        t0 = time.perf_counter()
        _, report = airlight.display_report(radiance, glare=glare, fov_y=fov, renderer=renderer)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=None, help="also write the table to this file")
    args = parser.parse_args()
    backends = airlight.available_backends()
    renderers = {b: airlight.Renderer(b) for b in backends}
    lines = [f"display stage, median of {args.repeats} runs (tone curve loglog, auto exposure; "
             f"glare: pupil {GLARE['pupil_diameter']} mm with eyelashes)",
             f"{'scene':27} {'size':>9} {'backend':7} {'no glare ms':>11} {'glare ms':>9} "
             f"{'method':>8} {'spread px':>10} {'kernel r':>8}"]
    print("\n".join(lines), flush=True)
    for name, scene in scenes().items():
        for width, height in SIZES:
            radiance = renderers["cpu"].render(scene, width=width, height=height)
            fov = float(scene["camera"]["fov_y"])
            for backend in backends:
                renderer = renderers[backend] if backend == "gl" else None
                plain, _ = time_display(radiance, fov, None, renderer, args.repeats)
                glared, report = time_display(radiance, fov, GLARE, renderer, args.repeats)
                line = (f"{name:27} {width:>4}x{height:<4} {backend:7} {1e3 * plain:11.1f} "
                        f"{1e3 * glared:9.1f} {report['glare']:>8} {report['glare_sources']:10d} "
                        f"{report['glare_kernel_radius']:8d}")
                lines.append(line)
                print(line, flush=True)
    if "gl" not in backends:
        lines.append(f"gl: skipped ({airlight.gl_unavailable_reason()})")
        print(lines[-1])
    if args.out is not None:
        args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
