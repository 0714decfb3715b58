"""Noise clouds against Mitsuba 3's path tracer at equal error: the sun's single scattering.

    .venv/bin/python effects/noise_clouds/bench/bench_mitsuba.py [--width 640 --height 360]
        [--out effects/noise_clouds/docs/bench_mitsuba.txt]
        [--plot effects/noise_clouds/docs/bench_mitsuba.png]

The tests' scene with the camera below the layer (effects/noise_clouds/tests/
test_clouds_against_reference.py), lit by the sun alone (irradiance 1, no sky), single scattering.

1. Error. The pixel-centre rays of an --error-width x --error-height film; those whose part in the
   layer's support slab lies inside a box (x in +-BOX/2, z in [-BOX, 0], the slab in y) are
   compared. Each method is measured against the exact single scattering of its own density:
   - the renderer (both backends share it) against the float64 reference (clouds_reference.py:
     the texture density, fine steps, no shortcuts);
   - Mitsuba 3 (``volpath``, max_depth 2, ``llvm_ad_mono``) on the same density sampled on a grid of
     --voxel metres over the box (trilinear between voxel centres, as fit_octaves.py builds it)
     against fit_octaves.py's float64 integrator on that grid (view steps of 5 m, light steps of
     10 m, the same box).
   Error: median and 99th percentile of |relative error| over the pixels above 1e-3 of the maximum.
2. Time. The renderer's frame time at --width x --height on each backend (median of --frames).
   Mitsuba's time per ray at each sample count, measured on the compared rays, times the frame's
   pixel count (the frame's other rays cross as much cloud or less; Mitsuba in this script traces
   rays against the box alone).
3. Equal error. Mitsuba's 99th percentile falls as spp^-1/2 (fitted to its runs); the samples it
   needs for the renderer's error, and so its time, are read off that fit.

Needs Mitsuba 3 and Dr.Jit (fit_octaves.py's notes on libLLVM apply), scipy and matplotlib.
"""

from __future__ import annotations

import argparse
import copy
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE.parents[2] / "tests" / "python"))  # shared_results, which the tests import

import clouds_reference as cr  # noqa: E402
import fit_octaves as fo  # noqa: E402
import test_clouds_against_reference as cases  # noqa: E402

BOX = 12000.0  # m: the compared part of the layer, x in +-BOX/2, z in [-BOX, 0]
SETTINGS = [(48, 8), (96, 32), (200, 64)]  # the renderer's (cloud_steps, cloud_light_steps)


def scene_sun_only() -> dict[str, Any]:
    scene = cases.scene_for("below")
    scene.pop("sky", None)
    scene["sun"]["irradiance"] = [1.0, 1.0, 1.0]
    scene["quality"] = {"multiple_scattering": False}
    return scene


def error_stats(values: np.ndarray, exact: np.ndarray) -> tuple[float, float]:
    mask = exact > 1e-3 * exact.max()
    rel = np.abs(values[mask] - exact[mask]) / exact[mask]
    return float(np.median(rel)), float(np.percentile(rel, 99))


