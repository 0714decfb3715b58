"""Independent float64 reference for spotlights and headlights (MODELS.md section 2).

Written from the model's definition, not from the shaders or docs/spot_table.md: no
tables, no closed forms, no ray-cone quadratic. Everything that is not specific to
spots (scene parsing, camera rays, intersections, lamp spheres, shadows, point-light
airlight and glow, pixel selection, compare()) is airlight_reference.py's.

* Profile (per channel): I(theta) = I0 [(1 - q)(cos theta - cos A)/(1 - cos A) + q] for
  theta <= A, else 0; theta is the angle between the emission direction (p - S)/|p - S|
  and the unit axis a; A = "cone_angle" (half-angle), q = "edge".
* Airlight of a spot over the visible part [x0, t_hit] of the ray o + x d:
  ``sigma_s / (4 pi) int I(theta(x)) exp(-sigma_t (x + |S - p(x)|)) / |S - p(x)|^2 dx``,
  nonzero only on the lit part theta(x) <= A. x0 = 0 unless the camera is inside the
  spot's lamp sphere (then where the ray leaves it); t_hit is the first surface or lamp
  sphere (spots are spheres of radius r like point lamps).
* The lit part is found numerically: g(x) = (p(x) - S).a - cos A |p(x) - S| is a linear
  function minus cos A times a convex one, so it is concave (the forward cone, A <= 90 deg,
  is a convex set), {g >= 0} is one interval, and the mirror cone (where (p - S).a < 0)
  is excluded by construction. Its maximum is bracketed by bisection on the sign of g'
  (non-increasing), its two zeros by bisection on the sign of g, in a variable s in
  [0, 1] with x = x0 + L s / (1 - s), so that escaping rays need no cut-off.
* The integral over the lit interval is taken with ``scipy.integrate.quad`` (epsabs 0,
  epsrel 1e-10 per piece) in the angle psi = atan2(h, b - x) under which the ray sees
  the lamp (b: closest approach, h: closest distance), for which dx / |S - p|^2 = dpsi / h
  exactly, x + |S - p| = b + h tan(psi / 2), and the emission direction is
  -cos(psi) d - sin(psi) m (m the unit vector from S to the closest point), so the
  integrand is smooth and bounded even for escaping rays and rays that pass the lamp at
  a tiny distance. Beyond the closest approach the complementary angle chi = pi - psi =
  atan2(h, x - b) is used so that no precision is lost near psi = pi. The exponent is
  shifted by its value at the start of the lit interval: the result is a logarithm
  (:func:`spot_airlight_log`) and never underflows.
  Checked (test_spot_airlight.py) against a brute-force midpoint rule in x with the cone
  tested pointwise, against airlight_reference's point-light quadrature (x-space,
  independent code) for q = 1 and for A = 90 deg (half-space), and against the closed
  forms without extinction.
* A ray that hits a spot's sphere sees I(theta_c) / (pi r^2), attenuated, with theta_c
  the angle between (camera position - S) and the axis.
* Surfaces: a spot adds the direct light albedo / pi I(theta_P) cos / max(d^2, r^2)
  exp(-sigma_t d), hard shadows (airlight_reference.trace). The light a spot scatters
  onto surfaces (its glow) is NOT modelled by the renderer (documented limitation), so
  this reference leaves it out too; point lights keep their glow.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from airlight_reference import (
    BACKGROUND,
    DIM_FRACTION,
    LAMP_BASE,
    REL_TOL,
    Samples,
    Scene,
    Trace,
    camera_rays,
    compare,
    parse_scene,
    ray_airlight,
    ray_light_geometry,
    smooth_pixels,
    surface_radiance,
    trace,
    transmittance,
)
from scipy.integrate import IntegrationWarning, quad

QUAD_EPSREL = 1e-10
DEFAULT_EDGE = 0.0
DEFAULT_RADIUS = 0.05

# A ray is "near-degenerate" for a spot (judged by absolute error, see spot_samples) when
# it meets the beam but its lit piece is shorter than this fraction of the ray's scale
# (|x0| + |b| + h): a ray almost tangent to the cone, whose lit length is ill-conditioned
# (a direction error eps moves it by O(sqrt(eps)) of the scale) ...
SLIVER_FRACTION = 1e-2
# ... or when it runs almost parallel to a generator of the cone, |(d.a)^2 - cos^2 A| below
# this, where the far end of the lit piece moves by O(eps / this).
PARALLEL_LIMIT = 1e-4


# ---- scene -------------------------------------------------------------------------------

@dataclass
class Spot:
    axis: np.ndarray  # unit
    cone_angle: float  # degrees, (0, 90]
    cos_a: float
    edge: float  # q


@dataclass
class SpotScene:
    sc: Scene  # every light (points and spots) as an airlight_reference.Light
    spots: list[Spot | None]  # per light: None for a point light

    @property
    def point_indices(self) -> list[int]:
        return [j for j, s in enumerate(self.spots) if s is None]

    @property
    def spot_indices(self) -> list[int]:
        return [j for j, s in enumerate(self.spots) if s is not None]

    def points_only(self) -> Scene:
        """The scene with only its point lights (for airlight_reference's functions)."""
        return dataclasses.replace(self.sc, lights=[self.sc.lights[j] for j in self.point_indices])


def make_spot(direction: Sequence[float], cone_angle: float, edge: float = DEFAULT_EDGE) -> Spot:
    axis = np.asarray(direction, dtype=np.float64).reshape(3)
    axis = axis / np.linalg.norm(axis)
    cos_a = 0.0 if cone_angle == 90.0 else math.cos(math.radians(cone_angle))
    return Spot(axis, float(cone_angle), cos_a, float(edge))


def parse_spot_scene(scene: Any) -> SpotScene:
    """The scene (dict or JSON text) in float64, spots included."""
    if isinstance(scene, str):
        scene = json.loads(scene)
    assert isinstance(scene, Mapping)
    spots: list[Spot | None] = []
    for li in scene.get("lights", []):
        kind = li.get("type", "point")
        if kind == "point":
            spots.append(None)
        elif kind == "spot":
            edge = float(li.get("edge", DEFAULT_EDGE))
            spots.append(make_spot(li["direction"], float(li["cone_angle"]), edge))
        else:
            raise ValueError(f"spot_reference: unknown light type {kind!r}")
    # airlight_reference.parse_scene reads position, intensity and radius of any light
    return SpotScene(parse_scene(scene), spots)


def profile(cos_theta: Any, spot: Spot) -> np.ndarray:
    """I(theta) / I0: the spot's relative intensity in a direction at angle theta from the
    axis (0 outside the cone)."""
    cos_theta = np.asarray(cos_theta, dtype=np.float64)
    inside = cos_theta >= spot.cos_a
    value = (1.0 - spot.edge) * (cos_theta - spot.cos_a) / (1.0 - spot.cos_a) + spot.edge
    return np.where(inside, np.maximum(value, 0.0), 0.0)


def direction_profile(spot: Spot, position: np.ndarray, points: np.ndarray) -> np.ndarray:
    """I / I0 towards points (N, 3) (or one point (3,)) from a spot at `position`."""
    rel = np.asarray(points, dtype=np.float64) - position
    dist = np.linalg.norm(rel, axis=-1)
    cos_t = np.where(dist > 0, (rel @ spot.axis) / np.where(dist > 0, dist, 1.0), 1.0)
    return profile(cos_t, spot)


# ---- the lit interval of a ray -----------------------------------------------------------------

@dataclass
class RayFrame:
    """A ray o + x d relative to a spot at S: b = (S - o).d, h = distance from S to the
    line, m = unit vector from S to the closest point (p - S = (x - b) d - h m)."""

    b: np.ndarray
    h: np.ndarray
    m: np.ndarray  # (N, 3)
    da: np.ndarray  # d.a
    ma: np.ndarray  # m.a
    wa: np.ndarray  # (o - S).a


def ray_frame(origin: np.ndarray, dirs: np.ndarray, position: np.ndarray, axis: np.ndarray) -> RayFrame:
    dirs = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    rel = np.asarray(position, dtype=np.float64) - np.asarray(origin, dtype=np.float64)  # S - o
    rel = np.broadcast_to(rel, dirs.shape)
    b = np.einsum("ij,ij->i", rel, dirs)
    cross = np.cross(rel, dirs)  # (S - o) x d, |.| = h
    h = np.linalg.norm(cross, axis=1)
    hm = np.cross(dirs, cross)  # d x ((S - o) x d) = (S - o) - b d = h m, so p - S = (x - b) d - h m
    safe = h > 0
    m = np.where(safe[:, None], hm / np.where(safe, h, 1.0)[:, None], 0.0)
    if not safe.all():  # the ray through the centre: any unit vector perpendicular to d
        for k in np.nonzero(~safe)[0]:
            t = np.cross(dirs[k], [1.0, 0.0, 0.0])
            if np.linalg.norm(t) < 0.5:
                t = np.cross(dirs[k], [0.0, 1.0, 0.0])
            m[k] = t / np.linalg.norm(t)
    return RayFrame(b, h, m, dirs @ axis, m @ axis, -(rel @ axis))


def _bisect(pred, lo: np.ndarray, hi: np.ndarray, iterations: int = 80) -> np.ndarray:
    """Vectorised bisection: pred(s) is True on [lo, boundary) and False on (boundary, hi];
    returns the boundary to within rounding."""
    lo, hi = lo.copy(), hi.copy()
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        p = pred(mid)
        lo = np.where(p, mid, lo)
        hi = np.where(p, hi, mid)
    return 0.5 * (lo + hi)


def lit_interval(origin: np.ndarray, dirs: np.ndarray, position: np.ndarray, spot: Spot, x0: Any,
                 x1: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi, meets) for rays origin + x dirs[k], x in [x0, x1] (x1 may be inf): the
    part inside the spot's forward cone is [lo, hi] where meets (measure zero otherwise)."""
    dirs = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    n = len(dirs)
    fr = ray_frame(origin, dirs, position, spot.axis)
    c = spot.cos_a
    x0 = np.broadcast_to(np.asarray(x0, dtype=np.float64), (n,)).copy()
    x1 = np.broadcast_to(np.asarray(x1, dtype=np.float64), (n,)).copy()
    scale = np.maximum(np.linalg.norm(np.asarray(position) - np.asarray(origin)), 1e-3)

    def x_of(s: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return np.where(s >= 1.0, np.inf, x0 + scale * s / (1.0 - s))

    def g(x: np.ndarray) -> np.ndarray:
        return fr.wa + x * fr.da - c * np.hypot(fr.h, x - fr.b)

    def gp(x: np.ndarray) -> np.ndarray:
        dist = np.hypot(fr.h, x - fr.b)
        return fr.da - c * np.where(dist > 0, (x - fr.b) / np.where(dist > 0, dist, 1.0), 0.0)

    with np.errstate(invalid="ignore", over="ignore"):  # g and g' at x = inf, where masked out
        return _lit_interval_search(x0, x1, scale, c, fr, x_of, g, gp)


def _lit_interval_search(x0, x1, scale, c, fr, x_of, g, gp):
    n = len(x0)
    finite = np.isfinite(x1)
    span = np.where(finite, x1 - x0, 1.0)
    s1 = np.where(finite, span / (scale + span), 1.0)
    s0 = np.zeros(n)
    # the maximum of the concave g on [x0, x1]
    gp0 = gp(x0)
    gp1 = np.where(finite, gp(np.where(finite, x1, 0.0)), fr.da - c)
    s_max = _bisect(lambda s: gp(x_of(s)) > 0, s0, s1)
    s_max = np.where(gp0 <= 0, 0.0, np.where(gp1 >= 0, s1, s_max))
    at_inf = s_max >= 1.0
    far = x0 + scale * 1e15
    g_inf = np.where(fr.da > c, np.inf, g(far))  # g(x) ~ x (d.a - c) + ... as x -> inf
    g_max = np.where(at_inf, g_inf, g(x_of(np.where(at_inf, 0.0, s_max))))
    meets = g_max > 0
    # entry: where g turns non-negative on [x0, x_max]
    g0 = g(x0)
    s_lo = _bisect(lambda s: g(x_of(s)) < 0, s0, s_max)
    lo = np.where(g0 >= 0, x0, x_of(s_lo))
    # exit: where g turns negative on [x_max, x1]
    g1 = np.where(finite, g(np.where(finite, x1, 0.0)), g_inf)
    s_hi = _bisect(lambda s: g(x_of(s)) >= 0, s_max, s1)
    hi = np.where(g1 >= 0, x1, x_of(s_hi))
    lo = np.where(meets, np.minimum(lo, hi), 0.0)
    hi = np.where(meets, hi, 0.0)
    return lo, hi, meets & (hi > lo)


# ---- the airlight of one spot along one ray ----------------------------------------------------------

def _psi_pieces(b: float, h: float, lo: float, hi: float) -> list[tuple[str, float, float]]:
    """The lit interval [lo, hi] as pieces in psi = atan2(h, b - x) (x <= b) and
    chi = atan2(h, x - b) (x >= b); each ("psi"|"chi", lower, upper) with lower < upper."""
    pieces = []
    if lo < b:
        top = min(hi, b)
        pieces.append(("psi", math.atan2(h, b - lo), math.atan2(h, b - top)))
    if hi > b:
        start = max(lo, b)
        chi_hi = 0.0 if math.isinf(hi) else math.atan2(h, hi - b)
        pieces.append(("chi", chi_hi, math.atan2(h, start - b)))
    return [p for p in pieces if p[2] > p[1]]


def _spot_unit_log(sigma: float, b: float, h: float, da: float, ma: float, cos_a: float, edge: float,
                   lo: float, hi: float) -> float:
    """log of int_lo^hi (I / I0) exp(-sigma (x + |S - p|)) / |S - p|^2 dx (-inf when 0)."""
    if not hi > lo:
        return -math.inf
    h = max(h, 1e-280)  # a ray through the centre: the same integral to 1e-280 m
    # T(x) = (x + |S - p| - b) / h = tan(psi / 2) = 1 / tan(chi / 2)
    t_lo = math.tan(0.5 * math.atan2(h, b - lo)) if lo <= b else 1.0 / math.tan(0.5 * math.atan2(h, lo - b))
    e = b + h * t_lo  # x + |S - p| at lo (the smallest light path on the piece)
    inv = 1.0 / (1.0 - cos_a)

    def prof(cos_t: float) -> float:
        return max((1.0 - edge) * (cos_t - cos_a) * inv + edge, 0.0)

    def f_psi(psi: float) -> float:
        cos_t = -math.cos(psi) * da - math.sin(psi) * ma
        return prof(cos_t) * math.exp(-sigma * h * (math.tan(0.5 * psi) - t_lo))

    def f_chi(chi: float) -> float:
        cos_t = math.cos(chi) * da - math.sin(chi) * ma
        half = math.tan(0.5 * chi)
        if half <= 0.0:
            return 0.0 if sigma > 0 else prof(cos_t)
        return prof(cos_t) * math.exp(-sigma * h * (1.0 / half - t_lo))

    total = err = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for kind, a, c in _psi_pieces(b, h, lo, hi):
            breaks = {a + (c - a) * k / 4.0 for k in range(1, 4)}
            if sigma * h > 0:
                for k in range(-2, 5):
                    tk = t_lo + 10.0 ** k / (sigma * h)
                    breaks.add(2.0 * math.atan(tk) if kind == "psi" else 2.0 * math.atan2(1.0, tk))
            edges = [a] + sorted(p for p in breaks if a < p < c) + [c]
            fun = f_psi if kind == "psi" else f_chi
            for p0, p1 in zip(edges[:-1], edges[1:]):
                value, e_abs = quad(fun, p0, p1, epsabs=0.0, epsrel=QUAD_EPSREL, limit=400)
                total += value
                err += e_abs
    if total <= 0.0:
        return -math.inf
    if not err <= 1e-8 * total:
        raise RuntimeError(f"spot reference quadrature did not converge: {total} +- {err}")
    return math.log(total / h) - sigma * e


@functools.lru_cache(maxsize=200_000)
def _spot_unit_log_cached(*args: float) -> float:
    return _spot_unit_log(*args)


def spot_unit_logs(sigma_t: float, origin: Sequence[float], dirs: np.ndarray, position: Sequence[float],
                   spot: Spot, x0: Any = 0.0, x1: Any = math.inf) -> np.ndarray:
    """Per ray (N,): log of int (I / I0) exp(-sigma_t (x + |S - p|)) / |S - p|^2 dx over the
    lit part of [x0, x1] (-inf when none); the lit intervals are found for all rays at once."""
    dirs = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    origin = np.asarray(origin, dtype=np.float64)
    position = np.asarray(position, dtype=np.float64)
    lo, hi, meets = lit_interval(origin, dirs, position, spot, x0, x1)
    fr = ray_frame(origin, dirs, position, spot.axis)
    out = np.full(len(dirs), -math.inf)
    for k in np.nonzero(meets)[0]:
        out[k] = _spot_unit_log_cached(float(sigma_t), float(fr.b[k]), float(fr.h[k]), float(fr.da[k]),
                                       float(fr.ma[k]), spot.cos_a, spot.edge, float(lo[k]), float(hi[k]))
    return out


def spot_airlight_log(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                      direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float = 0.0,
                      x1: float = math.inf) -> float:
    """log of the airlight (one channel, W/(m^2 sr)) of a spot (axial intensity
    `intensity`) over [x0, x1] of the ray origin + x direction (unit); -inf when 0."""
    if sigma_s <= 0 or intensity <= 0 or not x1 > x0:
        return -math.inf
    dirs = np.asarray(direction, dtype=np.float64)[None, :]
    unit = spot_unit_logs(sigma_t, origin, dirs, position, spot, x0, x1)[0]
    return math.log(sigma_s * intensity / (4.0 * math.pi)) + unit


def spot_airlight(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                  direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float = 0.0,
                  x1: float = math.inf) -> float:
    """The airlight of :func:`spot_airlight_log`; 0 where it underflows float64."""
    return math.exp(spot_airlight_log(sigma_t, sigma_s, intensity, origin, direction, position, spot, x0, x1))


def spot_airlight_riemann(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                          direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float,
                          x1: float, n: int = 2_000_000) -> float:
    """Brute force for checking: the midpoint rule with n points in x on [x0, x1] (finite)
    of the defining integrand, the cone tested at every point (no lit interval)."""
    origin = np.asarray(origin, dtype=np.float64)
    direction = np.asarray(direction, dtype=np.float64)
    position = np.asarray(position, dtype=np.float64)
    dx = (x1 - x0) / n
    total = 0.0
    for start in range(0, n, 250_000):
        x = x0 + (np.arange(start, min(n, start + 250_000)) + 0.5) * dx
        rel = origin[None, :] + x[:, None] * direction[None, :] - position[None, :]
        dist = np.linalg.norm(rel, axis=1)
        weight = profile((rel @ spot.axis) / dist, spot)
        total += float(np.sum(weight * np.exp(-sigma_t * (x + dist)) / dist ** 2))
    return sigma_s * intensity / (4.0 * math.pi) * total * dx


# ---- pixels -----------------------------------------------------------------------------------

def spot_core_radiance(ss: SpotScene, j: int, camera: np.ndarray) -> np.ndarray:
    """Radiance (3,) of lamp j's sphere as seen from `camera` (before attenuation)."""
    light = ss.sc.lights[j]
    spot = ss.spots[j]
    base = light.intensity / (math.pi * light.radius ** 2)
    if spot is None:
        return base
    return base * float(direction_profile(spot, light.position, camera))


def spot_direct(ss: SpotScene, point: np.ndarray, normal: np.ndarray, albedo: np.ndarray,
                lit: Sequence[bool]) -> np.ndarray:
    """Radiance (3,) leaving a Lambertian point from the spots' direct light (no glow)."""
    out = np.zeros(3)
    for j in ss.spot_indices:
        light, spot = ss.sc.lights[j], ss.spots[j]
        to_light = light.position - point
        dist = float(np.linalg.norm(to_light))
        if not lit[j] or dist <= 0.0:
            continue
        cos_s = float(to_light @ normal) / dist
        if cos_s <= 0:
            continue
        weight = float(direction_profile(spot, light.position, point))
        out += light.intensity * weight * cos_s / max(dist * dist, light.radius ** 2) * np.exp(
            -ss.sc.sigma_t * dist)
    return albedo / math.pi * out


def rays_spot_airlight(ss: SpotScene, dirs: np.ndarray, t_hit: np.ndarray) -> np.ndarray:
    """Airlight (N, 3) of all spots over the visible parts [x0, t_hit] of camera rays."""
    sc = ss.sc
    total = np.zeros((len(dirs), 3))
    for j in ss.spot_indices:
        light, spot = sc.lights[j], ss.spots[j]
        x0 = np.array([ray_light_geometry(sc.position, d, light)[2] for d in dirs])
        units: dict[float, np.ndarray] = {}
        for c in range(3):
            if sc.sigma_s[c] <= 0 or light.intensity[c] <= 0:
                continue
            sigma = float(sc.sigma_t[c])
            if sigma not in units:
                units[sigma] = spot_unit_logs(sigma, sc.position, dirs, light.position, spot, x0, t_hit)
            log_scale = math.log(sc.sigma_s[c] * light.intensity[c] / (4.0 * math.pi))
            total[:, c] += np.exp(log_scale + units[sigma])
    return total


def spot_pixel_radiance(ss: SpotScene, rows: Sequence[int], cols: Sequence[int], glow: bool = True,
                        airlight_on: bool = True) -> np.ndarray:
    """Reference radiance (N, 3) of the given pixels: points as airlight_reference, spots
    as above (no spot glow)."""
    sc = ss.sc
    points = ss.points_only()
    pidx = ss.point_indices
    dirs = camera_rays(sc, np.asarray(rows), np.asarray(cols))
    tr = trace(sc, dirs)
    out = np.zeros((len(dirs), 3))
    for k, d in enumerate(dirs):
        hid = int(tr.hit_id[k])
        t_hit = float(tr.t_hit[k])
        if hid == BACKGROUND:
            base = sc.background.copy()
        elif hid >= LAMP_BASE:
            base = spot_core_radiance(ss, hid - LAMP_BASE, sc.position)
        else:
            albedo = sc.surfaces[hid // 8].albedo
            base = surface_radiance(points, tr.point[k], tr.normal[k], albedo, tr.lit[pidx, k], glow=glow)
            base = base + spot_direct(ss, tr.point[k], tr.normal[k], albedo, tr.lit[:, k])
        value = base * transmittance(sc.sigma_t, t_hit)
        if airlight_on:
            value = value + ray_airlight(points, sc.position, d, t_hit)
        out[k] = value
    if airlight_on and len(dirs):
        out += rays_spot_airlight(ss, dirs, tr.t_hit)
    return out


# ---- pixel selection and comparison ------------------------------------------------------------------

@dataclass
class SpotGeometry:
    """Per pixel (H, W) facts used to choose and judge pixels."""

    trace: Trace
    smooth: np.ndarray  # away from edges, shadow boundaries, lamp cores and beam edges on surfaces
    degenerate: np.ndarray  # near-degenerate for some spot (silhouette, sliver, parallel to a wall)
    meets: np.ndarray  # (S, H, W) the visible part of the ray meets spot s's beam
    estimate: np.ndarray  # (H, W, 3) a cheap estimate of the radiance (no glow), for selection only


def _gauss_pieces_estimate(ss: SpotScene, dirs: np.ndarray, x0: np.ndarray, x1: np.ndarray, j: int,
                           lo: np.ndarray, hi: np.ndarray, nodes: int = 32) -> np.ndarray:
    """A rough vectorised estimate (N, 3) of light j's airlight on [lo, hi] (Gauss-Legendre
    in psi, no adaptivity): only used to rank pixels."""
    sc = ss.sc
    light, spot = sc.lights[j], ss.spots[j]
    axis = spot.axis if spot is not None else np.array([0.0, 0.0, 1.0])
    fr = ray_frame(sc.position, dirs, light.position, axis)
    h = np.maximum(fr.h, 1e-12)
    psi_lo = np.arctan2(h, fr.b - lo)
    psi_hi = np.where(np.isinf(hi), math.pi, np.arctan2(h, fr.b - np.where(np.isinf(hi), 0.0, hi)))
    xg, wg = np.polynomial.legendre.leggauss(nodes)
    total = np.zeros((len(dirs), 3))
    t_lo = np.tan(0.5 * psi_lo)
    for xi, wi in zip(xg, wg):
        psi = psi_lo + (psi_hi - psi_lo) * 0.5 * (xi + 1.0)
        weight = 0.5 * wi * (psi_hi - psi_lo)
        if spot is None:
            prof = np.ones(len(dirs))
        else:
            prof = profile(-np.cos(psi) * fr.da - np.sin(psi) * fr.ma, spot)
        with np.errstate(over="ignore", invalid="ignore"):
            path = h * (np.tan(0.5 * psi) - t_lo)
            term = np.exp(-np.outer(path, sc.sigma_t))
        total += np.nan_to_num(weight * prof)[:, None] * np.nan_to_num(term)
    with np.errstate(over="ignore", invalid="ignore"):
        e = lo + np.hypot(h, lo - fr.b)
        scale = np.exp(-np.outer(e, sc.sigma_t)) * (sc.sigma_s * light.intensity / (4 * math.pi))[None, :]
    return np.nan_to_num(total * scale / h[:, None])


def spot_geometry(ss: SpotScene, lamp_gap: float = 2.0) -> SpotGeometry:
    sc = ss.sc
    hh, ww = sc.height, sc.width
    smooth, tr = smooth_pixels(sc, lamp_gap=lamp_gap)
    dirs = camera_rays(sc)
    n = len(dirs)
    on_surface = (tr.hit_id >= 0) & (tr.hit_id < LAMP_BASE)
    degenerate = np.zeros(n, dtype=bool)
    meets_all = np.zeros((len(ss.spot_indices), hh, ww), dtype=bool)
    estimate = np.zeros((n, 3))
    for j, light in enumerate(sc.lights):
        spot = ss.spots[j]
        x0 = np.array([ray_light_geometry(sc.position, d, light)[2] for d in dirs])
        if spot is None:
            estimate += _gauss_pieces_estimate(ss, dirs, x0, tr.t_hit, j, x0, tr.t_hit)
            continue
        lo, hi, meets = lit_interval(sc.position, dirs, light.position, spot, x0, tr.t_hit)
        estimate += np.where(meets[:, None], _gauss_pieces_estimate(ss, dirs, x0, tr.t_hit, j, lo,
                                                                    np.where(meets, hi, lo + 1.0)), 0.0)
        fr = ray_frame(sc.position, dirs, light.position, spot.axis)
        ray_scale = np.abs(x0) + np.abs(fr.b) + fr.h
        with np.errstate(invalid="ignore"):
            sliver = meets & ((hi - lo) < SLIVER_FRACTION * ray_scale)
        parallel = meets & (np.abs(fr.da ** 2 - spot.cos_a ** 2) < PARALLEL_LIMIT)
        m2 = meets.reshape(hh, ww)
        meets_all[ss.spot_indices.index(j)] = m2
        edge = np.zeros((hh, ww), dtype=bool)  # the 3x3 neighbourhood disagrees on meeting the beam
        pad = np.pad(m2, 1, mode="edge")
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                edge |= pad[1 + dy:hh + 1 + dy, 1 + dx:ww + 1 + dx] != m2
        degenerate |= sliver | parallel | edge.ravel()
        # beam edges on surfaces are excluded like shadow boundaries
        in_beam = np.zeros(n, dtype=bool)
        in_beam[on_surface] = direction_profile(spot, light.position, tr.point[on_surface]) > 0
        in_beam = in_beam.reshape(hh, ww)
        pad = np.pad(in_beam, 1, mode="edge")
        same = np.ones((hh, ww), dtype=bool)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                same &= pad[1 + dy:hh + 1 + dy, 1 + dx:ww + 1 + dx] == in_beam
        smooth &= same
    # direct light and lamp cores in the estimate
    pidx = ss.point_indices
    points = ss.points_only()
    for k in np.nonzero(on_surface)[0]:
        albedo = sc.surfaces[int(tr.hit_id[k]) // 8].albedo
        base = surface_radiance(points, tr.point[k], tr.normal[k], albedo, tr.lit[pidx, k], glow=False)
        base = base + spot_direct(ss, tr.point[k], tr.normal[k], albedo, tr.lit[:, k])
        estimate[k] += base * transmittance(sc.sigma_t, float(tr.t_hit[k]))
    return SpotGeometry(tr, smooth, degenerate.reshape(hh, ww), meets_all, estimate.reshape(hh, ww, 3))


@dataclass
class SpotSamples:
    regular: Samples  # judged by relative error (airlight_reference.compare)
    peak: float  # the reference's maximum over the compared pixels (about the image maximum)
    rows_degenerate: np.ndarray
    cols_degenerate: np.ndarray
    reference_degenerate: np.ndarray  # (M, 3)


_SAMPLE_CACHE: dict[tuple[str, int, int, int], SpotSamples] = {}


def spot_samples(scene: dict[str, Any], n: int = 40, seed: int = 0, n_bright: int = 6,
                 n_degenerate: int = 12) -> SpotSamples:
    """Pixels to compare and their reference radiance (cached per scene). Among the pixels
    away from geometric edges, shadow boundaries, beam edges on surfaces and lamp cores,
    whose estimated radiance exceeds DIM_FRACTION of the maximum over such pixels (the
    estimate is the reference's own rough quadrature, not the renderer): ``n`` regular
    pixels, the ``n_bright`` brightest and the rest at random, judged by relative error;
    and up to ``n_degenerate`` near-degenerate ones (rays almost tangent to a cone, lit
    slivers, rays almost parallel to a cone wall, pixels next to a beam silhouette) judged
    by absolute error relative to the image maximum. Why: there the lit interval is
    ill-conditioned (a float32 direction error of 6e-8 moves a tangent ray's entry and
    exit by O(sqrt(6e-8)) of its length), so no float32 renderer can meet a relative
    bound, but the radiance itself is small and continuous across the silhouette."""
    key = (json.dumps(scene, sort_keys=True), n, seed, n_degenerate)
    if key in _SAMPLE_CACHE:
        return _SAMPLE_CACHE[key]
    ss = parse_spot_scene(scene)
    sc = ss.sc
    geo = spot_geometry(ss)
    brightness = geo.estimate.max(axis=2)
    assert geo.smooth.any(), "no pixel away from edges and lamps: fix the test scene"
    peak_estimate = float(brightness[geo.smooth].max())
    candidates = geo.smooth & (brightness > DIM_FRACTION * peak_estimate)
    rng = np.random.default_rng(seed)
    rows, cols = np.nonzero(candidates & ~geo.degenerate)
    order = np.argsort(-brightness[rows, cols], kind="stable")
    bright, rest = order[:n_bright], order[n_bright:]
    pick = np.concatenate([bright, rng.choice(rest, size=min(len(rest), n - len(bright)), replace=False)])
    rows, cols = rows[pick], cols[pick]
    ref = spot_pixel_radiance(ss, rows, cols)
    peak = float(ref.max())
    hit = geo.trace.hit_id.reshape(sc.height, sc.width)[rows, cols]
    regular = Samples(rows, cols, ref, DIM_FRACTION * peak, hit)
    drows, dcols = np.nonzero(geo.smooth & geo.degenerate)
    if len(drows) > n_degenerate:
        pick = rng.choice(len(drows), size=n_degenerate, replace=False)
        drows, dcols = drows[pick], dcols[pick]
    dref = spot_pixel_radiance(ss, drows, dcols) if len(drows) else np.zeros((0, 3))
    samples = SpotSamples(regular, peak, drows, dcols, dref)
    _SAMPLE_CACHE[key] = samples
    return samples


def spot_compare(image: np.ndarray, samples: SpotSamples, rel_tol: float = REL_TOL, abs_tol: float = REL_TOL,
                 min_values: int = 20, label: str = "") -> float:
    """Relative error <= rel_tol on the regular pixels (airlight_reference.compare), and
    absolute error <= abs_tol * peak on the near-degenerate ones; returns the worst
    relative error of the regular pixels."""
    worst = compare(image, samples.regular, rel_tol=rel_tol, min_values=min_values, label=label)
    if len(samples.rows_degenerate):
        got = np.asarray(image, dtype=np.float64)[samples.rows_degenerate, samples.cols_degenerate]
        ref = samples.reference_degenerate
        assert np.all(np.isfinite(got)), f"{label}: non-finite radiance at near-degenerate pixels"
        err = np.abs(got - ref) / samples.peak
        k, c = np.unravel_index(np.argmax(err), err.shape)
        row, col = samples.rows_degenerate[k], samples.cols_degenerate[k]
        assert err[k, c] <= abs_tol, (
            f"{label}: near-degenerate pixel (row {row}, col {col}) "
            f"channel {c}: rendered {got[k, c]:.7e}, reference {ref[k, c]:.7e}, error {err[k, c]:.3e} of the "
            f"image maximum {samples.peak:.4e}")
    return worst


# ---- scene helpers ------------------------------------------------------------------------------

def spot(position: Sequence[float], direction: Sequence[float], intensity: Any = 100.0,
         cone_angle: float = 30.0, edge: float = DEFAULT_EDGE,
         radius: float = DEFAULT_RADIUS) -> dict[str, Any]:
    """A spot light for a scene dict (the renderer's format)."""
    return {"type": "spot", "position": [float(v) for v in position],
            "direction": [float(v) for v in direction], "intensity": intensity,
            "cone_angle": float(cone_angle), "edge": float(edge), "radius": float(radius)}
