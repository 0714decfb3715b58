"""An independent reference for the irradiance of a point lamp's multiply scattered light on a surface
element (effects/multiple_scattering/physics.md section 13): a seeded numpy photon tracer that shares no
shortcut with the renderer's table. The table goes lamp -> in-scattering source J (binned) -> line
integrals L(tau, gamma) -> closed-form azimuthal kernel -> quadrature over gamma; this tracer follows
photons from the lamp, scores the track length of every flight of light already scattered twice or more
inside thin spherical shells around the lamp, and weighs each by the cosine factor of a surface element
at the flight's point, sampled over the element's azimuth (stratified, random offset). No J, no line
integral, no kernel formula, no radius cut (Russian roulette only, which is unbiased).

Optical units (sigma_t = 1), a lamp of unit intensity (power 4 pi): each photon carries 4 pi / N. The
shell [r0, r1] around tau gives the volume average of E over the shell,

    E_shell(beta) = 4 pi / (N V) sum w l <max(n . (-d), 0)>_azimuth,

w the photon's weight (albedo^k after k scatterings), l the flight's length inside the shell, d its
direction, n the element's normal at angle beta from the direction to the lamp. Compare it with the
table's volume average over the same shell (shell_average), not with E at the shell's middle. The
standard errors come from independent batches.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

AZIMUTHS = 16  # stratified azimuths of the surface element per scored flight
WEIGHT_FLOOR = 1e-6  # Russian roulette below this weight (survival 0.1)
SURVIVAL = 0.1


def shell_edges(tau: float) -> tuple[float, float]:
    """The shell scored for optical distance tau: tau +- 5 % (at most +- 0.25)."""
    half = min(0.05 * tau, 0.25)
    return tau - half, tau + half


def _sample_hg(g: float, xi: np.ndarray) -> np.ndarray:
    if abs(g) < 1e-6:
        return 2.0 * xi - 1.0
    q = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi)
    return np.clip((1.0 + g * g - q * q) / (2.0 * g), -1.0, 1.0)


def _turn(d: np.ndarray, mu: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Directions d (N, 3) turned by acos(mu) at azimuth phi about themselves."""
    # An orthonormal frame (d, a, b) per row.
    helper = np.where(np.abs(d[:, :1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    a = np.cross(d, helper)
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b = np.cross(d, a)
    st = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))[:, None]
    out = mu[:, None] * d + st * (np.cos(phi)[:, None] * a + np.sin(phi)[:, None] * b)
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out


def _inside_interval(p_dot_d: np.ndarray, p2: np.ndarray, s: np.ndarray,
                     r: float) -> tuple[np.ndarray, np.ndarray]:
    """[lo, hi] of t in [0, s] with |p + t d| <= r (lo = hi where empty)."""
    disc = p_dot_d * p_dot_d - (p2 - r * r)
    root = np.sqrt(np.maximum(disc, 0.0))
    lo = np.clip(-p_dot_d - root, 0.0, s)
    hi = np.clip(-p_dot_d + root, 0.0, s)
    empty = disc <= 0.0
    return np.where(empty, 0.0, lo), np.where(empty, 0.0, hi)


def _batch(g: float, albedo: float, shells: list[tuple[float, float]], betas: np.ndarray, photons: int,
           rng: np.random.Generator) -> np.ndarray:
    """Sum of w l <cos factor> per (shell, beta) for one batch of photons."""
    tally = np.zeros((len(shells), len(betas)))
    cos_b, sin_b = np.cos(betas), np.sin(betas)
    mu0 = 2.0 * rng.random(photons) - 1.0
    phi0 = 2.0 * math.pi * rng.random(photons)
    st0 = np.sqrt(1.0 - mu0 * mu0)
    d = np.stack([st0 * np.cos(phi0), st0 * np.sin(phi0), mu0], axis=1)
    p = np.zeros((photons, 3))
    w = np.ones(photons)
    order = np.zeros(photons, dtype=np.int64)
    while len(w):
        s = -np.log1p(-rng.random(len(w)))
        scored = order >= 2
        if np.any(scored):
            ps, ds, ss, ws = p[scored], d[scored], s[scored], w[scored]
            pd = np.einsum("ij,ij->i", ps, ds)
            p2 = np.einsum("ij,ij->i", ps, ps)
            for i, (r0, r1) in enumerate(shells):
                a_lo, a_hi = _inside_interval(pd, p2, ss, r1)
                c_lo, c_hi = _inside_interval(pd, p2, ss, r0)
                length = (a_hi - a_lo) - (c_hi - c_lo)
                hit = length > 1e-15
                if not np.any(hit):
                    continue
                # A uniform point of the flight inside the shell: [a_lo, a_hi] less [c_lo, c_hi].
                t = a_lo[hit] + rng.random(int(hit.sum())) * length[hit]
                t = np.where(t >= c_lo[hit], t + (c_hi[hit] - c_lo[hit]), t)
                x = ps[hit] + t[:, None] * ds[hit]
                # The light arrives from -d; mu its cosine with the direction to the lamp (-x / |x|).
                mu = np.einsum("ij,ij->i", x, ds[hit]) / np.linalg.norm(x, axis=1)
                perp = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
                phi = 2.0 * math.pi * (np.arange(AZIMUTHS)[None, :] + rng.random((len(mu), 1))) / AZIMUTHS
                # n . (-d) = cos beta mu + sin beta perp cos(phi - psi); phi is uniform, so psi = 0.
                cosines = (cos_b[None, :, None] * mu[:, None, None] +
                           sin_b[None, :, None] * perp[:, None, None] * np.cos(phi)[:, None, :])
                factor = np.maximum(cosines, 0.0).mean(axis=2)
                tally[i] += np.einsum("i,ij->j", ws[hit] * length[hit], factor)
        p = p + s[:, None] * d
        w = w * albedo
        order += 1
        low = w < WEIGHT_FLOOR
        survive = ~low | (rng.random(len(w)) < SURVIVAL)
        w = np.where(low, w / SURVIVAL, w)
        keep = survive & (w > 0.0)
        p, d, w, order = p[keep], d[keep], w[keep], order[keep]
        if not len(w):
            break
        d = _turn(d, _sample_hg(g, rng.random(len(w))), 2.0 * math.pi * rng.random(len(w)))
    return tally


def surface_irradiance_mc(g: float, albedo: float, taus: list[float], betas_deg: list[float], photons: int,
                          batches: int = 16, seed: int = 18) -> dict[str, Any]:
    """E_shell(tau, beta) of the light scattered at least twice (optical units, unit intensity) and its
    standard error, over `batches` independent batches of photons / batches photons each."""
    shells = [shell_edges(t) for t in taus]
    betas = np.radians(np.asarray(betas_deg, dtype=float))
    per_batch = photons // batches
    rng = np.random.default_rng(seed)
    sums = np.array([_batch(g, albedo, shells, betas, per_batch, rng) for _ in range(batches)])
    volume = np.array([4.0 / 3.0 * math.pi * (r1 ** 3 - r0 ** 3) for r0, r1 in shells])
    values = sums * (4.0 * math.pi / per_batch) / volume[None, :, None]
    return {"g": g, "albedo": albedo, "taus": list(taus), "betas_deg": list(betas_deg), "shells": shells,
            "photons": per_batch * batches, "batches": batches, "seed": seed,
            "mean": values.mean(axis=0).tolist(),
            "stderr": (values.std(axis=0, ddof=1) / math.sqrt(batches)).tolist()}


def shell_average(e_of_tau: Any, r0: float, r1: float, nodes: int = 8) -> Any:
    """The volume average over the shell [r0, r1] of e_of_tau(tau) (Gauss-Legendre in r, weight r^2)."""
    x, wts = np.polynomial.legendre.leggauss(nodes)
    r = 0.5 * (r0 + r1) + 0.5 * (r1 - r0) * x
    total = sum(wt * rr * rr * np.asarray(e_of_tau(float(rr))) for wt, rr in zip(wts, r))
    return total * 0.5 * (r1 - r0) / ((r1 ** 3 - r0 ** 3) / 3.0)


def ground_irradiance_mc(g: float, albedo: float, height: float, blocked: bool, photons: int,
                         disc: float = 0.2, seed: int = 18) -> tuple[float, float]:
    """The irradiance of the light scattered at least twice on an upward-facing disc of radius
    disc x height right below a lamp at optical height `height` (unit intensity), and its standard error
    (20 batches): with `blocked`, a black ground fills y < 0 (photons crossing it end there); without, the
    medium is infinite (the model of physics.md section 13). Their ratio is the infinite medium's error."""
    rng = np.random.default_rng(seed)
    radius = disc * height
    batches = 20
    values = []
    for _ in range(batches):
        n = photons // batches
        mu0 = 2.0 * rng.random(n) - 1.0
        phi0 = 2.0 * math.pi * rng.random(n)
        st0 = np.sqrt(1.0 - mu0 * mu0)
        d = np.stack([st0 * np.cos(phi0), mu0, st0 * np.sin(phi0)], axis=1)
        p = np.tile([0.0, height, 0.0], (n, 1))
        w = np.ones(n)
        order = np.zeros(n, dtype=np.int64)
        total = 0.0
        while len(w):
            s = -np.log1p(-rng.random(len(w)))
            q = p + s[:, None] * d
            down = (p[:, 1] > 0.0) & (q[:, 1] <= 0.0)
            t = np.where(down, p[:, 1] / np.where(down, -d[:, 1], 1.0), 0.0)
            x = p + t[:, None] * d
            on_disc = down & (x[:, 0] ** 2 + x[:, 2] ** 2 < radius * radius) & (order >= 2)
            total += float(w[on_disc].sum())
            keep = ~down if blocked else np.ones(len(w), dtype=bool)
            p, d, w, order = q, d, w * albedo, order + 1
            low = w < WEIGHT_FLOOR
            keep &= ~low | (rng.random(len(w)) < SURVIVAL)
            w = np.where(low, w / SURVIVAL, w)
            p, d, w, order = p[keep], d[keep], w[keep], order[keep]
            if len(w):
                d = _turn(d, _sample_hg(g, rng.random(len(w))), 2.0 * math.pi * rng.random(len(w)))
        values.append(total * 4.0 * math.pi / n / (math.pi * radius * radius))
    v = np.array(values)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(batches))
