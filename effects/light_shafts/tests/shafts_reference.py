"""Float64 numpy reference for light shafts: sunlight scattered once by the homogeneous fog
(`medium`) toward the camera, along the parts of each pixel's ray that the sun reaches.

Independent of the renderer (no airlight import): it reads the scene dict itself.

Geometry. A pixel's ray is x(t) = o + t d (o the camera position, d unit), t in [0, t_hit] with
t_hit the distance to the first surface (+inf if none). With s the unit direction toward the sun,
a point x is in shadow when the half-line x + u s, u > 0, meets a surface. For a convex caster C
the shadowed set is the caster swept away from the sun, C + {u s : u >= 0}, which is convex, so
its trace on the view ray is ONE interval of t, computed exactly per caster:

- plane (point p, normal n; a two-sided surface): x + u s meets it for some u > 0 iff
  ((x - p) . n) (s . n) < 0, the open half-space on the side away from the sun (nothing when
  s . n = 0). On the ray this is a half-line in t (or all or nothing).
- box [lo, hi]: the set {(t, u) : lo_i <= o_i + t d_i + u s_i <= hi_i (i = x, y, z), u >= 0}
  is a convex polygon; its projection on t is the interval, found by Fourier-Motzkin
  elimination of u (every pair of a lower and an upper bound on u gives a bound on t).
- sphere (centre c, radius r): with w = x - c, min over u >= 0 of |w + u s| is |w| when
  w . s >= 0, else |w - (w . s) s|. The shadow is the ball |w| <= r united with the half-cylinder
  |w - (w . s) s| <= r, w . s <= 0; on the ray each is an interval (a quadratic, and a quadratic
  intersected with a half-line), and their union is their hull (the union is convex).

The union over casters, clipped to [0, t_hit], is the shadow; its complement in [0, t_hit] the lit
set.

Radiance. Per RGB channel c, with sigma_s = albedo sigma_t and E the sun's irradiance:

    L_c = sum over lit [a, b] of
          sigma_s,c p(cos theta) E_c (exp(-sigma_t,c a) - exp(-sigma_t,c b)) / sigma_t,c,

cos theta = s . d (the light travels along -s, then along -d toward the camera: looking at the
sun is forward scattering). p is isotropic 1/(4 pi), Henyey-Greenstein
(1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^1.5), Rayleigh 3/(16 pi) (1 + cos^2 theta) or two HG
lobes w HG(g1) + (1 - w) HG(g2); |g| is clamped to 0.999 as the renderer does (README,
`medium.phase`). sigma_t,c = 0 gives 0 (no scatterers). b may be +inf. A sun below the horizon
(s_y <= 0) lights nothing (README, `sun`), so the result is 0 then.

Everything is vectorised over rays: the per-ray API (`shadow_intervals`, `lit_intervals`,
`first_hit` with one direction) is the same code with one row.

A point lamp with volumetric shadows (`lamp_shadow_intervals`, `lamp_airlight_radiance`) follows at
the end of the file, with its own notes: shadow intervals vectorised as above, the radiance one
scipy quad per lit piece in an angle variable.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

KOSCHMIEDER = 3.912  # sigma_t = 3.912 / V (2 % contrast), include/airlight/scene.hpp
PHASE_G_LIMIT = 0.999  # rendering clamps |g| to this (README, medium.phase)

Interval = tuple[float, float]


# --------------------------------------------------------------------------------------------
# Scene reading
# --------------------------------------------------------------------------------------------


def _load(scene: Any) -> dict:
    """The scene as a dict: a dict as is, a JSON file path, or JSON text."""
    if isinstance(scene, dict):
        return scene
    if isinstance(scene, Path) or (isinstance(scene, str) and not scene.lstrip().startswith("{")):
        return json.loads(Path(scene).read_text())
    return json.loads(scene)


def rgb(value: Any, default: float | None = None) -> np.ndarray:
    """An RGB value given as a number (every channel) or a 3-list, as float64 (3,)."""
    if value is None:
        if default is None:
            raise ValueError("missing RGB value")
        value = default
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        return np.full(3, float(a))
    if a.shape != (3,):
        raise ValueError(f"expected a number or 3 numbers, got {value!r}")
    return a.copy()


def _unit(v: Any) -> np.ndarray:
    a = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(a)
    if not n > 0:
        raise ValueError(f"zero vector {v!r}")
    return a / n


def sun_direction(sun: dict) -> np.ndarray:
    """Unit direction toward the sun: `direction` normalised, or from elevation el and azimuth az
    (degrees): (sin az cos el, sin el, -cos az cos el)."""
    if "direction" in sun:
        return _unit(sun["direction"])
    el = math.radians(float(sun["elevation"]))
    az = math.radians(float(sun["azimuth"]))
    return np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])


def medium_coefficients(medium: dict) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_t, sigma_s) RGB of the homogeneous medium: sigma_t given, or 3.912 / visibility on
    every channel; sigma_s = albedo sigma_t (albedo default 1)."""
    if ("sigma_t" in medium) == ("visibility" in medium):
        raise ValueError("medium needs exactly one of sigma_t and visibility")
    if "sigma_t" in medium:
        sigma_t = rgb(medium["sigma_t"])
    else:
        sigma_t = np.full(3, KOSCHMIEDER / float(medium["visibility"]))
    albedo = rgb(medium.get("albedo"), 1.0)
    return sigma_t, albedo * sigma_t


