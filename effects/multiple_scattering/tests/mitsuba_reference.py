"""Mitsuba 3 path-traced reference for multiple scattering (issue 18).

The outside reference a multiple-scattering solver is measured against: Mitsuba 3's volumetric
path tracer (``volpath``) renders the same scene as airlight, with unlimited path depth. How it is
built and what it is accurate to: effects/multiple_scattering/docs/reference.md.

Daytime (effects/daytime/physics.md): the slab 0 <= y <= top of air, aerosol and rain over the
ground plane y = 0, lit by the sky dome (radiance entering the top) and the sun.

* **Channels.** Every RGB channel is a separate monochromatic problem (docs/conventions.md
  section 6), and Mitsuba's phase blend takes one scalar weight for all channels, while the share
  of Rayleigh scattering in the total differs per channel. So each channel is rendered on its own
  with the ``llvm_ad_mono`` variant: extinction, albedo, phase mixture and the lights of that
  channel only. Nothing chromatic is left to Mitsuba's RGB handling.
* **Atmosphere.** A stack of horizontal layers, each a ``heterogeneous`` medium whose
  ``sigma_t``, ``albedo`` and phase-mixture weights are ``gridvolume`` s along the altitude with
  nearest-neighbour lookup: piecewise constant, every texel holding the exact mean extinction
  (the closed-form column difference of daytime_reference.Profile) and the scattering-weighted
  albedo and phase shares of its altitude range. So the vertical optical depth is exact at every
  texel boundary. The layers exist only for the speed of delta tracking (Mitsuba's heterogeneous
  medium has one majorant per medium): a layer spans at most one e-fold of the extinction unless
  it is optically thin. Layers are joined by null-BSDF rectangles whose interior is the layer
  below and whose exterior is the layer above; the slab is ``half_width`` (default 5000 km) wide
  each way, so that a ray leaves it through the side only below about 1 degree of elevation.
* **Phase.** ``blendphase(w_outer, rayleigh, blendphase(w_inner, hg(g_aerosol), hg(g_rain)))``
  with per-texel weights (Mitsuba's blend is (1 - w) first + w second; the weight may be a
  volume): w_outer = (sigma_s,aerosol + sigma_s,rain) / sigma_s, w_inner = sigma_s,rain /
  (sigma_s,aerosol + sigma_s,rain). The rain's sun phase is HG (scenes with ``"phase": "hg"``);
  the Mie rainbow phase is not modelled here.
* **Lights.** The sky dome as an ``envmap``: a lat-long bitmap of Lz shape(w) (0 below the
  horizon) in Mitsuba's mapping u = atan2(x, -z) / (2 pi), v = acos(y) / pi, which is exactly
  airlight's azimuth convention (az 0 along -z, 90 along +x); its rows are nodes in theta,
  its columns texel centres in azimuth (``sky_bitmap``). The sun as a ``directional``
  emitter of irradiance E_sun. Light enters only through the top (and through the far sides for
  rays within about 1 degree of the horizon).
* **Ground.** A ``rectangle`` at y = 0 with a ``diffuse`` BSDF (albedo 0: a black ground that
  still ends rays, as airlight's ground without a plane), exterior medium the lowest layer.
* **Estimator.** Rays from the camera position along given directions go through
  ``volpath.sample`` directly (no film, no reconstruction filter); each direction gets
  ``spp`` independent samples, and the mean and its standard error come from the samples
  themselves (float64 sums of the float32 samples).

Night (effects/lamp_airlight/physics.md): a ``point`` emitter of intensity I inside a homogeneous
sphere of radius ``radius`` (HG phase, albedo), the camera at distance d; the glow's radiance at
angles gamma from the lamp's direction.

``max_depth``: Mitsuba counts the emitter seen directly as depth 1, so ``max_depth = 2`` is single
scattering (one medium or surface vertex plus the light it samples) and -1 is unlimited; null
interfaces do not count (measured in test_reference_harness.py against airlight's single
scattering).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import daytime_reference as ref
import numpy as np

MITSUBA_VARIANT = "llvm_ad_rgb"
DENSITY_FLOOR = 1e-5  # the slab's top: every species below this fraction of its ground density
HALF_WIDTH = 5.0e6  # m, half the slab's width
TEXEL_SCALE_FRACTION = 0.01  # texel height / the local scale height of the extinction
MAX_TEXELS = 4096
THIN_LAYER_DEPTH = 0.2  # a layer may span several e-folds while its majorant depth is below this
# The thinnest layer Mitsuba can hold: its two null interfaces, float32 rectangles 2 x HALF_WIDTH
# wide, must be told apart (a 0.55 m layer at the rain's top lost 2-3 % of the rain's light).
MIN_LAYER_THICKNESS = 10.0  # m
ENVMAP_HEIGHT = 1025  # rows (nodes) of the sky bitmap over 180 degrees: 0.176 degree apart
BATCH = 1 << 18  # samples per volpath.sample call


_mi: Any = None


def load_mitsuba(threads: int = 1, variant: str = MITSUBA_VARIANT) -> Any:
    """Imports Mitsuba, selects ``variant`` and limits Dr.Jit to ``threads`` worker threads."""
    global _mi
    import drjit as dr
    import mitsuba as mi

    if mi.variant() != variant:
        mi.set_variant(variant)
    dr.set_thread_count(threads)
    _mi = mi
    return mi


def _m() -> Any:
    if _mi is None:
        load_mitsuba()
    return _mi


# ----------------------------------------------------------------------------------------------
# The atmosphere, discretised


@dataclass
class Layer:
    """One heterogeneous medium over [y0, y1]: per-texel (equal heights) extinction, albedo and
    phase-mixture weights of one channel."""

    y0: float
    y1: float
    sigma_t: np.ndarray
    albedo: np.ndarray
    w_outer: np.ndarray
    w_inner: np.ndarray

    @property
    def majorant_depth(self) -> float:
        return float(self.sigma_t.max()) * (self.y1 - self.y0)


def atmosphere_top(atm: ref.Atmosphere) -> float:
    """The lowest altitude above which every species is below DENSITY_FLOOR of its ground
    density (92.1 km with molecules; the renderer's rule, effects/daytime/physics.md section 1)."""
    top = 0.0
    for sp in atm.species:
        ys = np.concatenate([np.linspace(0.0, 2.0e5, 400001)])
        rho = sp.profile.density(ys)
        above = np.nonzero(rho >= DENSITY_FLOOR * float(sp.profile.density(0.0)))[0]
        top = max(top, float(ys[above[-1] + 1]) if above.size else 0.0)
    return top


def _species_shares(atm: ref.Atmosphere) -> list[int]:
    """Which phase slot each species fills: 0 Rayleigh, 1 first HG (aerosol), 2 second HG (rain)."""
    slots = []
    for sp in atm.species:
        slots.append({"molecules": 0, "aerosol": 1, "rain": 2}[sp.name])
    return slots


def _cell_integrals(profile: ref.Profile, edges: np.ndarray) -> np.ndarray:
    """Exact integral of the relative density over each [edges[k], edges[k+1]]."""
    col = profile.column(edges)
    return col[:-1] - col[1:]


def discretise(atm: ref.Atmosphere, channel: int, top: float | None = None) -> list[Layer]:
    """The layers and texels of one channel (see the module docstring)."""
    if top is None:
        top = atmosphere_top(atm)
    # Layer edges: the profile breaks always; between them, greedy layers that span at most one
    # e-fold of the densest channel's extinction, or any number while optically thin.
    fine = np.unique(np.concatenate([np.linspace(0.0, top, 100001), [b for b in atm.breaks() if b < top]]))
    smax = atm.sigma_t(fine).max(axis=-1)
    breaks = sorted({0.0, top, *[b for b in atm.breaks() if 0.0 < b < top]})
    edges_l = [0.0]
    for a, b in zip(breaks[:-1], breaks[1:]):
        idx = np.nonzero((fine >= a) & (fine <= b))[0]
        # The extinction inside [a, b]: at b its left limit (a profile that ends at b, the rain's
        # top, is 0 there, and taking that value would split off a spurious layer a fine step
        # thin, whose two interfaces Mitsuba's float32 intersections cannot tell apart).
        inside = smax[idx].copy()
        inside[-1] = float(atm.sigma_t(np.array([b - 1e-6 * (b - a)])).max())
        start = idx[0]
        lo_s = hi_s = float(inside[0])
        for k, j in enumerate(idx[1:], start=1):
            s_j = float(inside[k])
            lo_s, hi_s = min(lo_s, s_j), max(hi_s, s_j)
            ok = hi_s <= math.e * lo_s or hi_s * (fine[j] - fine[start]) <= THIN_LAYER_DEPTH
            if not ok:
                edges_l.append(float(fine[j - 1]))
                start = j - 1
                lo_s = min(float(inside[k - 1]), s_j)
                hi_s = max(float(inside[k - 1]), s_j)
        edges_l.append(float(b))
    # No layer thinner than MIN_LAYER_THICKNESS: an edge that is not a profile break gives way.
    kept: list[float] = []
    for e in sorted(set(edges_l)):
        if e in breaks:
            while kept and kept[-1] not in breaks and e - kept[-1] < MIN_LAYER_THICKNESS:
                kept.pop()
            kept.append(e)
        elif not kept or e - kept[-1] >= MIN_LAYER_THICKNESS:
            kept.append(e)
    edges_l = kept
    layers = []
    slots = _species_shares(atm)
    for y0, y1 in zip(edges_l[:-1], edges_l[1:]):
        ys = np.minimum(fine[(fine >= y0) & (fine <= y1)], y1 - 1e-6 * (y1 - y0))  # y1: its left limit
        st = atm.sigma_t(ys).max(axis=-1)
        # local scale height of the extinction: |d ln sigma / dy|^-1, at least that of its species
        with np.errstate(divide="ignore", invalid="ignore"):
            lns = np.log(np.maximum(st, 1e-300))
            grad = np.abs(np.diff(lns) / np.diff(ys)) if ys.size > 1 else np.zeros(1)
        h_local = 1.0 / max(float(np.nanmax(grad)) if grad.size else 0.0, 1.0 / (y1 - y0))
        n = int(min(MAX_TEXELS, max(8, math.ceil((y1 - y0) / (TEXEL_SCALE_FRACTION * h_local)))))
        edges = np.linspace(y0, y1, n + 1)
        dy = np.diff(edges)
        ext = np.zeros(n)
        sca = np.zeros((3, n))
        for sp, slot in zip(atm.species, slots):
            mean_rho = _cell_integrals(sp.profile, edges) / dy
            ext += mean_rho * sp.sigma_t0[channel]
            sca[slot] += mean_rho * sp.sigma_s0[channel]
        s_tot = sca.sum(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            albedo = np.where(ext > 0.0, s_tot / np.where(ext > 0.0, ext, 1.0), 0.0)
            w_outer = np.where(s_tot > 0.0, (sca[1] + sca[2]) / np.where(s_tot > 0.0, s_tot, 1.0), 0.0)
            hg = sca[1] + sca[2]
            w_inner = np.where(hg > 0.0, sca[2] / np.where(hg > 0.0, hg, 1.0), 0.0)
        layers.append(Layer(y0, y1, ext, np.clip(albedo, 0.0, 1.0), w_outer, w_inner))
    return layers


def discretisation_column_error(atm: ref.Atmosphere, layers: list[Layer], channel: int,
                                samples: int = 20001) -> float:
    """Largest relative error of the discretised vertical column C(y) against the exact one,
    over altitudes where C(y) > 1e-6 C(0) (exact at texel boundaries, so this is the
    within-texel error)."""
    top = layers[-1].y1
    ys = np.linspace(0.0, top, samples)
    exact = atm.column(ys)[..., channel] - float(atm.column(top)[channel])
    got = np.zeros_like(ys)
    for layer in reversed(layers):
        n = layer.sigma_t.size
        dy = (layer.y1 - layer.y0) / n
        cum = np.concatenate([[0.0], np.cumsum(layer.sigma_t[::-1] * dy)])[::-1]  # column above edge k
        above = float(sum(la.sigma_t.sum() * (la.y1 - la.y0) / la.sigma_t.size for la in layers
                          if la.y0 >= layer.y1))
        inside = (ys >= layer.y0) & (ys <= layer.y1)
        k = np.clip(((ys[inside] - layer.y0) / dy).astype(int), 0, n - 1)
        frac = (layer.y0 + (k + 1) * dy - ys[inside])
        got[inside] = above + cum[k + 1] + layer.sigma_t[k] * frac
    mask = exact > 1e-6 * exact[0]
    return float(np.max(np.abs(got[mask] - exact[mask]) / exact[mask]))


# ----------------------------------------------------------------------------------------------
# Mitsuba scene


def _grid(values: np.ndarray, y0: float, y1: float, half_width: float) -> dict:
    mi = _m()
    data = mi.TensorXf(np.asarray(values, dtype=np.float32).reshape(1, -1, 1, 1))
    to_world = mi.ScalarTransform4f().translate([-half_width, y0, -half_width]).scale(
        [2.0 * half_width, y1 - y0, 2.0 * half_width])
    return {"type": "gridvolume", "data": data, "filter_type": "nearest", "to_world": to_world}


def _phase_dict(layer: Layer, g_aerosol: float, g_rain: float, half_width: float) -> dict:
    def hg(g: float) -> dict:
        return {"type": "isotropic"} if g == 0.0 else {"type": "hg", "g": float(g)}

    inner = {"type": "blendphase", "weight": _grid(layer.w_inner, layer.y0, layer.y1, half_width),
             "phase1": hg(g_aerosol), "phase2": hg(g_rain)}
    return {"type": "blendphase", "weight": _grid(layer.w_outer, layer.y0, layer.y1, half_width),
            "phase1": {"type": "rayleigh"}, "phase2": inner}


def sky_bitmap(sky: ref.Sky, channel: int, height: int = ENVMAP_HEIGHT) -> np.ndarray:
    """(height, width, 3) float32 grey lat-long radiance of the dome in Mitsuba's envmap lookup
    (src/emitters/envmap.cpp, eval_spectrum): row i is the node theta_i = i pi / (height - 1)
    from +y (rows are nodes, the first the zenith and the last the nadir; an odd height puts a
    row on the horizon), column j the texel centre at azimuth (j + 0.5) 2 pi / width, width =
    2 (height - 1), direction (sin az sin theta, cos theta, -cos az sin theta); bilinear in
    between. Radiance Lz shape(w), 0 below the horizon."""
    width = 2 * (height - 1)
    theta = np.arange(height) * math.pi / (height - 1)
    az = (np.arange(width) + 0.5) * 2.0 * math.pi / width
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    dirs = np.stack(np.broadcast_arrays(np.sin(az)[None, :] * st, ct, -np.cos(az)[None, :] * st), axis=-1)
    dirs[np.abs(dirs[..., 1]) < 1e-12, 1] = 0.0  # the horizon row exactly on the horizon
    val = sky.shape(dirs) * float(sky.lz[channel])
    return np.repeat(val.astype(np.float32)[..., None], 3, axis=-1)


@dataclass
class DayScene:
    """A Mitsuba scene of one channel of an airlight daytime scene."""

    scene: Any
    camera_medium: Any
    layers: list[Layer]
    channel: int
    camera_y: float


def build_day_scene(scene: dict, channel: int, *, half_width: float = HALF_WIDTH,
                    envmap_height: int = ENVMAP_HEIGHT) -> DayScene:
    """Mitsuba scene of channel ``channel`` of the airlight daytime ``scene`` (a dict as
    daytime_scenes.day_scene makes: sky, sun, atmosphere, an optional ground plane at y = 0)."""
    import daytime_scenes as ds

    mi = _m()
    sky = ds.reference_sky(scene)
    atm = ds.reference_atmosphere(scene)
    a = scene.get("atmosphere") or {}
    rain = a.get("rain")
    if rain is not None and rain.get("phase", "mie") != "hg":
        raise ValueError("the Mitsuba reference models the rain's sun phase as HG: give \"phase\": \"hg\"")
    g_aer = float((a.get("aerosol") or {}).get("g", ref.AEROSOL_G))
    g_rain = float((rain or {}).get("g", ref.RAIN_G))
    camera_y = float(scene["camera"]["position"][1])
    ground = 0.0
    for s in scene.get("surfaces", []):
        if s["type"] != "plane" or list(s["normal"]) != [0, 1, 0] or s["point"][1] != 0:
            raise ValueError("the reference has only a ground plane at y = 0")
        alb = s.get("albedo", 0.5)
        ground = float(alb[channel] if isinstance(alb, (list, tuple)) else alb)

    layers = discretise(atm, channel) if atm.species else []
    media = []
    for layer in layers:
        media.append(mi.load_dict({
            "type": "heterogeneous",
            "sigma_t": _grid(layer.sigma_t, layer.y0, layer.y1, half_width),
            "albedo": _grid(layer.albedo, layer.y0, layer.y1, half_width),
            "scale": 1.0,
            "phase": _phase_dict(layer, g_aer, g_rain, half_width),
        }))

    def plane(y: float) -> Any:
        return mi.ScalarTransform4f().translate([0.0, y, 0.0]).rotate([1.0, 0.0, 0.0], -90.0).scale(
            [half_width, half_width, 1.0])

    d: dict[str, Any] = {"type": "scene", "integrator": {"type": "volpath"}}
    ground_shape: dict[str, Any] = {"type": "rectangle", "to_world": plane(0.0),
                                    "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform",
                                                                                "value": ground}}}
    if media:
        ground_shape["exterior"] = media[0]
    d["ground"] = ground_shape
    for k, layer in enumerate(layers):
        iface: dict[str, Any] = {"type": "rectangle", "to_world": plane(layer.y1), "bsdf": {"type": "null"},
                                 "interior": media[k]}
        if k + 1 < len(media):
            iface["exterior"] = media[k + 1]
        d[f"interface_{k}"] = iface
    if max(sky.lz) > 0.0:
        d["sky"] = {"type": "envmap", "bitmap": mi.Bitmap(sky_bitmap(sky, channel, envmap_height))}
    if sky.sun_visible:
        d["sun"] = {"type": "directional", "direction": [float(x) for x in -sky.sun],
                    "irradiance": {"type": "uniform", "value": float(sky.sun_irradiance[channel])}}
    return DayScene(mi.load_dict(d), media[0] if media else None, layers, channel, camera_y)


