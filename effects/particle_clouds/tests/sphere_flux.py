"""The energy that leaves the reference particle after each scattering order, from the solver's radiance.

The power leaving a body in direction -v per unit solid angle is the radiance an orthographic
camera looking along v sees, integrated over its image plane; the escaping power is that integrated
over all directions. Normalised by the incident power (pi R^2 E = pi for the unit sphere and E = 1),
order k's share is

    f_k = (1 / pi) integral_{4 pi} dOmega(v) integral_disc L_k(rho, phi; v) rho drho dphi

taken here by Gauss-Legendre rules in cos(v, sun) (the problem is symmetric about the sun's axis,
so the azimuth of v adds 2 pi) and rho^2, and the midpoint rule in phi over [0, pi] (mirror
symmetry), doubled. It is compared with sphere_paths.escaping_flux_by_order, which counts photons.
"""

from __future__ import annotations

import numpy as np

import airlight


def flux_rays(nodes: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rays (origins, dirs; the sun on +z) and their quadrature weights for f_k."""
    cos_a, w_a = np.polynomial.legendre.leggauss(nodes)
    x_r, w_r = np.polynomial.legendre.leggauss(nodes)
    phis = (np.arange(nodes) + 0.5) * np.pi / nodes
    origins, dirs, weights = [], [], []
    for ca, wa in zip(cos_a, w_a):
        sa = np.sqrt(1.0 - ca * ca)
        v = np.array([sa, 0.0, ca])
        a, b = np.array([ca, 0.0, -sa]), np.array([0.0, 1.0, 0.0])
        for x, wr in zip(x_r, w_r):
            rho = np.sqrt(0.5 * (x + 1.0))  # rho^2 = (x + 1) / 2: rho drho = d(rho^2) / 2 = dx / 4
            for phi in phis:
                origins.append(rho * (np.cos(phi) * a + np.sin(phi) * b) - 3.0 * v)
                dirs.append(v)
                weights.append(2.0 * np.pi * wa * 0.25 * wr * (np.pi / nodes) * 2.0)
    return np.array(origins), np.array(dirs), np.array(weights)


def solver_flux_by_order(tau: float, g: float, grid: dict | None = None, nodes: int = 12,
                         steps: int = 256) -> np.ndarray:
    """f_k for k = 1..orders from airlight's solver (``grid`` as for particle_sphere_radiance)."""
    origins, dirs, weights = flux_rays(nodes)
    sun = [0.0, 0.0, 1.0]
    radiance = airlight._core.particle_sphere_radiance(tau, g, sun, origins, dirs, grid or {}, steps)
    return (weights[:, None] * radiance).sum(axis=0) / np.pi
