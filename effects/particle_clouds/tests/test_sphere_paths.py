"""Self-test of the spherical particle's Monte Carlo reference (sphere_paths.py): the HG sampling
against the phase's moments; the single-scattering quadrature against closed forms on the sun's
axis; order 1 of the camera paths against the quadrature; the sun paths' energy balance (albedo 1)
against the closed-form direct transmission; and the camera paths against the sun paths order by
order (the power leaving the sphere after k scatterings, 4 pi E[L_k] over uniformly random rays),
the check that catches a sign error in the sun or phase convention of the next-event estimation.
No renderer."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sphere_paths as sp
from scipy import integrate


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


# The camera on -z looks toward +z; "front": the sun behind the camera, "back": the sun behind the
# sphere (the camera looks nearly at it: forward scattering).
SUNS = {"front": unit([0.3, 0.2, -1.0]), "side": unit([1.0, 0.3, 0.1]), "back": unit([-0.2, 0.15, 1.0])}
CAMERA = np.array([0.0, 0.0, -3.0])
TARGETS = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.8, 0.2], [-0.6, -0.6, 0.0], [0.95, 0.0, 0.0],
                    [0.0, -0.99, 0.0], [1.2, 0.0, 0.0]])  # the last one misses


def camera_rays() -> tuple[np.ndarray, np.ndarray]:
    return np.broadcast_to(CAMERA, TARGETS.shape).copy(), TARGETS - CAMERA


def uniform_rays(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Directions uniform on the sphere of directions, each through a point uniform on the unit disc
    perpendicular to it; origins 2 before the disc."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    a = np.where(np.abs(v[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(v, a)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(v, e1)
    r, phi = np.sqrt(rng.random(n)), 2.0 * math.pi * rng.random(n)
    return (r * np.cos(phi))[:, None] * e1 + (r * np.sin(phi))[:, None] * e2 - 2.0 * v, v


# ------------------------------------------------------------------------------------------------
# Building blocks


@pytest.mark.parametrize("g", [0.0, 0.5, 0.9, -0.5])
def test_hg_phase_and_sampling_moments(g: float) -> None:
    norm = 2.0 * math.pi * integrate.quad(lambda mu: float(sp.hg_phase(mu, g)), -1.0, 1.0, epsrel=1e-12)[0]
    mean = 2.0 * math.pi * integrate.quad(lambda mu: mu * float(sp.hg_phase(mu, g)), -1.0, 1.0,
                                          epsrel=1e-12)[0]
    assert norm == pytest.approx(1.0, abs=1e-9)
    assert mean == pytest.approx(g, abs=1e-9)
    n = 400_000
    mu = sp.sample_hg_cosine(g, np.random.default_rng(1).random(n))
    p2 = 0.5 * (3.0 * mu * mu - 1.0)  # HG's Legendre moments are g^l
    assert abs(mu.mean() - g) < 4.0 * mu.std() / math.sqrt(n)
    assert abs(p2.mean() - g * g) < 4.0 * p2.std() / math.sqrt(n)


def test_direct_transmission() -> None:
    for tau in (1e-4, 4e-3, 0.1, 1.0, 5.0, 50.0):
        ref = 2.0 * integrate.quad(lambda r, tau=tau: math.exp(-2.0 * tau * math.sqrt(1.0 - r * r)) * r,
                                   0.0, 1.0, epsabs=0.0, epsrel=1e-12)[0]
        assert sp.direct_transmission(tau) == pytest.approx(ref, rel=1e-10)


@pytest.mark.parametrize("tau", [0.05, 1.0, 20.0])
def test_single_scattering_on_the_sun_axis(tau: float) -> None:
    """Along the sun's axis through the centre D + (t - t0) is constant (looking toward the sun) or
    D = t - t0 (looking away): L_1 = 2 tau p(1) e^{-2 tau} and p(-1) (1 - e^{-4 tau}) / 2."""
    g = 0.7
    sun = unit([0.2, -0.5, 0.4])
    origins = np.stack([-2.0 * sun, 3.0 * sun])
    got = sp.single_scattering(tau, g, sun, origins, np.stack([sun, -sun]))
    toward = 2.0 * tau * sp.hg_phase(1.0, g) * math.exp(-2.0 * tau)
    away = sp.hg_phase(-1.0, g) * -math.expm1(-4.0 * tau) / 2.0
    assert got == pytest.approx([toward, away], rel=1e-9)


# ------------------------------------------------------------------------------------------------
# Camera paths


# Thick spheres lit from behind are left out: there the light comes from rare vertices near the
# far side (single scattering down to e^-90 at tau 50), a heavy-tailed estimate whose sample
# standard error means little.
@pytest.mark.parametrize("tau, g, sun, seed", [
    (0.1, 0.0, "front", 1), (0.1, 0.9, "back", 2), (1.0, 0.5, "side", 3), (1.0, 0.9, "back", 4),
    (5.0, 0.9, "front", 5), (5.0, 0.0, "side", 6), (50.0, 0.5, "front", 7), (50.0, 0.9, "side", 8)])
def test_order_one_matches_quadrature(tau: float, g: float, sun: str, seed: int) -> None:
    origins, dirs = camera_rays()
    mean, se = sp.radiance_by_order(tau, g, SUNS[sun], origins, dirs, orders=2, paths=4000, seed=seed)
    ref = sp.single_scattering(tau, g, SUNS[sun], origins, dirs)
    hit = ref > 0.0
    assert np.all(hit[:-1]) and not hit[-1]
    assert np.all(mean[~hit] == 0.0) and np.all(se[~hit] == 0.0)
    assert np.all(se[hit, 0] < 0.05 * ref[hit])  # the check has teeth
    z = (mean[hit, 0] - ref[hit]) / se[hit, 0]
    assert np.all(np.abs(z) < 4.0), z


def test_deterministic_for_a_seed() -> None:
    origins, dirs = camera_rays()
    a = sp.radiance_by_order(2.0, 0.6, SUNS["side"], origins, dirs, orders=4, paths=500, seed=9)
    b = sp.radiance_by_order(2.0, 0.6, SUNS["side"], origins, dirs, orders=4, paths=500, seed=9)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    f = sp.escaping_flux_by_order(2.0, 0.6, orders=4, paths=5000, seed=9)
    assert np.array_equal(f[0], sp.escaping_flux_by_order(2.0, 0.6, orders=4, paths=5000, seed=9)[0])


def test_every_order_summed_is_the_orders_followed_to_the_end() -> None:
    # The same camera paths (same seed, same draws) followed until all have left: their sum over every
    # order equals the per-order tallies taken to the most orders any path took; misses are 0.
    origins, dirs = camera_rays()
    total, se, most = sp.radiance_all_orders(3.0, 0.3, SUNS["side"], origins, dirs, paths=400, seed=4)
    by_order, _ = sp.radiance_by_order(3.0, 0.3, SUNS["side"], origins, dirs, orders=most, paths=400, seed=4)
    assert most > 20 and total[-1] == 0.0 and se[-1] == 0.0
    np.testing.assert_allclose(total, by_order.sum(axis=1), rtol=1e-12)
    assert np.all(se[:-1] > 0.0)


# ------------------------------------------------------------------------------------------------
# Sun paths


@pytest.mark.parametrize("tau, g, orders", [(0.5, 0.85, 60), (5.0, 0.85, 400), (20.0, 0.5, 400)])
def test_energy_balance(tau: float, g: float, orders: int) -> None:
    """Albedo 1: everything not transmitted unscattered leaves after some number of scatterings."""
    n = 1 << 16
    frac, se, beyond = sp.escaping_flux_by_order(tau, g, orders=orders, paths=n, seed=11)
    t = sp.direct_transmission(tau)
    assert beyond < 2e-3  # enough orders: the sum itself carries (almost) all of it
    assert abs(frac.sum() + beyond - (1.0 - t)) < 4.0 * math.sqrt(t * (1.0 - t) / n) + 1e-12


@pytest.mark.parametrize("tau, g", [(1.0, 0.5), (5.0, 0.5), (2.0, 0.7)])
def test_camera_paths_match_sun_paths_order_by_order(tau: float, g: float) -> None:
    """Power leaving after exactly k scatterings, as a fraction of the incident pi: the integral of
    L_k over all directions and the unit disc across each, 4 pi E[L_k] over uniform rays (camera
    paths, next-event estimation toward the sun), against the analog sun paths. A phase evaluated
    at -sun . d, or D measured along -sun, changes order 1 by tens of standard errors."""
    orders = 3
    origins, dirs = uniform_rays(1 << 16, np.random.default_rng(21))
    mean, _ = sp.radiance_by_order(tau, g, unit([0.0, 0.6, 0.8]), origins, dirs, orders=orders, paths=2,
                                   seed=22)
    back = 4.0 * math.pi * mean.mean(axis=0)
    back_se = 4.0 * math.pi * mean.std(axis=0) / math.sqrt(len(mean))
    fwd, fwd_se, _ = sp.escaping_flux_by_order(tau, g, orders=orders, paths=1 << 17, seed=23)
    z = (back - fwd) / np.hypot(back_se, fwd_se)
    assert np.all(np.abs(z) < 4.0), (back, fwd, z)
    assert np.all(back_se < 0.03 * back)
