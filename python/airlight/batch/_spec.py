"""Sweep descriptions (README "Datasets: batch sweeps"): loading, checking, and expanding
into items, each a complete scene with its parameters. Everything here is deterministic:
the same spec (and seed) gives the same items in the same order."""

from __future__ import annotations

import copy
import itertools
import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

from .._rendering import LAYERS, OUTPUTS
from .._scenes import _with_film_size, preset, preset_names

SpecLike = Union[Mapping[str, Any], str, "os.PathLike[str]"]

# The spec's keys, with their defaults (None: required or computed).
_DEFAULTS: dict[str, Any] = {
    "scenes": None,
    "vary": {},
    "cameras": [],
    "repeat": 1,
    "seed": 0,
    "film": None,
    "outputs": ["radiance"],
    "half": False,
    "png": True,
    "masks": [],
    "backend": "auto",
}
MASKS = ("sky", "lights")
_DISTRIBUTIONS = ("uniform", "loguniform", "normal", "choice")


@dataclass
class BatchItem:
    """One frame of a sweep: its id, the scene to render (complete but not yet validated:
    a substitution may make it invalid, which the batch reports), and what made it."""

    id: str
    scene: dict[str, Any]
    source: str
    camera: int | None
    parameters: dict[str, Any] = field(default_factory=dict)


@dataclass
class BatchSpec:
    """A checked sweep description (:func:`load_spec`)."""

    scenes: list[tuple[str, dict[str, Any]]]
    grid: list[tuple[str, list[Any]]]
    draws: list[tuple[str, str, Any]]
    cameras: list[dict[str, Any]]
    repeat: int
    seed: int
    film: dict[str, int] | None
    outputs: list[str]
    half: bool
    png: bool
    masks: list[str]
    backend: str
    raw: dict[str, Any]


def _read(spec: SpecLike) -> tuple[dict[str, Any], Path | None]:
    if isinstance(spec, Mapping):
        return dict(spec), None
    if not isinstance(spec, (str, os.PathLike)):
        raise TypeError(f"spec: expected a dict or a JSON/YAML file path, got {type(spec).__name__}")
    path = Path(spec)
    if not path.is_file():
        raise FileNotFoundError(f"spec file not found: {path}")
    text = path.read_text()
    if path.suffix.lower() in (".yaml", ".yml"):
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as e:
            raise ValueError(f"{path}: invalid YAML: {e}") from None
    else:
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"{path}: invalid JSON at line {e.lineno}, column {e.colno}: {e.msg}") from None
    if not isinstance(data, dict):
        raise TypeError(f"{path}: expected an object at the top, got {type(data).__name__}")
    return data, path.parent


# A key path: a key, then ".key", ".index" or "[index]" parts.
_KEY_PATH = re.compile(r"[^.\[\]]+(?:\.[^.\[\]]+|\[\d+\])*")
_PATH_PART = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def key_path(path: str) -> list[str | int]:
    """``"lights[0].intensity"`` or ``"lights.0.intensity"`` -> ``["lights", 0, "intensity"]``."""
    if not isinstance(path, str) or _KEY_PATH.fullmatch(path) is None:
        raise ValueError(f"vary: bad key path {path!r} (keys joined by '.', list indices as .0 or [0])")
    return [int(index) if index else int(name) if name.isdigit() else name
            for name, index in _PATH_PART.findall(path)]


