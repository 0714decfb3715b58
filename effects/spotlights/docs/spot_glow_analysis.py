"""Error and cost of the spots' surface glow against its quadrature resolution
(effects/spotlights/docs/spot_table.md section 9), measured on the renderer itself:

    .venv/bin/python effects/spotlights/docs/spot_glow_analysis.py [--backend cpu] [--samples 4 8 12 16 24] [--parts 1 2 3 4 5]

1. Convergence: road scenes lit by one spot (street lamp, headlight, spot by the
   from above: CASES below), rendered at each
   quality.spot_glow_samples; error = max relative error of the whole pixel
   (direct light + glow + airlight; pixels above 1e-3 of the image maximum)
   against the same scene at 64 samples, and the frame time.
2. An independent identity: two opposite 90-degree spots with q = 1 are one
   isotropic point lamp, whose glow comes from the point lamps' G table
   (effects/lamp_airlight/docs/airlight_table.md, built by another method): max relative pixel error of
   the two-spot image against the point-lamp image, lamp cores excluded.

3. Frame cost of the glow in the spot presets (320x180, both backends where
   available): as shipped, with spot_glow_samples 8, and with black surfaces
   (which skips all surface lighting, so the difference is the lighting).

4. The glow alone, per spot (what the surface culling's coarse rule rests on,
   effects/lamp_airlight/docs/culling.md): the glow at n samples against 64,
   max relative error over the road pixels of each case where the glow is
   above 1e-6 of its largest and above 1e-3 of the road's own radiance
   (below that, the glow is measured as a difference of renders and float32
   rounding of the direct light hides it). The glow is separated from the
   direct light by rendering the road grey and black, with the medium's
   albedo 0.9 and 0 (sigma_t unchanged: only the glow and airlight change).

5. The 64-headlight street of effects/lamp_airlight/bench/bench_airlight.py over a grey
   road and buildings (albedo 0.3), 160x90: frame time with the default culling and
   with culling off, and the largest relative change culling makes, on each backend;
   the spots' glows are most of this frame.

Timings are whole frames on a shared machine: compare ratios.
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

CASES: list[tuple[str, dict[str, Any]]] = [
    ("spot 5 m up, 30 deg, tilted", {}),
    ("spot 80 deg, q 1", {"cone": 80, "q": 1}),
    ("spot 90 deg, q 0.5", {"cone": 90, "q": 0.5}),
    ("spot 0.1 m above the road", {"pos": (0, 0.1, -4)}),
    ("spot 0.01 m above the road, r 0.005", {"pos": (0, 0.01, -4), "radius": 0.005}),
    ("headlight 0.65 m, 20 deg", {"pos": (0, 0.65, 0), "direction": (0, -0.05, -1), "cone": 20, "q": 0.2}),
    ("headlight, sigma 0.3", {"pos": (0, 0.65, 0), "direction": (0, -0.05, -1), "cone": 20, "q": 0.2,
                              "sigma": 0.3}),
    ("street lamp spot 6 m, 35 deg", {"pos": (0, 6, -10), "direction": (0, -1, 0), "cone": 35, "q": 0.3}),
    ("spot across the road, 10 deg", {"pos": (2, 1, -3), "direction": (-1, 0, 0), "cone": 10, "q": 0}),
    ("spot below the road, up", {"pos": (0, -1, -4), "direction": (0, 1, 0), "cone": 40}),
    ("thin fog 0.001", {"sigma": 0.001}),
    ("thick fog 2", {"sigma": 2.0}),
]


def road_scene(samples: int, sigma: float = 0.04, cone: float = 30, q: float = 0.0,
               pos: tuple[float, ...] = (0, 5, -4), direction: tuple[float, ...] = (0.3, -1, 0.2),
               radius: float = 0.05) -> dict:
    return {"film": {"width": 160, "height": 120},
            "camera": {"position": [0, 1.6, 8], "look_at": [0, 0, -5], "up": [0, 1, 0], "fov_y": 60},
            "medium": {"sigma_t": sigma, "albedo": 0.9},
            "lights": [{"type": "spot", "position": list(pos), "direction": list(direction),
                        "intensity": 1000, "cone_angle": cone, "edge": q, "radius": radius}],
            "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.5}],
            "quality": {"spot_glow_samples": samples}}


def max_rel(image: np.ndarray, ref: np.ndarray, exclude: np.ndarray | None = None) -> float:
    mask = ref > 1e-3 * (ref[~exclude].max() if exclude is not None else ref.max())
    if exclude is not None:
        mask &= ~exclude
    return float(np.max(np.abs(image[mask] / ref[mask] - 1.0)))


def timed(renderer: airlight.Renderer, scene: dict) -> tuple[float, np.ndarray]:
    image = renderer.render(scene)
    best = float("inf")
    for _ in range(2):
        t0 = time.perf_counter()
        image = renderer.render(scene)
        best = min(best, time.perf_counter() - t0)
    return best, image


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--samples", type=int, nargs="+", default=[4, 8, 12, 16, 24])
    ap.add_argument("--parts", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    args = ap.parse_args()
    renderer = airlight.Renderer(args.backend)
    if 1 in args.parts:
        convergence(renderer, args)
    if 2 in args.parts:
        two_spots_are_a_lamp(renderer, args)
    if 3 in args.parts:
        preset_frame_cost()
    if 4 in args.parts:
        glow_alone(renderer, args)
    if 5 in args.parts:
        grey_headlight_street()


def convergence(renderer: airlight.Renderer, args: argparse.Namespace) -> None:
    print(f"1. max relative pixel error against 64 samples, and frame time ({args.backend}, 160x120)")
    print(f"  {'case':32} " + " ".join(f"{'n=' + str(n):>17}" for n in args.samples))
    worst = {n: 0.0 for n in args.samples}
    for name, kw in CASES:
        ref = renderer.render(road_scene(64, **kw))
        cells = []
        for n in args.samples:
            t, img = timed(renderer, road_scene(n, **kw))
            err = max_rel(img, ref)
            worst[n] = max(worst[n], err)
            cells.append(f"{err:8.1e} {1e3 * t:5.0f} ms")
        print(f"  {name:32} " + " ".join(f"{c:>17}" for c in cells))
    print(f"  {'worst':32} " + " ".join(f"{worst[n]:8.1e}{'':9}" for n in args.samples))


def two_spots_are_a_lamp(renderer: airlight.Renderer, args: argparse.Namespace) -> None:
    print("\n2. two opposite 90-degree spots (q = 1) against one point lamp (G table): "
          "max relative pixel error")
    for sigma in (0.001, 0.04, 0.3, 1.5):
        for position in ([1, 3, -4], [1, 0.05, -4], [0, 8, -20]):
            cells = []
            for n in args.samples:
                base = road_scene(n, sigma=sigma)
                wall = {"type": "plane", "point": [-6, 0, 0], "normal": [1, 0, 0], "albedo": 0.5}
                base["surfaces"].append(wall)
                lamp = dict(base, lights=[{"type": "point", "position": position, "intensity": 1000}])
                pair = dict(base, lights=[{"type": "spot", "position": position, "direction": d,
                                           "intensity": 1000, "cone_angle": 90, "edge": 1}
                                          for d in ([0.2, 1, 0.1], [-0.2, -1, -0.1])])
                a, b = renderer.render(lamp), renderer.render(pair)
                # The lamp's core and its rim pixels (the two spheres coincide; which spot's
                # core is seen there is arbitrary), found in clear air.
                core = np.zeros(a.shape, bool)
                clear = renderer.render({k: v for k, v in lamp.items() if k != "medium"})
                ys, xs = np.nonzero(clear[..., 0] > 1e3)
                for y, x in zip(ys, xs):
                    core[max(y - 1, 0):y + 2, max(x - 1, 0):x + 2] = True
                cells.append(f"n={n}: {max_rel(b, a, core):.1e}")
            print(f"  sigma_t {sigma:<6} lamp at {str(position):14} " + "  ".join(cells))


def preset_frame_cost() -> None:
    print("\n3. frame time of the spot presets at 320x180: as shipped | spot_glow_samples 8 | black surfaces")
    for backend in airlight.available_backends():
        frame_renderer = airlight.Renderer(backend)
        for name in ("spotlights_crossing_004", "crane_searchlight"):
            shipped = airlight.preset(name)
            shipped["film"] = {"width": 320, "height": 180}
            fewer = copy.deepcopy(shipped)
            fewer["quality"] = dict(shipped.get("quality", {}), spot_glow_samples=8)
            black = copy.deepcopy(shipped)
            for surface in black["surfaces"]:
                surface["albedo"] = 0.0
            times = [1e3 * timed(frame_renderer, sc)[0] for sc in (shipped, fewer, black)]
            print(f"  {backend:4} {name:24} " + " | ".join(f"{t:6.0f} ms" for t in times))


def road_glow(renderer: airlight.Renderer, scene: dict) -> tuple[np.ndarray, np.ndarray]:
    """The road's glow and its own radiance (direct light + glow, times the transmittance) in
    `scene` with culling off, from four renders (road grey and black, medium albedo 0.9 and 0)."""
    def road_term(medium_albedo: float) -> np.ndarray:
        grey = copy.deepcopy(scene)
        grey["medium"]["albedo"] = medium_albedo
        grey["quality"]["cull_fraction"] = 0.0
        black = copy.deepcopy(grey)
        for surface in black["surfaces"]:
            surface["albedo"] = 0.0
        return (np.asarray(renderer.render(grey), np.float64) - np.asarray(renderer.render(black), np.float64))
    lit = road_term(0.9)
    return lit - road_term(0.0), lit


def glow_alone(renderer: airlight.Renderer, args: argparse.Namespace) -> None:
    print(f"\n4. the glow alone: max relative error against 64 samples ({args.backend}, 160x120)")
    print(f"  {'case':36} " + " ".join(f"{'n=' + str(n):>9}" for n in args.samples) + "   pixels")
    worst = {n: 0.0 for n in args.samples}
    for name, kw in CASES:
        ref, road = road_glow(renderer, road_scene(64, **kw))
        mask = (ref > 1e-6 * ref.max()) & (ref > 1e-3 * road)
        cells = []
        for n in args.samples:
            glow, _ = road_glow(renderer, road_scene(n, **kw))
            err = float(np.max(np.abs(glow[mask] / ref[mask] - 1.0)))
            worst[n] = max(worst[n], err)
            cells.append(f"{err:9.1e}")
        print(f"  {name:36} " + " ".join(cells) + f"   {int(mask.sum()):6d}")
    print(f"  {'worst':36} " + " ".join(f"{worst[n]:9.1e}" for n in args.samples))


def grey_headlight_street() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
    from effects.lamp_airlight.bench.bench_airlight import street_scene

    scene = street_scene(64, 160, 90, surface_albedo=0.3, light_type="headlights")
    print("\n5. 64 headlights over a grey street, 160x90: frame time culled (default) | unculled, "
          "largest relative change")
    for backend in airlight.available_backends():
        frame_renderer = airlight.Renderer(backend)
        unculled = copy.deepcopy(scene)
        unculled["quality"] = {"cull_fraction": 0.0}
        t_culled, culled_image = timed(frame_renderer, scene)
        t_unculled, unculled_image = timed(frame_renderer, unculled)
        change = float(np.max(np.abs(culled_image - unculled_image) / np.maximum(unculled_image, 1e-30)))
        print(f"  {backend:4} {t_culled:7.2f} s | {t_unculled:7.2f} s ({t_unculled / t_culled:4.2f}x)   {change:.1e}")


if __name__ == "__main__":
    main()
