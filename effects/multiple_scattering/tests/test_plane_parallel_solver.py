"""The plane-parallel multiple-scattering solver through Python (airlight._core.solve_plane_parallel;
effects/multiple_scattering/docs/solver.md): against an independent discrete-ordinate solver
(PythonicDISORT: eigenvectors per layer and a boundary-value solve, where airlight doubles and adds),
live when it is installed and through its stored values otherwise; random slabs stay finite and
conserve energy (hypothesis); the renderer's weathers solve through solve_plane_parallel_scene."""

from __future__ import annotations

import json
import math
from pathlib import Path

import disort_cases
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airlight import _core

HERE = Path(__file__).resolve().parent
STORED = json.loads((HERE / "disort_reference.json").read_text())

# Agreement with DISORT at the same ordinates and delta-M truncation
# (measured: fluxes within 1e-8 of the incident flux, radiances within 1e-4 of
# the largest; solver.md section 4).
FLUX_TOL = 1e-6
RADIANCE_TOL = 5e-4


@pytest.mark.parametrize("case", disort_cases.CASES, ids=[c["name"] for c in disort_cases.CASES])
def test_matches_stored_disort_values(case):
    """Fluxes at every interface and radiances at the top and the ground match PythonicDISORT's stored
    values for sun, sky, ground, Rayleigh, HG up to g = 0.87, depths 0.01-100 and three layers."""
    ours = disort_cases.run_airlight(case)
    ref = STORED["cases"][case["name"]]
    assert np.allclose(ours["mu"], ref["mu"], rtol=1e-12)  # the same double-Gauss ordinates
    d = disort_cases.worst_differences(ours, ref, disort_cases.incident_flux(case))
    assert d["flux_up"] < FLUX_TOL and d["flux_down"] < FLUX_TOL, d
    assert d["radiance_top_up"] < RADIANCE_TOL and d["radiance_bottom_down"] < RADIANCE_TOL, d


@pytest.mark.slow
@pytest.mark.parametrize("case", disort_cases.CASES[:4], ids=[c["name"] for c in disort_cases.CASES[:4]])
def test_matches_live_disort(case):
    """The same comparison against PythonicDISORT run now (skipped when it is not installed), which
    also shows that the stored values are what it computes."""
    pytest.importorskip("PythonicDISORT")
    live = disort_cases.run_pythonic_disort(case)
    stored = STORED["cases"][case["name"]]
    assert np.allclose(live["flux_up"], stored["flux_up"], rtol=1e-9, atol=1e-12)
    ours = disort_cases.run_airlight(case)
    d = disort_cases.worst_differences(ours, live, disort_cases.incident_flux(case))
    assert max(d.values()) < RADIANCE_TOL, d


def slab(tau: float, omega: float, phase: str | tuple[str, float], parts: int = 2) -> dict:
    t = tau / parts
    return {"phases": [phase], "layer_tops": [100.0 * (k + 1) for k in range(parts)],
            "extinction_depth": [[[t] * 3] for _ in range(parts)],
            "scattering_depth": [[[t * omega] * 3] for _ in range(parts)]}


phases = st.one_of(st.just("rayleigh"), st.tuples(st.just("hg"), st.floats(-0.9, 0.97)))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tau=st.floats(0.0, 2000.0), omega=st.floats(0.0, 1.0), phase=phases, mu0=st.floats(-0.2, 1.0),
       albedo=st.floats(0.0, 1.0), sky_tilt=st.floats(-1.0, 1.0), parts=st.integers(1, 4))
def test_random_slabs_are_finite_and_conserve_energy(tau, omega, phase, mu0, albedo, sky_tilt, parts):
    """Any slab, sun (below the horizon too), sky and ground: finite non-negative fluxes, a finite
    source; with albedo 1 and a black ground, what enters leaves (within 0.5 %)."""
    f = _core.solve_plane_parallel(
        **slab(tau, omega, phase, parts), sun_mu=mu0, sun_irradiance=(2.0, 1.0, 0.5),
        sky=lambda mu, phi: (1.0 + sky_tilt * mu * math.sin(phi),) * 3, ground_albedo=(albedo,) * 3,
        streams=8)
    for key in ("phased_radiance", "node_radiance", "radiance_sh", "irradiance_down", "irradiance_up"):
        assert np.all(np.isfinite(f[key])), key
    incident = np.asarray(f["incident_flux"])
    assert np.all(f["irradiance_down"] >= -1e-9 * incident) and np.all(f["irradiance_up"] >= -1e-9 * incident)
    if omega == 1.0 and albedo == 0.0:
        transmitted = f["irradiance_down"][0] + f["sun_direct_irradiance"][0] + f["sky_direct_irradiance"][0]
        assert np.allclose(f["irradiance_up"][-1] + transmitted, incident, rtol=5e-3)
    if omega == 0.0 and albedo == 0.0:
        assert not np.any(f["phased_radiance"]) and not np.any(f["irradiance_down"])


def day_scene(atmosphere: dict) -> dict:
    return {"camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 50},
            "film": {"width": 8, "height": 8},
            "sky": {"model": "overcast", "zenith_radiance": [0.3, 0.3, 0.3]},
            "sun": {"direction": [0.3, 0.6, -0.5], "irradiance": [1.0, 1.0, 1.0]},
            "atmosphere": atmosphere}


WEATHERS = {
    "clear": {"molecules": {}},
    "rain_40": {"molecules": {}, "rain": {"rate": 40.0}},
    "fog_50m": {"molecules": {}, "aerosol": {"visibility": 50.0}},
}


@pytest.mark.parametrize("weather", list(WEATHERS))
def test_renderer_weathers_solve(weather):
    """The renderer's weathers (clear, 40 mm/h rain, 50 m fog) through the scene path: the source
    is finite and positive, the ground's diffuse light is a sensible share of what enters, and the
    denser the air the larger that share of diffuse light."""
    f = _core.solve_plane_parallel_scene(day_scene(WEATHERS[weather]), ground_albedo=0.2)
    assert np.all(np.isfinite(f["phased_radiance"])) and np.all(f["phased_radiance"] >= 0.0)
    diffuse = f["irradiance_down"][0, 1]
    direct = f["sun_direct_irradiance"][0, 1] + f["sky_direct_irradiance"][0, 1]
    share = diffuse / (diffuse + direct)
    assert {"clear": 0.0 < share < 0.2, "rain_40": share > 0.5, "fog_50m": share > 0.99}[weather], share
