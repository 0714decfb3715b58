"""The sun's shadow map (effects/sun_shadow_map/physics.md) against the exact shadow rays on both
backends: the map's image differs from the rays' only in a band about its texel size wide around
shadow edges, that band narrows as the map gets finer, the backends agree, and a scene that does
not need the map is not changed by asking for one."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest

import airlight

SCENE: dict[str, Any] = {
    "film": {"width": 160, "height": 120},
    "camera": {"position": [0.0, 6.0, 6.0], "look_at": [0.0, 0.0, -8.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 60.0},
    "sky": {"model": "overcast", "zenith_radiance": 0.05},
    "sun": {"elevation": 35.0, "azimuth": 120.0, "irradiance": 100.0},
    "surfaces": [
        {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
        {"type": "box", "min": [-3, 0, -14], "max": [-1, 3, -10], "albedo": 0.5},
        {"type": "box", "min": [1, 0, -9], "max": [2, 1.5, -7], "albedo": [0.6, 0.4, 0.3]},
        {"type": "sphere", "center": [0.5, 1, -16], "radius": 1, "albedo": 0.5},
        {"type": "box", "min": [3, 0, -6], "max": [3.3, 4, -5.7], "albedo": 0.4},
    ],
}


def with_map(size: int, scene: dict[str, Any] = SCENE) -> dict[str, Any]:
    s = copy.deepcopy(scene)
    s.setdefault("quality", {})["sun_shadow_map"] = size
    return s


def differing_fraction(a: np.ndarray, b: np.ndarray, tol: float = 0.02) -> float:
    """Fraction of pixels where the two images differ by more than tol of the brighter (per channel)."""
    scale = np.maximum(np.maximum(a, b), 1e-3)
    return float(np.mean(np.any(np.abs(a - b) > tol * scale, axis=-1)))


@pytest.fixture(scope="module")
def rays(renderer_cache):
    return {name: renderer_cache(name).render(SCENE) for name in ("cpu", "gl")
            if airlight.gl_unavailable_reason() is None or name == "cpu"}


def test_the_scene_has_shadows_to_get_right(renderer):
    img = renderer.render(SCENE)
    no_sun = copy.deepcopy(SCENE)
    no_sun["sun"]["irradiance"] = 0.0
    # The sun lights most of the ground; the casters' shadows cover a few percent of the image.
    lit = renderer.render(no_sun)
    sunlit = np.mean(img[..., 1] > 3 * lit[..., 1])
    assert 0.3 < sunlit < 0.95


@pytest.mark.parametrize("size", [256, 1024])
def test_map_differs_from_shadow_rays_only_near_shadow_edges(renderer, rays, size):
    ref = rays[renderer.backend]
    img = renderer.render(with_map(size))
    assert np.all(np.isfinite(img)) and np.all(img >= 0)
    frac = differing_fraction(img, ref)
    # The band of width ~2 texels around the edges (measured: 0.13 % of the pixels at 256, 0.05 % at
    # 1024, the same on both backends).
    assert frac < (0.004 if size == 256 else 0.0015), frac
    # Away from the edges the answer is the shadow ray's to float rounding.
    close = np.all(np.abs(img - ref) <= 1e-5 * np.maximum(ref, 1e-3), axis=-1)
    assert np.mean(close) > 1.0 - 2.0 * frac - 0.002


def test_map_converges_to_shadow_rays(renderer, rays):
    ref = rays[renderer.backend]
    fracs = [differing_fraction(renderer.render(with_map(n)), ref) for n in (64, 256, 1024)]
    assert fracs[0] > fracs[1] > fracs[2], fracs
    assert fracs[0] > 2.0 * fracs[2], fracs


def test_backends_agree_with_the_map(renderer_cache):
    if airlight.gl_unavailable_reason() is not None:
        pytest.skip(f"GL backend unavailable: {airlight.gl_unavailable_reason()}")
    cpu = renderer_cache("cpu").render(with_map(512))
    gl = renderer_cache("gl").render(with_map(512))
    assert differing_fraction(cpu, gl, tol=1e-3) < 0.003


@pytest.mark.parametrize("change", ["no_sun", "no_casters", "sun_below_horizon"])
def test_scene_without_a_map_to_make_is_unchanged(renderer, change):
    scene = copy.deepcopy(SCENE)
    if change == "no_sun":
        del scene["sun"]
    elif change == "no_casters":
        scene["surfaces"] = scene["surfaces"][:1]
    else:
        scene["sun"]["elevation"] = -5.0
    np.testing.assert_array_equal(renderer.render(with_map(1024, scene)), renderer.render(scene))


@pytest.mark.parametrize("bad", [-1, 8, 15, 4097, 1.5, True, "256"])
def test_bad_map_size_names_the_field(bad):
    with pytest.raises((ValueError, TypeError), match=r"quality\.sun_shadow_map"):
        airlight.load_scene(with_map(bad))


def test_map_size_is_written_back():
    assert airlight.load_scene(with_map(512))["quality"]["sun_shadow_map"] == 512
    assert airlight.load_scene(SCENE)["quality"]["sun_shadow_map"] == 0
