"""The renderer's daytime multiple scattering (issue 18; effects/multiple_scattering/physics.md
section 9; effects/multiple_scattering/docs/renderer.md): the views of the stored Mitsuba
reference (24 weathers and suns, 14 views, 3 channels) within max(3 %, 3 path-tracer standard
errors) on 99 % of the values through the aerial table (the default for street cameras on films of
320 x 180 and more; the issue asks 99 %) and on 97 % through the scattering volumes (renderer.md
says where the rest are);
``quality.multiple_scattering`` false is single scattering exactly; an atmosphere that does not
scatter builds no solve; the ground's reflection reaches walls continuously as the air thins; no
NaN or Inf over a wide sweep; GL equals the CPU."""

from __future__ import annotations

import copy
import functools
import json
import subprocess
import sys
import textwrap

import ms_cases
import numpy as np
import plane_parallel_mc
import pytest
from daytime_reference import rain_extinction
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shared_results import computed_once

import airlight

DAY = ms_cases.load_cases("day")["cases"]
# Share of the reference's values within the allowed deviation (the issue asks 0.99): through the
# aerial table at 16 nodes measured 0.998, through the volumes at 16 levels 0.977 (their misses: rain
# of 40 and 100 mm/h near the horizon, 2-5 % below; effects/multiple_scattering/docs/renderer.md
# section 2).
ACCEPT_FRACTION_TABLE = 0.99
ACCEPT_FRACTION_VOLUMES = 0.97


def render_views(case: dict, quality: dict | None = None) -> np.ndarray:
    """airlight's radiance (CPU) of every view of a case, with ``quality`` keys added:
    [view, channel]."""
    renderer = airlight.Renderer("cpu")
    out = []
    for i in range(len(case["views"])):
        scene = ms_cases.view_scene(case, i)
        if quality:
            scene["quality"] = {**scene.get("quality", {}), **quality}
        out.append(renderer.render(scene)[0, 0, :3])
    renderer.close()
    return np.array(out)


@functools.cache
def rendered_views(name: str, quality: tuple = ()) -> np.ndarray:
    """The render of every view of a stored case (render_views) with ``quality`` items, computed once."""
    return render_views(DAY[name], dict(quality))


def views_through_volumes_and_table(name: str) -> tuple[np.ndarray, np.ndarray]:
    """A case's views by default (the volumes, for one pixel) and through the aerial table at 16
    nodes, one after the other so that the second re-uses the first's solve; once per test run."""
    return computed_once(f"daytime_views_{name}",
                         lambda: (rendered_views(name), rendered_views(name, (("aerial_table", 16),))))


def reference_views(name: str, key: str = "radiance") -> np.ndarray:
    return np.array([v[key] for v in DAY[name]["views"]])


def test_daytime_radiance_matches_the_path_tracer_on_97_percent_of_values_through_the_volumes() -> None:
    """The issue's acceptance measure: sky and ground radiance within 3 % (or the path tracer's
    noise) over clear, hazy, rain 3/40/100 mm/h and fog of 50-200 m under a high, a low and no
    sun. Through the scattering volumes at 16 levels (what these one-pixel views get by default):
    on 97 % of the values, and none beyond 2 allowed deviations (measured 1.76)."""
    got = np.concatenate([views_through_volumes_and_table(n)[0] for n in sorted(DAY)])
    want = np.concatenate([reference_views(n) for n in sorted(DAY)])
    err = np.concatenate([reference_views(n, "stderr") for n in sorted(DAY)])
    assert ms_cases.fraction_within(got, want, err) >= ACCEPT_FRACTION_VOLUMES
    assert np.max(np.abs(got - want) / ms_cases.allowed_deviation(want, err)) < 2.0


@pytest.mark.slow
def test_daytime_radiance_matches_the_path_tracer_on_99_percent_of_values_through_the_aerial_table() -> None:
    """The same measure through the aerial table at 16 nodes (effects/daytime/docs/aerial_table.md;
    what a street camera's film of 320 x 180 or more gets by default): the issue's 99 % of the
    values (measured 99.8 %: two of 1008 miss, by 1.3 and 1.03 allowed deviations)."""
    got = np.concatenate([views_through_volumes_and_table(n)[1] for n in sorted(DAY)])
    want = np.concatenate([reference_views(n) for n in sorted(DAY)])
    err = np.concatenate([reference_views(n, "stderr") for n in sorted(DAY)])
    assert ms_cases.fraction_within(got, want, err) >= ACCEPT_FRACTION_TABLE
    assert np.max(np.abs(got - want) / ms_cases.allowed_deviation(want, err)) < 1.5


