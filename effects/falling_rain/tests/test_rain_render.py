"""Rendered drops against independent radiometry (issue 23's acceptance; physics.md sections 4-5): one
drop's streak carries, summed over the film, the drop's radiance times its solid angle over the exposure
(within 1 %, both backends), its radiance the lamp's I / d^2 exp(-sigma_t d) through the drop's closed-form
optics; outside a spot's cone it is dark; a scene without rain or without a light builds nothing; and
the corners (a drop on the camera, rate 0 and 1000 mm/h, 50 m/s wind, zero and long exposures) give
finite, non-negative light whose layers still sum to the radiance."""

from __future__ import annotations

import copy
import functools
import json
import math
import subprocess
import sys
import textwrap
from typing import Any

import numpy as np
import pytest
import rain_reference as ref
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import airlight

# The renderer's RGB wavelengths for water (physics.md eq. 4.3).
WAVELENGTHS = (610.0, 550.0, 465.0)

VIEWS: dict[str, dict[str, Any]] = {
    # Drops well under a pixel, 0.3 to 1 m away.
    "far": {"fov_y": 6.0, "radius": 1.0, "rate": 0.2, "exposure_time": 1 / 400},
    # Drops over a pixel wide, a few centimetres to 0.3 m away.
    "near": {"fov_y": 24.0, "radius": 0.3, "rate": 0.2, "exposure_time": 1 / 250},
}
SIZE = 40


def base_scene(view: str, seed: int) -> dict[str, Any]:
    v = VIEWS[view]
    return {
        "film": {"width": SIZE, "height": SIZE},
        "camera": {
            "position": [0.0, 1.5, 0.0],
            "look_at": [0.0, 1.5, -5.0],
            "up": [0, 1, 0],
            "fov_y": v["fov_y"],
            "exposure_time": v["exposure_time"],
        },
        "lights": [{"type": "point", "position": [0, 30, 0], "intensity": [1, 1, 1], "radius": 0.01}],
        "falling_rain": {
            "rate": v["rate"],
            "radius": v["radius"],
            "full_diameter": 0.1,
            "time": 3.0,
            "seed": seed,
        },
    }


