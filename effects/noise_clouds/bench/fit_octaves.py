"""Fit of multiple scattering's octaves (effects/noise_clouds/physics.md eq. 6.1) to Mitsuba 3.

    .venv/bin/python effects/noise_clouds/bench/fit_octaves.py [--quick] [--out TXT] [--plot PNG]

Default: writes effects/noise_clouds/docs/fit_octaves.txt and .png (about 17 min on 2 cores);
--quick: two clouds, two suns, 12 rays per camera, 256 samples, written to the temporary directory
(fit_octaves_quick.txt / .png; about half a minute).

The sun's term of eq. 3.1, T_c p_HG(mu, g), becomes sum_{i<N} a^i T_c^(b^i) p_HG(mu, c^i g) in the
renderer. This script finds a, b, c (for several N) by least squares against Mitsuba 3's volumetric
path tracer on the SAME density, and reports how far the fitted model and plain single scattering
are from the path tracer. The method, the settings and the result are written up in
effects/noise_clouds/docs/multiple_scattering.md.

1. Density grids. For each cloud case the reference density d(p)
   (effects/noise_clouds/tests/clouds_reference.py, the renderer's noise textures of seed 0) is
   evaluated at the voxel centres of a box: BOX_WIDTH in x and z around the origin, the support slab
   [base, base + t (top - base)] in y (d = 0 outside it), voxels of about --voxel metres. sigma_t =
   extinction d, rounded to float32 (what Mitsuba holds); both sides use that grid with trilinear
   interpolation between voxel centres, clamped to the outermost centres at the faces (Mitsuba's
   gridvolume default), and 0 outside the box.

2. Mitsuba. ``volpath`` in ``llvm_ad_mono``: a ``cube`` with a ``null`` BSDF holding a
   ``heterogeneous`` medium (sigma_t the grid, albedo 1, ``hg`` phase g), a ``directional`` sun of
   irradiance 1, nothing else (no sky, black background, no ground). Rays from three cameras (below
   the box, at its centre, above it) along fixed directions go to ``volpath.sample`` directly; each
   gets --spp samples in independently seeded batches, the mean and its standard error from the
   samples. max_depth = -1 (all orders; Russian roulette only after RR_DEPTH real scatterings:
   with albedo 1 the path throughput stays 1, so Mitsuba's roulette would survive with 0.95 at each
   vertex and multiply the weight of long paths by 0.95^-n, a huge variance for the diffuse light
   through thick clouds, while every path leaves the finite box anyway) and max_depth = 2 (single
   scattering, the check of the whole setup).
3. Float64 integrator (eqs. 3.3, 4.1, 6.1) on the same grid: equal view steps of about
   --view-step metres over the ray's part in the box (energy-conserving step, eq. 4.1, albedo 1),
   and at every sample with sigma > 0 the sun's optical depth tau_s by its own midpoint march of
   about --light-step metres out of the box. Cached per ray: the view weights w_k = T_k (1 -
   e^{-sigma_k dt}) and tau_s,k (binned in tau_s to TAU_BIN), and mu = s . d. Then for any
   (a, b, c, N): L = sum_i a^i p_HG(mu, c^i g) sum_k w_k exp(-b^i tau_s,k), a few ms per candidate.
4. Fit. a, b, c for each N in --octaves by scipy.optimize.least_squares, parameterised as
   b in (0, 1], a = r b with r in (0, 1], c in [0, 1] (so 0 < a <= b <= 1), on relative residuals
   (model - mitsuba) / mitsuba over rays with signal (view optical depth >= MIN_VIEW_TAU, Mitsuba's
   standard error <= MAX_REL_SE of its mean), each divided by sqrt(1 + (se_rel / NOISE_SCALE)^2)
   so that noisy rays count less. Several starting points; the best is kept. The same fit without
   a <= b (a in (0, 1]) is reported for information, and so are fits of the chosen N to each
   cloud case alone and one on the log of the ratio instead of the relative error (the relative
   error is asymmetric: a model 5 times too dark costs 0.64, one 2 times too bright 1). The N
   printed last is the smallest whose cost is within N_TOLERANCE of the best N's.

Statistics: |relative error| of a model against Mitsuba all-orders per ray (median, 90th, 99th
percentile) and the mean signed relative error, for all rays with signal and per class (camera,
sun elevation, cloud case, g), single scattering beside the fitted model; the median relative
standard error of Mitsuba is given per class so that the noise's share of the residual is visible.

Needs Mitsuba 3 and Dr.Jit (pyproject's ``reference`` extra), scipy and matplotlib. Mitsuba >= 3.6
emits LLVM IR that LLVM 14/15 cannot compile (the process aborts at the first kernel); when
DRJIT_LIBLLVM_PATH is not set this script looks for a newer libLLVM (a system llvm-16+ or a Rust
toolchain's) and points Dr.Jit at it (--libllvm to choose).
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import pickle
import re
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
TESTS = ROOT / "effects" / "noise_clouds" / "tests"
if str(TESTS) not in sys.path:
    sys.path.insert(0, str(TESTS))

import clouds_reference as cr  # noqa: E402

BASE, TOP = 1500.0, 4000.0  # m: the layer
SHAPE_SCALE = 4000.0  # m: one shape tile per box width, so that the box holds whole clouds
BOX_WIDTH = 4000.0  # m, in x and z, centred on the origin
CAMERA_GAP = 500.0  # m: the cameras below / above the box are this far from its bottom / top
CONE_DEG = 55.0  # below / above: directions within this angle of the vertical
SUN_AZIMUTH_DEG = 0.0  # the sun toward -z (physics.md's convention: (sin az cos el, sin el, -cos az cos el))
RR_DEPTH = 2000  # Mitsuba's Russian roulette starts after this many real scatterings
BATCH = 1 << 18  # lanes per volpath.sample call
TAU_BIN = 0.005  # bin width of the cached sun optical depths (error < b^2 TAU_BIN^2 / 8)
T_VIEW_CUT = 1e-10  # view samples behind this transmittance are dropped (they add < 1e-10 J)
VALIDATION_REL_SE = 0.1  # the single-scattering check uses rays whose Mitsuba se is below this
MIN_VIEW_TAU = 0.02  # a ray "has signal" when it crosses at least this optical depth of cloud
MAX_REL_SE = 0.25  # ... and Mitsuba's standard error is at most this fraction of its mean
NOISE_SCALE = 0.05  # residuals of rays noisier than this are down-weighted in the fit
N_TOLERANCE = 0.05  # the reported N: the smallest whose fit cost is within 5 % of the best


@dataclass(frozen=True)
class CloudCase:
    name: str
    coverage: float
    type: float
    extinction: float

    def params(self) -> cr.CloudParams:
        return cr.CloudParams(base=BASE, top=TOP, coverage=self.coverage, type=self.type,
                              extinction=self.extinction, shape_scale=SHAPE_SCALE, seed=0)


# Column optical depths through the layer (10th / 50th / 90th percentile / max over the box at
# 30 m voxels) are printed by the run; roughly: thin 0.5 / 1 / 1.6 / 2.5, broken 0.1 / 1.6 / 5.5 /
# 14 (7 % of the columns clear), medium 3.9 / 7.9 / 13 / 20, thick 33 / 39 / 46 / 53.
CLOUDS = {
    "thin": CloudCase("thin", 0.5, 0.5, 0.01),
    "broken": CloudCase("broken", 0.4, 0.5, 0.1),
    "medium": CloudCase("medium", 0.5, 0.5, 0.08),
    "thick": CloudCase("thick", 0.7, 1.0, 0.06),
}
CAMERAS = ("below", "inside", "above")


# ------------------------------------------------------------------------------------------------
# Mitsuba and Dr.Jit's LLVM


def _llvm_major(path: str) -> int:
    m = re.search(r"libLLVM[-.]?(?:so\.)?(\d+)", os.path.basename(path))
    if m:
        return int(m.group(1))
    m = re.search(r"llvm-(\d+)", path)
    return int(m.group(1)) if m else 0


def configure_llvm(explicit: str | None) -> str | None:
    """Sets DRJIT_LIBLLVM_PATH (before Dr.Jit is imported): ``explicit``, else the environment's,
    else the newest libLLVM of major version >= 16 found on this machine (system llvm-N packages,
    Rust toolchains); None when none is found (Dr.Jit then looks for libLLVM.so itself)."""
    if explicit:
        os.environ["DRJIT_LIBLLVM_PATH"] = explicit
        return explicit
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    patterns = ["/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib/x86_64-linux-gnu/libLLVM*.so*",
                "/usr/local/lib/libLLVM*.so*", os.path.expanduser("~/.rustup/toolchains/*/lib/libLLVM.so.*")]
    found = []
    for pat in patterns:
        for p in glob.glob(pat):
            if os.path.isfile(p) and os.path.getsize(p) > 1 << 20 and _llvm_major(p) >= 16:
                found.append((_llvm_major(p), "stable" in p, p))
    if not found:
        return None
    path = max(found)[2]
    os.environ["DRJIT_LIBLLVM_PATH"] = path
    return path


_mi: Any = None


def load_mitsuba(threads: int) -> Any:
    global _mi
    if _mi is None:
        import drjit as dr
        import mitsuba as mi

        mi.set_variant("llvm_ad_mono")
        dr.set_thread_count(threads)
        _mi = mi
    return _mi


# ------------------------------------------------------------------------------------------------
# The grid


@dataclass
class Grid:
    """sigma_t (1/m) at voxel centres, values[k, j, i] (z, y, x), over the box [lo, hi]."""

    values: np.ndarray  # float64 copy of the float32 values Mitsuba gets
    lo: np.ndarray
    hi: np.ndarray

    @property
    def shape_zyx(self) -> tuple[int, int, int]:
        return self.values.shape  # type: ignore[return-value]

    @property
    def voxel(self) -> np.ndarray:  # (x, y, z) sizes
        nz, ny, nx = self.values.shape
        return (self.hi - self.lo) / np.array([nx, ny, nz])

    def sigma(self, pts: np.ndarray) -> np.ndarray:
        """Trilinear between voxel centres, clamped to the outermost centres, 0 outside the box."""
        from scipy.ndimage import map_coordinates

        f = (pts - self.lo) / self.voxel - 0.5  # index space, (x, y, z)
        out = map_coordinates(self.values, f[:, ::-1].T, order=1, mode="nearest", prefilter=False)
        outside = np.any((pts < self.lo) | (pts > self.hi), axis=1)
        out[outside] = 0.0
        return out

    def interval(self, origin: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """[t0, t1] of origin + t dirs inside the box, t0 >= 0 (t1 <= t0: misses)."""
        o = np.broadcast_to(np.asarray(origin, dtype=np.float64), dirs.shape)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / dirs
            a = (self.lo - o) * inv
            b = (self.hi - o) * inv
        lo_t = np.where(np.isnan(a), -np.inf, np.minimum(a, b))
        hi_t = np.where(np.isnan(b), np.inf, np.maximum(a, b))
        # a zero direction component: inside that slab for all t, or never
        flat = dirs == 0.0
        inside = (o >= self.lo) & (o <= self.hi)
        lo_t = np.where(flat, np.where(inside, -np.inf, np.inf), lo_t)
        hi_t = np.where(flat, np.where(inside, np.inf, -np.inf), hi_t)
        t0 = np.maximum(lo_t.max(axis=1), 0.0)
        t1 = hi_t.min(axis=1)
        return t0, np.where(t1 > t0, t1, t0)


def build_grid(case: CloudCase, voxel: float, shape: Any, detail: Any) -> Grid:
    prm = case.params()
    y_lo, y_hi = prm.support
    nx = int(round(BOX_WIDTH / voxel))
    ny = max(2, int(math.ceil((y_hi - y_lo) / voxel)))
    lo = np.array([-BOX_WIDTH / 2, y_lo, -BOX_WIDTH / 2])
    hi = np.array([BOX_WIDTH / 2, y_hi, BOX_WIDTH / 2])
    xs = lo[0] + (np.arange(nx) + 0.5) * (hi[0] - lo[0]) / nx
    ys = lo[1] + (np.arange(ny) + 0.5) * (hi[1] - lo[1]) / ny
    out = np.empty((nx, ny, nx), dtype=np.float32)
    for k, z in enumerate(xs):  # one z slice at a time (bounded memory)
        yy, xx = np.meshgrid(ys, xs, indexing="ij")
        p = np.stack([xx, yy, np.full_like(xx, z)], axis=-1)
        out[k] = (prm.extinction * cr.density(p, prm, shape, detail)).astype(np.float32)
    return Grid(out.astype(np.float64), lo, hi)


def column_depths(grid: Grid) -> np.ndarray:
    """Vertical optical depth of every voxel column (trapezoid-free: voxel sums times height)."""
    return grid.values.sum(axis=1) * grid.voxel[1]


# ------------------------------------------------------------------------------------------------
# Cameras, directions, sun


def sun_direction(elevation_deg: float) -> np.ndarray:
    el, az = math.radians(elevation_deg), math.radians(SUN_AZIMUTH_DEG)
    return np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])


def fibonacci_dirs(n: int, cos_min: float) -> np.ndarray:
    """n unit vectors around +y on the cap y >= cos_min (Fibonacci spiral, equal areas)."""
    k = np.arange(n) + 0.5
    y = 1.0 - (1.0 - cos_min) * k / n
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(np.maximum(0.0, 1.0 - y * y))
    return np.stack([r * np.cos(phi), y, r * np.sin(phi)], axis=-1)


def camera(grid: Grid, which: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), unit directions (n, 3)) of camera ``which``."""
    mid_y = 0.5 * (grid.lo[1] + grid.hi[1])
    cos_cone = math.cos(math.radians(CONE_DEG))
    if which == "below":
        return np.array([0.0, grid.lo[1] - CAMERA_GAP, 0.0]), fibonacci_dirs(n, cos_cone)
    if which == "above":
        d = fibonacci_dirs(n, cos_cone)
        d[:, 1] *= -1.0
        return np.array([0.0, grid.hi[1] + CAMERA_GAP, 0.0]), d
    if which == "inside":
        # offset a little from the grid's symmetry planes (no ray along a voxel face)
        return np.array([13.0, mid_y + 7.0, -11.0]), fibonacci_dirs(n, -1.0)
    raise ValueError(which)