@pytest.mark.parametrize("name", ["day_rain40_overcast", "day_fog50_sun60", "day_clear_sun10"])
def test_multiple_scattering_is_most_of_the_light_in_rain_and_fog(name: str) -> None:
    """Single scattering alone is far too dark in rain and fog (the issue's 200,000 times) and
    visibly too dark on a clear day; the renderer's multiple scattering closes the gap."""
    single = reference_views(name, "airlight_single")
    want = reference_views(name)
    got = rendered_views(name)
    allowed = ms_cases.allowed_deviation(want, reference_views(name, "stderr"))
    assert np.median(np.abs(got - want) / allowed) < 0.5
    assert np.median(want / single) > (1.2 if "clear" in name else 20.0)


@pytest.mark.parametrize("name", ["day_rain40_overcast", "day_rain100_sun10"])
def test_aerial_table_agrees_with_the_march_in_rain(name: str) -> None:
    """In rain the volumes at 16 levels are up to 2.7 % below the brute-force march of the same
    multiple-scattering field (the misses above). Through the aerial table
    (effects/daytime/docs/aerial_table.md section 3) every view agrees with the march of 4000 steps
    within 0.5 % (measured 0.21 %): the table, not the field, is what the volumes miss."""
    march = render_views(DAY[name], {"airlight": "march", "march_steps": 4000})
    table = render_views(DAY[name], {"aerial_table": 16})
    assert np.max(np.abs(table / march - 1)) <= 5e-3


@pytest.mark.slow
def test_table_and_path_tracer_agree_with_an_analog_monte_carlo_in_rain() -> None:
    """A third reference that shares neither the solver nor Mitsuba's scene and estimators
    (plane_parallel_mc.py, an analog walk in altitude and direction cosine) on six views of
    day_rain40_overcast (green): airlight through the aerial table within 4 of its standard
    errors + 0.5 % on every view (measured 0.2 %), and the stored path tracer's values within 1 %
    of it on average (they were 2 % dark before the reference's layering was fixed:
    effects/multiple_scattering/docs/reference.md section 3)."""
    case = DAY["day_rain40_overcast"]
    views = [0, 1, 4, 6, 11, 12]
    table = render_views(case, {"aerial_table": 16})[:, 1]
    ratios = []
    for i in views:
        view = case["views"][i]
        walk = plane_parallel_mc.overcast_view_radiance(case["scene"], 1, view["direction"][1], 100_000,
                                                        seed=i)
        assert abs(table[i] - walk.mean) <= 4.0 * walk.stderr + 5e-3 * walk.mean, (i, table[i], walk)
        ratios.append(view["radiance"][1] / walk.mean)
    assert abs(np.mean(ratios) - 1.0) <= 0.01, ratios


@pytest.mark.parametrize("name", ["day_clear_sun60", "day_rain100_sun10", "day_fog100_overcast"])
def test_quality_false_gives_single_scattering_exactly(name: str) -> None:
    """``quality.multiple_scattering: false`` renders today's single scattering: the values
    stored when the reference was made (before multiple scattering existed)."""
    renderer = airlight.Renderer("cpu")
    case = DAY[name]
    for i, view in enumerate(case["views"]):
        scene = ms_cases.view_scene(case, i)
        scene["quality"] = {"multiple_scattering": False}
        np.testing.assert_allclose(renderer.render(scene)[0, 0, :3], view["airlight_single"], rtol=1e-5)
    renderer.close()


SCRIPT = textwrap.dedent("""
    import json, sys, airlight
    out = []
    for scene in json.loads(sys.argv[1]):
        image = airlight.render(scene, backend="cpu")
        stats = airlight.table_stats()
        out.append({"tables": sorted(stats), "builds": {k: v["builds"] for k, v in stats.items()},
                    "mean": float(image[..., :3].mean())})
    print(json.dumps(out))
""")


def fresh_process_renders(scenes: list[dict]) -> list[dict]:
    """Renders in a fresh interpreter (tables live for the process): each scene's table names so
    far and its mean radiance."""
    out = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(scenes)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout)


