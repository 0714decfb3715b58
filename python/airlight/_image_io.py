"""Image files: 8-bit sRGB PNG (:func:`save_png`), HDR portable float maps
(:func:`save_pfm`, :func:`load_pfm`) of linear radiance, and OpenEXR files
(:func:`save_exr`, :func:`load_exr`) of radiance and any other named images
(depth, transmittance, normals), through the OpenEXR C++ library.

EXR channel naming (cpp/image_io.cpp): the image ``radiance`` is the channels
``R``, ``G``, ``B`` (what every EXR viewer shows); ``normal`` is ``normal.X``,
``normal.Y``, ``normal.Z``; any other 3-channel image ``name`` is ``name.R``,
``name.G``, ``name.B``; a 1-channel image ``name`` is the channel ``name``.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Mapping

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


def _exr_image(key: str, value: object) -> np.ndarray:
    """One image of :func:`save_exr` as a C-contiguous float32 (H, W) or (H, W, 3) array."""
    if not isinstance(value, np.ndarray):
        raise TypeError(f"{key}: expected a numpy array, got {type(value).__name__}")
    if value.dtype.kind not in "fiu" or value.dtype == np.bool_:
        raise TypeError(f"{key}: expected a real-valued array, got dtype {value.dtype}")
    if value.ndim == 3 and value.shape[2] == 1:
        value = value[:, :, 0]
    if not (value.ndim == 2 or (value.ndim == 3 and value.shape[2] == 3)):
        raise ValueError(f"{key}: expected shape (H, W) or (H, W, 3), got {value.shape}")
    if value.shape[0] < 1 or value.shape[1] < 1:
        raise ValueError(f"{key}: expected at least 1 x 1 pixels, got shape {value.shape}")
    return np.ascontiguousarray(value, dtype=np.float32)


def save_exr(path: str | os.PathLike[str], images: np.ndarray | Mapping[str, np.ndarray], *,
             half: bool = False) -> None:
    """Writes linear images to an OpenEXR file (single part, scanlines, ZIP compression).

    ``images`` is a float array of shape (H, W, 3), written as ``radiance``, or a
    mapping of names to arrays of shape (H, W, 3) or (H, W) (or (H, W, 1)), all of
    the same H and W, e.g. ``{"radiance": img, "depth": depth}``. Values are
    written as float32 as they are (inf, NaN included), or as half floats with
    ``half=True`` (beyond +-65504: +-inf). Channels: ``radiance`` -> ``R, G, B``;
    ``normal`` -> ``normal.X, normal.Y, normal.Z``; another 3-channel ``name`` ->
    ``name.R, name.G, name.B``; a 1-channel ``name`` -> ``name``.

    Raises ``TypeError``/``ValueError`` naming the argument or key
    (``images['depth']: expected shape (H, W) or (H, W, 3), got (2, 3, 4)``) and
    ``OSError`` when the file cannot be written.
    """
    if not isinstance(half, bool):
        raise TypeError(f"half: expected a bool, got {type(half).__name__}")
    if isinstance(images, np.ndarray):
        if not (images.ndim == 3 and images.shape[2] == 3):
            raise ValueError(f"images: expected shape (H, W, 3) (radiance) or a mapping of names to arrays, "
                             f"got {images.shape}")
        items = [("radiance", _exr_image("images", images))]
    elif isinstance(images, Mapping):
        if not images:
            raise ValueError("images: expected at least one image, got an empty mapping")
        items = []
        for name, value in images.items():
            if not isinstance(name, str):
                raise TypeError(f"images: keys must be str, got {type(name).__name__} {name!r}")
            key = f"images[{name!r}]"
            if not name:
                raise ValueError(f"{key}: the name must not be empty")
            if "." in name:
                raise ValueError(f"{key}: the name must not contain '.' (it separates an image's channels)")
            array = _exr_image(key, value)
            if name == "radiance" and array.ndim != 3:
                raise ValueError(f"{key}: expected shape (H, W, 3), got {np.shape(value)}")
            if name in ("R", "G", "B") and array.ndim != 3:
                raise ValueError(f"{key}: {name!r} is a channel of 'radiance' (R, G, B); use another name")
            if items and array.shape[:2] != items[0][1].shape[:2]:
                first, first_array = items[0]
                raise ValueError(f"{key}: expected (H, W) = {first_array.shape[:2]} as images[{first!r}], "
                                 f"got {array.shape[:2]}")
            items.append((name, array))
    else:
        raise TypeError(f"images: expected a numpy array or a mapping of names to arrays, "
                        f"got {type(images).__name__}")
    _core.write_exr(os.fspath(path), items, half)


def load_exr(path: str | os.PathLike[str]) -> dict[str, np.ndarray]:
    """Reads an OpenEXR file into float32 arrays by name: (H, W, 3) or (H, W), row 0 on top.

    The channel naming of :func:`save_exr` reversed: ``R, G, B`` -> ``"radiance"``;
    ``x.R, x.G, x.B`` and ``x.X, x.Y, x.Z`` -> ``"x"`` (3 channels); any other
    channel (``A``, ``x.R`` without ``x.G``) -> a 2-D array named by the full
    channel name. ``"radiance"`` comes first, the others in the file's channel
    order (sorted by name). Reads scanline or tiled files of half, float or uint
    channels (the first part of a multi-part file). Raises
    ``FileNotFoundError`` when there is no such file and ``OSError`` when it is
    not a readable EXR file.
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(errno.ENOENT, "no such EXR file", path)
    return dict(_core.read_exr(path))
