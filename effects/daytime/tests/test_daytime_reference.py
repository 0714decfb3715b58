"""The issue-6 reference (effects/daytime/tests/daytime_reference.py) against closed forms and against
itself by an independent method: groundwork for the daytime sky and atmosphere, which the
renderer does not have yet. A future test suite compares the renderer with this reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from daytime_reference import (
    RAYLEIGH_SCALE_HEIGHT,
    RAYLEIGH_SIGMA_S0,
    Sky,
    aerosol_profile,
    attenuated_irradiance,
    cie_parameters,
    make_atmosphere,
    molecule_profile,
    overcast_horizontal_irradiance,
    rain_extinction,
    rain_extinction_quadrature,
    sun_direction,
    view_direction,
    view_ray_gauss,
    view_ray_quad,
)
from scipy import integrate


def test_overcast_ground_irradiance_is_seven_pi_lz_over_nine() -> None:
    """E = int (1 + 2 cos Z) / 3 Lz cos Z dw = 7 pi Lz / 9 (effects/daytime/physics.md), no particles."""
    e = attenuated_irradiance(Sky(cie_type=0, lz=(2.0, 1.0, 0.5)), np.zeros(3))
    np.testing.assert_allclose(e, np.array([2.0, 1.0, 0.5]) * overcast_horizontal_irradiance(1.0), rtol=1e-6)


@pytest.mark.parametrize("sky_type", range(1, 16))
@pytest.mark.parametrize("sun_elevation", [5.0, 30.0, 80.0])
def test_every_cie_sky_is_lz_at_the_zenith_and_dark_below_the_horizon(sky_type: int,
                                                                      sun_elevation: float) -> None:
    sky = Sky(cie_type=sky_type, sun_elevation_deg=sun_elevation, sun_azimuth_deg=40.0)
    assert sky.shape(np.array([0.0, 1.0, 0.0])) == pytest.approx(1.0, rel=1e-12)
    assert sky.shape(np.array([0.0, -0.2, -1.0]) / math.hypot(0.2, 1.0)) == 0.0
    dirs = np.array([view_direction(az, el) for az in range(0, 360, 30) for el in (1.0, 20.0, 60.0)])
    assert np.all(np.isfinite(sky.shape(dirs))) and np.all(sky.shape(dirs) > 0.0)


def test_cie_parameters_match_models_md() -> None:
    """The rows the source paper (effects/daytime/physics.md) quotes from ISO 15469: types 1, 5, 12 and 13."""
    assert cie_parameters(1) == (4.0, -0.70, 0.0, -1.0, 0.0)
    assert cie_parameters(5) == (0.0, -1.0, 0.0, -1.0, 0.0)
    assert cie_parameters(12) == (-1.0, -0.32, 10.0, -3.0, 0.45)
    assert cie_parameters(13) == (-1.0, -0.32, 16.0, -3.0, 0.30)
    uniform = Sky(cie_type=5)
    np.testing.assert_allclose(uniform.shape(np.array([view_direction(a, 10.0) for a in (0, 90, 200)])), 1.0)


def test_clear_sky_is_brightest_near_the_sun() -> None:
    sky = Sky(cie_type=12, sun_elevation_deg=30.0, sun_azimuth_deg=0.0)
    toward = sky.shape(sun_direction(0.0, 35.0))
    away = sky.shape(sun_direction(180.0, 35.0))
    assert toward > 3.0 * away


def test_rayleigh_vertical_optical_depth_has_its_closed_form() -> None:
    """int_y^inf beta0 exp(-h / H) dh = beta0 H exp(-y / H)."""
    atm = make_atmosphere()
    for y in (0.0, 1000.0, 10000.0):
        np.testing.assert_allclose(atm.column(y), RAYLEIGH_SIGMA_S0 * RAYLEIGH_SCALE_HEIGHT
                                   * math.exp(-y / RAYLEIGH_SCALE_HEIGHT), rtol=1e-12)


@pytest.mark.parametrize("mu", [1.0, 0.3, 1e-3, 1e-9, 0.0, -0.2])
def test_slant_optical_depth_matches_quadrature(mu: float) -> None:
    """The piecewise-exponential ray integral (stable for rays along the horizon) against
    scipy's quad of the density, for the aerosol profile with its minimum and rise."""
    profile = aerosol_profile()
    y0 = 1800.0
    s1 = 5000.0 if mu >= 0.0 else y0 / -mu
    got = float(profile.ray_integral(y0, mu, 0.0, s1))
    points = [s for s in ((2250.0 - y0) / mu, (3250.0 - y0) / mu) if mu != 0.0 and 0.0 < s < s1] if mu else []
    want, _ = integrate.quad(lambda s: float(profile.density(y0 + mu * s)), 0.0, s1, points=points or None,
                             epsabs=0.0, epsrel=1e-12, limit=200)
    assert got == pytest.approx(want, rel=1e-9)
    assert float(molecule_profile().ray_integral(0.0, 1.0, 0.0, math.inf)) == pytest.approx(
        RAYLEIGH_SCALE_HEIGHT, rel=1e-12)


