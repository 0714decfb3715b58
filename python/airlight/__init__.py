"""airlight: fast and accurate rendering of light scattering in bad weather.

Scenes are plain dicts (or JSON files / JSON text) in the format documented in
the README; they are validated on load and bad input raises ``TypeError`` or
``ValueError`` whose message starts with the offending field
(``"camera.fov_y: ..."``). Rendering returns linear radiance, W/(m^2 sr), as a
float32 array of shape (height, width, 3) with row 0 on top.

Quick start::

    import airlight
    img = airlight.render(airlight.preset("default"))
    airlight.save_png("out.png", img, exposure=1.0)
"""

from __future__ import annotations

import copy
import json
import math
import numbers
import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, Union

import numpy as np

from . import _core
from ._core import BackendUnavailableError

__all__ = [
    "TONEMAPS",
    "BackendUnavailableError",
    "Renderer",
    "SceneLike",
    "auto_exposure",
    "available_backends",
    "display",
    "display_report",
    "display_scene",
    "gl_unavailable_reason",
    "glare",
    "headlights",
    "load_pfm",
    "load_scene",
    "preset",
    "preset_names",
    "rainbow_phase",
    "render",
    "save_pfm",
    "save_png",
    "table_stats",
    "to_srgb8",
    "tone_curve",
]

SceneLike = Union[Mapping[str, Any], str, "os.PathLike[str]"]
"""A scene dict, a path to a JSON scene file, or JSON text."""

_SCENES_DIR = Path(__file__).resolve().parent / "scenes"
_BACKENDS = ("auto", "gl", "cpu")
_warned_fallback = False


def _scene_source(scene: SceneLike) -> Any:
    """What the native validator takes: a dict, or JSON text read from a file."""
    if isinstance(scene, Mapping):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        text = os.fspath(scene)
        if isinstance(scene, str) and text.lstrip().startswith("{"):
            return text
        try:
            return Path(text).read_text(encoding="utf-8")
        except OSError as exc:
            raise ValueError(f"path: cannot read scene file {text!r}: {exc.strerror}") from None
        except (ValueError, UnicodeError) as exc:  # embedded NUL, undecodable bytes
            raise ValueError(f"path: cannot read scene file {text!r}: {exc}") from None
    raise TypeError(f"scene: expected a dict, a path or JSON text, got {type(scene).__name__}")


def load_scene(scene: SceneLike) -> dict[str, Any]:
    """Validates a scene and returns it normalised: every default filled in and
    every RGB value expanded to a list of three floats.

    Raises ``TypeError``/``ValueError`` naming the offending field.
    """
    return json.loads(_core.validate_scene(_scene_source(scene)))


def _with_film_size(scene: SceneLike, width: int | None, height: int | None) -> Any:
    source = _scene_source(scene)
    if width is None and height is None:
        return source
    data = json.loads(source) if isinstance(source, str) else copy.deepcopy(dict(source))
    film = data.get("film")
    film = dict(film) if isinstance(film, Mapping) else {}
    if width is not None:
        film["width"] = width
    if height is not None:
        film["height"] = height
    data["film"] = film
    return data


def gl_unavailable_reason() -> str | None:
    """None when the GL backend can run here, else the reason it cannot."""
    ok, reason = _core.gl_backend_available()
    return None if ok else reason


def available_backends() -> list[str]:
    """The backends that can run on this machine: ``["gl", "cpu"]`` or ``["cpu"]``."""
    return ["gl", "cpu"] if gl_unavailable_reason() is None else ["cpu"]


