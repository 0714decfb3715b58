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

The public API is the names in ``__all__``, used as ``airlight.<name>``; the
modules that hold them are private (their layout may change):

- ``_scenes``: scene input, validation and the shipped presets;
- ``_rendering``: backends and the :class:`Renderer`;
- ``_display``: the display stage (exposure, tone curves, sRGB);
- ``_glare``: the eye's diffraction glare;
- ``_image_io``: PNG, PFM and OpenEXR files;
- ``_lights``: light helpers (headlights);
- ``_rainbow``: the raindrops' phase function for sunlight;
- ``photo`` (public): weather on a photograph with its depth (``airlight.photo.apply_weather``);
- ``_checks``: the argument checks they share;
- ``_core``: the native module (cpp/python_module.cpp).
"""

from . import _core as _core
from . import photo as photo
from ._display import (
    TONEMAPS,
    auto_exposure,
    display,
    display_report,
    display_scene,
    to_srgb8,
    tone_curve,
)
from ._falling_rain import rain_drops
from ._glare import GlareLike, glare
from ._image_io import load_exr, load_pfm, save_exr, save_pfm, save_png
from ._lights import headlights
from ._rainbow import rainbow_phase
from ._rendering import (
    LAYERS,
    OUTPUTS,
    BackendUnavailableError,
    Renderer,
    available_backends,
    backend_info,
    gl_unavailable_reason,
    render,
    table_stats,
)
from ._scenes import SceneLike, load_scene, preset, preset_names
from ._version import __version__ as __version__

__all__ = [
    "LAYERS",
    "OUTPUTS",
    "TONEMAPS",
    "BackendUnavailableError",
    "GlareLike",
    "Renderer",
    "SceneLike",
    "auto_exposure",
    "available_backends",
    "backend_info",
    "display",
    "display_report",
    "display_scene",
    "gl_unavailable_reason",
    "glare",
    "headlights",
    "load_exr",
    "load_pfm",
    "load_scene",
    "photo",
    "preset",
    "preset_names",
    "rain_drops",
    "rainbow_phase",
    "render",
    "save_exr",
    "save_pfm",
    "save_png",
    "table_stats",
    "to_srgb8",
    "tone_curve",
]