def streak_corners(scene: dict[str, Any], drops: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each drop's streak's pixel bounding box (x0, y0, x1, y1), grown by the drop's width, and whether
    both ends are in front of the camera."""
    t = scene["camera"]["exposure_time"]
    ends = [drops["position"] + s * 0.5 * t * drops["velocity"] for s in (-1, 1)]
    o, _, u, f = ref.camera_frame(scene)
    z = np.stack([(e - o) @ f for e in ends])
    pix = np.stack([ref.film_position(scene, e) for e in ends])
    width_px = 1e-3 * drops["diameter"] / (np.maximum(z.min(axis=0), 1e-3) * 2 * np.linalg.norm(u) / SIZE)
    lo = pix.min(axis=0) - width_px[:, None]
    hi = pix.max(axis=0) + width_px[:, None]
    return np.concatenate([lo, hi], axis=1), (z > 0.06).all(axis=0)


@functools.cache
def one_drop(view: str) -> tuple[int, int]:
    """A seed whose field has exactly one streak on the film, well inside it, and the drop's index."""
    for seed in range(2000):
        scene = base_scene(view, seed)
        drops = airlight._core.rain_drops(scene)
        box, in_front = streak_corners(scene, drops)
        touches = (
            (box[:, 2] > -2)
            & (box[:, 3] > -2)
            & (box[:, 0] < SIZE + 2)
            & (box[:, 1] < SIZE + 2)
            & (
                np.array(
                    [
                        (p - np.array(scene["camera"]["position"])) @ ref.camera_frame(scene)[3]
                        for p in drops["position"]
                    ]
                )
                > -0.1
            )
        )
        inside = (
            touches
            & in_front
            & (box[:, 0] > 3)
            & (box[:, 1] > 3)
            & (box[:, 2] < SIZE - 3)
            & (box[:, 3] < SIZE - 3)
            & (drops["weight"] > 0.2)
        )
        if touches.sum() == 1 and inside.sum() == 1:
            return seed, int(np.flatnonzero(inside)[0])
    raise AssertionError(f"no seed gives one drop in view for {view}")


def lit_scene(
    view: str, angle_deg: float, *, sigma_t: float = 0.0, spot_aim_deg: float | None = None
) -> tuple[dict[str, Any], dict[str, np.ndarray], int, np.ndarray]:
    """The one-drop scene with a lamp 2 m from the drop, which sends its light to the camera at the
    scattering angle `angle_deg` (or a spot there aimed `spot_aim_deg` off the drop)."""
    seed, k = one_drop(view)
    scene = base_scene(view, seed)
    drops = airlight._core.rain_drops(scene)
    p = drops["position"][k]
    v = p - np.array(scene["camera"]["position"])
    v /= np.linalg.norm(v)
    # The light travels along w, at the scattering angle angle_deg from the light the camera receives,
    # which travels along -v: the lamp sits at p - 2 w.
    side = np.cross(v, [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    a = math.radians(angle_deg)
    w = -math.cos(a) * v + math.sin(a) * side
    lamp = p - 2.0 * w
    intensity = [700.0, 500.0, 300.0]
    if spot_aim_deg is None:
        scene["lights"] = [
            {"type": "point", "position": lamp.tolist(), "intensity": intensity, "radius": 0.01}
        ]
    else:
        b = math.radians(spot_aim_deg)
        aim = math.cos(b) * w + math.sin(b) * np.cross(w, side)
        scene["lights"] = [
            {
                "type": "spot",
                "position": lamp.tolist(),
                "direction": aim.tolist(),
                "intensity": intensity,
                "cone_angle": 10.0,
                "edge": 0.2,
                "radius": 0.01,
            }
        ]
    if sigma_t > 0:
        scene["medium"] = {"sigma_t": sigma_t, "albedo": 0.0, "phase": {"type": "isotropic"}}
    return scene, drops, k, np.array(intensity)


def rendered_energy(
    renderer: airlight.Renderer, scene: dict[str, Any]
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    out = renderer.render(scene, outputs=["falling_rain", "radiance", "layers"])
    return np.einsum("hwc,hw->c", out["falling_rain"].astype(np.float64), ref.pixel_solid_angles(scene)), out


def expected_energy(
    scene: dict[str, Any],
    drops: dict[str, np.ndarray],
    k: int,
    intensity: np.ndarray,
    angle_deg: float,
    sigma_t: float,
) -> np.ndarray:
    f = np.array(
        [
            ref.drop_phase(
                airlight._core.water_refractive_index(wl), math.radians(angle_deg), airlight._core.DROP_ORDERS
            )
            for wl in WAVELENGTHS
        ]
    )
    radiance = intensity / 4.0 * math.exp(-2.0 * sigma_t) * f  # I / d^2 exp(-sigma_t d) f(theta), d = 2 m
    seen = ref.streak_solid_angle_time(
        scene, drops["position"][k], drops["velocity"][k], drops["diameter"][k], sigma_t
    )
    return drops["weight"][k] * radiance * seen


@pytest.mark.parametrize("view", list(VIEWS))
@pytest.mark.parametrize(("angle", "sigma_t"), [(25.0, 0.0), (60.0, 0.3), (150.0, 0.0)])
def test_a_streaks_energy_is_the_drops_radiance_times_its_solid_angle_and_time(
    renderer, view, angle, sigma_t
):
    scene, drops, k, intensity = lit_scene(view, angle, sigma_t=sigma_t)
    energy, out = rendered_energy(renderer, scene)
    exact = expected_energy(scene, drops, k, intensity, angle, sigma_t)
    np.testing.assert_allclose(energy, exact, rtol=0.01)
    # The streak is all there is, and the layers still add up to the radiance.
    assert (out["falling_rain"] > 0).sum() >= 1
    np.testing.assert_allclose(out["radiance"], out["falling_rain"], rtol=1e-5, atol=1e-30)


def test_a_drop_outside_a_spots_cone_is_dark_and_inside_it_lit(renderer):
    scene, drops, k, intensity = lit_scene("far", 25.0, spot_aim_deg=0.0)
    energy, _ = rendered_energy(renderer, scene)
    np.testing.assert_allclose(energy, expected_energy(scene, drops, k, intensity, 25.0, 0.0), rtol=0.01)
    scene, *_ = lit_scene("far", 25.0, spot_aim_deg=30.0)
    energy, out = rendered_energy(renderer, scene)
    assert np.all(out["falling_rain"] == 0.0), energy


def test_a_surface_in_front_hides_the_drop_and_one_behind_does_not(renderer):
    scene, drops, k, _ = lit_scene("far", 25.0)
    cam = np.array(scene["camera"]["position"])
    dist = float(np.linalg.norm(drops["position"][k] - cam))
    clear, _ = rendered_energy(renderer, scene)
    for at, hidden in ((0.5 * dist, True), (dist + 2.5, False)):  # the lamp is 2 m beyond the drop
        wall = copy.deepcopy(scene)
        wall["surfaces"] = [{"type": "plane", "point": [0, 0, -at], "normal": [0, 0, 1], "albedo": [0, 0, 0]}]
        energy, _ = rendered_energy(renderer, wall)
        if hidden:
            assert np.all(energy == 0.0)
        else:
            np.testing.assert_allclose(energy, clear, rtol=1e-4)


def test_a_box_between_the_lamp_and_the_drop_shadows_it_and_one_beside_does_not(renderer):
    scene, drops, k, _ = lit_scene("far", 60.0)
    p = drops["position"][k]
    lamp = np.array(scene["lights"][0]["position"])
    clear, _ = rendered_energy(renderer, scene)
    assert np.all(clear > 0)
    # A 0.2 m cube halfway along the lamp's light, then the same cube moved 0.5 m off that line
    # (along the camera's up, so it neither crosses the light nor the camera's view of the drop).
    middle = 0.5 * (p + lamp)
    up = np.array([0.0, 1.0, 0.0])
    for offset, shadowed in ((0.0, True), (0.5, False)):
        centre = middle + offset * up
        boxed = copy.deepcopy(scene)
        boxed["surfaces"] = [
            {
                "type": "box",
                "min": (centre - 0.1).tolist(),
                "max": (centre + 0.1).tolist(),
                "albedo": [0, 0, 0],
            }
        ]
        energy, _ = rendered_energy(renderer, boxed)
        if shadowed:
            assert np.all(energy == 0.0), energy
        else:
            np.testing.assert_allclose(energy, clear, rtol=1e-4)


TABLES = textwrap.dedent("""
    import json, sys, airlight
    out = airlight.render(json.loads(sys.argv[1]), backend="cpu", outputs=["falling_rain"])
    print(json.dumps([sorted(airlight.table_stats()), float(out["falling_rain"].sum())]))
""")


@pytest.mark.parametrize(
    "change", [None, {"falling_rain": None}, {"lights": []}, {"falling_rain": {"rate": 0}}]
)
def test_a_scene_without_rain_or_without_light_builds_nothing(change):
    scene, *_ = lit_scene("far", 25.0)
    scene.update(change or {})
    out = subprocess.run(
        [sys.executable, "-c", TABLES, json.dumps(scene)], capture_output=True, text=True, check=True
    )
    tables, light = json.loads(out.stdout)
    assert ("drop_optics" in tables) == (change is None), tables
    assert (light > 0) == (change is None)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    rate=st.sampled_from([0.0, 1e-3, 5.0, 200.0, 1000.0]),
    wind=st.sampled_from([[0, 0, 0], [50, 0, 0], [-30, 0, 40]]),
    exposure=st.sampled_from([0.0, 1e-4, 1 / 60, 0.5, 10.0]),
    look=st.sampled_from([[0, 1.5, -5], [0, 40, -0.01], [0, -40, -0.01], [5, 1.5, 0]]),
)
def test_corners_give_finite_non_negative_light(rate, wind, exposure, look):
    scene = {
        "film": {"width": 24, "height": 16},
        "camera": {
            "position": [0, 1.5, 0],
            "look_at": look,
            "up": [0, 1, 0],
            "fov_y": 70,
            "exposure_time": exposure,
        },
        "medium": {"sigma_t": 0.05, "albedo": 0.9, "phase": {"type": "isotropic"}},
        "lights": [
            {"type": "point", "position": [0.5, 2.5, -1], "intensity": [300, 300, 300], "radius": 0.05},
            {
                "type": "spot",
                "position": [0, 1.6, 0.2],
                "direction": [0, -0.2, -1],
                "intensity": [1e4] * 3,
                "cone_angle": 20,
            },
        ],
        "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.3, 0.3, 0.3]}],
        "falling_rain": {"rate": rate, "radius": 1.5, "wind": wind, "time": 11.0},
        "quality": {"multiple_scattering": False},
    }
    out = airlight.render(scene, "cpu", outputs=["radiance", "falling_rain", "layers"])
    for name, image in out.items():
        assert np.isfinite(image).all(), name
        assert (image >= 0).all(), name


def test_a_drop_on_the_camera_is_finite(backend):
    # The camera inside the drops' volume with every size drawn right up to it: some streaks pass through
    # the near plane and the camera itself.
    scene = {
        "film": {"width": 24, "height": 16},
        "camera": {
            "position": [0, 1.5, 0],
            "look_at": [0, 1.0, -5],
            "up": [0, 1, 0],
            "fov_y": 90,
            "exposure_time": 0.2,
        },
        "lights": [
            {"type": "point", "position": [0, 1.6, -0.3], "intensity": [100, 100, 100], "radius": 0.05}
        ],
        "falling_rain": {"rate": 500, "radius": 0.2, "full_diameter": 0.1},
    }
    out = airlight.render(scene, backend, outputs=["radiance", "falling_rain"])
    assert np.isfinite(out["radiance"]).all() and (out["radiance"] >= 0).all()
    assert out["falling_rain"].max() > 0


def test_frames_change_continuously_as_time_goes_on(renderer):
    # A streak moves by its velocity times the frame time: at 1/2000 s apart the image barely changes.
    scene = {
        "film": {"width": 48, "height": 32},
        "camera": {"position": [0, 1.5, 0], "look_at": [0, 1.5, -5], "up": [0, 1, 0], "fov_y": 50},
        "lights": [
            {"type": "point", "position": [0.4, 2.2, -1.5], "intensity": [300, 300, 300], "radius": 0.05}
        ],
        "falling_rain": {"rate": 20, "radius": 2.0, "time": 5.0},
    }
    a = renderer.render(scene, outputs=["falling_rain"])["falling_rain"]
    scene["falling_rain"]["time"] += 1 / 2000
    b = renderer.render(scene, outputs=["falling_rain"])["falling_rain"]
    scene["falling_rain"]["time"] += 0.5
    c = renderer.render(scene, outputs=["falling_rain"])["falling_rain"]
    step, far = np.abs(b - a).sum(), np.abs(c - a).sum()
    assert a.sum() > 0 and far > 0
    assert step < 0.2 * far, (step, far)


def background_behind_the_streaks(scene: dict[str, Any], seeds: int) -> tuple[float, float]:
    """The mean over frames of different seeds of (radiance - the streaks' light) over the same scene's
    radiance without falling rain, and its standard error."""
    dry = {k: v for k, v in scene.items() if k != "falling_rain"}
    base = airlight.render(dry, "cpu").astype(np.float64).mean()
    ratios = []
    for seed in range(seeds):
        wet = copy.deepcopy(scene)
        wet["falling_rain"]["seed"] = seed
        out = airlight.render(wet, "cpu", outputs=["radiance", "falling_rain"])
        ratios.append((out["radiance"].astype(np.float64) - out["falling_rain"]).mean() / base)
    return float(np.mean(ratios)), float(np.std(ratios, ddof=1) / math.sqrt(seeds))


AVERAGE_SCENE: dict[str, Any] = {
    "film": {"width": 64, "height": 48},
    "camera": {"position": [0, 1.6, 0], "look_at": [0, 1.6, -10], "up": [0, 1, 0], "fov_y": 50},
    "falling_rain": {"rate": 50, "time": 1.0},
    "quality": {"multiple_scattering": False},
}


def test_on_average_streaks_take_away_what_the_drawn_drops_cover():
    # Without a rain medium the drops are all the rain: on average over the field a pixel's background
    # is seen through exp(-tau_d), tau_d the drops' expected coverage (physics.md eq. 2.3; a Poisson
    # field: E[prod(1 - alpha)] = exp(-E[sum alpha])).
    scene = {**copy.deepcopy(AVERAGE_SCENE), "background": [1.0, 1.0, 1.0]}
    mean, error = background_behind_the_streaks(scene, 6)
    expected = math.exp(-ref.drawn_optical_depth(50, 8.0, 2.0))
    assert expected < 0.995
    assert abs(mean - expected) < max(4 * error, 5e-4), (mean, expected, error)


def test_with_the_atmospheres_rain_the_total_extinction_is_unchanged():
    # With the atmosphere's rain the drawn drops stand for its near part (eq. 2.4): what they take away
    # is given back, so on average the background is seen exactly as without them.
    scene = {
        **copy.deepcopy(AVERAGE_SCENE),
        "sky": {"model": "overcast", "zenith_radiance": [0.3, 0.3, 0.3]},
        "atmosphere": {"rain": {"rate": 50}},
    }
    scene["falling_rain"] = {"time": 1.0}  # the atmosphere's rate
    mean, error = background_behind_the_streaks(scene, 6)
    assert abs(mean - 1.0) < max(4 * error, 5e-4), (mean, error)
