"""Scene validation through the Python API: every bad input raises TypeError (wrong
JSON type) or ValueError (bad value) naming the offending field, and nothing else
ever escapes; random valid scenes render to finite, non-negative radiance."""

from __future__ import annotations

import copy
import math
import re
from typing import Any, Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scene_edit import delete_at, set_at

import airlight

VALID: dict[str, Any] = {
    "film": {"width": 24, "height": 16},
    "camera": {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.7, -10.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 60.0},
    "medium": {"sigma_t": 0.05, "albedo": 1.0, "phase": {"type": "isotropic"}},
    "lights": [
        {"type": "point", "position": [3.0, 5.0, -20.0], "intensity": [100.0, 90.0, 70.0], "radius": 0.1},
    ],
    "surfaces": [
        {"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "albedo": [0.3, 0.3, 0.3]},
        {"type": "box", "min": [-8.0, 0.0, -40.0], "max": [-4.0, 12.0, -25.0], "albedo": 0.5},
        {"type": "sphere", "center": [1.0, 1.0, -15.0], "radius": 1.0, "albedo": [0.7, 0.2, 0.2]},
    ],
    "background": [0.0, 0.0, 0.0],
}


_set = set_at
_delete = delete_at


def _rename(path: str, new_key: str) -> Callable[[dict], None]:
    keys = [int(k) if k.isdigit() else k for k in re.findall(r"[^.\[\]]+", path)]

    def mutate(scene: dict) -> None:
        node = scene
        for k in keys[:-1]:
            node = node[k]
        node[new_key] = node.pop(keys[-1])

    return mutate


NAN, INF = float("nan"), float("inf")
_MISSING = object()


def _hg2(**changes: Any) -> Callable[[dict], None]:
    """Mutation setting medium.phase to a valid hg2 phase with `changes` (_MISSING: key removed)."""
    phase: dict[str, Any] = {"type": "hg2", "forward_g": 0.9, "backward_g": -0.3, "forward_weight": 0.85}
    phase.update(changes)
    return _set("medium.phase", {k: v for k, v in phase.items() if v is not _MISSING})


# (id, mutation, exception type, field the message must start with)
BAD_SCENES = [
    ("missing_camera", _delete("camera"), ValueError, "camera"),
    ("missing_film", _delete("film"), ValueError, "film"),
    ("missing_fov_y", _delete("camera.fov_y"), ValueError, "camera.fov_y"),
    ("missing_sigma_t", _delete("medium.sigma_t"), ValueError, "medium.sigma_t"),
    ("missing_light_intensity", _delete("lights[0].intensity"), ValueError, "lights[0].intensity"),
    ("missing_light_type", _delete("lights[0].type"), ValueError, "lights[0].type"),
    ("missing_sphere_radius", _delete("surfaces[2].radius"), ValueError, "surfaces[2].radius"),
    ("misspelt_camera", _rename("camera", "camra"), ValueError, "camra"),
    ("misspelt_sigma_t", _rename("medium.sigma_t", "sigmat"), ValueError, "medium.sigmat"),
    ("misspelt_box_max", _rename("surfaces[1].max", "maxx"), ValueError, "surfaces[1].maxx"),
    ("key_of_other_surface_type", _set("surfaces[2].normal", [0, 1, 0]), ValueError, "surfaces[2].normal"),
    ("string_for_number", _set("camera.fov_y", "60"), TypeError, "camera.fov_y"),
    ("bool_for_number", _set("camera.fov_y", True), TypeError, "camera.fov_y"),
    ("bool_for_width", _set("film.width", False), TypeError, "film.width"),
    ("none_for_number", _set("lights[0].radius", None), TypeError, "lights[0].radius"),
    ("string_in_vector", _set("camera.position", [0, "1", 0]), TypeError, "camera.position"),
    ("dict_for_list", _set("lights", {"type": "point"}), TypeError, "lights"),
    ("dict_for_vector", _set("surfaces[0].point", {"x": 0}), TypeError, "surfaces[0].point"),
    ("list_for_object", _set("film", [24, 16]), TypeError, "film"),
    ("number_for_surface", _set("surfaces[1]", 3), TypeError, "surfaces[1]"),
    ("number_for_type_name", _set("surfaces[0].type", 0), TypeError, "surfaces[0].type"),
    ("two_element_vector", _set("camera.look_at", [0, 1]), ValueError, "camera.look_at"),
    ("four_element_rgb", _set("background", [0, 0, 0, 0]), ValueError, "background"),
    ("negative_sigma_t", _set("medium.sigma_t", -0.1), ValueError, "medium.sigma_t"),
    ("negative_sigma_t_channel", _set("medium.sigma_t", [0.1, -0.1, 0.1]), ValueError, "medium.sigma_t"),
    ("nan_sigma_t", _set("medium.sigma_t", NAN), ValueError, "medium.sigma_t"),
    ("inf_sigma_t", _set("medium.sigma_t", INF), ValueError, "medium.sigma_t"),
    ("nan_intensity_channel", _set("lights[0].intensity", [1, NAN, 1]), ValueError, "lights[0].intensity"),
    ("negative_intensity", _set("lights[0].intensity", -5), ValueError, "lights[0].intensity"),
    ("nan_position", _set("camera.position", [0, NAN, 0]), ValueError, "camera.position"),
    ("inf_position", _set("lights[0].position", [INF, 0, 0]), ValueError, "lights[0].position"),
    ("negative_background", _set("background", -1), ValueError, "background"),
    ("surface_albedo_above_1", _set("surfaces[2].albedo", 1.5), ValueError, "surfaces[2].albedo"),
    ("surface_albedo_channel_above_1", _set("surfaces[0].albedo", [0.3, 1.01, 0.3]), ValueError,
     "surfaces[0].albedo"),
    ("medium_albedo_above_1", _set("medium.albedo", 2.0), ValueError, "medium.albedo"),
    ("negative_albedo", _set("surfaces[1].albedo", -0.5), ValueError, "surfaces[1].albedo"),
    ("zero_width", _set("film.width", 0), ValueError, "film.width"),
    ("zero_height", _set("film.height", 0), ValueError, "film.height"),
    ("width_too_large", _set("film.width", 16385), ValueError, "film.width"),
    ("height_too_large", _set("film.height", 100000), ValueError, "film.height"),
    ("fractional_width", _set("film.width", 24.5), ValueError, "film.width"),
    ("look_at_equals_position", _set("camera.look_at", [0.0, 1.7, 0.0]), ValueError, "camera.look_at"),
    ("up_parallel_to_view", _set("camera.up", [0.0, 0.0, -1.0]), ValueError, "camera.up"),
    ("up_antiparallel_to_view", _set("camera.up", [0.0, 0.0, 5.0]), ValueError, "camera.up"),
    ("zero_up", _set("camera.up", [0.0, 0.0, 0.0]), ValueError, "camera.up"),
    ("fov_y_zero", _set("camera.fov_y", 0), ValueError, "camera.fov_y"),
    ("fov_y_180", _set("camera.fov_y", 180), ValueError, "camera.fov_y"),
    ("fov_y_negative", _set("camera.fov_y", -5), ValueError, "camera.fov_y"),
    ("fov_y_nan", _set("camera.fov_y", NAN), ValueError, "camera.fov_y"),
    ("zero_plane_normal", _set("surfaces[0].normal", [0, 0, 0]), ValueError, "surfaces[0].normal"),
    ("unknown_light_type", _set("lights[0].type", "area"), ValueError, "lights[0].type"),
    ("unknown_surface_type", _set("surfaces[1].type", "cylinder"), ValueError, "surfaces[1].type"),
    ("unknown_phase_type", _set("medium.phase.type", "mie"), ValueError, "medium.phase.type"),
    # medium.phase (issue 5): hg {g}, rayleigh, hg2 {forward_g, backward_g, forward_weight}
    ("phase_not_an_object", _set("medium.phase", "hg"), TypeError, "medium.phase"),
    ("phase_list", _set("medium.phase", [{"type": "hg", "g": 0.5}]), TypeError, "medium.phase"),
    ("phase_missing_type", _set("medium.phase", {"g": 0.5}), ValueError, "medium.phase.type"),
    ("phase_type_not_a_string", _set("medium.phase", {"type": 1}), TypeError, "medium.phase.type"),
    ("hg_missing_g", _set("medium.phase", {"type": "hg"}), ValueError, "medium.phase.g"),
    ("hg_g_1", _set("medium.phase", {"type": "hg", "g": 1}), ValueError, "medium.phase.g"),
    ("hg_g_minus_1", _set("medium.phase", {"type": "hg", "g": -1.0}), ValueError, "medium.phase.g"),
    ("hg_g_above_1", _set("medium.phase", {"type": "hg", "g": 1.5}), ValueError, "medium.phase.g"),
    ("hg_g_nan", _set("medium.phase", {"type": "hg", "g": NAN}), ValueError, "medium.phase.g"),
    ("hg_g_inf", _set("medium.phase", {"type": "hg", "g": -INF}), ValueError, "medium.phase.g"),
    ("hg_g_string", _set("medium.phase", {"type": "hg", "g": "0.5"}), TypeError, "medium.phase.g"),
    ("hg_g_bool", _set("medium.phase", {"type": "hg", "g": True}), TypeError, "medium.phase.g"),
    ("hg_g_null", _set("medium.phase", {"type": "hg", "g": None}), TypeError, "medium.phase.g"),
    ("hg_g_list", _set("medium.phase", {"type": "hg", "g": [0.5, 0.5, 0.5]}), TypeError, "medium.phase.g"),
    ("hg_misspelt_g", _set("medium.phase", {"type": "hg", "G": 0.5}), ValueError, "medium.phase.G"),
    ("hg_key_of_hg2", _set("medium.phase", {"type": "hg", "g": 0.5, "forward_weight": 1.0}), ValueError,
     "medium.phase.forward_weight"),
    ("isotropic_with_g", _set("medium.phase", {"type": "isotropic", "g": 0.5}), ValueError, "medium.phase.g"),
    ("rayleigh_with_g", _set("medium.phase", {"type": "rayleigh", "g": 0.0}), ValueError, "medium.phase.g"),
    ("hg2_with_g", _hg2(g=0.5), ValueError, "medium.phase.g"),
    ("hg2_missing_forward_g", _hg2(forward_g=_MISSING), ValueError, "medium.phase.forward_g"),
    ("hg2_missing_backward_g", _hg2(backward_g=_MISSING), ValueError, "medium.phase.backward_g"),
    ("hg2_missing_weight", _hg2(forward_weight=_MISSING), ValueError, "medium.phase.forward_weight"),
    ("hg2_forward_g_1", _hg2(forward_g=1.0), ValueError, "medium.phase.forward_g"),
    ("hg2_forward_g_string", _hg2(forward_g="0.9"), TypeError, "medium.phase.forward_g"),
    ("hg2_backward_g_minus_1", _hg2(backward_g=-1), ValueError, "medium.phase.backward_g"),
    ("hg2_backward_g_nan", _hg2(backward_g=NAN), ValueError, "medium.phase.backward_g"),
    ("hg2_weight_above_1", _hg2(forward_weight=1.5), ValueError, "medium.phase.forward_weight"),
    ("hg2_weight_negative", _hg2(forward_weight=-0.1), ValueError, "medium.phase.forward_weight"),
    ("hg2_weight_nan", _hg2(forward_weight=NAN), ValueError, "medium.phase.forward_weight"),
    ("hg2_weight_inf", _hg2(forward_weight=INF), ValueError, "medium.phase.forward_weight"),
    ("hg2_weight_string", _hg2(forward_weight="0.5"), TypeError, "medium.phase.forward_weight"),
    ("hg2_weight_bool", _hg2(forward_weight=True), TypeError, "medium.phase.forward_weight"),
    ("hg2_unknown_key", _hg2(third_g=0.1), ValueError, "medium.phase.third_g"),
    ("box_min_equals_max", _set("surfaces[1].max", [-8.0, 12.0, -25.0]), ValueError, "surfaces[1].max"),
    ("box_min_above_max", _set("surfaces[1].min", [-3.0, 0.0, -40.0]), ValueError, "surfaces[1].max"),
    ("zero_sphere_radius", _set("surfaces[2].radius", 0), ValueError, "surfaces[2].radius"),
    ("negative_light_radius", _set("lights[0].radius", -0.1), ValueError, "lights[0].radius"),
    ("absurd_coordinate", _set("surfaces[2].center", [1e8, 0, 0]), ValueError, "surfaces[2].center"),
    ("unknown_top_level_key", _set("fog", 1), ValueError, "fog"),
    ("non_string_dict_key", _set("camera", {1: 2}), TypeError, "camera"),
    ("unsupported_python_type", _set("camera.position", {0, 1, 2}), TypeError, "camera.position"),
    ("march_steps_zero", _set("quality", {"march_steps": 0}), ValueError, "quality.march_steps"),
    ("cull_fraction_too_big", _set("quality", {"cull_fraction": 0.5}), ValueError, "quality.cull_fraction"),
    ("spot_glow_samples_not_multiple_of_4", _set("quality", {"spot_glow_samples": 10}), ValueError,
     "quality.spot_glow_samples"),
    ("spot_glow_samples_too_many", _set("quality", {"spot_glow_samples": 68}), ValueError,
     "quality.spot_glow_samples"),
    ("spot_glow_samples_float", _set("quality", {"spot_glow_samples": 8.5}), ValueError,
     "quality.spot_glow_samples"),
    # Daytime (issue 6)
    ("unknown_sky_model", _set("sky", {"model": "sunny", "zenith_radiance": 1}), ValueError, "sky.model"),
    ("unknown_sky_type", _set("sky", {"model": "cie", "type": 16, "zenith_radiance": 1}), ValueError,
     "sky.type"),
    ("sky_type_string", _set("sky", {"model": "cie", "type": "clear", "zenith_radiance": 1}), TypeError,
     "sky.type"),
    ("sky_type_needs_sun", _set("sky", {"model": "cie", "type": 13, "zenith_radiance": 1}), ValueError,
     "sky.type"),
    ("negative_zenith_radiance", _set("sky", {"model": "overcast", "zenith_radiance": [1, -1, 1]}),
     ValueError, "sky.zenith_radiance"),
    ("sun_zero_direction", _set("sun", {"direction": [0, 0, 0]}), ValueError, "sun.direction"),
    ("sun_elevation_out_of_range", _set("sun", {"elevation": -91, "azimuth": 0}), ValueError,
     "sun.elevation"),
    ("sun_negative_irradiance", _set("sun", {"elevation": 30, "azimuth": 0, "irradiance": -1}), ValueError,
     "sun.irradiance"),
    ("negative_rain_rate", _set("atmosphere", {"rain": {"rate": -2}}), ValueError, "atmosphere.rain.rate"),
    ("nan_rain_rate", _set("atmosphere", {"rain": {"rate": NAN}}), ValueError, "atmosphere.rain.rate"),
    ("negative_visibility", _set("atmosphere", {"aerosol": {"visibility": -100}}), ValueError,
     "atmosphere.aerosol.visibility"),
    ("zero_visibility", _set("atmosphere", {"aerosol": {"visibility": 0}}), ValueError,
     "atmosphere.aerosol.visibility"),
    ("aerosol_g_out_of_range", _set("atmosphere", {"aerosol": {"visibility": 100, "g": 1.5}}), ValueError,
     "atmosphere.aerosol.g"),
    ("negative_molecule_density", _set("atmosphere", {"molecules": {"density_scale": -1}}), ValueError,
     "atmosphere.molecules.density_scale"),
    ("misspelt_species", _set("atmosphere", {"rian": {"rate": 2}}), ValueError, "atmosphere.rian"),
    ("sky_segments_too_few", _set("quality", {"sky_segments": 1}), ValueError, "quality.sky_segments"),
    ("sky_segments_too_many", _set("quality", {"sky_segments": 65}), ValueError, "quality.sky_segments"),
    ("sky_segments_float", _set("quality", {"sky_segments": 8.5}), ValueError, "quality.sky_segments"),
    ("multiple_scattering_not_bool", _set("quality", {"multiple_scattering": 1}), TypeError,
     "quality.multiple_scattering"),
    ("sky_not_object", _set("sky", "blue"), TypeError, "sky"),
    ("sky_type_on_overcast", _set("sky", {"model": "overcast", "type": 1, "zenith_radiance": 1}), ValueError,
     "sky.type"),
    ("sky_type_missing", _set("sky", {"model": "cie", "zenith_radiance": 1}), ValueError, "sky.type"),
    ("sky_type_fraction", _set("sky", {"model": "cie", "type": 1.5, "zenith_radiance": 1}), ValueError,
     "sky.type"),
    ("sky_zenith_radiance_missing", _set("sky", {"model": "overcast"}), ValueError, "sky.zenith_radiance"),
    ("sky_zenith_radiance_inf", _set("sky", {"model": "overcast", "zenith_radiance": INF}), ValueError,
     "sky.zenith_radiance"),
    ("sun_empty", _set("sun", {}), ValueError, "sun.elevation"),
    ("sun_azimuth_missing", _set("sun", {"elevation": 20}), ValueError, "sun.azimuth"),
    ("sun_azimuth_nan", _set("sun", {"elevation": 20, "azimuth": NAN}), ValueError, "sun.azimuth"),
    ("sun_direction_and_angles", _set("sun", {"direction": [0, 1, 0], "elevation": 20, "azimuth": 0}),
     ValueError, "sun.direction"),
    ("misspelt_sun_key", _set("sun", {"elevation": 20, "azimuth": 0, "irradience": 1}), ValueError,
     "sun.irradience"),
    ("atmosphere_not_object", _set("atmosphere", [1]), TypeError, "atmosphere"),
    ("molecules_not_object", _set("atmosphere", {"molecules": 1}), TypeError, "atmosphere.molecules"),
    ("huge_molecule_density", _set("atmosphere", {"molecules": {"density_scale": 1e7}}), ValueError,
     "atmosphere.molecules.density_scale"),
    ("aerosol_without_amount", _set("atmosphere", {"aerosol": {"g": 0.5}}), ValueError,
     "atmosphere.aerosol.visibility"),
    ("aerosol_both_amounts", _set("atmosphere", {"aerosol": {"visibility": 100, "coefficient": 0.01}}),
     ValueError, "atmosphere.aerosol.coefficient"),
    ("huge_visibility", _set("atmosphere", {"aerosol": {"visibility": 1e10}}), ValueError,
     "atmosphere.aerosol.visibility"),
    ("negative_aerosol_coefficient", _set("atmosphere", {"aerosol": {"coefficient": -1e-3}}), ValueError,
     "atmosphere.aerosol.coefficient"),
    ("zero_scale_height", _set("atmosphere", {"aerosol": {"visibility": 100, "scale_height": 0}}), ValueError,
     "atmosphere.aerosol.scale_height"),
    ("aerosol_albedo_above_one", _set("atmosphere", {"aerosol": {"visibility": 100, "albedo": 1.5}}),
     ValueError, "atmosphere.aerosol.albedo"),
    ("rain_rate_missing", _set("atmosphere", {"rain": {"top": 1000}}), ValueError, "atmosphere.rain.rate"),
    ("huge_rain_rate", _set("atmosphere", {"rain": {"rate": 1e4}}), ValueError, "atmosphere.rain.rate"),
    ("rain_rate_string", _set("atmosphere", {"rain": {"rate": "heavy"}}), TypeError, "atmosphere.rain.rate"),
    ("negative_rain_density", _set("atmosphere", {"rain": {"rate": 1, "density_scale": -1}}), ValueError,
     "atmosphere.rain.density_scale"),
    ("zero_rain_top", _set("atmosphere", {"rain": {"rate": 1, "top": 0}}), ValueError, "atmosphere.rain.top"),
    ("rain_g_minus_one", _set("atmosphere", {"rain": {"rate": 1, "g": -1}}), ValueError, "atmosphere.rain.g"),
    ("rain_phase_unknown", _set("atmosphere", {"rain": {"rate": 1, "phase": "geometric"}}), ValueError,
     "atmosphere.rain.phase"),
    ("rain_phase_number", _set("atmosphere", {"rain": {"rate": 1, "phase": 0.87}}), TypeError,
     "atmosphere.rain.phase"),
    ("rainbow_wavelengths_four", _set("quality", {"rainbow_wavelengths": 4}), ValueError,
     "quality.rainbow_wavelengths"),
    ("rainbow_wavelengths_too_many", _set("quality", {"rainbow_wavelengths": 65}), ValueError,
     "quality.rainbow_wavelengths"),
    ("rainbow_wavelengths_float", _set("quality", {"rainbow_wavelengths": 9.5}), ValueError,
     "quality.rainbow_wavelengths"),
]


BAD_IDS = [b[0] for b in BAD_SCENES]


def _bad(mutate: Callable[[dict], None]) -> dict:
    scene = copy.deepcopy(VALID)
    mutate(scene)
    return scene


def test_valid_base_scene_loads_and_is_normalised() -> None:
    loaded = airlight.load_scene(VALID)
    assert loaded["surfaces"][1]["albedo"] == [0.5, 0.5, 0.5]
    assert loaded["medium"]["sigma_t"] == pytest.approx([0.05] * 3)


def _foggy(**medium: object) -> dict:
    scene = copy.deepcopy(VALID)
    scene["medium"] = {k: v for k, v in {**scene["medium"], **medium}.items() if v is not None}
    return scene


def test_medium_given_by_its_visibility_renders_as_koschmieder_sigma_t() -> None:
    """medium.visibility V (m) is the night fog's alternative to sigma_t (issue 17), as for the
    daytime aerosol: sigma_t = 3.912 / V on every channel; the loaded scene keeps the
    visibility (not both keys, which are refused together), reloads to itself, and renders
    exactly as the same medium given by sigma_t."""
    by_visibility = _foggy(sigma_t=None, visibility=97.8)
    loaded = airlight.load_scene(by_visibility)
    assert loaded["medium"]["visibility"] == pytest.approx(97.8) and "sigma_t" not in loaded["medium"]
    assert airlight.load_scene(loaded) == loaded
    by_sigma = _foggy(sigma_t=float(np.float32(3.912 / np.float64(np.float32(97.8)))))
    np.testing.assert_array_equal(airlight.render(by_visibility, backend="cpu", width=24, height=16),
                                  airlight.render(by_sigma, backend="cpu", width=24, height=16))


@pytest.mark.parametrize(("medium", "exc", "field", "needle"), [
    ({"visibility": 100.0}, ValueError, "medium.visibility", "not both"),
    ({"sigma_t": None}, ValueError, "medium.sigma_t", "visibility"),
    ({"sigma_t": None, "visibility": 0}, ValueError, "medium.visibility", "> 0"),
    ({"sigma_t": None, "visibility": -3.0}, ValueError, "medium.visibility", "> 0"),
    ({"sigma_t": None, "visibility": float("nan")}, ValueError, "medium.visibility", "finite"),
    ({"sigma_t": None, "visibility": "dense"}, TypeError, "medium.visibility", "number"),
])
def test_medium_visibility_errors_name_the_field(medium: dict, exc: type, field: str, needle: str) -> None:
    with pytest.raises(exc, match=f"^{re.escape(field)}: .*{needle}"):
        airlight.load_scene(_foggy(**medium))


@pytest.mark.parametrize(("mutate", "exc", "field"), [b[1:] for b in BAD_SCENES], ids=BAD_IDS)
def test_load_scene_rejects_bad_input_naming_the_field(mutate, exc, field) -> None:
    with pytest.raises(exc) as info:
        airlight.load_scene(_bad(mutate))
    assert type(info.value) is exc, f"expected exactly {exc.__name__}, got {type(info.value).__name__}"
    message = str(info.value)
    assert message.startswith(field + ":"), f"message {message!r} does not start with {field!r}"


@pytest.mark.parametrize(("mutate", "exc", "field"), [b[1:] for b in BAD_SCENES], ids=BAD_IDS)
def test_render_rejects_bad_input_naming_the_field(mutate, exc, field) -> None:
    with pytest.raises(exc, match="^" + re.escape(field) + ":"):
        airlight.render(_bad(mutate), backend="cpu")


@pytest.mark.parametrize("scene", [5, 3.5, None, [VALID], b"{}", (1, 2)], ids=repr)
def test_non_dict_scene_is_a_type_error(scene) -> None:
    with pytest.raises(TypeError, match="scene"):
        airlight.load_scene(scene)
    with pytest.raises(TypeError, match="scene"):
        airlight.render(scene, backend="cpu")


def test_invalid_json_text_is_a_value_error() -> None:
    # Text starting with "{" is JSON; a JSON list is read from a file to test it.
    with pytest.raises(ValueError, match="invalid JSON"):
        airlight.load_scene("{not json")


@pytest.mark.parametrize("via", ["text", "file"])
def test_invalid_json_message_is_one_clean_line_saying_where(tmp_path, via: str) -> None:
    """The parser library's "[json.exception.parse_error.101] parse error" prefix is not shown
    (issue 17): the message is one line, "invalid JSON at line L, column C: ...", from JSON text
    and from a file, through load_scene and render."""
    text = '{"film": {"width": 10,\n\n "height": }'
    path = tmp_path / "broken.json"
    path.write_text(text)
    source = text if via == "text" else str(path)
    for call in (airlight.load_scene, lambda s: airlight.render(s, backend="cpu")):
        with pytest.raises(ValueError) as info:
            call(source)
        message = str(info.value)
        assert message.startswith("invalid JSON at line 3, column 12: syntax error"), message
        assert "json.exception" not in message and "\n" not in message, message


def test_json_file_holding_a_list_is_a_type_error(tmp_path) -> None:
    path = tmp_path / "list.json"
    path.write_text("[1, 2, 3]")
    with pytest.raises(TypeError, match="object"):
        airlight.load_scene(str(path))


def test_unreadable_path_is_a_value_error_naming_path(tmp_path) -> None:
    """A missing file says "scene file not found: PATH" (issue 17; it was a bare "path:" label),
    an unreadable one "cannot read scene file PATH: why"."""
    missing = tmp_path / "does_not_exist.json"
    not_found = f"^scene file not found: {re.escape(str(missing))}$"
    with pytest.raises(ValueError, match=not_found):
        airlight.load_scene(str(missing))
    with pytest.raises(ValueError, match=not_found):
        airlight.load_scene(missing)
    with pytest.raises(ValueError, match=not_found):
        airlight.render(str(missing), backend="cpu")
    unreadable = f"^cannot read scene file {re.escape(str(tmp_path))}: Is a directory$"
    with pytest.raises(ValueError, match=unreadable):
        airlight.load_scene(str(tmp_path))  # a directory


def test_path_with_a_nul_byte_is_a_value_error_naming_path() -> None:
    path = "scene\0.json"
    with pytest.raises(ValueError, match="^" + re.escape(f"cannot read scene file {path!r}: ") + ".*null"):
        airlight.load_scene(path)


def test_bad_film_override_is_rejected_naming_the_film_field() -> None:
    with pytest.raises(ValueError, match="^film.width:"):
        airlight.render(VALID, backend="cpu", width=0)
    with pytest.raises(ValueError, match="^film.height:"):
        airlight.render(VALID, backend="cpu", height=16385)
    with pytest.raises(TypeError, match="^film.width:"):
        airlight.render(VALID, backend="cpu", width="24")


def test_huge_python_integer_is_a_value_error_not_a_runtime_error() -> None:
    with pytest.raises(ValueError, match="^camera.fov_y"):
        airlight.load_scene(_bad(_set("camera.fov_y", 10**400)))
    with pytest.raises(ValueError, match="^lights"):
        airlight.load_scene(_bad(_set("lights[0].position", [10**400, 0, 0])))


def test_unencodable_string_is_a_type_or_value_error_not_a_runtime_error() -> None:
    # A lone surrogate cannot be encoded as UTF-8.
    with pytest.raises((TypeError, ValueError)):
        airlight.load_scene(_bad(_set("surfaces[0].type", "\ud800")))
    with pytest.raises((TypeError, ValueError)):
        airlight.load_scene(_bad(_set("\ud800", 1)))


def test_non_string_top_level_key_error_names_a_field() -> None:
    scene = copy.deepcopy(VALID)
    scene[1] = 2
    with pytest.raises(TypeError) as info:
        airlight.load_scene(scene)
    assert not str(info.value).startswith(":"), f"message with an empty field: {str(info.value)!r}"


def test_numpy_values_are_accepted_as_numbers() -> None:
    scene = copy.deepcopy(VALID)
    scene["camera"]["position"] = np.array([0.0, 1.7, 0.0])
    scene["camera"]["fov_y"] = np.float32(45.0)
    scene["film"]["width"] = np.int64(24)
    loaded = airlight.load_scene(scene)
    assert loaded["camera"]["fov_y"] == 45.0 and loaded["film"]["width"] == 24


def test_zero_dimensional_numpy_array_is_accepted_as_a_number() -> None:
    loaded = airlight.load_scene(_bad(_set("camera.fov_y", np.array(45.0))))
    assert loaded["camera"]["fov_y"] == 45.0


# --- property-based: garbage never crashes ------------------------------------------------

_garbage = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=10) | st.sampled_from(["plane", "box", "sphere", "point", "isotropic", ""]),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=8) | st.sampled_from(["type", "position", "radius", "min", "max"]),
                      children, max_size=4),
    max_leaves=12,
)


