"""Independent float64 reference for the airlight of a point lamp with an anisotropic phase
function (effects/lamp_airlight/physics.md, "general phase function"; issue 5).

Written from the defining integral, not from the renderer (which tabulates the xi integral
per g): here the phase function is evaluated directly at every quadrature node.

Conventions (docs/conventions.md): p(cos theta) is normalised to 1 over the sphere (isotropic
1 / (4 pi)); theta is the angle between the light's propagation direction before and after
scattering (0: forward). For the ray o + x d and a lamp at L (closest approach at x = b,
closest distance h, d(x) = |o + x d - L|), the light reaching o + x d travels along
(o + x d - L) / d(x) and is scattered towards the camera, along -d, so
cos theta(x) = (b - x) / d(x).

The airlight of the ray interval [x0, x1] (x1 = inf: an escaping ray) is

    L = sigma_s I int_{x0}^{x1} p(cos theta(x)) exp(-sigma_t (x + d(x))) / d(x)^2 dx.

Two independent evaluations:

* :func:`airlight_xi_log` (the reference): in the source paper's variable xi,
  x = b + h tan(2 xi - pi/2), the scattering angle is exactly 2 xi, dx / d^2 = 2 dxi / h and
  x + d = b + h tan xi, so

      L = 2 sigma_s I / h exp(-sigma_t e0) int_{xi0}^{xi1} p(cos 2 xi) exp(-sigma_t h (tan xi - tan xi0)) dxi

  with e0 = x0 + d(x0) (the shortest light path on the interval, so the integrand is at most
  max p and never overflows). The integrand is bounded; it is integrated by a composite
  Gauss-Legendre rule (``nodes`` per piece, vectorised) on pieces graded geometrically
  towards the phase function's forward (xi = 0) and backward (xi = pi/2) lobes (scale
  1 - |g|) and in the optical depth sigma_t h (tan xi - tan xi0), or by ``scipy.integrate.quad``
  on the same pieces (``nodes=None``).
* :func:`airlight_x_log` (the check): ``quad`` in the ray parameter x itself, split at the
  closest approach, at b +- h 10^k, at the optical depths 10^k and where the scattering
  angle is (1 - |g|) 10^k (the lobes), with 1 -+ cos theta formed without cancellation.

Closed form for sigma_t = 0 (:func:`airlight_no_extinction`): L = sigma_s I / h
int_{theta0}^{theta1} p(cos theta) dtheta, for HG through the incomplete elliptic integral of
the second kind (derivation in its docstring), for Rayleigh elementary.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.integrate import IntegrationWarning, quad

HG_G_LIMIT = 0.999  # the renderer clamps |g| to this (the scene format allows g in (-1, 1))
QUAD_EPSREL = 1e-10
XI_NODES = 24  # Gauss-Legendre nodes per piece of the xi rule (48 agrees to about 1e-12)
LOBE_RATIO = 2.0  # geometric grading of the pieces towards a lobe / in optical depth
MAX_PIECE = math.pi / 16  # no piece of the xi rule is longer than this
FOUR_PI = 4.0 * math.pi


# ---- phase functions ------------------------------------------------------------------------

def _hg_from_one_minus(g: float, one_minus_mu: Any, one_plus_mu: Any) -> Any:
    """HG p(mu) from 1 - mu and 1 + mu (given without cancellation), normalised:
    1 + g^2 - 2 g mu = (1 - g)^2 + 2 g (1 - mu) = (1 + g)^2 - 2 g (1 + mu)."""
    if g >= 0.0:
        den = (1.0 - g) ** 2 + 2.0 * g * one_minus_mu
    else:
        den = (1.0 + g) ** 2 - 2.0 * g * one_plus_mu
    return (1.0 - g * g) / (FOUR_PI * den ** 1.5)


@dataclass(frozen=True)
class Phase:
    """A normalised phase function p(cos theta) (frozen: it keys caches).

    kind "isotropic": 1 / (4 pi); "hg": Henyey-Greenstein with asymmetry g; "rayleigh":
    3 / (16 pi) (1 + cos^2 theta); "hg2": w HG(g) + (1 - w) HG(g2) (w = ``weight``)."""

    kind: str = "isotropic"
    g: float = 0.0
    g2: float = 0.0
    weight: float = 1.0

    def __post_init__(self) -> None:
        if self.kind not in ("isotropic", "hg", "rayleigh", "hg2"):
            raise ValueError(f"phase_reference: unknown phase kind {self.kind!r}")

    @property
    def isotropic(self) -> bool:
        return self.kind == "isotropic"

    def lobes(self) -> tuple[tuple[float, float], ...]:
        """HG lobes as (g, weight) (empty for isotropic and Rayleigh)."""
        if self.kind == "hg":
            return ((self.g, 1.0),)
        if self.kind == "hg2":
            return ((self.g, self.weight), (self.g2, 1.0 - self.weight))
        return ()

    def widths(self) -> tuple[tuple[int, float], ...]:
        """(+1 forward | -1 backward, angular width 1 - |g|) of each lobe with |g| >= 0.2 and
        nonzero weight: where the quadratures grade their pieces."""
        return tuple((1 if g > 0 else -1, 1.0 - abs(g)) for g, w in self.lobes() if abs(g) >= 0.2 and w != 0)

    def of_sides(self, one_minus_mu: Any, one_plus_mu: Any) -> Any:
        """p from 1 - cos theta and 1 + cos theta (float or array)."""
        if self.kind == "isotropic":
            return np.ones_like(np.asarray(one_minus_mu, dtype=np.float64)) / FOUR_PI
        if self.kind == "rayleigh":
            mu = np.where(np.asarray(one_minus_mu) < np.asarray(one_plus_mu), 1.0 - one_minus_mu,
                          one_plus_mu - 1.0)
            return 3.0 / (16.0 * math.pi) * (1.0 + mu * mu)
        return sum(w * _hg_from_one_minus(g, one_minus_mu, one_plus_mu) for g, w in self.lobes() if w != 0)

    def __call__(self, mu: Any) -> Any:
        """p(cos theta)."""
        mu = np.asarray(mu, dtype=np.float64)
        return self.of_sides(1.0 - mu, 1.0 + mu)

    def of_angle(self, theta: Any) -> Any:
        """p at the scattering angle theta (1 -+ cos theta from sin^2 / cos^2 (theta / 2))."""
        half = 0.5 * np.asarray(theta, dtype=np.float64)
        return self.of_sides(2.0 * np.sin(half) ** 2, 2.0 * np.cos(half) ** 2)


ISOTROPIC = Phase()


def hg(g: float) -> Phase:
    return Phase("hg", float(g))


def hg2(forward_g: float, backward_g: float, forward_weight: float) -> Phase:
    return Phase("hg2", float(forward_g), float(backward_g), float(forward_weight))


RAYLEIGH = Phase("rayleigh")


def clamp_g(g: float) -> float:
    """The renderer's documented clamp |g| <= HG_G_LIMIT."""
    return float(min(max(float(g), -HG_G_LIMIT), HG_G_LIMIT))


