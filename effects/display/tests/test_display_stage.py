"""The display stage as a whole (issue 8): the scene's "display" object, glare
inside display() (skipped, sparse or exact FFT, always within half an 8-bit
step of the exact convolution), both backends showing the same image, the
Rayleigh criterion on rendered images, and lamp cores smaller than a pixel
carrying their true energy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airlight
from conftest import make_scene

# The peak of the photopic response: white light's resolution angle is 1.22 lambda / D at it.
RESOLUTION_WAVELENGTH = 555e-9


def _hdr_image(rng: np.random.Generator, height: int, width: int, sources: int, peak: float) -> np.ndarray:
    """A dim, smoothly varying coloured background (like fog) with `sources` single bright pixels."""
    y, x = np.mgrid[0:height, 0:width]
    shade = (1.0 + 0.3 * np.sin(x / 40.0) * np.cos(y / 30.0))[..., None]
    image = (0.02 * shade * np.array([1.0, 0.9, 0.7])).astype(np.float32)
    for _ in range(sources):
        image[rng.integers(8, height - 8), rng.integers(8, width - 8)] = peak * rng.uniform(0.2, 1.0, 3)
    return image


def test_scene_display_object_defaults_and_round_trip() -> None:
    loaded = airlight.load_scene(make_scene())
    assert loaded["display"] == {"exposure": "auto", "tonemap": "loglog", "glare": None, "dither": True}
    display = {"exposure": 0.25, "tonemap": "reinhard", "white": 8.0,
               "glare": {"pupil_diameter": 2.5, "eyelashes": True}, "dither": False}
    loaded = airlight.load_scene(make_scene(display=display))
    assert loaded["display"] == display
    assert airlight.load_scene(loaded)["display"] == display
    auto_pupil = airlight.load_scene(make_scene(display={"glare": {}}))["display"]["glare"]
    assert auto_pupil == {"pupil_diameter": "auto", "eyelashes": False}


@pytest.mark.parametrize(("display", "exc", "field"), [
    ({"exposure": -1}, ValueError, "display.exposure"),
    ({"exposure": "bright"}, ValueError, "display.exposure"),
    ({"tonemap": "hable"}, ValueError, "display.tonemap"),
    ({"white": -3}, ValueError, "display.white"),
    ({"glare": {"pupil_diameter": 0.9}}, ValueError, "display.glare.pupil_diameter"),
    ({"glare": {"pupil_diameter": 9.01}}, ValueError, "display.glare.pupil_diameter"),
    ({"glare": {"eyelashes": "yes"}}, TypeError, "display.glare.eyelashes"),
    ({"glare": 4.0}, TypeError, "display.glare"),
    ({"gamma": 2.2}, ValueError, "display.gamma"),
])
def test_bad_display_object_names_the_field(display: dict, exc: type, field: str) -> None:
    with pytest.raises(exc, match="^" + field.replace(".", r"\.") + ":"):
        airlight.load_scene(make_scene(display=display))


@pytest.mark.parametrize(("kwargs", "exc", "field"), [
    ({"glare": {"pupil_diameter": 0.5}, "fov_y": 60}, ValueError, "glare.pupil_diameter"),
    ({"glare": {"pupil_diameter": 10}, "fov_y": 60}, ValueError, "glare.pupil_diameter"),
    ({"glare": {"pupil_diameter": "wide"}, "fov_y": 60}, ValueError, "glare.pupil_diameter"),
    ({"glare": {"eyelashes": 1}, "fov_y": 60}, TypeError, "glare.eyelashes"),
    ({"glare": {"pupil": 3}, "fov_y": 60}, ValueError, "glare.pupil"),
    ({"glare": "on", "fov_y": 60}, TypeError, "glare"),
    ({"glare": True}, TypeError, "fov_y"),
    ({"glare": True, "fov_y": 180}, ValueError, "fov_y"),
])
def test_display_glare_bad_arguments_name_the_field(kwargs: dict, exc: type, field: str) -> None:
    with pytest.raises(exc, match="^" + field.replace(".", r"\.") + ":"):
        airlight.display(np.ones((8, 8, 3), np.float32), **kwargs)


def _exact_glare_display(image: np.ndarray, report: dict, fov_y: float, eyelashes: bool,
                         tonemap: str) -> np.ndarray:
    """The reference: every pixel convolved (airlight.glare, double-precision FFT), then shown."""
    spread = airlight.glare(image, fov_y=fov_y, pupil_diameter=report["pupil_diameter"], eyelashes=eyelashes)
    return airlight.display(spread, exposure=report["exposure"], tonemap=tonemap)


@pytest.mark.parametrize("tonemap", airlight.TONEMAPS)
@pytest.mark.parametrize(("case", "method"), [("smooth fog", "skipped"), ("lamps in the dark", "sparse"),
                                              ("lamps in fog", "sparse|fft"), ("noise", "fft")])
def test_display_glare_is_within_one_step_of_the_exact_convolution(tonemap: str, case: str,
                                                                   method: str) -> None:
    rng = np.random.default_rng(7)
    if case == "smooth fog":
        image = _hdr_image(rng, 90, 120, 0, peak=0.0)
    elif case == "lamps in the dark":
        image = np.zeros((90, 120, 3), np.float32)
        image[rng.integers(0, 90, 6), rng.integers(0, 120, 6)] = [5e3, 4e3, 3e3]
    elif case == "lamps in fog":
        image = _hdr_image(rng, 90, 120, 6, peak=5e3)
    else:  # bright everywhere, no smoothness: the sparse split would cost more than the FFT
        image = (rng.random((90, 120, 3)) * 50 + 10).astype(np.float32)
    sources = 0 if case == "smooth fog" else 6
    glare = {"pupil_diameter": 3.0, "eyelashes": sources == 6}
    shown, report = airlight.display_report(image, tonemap=tonemap, glare=glare, fov_y=20.0)
    if case == "lamps in the dark":
        assert report["glare_sources"] <= 6 * 9  # the lamps (and at most their 3x3 pixels), not the sky
    assert report["glare"] in method.split("|")
    reference = _exact_glare_display(image, report, 20.0, glare["eyelashes"], tonemap)
    diff = np.abs(shown.astype(int) - reference.astype(int))
    assert diff.max() <= 1, f"{method}/{tonemap}: {np.count_nonzero(diff)} pixels differ, max {diff.max()}"
    if method == "skipped":
        assert report["glare_sources"] == 0
        np.testing.assert_array_equal(shown, airlight.display(image, tonemap=tonemap))
    else:
        # The glare is visible: without it the bright pixels' surroundings differ.
        assert np.abs(shown.astype(int) - airlight.display(image, tonemap=tonemap).astype(int)).max() >= 2


def test_auto_pupil_follows_the_adaptation_luminance() -> None:
    dark = np.full((32, 32, 3), 1e-6, np.float32)
    bright = np.full((32, 32, 3), 10.0, np.float32)
    dark[16, 16] = bright[16, 16] = 1e9
    _, dark_report = airlight.display_report(dark, glare=True, fov_y=10.0)
    _, bright_report = airlight.display_report(bright, glare=True, fov_y=10.0)
    assert dark_report["pupil_diameter"] > 7.0  # 683e-6 cd/m^2: night, wide open
    assert bright_report["pupil_diameter"] < 3.0  # 6830 cd/m^2: daylight


def test_display_scene_uses_the_scene_settings(renderer_cache) -> None:
    scene = make_scene(display={"exposure": 0.5, "tonemap": "filmic",
                                "glare": {"pupil_diameter": 4.0, "eyelashes": False}})
    radiance = renderer_cache("cpu").render(scene)
    expected = airlight.display(radiance, exposure=0.5, tonemap="filmic",
                                glare={"pupil_diameter": 4.0}, fov_y=60.0)
    np.testing.assert_array_equal(airlight.display_scene(radiance, scene), expected)


@pytest.mark.parametrize("case", ["lamps in the dark", "lamps in fog", "noise"])
def test_gl_display_matches_cpu_display(renderer_cache, case: str) -> None:
    """Both backends show the same bytes (within one step) and choose the same way: few
    sources are splatted on the CPU for GL too, many go through the GPU's FFT."""
    gl = renderer_cache("gl")
    rng = np.random.default_rng(3)
    if case == "lamps in fog":
        image = _hdr_image(rng, 120, 160, 12, peak=2e4)
    elif case == "lamps in the dark":
        image = np.zeros((120, 160, 3), np.float32)
        image[rng.integers(0, 120, 8), rng.integers(0, 160, 8)] = [2e4, 1.5e4, 1e4]
    else:
        image = (rng.random((120, 160, 3)) * 50 + 10).astype(np.float32)
        image[60, 80] = 1e7  # a lamp: splatted on top of the GPU's FFT
    for tonemap in airlight.TONEMAPS:
        for glare in (None, {"pupil_diameter": 2.0, "eyelashes": True}):
            cpu_out, cpu_report = airlight.display_report(image, tonemap=tonemap, glare=glare, fov_y=30.0)
            gl_out, gl_report = airlight.display_report(image, tonemap=tonemap, glare=glare, fov_y=30.0,
                                                        renderer=gl)
            assert gl_report["glare"] == {"fft": "gl-fft"}.get(cpu_report["glare"], cpu_report["glare"])
            if glare is None or case != "lamps in fog":
                assert gl_report["glare"] == ("off" if glare is None else
                                              "sparse" if case == "lamps in the dark" else "gl-fft")
            assert gl_report["exposure"] == cpu_report["exposure"]
            diff = np.abs(gl_out.astype(int) - cpu_out.astype(int))
            assert diff.max() <= 1, f"{tonemap}, glare {glare}: max difference {diff.max()}"