def _containers(node: Any, out: list) -> list:
    """Every dict and list inside ``node`` (``node`` included)."""
    out.append(node)
    children = node.values() if isinstance(node, dict) else node if isinstance(node, list) else ()
    for child in children:
        if isinstance(child, (dict, list)):
            _containers(child, out)
    return out


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_garbage_anywhere_in_a_scene_raises_only_type_or_value_errors(data) -> None:
    scene = copy.deepcopy(VALID)
    for _ in range(data.draw(st.integers(1, 3), label="edits")):
        container = data.draw(st.sampled_from(_containers(scene, [])), label="container")
        action = data.draw(st.sampled_from(["replace", "insert", "delete"]), label="action")
        value = data.draw(_garbage, label="value")
        if isinstance(container, dict):
            if action == "insert" or not container:
                known = st.sampled_from(sorted(container) or ["x"])
                key = data.draw(st.text(max_size=8) | known, label="key")
                container[key] = value
            else:
                key = data.draw(st.sampled_from(sorted(container)), label="key")
                if action == "delete":
                    del container[key]
                else:
                    container[key] = value
        else:
            if action == "insert" or not container:
                container.insert(data.draw(st.integers(0, len(container)), label="at"), value)
            else:
                i = data.draw(st.integers(0, len(container) - 1), label="index")
                if action == "delete":
                    del container[i]
                else:
                    container[i] = value
    try:
        airlight.load_scene(scene)
    except (TypeError, ValueError):
        return
    # Valid after all: it must render (on a tiny film, whatever its film says).
    try:
        img = airlight.render(scene, backend="cpu", width=8, height=6)
    except (TypeError, ValueError):
        return
    assert img.shape == (6, 8, 3)