def set_path(scene: dict[str, Any], path: str, value: Any) -> None:
    """Sets ``scene``'s value at ``path`` (:func:`key_path`), creating missing objects on the way."""
    parts = key_path(path)
    node: Any = scene
    for k, part in enumerate(parts[:-1]):
        nxt = parts[k + 1]
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise ValueError(f"{path}: no element {part} here")
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise ValueError(f"{path}: {part!r} is not inside an object")
        if node.get(part) is None:
            node[part] = [] if isinstance(nxt, int) else {}
        node = node[part]
    last = parts[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise ValueError(f"{path}: no element {last} here")
        node[last] = copy.deepcopy(value)
    else:
        if not isinstance(node, dict):
            raise ValueError(f"{path}: {last!r} is not inside an object")
        node[last] = copy.deepcopy(value)


def _scene_entry(entry: Any, where: str, base_dir: Path | None) -> tuple[str, dict[str, Any]]:
    if isinstance(entry, dict):
        return where, copy.deepcopy(entry)
    if not isinstance(entry, str):
        raise TypeError(f"{where}: expected a preset name, a scene file or a scene object, "
                        f"got {type(entry).__name__}")
    if entry in preset_names():
        return entry, preset(entry)
    path = Path(entry)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    if path.is_file():
        return entry, json.loads(path.read_text())
    raise ValueError(f"{where}: {entry!r} is neither a preset ({', '.join(preset_names())}) nor a scene file")


def _finite_number(a: Any) -> bool:
    return isinstance(a, (int, float)) and not isinstance(a, bool) and math.isfinite(a)


def _values(path: str, rule: Any) -> tuple[str, Any]:
    """("grid", values) or ("draw", (distribution, arguments)) for one vary entry."""
    where = f"vary[{path!r}]"
    if isinstance(rule, list):
        if not rule:
            raise ValueError(f"{where}: an empty list of values")
        return "grid", rule
    if not isinstance(rule, dict) or len(rule) != 1:
        raise ValueError(f"{where}: expected a list of values or one of {{range: [start, stop], steps: n}}, "
                         f"{{{': ..., '.join(_DISTRIBUTIONS)}: ...}}")
    if "range" in rule or "steps" in rule:
        raise ValueError(f"{where}: 'range' needs 'steps' beside it, in one object")
    (kind, args), = rule.items()
    if kind not in _DISTRIBUTIONS:
        raise ValueError(f"{where}: unknown rule {kind!r}; one of range, {', '.join(_DISTRIBUTIONS)}")
    if kind == "choice":
        if not isinstance(args, list) or not args:
            raise ValueError(f"{where}.choice: expected a non-empty list of values")
    else:
        ok = isinstance(args, list) and len(args) == 2 and all(_finite_number(a) for a in args)
        if not ok:
            raise ValueError(f"{where}.{kind}: expected two finite numbers, got {args!r}")
        if kind == "loguniform" and not 0 < args[0] <= args[1]:
            raise ValueError(f"{where}.loguniform: expected 0 < low <= high, got {args!r}")
        if kind == "uniform" and not args[0] <= args[1]:
            raise ValueError(f"{where}.uniform: expected low <= high, got {args!r}")
        if kind == "normal" and args[1] < 0:
            raise ValueError(f"{where}.normal: expected a standard deviation >= 0, got {args[1]!r}")
    return "draw", (kind, args)


def _range_values(path: str, rule: dict[str, Any]) -> list[float]:
    where = f"vary[{path!r}]"
    r, steps = rule.get("range"), rule.get("steps")
    if set(rule) != {"range", "steps"} or not isinstance(r, list) or len(r) != 2:
        raise ValueError(f"{where}: expected {{range: [start, stop], steps: n}}")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ValueError(f"{where}.steps: expected an integer >= 1, got {steps!r}")
    if not all(_finite_number(a) for a in r):
        raise ValueError(f"{where}.range: expected two finite numbers, got {r!r}")
    return [float(v) for v in np.linspace(r[0], r[1], steps)]


def _camera_entries(cameras: Any) -> list[dict[str, Any]]:
    if not isinstance(cameras, list):
        raise TypeError(f"cameras: expected a list, got {type(cameras).__name__}")
    out: list[dict[str, Any]] = []
    for i, c in enumerate(cameras):
        if not isinstance(c, dict):
            raise TypeError(f"cameras[{i}]: expected a camera object or {{path: ...}}, "
                            f"got {type(c).__name__}")
        if "path" not in c:
            out.append(copy.deepcopy(c))
            continue
        p = c["path"]
        if not isinstance(p, dict) or not {"from", "to", "frames"} <= set(p):
            raise ValueError(f"cameras[{i}].path: expected {{from: camera, to: camera, frames: n}}")
        frames = p["frames"]
        if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
            raise ValueError(f"cameras[{i}].path.frames: expected an integer >= 1, got {frames!r}")
        a, b = p["from"], p["to"]
        for key in ("position", "look_at"):
            for end, cam in (("from", a), ("to", b)):
                v = cam.get(key) if isinstance(cam, dict) else None
                if not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) for x in v)):
                    raise ValueError(f"cameras[{i}].path.{end}.{key}: expected [x, y, z]")
        for f in range(frames):
            t = 0.0 if frames == 1 else f / (frames - 1)
            cam = copy.deepcopy(a)
            for key in ("position", "look_at"):
                cam[key] = [(1 - t) * float(x) + t * float(y) for x, y in zip(a[key], b[key])]
            out.append(cam)
    return out


