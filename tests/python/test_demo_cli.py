"""The airlight-demo command line: success writes the file; every failure exits
non-zero with exactly one line on stderr that says what is wrong."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

DEMO = Path(sys.executable).with_name("airlight-demo")


def _demo(*args: str) -> subprocess.CompletedProcess:
    if not DEMO.exists():
        pytest.skip(f"{DEMO} is not installed")
    return subprocess.run([str(DEMO), *args], capture_output=True, text=True, timeout=60)


def _assert_one_line_error(proc: subprocess.CompletedProcess, *needles: str) -> str:
    assert proc.returncode != 0, f"exit 0; stdout {proc.stdout!r}"
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, f"expected exactly one line on stderr, got {proc.stderr!r}"
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    return lines[0]


@pytest.fixture
def scene_file(tmp_path: Path, scene_factory) -> Path:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene_factory()))
    return path


def _write_scene(tmp_path: Path, scene: dict) -> Path:
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    return path


@pytest.mark.parametrize("ext", ["png", "pfm"])
def test_demo_exits_zero_and_writes_the_file(
        tmp_path: Path, scene_file: Path, backend: str, ext: str) -> None:
    out = tmp_path / f"x.{ext}"
    proc = _demo("--scene", str(scene_file), "--out", str(out), "--backend", backend, "--width", "40",
                 "--height", "30")
    assert proc.returncode == 0, proc.stderr
    assert out.is_file() and out.stat().st_size > 0
    assert proc.stderr == "", "a successful run with an explicit backend prints nothing on stderr"
    assert backend in proc.stdout


def test_demo_uses_the_scene_film_size_without_overrides(tmp_path: Path, scene_factory) -> None:
    path = _write_scene(tmp_path, scene_factory(film={"width": 30, "height": 20}))
    out = tmp_path / "x.png"
    proc = _demo("--scene", str(path), "--out", str(out), "--backend", "cpu")
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as png:
        assert png.size == (30, 20)
        assert np.asarray(png).any()


@pytest.mark.parametrize(("args", "size"), [(["--width", "40"], (40, 30)), (["--height", "45"], (60, 45)),
                                            (["--width", "40", "--height", "10"], (40, 10))])
def test_demo_width_or_height_alone_keeps_the_aspect_ratio(tmp_path: Path, scene_file: Path, args: list[str],
                                                           size: tuple[int, int]) -> None:
    """The scene's film is 160x120: --width or --height alone keeps its aspect ratio (issue 17)."""
    out = tmp_path / "x.png"
    proc = _demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu", *args)
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as png:
        assert png.size == size


def test_demo_auto_backend_renders(tmp_path: Path, scene_file: Path) -> None:
    """--backend auto picks what airlight.backend_info() says and names the GL renderer it found
    (issue 17): the CPU where it is a software rasteriser (llvmpipe)."""
    import airlight

    out = tmp_path / "x.png"
    proc = _demo("--scene", str(scene_file), "--out", str(out), "--width", "16", "--height", "12")
    assert proc.returncode == 0, proc.stderr
    assert out.is_file()
    info = airlight.backend_info()
    assert f"({info['auto']} backend" in proc.stdout, proc.stdout
    if info["gl_available"]:
        assert f"backend auto: {info['auto']} " in proc.stdout, proc.stdout
        assert info["gl_renderer"] in proc.stdout, proc.stdout
        assert proc.stderr == ""


@pytest.mark.parametrize(("edit", "field"), [
    (lambda s: s["camera"].update(fov_y=200), "camera.fov_y"),
    (lambda s: s["medium"].update(sigma_t=-1), "medium.sigma_t"),
    (lambda s: s["surfaces"][1].update(max=[-4, 0, -12]), "surfaces[1].max"),
    (lambda s: s.update(camra=s.pop("camera")), "camra"),
    (lambda s: s["lights"][0].update(type="area"), "lights[0].type"),
    (lambda s: s["film"].update(width="wide"), "film.width"),
])
def test_demo_bad_scene_exits_nonzero_with_one_line_naming_the_field(
        tmp_path: Path, scene_factory, edit, field: str) -> None:
    scene = scene_factory()
    edit(scene)
    out = tmp_path / "x.png"
    proc = _demo("--scene", str(_write_scene(tmp_path, scene)), "--out", str(out), "--backend", "cpu")
    _assert_one_line_error(proc, field)
    assert not out.exists()


