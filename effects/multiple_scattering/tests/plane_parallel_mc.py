"""An analog Monte Carlo of the plane-parallel daytime atmosphere under an overcast sky: a third
reference for multiple scattering, independent of the solver (effects/multiple_scattering/
plane_parallel.cpp) and of Mitsuba's scene construction and estimators
(effects/multiple_scattering/docs/reference.md).

The atmosphere depends on altitude only and the overcast sky on elevation only, so a backward
path needs its altitude and its direction cosine mu alone. From the camera along the view:

* free flights by inverting the vertical column: a flight of optical depth t from altitude y
  along mu ends where C(y') = C(y) - t mu (effects/daytime/physics.md, C the column above y),
  through a fine table of C; past the top the path escapes, below the ground it lands;
* at a collision the weight takes the single-scattering albedo, a species is drawn by its share
  of the scattering, and the new direction from its phase (Rayleigh by the closed-form inverse of
  its CDF, Henyey-Greenstein by the standard inverse), at a uniform azimuth about the old one;
* at the ground the weight takes the albedo and the path leaves at a cosine-distributed angle;
* an escaping path scores its weight times the overcast sky's radiance Lz (1 + 2 mu) / 3.

No next-event estimation, no multiple importance sampling, no interfaces: nothing that a bug of a
path tracer's shortcuts could share. Russian roulette below a weight of 1e-3 (unbiased).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import daytime_reference as ref
import daytime_scenes as ds
import numpy as np

ROULETTE_WEIGHT = 1e-3
ROULETTE_SURVIVAL = 0.1


@dataclass
class Estimate:
    mean: float
    stderr: float


def _column_table(atm: ref.Atmosphere, channel: int) -> tuple[np.ndarray, np.ndarray]:
    """Altitudes (increasing) and the column above each, fine where the weather is dense, with
    both sides of every profile break."""
    ys = np.concatenate([np.linspace(0.0, 3500.0, 350001), np.linspace(3500.0, 120000.0, 200001)[1:]])
    for b in atm.breaks():
        ys = np.union1d(ys, [b - 1e-6, b, b + 1e-6])
    return ys, atm.column(ys)[:, channel]


def _sample_phase(phase: object, u: np.ndarray) -> np.ndarray:
    """cos(theta) drawn from a Rayleigh or HG(g) phase function by inverting its CDF."""
    if phase == "rayleigh":
        # 3/8 (1 + c^2) has the CDF (c^3 + 3 c + 4) / 8 = u: Cardano's root of c^3 + 3c - q = 0.
        q = 4.0 * u - 2.0
        r = np.sqrt(q * q + 1.0)
        return np.cbrt(q + r) + np.cbrt(q - r)
    g = float(phase)
    if abs(g) < 1e-6:
        return 1.0 - 2.0 * u
    t = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
    return (1.0 + g * g - t * t) / (2.0 * g)


def ground_albedo(scene: dict, channel: int) -> float:
    """The albedo of the scene's ground plane (0: no plane, a black ground)."""
    for surface in scene.get("surfaces", []):
        if surface["type"] == "plane":
            albedo = surface.get("albedo", 0.5)
            return float(albedo[channel] if isinstance(albedo, (list, tuple)) else albedo)
    return 0.0


def overcast_view_radiance(scene: dict, channel: int, mu_view: float, paths: int, seed: int = 0) -> Estimate:
    """Radiance (one channel) seen from the scene's camera altitude along a view of cosine
    ``mu_view`` from the zenith, under the scene's overcast sky, over its Lambertian ground."""
    sky = ds.reference_sky(scene)
    if scene["sky"]["model"] != "overcast" or "sun" in scene:
        raise ValueError("the analog walk scores only an overcast sky without a sun")
    albedo = ground_albedo(scene, channel)
    atm = ds.reference_atmosphere(scene)
    rng = np.random.default_rng(seed)
    ys, column = _column_table(atm, channel)
    ground_column = column[0]
    lz = float(np.asarray(sky.lz, dtype=float)[channel])
    species = [(sp.sigma_s0[channel], sp.sigma_t0[channel], sp.profile, sp.phase) for sp in atm.species]

    y = np.full(paths, float(scene["camera"]["position"][1]))
    mu = np.full(paths, float(mu_view))
    weight = np.ones(paths)
    alive = np.ones(paths, dtype=bool)
    score = np.zeros(paths)
    while alive.any():
        idx = np.nonzero(alive)[0]
        depth = -np.log(rng.random(idx.size))
        c_end = np.interp(y[idx], ys, column) - depth * mu[idx]
        escaped, landed = c_end <= 0.0, c_end >= ground_column
        hit = ~(escaped | landed)

        out = idx[escaped]
        score[out] += weight[out] * lz * (1.0 + 2.0 * mu[out]) / 3.0
        alive[out] = False

        down = idx[landed]
        weight[down] *= albedo
        y[down] = 0.0
        mu[down] = np.sqrt(rng.random(down.size))

        at = idx[hit]
        y_new = np.interp(c_end[hit], column[::-1], ys[::-1])
        y[at] = y_new
        sigma_s = np.stack([p.density(y_new) * s for s, _t, p, _ph in species])
        sigma_t = sum(p.density(y_new) * t for _s, t, p, _ph in species)
        weight[at] *= sigma_s.sum(axis=0) / sigma_t
        which = (rng.random(at.size)[None, :] > np.cumsum(sigma_s, axis=0) / sigma_s.sum(axis=0)).sum(axis=0)
        cos_theta = np.empty(at.size)
        for k, (_s, _t, _p, phase) in enumerate(species):
            chosen = which == k
            cos_theta[chosen] = _sample_phase(phase, rng.random(int(chosen.sum())))
        azimuth = 2.0 * math.pi * rng.random(at.size)
        old = mu[at]
        sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
        sin_old = np.sqrt(np.maximum(0.0, 1.0 - old * old))
        mu[at] = np.clip(old * cos_theta + sin_old * sin_theta * np.cos(azimuth), -1.0, 1.0)

        faint = np.nonzero(alive & (weight < ROULETTE_WEIGHT))[0]
        survive = rng.random(faint.size) < ROULETTE_SURVIVAL
        weight[faint[survive]] /= ROULETTE_SURVIVAL
        alive[faint[~survive]] = False
    return Estimate(float(score.mean()), float(score.std() / math.sqrt(paths)))