# ---- lamps smaller than a pixel ------------------------------------------------

def _lamp_scene(positions: list[list[float]], radius: float, fov_y: float, size: tuple[int, int],
                intensity: float = 100.0) -> dict:
    width, height = size
    return make_scene(film={"width": width, "height": height}, medium=None, surfaces=[],
                      camera={"position": [0.0, 0.0, 0.0], "look_at": [0.0, 0.0, -1.0], "up": [0, 1, 0],
                              "fov_y": fov_y},
                      lights=[{"type": "point", "position": p, "intensity": intensity, "radius": radius}
                              for p in positions])


def _pixel_solid_angles(width: int, height: int, fov_y: float) -> np.ndarray:
    """Exact solid angle of each pixel of the pinhole camera (corner formula)."""
    t = math.tan(math.radians(fov_y) / 2)
    xs = (np.arange(width + 1) * 2.0 / width - 1.0) * t * width / height
    ys = (1.0 - np.arange(height + 1) * 2.0 / height) * t

    def corner(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Solid angle of [0, x] x [0, y] on the plane z = 1."""
        return np.arctan2(x * y, np.sqrt(1.0 + x * x + y * y))

    X, Y = np.meshgrid(xs, ys)
    F = corner(X, Y)
    return np.abs(F[:-1, :-1] - F[:-1, 1:] - F[1:, :-1] + F[1:, 1:])


@pytest.mark.parametrize("offset", [0.0, 0.13, 0.5, 0.77])
@pytest.mark.parametrize("angle_deg", [0.0, 20.0])
def test_subpixel_lamp_carries_its_energy_wherever_it_falls(renderer, offset: float,
                                                            angle_deg: float) -> None:
    width, height, fov = 64, 48, 40.0
    pixel = 2 * math.tan(math.radians(fov) / 2) / height
    d = 50.0
    x = d * (math.tan(math.radians(angle_deg)) + offset * pixel)
    for radius in (0.002, 0.01, 0.02):  # 0.05 to 0.55 pixels in radius
        position = [x, 0.3 * offset * pixel * d, -d]
        image = renderer.render(_lamp_scene([position], radius, fov, (width, height)))
        energy = float((image[..., 1] * _pixel_solid_angles(width, height, fov)).sum())
        # The irradiance the lamp gives at the camera: I / distance^2 (its disc's radiance times its
        # solid angle).
        expected = 100.0 / float(np.dot(position, position))
        assert energy == pytest.approx(expected, rel=2e-3), f"radius {radius}"
        assert np.count_nonzero(image[..., 1]) <= 9


def _row_peaks(profile: np.ndarray, min_dip: int = 3) -> int:
    """Number of maxima above half the profile's peak (the Airy rings around the
    lamps are fainter) separated by a dip of at least min_dip 8-bit steps."""
    peaks, best, low = 0, -1, 0
    rising = True
    values = profile.astype(int)
    values = np.where(values >= values.max() // 2, values, 0)
    for v in values:
        if rising:
            if v > best:
                best = v
            elif v <= best - min_dip:
                peaks += 1
                rising, low = False, v
        else:
            low = min(low, v)
            if v >= low + min_dip:
                rising, best = True, v
    if rising and best > 0:
        peaks += 1
    return peaks


@pytest.mark.parametrize(("separation", "peaks"), [(0.7, 1), (1.5, 2)])
def test_rayleigh_criterion_on_rendered_lamps(renderer, separation: float, peaks: int) -> None:
    """Two equal white lamps separated by 0.7 and 1.5 times 1.22 lambda / D, rendered
    (sub-pixel cores) and shown through the eye's glare, give one and two peaks."""
    pupil = 4.0
    resolution = 1.22 * RESOLUTION_WAVELENGTH / (pupil * 1e-3)
    width, height = 120, 60
    pixel = resolution / 10
    fov = math.degrees(2 * math.atan(pixel * height / 2))
    d = 1000.0
    half = 0.5 * separation * resolution * d
    scene = _lamp_scene([[-half, 0.0, -d], [half, 0.0, -d]], 1e-4, fov, (width, height), intensity=1e6)
    image = renderer.render(scene)
    spread = airlight.glare(image, fov_y=fov, pupil_diameter=pupil)
    white = float(spread.max()) * 1.05
    shown, report = airlight.display_report(image, exposure=1.0, tonemap="linear", white=white,
                                            glare={"pupil_diameter": pupil}, fov_y=fov, renderer=renderer)
    assert report["glare"] in ("sparse", "fft", "gl-fft")
    row = shown[height // 2 - 1: height // 2 + 1, :, 1].max(axis=0)
    assert _row_peaks(row) == peaks, row.tolist()


# ---- property: the glare's shortcuts never show --------------------------------------------

@st.composite
def _glare_cases(draw: st.DrawFn) -> tuple[np.ndarray, dict]:
    """Random scenes for the display stage: a smooth or noisy background of random level,
    a few lamps of random brightness (some on the border, some non-finite), random curve,
    exposure, pupil, eyelashes and field of view."""
    height = draw(st.integers(8, 48))
    width = draw(st.integers(8, 64))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    level = 10.0 ** draw(st.floats(-4, 2))
    y, x = np.mgrid[0:height, 0:width]
    period = draw(st.floats(2.0, 200.0))
    background = level * (1.0 + draw(st.floats(0, 0.9)) * np.sin(x / period + y / (1.3 * period)))
    image = np.repeat(background[..., None], 3, axis=2) * rng.uniform(0.5, 1.0, 3)
    if draw(st.booleans()):
        image *= 1.0 + draw(st.floats(0, 0.5)) * rng.random(image.shape)
    for _ in range(draw(st.integers(0, 5))):
        image[rng.integers(0, height), rng.integers(0, width)] = level * 10.0 ** draw(st.floats(0, 8))
    if draw(st.booleans()):
        image[rng.integers(0, height), rng.integers(0, width), rng.integers(0, 3)] = draw(
            st.sampled_from([np.nan, np.inf, -np.inf, -1.0]))
    kwargs = {
        "tonemap": draw(st.sampled_from(airlight.TONEMAPS)),
        "exposure": draw(st.one_of(st.just("auto"), st.floats(1e-3, 1e3).map(lambda e: e / level))),
        "glare": {"pupil_diameter": draw(st.floats(1.0, 9.0)), "eyelashes": draw(st.booleans())},
        "fov_y": draw(st.floats(0.5, 120.0)),
    }
    return image.astype(np.float32), kwargs


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=_glare_cases())
def test_glare_shortcuts_never_move_a_value_by_more_than_one_step(case: tuple[np.ndarray, dict]) -> None:
    image, kwargs = case
    shown, report = airlight.display_report(image, **kwargs)
    clean = np.where(np.isfinite(image), np.maximum(image, 0.0), np.where(image > 0, 3e38, 0.0))
    spread = airlight.glare(clean.astype(np.float32), fov_y=kwargs["fov_y"],
                            pupil_diameter=report["pupil_diameter"], eyelashes=kwargs["glare"]["eyelashes"])
    reference = airlight.display(spread, exposure=report["exposure"], tonemap=kwargs["tonemap"])
    diff = np.abs(shown.astype(int) - reference.astype(int))
    assert diff.max() <= 1, (report, int(np.count_nonzero(diff > 1)))