def street(atmosphere: dict | None, surfaces: list[dict], **extra) -> dict:
    scene = {"film": {"width": 12, "height": 8},
             "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 100},
             "sky": copy.deepcopy(ms_cases.CLEAR_SKY),
             "sun": {"elevation": 30, "azimuth": 0, "irradiance": list(ms_cases.SUN_IRRADIANCE)},
             "surfaces": surfaces}
    if atmosphere is not None:
        scene["atmosphere"] = atmosphere
    scene.update(extra)
    return scene


GROUND = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.3}]
WALL = [{"type": "box", "min": [-3, 0, -12], "max": [-1, 4, -9], "albedo": 0.5}]
BLACK_GROUND = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.0}]


def test_an_atmosphere_that_scatters_nothing_is_not_solved() -> None:
    """Scattering optical depth below 1e-3 (molecules at 0.3 % of sea level, an absorbing
    haze), or quality off: no solve; without an atmosphere a wall beside the ground gets the
    ground's reflection only (no solve); the clear air of a real day (0.27 in blue) is solved."""
    scenes = [
        street({"molecules": {"density_scale": 0.003}}, GROUND),
        street({"aerosol": {"visibility": 5000, "albedo": 0.0}}, GROUND),
        street({"molecules": {"density_scale": 1}}, GROUND, quality={"multiple_scattering": False}),
        street(None, GROUND + WALL),
        street({"molecules": {"density_scale": 1}}, GROUND),
    ]
    seen = fresh_process_renders(scenes)  # table names are those built so far in the process
    assert not {"ms_field", "ms_ground_bounce"} & set(seen[2]["tables"]), seen[2]
    assert "ms_field" not in seen[3]["tables"] and "ms_ground_bounce" in seen[3]["tables"]
    assert "ms_field" in seen[4]["tables"]


def test_skipping_a_thin_atmosphere_changes_the_image_by_under_one_percent() -> None:
    """Just above the threshold (scattering depth 1.1e-3 in blue) the solved image differs from
    single scattering by < 1 % in every pixel: what the skip below it leaves out."""
    renderer = airlight.Renderer("cpu")
    for surfaces in (GROUND, BLACK_GROUND, []):
        scene = street({"molecules": {"density_scale": 0.0042}}, surfaces, film={"width": 24, "height": 16})
        with_ms = renderer.render(scene)[..., :3]
        scene["quality"] = {"multiple_scattering": False}
        without = renderer.render(scene)[..., :3]
        gain = with_ms / np.maximum(without, 1e-12) - 1.0
        assert np.all(gain >= -1e-6) and gain.max() < 0.01, (surfaces, gain.max())
    renderer.close()


def test_the_grounds_reflection_lights_walls_continuously_as_the_air_thins() -> None:
    """A wall beside a bright ground receives the ground's reflection: with no atmosphere, a
    skipped thin one and a solved one the wall's light agrees within 1 %, and it is there (the
    wall is brighter than with multiple scattering off)."""
    renderer = airlight.Renderer("cpu")
    means = []
    thin, solved = {"molecules": {"density_scale": 0.003}}, {"molecules": {"density_scale": 0.0042}}
    for atmosphere in (None, thin, solved):
        camera = {"position": [2, 1.7, -7], "look_at": [-1, 1.7, -10.5], "up": [0, 1, 0], "fov_y": 30}
        scene = street(atmosphere, GROUND + WALL, film={"width": 24, "height": 16}, camera=camera)
        means.append(float(renderer.render(scene)[..., :3].mean()))
        if atmosphere is None:
            scene["quality"] = {"multiple_scattering": False}
            off = float(renderer.render(scene)[..., :3].mean())
    renderer.close()
    assert max(means) / min(means) - 1.0 < 0.01, means
    assert means[0] > 1.05 * off


# ---- A fading rain (physics.md eq. 9.3): the field blended between solves on a ladder of extinctions

def faded(case: dict, view: int, density_scale: float, steps: int) -> dict:
    scene = ms_cases.view_scene(case, view)
    scene["atmosphere"]["rain"]["density_scale"] = density_scale
    scene["quality"] = {"fading_rain_steps": steps}
    return scene


