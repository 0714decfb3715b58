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


def test_approaching_car_preset_shows_the_car():
    """approaching_car renders the car on its own (issue 17; it was black, its headlights only
    in the demo's sequence): two spot lights 1.5 m apart 200 m ahead, aimed at the camera, each
    imaged as a bright core where _pixel_of puts it, with darker sky between them."""
    scene = airlight.preset("approaching_car")
    spots = [light for light in scene["lights"] if light["type"] == "spot"]
    assert len(spots) == 2
    a, b = (np.array(s["position"], float) for s in spots)
    assert abs(np.linalg.norm(a - b) - 1.5) < 1e-9 and a[2] == b[2] == -200.0
    scene["film"] = {"width": 320, "height": 180}  # 1.36 mrad pixels: the lamps 5.5 pixels apart
    image = airlight.render(scene, backend="cpu")[..., 1]
    cores = []
    for lamp in (a, b):
        col, row = _pixel_of(scene, lamp)
        cores.append(image[int(row) - 1:int(row) + 2, int(col) - 1:int(col) + 2].max())
    col_a, row_a = _pixel_of(scene, a)
    col_b, _ = _pixel_of(scene, b)
    between = image[int(row_a), int((col_a + col_b) / 2)]
    assert min(cores) > 100 * max(between, 1e-30) and min(cores) > 1.0, (cores, between)
