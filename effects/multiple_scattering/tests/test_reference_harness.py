"""The Mitsuba reference models the same scene as airlight (issue 18): limited to single
scattering (volpath max_depth = 2), it agrees with airlight's current renders, which are single
scattering, on sky and ground pixels of several daytime presets and on the glow of a lamp in fog.
A second check shows the comparison has the power to see one more scattering order.

Skipped without Mitsuba (pip install ".[reference]"); slow (about a minute and a half on one
thread). Tolerance per pixel and channel: 4.5 standard errors of the path tracer plus 1 % for
airlight's own discretisation (effects/daytime/physics.md section 7 measures up to 0.6 %)."""

from __future__ import annotations

import math

import numpy as np
import pytest

mitsuba = pytest.importorskip("mitsuba")

import daytime_scenes as ds  # noqa: E402
import mitsuba_reference as mr  # noqa: E402
import ms_cases  # noqa: E402

import airlight  # noqa: E402

pytestmark = pytest.mark.slow

SIGMAS = 4.5
MODEL_TOLERANCE = 0.01
SPP = 16384

CLEAR_SKY = ms_cases.CLEAR_SKY
SUN_HIGH = {"elevation": 60.0, "azimuth": 30.0, "irradiance": [12.0, 11.5, 10.5]}
SUN_LOW = {"elevation": 10.0, "azimuth": 150.0, "irradiance": [12.0, 11.5, 10.5]}

# (name, scene, channels, spp): a column of 9 pixels from 57 degrees up to 57 degrees down (the
# middle one horizontal), over a ground of albedo 0.3.
CLEAR_AIR = ds.atmosphere(visibility=30000, scale_height=1200)
HAZE = ds.atmosphere(visibility=5000, scale_height=1200)
LIGHT_RAIN = ds.atmosphere(visibility=10000, rain=3.0, scale_height=1200)
HARNESS_SCENES = [
    ("clear_sun_high", dict(sky=CLEAR_SKY, sun=SUN_HIGH, atmosphere=CLEAR_AIR), (1, 2), SPP),
    ("hazy_sun_low", dict(sky=CLEAR_SKY, sun=SUN_LOW, atmosphere=HAZE), (1,), 4 * SPP),
    ("light_rain_sun_high", dict(sky=CLEAR_SKY, sun=SUN_HIGH, atmosphere=LIGHT_RAIN), (0,), SPP),
    ("overcast_hazy", dict(sky=ms_cases.OVERCAST_SKY, sun=None, atmosphere=HAZE), (1,), SPP),
]


@pytest.fixture(scope="module")
def mi():
    return mr.load_mitsuba(threads=1)


def _column_scene(kwargs: dict) -> dict:
    return ds.day_scene(**kwargs, camera_y=1.7, pitch=0.0, fov=120.0, width=1, height=9, ground=0.3)


def _agreement(got: np.ndarray, err: np.ndarray, want: np.ndarray) -> np.ndarray:
    """|got - want| in units of the allowed deviation (<= 1 passes)."""
    return np.abs(got - want) / (SIGMAS * err + MODEL_TOLERANCE * np.abs(want))


@pytest.mark.parametrize(("name", "kwargs", "channels", "spp"), HARNESS_SCENES,
                         ids=[s[0] for s in HARNESS_SCENES])
def test_single_scattering_matches_airlight_day(mi, name: str, kwargs: dict, channels: tuple,
                                                spp: int) -> None:
    scene = _column_scene(kwargs)
    want = airlight.render(scene, backend="cpu")[:, 0].astype(float)  # (9, 3)
    dirs = ds.scene_directions(scene)[:, 0]
    est = mr.estimate_day(scene, dirs, spp, max_depth=2, seed=11, channels=channels)
    for c in channels:
        ratio = _agreement(est.mean[:, c], est.stderr[:, c], want[:, c])
        assert np.all(est.stderr[:, c] < 0.03 * want[:, c]), (name, c, est.stderr[:, c] / want[:, c])
        assert np.all(ratio <= 1.0), (name, "rgb"[c], est.mean[:, c], want[:, c], est.stderr[:, c])


def test_the_comparison_sees_one_more_scattering_order(mi) -> None:
    """Double scattering (max_depth = 3) of the hazy day fails the same comparison on the ground
    and near the horizon: the check above can fail."""
    scene = _column_scene(HARNESS_SCENES[1][1])
    want = airlight.render(scene, backend="cpu")[:, 0].astype(float)
    dirs = ds.scene_directions(scene)[:, 0]
    est = mr.estimate_day(scene, dirs, SPP, max_depth=3, seed=12, channels=(1,))
    ratio = _agreement(est.mean[:, 1], est.stderr[:, 1], want[:, 1])
    assert np.count_nonzero(ratio > 1.0) >= 4, ratio


NIGHT = [(0.5, 0.0), (2.0, 0.9), (5.0, 0.5)]
NIGHT_ANGLES = (1.0, 5.0, 20.0, 90.0)


@pytest.mark.parametrize(("tau", "g"), NIGHT, ids=[f"tau{t:g}_g{g:g}" for t, g in NIGHT])
def test_single_scattering_matches_airlight_lamp(mi, tau: float, g: float) -> None:
    scene = ms_cases.night_scene(tau, g)
    want = []
    for a in NIGHT_ANGLES:
        s = dict(scene, camera=ms_cases.camera(scene["camera"]["position"], ms_cases.glow_direction(a)))
        want.append(float(airlight.render(s, backend="cpu")[0, 0, 1]))
    want_a = np.array(want)
    est = mr.estimate_lamp(tau / ms_cases.LAMP_DISTANCE, ms_cases.NIGHT_ALBEDO, g, ms_cases.LAMP_INTENSITY,
                           ms_cases.LAMP_DISTANCE, NIGHT_ANGLES, 65536, max_depth=2, seed=13)
    assert np.all(est.stderr < 0.1 * want_a), est.stderr / want_a
    ratio = _agreement(est.mean, est.stderr, want_a)
    assert np.all(ratio <= 1.0), (est.mean, want_a, est.stderr)
    assert math.isfinite(est.settings["fog_radius_m"])
