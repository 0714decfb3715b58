"""Other local models of the clouds' multiple scattering, fitted to the same Mitsuba 3 renders as the
octaves (effects/noise_clouds/docs/multiple_scattering.md section 6: none of them does much better).

    .venv/bin/python effects/noise_clouds/bench/fit_octaves.py --cache RENDERS.pkl   # once, ~17 min
    .venv/bin/python effects/noise_clouds/bench/ms_alternatives.py --cache RENDERS.pkl [--out TXT]

Every model here is what a ray marcher can afford at each view sample: a function of the optical
depths of straight marches out of the box from the sample, toward the sun (tau_s, the one
single scattering needs), away from it (tau_o), up (tau_u) and down (tau_d). For each block of the
cached renders this script re-marches the view rays (steps of about 5 m, the samples behind
transmittance 1e-5 dropped) and the four depths (steps of about 10 m) on the same density grid,
then fits each model's parameters by least squares of the same noise-weighted relative residuals as
fit_octaves.py and prints the error against Mitsuba's all orders per class.

The models (S = p_HG(mu, g) e^{-tau_s}, single scattering; J the added multiple scattering):
  octaves N=8        eq. 6.1 with a, b, c free (a <= b not imposed)
  tau_s power law    S + A / (1 + B tau_s)^q / (4 pi): the diffusion-like slow decay with depth
  slab, sun chord    S + A p_HG(mu, c g) (1 - e^{-k T}) (tau_o + z) / (T + 2 z), T = tau_s + tau_o:
                     the linear fluence profile of a conservative slab in the diffusion approximation
                     (z the extrapolation length), vanishing for an optically thin chord
  slab, vertical     the same with the vertical chord, tau_u above and tau_d below
  octaves + slab     the fitted octaves (physics.md's constants) plus the sun-chord slab term
"""

from __future__ import annotations

import argparse
import math
import pickle
import sys
from pathlib import Path
from typing import Callable

import numpy as np

import __main__

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

import clouds_reference as cr  # noqa: E402
import fit_octaves as fo  # noqa: E402

VIEW_STEP, LIGHT_STEP, T_CUT = 5.0, 10.0, 1e-5


def load_renders(path: str) -> list[fo.Block]:
    # fit_octaves.py pickles its classes as __main__'s when run as a script.
    for name in ("Block", "RayCache", "Render", "CloudCase", "Grid"):
        setattr(__main__, name, getattr(fo, name))
    with open(path, "rb") as fh:
        blocks, _info = pickle.load(fh)
    return blocks


def march_samples(blocks: list[fo.Block]) -> list[dict[str, np.ndarray]]:
    """Per block: the view samples' ray, weight T (1 - e^{-sigma dt}) and the four optical depths."""
    import airlight

    shape, detail = (cr.NoiseTexture(t) for t in airlight._core.cloud_noise_textures(0))
    grids: dict[str, fo.Grid] = {}
    up = np.array([0.0, 1.0, 0.0])
    out: list[dict[str, np.ndarray]] = []
    done: dict[tuple, dict[str, np.ndarray]] = {}
    for blk in blocks:
        key = (blk.cloud, blk.sun_deg, blk.camera)
        if key in done:  # another g on the same geometry
            out.append(done[key])
            continue
        if blk.cloud not in grids:
            grids[blk.cloud] = fo.build_grid(fo.CLOUDS[blk.cloud], 30.0, shape, detail)
        grid = grids[blk.cloud]
        sun = fo.sun_direction(blk.sun_deg)
        origin, dirs = fo.camera(grid, blk.camera, len(blk.cache.mu))
        t0, t1 = grid.interval(origin[None, :], dirs)
        tau_view = np.zeros(len(dirs))
        rays, weights, points = [], [], []
        for ray, _k, _t, dt, sig, x in fo._segments(grid, origin[None, :], dirs, t0, t1, VIEW_STEP):
            step = sig * dt
            first = np.r_[True, ray[1:] != ray[:-1]]
            csum = np.cumsum(step)
            start = np.maximum.accumulate(np.where(first, np.arange(len(ray)), 0))
            before = csum - step - (csum[start] - step[start]) + tau_view[ray]
            tau_view += np.bincount(ray, weights=step, minlength=len(dirs))
            keep = (sig > 0.0) & (np.exp(-before) > T_CUT)
            rays.append(ray[keep])
            weights.append(np.exp(-before[keep]) * -np.expm1(-step[keep]))
            points.append(x[keep])
        x = np.concatenate(points)
        smp = {"ray": np.concatenate(rays), "w": np.concatenate(weights)}
        for name, d in (("s", sun), ("o", -sun), ("u", up), ("d", -up)):
            smp[name] = fo.sun_depth(grid, x, d, LIGHT_STEP)
        done[key] = smp
        out.append(smp)
        print(f"  {blk.cloud} sun {blk.sun_deg:g} {blk.camera}: {len(x)} samples", flush=True)
    return out