@settings(max_examples=100, deadline=None)
@given(scene=_garbage)
def test_garbage_as_the_whole_scene_raises_only_type_or_value_errors(scene) -> None:
    try:
        airlight.load_scene(scene)
    except (TypeError, ValueError):
        pass


# --- property-based: random valid scenes render sanely -------------------------------------

_coord = st.floats(-100.0, 100.0, allow_nan=False)
_point = st.lists(_coord, min_size=3, max_size=3)
_rgb01 = st.lists(st.floats(0.0, 1.0), min_size=3, max_size=3)


@st.composite
def _valid_scenes(draw) -> dict[str, Any]:
    position = draw(_point)
    look_at = draw(_point)
    up = draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
    view = np.subtract(look_at, position)
    assume(np.linalg.norm(view) > 1e-3)
    assume(np.linalg.norm(np.cross(view / np.linalg.norm(view), up)) > 1e-3 * max(np.linalg.norm(up), 1e-30))
    assume(np.linalg.norm(up) > 1e-3)
    scene: dict[str, Any] = {
        "film": {"width": 24, "height": 16},
        "camera": {"position": position, "look_at": look_at, "up": up, "fov_y": draw(st.floats(1.0, 170.0))},
        "background": draw(st.lists(st.floats(0.0, 10.0), min_size=3, max_size=3)),
    }
    if draw(st.booleans()):
        scene["medium"] = {"sigma_t": draw(st.lists(st.floats(0.0, 2.0), min_size=3, max_size=3)),
                           "albedo": draw(_rgb01)}
    scene["lights"] = [
        {"type": "point", "position": draw(_point),
         "intensity": draw(st.lists(st.floats(0.0, 1000.0), min_size=3, max_size=3)),
         "radius": draw(st.floats(0.01, 10.0))}
        for _ in range(draw(st.integers(0, 4)))
    ]
    surfaces = []
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["plane", "box", "sphere"]))
        albedo = draw(_rgb01)
        if kind == "plane":
            normal = draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
            assume(np.linalg.norm(normal) > 1e-3)
            surfaces.append({"type": "plane", "point": draw(_point), "normal": normal, "albedo": albedo})
        elif kind == "box":
            lo = draw(_point)
            size = draw(st.lists(st.floats(0.01, 50.0), min_size=3, max_size=3))
            hi = [a + b for a, b in zip(lo, size)]
            surfaces.append({"type": "box", "min": lo, "max": hi, "albedo": albedo})
        else:
            surfaces.append({"type": "sphere", "center": draw(_point), "radius": draw(st.floats(0.01, 50.0)),
                             "albedo": albedo})
    scene["surfaces"] = surfaces
    return scene


