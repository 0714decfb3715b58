"""Rendering one item of a sweep and writing its files (README "Datasets"): the EXR of
its outputs, the displayed PNG, the masks and the metadata JSON, each written under a
temporary name and renamed, so that a killed run never leaves half a file. The metadata
is written last: an item is done when its JSON exists."""

from __future__ import annotations

import json
import os
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np

from .._display import display_scene
from .._image_io import save_exr
from .._rendering import Renderer
from .._scenes import load_scene
from .._version import __version__
from ._spec import BatchItem, BatchSpec


def item_dir(out: Path) -> Path:
    return out / "items"


def metadata_path(out: Path, item_id: str) -> Path:
    return item_dir(out) / f"{item_id}.json"


def _atomic(path: Path, write: Any) -> None:
    """Calls write(temporary path), then renames it to path."""
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def masks_of(outputs: dict[str, np.ndarray], names: list[str]) -> dict[str, np.ndarray]:
    """8-bit masks (255 where true) from the render outputs: ``sky``, the pixels whose ray
    meets nothing (depth +inf); ``lights``, the pixels that see a lamp's or spot's sphere
    (a finite depth without a surface normal)."""
    depth = outputs["depth"]
    out: dict[str, np.ndarray] = {}
    for name in names:
        if name == "sky":
            m = np.isinf(depth)
        else:  # "lights"
            m = np.isfinite(depth) & ~np.any(outputs["normal"] != 0.0, axis=-1)
        out[name] = np.where(m, 255, 0).astype(np.uint8)
    return out


def render_item(renderer: Renderer, spec: BatchSpec, item: BatchItem, out: Path) -> dict[str, Any]:
    """Renders ``item`` and writes its files into ``out/items``; returns its index record, or
    ``{"id", "failed": stage, "error"}`` when its scene is invalid or rendering or writing fails
    (nothing of it is left on disk then)."""
    start = time.perf_counter()
    try:
        if "__invalid__" in item.scene:
            raise ValueError(item.scene["__invalid__"])
        scene = load_scene(item.scene)
    except (TypeError, ValueError) as e:
        return {"id": item.id, "failed": "scene", "error": str(e)}
    names = list(spec.outputs)
    masks = list(spec.masks)
    extra = [n for n in ("depth", "normal") if masks and n not in names]
    try:
        outputs = renderer.render(scene, outputs=names + extra)
    except Exception as e:  # a render error is the item's, the batch goes on
        return {"id": item.id, "failed": "render", "error": f"{type(e).__name__}: {e}"}
    rendered = time.perf_counter()
    base = item_dir(out) / item.id
    files: dict[str, str] = {}
    try:
        exr = base.with_suffix(".exr")
        _atomic(exr, lambda p: save_exr(p, {n: outputs[n] for n in names}, half=spec.half))
        files["exr"] = exr.name
        if spec.png:
            from PIL import Image

            png = base.with_suffix(".png")
            shown = display_scene(outputs["radiance"], scene, renderer=renderer)
            _atomic(png, lambda p: Image.fromarray(shown, mode="RGB").save(p, format="PNG"))
            files["png"] = png.name
        for name, mask in masks_of(outputs, masks).items():
            from PIL import Image

            path = item_dir(out) / f"{item.id}_mask_{name}.png"
            _atomic(path, lambda p, m=mask: Image.fromarray(m, mode="L").save(p, format="PNG"))
            files[f"mask_{name}"] = path.name
        record = {"id": item.id, "source": item.source, "camera": item.camera, "parameters": item.parameters,
                  "files": files, "outputs": names}
        metadata = {**record, "scene": scene, "airlight_version": __version__, "backend": renderer.backend,
                    "timings": {"render_s": rendered - start, "write_s": time.perf_counter() - rendered}}
        _atomic(metadata_path(out, item.id), lambda p: p.write_text(json.dumps(metadata, indent=1)))
    except Exception as e:
        for name in files.values():
            (item_dir(out) / name).unlink(missing_ok=True)
        return {"id": item.id, "failed": "write", "error": f"{type(e).__name__}: {e}",
                "trace": traceback.format_exc(limit=3)}
    return record
