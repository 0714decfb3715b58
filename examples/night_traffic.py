"""A scripted animation: cars with headlights driving along a foggy street.

    .venv/bin/python examples/night_traffic.py [--frames 24] [--out out/traffic] [--backend auto]

Each frame moves two cars (airlight.headlights places each car's pair of spots)
and renders with one Renderer, which keeps its GL context, compiled shaders and
tables, so only the first frame pays the set-up. Writes PNG frames.
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

import airlight


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=24)
    ap.add_argument("--out", default="out/traffic")
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=180)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    street = airlight.preset("foggy_street")
    street["film"] = {"width": args.width, "height": args.height}
    with airlight.Renderer(args.backend) as renderer:
        for frame in range(args.frames):
            scene = copy.deepcopy(street)
            t = frame / max(args.frames - 1, 1)
            # An oncoming car in the left lane, a car driving away in the right lane.
            scene["lights"] += airlight.headlights([-1.8, 0.0, -120.0 + 100.0 * t], 180.0, lens_lamps=True)
            scene["lights"] += airlight.headlights([1.8, 0.0, -10.0 - 60.0 * t], 0.0)
            start = time.perf_counter()
            radiance = renderer.render(scene)
            airlight.save_png(out / f"frame_{frame:03d}.png", radiance, exposure=0.1)
            print(f"frame {frame}: {1e3 * (time.perf_counter() - start):.0f} ms ({renderer.backend})")


if __name__ == "__main__":
    main()