def main() -> None:
    from scipy.optimize import least_squares

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", required=True, help="the renders pickle of fit_octaves.py --cache")
    ap.add_argument("--out", default=None, help="text report (default: print only)")
    args = ap.parse_args()
    blocks = load_renders(args.cache)
    data = fo.collect(blocks)
    samples = march_samples(blocks)
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("ray", "w", "s", "o", "u", "d", "mu", "g")}
    offset = 0
    for blk, m, smp in zip(data.blocks, data.masks, samples):
        idx = np.flatnonzero(m)
        remap = np.full(len(m), -1, np.int64)
        remap[idx] = np.arange(len(idx)) + offset
        keep = remap[smp["ray"]] >= 0
        cols["ray"].append(remap[smp["ray"][keep]])
        for k in ("w", "s", "o", "u", "d"):
            cols[k].append(smp[k][keep])
        cols["mu"].append(blk.cache.mu[smp["ray"][keep]])
        cols["g"].append(np.full(int(keep.sum()), blk.g))
        offset += len(idx)
    v = {k: np.concatenate(c) for k, c in cols.items()}
    mu, g, s, o, u, d = v["mu"], v["g"], v["s"], v["o"], v["u"], v["d"]
    hg = cr.hg_phase
    single = hg(mu, g) * np.exp(-s)
    weight = 1.0 / np.sqrt(1.0 + ((data.se / data.ref) / fo.NOISE_SCALE) ** 2)

    def predict(f: np.ndarray) -> np.ndarray:
        return np.bincount(v["ray"], weights=v["w"] * f, minlength=offset)

    def octaves(a: float, b: float, c: float, n: int) -> np.ndarray:
        return sum(a ** i * hg(mu, c ** i * g) * np.exp(-b ** i * s) for i in range(n))

    def slab(x: np.ndarray, top: np.ndarray, bottom: np.ndarray) -> np.ndarray:
        amp, k, z, c = x
        chord = top + bottom
        return amp * hg(mu, c * g) * -np.expm1(-k * chord) * (bottom + z) / (chord + 2.0 * z)

    models: dict[str, tuple[list[float], list[float], list[tuple], Callable[[np.ndarray], np.ndarray]]] = {
        "octaves N=8": ([1e-4] * 3, [1.0] * 3, [(0.5, 0.5, 0.5)], lambda x: octaves(*x, 8)),
        "tau_s power law": ([0, 0, 0.1], [10, 10, 4], [(0.1, 0.1, 1.0), (1.0, 1.0, 2.0)],
                            lambda x: single + x[0] / (4 * math.pi) / (1 + x[1] * s) ** x[2]),
        "slab, sun chord": ([0] * 4, [20, 10, 50, 1], [(0.5, 0.3, 1, 0.5), (2, 0.1, 5, 0.3)],
                            lambda x: single + slab(x, s, o)),
        "slab, vertical": ([0] * 4, [20, 10, 50, 1], [(0.5, 0.3, 1, 0.5), (2, 0.1, 5, 0.3)],
                           lambda x: single + slab(x, u, d)),
        "octaves + slab": ([0] * 4, [20, 10, 50, 1], [(0.5, 0.3, 1, 0.5)],
                           lambda x: octaves(0.5434, 0.5434, 0.6092, 8) + slab(x, s, o)),
    }

    def stats(pred: np.ndarray, sel: np.ndarray) -> str:
        r = ((pred - data.ref) / data.ref)[sel]
        a = np.abs(r)
        p90, p99 = np.percentile(a, [90, 99])
        return f"{100 * np.median(a):5.1f} {100 * p90:6.1f} {100 * p99:6.1f} {100 * r.mean():+6.1f}"

    classes = [("all", np.ones(offset, bool))] + [
        (str(val), data.labels[key] == val) for key in ("cloud", "camera", "sun")
        for val in dict.fromkeys(data.labels[key])]
    lines = [f"Local multiple-scattering models against Mitsuba 3 all orders ({offset} rays with signal; "
             f"renders {args.cache})", "|relative error| % median / p90 / p99, mean signed %", ""]
    preds = {"single scattering": predict(single)}
    for name, (lo, hi, starts, f) in models.items():
        best = None
        for x0 in starts:
            res = least_squares(lambda x, f=f: (predict(f(x)) - data.ref) / data.ref * weight,
                                np.array(x0, float), bounds=(lo, hi), x_scale=0.1, diff_step=1e-4)
            if best is None or res.cost < best.cost:
                best = res
        preds[name] = predict(f(best.x))
        lines.append(f"{name}: parameters {np.round(best.x, 4).tolist()}, cost {best.cost:.1f}")
    lines.append("")
    lines.append(f"{'class':10s} " + " ".join(f"{n[:24]:>26s}" for n in preds))
    for label, sel in classes:
        lines.append(f"{label:10s} " + " ".join(f"{stats(p, sel):>26s}" for p in preds.values()))
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