# ----------------------------------------------------------------------------------------------
# Night: a point lamp in a homogeneous fog sphere


def build_lamp_scene(sigma_t: float, albedo: float, g: float, intensity: float,
                     lamp_position: Sequence[float], radius: float) -> tuple[Any, Any]:
    """(scene, medium): an isotropic point lamp of ``intensity`` W/sr inside a homogeneous sphere
    of ``radius`` m centred on the lamp (HG g, albedo), nothing else."""
    mi = _m()
    medium = mi.load_dict({
        "type": "homogeneous", "sigma_t": {"type": "uniform", "value": float(sigma_t)},
        "albedo": {"type": "uniform", "value": float(albedo)}, "scale": 1.0,
        "phase": {"type": "isotropic"} if g == 0.0 else {"type": "hg", "g": float(g)}})
    scene = mi.load_dict({
        "type": "scene", "integrator": {"type": "volpath"},
        "fog": {"type": "sphere", "center": [float(x) for x in lamp_position], "radius": float(radius),
                "bsdf": {"type": "null"}, "interior": medium},
        "lamp": {"type": "point", "position": [float(x) for x in lamp_position],
                 "intensity": {"type": "uniform", "value": float(intensity)}},
    })
    return scene, medium


# ----------------------------------------------------------------------------------------------
# The estimator


