"""Scenes past the GL driver's loop limit are still right on GL (issue 27, item 2).

Mesa's llvmpipe ends all the loops of a shader invocation once it has run
65535 loop iterations in all, without a word: thousands of lamps or spots over
lit surfaces lost up to 81 % of their light on GL. render.frag's last loop
detects a spent budget and the renderer recomputes those pixels on the CPU
(Renderer.cpu_fallback_pixels counts them)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import airlight
from conftest import skip_unless_backend_available

ROOT = Path(__file__).resolve().parents[2]


def many_lights(count: int, kind: str) -> dict:
    rng = np.random.default_rng(1)
    lights = []
    for _ in range(count):
        light = {"type": kind, "intensity": [10, 9, 7],
                 "position": [float(rng.uniform(-50, 50)), float(rng.uniform(2, 10)),
                              float(rng.uniform(-100, -5))]}
        if kind == "spot":
            light.update(direction=[0, -1, 0], cone_angle=30)
        lights.append(light)
    return {"film": {"width": 16, "height": 12},
            "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 60},
            "medium": {"sigma_t": 0.05, "albedo": 1.0, "phase": {"type": "isotropic"}},
            "lights": lights,
            "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
                         {"type": "box", "min": [-8, 0, -40], "max": [-4, 12, -25], "albedo": 0.5}]}


@pytest.mark.slow
@pytest.mark.parametrize(("count", "kind"), [(12000, "point"), (1000, "spot")])
def test_lights_past_the_gl_loop_limit_are_not_dropped(count, kind, renderer_cache):
    skip_unless_backend_available("gl")
    scene = many_lights(count, kind)
    gl = renderer_cache("gl")
    on_gl = gl.render(scene)
    assert gl.cpu_fallback_pixels > 0  # the scene does go past the limit
    on_cpu = renderer_cache("cpu").render(scene)
    scale = float(on_cpu.max())
    np.testing.assert_allclose(on_gl, on_cpu, rtol=2e-3, atol=1e-6 * scale)


@pytest.mark.parametrize("name", ["default", "foggy_street", "day_clear", "spotlights_crossing_002",
                                  "rainbow_after_heavy_rain", "crane_searchlight"])
def test_ordinary_scenes_stay_on_gl(name, renderer_cache):
    skip_unless_backend_available("gl")
    gl = renderer_cache("gl")
    gl.render(airlight.load_scene(ROOT / "scenes" / f"{name}.json"), width=32, height=24)
    assert gl.cpu_fallback_pixels == 0


def test_the_cpu_backend_never_falls_back(renderer_cache):
    cpu = renderer_cache("cpu")
    cpu.render(many_lights(10, "point"))
    assert cpu.cpu_fallback_pixels == 0
