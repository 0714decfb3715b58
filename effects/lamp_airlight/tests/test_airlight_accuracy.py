"""Street-lamp airlight (effects/lamp_airlight/physics.md) against the independent float64 reference
(airlight_reference.py): rendered radiance = what the ray hits, attenuated, plus the
single-scattered glow of the fog in front of it; surfaces get the direct light and the
glow of the fog around them.

Each image is small (48 x 32); about 40 pixels per image are compared, chosen away
from geometric edges, shadow boundaries and lamp cores, among those brighter than
1e-3 of the image maximum (lamp cores left out). Every compared channel value must be
within 0.5 % of the reference. Culling is disabled (cull_fraction 0)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from airlight_reference import (
    DIM_FRACTION,
    REL_TOL,
    F_exact,
    airlight_log,
    box,
    compare,
    get_renderer,
    light,
    make_scene,
    parse_scene,
    plane,
    reference_samples,
    smooth_pixels,
    sphere,
)

BACKENDS = ("cpu", "gl")


def street(sigma_t, albedo=1.0) -> dict:
    """A lamp over a road, a wall on the left, a ball on the road."""
    return make_scene(
        (0.0, 1.7, 0.0), (0.0, 1.0, -10.0),
        [light((2.0, 4.0, -6.0), [100.0, 90.0, 70.0])],
        [plane((0, 0, 0), (0, 1, 0), 0.3), box((-4, 0, -15), (-3, 5, -2), 0.5),
         sphere((1.0, 0.6, -4.0), 0.6, [0.7, 0.3, 0.2])],
        sigma_t=sigma_t, albedo=albedo)


def lamp_at_distance(distance: float) -> dict:
    """A lamp `distance` metres away, 10 degrees off the view axis, a wall twice as far."""
    a = math.radians(10.0)
    pos = (distance * math.sin(a), 0.0, -distance * math.cos(a))
    return make_scene((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), [light(pos, 200.0)],
                      [plane((0, 0, -2.0 * distance), (0, 0, 1), 0.5)], sigma_t=0.02, fov_y=40.0)


VIEWS = {
    # gamma from 0.3 to 4 degrees around the lamp; a wall 20 m behind it ends the rays.
    "light_near_view_axis": make_scene((0, 0, 0), (0, 0, -10), [light((0, 0, -10), 100.0)],
                                       [plane((0, 0, -30), (0, 0, 1), 0.5)], sigma_t=0.1, fov_y=6.0),
    # gamma from 75 to 105 degrees: the lamp beside the camera, escaping rays and a road.
    "light_at_90_degrees": make_scene((0, 0, 0), (0, 0, -1), [light((5, 0, 0), 100.0)],
                                      [plane((0, -2, 0), (0, 1, 0), 0.3)], sigma_t=0.1, fov_y=30.0),
    # gamma from about 120 to 180 degrees: the lamp behind the camera.
    "light_behind_camera": make_scene((0, 0, 0), (0, 0, -1), [light((0.5, 0.3, 3.0), 100.0)],
                                      [plane((0, -1.5, 0), (0, 1, 0), 0.3)], sigma_t=0.1, fov_y=60.0),
}


def wall_scene(wall: float, lamp: float) -> dict:
    """A wall `wall` metres in front of the camera, facing it, and a lamp `lamp` metres
    away: in front of the wall (lit directly and by the glow) or behind it (the side
    facing the camera gets only the glow)."""
    return make_scene((0.0, 1.5, 0.0), (0.0, 1.5, -1.0), [light((1.5, 2.5, -lamp), [100.0, 80.0, 60.0])],
                      [plane((0, 0, -wall), (0, 0, 1), 0.6)], sigma_t=0.05, fov_y=50.0)


def _check(scene: dict, backend: str, label: str) -> None:
    samples = reference_samples(scene)
    image = get_renderer(backend).render(scene)
    compare(image, samples, label=f"{label} [{backend}]")


# ---- the reference itself ------------------------------------------------------------------------

@pytest.mark.parametrize("u,v,expected", [
    (0.5, 0.3, 0.2782776998), (1.0, math.pi / 4, 0.5247971433), (3.0, 1.2, 0.2919415871),
    (10.0, math.pi / 2, 0.0981910350), (100.0, 0.01, 0.0063211676)])
def test_reference_matches_closed_form_F(u, v, expected):
    """The quadrature reference reproduces L = A0 [F(A1, v) - F(A1, gamma / 2)] (the source paper
    (effects/lamp_airlight/physics.md)),
    F from the complex exponential integral, checked against effects/lamp_airlight/docs/airlight_table.md's
    values; compared in log space because A0 = exp(-T cos gamma) ... underflows for
    (u, v) = (100, 0.01)."""
    assert F_exact(u, v) == pytest.approx(expected, abs=1e-10)
    sigma, gamma = 0.7, min(v, 1.1)
    dist = u / (sigma * math.sin(gamma))  # A1 = T sin(gamma) = u
    b, h = dist * math.cos(gamma), dist * math.sin(gamma)
    x1 = math.inf if v == math.pi / 2 else b + h * math.tan(2.0 * v - math.pi / 2)  # xi(x1) = v
    optical = sigma * dist
    log_exact = (math.log(sigma * sigma / (2 * math.pi * optical * math.sin(gamma)))
                 - optical * math.cos(gamma) + math.log(F_exact(u, v) - F_exact(u, gamma / 2)))
    log_ref = airlight_log(sigma, sigma, 1.0, b, h, 0.0, x1)
    assert log_ref == pytest.approx(log_exact, abs=1e-8)


# ---- sweeps -------------------------------------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.001, 0.01, 0.1, 0.5, 2.0])
def test_sigma_t_and_albedo_sweep(sigma_t, backend):
    for albedo in (0.3, 1.0):
        _check(street(sigma_t, albedo), backend, f"street sigma_t={sigma_t} albedo={albedo}")


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_per_channel_sigma_t_and_albedo(backend):
    _check(street([0.02, 0.2, 1.0], [1.0, 0.6, 0.3]), backend, "street, per-channel medium")


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("distance", [0.5, 5.0, 50.0, 500.0])
def test_lamp_distance(distance, backend):
    _check(lamp_at_distance(distance), backend, f"lamp at {distance} m")


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("view", sorted(VIEWS))
def test_viewing_angle(view, backend):
    _check(VIEWS[view], backend, view)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("wall,lamp", [(1.0, 5.0), (10.0, 5.0), (100.0, 5.0), (1.0, 50.0), (10.0, 50.0),
                                       (100.0, 50.0)])
def test_wall_distance(wall, lamp, backend):
    _check(wall_scene(wall, lamp), backend, f"wall at {wall} m, lamp at {lamp} m")


# ---- the two backends agree ----------------------------------------------------------------------------

AGREEMENT_SCENES = {
    "street_thin": street(0.01),
    "street_thick": street(0.5, 0.3),
    "street_per_channel": street([0.02, 0.2, 1.0], [1.0, 0.6, 0.3]),
    "lamp_at_500m": lamp_at_distance(500.0),
    "wall_behind_lamp": wall_scene(1.0, 5.0),
    **VIEWS,
}


@pytest.mark.parametrize("name", sorted(AGREEMENT_SCENES))
def test_gl_matches_cpu(name):
    """GL and CPU within 0.5 % on every pixel away from edges and lamps that is above
    1e-3 of the image maximum."""
    scene = AGREEMENT_SCENES[name]
    gl = np.asarray(get_renderer("gl").render(scene), dtype=np.float64)
    cpu = np.asarray(get_renderer("cpu").render(scene), dtype=np.float64)
    mask, _ = smooth_pixels(parse_scene(scene))
    assert np.all(np.isfinite(gl)) and np.all(np.isfinite(cpu))
    peak = cpu[mask].max()
    use = mask[:, :, None] & (cpu > DIM_FRACTION * peak)
    assert use.sum() >= 100
    rel = np.where(use, np.abs(gl - cpu) / np.where(use, cpu, 1.0), 0.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    assert rel[worst] <= REL_TOL, f"{name}: GL {gl[worst]:.7e} vs CPU {cpu[worst]:.7e} at {worst}"


@pytest.mark.parametrize("backend", BACKENDS)
def test_march_mode_converges_to_reference(backend):
    """The brute-force ray-marching mode used by the benchmarks ("airlight": "march")
    with many steps agrees with the reference too (so that it is a fair baseline)."""
    scene = street(0.1)
    marched = copy.deepcopy(scene)
    marched["quality"] = {"cull_fraction": 0.0, "airlight": "march", "march_steps": 4096}
    compare(get_renderer(backend).render(marched), reference_samples(scene), label=f"march [{backend}]")