@pytest.fixture(scope="module")
def renderers_for_property_test(renderer_cache) -> list[airlight.Renderer]:
    names = ["cpu"] if airlight.gl_unavailable_reason() is not None else ["cpu", "gl"]
    return [renderer_cache(name) for name in names]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                   HealthCheck.filter_too_much])
@given(scene=_valid_scenes())
def test_random_valid_scenes_render_finite_non_negative_radiance(scene, renderers_for_property_test) -> None:
    airlight.load_scene(scene)  # valid by construction
    for renderer in renderers_for_property_test:
        img = renderer.render(scene)
        assert img.shape == (16, 24, 3)
        bad = ~np.isfinite(img) | (img < 0)
        assert not bad.any(), (
            f"{renderer.backend}: {int(bad.sum())} bad values, e.g. {img[bad][:4]!r} "
            f"at {np.argwhere(bad)[:2].tolist()}")


@pytest.mark.parametrize("phase", [
    {"type": "isotropic"}, {"type": "rayleigh"}, {"type": "hg", "g": 0.85}, {"type": "hg", "g": -0.9999},
    {"type": "hg", "g": 0.9995}, {"type": "hg", "g": 0},
    {"type": "hg2", "forward_g": 0.9, "backward_g": -0.3, "forward_weight": 0.85},
    {"type": "hg2", "forward_g": 0.5, "backward_g": 0.5, "forward_weight": 0},
    {"type": "hg2", "forward_g": -0.2, "backward_g": 0.7, "forward_weight": 1}], ids=repr)
