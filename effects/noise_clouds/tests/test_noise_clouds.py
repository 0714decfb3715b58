"""Noise clouds (issue 21; effects/noise_clouds/physics.md): the scene keys, the noise
textures, what a scene without clouds pays, both backends agreeing, robustness over
wide parameter ranges and the wind's continuity. The comparisons with the float64
reference are in test_clouds_against_reference.py."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import textwrap
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airlight

SKY_SCENE: dict[str, Any] = {
    "film": {"width": 48, "height": 27},
    "camera": {"position": [0, 2, 0], "look_at": [0, 900, -3000], "up": [0, 1, 0], "fov_y": 70},
    "sky": {"model": "cie", "type": 12, "zenith_radiance": [0.5, 0.75, 1.3]},
    "sun": {"elevation": 30, "azimuth": 20, "irradiance": [12, 11.5, 10.5]},
    "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.2}],
    "clouds": {"base": 1500, "top": 4000, "coverage": 0.6, "extinction": 0.05},
    "quality": {"multiple_scattering": False},
}


def with_clouds(**clouds: Any) -> dict[str, Any]:
    scene = copy.deepcopy(SKY_SCENE)
    scene["clouds"].update(clouds)
    return scene


# ---- Scene keys -------------------------------------------------------------------------------

def test_cloud_keys_are_read_with_defaults_and_written_back():
    scene = airlight.load_scene({**SKY_SCENE, "clouds": {}})
    c = scene["clouds"]
    assert c == {"base": 1500.0, "top": 4000.0, "coverage": 0.5, "type": 0.5, "extinction": 0.05,
                 "albedo": 1.0, "g": pytest.approx(0.2), "second_g": pytest.approx(-0.3),
                 "second_weight": 0.0, "powder": 0.0, "erosion": pytest.approx(0.35),
                 "shape_scale": 8000.0, "detail_scale": 600.0, "wind": [0.0, 0.0], "time": 0.0, "seed": 0}
    q = scene["quality"]
    assert (q["clouds"], q["cloud_steps"], q["cloud_light_steps"]) == ("adaptive", 96, 32)
    assert q["cloud_shadow_steps"] == 16
    given_keys = {"base": 800, "top": 1200, "coverage": 1, "type": 0, "extinction": 0.2, "albedo": 0.9,
                  "g": 0.5, "second_g": -0.4, "second_weight": 0.25, "powder": 0.5, "erosion": 0.1,
                  "shape_scale": 5000, "detail_scale": 300, "wind": [10, -5],
                  "time": 60, "seed": 7}
    again = airlight.load_scene({**SKY_SCENE, "clouds": given_keys,
                                 "quality": {"clouds": "march", "cloud_steps": 200, "cloud_light_steps": 3,
                                             "cloud_shadow_steps": 0}})
    read = dict(again["clouds"])
    assert read.pop("wind") == [10.0, -5.0]
    assert read == pytest.approx({k: v for k, v in given_keys.items() if k != "wind"})
    assert airlight.load_scene(again) == again
    assert airlight.load_scene({**SKY_SCENE, "clouds": None})["clouds"] is None


@pytest.mark.parametrize("clouds, field, error", [
    ({"coverage": 1.5}, "clouds.coverage", ValueError),
    ({"base": 3000, "top": 2000}, "clouds.top", ValueError),
    ({"base": 5000}, "clouds.base", ValueError),
    ({"extinction": -1}, "clouds.extinction", ValueError),
    ({"wind": [1, 2, 3]}, "clouds.wind", TypeError),
    ({"wind": [1, "x"]}, "clouds.wind[1]", TypeError),
    ({"seed": 1.5}, "clouds.seed", ValueError),
    ({"g": 1}, "clouds.g", ValueError),
    ({"second_g": -1}, "clouds.second_g", ValueError),
    ({"second_weight": 1.5}, "clouds.second_weight", ValueError),
    ({"powder": -0.1}, "clouds.powder", ValueError),
    ({"colour": 1}, "clouds.colour", ValueError),
])
def test_bad_cloud_keys_name_the_field(clouds, field, error):
    with pytest.raises(error, match=field.replace("[", r"\[").replace("]", r"\]")):
        airlight.load_scene({**SKY_SCENE, "clouds": clouds})


def test_rain_falls_from_the_cloud_base_unless_given_a_top():
    def rain_top(scene: dict[str, Any]) -> float:
        return airlight.load_scene(scene)["atmosphere"]["rain"]["top"]

    rain = {"atmosphere": {"rain": {"rate": 5}}}
    assert rain_top({**with_clouds(base=900, top=3000), **rain}) == 900
    given_top = {"atmosphere": {"rain": {"rate": 5, "top": 700}}}
    assert rain_top({**with_clouds(base=900, top=3000), **given_top}) == 700
    assert rain_top({**SKY_SCENE, "clouds": None, **rain}) == 1500  # the rain's own default
    with pytest.raises(ValueError, match="atmosphere.rain.top"):
        airlight.load_scene({**with_clouds(base=0, top=3000), **rain})


def test_bad_cloud_quality_names_the_field():
    with pytest.raises(ValueError, match="quality.clouds"):
        airlight.load_scene({**SKY_SCENE, "quality": {"clouds": "fast"}})
    with pytest.raises(ValueError, match="quality.cloud_steps"):
        airlight.load_scene({**SKY_SCENE, "quality": {"cloud_steps": 1}})
    with pytest.raises(ValueError, match="quality.cloud_shadow_steps"):
        airlight.load_scene({**SKY_SCENE, "quality": {"cloud_shadow_steps": -1}})


# ---- The noise textures -----------------------------------------------------------------------

def test_noise_textures_are_deterministic_per_seed_in_range_and_tile_without_seams():
    shape, detail = airlight._core.cloud_noise_textures(3)
    again = airlight._core.cloud_noise_textures(3)
    assert shape.shape == (128, 128, 128, 4) and detail.shape == (32, 32, 32, 4)
    assert np.array_equal(shape, again[0]) and np.array_equal(detail, again[1])
    assert not np.array_equal(shape, airlight._core.cloud_noise_textures(4)[0])
    for tex in (shape, detail):
        assert tex.min() >= 0.0 and tex.max() <= 1.0
        for axis in range(3):
            # Across the tile's edge (texel n-1 to texel 0) the noise changes as between any two
            # neighbours: a seam would show a jump far above the interior's steps.
            seam = np.abs(np.take(tex, [0], axis) - np.take(tex, [-1], axis)).mean()
            inner = np.abs(np.diff(tex, axis=axis)).mean()
            assert seam < 1.5 * inner, (axis, seam, inner)
    # The channels are at rising frequencies: the mean step between neighbours grows.
    steps = [np.abs(np.diff(detail[..., c], axis=2)).mean() for c in range(4)]
    assert steps == sorted(steps)


NO_CLOUD_TABLES = textwrap.dedent("""
    import json, sys, airlight
    airlight.render(json.loads(sys.argv[1]), backend="cpu")
    print(json.dumps(sorted(airlight.table_stats())))