def test_fading_rain_through_the_ladder_stays_near_the_exact_solve() -> None:
    """Rain 40 mm/h under a sun 10 degrees high, fading over half an octave (the scene's rain at
    several places between two rungs of 4 per octave): all 14 views of sky and ground within 0.25 %
    of the field solved for each rain (measured at most 0.17 % over 16 scales, 0.29 % over all 9 rain cases:
    effects/multiple_scattering/docs/bench_fading_rain.txt)."""
    renderer = airlight.Renderer("cpu")
    case = DAY["day_rain40_sun10"]
    for density_scale in (1.0, 0.9, 0.8, 0.7):
        for i in range(len(case["views"])):
            exact = renderer.render(faded(case, i, density_scale, 0))[0, 0, :3]
            ladder = renderer.render(faded(case, i, density_scale, 4))[0, 0, :3]
            np.testing.assert_allclose(ladder, exact, rtol=2.5e-3, err_msg=f"scale {density_scale} view {i}")
    renderer.close()


def test_fading_rain_is_continuous_across_a_rung() -> None:
    """The two sides of a rung of the ladder (the rain's extinction a factor 1 -+ 1e-6 from it)
    differ by what the rain itself changes, about 1e-6: each rung is the same function of altitude
    in both of the pairs it belongs to (the blend is taken on the union of their levels)."""
    renderer = airlight.Renderer("cpu")
    case = DAY["day_rain40_sun10"]
    extinction = rain_extinction(case["scene"]["atmosphere"]["rain"]["rate"])
    steps = 4
    floor = airlight._core.MS_RAIN_LADDER_FLOOR
    rung = floor * 2.0 ** (np.ceil(steps * np.log2(extinction / floor)) / steps)  # eq. 9.3: floor 2^(k/N)
    for i in range(len(case["views"])):
        below = renderer.render(faded(case, i, rung / extinction * (1 - 1e-6), steps))[0, 0, :3]
        above = renderer.render(faded(case, i, rung / extinction * (1 + 1e-6), steps))[0, 0, :3]
        np.testing.assert_allclose(above, below, rtol=2e-5, err_msg=f"view {i}")
    renderer.close()


def test_a_fading_rain_shares_its_solves() -> None:
    """Eight frames of a rain fading within one rung pair solve the field twice (the two rungs)
    with fading_rain_steps 4, eight times without; a rain thinner than the ladder's floor is
    solved exactly."""
    case = DAY["day_rain40_overcast"]
    extinction = rain_extinction(case["scene"]["atmosphere"]["rain"]["rate"])
    floor = airlight._core.MS_RAIN_LADDER_FLOOR
    lower = floor * 2.0 ** (np.floor(4 * np.log2(extinction / floor)) / 4)  # the rung below, of 4 per octave
    scales = [lower * 2.0 ** ((k + 0.5) / 32) / extinction for k in range(8)]  # between it and the next
    ladder = fresh_process_renders([faded(case, 0, s, 4) for s in scales])
    exact = fresh_process_renders([faded(case, 0, s, 0) for s in scales])
    assert ladder[-1]["builds"]["ms_field"] == 2 and ladder[-1]["builds"]["ms_field_rain_blend"] == 8
    assert exact[-1]["builds"]["ms_field"] == 8 and "ms_field_rain_blend" not in exact[-1]["builds"]
    thin = fresh_process_renders([faded(case, 0, 1e-5, 4)])  # extinction 4e-8 /m, below the floor
    assert thin[0]["builds"]["ms_field"] == 1 and "ms_field_rain_blend" not in thin[0]["builds"]


def sunlit_street(scale: float) -> dict:
    """A rainy street whose sun shines at ``scale`` times its irradiance (0: behind the clouds)."""
    scene = street({"molecules": {"density_scale": 1}, "rain": {"rate": 20}}, GROUND + WALL)
    scene["sun"]["irradiance"] = [scale * e for e in ms_cases.SUN_IRRADIANCE]
    return scene


def test_a_brightening_sun_shares_its_solve() -> None:
    """The sun coming out (its irradiance 0 to 1 of the scene's, all else fixed) solves the field
    twice: the sky alone while the sun is out of the scene, then once by source (eq. 9.4), each
    frame adding the sun's part at its own irradiance."""
    frames = fresh_process_renders([sunlit_street(s) for s in (0.0, 0.1, 0.4, 0.7, 1.0)])
    assert frames[-1]["builds"]["ms_field"] == 2 and frames[-1]["builds"]["ms_field_sunlit"] == 4, frames[-1]
    assert frames[0]["builds"]["ms_field"] == 1 and "ms_field_sunlit" not in frames[0]["builds"]


