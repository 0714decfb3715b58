"""Independent float64 reference for the street-lamp airlight (effects/lamp_airlight/physics.md).

Written from the model's definition, not from the shaders: nothing here uses the
renderer's tables, tail folding, short-segment rule or closed forms.

* Camera: pinhole, ``fov_y`` the full vertical angle, aspect ratio from the film, one ray
  through each pixel centre, row 0 on top, right-handed and y up
  (right = normalize(forward x up), true up = right x forward).
* Geometry: Lambertian planes (two-sided), axis-aligned boxes and spheres, the shading
  normal turned to face the ray; lamps are spheres of radius r that end a view ray
  (radiance I / (pi r^2)) unless the camera is inside them.
* Airlight of a light over [x0, x1] of the ray o + x d (per channel):
  ``sigma_s I / (4 pi) int_{x0}^{x1} exp(-sigma_t (x + |S - p(x)|)) / |S - p(x)|^2 dx``,
  integrated with ``scipy.integrate.quad`` (epsabs = 0, epsrel = 1e-10 on each piece),
  split at the closest approach x = b and at b +- h 10^k (h the closest distance), and
  on [last break point, inf) for escaping rays. The exponent is shifted by its value at
  x0, so the integral never underflows and :func:`airlight_log` works in log space.
* Surfaces: albedo / pi times, per light, the direct term
  ``I cos(theta) / max(d^2, r^2) exp(-sigma_t d)`` (hard shadows; the shadow segment ends
  at the lamp sphere) plus the glow: the hemisphere integral of the airlight of the
  infinite ray leaving the surface point, cosine weighted (not shadowed). The airlight of
  such a ray depends only on the angle alpha between the ray and the direction to the
  light, so the hemisphere integral is written in polar coordinates (alpha, beta) around
  that direction: the inner integral over the azimuth beta of max(cos, 0) is taken in
  closed form on the exact lit arc, the outer integral over alpha by Gauss-Legendre with a
  smoothstep map on pieces split where the lit arc changes shape, and each airlight by
  ``quad``. 24 nodes per piece converge to about 1e-8 (checked by doubling in
  test_airlight_surface_glow.py).
* Phase functions (issue 5): the scene's ``medium.phase`` is read into ``Scene.phase``
  (phase_reference.Phase, |g| clamped to 0.999 as the renderer documents). An isotropic
  phase takes exactly the paths above; any other takes phase_reference's quadrature of the
  defining integral in the xi variable (the phase function evaluated at every node), and
  the glow the same polar reduction (the airlight of a ray leaving the surface still depends
  only on the angle alpha between the ray and the direction to the light: the scattering
  angle at parameter x is theta with cos theta = (b - x) / d), its pieces also graded
  towards the phase function's lobes (alpha ~ 1 - |g| forward, pi - alpha backward).
"""

from __future__ import annotations

import functools
import json
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from phase_reference import ISOTROPIC, Phase, airlight_x_log, airlight_xi_log, parse_phase
from reference import _INTERSECT as _REFERENCE_INTERSECT
from scipy.integrate import IntegrationWarning, quad

DEFAULT_LAMP_RADIUS = 0.05
DEFAULT_SURFACE_ALBEDO = 0.5
DEFAULT_CULL_FRACTION = 1e-5
QUAD_EPSREL = 1e-10
GLOW_NODES = 24

BACKGROUND = -1
LAMP_BASE = 1_000_000  # hit id of lamp j: LAMP_BASE + j; surface i, face f: 8 i + f


# ---- scene -------------------------------------------------------------------------------

def _rgb(value: Any, default: float) -> np.ndarray:
    if value is None:
        return np.full(3, float(default))
    return np.broadcast_to(np.asarray(value, dtype=np.float64), (3,)).copy()


def _vec3(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=np.float64).reshape(3)


@dataclass
class Light:
    position: np.ndarray
    intensity: np.ndarray
    radius: float


@dataclass
class Surface:
    kind: str  # "plane", "box", "sphere"
    albedo: np.ndarray
    a: np.ndarray  # plane: point, box: min corner, sphere: centre
    b: np.ndarray  # plane: unit normal, box: max corner
    radius: float = 0.0


