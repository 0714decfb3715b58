"""Independent float64 reference for spotlights and headlights (effects/spotlights/physics.md).

Written from the model's definition, not from the shaders or effects/spotlights/docs/spot_table.md: no
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
  exp(-sigma_t d), hard shadows (airlight_reference.trace), and albedo / pi E_glow, the
  light it scatters once onto the surface point P (normal n), not shadowed:
  ``E_glow = sigma_s / (4 pi) int I(theta_y) exp(-sigma_t (|y - S| + |y - P|)) / |y - S|^2
  max(n.(y - P), 0) / |y - P|^3 dV`` over all space (:func:`spot_glow_unit`). Written as
  the cosine-weighted hemisphere integral about P of the spot's airlight along the rays
  leaving P, in polar coordinates (alpha, beta) about the direction u from P to S (the
  1/alpha peak of rays passing the lamp meets the Jacobian sin(alpha)); along a ray the
  variable is the angle psi at S between S->P and S->y, in which dt / |y - S|^2 =
  dpsi / (D sin alpha), the exponent is 2 sigma D sin(alpha/2) sin(psi/2) / cos((alpha +
  psi)/2) above exp(-sigma D), and the lit part is an exact arc (the emission direction
  runs along a great circle from -u). Each of the three integrals is Gauss-Legendre on
  pieces between exact break points (the hemisphere's edge, the cone's circle of
  directions, the great circles through u tangent to it, their crossings; exponent
  levels and a geometric grading to infinity along the ray), each half piece mapped by a
  smoothstep (square-root end points) or an exponential grading (layers of light from
  far along the cone's wall, nearby complex singularities). Measured (test_spot_glow.py):
  doubling the nodes changes it by < 1e-6 (about 1e-7 or less typically); two opposite
  90-degree q = 1 spots give airlight_reference's point-lamp glow within 1e-7; its ray
  integrals equal this module's view-ray airlight within 1e-8; scipy nquad of the volume
  integral about the lamp agrees within 1e-7; about 30 ms per point and channel.
* Phase functions (medium.phase, :class:`Phase`; default isotropic, which leaves every result
  above unchanged): every integrand is multiplied by P = 4 pi p(cos theta), evaluated directly
  at the scattering angle (no substitution, no table). theta is the angle between the light's
  propagation directions before and after scattering: along a view ray, between (p - S)/|p - S|
  and -d (cos theta = cos psi = -cos chi in the variables above; looking into a headlight is
  forward scattering); in the glow, between y - S and P - y (cos theta = cos(alpha + psi)).
  Narrow HG lobes (|g| >= 0.5, width w = 1 - |g|) add break points at their scale: in psi or
  chi along view rays; in the glow in alpha, in beta (next to the tangent azimuths for a
  forward lobe when P is near the cone's wall, and next to the crossings of the cone's circle
  of directions for a backward lobe) and along each ray (a geometric grid in psi from
  hypot(w, alpha), and z = pi - theta at multiples of w); any phase that varies adds z = 2^-k
  along the glow's rays. Measured (test_phase_spot.py): the view-ray airlight equals scipy quad
  of the x-space integral over the ray-cone quadratic's interval to about 1e-14 (HG -0.9 to
  0.95, Rayleigh, hg2); HG g = 0 is the isotropic result exactly; doubling the glow's nodes
  moves it < 1e-6; two opposite 90-degree q = 1 spots are the point lamp with the same phase;
  scipy nquad of the volume integral agrees within 1e-6.
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
from scipy.integrate import IntegrationWarning, nquad, quad

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


# ---- phase functions -----------------------------------------------------------------------------

HG_G_LIMIT = 0.999  # the renderer clamps |g| to this (scene format: g in (-1, 1))


def _hg(g: float, cos_t: Any) -> Any:
    """4 pi p_HG(cos theta) = (1 - g^2) / (1 + g^2 - 2 g cos theta)^1.5 (float or array)."""
    if isinstance(cos_t, float):
        return (1.0 - g * g) / (1.0 + g * g - 2.0 * g * cos_t) ** 1.5
    cos_t = np.asarray(cos_t, dtype=np.float64)
    return (1.0 - g * g) / (1.0 + g * g - 2.0 * g * cos_t) ** 1.5


@dataclass(frozen=True)
class Phase:
    """A phase function as 4 pi p(cos theta) (so isotropic is 1), theta the angle between the
    light's propagation directions before and after scattering (0: forward). Frozen, so it
    can key caches. Any callable taking cos theta (float or array) and returning 4 pi p can
    be used wherever a phase is accepted; an optional ``peaks`` attribute (as here) names
    narrow lobes so that the quadratures put break points at their scale.

    kind "isotropic"; "hg": Henyey-Greenstein with g; "rayleigh": 3/4 (1 + cos^2 theta);
    "hg2": weight HG(g) + (1 - weight) HG(g2)."""

    kind: str = "isotropic"
    g: float = 0.0
    g2: float = 0.0
    weight: float = 1.0

    def __call__(self, cos_t: Any) -> Any:
        if self.kind == "hg":
            return _hg(self.g, cos_t)
        if self.kind == "hg2":
            return self.weight * _hg(self.g, cos_t) + (1.0 - self.weight) * _hg(self.g2, cos_t)
        if self.kind == "rayleigh":
            if isinstance(cos_t, float):
                return 0.75 * (1.0 + cos_t * cos_t)
            cos_t = np.asarray(cos_t, dtype=np.float64)
            return 0.75 * (1.0 + cos_t * cos_t)
        if self.kind == "isotropic":
            return 1.0 if isinstance(cos_t, float) else np.ones_like(np.asarray(cos_t, dtype=np.float64))
        raise ValueError(f"unknown phase kind {self.kind!r}")

    @property
    def constant(self) -> bool:
        """4 pi p = 1 everywhere (isotropic, or HG lobes with g = 0)."""
        return self.kind == "isotropic" or (self.kind in ("hg", "hg2") and self.g == 0.0
                                            and (self.kind == "hg" or self.g2 == 0.0))

    @property
    def peaks(self) -> tuple[tuple[float, float], ...]:
        """Narrow lobes as (+1 forward | -1 backward, angular width ~ 1 - |g|): HG lobes with
        |g| >= 0.5 (wider ones need no break points)."""
        lobes = {"hg": [(self.g, 1.0)], "hg2": [(self.g, self.weight), (self.g2, 1.0 - self.weight)]}
        out = []
        for g, w in lobes.get(self.kind, []):
            if abs(g) >= 0.5 and w != 0.0:
                out.append((1.0 if g > 0 else -1.0, 1.0 - abs(g)))
        return tuple(out)


ISOTROPIC = Phase()


def is_isotropic(phase: Any) -> bool:
    """True for None (the default everywhere) and the isotropic Phase."""
    return phase is None or (isinstance(phase, Phase) and phase.kind == "isotropic")


def phase_peaks(phase: Any) -> tuple[tuple[float, float], ...]:
    return tuple(getattr(phase, "peaks", ())) if phase is not None else ()


def phase_varies(phase: Any) -> bool:
    """False for None and constant Phases; True for any other phase (callables included)."""
    return phase is not None and not getattr(phase, "constant", False)


def parse_phase(value: Any) -> Phase:
    """medium.phase of a scene dict (absent or None: isotropic); |g| clamped to HG_G_LIMIT
    as the renderer does."""
    if value is None:
        return ISOTROPIC
    kind = value.get("type", "isotropic")

    def g_of(key: str) -> float:
        return float(np.clip(float(value[key]), -HG_G_LIMIT, HG_G_LIMIT))

    if kind == "isotropic":
        return ISOTROPIC
    if kind == "hg":
        return Phase("hg", g_of("g"))
    if kind == "rayleigh":
        return Phase("rayleigh")
    if kind == "hg2":
        return Phase("hg2", g_of("forward_g"), g_of("backward_g"), float(value["forward_weight"]))
    raise ValueError(f"spot_reference: unknown phase type {kind!r}")


def phase_dict(phase: Phase) -> dict[str, Any]:
    """The scene format's medium.phase for a Phase."""
    if phase.kind == "hg":
        return {"type": "hg", "g": phase.g}
    if phase.kind == "hg2":
        return {"type": "hg2", "forward_g": phase.g, "backward_g": phase.g2, "forward_weight": phase.weight}
    return {"type": phase.kind}


