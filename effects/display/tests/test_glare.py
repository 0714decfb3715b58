"""airlight.glare: the eye's diffraction glare applied to radiance from Python
(the PSF itself is tested in effects/display/tests/test_glare.cpp)."""

from __future__ import annotations

import numpy as np
import pytest

import airlight


def _point_image(width: int = 121, height: int = 121) -> np.ndarray:
    image = np.zeros((height, width, 3), np.float32)
    image[height // 2, width // 2] = [1000.0, 800.0, 600.0]
    return image


def test_glare_moves_light_without_creating_it():
    """A point source spreads into a halo centred on it, and each channel's total is kept
    within 1e-5 (the kernel sums to 1; nothing falls off this image)."""
    image = _point_image()
    out = airlight.glare(image, fov_y=2.0, pupil_diameter=4.0)
    assert out.dtype == np.float32 and out.shape == image.shape
    assert np.isfinite(out).all() and (out >= -1e-3).all()
    np.testing.assert_allclose(out.sum(axis=(0, 1)), image.sum(axis=(0, 1)), rtol=1e-5)
    c = 60
    assert out[c, c, 1] < image[c, c, 1] and out[c, c + 3, 1] > 0  # the core gives light to the halo
    assert np.allclose(out[c, c + 5], out[c, c - 5], rtol=1e-3)  # a round pupil: symmetric


def test_smaller_pupil_spreads_more():
    """Diffraction scales as lambda / D: a 2 mm pupil keeps less light in the core pixel
    than an 8 mm one."""
    image = _point_image()
    small = airlight.glare(image, fov_y=1.0, pupil_diameter=2.0)
    large = airlight.glare(image, fov_y=1.0, pupil_diameter=8.0)
    assert small[60, 60, 1] < large[60, 60, 1]


@pytest.mark.parametrize("kwargs,error,field", [
    ({"fov_y": 60.0, "pupil_diameter": 0.5}, ValueError, "pupil_diameter"),
    ({"fov_y": 60.0, "pupil_diameter": 12.0}, ValueError, "pupil_diameter"),
    ({"fov_y": 0.0}, ValueError, "fov_y"),
    ({"fov_y": "wide"}, TypeError, "fov_y"),
    ({"fov_y": 60.0, "eyelashes": 1}, TypeError, "eyelashes"),
])
def test_glare_bad_arguments_name_the_field(kwargs, error, field):
    with pytest.raises(error, match=field):
        airlight.glare(_point_image(16, 16), **kwargs)


def _rings(values: np.ndarray, centre: int, min_distance: int, zero: float) -> tuple[float, int]:
    """(worst (max - min) / max over pixels at the same distance >= min_distance from the centre, the
    number of steps along 16 rays from the centre where the values grow by more than ``zero``)."""
    n = values.shape[0]
    yy, xx = np.mgrid[0:n, 0:n]
    d2 = (yy - centre) ** 2 + (xx - centre) ** 2
    v = np.where(values > zero, values, 0.0)
    worst = 0.0
    for ring in np.unique(d2[d2 >= min_distance**2]):
        group = v[d2 == ring]
        if group.size > 1 and group.max() > 0:
            worst = max(worst, float((group.max() - group.min()) / group.max()))
    rises = 0
    for dx, dy in [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1),
                   (2, 1), (1, 2), (-2, 1), (-1, 2), (2, -1), (1, -2), (-2, -1), (-1, -2)]:
        k = np.arange(0, n)
        x, y = centre + k * dx, centre + k * dy
        inside = (x >= 0) & (y >= 0) & (x < n) & (y < n)
        ray = values[y[inside], x[inside]]
        rises += int(np.sum(np.diff(ray) > zero))
    return worst, rises


# The approaching car's eye (1 mm pupil, 14 degrees over 360 rows: a pixel per resolution angle; square
# pixels over rings of their own size differ by a few % within 5 pixels) and a 4 mm pupil at 60 / 360.
ROUND_CASES = [(1.0, 14.0, 6), (4.0, 60.0, 1)]


@pytest.mark.parametrize(("pupil", "fov_360", "min_distance"), ROUND_CASES)
def test_glare_of_a_bright_pixel_is_round(pupil: float, fov_360: float, min_distance: int) -> None:
    """Issue 17: the exact convolution (FFT) of one bright pixel is radially symmetric within 1 % and
    falls off along rays; it used to be the kernel's (2r + 1)^2 square, a square halo with a hard edge."""
    n = 77
    pixel = 2 * np.tan(np.radians(fov_360) / 2) / 360
    fov = float(np.degrees(2 * np.arctan(pixel * n / 2)))  # the same angle per pixel on n rows
    image = np.zeros((n, n, 3), np.float32)
    image[n // 2, n // 2] = 1.0
    spread = airlight.glare(image, fov_y=fov, pupil_diameter=pupil).astype(np.float64)
    for c in range(3):
        peak = spread[n // 2, n // 2, c]
        worst, rises = _rings(spread[..., c], n // 2, min_distance, 1e-12 * peak)
        assert worst <= 0.01, f"channel {c}: asymmetry {worst:.3f}"
        assert rises == 0


@pytest.mark.parametrize(("pupil", "fov_360", "min_distance"), ROUND_CASES)
def test_displayed_glare_of_a_headlight_is_round(renderer, pupil: float, fov_360: float,
                                                 min_distance: int) -> None:
    """The display stage on either backend (one bright pixel: splatted) at an exposure that shows the glare
    down to 1e-7 of the source, as in the approaching car's frame at 20 m (the linear curve, so that each
    channel's display value follows its radiance): pixels at the same distance show
    the same 8-bit value within one step, and the halo only darkens outwards."""
    n = 77
    pixel = 2 * np.tan(np.radians(fov_360) / 2) / 360
    fov = float(np.degrees(2 * np.arctan(pixel * n / 2)))
    image = np.zeros((n, n, 3), np.float32)
    image[n // 2, n // 2] = 1.0
    out, report = airlight.display_report(image, exposure=3e6, tonemap="linear",
                                          glare={"pupil_diameter": pupil}, fov_y=fov, renderer=renderer,
                                          dither=False)
    assert report["glare"] == "sparse"
    shown = out.astype(np.float64)
    yy, xx = np.mgrid[0:n, 0:n]
    d2 = (yy - n // 2) ** 2 + (xx - n // 2) ** 2
    for c in range(3):
        for ring in np.unique(d2[d2 >= min_distance**2]):
            group = shown[..., c][d2 == ring]
            assert group.max() - group.min() <= 1, f"channel {c}, distance {np.sqrt(ring):.1f}: {group}"
    # Along rays, from where the halo drops below white (inside, the curve's clipping scales each pixel's
    # channels by 1 / Y, which follows the halo's colour, not its fall-off): only darker outwards.
    below_white = np.where(shown.max(axis=2, keepdims=True) < 250, shown, 255.0)
    for c in range(3):
        assert _rings(below_white[..., c], n // 2, 0, 0.0)[1] == 0
