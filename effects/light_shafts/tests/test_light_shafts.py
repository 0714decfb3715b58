"""Light shafts (effects/light_shafts/physics.md): the sun's light scattered by the air counts only over
the lit parts of each view ray. Against the exact float64 reference (shafts_reference.py: each
surface's shadow on a ray is one interval, closed-form integral over the lit ones) on both backends,
for the sun on screen, off screen, behind the camera, at the zenith and at the screen's edge; over
random occluder sets (hypothesis); the brute-force march converging to it; the atmosphere's
shadowed volumes against marching; and the scene keys."""

from __future__ import annotations

import copy
import math
from typing import Any

import numpy as np
import pytest
import shafts_reference as reference
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airlight

WIDTH, HEIGHT = 64, 36

# A street of boxes and a sphere in a hazy homogeneous medium (red, green and blue extinction differ).
STREET: dict[str, Any] = {
    "film": {"width": WIDTH, "height": HEIGHT},
    "camera": {"position": [0, 1.7, 0], "look_at": [0, 6, -30], "up": [0, 1, 0], "fov_y": 60},
    "medium": {"sigma_t": [0.02, 0.03, 0.04], "albedo": 0.9, "phase": {"type": "hg", "g": 0.6}},
    "surfaces": [
        {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
        {"type": "box", "min": [-8, 0, -40], "max": [-4, 12, -35]},
        {"type": "box", "min": [-2, 0, -45], "max": [1, 15, -40]},
        {"type": "box", "min": [3, 0, -42], "max": [9, 10, -38]},
        {"type": "box", "min": [-30, 0, -80], "max": [30, 4, -70]},
        {"type": "sphere", "center": [1, 6, -60], "radius": 3},
    ],
    "quality": {"multiple_scattering": False},
}


def camera_basis(scene: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right scaled to the film's half width, up scaled to its half height), as the renderer."""
    cam = scene["camera"]
    forward = np.subtract(cam["look_at"], cam["position"]).astype(float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, cam["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_half = math.tan(math.radians(cam["fov_y"]) / 2)
    aspect = scene["film"]["width"] / scene["film"]["height"]
    return forward, right * tan_half * aspect, up * tan_half


def _unit(v: np.ndarray) -> list[float]:
    return list(map(float, v / np.linalg.norm(v)))


def _sun_cases() -> dict[str, tuple[dict[str, Any], dict[str, Any]]]:
    """name: (camera, sun) with the sun on screen, off screen, behind the camera, at the zenith, on the
    right edge of the screen, and exactly behind the camera (at the antisolar point's opposite)."""
    down_camera = {"position": [0, 20, 10], "look_at": [0, 0, -40], "up": [0, 1, 0], "fov_y": 60}
    street = STREET["camera"]
    forward, right, _ = camera_basis(STREET)
    dforward, _, _ = camera_basis({**STREET, "camera": down_camera})
    return {
        "on_screen": (street, {"elevation": 12, "azimuth": 3}),
        "off_screen": (street, {"elevation": 20, "azimuth": 70}),
        "behind_camera": (street, {"elevation": 25, "azimuth": 170}),
        "zenith": (street, {"direction": [0, 1, 0]}),
        "screen_edge": (street, {"direction": _unit(forward + right)}),
        "exactly_behind": (down_camera, {"direction": _unit(-dforward)}),
    }


SUN_CASES = _sun_cases()


def street_with_sun(case: str) -> dict[str, Any]:
    camera, sun = SUN_CASES[case]
    scene = copy.deepcopy(STREET)
    scene["camera"] = copy.deepcopy(camera)
    scene["sun"] = {**sun, "irradiance": [1.0, 0.95, 0.9]}
    return scene


def relative_errors(image: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relative errors over the pixels (and channels) above 1e-3 of the reference's maximum (the
    issue's measure), and the mask."""
    mask = ref > 1e-3 * ref.max()
    return np.abs(image.astype(np.float64) - ref)[mask] / ref[mask], mask


def worst_pixels(image: np.ndarray, ref: np.ndarray, mask: np.ndarray, n: int = 3) -> str:
    rel = np.where(mask, np.abs(image - ref) / np.maximum(ref, 1e-300), 0.0).max(axis=-1)
    order = np.argsort(rel, axis=None)[::-1][:n]
    rows, cols = np.unravel_index(order, rel.shape)
    return ", ".join(f"(row {r}, col {c}): {rel[r, c]:.2e}" for r, c in zip(rows, cols))


def medium_sun(renderer: airlight.Renderer, scene: dict[str, Any]) -> np.ndarray:
    return renderer.render(scene, outputs=["medium_sun"])["medium_sun"]


@pytest.mark.parametrize("case", list(SUN_CASES))
def test_medium_sunlight_matches_the_exact_reference(renderer, case):
    scene = street_with_sun(case)
    ref = reference.medium_sun_radiance(scene, WIDTH, HEIGHT)
    unshadowed = reference.medium_sun_radiance({**scene, "surfaces": []}, WIDTH, HEIGHT)
    assert ref.max() > 0
    image = medium_sun(renderer, scene)
    assert np.all(np.isfinite(image))
    rel, mask = relative_errors(image, ref)
    where = worst_pixels(image, ref, mask)
    # Float32 rounding of the run ends and of exp: measured median 1-2e-7, max 6e-6 on both backends.
    assert np.median(rel) < 1e-5, where
    assert np.percentile(rel, 99) < 1e-4, where
    assert rel.max() < 1e-3, where
    # The scene has shadows to get right: the rays that reach the sky miss much of the sunlight.
    if case != "exactly_behind":
        assert np.max(1 - ref / np.maximum(unshadowed, 1e-300)) > 0.3


def test_sun_at_or_below_the_horizon_scatters_nothing(renderer):
    for direction in ([0, 0, -1], [0.3, -0.2, -1]):
        scene = copy.deepcopy(STREET)
        scene["sun"] = {"direction": direction, "irradiance": 1.0}
        out = renderer.render(scene, outputs=["medium_sun", "radiance"])
        assert np.all(out["medium_sun"] == 0)
        assert np.all(np.isfinite(out["radiance"]))


def test_shafts_off_is_the_unshadowed_closed_form(renderer):
    scene = street_with_sun("on_screen")
    scene["quality"]["shafts"] = "off"
    image = medium_sun(renderer, scene)
    # J_sun (1 - e^{-sigma_t t_hit}) / sigma_t with t_hit from the reference's own ray casting.
    origin, dirs = reference.camera_rays(scene, WIDTH, HEIGHT)
    t_hit = reference.first_hit(origin, dirs, scene["surfaces"])
    sigma_t, sigma_s = reference.medium_coefficients(scene["medium"])
    s = reference.sun_direction(scene["sun"])
    phase = reference.phase_value(scene["medium"]["phase"], dirs @ s)[..., None]
    e = reference.rgb(scene["sun"]["irradiance"])
    ref = sigma_s * phase * e / sigma_t * -np.expm1(-sigma_t * t_hit[..., None])
    rel, _ = relative_errors(image, ref)
    assert rel.max() < 1e-5


def test_scene_without_casters_renders_as_without_shafts(renderer):
    """Skipped where it cannot matter: no surfaces, nothing changes (bit for bit) and no shadow
    runs are sought."""
    scene = street_with_sun("on_screen")
    scene["surfaces"] = []
    scene["sky"] = {"model": "cie", "type": 12, "zenith_radiance": 0.3}
    scene["atmosphere"] = {"molecules": {}, "aerosol": {"visibility": 5000}}
    on = renderer.render(scene, outputs=["radiance", "medium_sun"])
    scene["quality"]["shafts"] = "off"
    off = renderer.render(scene, outputs=["radiance", "medium_sun"])
    assert np.array_equal(on["radiance"], off["radiance"])
    assert np.array_equal(on["medium_sun"], off["medium_sun"])


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_random_occluders_match_the_reference(renderer_cache, data):
    """Random boxes and spheres, any sun above the horizon (axis-aligned ones included), any fog."""
    draw = data.draw
    coordinate = st.floats(-30, 30)
    surfaces: list[dict[str, Any]] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]
    # The camera (STREET's, at (0, 1.7, 0)) stays outside every caster, 1 cm clear of it: a camera on
    # a box's face or edge is a degenerate scene (inside or outside is a matter of rounding, and the
    # renderer and the reference may round differently), not a shadow to measure.
    camera = np.array(STREET["camera"]["position"], float)
    for _ in range(draw(st.integers(1, 8))):
        lo = [draw(coordinate), draw(st.floats(0, 5)), draw(st.floats(-80, -5))]
        size = [draw(st.floats(0.05, 12)) for _ in range(3)]
        hi = [a + b for a, b in zip(lo, size)]
        if all(a - 0.01 <= c <= b + 0.01 for a, b, c in zip(lo, hi, camera)):
            continue
        surfaces.append({"type": "box", "min": lo, "max": hi})
    for _ in range(draw(st.integers(0, 3))):
        centre = [draw(coordinate), draw(st.floats(0, 15)), draw(st.floats(-80, -5))]
        radius = draw(st.floats(0.1, 6))
        if np.linalg.norm(np.subtract(centre, camera)) <= radius + 0.01:
            continue
        surfaces.append({"type": "sphere", "center": centre, "radius": radius})
    axis = st.sampled_from([0.0, 0.0, 1.0, -1.0]) | st.floats(-1, 1)
    sun = [draw(axis), draw(st.sampled_from([1.0]) | st.floats(0.02, 1)), draw(axis)]
    scene = copy.deepcopy(STREET)
    scene["surfaces"] = surfaces
    scene["sun"] = {"direction": sun, "irradiance": 1.0}
    scene["medium"] = {"sigma_t": draw(st.floats(1e-4, 0.5)), "albedo": 1.0,
                       "phase": {"type": "hg", "g": draw(st.floats(-0.9, 0.9))}}
    scene["film"] = {"width": 32, "height": 18}
    # The reference sees the sun as the renderer stores it (float32): a component like 1e-140 is
    # 0 there, and a box face then lies exactly along the sunlight on both sides.
    scene["sun"] = airlight.load_scene(scene)["sun"]
    ref = reference.medium_sun_radiance(scene, 32, 18)
    image = medium_sun(renderer_cache("cpu"), scene)
    assert np.all(np.isfinite(image))
    if ref.max() == 0:  # all shadowed: float32 run ends may leave a sliver lit, nothing more
        unshadowed = medium_sun(renderer_cache("cpu"), {**scene, "quality": {"shafts": "off"}})
        assert image.max() <= 1e-5 * unshadowed.max()
        return
    rel, mask = relative_errors(image, ref)
    where = worst_pixels(image, ref, mask)
    assert np.median(rel) < 1e-5, where
    # A pixel whose ray grazes a box's edge or a sphere's rim may see float32's run ends differ
    # from float64's; that costs a few pixels a bit more.
    assert np.percentile(rel, 99) < 1e-3, where


def test_more_separate_shadows_than_kept_only_darken(renderer):
    """A ray through a colonnade of 80 thin pillars crosses more separate shadows than the 64 runs
    a ray keeps (physics.md section 4): joined runs lose a lit gap, so the pixel can only be darker
    than the reference, and pixels whose rays cross fewer are exact."""
    scene = copy.deepcopy(STREET)
    scene["camera"] = {"position": [0, 1, 0], "look_at": [0, 1, -10], "up": [0, 1, 0], "fov_y": 30}
    scene["sun"] = {"direction": [1, 0.4, 0], "irradiance": 1.0}
    scene["medium"] = {"sigma_t": 0.002, "albedo": 1.0}
    # Pillars beside the view, toward the sun: each shadows its own 0.5 m of the central rays.
    scene["surfaces"] = [{"type": "box", "min": [2, 0, -3 - 2 * k], "max": [4, 30, -2.5 - 2 * k]}
                         for k in range(80)]
    ref = reference.medium_sun_radiance(scene, WIDTH, HEIGHT)
    image = medium_sun(renderer, scene).astype(np.float64)
    assert np.all(image <= ref * (1 + 5e-5))  # float32 sums of 80 runs: up to 2.2e-5 above on GL
    assert np.any(image < ref * (1 - 1e-3))  # some rays did cross more than 64
    rel, _ = relative_errors(image, ref)
    assert np.median(rel) < 1e-5


def test_march_converges_to_the_closed_form(renderer_cache):
    renderer = renderer_cache("cpu")
    scene = street_with_sun("on_screen")
    exact = medium_sun(renderer, scene)
    errors = []
    for steps in (256, 1024, 4096):
        march = copy.deepcopy(scene)
        march["quality"].update(shafts="march", march_steps=steps)
        rel, _ = relative_errors(medium_sun(renderer, march), exact.astype(np.float64))
        errors.append((np.median(rel), np.percentile(rel, 99)))
    # Measured: p99 0.27, 0.059, 0.014 (each shadow edge inside a step costs up to the step's share).
    assert errors[0][1] > 3 * errors[1][1] > 9 * errors[2][1]
    assert errors[2][0] < 1e-3 and errors[2][1] < 0.02


# A daytime street: the atmosphere (molecules and a 3 km haze), the sky and a thin homogeneous fog.
DAY: dict[str, Any] = {
    **copy.deepcopy(STREET),
    "film": {"width": 48, "height": 27},
    "camera": {"position": [0, 1.7, 0], "look_at": [0, 8, -30], "up": [0, 1, 0], "fov_y": 60},
    "sky": {"model": "cie", "type": 12, "zenith_radiance": 0.3},
    "sun": {"elevation": 12, "azimuth": 3, "irradiance": 100.0},
    "atmosphere": {"molecules": {}, "aerosol": {"visibility": 3000}},
    "medium": {"sigma_t": 0.01, "albedo": 0.9, "phase": {"type": "hg", "g": 0.6}},
}

DAY_LAYERS = ["radiance", "sky", "rainbow", "medium_sun"]


def render_day(renderer: airlight.Renderer, shafts: str, steps: int = 64) -> dict[str, np.ndarray]:
    scene = copy.deepcopy(DAY)
    scene["quality"].update(shafts=shafts, march_steps=steps)
    if shafts == "off" and steps > 64:
        scene["quality"]["airlight"] = "march"  # the unshadowed atmosphere marched
    return renderer.render(scene, outputs=DAY_LAYERS)


@pytest.mark.slow
def test_atmosphere_shadows_match_marching_at_convergence(renderer_cache):
    """The atmosphere's lit parts of each volume (physics.md section 5) against the brute-force
    march with a shadow ray per step at 16384 steps (converged: 65536 changes it by < 1e-3). The
    scattering volumes' own model error (the unshadowed atmosphere against its march: median 0.44 %,
    p99 0.8 % here) is all there is: the shadows add under 0.1 %."""
    renderer = renderer_cache("cpu")
    fast, slow = render_day(renderer, "analytic"), render_day(renderer, "march", 16384)
    fast_off, slow_off = render_day(renderer, "off"), render_day(renderer, "off", 16384)
    for layer in ("radiance", "sky", "medium_sun"):
        ref = slow[layer].astype(np.float64)
        rel, mask = relative_errors(fast[layer], ref)
        where = worst_pixels(fast[layer], ref, mask)
        assert np.median(rel) < 0.006, (layer, where)
        assert np.percentile(rel, 99) < 0.012, (layer, where)
        rel_model, _ = relative_errors(fast_off[layer], slow_off[layer].astype(np.float64))
        assert np.percentile(rel, 99) < np.percentile(rel_model, 99) + 0.002, (layer, where)
        # ... and the shadows matter here (unshadowed, it is far off).
        rel_off, _ = relative_errors(fast_off[layer], ref)
        assert np.percentile(rel_off, 99) > 0.2, layer


def test_day_shafts_agree_on_both_backends_and_layers_sum(renderer_cache):
    if airlight.gl_unavailable_reason() is not None:
        pytest.skip(f"no GL here: {airlight.gl_unavailable_reason()}")
    scene = copy.deepcopy(DAY)
    scene["atmosphere"]["rain"] = {"rate": 2}  # a rainbow layer apart
    scene["sun"] = {"elevation": 30, "azimuth": 180, "irradiance": 100.0}
    outs = {b: renderer_cache(b).render(scene, outputs=["layers", "radiance"]) for b in ("cpu", "gl")}
    for name in ["radiance", *airlight.LAYERS]:
        cpu, gl = outs["cpu"][name], outs["gl"][name]
        # (the atmosphere: float32 exp and log differ by up to 2e-4 between the backends)
        assert np.allclose(cpu, gl, rtol=1e-3, atol=1e-6 * outs["cpu"]["radiance"].max()), name
    for out in outs.values():
        total = sum(out[name] for name in airlight.LAYERS)
        assert np.allclose(total, out["radiance"], rtol=4e-6, atol=1e-12)
        assert out["medium_sun"].max() > 0 and out["rainbow"].max() > 0


@pytest.mark.parametrize("method", ["analytic", "march", "off"])
def test_shafts_method_is_read_and_written_back(method):
    scene = copy.deepcopy(STREET)
    scene["quality"]["shafts"] = method
    assert airlight.load_scene(scene)["quality"]["shafts"] == method


def test_default_shafts_method_is_analytic():
    assert airlight.load_scene(STREET)["quality"]["shafts"] == "analytic"


@pytest.mark.parametrize("bad, error", [("epipolar ", ValueError), ("", ValueError), (1, TypeError)])
def test_bad_shafts_method_names_the_field(bad, error):
    scene = copy.deepcopy(STREET)
    scene["quality"]["shafts"] = bad
    with pytest.raises(error, match="quality.shafts"):
        airlight.load_scene(scene)


def test_sun_moving_in_small_steps_changes_like_the_reference(renderer):
    """Stability: the sun moving 0.1 degree per frame changes each pixel as the exact reference does
    (no flicker of the method's own)."""
    frames, refs = [], []
    for k in range(6):
        scene = street_with_sun("on_screen")
        scene["sun"]["elevation"] = 12 + 0.1 * k
        frames.append(medium_sun(renderer, scene).astype(np.float64))
        refs.append(reference.medium_sun_radiance(scene, WIDTH, HEIGHT))
    peak = max(r.max() for r in refs)
    for k in range(1, len(frames)):
        ours = frames[k] - frames[k - 1]
        theirs = refs[k] - refs[k - 1]
        assert np.abs(theirs).max() > 1e-3 * peak  # the shafts move
        assert np.abs(ours - theirs).max() < 1e-4 * peak


# ---- lamps' volumetric shadows (physics.md section 7) ----------------------------------------

# A lamp between two buildings over a street, a low wall and a ball near it casting shadows into
# the fog; the camera stands in the street.
ALLEY: dict[str, Any] = {
    "film": {"width": 48, "height": 27},
    "camera": {"position": [0, 1.7, 12], "look_at": [0, 4, -10], "up": [0, 1, 0], "fov_y": 60},
    "medium": {"sigma_t": [0.05, 0.06, 0.07], "albedo": 0.9, "phase": {"type": "hg", "g": 0.3}},
    "surfaces": [
        {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3},
        {"type": "box", "min": [-8, 0, -10], "max": [-3, 12, 0]},
        {"type": "box", "min": [3, 0, -10], "max": [8, 12, 0]},
        {"type": "box", "min": [-1, 0, -3], "max": [1, 3, -2]},
        {"type": "sphere", "center": [1, 6, -6], "radius": 1},
    ],
    "lights": [{"type": "point", "position": [0, 5, -5], "intensity": [100, 90, 70],
                "volumetric_shadows": True}],
    "quality": {"multiple_scattering": False},
}


def lamp_errors(image: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, str]:
    rel, mask = relative_errors(image, ref)
    return rel, worst_pixels(image, ref, mask)


def assert_lamp_matches(image: np.ndarray, ref: np.ndarray) -> None:
    assert np.all(np.isfinite(image))
    rel, where = lamp_errors(image, ref)
    # Measured median 4e-6; the rays passing within a lamp radius of the lamp carry the
    # airlight tables' own error near the singular point (1.3%, the same without shadows).
    assert np.median(rel) < 1e-4, where
    assert np.percentile(rel, 95) < 1e-3, where
    assert rel.max() < 3e-2, where


@pytest.mark.parametrize("camera", ["street", "in_shadow", "above"])
def test_lamp_shadows_match_the_exact_reference(renderer, camera):
    scene = copy.deepcopy(ALLEY)
    if camera == "in_shadow":  # behind the low wall, looking at the lamp over it
        scene["camera"] = {"position": [0.2, 1.0, -1.0], "look_at": [0, 5, -5], "up": [0, 1, 0], "fov_y": 70}
    elif camera == "above":  # over the roofs, the lamp's shadows fanning out below
        scene["camera"] = {"position": [6, 20, 10], "look_at": [0, 3, -5], "up": [0, 1, 0], "fov_y": 50}
    ref = reference.lamp_airlight_radiance(scene, 48, 27)
    image = renderer.render(scene, outputs=["lamps"])["lamps"]
    assert_lamp_matches(image, ref)
    # The shadows matter: unshadowed, the airlight is brighter by more than the error allowed.
    scene["lights"][0]["volumetric_shadows"] = False
    unshadowed = renderer.render(scene, outputs=["lamps"])["lamps"]
    assert np.all(unshadowed >= image * (1 - 1e-5))
    assert np.max(relative_errors(unshadowed, ref)[0]) > 0.3


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_lamp_shadows_of_random_occluders_match_the_reference(renderer_cache, data):
    """Random boxes and spheres around a lamp at a random place (inside a caster's shadow cone or
    between casters), any fog."""
    draw = data.draw
    # Geometry as the renderer holds it (float32): a float64-only value such as 2e-216 would put a
    # caster's face on one side of the lamp for the reference and on the lamp for the renderer.
    def coordinate(lo: float, hi: float) -> float:
        return draw(st.floats(float(np.float32(lo)), float(np.float32(hi)), width=32))

    surfaces: list[dict[str, Any]] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]
    for _ in range(draw(st.integers(1, 5))):
        lo = [coordinate(-10, 10), coordinate(0, 6), coordinate(-20, -2)]
        size = [coordinate(0.05, 6) for _ in range(3)]
        surfaces.append({"type": "box", "min": lo, "max": [a + b for a, b in zip(lo, size)]})
    for _ in range(draw(st.integers(0, 2))):
        centre = [coordinate(-10, 10), coordinate(0, 10), coordinate(-20, -2)]
        surfaces.append({"type": "sphere", "center": centre, "radius": coordinate(0.1, 3)})
    lamp = [coordinate(-8, 8), coordinate(0.5, 10), coordinate(-18, -1)]
    scene = copy.deepcopy(ALLEY)
    scene["film"] = {"width": 32, "height": 18}
    scene["surfaces"] = surfaces
    scene["lights"] = [{"type": "point", "position": lamp, "intensity": 50, "volumetric_shadows": True}]
    scene["medium"] = {"sigma_t": draw(st.floats(1e-3, 0.5)), "albedo": 1.0,
                       "phase": {"type": "hg", "g": draw(st.floats(-0.8, 0.8))}}
    ref = reference.lamp_airlight_radiance(scene, 32, 18)
    image = renderer_cache("cpu").render(scene, outputs=["lamps"])["lamps"]
    assert np.all(np.isfinite(image))
    if ref.max() == 0:
        assert image.max() == 0
        return
    rel, where = lamp_errors(image, ref)
    assert np.median(rel) < 1e-4, where
    # Rays grazing a caster's silhouette may see float32's run ends differ from float64's.
    assert np.percentile(rel, 95) < 2e-3, where


def spot_alley() -> dict[str, Any]:
    scene = copy.deepcopy(ALLEY)
    scene["lights"] = [{"type": "spot", "position": [0, 5, -5], "direction": [0.2, -1, 0.3], "cone_angle": 40,
                        "intensity": [300, 280, 250], "volumetric_shadows": True}]
    return scene


def test_spot_shadows_match_marching_at_convergence(renderer_cache):
    """Spots have no exact reference with shadows; the brute-force march (a shadow ray per step,
    reusing nothing of the closed form) converges to the same image."""
    scene = spot_alley()
    cpu = renderer_cache("cpu")
    image = cpu.render(scene, outputs=["spots"])["spots"]
    scene["quality"]["airlight"] = "march"
    scene["quality"]["march_steps"] = 8192
    marched = cpu.render(scene, outputs=["spots"])["spots"].astype(np.float64)
    rel, mask = relative_errors(image, marched)
    where = worst_pixels(image, marched, mask)
    assert np.median(rel) < 2e-3, where
    assert np.percentile(rel, 95) < 2e-2, where
    scene = spot_alley()
    scene["lights"][0]["volumetric_shadows"] = False
    unshadowed = cpu.render(scene, outputs=["spots"])["spots"]
    assert np.all(unshadowed >= image * (1 - 1e-5))
    assert np.max(relative_errors(unshadowed, marched)[0]) > 0.3


def test_lamp_and_spot_shadows_agree_on_both_backends(renderer_cache):
    scene = spot_alley()
    scene["lights"].append(ALLEY["lights"][0])
    outputs = ["radiance", "layers"]
    cpu = renderer_cache("cpu").render(scene, outputs=outputs)
    gl = renderer_cache("gl").render(scene, outputs=outputs)
    for name in ("lamps", "spots", "radiance"):
        np.testing.assert_allclose(gl[name], cpu[name], rtol=1e-3, atol=1e-5 * float(cpu[name].max()))


def test_shafts_off_turns_lamp_shadows_off(renderer):
    scene = copy.deepcopy(ALLEY)
    scene["quality"]["shafts"] = "off"
    off = renderer.render(scene, outputs=["lamps"])["lamps"]
    scene["quality"].pop("shafts")
    scene["lights"][0]["volumetric_shadows"] = False
    unshadowed = renderer.render(scene, outputs=["lamps"])["lamps"]
    assert np.array_equal(off, unshadowed)


@pytest.mark.parametrize("light", [ALLEY["lights"][0], spot_alley()["lights"][0]])
def test_volumetric_shadows_key_is_read_and_written_back(light):
    scene = {**copy.deepcopy(ALLEY), "lights": [copy.deepcopy(light)]}
    assert airlight.load_scene(scene)["lights"][0]["volumetric_shadows"] is True
    scene["lights"][0].pop("volumetric_shadows")
    assert airlight.load_scene(scene)["lights"][0]["volumetric_shadows"] is False


@pytest.mark.parametrize("bad", [1, "yes", None])
def test_bad_volumetric_shadows_names_the_field(bad):
    scene = copy.deepcopy(ALLEY)
    scene["lights"][0]["volumetric_shadows"] = bad
    with pytest.raises(TypeError, match=r"lights\[0\]\.volumetric_shadows"):
        airlight.load_scene(scene)