@dataclass
class SpotScene:
    sc: Scene  # every light (points and spots) as an airlight_reference.Light
    spots: list[Spot | None]  # per light: None for a point light
    phase: Any = None  # the medium's phase (None: isotropic); see Phase

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
    medium = scene.get("medium")
    phase = parse_phase(medium.get("phase") if isinstance(medium, Mapping) else None)
    return SpotScene(parse_scene(scene), spots, None if is_isotropic(phase) else phase)


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
                   lo: float, hi: float, phase: Any = None) -> float:
    """log of int_lo^hi (I / I0) P exp(-sigma (x + |S - p|)) / |S - p|^2 dx (-inf when 0), with
    P = 4 pi p(cos theta) the phase (1 when None), cos theta = ((p - S)/|p - S|).(-d) =
    cos(psi) = -cos(chi): psi is the scattering angle itself."""
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
        value = prof(cos_t) * math.exp(-sigma * h * (math.tan(0.5 * psi) - t_lo))
        return value if phase is None else value * phase(math.cos(psi))

    def f_chi(chi: float) -> float:
        cos_t = math.cos(chi) * da - math.sin(chi) * ma
        half = math.tan(0.5 * chi)
        if half <= 0.0:
            value = 0.0 if sigma > 0 else prof(cos_t)
        else:
            value = prof(cos_t) * math.exp(-sigma * h * (1.0 / half - t_lo))
        return value if phase is None else value * phase(-math.cos(chi))

    total = err = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for kind, a, c in _psi_pieces(b, h, lo, hi):
            breaks = {a + (c - a) * k / 4.0 for k in range(1, 4)}
            if sigma * h > 0:
                for k in range(-2, 5):
                    tk = t_lo + 10.0 ** k / (sigma * h)
                    breaks.add(2.0 * math.atan(tk) if kind == "psi" else 2.0 * math.atan2(1.0, tk))
            for side, width in phase_peaks(phase):  # a narrow lobe at psi = 0 (forward) or chi = 0
                if (side > 0) == (kind == "psi"):
                    breaks.update(width * f for f in (0.125, 0.5, 2.0, 8.0))
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
                   spot: Spot, x0: Any = 0.0, x1: Any = math.inf, phase: Any = None) -> np.ndarray:
    """Per ray (N,): log of int (I / I0) P exp(-sigma_t (x + |S - p|)) / |S - p|^2 dx over the
    lit part of [x0, x1] (-inf when none); the lit intervals are found for all rays at once.
    P = 4 pi p(cos theta) is the phase (a Phase or any callable of cos theta; None or
    isotropic: 1), theta between the light's direction (p - S)/|p - S| and -d."""
    phase = None if is_isotropic(phase) else phase
    dirs = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    origin = np.asarray(origin, dtype=np.float64)
    position = np.asarray(position, dtype=np.float64)
    lo, hi, meets = lit_interval(origin, dirs, position, spot, x0, x1)
    fr = ray_frame(origin, dirs, position, spot.axis)
    out = np.full(len(dirs), -math.inf)
    for k in np.nonzero(meets)[0]:
        out[k] = _spot_unit_log_cached(float(sigma_t), float(fr.b[k]), float(fr.h[k]), float(fr.da[k]),
                                       float(fr.ma[k]), spot.cos_a, spot.edge, float(lo[k]), float(hi[k]),
                                       phase)
    return out


