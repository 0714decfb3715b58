"""The preset scenes shipped in scenes/: each loads and renders, and the
forward-scattering street shows what it is there to show."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

import airlight


@pytest.mark.parametrize("name", airlight.preset_names())
def test_every_preset_renders_finite_non_negative(name):
    """Every shipped scene is valid and renders (small, CPU) without NaN, Inf or negative radiance."""
    image = airlight.render(airlight.preset(name), backend="cpu", width=48, height=27)
    assert image.shape == (27, 48, 3)
    assert np.isfinite(image).all() and (image >= 0).all()


def _pixel_of(scene: dict, point: np.ndarray) -> tuple[float, float]:
    """(column, row) of a world point's image (pixel centres at integer + 0.5)."""
    cam = scene["camera"]
    pos = np.array(cam["position"], float)
    fwd = np.array(cam["look_at"], float) - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, cam["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    w, h = scene["film"]["width"], scene["film"]["height"]
    th = math.tan(math.radians(cam["fov_y"]) / 2)
    v = point - pos
    sx = (v @ right) / (v @ fwd) / (th * w / h)
    sy = (v @ up) / (v @ fwd) / th
    return (sx + 1) * w / 2, (1 - sy) * h / 2


def test_forward_scattering_street_tightens_the_halos():
    """foggy_street_hg is foggy_street with HG g = 0.85 and nothing else changed, and around
    a lamp its halo falls off much faster: the radiance 2 degrees beside the lamp's image
    over that 12 degrees beside it is more than twice the isotropic street's ratio."""
    iso, hg = airlight.preset("foggy_street"), airlight.preset("foggy_street_hg")
    assert hg["medium"]["phase"] == {"type": "hg", "g": 0.85}
    same = copy.deepcopy(hg)
    same["medium"]["phase"] = iso["medium"]["phase"]
    assert same == iso
    width, height = 320, 180
    ratios = []
    for scene in (iso, hg):
        scene["film"] = {"width": width, "height": height}
        image = airlight.render(scene, backend="cpu")[..., 1]
        lamp = np.array(scene["lights"][1]["position"], float)  # on the right, 17 m ahead
        col, row = _pixel_of(scene, lamp)
        per_degree = height / scene["camera"]["fov_y"]
        near = image[int(row), int(col - 2 * per_degree)]
        far = image[int(row), int(col - 12 * per_degree)]
        ratios.append(near / far)
    print(f"halo ratios near/far: isotropic {ratios[0]:.2f}, hg {ratios[1]:.2f}")
    assert ratios[1] > 2 * ratios[0], f"halo ratios near/far: isotropic {ratios[0]:.2f}, hg {ratios[1]:.2f}"
