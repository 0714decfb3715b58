"""The render outputs beside the radiance (issue 19, README "Render outputs"): depth,
distance_z, normal and transmittance against closed forms, the layers summing to the
radiance on every preset and on random scenes, both backends agreeing, and the
``outputs`` argument's checks."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from reference import camera_rays

import airlight
from conftest import run_demo

SMALL = {"width": 40, "height": 30}


def camera(position, look_at, fov_y: float = 60.0, up=(0.0, 1.0, 0.0)) -> dict[str, Any]:
    return {"position": list(position), "look_at": list(look_at), "up": list(up), "fov_y": fov_y}


def rays(scene: dict) -> tuple[np.ndarray, np.ndarray]:
    return camera_rays(scene["camera"], scene["film"]["width"], scene["film"]["height"])


def forward(scene: dict) -> np.ndarray:
    c = scene["camera"]
    f = np.asarray(c["look_at"], float) - np.asarray(c["position"], float)
    return f / np.linalg.norm(f)


def layer_sum(out: dict[str, np.ndarray]) -> np.ndarray:
    return sum(out[name].astype(np.float64) for name in airlight.LAYERS)


def assert_layers_sum_to_radiance(out: dict[str, np.ndarray], label: str) -> None:
    """Every layer finite and >= 0, their sum the radiance to float32 rounding (each pixel
    relative to its own radiance: the layers are non-negative, so nothing cancels)."""
    radiance = out["radiance"].astype(np.float64)
    for name in airlight.LAYERS:
        assert np.isfinite(out[name]).all(), f"{label}: layer {name} not finite"
        assert (out[name] >= 0.0).all(), f"{label}: layer {name} negative"
    gap = np.abs(layer_sum(out) - radiance)
    bound = 4e-6 * radiance + 1e-30
    worst = np.unravel_index(int(np.argmax(gap - bound)), gap.shape)
    assert (gap <= bound).all(), (f"{label}: layers sum {layer_sum(out)[worst]} against radiance "
                                  f"{radiance[worst]} at {worst}")


# ---- depth, distance_z and normal against closed forms --------------------------------

def test_depth_of_a_plane_facing_the_camera_has_its_closed_form(renderer) -> None:
    # A wall z = -10 seen from the origin: depth 10 / cos(angle to the axis), distance_z 10.
    scene = {"film": SMALL, "camera": camera((0, 0, 0), (0, 0, -1), fov_y=70.0),
             "surfaces": [{"type": "plane", "point": [0, 0, -10], "normal": [0, 0, 1], "albedo": 0.5}]}
    out = renderer.render(scene, outputs=["depth", "distance_z", "normal"])
    _, dirs = rays(scene)
    expected = 10.0 / -dirs[..., 2]
    np.testing.assert_allclose(out["depth"], expected, rtol=2e-6)
    np.testing.assert_allclose(out["distance_z"], 10.0, rtol=2e-6)
    np.testing.assert_allclose(out["normal"], np.broadcast_to([0.0, 0.0, 1.0], dirs.shape), atol=1e-7)
    assert out["depth"].shape == (30, 40) and out["depth"].dtype == np.float32


def test_depth_of_a_box_and_a_sphere_against_ray_intersection_in_float64(renderer) -> None:
    box_lo, box_hi = np.array([-3.0, -1.0, -9.0]), np.array([-0.5, 1.5, -6.0])
    centre, radius = np.array([1.5, 0.2, -8.0]), 1.3
    scene = {"film": {"width": 48, "height": 32}, "camera": camera((0.3, 0.4, 0.0), (0.0, 0.2, -8.0)),
             "surfaces": [{"type": "box", "min": box_lo.tolist(), "max": box_hi.tolist(), "albedo": 0.4},
                          {"type": "sphere", "center": centre.tolist(), "radius": radius, "albedo": 0.6}]}
    out = renderer.render(scene, outputs=["depth", "distance_z", "normal"])
    origin, dirs = rays(scene)
    d = dirs.reshape(-1, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (box_lo - origin) / d, (box_hi - origin) / d
        t_near = np.minimum(ta, tb).max(axis=1)
        t_far = np.maximum(ta, tb).min(axis=1)
    t_box = np.where((t_near <= t_far) & (t_near > 0), t_near, np.inf)
    face = np.argmax(np.minimum(ta, tb), axis=1)
    n_box = np.zeros_like(d)
    n_box[np.arange(len(d)), face] = -np.sign(d[np.arange(len(d)), face])
    oc = origin - centre
    b = d @ oc
    disc = b * b - (oc @ oc - radius * radius)
    t_sphere = np.where(disc >= 0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    t_sphere = np.where(t_sphere > 0, t_sphere, np.inf)
    n_sphere = (origin + t_sphere[:, None] * d - centre) / radius
    t = np.minimum(t_box, t_sphere)
    normal = np.where((t_box <= t_sphere)[:, None], n_box, n_sphere)
    normal[~np.isfinite(t)] = 0.0
    depth = out["depth"].reshape(-1)
    # Pixels whose ray grazes an edge (the two surfaces within 0.1 %, or a silhouette) are
    # left out: float32 may pick either side there.
    hit = np.isfinite(t)
    assert hit.sum() > 150 and (~hit).sum() > 300
    np.testing.assert_array_equal(np.isinf(depth), ~hit)
    with np.errstate(invalid="ignore"):  # inf - inf where the ray misses both
        apart = np.abs(t_box - t_sphere) > 1e-3 * t
    steady = hit & apart & (np.abs(disc) > 1e-3) & (
        np.isinf(t_box) | (np.sort(np.abs(np.minimum(ta, tb) - t_near[:, None]), axis=1)[:, 1] > 1e-3))
    np.testing.assert_allclose(depth[steady], t[steady], rtol=1e-5)
    np.testing.assert_allclose(out["normal"].reshape(-1, 3)[steady], normal[steady], atol=2e-4)
    np.testing.assert_allclose(out["distance_z"].reshape(-1)[steady], (t * (d @ forward(scene)))[steady],
                               rtol=1e-5)
    assert np.isinf(out["distance_z"].reshape(-1)[~hit]).all()
    np.testing.assert_array_equal(out["normal"].reshape(-1, 3)[~hit], 0.0)


def test_a_lamp_sphere_has_its_depth_and_no_normal(renderer) -> None:
    scene = {"film": SMALL, "camera": camera((0, 0, 0), (0, 0, -1), fov_y=20.0),
             "lights": [{"type": "point", "position": [0, 0, -5], "intensity": 10.0, "radius": 0.5}]}
    out = renderer.render(scene, outputs=["depth", "normal", "surfaces", "radiance"])
    centre = out["depth"][15, 20]
    _, dirs = rays(scene)
    d = dirs[15, 20]
    b = d @ np.array([0, 0, -5.0])
    assert centre == pytest.approx(b - math.sqrt(0.25 - (25.0 - b * b)), rel=1e-5)
    np.testing.assert_array_equal(out["normal"][15, 20], 0.0)
    np.testing.assert_array_equal(out["surfaces"], out["radiance"])  # no medium: nothing else


# ---- transmittance against closed forms --------------------------------------------------

def test_transmittance_of_a_homogeneous_medium_is_exp_minus_sigma_t_depth(renderer) -> None:
    sigma = np.array([0.02, 0.05, 0.11])
    scene = {"film": SMALL, "camera": camera((0, 1.5, 0), (0, 0.8, -10)),
             "medium": {"sigma_t": sigma.tolist(), "albedo": 0.8},
             "lights": [{"type": "point", "position": [2, 4, -8], "intensity": 50.0}],
             "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3}]}
    out = renderer.render(scene, outputs=["depth", "transmittance"])
    depth = out["depth"].astype(np.float64)
    hit = np.isfinite(depth)
    assert hit.sum() > 100 and (~hit).sum() > 100
    np.testing.assert_allclose(out["transmittance"][hit], np.exp(-depth[hit][:, None] * sigma), rtol=2e-5)
    np.testing.assert_array_equal(out["transmittance"][~hit], 0.0)  # an endless ray through fog


def test_transmittance_without_any_medium_is_one(renderer, scene_factory) -> None:
    out = renderer.render(scene_factory(film=SMALL, drop=["medium"]), outputs=["transmittance", "depth"])
    np.testing.assert_array_equal(out["transmittance"], 1.0)


@pytest.mark.parametrize("pitch", [-20.0, -3.0, 0.0, 4.0, 30.0])
def test_atmosphere_slant_transmittance_against_the_float64_reference(renderer, pitch) -> None:
    import daytime_reference as ref
    import daytime_scenes as day

    scene = day.day_scene(sun=day.SUN30, atmosphere=day.atmosphere(visibility=3000.0, rain=20.0), pitch=pitch,
                          fov=40.0, width=3, height=9, ground=0.2, camera_y=30.0)
    out = renderer.render(scene, outputs=["transmittance", "depth"])
    atm = day.reference_atmosphere(scene)
    _, dirs = rays(scene)
    for row in range(dirs.shape[0]):
        for col in range(dirs.shape[1]):
            mu = float(dirs[row, col][1])
            s_end = ref.Ray(30.0, dirs[row, col]).end()
            depth = float(out["depth"][row, col])
            # The float32 ray direction carries an absolute error of about 1e-6 in mu, which
            # grazing rays feel as 1e-6 / |mu| relative in their length and optical depth.
            direction_rel = 2e-6 / max(abs(mu), 1e-12)
            if math.isfinite(s_end):
                assert depth == pytest.approx(s_end, rel=direction_rel)
                mu = -30.0 / depth  # the renderer's own ray, which ends on the ground there
            else:
                assert math.isinf(depth)
            # Compared as optical depth: float32 carries tau, not e^-tau, to its relative precision.
            tau = atm.optical_depth(30.0, mu, 0.0, s_end if math.isinf(s_end) else depth)
            got = out["transmittance"][row, col].astype(np.float64)
            assert (got > 0).all() == (tau < 80).all(), (row, col, tau, got)
            if (tau < 80).all():
                tolerance = 1e-5 + (direction_rel if math.isinf(s_end) else 0.0)
                assert -np.log(got) == pytest.approx(tau, rel=tolerance, abs=1e-6), (row, col, mu)


# ---- layers ------------------------------------------------------------------------------

@pytest.mark.parametrize("name", airlight.preset_names())
def test_layers_sum_to_the_radiance_on_every_preset(renderer, name) -> None:
    out = renderer.render(airlight.preset(name), width=48, outputs=["radiance", "layers"])
    assert_layers_sum_to_radiance(out, f"{name} ({renderer.backend})")
    plain = renderer.render(airlight.preset(name), width=48)
    # Asking for the outputs changes the radiance by float rounding at most (the rainbow's
    # part is summed apart).
    np.testing.assert_allclose(out["radiance"], plain, rtol=2e-6, atol=1e-30)


def test_each_effect_fills_its_own_layer() -> None:
    def layers(name: str) -> dict[str, float]:
        out = airlight.render(airlight.preset(name), "cpu", width=48, outputs=["layers"])
        return {k: float(v.mean()) for k, v in out.items()}

    night = layers("foggy_street")
    assert night["lamps"] > 0.1 * night["surfaces"]
    assert night["sky"] == night["spots"] == night["rainbow"] == 0
    spots = layers("spotlights_crossing_002")
    assert spots["spots"] > 0 and spots["lamps"] == spots["sky"] == 0
    bow = layers("rainbow_after_heavy_rain")
    assert bow["rainbow"] > 0 and bow["sky"] > 0 and bow["lamps"] == 0


def test_rainbow_layer_is_the_rain_once_scattered_sunlight() -> None:
    # The rainbow layer is exactly what the rain's Mie-phase sunlight adds: the same scene
    # without the rain's single-scattered sun (its phase "hg" routes it into the sky layer)
    # has no rainbow layer, and the bow's angle (about 42 degrees from the antisolar point)
    # is where the layer peaks.
    scene = airlight.preset("rainbow_after_heavy_rain")
    out = airlight.render(scene, "cpu", width=96, outputs=["rainbow", "sky", "radiance"])
    scene["atmosphere"]["rain"]["phase"] = "hg"
    hg = airlight.render(scene, "cpu", width=96, outputs=["rainbow", "sky", "radiance"])
    np.testing.assert_array_equal(hg["rainbow"], 0.0)
    assert float(out["rainbow"].max()) > 0.0
    # Where the layer peaks in the air (not on surfaces): the primary bow, 40-42.5 degrees
    # from the antisolar point in red.
    loaded = airlight.load_scene(airlight.preset("rainbow_after_heavy_rain"))
    antisolar = -np.asarray(loaded["sun"]["direction"], float)
    _, dirs = rays({**loaded, "film": {"width": 96, "height": out["rainbow"].shape[0]}})
    angle = np.degrees(np.arccos(np.clip(dirs @ antisolar, -1, 1)))
    depth = airlight.render(scene, "cpu", width=96, outputs=["depth"])["depth"]
    red = np.where(np.isinf(depth), out["rainbow"][..., 0], 0.0)
    assert red.max() > 0
    assert 39.0 < angle.reshape(-1)[int(np.argmax(red))] < 43.5


@st.composite
def night_scenes(draw) -> dict:
    n_lamps = draw(st.integers(0, 3))
    n_spots = draw(st.integers(0, 2))
    sigma = draw(st.floats(1e-4, 0.5))
    scene: dict[str, Any] = {
        "film": {"width": 12, "height": 9},
        "camera": camera((0, draw(st.floats(0.5, 20.0)), 0), (draw(st.floats(-5, 5)), 1.0, -10.0),
                         fov_y=draw(st.floats(10.0, 120.0))),
        "medium": {"sigma_t": sigma, "albedo": draw(st.floats(0.0, 1.0)),
                   "phase": {"type": "hg", "g": draw(st.floats(-0.9, 0.95))}},
        "lights": [{"type": "point", "position": [draw(st.floats(-20, 20)), draw(st.floats(0.2, 15)),
                                                   draw(st.floats(-60, 5))],
                    "intensity": draw(st.floats(1e-3, 1e5)), "radius": draw(st.floats(0.01, 1.0))}
                   for _ in range(n_lamps)]
        + [{"type": "spot", "position": [draw(st.floats(-10, 10)), 5.0, draw(st.floats(-40, 0))],
            "direction": [draw(st.floats(-1, 1)), -1.0, draw(st.floats(-1, 1))],
            "cone_angle": draw(st.floats(5.0, 80.0)), "intensity": draw(st.floats(1.0, 1e4))}
           for _ in range(n_spots)],
        "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0],
                      "albedo": draw(st.floats(0.0, 1.0))}],
        "quality": {"multiple_scattering": draw(st.booleans())},
    }
    if draw(st.booleans()):
        scene["surfaces"].append({"type": "sphere", "center": [0.0, 1.0, -draw(st.floats(3, 30))],
                                  "radius": draw(st.floats(0.1, 3.0)), "albedo": 0.5})
    return scene


# Random scenes are random shader variants on GL, each compiled for seconds on a cold cache.
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scene=night_scenes())
def test_layers_sum_to_the_radiance_on_random_night_scenes(renderer, scene) -> None:
    out = renderer.render(scene, outputs=["radiance", "layers", "transmittance", "depth"])
    assert_layers_sum_to_radiance(out, str(scene))
    t = out["transmittance"]
    assert np.isfinite(t).all() and (t >= 0).all() and (t <= 1).all()
    assert not np.isnan(out["depth"]).any() and (out["depth"] > 0).all()


@st.composite
def day_scenes(draw) -> dict:
    import daytime_scenes as day

    rain = draw(st.sampled_from([0.0, 0.5, 5.0, 60.0]))
    atm = day.atmosphere(visibility=draw(st.sampled_from([None, 300.0, 5000.0, 50000.0])), rain=rain)
    if rain > 0.0 and draw(st.booleans()):
        atm["rain"]["phase"] = "mie"
    # (a CIE sky needs a sun's position: an irradiance of 0 is a sky without a sun disc)
    sun = day.sun(draw(st.floats(-5.0, 85.0)), draw(st.floats(0.0, 360.0)), draw(st.sampled_from([0.0, 5.0])))
    return day.day_scene(sky=draw(st.sampled_from([day.OVERCAST, day.CLEAR])), sun=sun, atmosphere=atm,
                         pitch=draw(st.floats(-30.0, 60.0)), width=5, height=7,
                         camera_y=draw(st.floats(0.5, 2000.0)), ground=draw(st.sampled_from([None, 0.3])),
                         multiple_scattering=draw(st.booleans()))


@pytest.mark.slow
@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scene=day_scenes())
def test_layers_sum_to_the_radiance_on_random_days(renderer, scene) -> None:
    out = renderer.render(scene, outputs=["radiance", "layers", "transmittance"])
    assert_layers_sum_to_radiance(out, str(scene))


def test_outputs_agree_between_the_backends(renderer_cache, scene_factory) -> None:
    cpu = renderer_cache("cpu").render(scene_factory(film=SMALL), outputs=list(airlight.OUTPUTS))
    gl = renderer_cache("gl").render(scene_factory(film=SMALL), outputs=list(airlight.OUTPUTS))
    for name in airlight.OUTPUTS:
        np.testing.assert_allclose(gl[name], cpu[name], rtol=2e-4, atol=1e-6, err_msg=name)


@pytest.mark.slow
def test_gl_pixels_recomputed_on_the_cpu_keep_their_outputs(renderer_cache) -> None:
    # A thousand spots over lit surfaces run past llvmpipe's loop limit (test_gl_loop_limit.py):
    # the renderer recomputes those pixels on the CPU, outputs included.
    from test_gl_loop_limit import many_lights

    scene = many_lights(1000, "spot")
    gl = renderer_cache("gl")
    out = gl.render(scene, outputs=["radiance", "layers", "depth"])
    if gl.cpu_fallback_pixels == 0:
        pytest.skip("this GL driver finished every pixel (no loop limit to exercise)")
    cpu = renderer_cache("cpu").render(scene, outputs=["radiance", "layers", "depth"])
    assert_layers_sum_to_radiance(out, "GL with CPU fallback")
    np.testing.assert_allclose(out["depth"], cpu["depth"], rtol=1e-5)
    np.testing.assert_allclose(out["spots"], cpu["spots"], rtol=2e-3, atol=1e-6 * float(cpu["spots"].max()))


# ---- the outputs argument --------------------------------------------------------------

def test_outputs_lists_and_describes_every_output() -> None:
    assert list(airlight.OUTPUTS)[:5] == ["radiance", "depth", "distance_z", "normal", "transmittance"]
    assert set(airlight.LAYERS) == {
        "surfaces", "lamps", "spots", "rainbow", "atmospheric_light", "sky", "medium_sun", "clouds",
        "particle_clouds", "falling_rain"}
    assert all(len(text) > 20 for text in airlight.OUTPUTS.values())


def test_outputs_returns_exactly_what_was_asked_in_order(scene_factory) -> None:
    out = airlight.render(scene_factory(film=SMALL), "cpu", outputs=["depth", "layers", "radiance", "lamps"])
    assert list(out) == ["depth", *airlight.LAYERS, "radiance"]
    assert all(v.dtype == np.float32 for v in out.values())
    assert out["radiance"].shape == (30, 40, 3) and out["depth"].shape == (30, 40)


@pytest.mark.parametrize("outputs, error, message", [
    ("depth", TypeError, "outputs: expected a list of output names, got str"),
    ([], ValueError, "outputs: asks for no output"),
    (["depth", 3], TypeError, "outputs[1]: expected an output name (str), got int"),
    (["radiance", "albedo"], ValueError, "outputs[1]: unknown output 'albedo'"),
    (7, TypeError, "outputs: expected a list of output names, got int"),
])
def test_bad_outputs_argument_names_the_entry(scene_factory, outputs, error, message) -> None:
    with pytest.raises(error) as e:
        airlight.render(scene_factory(film=SMALL), "cpu", outputs=outputs)
    assert str(e.value).startswith(message)


# ---- the demo's --outputs ----------------------------------------------------------------

def test_demo_writes_the_outputs_asked_for_into_its_exr(tmp_path, scene_factory) -> None:
    scene = scene_factory(film=SMALL, quality={"multiple_scattering": False})
    (tmp_path / "s.json").write_text(json.dumps(scene))
    out = tmp_path / "x.exr"
    proc = run_demo("--scene", str(tmp_path / "s.json"), "--out", str(out), "--backend", "cpu",
                 "--outputs", "depth,layers,transmittance")
    assert proc.returncode == 0, proc.stderr
    from_demo = airlight.load_exr(out)
    assert set(from_demo) == {"radiance", "depth", "transmittance", *airlight.LAYERS}
    from_api = airlight.render(scene, "cpu", outputs=list(from_demo))
    for name, values in from_api.items():
        np.testing.assert_array_equal(from_demo[name], values, err_msg=name)
    assert np.isinf(from_demo["depth"]).any()


@pytest.mark.parametrize("args, message", [
    (["--outputs", "depth,albedo"], "--outputs: unknown output 'albedo'"),
    (["--outputs", "depth", "--out-png"], "--outputs needs --out F.exr"),
])
def test_demo_bad_outputs_exit_with_one_line(tmp_path, scene_factory, args, message) -> None:
    (tmp_path / "s.json").write_text(json.dumps(scene_factory(film=SMALL)))
    out = tmp_path / ("x.png" if "--out-png" in args else "x.exr")
    proc = run_demo("--scene", str(tmp_path / "s.json"), "--out", str(out),
                 *[a for a in args if a != "--out-png"])
    assert proc.returncode != 0 and not out.exists()
    assert len(proc.stderr.splitlines()) == 1 and message in proc.stderr, proc.stderr


def test_readme_documents_every_output() -> None:
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    section = readme.split("### Render outputs", 1)[1].split("\n## ", 1)[0]
    rows = {line.split("`")[1] for line in section.splitlines() if line.startswith("| `")}
    assert rows == set(airlight.OUTPUTS), rows ^ set(airlight.OUTPUTS)