def spot_airlight_log(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                      direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float = 0.0,
                      x1: float = math.inf, phase: Any = None) -> float:
    """log of the airlight (one channel, W/(m^2 sr)) of a spot (axial intensity
    `intensity`) over [x0, x1] of the ray origin + x direction (unit); -inf when 0.
    `phase`: see :func:`spot_unit_logs` (default isotropic)."""
    if sigma_s <= 0 or intensity <= 0 or not x1 > x0:
        return -math.inf
    dirs = np.asarray(direction, dtype=np.float64)[None, :]
    unit = spot_unit_logs(sigma_t, origin, dirs, position, spot, x0, x1, phase)[0]
    return math.log(sigma_s * intensity / (4.0 * math.pi)) + unit


def spot_airlight(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                  direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float = 0.0,
                  x1: float = math.inf, phase: Any = None) -> float:
    """The airlight of :func:`spot_airlight_log`; 0 where it underflows float64."""
    return math.exp(spot_airlight_log(sigma_t, sigma_s, intensity, origin, direction, position, spot, x0, x1,
                                      phase))


def spot_airlight_riemann(sigma_t: float, sigma_s: float, intensity: float, origin: Sequence[float],
                          direction: Sequence[float], position: Sequence[float], spot: Spot, x0: float,
                          x1: float, n: int = 2_000_000, phase: Any = None) -> float:
    """Brute force for checking: the midpoint rule with n points in x on [x0, x1] (finite)
    of the defining integrand, the cone tested at every point (no lit interval); `phase`
    (4 pi p) evaluated at cos theta = -((p - S)/|p - S|).d."""
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
        if not is_isotropic(phase):
            weight = weight * phase(-(rel @ direction) / dist)
        total += float(np.sum(weight * np.exp(-sigma_t * (x + dist)) / dist ** 2))
    return sigma_s * intensity / (4.0 * math.pi) * total * dx


# ---- the light a spot scatters onto a surface (its glow) ---------------------------------------------

# Gauss-Legendre nodes per half piece in alpha and in beta, and per piece along the ray (see
# spot_glow_unit); doubling all three changes the glow by < 1e-6 relative (test_spot_glow.py).
GLOW_NODES = (12, 12, 16)
_GLOW_GRADE = 4.0  # e-folds of the exponential map towards a break point with a layer
_GLOW_ALPHA_PIECE = 0.6  # radians: no alpha piece is wider
_GLOW_RAY_LEVELS = (0.25, 1.0, 4.0, 16.0)  # break points along a ray: excess optical path above its start
_GLOW_RAY_CUT = 64.0  # ... and where the ray's integral stops (exp(-64) of its start)
# kinds of break point (a value >= 0 is the distance of a nearby complex singularity: graded to it)
_SMOOTH = -1.0  # an algebraic end point (a square root, a kink): smoothstep map
_PLAIN = -2.0  # a regular point: plain Gauss-Legendre
_FINE = 0.0  # a layer (light from far along the cone's wall): graded over _GLOW_GRADE e-folds
# with a phase (lobe width w = 1 - |g|, see Phase.peaks): break points in alpha at w * these
# (forward lobe) or pi - w * these (backward); in beta at +- w 2^k around the tangent azimuths
# (forward lobe, P near the wall) and the crossings of the cone's circle of directions (backward
# lobe); along a ray at z = 2^-k for a phase that varies at all, at psi = hypot(w, alpha) 2^k
# (forward lobe) and z = w * these (backward lobe, towards infinity). Chosen against a doubled-node
# run with denser break sets over 43 configurations: all within 1e-6 of it, 2-3x the isotropic cost.
_LOBE_ALPHA = (0.25, 2.0)
_LOBE_BETA_TANGENT = (-1, 1)
_LOBE_BETA_CROSSING = (-1, 1)
_LOBE_WALL_GAP = 2.0  # tangent-azimuth breaks only when P is within this many lobe widths of the wall
_PHASE_Z = range(-1, 4)
_LOBE_Z_FORWARD = range(-2, 7, 2)
_LOBE_Z_BACKWARD = (0.125, 0.5, 2.0, 8.0)


@dataclass
class GlowFrame:
    """A surface point P (unit normal n) and a spot at S in the polar frame about u = (S - P)/D:
    a direction from P is w = cos(alpha) u + sin(alpha) (cos(beta) e1 + sin(beta) e2), with e1
    along the part of n across u, so n.w = cos(alpha) cos_s + sin(alpha) sin_s cos(beta); the
    spot's axis is a = cos(gamma) u + sin(gamma) (cos(beta_a) e1 + sin(beta_a) e2)."""

    dist: float  # D
    u: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    cos_s: float  # n.u
    sin_s: float
    cos_g: float  # a.u
    sin_g: float
    beta_a: float
    cos_a: float  # the spot's cos A
    edge: float  # q


