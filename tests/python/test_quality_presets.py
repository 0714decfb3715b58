"""The quality presets (``quality.preset``: "fast", "default", "reference"; docs/quality_presets.md):
how they map onto the knobs, that explicit keys override them, and that their images stay within
the errors the documentation states, against the reference preset, on small films."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import airlight
from tools.fuzz.compare import error_against_reference

ROOT = Path(__file__).resolve().parents[2]


def preset_scene(name: str, width: int = 96, height: int = 54, **quality: Any) -> dict[str, Any]:
    scene = json.loads((ROOT / "scenes" / f"{name}.json").read_text())
    scene["film"] = {"width": width, "height": height}
    scene["quality"] = {**scene.get("quality", {}), **quality}
    return scene


def test_no_preset_and_the_default_preset_give_the_same_knobs() -> None:
    bare = airlight.load_scene(preset_scene("day_clear"))["quality"]
    named = airlight.load_scene(preset_scene("day_clear", preset="default"))["quality"]
    assert bare == named
    assert bare["preset"] == "default"


@pytest.mark.parametrize("preset", ["fast", "reference"])
def test_a_preset_moves_knobs_off_their_defaults(preset: str) -> None:
    default = airlight.load_scene(preset_scene("day_clear"))["quality"]
    quality = airlight.load_scene(preset_scene("day_clear", preset=preset))["quality"]
    moved = {k for k in default if k != "preset" and quality[k] != default[k]}
    assert moved, "the preset changed no knob"
    # Methods that are comparisons or different physics are never a preset's choice.
    assert (
        quality["airlight"] == "analytic"
        and quality["clouds"] == "adaptive"
        and quality["shafts"] == "analytic"
    )
    assert quality["multiple_scattering"] is True


def test_explicit_keys_override_the_preset() -> None:
    q = airlight.load_scene(preset_scene("day_clear", preset="fast", sky_segments=16, cull_fraction=0))[
        "quality"
    ]
    assert q["preset"] == "fast"
    assert q["sky_segments"] == 16 and q["cull_fraction"] == 0
    # ... and the knobs not named keep the preset's values.
    fast = airlight.load_scene(preset_scene("day_clear", preset="fast"))["quality"]
    assert q["cloud_steps"] == fast["cloud_steps"] and q["spot_glow_samples"] == fast["spot_glow_samples"]


@pytest.mark.parametrize("preset", ["fast", "default", "reference"])
def test_a_loaded_scene_reloads_to_the_same_knobs(preset: str) -> None:
    once = airlight.load_scene(preset_scene("crane_searchlight", preset=preset, spot_glow_samples=20))
    assert airlight.load_scene(once) == once


@pytest.mark.parametrize(
    ("value", "error", "message"),
    [
        ("fastest", ValueError, "quality.preset"),
        (1, TypeError, "quality.preset"),
        (None, TypeError, "quality.preset"),
    ],
)
def test_a_bad_preset_is_named(value: object, error: type[Exception], message: str) -> None:
    with pytest.raises(error, match=message):
        airlight.load_scene(preset_scene("default", preset=value))


def preset_errors(name: str, width: int = 96, height: int = 54) -> dict[str, np.ndarray]:
    """Each preset's per-pixel error against the reference preset, CPU backend."""
    reference = airlight.render(preset_scene(name, width, height, preset="reference"), backend="cpu")
    return {
        p: error_against_reference(
            airlight.render(preset_scene(name, width, height, preset=p), backend="cpu"), reference
        )
        for p in ("fast", "default")
    }


# (scene, the default's largest error against the reference, the fast preset's, where stated):
# culling adds at most (lamps skipped) x cull_fraction (effects/lamp_airlight/docs/culling.md:
# 16 lamps x 1e-5, x 1e-4 fast); a spot's glow quadrature 8e-4 at 12 samples, 5e-3 at 8
# (effects/spotlights/docs/spot_table.md section 9); the atmosphere's volumes, 16 levels (8 fast)
# against 64 (effects/daytime/docs/daytime.md section 3: up to 2.4 % in heavy rain, where the
# fog's share changes fastest); the clouds' marches (docs/quality_presets.md, measured by
# benchmarks/bench_quality.py).
BOUNDS = [
    ("foggy_street", 16 * 1e-5, 16 * 1e-4),
    ("spotlights_crossing_002", 8e-4, 5e-3),
    ("day_clear", 1e-2, 1.5e-2),
    ("day_heavy_rain", 2.5e-2, 4e-2),
    ("rainbow_after_light_rain", 2e-2, 3e-2),
    pytest.param("clouds_cumulus_town", 3e-2, 8e-2, marks=pytest.mark.slow),
]


@pytest.mark.parametrize(("name", "default_bound", "fast_bound"), BOUNDS)
def test_default_and_fast_presets_stay_within_their_stated_errors(
    name: str, default_bound: float, fast_bound: float
) -> None:
    errors = preset_errors(name, *((64, 36) if name.startswith("clouds") else (96, 54)))
    assert float(errors["default"].max()) <= default_bound
    assert float(errors["fast"].max()) <= fast_bound
    # The fast preset is a different image (its knobs reach the renderer), except where culling
    # finds nothing to skip at either threshold (the 16-lamp street).
    if name != "foggy_street":
        assert float(errors["fast"].max()) > 0.0