class Renderer:
    """Renders scenes, keeping the GL context, compiled shader variants and
    tables across frames so that animations pay the set-up once.

    ``backend`` is ``"gl"``, ``"cpu"`` or ``"auto"`` (GL when an EGL device
    works, otherwise CPU with one warning). Asking for ``"gl"`` where it cannot
    run raises :class:`BackendUnavailableError`.
    """

    def __init__(self, backend: str = "auto", *, cpu_threads: int = 0) -> None:
        global _warned_fallback
        if not isinstance(backend, str):
            raise TypeError(f"backend: expected a string, got {type(backend).__name__}")
        if backend not in _BACKENDS:
            raise ValueError(f"backend: must be one of {', '.join(_BACKENDS)}, got {backend!r}")
        if backend == "auto":
            reason = gl_unavailable_reason()
            if reason is None:
                backend = "gl"
            else:
                backend = "cpu"
                if not _warned_fallback:
                    warnings.warn(f"airlight: GL backend unavailable ({reason}); using the CPU backend",
                                  RuntimeWarning, stacklevel=2)
                    _warned_fallback = True
        if not isinstance(cpu_threads, int) or cpu_threads < 0:
            raise ValueError(f"cpu_threads: must be an integer >= 0, got {cpu_threads!r}")
        self._native: _core.Renderer | None = _core.Renderer(backend)
        self._native.set_cpu_threads(cpu_threads)

    @property
    def backend(self) -> str:
        """The backend in use: ``"gl"`` or ``"cpu"``."""
        return self._active().backend

    def _active(self) -> _core.Renderer:
        if self._native is None:
            raise RuntimeError("Renderer is closed")
        return self._native

    def render(self, scene: SceneLike, *, width: int | None = None,
               height: int | None = None) -> np.ndarray:
        """Linear radiance of ``scene``: float32 array (height, width, 3), row 0
        on top. ``width``/``height`` override the scene's film size."""
        return self._active().render(_with_film_size(scene, width, height))

    def close(self) -> None:
        """Releases the GL context and everything cached (idempotent)."""
        self._native = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def render(scene: SceneLike, backend: str = "auto", *, width: int | None = None,
           height: int | None = None) -> np.ndarray:
    """Renders one frame; see :class:`Renderer` (which is faster for many frames)."""
    with Renderer(backend) as renderer:
        return renderer.render(scene, width=width, height=height)