def test_demo_invalid_json_exits_nonzero_with_one_line(tmp_path: Path) -> None:
    """The file, then where the JSON breaks, without the parser library's prefix (issue 17)."""
    path = tmp_path / "broken.json"
    path.write_text('{"film": {"width": 10,\n\n "height": }')
    proc = _demo("--scene", str(path), "--out", str(tmp_path / "x.png"), "--backend", "cpu")
    line = _assert_one_line_error(proc, "JSON")
    assert line.startswith(f"airlight-demo: {path}: invalid JSON at line 3, column 12: syntax error"), line
    assert "json.exception" not in line, line


def test_demo_missing_scene_file_exits_nonzero_with_one_line(tmp_path: Path) -> None:
    missing = tmp_path / "missing.json"
    proc = _demo("--scene", str(missing), "--out", str(tmp_path / "x.png"))
    line = _assert_one_line_error(proc, str(missing))
    assert line == f"airlight-demo: scene file not found: {missing}", line


@pytest.mark.parametrize("args", [["--bogus", "1"], ["--bogus"], ["-x"], ["extra"]])
def test_demo_unknown_option_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path, args) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), *args)
    _assert_one_line_error(proc, args[0])
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("value", ["0", "-3", "abc", "12abc", "16385", "1.5", ""])
def test_demo_bad_width_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path, value: str) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), "--width", value)
    _assert_one_line_error(proc, "--width")


def test_demo_bad_height_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), "--height", "0")
    _assert_one_line_error(proc, "--height")


@pytest.mark.parametrize("value", ["-1", "nan", "inf", "bright"])
def test_demo_bad_exposure_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path, value: str) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), "--exposure", value)
    _assert_one_line_error(proc, "--exposure")


@pytest.mark.parametrize("name", ["x.jpg", "x.PNG.txt", "x", "x.tif", "x.EXR"])
def test_demo_unsupported_output_extension_exits_nonzero_with_one_line(
        tmp_path: Path, scene_file: Path, name: str) -> None:
    out = tmp_path / name
    _assert_one_line_error(_demo("--scene", str(scene_file), "--out", str(out)), "--out")
    assert not out.exists()


def test_demo_bad_backend_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), "--backend", "vulkan")
    _assert_one_line_error(proc, "--backend")


def test_demo_missing_required_options_exit_nonzero_with_one_line(tmp_path: Path, scene_file: Path) -> None:
    _assert_one_line_error(_demo("--out", str(tmp_path / "x.png")), "--scene")
    _assert_one_line_error(_demo("--scene", str(scene_file)), "--out")
    _assert_one_line_error(_demo("--scene"), "--scene")


def test_demo_unwritable_output_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "no_such_dir" / "x.png"
    _assert_one_line_error(_demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu",
                                 "--width", "8", "--height", "8"), str(out))


def test_demo_help_exits_zero_with_usage() -> None:
    for flag in ("--help", "-h"):
        proc = _demo(flag)
        assert proc.returncode == 0
        assert "usage" in proc.stdout and "--scene" in proc.stdout
        assert proc.stderr == ""


def test_demo_help_documents_the_window_and_its_keys() -> None:
    """--help shows --window without a required --out and every key of the window (issue 17:
    Esc was not documented)."""
    proc = _demo("--help")
    assert proc.returncode == 0
    assert "--window [--out" in proc.stdout, proc.stdout
    for key in ("W/S", "A/D", "Q/E", "arrow keys", "+/-", "Esc"):
        assert key in proc.stdout, (key, proc.stdout)


def test_demo_window_needs_no_out(tmp_path: Path, scene_file: Path) -> None:
    """--window without --out is accepted (the last frame is saved only when --out is given):
    here, without a display, it fails only for want of a window, on one line."""
    if not DEMO.exists():
        pytest.skip(f"{DEMO} is not installed")
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.run([str(DEMO), "--scene", str(scene_file), "--window", "--backend", "cpu"],
                          capture_output=True, text=True, timeout=60, env=env)
    line = _assert_one_line_error(proc, "window")
    assert "--out" not in line, line


@pytest.mark.parametrize(("args", "needle"), [
    (["--window", "--sequence", "approaching-car", "--out", "{tmp}/frames"], "--window"),
    (["--window", "--out", "{tmp}/x.jpg"], "--out"),
])
def test_demo_bad_window_options_exit_nonzero_with_one_line(tmp_path: Path, scene_file: Path,
                                                            args: list[str], needle: str) -> None:
    _assert_one_line_error(_demo("--scene", str(scene_file), *(a.format(tmp=tmp_path) for a in args)), needle)
    assert not any(tmp_path.glob("frames*")) and not (tmp_path / "x.jpg").exists()


def _demo_without_gl(*args: str) -> subprocess.CompletedProcess:
    if not DEMO.exists():
        pytest.skip(f"{DEMO} is not installed")
    env = {**os.environ, "AIRLIGHT_DISABLE_GL": "1"}
    return subprocess.run([str(DEMO), *args], capture_output=True, text=True, timeout=60, env=env)