# ------------------------------------------------------------------------------------------------
# Mitsuba renders


@dataclass
class Render:
    mean: np.ndarray
    stderr: np.ndarray
    spp: int
    seconds: float


def mitsuba_scene(grid: Grid, g: float, sun: np.ndarray) -> tuple[Any, Any]:
    mi = _mi
    size = grid.hi - grid.lo
    centre = 0.5 * (grid.lo + grid.hi)
    data = mi.TensorXf(np.ascontiguousarray(grid.values.astype(np.float32)[..., None]))
    medium = mi.load_dict({
        "type": "heterogeneous", "albedo": 1.0, "scale": 1.0,
        "sigma_t": {"type": "gridvolume", "data": data, "filter_type": "trilinear", "wrap_mode": "clamp",
                    "to_world": mi.ScalarTransform4f().translate(grid.lo.tolist()).scale(size.tolist())},
        "phase": {"type": "hg", "g": float(g)} if g != 0.0 else {"type": "isotropic"},
    })
    scene = mi.load_dict({
        "type": "scene",
        "box": {"type": "cube", "bsdf": {"type": "null"}, "interior": medium,
                "to_world": mi.ScalarTransform4f().translate(centre.tolist()).scale((0.5 * size).tolist())},
        "sun": {"type": "directional", "direction": [float(-x) for x in sun], "irradiance": 1.0},
    })
    return scene, medium