def load_spec(spec: SpecLike) -> BatchSpec:
    """Reads and checks a sweep description (a dict, or a JSON or YAML file); errors
    (``TypeError``/``ValueError``) name the key. The keys (README "Datasets"):
    ``scenes`` (presets, scene files relative to the spec's folder, or scene objects),
    ``vary`` (key path -> a list of values, ``{range: [a, b], steps: n}``, or a random
    ``{uniform|loguniform|normal: [a, b]}`` / ``{choice: [...]}``), ``cameras`` (camera
    objects, or ``{path: {from, to, frames}}``), ``repeat`` (draws of the random parameters
    per grid point), ``seed``, ``film`` ({width, height}), ``outputs`` (names of
    ``airlight.OUTPUTS``, ``"layers"``), ``half``, ``png``, ``masks`` (``sky``, ``lights``),
    ``backend``."""
    data, base_dir = _read(spec)
    unknown = sorted(set(data) - set(_DEFAULTS))
    if unknown:
        raise ValueError(f"{unknown[0]}: unknown key; the keys are {', '.join(_DEFAULTS)}")
    d = {**copy.deepcopy(_DEFAULTS), **data}
    if d["scenes"] is None:
        raise ValueError("scenes: required (a list of presets, scene files or scene objects)")
    scenes_in = d["scenes"] if isinstance(d["scenes"], list) else [d["scenes"]]
    if not scenes_in:
        raise ValueError("scenes: an empty list")
    scenes = [_scene_entry(s, f"scenes[{i}]", base_dir) for i, s in enumerate(scenes_in)]
    if not isinstance(d["vary"], dict):
        raise TypeError(f"vary: expected an object of key paths, got {type(d['vary']).__name__}")
    grid: list[tuple[str, list[Any]]] = []
    draws: list[tuple[str, str, Any]] = []
    for path, rule in d["vary"].items():
        key_path(path)
        if isinstance(rule, dict) and "range" in rule:
            grid.append((path, _range_values(path, rule)))
            continue
        kind, values = _values(path, rule)
        if kind == "grid":
            grid.append((path, values))
        else:
            draws.append((path, values[0], values[1]))
    for key in ("repeat", "seed"):
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < (1 if key == "repeat" else 0):
            raise ValueError(f"{key}: expected an integer >= {1 if key == 'repeat' else 0}, got {v!r}")
    film = d["film"]
    if film is not None:
        if not isinstance(film, dict) or set(film) - {"width", "height"} or not film:
            raise ValueError("film: expected {width: W, height: H} "
                             "(one alone keeps the scene's aspect ratio)")
        for k, v in film.items():
            if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= 16384:
                raise ValueError(f"film.{k}: expected an integer in [1, 16384], got {v!r}")
    outputs = d["outputs"]
    if not isinstance(outputs, list) or not outputs:
        raise ValueError("outputs: expected a non-empty list of output names")
    names: list[str] = []
    for i, name in enumerate(outputs):
        if name == "layers":
            names += [n for n in LAYERS if n not in names]
        elif name in OUTPUTS:
            if name not in names:
                names.append(name)
        else:
            raise ValueError(f"outputs[{i}]: unknown output {name!r}; "
                             f"one of {', '.join(OUTPUTS)}, or 'layers'")
    if "radiance" not in names:
        names.insert(0, "radiance")
    masks = d["masks"]
    if not isinstance(masks, list) or any(m not in MASKS for m in masks):
        raise ValueError(f"masks: expected a list of {', '.join(MASKS)}, got {masks!r}")
    for key in ("half", "png"):
        if not isinstance(d[key], bool):
            raise TypeError(f"{key}: expected true or false, got {type(d[key]).__name__}")
    if d["backend"] not in ("auto", "gl", "cpu"):
        raise ValueError(f"backend: must be auto, gl or cpu, got {d['backend']!r}")
    return BatchSpec(scenes=scenes, grid=grid, draws=draws, cameras=_camera_entries(d["cameras"]),
                     repeat=d["repeat"], seed=d["seed"], film=film, outputs=names, half=d["half"],
                     png=d["png"], masks=list(masks), backend=d["backend"], raw=data)


def _draw(rng: np.random.Generator, kind: str, args: Any) -> Any:
    if kind == "uniform":
        return float(rng.uniform(args[0], args[1]))
    if kind == "loguniform":
        return float(math.exp(rng.uniform(math.log(args[0]), math.log(args[1]))))
    if kind == "normal":
        return float(rng.normal(args[0], args[1]))
    return copy.deepcopy(args[int(rng.integers(len(args)))])


def expand(spec: SpecLike | BatchSpec) -> list[BatchItem]:
    """The sweep's items, in order: scenes x cameras x the grid of listed values (in the
    order of ``vary``) x ``repeat``; random parameters drawn per item from a generator
    seeded by (seed, item index), so an item's draws do not depend on the others."""
    s = spec if isinstance(spec, BatchSpec) else load_spec(spec)
    cameras: list[tuple[int | None, dict[str, Any] | None]] = (
        [(i, c) for i, c in enumerate(s.cameras)] if s.cameras else [(None, None)])
    grid_paths = [p for p, _ in s.grid]
    items: list[BatchItem] = []
    for (source, base), (cam_index, cam), values in itertools.product(
            s.scenes, cameras, itertools.product(*[v for _, v in s.grid])):
        for _ in range(s.repeat):
            index = len(items)
            scene = copy.deepcopy(base)
            parameters: dict[str, Any] = {}
            if cam is not None:
                scene["camera"] = {**scene.get("camera", {}), **copy.deepcopy(cam)}
            if s.film is not None:
                # One side alone keeps the scene's aspect ratio, as Renderer.render(width=...) does.
                scene = _with_film_size(scene, s.film.get("width"), s.film.get("height"))
            for path, value in zip(grid_paths, values):
                parameters[path] = copy.deepcopy(value)
            rng = np.random.default_rng([s.seed, index])
            for path, kind, args in s.draws:
                parameters[path] = _draw(rng, kind, args)
            items.append(BatchItem(id=f"{index:06d}", scene=scene, source=source, camera=cam_index,
                                   parameters=parameters))
    for item in items:
        for path, value in item.parameters.items():
            try:
                set_path(item.scene, path, value)
            except ValueError as e:
                item.scene = {"__invalid__": f"vary: {e}"}
                break
    return items
