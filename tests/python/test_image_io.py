"""8-bit sRGB conversion, PNG and PFM files, and the demo's files against the API."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import airlight
from conftest import run_demo


def _srgb8(values) -> np.ndarray:
    """to_srgb8 of a 1-pixel-high image whose pixels are grey levels ``values``."""
    radiance = np.repeat(np.asarray(values, dtype=np.float32)[None, :, None], 3, axis=2)
    out = airlight.to_srgb8(radiance)
    assert out.dtype == np.uint8 and out.shape == radiance.shape
    assert (out == out[..., :1]).all()
    return out[0, :, 0]


@pytest.mark.parametrize(("linear", "code"), [
    (0.0, 0),
    (1.0, 255),
    (0.5, 188),
    (0.0031308, 10),  # the sRGB breakpoint: 12.92 * 0.0031308 * 255 = 10.3
    (0.001, 3),  # linear segment: 12.92 * 0.001 * 255 = 3.29
    (0.2, 124),
    (0.9, 243),
    (2.0, 255),
    (float("inf"), 255),
    (-0.5, 0),
    (float("-inf"), 0),
    (float("nan"), 0),
])
def test_to_srgb8_known_values(linear: float, code: int) -> None:
    assert _srgb8([linear])[0] == code


def test_to_srgb8_is_continuous_and_monotonic_across_the_breakpoint() -> None:
    levels = np.linspace(0.0, 1.0, 4097, dtype=np.float32)
    codes = _srgb8(levels).astype(int)
    assert (np.diff(codes) >= 0).all()
    assert codes[0] == 0 and codes[-1] == 255
    assert len(np.unique(codes)) == 256, "every 8-bit code is reachable"
    below, above = _srgb8([np.nextafter(np.float32(0.0031308), np.float32(0)), 0.0031309])
    assert below == above == 10


def test_to_srgb8_matches_the_srgb_formula() -> None:
    levels = np.linspace(0.0, 1.0, 1001)
    expected = np.where(levels <= 0.0031308, 12.92 * levels, 1.055 * levels ** (1 / 2.4) - 0.055)
    assert np.abs(_srgb8(levels).astype(int) - np.round(255 * expected)).max() <= 1


def test_to_srgb8_treats_channels_independently() -> None:
    radiance = np.array([[[0.0, 0.5, 1.0], [1.0, float("nan"), -1.0]]], dtype=np.float32)
    np.testing.assert_array_equal(airlight.to_srgb8(radiance), [[[0, 188, 255], [255, 0, 0]]])


def test_to_srgb8_exposure_scales_radiance() -> None:
    radiance = np.full((2, 3, 3), 0.25, dtype=np.float32)
    assert (airlight.to_srgb8(radiance, 2.0) == 188).all()
    assert (airlight.to_srgb8(radiance, 4.0) == 255).all()
    assert (airlight.to_srgb8(radiance, 0.0) == 0).all()
    np.testing.assert_array_equal(airlight.to_srgb8(radiance * 3, 1.0), airlight.to_srgb8(radiance, 3.0))


def test_to_srgb8_accepts_float64_and_non_contiguous_arrays() -> None:
    radiance = np.full((4, 6, 3), 0.5)[:, ::2]
    out = airlight.to_srgb8(radiance)
    assert out.shape == (4, 3, 3) and (out == 188).all()


@pytest.mark.parametrize("exposure", [-1.0, float("nan"), float("inf"), -0.001])
def test_to_srgb8_rejects_negative_or_non_finite_exposure(exposure: float, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="exposure"):
        airlight.to_srgb8(np.zeros((2, 2, 3), dtype=np.float32), exposure)
    with pytest.raises(ValueError, match="exposure"):
        airlight.save_png(tmp_path / "unused.png", np.zeros((2, 2, 3), dtype=np.float32), exposure)
    assert not (tmp_path / "unused.png").exists()


@pytest.mark.parametrize("shape", [(4, 4), (4, 4, 4), (4, 4, 1), (12,)])
def test_to_srgb8_rejects_images_without_three_channels(shape) -> None:
    with pytest.raises(ValueError):
        airlight.to_srgb8(np.zeros(shape, dtype=np.float32))


def _test_image(height: int = 13, width: int = 17) -> np.ndarray:
    rng = np.random.default_rng(1234)
    img = rng.uniform(-0.1, 1.3, size=(height, width, 3)).astype(np.float32)
    img[0, 0] = [np.nan, np.inf, -np.inf]
    return img


def test_save_png_writes_what_pillow_reads_back_as_to_srgb8(tmp_path: Path) -> None:
    img = _test_image()
    path = tmp_path / "out.png"
    airlight.save_png(path, img, exposure=0.8)
    with Image.open(path) as png:
        assert png.format == "PNG" and png.mode == "RGB" and png.size == (17, 13)
        np.testing.assert_array_equal(np.asarray(png), airlight.to_srgb8(img, 0.8))


def test_save_pfm_and_load_pfm_round_trip_exactly(tmp_path: Path) -> None:
    img = _test_image()
    img[1, 2] = [0.0, -0.0, 1e-40]  # signed zero and a subnormal survive too
    path = tmp_path / "out.pfm"
    airlight.save_pfm(path, img)
    back = airlight.load_pfm(path)
    assert back.dtype == np.float32 and back.shape == img.shape
    np.testing.assert_array_equal(back.view(np.uint32), img.view(np.uint32))


def test_pfm_file_stores_bottom_row_first_little_endian(tmp_path: Path) -> None:
    img = np.zeros((2, 3, 3), dtype=np.float32)
    img[0] = 1.0  # top row
    path = tmp_path / "rows.pfm"
    airlight.save_pfm(path, img)
    data = path.read_bytes()
    header = b"PF\n3 2\n-1.0\n"
    assert data.startswith(header)
    pixels = np.frombuffer(data[len(header):], dtype="<f4").reshape(2, 3, 3)
    np.testing.assert_array_equal(pixels[::-1], img)


def test_load_pfm_rejects_other_files(tmp_path: Path) -> None:
    path = tmp_path / "grey.pfm"
    path.write_bytes(b"Pf\n1 1\n-1.0\n\0\0\0\0")
    with pytest.raises(ValueError, match="PFM"):
        airlight.load_pfm(path)


def test_demo_png_is_the_display_stage_of_the_cpu_render(tmp_path: Path, scene_file: Path) -> None:
    out = tmp_path / "x.png"
    proc = run_demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu", "--width", "64",
                 "--height", "48")
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as png:
        decoded = np.asarray(png.convert("RGB"))
    radiance = airlight.render(str(scene_file), backend="cpu", width=64, height=48)
    expected = airlight.display_scene(radiance, str(scene_file))
    assert decoded.shape == (48, 64, 3)
    np.testing.assert_array_equal(decoded, expected)
    assert 0 < expected.mean() < 255


@pytest.mark.parametrize(("flags", "kwargs"), [
    (["--exposure", "4"], {"exposure": 4.0}),
    (["--exposure", "0.5", "--tonemap", "filmic", "--white", "3"],
     {"exposure": 0.5, "tonemap": "filmic", "white": 3.0}),
    (["--tonemap", "linear", "--glare", "--pupil", "3"],
     {"tonemap": "linear", "glare": {"pupil_diameter": 3.0}}),
    (["--eyelashes"], {"glare": {"pupil_diameter": "auto", "eyelashes": True}}),
])
def test_demo_png_applies_the_display_flags(tmp_path: Path, scene_file: Path, flags: list[str],
                                            kwargs: dict) -> None:
    out = tmp_path / "x.png"
    proc = run_demo("--scene", str(scene_file), "--out", str(out), "--backend", "cpu", "--width", "32",
                 "--height", "24", *flags)
    assert proc.returncode == 0, proc.stderr
    with Image.open(out) as png:
        decoded = np.asarray(png.convert("RGB"))
    radiance = airlight.render(str(scene_file), backend="cpu", width=32, height=24)
    fov = airlight.load_scene(str(scene_file))["camera"]["fov_y"]
    expected = airlight.display(radiance, fov_y=fov, **kwargs)
    np.testing.assert_array_equal(decoded, expected)


def test_demo_pfm_equals_the_render_output(tmp_path: Path, scene_file: Path, backend: str) -> None:
    out = tmp_path / "x.pfm"
    proc = run_demo("--scene", str(scene_file), "--out", str(out), "--backend", backend, "--width", "64",
                 "--height", "48")
    assert proc.returncode == 0, proc.stderr
    from_demo = airlight.load_pfm(out)
    from_api = airlight.render(str(scene_file), backend=backend, width=64, height=48)
    assert from_demo.shape == (48, 64, 3)
    np.testing.assert_allclose(from_demo, from_api, rtol=1e-6, atol=0)
