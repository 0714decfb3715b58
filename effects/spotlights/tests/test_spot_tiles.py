"""The spots' screen tiles (effects/spotlights/physics.md section 9): a pixel's view ray walks only the
spots whose beams can meet a ray of its 16 x 16 tile. The lists are conservative, so the image is
exactly the one every pixel walking every spot gives (`quality.spot_lists: "all"`), on both
backends, for the presets with spots, a street of 64 headlights, the camera inside a beam and beams
behind the camera, and random spots around a tilted camera (hypothesis)."""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airlight

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))
from effects.lamp_airlight.bench.bench_airlight import street_scene  # noqa: E402


def with_lists(scene: dict[str, Any], lists: str) -> dict[str, Any]:
    scene = copy.deepcopy(scene)
    scene["quality"] = {**scene.get("quality", {}), "spot_lists": lists}
    return scene


def assert_lists_change_nothing(renderer: airlight.Renderer, scene: dict[str, Any]) -> None:
    tiles = renderer.render(with_lists(scene, "tiles"))
    every = renderer.render(with_lists(scene, "all"))
    assert every.max() > 0.0
    np.testing.assert_array_equal(tiles, every)


def headlight_street(width: int, height: int) -> dict[str, Any]:
    """bench_airlight's street of 32 cars' headlights over black surfaces."""
    return street_scene(64, width, height, 0.0, "headlights")


def test_spot_lists_are_a_quality_key():
    assert airlight.load_scene(airlight.preset("crane_searchlight"))["quality"]["spot_lists"] == "tiles"
    with pytest.raises(ValueError, match="quality.spot_lists"):
        airlight.load_scene(with_lists(airlight.preset("crane_searchlight"), "some"))


@pytest.mark.parametrize("name", ["spotlights_crossing_002", "spotlights_crossing_004", "crane_searchlight",
                                  "approaching_car", "shafts_lamp_alley", "falling_rain_night_light"])
def test_tiles_give_the_image_of_every_spot_on_the_presets(renderer, name):
    scene = airlight.preset(name)
    scene["film"] = {"width": 64, "height": 36}
    assert_lists_change_nothing(renderer, scene)


def test_tiles_give_the_image_of_every_spot_on_a_headlight_street(renderer):
    assert_lists_change_nothing(renderer, headlight_street(80, 45))


def test_tiles_with_the_camera_inside_a_beam_and_beams_behind_it(renderer):
    spot = {"type": "spot", "intensity": [300, 300, 300], "cone_angle": 20}
    scene = {"film": {"width": 48, "height": 32},
             "camera": {"position": [0, 1.5, 0], "look_at": [0, 1.5, -10], "up": [0, 1, 0], "fov_y": 60},
             "medium": {"sigma_t": 0.05, "albedo": 0.9},
             # The camera in a beam, a spot behind aimed away, one across the view, one nearly a half-space.
             "lights": [{**spot, "position": [0, 1.5, 3], "direction": [0, 0, -1]},
                        {**spot, "position": [0, 1.5, 5], "direction": [0, 0, 1]},
                        {**spot, "position": [4, 3, -8], "direction": [-1, -0.2, 0.3]},
                        {**spot, "position": [-2, 0.5, -3], "direction": [0, 1, 0], "cone_angle": 89}]}
    assert_lists_change_nothing(renderer, scene)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_tiles_give_the_image_of_every_spot_for_random_spots(renderer, data):
    def vec(lo: float, hi: float) -> list[float]:
        return [data.draw(st.floats(lo, hi)) for _ in range(3)]

    lights = []
    for _ in range(data.draw(st.integers(1, 6))):
        direction = vec(-1, 1)
        if max(abs(c) for c in direction) < 1e-3:
            direction = [0.0, 0.0, -1.0]
        lights.append({"type": "spot", "position": vec(-20, 20), "direction": direction,
                       "intensity": [100, 90, 80], "cone_angle": data.draw(st.floats(0.5, 90)),
                       "radius": data.draw(st.floats(0.01, 2.0))})
    look = vec(-10, 10)
    if abs(look[0]) + abs(look[2]) < 1e-2:
        look[2] = -5.0
    scene = {"film": {"width": data.draw(st.integers(8, 40)), "height": data.draw(st.integers(8, 40))},
             "camera": {"position": [0, 0, 0], "look_at": look, "up": [0, 1, 0],
                        "fov_y": data.draw(st.floats(10, 120))},
             "medium": {"sigma_t": data.draw(st.floats(0.001, 0.5)), "albedo": 0.9},
             "lights": lights}
    tiles = renderer.render(with_lists(scene, "tiles"))
    np.testing.assert_array_equal(tiles, renderer.render(with_lists(scene, "all")))
