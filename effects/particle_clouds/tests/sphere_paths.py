"""Float64 Monte Carlo reference for light scattered inside one homogeneous spherical cloud particle.

The outside reference of the particle clouds' precomputed scattering table: an independent numpy
path tracer (nothing of the renderer is used), checked against closed forms by
test_sphere_paths.py and against Mitsuba 3 by effects/particle_clouds/bench/sphere_mitsuba.py.

Conventions
-----------
* The unit sphere (radius 1, centre 0) holds a homogeneous medium of extinction sigma_t = tau (the
  optical radius), single-scattering albedo 1 and the Henyey-Greenstein phase
  p(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5), mu the cosine between the propagation
  directions before and after scattering (g > 0 forward). Outside the sphere: vacuum.
* ``sun`` is a unit vector TOWARD the sun; sunlight propagates along -sun with irradiance 1 on a
  plane perpendicular to it. Directly transmitted sunlight is never counted.
* A view ray has an origin o outside the sphere or on its surface and a unit direction v (the
  camera looks along v). L_k(o, v) is the radiance reaching the camera along the ray from light
  scattered exactly k times in the sphere (k = 1: single scattering); 0 for rays that miss.
* Single scattering, closed form: L_1 = int_{t0}^{t1} tau p(sun . v) exp(-tau D(o + t v))
  exp(-tau (t - t0)) dt, t0 / t1 the entry / exit distances of the ray, D(x) the distance from x to
  the boundary along +sun. (Light travelling along -sun is scattered to travel along -v: the
  cosine is (-sun) . (-v) = sun . v.)

Estimators
----------
``radiance_by_order``: backward paths from the camera (``radiance_all_orders``: the same paths
followed to the end, every order summed). The first collision is forced inside the
chord (distance from the truncated exponential, weight 1 - exp(-tau chord)); at every vertex x with
path direction d (the reverse of the light's propagation) next-event estimation toward the sun
adds weight * p(sun . d) * exp(-tau D(x)) to the order of that vertex; the next path direction d'
is drawn from HG(g) about d (the light arrives along -d' and leaves along -d, cosine d . d'), so
the weight stays unchanged (albedo 1); free flights are exponential of rate tau and a path that
leaves the sphere stops. The exit distances are exact ray-sphere intersections. Order k tallies
the NEE of the k-th vertex. Cost (numpy, one core): about 0.5 / 3 / 5 s per million camera paths of
18 orders at tau = 0.5 / 5 / 50 (paths leave thin spheres early), memory bounded by CHUNK paths at a
time; the sun paths about half of that.

``escaping_flux_by_order``: analog forward paths from the sun (entry points uniform over the unit
disc perpendicular to the sun, direction -sun): the fraction of the incident power pi that leaves
after exactly k scatterings. With albedo 1 every path is in exactly one class (unscattered, k =
1..orders, beyond), so sum_k fractions + beyond = 1 - T_direct holds path by path; T_direct has
the closed form ``direct_transmission``.

Everything is float64, vectorised over all paths (in chunks), and deterministic for a seed.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate

CHUNK = 1 << 18  # paths per vectorised batch (about 60 MB of float64 state)


# ------------------------------------------------------------------------------------------------
# Building blocks


def hg_phase(mu: np.ndarray | float, g: float) -> np.ndarray:
    """Henyey-Greenstein phase (1/sr) at the cosine ``mu`` between propagation directions."""
    mu = np.asarray(mu, dtype=np.float64)
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * mu) ** 1.5)


def sample_hg_cosine(g: float, u: np.ndarray) -> np.ndarray:
    """Cosines distributed as HG(g) (forward peak for g > 0) from uniform numbers ``u`` in [0, 1)."""
    if abs(g) < 1e-6:
        return 1.0 - 2.0 * u
    f = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
    return np.clip((1.0 + g * g - f * f) / (2.0 * g), -1.0, 1.0)


def _rotate(d: np.ndarray, cos_t: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Unit vectors at polar cosine ``cos_t`` and azimuth ``phi`` about the unit vectors ``d`` (m, 3)
    (the orthonormal basis of Duff et al. 2017)."""
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    sign = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    b = x * y * a
    t = np.stack([1.0 + sign * x * x * a, sign * b, -sign * x], axis=1)
    s = np.stack([b, sign + y * y * a, -y], axis=1)
    sin_t = np.sqrt(np.maximum(1.0 - cos_t * cos_t, 0.0))
    out = ((sin_t * np.cos(phi))[:, None] * t + (sin_t * np.sin(phi))[:, None] * s + cos_t[:, None] * d)
    return out / np.linalg.norm(out, axis=1)[:, None]


def _scatter(d: np.ndarray, g: float, rng: np.random.Generator) -> np.ndarray:
    """New directions drawn from HG(g) about the directions ``d``."""
    cos_t = sample_hg_cosine(g, rng.random(len(d)))
    return _rotate(d, cos_t, 2.0 * math.pi * rng.random(len(d)))