def to_srgb8(radiance: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """8-bit sRGB image (uint8, same shape) of ``radiance * exposure`` clipped to [0, 1]."""
    if not np.isfinite(exposure) or exposure < 0:
        raise ValueError(f"exposure: must be finite and >= 0, got {exposure!r}")
    return _core.to_srgb8(np.asarray(radiance, dtype=np.float32), float(exposure))


TONEMAPS = ("linear", "loglog", "reinhard", "filmic")
"""The tone curves of :func:`display` (see its docstring)."""


def _radiance_array(radiance: Any) -> np.ndarray:
    """``radiance`` as a float32 (height, width, 3) array; TypeError/ValueError naming it."""
    if not isinstance(radiance, np.ndarray):
        raise TypeError(f"radiance: expected a numpy array, got {type(radiance).__name__}")
    if radiance.dtype.kind not in "fiu" or radiance.dtype == np.bool_:
        raise TypeError(f"radiance: expected a real-valued array, got dtype {radiance.dtype}")
    if radiance.ndim != 3 or radiance.shape[2] != 3:
        raise ValueError(f"radiance: expected shape (height, width, 3), got {radiance.shape}")
    return np.ascontiguousarray(radiance, dtype=np.float32)


def _tonemap_args(tonemap: Any, white: Any) -> tuple[str, float | None]:
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


def _display(radiance: Any, exposure: Any, tonemap: Any, white: Any, glare: Any, fov_y: Any,
             renderer: Renderer | None) -> tuple[np.ndarray, dict[str, Any]]:
    image = _radiance_array(radiance)
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
    out, report = _core.display(image, manual, tonemap, w, enabled, pupil, eyelashes, fov, native)
    return out, dict(report)


def display(radiance: np.ndarray, *, exposure: str | float = "auto", tonemap: str = "loglog",
            white: float | None = None, glare: GlareLike = None, fov_y: float | None = None,
            renderer: Renderer | None = None) -> np.ndarray:
    """What the eye sees: 8-bit sRGB (uint8, shape (height, width, 3)) of linear
    radiance (float (height, width, 3), e.g. from :func:`render`), computed by
    the native display stage: on the CPU (multithreaded), or on ``renderer``'s
    backend when given (the GL backend runs the glare and the tone curve on the
    GPU; the same per-pixel code, ``shaders/display.glsl``).

    Steps: optional glare (below); each channel is multiplied by the exposure
    (NaN, negative and infinite values count as 0); the tone curve is applied
    to the Rec. 709 luminance ``Y = 0.2126 R + 0.7152 G + 0.0722 B`` and the
    pixel scaled by ``f(Y) / Y`` (colours keep their chromaticity; channels
    above 1 clip); then the sRGB OETF (IEC 61966-2-1) and rounding to 8 bits.

    - ``exposure``: ``"auto"`` (default) maps the log-average luminance of
      the pixels with finite ``Y > 0`` to the key 0.18 (Reinhard et al. 2002);
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
      ``docs/glare.md``), ``None`` (off), ``True`` or
      ``{"pupil_diameter": mm in [1, 9] or "auto", "eyelashes": bool}``;
      ``"auto"`` takes the pupil from the image's log-average luminance
      (Moon & Spencer). Light the glare would visibly move is spread
      exactly; light whose glare provably moves no 8-bit value by more than
      one step stays in place, and with nothing to spread the convolution is
      skipped (``docs/glare.md``). Needs ``fov_y``.
    - ``fov_y``: the camera's vertical field of view in degrees (the glare's
      angle per pixel).

    Bad arguments raise ``TypeError``/``ValueError`` naming the argument
    (``"exposure: must be >= 0, got -1"``). :func:`display_report` returns
    what was done as well.
    """
    return _display(radiance, exposure, tonemap, white, glare, fov_y, renderer)[0]


def display_report(radiance: np.ndarray, *, exposure: str | float = "auto", tonemap: str = "loglog",
                   white: float | None = None, glare: GlareLike = None, fov_y: float | None = None,
                   renderer: Renderer | None = None) -> tuple[np.ndarray, dict[str, Any]]:
    """:func:`display` and what it did: ``exposure`` and ``white`` used,
    ``glare`` (``"off"``, ``"skipped"`` when no pixel is bright enough,
    ``"sparse"`` (splats on the CPU, on either backend), ``"fft"`` on the
    CPU, ``"gl-fft"`` on GL),
    ``pupil_diameter`` (mm), ``glare_kernel_radius`` (pixels),
    ``glare_threshold`` (radiance: the excess of each channel over it is
    spread, see ``docs/glare.md``), ``glare_error_bound`` (radiance: no pixel
    differs from the exact convolution by more), ``glare_sources`` (pixels
    spread), ``glare_ms`` and ``tone_ms``."""
    return _display(radiance, exposure, tonemap, white, glare, fov_y, renderer)


def display_scene(radiance: np.ndarray, scene: SceneLike, *, renderer: Renderer | None = None) -> np.ndarray:
    """:func:`display` with the settings of ``scene``'s ``"display"`` object and
    its camera's field of view (what ``airlight-demo`` writes to a PNG)."""
    loaded = load_scene(scene)
    settings = loaded["display"]
    return display(radiance, exposure=settings["exposure"], tonemap=settings["tonemap"],
                   white=settings.get("white"), glare=settings.get("glare"),
                   fov_y=loaded["camera"]["fov_y"], renderer=renderer)


def auto_exposure(radiance: np.ndarray) -> float:
    """The exposure ``display(radiance, exposure="auto")`` uses: 0.18 divided by
    the log-average Rec. 709 luminance ``exp(mean(ln Y))`` over the pixels with
    finite ``Y > 0`` (black, negative, NaN and infinite pixels are ignored); 1.0
    when there is none."""
    return float(_core.auto_exposure(_radiance_array(radiance)))


def tone_curve(luminance: Any, tonemap: str = "loglog", white: float | None = None) -> np.ndarray:
    """The tone curve of :func:`display` applied to exposed luminance values
    (any shape, float32 result in [0, 1], before sRGB encoding); ``white=None``
    is the curve's default white point."""
    tonemap, w = _tonemap_args(tonemap, white)
    values = np.asarray(luminance, dtype=np.float32)
    return np.asarray(_core.tone_curve(np.ascontiguousarray(values), tonemap, w), dtype=np.float32)


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
    1 per channel: glare moves light, it does not create it (docs/glare.md).
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


def save_png(path: str | os.PathLike[str], radiance: np.ndarray, exposure: float = 1.0) -> None:
    """Writes ``radiance * exposure`` as an 8-bit sRGB PNG (through Pillow)."""
    from PIL import Image

    Image.fromarray(to_srgb8(radiance, exposure), mode="RGB").save(os.fspath(path), format="PNG")


def save_pfm(path: str | os.PathLike[str], radiance: np.ndarray) -> None:
    """Writes linear radiance as a portable float map (HDR, little-endian)."""
    _core.write_pfm(os.fspath(path), np.asarray(radiance, dtype=np.float32))


def load_pfm(path: str | os.PathLike[str]) -> np.ndarray:
    """Reads a colour portable float map into a float32 (height, width, 3) array, row 0 on top."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            raise ValueError(f"path: {os.fspath(path)!r} is not a colour PFM file")
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.frombuffer(f.read(width * height * 12), dtype=dtype).reshape(height, width, 3)
    return data[::-1].astype(np.float32)


def table_stats() -> dict[str, dict[str, Any]]:
    """The scattering tables built so far in this process (each is built once, on
    first need): name -> width, height, bytes, build_seconds, builds. Empty until a
    scene with lamps in a scattering medium or a sky over an atmosphere or surfaces is
    rendered. The sky table ("sky_phase", docs/daytime.md) is rebuilt when the sky or
    the species' phase functions change: ``builds`` counts its builds, the other
    fields describe the last one."""
    return dict(_core.tables_built())


def rainbow_phase(rate: float, angles_deg: Any = None, *, wavelengths: int = 33) -> np.ndarray:
    """The raindrops' phase function for sunlight that the renderer uses (rain with
    ``"phase": "mie"``; MODELS.md section 4, docs/rainbow.md): Lorenz-Mie, averaged over
    the Marshall-Palmer drop sizes of ``rate`` (mm/h), seen through the sun's
    0.53-degree disc, converted from ``wavelengths`` spectral nodes (3, 5, 9, 17 or 33) to
    linear sRGB (CIE 1931, D65). Returns float32 (n, 3) in sr^-1 at ``angles_deg``
    (scattering angles, 0 = forward; default: the table's own 0.05-degree grid),
    interpolated linearly in angle as the shaders do."""
    r = _real("rate", rate)
    if r <= 0.0:
        raise ValueError(f"rate: must be positive (mm/h), got {rate!r}")
    if isinstance(wavelengths, bool) or not isinstance(wavelengths, numbers.Integral):
        raise TypeError(f"wavelengths: expected an integer, got {type(wavelengths).__name__}")
    table = _core.rainbow_phase_table(r, int(wavelengths))[:, :3]
    grid = np.linspace(0.0, 180.0, table.shape[0])
    if angles_deg is None:
        return table.copy()
    a = np.asarray(angles_deg, dtype=np.float64)
    if a.ndim != 1 or not np.all(np.isfinite(a)) or np.any((a < 0.0) | (a > 180.0)):
        raise ValueError("angles_deg: must be a 1-D array of angles in [0, 180] degrees")
    return np.stack([np.interp(a, grid, table[:, c]) for c in range(3)], axis=1).astype(np.float32)


def _real(name: str, value: Any) -> float:
    """``value`` as a finite float; TypeError/ValueError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {value!r}")
    return x


def _vec3(name: str, value: Any) -> list[float]:
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise TypeError(f"{name}: expected a list of 3 numbers, got {type(value).__name__}")
    if len(value) != 3:
        raise ValueError(f"{name}: expected a list of exactly 3 numbers, got {len(value)}")
    return [_real(f"{name}[{i}]", v) for i, v in enumerate(value)]


def _rgb(name: str, value: Any) -> list[float]:
    """An RGB value (a number or 3 numbers), each channel finite and >= 0."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        rgb = [_real(name, value)] * 3
    else:
        rgb = _vec3(name, value)
    if any(c < 0 for c in rgb):
        raise ValueError(f"{name}: must be >= 0, got {value!r}")
    return rgb


def _sin_cos_degrees(angle: float) -> tuple[float, float]:
    """(sin, cos) of an angle in degrees, exact at multiples of 90."""
    quarter, rest = divmod(angle, 90.0)
    if rest == 0:
        return ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0))[int(quarter) % 4]
    a = math.radians(angle)
    return math.sin(a), math.cos(a)


def headlights(position: Sequence[float], heading: float, *, spacing: float = 1.4, height: float = 0.65,
               intensity: float | Sequence[float] = (20000.0, 19000.0, 17000.0), cone_angle: float = 25.0,
               edge: float = 0.15, pitch: float = -2.0, lens_lamps: bool = False,
               lens_intensity: float | Sequence[float] = 50.0, radius: float = 0.05) -> list[dict[str, Any]]:
    """A car's two headlights as light dicts for a scene's ``"lights"`` list.

    ``position`` is the car's front centre on the ground ``[x, y, z]`` (y is
    usually 0); ``heading`` the direction of travel in degrees, measured like
    the sun's azimuth: 0 is -z, 90 is +x, i.e. the direction
    ``(sin h, 0, -cos h)``. The two spot lights sit ``spacing`` metres apart,
    ``spacing / 2`` either side of the heading, ``height`` metres above
    ``position``, and shine along the heading tilted by ``pitch`` degrees
    (negative: down), with on-axis intensity ``intensity`` (W/sr, RGB),
    half-angle ``cone_angle`` (degrees, in (0, 90]) and edge softness ``edge``
    (in [0, 1]); see the README's scene format. ``radius`` is each lamp's
    emitting sphere. With ``lens_lamps=True`` two small point lamps of
    intensity ``lens_intensity`` and the same radius are added at the same
    places, so that the lenses are seen glowing from any direction.

    Returns ``[left spot, right spot]`` (left and right as seen from the
    driver's seat), followed by ``[left lamp, right lamp]`` with
    ``lens_lamps``. Bad arguments raise ``TypeError``/``ValueError`` whose
    message starts with the argument's name.
    """
    origin = _vec3("position", position)
    sin_h, cos_h = _sin_cos_degrees(_real("heading", heading))
    spacing = _real("spacing", spacing)
    if spacing <= 0:
        raise ValueError(f"spacing: must be > 0, got {spacing!r}")
    height = _real("height", height)
    if height < 0:
        raise ValueError(f"height: must be >= 0, got {height!r}")
    rgb = _rgb("intensity", intensity)
    cone_angle = _real("cone_angle", cone_angle)
    if not 0 < cone_angle <= 90:
        raise ValueError(f"cone_angle: must be in (0, 90], got {cone_angle!r}")
    edge = _real("edge", edge)
    if not 0 <= edge <= 1:
        raise ValueError(f"edge: must be in [0, 1], got {edge!r}")
    pitch = _real("pitch", pitch)
    if not -90 <= pitch <= 90:
        raise ValueError(f"pitch: must be in [-90, 90], got {pitch!r}")
    if not isinstance(lens_lamps, bool):
        raise TypeError(f"lens_lamps: expected a bool, got {type(lens_lamps).__name__}")
    lens_rgb = _rgb("lens_intensity", lens_intensity)
    radius = _real("radius", radius)
    if not 0 < radius <= 1000:
        raise ValueError(f"radius: must be in (0, 1000], got {radius!r}")

    sin_p, cos_p = _sin_cos_degrees(pitch)
    forward = (sin_h, 0.0, -cos_h)
    right = (cos_h, 0.0, sin_h)  # forward x up
    direction = [cos_p * forward[0] + 0.0, sin_p + 0.0, cos_p * forward[2] + 0.0]  # + 0.0: no -0.0
    places = [[origin[0] + side * 0.5 * spacing * right[0] + 0.0, origin[1] + height + 0.0,
               origin[2] + side * 0.5 * spacing * right[2] + 0.0] for side in (-1.0, 1.0)]
    lights: list[dict[str, Any]] = [
        {"type": "spot", "position": list(at), "direction": list(direction), "intensity": list(rgb),
         "cone_angle": cone_angle, "edge": edge, "radius": radius}
        for at in places
    ]
    if lens_lamps:
        lights += [{"type": "point", "position": list(at), "intensity": list(lens_rgb), "radius": radius}
                   for at in places]
    return lights


def preset_names() -> list[str]:
    """Names of the scenes shipped with airlight (``preset(name)`` loads one)."""
    return sorted(p.stem for p in _SCENES_DIR.glob("*.json"))


def preset(name: str) -> dict[str, Any]:
    """A shipped scene as a dict (edit it freely before rendering)."""
    path = _SCENES_DIR / f"{name}.json"
    if not path.is_file():
        raise ValueError(f"preset: unknown preset {name!r}; available: {', '.join(preset_names())}")
    return json.loads(path.read_text(encoding="utf-8"))
