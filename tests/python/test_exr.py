"""OpenEXR files: save_exr / load_exr round trips (float32 bit-exact, half within half
precision), the channel naming checked with an independent reader (the official
``OpenEXR`` bindings from PyPI, used here only), files written by that package read
back, the demo's ``--out x.exr`` against the API's render, and the errors."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import airlight
from conftest import run_demo

HALF_MAX = 65504.0


@pytest.fixture
def openexr() -> Any:
    """The independent reader and writer: the PyPI ``OpenEXR`` package (3.x ``OpenEXR.File`` API)."""
    return pytest.importorskip("OpenEXR", minversion="3.3")


def _values(shape: tuple[int, ...], seed: int) -> np.ndarray:
    """float32 values of every kind: ordinary, negative, tiny, subnormal, signed zero, +-inf, NaNs."""
    rng = np.random.default_rng(seed)
    v = rng.uniform(-2.0, 50.0, size=shape).astype(np.float32)
    specials = np.array([np.inf, np.nan, -0.0, 1e-40, -1e-38, -np.inf, 3.4e38, 1e-7, -123.25, 0.0, 0.0],
                        dtype=np.float32)
    specials[-2:] = np.array([0x7FC00123, 0xFFC00000], dtype=np.uint32).view(np.float32)  # NaNs with payloads
    flat = v.reshape(-1)
    n = min(flat.size, specials.size)
    flat[:n] = specials[:n]
    return v


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype == np.float32 and a.shape == b.shape and bool(
        (a.view(np.uint32) == b.view(np.uint32)).all())


@pytest.mark.parametrize(("height", "width"), [(1, 1), (1, 7), (5, 3), (13, 17)])
def test_float32_round_trip_is_bit_exact_including_inf_nan_and_tiny_values(
        tmp_path: Path, height: int, width: int) -> None:
    images = {
        "depth": _values((height, width), 1),
        "radiance": _values((height, width, 3), 2),
        "normal": _values((height, width, 3), 3),
        "transmittance": _values((height, width, 3), 4),
    }
    path = tmp_path / "round_trip.exr"
    airlight.save_exr(path, images)
    back = airlight.load_exr(path)
    # radiance first, then the file's channel order (sorted by name).
    assert list(back) == ["radiance", "depth", "normal", "transmittance"]
    for name, array in images.items():
        assert _same_bits(back[name], array), name


def test_plain_array_is_saved_as_radiance(tmp_path: Path) -> None:
    img = _values((4, 6, 3), 5)
    airlight.save_exr(tmp_path / "x.exr", img)
    back = airlight.load_exr(tmp_path / "x.exr")
    assert list(back) == ["radiance"]
    assert _same_bits(back["radiance"], img)


def test_float64_and_non_contiguous_input_is_written_as_float32(tmp_path: Path) -> None:
    img = np.linspace(0.0, 1.0, 4 * 10 * 3).reshape(4, 10, 3)[:, ::2]
    depth = np.arange(20, dtype=np.int32).reshape(4, 5)
    mask = np.ones((4, 5, 1), dtype=np.float32)
    airlight.save_exr(tmp_path / "x.exr", {"radiance": img, "depth": depth, "mask": mask})
    back = airlight.load_exr(tmp_path / "x.exr")
    np.testing.assert_array_equal(back["radiance"], img.astype(np.float32))
    np.testing.assert_array_equal(back["depth"], depth.astype(np.float32))
    assert back["mask"].shape == (4, 5), "(H, W, 1) is written as one channel"


def test_half_round_trip_is_within_half_precision_and_overflows_to_inf(tmp_path: Path) -> None:
    rng = np.random.default_rng(6)
    # 1e-4 .. 4e4: normal halves, where the relative rounding error is at most 2^-11.
    radiance = (10.0 ** rng.uniform(-4.0, 4.6, size=(7, 9, 3))).astype(np.float32)
    radiance[0, 0] = [-3.14159, 1.0, 0.0]
    depth = np.array([[HALF_MAX, 65519.0, 65536.0, 1e5, -1e6, np.inf, -np.inf, np.nan, 0.5]],
                     dtype=np.float32)
    path = tmp_path / "half.exr"
    airlight.save_exr(path, {"radiance": radiance, "depth": np.repeat(depth, 7, axis=0)}, half=True)
    back = airlight.load_exr(path)
    assert back["radiance"].dtype == np.float32
    np.testing.assert_allclose(back["radiance"], radiance, rtol=2.0**-11, atol=0)
    assert not np.array_equal(back["radiance"], radiance), "the values were rounded to half"
    got = back["depth"][3]
    # Beyond the largest half, 65504, a value becomes inf (OpenEXR's float-to-half conversion).
    np.testing.assert_array_equal(got[:7], [HALF_MAX, np.inf, np.inf, np.inf, -np.inf, np.inf, -np.inf])
    assert np.isnan(got[7]) and got[8] == 0.5


def test_the_independent_reader_sees_the_channel_names_and_values(tmp_path: Path, openexr: Any) -> None:
    h, w = 5, 7
    images = {"radiance": _values((h, w, 3), 7), "depth": _values((h, w), 8), "normal": _values((h, w, 3), 9),
              "albedo": _values((h, w, 3), 10)}
    path = tmp_path / "x.exr"
    airlight.save_exr(path, images)
    f = openexr.File(str(path), separate_channels=True)
    header = f.header()
    assert header["compression"] == openexr.ZIP_COMPRESSION
    assert header["type"] == openexr.scanlineimage
    lo, hi = header["dataWindow"]
    assert list(lo) == [0, 0] and list(hi) == [w - 1, h - 1]
    channels = {name: ch.pixels for name, ch in f.channels().items()}
    assert sorted(channels) == ["B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth",
                                "normal.X", "normal.Y", "normal.Z"]
    expected = {"depth": images["depth"]}
    for i, c in enumerate("RGB"):
        expected[c] = images["radiance"][..., i]
    for i, c in enumerate("XYZ"):
        expected[f"normal.{c}"] = images["normal"][..., i]
    for i, c in enumerate("RGB"):
        expected[f"albedo.{c}"] = images["albedo"][..., i]
    for name, values in expected.items():
        assert _same_bits(np.ascontiguousarray(channels[name]), np.ascontiguousarray(values)), name


def test_the_independent_reader_sees_half_channels(tmp_path: Path, openexr: Any) -> None:
    img = _values((3, 4, 3), 11)
    airlight.save_exr(tmp_path / "x.exr", img, half=True)
    channels = openexr.File(str(tmp_path / "x.exr"), separate_channels=True).channels()
    assert sorted(channels) == ["B", "G", "R"]
    assert all(ch.pixels.dtype == np.float16 for ch in channels.values())
    np.testing.assert_array_equal(channels["G"].pixels, img[..., 1].astype(np.float16))


def test_load_exr_reads_a_file_written_by_the_openexr_package(tmp_path: Path, openexr: Any) -> None:
    """The reading rule on a foreign file: R, G, B -> radiance; n.X/Y/Z and c.R/G/B -> 3 channels;
    anything else (a lone A, x.R without x.B) -> 2-D arrays named by the channel; half and uint channels
    are read as float32; a tiled file is read like a scanline one."""
    h, w = 4, 6
    rng = np.random.default_rng(12)
    r, g, b, depth = (rng.uniform(0, 10, (h, w)).astype(np.float32) for _ in range(4))
    alpha = rng.uniform(0, 1, (h, w)).astype(np.float16)
    ids = np.arange(h * w, dtype=np.uint32).reshape(h, w)
    n = rng.uniform(-1, 1, (h, w, 3)).astype(np.float32)
    # Contiguous arrays: the package's writer ignores a view's strides.
    channels = {"R": r, "G": g, "B": b, "A": alpha, "depth": depth, "id": ids,
                **{f"n.{c}": np.ascontiguousarray(n[..., i]) for i, c in enumerate("XYZ")},
                "c.R": b, "c.G": g, "c.B": r, "x.R": r, "x.G": g}
    tiles = openexr.TileDescription()
    tiles.xSize, tiles.ySize = 4, 4
    for header in ({"compression": openexr.ZIP_COMPRESSION, "type": openexr.scanlineimage},
                   {"compression": openexr.PIZ_COMPRESSION, "type": openexr.tiledimage, "tiles": tiles}):
        path = tmp_path / f"foreign_{header['type']}.exr"
        openexr.File(header, channels).write(str(path))
        back = airlight.load_exr(path)
        assert list(back) == ["radiance", "A", "c", "depth", "id", "n", "x.G", "x.R"]
        assert all(v.dtype == np.float32 for v in back.values())
        np.testing.assert_array_equal(back["radiance"], np.stack([r, g, b], axis=-1))
        np.testing.assert_array_equal(back["c"], np.stack([b, g, r], axis=-1))
        np.testing.assert_array_equal(back["n"], n)
        np.testing.assert_array_equal(back["A"], alpha.astype(np.float32))
        np.testing.assert_array_equal(back["id"], ids.astype(np.float32))
        np.testing.assert_array_equal(back["depth"], depth)
        np.testing.assert_array_equal(back["x.R"], r)
        np.testing.assert_array_equal(back["x.G"], g)


def test_load_exr_reads_a_data_window_that_does_not_start_at_the_origin(tmp_path: Path, openexr: Any) -> None:
    depth = np.arange(12, dtype=np.float32).reshape(3, 4)
    header = {"dataWindow": (np.array([10, 20], dtype=np.int32), np.array([13, 22], dtype=np.int32)),
              "displayWindow": (np.array([0, 0], dtype=np.int32), np.array([99, 99], dtype=np.int32))}
    openexr.File(header, {"depth": depth}).write(str(tmp_path / "window.exr"))
    back = airlight.load_exr(tmp_path / "window.exr")
    assert list(back) == ["depth"]
    np.testing.assert_array_equal(back["depth"], depth)


# --- errors -------------------------------------------------------------------------------------------

@pytest.mark.parametrize(("images", "error", "needle"), [
    ([[0.0, 1.0]], TypeError, "images: expected a numpy array or a mapping"),
    (np.zeros((2, 3)), ValueError, "images: expected shape (H, W, 3)"),
    ({}, ValueError, "images: expected at least one image"),
    ({"depth": np.zeros((2, 3, 4))}, ValueError,
     "images['depth']: expected shape (H, W) or (H, W, 3), got (2, 3, 4)"),
    ({"depth": np.zeros(6)}, ValueError, "images['depth']: expected shape (H, W) or (H, W, 3), got (6,)"),
    ({"depth": np.zeros((0, 3))}, ValueError, "images['depth']: expected at least 1 x 1 pixels"),
    ({"depth": [[1.0]]}, TypeError, "images['depth']: expected a numpy array, got list"),
    ({"depth": np.zeros((2, 3), dtype=bool)}, TypeError, "images['depth']: expected a real-valued array"),
    ({"depth": np.zeros((2, 3), dtype=complex)}, TypeError, "images['depth']: expected a real-valued array"),
    ({"radiance": np.zeros((2, 3, 3)), "depth": np.zeros((3, 2))}, ValueError,
     "images['depth']: expected (H, W) = (2, 3) as images['radiance'], got (3, 2)"),
    ({"": np.zeros((2, 3))}, ValueError, "images['']: the name must not be empty"),
    ({"a.b": np.zeros((2, 3))}, ValueError, "images['a.b']: the name must not contain '.'"),
    ({1: np.zeros((2, 3))}, TypeError, "images: keys must be str, got int"),
    ({"radiance": np.zeros((2, 3))}, ValueError, "images['radiance']: expected shape (H, W, 3), got (2, 3)"),
    ({"G": np.zeros((2, 3))}, ValueError, "images['G']: 'G' is a channel of 'radiance'"),
])
def test_save_exr_rejects_bad_images_naming_the_argument_or_key(tmp_path: Path, images: Any,
                                                                error: type[Exception], needle: str) -> None:
    path = tmp_path / "bad.exr"
    with pytest.raises(error) as info:
        airlight.save_exr(path, images)
    assert needle in str(info.value)
    assert not path.exists()


def test_save_exr_rejects_a_non_bool_half(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="half: expected a bool"):
        airlight.save_exr(tmp_path / "x.exr", np.zeros((1, 1, 3)), half=1)  # type: ignore[arg-type]


def test_save_exr_to_a_missing_directory_raises_oserror_naming_the_path(tmp_path: Path) -> None:
    path = tmp_path / "no_such_dir" / "x.exr"
    with pytest.raises(OSError) as info:
        airlight.save_exr(path, np.zeros((2, 2, 3)))
    assert str(path) in str(info.value)


def test_load_exr_of_a_missing_file_raises_file_not_found(tmp_path: Path) -> None:
    path = tmp_path / "missing.exr"
    with pytest.raises(FileNotFoundError) as info:
        airlight.load_exr(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize("content", [b"", b"not an EXR file at all\n", b"v/1\x01" + bytes(64)])
def test_load_exr_of_a_non_exr_file_raises_oserror_naming_the_path(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "fake.exr"
    path.write_bytes(content)
    with pytest.raises(OSError) as info:
        airlight.load_exr(path)
    assert str(path) in str(info.value)


def test_load_exr_of_a_truncated_file_raises_oserror(tmp_path: Path) -> None:
    path = tmp_path / "x.exr"
    airlight.save_exr(path, _values((64, 64, 3), 13))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(OSError, match="cannot read EXR file"):
        airlight.load_exr(path)


# --- the demo -----------------------------------------------------------------------------------------

def test_demo_exr_equals_the_cpu_render(tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "x.exr"
    proc = run_demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu", "--width", "64",
                 "--height", "48")
    assert proc.returncode == 0, proc.stderr
    assert str(out) in proc.stdout
    from_demo = airlight.load_exr(out)
    from_api = airlight.render(str(scene_file), backend="cpu", width=64, height=48)
    assert list(from_demo) == ["radiance"]
    assert from_demo["radiance"].shape == (48, 64, 3)
    np.testing.assert_allclose(from_demo["radiance"], from_api, rtol=1e-6, atol=0)
    assert from_api.mean() > 0


def test_demo_exr_half_is_the_cpu_render_in_half_precision(tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "x.exr"
    proc = run_demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu", "--width", "32",
                 "--height", "24", "--half")
    assert proc.returncode == 0, proc.stderr
    from_api = airlight.render(str(scene_file), backend="cpu", width=32, height=24)
    from_demo = airlight.load_exr(out)["radiance"]
    np.testing.assert_allclose(from_demo, from_api, rtol=2.0**-11 + 1e-6, atol=1e-7)
    np.testing.assert_array_equal(from_demo, from_demo.astype(np.float16), "every value is a half float")


@pytest.mark.parametrize("out", ["x.png", "x.pfm"])
def test_demo_half_without_an_exr_output_exits_nonzero_with_one_line(tmp_path: Path, scene_file: Path,
                                                                     out: str) -> None:
    proc = run_demo("--scene", str(scene_file), "--out", str(tmp_path / out), "--half")
    assert proc.returncode != 0
    assert len(proc.stderr.splitlines()) == 1 and "--half" in proc.stderr, proc.stderr
    assert not (tmp_path / out).exists()


def test_demo_help_documents_exr_and_half() -> None:
    proc = run_demo("--help")
    assert proc.returncode == 0
    assert "F.exr" in proc.stdout and "--half" in proc.stdout
