"""The display stage: what the eye sees of linear radiance, as 8-bit sRGB.

:func:`display` (exposure, optional glare, a tone curve of luminance, the sRGB
OETF) on the CPU or on a :class:`Renderer`'s backend, :func:`display_report`
(and what it did), :func:`display_scene` (with a scene's ``"display"``
settings), the pieces on their own (:func:`auto_exposure`, :func:`tone_curve`,
:data:`TONEMAPS`), and the plain clip-and-encode :func:`to_srgb8`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _core
from ._checks import _radiance_array, _real
from ._glare import GlareLike, _glare_args
from ._rendering import Renderer
from ._scenes import SceneLike, load_scene


def to_srgb8(radiance: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """8-bit sRGB image (uint8, same shape) of ``radiance * exposure`` clipped to [0, 1]."""
    if not np.isfinite(exposure) or exposure < 0:
        raise ValueError(f"exposure: must be finite and >= 0, got {exposure!r}")
    return _core.to_srgb8(np.asarray(radiance, dtype=np.float32), float(exposure))


TONEMAPS = ("linear", "loglog", "reinhard", "filmic")
"""The tone curves of :func:`display` (see its docstring)."""


def _tonemap_args(tonemap: Any, white: Any) -> tuple[str, float | None]:
    """(tone curve, white point or None for the curve's default); errors name the argument."""
    if not isinstance(tonemap, str):
        raise TypeError(f"tonemap: expected a string, got {type(tonemap).__name__}")
    if tonemap not in TONEMAPS:
        raise ValueError(f"tonemap: unknown tone curve {tonemap!r}; expected one of {', '.join(TONEMAPS)}")
    if white is None:
        return tonemap, None
    w = _real("white", white)
    if w <= 0:
        raise ValueError(f"white: must be > 0, got {white!r}")
    return tonemap, w


def _display(radiance: Any, exposure: Any, tonemap: Any, white: Any, glare: Any, fov_y: Any,
             renderer: Renderer | None, dither: Any) -> tuple[np.ndarray, dict[str, Any]]:
    """:func:`display_report` after checking every argument (errors name it)."""
    image = _radiance_array(radiance)
    if not isinstance(dither, bool):
        raise TypeError(f"dither: expected a bool, got {type(dither).__name__}")
    tonemap, w = _tonemap_args(tonemap, white)
    if isinstance(exposure, str):
        if exposure != "auto":
            raise ValueError(f"exposure: must be 'auto' or a number >= 0, got {exposure!r}")
        manual = None
    else:
        manual = _real("exposure", exposure)
        if manual < 0:
            raise ValueError(f"exposure: must be >= 0, got {exposure!r}")
    enabled, pupil, eyelashes = _glare_args(glare)
    fov = 60.0
    if enabled:
        if fov_y is None:
            raise TypeError("fov_y: the camera's vertical field of view (degrees) is needed for glare")
        fov = _real("fov_y", fov_y)
        if not 0 < fov < 180:
            raise ValueError(f"fov_y: must be in (0, 180) degrees, got {fov_y!r}")
    native = renderer._active() if renderer is not None else None
    out, report = _core.display(image, manual, tonemap, w, enabled, pupil, eyelashes, fov, native, dither)
    return out, dict(report)


def display(radiance: np.ndarray, *, exposure: str | float = "auto", tonemap: str = "loglog",
            white: float | None = None, glare: GlareLike = None, fov_y: float | None = None,
            renderer: Renderer | None = None, dither: bool = True) -> np.ndarray:
    """What the eye sees: 8-bit sRGB (uint8, shape (height, width, 3)) of linear
    radiance (float (height, width, 3), e.g. from :func:`render`), computed by
    the native display stage: on the CPU (multithreaded), or on ``renderer``'s
    backend when given (the GL backend runs the glare and the tone curve on the
    GPU; the same per-pixel code, ``effects/display/display.glsl``).

    Steps: optional glare (below); each channel is multiplied by the exposure
    (NaN, negative and infinite values count as 0); the tone curve is applied
    to the Rec. 709 luminance ``Y = 0.2126 R + 0.7152 G + 0.0722 B`` and the
    pixel scaled by ``f(Y) / Y`` (colours keep their chromaticity; channels
    above 1 clip); then the sRGB OETF (IEC 61966-2-1) and 8 bits, dithered.

    - ``exposure``: ``"auto"`` (default) maps the log-average luminance of
      the pixels with finite ``Y`` at least ``1e-6`` times the median
      luminance to the key 0.18 (Reinhard et al. 2002);
      see :func:`auto_exposure`. A number >= 0 multiplies the radiance.
    - ``tonemap``, the curve ``f`` of exposed luminance ``L`` with white point
      ``W`` (the exposed luminance shown as display value 1):
      ``"linear"`` ``L / W`` (W = 1 by default: like :func:`to_srgb8`);
      ``"loglog"`` (default), the source paper's double logarithm,
      ``ln(1 + ln(1 + L)) / ln(1 + ln(1 + W))``, W = 100;
      ``"reinhard"``, extended Reinhard (2002), ``L (1 + L / W^2) / (1 + L)``, W = 16;
      ``"filmic"``, the ACES fit of Narkowicz (2015),
      ``x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)`` with ``x = 7.2439 L / W``,
      W = 7.2439 (the published curve). Every curve maps 0 to 0, is
      non-decreasing, and is clipped to [0, 1]; see
      ``docs/images/tone_curves.png``.
    - ``white``: ``W``, a number > 0; ``None`` for the curve's default.
    - ``glare``: the eye's diffraction glare (see :func:`glare` and
      ``effects/display/docs/glare.md``), ``None`` (off), ``True`` or
      ``{"pupil_diameter": mm in [1, 9] or "auto", "eyelashes": bool}``;
      ``"auto"`` takes the pupil from the image's log-average luminance
      (Moon & Spencer). Light the glare would visibly move is spread
      exactly; light whose glare provably moves no 8-bit value by more than
      one step stays in place, and with nothing to spread the convolution is
      skipped (``effects/display/docs/glare.md``). Needs ``fov_y``.
    - ``fov_y``: the camera's vertical field of view in degrees (the glare's
      angle per pixel).
    - ``dither``: ``True`` (default) quantizes each encoded value ``v`` to
      ``floor(255 v + t)`` with an ordered threshold ``t`` in [0, 1) per pixel
      (the R2 low-discrepancy sequence, the same on both backends), so smooth
      gradients show no bands; ``False`` rounds, ``round(255 v)``
      (``effects/display/physics.md`` section 5).

    Bad arguments raise ``TypeError``/``ValueError`` naming the argument
    (``"exposure: must be >= 0, got -1"``). :func:`display_report` returns
    what was done as well.
    """
    return _display(radiance, exposure, tonemap, white, glare, fov_y, renderer, dither)[0]


def display_report(radiance: np.ndarray, *, exposure: str | float = "auto", tonemap: str = "loglog",
                   white: float | None = None, glare: GlareLike = None, fov_y: float | None = None,
                   renderer: Renderer | None = None,
                   dither: bool = True) -> tuple[np.ndarray, dict[str, Any]]:
    """:func:`display` and what it did: ``exposure`` and ``white`` used,
    ``glare`` (``"off"``, ``"skipped"`` when no pixel is bright enough,
    ``"sparse"`` (splats on the CPU, on either backend), ``"fft"`` on the
    CPU, ``"gl-fft"`` on GL),
    ``pupil_diameter`` (mm), ``glare_kernel_radius`` (pixels),
    ``glare_threshold`` (radiance: the excess of each channel over it is
    spread, see ``effects/display/docs/glare.md``), ``glare_error_bound`` (radiance: no pixel
    differs from the exact convolution by more), ``glare_sources`` (pixels
    spread), ``glare_ms`` and ``tone_ms``."""
    return _display(radiance, exposure, tonemap, white, glare, fov_y, renderer, dither)


def display_scene(radiance: np.ndarray, scene: SceneLike, *, renderer: Renderer | None = None) -> np.ndarray:
    """:func:`display` with the settings of ``scene``'s ``"display"`` object and
    its camera's field of view (what ``airlight-demo`` writes to a PNG)."""
    loaded = load_scene(scene)
    settings = loaded["display"]
    return display(radiance, exposure=settings["exposure"], tonemap=settings["tonemap"],
                   white=settings.get("white"), glare=settings.get("glare"),
                   fov_y=loaded["camera"]["fov_y"], renderer=renderer, dither=settings["dither"])


def auto_exposure(radiance: np.ndarray) -> float:
    """The exposure ``display(radiance, exposure="auto")`` uses: 0.18 divided by
    the log-average Rec. 709 luminance ``exp(mean(ln Y))`` over the pixels with
    finite ``Y >= max(1e-6 * Y_median, FLT_MIN)``, ``Y_median`` the median of the
    luminances that are normal positive floats (black, negative, NaN, infinite,
    subnormal and near-zero pixels are ignored; adding zero or subnormal pixels
    never changes the exposure; ``effects/display/physics.md`` equation 5.1);
    1.0 when there is none."""
    return float(_core.auto_exposure(_radiance_array(radiance)))


def tone_curve(luminance: Any, tonemap: str = "loglog", white: float | None = None) -> np.ndarray:
    """The tone curve of :func:`display` applied to exposed luminance values
    (any shape, float32 result in [0, 1], before sRGB encoding); ``white=None``
    is the curve's default white point."""
    tonemap, w = _tonemap_args(tonemap, white)
    values = np.asarray(luminance, dtype=np.float32)
    return np.asarray(_core.tone_curve(np.ascontiguousarray(values), tonemap, w), dtype=np.float32)
