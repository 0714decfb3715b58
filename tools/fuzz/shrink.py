"""A greedy shrinker for failing scenes.

Given a scene and a predicate ("does it still fail the same way?"), it tries simpler
scenes, largest simplifications first, and keeps each one that still fails: drop a
top-level key, halves and then single elements of the lights and surfaces, keys of any
object, a spot replaced by a point lamp, a phase function by the isotropic one, a smaller
film, RGB triples collapsed to one number, numbers replaced by 0 or 1 or rounded to fewer
significant digits. It stops when a whole pass changes nothing or the budget is spent.
Candidates the predicate cannot judge (e.g. invalid scenes, for a valid-scene finding)
must make it return False.
"""

from __future__ import annotations

import copy
import json
import math
import time
from collections.abc import Iterator
from typing import Any, Callable

from .mutate import Path

Scene = dict[str, Any]
_REQUIRED_TOP = ("film", "camera")


def _get(node: Any, path: Path) -> Any:
    for p in path:
        node = node[p]
    return node


def _replaced(scene: Scene, path: Path, value: Any) -> Scene:
    out = copy.deepcopy(scene)
    parent = _get(out, path[:-1])
    parent[path[-1]] = value
    return out


def _removed(scene: Scene, path: Path) -> Scene:
    out = copy.deepcopy(scene)
    parent = _get(out, path[:-1])
    if isinstance(parent, dict):
        del parent[path[-1]]
    else:
        parent.pop(path[-1])
    return out


def _round(x: float, digits: int) -> float:
    if x == 0 or not math.isfinite(x):
        return x
    return float(f"{x:.{digits}g}")


def _numbers(node: Any, path: Path = ()) -> Iterator[tuple[Path, float]]:
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _numbers(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _numbers(v, (*path, i))
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield path, float(node)


def _objects(node: Any, path: Path = ()) -> Iterator[tuple[Path, dict[str, Any]]]:
    if isinstance(node, dict):
        yield path, node
        for k, v in node.items():
            yield from _objects(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _objects(v, (*path, i))


def candidates(scene: Scene) -> Iterator[Scene]:
    """Simpler variants of ``scene``, the largest simplifications first."""
    for key in list(scene):
        if key not in _REQUIRED_TOP:
            yield _removed(scene, (key,))
    for key in ("lights", "surfaces"):
        items = scene.get(key)
        if isinstance(items, list) and len(items) > 1:
            half = len(items) // 2
            yield _replaced(scene, (key,), items[:half])
            yield _replaced(scene, (key,), items[half:])
            for i in range(len(items)):
                yield _removed(scene, (key, i))
    for path, obj in list(_objects(scene)):
        if path == ():
            continue
        for key in list(obj):
            if key != "type":
                yield _removed(scene, (*path, key))
    for i, light in enumerate(scene.get("lights") or []):
        if isinstance(light, dict) and light.get("type") == "spot":
            point = {k: light[k] for k in ("position", "intensity", "radius") if k in light}
            yield _replaced(scene, ("lights", i), {"type": "point", **point})
    medium = scene.get("medium")
    phase = medium.get("phase") if isinstance(medium, dict) else None
    if isinstance(phase, dict) and phase.get("type") != "isotropic":
        yield _replaced(scene, ("medium", "phase"), {"type": "isotropic"})
    film = scene.get("film")
    if isinstance(film, dict):
        w, h = film.get("width"), film.get("height")
        if isinstance(w, int) and isinstance(h, int):
            for size in ((1, 1), (w // 2, h), (w, h // 2), (w - 1, h), (w, h - 1)):
                if size[0] >= 1 and size[1] >= 1 and size != (w, h):
                    yield _replaced(scene, ("film",), {"width": size[0], "height": size[1]})
    for path, obj in list(_objects(scene)):
        for key, value in obj.items():
            triple = isinstance(value, list) and len(value) == 3
            if triple and all(isinstance(x, (int, float)) for x in value):
                yield _replaced(scene, (*path, key), value[0])
                yield _replaced(scene, (*path, key), max(value))
    for path, x in list(_numbers(scene)):
        simpler = [0.0, 1.0, -1.0] + [_round(x, d) for d in (1, 2, 3)]
        if abs(x) > 1 and x != round(x):
            simpler.append(float(round(x)))
        tried = set()
        for s in simpler:
            if s != x and s not in tried and _size(s) < _size(x):
                tried.add(s)
                number: Any = int(s) if isinstance(_get(scene, path), int) and s == int(s) else s
                yield _replaced(scene, path, number)


def _size(x: float) -> tuple[int, float]:
    """An order on numbers by simplicity: fewer significant digits first, then magnitude."""
    if x == 0:
        return (0, 0.0)
    digits = len(f"{abs(x):.9g}".replace(".", "").replace("-", "").split("e")[0].strip("0"))
    return (digits, abs(math.log10(abs(x))) if math.isfinite(x) else 1e9)


def shrink(scene: Scene, still_fails: Callable[[Scene], bool], *, budget_seconds: float = 120.0,
           max_attempts: int = 400, progress: Callable[[str], None] | None = None) -> tuple[Scene, int]:
    """The simplest scene found that still fails, and the number of attempts made."""
    best = copy.deepcopy(scene)
    deadline = time.monotonic() + budget_seconds
    attempts = 0
    rejected: set[str] = set()  # candidates that passed: not tried again in later passes
    improved = True
    while improved:
        improved = False
        for candidate in candidates(best):
            key = _json_text(candidate)
            if key in rejected:
                continue
            if attempts >= max_attempts or time.monotonic() > deadline:
                return best, attempts
            attempts += 1
            if not still_fails(candidate):
                rejected.add(key)
            else:
                best = candidate
                improved = True
                if progress is not None:
                    progress(f"shrinking: {attempts} tries, {len(_json_text(best))} characters")
                break
    return best, attempts


def _json_text(scene: Scene) -> str:
    try:
        return json.dumps(scene, sort_keys=True)
    except (TypeError, ValueError):
        return repr(scene)
