"""The comparison cases of the plane-parallel solver against an independent
discrete-ordinate solver (PythonicDISORT, a Python reimplementation of
Stamnes' DISORT: eigenvectors per layer and one boundary-value solve, not
doubling and adding): their definition, how each solver is called, and how
the results are reduced to comparable numbers (effects/multiple_scattering/docs/solver.md
section 4). Used by test_plane_parallel_solver.py and bench/make_disort_reference.py.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

STREAMS = 16  # ordinates per hemisphere (PythonicDISORT's NQuad = 2 x this)
PHIS = (0.0, 1.0, math.pi)  # azimuths (from the sun) of the compared radiances

# Layers from the top down: (extinction depth, albedo, phase); phase "rayleigh"
# or ("hg", g). PythonicDISORT rejects albedo 1, hence 0.999999.
CASES: list[dict[str, Any]] = [
    {"name": "hg0.5_tau1", "layers": [(1.0, 0.999999, ("hg", 0.5))], "mu0": 0.5, "albedo": 0.0, "sky": False},
    {"name": "rain_tau20_sky_ground", "layers": [(20.0, 0.999999, ("hg", 0.87))], "mu0": 0.3,
     "albedo": 0.3, "sky": True},
    {"name": "rayleigh_tau0.3_sky", "layers": [(0.3, 0.999999, "rayleigh")], "mu0": 0.8, "albedo": 0.0,
     "sky": True},
    {"name": "rayleigh_over_rain", "layers": [(0.1, 0.999999, "rayleigh"), (50.0, 0.999, ("hg", 0.85))],
     "mu0": 0.6, "albedo": 0.2, "sky": False},
    {"name": "fog_tau100", "layers": [(100.0, 0.9, ("hg", 0.7))], "mu0": 0.7, "albedo": 0.1, "sky": True},
    {"name": "thin_forward_low_sun", "layers": [(0.01, 0.999999, ("hg", 0.9))], "mu0": 0.2, "albedo": 0.0,
     "sky": False},
    {"name": "three_layers_low_sun", "layers": [(0.05, 0.999999, "rayleigh"), (2.0, 0.95, ("hg", 0.7)),
                                                (8.0, 0.999999, ("hg", 0.87))], "mu0": 0.15, "albedo": 0.5,
     "sky": True},
]


def sky_radiance(mu: float) -> float:
    """The cases' sky: the CIE overcast shape 1 + 2 mu (azimuth-free, so
    PythonicDISORT's mode-0 boundary condition carries it exactly)."""
    return 1.0 + 2.0 * mu


def moments(phase: Any, count: int) -> np.ndarray:
    if phase == "rayleigh":
        chi = np.zeros(count)
        chi[0], chi[2] = 1.0, 0.1
        return chi
    return float(phase[1]) ** np.arange(count)


def reduce(mu_up: np.ndarray, flux_up: np.ndarray, flux_down: np.ndarray, rad_top_up: np.ndarray,
           rad_bottom_down: np.ndarray) -> dict[str, list[float]]:
    """Comparable numbers: interface fluxes (total down = diffuse + direct;
    up) from the top down, the upward radiance at the top and the total
    downward radiance (diffuse + unscattered sky) at the ground at the
    ordinates mu_up (ascending) for each of PHIS."""
    return {"mu": list(map(float, mu_up)), "flux_up": list(map(float, flux_up)),
            "flux_down": list(map(float, flux_down)), "radiance_top_up": list(map(float, rad_top_up.ravel())),
            "radiance_bottom_down": list(map(float, rad_bottom_down.ravel()))}