def render(scene: Any, medium: Any, origin: np.ndarray, dirs: np.ndarray, spp: int, max_depth: int,
           seed: int, rr_depth: int = RR_DEPTH) -> Render:
    """Mean and standard error of volpath's radiance along each direction from ``origin``:
    ``spp`` samples each, in batches of at most BATCH lanes, batch b seeded (seed, b); Russian
    roulette after ``rr_depth`` real scatterings."""
    mi = _mi
    integrator = mi.load_dict({"type": "volpath", "max_depth": int(max_depth), "rr_depth": int(rr_depth)})
    sampler = mi.load_dict({"type": "independent"})
    n = len(dirs)
    per_batch = max(1, BATCH // n)
    s1, s2 = np.zeros(n), np.zeros(n)
    d32 = (dirs / np.linalg.norm(dirs, axis=1)[:, None]).astype(np.float32)
    done, batch = 0, 0
    t0 = time.perf_counter()
    while done < spp:
        k = min(per_batch, spp - done)
        d = np.repeat(d32, k, axis=0)
        o = np.broadcast_to(origin.astype(np.float32), d.shape)
        ray = mi.Ray3f(mi.Point3f(o[:, 0], o[:, 1], o[:, 2]), mi.Vector3f(d[:, 0], d[:, 1], d[:, 2]))
        sampler.seed((seed * 7919 + batch) % (1 << 31), n * k)
        result = integrator.sample(scene, sampler, ray, medium)
        val = np.asarray(result[0], dtype=np.float64).reshape(-1)[: n * k].reshape(n, k)
        val = np.where(np.isfinite(val), val, 0.0)
        s1 += val.sum(axis=1)
        s2 += np.square(val).sum(axis=1)
        done += k
        batch += 1
    mean = s1 / spp
    var = np.maximum(s2 / spp - mean * mean, 0.0) * spp / max(spp - 1, 1)
    return Render(mean, np.sqrt(var / spp), spp, time.perf_counter() - t0)


# ------------------------------------------------------------------------------------------------
# Float64 integrator


def _segments(grid: Grid, origins: np.ndarray, dirs: np.ndarray, t0: np.ndarray, t1: np.ndarray,
              step: float, chunk: int = 1 << 21):
    """Yields (ray index, k, t_mid, dt, sigma) chunks of the midpoint samples of equal steps of about
    ``step`` over [t0, t1] of each ray (origins and dirs (M, 3) or broadcastable)."""
    length = np.maximum(t1 - t0, 0.0)
    counts = np.where(length > 0.0, np.maximum(1, np.ceil(length / step)), 0).astype(np.int64)
    dt_all = np.where(counts > 0, length / np.maximum(counts, 1), 0.0)
    m = len(counts)
    for _rays, _n, ray, k in cr.sample_chunks(counts, chunk):
        dt = dt_all[ray]
        t = t0[ray] + (k + 0.5) * dt
        o = origins[ray] if origins.ndim == 2 and len(origins) == m else origins.reshape(-1, 3)[0]
        d = dirs[ray] if dirs.ndim == 2 and len(dirs) == m else dirs.reshape(-1, 3)[0]
        x = o + t[:, None] * d
        yield ray, k, t, dt, grid.sigma(x), x


def sun_depth(grid: Grid, pts: np.ndarray, sun: np.ndarray, step: float) -> np.ndarray:
    """int_0^inf sigma(p + u s) du for points inside the box: midpoint rule of equal steps of about
    ``step`` from p to where the half-line leaves the box."""
    out = np.zeros(len(pts))
    if len(pts) == 0:
        return out
    dirs = np.broadcast_to(sun, pts.shape)
    t0, t1 = grid.interval(pts, np.ascontiguousarray(dirs))
    t0 = np.zeros_like(t0)
    for ray, _k, _t, dt, sig, _x in _segments(grid, pts, sun[None, :], t0, t1, step):
        out += np.bincount(ray, weights=sig * dt, minlength=len(pts))
    return out


@dataclass
class RayCache:
    """Per-ray quantities of one (cloud, sun, camera): mu = s . d, the view optical depth, and the
    binned view weights: entry e belongs to ray[e], carries weight w[e] (sum of T (1 - e^{-sigma dt})
    over the samples in the bin) at the w-weighted mean sun optical depth tau[e]."""

    mu: np.ndarray
    tau_view: np.ndarray
    ray: np.ndarray
    w: np.ndarray
    tau: np.ndarray

    def octave_sums(self, b_powers: np.ndarray) -> np.ndarray:
        """(len(b_powers), rays): sum_k w_k exp(-beta tau_k) for each beta."""
        n = len(self.mu)
        return np.stack([np.bincount(self.ray, weights=self.w * np.exp(-beta * self.tau), minlength=n)
                         for beta in b_powers])


def integrate_camera(grid: Grid, origin: np.ndarray, dirs: np.ndarray, sun: np.ndarray, view_step: float,
                     light_step: float) -> RayCache:
    n = len(dirs)
    t0, t1 = grid.interval(origin[None, :], dirs)
    rays_l, w_l, tau_l = [], [], []
    tau_view = np.zeros(n)
    for ray, _k, _t, dt, sig, x in _segments(grid, origin[None, :], dirs, t0, t1, view_step):
        # Steps of one ray are contiguous and in order within a chunk; a ray never spans chunks
        # unless it alone exceeds the chunk (then its T must carry over: handled by tau_view).
        step_tau = sig * dt
        first = np.r_[True, ray[1:] != ray[:-1]]
        csum = np.cumsum(step_tau)
        start_idx = np.maximum.accumulate(np.where(first, np.arange(len(ray)), 0))
        before = csum - step_tau - (csum[start_idx] - step_tau[start_idx]) + tau_view[ray]
        tau_view += np.bincount(ray, weights=step_tau, minlength=n)
        t_start = np.exp(-before)
        keep = (sig > 0.0) & (t_start > T_VIEW_CUT)
        if not keep.any():
            continue
        w = t_start[keep] * -np.expm1(-step_tau[keep])  # albedo 1: T (1 - e^{-sigma dt}) (eq. 4.1)
        rays_l.append(ray[keep])
        w_l.append(w)
        tau_l.append(sun_depth(grid, x[keep], sun, light_step))
    mu = dirs @ sun
    if not rays_l:
        return RayCache(mu, tau_view, np.zeros(0, np.int64), np.zeros(0), np.zeros(0))
    ray = np.concatenate(rays_l)
    w = np.concatenate(w_l)
    tau = np.concatenate(tau_l)
    # bin in tau_s: (ray, bin) -> summed weight, weighted mean tau
    key = ray * (1 << 24) + np.minimum(np.floor(tau / TAU_BIN), (1 << 24) - 1).astype(np.int64)
    uniq, inv = np.unique(key, return_inverse=True)
    wb = np.bincount(inv, weights=w)
    tb = np.bincount(inv, weights=w * tau) / np.where(wb > 0, wb, 1.0)
    return RayCache(mu, tau_view, (uniq >> 24).astype(np.int64), wb, tb)


def octave_model(cache: RayCache, g: float, a: float, b: float, c: float, n_oct: int) -> np.ndarray:
    """Eq. 6.1 along each ray (sun irradiance 1, albedo 1)."""
    sums = cache.octave_sums(b ** np.arange(n_oct))
    out = np.zeros(len(cache.mu))
    for i in range(n_oct):
        out += a ** i * cr.hg_phase(cache.mu, c ** i * g) * sums[i]
    return out


# ------------------------------------------------------------------------------------------------
# The experiment


@dataclass
class Block:
    """One (cloud, g, sun, camera): its rays."""

    cloud: str
    g: float
    sun_deg: float
    camera: str
    cache: RayCache
    all_orders: Render
    single: Render
    ss_py: np.ndarray = field(default_factory=lambda: np.zeros(0))


def run_experiment(args: argparse.Namespace) -> tuple[list[Block], dict]:
    import airlight

    shape, detail = airlight._core.cloud_noise_textures(0)
    shape, detail = cr.NoiseTexture(shape), cr.NoiseTexture(detail)
    info: dict[str, Any] = {"grids": {}, "timing": {}}
    blocks: list[Block] = []
    t_py = t_mi = 0.0
    for ci, name in enumerate(args.clouds):
        case = CLOUDS[name]
        t = time.perf_counter()
        grid = build_grid(case, args.voxel, shape, detail)
        col = column_depths(grid)
        info["grids"][name] = {
            "case": case, "shape_zyx": grid.shape_zyx, "voxel": grid.voxel.tolist(),
            "lo": grid.lo.tolist(), "hi": grid.hi.tolist(),
            "col_pct": np.percentile(col, [10, 50, 90, 100]).tolist(), "clear": float(np.mean(col == 0.0)),
        }
        print(f"[{name}] grid {grid.shape_zyx} voxel {grid.voxel.round(1).tolist()} m, column optical depth "
              f"p10/50/90/max {np.percentile(col, [10, 50, 90, 100]).round(2).tolist()} "
              f"({time.perf_counter() - t:.1f} s)", flush=True)
        gs = [args.g] + ([gf for gf in args.g_forward] if name in args.forward_clouds else [])
        for si, sun_deg in enumerate(args.suns):
            sun = sun_direction(sun_deg)
            caches = {}
            t = time.perf_counter()
            for cam in CAMERAS:
                origin, dirs = camera(grid, cam, args.rays)
                caches[cam] = (origin, dirs, integrate_camera(grid, origin, dirs, sun, args.view_step,
                                                              args.light_step))
            dt_py = time.perf_counter() - t
            t_py += dt_py
            for gi, g in enumerate(gs):
                scene, medium = mitsuba_scene(grid, g, sun)
                for cj, cam in enumerate(CAMERAS):
                    origin, dirs, cache = caches[cam]
                    med = medium if cam == "inside" else None
                    seed = ((ci * 16 + si) * 8 + gi) * 4 + cj
                    ao = render(scene, med, origin, dirs, args.spp, -1, 2 * seed)
                    ss = render(scene, med, origin, dirs, args.spp_single, 2, 2 * seed + 1)
                    t_mi += ao.seconds + ss.seconds
                    blk = Block(name, g, sun_deg, cam, cache, ao, ss)
                    blk.ss_py = octave_model(cache, g, 0.0, 1.0, 1.0, 1)
                    blocks.append(blk)
                    print(f"  sun {sun_deg:4.0f} g {g:.2f} {cam:6s}: mitsuba all {ao.seconds:6.1f} s, "
                          f"depth 2 {ss.seconds:5.1f} s; mean all-orders {ao.mean.mean():.4g}, single (py) "
                          f"{blk.ss_py.mean():.4g}, (mi) {ss.mean.mean():.4g}", flush=True)
            print(f"  python integrator for sun {sun_deg:.0f}: {dt_py:.1f} s", flush=True)
    info["timing"] = {"python_s": t_py, "mitsuba_s": t_mi}
    return blocks, info


def convergence_check(args: argparse.Namespace) -> dict:
    """Single scattering of one cloud and sun at the given steps and at half of both, relative
    change over rays with signal."""
    import airlight

    shape, detail = airlight._core.cloud_noise_textures(0)
    shape, detail = cr.NoiseTexture(shape), cr.NoiseTexture(detail)
    name = "medium" if "medium" in args.clouds else args.clouds[0]
    grid = build_grid(CLOUDS[name], args.voxel, shape, detail)
    sun_deg = args.suns[0]
    sun = sun_direction(sun_deg)
    out = {"cloud": name, "sun": sun_deg}
    for cam in CAMERAS:
        origin, dirs = camera(grid, cam, args.rays)
        res = []
        for vs, ls in ((args.view_step, args.light_step), (args.view_step / 2, args.light_step / 2)):
            cache = integrate_camera(grid, origin, dirs, sun, vs, ls)
            res.append((octave_model(cache, args.g, 0.0, 1.0, 1.0, 1),
                        octave_model(cache, args.g, 0.5, 0.5, 0.5, 4), cache.tau_view))
        sig = res[1][2] >= MIN_VIEW_TAU
        ss_change = np.abs(res[0][0] - res[1][0])[sig] / np.maximum(res[1][0][sig], 1e-300)
        oct_change = np.abs(res[0][1] - res[1][1])[sig] / np.maximum(res[1][1][sig], 1e-300)
        out[cam] = (float(ss_change.max()) if ss_change.size else 0.0,
                    float(oct_change.max()) if oct_change.size else 0.0)
    return out


# ------------------------------------------------------------------------------------------------
# Fit and statistics


@dataclass
class Data:
    """All rays with signal, flattened, with the per-block caches for the model."""

    blocks: list[Block]
    masks: list[np.ndarray]
    ref: np.ndarray
    se: np.ndarray
    ss: np.ndarray
    labels: dict[str, np.ndarray]

    def model(self, a: float, b: float, c: float, n_oct: int) -> np.ndarray:
        return np.concatenate([octave_model(blk.cache, blk.g, a, b, c, n_oct)[m]
                               for blk, m in zip(self.blocks, self.masks)])


def collect(blocks: list[Block]) -> Data:
    masks, ref, se, ss = [], [], [], []
    labels: dict[str, list] = {"camera": [], "sun": [], "cloud": [], "g": []}
    for blk in blocks:
        r = blk.all_orders
        m = (blk.cache.tau_view >= MIN_VIEW_TAU) & (r.mean > 0.0) & (r.stderr <= MAX_REL_SE * r.mean)
        masks.append(m)
        ref.append(r.mean[m])
        se.append(r.stderr[m])
        ss.append(blk.ss_py[m])
        k = int(m.sum())
        labels["camera"] += [blk.camera] * k
        labels["sun"] += [f"{blk.sun_deg:g} deg"] * k
        labels["cloud"] += [blk.cloud] * k
        labels["g"] += [f"g={blk.g:g}"] * k
    return Data(blocks, masks, np.concatenate(ref), np.concatenate(se), np.concatenate(ss),
                {k: np.array(v) for k, v in labels.items()})


def fit(data: Data, n_oct: int, constrained: bool = True, select: np.ndarray | None = None,
        log_ratio: bool = False) -> dict:
    """Least squares of the noise-weighted relative residuals (log_ratio: of log(model / mitsuba));
    parameters (b, r = a / b, c) with a <= b when constrained, else (a, b, c) each in (0, 1]."""
    from scipy.optimize import least_squares

    sel = np.ones(len(data.ref), bool) if select is None else select
    rel_se = data.se / data.ref
    weight = 1.0 / np.sqrt(1.0 + (rel_se / NOISE_SCALE) ** 2)

    def abc(x: np.ndarray) -> tuple[float, float, float]:
        return (x[0] * x[1], x[0], x[2]) if constrained else (x[0], x[1], x[2])

    def residual(x: np.ndarray) -> np.ndarray:
        a, b, c = abc(x)
        model = data.model(a, b, c, n_oct)
        if log_ratio:
            return (np.log(np.maximum(model, 1e-300) / data.ref) * weight)[sel]
        return ((model - data.ref) / data.ref * weight)[sel]

    best = None
    starts = [(b0, r0, c0) for b0 in (0.3, 0.6, 0.9) for r0 in (0.5, 0.9) for c0 in (0.3, 0.8)]
    for s in starts:
        x0 = np.array(s) if constrained else np.array([s[0] * s[1], s[0], s[2]])
        res = least_squares(residual, x0, bounds=([1e-4, 1e-4, 0.0], [1.0, 1.0, 1.0]), x_scale=0.1,
                            diff_step=1e-4, xtol=1e-10, ftol=1e-10)
        if best is None or res.cost < best.cost:
            best = res
    a, b, c = abc(best.x)
    return {"a": a, "b": b, "c": c, "N": n_oct, "cost": float(best.cost), "constrained": constrained,
            "n_rays": int(sel.sum())}


def error_stats(pred: np.ndarray, ref: np.ndarray) -> tuple[float, float, float, float]:
    rel = (pred - ref) / ref
    ab = np.abs(rel)
    if ab.size == 0:
        return (math.nan,) * 4  # type: ignore[return-value]
    p90, p99 = np.percentile(ab, [90, 99])
    return float(np.median(ab)), float(p90), float(p99), float(rel.mean())


def validation(blocks: list[Block]) -> dict:
    """Python single scattering against Mitsuba max_depth = 2: z-scores per ray with signal whose
    Mitsuba standard error is at most VALIDATION_REL_SE of its mean, and the summed radiance of those
    rays per camera and overall with its standard error. (With few samples per ray the standard
    error of a heavy-tailed estimator, such as the sun's ratio-tracked transmittance through tens of
    optical depths seen from below a thick cloud, is itself underestimated; those rays are left
    out, and counted.)"""
    z, num, den, var = [], 0.0, 0.0, 0.0
    per: dict[str, list] = {}
    rel = []
    for blk in blocks:
        s = blk.single
        m = (blk.cache.tau_view >= MIN_VIEW_TAU) & (s.stderr > 0.0) & (s.stderr <= VALIDATION_REL_SE * s.mean)
        zz = (blk.ss_py[m] - s.mean[m]) / s.stderr[m]
        z.append(zz)
        good = m & (s.stderr <= 0.05 * s.mean)
        rel.append((blk.ss_py[good] - s.mean[good]) / s.mean[good])
        p = per.setdefault(blk.camera, [0.0, 0.0, 0.0])
        p[0] += blk.ss_py[m].sum()
        p[1] += s.mean[m].sum()
        p[2] += np.square(s.stderr[m]).sum()
        num += blk.ss_py[m].sum()
        den += s.mean[m].sum()
        var += np.square(s.stderr[m]).sum()
    z_all = np.concatenate(z)
    rel_all = np.concatenate(rel)
    total = sum(int(np.sum(blk.cache.tau_view >= MIN_VIEW_TAU)) for blk in blocks)
    return {"n": int(z_all.size), "n_signal": total, "z_mean": float(z_all.mean()),
            "z_rms": float(np.sqrt(np.mean(z_all ** 2))),
            "frac_within_2": float(np.mean(np.abs(z_all) < 2.0)),
            "frac_within_3": float(np.mean(np.abs(z_all) < 3.0)),
            "sum_ratio": num / den, "sum_ratio_se": math.sqrt(var) / den,
            "per_camera": {k: (v[0] / v[1], math.sqrt(v[2]) / v[1]) for k, v in per.items()},
            "rel_precise_n": int(rel_all.size),
            "rel_precise_median": float(np.median(np.abs(rel_all))) if rel_all.size else math.nan,
            "rel_precise_max": float(np.max(np.abs(rel_all))) if rel_all.size else math.nan}


# ------------------------------------------------------------------------------------------------
# Report


def fmt_row(cells: list[str], widths: list[int]) -> str:
    return "  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, widths)))


def report(args: argparse.Namespace, blocks: list[Block], info: dict, data: Data, fits: list[dict],
           relaxed: list[dict], chosen: dict, per_g: list[dict], val: dict, conv: dict | None,
           elapsed: float) -> str:
    lines = []
    add = lines.append
    add("Multiple scattering's octaves (physics.md eq. 6.1) fitted to Mitsuba 3 volpath")
    add("=" * 78)
    command = f".venv/bin/python effects/noise_clouds/bench/fit_octaves.py {' '.join(sys.argv[1:])}"
    add(f"command: {command.rstrip()}")
    add(f"mitsuba {_mi.__version__} llvm_ad_mono, {args.threads} threads; DRJIT_LIBLLVM_PATH="
        f"{os.environ.get('DRJIT_LIBLLVM_PATH', '(unset)')}")
    add(f"run time {elapsed / 60:.1f} min (mitsuba {info['timing']['mitsuba_s'] / 60:.1f} min, python "
        f"integrator {info['timing']['python_s'] / 60:.1f} min)")
    add("")
    add("Setup")
    add(f"  layer base {BASE:g} m, top {TOP:g} m, shape_scale {SHAPE_SCALE:g} m, detail_scale 600 m, "
        f"erosion 0.35, seed 0; box {BOX_WIDTH:g} m x {BOX_WIDTH:g} m around the origin, the support slab "
        "in y")
    for name, gi in info["grids"].items():
        c = gi["case"]
        add(f"  {name:7s} coverage {c.coverage:g} type {c.type:g} extinction {c.extinction:g}/m: grid "
            f"(z,y,x) {gi['shape_zyx']}, voxel {np.round(gi['voxel'], 1).tolist()} m, "
            f"y {gi['lo'][1]:g}-{gi['hi'][1]:g} m; column optical depth p10/50/90/max "
            f"{np.round(gi['col_pct'], 2).tolist()}, clear columns {100 * gi['clear']:.0f} %")
    add(f"  suns {args.suns} deg elevation (azimuth {SUN_AZIMUTH_DEG:g}), irradiance 1; g {args.g} "
        f"(all clouds) and {args.g_forward} ({', '.join(args.forward_clouds)})")
    add(f"  cameras: below ({CAMERA_GAP:g} m under the box) and above ({CAMERA_GAP:g} m over it), "
        f"{args.rays} directions within {CONE_DEG:g} deg of the vertical; inside (the box's centre), "
        f"{args.rays} directions over the sphere")
    add(f"  mitsuba: {args.spp} spp all orders (max_depth -1, rr_depth {RR_DEPTH}), {args.spp_single} spp "
        "max_depth 2")
    add(f"  python: view step ~{args.view_step:g} m, light step ~{args.light_step:g} m (midpoint), "
        f"tau_s bins {TAU_BIN:g}")
    add(f"  rays with signal: view optical depth >= {MIN_VIEW_TAU:g}, mitsuba rel. std. error <= "
        f"{MAX_REL_SE:g}: {len(data.ref)} of {sum(len(b.cache.mu) for b in blocks)}")
    add("")
    add("Check of the setup: python single scattering vs mitsuba max_depth = 2")
    add(f"  {val['n']} of {val['n_signal']} rays with signal (those where mitsuba's se <= "
        f"{100 * VALIDATION_REL_SE:g} % of its mean): z = (py - mi) / se: mean {val['z_mean']:+.2f}, "
        f"rms {val['z_rms']:.2f}, "
        f"|z| < 2: {100 * val['frac_within_2']:.1f} %, |z| < 3: {100 * val['frac_within_3']:.1f} %")
    add(f"  sum over rays py / mi = {val['sum_ratio']:.4f} +- {val['sum_ratio_se']:.4f}; per camera: " +
        ", ".join(f"{k} {v[0]:.4f} +- {v[1]:.4f}" for k, v in val["per_camera"].items()))
    add(f"  rays where mitsuba's se < 5 %: {val['rel_precise_n']}, |py/mi - 1| median "
        f"{100 * val['rel_precise_median']:.2f} %, max {100 * val['rel_precise_max']:.2f} %")
    if conv:
        add(f"  python convergence ({conv['cloud']}, sun {conv['sun']:g}): halving view and light steps "
            "changes single scattering / a 4-octave model by at most " +
            ", ".join(f"{cam} {100 * conv[cam][0]:.2f} % / {100 * conv[cam][1]:.2f} %" for cam in CAMERAS))
    add("")
    add("Fits (least squares of noise-weighted relative residuals, all rays with signal)")
    w = [26, 8, 8, 8, 10, 8, 8, 8, 9]
    add(fmt_row(["model", "a", "b", "c", "cost", "med %", "p90 %", "p99 %", "bias %"], w))
    med, p90, p99, bias = error_stats(data.ss, data.ref)
    add(fmt_row(["single scattering (N=1)", "-", "-", "-", "-", f"{100 * med:.1f}", f"{100 * p90:.1f}",
                 f"{100 * p99:.1f}", f"{100 * bias:+.1f}"], w))
    everything = np.ones(len(data.ref), bool)
    groups = [("a<=b", fits, everything), ("a free (info)", relaxed, everything)]
    groups += [(f["label"], [f], f["select"]) for f in per_g]
    for label, group, sel in groups:
        for f in group:
            pred = data.model(f["a"], f["b"], f["c"], f["N"])
            med, p90, p99, bias = error_stats(pred[sel], data.ref[sel])
            add(fmt_row([f"N={f['N']} {label}", f"{f['a']:.4f}", f"{f['b']:.4f}", f"{f['c']:.4f}",
                         f"{f['cost']:.3g}", f"{100 * med:.1f}", f"{100 * p90:.1f}", f"{100 * p99:.1f}",
                         f"{100 * bias:+.1f}"], w))
    add("  (|relative error| vs mitsuba all orders: median, 90th, 99th percentile; bias: mean signed; "
        "a fit to a subset alone is evaluated on that subset's rays)")
    add(f"  a <= b: {'holds' if chosen['a'] <= chosen['b'] + 1e-12 else 'VIOLATED'} for the chosen fit "
        f"(a/b = {chosen['a'] / chosen['b']:.3f}); unconstrained fits: " +
        ", ".join(f"N={f['N']} a/b={f['a'] / f['b']:.3f}" for f in relaxed))
    add("")
    add(f"Per class, chosen fit N={chosen['N']} a={chosen['a']:.4f} b={chosen['b']:.4f} c={chosen['c']:.4f} "
        "against single scattering (|rel. error| %: median / p90 / p99, bias = mean signed %)")
    pred = data.model(chosen["a"], chosen["b"], chosen["c"], chosen["N"])
    w2 = [22, 5, 7, 26, 26]
    add(fmt_row(["class", "rays", "mi se%", "single: med/p90/p99 bias", "octaves: med/p90/p99 bias"], w2))

    def row(label: str, m: np.ndarray) -> None:
        if not m.any():
            return
        s = error_stats(data.ss[m], data.ref[m])
        o = error_stats(pred[m], data.ref[m])
        se = float(np.median(data.se[m] / data.ref[m]))
        add(fmt_row([label, str(int(m.sum())), f"{100 * se:.1f}",
                     f"{100 * s[0]:.0f}/{100 * s[1]:.0f}/{100 * s[2]:.0f} {100 * s[3]:+.0f}",
                     f"{100 * o[0]:.1f}/{100 * o[1]:.0f}/{100 * o[2]:.0f} {100 * o[3]:+.1f}"], w2))

    row("all", np.ones(len(data.ref), bool))
    for key in ("camera", "sun", "cloud", "g"):
        for v in dict.fromkeys(data.labels[key]):
            row(f"{key} {v}", data.labels[key] == v)
    for cloud in dict.fromkeys(data.labels["cloud"]):
        for cam in CAMERAS:
            row(f"{cloud}/{cam}", (data.labels["cloud"] == cloud) & (data.labels["camera"] == cam))
    add("")
    add(f"a={chosen['a']:.4f} b={chosen['b']:.4f} c={chosen['c']:.4f} N={chosen['N']}")
    return "\n".join(lines) + "\n"


def plot(path: str, data: Data, blocks: list[Block], chosen: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = {"below": "tab:blue", "inside": "tab:green", "above": "tab:red"}
    pred = data.model(chosen["a"], chosen["b"], chosen["c"], chosen["N"])
    fig, axes = plt.subplots(2, 2, figsize=(11, 10))
    # (a) the check: python single scattering vs mitsuba max_depth 2
    ax = axes[0, 0]
    for cam, col in colours.items():
        xs, ys = [], []
        for blk in blocks:
            if blk.camera != cam:
                continue
            s = blk.single
            m = (blk.cache.tau_view >= MIN_VIEW_TAU) & (s.mean > 0) & (s.stderr < 0.25 * s.mean)
            xs.append(blk.single.mean[m])
            ys.append(blk.ss_py[m])
        ax.scatter(np.concatenate(xs), np.concatenate(ys), s=5, c=col, label=cam, alpha=0.6)
    ax.set_title("check: python single scattering vs Mitsuba max_depth=2")
    ax.set_xlabel("Mitsuba max_depth=2")
    ax.set_ylabel("python float64 single scattering")
    for ax, y, title in ((axes[0, 1], data.ss, "single scattering vs Mitsuba all orders"),
                         (axes[1, 0], pred, f"octaves N={chosen['N']} a={chosen['a']:.3f} "
                          f"b={chosen['b']:.3f} c={chosen['c']:.3f} vs Mitsuba all orders")):
        for cam, col in colours.items():
            m = data.labels["camera"] == cam
            ax.scatter(data.ref[m], y[m], s=5, c=col, label=cam, alpha=0.6)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("Mitsuba volpath, all orders")
        ax.set_ylabel("model")
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.set_xscale("log")
        ax.set_yscale("log")
        lim = [max(1e-6, min(ax.get_xlim()[0], ax.get_ylim()[0])), max(ax.get_xlim()[1], ax.get_ylim()[1])]
        ax.plot(lim, lim, "k-", lw=0.8)
        ax.set_xlim(lim)
        ax.set_ylim(lim)
        ax.legend(loc="upper left", fontsize=8)
    # (d) ratio against the view optical depth, per cloud case (single scattering clipped at 0.01)
    ax = axes[1, 1]
    tau_view = np.concatenate([blk.cache.tau_view[m] for blk, m in zip(data.blocks, data.masks)])
    ax.scatter(tau_view, np.clip(data.ss / data.ref, 0.01, 10.0), s=4, c="0.6", marker="x", alpha=0.4,
               label="single scattering")
    for cloud, col in zip(dict.fromkeys(data.labels["cloud"]), ("tab:orange", "tab:purple", "tab:cyan", "k")):
        m = data.labels["cloud"] == cloud
        ax.scatter(tau_view[m], np.clip(pred[m] / data.ref[m], 0.01, 10.0), s=5, c=col, alpha=0.6,
                   label=f"octaves, {cloud}")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(0.009, 11.0)
    ax.set_xlabel("cloud optical depth along the view ray (in the box)")
    ax.set_ylabel("model / Mitsuba all orders (clipped to [0.01, 10])")
    ax.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small run: two clouds, two suns, few rays, samples")
    ap.add_argument("--out", default=None, help="text report (default "
                    "effects/noise_clouds/docs/fit_octaves.txt; --quick: in the "
                    "temporary directory, so that a quick run leaves the documented result alone)")
    ap.add_argument("--plot", default=None, help="PNG (default beside --out's default)")
    ap.add_argument("--clouds", nargs="+", choices=list(CLOUDS), default=None)
    ap.add_argument("--suns", type=float, nargs="+", default=None, help="sun elevations (deg)")
    ap.add_argument("--g", type=float, default=0.2)
    ap.add_argument("--g-forward", type=float, nargs="*", default=None, help="more forward g values")
    ap.add_argument("--forward-clouds", nargs="*", default=None, help="clouds also rendered at --g-forward")
    ap.add_argument("--rays", type=int, default=None, help="directions per camera")
    ap.add_argument("--spp", type=int, default=None, help="samples per ray, all orders")
    ap.add_argument("--spp-single", type=int, default=None, help="samples per ray, max_depth 2")
    ap.add_argument("--voxel", type=float, default=None, help="voxel size (m)")
    ap.add_argument("--view-step", type=float, default=5.0)
    ap.add_argument("--light-step", type=float, default=10.0)
    ap.add_argument("--octaves", type=int, nargs="+", default=[2, 4, 8, 16])
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--libllvm", default=None, help="libLLVM for Dr.Jit (else DRJIT_LIBLLVM_PATH, or search)")
    ap.add_argument("--no-convergence", action="store_true", help="skip the python step-halving check")
    ap.add_argument("--cache", default=None, help="pickle of the renders: loaded if it exists, else written")
    args = ap.parse_args()
    q = args.quick
    defaults = {"clouds": ["thin", "medium"] if q else ["thin", "broken", "medium", "thick"],
                "suns": [10.0, 45.0] if q else [10.0, 30.0, 60.0],
                "g_forward": [] if q else [0.6], "forward_clouds": [] if q else ["broken", "medium"],
                "rays": 12 if q else 24, "spp": 256 if q else 1024, "spp_single": 1024 if q else 4096,
                "voxel": 40.0 if q else 30.0}
    for k, v in defaults.items():
        if getattr(args, k) is None:
            setattr(args, k, v)
    out_dir = Path(tempfile.gettempdir()) if q else ROOT / "effects" / "noise_clouds" / "docs"
    stem = "fit_octaves_quick" if q else "fit_octaves"
    if args.out is None:
        args.out = str(out_dir / f"{stem}.txt")
    if args.plot is None:
        args.plot = str(out_dir / f"{stem}.png")

    t_start = time.perf_counter()
    llvm = configure_llvm(args.libllvm)
    print(f"Dr.Jit LLVM: {llvm or '(default search)'}", flush=True)
    load_mitsuba(args.threads)

    if args.cache and Path(args.cache).exists():
        with open(args.cache, "rb") as fh:
            blocks, info = pickle.load(fh)
        print(f"renders loaded from {args.cache}", flush=True)
    else:
        blocks, info = run_experiment(args)
        if args.cache:
            with open(args.cache, "wb") as fh:
                pickle.dump((blocks, info), fh)
    conv = None if args.no_convergence else convergence_check(args)
    data = collect(blocks)
    print(f"{len(data.ref)} rays with signal; fitting", flush=True)
    fits = [fit(data, n) for n in args.octaves]
    relaxed = [fit(data, n, constrained=False) for n in args.octaves]
    best_cost = min(f["cost"] for f in fits)
    chosen = next(f for f in sorted(fits, key=lambda f: f["N"]) if f["cost"] <= (1 + N_TOLERANCE) * best_cost)
    per_g = []  # fits of the chosen N to subsets, each evaluated on its own rays
    for key in ("g", "cloud"):
        values = list(dict.fromkeys(data.labels[key]))
        if len(values) < 2:
            continue
        for v in values:
            sel = data.labels[key] == v
            f = fit(data, chosen["N"], select=sel)
            f["label"], f["select"] = f"a<=b, {v} only", sel
            per_g.append(f)
    f = fit(data, chosen["N"], log_ratio=True)
    f["label"], f["select"] = "a<=b, log-ratio fit", np.ones(len(data.ref), bool)
    per_g.append(f)
    val = validation(blocks)
    elapsed = time.perf_counter() - t_start
    text = report(args, blocks, info, data, fits, relaxed, chosen, per_g, val, conv, elapsed)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text)
    if args.plot:
        plot(args.plot, data, blocks, chosen)
    print(text)


if __name__ == "__main__":
    main()
