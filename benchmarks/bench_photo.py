"""Time per megapixel of airlight.photo.apply_weather (issue 26), CPU backend.

A 1280x720 image with random depth (a tenth of it sky) in a fog of 60 m with the
foggy_street preset's 16 lamps, and without lamps (Koschmieder's law alone);
the best of 3 runs through one Renderer.

    .venv/bin/python benchmarks/bench_photo.py [--backend cpu|gl]
"""

import argparse
import time

import numpy as np

import airlight
from airlight import photo


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--backend", default="cpu")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=720)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    image = rng.uniform(0, 1, (args.height, args.width, 3)).astype(np.float32)
    depth = rng.uniform(1, 80, (args.height, args.width)).astype(np.float32)
    depth[: args.height // 10] = np.inf
    scene = airlight.preset("foggy_street")
    weather = {"medium": {"visibility": 60.0, "albedo": 0.9}, "atmospheric_light": 0.05}
    megapixels = args.width * args.height / 1e6
    with airlight.Renderer(args.backend) as r:
        for label, lights in (("fog + atmospheric light", None), ("fog + 16 lamps (multiple scattering)",
                                                                   scene["lights"])):
            best = float("inf")
            for _ in range(3):
                start = time.perf_counter()
                photo.apply_weather(image, depth, scene["camera"], weather, lights, renderer=r)
                best = min(best, time.perf_counter() - start)
            print(f"{args.backend} {args.width}x{args.height} {label}: {best:.3f} s, "
                  f"{best / megapixels:.3f} s per megapixel")


if __name__ == "__main__":
    main()
