"""Batch sweeps (issue 25, airlight.batch, README "Datasets: batch sweeps"): the sweep's
expansion (deterministic, seeded), its checks, and runs on Ray in a local cluster: the
files each item leaves, the metadata reproducing the item, the same seed giving the same
dataset, a killed run resumed without loss, a bad item reported by name."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

import airlight
from airlight import batch

NIGHT: dict[str, Any] = {
    "film": {"width": 24, "height": 16},
    "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.2, -10], "up": [0, 1, 0], "fov_y": 60},
    "medium": {"sigma_t": 0.03, "albedo": 0.9},
    "lights": [{"type": "point", "position": [1, 4, -8], "intensity": 80, "radius": 0.2}],
    "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
                 {"type": "box", "min": [-3, 0, -12], "max": [-1, 3, -9], "albedo": 0.5}],
    "quality": {"multiple_scattering": False},
}


def sweep(**extra: Any) -> dict[str, Any]:
    return {"scenes": [NIGHT], "vary": {"medium.sigma_t": [0.01, 0.05],
                                        "lights[0].intensity": {"loguniform": [10, 1000]}},
            "outputs": ["depth", "transmittance", "layers"], "masks": ["sky", "lights"], "seed": 7, **extra}


# ---- the sweep description ------------------------------------------------------------

def test_expand_is_scenes_by_cameras_by_grid_by_repeat() -> None:
    cams = [{"position": [0, 2, 0], "look_at": [0, 2, -1]},
            {"path": {"from": {"position": [0, 2, 0], "look_at": [0, 2, -1]},
                      "to": {"position": [0, 2, -10], "look_at": [0, 2, -11]}, "frames": 3}}]
    items = batch.expand({**sweep(), "cameras": cams, "repeat": 2,
                          "vary": {"medium.sigma_t": {"range": [0.01, 0.03], "steps": 3}}})
    assert len(items) == 1 * 4 * 3 * 2
    assert [it.id for it in items] == [f"{i:06d}" for i in range(24)]
    assert [it.scene["camera"]["position"][2] for it in items[::6]] == [0.0, 0.0, -5.0, -10.0]
    assert [it.parameters["medium.sigma_t"] for it in items[:6]] == pytest.approx([0.01] * 2 + [0.02] * 2
                                                                                  + [0.03] * 2)
    assert items[0].scene["camera"]["up"] == NIGHT["camera"]["up"]  # the rest of the camera kept


def test_random_parameters_are_seeded_per_item() -> None:
    a, b = batch.expand(sweep()), batch.expand(sweep())
    assert [it.parameters for it in a] == [it.parameters for it in b]
    other = batch.expand(sweep(seed=8))
    assert [it.parameters for it in a] != [it.parameters for it in other]
    values = [it.scene["lights"][0]["intensity"] for it in a]
    assert all(10 <= v <= 1000 for v in values) and len(set(values)) == len(values)


def test_key_paths_reach_into_lists_and_create_objects() -> None:
    assert batch.key_path("lights[0].intensity") == ["lights", 0, "intensity"]
    assert batch.key_path("lights.0.intensity") == ["lights", 0, "intensity"]
    scene: dict[str, Any] = {"lights": [{"intensity": 1}]}
    batch.set_path(scene, "atmosphere.rain.rate", 5.0)
    batch.set_path(scene, "lights[0].intensity", [1, 2, 3])
    assert scene == {"lights": [{"intensity": [1, 2, 3]}], "atmosphere": {"rain": {"rate": 5.0}}}


@pytest.mark.parametrize("change, error, message", [
    ({"scenes": None}, ValueError, "scenes: required"),
    ({"scenes": ["no_such_preset"]}, ValueError, "scenes[0]: 'no_such_preset' is neither a preset"),
    ({"vary": {"medium.sigma_t": []}}, ValueError, "vary['medium.sigma_t']: an empty list"),
    ({"vary": {"a.b": {"gauss": [0, 1]}}}, ValueError, "vary['a.b']: unknown rule 'gauss'"),
    ({"vary": {"a": {"uniform": [1]}}}, ValueError, "vary['a'].uniform: expected two finite numbers"),
    ({"vary": {"a": {"range": [0, 1], "steps": 0}}}, ValueError, "vary['a'].steps: expected an integer >= 1"),
    ({"outputs": ["albedo"]}, ValueError, "outputs[0]: unknown output 'albedo'"),
    ({"masks": ["clouds"]}, ValueError, "masks: expected a list of sky, lights"),
    ({"film": {"width": 0}}, ValueError, "film.width: expected an integer in [1, 16384]"),
    ({"repeat": 0}, ValueError, "repeat: expected an integer >= 1"),
    ({"colour": 1}, ValueError, "colour: unknown key"),
    ({"backend": "vulkan"}, ValueError, "backend: must be auto, gl or cpu"),
])
def test_bad_spec_names_the_key(change, error, message) -> None:
    with pytest.raises(error) as e:
        batch.load_spec({**sweep(), **change})
    assert str(e.value).startswith(message), str(e.value)


def test_yaml_and_json_files_are_the_same_sweep(tmp_path: Path) -> None:
    import yaml

    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sweep()))
    (tmp_path / "s.json").write_text(json.dumps(sweep()))
    a, b = batch.expand(tmp_path / "s.yaml"), batch.expand(str(tmp_path / "s.json"))
    assert [(it.id, it.scene) for it in a] == [(it.id, it.scene) for it in b]


# ---- runs on Ray ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def ray_cluster():
    ray = pytest.importorskip("ray")
    started = not ray.is_initialized()
    if started:
        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    if started:
        ray.shutdown()


def check_dataset(out: Path, spec: dict[str, Any]) -> list[dict[str, Any]]:
    """Every item of the sweep is in the index with its files; returns the index."""
    items = batch.expand(spec)
    index = [json.loads(line) for line in (out / "index.jsonl").read_text().splitlines()]
    assert [r["id"] for r in index] == [it.id for it in items]
    for record in index:
        for name in record["files"].values():
            assert (out / "items" / name).is_file(), name
    assert not [p for p in (out / "items").iterdir() if p.name.startswith(".")], "temporary files left"
    return index


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["cpu", "gl"])
def test_a_sweep_writes_items_that_reproduce_from_their_metadata(ray_cluster, tmp_path, backend) -> None:
    if backend == "gl" and airlight.gl_unavailable_reason() is not None:
        pytest.skip(f"GL backend unavailable: {airlight.gl_unavailable_reason()}")
    spec = sweep(backend=backend)
    summary = batch.run(spec, tmp_path, workers=2, progress=False)
    assert (summary.succeeded, summary.failed, summary.skipped, summary.total) == (2, 0, 0, 2)
    index = check_dataset(tmp_path, spec)
    with airlight.Renderer(backend) as renderer:
        for record in index:
            meta = json.loads((tmp_path / "items" / f"{record['id']}.json").read_text())
            assert meta["backend"] == backend and meta["airlight_version"] == airlight.__version__
            assert meta["timings"]["render_s"] > 0
            stored = airlight.load_exr(tmp_path / "items" / record["files"]["exr"])
            assert set(stored) == {"radiance", "depth", "transmittance", *airlight.LAYERS}
            again = renderer.render(meta["scene"], outputs=list(stored))
            for name, values in again.items():
                np.testing.assert_array_equal(stored[name], values, err_msg=name)  # float32 EXR: exact
            sky = np.asarray(Image.open(tmp_path / "items" / record["files"]["mask_sky"]))
            np.testing.assert_array_equal(sky == 255, np.isinf(stored["depth"]))


@pytest.mark.slow
def test_the_same_seed_gives_the_same_dataset(ray_cluster, tmp_path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    batch.run(sweep(), a, workers=2, progress=False)
    batch.run(sweep(), b, workers=1, progress=False)
    assert (a / "index.jsonl").read_text() == (b / "index.jsonl").read_text()
    for record in check_dataset(a, sweep()):
        left = airlight.load_exr(a / "items" / record["files"]["exr"])
        right = airlight.load_exr(b / "items" / record["files"]["exr"])
        for name in left:
            np.testing.assert_array_equal(left[name], right[name])


@pytest.mark.slow
def test_a_bad_item_is_reported_by_name_and_the_rest_complete(ray_cluster, tmp_path) -> None:
    spec = sweep(vary={"medium.sigma_t": [0.01, -1.0, 0.02]})
    summary = batch.run(spec, tmp_path, workers=2, progress=False)
    assert (summary.succeeded, summary.failed) == (2, 1)
    failures = [json.loads(line) for line in (tmp_path / "failures.jsonl").read_text().splitlines()]
    assert [f["id"] for f in failures] == ["000001"] and failures[0]["failed"] == "scene"
    assert failures[0]["error"].startswith("medium.sigma_t")
    index = [json.loads(line)["id"] for line in (tmp_path / "index.jsonl").read_text().splitlines()]
    assert index == ["000000", "000002"]
    assert not list((tmp_path / "items").glob("000001*"))


@pytest.mark.slow
def test_a_killed_run_resumes_without_loss(ray_cluster, tmp_path) -> None:
    spec = sweep(vary={"medium.sigma_t": [0.01, 0.02, 0.03, 0.04, 0.05, 0.06]})
    (tmp_path / "spec.json").write_text(json.dumps(spec))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "airlight.batch", str(tmp_path / "spec.json"),
                             "--out", str(out), "--workers", "1", "--no-progress"], start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if (out / "items").is_dir() and list((out / "items").glob("*.json")):
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver and its Ray processes, mid-sweep
    proc.wait()
    done_before = len(list((out / "items").glob("*.json")))
    summary = batch.run(spec, out, workers=2, progress=False)
    assert summary.skipped == done_before and summary.succeeded == 6 - done_before and summary.failed == 0
    for record in check_dataset(out, spec):
        airlight.load_exr(out / "items" / record["files"]["exr"])  # whole files only


@pytest.mark.slow
def test_command_line_runs_a_yaml_sweep_and_reports_failures(tmp_path) -> None:
    import yaml

    (tmp_path / "s.yaml").write_text(yaml.safe_dump(sweep(vary={"medium.sigma_t": [0.01, -1.0]})))
    proc = subprocess.run([sys.executable, "-m", "airlight.batch", str(tmp_path / "s.yaml"), "--out",
                           str(tmp_path / "out"), "--workers", "1", "--no-progress"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1, proc.stderr
    assert "1 rendered, 0 skipped (already written), 1 failed, of 2" in proc.stdout
    assert "item 000001 failed (scene): medium.sigma_t" in proc.stderr


def test_command_line_bad_spec_exits_2_with_one_line(tmp_path) -> None:
    (tmp_path / "s.json").write_text(json.dumps({**sweep(), "outputs": ["albedo"]}))
    proc = subprocess.run([sys.executable, "-m", "airlight.batch", str(tmp_path / "s.json"), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.strip() == ("airlight-batch: outputs[0]: unknown output 'albedo'; one of "
                                   f"{', '.join(airlight.OUTPUTS)}, or 'layers'")


def test_the_readme_sweep_is_the_example_file_and_expands_to_27_items() -> None:
    root = Path(__file__).resolve().parents[2]
    example = root / "examples" / "sweep_foggy_street.yaml"
    body = "".join(line + "\n" for line in example.read_text().splitlines() if not line.startswith("#"))
    assert f"```yaml\n{body}```" in (root / "README.md").read_text()
    items = batch.expand(example)
    assert len(items) == 27
    for it in items:
        airlight.load_scene(it.scene)  # every item valid


def test_film_width_alone_keeps_each_scene_aspect_ratio() -> None:
    items = batch.expand({**sweep(), "scenes": [NIGHT, "day_clear"], "film": {"width": 48}, "vary": {}})
    assert [it.scene["film"] for it in items] == [{"width": 48, "height": 32}, {"width": 48, "height": 27}]
    for it in items:
        airlight.load_scene(it.scene)


@pytest.mark.parametrize("path", ["", "a..b", "a[x]", "[0]", "a.", "a[0", 3])
def test_bad_key_paths_are_refused(path) -> None:
    with pytest.raises(ValueError, match="vary: bad key path"):
        batch.key_path(path)
