"""The particle lighting table (physics.md section 3) against the solver it is built from, evaluated
directly at the same rays: interpolation in the angles and the optical radius, the thin-particle
limit below the table, and clear errors for a bad shape. (The solver itself is checked against path
tracers in test_sphere_scattering.py.)"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import airlight

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
import table_resolution as analysis  # noqa: E402

GRID = {"radii": 12, "polar": 16, "zenith": 16, "azimuth": 8, "orders": 4}  # small: these tests compare
# the table with the solver on the same grid, so its accuracy against the light itself does not matter


def lookup_all(table: airlight._core.ParticleTable, tau: float, normals: np.ndarray, dirs: np.ndarray,
               suns: np.ndarray) -> np.ndarray:
    return analysis.lookup(table, tau, normals, dirs, suns)


@pytest.mark.slow
def test_the_table_interpolates_the_solver_between_its_angles() -> None:
    g, tau = 0.85, 4.0
    origins, dirs, normals, suns = analysis.random_rays(200, seed=7)
    exact = analysis.direct(tau, g, origins, dirs, suns, GRID)
    table = airlight._core.ParticleTable(g, {"taus": 2, "tau_min": tau, "tau_max": 2 * tau, "grid": GRID})
    med, p99, worst = analysis.stats(lookup_all(table, tau, normals, dirs, suns), exact)
    assert med < 0.005 and p99 < 0.03 and worst < 0.06, (med, p99, worst)


@pytest.mark.slow
def test_entry_angles_dense_across_the_terminator_beat_uniform_ones_on_a_thick_particle() -> None:
    # Eq. 3.2: a thick particle's light falls steeply across the terminator (and order 1 peaks on the
    # rays grazing it there); the same number of entry nodes placed densely there interpolate it better.
    g, tau = 0.85, 20.0
    grid = {**GRID, "polar": 32, "beyond": True}
    origins, dirs, normals, suns = analysis.random_rays(600, seed=9)
    entry = np.degrees(np.arccos(np.clip((normals * suns).sum(axis=1), -1.0, 1.0)))
    near = (entry > 80.0) & (entry < 100.0)
    exact = analysis.direct(tau, g, origins[near], dirs[near], suns[near], grid)
    p99 = {}
    for dense in (False, True):
        table = airlight._core.ParticleTable(g, {"entry": 24, "taus": 2, "tau_min": tau, "tau_max": 2 * tau,
                                                 "dense_terminator": dense, "grid": grid})
        p99[dense] = analysis.stats(lookup_all(table, tau, normals[near], dirs[near], suns[near]), exact)[1]
    assert p99[True] < 0.5 * p99[False], p99


@pytest.mark.slow
def test_the_table_interpolates_the_solver_between_its_optical_radii() -> None:
    g = 0.5
    origins, dirs, normals, suns = analysis.random_rays(150, seed=8)
    table = airlight._core.ParticleTable(g, {"taus": 5, "tau_min": 1.0, "tau_max": 2.9, "grid": GRID})
    tau = 1.4  # between the nodes 1.31 and 1.70
    exact = analysis.direct(tau, g, origins, dirs, suns, GRID)
    med, p99, worst = analysis.stats(lookup_all(table, tau, normals, dirs, suns), exact)
    assert med < 0.005 and p99 < 0.015, (med, p99, worst)


def test_a_thin_particle_scales_from_the_thinnest_slice() -> None:
    # Below tau_min order 1 grows as tau and the rest as tau^2: half the optical radius, half the
    # single scattering and a quarter of the rest.
    grid = {**GRID, "orders": 2}
    table = airlight._core.ParticleTable(0.5, {"entry": 5, "view_zenith": 3, "view_azimuth": 4, "taus": 2,
                                               "tau_min": 0.2, "tau_max": 0.4, "grid": grid})
    normal, view, sun = np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, -1.0]]), np.array([0.0, 0.6, 0.8])
    at_min = table.lookup(np.array([0.2]), normal, view, sun)[0]
    half = table.lookup(np.array([0.1]), normal, view, sun)[0]
    assert at_min.min() > 0.0
    np.testing.assert_allclose(half, at_min * np.array([0.5, 0.25]), rtol=1e-12)


@pytest.mark.parametrize(("shape", "field"), [({"entry": 1}, "shape.entry"), ({"taus": 1}, "shape.taus"),
                                              ({"tau_min": 5.0, "tau_max": 1.0}, "shape.tau_min"),
                                              ({"colour": 3}, "shape.colour"),
                                              ({"dense_terminator": 1}, "shape.dense_terminator"),
                                              ({"grid": {"radii": 0}}, "grid.radii")])
def test_a_bad_table_shape_is_a_clear_error(shape: dict, field: str) -> None:
    with pytest.raises((ValueError, TypeError), match=field):
        airlight._core.ParticleTable(0.5, shape)
