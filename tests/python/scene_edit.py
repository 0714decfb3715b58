"""Test helpers: mutations of a scene dict at a dotted/indexed field path
("surfaces[1].max"), used to build bad-input cases."""

from __future__ import annotations

import re
from typing import Any, Callable


def _keys(path: str) -> list[Any]:
    return [int(k) if k.isdigit() else k for k in re.findall(r"[^.\[\]]+", path)]


def set_at(path: str, value: Any) -> Callable[[dict], None]:
    """Mutation setting the field at ``path`` to ``value``."""
    keys = _keys(path)

    def mutate(scene: dict) -> None:
        node = scene
        for k in keys[:-1]:
            node = node[k]
        node[keys[-1]] = value

    return mutate


def delete_at(path: str) -> Callable[[dict], None]:
    """Mutation removing the field at ``path``."""
    keys = _keys(path)

    def mutate(scene: dict) -> None:
        node = scene
        for k in keys[:-1]:
            node = node[k]
        del node[keys[-1]]

    return mutate
