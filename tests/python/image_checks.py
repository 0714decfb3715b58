"""Assertions on rendered images shared by the test files: physically valid radiance and
continuity of sampled profiles."""

from __future__ import annotations

import numpy as np


def finite_non_negative(image: np.ndarray, label: str) -> None:
    """No NaN, no Inf and no negative radiance anywhere in `image`."""
    image = np.asarray(image)
    assert np.all(np.isfinite(image)), f"{label}: {np.count_nonzero(~np.isfinite(image))} non-finite values"
    assert np.all(image >= 0), f"{label}: negative radiance, min {image.min()}"


def no_jumps(values: np.ndarray, label: str, floor: float, factor: float = 4.0) -> None:
    """Every step between neighbours is at most `factor` times the largest of the (up to
    four) steps around it, plus `floor`: a kink passes, a jump does not."""
    steps = np.abs(np.diff(values))
    for k in range(len(steps)):
        around = np.concatenate([steps[max(0, k - 2):k], steps[k + 1:k + 3]])
        assert steps[k] <= factor * around.max() + floor, (
            f"{label}: jump of {steps[k]:.4e} between samples {k} and {k + 1} ({values[k]:.6e} -> "
            f"{values[k + 1]:.6e}); steps around it {around}")
