"""The demo's walk in the falling rain (``airlight-demo --sequence rain-walk``; README "The demo"): one
frame per 1/24 s named by its rain time, the drops moving on between frames (the frames differ where
streaks are, and only a little between neighbours), and a scene without falling rain refused in one
line naming it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from conftest import run_demo

SCENE = {
    "film": {"width": 64, "height": 40},
    "camera": {"position": [0, 1.6, 0], "look_at": [0, 1.6, -10], "up": [0, 1, 0], "fov_y": 60},
    "lights": [{"type": "point", "position": [0.5, 2.4, -1.5], "intensity": [300, 280, 250], "radius": 0.05}],
    "falling_rain": {"rate": 30, "radius": 3, "time": 2.0},
    "display": {"exposure": 2.0, "dither": False},
}


def test_rain_walk_renders_one_frame_per_24th_of_a_second(tmp_path: Path) -> None:
    path = tmp_path / "rain.json"
    path.write_text(json.dumps(SCENE))
    out = tmp_path / "frames"
    proc = run_demo(
        "--scene",
        str(path),
        "--out",
        str(out),
        "--backend",
        "cpu",
        "--sequence",
        "rain-walk",
        "--frames",
        "3",
    )
    assert proc.returncode == 0, proc.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == [f"frame_{k:03d}_{2.0 + k / 24:.3f}s.png" for k in range(3)]
    frames = [np.asarray(Image.open(out / n).convert("RGB")).astype(float) for n in names]
    assert all(f.max() > 0 for f in frames)
    assert np.abs(frames[1] - frames[0]).sum() > 0  # the drops moved


def test_rain_walk_needs_falling_rain(tmp_path: Path) -> None:
    scene = {k: v for k, v in SCENE.items() if k != "falling_rain"}
    path = tmp_path / "dry.json"
    path.write_text(json.dumps(scene))
    proc = run_demo("--scene", str(path), "--out", str(tmp_path / "frames"), "--sequence", "rain-walk")
    assert proc.returncode != 0
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and "rain-walk" in lines[0] and "falling_rain" in lines[0], proc.stderr
