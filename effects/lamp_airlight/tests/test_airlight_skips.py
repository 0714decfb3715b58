"""Skip what the scene does not need: a lamp's contribution is dropped when it is
provably below cull_fraction (default 1e-5) of what the pixel (or the surface
irradiance) has summed before it (effects/lamp_airlight/docs/culling.md). So the default culling may change
a pixel with N lamps by at most N * cull_fraction * its unculled value (plus the
float32 rounding of the N terms' sum)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from airlight_reference import (
    DEFAULT_CULL_FRACTION,
    box,
    get_renderer,
    light,
    make_scene,
    parse_scene,
    plane,
    sphere,
)

import airlight

BACKENDS = ("cpu", "gl")


def _street_of_lamps(sigma_t=0.05, albedo=0.9) -> dict:
    """20 lamps 6 m apart along a road, then 10 more up to 1 km away."""
    lamps = [light((3.0 * (-1) ** k, 5.0, -6.0 * k), [100.0, 90.0, 70.0]) for k in range(20)]
    lamps += [light((0.0, 5.0, -100.0 * k), 100.0) for k in range(1, 11)]
    return make_scene((0, 1.7, 0), (0, 1.5, -20), lamps,
                      [plane((0, 0, 0), (0, 1, 0), 0.3), box((-8, 0, -200), (-6, 10, -5), 0.5),
                       sphere((1.0, 0.6, -8.0), 0.6, 0.7)],
                      sigma_t=sigma_t, albedo=albedo, fov_y=60.0, width=48, height=32)


def _thick_fog() -> dict:
    lamps = [light((0.5 * k, 2.0, -1.5 * k), 50.0) for k in range(1, 15)]
    lamps.append(light((0.0, 1.0, 30.0), 1e4))  # far behind the camera
    return make_scene((0, 1.5, 0), (0, 1.0, -5), lamps, [plane((0, 0, 0), (0, 1, 0), 0.4)],
                      sigma_t=1.0, albedo=0.95, fov_y=70.0, width=48, height=32)


def _bright_core_and_dim_lamp() -> dict:
    """A lamp core in view (radiance I / (pi r^2), about 1e4) and a second, dim lamp far
    to the side whose airlight over the whole image, the core's pixels included, is
    about 1e-3: far below the core, far above cull_fraction * reference."""
    return make_scene((0, 0, 0), (0, 0, -1), [light((0, 0, -10), 100.0), light((25, 0, -10), 100.0)], [],
                      sigma_t=0.05, albedo=1.0, fov_y=2.0, width=24, height=16)


def _camera_inside_lamp() -> dict:
    lamps = [light((0.1, 1.5, 0.0), 100.0, 0.5)] + [light((4.0, 4.0, -10.0 * k), 80.0) for k in range(1, 8)]
    return make_scene((0, 1.5, 0), (0, 1.0, -5), lamps, [plane((0, 0, 0), (0, 1, 0), 0.3)],
                      sigma_t=0.2, albedo=1.0, fov_y=80.0, width=48, height=32)


SCENES = {
    "street_of_lamps": _street_of_lamps(),
    "street_per_channel_fog": _street_of_lamps([0.01, 0.1, 0.5], [1.0, 0.7, 0.4]),
    "street_absorbing_fog": _street_of_lamps(0.1, 0.0),
    "thick_fog": _thick_fog(),
    "bright_core_and_dim_lamp": _bright_core_and_dim_lamp(),
    "camera_inside_lamp": _camera_inside_lamp(),
}


def test_default_cull_fraction():
    scene = copy.deepcopy(SCENES["street_of_lamps"])
    del scene["quality"]
    assert airlight.load_scene(scene)["quality"]["cull_fraction"] == pytest.approx(DEFAULT_CULL_FRACTION)


def _renders(name: str, backend: str, cull_fraction=None):
    exact_scene = SCENES[name]
    assert exact_scene["quality"]["cull_fraction"] == 0.0
    culled_scene = copy.deepcopy(exact_scene)
    if cull_fraction is None:
        del culled_scene["quality"]  # the default
    else:
        culled_scene["quality"] = {"cull_fraction": cull_fraction}
    r = get_renderer(backend)
    exact = np.asarray(r.render(exact_scene), dtype=np.float64)
    culled = np.asarray(r.render(culled_scene), dtype=np.float64)
    assert np.all(np.isfinite(exact)) and np.all(np.isfinite(culled))
    sc = parse_scene(exact_scene)
    rounding = len(sc.lights) * np.spacing(np.maximum(exact, culled).astype(np.float32)).astype(np.float64)
    return exact, culled, sc, rounding


def _assert_within(exact, culled, bound, rounding, label: str) -> None:
    excess = np.abs(culled - exact) - bound - rounding
    worst = np.unravel_index(np.argmax(excess), excess.shape)
    b = bound if np.ndim(bound) == 0 else bound[worst]
    assert excess[worst] <= 0, (
        f"{label}: culling changed pixel {tuple(int(i) for i in worst[:2])} channel {worst[2]} from "
        f"{exact[worst]:.7e} to {culled[worst]:.7e} (by {abs(culled[worst] - exact[worst]):.3e}), bound "
        f"{b:.3e}; {int((excess > 0).sum())} values over the bound")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", sorted(SCENES))
def test_default_culling_relative_bound(name, backend):
    """|culled - unculled| <= N * cull_fraction * unculled on every pixel and channel."""
    exact, culled, sc, rounding = _renders(name, backend)
    bound = len(sc.lights) * DEFAULT_CULL_FRACTION * exact
    _assert_within(exact, culled, bound, rounding, f"{name} [{backend}], relative bound")


@pytest.mark.parametrize("backend", BACKENDS)
def test_larger_cull_fraction_scales_the_bound(backend):
    """cull_fraction 1e-3 (a hundred times the default): the relative bound scales with it."""
    exact, culled, sc, rounding = _renders("street_of_lamps", backend, 1e-3)
    _assert_within(exact, culled, len(sc.lights) * 1e-3 * exact, rounding, f"cull_fraction 1e-3 [{backend}]")
    assert np.any(culled != exact), "nothing was culled at cull_fraction 1e-3 in a street of 30 lamps"