@dataclass
class Scene:
    width: int
    height: int
    position: np.ndarray
    forward: np.ndarray
    right: np.ndarray  # unit
    up: np.ndarray  # unit
    tan_half: float  # tan(fov_y / 2)
    sigma_t: np.ndarray
    sigma_s: np.ndarray
    lights: list[Light] = field(default_factory=list)
    surfaces: list[Surface] = field(default_factory=list)
    background: np.ndarray = field(default_factory=lambda: np.zeros(3))
    cull_fraction: float = DEFAULT_CULL_FRACTION
    phase: Phase = ISOTROPIC


def parse_scene(scene: Any) -> Scene:
    """The scene (dict or JSON text, as given to airlight) in float64."""
    if isinstance(scene, str):
        scene = json.loads(scene)
    assert isinstance(scene, Mapping)
    cam = scene["camera"]
    position = _vec3(cam["position"])
    forward = _vec3(cam["look_at"]) - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, _vec3(cam.get("up", [0.0, 1.0, 0.0])))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    medium = scene.get("medium")
    phase = ISOTROPIC
    if medium is None:
        sigma_t = np.zeros(3)
        albedo = np.zeros(3)
    else:
        sigma_t = _rgb(medium["sigma_t"], 0.0)
        albedo = _rgb(medium.get("albedo"), 1.0)
        phase = parse_phase(medium.get("phase"))
    lights = [Light(_vec3(li["position"]), _rgb(li["intensity"], 0.0),
                    float(li.get("radius", DEFAULT_LAMP_RADIUS))) for li in scene.get("lights", [])]
    surfaces = []
    for s in scene.get("surfaces", []):
        albedo_s = _rgb(s.get("albedo"), DEFAULT_SURFACE_ALBEDO)
        if s["type"] == "plane":
            n = _vec3(s["normal"])
            surfaces.append(Surface("plane", albedo_s, _vec3(s["point"]), n / np.linalg.norm(n)))
        elif s["type"] == "box":
            surfaces.append(Surface("box", albedo_s, _vec3(s["min"]), _vec3(s["max"])))
        elif s["type"] == "sphere":
            surfaces.append(Surface("sphere", albedo_s, _vec3(s["center"]), np.zeros(3), float(s["radius"])))
        else:
            raise ValueError(f"airlight_reference: unknown surface type {s['type']!r}")
    quality = scene.get("quality") or {}
    return Scene(
        width=int(scene["film"]["width"]), height=int(scene["film"]["height"]),
        position=position, forward=forward, right=right, up=up,
        tan_half=math.tan(math.radians(float(cam["fov_y"])) / 2.0),
        sigma_t=sigma_t, sigma_s=albedo * sigma_t, lights=lights, surfaces=surfaces,
        background=_rgb(scene.get("background"), 0.0),
        cull_fraction=float(quality.get("cull_fraction", DEFAULT_CULL_FRACTION)),
        phase=phase,
    )


def camera_rays(sc: Scene, rows: np.ndarray | None = None,
                cols: np.ndarray | None = None) -> np.ndarray:
    """Unit directions (N, 3) of the rays through the centres of pixels (rows, cols);
    all pixels in row-major order when both are None."""
    if rows is None or cols is None:
        rr, cc = np.meshgrid(np.arange(sc.height), np.arange(sc.width), indexing="ij")
        rows, cols = rr.ravel(), cc.ravel()
    rows = np.asarray(rows, dtype=np.float64)
    cols = np.asarray(cols, dtype=np.float64)
    aspect = sc.width / sc.height
    sx = (2.0 * (cols + 0.5) / sc.width - 1.0) * sc.tan_half * aspect
    sy = (1.0 - 2.0 * (rows + 0.5) / sc.height) * sc.tan_half
    dirs = sc.forward[None, :] + sx[:, None] * sc.right[None, :] + sy[:, None] * sc.up[None, :]
    return dirs / np.linalg.norm(dirs, axis=1, keepdims=True)


# ---- intersections (vectorised over rays) --------------------------------------------------