@pytest.mark.parametrize("fov_y", [10.0, 30.0])
def test_infinite_pixel_glares_only_within_the_kernel(fov_y: float) -> None:
    """+inf radiance is shown as 1e30 (white): its glare reaches the kernel's radius and no
    further (the FFT, whose roundoff is relative to its largest input, never sees it)."""
    image = np.full((48, 64, 3), [0.8, 0.6, 0.5], np.float32)
    image[0, 0, 0] = np.inf
    glare = {"pupil_diameter": 1.0}
    shown, report = airlight.display_report(image, tonemap="linear", exposure=0.27, glare=glare, fov_y=fov_y)
    r = report["glare_kernel_radius"]
    assert r < 40
    plain = airlight.display(image, tonemap="linear", exposure=0.27)
    np.testing.assert_array_equal(shown[r + 1:, r + 1:], plain[r + 1:, r + 1:])
    assert shown[0, 1, 0] == 255  # the glare next to it saturates
    exact = airlight.glare(image, fov_y=fov_y, pupil_diameter=1.0)
    assert np.isfinite(exact).all()
    reference = airlight.display(exact, exposure=0.27, tonemap="linear")
    assert np.abs(shown.astype(int) - reference.astype(int)).max() <= 1


def test_dark_subpixel_lamps_never_make_radiance_negative(renderer) -> None:
    """A core box-filtered onto pixels farther off-axis than itself weighs slightly more
    than the pixel's area (the solid-angle ratio): the background it hides must stop at
    zero, not go negative (a dark lamp over a bright background)."""
    width, height, fov = 64, 48, 100.0
    pixel = 2 * math.tan(math.radians(fov) / 2) / height
    d = 20.0
    lamps = []
    for angle in (35.0, 40.0, 45.0):
        for shift in (0.0, 0.3, 0.5):
            x = d * math.tan(math.radians(angle)) + shift * pixel * d
            lamps.append([x, shift * pixel * d, -d])
    scene = _lamp_scene(lamps, 0.85 * pixel * d, fov, (width, height), intensity=0.0)
    scene["background"] = [1.0, 1.0, 1.0]
    image = renderer.render(scene)
    assert image.min() >= 0.0
    assert image.min() < 0.5  # the dark cores do hide the background


FLT_MIN = np.finfo(np.float32).tiny


def test_spotlights_crossing_radiance_has_no_denormals_and_one_exposure(renderer_cache) -> None:
    """Issue 17: on a small film the spotlights in a medium of 0.02 /m left subnormal radiance
    (1e-45..1e-38) on the CPU, flushed on GL, so the automatic exposures differed (3549 against 972 at
    80 x 60) and so did the images. Radiance carries no subnormals (shaders/shading.glsl), and the
    exposure's floor (physics.md (5.1)) ignores what is left near zero: one exposure on both backends."""
    scene = airlight.preset("spotlights_crossing_002")
    exposures = []
    for name in ("cpu", "gl"):
        try:
            r = renderer_cache(name)
        except pytest.skip.Exception:
            continue
        radiance = r.render(scene, width=80, height=60)
        subnormal = (radiance != 0) & (np.abs(radiance) < FLT_MIN)
        assert not subnormal.any(), f"{name}: {int(subnormal.sum())} subnormal values"
        exposures.append(airlight.auto_exposure(radiance))
    if len(exposures) == 2:
        assert exposures[1] == pytest.approx(exposures[0], rel=1e-3)
