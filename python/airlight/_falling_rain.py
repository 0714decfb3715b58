"""Falling rain: the drops of the scene's rain field (:func:`rain_drops`; effects/falling_rain/physics.md)."""

from __future__ import annotations

import numpy as np

from . import _core
from ._scenes import SceneLike, load_scene


def rain_drops(scene: SceneLike) -> dict[str, np.ndarray]:
    """The drops of ``scene``'s ``falling_rain`` within their draw distances of the camera, in every
    direction, at the middle of the exposure (``camera.exposure_time`` ending at ``falling_rain.time``;
    effects/falling_rain/physics.md sections 2-3): ``position`` (n, 3) world metres, ``velocity`` (n, 3)
    m/s, ``diameter`` (n,) mm, ``weight`` (n,) their fade at the draw distance (eq. 2.2) and ``id`` (n,)
    uint64, the same for a drop in every frame (labels for datasets, tracking across an animation).
    A scene without falling rain, or with rate 0, has none. Raises what :func:`load_scene` raises, and
    ``ValueError`` naming the keys when more drops would be drawn than the renderer's bound."""
    return dict(_core.rain_drops(load_scene(scene)))