@pytest.mark.parametrize("backend", airlight.available_backends())
def test_the_image_is_linear_in_the_suns_irradiance(backend: str) -> None:
    """Everything the sun lights is linear in its irradiance, so a frame at a share s of it is the
    sunless frame plus s times the sun's light: the sky's part of the by-source solve agrees with the
    sky solved alone, and the sun's part is scaled per channel (a reddened sun included)."""
    renderer = airlight.Renderer(backend)
    dark, full = renderer.render(sunlit_street(0.0))[..., :3], renderer.render(sunlit_street(1.0))[..., :3]
    for s in (0.05, 0.3, 0.8):
        np.testing.assert_allclose(renderer.render(sunlit_street(s))[..., :3], dark + s * (full - dark),
                                   rtol=2e-4, atol=1e-6 * float(full.max()), err_msg=f"share {s}")
    red = sunlit_street(1.0)
    tint = np.array([1.0, 0.5, 0.2], np.float32)
    red["sun"]["irradiance"] = [float(e * w) for e, w in zip(ms_cases.SUN_IRRADIANCE, tint)]
    np.testing.assert_allclose(renderer.render(red)[..., :3], dark + (full - dark) * tint, rtol=2e-4,
                               atol=1e-6 * float(full.max()))
    renderer.close()


@pytest.mark.parametrize("steps", [-1, 17, 2.5, "4"])
def test_fading_rain_steps_out_of_range_is_a_clear_error(steps) -> None:
    scene = faded(DAY["day_rain40_overcast"], 0, 1.0, 0)
    scene["quality"]["fading_rain_steps"] = steps
    with pytest.raises((ValueError, TypeError), match="quality.fading_rain_steps"):
        airlight.load_scene(scene)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rain=st.sampled_from([0.0, 0.2, 10.0, 150.0]),
       visibility=st.sampled_from([None, 20.0, 300.0, 5000.0, 100000.0]),
       aerosol_albedo=st.floats(0.0, 1.0), g=st.floats(-0.5, 0.95),
       sun_elevation=st.floats(-10.0, 90.0), camera_y=st.sampled_from([0.05, 1.7, 300.0, 5000.0]),
       pitch=st.floats(-89.0, 89.0), overcast=st.booleans(),
       rain_scale=st.sampled_from([0.0, 0.01, 1.0, 30.0]),
       fading_rain_steps=st.sampled_from([0, 1, 4, 16]))
def test_no_nan_or_inf_over_weathers_suns_and_cameras(rain, visibility, aerosol_albedo, g, sun_elevation,
                                                      camera_y, pitch, overcast, rain_scale,
                                                      fading_rain_steps) -> None:
    atmosphere: dict = {"molecules": {"density_scale": 1}}
    if visibility is not None:
        atmosphere["aerosol"] = {"visibility": visibility, "scale_height": 300, "g": g,
                                 "albedo": aerosol_albedo}
    if rain > 0.0:
        atmosphere["rain"] = {"rate": rain, "density_scale": rain_scale}
    p = np.radians(pitch)
    scene = street(atmosphere, GROUND + WALL, film={"width": 6, "height": 4},
                   camera={"position": [0, camera_y, 0], "look_at": [0, camera_y + np.sin(p), -np.cos(p)],
                           "up": [0, 1, 0], "fov_y": 60})
    scene["sun"]["elevation"] = sun_elevation
    if overcast:
        scene["sky"] = copy.deepcopy(ms_cases.OVERCAST_SKY)
    scene["quality"] = {"fading_rain_steps": fading_rain_steps}
    image = airlight.render(scene, backend="cpu")
    assert np.all(np.isfinite(image)) and np.all(image[..., :3] >= 0.0)


@pytest.mark.parametrize("name, fading_rain_steps", [("day_rain40_sun10", 0), ("day_fog100_overcast", 0),
                                                     ("day_rain40_sun10", 4)])
def test_gl_renders_multiple_scattering_as_the_cpu_does(renderer_cache, name: str,
                                                        fading_rain_steps: int) -> None:
    gl = renderer_cache("gl")
    cpu = renderer_cache("cpu")
    scene = ms_cases.view_scene(DAY[name], 1)
    scene["quality"] = {"fading_rain_steps": fading_rain_steps}
    scene["film"] = {"width": 24, "height": 16}
    scene["camera"]["fov_y"] = 100.0
    scene["surfaces"] += WALL
    a, b = cpu.render(scene)[..., :3], gl.render(scene)[..., :3]
    np.testing.assert_allclose(b, a, rtol=2e-3, atol=1e-6 * float(a.max()))
