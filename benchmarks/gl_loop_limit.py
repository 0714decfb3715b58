"""Measures the GL driver's loop limit through airlight: the fewest point lamps at which
the GL backend's pixels start falling back to the CPU (Renderer.cpu_fallback_pixels > 0),
on a scene without surfaces, where a pixel runs three loop iterations per lamp (the lamp
cores, the airlight and the sub-pixel cores loops of shaders/shading.glsl).

    .venv/bin/python benchmarks/gl_loop_limit.py

On Mesa's llvmpipe (22.3) this finds 21844 lamps: 3 x 21844 iterations plus the 2 of
render.frag's guard loop reach 65534, and the guard's loop is cut: the loop limiter of
llvmpipe's shader compiler, 65535 iterations counted over all the loops of an invocation.
On a GPU driver no fallback happens up to the largest count tried.
"""

from __future__ import annotations

import argparse

import airlight


def scene(lamps: int) -> dict:
    # Lamps in a row far behind the camera: invisible, so each costs the same loop iterations.
    lights = [{"type": "point", "position": [0.01 * i, 0, 50], "intensity": 1} for i in range(lamps)]
    return {"film": {"width": 4, "height": 4},
            "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 60},
            "medium": {"sigma_t": 0.01, "albedo": 0.9}, "lights": lights}


def falls_back(renderer: airlight.Renderer, lamps: int) -> bool:
    renderer.render(scene(lamps))
    return renderer.cpu_fallback_pixels > 0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--max-lamps", type=int, default=100000)
    args = ap.parse_args()
    renderer = airlight.Renderer("gl")
    if not falls_back(renderer, args.max_lamps):
        print(f"no fallback up to {args.max_lamps} lamps: this driver has no loop limit below that")
        return
    lo, hi = 1, args.max_lamps  # lo: no fallback, hi: fallback
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if falls_back(renderer, mid) else (mid, hi)
    print(f"fallback from {hi} lamps (none at {lo}): the guard loop is cut after "
          f"{3 * hi} + 2 = {3 * hi + 2} loop iterations of an invocation")


if __name__ == "__main__":
    main()