def test_valid_phases_load_and_round_trip(phase) -> None:
    """Every phase type of the format loads with its values kept (g in the open interval
    (-1, 1), beyond the rendering clamp of 0.999 included; forward_weight in the closed
    [0, 1]), and a loaded scene loads again to itself."""
    scene = copy.deepcopy(VALID)
    scene["medium"]["phase"] = copy.deepcopy(phase)
    loaded = airlight.load_scene(scene)
    got = loaded["medium"]["phase"]
    assert sorted(got) == sorted(phase)
    assert got["type"] == phase["type"]
    for key, value in phase.items():
        if key != "type":
            assert got[key] == pytest.approx(value, rel=1e-7, abs=1e-12), key
    assert airlight.load_scene(loaded) == loaded


def test_phase_defaults_to_isotropic() -> None:
    """A medium without "phase" gets {"type": "isotropic"} filled in."""
    scene = copy.deepcopy(VALID)
    del scene["medium"]["phase"]
    assert airlight.load_scene(scene)["medium"]["phase"] == {"type": "isotropic"}


def test_light_radius_default_and_bounds_follow_the_format() -> None:
    scene = copy.deepcopy(VALID)
    del scene["lights"][0]["radius"]
    assert airlight.load_scene(scene)["lights"][0]["radius"] == pytest.approx(0.05)
    scene["lights"][0]["radius"] = 1000.0
    assert math.isclose(airlight.load_scene(scene)["lights"][0]["radius"], 1000.0)
    scene["lights"][0]["radius"] = 1000.5
    with pytest.raises(ValueError, match="^lights\\[0\\].radius:"):
        airlight.load_scene(scene)


