"""The display stage (airlight.display, effects/display/display.glsl through the C++
CPU implementation): tone curves monotonic, 0 -> 0, white -> 1, finite on
huge/zero/NaN input; the sRGB OETF at known points; automatic exposure maps a
uniform image to the key 0.18; the native result equals an independent numpy
evaluation of the documented formulas to 1 LSB; bad arguments name the field."""

from __future__ import annotations

import numpy as np
import pytest

import airlight

DEFAULT_WHITE = {"linear": 1.0, "loglog": 100.0, "reinhard": 16.0, "filmic": 7.2439203}
ACES_WHITE = 7.2439203


def curve_reference(name: str, lum: np.ndarray, white: float) -> np.ndarray:
    """The tone curves in float64, from their definitions (display()'s docstring)."""
    x = np.where(np.isfinite(lum) & (lum > 0), np.minimum(lum, 1e30), np.where(lum == np.inf, 1e30, 0.0))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if name == "linear":
            v = x / white
        elif name == "loglog":
            v = np.log1p(np.log1p(x)) / np.log1p(np.log1p(white))
        elif name == "reinhard":
            v = x * (1 + x / white**2) / (1 + x)
        else:
            y = x * ACES_WHITE / white
            v = y * (2.51 * y + 0.03) / (y * (2.43 * y + 0.59) + 0.14)
    return np.clip(np.nan_to_num(v, nan=1.0), 0.0, 1.0)


def srgb_reference(v: np.ndarray) -> np.ndarray:
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


def dither_reference(height: int, width: int) -> np.ndarray:
    """The ordered dither thresholds of display() (physics.md section 5, "Dithering"): the R2 sequence
    frac(a1 x + a2 y) in 32-bit fixed point, its top 24 bits, per pixel (height, width)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.uint64)
    h = (x * 3242174889 + y * 2447445413) % (1 << 32)
    return (h >> 8).astype(np.float64) / (1 << 24)


def quantize_reference(v: np.ndarray, dither: bool) -> np.ndarray:
    """8 bits of encoded values v (height, width, 3): floor(255 v + t), t the pixel's threshold or 1/2."""
    t = dither_reference(*v.shape[:2])[..., None] if dither else 0.5
    return np.floor(255 * v + t).astype(np.int64)


def display_reference(radiance: np.ndarray, exposure: float, name: str, white: float,
                      dither: bool = True) -> np.ndarray:
    """display() in float64 numpy: exposure, curve on Rec. 709 luminance, sRGB, 8 bits (dithered)."""
    with np.errstate(invalid="ignore"):
        c = radiance.astype(np.float64) * exposure  # inf * 0 = NaN: shown as 0, like the native code
    c = np.where(np.isfinite(c) & (c > 0), np.minimum(c, 1e30), np.where(c == np.inf, 1e30, 0.0))
    lum = c @ np.array([0.2126, 0.7152, 0.0722])
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(lum > 0, curve_reference(name, lum, white) / lum, 0.0)
    return quantize_reference(srgb_reference(c * scale[..., None]), dither)


