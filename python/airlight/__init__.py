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
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Union

import numpy as np

from . import _core
from ._core import BackendUnavailableError

__all__ = [
    "BackendUnavailableError",
    "Renderer",
    "SceneLike",
    "available_backends",
    "gl_unavailable_reason",
    "load_pfm",
    "load_scene",
    "preset",
    "preset_names",
    "render",
    "save_pfm",
    "save_png",
    "table_stats",
    "to_srgb8",
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
    first need): name -> width, height, bytes, build_seconds. Empty until a scene
    with lamps in a scattering medium is rendered."""
    return dict(_core.tables_built())


def preset_names() -> list[str]:
    """Names of the scenes shipped with airlight (``preset(name)`` loads one)."""
    return sorted(p.stem for p in _SCENES_DIR.glob("*.json"))


def preset(name: str) -> dict[str, Any]:
    """A shipped scene as a dict (edit it freely before rendering)."""
    path = _SCENES_DIR / f"{name}.json"
    if not path.is_file():
        raise ValueError(f"preset: unknown preset {name!r}; available: {', '.join(preset_names())}")
    return json.loads(path.read_text(encoding="utf-8"))
