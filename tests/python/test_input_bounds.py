"""Unbounded reads and messages (issue 27, items 8 and 11): load_scene('/dev/zero') grew
to 12 GB, a list of 10^7 elements took 28 s and 670 MB before it was refused, a 100 MB
unknown key was echoed whole in the error, a key with an embedded NUL cut the message
short, and JSON text starting with a byte order mark was taken for a path."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import airlight

BASE = {"film": {"width": 4, "height": 3},
        "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 60}}


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_an_endless_file_is_refused_after_64_mib():
    with pytest.raises(ValueError, match=r"^scene file /dev/zero is larger than 64 MiB$"):
        airlight.load_scene("/dev/zero")


def test_a_huge_file_is_refused_by_python_and_by_the_demo(tmp_path):
    big = tmp_path / "big.json"
    with open(big, "wb") as f:
        f.truncate((64 << 20) + 1)
    with pytest.raises(ValueError, match="larger than 64 MiB"):
        airlight.load_scene(big)
    demo = Path(sys.executable).with_name("airlight-demo")
    if not demo.exists():
        pytest.skip(f"{demo} is not installed")
    done = subprocess.run([str(demo), "--scene", str(big), "--out", str(tmp_path / "x.png")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.strip() == f"airlight-demo: scene file {big} is larger than 64 MiB", done.stderr


def test_a_list_of_ten_million_elements_is_refused_before_conversion():
    scene = dict(BASE, lights=[0] * 10_000_000)
    with pytest.raises(ValueError, match=r"^lights: list too long \(10000000 elements, at most 1048576\)$"):
        airlight.load_scene(scene)


def test_a_huge_unknown_key_is_not_echoed_whole():
    scene = dict(BASE, **{"x" * 10_000_000: 1})
    with pytest.raises(ValueError) as info:
        airlight.load_scene(scene)
    message = str(info.value)
    assert len(message) < 1000 and "more bytes" in message, message[:300]


def test_a_key_with_an_embedded_nul_is_named_whole():
    scene = dict(BASE, **{"bad\x00key": 1})
    with pytest.raises(ValueError) as info:
        airlight.load_scene(scene)
    assert "bad\\x00key" in str(info.value)


def test_json_text_with_a_byte_order_mark_is_json(tmp_path):
    text = "\ufeff" + json.dumps(BASE)
    assert airlight.load_scene(text)["film"]["width"] == 4
    path = tmp_path / "bom.json"
    path.write_bytes(text.encode("utf-8"))
    assert airlight.load_scene(path)["film"]["width"] == 4


def test_an_empty_key_is_named_in_the_message():
    """Fuzz finding bad-input-empty-key: '' gave 'camera.: unknown key' (no field)."""
    scene = {**BASE, "camera": {**BASE["camera"], "": 1}}
    with pytest.raises(ValueError, match=r'^camera\."": unknown key'):
        airlight.load_scene(scene)
    with pytest.raises(ValueError, match=r'^"": unknown key'):
        airlight.load_scene({**BASE, "": 1})


def test_display_white_takes_its_documented_bound_itself():
    """Fuzz finding display-white-1e30-refused: float32(1e30) > 1e30 refused the bound itself."""
    loaded = airlight.load_scene({**BASE, "display": {"white": 1e30}})
    assert loaded["display"]["white"] == pytest.approx(1e30)
    with pytest.raises(ValueError, match=r"^display\.white: must be <= 1e\+30$"):
        airlight.load_scene({**BASE, "display": {"white": 2e30}})


def test_cpu_threads_must_be_a_plain_integer_in_range():
    with pytest.raises(TypeError, match=r"^cpu_threads: expected an integer, got bool$"):
        airlight.Renderer("cpu", cpu_threads=True)
    with pytest.raises(ValueError, match=r"^cpu_threads: must be in \[0, 1024\]"):
        airlight.Renderer("cpu", cpu_threads=2**40)


def test_a_deeply_nested_scene_with_a_film_override_is_a_value_error():
    deep: dict = {}
    node = deep
    for _ in range(5000):
        node["x"] = {}
        node = node["x"]
    with pytest.raises(ValueError, match="nesting too deep"):
        airlight.render({**BASE, "extra": deep}, backend="cpu", width=4)


def test_a_duplicate_json_key_is_refused_naming_it():
    text = json.dumps(BASE)[:-1] + ', "film": {"width": 8, "height": 6}}'
    with pytest.raises(ValueError, match=r"^film: duplicate key"):
        airlight.load_scene(text)


@pytest.mark.parametrize("args", [["--width", " 10"], ["--width", "0x10"], ["--exposure", "0x10"],
                                  ["--exposure", "inf"], ["--height", "+12"]])
def test_the_demo_takes_plain_decimal_numbers_only(args, tmp_path):
    demo = Path(sys.executable).with_name("airlight-demo")
    if not demo.exists():
        pytest.skip(f"{demo} is not installed")
    command = [str(demo), "--scene", "scenes/default.json", "--out", str(tmp_path / "x.png"), *args]
    done = subprocess.run(command, capture_output=True, text=True, timeout=60,
                          cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 2 and f"got '{args[1]}'" in done.stderr, done.stderr
    assert not (tmp_path / "x.png").exists()


def test_the_demo_reports_a_bad_out_directory_before_rendering(tmp_path):
    demo = Path(sys.executable).with_name("airlight-demo")
    if not demo.exists():
        pytest.skip(f"{demo} is not installed")
    missing = tmp_path / "no" / "such"
    done = subprocess.run([str(demo), "--scene", "scenes/default.json", "--out", str(missing / "x.png"),
                           "--width", "8000", "--height", "8000"],
                          capture_output=True, text=True, timeout=60, cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 2
    assert done.stderr.strip() == (f"airlight-demo: --out: cannot write '{missing / 'x.png'}': directory "
                                   f"'{missing}' does not exist"), done.stderr
