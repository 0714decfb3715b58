"""Rendering: backend discovery and selection (``"gl"``, ``"cpu"``, ``"auto"``;
:func:`backend_info`), the :class:`Renderer` that keeps its backend's state across
frames, one-frame :func:`render`, the render outputs beside the radiance
(:data:`OUTPUTS`, :data:`LAYERS`), and :func:`table_stats` on the scattering tables
built."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any, overload

import numpy as np

from . import _core
from ._core import BackendUnavailableError
from ._scenes import SceneLike, _with_film_size

# The class is registered by the native module, which gives it no docstring.
BackendUnavailableError.__doc__ = (
    "Raised (a ``RuntimeError``) when the GL backend is asked for where it cannot run:\n"
    "``Renderer(\"gl\")`` with no working EGL device, GL disabled by ``AIRLIGHT_DISABLE_GL``\n"
    "or a build without EGL/OpenGL. The message gives the reason; ``backend=\"auto\"``\n"
    "falls back to the CPU instead (see :func:`gl_unavailable_reason`)."
)

_BACKENDS = ("auto", "gl", "cpu")

#: The outputs a render can return (``render(scene, outputs=[...])``), name ->
#: what it holds and its unit, in a fixed order: ``radiance``, ``depth``,
#: ``distance_z``, ``normal``, ``transmittance``, then the layers (:data:`LAYERS`).
OUTPUTS: dict[str, str] = {o["name"]: o["description"] for o in _core.render_outputs()}
#: The outputs that are layers of the radiance: parts that sum to it (each
#: effect declares its own), in the order of :data:`OUTPUTS`.
LAYERS: tuple[str, ...] = tuple(o["name"] for o in _core.render_outputs() if o["layer"])


def _output_names(outputs: object) -> list[str]:
    """The output names asked for, checked, ``"layers"`` expanded to every layer,
    each once in the order asked."""
    if isinstance(outputs, (str, bytes)) or not isinstance(outputs, Sequence):
        raise TypeError(f"outputs: expected a list of output names, got {type(outputs).__name__}")
    if len(outputs) == 0:
        raise ValueError("outputs: asks for no output (leave it out for the radiance alone)")
    names: list[str] = []
    for i, name in enumerate(outputs):
        if not isinstance(name, str):
            raise TypeError(f"outputs[{i}]: expected an output name (str), got {type(name).__name__}")
        if name == "layers":
            expanded = list(LAYERS)
        elif name in OUTPUTS:
            expanded = [name]
        else:
            raise ValueError(f"outputs[{i}]: unknown output {name!r}; one of {', '.join(OUTPUTS)}, "
                             f"or 'layers' (all of {', '.join(LAYERS)})")
        names += [n for n in expanded if n not in names]
    return names
_MAX_CPU_THREADS = 1024
_warned_fallback = False


def gl_unavailable_reason() -> str | None:
    """None when the GL backend can run here, else the reason it cannot."""
    ok, reason = _core.gl_backend_available()
    return None if ok else reason


def available_backends() -> list[str]:
    """The backends that can run on this machine: ``["gl", "cpu"]`` or ``["cpu"]``
    (``"gl"`` also where it is a software rasteriser: see :func:`backend_info`)."""
    return ["gl", "cpu"] if gl_unavailable_reason() is None else ["cpu"]


def backend_info() -> dict[str, Any]:
    """Which backend ``"auto"`` picks here, and the GL renderer it found:

    - ``"auto"``: ``"gl"`` or ``"cpu"``, what ``Renderer("auto")`` uses;
    - ``"gl_available"``: whether an OpenGL 4.5 context works (``backend="gl"`` runs);
    - ``"gl_renderer"``: its ``GL_RENDERER`` string (e.g. ``"llvmpipe (LLVM 15.0.6, 256
      bits)"``), None where GL cannot run;
    - ``"gl_software"``: True where that renderer is a software rasteriser (Mesa's
      llvmpipe, softpipe or swrast), which runs on the CPU's cores;
    - ``"gl_unavailable_reason"``: why GL cannot run, None where it can.

    ``"auto"`` is GL only on a hardware renderer: a software one shares the CPU backend's
    cores and pays a much larger set-up (README, "Measurements"); ask for ``"gl"`` to use
    it anyway.
    """
    return dict(_core.backend_info())


class Renderer:
    """Renders scenes, keeping the GL context, compiled shader variants and
    tables across frames so that animations pay the set-up once.

    ``backend`` is ``"gl"``, ``"cpu"`` or ``"auto"``: GL when an EGL device with a
    hardware GL renderer works; the CPU where the only GL renderer is a software
    rasteriser (llvmpipe), and where GL cannot run (then with one warning); see
    :func:`backend_info`. Asking for ``"gl"`` where it cannot run raises
    :class:`BackendUnavailableError`.
    """

    def __init__(self, backend: str = "auto", *, cpu_threads: int = 0) -> None:
        global _warned_fallback
        if not isinstance(backend, str):
            raise TypeError(f"backend: expected a string, got {type(backend).__name__}")
        if backend not in _BACKENDS:
            raise ValueError(f"backend: must be one of {', '.join(_BACKENDS)}, got {backend!r}")
        if backend == "auto":
            info = backend_info()
            backend = info["auto"]
            reason = info["gl_unavailable_reason"]
            if reason is not None:
                if not _warned_fallback:
                    warnings.warn(f"airlight: GL backend unavailable ({reason}); using the CPU backend",
                                  RuntimeWarning, stacklevel=2)
                    _warned_fallback = True
        if isinstance(cpu_threads, bool) or not isinstance(cpu_threads, int):
            raise TypeError(f"cpu_threads: expected an integer, got {type(cpu_threads).__name__}")
        if not 0 <= cpu_threads <= _MAX_CPU_THREADS:
            raise ValueError(f"cpu_threads: must be in [0, {_MAX_CPU_THREADS}] (0: all cores), "
                             f"got {cpu_threads}")
        self._native: _core.Renderer | None = _core.Renderer(backend)
        self._native.set_cpu_threads(cpu_threads)

    @property
    def backend(self) -> str:
        """The backend in use: ``"gl"`` or ``"cpu"``."""
        return self._active().backend

    @property
    def cpu_fallback_pixels(self) -> int:
        """Pixels of the last frame that the GL backend could not finish and
        recomputed on the CPU: Mesa's llvmpipe cuts a pixel's shader loops after
        65535 iterations in all (thousands of lamps or spots over lit
        surfaces). 0 on the CPU backend and for ordinary scenes."""
        return self._active().cpu_fallback_pixels

    def _active(self) -> _core.Renderer:
        if self._native is None:
            raise RuntimeError("Renderer is closed")
        return self._native

    @overload
    def render(self, scene: SceneLike, *, width: int | None = ..., height: int | None = ...,
               outputs: None = ...) -> np.ndarray: ...

    @overload
    def render(self, scene: SceneLike, *, width: int | None = ..., height: int | None = ...,
               outputs: Sequence[str]) -> dict[str, np.ndarray]: ...

    def render(self, scene: SceneLike, *, width: int | None = None, height: int | None = None,
               outputs: Sequence[str] | None = None) -> np.ndarray | dict[str, np.ndarray]:
        """Linear radiance of ``scene``: float32 array (height, width, 3), row 0
        on top. ``width``/``height`` override the scene's film size; one of them alone
        keeps the film's aspect ratio (``render(scene, width=160)`` of a 320x240 film
        is 160x120: the other side rounded to the nearest integer, at least 1).

        ``outputs``: names from :data:`OUTPUTS` (``"layers"`` for every layer); the
        result is then a dict of those names to float32 arrays, (height, width) for
        ``depth`` and ``distance_z``, (height, width, 3) for the others, all computed
        in the same pass. The layers (:data:`LAYERS`) sum to ``radiance``. A frame
        that asks for the radiance alone computes none of the others."""
        sized = _with_film_size(scene, width, height)
        if outputs is None:
            return self._active().render(sized)
        return self._active().render_outputs(sized, _output_names(outputs))

    def close(self) -> None:
        """Releases the GL context and everything cached (idempotent)."""
        self._native = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@overload
def render(scene: SceneLike, backend: str = ..., *, width: int | None = ..., height: int | None = ...,
           outputs: None = ...) -> np.ndarray: ...


@overload
def render(scene: SceneLike, backend: str = ..., *, width: int | None = ..., height: int | None = ...,
           outputs: Sequence[str]) -> dict[str, np.ndarray]: ...


def render(scene: SceneLike, backend: str = "auto", *, width: int | None = None,
           height: int | None = None,
           outputs: Sequence[str] | None = None) -> np.ndarray | dict[str, np.ndarray]:
    """Renders one frame; see :meth:`Renderer.render` (``outputs``: the render outputs
    beside the radiance) and :class:`Renderer` (which is faster for many frames)."""
    with Renderer(backend) as renderer:
        if outputs is None:
            return renderer.render(scene, width=width, height=height)
        return renderer.render(scene, width=width, height=height, outputs=outputs)


def table_stats() -> dict[str, dict[str, Any]]:
    """The scattering tables built so far in this process (each is built once, on
    first need): name -> width, height, bytes, build_seconds, builds. Empty until a
    scene with lamps in a scattering medium or a sky over an atmosphere or surfaces is
    rendered. The sky table ("sky_phase", effects/daytime/docs/daytime.md) is rebuilt when the sky or
    the species' phase functions change: ``builds`` counts its builds, the other
    fields describe the last one. ``resident``: how many of the tables of that name are
    in memory now; the tables of an animated parameter (a phase lobe's g, the sky) are
    cached for the last 8 values, the least recently used dropped first."""
    return dict(_core.tables_built())