def _hg(cos_theta: np.ndarray, g: float) -> np.ndarray:
    """Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^1.5)."""
    g = float(np.clip(g, -PHASE_G_LIMIT, PHASE_G_LIMIT))
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * cos_theta) ** 1.5)


def phase_value(phase: dict | None, cos_theta: np.ndarray) -> np.ndarray:
    """p(cos theta) per steradian for the scene's `medium.phase` (isotropic when absent)."""
    cos_theta = np.asarray(cos_theta, dtype=np.float64)
    kind = "isotropic" if phase is None else phase.get("type", "isotropic")
    if kind == "isotropic":
        return np.full_like(cos_theta, 1.0 / (4.0 * math.pi))
    if kind == "hg":
        return _hg(cos_theta, phase.get("g", 0.0))
    if kind == "rayleigh":
        return 3.0 / (16.0 * math.pi) * (1.0 + cos_theta**2)
    if kind == "hg2":
        w = float(phase["forward_weight"])
        return w * _hg(cos_theta, phase["forward_g"]) + (1.0 - w) * _hg(cos_theta, phase["backward_g"])
    raise ValueError(f"unknown phase type {kind!r}")


# --------------------------------------------------------------------------------------------
# Camera
# --------------------------------------------------------------------------------------------


def camera_rays(scene: Any, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), unit directions (H, W, 3)) of the pixel rays, as cpp/frame_data.cpp and
    shaders/geometry.glsl `camera_ray_direction` build them (in float64):

        forward = normalize(look_at - position), right = normalize(forward x up),
        up' = right x forward, R = right tan(fov_y / 2) W / H, U = up' tan(fov_y / 2),
        sx = 2 (x + 0.5) / W - 1, sy = 1 - 2 (row + 0.5) / H   (pixel centres, row 0 on top),
        d = normalize(forward + sx R + sy U).
    """
    cam = _load(scene)["camera"]
    position = np.asarray(cam["position"], dtype=np.float64)
    forward = _unit(np.asarray(cam["look_at"], dtype=np.float64) - position)
    right = _unit(np.cross(forward, np.asarray(cam["up"], dtype=np.float64)))
    up = np.cross(right, forward)
    tan_half = math.tan(0.5 * math.radians(float(cam["fov_y"])))
    right = right * (tan_half * width / height)
    up = up * tan_half
    sx = 2.0 * (np.arange(width) + 0.5) / width - 1.0
    sy = 1.0 - 2.0 * (np.arange(height) + 0.5) / height
    d = forward + sx[None, :, None] * right + sy[:, None, None] * up
    return position, d / np.linalg.norm(d, axis=-1, keepdims=True)


# --------------------------------------------------------------------------------------------
# First hit (vectorised over rays: dirs (N, 3) -> (N,))
# --------------------------------------------------------------------------------------------


def _ball_interval(w0: np.ndarray, dirs: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    """t with |w0 + t d| <= r (|d| = 1): [-b - h, -b + h], b = w0 . d, h^2 = r^2 - dist^2 formed as
    (r - dist)(r + dist) (dist: distance of the line from the centre); empty: (+inf, -inf)."""
    b = dirs @ w0
    dist = np.linalg.norm(w0[None, :] - b[:, None] * dirs, axis=-1)
    h2 = (r - dist) * (r + dist)
    ok = h2 >= 0.0
    h = np.sqrt(np.where(ok, h2, 0.0))
    return np.where(ok, -b - h, np.inf), np.where(ok, -b + h, -np.inf)


def _surface_hit(origin: np.ndarray, dirs: np.ndarray, surface: dict) -> np.ndarray:
    """Nearest t > 0 where each ray meets `surface` (+inf if none); from inside a box or sphere,
    where it leaves (as the renderer's intersect_surface)."""
    kind = surface["type"]
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "plane":
            # (o + t d - p) . n = 0  ->  t = (p - o) . n / (d . n)
            n = _unit(surface["normal"])
            denom = dirs @ n
            t = ((np.asarray(surface["point"], dtype=np.float64) - origin) @ n) / denom
            return np.where((denom != 0.0) & (t > 0.0) & np.isfinite(t), t, np.inf)
        if kind == "box":
            # Slabs: per axis, lo_i <= o_i + t d_i <= hi_i; an axis with d_i = 0 is all t or none.
            lo = np.asarray(surface["min"], dtype=np.float64)
            hi = np.asarray(surface["max"], dtype=np.float64)
            ta = (lo - origin)[None, :] / dirs
            tb = (hi - origin)[None, :] / dirs
            parallel = dirs == 0.0
            inside = ((lo <= origin) & (origin <= hi))[None, :]
            t_lo = np.where(parallel, np.where(inside, -np.inf, np.inf), np.minimum(ta, tb))
            t_hi = np.where(parallel, np.where(inside, np.inf, -np.inf), np.maximum(ta, tb))
            t_near = t_lo.max(axis=-1)
            t_far = t_hi.min(axis=-1)
            t = np.where(t_near > 0.0, t_near, t_far)
            return np.where((t_near <= t_far) & (t > 0.0), t, np.inf)
        if kind == "sphere":
            c = np.asarray(surface["center"], dtype=np.float64)
            t0, t1 = _ball_interval(origin - c, dirs, float(surface["radius"]))
            t = np.where(t0 > 0.0, t0, t1)
            return np.where(np.isfinite(t) & (t > 0.0), t, np.inf)
    raise ValueError(f"unknown surface type {kind!r}")


def first_hit(origin: Any, dir: Any, surfaces: Sequence[dict]) -> Any:
    """Distance t > 0 to the first surface along o + t d (+inf if none). `dir` (3,) gives a float,
    (..., 3) an array of shape (...). Directions must be unit (t is then a distance)."""
    origin = np.asarray(origin, dtype=np.float64)
    d = np.asarray(dir, dtype=np.float64)
    flat = d.reshape(-1, 3)
    t = np.full(flat.shape[0], np.inf)
    for surface in surfaces:
        t = np.minimum(t, _surface_hit(origin, flat, surface))
    return float(t[0]) if d.ndim == 1 else t.reshape(d.shape[:-1])


# --------------------------------------------------------------------------------------------
# Shadow interval of one caster (vectorised over rays: dirs (N, 3) -> lo (N,), hi (N,))
# Empty: lo = +inf, hi = -inf; the whole line: (-inf, +inf).
# --------------------------------------------------------------------------------------------


def _half_line(k0: np.ndarray, k1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The set {t : k0 + k1 t <= 0} as (lo, hi)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        root = -k0 / k1
    lo = np.where(k1 > 0.0, -np.inf, np.where(k1 < 0.0, root, np.where(k0 <= 0.0, -np.inf, np.inf)))
    hi = np.where(k1 > 0.0, root, np.where(k1 < 0.0, np.inf, np.where(k0 <= 0.0, np.inf, -np.inf)))
    return lo, hi


def _plane_shadow(origin, dirs, s, surface) -> tuple[np.ndarray, np.ndarray]:
    """Half-space away from the sun: ((x - p) . n) sign(s . n) < 0, x = o + t d."""
    n = _unit(surface["normal"])
    sn = float(s @ n)
    if sn == 0.0:  # sun in the plane: its rays never cross it
        return np.full(len(dirs), np.inf), np.full(len(dirs), -np.inf)
    sign = math.copysign(1.0, sn)
    k0 = np.full(len(dirs), sign * float((origin - np.asarray(surface["point"], dtype=np.float64)) @ n))
    return _half_line(k0, sign * (dirs @ n))


def _box_shadow(origin, dirs, s, surface) -> tuple[np.ndarray, np.ndarray]:
    """Projection on t of {(t, u) : A t + B u <= C} by Fourier-Motzkin elimination of u.

    Rows, per axis i:  d_i t + s_i u <= hi_i - o_i,   -d_i t - s_i u <= o_i - lo_i;  and -u <= 0.
    A row j with B_j < 0 bounds u below, a row k with B_k > 0 above; B_k (row j) - B_j (row k)
    eliminates u: (B_k A_j - B_j A_k) t <= B_k C_j - B_j C_k. Rows with B = 0 bound t directly.
    Each alpha t <= beta gives t <= beta / alpha (alpha > 0), t >= beta / alpha (alpha < 0), or
    nothing / infeasibility (alpha = 0, beta >= 0 / beta < 0). FM is exact: the result is the
    projection of the polygon.
    """
    lo_box = np.asarray(surface["min"], dtype=np.float64)
    hi_box = np.asarray(surface["max"], dtype=np.float64)
    n = len(dirs)
    A = np.concatenate([dirs, -dirs, np.zeros((n, 1))], axis=1)  # (N, 7)
    B = np.concatenate([s, -s, [-1.0]])  # (7,): the same for every ray
    C = np.concatenate([hi_box - origin, origin - lo_box, [0.0]])  # (7,)
    alphas, betas = [], []
    for j in range(7):
        if B[j] == 0.0:
            alphas.append(A[:, j])
            betas.append(np.full(n, C[j]))
        elif B[j] < 0.0:
            for k in range(7):
                if B[k] > 0.0:
                    alphas.append(B[k] * A[:, j] - B[j] * A[:, k])
                    betas.append(np.full(n, B[k] * C[j] - B[j] * C[k]))
    alpha = np.stack(alphas, axis=1)
    beta = np.stack(betas, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = beta / alpha
    lo = np.where(alpha < 0.0, bound, -np.inf).max(axis=1)
    hi = np.where(alpha > 0.0, bound, np.inf).min(axis=1)
    infeasible = ((alpha == 0.0) & (beta < 0.0)).any(axis=1) | ~(lo <= hi)
    return np.where(infeasible, np.inf, lo), np.where(infeasible, -np.inf, hi)


def _sphere_shadow(origin, dirs, s, surface) -> tuple[np.ndarray, np.ndarray]:
    """Ball |w| <= r united with the half-cylinder |w - (w . s) s| <= r, w . s <= 0 (w = x - c)."""
    c = np.asarray(surface["center"], dtype=np.float64)
    r = float(surface["radius"])
    w0 = origin - c
    ball_lo, ball_hi = _ball_interval(w0, dirs, r)
    # Infinite cylinder: |wp + t dp|^2 <= r^2 with wp, dp the parts across s.
    wp = w0 - (w0 @ s) * s
    dp = dirs - (dirs @ s)[:, None] * s[None, :]
    a2 = np.einsum("ij,ij->i", dp, dp)
    with np.errstate(divide="ignore", invalid="ignore"):
        tc = np.where(a2 > 0.0, -(dp @ wp) / a2, 0.0)  # t nearest the axis
        dist = np.linalg.norm(wp[None, :] + tc[:, None] * dp, axis=-1)
        h2 = (r - dist) * (r + dist)
        ok = h2 >= 0.0
        h = np.where(a2 > 0.0, np.sqrt(np.where(ok, h2, 0.0) / np.where(a2 > 0.0, a2, 1.0)), np.inf)
    cyl_lo = np.where(ok, tc - h, np.inf)
    cyl_hi = np.where(ok, tc + h, -np.inf)
    # Half-space w . s <= 0: (w0 . s) + t (d . s) <= 0.
    hs_lo, hs_hi = _half_line(np.full(len(dirs), float(w0 @ s)), dirs @ s)
    hc_lo, hc_hi = np.maximum(cyl_lo, hs_lo), np.minimum(cyl_hi, hs_hi)
    hc_empty = ~(hc_lo <= hc_hi)
    ball_empty = ~(ball_lo <= ball_hi)
    # Union of two intervals of a convex set's trace: their hull (they overlap or touch).
    lo = np.where(hc_empty, ball_lo, np.where(ball_empty, hc_lo, np.minimum(ball_lo, hc_lo)))
    hi = np.where(hc_empty, ball_hi, np.where(ball_empty, hc_hi, np.maximum(ball_hi, hc_hi)))
    return lo, hi


_CASTERS = {"plane": _plane_shadow, "box": _box_shadow, "sphere": _sphere_shadow}


def caster_shadow_arrays(origin: Any, dirs: Any, sun_dir: Any, surfaces: Sequence[dict]):
    """Per ray and caster, the shadowed interval of t on the whole line (unclipped):
    lo, hi of shape (N, K) for dirs (N, 3) and K surfaces; empty: lo = +inf, hi = -inf."""
    origin = np.asarray(origin, dtype=np.float64)
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    s = _unit(sun_dir)
    lo = np.empty((len(dirs), len(surfaces)))
    hi = np.empty((len(dirs), len(surfaces)))
    for k, surface in enumerate(surfaces):
        lo[:, k], hi[:, k] = _CASTERS[surface["type"]](origin, dirs, s, surface)
    return lo, hi


# --------------------------------------------------------------------------------------------
# Union and lit set
# --------------------------------------------------------------------------------------------


def _clip_sort(lo, hi, t_max):
    """Clip to [0, t_max]; empty ones (lo >= hi) become (+inf, +inf); sorted by lo per ray."""
    lo = np.maximum(lo, 0.0)
    hi = np.minimum(hi, np.asarray(t_max, dtype=np.float64).reshape(-1, 1))
    valid = lo < hi
    lo = np.where(valid, lo, np.inf)
    hi = np.where(valid, hi, np.inf)
    order = np.argsort(lo, axis=1, kind="stable")
    return np.take_along_axis(lo, order, 1), np.take_along_axis(hi, order, 1)


def shadow_intervals(origin: Any, dir: Any, sun_dir: Any, surfaces: Sequence[dict],
                     t_max: float = math.inf) -> list[Interval]:
    """Shadowed parts of the ray o + t d within [0, t_max]: sorted, disjoint, merged (intervals
    that overlap or touch are joined)."""
    lo, hi = caster_shadow_arrays(origin, np.asarray(dir, dtype=np.float64)[None, :], sun_dir, surfaces)
    lo, hi = _clip_sort(lo, hi, t_max)
    merged: list[list[float]] = []
    for a, b in zip(lo[0], hi[0]):
        if not np.isfinite(a):
            break
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], float(b))
        else:
            merged.append([float(a), float(b)])
    return [(a, b) for a, b in merged]


def lit_intervals(origin: Any, dir: Any, sun_dir: Any, surfaces: Sequence[dict],
                  t_max: float | None = None) -> list[Interval]:
    """The complement of `shadow_intervals` in [0, t_max] (t_max: `first_hit` by default)."""
    if t_max is None:
        t_max = first_hit(origin, dir, surfaces)
    lit, pos = [], 0.0
    for a, b in shadow_intervals(origin, dir, sun_dir, surfaces, t_max):
        if a > pos:
            lit.append((pos, a))
        pos = max(pos, b)
    if t_max > pos:
        lit.append((pos, float(t_max)))
    return lit


def _exp_segment(a, b, sigma_t):
    """(exp(-sigma_t a) - exp(-sigma_t b)) / sigma_t per channel, formed as
    -exp(-sigma_t a) expm1(-sigma_t (b - a)) / sigma_t (no cancellation for short segments);
    a (N,), b (N,) with a <= b (b may be +inf); sigma_t (3,) > 0."""
    with np.errstate(invalid="ignore", over="ignore"):
        length = (b - a)[:, None]
        return -np.exp(-sigma_t * a[:, None]) * np.expm1(-sigma_t * length) / sigma_t


def lit_transmittance_integral(origin: Any, dirs: Any, sun_dir: Any, surfaces: Sequence[dict],
                               sigma_t: Any, t_hit: Any = None) -> np.ndarray:
    """Sum over lit [a, b] of (exp(-sigma_t a) - exp(-sigma_t b)) / sigma_t, per ray and channel:
    (N, 3) for dirs (N, 3). Channels with sigma_t = 0 give the lit length (unused by the radiance,
    which multiplies by sigma_s = 0 there). Sweep over the casters' clipped intervals sorted by
    start: `pos` is the end of the shadow so far; a start beyond it closes the lit gap [pos, start]."""
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    sigma_t = rgb(sigma_t)
    if t_hit is None:
        t_hit = first_hit(origin, dirs, surfaces)
    t_hit = np.asarray(t_hit, dtype=np.float64).reshape(-1)
    lo, hi = _clip_sort(*caster_shadow_arrays(origin, dirs, sun_dir, surfaces), t_hit)
    positive = sigma_t > 0.0
    safe_sigma = np.where(positive, sigma_t, 1.0)

    def segment(a, b):
        length = np.where(b > a, b - a, 0.0)
        seg = _exp_segment(a, np.where(b > a, b, a), safe_sigma)
        return np.where(positive[None, :], np.nan_to_num(seg, nan=0.0), length[:, None])

    total = np.zeros((len(dirs), 3))
    pos = np.zeros(len(dirs))
    for k in range(lo.shape[1]):
        a, b = lo[:, k], hi[:, k]
        valid = np.isfinite(a)
        gap = valid & (a > pos)
        total += np.where(gap[:, None], segment(pos, np.where(gap, a, pos)), 0.0)
        pos = np.where(valid, np.maximum(pos, b), pos)
    gap = t_hit > pos
    total += np.where(gap[:, None], segment(np.where(gap, pos, 0.0), np.where(gap, t_hit, 0.0)), 0.0)
    return total


def medium_sun_radiance(scene: Any, width: int, height: int) -> np.ndarray:
    """Radiance (W/(m^2 sr)) of the sunlight the homogeneous medium scatters once toward the
    camera along the lit parts of each pixel's ray, float64 (H, W, 3):

        L_c = sigma_s,c p(s . d) E_c sum_lit (exp(-sigma_t,c a) - exp(-sigma_t,c b)) / sigma_t,c.

    0 without a medium or a sun, with the sun below the horizon, and on channels with
    sigma_t = 0."""
    scene = _load(scene)
    out = np.zeros((height, width, 3))
    medium, sun = scene.get("medium"), scene.get("sun")
    if not medium or not sun:
        return out
    s = sun_direction(sun)
    if s[1] <= 0.0:  # on or below the horizon it lights nothing (README, `sun`)
        return out
    irradiance = rgb(sun.get("irradiance"), 0.0)
    sigma_t, sigma_s = medium_coefficients(medium)
    surfaces = scene.get("surfaces") or []
    origin, dirs = camera_rays(scene, width, height)
    flat = dirs.reshape(-1, 3)
    integral = lit_transmittance_integral(origin, flat, s, surfaces, sigma_t)
    integral[:, sigma_t == 0.0] = 0.0  # no scatterers (the lit length there may be +inf)
    p = phase_value(medium.get("phase"), flat @ s)
    radiance = sigma_s[None, :] * p[:, None] * irradiance[None, :] * integral
    return radiance.reshape(height, width, 3)


# ============================================================================================
# A point lamp with volumetric shadows
# ============================================================================================
#
# Geometry. With the lamp at l, a point x is shadowed when the SEGMENT [x, l] meets a surface.
# For a convex caster C (l outside it) the shadowed set is S = {l + lam (c - l) : c in C,
# lam >= 1}, convex, so its trace on a view line is ONE interval of t, computed exactly:
#
# - plane: the closed half-space on the side opposite the lamp, sigma (x - p) . n <= 0 with
#   sigma = sign((l - p) . n); nothing when the lamp is in the plane.
# - box: S = K n F with K = l + R+ (C - l) the cone from l over the box and F the intersection of
#   the half-spaces behind the faces that face l (x_i >= lo_i where l_i < lo_i, x_i <= hi_i where
#   l_i > hi_i). Proof: for x in K the ray from l through x enters C at e on a front face f (the
#   outward distance g_f falls from g_f(l) > 0 to g_f(e) = 0); x lies beyond e iff g_f(x) <= 0,
#   and then every front face's g, linear along the ray and > 0 at l, <= 0 at e, is <= 0 at x too.
#   K's facets are planes through l and an edge of the box that support the box (the other six
#   corners on one side): all 12 edges are tried, and a supporting plane through l is a valid
#   half-space of K even where it is not a facet. The view line is clipped against these at most
#   3 + 12 half-spaces (each a half-line in t, as for the sun's plane): exact, no vertex search.
# - sphere (centre c, radius r, D = |c - l| > r): S is the ball united with the forward nappe of
#   the cone from l tangent to the sphere (axis a = (c - l) / D, sin(alpha) = r / D) beyond the
#   plane of the tangent circle, (x - l) . a >= D cos^2(alpha): a point of the cone before that
#   plane but beyond the near cap is in the ball, and one beyond the plane lies behind the near
#   cap (the visible cap has (x - l) . a <= D cos^2 alpha). The plane's half-space also selects the
#   forward nappe. Inside the double cone: |x_perp|^2 <= sin^2(alpha) |x - l|^2 (x_perp the part
#   of x - l across a), a quadratic in t; its solution set is an interval or two half-lines (one per
#   nappe: the forward one is t -> +inf when d . a > 0).
# - A lamp inside (or on) a box or sphere: everything outside is dark, [0, t_max].
#
# Radiance. L_c = sigma_s,c I_c sum over lit [a, c] of
#     int_a^c p(cos theta) exp(-sigma_t,c (x + d(x))) / d(x)^2 dx,   d(x) = |o + x d - l|,
# cos theta = unit(x - l) . (-d). With b = (l - o) . d (closest approach) and h = |o + b d - l|:
# right of b, phi = atan2(h, x - b) in (0, pi/2]: x - b = h cot phi, dx / d^2 = -dphi / h,
# x + d = b + h cot(phi / 2), cos theta = -cos phi; left of b, psi = atan2(h, b - x):
# dx / d^2 = dpsi / h, x + d = b + h tan(psi / 2), cos theta = cos psi. The integrands in the angle
# are smooth and bounded (no 1/d^2 peak), and small angles (far points, grazing rays) keep their
# relative precision. Each is integrated by scipy quad (epsrel 1e-12).


def _merged(lo_row: np.ndarray, hi_row: np.ndarray) -> list[Interval]:
    """Intervals sorted by start (empty ones at +inf) joined where they overlap or touch."""
    merged: list[list[float]] = []
    for a, b in zip(lo_row, hi_row):
        if not np.isfinite(a):
            break
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], float(b))
        else:
            merged.append([float(a), float(b)])
    return [(a, b) for a, b in merged]


