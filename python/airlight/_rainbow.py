"""Rainbows: the raindrops' Lorenz-Mie phase function for sunlight that the
renderer tabulates (:func:`rainbow_phase`; effects/rainbow/physics.md, effects/rainbow/docs/rainbow.md)."""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from . import _core
from ._checks import _real


def rainbow_phase(rate: float, angles_deg: Any = None, *, wavelengths: int = 33) -> np.ndarray:
    """The raindrops' phase function for sunlight that the renderer uses (rain with
    ``"phase": "mie"``; effects/rainbow/physics.md, effects/rainbow/docs/rainbow.md): Lorenz-Mie,
    averaged over the Marshall-Palmer drop sizes of ``rate`` (mm/h), seen through the sun's
    0.53-degree disc, converted from ``wavelengths`` spectral nodes (3, 5, 9, 17 or 33) to
    linear sRGB (CIE 1931, D65). Returns float32 (n, 3) in sr^-1 at ``angles_deg``
    (scattering angles, 0 = forward; default: the table's own 0.05-degree grid),
    interpolated linearly in angle as the shaders do."""
    r = _real("rate", rate)
    if r <= 0.0:
        raise ValueError(f"rate: must be positive (mm/h), got {rate!r}")
    if isinstance(wavelengths, bool) or not isinstance(wavelengths, numbers.Integral):
        raise TypeError(f"wavelengths: expected an integer, got {type(wavelengths).__name__}")
    table = _core.rainbow_phase_table(r, int(wavelengths))[:, :3]
    grid = np.linspace(0.0, 180.0, table.shape[0])
    if angles_deg is None:
        return table.copy()
    a = np.asarray(angles_deg, dtype=np.float64)
    if a.ndim != 1 or not np.all(np.isfinite(a)) or np.any((a < 0.0) | (a > 180.0)):
        raise ValueError("angles_deg: must be a 1-D array of angles in [0, 180] degrees")
    return np.stack([np.interp(a, grid, table[:, c]) for c in range(3)], axis=1).astype(np.float32)
