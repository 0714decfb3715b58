"""Rendered particle clouds against the independent float64 compositor (particle_reference.py) of the
same particle set (issue 22's acceptance: median relative error <= 0.5 %, both backends), with the
camera below, inside and above the layer and a tower cutting into it; and the modelling's
promises: no NaN, Inf or negative light in the nasty corners, a scene without particle clouds builds
nothing, and the image changes continuously as the camera and the wind move."""

from __future__ import annotations

import copy
import functools
from typing import Any

import numpy as np
import particle_reference as ref
import pytest

import airlight

WIDTH, HEIGHT = 32, 18

SCENE: dict[str, Any] = {
    "film": {"width": WIDTH, "height": HEIGHT},
    "sky": {"model": "overcast", "zenith_radiance": [0.4, 0.5, 0.7]},
    "sun": {"elevation": 35, "azimuth": 30, "irradiance": [10, 9.5, 9]},
    "particle_clouds": {"base": 1000, "top": 2500, "coverage": 0.6, "cell_size": 300, "ring_cells": 6,
                        "rings": 2, "extinction": 0.02, "seed": 3},
    "quality": {"particle_table": "preview", "multiple_scattering": False},
}

CAMERAS: dict[str, dict[str, Any]] = {
    "below": {"position": [0, 2, 0], "look_at": [300, 1200, -2500], "up": [0, 1, 0], "fov_y": 70},
    "inside": {"position": [150, 1500, 100], "look_at": [0, 1600, -1000], "up": [0, 1, 0], "fov_y": 80},
    "above": {"position": [0, 4000, 0], "look_at": [0, 1500, -3000], "up": [0, 1, 0], "fov_y": 70},
}


def scene_for(camera: str) -> dict[str, Any]:
    scene = copy.deepcopy(SCENE)
    scene["camera"] = copy.deepcopy(CAMERAS[camera])
    return scene


@functools.cache
def table() -> airlight._core.ParticleTable:
    return airlight._core.ParticleTable.for_quality(SCENE["particle_clouds"].get("g", 0.85), "preview")


def relative_errors(image: np.ndarray, exact: np.ndarray) -> tuple[np.ndarray, str]:
    mask = exact.max(axis=-1) > 1e-3 * exact.max()
    rel = np.abs(image - exact)[mask] / exact[mask]
    where = np.unravel_index(int(np.argmax(np.where(mask[..., None], np.abs(image - exact) / np.maximum(
        exact, 1e-30), 0))), image.shape)
    return rel, f"worst at (row, col, channel) {where}: {image[where]} against {exact[where]}"


@pytest.mark.parametrize("camera", list(CAMERAS))
def test_compositing_matches_the_float64_reference(renderer, camera):
    scene = scene_for(camera)
    particles = airlight._core.particle_frame(scene)
    assert particles["drawn"] > 20, particles["drawn"]
    out = renderer.render(scene, outputs=["particle_clouds", "transmittance"])
    light, through = ref.composite(scene, particles, table())
    rel, where = relative_errors(out["particle_clouds"], light)
    assert rel.size > 0.2 * WIDTH * HEIGHT
    assert np.median(rel) <= 5e-3, where
    assert np.percentile(rel, 99) <= 3e-2, where
    np.testing.assert_allclose(out["transmittance"][..., 1], through, rtol=1e-3, atol=2e-4)