def build_box_grid(prm: cr.CloudParams, voxel: float, shape: Any, detail: Any) -> fo.Grid:
    y_lo, y_hi = prm.support
    nx = int(round(BOX / voxel))
    ny = max(2, int(math.ceil((y_hi - y_lo) / voxel)))
    lo = np.array([-BOX / 2, y_lo, -BOX])
    hi = np.array([BOX / 2, y_hi, 0.0])
    xs = lo[0] + (np.arange(nx) + 0.5) * (hi[0] - lo[0]) / nx
    ys = lo[1] + (np.arange(ny) + 0.5) * (hi[1] - lo[1]) / ny
    zs = lo[2] + (np.arange(nx) + 0.5) * (hi[2] - lo[2]) / nx
    out = np.empty((nx, ny, nx), dtype=np.float32)
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    for k, z in enumerate(zs):
        p = np.stack([xx, yy, np.full_like(xx, z)], axis=-1)
        out[k] = (prm.extinction * cr.density(p, prm, shape, detail)).astype(np.float32)
    return fo.Grid(out.astype(np.float64), lo, hi)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--error-width", type=int, default=48)
    ap.add_argument("--error-height", type=int, default=27)
    ap.add_argument("--spp", type=int, nargs="+", default=[16, 64, 256, 1024])
    ap.add_argument("--voxel", type=float, default=30.0)
    ap.add_argument("--frames", type=int, default=1)
    ap.add_argument("--backends", nargs="+", default=None)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--libllvm", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--plot", default=None)
    args = ap.parse_args()
    import os

    import airlight

    backends = args.backends or airlight.available_backends()
    fo.configure_llvm(args.libllvm)
    mi = fo.load_mitsuba(args.threads or os.cpu_count() or 1)
    shape_tex, detail_tex = airlight._core.cloud_noise_textures(0)
    shape, detail = cr.NoiseTexture(shape_tex), cr.NoiseTexture(detail_tex)

    scene = scene_sun_only()
    prm = cr.cloud_params(scene["clouds"])
    sun, _ = cr.sun_light(scene)
    small = copy.deepcopy(scene)
    small["film"] = {"width": args.error_width, "height": args.error_height}
    origin, dirs, _t_end = cr.view_rays(small, args.error_width, args.error_height)
    y_lo, y_hi = prm.support
    up = dirs[:, 1] > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        enter = origin + ((y_lo - origin[1]) / dirs[:, 1])[:, None] * dirs
        leave = origin + ((y_hi - origin[1]) / dirs[:, 1])[:, None] * dirs
    inside = up.copy()
    for p in (enter, leave):
        inside &= (np.abs(p[:, 0]) < BOX / 2) & (p[:, 2] < 0.0) & (p[:, 2] > -BOX)
    sel = np.flatnonzero(inside)
    print(f"{len(sel)} of {len(dirs)} rays cross the layer inside the box", file=sys.stderr)

    # The renderer against the float64 reference.
    t0 = time.perf_counter()
    exact = cr.clouds_layer_radiance(small, args.error_width, args.error_height, shape, detail)
    exact = exact.reshape(-1, 3)[sel, 0]
    print(f"reference in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    renderers = {b: airlight.Renderer(b) for b in backends}
    big = copy.deepcopy(scene)
    big["film"] = {"width": args.width, "height": args.height}
    ours = []
    for steps, light in SETTINGS:
        quality = {**scene["quality"], "cloud_steps": steps, "cloud_light_steps": light}
        image = renderers["cpu" if "cpu" in renderers else backends[0]].render(
            {**small, "quality": quality}, outputs=["clouds"])["clouds"]
        med, p99 = error_stats(image.reshape(-1, 3)[sel, 0], exact)
        times = {}
        for b, r in renderers.items():
            r.render({**big, "quality": quality})  # warm: tables, textures, shaders
            runs = []
            for _ in range(args.frames):
                t = time.perf_counter()
                r.render({**big, "quality": quality})
                runs.append(time.perf_counter() - t)
            times[b] = statistics.median(runs)
        ours.append((f"{steps}/{light}", med, p99, times))
        print(ours[-1], file=sys.stderr)

    # Mitsuba against the float64 integrator on its grid.
    t0 = time.perf_counter()
    grid = build_box_grid(prm, args.voxel, shape, detail)
    cache = fo.integrate_camera(grid, origin, dirs[sel], sun, 5.0, 10.0)
    grid_exact = fo.octave_model(cache, prm.g, 0.0, 1.0, 1.0, 1)
    print(f"grid {grid.shape_zyx} and its integral in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    mscene, _medium = fo.mitsuba_scene(grid, prm.g, sun)
    pixels = args.width * args.height
    theirs = []
    checks = []  # Mitsuba agrees with the grid's exact integral within its noise
    for i, spp in enumerate(args.spp):
        result = fo.render(mscene, None, origin, dirs[sel], spp, 2, 1000 + i)
        med, p99 = error_stats(result.mean, grid_exact)
        z = (result.mean - grid_exact) / np.maximum(result.stderr, 1e-300)
        checks.append(f"{spp} spp: sum mitsuba / sum exact {result.mean.sum() / grid_exact.sum():.4f} "
                      f"+- {math.sqrt(np.sum(result.stderr ** 2)) / grid_exact.sum():.4f}; "
                      f"|z| < 3 on {np.mean(np.abs(z[result.stderr > 0]) < 3) * 100:.1f} % of the rays")
        theirs.append((spp, med, p99, result.seconds * pixels / len(sel)))
        print(theirs[-1], checks[-1], file=sys.stderr)
    spp_arr = np.array([t[0] for t in theirs], float)
    sec_per_spp = float(np.median([t[3] / t[0] for t in theirs]))
    # error = k spp^-1/2, k by least squares in log space, for the median and the 99th percentile
    k_med, k_p99 = (float(np.exp(np.mean(np.log([t[i] for t in theirs]) + 0.5 * np.log(spp_arr))))
                    for i in (1, 2))

    lines = [f"Noise clouds against Mitsuba 3 {mi.__version__} (volpath, max_depth 2, llvm_ad_mono): "
             "the sun's single scattering, camera below the layer",
             f"error on the {len(sel)} of {args.error_width}x{args.error_height} pixel-centre rays that "
             f"cross the layer inside a {BOX / 1000:g} km box, each method against the exact integral of "
             f"its own density; time for a {args.width}x{args.height} frame (s)",
             "", f"{'method':26} {'median err':>10} {'p99 err':>9} " + " ".join(f"{b:>7}" for b in backends)
             + "   Mitsuba at equal median / p99: spp, s, time over each backend's"]
    for label, med, p99, times in ours:
        cells = []
        for k, err in ((k_med, med), (k_p99, p99)):
            spp_needed = (k / err) ** 2
            t_mi = spp_needed * sec_per_spp
            ratios = "/".join(f"{t_mi / times[b]:.3g}" for b in backends)
            cells.append(f"{spp_needed:9.3g} {t_mi:9.3g} {ratios}")
        lines.append(f"{'airlight adaptive ' + label:26} {med:10.2e} {p99:9.2e} "
                     + " ".join(f"{times[b]:7.2f}" for b in backends) + "   " + " | ".join(cells))
    for spp, med, p99, secs in theirs:
        lines.append(f"{'mitsuba ' + str(spp) + ' spp':26} {med:10.2e} {p99:9.2e} "
                     + " ".join(f"{'':7}" for _ in backends) + f"   {secs:9.3g} s")
    slopes = [float(np.polyfit(np.log(spp_arr), np.log([t[i] for t in theirs]), 1)[0]) if len(theirs) > 1
              else math.nan for i in (1, 2)]
    lines += ["", f"Mitsuba's median error = {k_med:.3g} spp^-1/2, p99 = {k_p99:.3g} spp^-1/2 (fitted to its "
              f"runs); {sec_per_spp:.3g} s per sample per {args.width}x{args.height} frame. Its errors fall "
              f"as spp^{slopes[0]:.2f} (median) and spp^{slopes[1]:.2f} (p99) over these runs: where that is "
              "slower than spp^-0.5 (heavy tails) the samples it needs, and the ratios, are underestimated, "
              "where faster overestimated.",
              "",
              "check of the setup (Mitsuba against the grid's float64 integral; heavy-tailed samples make "
              "the standard errors, and so the z-scores, unreliable at low counts):"]
    lines += ["  " + c for c in checks]
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        for b in backends:
            ax.plot([t[3][b] for t in ours], [t[2] for t in ours], "o-", label=f"airlight adaptive ({b})")
        ax.plot([t[3] for t in theirs], [t[2] for t in theirs], "s--", label="Mitsuba 3 volpath (CPU)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"time for a {args.width}x{args.height} frame (s)")
        ax.set_ylabel("99th percentile relative error")
        ax.set_title("noise clouds, single scattering: airlight against Mitsuba 3")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
    for r in renderers.values():
        r.close()


if __name__ == "__main__":
    main()
