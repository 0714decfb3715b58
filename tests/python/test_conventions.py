"""Image and camera conventions: orientation, field of view, aspect, array layout,
film overrides, media, lights, background and lamp cores."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import airlight


def _camera(fov_y: float = 60.0) -> dict[str, Any]:
    return {"position": [0.0, 0.0, 0.0], "look_at": [0.0, 0.0, -1.0], "up": [0.0, 1.0, 0.0], "fov_y": fov_y}


def _lamp(position, radius=0.1, intensity=10.0) -> dict[str, Any]:
    return {"type": "point", "position": list(position), "intensity": intensity, "radius": radius}


def _lamp_scene(lamps, width=80, height=60, fov_y=60.0, medium=None) -> dict[str, Any]:
    """Only lamps (self-luminous spheres) in front of a black background."""
    scene = {"film": {"width": width, "height": height}, "camera": _camera(fov_y), "lights": lamps}
    if medium is not None:
        scene["medium"] = medium
    return scene


def _lit_pixels(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    rows, cols = np.nonzero(img.max(axis=2) > 0)
    assert len(rows) > 0, "nothing visible"
    return rows, cols


def test_row_zero_is_the_top_of_the_image(renderer: airlight.Renderer) -> None:
    img = renderer.render(_lamp_scene([_lamp((0.0, 2.0, -10.0), radius=1.0)]))
    rows, _ = _lit_pixels(img)
    assert rows.max() < img.shape[0] // 2, "a lamp above the view axis must appear in the top half"


def test_positive_x_is_on_the_right_looking_down_negative_z(renderer: airlight.Renderer) -> None:
    img = renderer.render(_lamp_scene([_lamp((2.0, 0.0, -10.0), radius=1.0)]))
    _, cols = _lit_pixels(img)
    assert cols.min() >= img.shape[1] // 2, "right-handed, y up: +x must appear in the right half"


def test_rolled_up_vector_rotates_the_image(renderer: airlight.Renderer) -> None:
    scene = _lamp_scene([_lamp((0.0, 2.0, -10.0), radius=1.0)])
    scene["camera"]["up"] = [-1.0, 0.0, 0.0]  # the camera's up now points along -x
    img = renderer.render(scene)
    _, cols = _lit_pixels(img)
    # +y is now to the camera's right.
    assert cols.min() >= img.shape[1] // 2


@pytest.mark.parametrize("fov_y", [30.0, 60.0, 100.0])
def test_fov_y_is_the_full_vertical_angle_so_edge_directions_land_on_edge_rows(
        renderer: airlight.Renderer, fov_y: float) -> None:
    width, height, distance = 81, 40, 20.0
    half = math.radians(fov_y) / 2.0
    edge = distance * math.tan(half)
    # The width of one edge pixel, in metres, across the lamp's line of sight: the
    # lamp is distance / cos(half) away and a pixel there spans an angle of
    # tan(half) cos(half)^2 * 2 / height.
    pixel = distance * math.cos(half) * (2.0 * math.tan(half) / height)
    # Lamps smaller than a pixel are box-filtered around their centre: 0.3 pixel keeps each in one pixel.
    lamps = [_lamp((0.0, y, -distance), radius=0.3 * pixel) for y in (edge, -edge)]
    img = renderer.render(_lamp_scene(lamps, width, height, fov_y))
    rows, cols = _lit_pixels(img)
    assert set(rows.tolist()) == {0, height - 1}, f"lamps on the edge directions lit rows {sorted(set(rows))}"
    assert set(cols.tolist()) == {width // 2}


def test_aspect_ratio_comes_from_the_film_so_horizontal_edges_land_on_edge_columns(
        renderer: airlight.Renderer) -> None:
    width, height, fov_y, distance = 120, 41, 40.0, 20.0
    half_x = math.atan(math.tan(math.radians(fov_y) / 2.0) * width / height)
    edge = distance * math.tan(half_x)
    pixel = distance * math.cos(half_x) * (2.0 * math.tan(half_x) / width)
    lamps = [_lamp((x, 0.0, -distance), radius=0.3 * pixel) for x in (edge, -edge)]
    img = renderer.render(_lamp_scene(lamps, width, height, fov_y))
    rows, cols = _lit_pixels(img)
    assert set(cols.tolist()) == {0, width - 1}
    assert set(rows.tolist()) == {height // 2}


def test_square_pixels_a_sphere_is_as_wide_as_it_is_tall(renderer: airlight.Renderer) -> None:
    for width, height in [(61, 61), (121, 61), (61, 121)]:
        img = renderer.render(_lamp_scene([_lamp((0.0, 0.0, -10.0), radius=1.5)], width, height, fov_y=40.0))
        lit = img.max(axis=2) > 0
        tall = int(lit[:, width // 2].sum())
        wide = int(lit[height // 2, :].sum())
        assert tall > 5
        assert abs(tall - wide) <= 1, f"{width}x{height}: lamp {wide} px wide, {tall} px tall"


def test_image_is_float32_height_width_3_c_contiguous(renderer: airlight.Renderer, scene_factory) -> None:
    scene = scene_factory(film={"width": 37, "height": 23})
    img = renderer.render(scene)
    assert isinstance(img, np.ndarray)
    assert img.dtype == np.float32
    assert img.shape == (23, 37, 3)
    assert img.flags["C_CONTIGUOUS"]


def test_module_level_render_returns_the_same_layout(backend: str, scene_factory) -> None:
    img = airlight.render(scene_factory(film={"width": 20, "height": 10}), backend=backend)
    assert img.dtype == np.float32 and img.shape == (10, 20, 3) and img.flags["C_CONTIGUOUS"]


def test_width_and_height_arguments_override_the_film(renderer: airlight.Renderer, scene_factory) -> None:
    scene = scene_factory()
    overridden = renderer.render(scene, width=40, height=30)
    explicit = renderer.render(scene_factory(film={"width": 40, "height": 30}))
    assert overridden.shape == (30, 40, 3)
    np.testing.assert_array_equal(overridden, explicit)
    assert scene["film"] == {"width": 160, "height": 120}, "the caller's scene must not be modified"


@pytest.mark.parametrize(("film", "width", "height", "shape"), [
    ((160, 120), 24, None, (18, 24)),      # one side alone keeps the aspect ratio (issue 17)
    ((160, 120), None, 18, (18, 24)),
    ((320, 240), 160, None, (120, 160)),
    ((320, 240), None, 7, (7, 9)),         # 9.33 -> 9
    ((320, 240), 10, None, (8, 10)),       # 7.5 -> 8: halves round up
    ((320, 240), 1, None, (1, 1)),         # 0.75 -> 1
    ((1000, 10), 50, None, (1, 50)),       # 0.5 -> 1, never 0
    ((10, 1000), None, 30, (30, 1)),       # 0.3 -> at least 1
])
def test_width_or_height_alone_keeps_the_film_aspect_ratio(scene_factory, film, width, height,
                                                          shape) -> None:
    scene = scene_factory(film={"width": film[0], "height": film[1]})
    assert airlight.render(scene, backend="cpu", width=width, height=height).shape == (*shape, 3)
    assert scene["film"] == {"width": film[0], "height": film[1]}, "the caller's scene must not be modified"


def test_film_override_applies_to_json_text_and_files(
        renderer: airlight.Renderer, scene_factory, tmp_path) -> None:
    import json

    text = json.dumps(scene_factory())
    path = tmp_path / "scene.json"
    path.write_text(text)
    expected = renderer.render(scene_factory(), width=16, height=12)
    np.testing.assert_array_equal(renderer.render(text, width=16, height=12), expected)
    np.testing.assert_array_equal(renderer.render(str(path), width=16, height=12), expected)
    np.testing.assert_array_equal(renderer.render(path, width=16, height=12), expected)


def test_no_medium_renders_exactly_like_zero_extinction(renderer: airlight.Renderer, scene_factory) -> None:
    zero = renderer.render(scene_factory(medium={"sigma_t": 0.0}, background=[0.1, 0.2, 0.3]))
    absent = renderer.render(scene_factory(drop=["medium"], background=[0.1, 0.2, 0.3]))
    null = renderer.render(scene_factory(medium=None, background=[0.1, 0.2, 0.3]))
    np.testing.assert_array_equal(zero, absent)
    np.testing.assert_array_equal(null, absent)
    assert (absent > 0).mean() > 0.9


def test_no_lights_leaves_surfaces_black(renderer: airlight.Renderer, scene_factory) -> None:
    img = renderer.render(scene_factory(lights=[], background=[0.0, 0.0, 0.0]))
    assert not img.any()
    img = renderer.render(scene_factory(drop=["lights"], medium=None, background=[1.0, 1.0, 1.0]))
    # Sky pixels show the background, ground and objects stay black.
    assert not img[-1].any(), "the bottom row sees the unlit ground plane"
    assert (img[0] == 1.0).all(), "the top row sees the sky"


def test_background_is_seen_without_medium_and_extinguished_per_channel_with_one(
        renderer: airlight.Renderer) -> None:
    scene = {"film": {"width": 16, "height": 12}, "camera": _camera(), "background": [0.25, 0.5, 2.0]}
    img = renderer.render(scene)
    np.testing.assert_array_equal(img, np.broadcast_to(np.float32([0.25, 0.5, 2.0]), img.shape))
    scene["medium"] = {"sigma_t": [0.1, 0.0, 1e-4]}
    img = renderer.render(scene)
    # An escaping ray travels an infinite distance: 0 where sigma_t > 0.
    np.testing.assert_array_equal(img[..., 0], 0.0)
    np.testing.assert_array_equal(img[..., 1], 0.5)
    np.testing.assert_array_equal(img[..., 2], 0.0)


@pytest.mark.parametrize("sigma_t", [0.0, [0.01, 0.05, 0.2]])
def test_lamp_core_radiance_is_intensity_over_pi_r_squared_attenuated(
        renderer: airlight.Renderer, sigma_t) -> None:
    distance, radius = 10.0, 0.5
    intensity = np.array([100.0, 50.0, 20.0])
    scene = _lamp_scene([{"type": "point", "position": [0.0, 0.0, -distance], "intensity": intensity.tolist(),
                          "radius": radius}], width=41, height=41, fov_y=10.0,
                        medium={"sigma_t": sigma_t, "albedo": 0.0})  # no airlight: the core alone
    img = renderer.render(scene)
    centre = img[20, 20].astype(np.float64)
    expected = intensity / (math.pi * radius**2) * np.exp(-np.asarray(sigma_t) * (distance - radius))
    np.testing.assert_allclose(centre, expected, rtol=1e-5)


def test_lamp_core_hides_surfaces_behind_it_but_not_in_front(renderer: airlight.Renderer) -> None:
    lamp = {"type": "point", "position": [0.0, 0.0, -10.0], "intensity": 10.0, "radius": 0.5}
    core = 10.0 / (math.pi * 0.25)
    wall_behind = {"type": "plane", "point": [0, 0, -12], "normal": [0, 0, 1], "albedo": 1.0}
    wall_front = {"type": "plane", "point": [0, 0, -8], "normal": [0, 0, 1], "albedo": 1.0}
    base = {"film": {"width": 21, "height": 21}, "camera": _camera(10.0), "lights": [lamp]}
    img = renderer.render({**base, "surfaces": [wall_behind]})
    assert img[10, 10, 0] == pytest.approx(core, rel=1e-5)
    img = renderer.render({**base, "surfaces": [wall_front]})
    # The front wall is lit from behind (the lamp is on its far side): black.
    assert img[10, 10, 0] == 0.0


def test_planes_are_two_sided(renderer: airlight.Renderer) -> None:
    plane = {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.5}
    camera = {"position": [0, -2, 0], "look_at": [0, 0, -5], "up": [0, 1, 0], "fov_y": 40}
    base = {"film": {"width": 16, "height": 12}, "camera": camera, "surfaces": [plane]}
    below = renderer.render({**base, "lights": [_lamp((0, -3, -5), intensity=50.0)]})
    assert (below[0] > 0).all(), "a plane seen from below is lit by a lamp below it"
    above = renderer.render({**base, "lights": [_lamp((0, 3, -5), intensity=50.0)]})
    assert not above[0].any(), "a lamp on the plane's far side does not light the side seen"
