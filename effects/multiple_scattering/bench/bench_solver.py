"""Cost and accuracy of the plane-parallel solver per weather state
(effects/multiple_scattering/docs/solver.md section 5): for a clear day, 40 mm/h rain and
50 m fog under the overcast sky and a sun 37 degrees up, over a grey ground (albedo 0.2), the
solve time against the streams per hemisphere, and the error against 48 streams of the ground's
diffuse irradiance and of the multiple-scattering source K (largest difference over the view grid
and the altitudes, relative to the largest K of each species).

    .venv/bin/python effects/multiple_scattering/bench/bench_solver.py [--repeat 3] [--streams 8 16 32]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from airlight import _core

WEATHERS = {
    "clear": {"molecules": {}, "aerosol": {"visibility": 30000.0}},
    "rain 40 mm/h": {"molecules": {}, "aerosol": {"visibility": 3000.0, "scale_height": 1200.0},
                     "rain": {"rate": 40.0}},
    "fog 50 m": {"molecules": {}, "aerosol": {"visibility": 50.0}},
}


def scene(atmosphere: dict) -> dict:
    return {"camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 50},
            "film": {"width": 8, "height": 8},
            "sky": {"model": "overcast", "zenith_radiance": [0.3, 0.3, 0.3]},
            "sun": {"direction": [0.6, 0.6, 0.0], "irradiance": [1.0, 1.0, 1.0]},
            "atmosphere": atmosphere}


def interpolation() -> None:
    """K between interfaces: a fine solve (layers of depth <= 0.25), every s-th interface kept and
    the dropped ones interpolated in the column C (green), linearly and linearly in log K; the
    largest error relative to each species' largest K, against the kept interfaces' spacing in C."""
    print(f"{'weather':14} {'max dC':>7} {'linear':>9} {'log-linear':>10}")
    for name, atm in WEATHERS.items():
        f = _core.solve_plane_parallel_scene(scene(atm), ground_albedo=0.2, max_layer_depth=0.25)
        c = f["column"][:, 1]
        k = f["phased_radiance"]
        scale = k.max(axis=(0, 2, 3, 4), keepdims=True)[0]
        for step in (2, 4, 8, 16):
            kept = list(range(0, len(c), step))
            if kept[-1] != len(c) - 1:
                kept.append(len(c) - 1)
            lin = logl = 0.0
            for a, b in zip(kept[:-1], kept[1:]):
                for j in range(a + 1, b):
                    t = (c[j] - c[a]) / (c[b] - c[a])
                    guess = (1 - t) * k[a] + t * k[b]
                    la, lb = np.log(np.maximum(k[a], 1e-300)), np.log(np.maximum(k[b], 1e-300))
                    lg = np.exp((1 - t) * la + t * lb)
                    lin = max(lin, float(np.max(np.abs(guess - k[j]) / scale)))
                    logl = max(logl, float(np.max(np.abs(lg - k[j]) / scale)))
            spacing = max(c[a] - c[b] for a, b in zip(kept[:-1], kept[1:]))
            print(f"{name:14} {spacing:7.2f} {lin:9.2e} {logl:10.2e}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--streams", type=int, nargs="*", default=[8, 12, 16, 24, 32])
    ap.add_argument("--reference", type=int, default=48)
    ap.add_argument("--initial-depth", type=float, default=1.0 / 16.0)
    ap.add_argument("--interpolation", action="store_true",
                    help="also measure interpolating K between interfaces (solver.md section 6)")
    args = ap.parse_args()
    if args.interpolation:
        interpolation()
    print(f"{'weather':14} {'N':>3} {'layers':>6} {'column':>8} {'modes':>5} {'time s':>8} "
          f"{'E_diff err':>10} {'K err':>9}")
    for name, atm in WEATHERS.items():
        s = scene(atm)
        ref = _core.solve_plane_parallel_scene(s, ground_albedo=0.2, streams=args.reference,
                                               initial_depth=args.initial_depth)
        k_ref = ref["phased_radiance"]
        k_scale = k_ref.max(axis=(0, 2, 3, 4), keepdims=True)
        for n in args.streams:
            times = []
            for _ in range(args.repeat):
                # CPU time of this process: the solver runs on one thread, and
                # wall time on a shared machine counts the other jobs too.
                t0 = time.process_time()
                f = _core.solve_plane_parallel_scene(s, ground_albedo=0.2, streams=n,
                                                     initial_depth=args.initial_depth)
                times.append(time.process_time() - t0)
            e_err = abs(f["irradiance_down"][0, 1] / ref["irradiance_down"][0, 1] - 1.0)
            k_err = float(np.max(np.abs(f["phased_radiance"] - k_ref) / k_scale))
            print(f"{name:14} {n:3d} {f['layers']:6d} {ref['column'][0, 1]:8.2f} {f['modes_solved']:5d} "
                  f"{statistics.median(times):8.3f} {e_err:10.2e} {k_err:9.2e}")


if __name__ == "__main__":
    main()
