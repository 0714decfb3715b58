"""Checks on rendered images: shape, finiteness, sign, the GL/CPU disagreement metric, and the
error of an image against a reference image (``error_against_reference``).

The disagreement metric. Both backends run the same GLSL in float32, so they differ by
rounding, except where a rounding decides a discrete event: a ray that grazes an edge hits
a surface on one backend and misses it on the other. Per pixel and channel,

    e = |gl - cpu| / (max(gl, cpu) + floor),   floor = max(FLOOR_FRACTION x (the image's largest
                                                           value), ABSOLUTE_FLOOR),

so pixels far below the image's maximum (relative to it) do not count, nor radiances below
ABSOLUTE_FLOOR (1e-30: llvmpipe flushes float32 subnormals, below 1.2e-38, to zero where the CPU
keeps them; the first long run's only "disagreement" was 0 against 4e-45), and a pixel is *bad*
when its largest e exceeds the tolerance. A bad pixel is *excused* when it is a single-pixel
edge difference: none of its 8 neighbours is bad and it lies on a discontinuity of the CPU
or the GL image (a neighbour differs from it by more than EDGE_JUMP in the same measure).
The images disagree when any bad pixel is not excused. TOLERANCE was calibrated on the
shipped presets (``python -m tools.fuzz --calibrate``; README "Reliability").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FLOOR_FRACTION = 1e-3
ABSOLUTE_FLOOR = 1e-30
TOLERANCE = 1e-2
EDGE_JUMP = 0.2


@dataclass
class Disagreement:
    """The metric's result: the largest e over unexcused pixels (``max_error``) and over all
    pixels (``max_error_all``), bad and excused pixel counts, the worst unexcused pixel
    (row, column) and whether the images disagree."""

    disagree: bool
    max_error: float
    max_error_all: float
    bad_pixels: int
    excused_pixels: int
    worst_pixel: tuple[int, int] | None

    def describe(self) -> str:
        """One line for a report."""
        where = f" at row {self.worst_pixel[0]}, column {self.worst_pixel[1]}" if self.worst_pixel else ""
        return (f"relative error {self.max_error:.3g}{where} (tolerance {TOLERANCE:g}); "
                f"{self.bad_pixels} bad pixels, {self.excused_pixels} excused as single-pixel edges")


def image_problems(image: np.ndarray, width: int, height: int) -> list[tuple[str, str]]:
    """Problems of one radiance image as (kind, detail): ``"shape"``, ``"nonfinite"``,
    ``"negative"``; empty when the image is a finite, non-negative float32 (height, width, 3)."""
    if image.shape != (height, width, 3) or image.dtype != np.float32:
        return [("shape", f"expected float32 {(height, width, 3)}, got {image.dtype} {image.shape}")]
    problems = []
    finite = np.isfinite(image)
    if not finite.all():
        rows, cols = np.nonzero(~finite.all(axis=2))
        values = image[rows[0], cols[0]].tolist()
        problems.append(("nonfinite", f"{int((~finite).sum())} non-finite values, first at row {rows[0]}, "
                                      f"column {cols[0]}: {values}"))
    negative = finite & (image < 0)
    if negative.any():
        rows, cols = np.nonzero(negative.any(axis=2))
        least = float(image[negative].min())
        problems.append(("negative", f"{int(negative.sum())} negative values (least {least:.3g}), "
                                     f"first at row {rows[0]}, column {cols[0]}"))
    return problems


def _relative(a: np.ndarray, b: np.ndarray, floor: float) -> np.ndarray:
    """Per-pixel largest channel of |a - b| / (max(a, b) + floor)."""
    num = np.abs(a - b)
    den = np.maximum(a, b) + floor
    with np.errstate(invalid="ignore", divide="ignore"):
        e = np.where(num > 0, num / den, 0.0)
    return np.asarray(e.max(axis=2))


def error_against_reference(image: np.ndarray, reference: np.ndarray,
                            floor_fraction: float = FLOOR_FRACTION) -> np.ndarray:
    """Per pixel, the largest channel of |image - ref| / (ref + floor), floor = ``floor_fraction``
    x the reference's mean radiance (at least ABSOLUTE_FLOOR): pixels a thousand times darker than
    the image's average do not count (the quality presets' error, docs/quality_presets.md)."""
    ref = reference.astype(np.float64)
    floor = max(floor_fraction * float(ref.mean()), ABSOLUTE_FLOOR)
    return np.asarray((np.abs(image.astype(np.float64) - ref) / (ref + floor)).max(axis=2))


def _neighbour_max(values: np.ndarray) -> np.ndarray:
    """For each pixel, the largest of ``values`` over its 8 neighbours (0 beyond the edges)."""
    h, w = values.shape
    padded = np.zeros((h + 2, w + 2), dtype=values.dtype)
    padded[1:-1, 1:-1] = values
    out = np.zeros_like(values)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                out = np.maximum(out, padded[1 + dy:h + 1 + dy, 1 + dx:w + 1 + dx])
    return out


def _discontinuity(image: np.ndarray, floor: float) -> np.ndarray:
    """Pixels that differ from one of their 8 neighbours by more than EDGE_JUMP."""
    h, w, _ = image.shape
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    out = np.zeros((h, w), dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if dy or dx:
                out |= _relative(image, padded[1 + dy:h + 1 + dy, 1 + dx:w + 1 + dx], floor) > EDGE_JUMP
    return out


def disagreement(gl: np.ndarray, cpu: np.ndarray, tolerance: float = TOLERANCE) -> Disagreement:
    """The GL/CPU disagreement of two finite radiance images of one scene (module docstring)."""
    a = gl.astype(np.float64)
    b = cpu.astype(np.float64)
    top = float(max(a.max(initial=0.0), b.max(initial=0.0)))
    if top == 0.0:
        return Disagreement(False, 0.0, 0.0, 0, 0, None)
    floor = max(FLOOR_FRACTION * top, ABSOLUTE_FLOOR)
    e = _relative(a, b, floor)
    bad = e > tolerance
    isolated = _neighbour_max(bad.astype(np.uint8)) == 0
    edge = _discontinuity(a, floor) | _discontinuity(b, floor)
    excused = bad & isolated & edge
    counted = bad & ~excused
    worst = None
    max_error = 0.0
    if counted.any():
        masked = np.where(counted, e, -1.0)
        r, c = np.unravel_index(int(np.argmax(masked)), masked.shape)
        worst = (int(r), int(c))
        max_error = float(e[r, c])
    else:
        max_error = float(np.where(excused, 0.0, e).max(initial=0.0))
    return Disagreement(bool(counted.any()), max_error, float(e.max(initial=0.0)), int(bad.sum()),
                        int(excused.sum()), worst)