# --- daytime keys (issue 6) ---------------------------------------------------------------

ISSUE_EXAMPLE = {
    "sky": {"model": "cie", "type": 12, "zenith_radiance": [1, 1, 1]},
    "sun": {"elevation": 30, "azimuth": 0, "irradiance": [5, 5, 5]},
    "atmosphere": {"molecules": {"density_scale": 1},
                   "aerosol": {"visibility": 5000, "scale_height": 1200, "g": 0.7},
                   "rain": {"rate": 10}},
}


def test_issue_example_loads_with_defaults_filled_in() -> None:
    scene = copy.deepcopy(VALID)
    scene.update(copy.deepcopy(ISSUE_EXAMPLE))
    loaded = airlight.load_scene(scene)
    assert loaded["sky"] == {"model": "cie", "type": 12, "zenith_radiance": [1.0, 1.0, 1.0]}
    assert sorted(loaded["sun"]) == ["direction", "irradiance"]
    assert loaded["sun"]["direction"] == pytest.approx([0.0, 0.5, -math.sqrt(3) / 2], abs=1e-7)
    assert loaded["sun"]["irradiance"] == [5.0, 5.0, 5.0]
    atmosphere = loaded["atmosphere"]
    assert atmosphere["molecules"] == {"density_scale": 1.0}
    assert atmosphere["aerosol"] == {"visibility": 5000.0, "scale_height": 1200.0, "g": 0.7, "albedo": 0.9}
    assert atmosphere["rain"] == {"rate": 10.0, "density_scale": 1.0, "top": 1500.0, "g": 0.87,
                                  "phase": "mie"}
    assert loaded["quality"]["sky_segments"] == 16
    assert loaded["quality"]["multiple_scattering"] is True
    assert airlight.load_scene(loaded) == loaded