def _intersect(s: Surface, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest t > 0 (inf if none), face index and geometric normal of rays o + t d:
    the foundation reference's intersection routines (same surface fields)."""
    o = np.broadcast_to(np.asarray(o, dtype=np.float64), d.shape)
    t, face, normal = _REFERENCE_INTERSECT[s.kind](s, o, d)
    return t, face, np.array(normal, dtype=np.float64)


def lamp_entry(light: Light, o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance along each ray to the near side of the lamp sphere; inf when the ray
    misses it, when it lies behind, or when the origin is inside it."""
    oc = o - light.position
    b = np.einsum("ij,ij->i", oc, d)
    c = np.einsum("ij,ij->i", oc, oc) - light.radius ** 2
    disc = b * b - c
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (c > 0) & (t > 0), t, np.inf)


@dataclass
class Trace:
    t_hit: np.ndarray  # (N,) distance to what the ray sees (inf: escapes)
    hit_id: np.ndarray  # (N,) BACKGROUND, LAMP_BASE + j, or 8 * surface + face
    point: np.ndarray  # (N, 3) hit point (surfaces only)
    normal: np.ndarray  # (N, 3) unit normal facing the ray (surfaces only)
    lit: np.ndarray  # (L, N) light j reaches the surface point directly
    min_lamp_gap: np.ndarray  # (N,) min over lamps of (closest distance of [0, t_hit] to the centre) / r


def trace(sc: Scene, dirs: np.ndarray) -> Trace:
    """What each camera ray (origin sc.position) sees."""
    n = len(dirs)
    o = np.broadcast_to(sc.position, (n, 3))
    t_surf = np.full(n, np.inf)
    index = np.full(n, -1, dtype=np.int64)
    face = np.zeros(n, dtype=np.int64)
    normal = np.zeros((n, 3))
    for i, s in enumerate(sc.surfaces):
        t, f, nrm = _intersect(s, o, dirs)
        closer = t < t_surf
        t_surf = np.where(closer, t, t_surf)
        index = np.where(closer, i, index)
        face = np.where(closer, f, face)
        normal = np.where(closer[:, None], nrm, normal)
    t_hit = t_surf.copy()
    hit_id = np.where(index >= 0, 8 * index + face, BACKGROUND)
    for j, light in enumerate(sc.lights):
        t = lamp_entry(light, o, dirs)
        closer = t < t_hit
        t_hit = np.where(closer, t, t_hit)
        hit_id = np.where(closer, LAMP_BASE + j, hit_id)
    on_surface = (hit_id >= 0) & (hit_id < LAMP_BASE)
    normal = np.where((np.einsum("ij,ij->i", normal, dirs) > 0)[:, None], -normal, normal)
    point = o + np.where(on_surface, t_hit, 0.0)[:, None] * dirs
    lit = np.zeros((len(sc.lights), n), dtype=bool)
    gap = np.full(n, np.inf)
    offset = 1e-7 * (1.0 + np.abs(point).max(axis=1))
    shadow_origin = point + offset[:, None] * normal
    for j, light in enumerate(sc.lights):
        to_light = light.position - point
        dist = np.linalg.norm(to_light, axis=1)
        ldir = to_light / np.maximum(dist, 1e-300)[:, None]
        reaches = on_surface & (np.einsum("ij,ij->i", ldir, normal) > 0)
        for s in sc.surfaces:
            t, _, _ = _intersect(s, shadow_origin, ldir)
            reaches &= ~(t < dist - light.radius)
        lit[j] = reaches
        rel = light.position - sc.position
        x = np.clip(dirs @ rel, 0.0, t_hit)
        closest = np.linalg.norm(sc.position + x[:, None] * dirs - light.position, axis=1)
        gap = np.minimum(gap, closest / light.radius)
    return Trace(t_hit, hit_id, point, normal, lit, gap)


# ---- airlight along a ray -------------------------------------------------------------------

def _segment_integral(sigma: float, b: float, h: float, x0: float, x1: float) -> tuple[float, float]:
    """(J, e) with int_{x0}^{x1} exp(-sigma (x + d(x))) / d(x)^2 dx = J exp(-sigma e),
    d(x) = sqrt(h^2 + (x - b)^2), by adaptive quadrature; e = x0 + d(x0) is the
    smallest light path on the segment, so the integrand of J is at most 1 / d^2."""
    e = x0 + math.hypot(h, x0 - b)

    def f(x: float) -> float:
        d = math.hypot(h, x - b)
        return math.exp(-sigma * (x + d - e)) / (d * d)

    breaks = {b}
    for k in range(-1, 7):
        breaks.add(b - h * 10.0 ** k)
        breaks.add(b + h * 10.0 ** k)
    if sigma > 0:
        for k in range(-2, 4):
            breaks.add(x0 + 10.0 ** k / sigma)
    edges = [x0] + sorted(p for p in breaks if x0 < p < x1)
    pieces = list(zip(edges[:-1], edges[1:]))
    pieces.append((edges[-1], x1))
    total = err = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        for lo, hi in pieces:
            value, e_abs = quad(f, lo, hi, epsabs=0.0, epsrel=QUAD_EPSREL, limit=400)
            total += value
            err += e_abs
    if not err <= 1e-8 * total + 1e-300:
        raise RuntimeError(f"reference airlight quadrature did not converge: {total} +- {err}")
    return total, e


@functools.lru_cache(maxsize=200_000)
def _segment_integral_cached(sigma: float, b: float, h: float, x0: float, x1: float) -> tuple[float, float]:
    return _segment_integral(sigma, b, h, x0, x1)


def airlight_log(sigma_t: float, sigma_s: float, intensity: float, b: float, h: float,
                 x0: float = 0.0, x1: float = math.inf) -> float:
    """log of the airlight (one channel) of a light at closest distance h from the ray,
    closest approach at x = b, over the ray interval [x0, x1] (x1 = inf: escaping);
    -inf when it is 0."""
    if sigma_s <= 0 or intensity <= 0 or not x1 > x0:
        return -math.inf
    j, e = _segment_integral_cached(float(sigma_t), float(b), float(h), float(x0), float(x1))
    if j <= 0:
        return -math.inf
    return math.log(sigma_s * intensity / (4.0 * math.pi)) + math.log(j) - sigma_t * e


def airlight(sigma_t: float, sigma_s: float, intensity: float, b: float, h: float,
             x0: float = 0.0, x1: float = math.inf) -> float:
    """The airlight of :func:`airlight_log` (W/(m^2 sr)); 0 where it underflows float64."""
    return math.exp(airlight_log(sigma_t, sigma_s, intensity, b, h, x0, x1))


def airlight_phase(sigma_t: float, sigma_s: float, intensity: float, b: float, h: float,
                   x0: float = 0.0, x1: float = math.inf, phase: Phase = ISOTROPIC) -> float:
    """:func:`airlight` with a phase function: the isotropic one is :func:`airlight` itself,
    any other phase_reference's xi quadrature (x quadrature where h = 0)."""
    if phase.isotropic:
        return airlight(sigma_t, sigma_s, intensity, b, h, x0, x1)
    if h > 0:
        return math.exp(airlight_xi_log(sigma_t, sigma_s, intensity, b, h, x0, x1, phase))
    return math.exp(airlight_x_log(sigma_t, sigma_s, intensity, b, h, x0, x1, phase))


def ray_light_geometry(origin: np.ndarray, direction: np.ndarray, light: Light) -> tuple[float, float, float]:
    """(b, h, x0) of a light for the ray origin + x direction: closest approach, closest
    distance, and where the visible fog starts (0, or where the ray leaves the lamp's
    sphere when the origin is inside it)."""
    rel = light.position - origin
    b = float(rel @ direction)
    h = float(np.linalg.norm(rel - b * direction))
    x0 = 0.0
    if float(rel @ rel) < light.radius ** 2:
        x0 = b + math.sqrt(max(light.radius ** 2 - h * h, 0.0))
    return b, h, x0


def ray_airlight(sc: Scene, origin: np.ndarray, direction: np.ndarray, t_hit: float) -> np.ndarray:
    """Airlight (3,) of all lights over the visible part [x0, t_hit] of a ray."""
    total = np.zeros(3)
    for light in sc.lights:
        b, h, x0 = ray_light_geometry(origin, direction, light)
        for c in range(3):
            total[c] += airlight_phase(sc.sigma_t[c], sc.sigma_s[c], light.intensity[c], b, h, x0, t_hit,
                                       sc.phase)
    return total


def F_exact(u: float, v: float) -> float:
    """F(u, v) = int_0^v exp(-u tan xi) d xi through the complex exponential integral,
    Im{exp(-i u) [E1(-i u) - E1(u (tan v - i))]} (the source paper (effects/lamp_airlight/physics.md)),
    for checking the quadrature."""
    from scipy.special import exp1

    if u == 0:
        return v
    far = 0.0 if v >= math.pi / 2 else exp1(u * (math.tan(v) - 1j))
    return float((np.exp(-1j * u) * (exp1(-1j * u) - far)).imag)


# ---- light scattered onto surfaces -----------------------------------------------------------

def _lit_azimuth_weight(alpha: float, cos_s: float, sin_s: float) -> float:
    """int over the azimuth beta around the light direction of max(n . w, 0), where w
    makes angle alpha with the light direction and the light makes theta_s with n:
    n . w = cos(alpha) cos(theta_s) + sin(alpha) sin(theta_s) cos(beta)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    across = sa * sin_s
    along = ca * cos_s
    if across <= 0.0:
        beta_max = math.pi if along > 0 else 0.0
    else:
        c = -along / across
        beta_max = math.pi if c <= -1.0 else (0.0 if c >= 1.0 else math.acos(c))
    return 2.0 * (beta_max * along + across * math.sin(beta_max))


@functools.lru_cache(maxsize=8)
def _smoothstep_gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    t = 0.5 * (x + 1.0)
    return t * t * (3.0 - 2.0 * t), 0.5 * w * 6.0 * t * (1.0 - t)


def glow_unit(sigma_t: float, dist: float, cos_theta_s: float, nodes: int = GLOW_NODES,
              phase: Phase = ISOTROPIC) -> float:
    """Irradiance from the light scattered once by the medium at a surface point at
    distance dist from a light, per unit sigma_s * I: the cosine-weighted hemisphere
    integral of the (unshadowed) airlight of the infinite ray leaving the point. Along the
    ray from the point in direction w, the scattering angle at y is between (y - light)
    and -w (0: the light goes on towards the point)."""
    cos_s = float(np.clip(cos_theta_s, -1.0, 1.0))
    if phase.isotropic:
        return _glow_unit_cached(float(sigma_t), float(dist), cos_s, int(nodes))
    return _glow_unit_phase_cached(float(sigma_t), float(dist), cos_s, int(nodes), phase)


def _polar_glow(sigma_t: float, dist: float, cos_s: float, nodes: int, ray_log: Any,
                lobe_widths: Sequence[float] = ()) -> float:
    """The polar reduction of glow_unit: alpha (the angle of the ray from the light
    direction) in pieces cut where the lit azimuth changes form, graded towards the light
    in thick fog and, for each phase lobe of width w, at alpha ~ w and pi - alpha ~ w;
    ray_log(b, h) is the log airlight of the ray per unit sigma_s I."""
    theta = math.acos(cos_s)
    sin_s = math.sin(theta)
    lo, hi = max(0.0, theta - math.pi / 2), min(math.pi, theta + math.pi / 2)
    breaks = [p for p in (math.pi / 2 - theta, 1.5 * math.pi - theta) if lo < p < hi]
    optical = sigma_t * dist
    if optical > 1.0 and lo == 0.0:  # the glow concentrates near the light direction
        breaks += [p for p in (1.0 / math.sqrt(optical), 4.0 / math.sqrt(optical)) if lo < p < hi]
    for width in lobe_widths:
        k = -6
        while width * 2.0 ** k < math.pi:
            a = width * 2.0 ** k
            breaks += [p for p in (a, math.pi - a) if lo < p < hi]
            k += 1
    edges = [lo] + sorted(set(breaks)) + [hi]
    s, w = _smoothstep_gauss(nodes)
    total = 0.0
    for a, c in zip(edges[:-1], edges[1:]):
        for si, wi in zip(s, w):
            alpha = a + (c - a) * si
            weight = _lit_azimuth_weight(alpha, cos_s, sin_s) * math.sin(alpha)
            if weight <= 0.0:
                continue
            total += wi * (c - a) * weight * math.exp(ray_log(dist * math.cos(alpha), dist * math.sin(alpha)))
    return total


@functools.lru_cache(maxsize=100_000)
def _glow_unit_cached(sigma_t: float, dist: float, cos_s: float, nodes: int) -> float:
    return _polar_glow(sigma_t, dist, cos_s, nodes, lambda b, h: airlight_log(sigma_t, 1.0, 1.0, b, h))


@functools.lru_cache(maxsize=100_000)
def _glow_unit_phase_cached(sigma_t: float, dist: float, cos_s: float, nodes: int, phase: Phase) -> float:
    """glow_unit for an anisotropic phase: each ray's airlight by phase_reference's xi rule."""
    return _polar_glow(sigma_t, dist, cos_s, nodes,
                       lambda b, h: airlight_xi_log(sigma_t, 1.0, 1.0, b, h, phase=phase),
                       [w for _, w in phase.widths()])


def glow_hemisphere_bruteforce(sigma_t: float, dist: float, cos_theta_s: float, n_polar: int = 32,
                               n_azimuth: int = 64, phase: Phase = ISOTROPIC) -> float:
    """glow_unit by a plain product rule over the hemisphere in the normal's own polar
    coordinates (for checking the reduction above; only accurate when the light is
    below the horizon, cos_theta_s < 0, so that the integrand has no singularity). With
    an anisotropic phase each ray's airlight is phase_reference's quadrature in x (not the
    xi rule that glow_unit uses)."""
    theta_s = math.acos(cos_theta_s)
    to_light = np.array([math.sin(theta_s), 0.0, cos_theta_s])  # normal = +z
    xp, wp = np.polynomial.legendre.leggauss(n_polar)
    theta = (xp + 1.0) * math.pi / 4.0
    wt = wp * math.pi / 4.0
    phi = (np.arange(n_azimuth) + 0.5) * 2.0 * math.pi / n_azimuth
    total = 0.0
    for th, w in zip(theta, wt):
        for ph in phi:
            omega = np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])
            b = dist * float(omega @ to_light)
            h = dist * float(np.linalg.norm(to_light - (b / dist) * omega))
            if phase.isotropic:
                ray = airlight(sigma_t, 1.0, 1.0, b, h)
            else:
                ray = math.exp(airlight_x_log(sigma_t, 1.0, 1.0, b, h, phase=phase, epsrel=1e-9))
            total += w * (2.0 * math.pi / n_azimuth) * math.cos(th) * math.sin(th) * ray
    return total


def surface_radiance(sc: Scene, point: np.ndarray, normal: np.ndarray, albedo: np.ndarray,
                     lit: Sequence[bool], glow: bool = True) -> np.ndarray:
    """Radiance (3,) leaving a Lambertian surface point (normal facing the viewer)."""
    irradiance = np.zeros(3)
    for j, light in enumerate(sc.lights):
        to_light = light.position - point
        dist = float(np.linalg.norm(to_light))
        if dist <= 0.0:
            continue
        cos_s = float(to_light @ normal) / dist
        if lit[j] and cos_s > 0:
            irradiance += light.intensity * cos_s / max(dist * dist, light.radius ** 2) * np.exp(
                -sc.sigma_t * dist)
        if glow:
            if dist < light.radius:
                raise ValueError("reference: surface point inside a lamp (the renderer clamps D there)")
            for c in range(3):
                if sc.sigma_s[c] > 0 and light.intensity[c] > 0:
                    glow_c = glow_unit(sc.sigma_t[c], dist, cos_s, phase=sc.phase)
                    irradiance[c] += sc.sigma_s[c] * light.intensity[c] * glow_c
    return albedo / math.pi * irradiance


def transmittance(sigma_t: np.ndarray, t: float) -> np.ndarray:
    """exp(-sigma_t t) per channel; an escaping ray (t = inf) keeps what sigma_t = 0 lets through."""
    if math.isinf(t):
        return np.where(sigma_t > 0, 0.0, 1.0)
    return np.exp(-sigma_t * t)


def pixel_radiance(sc: Scene, rows: Sequence[int], cols: Sequence[int], glow: bool = True,
                   airlight_on: bool = True) -> np.ndarray:
    """Reference radiance (N, 3) of the given pixels."""
    dirs = camera_rays(sc, np.asarray(rows), np.asarray(cols))
    tr = trace(sc, dirs)
    out = np.zeros((len(dirs), 3))
    for k, d in enumerate(dirs):
        hid = int(tr.hit_id[k])
        t_hit = float(tr.t_hit[k])
        if hid == BACKGROUND:
            base = sc.background.copy()
        elif hid >= LAMP_BASE:
            light = sc.lights[hid - LAMP_BASE]
            base = light.intensity / (math.pi * light.radius ** 2)
        else:
            base = surface_radiance(sc, tr.point[k], tr.normal[k], sc.surfaces[hid // 8].albedo,
                                    tr.lit[:, k], glow=glow)
        value = base * transmittance(sc.sigma_t, t_hit)
        if airlight_on:
            value = value + ray_airlight(sc, sc.position, d, t_hit)
        out[k] = value
    return out


def cull_reference_radiance(sc: Scene) -> float:
    """The culling reference: max over lights and channels of I max(sigma_s / 4, 1 / (25 pi))."""
    best = 0.0
    for light in sc.lights:
        per_intensity = np.maximum(sc.sigma_s / 4.0, 1.0 / (25.0 * math.pi))
        best = max(best, float(np.max(light.intensity * per_intensity)))
    return best


# ---- pixel selection ---------------------------------------------------------------------------

def subpixel_core_pixels(sc: Scene, centres: Sequence[np.ndarray], margin: int = 2) -> np.ndarray:
    """Mask (H, W) of the pixels within ``margin`` pixels of where each lamp centre
    projects: a lamp smaller than a pixel is drawn box-filtered there (shading.glsl,
    point_lights_pixel_cores), which this reference does not model."""
    h, w = sc.height, sc.width
    mask = np.zeros((h, w), dtype=bool)
    aspect = w / h
    for centre in centres:
        rel = np.asarray(centre, dtype=np.float64) - sc.position
        z = float(rel @ sc.forward)
        if z <= 0:
            continue
        col = (float(rel @ sc.right) / (z * sc.tan_half * aspect) + 1.0) / 2.0 * w - 0.5
        row = (1.0 - float(rel @ sc.up) / (z * sc.tan_half)) / 2.0 * h - 0.5
        r0, r1 = int(np.floor(row)) - margin, int(np.ceil(row)) + margin
        c0, c1 = int(np.floor(col)) - margin, int(np.ceil(col)) + margin
        if r1 < 0 or c1 < 0 or r0 >= h or c0 >= w:
            continue
        mask[max(r0, 0):min(r1, h - 1) + 1, max(c0, 0):min(c1, w - 1) + 1] = True
    return mask


def smooth_pixels(sc: Scene, lamp_gap: float = 2.0) -> tuple[np.ndarray, Trace]:
    """Mask (H, W) of pixels away from geometric edges, shadow boundaries and lamp cores:
    the whole 3x3 neighbourhood sees the same surface face with the same lit state, no
    ray of it passes within ``lamp_gap`` lamp radii of a lamp centre, and none is near
    a lamp core smaller than a pixel (the film border is excluded). Also returns the
    trace of every pixel."""
    h, w = sc.height, sc.width
    tr = trace(sc, camera_rays(sc))
    keys = [tr.hit_id.reshape(h, w)]
    keys += [tr.lit[j].reshape(h, w).astype(np.int64) for j in range(len(sc.lights))]
    near_lamp = (tr.min_lamp_gap < lamp_gap).reshape(h, w) | (tr.hit_id >= LAMP_BASE).reshape(h, w)
    near_lamp |= subpixel_core_pixels(sc, [light.position for light in sc.lights])
    inner = np.ones((h - 2, w - 2), dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            inner &= ~near_lamp[1 + dy:h - 1 + dy, 1 + dx:w - 1 + dx]
            for key in keys:
                inner &= key[1 + dy:h - 1 + dy, 1 + dx:w - 1 + dx] == key[1:-1, 1:-1]
    mask = np.zeros((h, w), dtype=bool)
    mask[1:-1, 1:-1] = inner
    return mask, tr


# ---- helpers shared by the test_airlight_* files --------------------------------------------------

REL_TOL = 5e-3  # accuracy bound on every compared pixel
DIM_FRACTION = 1e-3  # pixels below this fraction of the image maximum are not compared

_RENDERERS: dict[str, Any] = {}


def get_renderer(backend: str) -> Any:
    """One airlight.Renderer per backend, shared by the test_airlight_* files; skips
    the calling test where the backend cannot run."""
    import pytest

    import airlight

    if backend == "gl":
        reason = airlight.gl_unavailable_reason()
        if reason is not None:
            pytest.skip(f"GL backend unavailable: {reason}")
    if backend not in _RENDERERS:
        _RENDERERS[backend] = airlight.Renderer(backend)
    return _RENDERERS[backend]


def light(position: Sequence[float], intensity: Any = 100.0,
          radius: float = DEFAULT_LAMP_RADIUS) -> dict[str, Any]:
    return {"type": "point", "position": [float(v) for v in position], "intensity": intensity,
            "radius": radius}


def plane(point: Sequence[float], normal: Sequence[float], albedo: Any = 0.5) -> dict[str, Any]:
    return {"type": "plane", "point": [float(v) for v in point], "normal": [float(v) for v in normal],
            "albedo": albedo}


def box(lo: Sequence[float], hi: Sequence[float], albedo: Any = 0.5) -> dict[str, Any]:
    return {"type": "box", "min": [float(v) for v in lo], "max": [float(v) for v in hi], "albedo": albedo}


def sphere(center: Sequence[float], radius: float, albedo: Any = 0.5) -> dict[str, Any]:
    return {"type": "sphere", "center": [float(v) for v in center], "radius": float(radius), "albedo": albedo}


def make_scene(position: Sequence[float], look_at: Sequence[float], lights: list[dict[str, Any]],
               surfaces: list[dict[str, Any]] | None = None, sigma_t: Any = 0.1, albedo: Any = 1.0,
               fov_y: float = 60.0, width: int = 48, height: int = 32, cull_fraction: float | None = 0.0,
               up: Sequence[float] = (0.0, 1.0, 0.0),
               phase: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """A scene dict; sigma_t None means no medium; cull_fraction None keeps the default;
    phase: the medium's phase (None: isotropic)."""
    scene: dict[str, Any] = {
        "film": {"width": width, "height": height},
        "camera": {"position": [float(v) for v in position], "look_at": [float(v) for v in look_at],
                   "up": [float(v) for v in up], "fov_y": fov_y},
        "lights": lights,
        "surfaces": surfaces or [],
        "background": [0.0, 0.0, 0.0],
    }
    if sigma_t is not None:
        scene["medium"] = {"sigma_t": sigma_t, "albedo": albedo,
                           "phase": dict(phase) if phase is not None else {"type": "isotropic"}}
    if cull_fraction is not None:
        scene["quality"] = {"cull_fraction": cull_fraction}
    return scene


@dataclass
class Samples:
    rows: np.ndarray
    cols: np.ndarray
    reference: np.ndarray  # (N, 3)
    threshold: float  # radiance below which a channel value is not compared
    hit_id: np.ndarray  # (N,)


_SAMPLE_CACHE: dict[tuple[str, int, int], Samples] = {}


def reference_samples(scene: dict[str, Any], n: int = 40, seed: int = 0, n_bright: int = 6) -> Samples:
    """Pixels to compare and their reference radiance (cached per scene): ``n`` pixels
    among those away from edges, shadow boundaries and lamps (:func:`smooth_pixels`) whose
    CPU-rendered radiance exceeds DIM_FRACTION of the maximum over such pixels: the
    ``n_bright`` brightest and the rest drawn at random."""
    key = (json.dumps(scene, sort_keys=True), n, seed)
    if key in _SAMPLE_CACHE:
        return _SAMPLE_CACHE[key]
    sc = parse_scene(scene)
    mask, tr = smooth_pixels(sc)
    assert mask.any(), "no pixel away from edges and lamps: fix the test scene"
    cpu = np.asarray(get_renderer("cpu").render(scene), dtype=np.float64)
    brightness = np.where(np.isfinite(cpu), cpu, 0.0).max(axis=2)
    peak = float(brightness[mask].max())
    threshold = DIM_FRACTION * peak
    rows, cols = np.nonzero(mask & (brightness > threshold))
    order = np.argsort(-brightness[rows, cols], kind="stable")
    bright = order[:n_bright]
    rest = order[n_bright:]
    rng = np.random.default_rng(seed)
    pick = np.concatenate([bright, rng.choice(rest, size=min(len(rest), n - len(bright)), replace=False)])
    rows, cols = rows[pick], cols[pick]
    ref = pixel_radiance(sc, rows, cols)
    samples = Samples(rows, cols, ref, threshold, tr.hit_id.reshape(sc.height, sc.width)[rows, cols])
    _SAMPLE_CACHE[key] = samples
    return samples


def compare(image: np.ndarray, samples: Samples, rel_tol: float = REL_TOL, min_values: int = 20,
            label: str = "") -> float:
    """Asserts |image - reference| <= rel_tol * reference on every sampled channel value
    above the threshold; returns the worst relative error."""
    got = np.asarray(image, dtype=np.float64)[samples.rows, samples.cols]
    ref = samples.reference
    assert np.all(np.isfinite(got)), f"{label}: non-finite radiance {got[~np.isfinite(got)]}"
    use = ref > samples.threshold
    assert use.sum() >= min_values, f"{label}: only {use.sum()} channel values compared"
    rel = np.abs(got - ref) / np.where(use, ref, 1.0)
    rel = np.where(use, rel, 0.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    k, c = worst
    assert rel[worst] <= rel_tol, (
        f"{label}: relative error {rel[worst]:.3e} > {rel_tol} at pixel (row {samples.rows[k]}, col "
        f"{samples.cols[k]}) channel {c} (hit id {samples.hit_id[k]}): rendered {got[k, c]:.7e}, "
        f"reference {ref[k, c]:.7e}; {int((rel > rel_tol).sum())} of {int(use.sum())} values fail")
    return float(rel[worst])
