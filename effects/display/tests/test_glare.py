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
