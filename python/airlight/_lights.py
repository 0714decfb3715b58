"""Light helpers: light dicts for a scene's ``"lights"`` list (:func:`headlights`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from . import _core
from ._checks import _real, _rgb, _vec3

_LIMITS: dict[str, Any] = _core.scene_limits  # the scene format's bounds (include/airlight/scene_io.hpp)


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
               lens_intensity: float | Sequence[float] = 50.0, radius: float = 0.05,
               volumetric_shadows: bool = False) -> list[dict[str, Any]]:
    """A car's two headlights as light dicts for a scene's ``"lights"`` list.

    ``position`` is the car's front centre on the ground ``[x, y, z]`` (y is
    usually 0); ``heading`` the direction of travel in degrees, measured like
    the sun's azimuth: 0 is -z, 90 is +x, i.e. the direction
    ``(sin h, 0, -cos h)``. The two spot lights sit ``spacing`` metres apart,
    ``spacing / 2`` either side of the heading, ``height`` metres above
    ``position``, and shine along the heading tilted by ``pitch`` degrees
    (negative: down), with on-axis intensity ``intensity`` (W/sr, RGB),
    half-angle ``cone_angle`` (degrees, in [0.001, 90]) and edge softness ``edge``
    (in [0, 1]); see the README's scene format. ``radius`` is each lamp's
    emitting sphere. With ``lens_lamps=True`` two small point lamps of
    intensity ``lens_intensity`` and the same radius are added at the same
    places, so that the lenses are seen glowing from any direction.
    ``volumetric_shadows=True`` makes the surfaces cast shadows into the fog
    the beams light (effects/light_shafts/physics.md section 7).

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
    if not _LIMITS["min_cone_angle"] <= cone_angle <= 90:
        raise ValueError(f"cone_angle: must be in [{_LIMITS['min_cone_angle']:g}, 90], got {cone_angle!r}")
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
    lo, hi = _LIMITS["min_light_radius"], _LIMITS["max_light_radius"]
    if not lo <= radius <= hi:
        raise ValueError(f"radius: must be in [{lo:g}, {hi:g}], got {radius!r}")
    if not isinstance(volumetric_shadows, bool):
        raise TypeError(f"volumetric_shadows: expected a bool, got {type(volumetric_shadows).__name__}")

    sin_p, cos_p = _sin_cos_degrees(pitch)
    forward = (sin_h, 0.0, -cos_h)
    right = (cos_h, 0.0, sin_h)  # forward x up
    direction = [cos_p * forward[0] + 0.0, sin_p + 0.0, cos_p * forward[2] + 0.0]  # + 0.0: no -0.0
    places = [[origin[0] + side * 0.5 * spacing * right[0] + 0.0, origin[1] + height + 0.0,
               origin[2] + side * 0.5 * spacing * right[2] + 0.0] for side in (-1.0, 1.0)]
    lights: list[dict[str, Any]] = [
        {"type": "spot", "position": list(at), "direction": list(direction), "intensity": list(rgb),
         "cone_angle": cone_angle, "edge": edge, "radius": radius, "volumetric_shadows": volumetric_shadows}
        for at in places
    ]
    if lens_lamps:
        lights += [{"type": "point", "position": list(at), "intensity": list(lens_rgb), "radius": radius}
                   for at in places]
    return lights