def run_airlight(case: dict[str, Any], streams: int = STREAMS) -> dict[str, list[float]]:
    from airlight import _core

    layers = list(reversed(case["layers"]))  # from the ground up
    phases = []
    for _, _, p in case["layers"]:
        if p not in phases:
            phases.append(p)
    ext, sca, tops = [], [], []
    height = 0.0
    for depth, albedo, p in layers:
        e = [[0.0] * 3 for _ in phases]
        s = [[0.0] * 3 for _ in phases]
        i = phases.index(p)
        e[i] = [depth] * 3
        s[i] = [depth * albedo] * 3
        ext.append(e)
        sca.append(s)
        height += 100.0
        tops.append(height)
    sky = (lambda mu, phi: (sky_radiance(mu),) * 3) if case["sky"] else None
    f = _core.solve_plane_parallel([p if p == "rayleigh" else tuple(p) for p in phases], tops, ext, sca,
                                   sun_mu=case["mu0"], sun_irradiance=(1.0, 1.0, 1.0), sky=sky,
                                   ground_albedo=(case["albedo"],) * 3, streams=streams)
    n = f["streams"]
    mu = np.asarray(f["node_mu"])
    nodes = np.asarray(f["node_radiance"])[:, 1]  # [level, mode, node, sine], green
    modes = np.arange(nodes.shape[1])

    def radiance(level: int, node_slice: slice) -> np.ndarray:
        out = []
        for phi in PHIS:
            c, s = np.cos(modes * phi), np.sin(modes * phi)
            out.append(nodes[level, :, node_slice, 0].T @ c + nodes[level, :, node_slice, 1].T @ s)
        return np.array(out)

    top, bottom = len(f["altitudes"]) - 1, 0
    down = np.asarray(f["irradiance_down"])[:, 1] + np.asarray(f["sun_direct_irradiance"])[:, 1] + \
        np.asarray(f["sky_direct_irradiance"])[:, 1]
    up = np.asarray(f["irradiance_up"])[:, 1]
    rad_up = radiance(top, slice(n, 2 * n))  # look down = upward light
    depth_total = sum(d for d, _, _ in case["layers"])
    sky_unscattered = 0.0
    if case["sky"]:
        sky_unscattered = np.array([sky_radiance(m) * math.exp(-depth_total / m) for m in mu])
    rad_down = radiance(bottom, slice(0, n)) + sky_unscattered
    return reduce(mu, up[::-1], down[::-1], rad_up, rad_down)


def run_pythonic_disort(case: dict[str, Any], streams: int = STREAMS) -> dict[str, list[float]]:
    import warnings

    from PythonicDISORT import pydisort

    nleg = 2 * streams
    tau = np.cumsum([d for d, _, _ in case["layers"]])
    omega = np.array([a for _, a, _ in case["layers"]])
    leg = np.array([moments(p, nleg + 1) for _, _, p in case["layers"]])
    kwargs: dict[str, Any] = {"NLeg": nleg, "f_arr": leg[:, nleg], "NT_cor": False}
    if case["albedo"] > 0.0:
        kwargs["BDRF_Fourier_modes"] = [case["albedo"]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mu_arr = pydisort(tau, omega, 2 * streams, leg, case["mu0"], 1.0, 0.0, only_flux=True, **kwargs)[0]
        if case["sky"]:
            kwargs["b_neg"] = np.array([sky_radiance(m) for m in mu_arr[:streams]])
        mu_arr, fp, fm, _, u = pydisort(tau, omega, 2 * streams, leg, case["mu0"], 1.0, 0.0, **kwargs)
        levels = np.concatenate([[0.0], tau])
        up = np.array([fp(t) for t in levels])
        down = np.array([sum(fm(t)) for t in levels])
        rad_top = np.array([u(0.0, phi)[:streams] for phi in PHIS])
        rad_bottom = np.array([u(tau[-1], phi)[streams:] for phi in PHIS])
    return reduce(mu_arr[:streams], up, down, rad_top, rad_bottom)


def worst_differences(a: dict[str, list[float]], b: dict[str, list[float]],
                      incident: float) -> dict[str, float]:
    """Largest flux difference over the incident flux; largest radiance
    difference over the largest radiance of the reference b."""
    out = {}
    for key in ("flux_up", "flux_down"):
        out[key] = float(np.max(np.abs(np.subtract(a[key], b[key]))) / incident)
    for key in ("radiance_top_up", "radiance_bottom_down"):
        ref = np.asarray(b[key])
        out[key] = float(np.max(np.abs(np.asarray(a[key]) - ref)) / np.max(np.abs(ref)))
    return out


def incident_flux(case: dict[str, Any]) -> float:
    return case["mu0"] + (2.0 * math.pi * (0.5 + 2.0 / 3.0) if case["sky"] else 0.0)