@dataclass
class Estimate:
    """Per-direction mean radiance and its standard error (one channel or (..., 3))."""

    mean: np.ndarray
    stderr: np.ndarray
    spp: int
    seconds: float
    settings: dict = field(default_factory=dict)


class Accumulator:
    """Running sums of volpath samples along fixed directions from one origin: add batches of
    samples until a noise target or a time limit is met."""

    def __init__(self, scene: Any, medium: Any, origin: Sequence[float], directions: np.ndarray,
                 max_depth: int = -1, seed: int = 0, rr_depth: int = 5) -> None:
        mi = _m()
        self.scene, self.medium = scene, medium
        self.origin = np.asarray(origin, dtype=np.float32)
        self.dirs = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        self.integrator = mi.load_dict({"type": "volpath", "max_depth": int(max_depth),
                                        "rr_depth": int(rr_depth)})
        self.sampler = mi.load_dict({"type": "independent"})
        self.seed, self.max_depth, self.rr_depth = seed, max_depth, rr_depth
        n = self.dirs.shape[0]
        self.s1 = np.zeros(n)
        self.s2 = np.zeros(n)
        self.spp = 0
        self.batch = 0
        self.seconds = 0.0

    def add(self, spp: int) -> None:
        """``spp`` more samples per direction (in batches of at most BATCH lanes, batch b seeded
        with (seed * 1000003 + b) mod 2^32)."""
        mi = _m()
        n_dir = self.dirs.shape[0]
        per_batch = max(1, BATCH // n_dir)
        done = 0
        t0 = time.perf_counter()
        while done < spp:
            k = min(per_batch, spp - done)
            lanes = n_dir * k
            d = np.repeat(self.dirs, k, axis=0).astype(np.float32)
            o = np.broadcast_to(self.origin, d.shape)
            ray = mi.Ray3f(mi.Point3f(o[:, 0], o[:, 1], o[:, 2]), mi.Vector3f(d[:, 0], d[:, 1], d[:, 2]))
            self.sampler.seed((self.seed * 1000003 + self.batch) % (1 << 32), lanes)
            result = self.integrator.sample(self.scene, self.sampler, ray, self.medium)
            # grey problem in an RGB variant: the three components are equal; take the first
            val = np.asarray(result[0], dtype=np.float64).reshape(lanes, -1)[:, 0].reshape(n_dir, k)
            val = np.where(np.isfinite(val), val, 0.0)
            self.s1 += val.sum(axis=1)
            self.s2 += np.square(val).sum(axis=1)
            done += k
            self.batch += 1
        self.spp += spp
        self.seconds += time.perf_counter() - t0

    @property
    def mean(self) -> np.ndarray:
        return self.s1 / max(self.spp, 1)

    @property
    def stderr(self) -> np.ndarray:
        n = max(self.spp, 1)
        m = self.s1 / n
        var = np.maximum(self.s2 / n - m * m, 0.0) * n / max(n - 1, 1)
        return np.sqrt(var / n)

    def result(self) -> Estimate:
        return Estimate(self.mean, self.stderr, self.spp, self.seconds,
                        {"max_depth": self.max_depth, "rr_depth": self.rr_depth, "seed": self.seed,
                         "variant": _m().variant()})

    def run(self, target_rel: float, max_seconds: float, min_spp: int = 1024, max_spp: int = 1 << 26,
            chunk: int = 4096, floor_fraction: float = 0.0, progress=None) -> Estimate:
        """Adds ``chunk`` samples per direction until every direction's standard error is below
        ``target_rel`` of max(its mean, floor_fraction x the largest mean), or ``max_seconds``
        or ``max_spp`` is reached (at least ``min_spp``). Stopping on the estimated error biases
        the mean by far less than its standard error for the thousands of samples used."""
        while True:
            self.add(chunk if self.spp >= min_spp else min_spp)
            m, e = self.mean, self.stderr
            scale = np.maximum(m, floor_fraction * float(m.max()))
            worst = float(np.max(np.where(scale > 0.0, e / np.where(scale > 0.0, scale, 1.0), np.inf)))
            if progress is not None:
                progress(self.spp, worst, self.seconds)
            if worst <= target_rel or self.seconds >= max_seconds or self.spp >= max_spp:
                return self.result()


def estimate(scene: Any, medium: Any, origin: Sequence[float], directions: np.ndarray, spp: int,
             max_depth: int = -1, seed: int = 0, rr_depth: int = 5) -> Estimate:
    """Mean radiance along each of ``directions`` (N, 3) from ``origin`` with ``spp`` samples
    each, by volpath with ``max_depth`` (-1 unlimited); the standard error is the samples'
    standard deviation over sqrt(spp)."""
    acc = Accumulator(scene, medium, origin, directions, max_depth, seed, rr_depth)
    acc.add(spp)
    return acc.result()


def estimate_day(scene: dict, directions: np.ndarray, spp: int, max_depth: int = -1, seed: int = 0,
                 channels: Sequence[int] = (0, 1, 2)) -> Estimate:
    """RGB radiance (N, 3) of the airlight daytime ``scene`` seen from its camera position along
    ``directions``: one monochromatic Mitsuba render per channel."""
    origin = [float(x) for x in scene["camera"]["position"]]
    means, errs, secs, info = [], [], 0.0, {}
    for c in range(3):
        if c not in channels:
            means.append(np.full(len(directions), np.nan))
            errs.append(np.full(len(directions), np.nan))
            continue
        ds_ = build_day_scene(scene, c)
        est = estimate(ds_.scene, ds_.camera_medium, origin, directions, spp, max_depth, seed + 7919 * c)
        means.append(est.mean)
        errs.append(est.stderr)
        secs += est.seconds
        info[f"layers_{'rgb'[c]}"] = len(ds_.layers)
        info[f"texels_{'rgb'[c]}"] = int(sum(la.sigma_t.size for la in ds_.layers))
        info.update(est.settings)
    return Estimate(np.stack(means, axis=-1), np.stack(errs, axis=-1), spp, secs, info)


def lamp_directions(distance: float, angles_deg: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """Camera position (3,) and unit view directions (N, 3) at the given angles from the
    direction to a lamp at the origin, for a camera at (0, 0, distance) (the angle turns
    about the x axis, upwards)."""
    a = np.radians(np.asarray(angles_deg, dtype=float))
    dirs = np.stack([np.zeros_like(a), np.sin(a), -np.cos(a)], axis=-1)
    return np.array([0.0, 0.0, float(distance)]), dirs


def fog_radius(sigma_t: float, albedo: float, g: float, distance: float) -> float:
    """Radius of the fog sphere around the lamp that stands for airlight's infinite medium: the
    camera's rays cross at least 30 optical depths of fog (to 1e-13) and the diffuse light
    beyond it, damped with the diffusion length L_d = 1 / (sigma_t sqrt(3 (1 - a)(1 - a g))),
    is below exp(-15) (albedo < 1 only)."""
    r = distance + 30.0 / sigma_t
    if albedo < 1.0:
        ld = 1.0 / (sigma_t * math.sqrt(3.0 * (1.0 - albedo) * (1.0 - albedo * g)))
        r = max(r, distance + 15.0 * ld)
    return r


def estimate_lamp(sigma_t: float, albedo: float, g: float, intensity: float, distance: float,
                  angles_deg: Sequence[float], spp: int, max_depth: int = -1, seed: int = 0) -> Estimate:
    """Radiance (N,) of a lamp's glow seen from ``distance`` at ``angles_deg`` from the lamp."""
    radius = fog_radius(sigma_t, albedo, g, distance)
    scene, medium = build_lamp_scene(sigma_t, albedo, g, intensity, [0.0, 0.0, 0.0], radius)
    origin, dirs = lamp_directions(distance, angles_deg)
    est = estimate(scene, medium, origin, dirs, spp, max_depth, seed)
    est.settings["fog_radius_m"] = radius
    return est
