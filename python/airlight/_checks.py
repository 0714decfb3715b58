"""Argument checks shared by the package's modules.

Each raises ``TypeError`` (wrong kind of value) or ``ValueError`` (right kind,
bad value) whose message starts with the name of the offending argument, as
the scene validator does for scene fields (``"fov_y: must be finite, got nan"``).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np


def _real(name: str, value: Any) -> float:
    """``value`` as a finite float; TypeError/ValueError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name}: must be finite, got {value!r}")
    return x


def _vec3(name: str, value: Any) -> list[float]:
    """``value`` (a sequence or 1-D array of 3 numbers) as a list of 3 finite floats."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise TypeError(f"{name}: expected a list of 3 numbers, got {type(value).__name__}")
    if len(value) != 3:
        raise ValueError(f"{name}: expected a list of exactly 3 numbers, got {len(value)}")
    return [_real(f"{name}[{i}]", v) for i, v in enumerate(value)]


def _rgb(name: str, value: Any) -> list[float]:
    """An RGB value (a number or 3 numbers), each channel finite and >= 0."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        rgb = [_real(name, value)] * 3
    else:
        rgb = _vec3(name, value)
    if any(c < 0 for c in rgb):
        raise ValueError(f"{name}: must be >= 0, got {value!r}")
    return rgb


def _radiance_array(radiance: Any) -> np.ndarray:
    """``radiance`` as a float32 (height, width, 3) array; TypeError/ValueError naming it."""
    if not isinstance(radiance, np.ndarray):
        raise TypeError(f"radiance: expected a numpy array, got {type(radiance).__name__}")
    if radiance.dtype.kind not in "fiu" or radiance.dtype == np.bool_:
        raise TypeError(f"radiance: expected a real-valued array, got dtype {radiance.dtype}")
    if radiance.ndim != 3 or radiance.shape[2] != 3:
        raise ValueError(f"radiance: expected shape (height, width, 3), got {radiance.shape}")
    return np.ascontiguousarray(radiance, dtype=np.float32)