def test_demo_gl_backend_where_unavailable_exits_nonzero_with_one_line(
        tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "x.png"
    proc = _demo_without_gl("--scene", str(scene_file), "--out", str(out), "--backend", "gl")
    _assert_one_line_error(proc, "GL")
    assert not out.exists()


def test_demo_auto_backend_falls_back_to_cpu_where_gl_is_unavailable(
        tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "x.pfm"
    proc = _demo_without_gl("--scene", str(scene_file), "--out", str(out), "--width", "16", "--height", "12")
    assert proc.returncode == 0, proc.stderr
    assert "cpu" in proc.stdout
    assert out.is_file()


@pytest.mark.parametrize(("args", "needle"), [
    (["--pupil", "0.5"], "--pupil"),
    (["--pupil", "12"], "--pupil"),
    (["--pupil", "wide"], "--pupil"),
    (["--tonemap", "aces"], "--tonemap"),
    (["--white", "0"], "--white"),
    (["--white", "-2"], "--white"),
    (["--sequence", "parade"], "--sequence"),
    (["--sequence", "approaching-car", "--frames", "0"], "--frames"),
    (["--sequence", "approaching-car", "--from", "10", "--to", "20"], "--to"),
])
def test_demo_bad_display_option_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path,
                                                             args: list[str], needle: str) -> None:
    proc = _demo("--scene", str(scene_file), "--out", str(tmp_path / "x.png"), *args)
    _assert_one_line_error(proc, needle)
    assert not (tmp_path / "x.png").exists()


def test_demo_bad_display_object_in_the_scene_names_the_field(tmp_path: Path, scene_factory) -> None:
    path = _write_scene(tmp_path, scene_factory(display={"glare": {"pupil_diameter": 11}}))
    _assert_one_line_error(_demo("--scene", str(path), "--out", str(tmp_path / "x.png")),
                           "display.glare.pupil_diameter")


def _approaching_car() -> Path:
    return Path(__file__).resolve().parents[2] / "scenes" / "approaching_car.json"


@pytest.mark.parametrize(("args", "names"), [
    (["--frames", "1", "--from", "20"], ["frame_00_0020m.png"]),
    (["--frames", "1", "--from", "25", "--to", "10"], ["frame_00_0025m.png"]),
    (["--frames", "2", "--from", "20", "--to", "20"], ["frame_00_0020m.png", "frame_01_0020m.png"]),
])
def test_demo_approaching_car_renders_a_single_distance(tmp_path: Path, args: list[str],
                                                        names: list[str]) -> None:
    """One frame (at --from), or --from equal to --to, is a sequence too (issue 17): at 20-25 m
    the car's two headlights are two bright spots either side of a darker middle."""
    out = tmp_path / "frames"
    proc = _demo("--scene", str(_approaching_car()), "--out", str(out), "--backend", "cpu", "--sequence",
                 "approaching-car", "--width", "64", "--height", "36", "--exposure", "1", *args)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == names
    for name in names:
        with Image.open(out / name) as png:
            row = np.asarray(png.convert("RGB")).astype(int)[16:20, :, 1].max(axis=0)
        left, right = int(np.argmax(row[:32])), 32 + int(np.argmax(row[32:]))
        assert min(row[left], row[right]) > 150 and left < 30 and right > 33, row.tolist()
        assert row[31:33].max() < 0.8 * min(row[left], row[right]), row.tolist()


def test_demo_approaching_car_needs_the_car_in_the_scene(tmp_path: Path, scene_factory) -> None:
    path = _write_scene(tmp_path, scene_factory(lights=[]))
    proc = _demo("--scene", str(path), "--out", str(tmp_path / "frames"), "--sequence", "approaching-car")
    _assert_one_line_error(proc, "approaching-car", "lights")


def test_demo_renders_the_approaching_car_preset_alone(tmp_path: Path) -> None:
    """scenes/approaching_car.json without --sequence shows the car 200 m away: two headlights
    (not a black frame)."""
    out = tmp_path / "car.png"
    proc = _demo("--scene", str(_approaching_car()), "--out", str(out), "--backend", "cpu", "--width", "160",
                 "--height", "90", "--exposure", "1")
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as png:
        pixels = np.asarray(png.convert("RGB")).astype(int)
    assert pixels.max() > 200, "the preset renders black"


@pytest.mark.slow
def test_demo_renders_the_approaching_car_sequence(tmp_path: Path, backend: str) -> None:
    """The headlight experiment: one PNG per distance, named by frame and distance; at 2 km
    the two headlights are one spot in the middle, at 20 m two spots either side of a
    darker middle (1.5 m apart: 5.5 pixels each side at 14 degrees over 36 rows). Pixels 10
    times the scene's on a side hold 100 times the solid angle: exposure 1, not 0.01."""
    scene = _approaching_car()
    out = tmp_path / "frames"
    proc = _demo("--scene", str(scene), "--out", str(out), "--backend", backend, "--sequence",
                 "approaching-car", "--frames", "3", "--width", "64", "--height", "36", "--exposure", "1")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("glare") == 3
    names = sorted(p.name for p in out.iterdir())
    assert names == ["frame_00_2000m.png", "frame_01_0200m.png", "frame_02_0020m.png"]
    rows = []
    for name in names:
        with Image.open(out / name) as png:
            pixels = np.asarray(png.convert("RGB")).astype(int)
        assert pixels.shape == (36, 64, 3)
        rows.append(pixels[16:20, :, 1].max(axis=0))
    far, near = rows[0], rows[2]
    assert far[30:34].max() > 150 and far[30:34].max() == far.max(), far.tolist()
    left, right = int(np.argmax(near[:32])), 32 + int(np.argmax(near[32:]))
    assert 24 <= left <= 29 and 35 <= right <= 40, near.tolist()
    assert near[31:33].max() < 0.8 * min(near[left], near[right]), near.tolist()


@pytest.mark.slow
def test_demo_renders_the_rain_ends_sequence(tmp_path: Path, backend: str) -> None:
    """The end of a shower (issue 7): one PNG per frame named by the drop density, falling
    100-fold; the sun comes out over the first 40 % (the first frame, sunless, is the darkest
    and has no bow); then the bow fades with the drops: the primary's ring (136.5-139.5 degrees
    of scattering angle) is brighter than the dark band outside it (131-135) by 2 levels or more
    in the second frame and by less than a third of that in the last. Multiple scattering is off:
    its sky light changes with the scattering angle across those bands too (a gradient that this
    contrast measure would count as bow)."""
    from reference import camera_rays

    import airlight

    preset = Path(__file__).resolve().parents[2] / "scenes" / "rainbow_after_heavy_rain.json"
    scene_json = json.loads(preset.read_text())
    scene_json["quality"] = {**scene_json.get("quality", {}), "multiple_scattering": False}
    path = tmp_path / "rainbow_after_heavy_rain.json"
    path.write_text(json.dumps(scene_json))
    out = tmp_path / "frames"
    proc = _demo("--scene", str(path), "--out", str(out), "--backend", backend, "--sequence", "rain-ends",
                 "--frames", "5", "--width", "160", "--height", "100")
    assert proc.returncode == 0, proc.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == [f"frame_{k:02d}_density_{d}.png"
                     for k, d in enumerate(("0.0400", "0.0126", "0.0040", "0.0013", "0.0004"))]
    frames = []
    for name in names:
        with Image.open(out / name) as png:
            frames.append(np.asarray(png.convert("RGB")).astype(float).mean(axis=-1))
    assert frames[0].mean() < 0.8 * frames[2].mean()
    scene = airlight.preset("rainbow_after_heavy_rain")
    _, dirs = camera_rays(scene["camera"], 160, 100)
    el, az = np.radians(scene["sun"]["elevation"]), np.radians(scene["sun"]["azimuth"])
    sun = np.array([np.sin(az) * np.cos(el), np.sin(el), -np.cos(az) * np.cos(el)])
    angle = np.degrees(np.arccos(np.clip(dirs @ sun, -1.0, 1.0)))
    sky = dirs[..., 1] > 0.05
    primary, band = sky & (angle > 136.5) & (angle < 139.5), sky & (angle > 131.0) & (angle < 135.0)
    contrast = [float(f[primary].mean() - f[band].mean()) for f in frames]
    assert contrast[0] < 0.0 and contrast[1] > 2.0 and contrast[4] < contrast[1] / 3.0, contrast


@pytest.mark.parametrize("edit, needle", [
    (lambda s: s["atmosphere"].pop("rain"), "atmosphere.rain"),
    (lambda s: (s.pop("sun"), s.update(sky={"model": "overcast", "zenith_radiance": [0.3] * 3})), "sun"),
])
def test_demo_rain_ends_needs_rain_and_a_sun(tmp_path: Path, edit, needle: str) -> None:
    import airlight

    scene = airlight.preset("rainbow_after_heavy_rain")
    edit(scene)
    path = _write_scene(tmp_path, scene)
    proc = _demo("--scene", str(path), "--out", str(tmp_path / "frames"), "--sequence", "rain-ends")
    _assert_one_line_error(proc, "rain-ends", needle)
