"""Shared fixtures of every test (the core's in tests/python, each effect's in
effects/<name>/tests): backend parametrisation, cached renderers, a small base
scene. The test folders are put on sys.path here, so that a test imports the
reference implementations beside it (and the core's helpers) by name."""

from __future__ import annotations

import copy
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

import pytest

import airlight

ROOT = Path(__file__).resolve().parent
TEST_DIRS = [ROOT / "tests" / "python", *sorted(ROOT.glob("effects/*/tests"))]
for _dir in TEST_DIRS:
    if str(_dir) not in sys.path:
        sys.path.insert(0, str(_dir))

BACKENDS = ("cpu", "gl")

# Mesa's llvmpipe compiles each shader variant single-threaded, and on a cold shader cache (every CI
# machine) that compile is most of a GL test's time. Without LLVM's optimisation passes it takes about
# half as long and the images are bit-for-bit the same (measured on three presets); the shaders then run
# up to 2x slower, which the tests' small films do not notice. scripts/test.sh sets it for ctest too.
os.environ.setdefault("GALLIVM_PERF", "nopt")

# Issue 18 turned multiple scattering on by default (quality.multiple_scattering). The tests written
# before it check the single-scattering renderer against single-scattering references, so a scene with
# point lamps in a medium rendered outside effects/multiple_scattering/ renders with it off unless the
# scene sets it.
MULTIPLE_SCATTERING_TESTS = ROOT / "effects" / "multiple_scattering"
# Particle clouds rendered outside effects/particle_clouds/ (the preset sweeps) use the preview lighting
# table unless the scene sets one: the full table is the same code at a finer resolution and costs
# five minutes of both cores on a cold cache, that is on every CI machine; its accuracy is measured by
# effects/particle_clouds/bench/table_resolution.py and the particle tests use the preview table too.
PARTICLE_CLOUDS_TESTS = ROOT / "effects" / "particle_clouds"


def _lamps_single_scattering(scene: dict) -> dict:
    lights = scene.get("lights")
    lamps = isinstance(lights, list) and any(isinstance(x, dict) and x.get("type", "point") == "point"
                                             for x in lights)
    if not (lamps and scene.get("medium")):  # only the lamps' term (the daytime tests set theirs)
        return scene
    quality = scene.get("quality")
    if quality is None or (isinstance(quality, dict) and "multiple_scattering" not in quality):
        scene = {**scene, "quality": {**(quality or {}), "multiple_scattering": False}}
    return scene


def _preview_particle_table(scene: dict) -> dict:
    quality = scene.get("quality")
    if scene.get("particle_clouds") and (quality is None or (isinstance(quality, dict)
                                                             and "particle_table" not in quality)):
        scene = {**scene, "quality": {**(quality or {}), "particle_table": "preview"}}
    return scene


@pytest.fixture(autouse=True)
def scene_defaults_for_tests(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    """The two rules above, applied to every scene a test renders in this process."""
    path = Path(str(request.fspath)).resolve()
    rules = [rule for rule, home in ((_lamps_single_scattering, MULTIPLE_SCATTERING_TESTS),
                                     (_preview_particle_table, PARTICLE_CLOUDS_TESTS))
             if not path.is_relative_to(home)]
    from airlight import _rendering

    original = _rendering._with_film_size

    def adjust(scene: dict) -> dict:
        for rule in rules:
            scene = rule(scene)
        return scene

    def with_test_defaults(scene: Any, width: Any, height: Any) -> Any:
        source = original(adjust(scene) if isinstance(scene, dict) else scene, width, height)
        if isinstance(source, dict):  # JSON text or a file with the film overridden
            return adjust(source)
        if isinstance(source, str):  # JSON text or a file's text
            try:
                data = json.loads(source)
            except (ValueError, RecursionError):
                return source  # the validator names the error
            if isinstance(data, dict):
                return json.dumps(adjust(data))
        return source

    monkeypatch.setattr(_rendering, "_with_film_size", with_test_defaults)


def skip_unless_backend_available(backend: str) -> None:
    """Skips the calling test when ``backend`` cannot run on this machine."""
    if backend == "gl":
        reason = airlight.gl_unavailable_reason()
        if reason is not None:
            pytest.skip(f"GL backend unavailable: {reason}")


@pytest.fixture(params=BACKENDS)
def backend(request: pytest.FixtureRequest) -> str:
    """Each test using it runs once per backend; "gl" is skipped where GL cannot run."""
    skip_unless_backend_available(request.param)
    return request.param


@pytest.fixture(scope="session")
def renderer_cache():
    """``get(backend)``: one airlight.Renderer per backend for the whole session."""
    cache: dict[str, airlight.Renderer] = {}

    def get(name: str) -> airlight.Renderer:
        skip_unless_backend_available(name)
        if name not in cache:
            cache[name] = airlight.Renderer(name)
        return cache[name]

    yield get
    for r in cache.values():
        r.close()


@pytest.fixture
def renderer(backend: str, renderer_cache) -> airlight.Renderer:
    """A (shared) Renderer for the parametrised backend."""
    return renderer_cache(backend)


BASE_SCENE: dict[str, Any] = {
    "film": {"width": 160, "height": 120},
    "camera": {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.0, -10.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 60.0},
    "medium": {"sigma_t": 0.05, "albedo": 1.0, "phase": {"type": "isotropic"}},
    "lights": [
        {"type": "point", "position": [3.0, 5.0, -8.0], "intensity": [100.0, 90.0, 70.0], "radius": 0.1},
    ],
    "surfaces": [
        {"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "albedo": [0.3, 0.3, 0.3]},
        {"type": "box", "min": [-3.0, 0.0, -12.0], "max": [-1.0, 2.0, -9.0], "albedo": 0.5},
        {"type": "sphere", "center": [1.5, 1.0, -10.0], "radius": 1.0, "albedo": [0.7, 0.2, 0.2]},
    ],
    "background": [0.0, 0.0, 0.0],
}


def make_scene(**overrides: Any) -> dict[str, Any]:
    """A deep copy of BASE_SCENE with top-level keys replaced (a value of None for
    "medium" keeps the key as null; use ``drop=[...]`` to remove keys)."""
    drop = overrides.pop("drop", ())
    scene = copy.deepcopy(BASE_SCENE)
    for key, value in overrides.items():
        scene[key] = copy.deepcopy(value)
    for key in drop:
        scene.pop(key, None)
    return scene


DEMO = Path(sys.executable).with_name("airlight-demo")


def run_demo(*args: str) -> subprocess.CompletedProcess:
    """Runs the installed airlight-demo (beside this Python) with ``args``; skips the test
    where it is not installed."""
    if not DEMO.exists():
        pytest.skip(f"{DEMO} is not installed")
    return subprocess.run([str(DEMO), *args], capture_output=True, text=True, timeout=60)


@pytest.fixture
def scene_file(tmp_path: Path, scene_factory) -> Path:
    """The base scene in a fog of per-channel extinction over a coloured background, as a
    file for the demo. Single scattering, as the API renders it in these tests (above); the
    demo reads the file as is."""
    path = tmp_path / "scene.json"
    scene = scene_factory(medium={"sigma_t": [0.01, 0.05, 0.2]}, background=[0.2, 0.3, 0.4],
                          quality={"multiple_scattering": False})
    path.write_text(json.dumps(scene))
    return path


@pytest.fixture
def scene_factory() -> Callable[..., dict[str, Any]]:
    """``scene_factory(**overrides)``: a fresh copy of the small base scene."""
    return make_scene