def test_daytime_keys_absent_or_null_load_as_null() -> None:
    loaded = airlight.load_scene(VALID)
    assert loaded["sky"] is None and loaded["sun"] is None and loaded["atmosphere"] is None
    scene = copy.deepcopy(VALID)
    scene.update({"sky": None, "sun": None, "atmosphere": {}})
    loaded = airlight.load_scene(scene)
    assert loaded["sky"] is None and loaded["sun"] is None and loaded["atmosphere"] is None


@pytest.mark.parametrize("sky_type", range(1, 16))
def test_only_cie_types_1_3_5_load_without_a_sun(sky_type) -> None:
    scene = _bad(_set("sky", {"model": "cie", "type": sky_type, "zenith_radiance": 1}))
    if sky_type in (1, 3, 5):
        assert airlight.load_scene(scene)["sky"]["type"] == sky_type
    else:
        with pytest.raises(ValueError, match='^sky.type:.*"sun"'):
            airlight.load_scene(scene)
        scene["sun"] = {"direction": [0, 1, 1]}
        assert airlight.load_scene(scene)["sun"]["direction"] == pytest.approx([0, 0.5**0.5, 0.5**0.5])


_positive = st.floats(1e-6, 1e6)
_asymmetry = st.floats(-0.999, 0.999)


