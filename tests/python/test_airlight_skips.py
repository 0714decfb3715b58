"""Skip what the scene does not need: lamps and contributions provably below
cull_fraction (default 1e-5) times the scene's reference radiance are dropped.
The reference radiance is the brightest, over lights and channels, of
I * max(sigma_s / 4, 1 / (25 pi)) (the glow 1 m from the lamp in its own fog, and a
white surface 5 m from it). With N lights, the default culling may change no pixel by
more than N * cull_fraction * reference (plus the float32 rounding of the N terms'
sum)."""

from __future__ import annotations

import copy
import math

import airlight
import numpy as np
import pytest
from airlight_reference import (
    DEFAULT_CULL_FRACTION,
    box,
    cull_reference_radiance,
    get_renderer,
    light,
    make_scene,
    parse_scene,
    plane,
    sphere,
)

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


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", sorted(SCENES))
def test_default_culling_error_bound(name, backend):
    """|culled - unculled| <= N * cull_fraction * reference on every pixel and channel,
    plus N float32 rounding steps of the pixel's value."""
    exact_scene = SCENES[name]
    assert exact_scene["quality"]["cull_fraction"] == 0.0
    culled_scene = copy.deepcopy(exact_scene)
    del culled_scene["quality"]  # the default
    r = get_renderer(backend)
    exact = np.asarray(r.render(exact_scene), dtype=np.float64)
    culled = np.asarray(r.render(culled_scene), dtype=np.float64)
    assert np.all(np.isfinite(exact)) and np.all(np.isfinite(culled))
    sc = parse_scene(exact_scene)
    n_lights = len(sc.lights)
    bound = n_lights * DEFAULT_CULL_FRACTION * cull_reference_radiance(sc)
    rounding = n_lights * np.spacing(np.maximum(exact, culled).astype(np.float32)).astype(np.float64)
    excess = np.abs(culled - exact) - bound - rounding
    worst = np.unravel_index(np.argmax(excess), excess.shape)
    assert excess[worst] <= 0, (
        f"{name} [{backend}]: culling changed pixel {worst[:2]} channel {worst[2]} from {exact[worst]:.7e} "
        f"to {culled[worst]:.7e} (by {abs(culled[worst] - exact[worst]):.3e}); bound N f ref = {bound:.3e} "
        f"(N = {n_lights}, reference {cull_reference_radiance(sc):.4g}); "
        f"{int((excess > 0).sum())} values over the bound")


@pytest.mark.parametrize("backend", BACKENDS)
def test_culling_keeps_everything_visible(backend):
    """With a larger cull fraction (1e-3) the bound scales with it; lamps far beyond any
    visible contribution (1 km in fog of visibility 40 m) change nothing visible."""
    scene = _street_of_lamps(0.1, 1.0)
    loose = copy.deepcopy(scene)
    loose["quality"] = {"cull_fraction": 1e-3}
    r = get_renderer(backend)
    exact = np.asarray(r.render(scene), dtype=np.float64)
    culled = np.asarray(r.render(loose), dtype=np.float64)
    sc = parse_scene(scene)
    bound = len(sc.lights) * 1e-3 * cull_reference_radiance(sc)
    rounding = len(sc.lights) * np.spacing(np.maximum(exact, culled).astype(np.float32)).astype(np.float64)
    assert np.all(np.abs(culled - exact) <= bound + rounding)
    assert math.isfinite(float(culled.sum()))
