"""How fast the sun's shadow map converges to the shadow rays, on the test scene of
effects/sun_shadow_map/tests (boxes, a thin slab and a sphere on a ground plane), both backends.

    .venv/bin/python effects/sun_shadow_map/bench/map_convergence.py [--sizes 64 256 1024 4096]

Prints, per backend and map size, the fraction of pixels whose radiance differs from the shadow
rays' image by more than 2 %, and the GL/CPU disagreement at 512 texels.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import airlight

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_sun_shadow_map import SCENE, differing_fraction, with_map  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[64, 256, 1024, 4096])
    args = ap.parse_args()
    backends = airlight.available_backends()
    print(f"{'backend':8} " + " ".join(f"{f'N={n}':>9}" for n in args.sizes) + "   (pixels off by > 2 %)")
    for b in backends:
        with airlight.Renderer(b) as r:
            ref = r.render(SCENE)
            fracs = [differing_fraction(r.render(with_map(n)), ref) for n in args.sizes]
        print(f"{b:8} " + " ".join(f"{100 * f:8.3f}%" for f in fracs))
    if {"cpu", "gl"} <= set(backends):
        cpu, gl = airlight.render(with_map(512), backend="cpu"), airlight.render(with_map(512), backend="gl")
        off = 100 * differing_fraction(cpu, gl, tol=1e-3)
        print(f"gl vs cpu at N=512: {off:.3f}% of pixels off by > 0.1 %, "
              f"largest difference {float(np.abs(cpu - gl).max()):.2e}")


if __name__ == "__main__":
    main()