def glow_frame(position: Any, spot: Spot, point: Any, normal: Any) -> GlowFrame:
    rel = np.asarray(position, dtype=np.float64) - np.asarray(point, dtype=np.float64)
    dist = float(np.linalg.norm(rel))
    if not dist > 0.0:
        raise ValueError("spot glow: the surface point is the lamp's centre")
    u = rel / dist
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    cos_s = float(np.clip(n @ u, -1.0, 1.0))
    across = n - cos_s * u
    if np.linalg.norm(across) > 1e-12:
        e1 = across / np.linalg.norm(across)
    else:
        t = np.cross(u, [1.0, 0.0, 0.0])
        if np.linalg.norm(t) < 0.5:
            t = np.cross(u, [0.0, 1.0, 0.0])
        e1 = t / np.linalg.norm(t)
    e2 = np.cross(u, e1)
    a1, a2 = float(spot.axis @ e1), float(spot.axis @ e2)
    return GlowFrame(dist, u, e1, e2, cos_s, math.sqrt(max(0.0, 1.0 - cos_s * cos_s)), float(spot.axis @ u),
                     math.hypot(a1, a2), math.atan2(a2, a1), spot.cos_a, spot.edge)


def glow_directions(fr: GlowFrame, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Unit directions (N, 3) from P at polar angles (alpha, beta)."""
    alpha, beta = np.asarray(alpha, dtype=np.float64), np.asarray(beta, dtype=np.float64)
    across = np.cos(beta)[:, None] * fr.e1 + np.sin(beta)[:, None] * fr.e2
    return np.cos(alpha)[:, None] * fr.u + np.sin(alpha)[:, None] * across


def _wrap(angle: Any) -> np.ndarray:
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


@functools.lru_cache(maxsize=32)
def _unit_gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def _half_rule(width: np.ndarray, kind: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (fractions of the width, from the outer end) and weights (..., n) of half pieces
    whose outer end is a break point of the given kind."""
    s, sw = _unit_gauss(n)
    smooth, smooth_w = s * s * (3.0 - 2.0 * s), sw * 6.0 * s * (1.0 - s)
    with np.errstate(divide="ignore", invalid="ignore"):
        folds = np.where(kind > 0, np.log(np.maximum(width, 1e-300) / np.where(kind > 0, kind, 1.0)) + 1.0,
                         _GLOW_GRADE)
    folds = np.clip(folds, 1.0, _GLOW_GRADE)[..., None]
    graded = np.expm1(folds * s) / np.expm1(folds)
    graded_w = folds * sw * np.exp(folds * s) / np.expm1(folds)
    is_smooth, is_plain = (kind == _SMOOTH)[..., None], (kind == _PLAIN)[..., None]
    return (np.where(is_smooth, smooth, np.where(is_plain, s, graded)),
            np.where(is_smooth, smooth_w, np.where(is_plain, sw, graded_w)))


def _piece_rule(edges: np.ndarray, kinds: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights (..., K - 1, 2 n) on the pieces between sorted break points (..., K):
    each piece is cut at its middle and each half mapped according to its outer end."""
    lo, hi = edges[..., :-1], edges[..., 1:]
    half = 0.5 * (hi - lo)
    t0, w0 = _half_rule(half, kinds[..., :-1], n)
    t1, w1 = _half_rule(half, kinds[..., 1:], n)
    nodes = np.concatenate([lo[..., None] + half[..., None] * t0, hi[..., None] - half[..., None] * t1],
                           axis=-1)
    weights = np.concatenate([half[..., None] * w0, half[..., None] * w1], axis=-1)
    return nodes, weights


def _tangent_azimuths(fr: GlowFrame) -> list[float]:
    """Azimuths beta of the great circles through u that touch the cone's circle of
    directions (where the lit length of the rays grows like a square root)."""
    c2, g2 = fr.cos_a * fr.cos_a, fr.cos_g * fr.cos_g
    if not (c2 >= g2 * (1.0 - 1e-12) and fr.sin_g > 0.0):  # equal: P on the wall, tangent at -u (or u)
        return []
    d = math.acos(min(1.0, math.sqrt(max(c2 - g2, 0.0)) / fr.sin_g))
    return [fr.beta_a + s for s in (d, -d, math.pi - d, math.pi + d)]


def _alpha_breaks(fr: GlowFrame, sigma: float, normal: np.ndarray, axis: np.ndarray,
                  phase: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Break points in alpha (sorted) and their kinds: the hemisphere's extent, where the
    horizon's circle and the cone's circle of directions enter or leave the alpha circles,
    where they cross each other and the tangent great circles, the tangent points, and, in
    thick fog, the scale 1/(sigma D) about alpha = 0."""
    theta_s = math.acos(fr.cos_s)
    gamma = math.atan2(fr.sin_g, fr.cos_g)
    cone = math.acos(fr.cos_a)
    a_min, a_max = max(0.0, theta_s - math.pi / 2), min(math.pi, theta_s + math.pi / 2)
    cand = [(math.pi / 2 - theta_s, _SMOOTH), (1.5 * math.pi - theta_s, _SMOOTH)]
    cand += [(v, _FINE) for v in (gamma - cone, cone - gamma, gamma + cone, 2.0 * math.pi - gamma - cone)]
    for bt in _tangent_azimuths(fr):
        cand.append((math.atan2(-fr.cos_s, fr.sin_s * math.cos(bt)) % math.pi, _SMOOTH))  # meets the horizon
        phi = math.atan2(fr.sin_g * math.cos(bt - fr.beta_a), -fr.cos_g)
        cand.append((math.pi - (phi + 2.0 * math.pi if phi < -math.pi / 2 else phi), _FINE))  # tangent point
    na = float(normal @ axis)  # the horizon meets the cone's circle: w.n = 0, w.a = cos A
    if 1.0 - na * na > 1e-14:
        base = fr.cos_a / (1.0 - na * na) * (axis - na * normal)
        rest = 1.0 - float(base @ base)
        if rest >= 0.0:
            side = np.cross(normal, axis)
            side = side / np.linalg.norm(side)
            for sgn in (1.0, -1.0):
                w = base + sgn * math.sqrt(rest) * side
                cand.append((math.acos(float(np.clip(w @ fr.u, -1.0, 1.0))), _FINE))
    if a_min == 0.0 and sigma * fr.dist > 1.0:
        cand += [(4.0 ** k / (sigma * fr.dist), _PLAIN) for k in (-2, -1, 0, 1)]
    for side, width in phase_peaks(phase):  # the scattering angle alpha + psi is >= alpha: a
        for f in _LOBE_ALPHA:  # forward lobe shapes small alpha, a backward one alpha near pi
            cand.append((width * f if side > 0 else math.pi - width * f, _PLAIN))
    points = {a_min: _FINE if a_min == 0.0 else _SMOOTH, a_max: _SMOOTH}
    for value, kind in cand:
        if a_min < value < a_max:
            points[value] = max(points.get(value, kind), kind)
    keys = sorted(points)
    for lo, hi in zip(keys[:-1], keys[1:]):
        m = int(math.ceil((hi - lo) / _GLOW_ALPHA_PIECE))
        for j in range(1, m):
            points.setdefault(lo + (hi - lo) * j / m, _PLAIN)
    keys = sorted(points)
    return np.array(keys), np.array([points[k] for k in keys])


def _beta_breaks(fr: GlowFrame, alpha: np.ndarray, phase: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """Per alpha (N,): break points in beta (N, K) (sorted; a full circle ends at its first
    point + 2 pi) and their kinds: the horizon, the tangent great circles, the cone's circle
    of directions, and nearby complex singularities (the circle almost reached; the lit arc
    swinging fast where a is almost perpendicular to the ray's plane)."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    smooth = np.full_like(alpha, _SMOOTH)
    with np.errstate(divide="ignore", invalid="ignore"):
        c_max = -ca * fr.cos_s / (sa * fr.sin_s)
        c_cone = (fr.cos_a - ca * fr.cos_g) / (sa * fr.sin_g)
    b_max = np.where(np.isnan(c_max), np.where(ca * fr.cos_s > 0, math.pi, 0.0),
                     np.arccos(np.clip(np.nan_to_num(c_max), -1.0, 1.0)))
    full = b_max >= math.pi
    opposite = float(_wrap(fr.beta_a + math.pi))  # a plain point for full circles
    cols = [np.where(full, opposite, -b_max), np.where(full, opposite, b_max)]
    kinds = [np.where(full, _PLAIN, _SMOOTH)] * 2
    # a forward lobe with P near the wall: the lit start psi_lo(beta) leaves 0 at a tangent azimuth,
    # sweeping the lobe over a small range of beta (small alpha only)
    wall_gap = abs(math.acos(float(np.clip(-fr.cos_g, -1.0, 1.0))) - math.acos(fr.cos_a))
    lobes = [width for side, width in phase_peaks(phase) if side > 0 and wall_gap < _LOBE_WALL_GAP * width]
    for bt in _tangent_azimuths(fr):
        cols.append(np.full_like(alpha, float(_wrap(bt))))
        kinds.append(smooth)
        for width in lobes:
            near = alpha < 16.0 * width
            for k in _LOBE_BETA_TANGENT:
                for sgn in (1.0, -1.0):
                    cols.append(np.where(near, _wrap(bt + sgn * width * 2.0 ** k), cols[0]))
                    kinds.append(np.where(near, _PLAIN, kinds[0]))
    crosses = np.abs(c_cone) <= 1.0
    d = np.arccos(np.clip(np.nan_to_num(c_cone), -1.0, 1.0))
    for sgn in (1.0, -1.0):
        cols.append(np.where(crosses, _wrap(fr.beta_a + sgn * d), cols[0]))
        kinds.append(np.where(crosses, _FINE, kinds[0]))
        # a backward lobe: whether the far end of the ray is lit changes at the crossing, and
        # the lobe (at z < width) makes that part weigh over a small range of beta
        for side, width in phase_peaks(phase):
            if side < 0:
                for k in _LOBE_BETA_CROSSING:
                    for off in (1.0, -1.0):
                        cols.append(np.where(crosses, _wrap(fr.beta_a + sgn * d + off * width * 2.0 ** k),
                                             cols[0]))
                        kinds.append(np.where(crosses, _PLAIN, kinds[0]))
    near = np.arccosh(np.clip(np.abs(np.nan_to_num(c_cone, nan=10.0, posinf=10.0, neginf=10.0)), 1.0, 10.0))
    near_ok = ~crosses & (near < 1.0)
    cols.append(np.where(near_ok, _wrap(fr.beta_a + np.where(c_cone < 0, math.pi, 0.0)), cols[0]))
    kinds.append(np.where(near_ok, near, kinds[0]))
    scale = math.asinh(abs(fr.cos_g) / fr.sin_g) if fr.sin_g > 0 else math.inf
    if fr.cos_g ** 2 > fr.cos_a ** 2 and fr.sin_g > 0:
        scale = min(scale, math.asinh(math.sqrt(fr.cos_g ** 2 - fr.cos_a ** 2) / fr.sin_g))
    if scale < 1.0:
        for sgn in (1.0, -1.0):
            cols.append(np.full_like(alpha, float(_wrap(fr.beta_a + sgn * math.pi / 2))))
            kinds.append(np.full_like(alpha, scale))
    lim = np.where(full, math.pi, b_max)[:, None]
    br, kd = np.stack(cols, axis=1), np.stack(kinds, axis=1)
    kd = np.where((br < -lim) | (br > lim), _SMOOTH, kd)
    br = np.clip(br, -lim, lim)
    order = np.argsort(br, axis=1, kind="stable")
    br, kd = np.take_along_axis(br, order, axis=1), np.take_along_axis(kd, order, axis=1)
    br = np.concatenate([br, np.where(full, br[:, 0] + 2.0 * math.pi, br[:, -1])[:, None]], axis=1)
    kd = np.concatenate([kd, np.where(full, kd[:, 0], kd[:, -1])[:, None]], axis=1)
    return br, kd


def glow_ray_units(fr: GlowFrame, sigma: float, alpha: np.ndarray, beta: np.ndarray,
                   nodes: int = GLOW_NODES[2], phase: Any = None) -> np.ndarray:
    """Per direction (alpha, beta) from P: J = int (I / I0) P exp(-x) dpsi over the lit part of
    the ray, psi the angle at S between S->P and S->y (0 at P, pi - alpha at infinity) and
    x = sigma (t + |y - S| - D); the airlight of the spot along the ray from P is then
    sigma_s I0 / (4 pi) exp(-sigma D) / (D sin alpha) J (dt / |y - S|^2 = dpsi / (D sin alpha)).
    P = 4 pi p(cos theta) is the phase (None: 1) for light going S -> y -> P: theta is the
    angle between y - S and P - y, cos theta = cos(alpha + psi) = -cos(z) below (forward
    only for y on the segment from S to P).
    The emission direction is -cos(psi) u + sin(psi) v, v = cos(beta) e1 + sin(beta) e2, so
    a.(y - S)/|y - S| = R cos(psi - phi) with R, phi closed forms of beta: the lit part of
    the ray is an exact arc. Pieces end where x rises by _GLOW_RAY_LEVELS; towards
    infinity (z = pi - alpha - psi -> 0, x ~ 2 sigma D sin(alpha) / z) the last piece is
    graded geometrically."""
    alpha = np.atleast_1d(np.asarray(alpha, dtype=np.float64))
    beta = np.atleast_1d(np.asarray(beta, dtype=np.float64))
    out = np.zeros(len(alpha))
    a_across = fr.sin_g * np.cos(beta - fr.beta_a)
    r = np.hypot(fr.cos_g, a_across)
    phi = np.arctan2(a_across, -fr.cos_g)
    phi = np.where(phi < -math.pi / 2, phi + 2.0 * math.pi, phi)  # the arc's centre, in [-pi/2, 3pi/2)
    lit = r > fr.cos_a
    half_arc = np.arccos(np.clip(fr.cos_a / np.where(lit, r, 1.0), -1.0, 1.0))
    end = math.pi - alpha
    lo, hi = np.maximum(0.0, phi - half_arc), np.minimum(end, phi + half_arc)
    idx = np.nonzero(lit & (hi > lo) & (alpha > 0.0))[0]
    if not len(idx):
        return out
    al, end, r, phi = alpha[idx], end[idx], r[idx], phi[idx]
    z_lo, z_hi = end - lo[idx], end - hi[idx]
    half = 0.5 * al
    k = 2.0 * sigma * fr.dist * np.sin(half)
    x_lo = k * np.cos(half + 0.5 * z_lo) / np.sin(0.5 * z_lo)
    zs = [z_lo]
    z_cut = np.zeros(len(idx))
    if sigma > 0.0:
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            scale = sigma * fr.dist * np.sin(al)
            for level in (*_GLOW_RAY_LEVELS, _GLOW_RAY_CUT):
                zk = 2.0 * np.arctan2(1.0, np.tan(half) + (x_lo + level) / scale)  # x(z) = x_lo + level
                zs.append(np.where(np.isfinite(zk), zk, 0.0))
        z_cut = zs.pop()
    if phase_varies(phase):  # the phase varies on the scale 1 of z: no long graded piece across it
        zs += [np.full(len(idx), 2.0 ** -k) for k in _PHASE_Z]
    for side, width in phase_peaks(phase):  # z = pi - (scattering angle alpha + psi)
        if side > 0:  # the forward lobe: psi on a geometric grid from the scale hypot(width, alpha)
            scale = np.hypot(width, al)
            zs += [end - scale * 2.0 ** k for k in _LOBE_Z_FORWARD]
        else:  # the backward lobe, towards infinity
            zs += [np.full(len(idx), width * f) for f in _LOBE_Z_BACKWARD]
    z_end = np.maximum(z_hi, z_cut)
    zz = np.clip(np.stack(zs + [z_end], axis=1), z_end[:, None], z_lo[:, None])
    zz = -np.sort(-zz, axis=1)  # decreasing: from the lit start towards infinity
    za, zb = zz[:, :-1], zz[:, 1:]
    with np.errstate(divide="ignore"):
        ratio = za / zb
    rows, cols = np.nonzero(za > zb)
    za, zb, ratio = za[rows, cols], zb[rows, cols], ratio[rows, cols]
    s, sw = _unit_gauss(nodes)
    folds = np.clip(np.log(np.where(ratio > 4.0, ratio, 2.0)) + 1.0, 1.0, 20.0)[:, None]
    graded = (ratio > 4.0)[:, None]  # towards z = zb, spanning the ratio geometrically
    t = np.where(graded, np.expm1(folds * s) / np.expm1(folds), s)
    tw = np.where(graded, folds * sw * np.exp(folds * s) / np.expm1(folds), sw)
    width = (za - zb)[:, None]
    z = zb[:, None] + width * t
    cos_t = r[rows, None] * np.cos(end[rows, None] - z - phi[rows, None])
    prof = np.maximum((1.0 - fr.edge) * (cos_t - fr.cos_a) / (1.0 - fr.cos_a) + fr.edge, 0.0)
    x = k[rows, None] * np.cos(0.5 * (al[rows, None] + z)) / np.sin(0.5 * z)
    if phase is not None:
        prof = prof * phase(-np.cos(z))
    values = (width * tw * prof * np.exp(-x)).sum(axis=1)
    out[idx] = np.bincount(rows, weights=values, minlength=len(idx))
    return out


def spot_glow_unit(sigma_t: float, position: Any, spot: Spot, point: Any, normal: Any,
                   nodes: tuple[int, int, int] = GLOW_NODES, phase: Any = None) -> float:
    """The glow of a spot at a surface point per unit sigma_s I0 / (4 pi):
    ``int over the hemisphere n.w > 0 of (n.w) int_0^inf (I / I0) P exp(-sigma_t (t + |y - S|))
    / |y - S|^2 dt dw``, y = P + t w, i.e. the volume integral of the source paper's glow with the
    medium filling all space (nothing occludes, the lamp's sphere included). P = 4 pi p(cos
    theta), theta between y - S and P - y, is the phase (None or isotropic: 1; a Phase or a
    hashable callable of cos theta).

    In polar coordinates (alpha, beta) about the direction u from P to S (so the 1/alpha
    peak of the airlight of rays passing S meets the Jacobian sin(alpha)), innermost the
    ray integral of :func:`glow_ray_units`, then beta, then alpha, each by Gauss-Legendre on
    pieces between exact break points (:func:`_beta_breaks`, :func:`_alpha_breaks`), each
    piece halved and each half mapped by smoothstep (algebraic end points), an exponential
    grading (layers, nearby complex singularities) or nothing."""
    key = (float(sigma_t), tuple(float(v) for v in position), tuple(float(v) for v in spot.axis), spot.cos_a,
           spot.edge, tuple(float(v) for v in point), tuple(float(v) for v in normal), tuple(nodes),
           None if is_isotropic(phase) else phase)
    return _spot_glow_unit_cached(key)


@functools.lru_cache(maxsize=20_000)
def _spot_glow_unit_cached(key: tuple) -> float:
    sigma, position, axis, cos_a, edge, point, normal, nodes, phase = key
    n_alpha, n_beta, n_ray = nodes
    sp = Spot(np.array(axis), math.degrees(math.acos(cos_a)), cos_a, edge)
    fr = glow_frame(position, sp, point, normal)
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    edges, kinds = _alpha_breaks(fr, sigma, n, np.asarray(axis), phase)
    alpha, w_alpha = (v.ravel() for v in _piece_rule(edges, kinds, n_alpha))
    br, kd = _beta_breaks(fr, alpha, phase)
    beta, w_beta = _piece_rule(br, kd, n_beta)
    per = beta.shape[1] * beta.shape[2]
    alpha = np.repeat(alpha, per)
    weight = np.repeat(w_alpha, per) * w_beta.ravel()
    beta = beta.ravel()
    cos_n = np.cos(alpha) * fr.cos_s + np.sin(alpha) * fr.sin_s * np.cos(beta)  # n.w
    keep = (weight > 0) & (cos_n > 0)
    units = glow_ray_units(fr, sigma, alpha[keep], beta[keep], n_ray, phase)
    total = float(np.sum(weight[keep] * cos_n[keep] * units))
    return math.exp(-sigma * fr.dist) / fr.dist * total


def spot_glow_irradiance(sigma_t: Any, sigma_s: Any, intensity: Any, position: Any, spot: Spot, point: Any,
                         normal: Any, nodes: tuple[int, int, int] = GLOW_NODES,
                         phase: Any = None) -> np.ndarray:
    """E_glow (3,), W/m^2: the light a spot (axial intensity I0, RGB) scatters once onto a
    Lambertian point with unit normal `normal`, per channel
    ``sigma_s / (4 pi) * I0 * spot_glow_unit(sigma_t, ...)`` (sigma_t, sigma_s, I0: RGB;
    `phase` as in spot_glow_unit)."""
    sigma_t = np.broadcast_to(np.asarray(sigma_t, dtype=np.float64), (3,))
    sigma_s = np.broadcast_to(np.asarray(sigma_s, dtype=np.float64), (3,))
    intensity = np.broadcast_to(np.asarray(intensity, dtype=np.float64), (3,))
    out = np.zeros(3)
    for c in range(3):
        if sigma_s[c] > 0 and intensity[c] > 0:
            unit = spot_glow_unit(float(sigma_t[c]), position, spot, point, normal, nodes, phase)
            out[c] = sigma_s[c] * intensity[c] / (4.0 * math.pi) * unit
    return out


def spot_glow_radiance(ss: SpotScene, point: np.ndarray, normal: np.ndarray,
                       albedo: np.ndarray) -> np.ndarray:
    """Radiance (3,) leaving a Lambertian point from the light every spot scatters onto it
    (albedo / pi * E_glow, not shadowed, effects/lamp_airlight/physics.md and
    effects/spotlights/physics.md)."""
    out = np.zeros(3)
    for j in ss.spot_indices:
        light, spot = ss.sc.lights[j], ss.spots[j]
        assert spot is not None
        if float(np.linalg.norm(light.position - point)) < light.radius:
            raise ValueError("reference: surface point inside a spot's sphere (the renderer clamps D there)")
        out += spot_glow_irradiance(ss.sc.sigma_t, ss.sc.sigma_s, light.intensity, light.position, spot,
                                    point, normal, phase=ss.phase)
    return albedo / math.pi * out


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
                lit: Sequence[bool] | np.ndarray) -> np.ndarray:
    """Radiance (3,) leaving a Lambertian point from the spots' direct light (hard shadows;
    the light they scatter onto it is :func:`spot_glow_radiance`)."""
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
                units[sigma] = spot_unit_logs(sigma, sc.position, dirs, light.position, spot, x0, t_hit,
                                              ss.phase)
            log_scale = math.log(sc.sigma_s[c] * light.intensity[c] / (4.0 * math.pi))
            total[:, c] += np.exp(log_scale + units[sigma])
    return total


def _check_point_lights_phase(ss: SpotScene) -> None:
    """Point lights go through airlight_reference, which this module only trusts with an
    isotropic phase unless its Scene carries a phase itself."""
    if ss.phase is not None and ss.point_indices and not hasattr(ss.sc, "phase"):
        raise NotImplementedError("spot_reference: point lights with an anisotropic phase are "
                                  "airlight_reference's (it has no phase support here)")


def spot_pixel_radiance(ss: SpotScene, rows: Sequence[int], cols: Sequence[int], glow: bool = True,
                        airlight_on: bool = True) -> np.ndarray:
    """Reference radiance (N, 3) of the given pixels: points as airlight_reference, spots
    as above; surfaces get every lamp's glow (point lamps' and spots') when `glow`."""
    sc = ss.sc
    _check_point_lights_phase(ss)
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
            if glow and np.any(sc.sigma_s > 0) and np.any(albedo > 0):
                base = base + spot_glow_radiance(ss, tr.point[k], tr.normal[k], albedo)
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
        if ss.phase is not None:
            prof = prof * ss.phase(np.cos(psi))
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


def spot_glow_volume_nquad(sigma: float, position: Any, sp: Spot, point: Any, normal: Any, phase: Any,
                 theta_range: tuple[float, float], uniform: bool = False, eps: float = 1e-9) -> float:
    """A check of the check: the glow's volume integral with a phase (per unit sigma_s I0 / (4 pi)) over the
    directions from the lamp at angles theta_range from the axis, by scipy nquad in
    spherical coordinates about the lamp (polar axis a): bounded wherever P is not in the
    region. cos(scattering angle) = e.(P - y)/|P - y|, e the direction from the lamp.
    `uniform`: profile 1 instead of I / I0."""
    s, p, n, a = (np.asarray(v, dtype=np.float64) for v in (position, point, normal, sp.axis))
    b1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(a, b1)
    w = p - s
    dist = float(np.linalg.norm(w))
    wa, w1, w2, na, n1, n2, nw = w @ a, w @ b1, w @ b2, n @ a, n @ b1, n @ b2, n @ w

    def f(r: float, ph: float, th: float) -> float:
        ct, st = math.cos(th), math.sin(th)
        e1, e2 = st * math.cos(ph), st * math.sin(ph)
        dx, dy, dz = r * ct - wa, r * e1 - w1, r * e2 - w2  # y - P
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        nd = na * dx + n1 * dy + n2 * dz
        if nd <= 0.0:
            return 0.0
        prof = 1.0 if uniform else (1.0 - sp.edge) * (ct - sp.cos_a) / (1.0 - sp.cos_a) + sp.edge
        cos_t = -(ct * dx + e1 * dy + e2 * dz) / d
        return prof * phase(cos_t) * st * math.exp(-sigma * (r + d - dist)) * nd / d ** 3

    def along(ph: float, th: float) -> float:
        e = np.array([math.cos(th), math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph)])
        en = e[0] * na + e[1] * n1 + e[2] * n2
        closest = max(float(e @ [wa, w1, w2]), 0.0)
        breaks = {closest}
        if en != 0.0 and nw / en > 0.0:
            breaks.add(nw / en)
        edges = [0.0, *sorted(breaks)]
        total = sum(quad(f, lo, hi, args=(ph, th), epsabs=0.0, epsrel=eps, limit=200)[0]
                    for lo, hi in zip(edges[:-1], edges[1:]) if hi > lo)
        return total + quad(f, edges[-1], math.inf, args=(ph, th), epsabs=0.0, epsrel=eps, limit=200)[0]

    opts = {"epsabs": 0.0, "epsrel": eps, "limit": 200}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        value = nquad(along, [[0.0, 2.0 * math.pi], list(theta_range)], opts=[opts, opts])[0]
    return value * math.exp(-sigma * dist)