def parse_phase(value: Any) -> Phase:
    """A scene's medium.phase (absent or None: isotropic) with |g| clamped as the renderer
    does (no validation: the renderer's job, tested in test_validation.py)."""
    if value is None:
        return ISOTROPIC
    assert isinstance(value, Mapping)
    kind = value.get("type", "isotropic")
    if kind == "hg":
        return hg(clamp_g(value["g"]))
    if kind == "hg2":
        return hg2(clamp_g(value["forward_g"]), clamp_g(value["backward_g"]), float(value["forward_weight"]))
    return Phase(kind)


def phase_dict(phase: Phase) -> dict[str, Any]:
    """The scene format's medium.phase of a Phase."""
    if phase.kind == "hg":
        return {"type": "hg", "g": phase.g}
    if phase.kind == "hg2":
        return {"type": "hg2", "forward_g": phase.g, "backward_g": phase.g2, "forward_weight": phase.weight}
    return {"type": phase.kind}


def sphere_integral(phase: Phase, n: int = 4000) -> float:
    """int p dOmega over the sphere (should be 1), by Gauss-Legendre in theta graded towards
    the lobes (a check of the normalisation)."""
    edges = {0.0, math.pi}
    for _, w in phase.widths():
        for k in range(-3, 12):
            t = w * LOBE_RATIO ** k
            if t < math.pi:
                edges.update((t, math.pi - t))
    grid = sorted(edges)
    x, wt = np.polynomial.legendre.leggauss(min(200, max(8, n // len(grid))))
    total = 0.0
    for a, c in zip(grid[:-1], grid[1:]):
        th = 0.5 * (a + c) + 0.5 * (c - a) * x
        total += 0.5 * (c - a) * float(np.sum(wt * 2.0 * math.pi * np.sin(th) * phase.of_angle(th)))
    return total


# ---- the airlight in the xi variable (the reference) -----------------------------------------

def _xi_of(x: float, b: float, h: float) -> float:
    """xi(x) = pi/4 + atan((x - b) / h) / 2 (pi/2 at x = inf)."""
    if math.isinf(x):
        return math.pi / 2
    return math.pi / 4 + 0.5 * math.atan2(x - b, h)


def _xi_breaks(xi0: float, xi1: float, sigma: float, h: float, phase: Phase) -> list[float]:
    """Piece edges of [xi0, xi1]: graded towards the lobes and in optical depth."""
    breaks = set()
    for sign, w in phase.widths():
        k = -6
        while True:
            half_theta = 0.5 * w * LOBE_RATIO ** k
            if half_theta > math.pi / 2:
                break
            breaks.add(half_theta if sign > 0 else math.pi / 2 - half_theta)
            k += 1
    if sigma * h > 0:
        t0 = math.tan(xi0)
        for k in range(-12, 10):  # optical depth sigma h (tan xi - tan xi0) = 2^k
            breaks.add(math.atan(t0 + LOBE_RATIO ** k / (sigma * h)))
    edges = [xi0] + sorted(p for p in breaks if xi0 < p < xi1) + [xi1]
    out = [edges[0]]
    for a, c in zip(edges[:-1], edges[1:]):
        m = max(1, math.ceil((c - a) / MAX_PIECE))
        out += [a + (c - a) * (i + 1) / m for i in range(m)]
    return out


def _xi_integrand(sigma: float, h: float, xi0: float, phase: Phase, xi: Any) -> Any:
    """p(cos 2 xi) exp(-sigma h (tan xi - tan xi0)), the difference of tangents as
    sin(xi - xi0) / (cos xi cos xi0)."""
    xi = np.asarray(xi, dtype=np.float64)
    cos_xi = np.cos(xi)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        depth = sigma * h * np.sin(xi - xi0) / (cos_xi * math.cos(xi0))
        weight = np.where(cos_xi > 0, np.exp(-depth), 0.0 if sigma * h > 0 else 1.0)
    return phase.of_sides(2.0 * np.sin(xi) ** 2, 2.0 * cos_xi ** 2) * weight


@functools.lru_cache(maxsize=8)
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.polynomial.legendre.leggauss(n)


def xi_integral(sigma: float, h: float, xi0: float, xi1: float, phase: Phase,
                nodes: int | None = XI_NODES) -> float:
    """int_{xi0}^{xi1} p(cos 2 xi) exp(-sigma h (tan xi - tan xi0)) dxi: composite
    Gauss-Legendre with ``nodes`` per piece, or ``quad`` per piece when nodes is None."""
    if not xi1 > xi0:
        return 0.0
    edges = np.asarray(_xi_breaks(xi0, xi1, sigma, h, phase))
    if nodes is not None:
        x, w = _gauss(nodes)
        a, c = edges[:-1, None], edges[1:, None]
        pts = 0.5 * (a + c) + 0.5 * (c - a) * x[None, :]
        vals = _xi_integrand(sigma, h, xi0, phase, pts)
        return float(np.sum(0.5 * (c - a) * w[None, :] * vals))
    total = err = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for a, c in zip(edges[:-1], edges[1:]):
            value, e_abs = quad(lambda t: float(_xi_integrand(sigma, h, xi0, phase, t)), a, c,
                                epsabs=0.0, epsrel=QUAD_EPSREL, limit=200)
            total += value
            err += e_abs
    if not err <= 1e-8 * total + 1e-300:
        raise RuntimeError(f"xi quadrature did not converge: {total} +- {err}")
    return total


@functools.lru_cache(maxsize=200_000)
def _airlight_xi_log_cached(sigma_t: float, b: float, h: float, x0: float, x1: float, phase: Phase,
                            nodes: int | None) -> float:
    xi0, xi1 = _xi_of(x0, b, h), _xi_of(x1, b, h)
    j = xi_integral(sigma_t, h, xi0, xi1, phase, nodes)
    if not j > 0:
        return -math.inf
    e0 = x0 + math.hypot(h, x0 - b)
    return math.log(2.0 / h) + math.log(j) - sigma_t * e0


def airlight_xi_log(sigma_t: float, sigma_s: float, intensity: float, b: float, h: float,
                    x0: float = 0.0, x1: float = math.inf, phase: Phase = ISOTROPIC,
                    nodes: int | None = XI_NODES) -> float:
    """log of the airlight (one channel) of a lamp at closest distance h > 0 from the ray,
    closest approach at x = b, over [x0, x1], in the xi variable (module docstring);
    -inf when it is 0."""
    if sigma_s <= 0 or intensity <= 0 or not x1 > x0:
        return -math.inf
    if not h > 0:
        raise ValueError("airlight_xi_log: the ray passes through the lamp (h = 0); use airlight_x_log")
    unit = _airlight_xi_log_cached(float(sigma_t), float(b), float(h), float(x0), float(x1), phase, nodes)
    return math.log(sigma_s * intensity) + unit


# ---- the airlight in the ray parameter x (an independent check) --------------------------------

def airlight_x_log(sigma_t: float, sigma_s: float, intensity: float, b: float, h: float,
                   x0: float = 0.0, x1: float = math.inf, phase: Phase = ISOTROPIC,
                   epsrel: float = QUAD_EPSREL) -> float:
    """log of the same airlight by ``quad`` in x: sigma_s I int p(cos theta(x))
    exp(-sigma_t (x + d(x))) / d(x)^2 dx, the exponent shifted by its value e0 at x0."""
    if sigma_s <= 0 or intensity <= 0 or not x1 > x0:
        return -math.inf
    e0 = x0 + math.hypot(h, x0 - b)

    def f(x: float) -> float:
        d = math.hypot(h, x - b)
        s = b - x  # d cos theta
        # 1 - cos theta = (d - s) / d, 1 + cos theta = (d + s) / d, each without cancellation
        one_minus = (d - s) / d if s <= 0 else h * h / (d * (d + s))
        one_plus = (d + s) / d if s >= 0 else h * h / (d * (d - s))
        return float(phase.of_sides(one_minus, one_plus)) * math.exp(-sigma_t * (x + d - e0)) / (d * d)

    breaks = {b}
    for k in range(-1, 7):
        breaks.add(b - h * 10.0 ** k)
        breaks.add(b + h * 10.0 ** k)
    for sign, w in phase.widths():  # scattering angle theta = w 10^k: x = b -+ h / tan(theta)
        for k in range(-1, 4):
            theta = w * 10.0 ** k
            if theta < math.pi / 2:
                breaks.add(b - sign * h / math.tan(theta))
    if sigma_t > 0:
        for k in range(-2, 4):
            breaks.add(x0 + 10.0 ** k / sigma_t)
    edges = [x0] + sorted(p for p in breaks if x0 < p < x1)
    pieces = list(zip(edges[:-1], edges[1:])) + [(edges[-1], x1)]
    total = err = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for lo, hi in pieces:
            value, e_abs = quad(f, lo, hi, epsabs=0.0, epsrel=epsrel, limit=400)
            total += value
            err += e_abs
    if not err <= 1e-8 * total + 1e-300:
        raise RuntimeError(f"x quadrature did not converge: {total} +- {err}")
    if not total > 0:
        return -math.inf
    return math.log(sigma_s * intensity) + math.log(total) - sigma_t * e0


# ---- closed forms ----------------------------------------------------------------------------------

def _pi3(phi: float, m: float) -> float:
    """int_0^phi ds / (1 - m sin^2 s)^(3/2)
    = [E(phi | m) - m sin phi cos phi / sqrt(1 - m sin^2 phi)] / (1 - m), E the incomplete elliptic
    integral of the second kind (differentiate: the bracket's derivative is
    (1 - m) / (1 - m sin^2 phi)^(3/2)); m < 1."""
    from scipy.special import ellipeinc

    s, c = math.sin(phi), math.cos(phi)
    return (float(ellipeinc(phi, m)) - m * s * c / math.sqrt(1.0 - m * s * s)) / (1.0 - m)


def _hg_angle_integral(g: float, theta0: float, theta1: float) -> float:
    """int_{theta0}^{theta1} dt / (1 + g^2 - 2 g cos t)^(3/2) for 0 <= theta0 <= theta1 <= pi
    within one half, [0, pi/2] or [pi/2, pi]. Forward half, s = t / 2:
    1 + g^2 - 2 g cos t = (1 - g)^2 (1 - m sin^2 s), m = -4 g / (1 - g)^2, so the integral is
    2 / (1 - g)^3 [Pi3(theta1 / 2) - Pi3(theta0 / 2)]. Backward half, s = (pi - t) / 2:
    (1 + g)^2 (1 - m sin^2 s), m = 4 g / (1 + g)^2, so
    2 / (1 + g)^3 [Pi3((pi - theta0) / 2) - Pi3((pi - theta1) / 2)].
    Each half's form is free of cancellation near its own end (0 or pi)."""
    if theta1 <= math.pi / 2:
        m = -4.0 * g / (1.0 - g) ** 2
        return 2.0 / (1.0 - g) ** 3 * (_pi3(theta1 / 2, m) - _pi3(theta0 / 2, m))
    m = 4.0 * g / (1.0 + g) ** 2
    return 2.0 / (1.0 + g) ** 3 * (_pi3((math.pi - theta0) / 2, m) - _pi3((math.pi - theta1) / 2, m))


def phase_angle_integral(phase: Phase, theta0: float, theta1: float) -> float:
    """int_{theta0}^{theta1} p(cos theta) dtheta (0 <= theta0 <= theta1 <= pi) in closed form:
    HG through the incomplete elliptic integral of the second kind (_hg_angle_integral),
    Rayleigh 3 / (16 pi) [3 theta / 2 + sin(2 theta) / 4]."""
    if phase.kind == "isotropic":
        return (theta1 - theta0) / FOUR_PI
    if phase.kind == "rayleigh":
        def anti(t: float) -> float:
            return 3.0 / (16.0 * math.pi) * (1.5 * t + 0.25 * math.sin(2.0 * t))
        return anti(theta1) - anti(theta0)
    halves = [(theta0, min(theta1, math.pi / 2)), (max(theta0, math.pi / 2), theta1)]
    total = 0.0
    for g, w in phase.lobes():
        for a, c in halves:
            if c > a and w != 0:
                total += w * (1.0 - g * g) / FOUR_PI * _hg_angle_integral(g, a, c)
    return total


def scattering_angle(b: float, h: float, x: float) -> float:
    """theta(x) = 2 xi(x): the scattering angle at ray parameter x (pi at x = inf)."""
    return 2.0 * _xi_of(x, b, h)


def airlight_no_extinction(sigma_s: float, intensity: float, b: float, h: float, x0: float = 0.0,
                           x1: float = math.inf, phase: Phase = ISOTROPIC) -> float:
    """The airlight with sigma_t = 0 (sigma_s kept): sigma_s I / h int_{theta(x0)}^{theta(x1)} p dtheta
    (isotropic: the source paper's sigma_s I / (4 pi h) [atan((x1 - b)/h) - atan((x0 - b)/h)])."""
    return sigma_s * intensity / h * phase_angle_integral(
        phase, scattering_angle(b, h, x0), scattering_angle(b, h, x1))


def glow_forward_limit(sigma_t: float, dist: float, cos_theta_s: float) -> float:
    """The g -> 1 limit of the glow per unit sigma_s I: all scattered light goes on along the
    lamp's ray, so the surface receives the direct beam's irradiance times sigma_s D:
    exp(-sigma_t D) max(cos theta_s, 0) / D."""
    return math.exp(-sigma_t * dist) * max(cos_theta_s, 0.0) / dist
