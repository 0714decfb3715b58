"""A day of changing weather over the town of the daytime presets (issue 6).

    .venv/bin/python examples/rain_day.py [--frames 12] [--out out/rain_day] [--backend auto]

The rain thickens from 0.5 to 50 mm/h and the haze with it, under the overcast
sky; each frame edits the scene dict and renders with one Renderer. The sky table
depends on the sky and the particles' phase functions, not on their densities,
so it is built once for the whole sequence (table_stats() shows one build). Each
frame is shown through the display stage with the scene's settings (automatic
exposure, filmic curve) and written as a PNG.
"""

from __future__ import annotations

import argparse
import copy
import time
from pathlib import Path

from PIL import Image

import airlight


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--out", default="out/rain_day")
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=180)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    town = airlight.preset("day_light_rain")
    with airlight.Renderer(args.backend) as r:
        for k in range(args.frames):
            f = k / max(args.frames - 1, 1)
            scene = copy.deepcopy(town)
            scene["atmosphere"]["rain"] = {"rate": 0.5 + 49.5 * f}
            scene["atmosphere"]["aerosol"]["visibility"] = 20000.0 * (1.0 - f) + 2000.0 * f
            t0 = time.perf_counter()
            radiance = r.render(scene, width=args.width, height=args.height)
            image = airlight.display_scene(radiance, scene, renderer=r)
            Image.fromarray(image).save(out / f"frame_{k:03d}.png")
            print(f"frame {k}: rain {0.5 + 49.5 * f:4.1f} mm/h, {1e3 * (time.perf_counter() - t0):6.1f} ms")
    print(f"sky table builds: {airlight.table_stats()['sky_phase']['builds']}; frames in {out}/")


if __name__ == "__main__":
    main()