def _clip_lines(origin, dirs, normals, offsets) -> tuple[np.ndarray, np.ndarray]:
    """{t : n_k . (o + t d) <= h_k for every k} as (lo, hi) per ray; empty: (+inf, -inf)."""
    lo = np.full(len(dirs), -np.inf)
    hi = np.full(len(dirs), np.inf)
    for n, h in zip(normals, offsets):
        a, b = _half_line(np.full(len(dirs), float(n @ origin - h)), dirs @ n)
        lo, hi = np.maximum(lo, a), np.minimum(hi, b)
    empty = ~(lo <= hi)
    return np.where(empty, np.inf, lo), np.where(empty, -np.inf, hi)


def _everything(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.full(n, -np.inf), np.full(n, np.inf)


def _nothing(n: int) -> tuple[np.ndarray, np.ndarray]:
    return np.full(n, np.inf), np.full(n, -np.inf)


def _plane_lamp_shadow(origin, dirs, lamp, surface) -> tuple[np.ndarray, np.ndarray]:
    n = _unit(surface["normal"])
    p = np.asarray(surface["point"], dtype=np.float64)
    side = float((lamp - p) @ n)
    if side == 0.0:  # lamp in the plane: no segment to it crosses the plane
        return _nothing(len(dirs))
    sign = math.copysign(1.0, side)
    return _clip_lines(origin, dirs, [sign * n], [sign * float(p @ n)])


def box_lamp_halfspaces(lamp: Any, box: dict) -> tuple[list[np.ndarray], list[float]] | None:
    """(normals n_k, offsets h_k) with S = {x : n_k . x <= h_k}: the front faces' half-spaces and
    the planes through the lamp and the box's supporting edges. None if the lamp is inside the box
    (or on it)."""
    lamp = np.asarray(lamp, dtype=np.float64)
    lo = np.asarray(box["min"], dtype=np.float64)
    hi = np.asarray(box["max"], dtype=np.float64)
    if np.all((lo <= lamp) & (lamp <= hi)):
        return None
    normals: list[np.ndarray] = []
    offsets: list[float] = []
    for i in range(3):
        e = np.eye(3)[i]
        if lamp[i] < lo[i]:
            normals.append(-e)
            offsets.append(-lo[i])
        elif lamp[i] > hi[i]:
            normals.append(e)
            offsets.append(hi[i])
    corners = np.array([[(lo, hi)[(k >> i) & 1][i] for i in range(3)] for k in range(8)])
    rel = corners - lamp
    scale = float(np.abs(rel).max())
    for k in range(8):
        for i in range(3):
            if (k >> i) & 1:
                continue
            q = k | (1 << i)  # the edge from corner k to corner q, along axis i
            n = np.cross(rel[k], rel[q])
            norm = float(np.linalg.norm(n))
            if norm == 0.0:  # the lamp on the edge's line: the faces' other edges give the planes
                continue
            n = n / norm
            side = rel @ n
            tol = 1e-12 * scale
            if np.all(side <= tol):
                normals.append(n)
            elif np.all(side >= -tol):
                normals.append(-n)
            else:
                continue
            offsets.append(float(normals[-1] @ lamp))
    return normals, offsets


def _box_lamp_shadow(origin, dirs, lamp, surface) -> tuple[np.ndarray, np.ndarray]:
    spaces = box_lamp_halfspaces(lamp, surface)
    if spaces is None:
        return _everything(len(dirs))
    return _clip_lines(origin, dirs, *spaces)


def _sphere_lamp_shadow(origin, dirs, lamp, surface) -> tuple[np.ndarray, np.ndarray]:
    c = np.asarray(surface["center"], dtype=np.float64)
    r = float(surface["radius"])
    axis = c - lamp
    dist = float(np.linalg.norm(axis))
    if dist <= r:
        return _everything(len(dirs))
    axis /= dist
    sin2 = (r / dist) ** 2
    plane = (dist - r) * (dist + r) / dist  # D cos^2(alpha): the tangent circle's plane
    ball_lo, ball_hi = _ball_interval(origin - c, dirs, r)
    w0 = origin - lamp
    s0, s1 = float(w0 @ axis), dirs @ axis
    # Beyond the plane: plane - (s0 + t s1) <= 0.
    pl_lo, pl_hi = _half_line(np.full(len(dirs), plane - s0), -s1)
    # Inside the double cone: g(t) = |w0p + t dp|^2 - sin2 |w0 + t d|^2 <= 0, g = A t^2 + 2 B t + C.
    w0p = w0 - s0 * axis
    dp = dirs - s1[:, None] * axis[None, :]
    A = np.einsum("ij,ij->i", dp, dp) - sin2
    B = dp @ w0p - sin2 * (dirs @ w0)
    C = float(w0p @ w0p - sin2 * (w0 @ w0))
    disc = B * B - A * C
    with np.errstate(divide="ignore", invalid="ignore"):
        sq = np.sqrt(np.maximum(disc, 0.0))
        q = -(B + np.copysign(sq, B))
        r1 = np.where(q != 0.0, q / A, 0.0)
        r2 = np.where(q != 0.0, C / q, 0.0)
        root_lo, root_hi = np.minimum(r1, r2), np.maximum(r1, r2)
        lin_lo, lin_hi = _half_line(np.full(len(dirs), C), 2.0 * B)
    # A > 0: [root_lo, root_hi] (empty when disc < 0); A < 0: the forward nappe's half-line.
    cone_lo = np.where(A > 0.0, np.where(disc >= 0.0, root_lo, np.inf),
                       np.where(A < 0.0, np.where(s1 > 0.0, root_hi, -np.inf), lin_lo))
    cone_hi = np.where(A > 0.0, np.where(disc >= 0.0, root_hi, -np.inf),
                       np.where(A < 0.0, np.where(s1 > 0.0, np.inf, root_lo), lin_hi))
    cone_lo, cone_hi = np.maximum(cone_lo, pl_lo), np.minimum(cone_hi, pl_hi)
    cone_empty = ~(cone_lo <= cone_hi)
    ball_empty = ~(ball_lo <= ball_hi)
    # The union is convex: on the line, the hull of the two intervals.
    lo = np.where(cone_empty, ball_lo, np.where(ball_empty, cone_lo, np.minimum(ball_lo, cone_lo)))
    hi = np.where(cone_empty, ball_hi, np.where(ball_empty, cone_hi, np.maximum(ball_hi, cone_hi)))
    return lo, hi


_LAMP_CASTERS = {"plane": _plane_lamp_shadow, "box": _box_lamp_shadow, "sphere": _sphere_lamp_shadow}


def lamp_caster_shadow_arrays(origin: Any, dirs: Any, light_pos: Any, surfaces: Sequence[dict]):
    """Per ray and caster, the interval of t (whole line, unclipped) whose points the caster hides
    from the lamp: lo, hi (N, K) for dirs (N, 3); empty: lo = +inf, hi = -inf."""
    origin = np.asarray(origin, dtype=np.float64)
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    lamp = np.asarray(light_pos, dtype=np.float64)
    lo = np.empty((len(dirs), len(surfaces)))
    hi = np.empty((len(dirs), len(surfaces)))
    for k, surface in enumerate(surfaces):
        lo[:, k], hi[:, k] = _LAMP_CASTERS[surface["type"]](origin, dirs, lamp, surface)
    return lo, hi


def lamp_shadow_intervals(origin: Any, dir: Any, light_pos: Any, surfaces: Sequence[dict],
                          t_max: float = math.inf) -> list[Interval]:
    """Parts of the ray o + t d within [0, t_max] hidden from the lamp at `light_pos` (the segment
    to the lamp meets a surface): sorted, disjoint, merged."""
    lo, hi = lamp_caster_shadow_arrays(origin, np.asarray(dir, dtype=np.float64)[None, :], light_pos,
                                       surfaces)
    lo, hi = _clip_sort(lo, hi, t_max)
    return _merged(lo[0], hi[0])


def _phase_scalar(phase: dict | None):
    """p(cos theta) as a float -> float function (for quad): `phase_value`'s formulas, written with
    floats for isotropic and HG (the common cases: 4x faster), through `phase_value` otherwise."""
    kind = "isotropic" if phase is None else phase.get("type", "isotropic")
    if kind == "isotropic":
        return lambda mu: 1.0 / (4.0 * math.pi)
    if kind == "hg":
        g = min(max(float(phase.get("g", 0.0)), -PHASE_G_LIMIT), PHASE_G_LIMIT)
        k, g2 = (1.0 - g * g) / (4.0 * math.pi), 1.0 + g * g
        return lambda mu: k / (g2 - 2.0 * g * mu) ** 1.5
    return lambda mu: float(phase_value(phase, np.float64(mu)))


def lamp_segment_integral(origin: Any, dir: Any, light_pos: Any, a: float, c: float, sigma_t: Any,
                          phase: dict | None = None) -> np.ndarray:
    """int_a^c p(cos theta) exp(-sigma_t (x + d(x))) / d(x)^2 dx per channel (3,), through the
    angle substitutions above (c may be +inf; a < c)."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(dir, dtype=np.float64)
    lamp = np.asarray(light_pos, dtype=np.float64)
    sigma_t = rgb(sigma_t)
    p = _phase_scalar(phase)
    b = float((lamp - o) @ d)
    h = float(np.linalg.norm(o + b * d - lamp))
    out = np.zeros(3)
    from scipy import integrate  # the module's sun part needs only numpy

    def quad(f, lo, hi):
        return integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-12, limit=400)[0] if hi > lo else 0.0

    done: dict[float, float] = {}
    for ch, sigma in enumerate(sigma_t):
        sigma = float(sigma)
        if sigma in done:
            out[ch] = done[sigma]
            continue

        def att(path: float, sigma: float = sigma) -> float:
            return 1.0 if sigma == 0.0 else math.exp(-sigma * path)

        if h == 0.0:  # the line through the lamp (the piece must not contain b)
            total = quad(lambda x: p(-math.copysign(1.0, x - b)) * att(x + abs(x - b)) / (x - b) ** 2, a, c)
        else:
            total = 0.0
            if c > b:  # right of b: phi = atan2(h, x - b), from phi(c) up to phi(max(a, b))
                total += quad(lambda f: p(-math.cos(f)) * att(b + h / math.tan(0.5 * f)),
                              math.atan2(h, c - b), math.atan2(h, max(a, b) - b)) / h
            if a < b:  # left of b: psi = atan2(h, b - x), from psi(a) up to psi(min(c, b))
                total += quad(lambda s: p(math.cos(s)) * att(b + h * math.tan(0.5 * s)),
                              math.atan2(h, b - a), math.atan2(h, b - min(c, b))) / h
        out[ch] = done[sigma] = total
    return out


def lamp_ray_extent(origin: Any, dirs: Any, light: dict, surfaces: Sequence[dict]):
    """(x0, t_hit) per ray (N,): t_hit the first surface or the lamp's sphere's entry if that is
    nearer; x0 the sphere's exit for a camera inside it, else 0."""
    origin = np.asarray(origin, dtype=np.float64)
    dirs = np.asarray(dirs, dtype=np.float64).reshape(-1, 3)
    lamp = np.asarray(light["position"], dtype=np.float64)
    t_hit = first_hit(origin, dirs, surfaces)
    t0, t1 = _ball_interval(origin - lamp, dirs, float(light.get("radius", 0.05)))
    t_hit = np.where(t0 > 0.0, np.minimum(t_hit, t0), t_hit)
    x0 = np.where((t0 <= 0.0) & (t1 > 0.0), t1, 0.0)
    return x0, t_hit


def lamp_airlight_radiance(scene: Any, width: int, height: int, light_index: int = 0) -> np.ndarray:
    """Radiance (W/(m^2 sr)) of the point lamp `lights[light_index]` scattered once by the
    homogeneous medium toward the camera along the parts of each pixel's ray the lamp reaches,
    float64 (H, W, 3):

        L_c = sigma_s,c I_c int over lit parts of [x0, t_hit] of
              p(cos theta) exp(-sigma_t,c (x + d(x))) / d(x)^2 dx.

    0 without a medium or lights."""
    scene = _load(scene)
    out = np.zeros((height, width, 3))
    medium, lights = scene.get("medium"), scene.get("lights") or []
    if not medium or not lights:
        return out
    light = lights[light_index]
    if light.get("type", "point") != "point":
        raise ValueError(f"lights[{light_index}] is not a point light")
    lamp = np.asarray(light["position"], dtype=np.float64)
    intensity = rgb(light.get("intensity"), 0.0)
    sigma_t, sigma_s = medium_coefficients(medium)
    phase = medium.get("phase")
    surfaces = scene.get("surfaces") or []
    origin, dirs = camera_rays(scene, width, height)
    flat = dirs.reshape(-1, 3)
    x0, t_hit = lamp_ray_extent(origin, flat, light, surfaces)
    lo, hi = _clip_sort(*lamp_caster_shadow_arrays(origin, flat, lamp, surfaces), t_hit)
    weight = sigma_s * intensity
    if not weight.any():
        return out
    result = out.reshape(-1, 3)
    for i in range(len(flat)):
        pos = x0[i]
        pieces = []
        for a, b in _merged(lo[i], hi[i]):
            if a > pos:
                pieces.append((pos, min(a, t_hit[i])))
            pos = max(pos, b)
        if t_hit[i] > pos:
            pieces.append((pos, t_hit[i]))
        for a, b in pieces:
            if b > a:
                result[i] += lamp_segment_integral(origin, flat[i], lamp, a, b, sigma_t, phase)
    return (result * weight).reshape(height, width, 3)
