"""The eye's diffraction glare (effects/display/docs/glare.md): the exact convolution
:func:`glare`, and the ``glare`` argument (:data:`GlareLike`) of the display
stage, which spreads only the light whose glare is visible."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Union

import numpy as np

from . import _core
from ._checks import _radiance_array, _real

GlareLike = Union[bool, None, Mapping[str, Any]]
"""The ``glare`` argument of :func:`display`: ``None``/``False`` (off),
``True`` (pupil from the adaptation luminance, no eyelashes) or a dict as the
scene format's ``display.glare``: ``{"pupil_diameter": mm or "auto",
"eyelashes": bool}``."""


def _glare_args(glare: Any) -> tuple[bool, float | None, bool]:
    """(enabled, pupil diameter or None for "auto", eyelashes); errors name ``glare...``."""
    if glare is None or glare is False:
        return False, None, False
    if glare is True:
        return True, None, False
    if not isinstance(glare, Mapping):
        raise TypeError(f"glare: expected None, a bool or a dict, got {type(glare).__name__}")
    unknown = sorted(set(glare) - {"pupil_diameter", "eyelashes"})
    if unknown:
        raise ValueError(f"glare.{unknown[0]}: unknown key (allowed: pupil_diameter, eyelashes)")
    pupil: float | None = None
    value = glare.get("pupil_diameter", "auto")
    if isinstance(value, str):
        if value != "auto":
            raise ValueError(f"glare.pupil_diameter: expected a diameter in mm or 'auto', got {value!r}")
    else:
        pupil = _real("glare.pupil_diameter", value)
        if not 1.0 <= pupil <= 9.0:
            raise ValueError(f"glare.pupil_diameter: must be in [1, 9] mm, got {value!r}")
    eyelashes = glare.get("eyelashes", False)
    if not isinstance(eyelashes, bool):
        raise TypeError(f"glare.eyelashes: expected a bool, got {type(eyelashes).__name__}")
    return True, pupil, eyelashes


def glare(radiance: np.ndarray, *, fov_y: float, pupil_diameter: float = 4.0,
          eyelashes: bool = False) -> np.ndarray:
    """The eye's diffraction glare applied to linear radiance (float32, same
    shape): each channel convolved with the point spread function of a pupil
    of ``pupil_diameter`` mm (1 to 9; optionally with eyelashes across its
    upper part), the Fraunhofer pattern of the aperture per wavelength over
    380-780 nm weighted by the CIE 1931 colour matching functions and
    integrated over each pixel, so the Airy core is honest whether it is
    smaller or larger than a pixel. ``fov_y`` (degrees) is the camera's
    vertical field of view, which sets the angle per pixel. The kernel sums to
    1 per channel: glare moves light, it does not create it (effects/display/docs/glare.md).
    Past the frame the image is taken to continue as its edge pixels (a
    uniform image is unchanged; the border gathers glare from outside as it
    loses glare to it). NaN and negative radiance count as 0.
    This is the exact convolution of every pixel; :func:`display` with
    ``glare=...`` spreads only the pixels whose glare is visible.
    """
    image = _radiance_array(radiance)
    fov = _real("fov_y", fov_y)
    if not 0 < fov < 180:
        raise ValueError(f"fov_y: must be in (0, 180) degrees, got {fov_y!r}")
    if not isinstance(eyelashes, bool):
        raise TypeError(f"eyelashes: expected a bool, got {type(eyelashes).__name__}")
    return np.asarray(_core.glare(image, fov, _real("pupil_diameter", pupil_diameter), eyelashes))
