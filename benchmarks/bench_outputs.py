"""What the render outputs cost (issue 19): frame time of the radiance alone against the
radiance with every output (depth, distance_z, normal, transmittance and the layers),
both backends, on the same presets, frames interleaved (radiance, outputs, radiance, ...)
so that the machine's load hits both alike; the median of the paired ratios.

    .venv/bin/python benchmarks/bench_outputs.py [--frames 7] [--width 320] [--scenes default day_clear ...]

That a frame asking for the radiance alone pays nothing is shown against the checkout
before the outputs existed, with benchmarks/compare_frames.py (README "Render outputs").
Absolute times on a shared 2-core machine are noisy; read the ratios.
"""

from __future__ import annotations

import argparse
import statistics
import time

import airlight

SCENES = ["default", "foggy_street", "day_clear", "rainbow_after_heavy_rain", "spotlights_crossing_002"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=7)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    ap.add_argument("--backends", nargs="+", default=airlight.available_backends())
    args = ap.parse_args()
    outputs = list(airlight.OUTPUTS)
    print(f"{'scene':28} {'backend':7} {'radiance ms':>12} {'all outputs ms':>15} {'outputs/radiance':>17}"
          f"   (medians of {args.frames} interleaved pairs, width {args.width})")
    for name in args.scenes:
        scene = airlight.preset(name)
        for backend in args.backends:
            with airlight.Renderer(backend) as r:
                r.render(scene, width=args.width)  # set-up: context, shader variants, tables
                r.render(scene, width=args.width, outputs=outputs)
                plain, full = [], []
                for _ in range(args.frames):
                    t0 = time.perf_counter()
                    r.render(scene, width=args.width)
                    t1 = time.perf_counter()
                    r.render(scene, width=args.width, outputs=outputs)
                    t2 = time.perf_counter()
                    plain.append(t1 - t0)
                    full.append(t2 - t1)
            ratio = statistics.median(f / p for p, f in zip(plain, full))
            print(f"{name:28} {backend:7} {1e3 * statistics.median(plain):12.1f} "
                  f"{1e3 * statistics.median(full):15.1f} {ratio:17.3f}", flush=True)


if __name__ == "__main__":
    main()