@st.composite
def _daytime_keys(draw) -> dict[str, Any]:
    keys: dict[str, Any] = {}
    model = draw(st.sampled_from([None, "overcast", "cie"]))
    if model is not None:
        keys["sky"] = {"model": model, "zenith_radiance": draw(st.lists(_positive, min_size=3, max_size=3))}
        if model == "cie":
            keys["sky"]["type"] = draw(st.integers(1, 15))
    if draw(st.booleans()) or model == "cie":
        if draw(st.booleans()):
            keys["sun"] = {"elevation": draw(st.floats(-90.0, 90.0)), "azimuth": draw(st.floats(-1e4, 1e4))}
        else:
            direction = draw(st.lists(st.floats(-10.0, 10.0), min_size=3, max_size=3))
            assume(np.linalg.norm(direction) > 1e-3)
            keys["sun"] = {"direction": direction}
        if draw(st.booleans()):
            keys["sun"]["irradiance"] = draw(_positive)
    atmosphere: dict[str, Any] = {}
    if draw(st.booleans()):
        atmosphere["molecules"] = {"density_scale": draw(st.floats(0.0, 1e6))}
    if draw(st.booleans()):
        amount = draw(st.sampled_from(["visibility", "coefficient"]))
        atmosphere["aerosol"] = {
            amount: draw(st.floats(3.912e-3, 1e9) if amount == "visibility" else st.floats(0.0, 1e3)),
            "scale_height": draw(st.floats(1.0, 1e5)), "g": draw(_asymmetry),
            "albedo": draw(st.floats(0.0, 1.0))}
    if draw(st.booleans()):
        atmosphere["rain"] = {"rate": draw(st.floats(0.0, 1000.0)), "top": draw(st.floats(1.0, 1e5)),
                              "density_scale": draw(st.floats(0.0, 1e6)), "g": draw(_asymmetry),
                              "phase": draw(st.sampled_from(["mie", "hg"]))}
    if atmosphere or draw(st.booleans()):
        keys["atmosphere"] = atmosphere
    keys["quality"] = {"sky_segments": draw(st.integers(2, 64)),
                       "rainbow_wavelengths": draw(st.sampled_from([3, 5, 9, 17, 33])),
                       "multiple_scattering": draw(st.booleans())}
    return keys


@settings(max_examples=200, deadline=None)
@given(keys=_daytime_keys())
def test_random_daytime_keys_load_and_round_trip(keys) -> None:
    """Random valid daytime keys load, the sun's direction is unit, and a loaded scene
    loads again to itself."""
    scene = copy.deepcopy(VALID)
    scene.update(keys)
    loaded = airlight.load_scene(scene)
    if loaded["sun"] is not None:
        assert np.linalg.norm(loaded["sun"]["direction"]) == pytest.approx(1.0, abs=1e-6)
    assert loaded["quality"]["sky_segments"] == keys["quality"]["sky_segments"]
    assert loaded["quality"]["rainbow_wavelengths"] == keys["quality"]["rainbow_wavelengths"]
    assert loaded["quality"]["multiple_scattering"] == keys["quality"]["multiple_scattering"]
    assert airlight.load_scene(loaded) == loaded
