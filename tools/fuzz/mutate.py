"""Bad input: random mutations of valid scenes, and the check of what the loader answers.

A mutation picks one place in a valid scene (a key of an object or an element of a list,
at any depth) and breaks it: a value of the wrong type, an out-of-range or non-finite
number, an unknown or misspelt key, a removed key, a huge list, a deep nesting, a
non-string key, an unencodable string, a Python type JSON has not got. The loader must
answer ``TypeError`` or ``ValueError`` whose message starts with a field path related to
the mutated place (the place itself, an object around it, a field inside it, or a sibling:
``camera.look_at`` for a broken ``camera.position``), or accept the scene if the mutation
happened to keep it valid. Anything else (another exception type, a message without a
field path or naming an unrelated field, a crash, a hang) is a finding.
"""

from __future__ import annotations

import copy
import math
import random
import re
from dataclasses import dataclass
from typing import Any

Path = tuple[Any, ...]

# A key is an identifier or "" (the loader's name for an empty key), an index [i].
_KEY = r'(?:[A-Za-z_][A-Za-z0-9_]*|"")'
_PATH_RE = re.compile(rf"^((?:{_KEY}|\[\d+\])(?:\.{_KEY}|\[\d+\])*): ")

# Fields whose validity depends on another top-level key (the CIE sky's sun, README "sky").
_CROSS_FIELDS = {("sun",): {"sky"}, ("sky",): {"sun"}}


@dataclass
class Mutation:
    """A broken scene, the place broken (``path``) and what was done (``what``)."""

    scene: Any
    path: Path
    what: str


def format_path(path: Path) -> str:
    """``("lights", 2, "intensity")`` -> ``"lights[2].intensity"``."""
    out = ""
    for p in path:
        if isinstance(p, int):
            out += f"[{p}]"
        else:
            out += ("." if out else "") + (str(p) if p != "" else '""')
    return out


def parse_path(text: str) -> Path:
    """The inverse of :func:`format_path`."""
    return tuple(int(p[1:-1]) if p.startswith("[") else ("" if p == '""' else p)
                 for p in re.findall(r"\[\d+\]|[^.\[\]]+", text))


def _places(node: Any, path: Path = ()) -> list[Path]:
    out: list[Path] = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((*path, k))
            out.extend(_places(v, (*path, k)))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((*path, i))
            out.extend(_places(v, (*path, i)))
    return out


def _get(node: Any, path: Path) -> Any:
    for p in path:
        node = node[p]
    return node


def _wrong_type(value: Any, rng: random.Random) -> Any:
    options: list[Any] = ["fog", True, None, {}, {"a": 1}, [], [1.0, 2.0], 1.5, 7, "auto"]
    same = [o for o in options if _json_kind(o) == _json_kind(value)]
    return rng.choice([o for o in options if o not in same] or options)


