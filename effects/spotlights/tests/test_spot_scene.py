"""Spot lights in the scene format (README "Scene format", effects/spotlights/physics.md) and
the airlight.headlights() helper, through load_scene only (no rendering): spots
load normalised with every default filled in, every bad spot input raises
TypeError/ValueError naming the field, and headlights() places and aims its
lamps as documented and names the argument it rejects."""

from __future__ import annotations

import copy
import math
import re
from typing import Any, Callable

import numpy as np
import pytest
from scene_edit import delete_at, set_at

import airlight

SPOT: dict[str, Any] = {"type": "spot", "position": [1.0, 4.0, -8.0], "direction": [0.0, -2.0, 0.0],
                        "intensity": 500.0, "cone_angle": 25.0}

SCENE: dict[str, Any] = {
    "film": {"width": 24, "height": 16},
    "camera": {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.7, -10.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 60.0},
    "medium": {"sigma_t": 0.05},
    # lights[0] a point light, lights[1] a spot light.
    "lights": [{"type": "point", "position": [3.0, 5.0, -20.0], "intensity": [100.0, 90.0, 70.0]}, SPOT],
    "surfaces": [{"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0]}],
}

SPOT_KEYS = {"type", "position", "direction", "intensity", "cone_angle", "edge", "radius",
             "volumetric_shadows"}


def _scene(*lights: dict[str, Any]) -> dict[str, Any]:
    scene = copy.deepcopy(SCENE)
    scene["lights"] = [copy.deepcopy(light) for light in lights]
    return scene


def _spots(loaded: dict[str, Any]) -> list[dict[str, Any]]:
    return [light for light in loaded["lights"] if light["type"] == "spot"]


# --- loading -----------------------------------------------------------------


def test_spot_loads_normalised_with_defaults() -> None:
    loaded = airlight.load_scene(copy.deepcopy(SCENE))
    assert [light["type"] for light in loaded["lights"]] == ["point", "spot"]
    spot = loaded["lights"][1]
    assert set(spot) == SPOT_KEYS
    assert spot["position"] == [1.0, 4.0, -8.0]
    assert spot["direction"] == [0.0, -1.0, 0.0]
    assert spot["intensity"] == [500.0, 500.0, 500.0]
    assert spot["cone_angle"] == 25.0
    assert spot["edge"] == 0
    assert spot["radius"] == pytest.approx(0.05)
    assert spot["volumetric_shadows"] is False
    assert "direction" not in loaded["lights"][0]


def test_spot_keeps_given_values_and_normalises_the_direction() -> None:
    spot = dict(SPOT, direction=[3.0, 0.0, -4.0], intensity=[1.0, 2.0, 3.0], cone_angle=90, edge=1,
                radius=0.2)
    (loaded,) = _spots(airlight.load_scene(_scene(spot)))
    assert loaded["direction"] == pytest.approx([0.6, 0.0, -0.8], abs=1e-7)
    assert math.hypot(*loaded["direction"]) == pytest.approx(1.0, abs=1e-6)
    assert loaded["intensity"] == [1.0, 2.0, 3.0]
    assert loaded["cone_angle"] == 90.0
    assert loaded["edge"] == 1.0
    assert loaded["radius"] == pytest.approx(0.2)


def test_points_are_written_before_spots_and_reloading_is_exact() -> None:
    point = SCENE["lights"][0]
    lights = [SPOT, point, dict(SPOT, edge=0.5, cone_angle=10.0), dict(point, position=[0.0, 2.0, 0.0])]
    loaded = airlight.load_scene(_scene(*lights))
    assert [light["type"] for light in loaded["lights"]] == ["point", "point", "spot", "spot"]
    assert [s["edge"] for s in _spots(loaded)] == [0.0, 0.5]  # spots keep their relative order
    assert airlight.load_scene(loaded) == loaded


def test_scene_of_spots_only_and_no_spots() -> None:
    loaded = airlight.load_scene(_scene(SPOT, SPOT))
    assert len(_spots(loaded)) == len(loaded["lights"]) == 2
    loaded = airlight.load_scene(_scene(SCENE["lights"][0]))
    assert _spots(loaded) == []


# --- bad spot input ------------------------------------------------------------


_set = set_at
_delete = delete_at


def _append_spot(**changes: Any) -> Callable[[dict], None]:
    def mutate(scene: dict) -> None:
        scene["lights"].append(dict(copy.deepcopy(SPOT), **changes))

    return mutate


NAN, INF = float("nan"), float("inf")

# (id, mutation, exception type, field the message must start with, text the message must contain)
BAD_SPOTS = [
    ("missing_position", _delete("lights[1].position"), ValueError, "lights[1].position",
     "missing required key"),
    ("missing_direction", _delete("lights[1].direction"), ValueError, "lights[1].direction",
     "missing required"),
    ("missing_intensity", _delete("lights[1].intensity"), ValueError, "lights[1].intensity",
     "missing required"),
    ("missing_cone_angle", _delete("lights[1].cone_angle"), ValueError, "lights[1].cone_angle",
     "missing required"),
    ("zero_direction", _set("lights[1].direction", [0, 0, 0]), ValueError, "lights[1].direction",
     "must not be zero"),
    ("tiny_direction", _set("lights[1].direction", [1e-14, 0, 0]), ValueError, "lights[1].direction",
     "must not be zero"),
    ("short_direction", _set("lights[1].direction", [0, -1]), ValueError, "lights[1].direction", "exactly 3"),
    ("string_direction", _set("lights[1].direction", "down"), TypeError, "lights[1].direction",
     "expected a list"),
    ("nan_direction", _set("lights[1].direction", [0, NAN, 0]), ValueError, "lights[1].direction", "finite"),
    ("cone_angle_zero", _set("lights[1].cone_angle", 0), ValueError, "lights[1].cone_angle",
     "must be in [0.001, 90]"),
    ("cone_angle_negative", _set("lights[1].cone_angle", -5), ValueError, "lights[1].cone_angle",
     "must be in [0.001, 90]"),
    ("cone_angle_above_90", _set("lights[1].cone_angle", 90.5), ValueError, "lights[1].cone_angle",
     "must be in [0.001, 90]"),
    ("cone_angle_180", _set("lights[1].cone_angle", 180), ValueError, "lights[1].cone_angle",
     "must be in [0.001, 90]"),
    ("cone_angle_nan", _set("lights[1].cone_angle", NAN), ValueError, "lights[1].cone_angle", "finite"),
    ("cone_angle_string", _set("lights[1].cone_angle", "25"), TypeError, "lights[1].cone_angle",
     "expected a number"),
    ("cone_angle_bool", _set("lights[1].cone_angle", True), TypeError, "lights[1].cone_angle",
     "expected a number"),
    ("edge_negative", _set("lights[1].edge", -0.1), ValueError, "lights[1].edge", "must be in [0, 1]"),
    ("edge_above_1", _set("lights[1].edge", 1.01), ValueError, "lights[1].edge", "must be in [0, 1]"),
    ("edge_none", _set("lights[1].edge", None), TypeError, "lights[1].edge", "expected a number"),
    ("edge_inf", _set("lights[1].edge", INF), ValueError, "lights[1].edge", "finite"),
    ("radius_zero", _set("lights[1].radius", 0), ValueError, "lights[1].radius",
     "must be in [1e-06, 1000] m"),
    ("radius_huge", _set("lights[1].radius", 5000), ValueError, "lights[1].radius",
     "must be in [1e-06, 1000] m"),
    ("negative_intensity", _set("lights[1].intensity", [1, -1, 1]), ValueError, "lights[1].intensity",
     "must be >= 0"),
    ("position_absurd", _set("lights[1].position", [0, 1e9, 0]), ValueError, "lights[1].position", "absurd"),
    ("unknown_key", _set("lights[1].colour", 1), ValueError, "lights[1].colour", "unknown key"),
    ("plane_key_on_spot", _set("lights[1].normal", [0, 1, 0]), ValueError, "lights[1].normal", "unknown key"),
    ("misspelt_cone_angle", _set("lights[1].cone_angel", 25), ValueError, "lights[1].cone_angel",
     "did you mean 'cone_angle'?"),
    ("point_with_direction", _set("lights[0].direction", [0, -1, 0]), ValueError, "lights[0].direction",
     "unknown key"),
    ("point_with_cone_angle", _set("lights[0].cone_angle", 30), ValueError, "lights[0].cone_angle",
     "unknown key"),
    ("point_with_edge", _set("lights[0].edge", 0.5), ValueError, "lights[0].edge", "unknown key"),
    ("unknown_light_type", _set("lights[1].type", "area"), ValueError, "lights[1].type", "point, spot"),
    ("third_light_bad_cone", _append_spot(cone_angle=91), ValueError, "lights[2].cone_angle",
     "must be in [0.001, 90]"),
    ("third_light_zero_direction", _append_spot(direction=[0.0, 0.0, 0.0]), ValueError, "lights[2].direction",
     "must not be zero"),
]


@pytest.mark.parametrize(("mutate", "exc", "field", "text"), [b[1:] for b in BAD_SPOTS],
                         ids=[b[0] for b in BAD_SPOTS])
def test_bad_spot_raises_naming_the_field(mutate, exc, field: str, text: str) -> None:
    scene = copy.deepcopy(SCENE)
    mutate(scene)
    with pytest.raises(exc) as info:
        airlight.load_scene(scene)
    assert type(info.value) is exc, f"expected exactly {exc.__name__}, got {type(info.value).__name__}"
    message = str(info.value)
    assert message.startswith(field + ":"), f"message {message!r} does not start with {field!r}"
    assert text in message


# --- headlights() ----------------------------------------------------------------


def _forward(heading: float) -> np.ndarray:
    h = math.radians(heading)
    return np.array([math.sin(h), 0.0, -math.cos(h)])


def test_headlights_defaults_at_heading_0() -> None:
    lights = airlight.headlights([2.0, 0.0, -10.0], 0.0)
    assert [light["type"] for light in lights] == ["spot", "spot"]
    left, right = lights
    assert left["position"] == pytest.approx([1.3, 0.65, -10.0])
    assert right["position"] == pytest.approx([2.7, 0.65, -10.0])
    pitch = math.radians(-2.0)
    for spot in lights:
        assert set(spot) == SPOT_KEYS
        assert spot["direction"] == pytest.approx([0.0, math.sin(pitch), -math.cos(pitch)])
        assert spot["intensity"] == [20000.0, 19000.0, 17000.0]
        assert spot["cone_angle"] == 25.0
        assert spot["edge"] == 0.15
        assert spot["radius"] == 0.05


@pytest.mark.parametrize("heading", [0.0, 90.0, 180.0, 270.0, -90.0, 37.5, -120.0, 725.0])
@pytest.mark.parametrize("pitch", [-2.0, 0.0, -15.0, 10.0])
def test_headlights_geometry(heading: float, pitch: float) -> None:
    origin = np.array([5.0, 0.2, -30.0])
    lights = airlight.headlights(origin.tolist(), heading, spacing=1.6, height=0.7, pitch=pitch)
    left, right = (np.array(light["position"]) for light in lights)
    forward = _forward(heading)
    across = np.cross(forward, [0.0, 1.0, 0.0])  # to the driver's right
    assert np.linalg.norm(right - left) == pytest.approx(1.6)
    assert (right - left) == pytest.approx(1.6 * across, abs=1e-12)
    assert (left + right) / 2 == pytest.approx(origin + [0.0, 0.7, 0.0])
    for light in lights:
        d = np.array(light["direction"])
        assert np.linalg.norm(d) == pytest.approx(1.0, abs=1e-12)
        assert d[1] == pytest.approx(math.sin(math.radians(pitch)), abs=1e-12)  # tilted by pitch
        assert np.dot(d, forward) == pytest.approx(math.cos(math.radians(pitch)), abs=1e-12)
        assert np.dot(d, across) == pytest.approx(0.0, abs=1e-12)
        assert light["direction"] == lights[0]["direction"]  # both aimed alike


def test_headlights_heading_convention() -> None:
    # 0 = -z, 90 = +x, 180 = +z, 270 = -x; exact on the axes.
    for heading, forward in [(0, [0.0, 0.0, -1.0]), (90, [1.0, 0.0, 0.0]), (180, [0.0, 0.0, 1.0]),
                             (270, [-1.0, 0.0, 0.0])]:
        (spot, _) = airlight.headlights([0, 0, 0], heading, pitch=0.0)
        assert spot["direction"] == forward
    # Pitch negative aims down, positive up.
    assert airlight.headlights([0, 0, 0], 30, pitch=-5)[0]["direction"][1] < 0
    assert airlight.headlights([0, 0, 0], 30, pitch=5)[0]["direction"][1] > 0


def test_headlights_lens_lamps() -> None:
    lights = airlight.headlights([0.0, 0.0, -5.0], 90.0, lens_lamps=True, lens_intensity=[30, 20, 10],
                                 radius=0.07)
    assert [light["type"] for light in lights] == ["spot", "spot", "point", "point"]
    spots, lamps = lights[:2], lights[2:]
    for spot, lamp in zip(spots, lamps):
        assert lamp == {"type": "point", "position": spot["position"], "intensity": [30.0, 20.0, 10.0],
                        "radius": 0.07}
        assert spot["radius"] == 0.07
    lamps = airlight.headlights([0.0, 0.0, -5.0], 90.0, lens_lamps=True)[2:]
    assert [lamp["intensity"] for lamp in lamps] == [[50.0] * 3] * 2
    assert len(airlight.headlights([0.0, 0.0, -5.0], 90.0, lens_lamps=False)) == 2


def test_headlights_options_and_independent_dicts() -> None:
    lights = airlight.headlights(np.array([1.0, 0.0, 2.0]), 45, intensity=1000, cone_angle=90, edge=1.0,
                                 height=0.0)
    assert all(light["intensity"] == [1000.0] * 3 for light in lights)
    assert all(light["cone_angle"] == 90.0 and light["edge"] == 1.0 for light in lights)
    assert all(light["position"][1] == 0.0 for light in lights)
    lights[0]["position"][0] = 99.0
    lights[0]["direction"][0] = 99.0
    assert lights[1]["position"][0] != 99.0 and lights[1]["direction"][0] != 99.0


def test_headlights_load_as_a_scene() -> None:
    lights = airlight.headlights([0.0, 0.0, -6.0], 15.0, lens_lamps=True)
    loaded = airlight.load_scene(_scene(*lights))
    assert [light["type"] for light in loaded["lights"]] == ["point", "point", "spot", "spot"]
    for given, spot in zip(lights[:2], _spots(loaded)):
        assert spot["position"] == pytest.approx(given["position"], rel=1e-6)
        assert spot["direction"] == pytest.approx(given["direction"], rel=1e-6, abs=1e-7)
        assert spot["intensity"] == given["intensity"]
        assert spot["cone_angle"] == 25.0
        assert spot["edge"] == pytest.approx(0.15)


BAD_HEADLIGHTS = [
    ("spacing_zero", {"spacing": 0}, ValueError, "spacing"),
    ("spacing_negative", {"spacing": -1.4}, ValueError, "spacing"),
    ("spacing_nan", {"spacing": NAN}, ValueError, "spacing"),
    ("spacing_bool", {"spacing": True}, TypeError, "spacing"),
    ("height_negative", {"height": -0.1}, ValueError, "height"),
    ("height_inf", {"height": INF}, ValueError, "height"),
    ("height_string", {"height": "low"}, TypeError, "height"),
    ("cone_angle_zero", {"cone_angle": 0}, ValueError, "cone_angle"),
    ("cone_angle_negative", {"cone_angle": -10}, ValueError, "cone_angle"),
    ("cone_angle_above_90", {"cone_angle": 90.5}, ValueError, "cone_angle"),
    ("cone_angle_nan", {"cone_angle": NAN}, ValueError, "cone_angle"),
    ("edge_negative", {"edge": -0.01}, ValueError, "edge"),
    ("edge_above_1", {"edge": 1.5}, ValueError, "edge"),
    ("edge_none", {"edge": None}, TypeError, "edge"),
    ("pitch_nan", {"pitch": NAN}, ValueError, "pitch"),
    ("pitch_beyond_vertical", {"pitch": -95}, ValueError, "pitch"),
    ("intensity_negative", {"intensity": -1}, ValueError, "intensity"),
    ("intensity_channel_negative", {"intensity": [1, -1, 1]}, ValueError, "intensity"),
    ("intensity_two_channels", {"intensity": [1, 1]}, ValueError, "intensity"),
    ("intensity_nan", {"intensity": [1, NAN, 1]}, ValueError, "intensity"),
    ("intensity_string", {"intensity": "bright"}, TypeError, "intensity"),
    ("lens_intensity_negative", {"lens_intensity": -5}, ValueError, "lens_intensity"),
    ("lens_lamps_string", {"lens_lamps": "yes"}, TypeError, "lens_lamps"),
    ("radius_zero", {"radius": 0}, ValueError, "radius"),
    ("radius_below_1_micrometre", {"radius": 9e-7}, ValueError, "radius"),
    ("cone_angle_below_0_001", {"cone_angle": 9e-4}, ValueError, "cone_angle"),
    ("radius_huge", {"radius": 2000}, ValueError, "radius"),
    ("position_short", {"position": [0, 0]}, ValueError, "position"),
    ("position_string", {"position": "here"}, TypeError, "position"),
    ("position_nan", {"position": [0, NAN, 0]}, ValueError, "position"),
    ("position_none", {"position": None}, TypeError, "position"),
    ("heading_string", {"heading": "north"}, TypeError, "heading"),
    ("heading_inf", {"heading": INF}, ValueError, "heading"),
]


@pytest.mark.parametrize(("kwargs", "exc", "name"), [b[1:] for b in BAD_HEADLIGHTS],
                         ids=[b[0] for b in BAD_HEADLIGHTS])
def test_headlights_rejects_bad_arguments_naming_them(kwargs: dict[str, Any], exc, name: str) -> None:
    args: dict[str, Any] = {"position": [0.0, 0.0, 0.0], "heading": 0.0}
    args.update(kwargs)
    position, heading = args.pop("position"), args.pop("heading")
    with pytest.raises(exc) as info:
        airlight.headlights(position, heading, **args)
    assert type(info.value) is exc, f"expected exactly {exc.__name__}, got {type(info.value).__name__}"
    message = str(info.value)
    assert re.match(re.escape(name) + r"(\[\d\])?:", message), f"message {message!r} does not name {name!r}"


def test_headlights_is_exported() -> None:
    assert "headlights" in airlight.__all__
    assert airlight.headlights.__doc__