@pytest.mark.parametrize("rate", [0.1, 1.0, 10.0, 25.0, 100.0])
@pytest.mark.parametrize(("d_min", "d_max"), [(0.0, math.inf), (0.1, 3.5)])
def test_marshall_palmer_extinction_closed_form(rate: float, d_min: float, d_max: float) -> None:
    want = rain_extinction_quadrature(rate, d_min, d_max)
    assert rain_extinction(rate, d_min, d_max) == pytest.approx(want, rel=1e-9)
    assert rain_extinction(0.0) == 0.0


def test_rain_extinction_grows_with_rate() -> None:
    """sigma_t = pi N0 1e-6 / Lambda^3, Lambda = 4.1 R^-0.21: about R^0.63."""
    values = [rain_extinction(r) for r in (1.0, 10.0, 100.0)]
    assert values[0] < values[1] < values[2]
    assert values[2] / values[1] == pytest.approx(10.0 ** 0.63, rel=1e-9)


@pytest.mark.parametrize(("rain", "visibility", "camera_y", "elevation"), [
    (0.0, None, 0.0, 10.0),
    (0.0, 5000.0, 0.0, 2.0),
    (25.0, 2000.0, 100.0, 20.0),
    (10.0, 500.0, 50.0, -5.0),
])
def test_view_ray_by_two_independent_quadratures(rain: float, visibility: float | None, camera_y: float,
                                                 elevation: float) -> None:
    """Adaptive quadrature in distance (quad_vec) and graded composite Gauss-Legendre agree,
    toward the sky and toward the ground, under an overcast sky."""
    atm = make_atmosphere(rain_rate=rain, visibility=visibility)
    sky = Sky(cie_type=0, lz=(1.0, 1.0, 1.0))
    view = view_direction(30.0, elevation)
    a = view_ray_quad(atm, sky, camera_y, view, ground_albedo=0.2, epsrel=1e-9)
    b = view_ray_gauss(atm, sky, camera_y, view, ground_albedo=0.2)
    assert np.all(np.isfinite(a)) and np.all(a > 0.0)
    np.testing.assert_allclose(a, b, rtol=1e-5)


def test_no_particles_leave_the_sky_unchanged_and_no_light_gives_darkness() -> None:
    empty = make_atmosphere(molecules=False)
    sky = Sky(cie_type=12, lz=(1.0, 2.0, 3.0), sun_elevation_deg=25.0)
    view = view_direction(60.0, 15.0)
    np.testing.assert_allclose(view_ray_quad(empty, sky, 10.0, view), sky.radiance(view), rtol=1e-12)
    dark = Sky(cie_type=0, lz=(0.0, 0.0, 0.0))
    np.testing.assert_array_equal(view_ray_gauss(make_atmosphere(rain_rate=10.0), dark, 0.0, view), 0.0)