def exit_distance(x: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance from points ``x`` (..., 3) inside the unit sphere (or on it) to its boundary along
    the unit directions ``d`` (broadcast against x)."""
    b = np.sum(x * d, axis=-1)
    c = np.minimum(np.sum(x * x, axis=-1) - 1.0, 0.0)
    return np.maximum(-b + np.sqrt(np.maximum(b * b - c, 0.0)), 0.0)


def chords(origins: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Entry and exit distances (t0, t1) of rays with the unit sphere, t0 clamped to >= 0
    (origins on the surface); t1 <= t0 for rays that miss it."""
    b = np.sum(origins * dirs, axis=1)
    c = np.sum(origins * origins, axis=1) - 1.0
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t0 = np.maximum(-b - root, 0.0)
    t1 = np.where(disc > 0.0, -b + root, 0.0)
    return t0, t1


def direct_transmission(tau: float) -> float:
    """Fraction of the sunlight crossing the sphere unscattered, 2 int_0^1 exp(-2 tau sqrt(1 - r^2))
    r dr = (1 - exp(-2 tau) (1 + 2 tau)) / (2 tau^2) (series for small tau)."""
    x = 2.0 * tau
    if x < 1e-2:
        num = x * x / 2 - x**3 / 3 + x**4 / 8 - x**5 / 30 + x**6 / 144
    else:
        num = -math.expm1(-x) - x * math.exp(-x)
    return 1.0 if tau == 0.0 else 2.0 * num / (x * x)


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# ------------------------------------------------------------------------------------------------
# Camera paths


def _camera_rays(sun: np.ndarray, origins: np.ndarray,
                 dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The unit sun, the rays as float64 (n, 3) with unit directions, their entry distances and chords
    (0 for rays that miss)."""
    sun = _unit(sun).reshape(3)
    origins = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    dirs = _unit(np.asarray(dirs, dtype=np.float64).reshape(-1, 3))
    t0, t1 = chords(origins, dirs)
    return sun, origins, dirs, t0, np.maximum(t1 - t0, 0.0)


def _first_collisions(tau: float, chord: np.ndarray, t0: np.ndarray, origins: np.ndarray, dirs: np.ndarray,
                      r: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The paths' first collisions forced inside their rays' chords (rays ``r``): the points and the
    weights 1 - exp(-tau chord) (the distance from tau exp(-tau s) / (1 - exp(-tau chord)))."""
    w = -np.expm1(-tau * chord[r])
    s = -np.log1p(-rng.random(len(r)) * w) / tau
    return origins[r] + (t0[r] + s)[:, None] * dirs[r], w


def radiance_by_order(tau: float, g: float, sun: np.ndarray, origins: np.ndarray, dirs: np.ndarray,
                      orders: int = 18, paths: int = 4096, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard error of L_k along each ray for k = 1..orders, arrays (n_rays, orders), from
    ``paths`` backward paths per ray (module docstring). Rays that miss: 0 with standard error 0."""
    sun, origins, dirs, t0, chord = _camera_rays(sun, origins, dirs)
    n = len(dirs)
    hit = np.nonzero(chord > 0.0)[0]
    s1 = np.zeros((n, orders))
    s2 = np.zeros((n, orders))
    rng = np.random.default_rng(seed)
    ray_of_path = np.repeat(hit, paths)
    for start in range(0, len(ray_of_path), CHUNK):
        r = ray_of_path[start:start + CHUNK]
        x, w = _first_collisions(tau, chord, t0, origins, dirs, r, rng)
        d = dirs[r]
        for k in range(orders):
            nee = w * hg_phase(d @ sun, g) * np.exp(-tau * exit_distance(x, sun))
            s1[:, k] += np.bincount(r, weights=nee, minlength=n)
            s2[:, k] += np.bincount(r, weights=nee * nee, minlength=n)
            if k == orders - 1:
                break
            d = _scatter(d, g, rng)
            s = -np.log1p(-rng.random(len(r))) / tau
            inside = s < exit_distance(x, d)
            r, w = r[inside], w[inside]
            x = x[inside] + s[inside, None] * d[inside]
            d = d[inside]
            if len(r) == 0:
                break
    mean = s1 / paths
    if paths < 2:
        return mean, np.full_like(mean, np.nan)
    var = np.maximum(s2 / paths - mean * mean, 0.0) * paths / (paths - 1)
    return mean, np.sqrt(var / paths)


def radiance_all_orders(tau: float, g: float, sun: np.ndarray, origins: np.ndarray, dirs: np.ndarray,
                        paths: int = 4096, seed: int = 0) -> tuple[np.ndarray, np.ndarray, int]:
    """Mean and standard error of the radiance of every order summed along each ray (n_rays,), and the
    most orders any path took: the camera paths of ``radiance_by_order`` followed until every one has
    left the sphere (no cut, no roulette; with albedo 1 the weight never changes). A thick isotropic
    sphere's shadowed side is lit by paths of thousands of scatterings (tau = 50, g = 0: up to about
    9000); about 90 s per 1.6 million paths there on one core."""
    sun, origins, dirs, t0, chord = _camera_rays(sun, origins, dirs)
    n = len(dirs)
    hit = np.nonzero(chord > 0.0)[0]
    s1, s2 = np.zeros(n), np.zeros(n)
    rng = np.random.default_rng(seed)
    ray_of_path = np.repeat(hit, paths)
    most = 0
    for start in range(0, len(ray_of_path), CHUNK):
        r = ray_of_path[start:start + CHUNK]
        alive = np.arange(len(r))  # the paths still inside, by index into r
        total = np.zeros(len(r))  # each path's summed next-event estimates
        x, w = _first_collisions(tau, chord, t0, origins, dirs, r, rng)
        d = dirs[r]
        order = 0
        while len(alive):
            total[alive] += w[alive] * hg_phase(d @ sun, g) * np.exp(-tau * exit_distance(x, sun))
            order += 1
            d = _scatter(d, g, rng)
            s = -np.log1p(-rng.random(len(alive))) / tau
            inside = s < exit_distance(x, d)
            alive, x, d = alive[inside], x[inside] + s[inside, None] * d[inside], d[inside]
        most = max(most, order)
        s1 += np.bincount(r, weights=total, minlength=n)
        s2 += np.bincount(r, weights=total * total, minlength=n)
    mean = s1 / paths
    var = np.maximum(s2 / paths - mean * mean, 0.0) * paths / max(paths - 1, 1)
    return mean, np.sqrt(var / paths), most


def single_scattering(tau: float, g: float, sun: np.ndarray, origins: np.ndarray,
                      dirs: np.ndarray) -> np.ndarray:
    """L_1 along each ray by scipy quadrature of the closed form (module docstring), float64."""
    sun = _unit(sun).reshape(3)
    origins = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    dirs = _unit(np.asarray(dirs, dtype=np.float64).reshape(-1, 3))
    t0, t1 = chords(origins, dirs)
    out = np.zeros(len(dirs))
    for i in range(len(dirs)):
        if t1[i] <= t0[i]:
            continue
        o, v, a = origins[i], dirs[i], t0[i]

        def f(t: float, o: np.ndarray = o, v: np.ndarray = v, a: float = a) -> float:
            return math.exp(-tau * (float(exit_distance(o + t * v, sun)) + (t - a)))

        # the integrand falls by e^-tau per unit of t: split where it matters
        length = t1[i] - a
        edges = [a] + [a + e for e in (1.0 / tau, 4.0 / tau, 16.0 / tau) if e < length] + [t1[i]]
        total = sum(integrate.quad(f, lo, hi, epsabs=0.0, epsrel=1e-11, limit=200)[0]
                    for lo, hi in zip(edges[:-1], edges[1:]))
        out[i] = tau * float(hg_phase(float(sun @ v), g)) * total
    return out


# ------------------------------------------------------------------------------------------------
# Sun paths


def escaping_flux_by_order(tau: float, g: float, orders: int = 18, paths: int = 1 << 17,
                           seed: int = 0) -> tuple[np.ndarray, np.ndarray, float]:
    """Fractions of the incident power (pi) leaving the sphere after exactly k = 1..orders
    scatterings, their binomial standard errors, and the fraction still inside after ``orders``
    scatterings (it leaves later): analog forward paths from the sun (module docstring)."""
    rng = np.random.default_rng(seed)
    counts = np.zeros(orders)
    beyond = 0
    down = np.array([0.0, 0.0, -1.0])  # the sun along +z; the answer does not depend on it
    for start in range(0, paths, CHUNK):
        m = min(CHUNK, paths - start)
        rho = np.sqrt(rng.random(m))
        phi = 2.0 * math.pi * rng.random(m)
        h = np.sqrt(np.maximum(1.0 - rho * rho, 0.0))
        s = -np.log1p(-rng.random(m)) / tau
        inside = s < 2.0 * h
        x = np.stack([rho * np.cos(phi), rho * np.sin(phi), h - s], axis=1)[inside]
        d = np.broadcast_to(down, x.shape).copy()
        for k in range(orders):
            d = _scatter(d, g, rng)
            s = -np.log1p(-rng.random(len(x))) / tau
            inside = s < exit_distance(x, d)
            counts[k] += len(x) - int(inside.sum())
            x = x[inside] + s[inside, None] * d[inside]
            d = d[inside]
        beyond += len(x)
    fractions = counts / paths
    return fractions, np.sqrt(fractions * (1.0 - fractions) / paths), beyond / paths