def _json_kind(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return "bool/null"
    if isinstance(value, (int, float)):
        return "number"
    return type(value).__name__


def _bad_number(value: Any, rng: random.Random) -> Any:
    return rng.choice([-1.0, -1e-300, -1e300, 1e300, 1e39, -1e39, math.nan, math.inf, -math.inf, 2 ** 70,
                       -(2 ** 70), 0.5, 0, 16385, 1e7 + 1, 180.0, 90.000001, 1.0000001, -0.0,
                       (value * 1e30 if isinstance(value, (int, float)) and not isinstance(value, bool)
                        else 1e30)])


def mutate(scene: dict[str, Any], rng: random.Random, *, empty_key: bool = True) -> Mutation:
    """One random mutation of a copy of ``scene`` (see the module docstring). ``empty_key=False``
    leaves out the unknown key ``""`` (a region the short run could exclude while its finding was open)."""
    bad = copy.deepcopy(scene)
    places = _places(bad)
    path = rng.choice(places)
    parent = _get(bad, path[:-1])
    key = path[-1]
    value = parent[key]
    kind = rng.choice(["wrong_type", "bad_number", "bad_number", "unknown_key", "typo_key", "remove",
                       "huge_list", "list_length", "deep", "non_string_key", "surrogate", "python_type",
                       "bad_string"])
    if kind == "wrong_type":
        parent[key] = _wrong_type(value, rng)
        what = f"value {parent[key]!r} of the wrong type"
    elif kind == "bad_number":
        target = path
        if isinstance(value, list) and value and all(isinstance(x, (int, float)) for x in value):
            i = rng.randrange(len(value))
            target, parent, key = (*path, i), value, i
        parent[key] = _bad_number(parent[key], rng)
        path = target
        what = f"number {parent[key]!r}"
    elif kind in ("unknown_key", "typo_key"):
        obj_path = path[:-1] if not isinstance(value, dict) else path
        obj = _get(bad, obj_path)
        if not isinstance(obj, dict):
            obj_path, obj = (), bad
        if kind == "typo_key" and obj:
            name = rng.choice(list(obj))
            typo = name[:-1] if len(name) > 1 else name + "x"
            obj[typo] = obj.pop(name) if rng.random() < 0.5 else 1.0
            new = typo
        else:
            names = ["colour", "intensities", "Type", "sigma_s", "x" * 300] + ([""] if empty_key else [])
            new = rng.choice(names)
            obj[new] = 1.0
        path = (*obj_path, new)
        what = f"unknown key {new!r}"
    elif kind == "remove":
        if isinstance(parent, dict):
            del parent[key]
        else:
            parent.pop(key)
        what = "removed"
    elif kind == "huge_list":
        n = rng.choice([10 ** 4, 10 ** 5])
        item = value if not isinstance(value, list) else (value[0] if value else 1.0)
        parent[key] = [copy.deepcopy(item) for _ in range(min(n, 2000))] * (n // min(n, 2000))
        what = f"a list of {n} copies"
    elif kind == "list_length":
        parent[key] = rng.choice([[], [1.0], [1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [[1.0, 2.0, 3.0]] * 3])
        what = f"list {parent[key]!r}"
    elif kind == "deep":
        nested: Any = 1.0
        for _ in range(rng.choice([70, 200])):  # deeper cannot be pickled to the worker
            nested = [nested]
        parent[key] = nested
        what = "deeply nested list"
    elif kind == "non_string_key":
        parent[key] = {1: 2.0} if rng.random() < 0.5 else {(1, 2): 3.0, "type": "point"}
        what = "dict with a non-string key"
    elif kind == "surrogate":
        parent[key] = "\udc80abc"
        what = "string with a lone surrogate"
    elif kind == "python_type":
        parent[key] = rng.choice([{1.0, 2.0}, b"bytes", 1 + 2j, object(), range(3), frozenset()])
        what = f"a {type(parent[key]).__name__}"
    else:
        parent[key] = rng.choice(["", "nan", "1e400", "ISOTROPIC", "hg ", "\x00", "\u00e9t\u00e9"])
        what = f"string {parent[key]!r}"
    return Mutation(bad, tuple(path), what)


# A message whose field the loader cut short: "<first 200 bytes>... (N more bytes): ...".
_TRUNCATED_FIELD_RE = re.compile(r"^(.*?)\.\.\. \(\d+ more bytes\): ")


def message_path(message: str) -> Path | None:
    """The field path a loader message starts with, or None when it starts with none."""
    m = _PATH_RE.match(message)
    return parse_path(m.group(1)) if m else None


def related(error_path: Path, mutated: Path) -> bool:
    """Whether a message naming ``error_path`` is about a mutation at ``mutated``."""
    n = min(len(error_path), len(mutated))
    if error_path[:n] == mutated[:n]:  # the place, an object around it or a field inside it
        return True
    if len(error_path) == len(mutated) and error_path[:-1] == mutated[:-1]:  # a sibling
        return True
    if len(error_path) >= 2 and mutated[:len(error_path) - 1] == error_path[:-1]:
        return True  # a sibling of an object around it: surfaces[1].max for surfaces[1].min[0]
    return bool(error_path) and mutated[:1] in _CROSS_FIELDS and error_path[0] in _CROSS_FIELDS[mutated[:1]]


def judge(status: str, error_type: str, message: str, mutation: Mutation) -> str | None:
    """None when the loader's answer to ``mutation`` is right, else what is wrong with it."""
    if status == "ok":
        return None
    if status in ("crash", "hang"):
        return f"{status}: {message.splitlines()[0] if message else ''}"
    if error_type not in ("TypeError", "ValueError"):
        return f"raised {error_type}, not TypeError or ValueError: {message}"
    cut = _TRUNCATED_FIELD_RE.match(message)
    if cut and format_path(mutation.path).startswith(cut.group(1)):
        return None  # a field longer than a message quotes (cpp/scene_keys.cpp, printable): its start
    path = message_path(message)
    if path is None:
        return f"{error_type} message does not start with a field path: {message!r}"
    if not related(path, mutation.path):
        return (f"{error_type} names {format_path(path)!r} for a mutation at {format_path(mutation.path)!r}: "
                f"{message!r}")
    return None