def auto_exposure_reference(radiance: np.ndarray) -> float:
    """0.18 / exp(mean ln Y) over finite Y >= max(1e-6 median, FLT_MIN), the median over the pixels whose
    luminance is a normal positive float (physics.md (5.1))."""
    lum = radiance.astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    tiny = float(np.finfo(np.float32).tiny)
    normal = np.sort(lum[np.isfinite(lum) & (lum >= tiny)].astype(np.float32))
    floor = max(1e-6 * float(normal[len(normal) // 2]), tiny) if normal.size else np.inf
    ok = np.isfinite(lum) & (lum >= floor)
    return 0.18 / float(np.exp(np.mean(np.log(lum[ok])))) if ok.any() else 1.0


@pytest.fixture(scope="module")
def hdr_image() -> np.ndarray:
    """Coloured pixels over 14 decades of radiance, plus black, NaN, inf and negative ones."""
    rng = np.random.default_rng(8)
    lum = 10 ** rng.uniform(-7, 7, size=(24, 40))
    tint = rng.uniform(0.05, 1.0, size=(24, 40, 3))
    img = (lum[..., None] * tint).astype(np.float32)
    img[0, 0] = 0
    img[0, 1] = [np.nan, 1, 1]
    img[0, 2] = [np.inf, 1, 1]
    img[0, 3] = [-1, 2, 3]
    return img


@pytest.mark.parametrize("name", airlight.TONEMAPS)
def test_curves_monotonic_zero_white_finite(name: str) -> None:
    lum = np.logspace(-6, 6, 60001)
    for white in (None, 0.5, 3.0, 1000.0):
        v = airlight.tone_curve(lum, name, white)
        assert v.dtype == np.float32 and v.shape == lum.shape
        assert np.all(np.diff(v) >= 0), f"{name} not monotonic, white {white}"
        assert np.all((v >= 0) & (v <= 1))
        w = DEFAULT_WHITE[name] if white is None else white
        np.testing.assert_allclose(v, curve_reference(name, lum, w), atol=2e-6)
        assert airlight.tone_curve([w], name, white)[0] == pytest.approx(1.0, abs=1e-5)
    special = airlight.tone_curve([0.0, 1e30, 3e38, np.inf, np.nan, -1.0], name)
    assert special.tolist() == [0.0, 1.0, 1.0, 1.0, 0.0, 0.0]
    for white in (1e-30, 1e30):
        assert np.all(np.isfinite(airlight.tone_curve([0.0, 1e-20, 1.0, 1e30], name, white)))


def test_srgb_oetf_known_points() -> None:
    grey = np.array([[[0.0] * 3, [0.0031308] * 3, [0.5] * 3, [1.0] * 3, [0.18] * 3, [0.001] * 3]], np.float32)
    out = airlight.display(grey, exposure=1.0, tonemap="linear", dither=False)[0, :, 0]
    dithered = airlight.display(grey, exposure=1.0, tonemap="linear")[0, :, 0]
    exact = 255 * np.array([0.0, 0.04045, 0.7353569, 1.0, 0.4613561, 0.01292])
    assert np.all((dithered == np.floor(exact)) | (dithered == np.ceil(exact)))
    # 0.0031308 -> 0.04045 on both pieces; 0.5 -> 0.7353569; 0.18 -> 0.4613561; 0.001 -> 0.01292.
    assert out.tolist() == [0, round(255 * 0.04045), round(255 * 0.7353569), 255, round(255 * 0.4613561),
                            round(255 * 0.01292)]
    assert srgb_reference(np.array([0.5]))[0] == pytest.approx(0.7353569, abs=1e-7)
    # The linear curve with white 1 is to_srgb8's clipping.
    img = np.linspace(0, 1.5, 300, dtype=np.float32).reshape(1, 100, 3)
    linear = airlight.display(img, exposure=1.0, tonemap="linear", dither=False)
    np.testing.assert_array_equal(linear, airlight.to_srgb8(img))


@pytest.mark.parametrize("level", [1e-4, 0.05, 1.0, 300.0])
def test_auto_exposure_maps_uniform_image_to_key(level: float) -> None:
    img = np.empty((5, 7, 3), np.float32)
    img[:] = [0.5 * level, 1.2 * level, 0.8 * level]
    lum = (0.2126 * 0.5 + 0.7152 * 1.2 + 0.0722 * 0.8) * level
    assert airlight.auto_exposure(img) * lum == pytest.approx(0.18, rel=1e-5)
    grey = np.full((3, 4, 3), level, np.float32)
    out = airlight.display(grey, tonemap="linear", dither=False)
    assert np.all(out == round(255 * 0.4613561))  # sRGB(0.18)
    dithered = airlight.display(grey, tonemap="linear")  # 117.65: 117 or 118
    assert set(np.unique(dithered)) <= {117, 118}


def test_auto_exposure_ignores_black_and_nonfinite(hdr_image: np.ndarray) -> None:
    img = np.full((4, 4, 3), 2.0, np.float32)
    img[0, 0] = 0
    img[0, 1] = np.nan
    img[0, 2] = np.inf
    img[0, 3] = -3
    assert airlight.auto_exposure(img) == pytest.approx(0.09, rel=1e-6)
    assert airlight.auto_exposure(np.zeros((3, 3, 3), np.float32)) == 1.0
    assert airlight.auto_exposure(hdr_image) == pytest.approx(auto_exposure_reference(hdr_image), rel=1e-5)


@pytest.mark.parametrize("name", airlight.TONEMAPS)
@pytest.mark.parametrize("exposure", ["auto", 0.0, 0.3, 1e20])
def test_display_matches_numpy_formulas(hdr_image: np.ndarray, name: str, exposure: str | float) -> None:
    out = airlight.display(hdr_image, exposure=exposure, tonemap=name)
    assert out.dtype == np.uint8 and out.shape == hdr_image.shape
    e = auto_exposure_reference(hdr_image) if exposure == "auto" else float(np.float32(exposure))
    ref = display_reference(hdr_image, e, name, DEFAULT_WHITE[name])
    assert np.abs(out.astype(np.int64) - ref).max() <= 1
    white = 2.5
    out = airlight.display(hdr_image, exposure=exposure, tonemap=name, white=white)
    assert np.abs(out.astype(np.int64) - display_reference(hdr_image, e, name, white)).max() <= 1
    out = airlight.display(hdr_image, exposure=exposure, tonemap=name, dither=False)
    ref = display_reference(hdr_image, e, name, DEFAULT_WHITE[name], dither=False)
    assert np.abs(out.astype(np.int64) - ref).max() <= 1


DENORMALS = np.array([1e-45, 1e-44, 3e-40, 1e-39, 1.1e-38], np.float32)  # subnormal float32


def test_auto_exposure_unchanged_by_pixels_below_the_floor() -> None:
    """Issue 17: adding zero or subnormal pixels (any number, in any channel) leaves the automatic exposure
    exactly as it was, and a few near-zero ones below the floor 1e-6 x the median luminance do not count
    (physics.md (5.1)); pixels above the floor do."""
    rng = np.random.default_rng(17)
    lum = 10 ** rng.uniform(-3, 3, size=(16, 16, 1))
    img = (lum * rng.uniform(0.2, 1.0, size=(16, 16, 3))).astype(np.float32)
    base = airlight.auto_exposure(img)
    assert base == pytest.approx(auto_exposure_reference(img), rel=1e-5)
    below = np.zeros((3, 16, 3), np.float32)
    below[0] = DENORMALS[np.arange(16) % len(DENORMALS), None]
    below[1, :, 1] = DENORMALS[np.arange(16) % len(DENORMALS)]  # one channel only
    for rows in (below, below[:1], below[1:2], np.repeat(below, 50, axis=0)):
        assert airlight.auto_exposure(np.concatenate([img, rows])) == base
    lum = img.astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
    floor = 1e-6 * float(np.sort(lum.ravel().astype(np.float32))[lum.size // 2])
    near_zero = np.full((1, 4, 3), np.float32(1e-30))  # normal floats far below the floor
    near_zero[0, 1:] = np.float32(0.1 * floor)
    with_near_zero = np.concatenate([img.reshape(-1, 4, 3), near_zero])
    assert airlight.auto_exposure(with_near_zero) == pytest.approx(base, rel=1e-6)
    above = np.full((1, 16, 3), np.float32(1e-3 * floor / 1e-6))  # 1e-3 of the median: counts
    assert airlight.auto_exposure(np.concatenate([img, above])) > 1.2 * base


def test_display_input_forms() -> None:
    img = np.full((2, 3, 3), 0.25)
    assert airlight.display(img, exposure=1, tonemap="linear").tolist() == airlight.display(
        img.astype(np.float32), exposure=1.0, tonemap="linear").tolist()
    assert airlight.display(np.asfortranarray(img)).shape == (2, 3, 3)
    assert airlight.display(np.zeros((0, 0, 3), np.float32)).shape == (0, 0, 3)
    # Bright lamps far above white: clipped, with no wrap-around or NaN artefacts.
    lamp = np.array([[[1e30, 1e30, 1e30], [3e38, 0, 0], [0, 0, 0]]], np.float32)
    for name in airlight.TONEMAPS:
        out = airlight.display(lamp, exposure=1.0, tonemap=name)
        assert out[0, 0].tolist() == [255, 255, 255]
        assert out[0, 1, 0] == 255 and out[0, 2].tolist() == [0, 0, 0]


@pytest.mark.parametrize(("kwargs", "error", "field"), [
    ({"exposure": -1.0}, ValueError, "exposure"),
    ({"exposure": float("nan")}, ValueError, "exposure"),
    ({"exposure": float("inf")}, ValueError, "exposure"),
    ({"exposure": 1e300}, ValueError, "exposure"),
    ({"exposure": "manual"}, ValueError, "exposure"),
    ({"exposure": True}, TypeError, "exposure"),
    ({"tonemap": "aces"}, ValueError, "tonemap"),
    ({"tonemap": 3}, TypeError, "tonemap"),
    ({"white": 0.0}, ValueError, "white"),
    ({"white": -2}, ValueError, "white"),
    ({"white": float("nan")}, ValueError, "white"),
    ({"white": "high"}, TypeError, "white"),
])
def test_display_bad_arguments(kwargs: dict, error: type, field: str) -> None:
    with pytest.raises(error, match=f"^{field}: "):
        airlight.display(np.ones((2, 2, 3), np.float32), **kwargs)


@pytest.mark.parametrize(("radiance", "error"), [
    (np.ones((2, 2), np.float32), ValueError),
    (np.ones((2, 2, 4), np.float32), ValueError),
    (np.ones((2, 2, 3, 1), np.float32), ValueError),
    (np.ones((2, 2, 3), np.complex64), TypeError),
    (np.array([[["a", "b", "c"]]]), TypeError),
    ([[[1.0, 1.0, 1.0]]], TypeError),
])
def test_display_bad_radiance(radiance: object, error: type) -> None:
    with pytest.raises(error, match="^radiance: "):
        airlight.display(radiance)  # type: ignore[arg-type]


def test_tone_curve_bad_arguments() -> None:
    with pytest.raises(ValueError, match="^tonemap: "):
        airlight.tone_curve([1.0], "hable")
    with pytest.raises(ValueError, match="^white: "):
        airlight.tone_curve([1.0], "reinhard", -1.0)
