"""A drop's optics table against closed forms (physics.md section 4): each Debye order's phase function
matches eps_p b |db/dtheta| / (pi sin theta) root-found per branch where it is smooth, carries the
order's share of the light (adaptive quadrature of eps_p over the cross-section), the primary rainbow
sits at Descartes' angle, and the orders together carry all but a sliver of the light."""

from __future__ import annotations

import math

import numpy as np
import pytest
import rain_reference as ref

import airlight

BINS = 720
SAMPLES = 1 << 20
N = 1.3335  # water near 550 nm


@pytest.fixture(scope="module")
def orders() -> list[np.ndarray]:
    return [airlight._core.drop_phase_order(N, p, BINS, SAMPLES) for p in range(airlight._core.DROP_ORDERS)]


def bin_center(theta_deg: float) -> tuple[int, float]:
    b = int(math.radians(theta_deg) / math.pi * BINS)
    return b, math.pi * (b + 0.5) / BINS


@pytest.mark.parametrize(
    ("p", "angles"),
    [(0, [10, 40, 90, 130, 170]), (1, [5, 20, 45, 70, 80]), (2, [145, 160, 175]), (3, [60, 90, 110])],
)
def test_each_order_matches_its_closed_form_where_smooth(orders, p, angles):
    for deg in angles:
        b, theta = bin_center(deg)
        exact = ref.order_phase(N, p, theta)
        assert exact > 0, (p, deg)
        assert orders[p][b] == pytest.approx(exact, rel=5e-3), (p, deg)


@pytest.mark.parametrize("p", range(8))
def test_each_order_carries_its_share_of_the_light(orders, p):
    edges = np.linspace(0, math.pi, BINS + 1)
    solid = 2 * math.pi * (np.cos(edges[:-1]) - np.cos(edges[1:]))
    assert float(np.sum(orders[p] * solid)) == pytest.approx(ref.order_power(N, p), rel=1e-6)


def test_the_orders_kept_carry_nearly_all_the_light():
    kept = sum(ref.order_power(N, p) for p in range(airlight._core.DROP_ORDERS))
    assert 0.999 < kept < 1.0
    for i in (0.1, 0.7, 1.3, 1.55):
        total = sum(airlight._core.drop_order_energy(N, p, i) for p in range(2000))
        assert total == pytest.approx(1.0, abs=1e-12)


def test_primary_and_secondary_rainbows_at_descartes_angles(orders):
    for p in (2, 3):
        # Minimum deviation: cos^2 i = (n^2 - 1) / (p^2 - 1) for p internal paths (Descartes, Newton).
        i = math.acos(math.sqrt((N * N - 1) / (p * p - 1)))
        theta = float(ref.scattering_angle(N, p, np.array(i)))
        peak = (int(np.argmax(orders[p])) + 0.5) * 180 / BINS
        assert abs(peak - math.degrees(theta)) < 0.5, (p, peak, math.degrees(theta))
