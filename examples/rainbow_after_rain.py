"""The end of a shower, scripted from Python (issue 7): the bow appears and fades.

    .venv/bin/python examples/rainbow_after_rain.py [--frames 12] [--out out/rainbow] [--backend auto]
        [--fading-rain-steps N]

The preset "after heavy rain" (50 mm/h drops) with the drop density falling
100-fold over the frames, evenly in log: the rain keeps its drop sizes while
fewer and fewer drops remain, so the bow keeps its shape and fades
(`density_scale`; the rainbow table depends on the rate only and is built once:
table_stats() shows one build). The daytime multiple-scattering field depends on the
drop density, so it is solved for every frame; with --fading-rain-steps N it is solved
on a ladder of N rain extinctions per halving and blended between them
(`quality.fading_rain_steps`; effects/multiple_scattering/physics.md eq. 9.3), which
saves solves when the sequence has more than N frames per halving of the drops (the
100-fold fade crosses 6.6 halvings: --frames 120 --fading-rain-steps 4 solves about 28
times instead of 120). One exposure, the full scene's, for every
frame, so the fading shows. airlight-demo --sequence rain-ends does the same,
with the sun coming out as well.
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
    ap.add_argument("--out", default="out/rainbow")
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=200)
    ap.add_argument("--fading-rain-steps", type=int, default=0)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    shower = airlight.preset("rainbow_after_heavy_rain")
    density = shower["atmosphere"]["rain"]["density_scale"]
    with airlight.Renderer(args.backend) as r:
        first = r.render(shower, width=args.width, height=args.height)
        exposure = airlight.auto_exposure(first)
        for k in range(args.frames):
            f = k / max(args.frames - 1, 1)
            scene = copy.deepcopy(shower)
            scene["atmosphere"]["rain"]["density_scale"] = drops = density * 0.01**f
            scene.setdefault("quality", {})["fading_rain_steps"] = args.fading_rain_steps
            t0 = time.perf_counter()
            radiance = r.render(scene, width=args.width, height=args.height)
            image = airlight.display(radiance, exposure=exposure, tonemap="filmic")
            Image.fromarray(image).save(out / f"frame_{k:03d}.png")
            print(f"frame {k}: drop density x{drops:.5f}, {1e3 * (time.perf_counter() - t0):6.1f} ms")
    stats = airlight.table_stats()
    print(f"rainbow table builds: {stats['rainbow_phase']['builds']}, multiple-scattering solves: "
          f"{stats.get('ms_field', {}).get('builds', 0)}; frames in {out}/")


if __name__ == "__main__":
    main()
