"""Scenes: the ``SceneLike`` inputs, validation and normalisation
(:func:`load_scene`), and the presets shipped in the package's ``scenes/``
directory (:func:`preset`, :func:`preset_names`)."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Union

from . import _core

SceneLike = Union[Mapping[str, Any], str, "os.PathLike[str]"]
"""A scene dict, a path to a JSON scene file, or JSON text."""

_SCENES_DIR = Path(__file__).resolve().parent / "scenes"
_MAX_FILM_SIZE: int = _core.scene_limits["max_film_size"]
_MAX_SCENE_FILE_BYTES: int = _core.scene_limits["max_scene_file_bytes"]


def _scene_source(scene: SceneLike) -> Any:
    """What the native validator takes: a dict, or JSON text read from a file."""
    if isinstance(scene, Mapping):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        text = os.fspath(scene)
        if isinstance(scene, str) and text.lstrip("\ufeff \t\r\n").startswith("{"):
            return text.lstrip("\ufeff")  # JSON text, a byte order mark or not
        try:
            # At most _MAX_SCENE_FILE_BYTES: '/dev/zero' or a huge file is refused, not read whole.
            with open(text, "rb") as f:
                data = f.read(_MAX_SCENE_FILE_BYTES + 1)
        except FileNotFoundError:
            raise ValueError(f"scene file not found: {text}") from None
        except OSError as exc:
            raise ValueError(f"cannot read scene file {text}: {exc.strerror}") from None
        except ValueError as exc:  # an embedded NUL in the path
            raise ValueError(f"cannot read scene file {text!r}: {exc}") from None
        if len(data) > _MAX_SCENE_FILE_BYTES:
            raise ValueError(f"scene file {text} is larger than {_MAX_SCENE_FILE_BYTES >> 20} MiB")
        try:
            return data.decode("utf-8-sig")
        except UnicodeError as exc:
            raise ValueError(f"cannot read scene file {text!r}: {exc}") from None
    raise TypeError(f"scene: expected a dict, a path or JSON text, got {type(scene).__name__}")


def load_scene(scene: SceneLike) -> dict[str, Any]:
    """Validates a scene and returns it normalised: every default filled in and
    every RGB value expanded to a list of three floats.

    Raises ``TypeError``/``ValueError`` naming the offending field.
    """
    return json.loads(_core.validate_scene(_scene_source(scene)))


def _is_film_size(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= _MAX_FILM_SIZE


def _with_film_size(scene: SceneLike, width: int | None, height: int | None) -> Any:
    """The scene source of ``scene`` with its film size overridden where given: one of
    ``width`` and ``height`` alone keeps the film's aspect ratio (the other side rounded,
    at least 1; ``airlight::resize_film``). Bad values are left for the validator to name."""
    source = _scene_source(scene)
    if width is None and height is None:
        return source
    # A shallow copy: only "film" changes (a deep copy of a deeply nested dict raised RecursionError).
    try:
        data = json.loads(source) if isinstance(source, str) else dict(source)
    except RecursionError:
        raise ValueError("scene: nesting too deep") from None
    except json.JSONDecodeError:
        return source  # the validator names the error
    film = data.get("film")
    film = dict(film) if isinstance(film, Mapping) else {}
    given = width if height is None else height if width is None else None
    if given is not None and _is_film_size(given) and all(
            _is_film_size(film.get(k)) for k in ("width", "height")):
        width, height = _core.resize_film(film["width"], film["height"], width or 0, height or 0)
    if width is not None:
        film["width"] = width
    if height is not None:
        film["height"] = height
    data["film"] = film
    return data


def preset_names() -> list[str]:
    """Names of the scenes shipped with airlight (``preset(name)`` loads one)."""
    return sorted(p.stem for p in _SCENES_DIR.glob("*.json"))


def preset(name: str) -> dict[str, Any]:
    """A shipped scene as a dict (edit it freely before rendering)."""
    path = _SCENES_DIR / f"{name}.json"
    if not path.is_file():
        raise ValueError(f"preset: unknown preset {name!r}; available: {', '.join(preset_names())}")
    return json.loads(path.read_text(encoding="utf-8"))
