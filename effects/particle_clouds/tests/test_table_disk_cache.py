"""The lighting table's disk cache (particle_frame.cpp, build_light_table): a process that finds the
table missing takes the table's lock file before building, so that renderers starting at once (a
batch's workers, parallel test workers) build it once and the others read the builder's file
instead of spending minutes on the same table."""

from __future__ import annotations

import fcntl
import json
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

SCENE = {
    "film": {"width": 12, "height": 8},
    "camera": {"position": [0, 2, 0], "look_at": [300, 1200, -2500], "up": [0, 1, 0], "fov_y": 70},
    "sky": {"model": "overcast", "zenith_radiance": [0.4, 0.5, 0.7]},
    "sun": {"elevation": 35, "azimuth": 30, "irradiance": [10, 9.5, 9]},
    "particle_clouds": {"base": 1000, "top": 2500, "coverage": 0.6, "cell_size": 300, "ring_cells": 6,
                        "rings": 2, "extinction": 0.02, "seed": 3, "g": 0.5},
    "quality": {"particle_table": "preview", "multiple_scattering": False},
}

RENDER = textwrap.dedent("""
    import json, sys
    import numpy as np
    import airlight
    image = airlight.render(json.loads(sys.argv[1]), backend="cpu")
    np.save(sys.argv[2], image)
""")


def render_in(cache: Path, out: Path, scene: dict) -> subprocess.Popen:
    env = {**os.environ, "AIRLIGHT_CACHE_DIR": str(cache)}
    return subprocess.Popen([sys.executable, "-c", RENDER, json.dumps(scene), str(out)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def opens(process: subprocess.Popen, path: Path, timeout: float = 120.0) -> bool:
    """Whether the running process opens ``path`` within ``timeout`` s (its /proc fd links)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and process.poll() is None:
        try:
            links = [os.readlink(fd) for fd in Path(f"/proc/{process.pid}/fd").iterdir()]
        except OSError:  # an fd closed while listing
            links = []
        if str(path) in links:
            return True
        time.sleep(0.05)
    return False


def test_a_process_waits_for_the_table_another_is_building_and_reads_its_file(tmp_path: Path) -> None:
    """The test holds the lock of a missing table (as a builder would); a renderer needing it
    waits on the lock, and once the holder has written a file and let go, uses that file: given
    another g's table under this g's name, its image is not the one it would have built."""
    built, other = tmp_path / "built", tmp_path / "other"
    for cache, g in ((built, 0.5), (other, 0.85)):  # the true table, and another g's, each built normally
        cache.mkdir()
        scene = {**SCENE, "particle_clouds": {**SCENE["particle_clouds"], "g": g}}
        run = render_in(cache, cache / "image.npy", scene)
        assert run.wait(timeout=300) == 0, run.stderr.read() if run.stderr else ""
    (name,) = [p.name for p in built.glob("particle_light_*.bin")]
    (other_file,) = other.glob("particle_light_*.bin")

    shared = tmp_path / "shared"
    shared.mkdir()
    with open(shared / (name + ".lock"), "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        waiting = render_in(shared, shared / "image.npy", SCENE)
        assert opens(waiting, shared / (name + ".lock")), "the renderer never opened the table's lock"
        time.sleep(0.5)
        assert waiting.poll() is None, "the renderer did not wait for the lock"
        (shared / name).write_bytes(other_file.read_bytes())  # the "builder's" file
        fcntl.flock(lock, fcntl.LOCK_UN)
    assert waiting.wait(timeout=300) == 0, waiting.stderr.read() if waiting.stderr else ""
    got = np.load(shared / "image.npy")
    assert np.all(np.isfinite(got))
    assert not np.array_equal(got, np.load(built / "image.npy"))  # it read the file, it did not build
