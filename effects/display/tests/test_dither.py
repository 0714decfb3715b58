"""Issue 17, item 8: the display stage dithers its 8-bit output (physics.md section 5, "Dithering"), so a
smooth gradient stretched in contrast shows no bands: along a ramp no run of equal 8-bit values is longer
than the ramp's slope allows, on both backends, with the same thresholds; ``dither=False`` (scene key
``display.dither``) rounds, and the bands come back."""

from __future__ import annotations

import numpy as np
import pytest
from test_display import dither_reference

import airlight
from conftest import make_scene


def _srgb_eotf(v: np.ndarray) -> np.ndarray:
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def _ramp(length: int, lo: float, hi: float, vertical: bool) -> np.ndarray:
    """Grey radiance whose sRGB encoding runs linearly from lo to hi (8-bit units) along x (or y)."""
    encoded = np.linspace(lo, hi, length) / 255.0
    line = _srgb_eotf(encoded).astype(np.float32)
    image = np.repeat(line[None, :, None], 12, axis=0).repeat(3, axis=2)
    return np.ascontiguousarray(image.transpose(1, 0, 2)) if vertical else image


def _longest_run(values: np.ndarray) -> int:
    """The longest run of equal values along the last axis, over all rows."""
    best = 0
    for row in values.reshape(-1, values.shape[-1]):
        edges = np.flatnonzero(np.diff(row) != 0)
        bounds = np.concatenate([[-1], edges, [len(row) - 1]])
        best = max(best, int(np.diff(bounds).max()))
    return best


@pytest.mark.parametrize("vertical", [False, True])
def test_dithered_ramp_has_no_bands(renderer, vertical: bool) -> None:
    # 8 steps over 256 pixels: a slope of 1/32 step per pixel, bands 32 pixels wide when rounded.
    length, lo, hi = 256, 40.0, 48.0
    slope = (hi - lo) / (length - 1)
    image = _ramp(length, lo, hi, vertical)
    out = airlight.display(image, exposure=1.0, tonemap="linear", renderer=renderer)[..., 1].astype(np.int64)
    along = out.T if vertical else out
    # Rounding shows each value for 1 / slope (32) pixels: bands. With thresholds spread over [0, 1), a
    # value k holds only while the ramp is close enough to k that every threshold of the run keeps it
    # (probability 1 - |v - k| each), which allows runs of order sqrt(1 / slope): at most 4 / sqrt(slope)
    # (22.6 here; the R2 thresholds give 17 on this ramp).
    assert _longest_run(along) <= 4.0 / np.sqrt(slope)
    # Unbiased: the mean over every 32-pixel window is the ramp's own within a quarter step.
    exact = np.linspace(lo, hi, length)
    window = 32
    means = np.convolve(along.mean(axis=0), np.ones(window) / window, mode="valid")
    assert np.abs(means - np.convolve(exact, np.ones(window) / window, mode="valid")).max() <= 0.25
    # The dither is the documented one: floor(255 v + t) (test_display.py's reference).
    t = dither_reference(*image.shape[:2])
    v = np.linspace(lo, hi, length) / 255.0
    v = v[:, None] if vertical else v[None, :]
    assert np.abs(out - np.floor(255 * v + t)).max() <= 1
    # Dithering off: plain rounding, and the bands are back.
    plain = airlight.display(image, exposure=1.0, tonemap="linear", renderer=renderer, dither=False)
    plain_along = plain[..., 1].T if vertical else plain[..., 1]
    assert _longest_run(plain_along.astype(np.int64)) >= 0.9 / slope


def test_dither_is_the_same_on_both_backends(renderer_cache) -> None:
    gl = renderer_cache("gl")
    image = _ramp(200, 10.0, 30.0, False) * np.float32(3.0)
    for tonemap in airlight.TONEMAPS:
        cpu = airlight.display(image, tonemap=tonemap).astype(int)
        on_gl = airlight.display(image, tonemap=tonemap, renderer=gl).astype(int)
        assert np.abs(cpu - on_gl).max() <= 1
        assert np.mean(cpu == on_gl) >= 0.99


def test_dither_scene_key_and_argument() -> None:
    assert airlight.load_scene(make_scene())["display"]["dither"] is True
    loaded = airlight.load_scene(make_scene(display={"dither": False}))
    assert loaded["display"]["dither"] is False
    with pytest.raises(TypeError, match=r"^display\.dither:"):
        airlight.load_scene(make_scene(display={"dither": "no"}))
    with pytest.raises(TypeError, match="^dither:"):
        airlight.display(np.ones((4, 4, 3), np.float32), dither=1)
    image = _ramp(64, 40.0, 48.0, False)
    scene = make_scene(display={"exposure": 1.0, "tonemap": "linear", "dither": False})
    np.testing.assert_array_equal(airlight.display_scene(image, scene),
                                  airlight.display(image, exposure=1.0, tonemap="linear", dither=False))
    _, report = airlight.display_report(image, dither=False)
    assert report["dither"] is False