""")


def tables_built_by(scene: dict[str, Any]) -> list[str]:
    out = subprocess.run([sys.executable, "-c", NO_CLOUD_TABLES, json.dumps(scene)], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout)


@pytest.mark.parametrize("clouds", [None, {"coverage": 0}, {"extinction": 0}])
def test_scene_without_visible_clouds_builds_no_noise(clouds):
    scene = {**SKY_SCENE, "clouds": clouds}
    built = tables_built_by(scene)
    assert not any(name.startswith("cloud_") for name in built), built


def test_scene_with_clouds_builds_both_noise_textures():
    built = tables_built_by(SKY_SCENE)
    assert {"cloud_shape", "cloud_detail"} <= set(built)
    assert "cloud_weather" not in built  # no weather map given


# ---- Rendering ---------------------------------------------------------------------------------

def test_clouds_agree_on_both_backends(renderer_cache):
    scene = copy.deepcopy(SKY_SCENE)
    cpu = renderer_cache("cpu").render(scene, outputs=["radiance", "clouds", "transmittance"])
    gl = renderer_cache("gl").render(scene, outputs=["radiance", "clouds", "transmittance"])
    assert cpu["clouds"].max() > 1e-3  # the clouds show
    for name in ("radiance", "clouds", "transmittance"):
        np.testing.assert_allclose(gl[name], cpu[name], rtol=2e-4, atol=1e-6 * float(cpu[name].max()))


def test_zero_coverage_renders_as_no_clouds(renderer):
    without = renderer.render({**SKY_SCENE, "clouds": None})
    assert np.array_equal(renderer.render(with_clouds(coverage=0)), without)


def test_clouds_darken_the_sky_behind_them_and_add_their_light(renderer):
    scene = copy.deepcopy(SKY_SCENE)
    out = renderer.render(scene, outputs=["radiance", "clouds", "transmittance", "sky"])
    clear = renderer.render({**scene, "clouds": None}, outputs=["radiance", "transmittance"])
    t = out["transmittance"]
    assert t.min() < 0.5 and np.all(t <= clear["transmittance"] + 1e-6)
    # Where the view ray misses the layer (the ground) the clouds add nothing and attenuate
    # nothing; the ground is darker only where they shadow the sun.
    below = slice(SKY_SCENE["film"]["height"] * 3 // 4, None)
    assert np.all(out["clouds"][below] == 0.0)
    assert np.array_equal(out["transmittance"][below], clear["transmittance"][below])
    assert np.all(out["radiance"][below] <= clear["radiance"][below] * (1 + 1e-6))


def test_clouds_shadow_the_ground_by_their_transmittance_toward_the_sun(renderer):
    """A grey ground seen straight down: the sun's part of its light is multiplied by the clouds'
    transmittance toward the sun (compared with a scene whose sun is off), so overcast shadows it
    deeply, and no coverage not at all."""
    def ground(coverage: float, sun: bool) -> float:
        scene = with_clouds(coverage=coverage, type=0.0, extinction=0.2)
        scene["camera"] = {"position": [0, 10, 0], "look_at": [0, 0, -0.01], "up": [0, 0, -1], "fov_y": 10}
        scene["film"] = {"width": 4, "height": 4}
        if not sun:
            scene["sun"]["irradiance"] = 0
        return float(renderer.render(scene).mean())
    sky_only = ground(1.0, False)
    assert ground(1.0, True) - sky_only < 1e-3 * (ground(1e-9, True) - ground(1e-9, False))
    clear = with_clouds()
    clear["clouds"] = None
    clear["camera"] = {"position": [0, 10, 0], "look_at": [0, 0, -0.01], "up": [0, 0, -1], "fov_y": 10}
    clear["film"] = {"width": 4, "height": 4}
    assert ground(1e-9, True) == pytest.approx(float(renderer.render(clear).mean()), rel=1e-5)


@pytest.mark.parametrize("medium", ["atmosphere", "fog"])
def test_clouds_shadow_the_air_below_them(renderer, medium):
    """The sunlight the atmosphere (the sky layer) or the fog (medium_sun) scatters under the
    layer is dimmed by the clouds' transmittance toward the sun (physics.md section 9): never
    brighter than without the shadow, much darker under overcast, unchanged by clouds too thin to
    matter and by cloud_shadow_steps 0."""
    layer = "sky" if medium == "atmosphere" else "medium_sun"

    def air(coverage: float, shadow_steps: int) -> np.ndarray:
        scene = with_clouds(coverage=coverage, type=0.0, extinction=0.05)
        if medium == "atmosphere":
            scene["atmosphere"] = {"molecules": {"density_scale": 1}, "aerosol": {"visibility": 20000}}
        else:
            scene["medium"] = {"visibility": 5000}
        scene["camera"] = {"position": [0, 2, 0], "look_at": [0, 300, -3000], "up": [0, 1, 0], "fov_y": 60}
        scene["quality"] = {"multiple_scattering": False, "cloud_shadow_steps": shadow_steps}
        return renderer.render(scene, outputs=[layer])[layer]

    free = air(1.0, 0)
    assert free.max() > 0.0
    overcast = air(1.0, 16)
    assert np.all(overcast <= free * (1 + 1e-5) + 1e-9)
    assert overcast.sum() < 0.7 * free.sum()
    # Cut into pieces, the atmosphere's volumes integrate the same light a little differently
    # (measured: 0.23 % at most); the fog's exact integral only by float32 rounding (3e-5 on GL).
    np.testing.assert_allclose(air(1e-9, 16), air(1e-9, 0), rtol=5e-3 if medium == "atmosphere" else 1e-4,
                               atol=1e-9)


@pytest.mark.parametrize("method", ["adaptive", "march"])
def test_clouds_layer_and_the_others_sum_to_the_radiance(renderer, method):
    from test_render_outputs import assert_layers_sum_to_radiance

    scene = with_clouds()
    scene["atmosphere"] = {"molecules": {"density_scale": 1}, "aerosol": {"visibility": 30000}}
    scene["quality"] = {"multiple_scattering": False, "clouds": method, "march_steps": 64}
    out = renderer.render(scene, outputs=["radiance", "layers"])
    assert out["clouds"].max() > 0.0
    assert_layers_sum_to_radiance(out, f"clouds, {method} ({renderer.backend})")


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_no_nan_inf_or_negative_radiance_over_wide_parameters(renderer_cache, data):
    """Camera below, inside, on the boundary or above the layer, looking anywhere; coverage and
    extinction from 0 to their limits; the sun from below the horizon to the zenith; with and
    without a ground (a sky lighting clouds with no surface once crashed: its table was not built)."""
    draw = data.draw
    base = draw(st.floats(0, 5000))
    top = base + draw(st.sampled_from([1.0, 50.0, 2000.0, 8000.0]))
    y = draw(st.sampled_from([0.5, base, top, 0.5 * (base + top), top + 100, base - 1e-3]))
    look = [draw(st.floats(-1, 1)), draw(st.floats(-1, 1)), draw(st.floats(-1, 1))]
    if np.linalg.norm(look) < 1e-3 or abs(look[1]) > 0.999 * np.linalg.norm(look):
        look = [0.0, 0.1, -1.0]
    # A unit offset: a camera 13 km up cannot aim at a point 2 mm away (float32, a clear scene error).
    look = [float(x) for x in np.asarray(look) / np.linalg.norm(look)]
    scene = with_clouds(base=base, top=top, coverage=draw(st.sampled_from([0.0, 0.3, 1.0])),
                        extinction=draw(st.sampled_from([0.0, 1e-4, 0.05, 1e3])),
                        type=draw(st.floats(0, 1)), g=draw(st.floats(-0.9, 0.9)),
                        wind=[draw(st.floats(-50, 50)), 0.0], time=draw(st.floats(0, 1e5)),
                        second_g=draw(st.floats(-0.9, 0.9)),
                        second_weight=draw(st.sampled_from([0.0, 0.5, 1.0])),
                        powder=draw(st.sampled_from([0.0, 1.0])))
    scene["film"] = {"width": 12, "height": 8}
    scene["camera"] = {"position": [0.0, y, 0.0], "look_at": [look[0], y + look[1], look[2]], "up": [0, 1, 0],
                       "fov_y": 60}
    scene["sun"] = {"elevation": draw(st.sampled_from([-5.0, 0.0, 0.5, 30.0, 90.0])), "azimuth": 20,
                    "irradiance": [12, 11.5, 10.5]}
    if draw(st.booleans()):
        del scene["surfaces"]  # no ground: the sky's light on the clouds needs its table all the same
    if draw(st.booleans()):
        scene["sky"] = {"model": "overcast", "zenith_radiance": 0.4}
    air = draw(st.sampled_from(["none", "atmosphere", "fog"]))  # the air in the clouds' shadow
    if air == "atmosphere":
        scene["atmosphere"] = {"molecules": {"density_scale": 1}, "aerosol": {"visibility": 20000}}
    elif air == "fog":
        scene["medium"] = {"visibility": draw(st.sampled_from([50.0, 3000.0]))}
    scene["quality"]["cloud_shadow_steps"] = draw(st.sampled_from([0, 1, 16]))
    backend = draw(st.sampled_from(["cpu", "gl"]))
    out = renderer_cache(backend).render(scene, outputs=["radiance", "clouds"])
    for name in ("radiance", "clouds"):
        assert np.all(np.isfinite(out[name])), name
        assert out[name].min() >= 0.0, name


def test_wind_moves_the_clouds_continuously(renderer):
    """Frame differences shrink in proportion as the time step shrinks (no jumps)."""
    scene = with_clouds(wind=[15.0, 5.0])
    frames = {dt: renderer.render(with_clouds(wind=[15.0, 5.0], time=100.0 + dt)) for dt in (0.0, 1.0, 4.0)}
    base = renderer.render(scene | {"clouds": {**scene["clouds"], "time": 100.0}})
    assert np.array_equal(base, frames[0.0])
    small = np.abs(frames[1.0] - frames[0.0]).mean()
    large = np.abs(frames[4.0] - frames[0.0]).mean()
    assert 0 < small < large
    assert large / small == pytest.approx(4.0, rel=0.5)


def test_wind_drift_is_the_field_shifted(renderer):
    """The field at time t with wind w is the field at time 0 moved by w t: a camera moved with
    it sees the same clouds (up to float32 rounding of the tile offsets)."""
    shift = [400.0, 0.0, -250.0]
    moved = copy.deepcopy(with_clouds(wind=[4.0, -2.5], time=100.0))
    for key in ("position", "look_at"):
        moved["camera"][key] = [a + b for a, b in zip(moved["camera"][key], shift)]
    still = with_clouds()
    a = renderer.render(still, outputs=["clouds"])["clouds"]
    b = renderer.render(moved, outputs=["clouds"])["clouds"]
    assert np.abs(a - b).max() <= 1e-3 * a.max()


# ---- Weather map (physics.md section 8) ------------------------------------------------------

def write_png(path: Any, values: np.ndarray) -> str:
    """values (rows, cols) or (rows, cols, 3) in [0, 1] as an 8-bit PNG (16-bit for a uint16 array)."""
    from PIL import Image

    if values.dtype == np.uint16:
        Image.fromarray(values).save(path)  # mode I;16: a 16-bit grey PNG
    else:
        Image.fromarray(np.round(255 * values).astype(np.uint8)).save(path)
    return str(path)


def with_map(path: str, **clouds: Any) -> dict[str, Any]:
    return with_clouds(**clouds, weather_map={"image": path, "size": [6000, 5000], "center": [100, -2000]})


def test_weather_map_that_clears_the_sky_builds_no_noise(tmp_path):
    # An all-zero red channel leaves no coverage anywhere: no noise texture, no cloud code (the map
    # itself is read to know it).
    path = write_png(tmp_path / "clear.png", np.zeros((4, 6)))
    built = tables_built_by({**SKY_SCENE, "clouds": {**SKY_SCENE["clouds"], "weather_map": {
        "image": path, "size": [6000, 5000]}}})
    assert not {"cloud_shape", "cloud_detail"} & set(built), built


def test_weather_map_is_read_with_its_keys_and_written_back(tmp_path):
    path = write_png(tmp_path / "map.png", np.full((4, 6, 3), 0.5))
    scene = airlight.load_scene(with_map(path))
    assert scene["clouds"]["weather_map"] == {"image": path, "size": [6000.0, 5000.0],
                                              "center": [100.0, -2000.0]}
    assert airlight.load_scene(scene) == scene
    assert "cloud_weather" in airlight.table_stats()


SIZE = [1000, 1000]


@pytest.mark.parametrize("weather_map, field, error, message", [
    ({"image": "no/such/map.png", "size": SIZE}, "clouds.weather_map.image", ValueError, "no such file"),
    ({"image": 3, "size": SIZE}, "clouds.weather_map.image", TypeError, "file path"),
    ({"image": "README.md", "size": SIZE}, "clouds.weather_map.image", ValueError, ".png or .exr"),
    ({"image": "MAP", "size": [1000]}, "clouds.weather_map.size", TypeError, r"\[x, z\]"),
    ({"image": "MAP", "size": [0, 1000]}, r"clouds.weather_map.size\[0\]", ValueError, ""),
    ({"image": "MAP"}, "clouds.weather_map.size", ValueError, "missing"),
    ({"image": "MAP", "size": SIZE, "centre": [0, 0]}, "clouds.weather_map.centre", ValueError, "center"),
    ({"image": "TINY", "size": SIZE}, "clouds.weather_map.image", ValueError, "2 x 2"),
    ({"image": "OUT_OF_RANGE", "size": SIZE}, "clouds.weather_map.image", ValueError, r"outside \[0, 1\]"),
])
def test_bad_weather_map_names_the_field(tmp_path, weather_map, field, error, message):
    import OpenEXR

    files = {"MAP": write_png(tmp_path / "map.png", np.ones((4, 4))),
             "TINY": write_png(tmp_path / "tiny.png", np.ones((1, 4)))}
    bad = np.ones((4, 4, 3), np.float32)
    bad[2, 1, 0] = 1.5
    files["OUT_OF_RANGE"] = str(tmp_path / "bad.exr")
    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                 {"RGB": bad}).write(files["OUT_OF_RANGE"])
    weather_map = {**weather_map, "image": files.get(weather_map["image"], weather_map["image"])}
    with pytest.raises(error, match=f"{field}.*{message}"):
        airlight.load_scene(with_clouds(weather_map=weather_map))


def test_uniform_weather_map_renders_as_its_values(renderer, tmp_path):
    """A map of one colour is the layer's coverage scaled by R and the type G; a grey map keeps
    the layer's type; 8-bit codes are code / 255 and 16-bit ones code / 65535 (data, no sRGB)."""
    def clouds(scene: dict[str, Any]) -> np.ndarray:
        return renderer.render(scene, outputs=["clouds"])["clouds"]

    colour = write_png(tmp_path / "colour.png", np.full((8, 8, 3), [153 / 255, 51 / 255, 0.0]))
    keyed = clouds(with_clouds(coverage=1.0 * 153 / 255, type=51 / 255))
    assert keyed.max() > 1e-3
    np.testing.assert_allclose(clouds(with_map(colour, coverage=1.0)), keyed, rtol=1e-4,
                               atol=1e-6 * keyed.max())
    grey16 = write_png(tmp_path / "grey16.png", np.full((8, 8), 39321, np.uint16))  # 0.6
    keyed = clouds(with_clouds(coverage=0.5 * 0.6, type=0.8))
    np.testing.assert_allclose(clouds(with_map(grey16, coverage=0.5, type=0.8)), keyed, rtol=1e-4,
                               atol=1e-6 * keyed.max())
    empty = write_png(tmp_path / "empty.png", np.zeros((8, 8, 3)))
    assert not clouds(with_map(empty, coverage=1.0)).any()


def test_weather_map_drifts_with_the_wind(renderer, tmp_path):
    """The map moves with the noise: a camera moved by wind x time sees the same clouds."""
    rng = np.random.default_rng(3)
    path = write_png(tmp_path / "patchy.png", rng.uniform(0, 1, (6, 6, 3)))
    shift = [400.0, 0.0, -250.0]
    moved = with_map(path, wind=[4.0, -2.5], time=100.0)
    for key in ("position", "look_at"):
        moved["camera"][key] = [a + b for a, b in zip(moved["camera"][key], shift)]
    a = renderer.render(with_map(path), outputs=["clouds"])["clouds"]
    b = renderer.render(moved, outputs=["clouds"])["clouds"]
    assert a.max() > 1e-3
    assert np.abs(a - b).max() <= 1e-3 * a.max()
