"""Culling of the spots' surface glow (effects/lamp_airlight/docs/culling.md; the bound, the
point lamp's glow, is in effects/spotlights/physics.md section 5): a spot's glow at a surface
point is skipped when its bound is below cull_fraction of what the point has summed, the
direct light of every spot included (the glows come in a second pass). So culling may change
a pixel lit by N lights by at most N * cull_fraction of its unculled value, plus the float32
rounding of the sum.

The bound is checked directly: a scene with one spot (and a point lamp, whose light is summed
first and gives the spot's glow something to be compared with) is rendered at cull fractions
from 1e-6 to 1e-2, 1.5x apart, and the surfaces' layer (their radiance, no airlight) is
compared with the unculled one. The lamp's surface light is never skipped (nothing precedes
it), and the spot is at most one skipped term (its direct light and glow together, or its
glow), so every surface pixel must stay within 1 x cull_fraction. Wherever the bound fell
below the glow the spot really computes, some fraction between the two would skip a glow
larger than that, and the pixel would leave its bound. Spots aimed away from the surface, across it, at it
and along it; wide and narrow cones; isotropic, forward, backward, Rayleigh and two-lobe
phases; a coloured medium."""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from airlight_reference import get_renderer, make_scene, plane
from spot_reference import spot

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from effects.lamp_airlight.bench.bench_airlight import street_scene  # noqa: E402  (the scene this culling was made for)

CULL_FRACTIONS = np.geomspace(1e-6, 1e-2, 24)  # the key's range is [0, 0.01]


def _assert_culling_within(exact_scene: dict, cull_fraction: float | None, backend: str, label: str,
                           terms: int | None = None, layer: str = "radiance") -> None:
    """Render exact_scene (cull_fraction 0) and the same with cull_fraction (None: the default),
    and check every pixel and channel of `layer` against `terms` (default: one per light) times
    cull_fraction of the unculled value."""
    assert exact_scene["quality"]["cull_fraction"] == 0.0
    culled_scene = copy.deepcopy(exact_scene)
    del culled_scene["quality"]["cull_fraction"]
    if cull_fraction is not None:
        culled_scene["quality"]["cull_fraction"] = float(cull_fraction)
    fraction = 1e-5 if cull_fraction is None else cull_fraction
    renderer = get_renderer(backend)
    exact = np.asarray(renderer.render(exact_scene, outputs=[layer])[layer], dtype=np.float64)
    culled = np.asarray(renderer.render(culled_scene, outputs=[layer])[layer], dtype=np.float64)
    assert np.all(np.isfinite(exact)) and np.all(np.isfinite(culled))
    lights = len(exact_scene["lights"])
    terms = lights if terms is None else terms
    rounding = 2 * lights * np.spacing(np.maximum(exact, culled).astype(np.float32)).astype(np.float64)
    excess = np.abs(culled - exact) - terms * fraction * exact - rounding
    worst = np.unravel_index(np.argmax(excess), excess.shape)
    assert excess[worst] <= 0, (
        f"{label}, cull_fraction {fraction:.3g}: pixel {tuple(int(i) for i in worst[:2])} channel {worst[2]} "
        f"went from {exact[worst]:.7e} to {culled[worst]:.7e}, more than {terms} x {fraction:.3g} of it "
        f"({int((excess > 0).sum())} values over)")


def _grey_headlight_street() -> dict:
    scene = street_scene(64, 40, 24, surface_albedo=0.3, light_type="headlights")
    scene["quality"] = {"cull_fraction": 0.0}
    return scene


@pytest.mark.parametrize("backend", ["cpu", "gl"])
def test_default_culling_of_64_headlights_over_a_grey_street_keeps_its_bound(backend):
    _assert_culling_within(_grey_headlight_street(), None, backend, f"64 headlights, grey street [{backend}]")


def test_culling_skips_glows_over_a_grey_street():
    """The bound is tight enough to skip something: a large fraction changes the image."""
    scene = _grey_headlight_street()
    renderer = get_renderer("cpu")
    exact = np.asarray(renderer.render(scene))
    culled_scene = copy.deepcopy(scene)
    culled_scene["quality"]["cull_fraction"] = 1e-3
    assert np.any(np.asarray(renderer.render(culled_scene)) != exact)


PHASES: dict[str, Any] = {
    "isotropic": None,
    "hg 0.9": {"type": "hg", "g": 0.9},
    "hg -0.6": {"type": "hg", "g": -0.6},
    "rayleigh": {"type": "rayleigh"},
    "hg2": {"type": "hg2", "forward_g": 0.8, "backward_g": -0.4, "forward_weight": 0.7},
}

# (position, direction, cone angle, edge): the spot over a road (y = 0) with a wall (x = -4).
SPOTS: dict[str, tuple[Any, Any, float, float]] = {
    "aimed away from the road": ((0.0, 1.5, -6.0), (0.2, 0.3, -1.0), 20.0, 0.2),
    "headlight along the road": ((1.0, 0.65, -3.0), (0.0, -0.03, -1.0), 25.0, 0.15),
    "narrow, across the road": ((3.0, 1.0, -8.0), (-1.0, -0.1, 0.0), 5.0, 0.0),
    "wide, down at the road": ((0.0, 4.0, -8.0), (0.3, -1.0, 0.1), 80.0, 0.5),
    "away from the camera, behind the wall": ((-5.0, 2.0, -10.0), (-1.0, 0.0, -0.2), 30.0, 0.3),
}


def _spot_scene(where: str, phase: Any, sigma_t: Any = 0.08) -> dict:
    position, direction, cone, edge = SPOTS[where]
    lights = [{"type": "point", "position": [2.0, 3.0, -30.0], "intensity": 5000.0, "radius": 0.05},
              spot(position, direction, 4000.0, cone, edge, 0.05)]
    surfaces = [plane((0, 0, 0), (0, 1, 0), 0.5), plane((-4, 0, 0), (1, 0, 0), 0.5)]
    return make_scene((0.5, 1.6, 2.0), (0.0, 1.0, -12.0), lights, surfaces, sigma_t=sigma_t, albedo=0.9,
                      width=32, height=24, phase=phase)


@pytest.mark.parametrize("phase", list(PHASES))
@pytest.mark.parametrize("where", list(SPOTS))
def test_spot_glow_bound_holds_at_every_cull_fraction(where, phase):
    scene = _spot_scene(where, PHASES[phase])
    for fraction in CULL_FRACTIONS:
        _assert_culling_within(scene, fraction, "cpu", f"{where}, {phase}", terms=1, layer="surfaces")


def test_spot_glow_bound_holds_in_a_coloured_medium():
    scene = _spot_scene("headlight along the road", None, sigma_t=[0.02, 0.08, 0.3])
    for fraction in CULL_FRACTIONS:
        _assert_culling_within(scene, fraction, "cpu", "coloured medium", terms=1, layer="surfaces")


@pytest.mark.parametrize("phase", ["isotropic", "hg 0.9"])
def test_spot_glow_bound_holds_on_gl(phase):
    scene = _spot_scene("away from the camera, behind the wall", PHASES[phase])
    for fraction in CULL_FRACTIONS[::3]:
        _assert_culling_within(scene, fraction, "gl", f"GL, {phase}", terms=1, layer="surfaces")
