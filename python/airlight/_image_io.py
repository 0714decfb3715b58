"""Image files: 8-bit sRGB PNG (:func:`save_png`) and HDR portable float maps
(:func:`save_pfm`, :func:`load_pfm`) of linear radiance."""

from __future__ import annotations

import os

import numpy as np

from . import _core
from ._display import to_srgb8


def save_png(path: str | os.PathLike[str], radiance: np.ndarray, exposure: float = 1.0) -> None:
    """Writes ``radiance * exposure`` as an 8-bit sRGB PNG (through Pillow)."""
    from PIL import Image

    Image.fromarray(to_srgb8(radiance, exposure), mode="RGB").save(os.fspath(path), format="PNG")


def save_pfm(path: str | os.PathLike[str], radiance: np.ndarray) -> None:
    """Writes linear radiance as a portable float map (HDR, little-endian)."""
    _core.write_pfm(os.fspath(path), np.asarray(radiance, dtype=np.float32))


def load_pfm(path: str | os.PathLike[str]) -> np.ndarray:
    """Reads a colour portable float map into a float32 (height, width, 3) array, row 0 on top."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            raise ValueError(f"path: {os.fspath(path)!r} is not a colour PFM file")
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        dtype = "<f4" if scale < 0 else ">f4"
        data = np.frombuffer(f.read(width * height * 12), dtype=dtype).reshape(height, width, 3)
    return data[::-1].astype(np.float32)
