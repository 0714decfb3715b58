"""Daytime rain and fog (issue 6; MODELS.md section 3; docs/daytime.md), rendered, against
closed forms and against the independent float64 reference of daytime_reference.py (the same
model: sky dome entering at the top of the atmosphere, single scattering, flat ground; the
reference integrates the exact sky-phase integral by a hemisphere rule at every point and the
view ray by Gauss-Legendre on graded panels, sharing none of the renderer's table, altitude
levels or source approximation)."""

from __future__ import annotations

import math

import daytime_reference as ref
import numpy as np
import pytest
import reference
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from image_checks import finite_non_negative

OVERCAST = {"model": "overcast", "zenith_radiance": [1.0, 1.0, 1.0]}
SUN30 = {"elevation": 30.0, "azimuth": 20.0, "irradiance": [3.0, 3.0, 3.0]}
CLEAR = {"model": "cie", "type": 12, "zenith_radiance": [0.5, 0.75, 1.2]}


def day_scene(*, sky: dict | None = OVERCAST, sun: dict | None = None, atmosphere: dict | None = None,
              camera_y: float = 1.7, pitch: float = 0.0, fov: float = 90.0, width: int = 1, height: int = 24,
              ground: float | None = None, **extra) -> dict:
    """A camera at altitude camera_y looking along -z tilted up by `pitch` degrees."""
    p = math.radians(pitch)
    up = [0.0, 0.0, -1.0] if abs(pitch) > 89.9 else [0.0, 1.0, 0.0]
    scene = {"film": {"width": width, "height": height},
             "camera": {"position": [0.0, camera_y, 0.0],
                        "look_at": [0.0, camera_y + math.sin(p), -math.cos(p)], "up": up, "fov_y": fov}}
    if sky is not None:
        scene["sky"] = sky
    if sun is not None:
        scene["sun"] = sun
    if atmosphere is not None:
        scene["atmosphere"] = atmosphere
    if ground is not None:
        scene["surfaces"] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": ground}]
    scene.update(extra)
    return scene


def atmosphere(molecules: bool = True, visibility: float | None = None, rain: float = 0.0,
               scale_height: float = 1000.0) -> dict:
    out: dict = {}
    if molecules:
        out["molecules"] = {"density_scale": 1}
    if visibility is not None:
        out["aerosol"] = {"visibility": visibility, "scale_height": scale_height, "g": 0.7, "albedo": 0.9}
    if rain > 0.0:
        out["rain"] = {"rate": rain}
    return out


def reference_sky(scene: dict) -> ref.Sky:
    sky, sun = scene.get("sky"), scene.get("sun") or {}
    cie = 0 if sky is None or sky["model"] == "overcast" else sky["type"]
    lz = tuple(sky["zenith_radiance"]) if sky is not None else (0.0, 0.0, 0.0)
    return ref.Sky(cie, lz, sun.get("azimuth", 0.0), sun.get("elevation", 30.0),
                   tuple(sun.get("irradiance", (0.0, 0.0, 0.0))))


def reference_atmosphere(scene: dict) -> ref.Atmosphere:
    a = scene.get("atmosphere") or {}
    aerosol = a.get("aerosol")
    return ref.make_atmosphere(
        rain_rate=a["rain"]["rate"] if "rain" in a else 0.0,
        visibility=aerosol["visibility"] if aerosol else None, molecules="molecules" in a,
        aerosol_g=aerosol["g"] if aerosol else ref.AEROSOL_G,
        aerosol_albedo=aerosol["albedo"] if aerosol else ref.AEROSOL_ALBEDO,
        aerosol_scale_height=aerosol["scale_height"] if aerosol else ref.AEROSOL_SCALE_HEIGHT)


def reference_column(scene: dict, column: int = 0) -> np.ndarray:
    """Reference radiance (H, 3) of one image column."""
    cam = scene["camera"]
    _o, dirs = reference.camera_rays(cam, scene["film"]["width"], scene["film"]["height"])
    sky, atm = reference_sky(scene), reference_atmosphere(scene)
    ground = scene["surfaces"][0]["albedo"] if "surfaces" in scene else 0.0
    return np.array([ref.view_ray_gauss(atm, sky, cam["position"][1], d, ground_albedo=ground)
                     for d in dirs[:, column]])


def relative_error(image: np.ndarray, expected: np.ndarray, floor_fraction: float = 1e-3) -> float:
    """Largest relative error over pixels above floor_fraction of the expected maximum."""
    floor = floor_fraction * float(expected.max())
    mask = expected > floor
    assert mask.any()
    return float((np.abs(image - expected)[mask] / expected[mask]).max())


# ---- Closed forms -------------------------------------------------------------------------------

@pytest.mark.parametrize("sky,sun", [
    (OVERCAST, None),
    ({"model": "cie", "type": 1, "zenith_radiance": [1, 2, 3]}, None),
    ({"model": "cie", "type": 5, "zenith_radiance": [1, 1, 1]}, None),
    ({"model": "cie", "type": 8, "zenith_radiance": [1, 1, 1]}, {"elevation": 10, "azimuth": 0}),
    ({"model": "cie", "type": 12, "zenith_radiance": [1, 1, 1]}, {"elevation": 30, "azimuth": 40}),
    ({"model": "cie", "type": 13, "zenith_radiance": [1, 1, 1]}, {"elevation": 60, "azimuth": -120}),
    ({"model": "cie", "type": 15, "zenith_radiance": [1, 1, 1]}, {"elevation": 5, "azimuth": 180}),
], ids=["overcast", "cie1", "cie5", "cie8", "cie12", "cie13", "cie15"])
def test_sky_without_particles_shows_the_cie_formulas(renderer, sky, sun):
    """No atmosphere: escaping rays see the CIE sky exactly (0.1 %)."""
    scene = day_scene(sky=sky, sun=sun, pitch=30.0, fov=100.0, width=16, height=12)
    image = renderer.render(scene)
    _o, dirs = reference.camera_rays(scene["camera"], 16, 12)
    expected = reference_sky(scene).radiance(dirs)
    up = dirs[..., 1] > 1e-3
    assert relative_error(image[up], expected[up], 0.0) < 1e-3


def test_overcast_ground_without_particles_receives_7_pi_lz_over_9(renderer):
    """A white Lambertian ground under the overcast sky: E = 7 pi Lz / 9, radiance 7 Lz / 9 (0.5 %)."""
    lz = np.array([1.0, 2.0, 0.5])
    scene = day_scene(sky={"model": "overcast", "zenith_radiance": lz.tolist()}, pitch=-45.0, fov=40.0,
                      width=8, height=8, ground=1.0)
    image = renderer.render(scene)
    assert np.abs(image / (7.0 * lz / 9.0) - 1.0).max() < 5e-3


@pytest.mark.parametrize("camera_y", [0.0, 1000.0, 10000.0])
def test_rayleigh_vertical_optical_depth_matches_its_closed_form(renderer, camera_y):
    """Molecules only, no sky or sun: the zenith pixel shows the background times
    exp(-sigma H exp(-y0 / H)) per channel (1e-4)."""
    scene = day_scene(sky=None, atmosphere=atmosphere(), camera_y=camera_y, pitch=90.0, fov=0.01,
                      width=1, height=1, background=[1.0, 1.0, 1.0])
    image = renderer.render(scene)[0, 0]
    expected = np.exp(-ref.RAYLEIGH_SIGMA_S0 * ref.RAYLEIGH_SCALE_HEIGHT * math.exp(-camera_y / 8000.0))
    assert np.abs(image / expected - 1.0).max() < 1e-4


def test_no_particles_give_no_airlight(renderer):
    """An atmosphere of molecules at density 0 is no atmosphere: the same image."""
    kw = {"sun": SUN30, "ground": 0.3, "width": 8, "height": 8, "sky": CLEAR, "pitch": 5.0}
    none = renderer.render(day_scene(**kw))
    empty = renderer.render(day_scene(atmosphere={"molecules": {"density_scale": 0}}, **kw))
    assert np.array_equal(none, empty)


# ---- Against the reference ----------------------------------------------------------------------

# (sky, sun, atmosphere, camera altitude, pitch, ground albedo): the sweeps of the issue (rain 0 to
# 100 mm/h, visibility 50 m to 50 km, altitude, view elevation) with their corners. A 90-degree
# column covers view elevations pitch +- 45 degrees, the horizon included where it is in view.
CASES = {
    "clear_air_overcast": (OVERCAST, None, atmosphere(), 1.7, 0.0, None),
    "haze_5km": (OVERCAST, None, atmosphere(visibility=5000.0), 1.7, 0.0, None),
    "haze_50km_clear_sun": (CLEAR, SUN30, atmosphere(visibility=50000.0), 1.7, 10.0, 0.3),
    "haze_500m": (OVERCAST, None, atmosphere(visibility=500.0), 1.7, 0.0, 0.2),
    "fog_50m_shallow": (OVERCAST, None, atmosphere(visibility=50.0, scale_height=100.0), 1.7, 0.0, 0.5),
    "rain_2": (OVERCAST, None, atmosphere(visibility=8000.0, rain=2.0), 1.7, 0.0, 0.2),
    "rain_10_haze_2km": (OVERCAST, None, atmosphere(visibility=2000.0, rain=10.0), 1.7, 0.0, None),
    "rain_50": (OVERCAST, None, atmosphere(visibility=3000.0, rain=50.0), 1.7, 10.0, 0.2),
    "rain_100": (OVERCAST, None, atmosphere(rain=100.0), 1.7, 0.0, 0.2),
    "rain_only_100": (OVERCAST, None, atmosphere(molecules=False, rain=100.0), 1.7, 0.0, None),
    "rain_10_cie8_low_sun": ({"model": "cie", "type": 8, "zenith_radiance": [1, 1, 1]},
                             {"elevation": 10.0, "azimuth": 0.0, "irradiance": [5.0, 5.0, 5.0]},
                             atmosphere(visibility=10000.0, rain=10.0), 500.0, 0.0, None),
    "camera_3km_down": (OVERCAST, None, atmosphere(visibility=50000.0), 3000.0, -30.0, None),
    "camera_3km_above_rain": (OVERCAST, None, atmosphere(visibility=5000.0, rain=20.0), 3000.0, -60.0, 0.2),
    "camera_10km_down": (CLEAR, SUN30, atmosphere(visibility=10000.0), 10000.0, -60.0, 0.3),
    "camera_10km_horizon": (CLEAR, SUN30, atmosphere(visibility=10000.0), 10000.0, 0.0, None),
    "camera_on_ground_up": (CLEAR, SUN30, atmosphere(visibility=20000.0, rain=5.0), 0.0, 45.0, None),
    "looking_down_steeply": (OVERCAST, None, atmosphere(visibility=1000.0, rain=30.0), 1.7, -60.0, 0.3),
    "sun_below_horizon": ({"model": "cie", "type": 13, "zenith_radiance": [1, 1, 1]},
                          {"elevation": -5.0, "azimuth": 0.0, "irradiance": [5.0, 5.0, 5.0]},
                          atmosphere(visibility=20000.0), 1.7, 10.0, 0.3),
    "sun_low_ahead_clear": (CLEAR, {"elevation": 5.0, "azimuth": 0.0, "irradiance": [5.0, 5.0, 5.0]},
                            atmosphere(visibility=30000.0), 1.7, 0.0, None),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_scattering_volumes_match_the_reference(renderer, case):
    """Within 1 % on pixels above 1e-3 of the column's maximum, both backends."""
    sky, sun, atm, camera_y, pitch, ground = CASES[case]
    scene = day_scene(sky=sky, sun=sun, atmosphere=atm, camera_y=camera_y, pitch=pitch, ground=ground)
    image = renderer.render(scene)[:, 0]
    finite_non_negative(image, case)
    assert relative_error(image, reference_column(scene)) < 0.01


def test_segments_converge_to_the_reference(renderer):
    """More altitude levels, smaller error: 4 levels worse than 64, 64 within 0.5 %."""
    sky, sun, atm, camera_y, pitch, ground = CASES["rain_10_haze_2km"]
    errors = {}
    expected = None
    for n in (4, 16, 64):
        scene = day_scene(sky=sky, sun=sun, atmosphere=atm, camera_y=camera_y, pitch=pitch, ground=ground,
                          quality={"sky_segments": n})
        if expected is None:
            expected = reference_column(scene)
        errors[n] = relative_error(renderer.render(scene)[:, 0], expected)
    assert errors[64] < 0.005
    assert errors[64] < errors[4]
    assert errors[16] < errors[4]


@pytest.mark.parametrize("case", ["camera_3km_down", "rain_only_100", "looking_down_steeply"])
def test_brute_force_marching_agrees_with_the_segments(renderer, case):
    """The brute-force march of the same medium (many small steps) agrees within 1 %. (1000 steps:
    llvmpipe stops longer shader loops; the march needs more only for rays that climb through dense
    haze, whose steps are spread up to the top of the atmosphere.)"""
    sky, sun, atm, camera_y, pitch, ground = CASES[case]
    kw = {"sky": sky, "sun": sun, "atmosphere": atm, "camera_y": camera_y, "pitch": pitch, "ground": ground}
    analytic = renderer.render(day_scene(**kw))[:, 0]
    marched = renderer.render(day_scene(quality={"airlight": "march", "march_steps": 1000}, **kw))[:, 0]
    assert relative_error(marched, analytic) < 0.01


@pytest.mark.parametrize("case", ["haze_50km_clear_sun", "rain_50", "camera_10km_down",
                                  "rain_10_cie8_low_sun"])
def test_gl_and_cpu_agree_on_daytime_scenes(renderer_cache, case):
    """The two backends within 0.5 % (pixels above 1e-3 of the maximum)."""
    sky, sun, atm, camera_y, pitch, ground = CASES[case]
    scene = day_scene(sky=sky, sun=sun, atmosphere=atm, camera_y=camera_y, pitch=pitch, ground=ground,
                      width=16, height=12)
    cpu = renderer_cache("cpu").render(scene)
    gl = renderer_cache("gl").render(scene)
    assert relative_error(gl, cpu) < 0.005


# ---- Stability ----------------------------------------------------------------------------------

@pytest.mark.parametrize("camera_y", [0.0, 10000.0])
def test_rays_along_the_horizon_are_finite(renderer, camera_y):
    """An odd film height puts the middle row exactly on the horizon (a ray that never leaves its
    altitude): finite, non-negative, and between its neighbours' values."""
    scene = day_scene(sky=CLEAR, sun=SUN30, atmosphere=atmosphere(visibility=5000.0, rain=10.0),
                      camera_y=camera_y, pitch=0.0, fov=2.0, width=3, height=5)
    image = renderer.render(scene)
    finite_non_negative(image, "horizon")
    assert image[2, 1].max() > 0.0


def test_extreme_rain_is_finite(renderer):
    scene = day_scene(sky=OVERCAST, sun=SUN30, atmosphere=atmosphere(visibility=50.0, rain=1000.0),
                      width=4, height=8, ground=0.5)
    finite_non_negative(renderer.render(scene), "rain 1000 mm/h")


sky_types = st.integers(min_value=0, max_value=15)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rain=st.floats(0.0, 100.0), visibility=st.floats(50.0, 50000.0), scale_height=st.floats(50.0, 2000.0),
       camera_y=st.floats(0.0, 10000.0), pitch=st.floats(-90.0, 90.0), sky_type=sky_types,
       sun_elevation=st.floats(-30.0, 90.0), sun_azimuth=st.floats(-180.0, 180.0), ground=st.booleans())
@example(rain=100.0, visibility=50.0, scale_height=2000.0, camera_y=0.0, pitch=0.0, sky_type=12,
         sun_elevation=-30.0, sun_azimuth=0.0, ground=True)
def test_random_daytime_scenes_are_finite_and_non_negative(renderer, rain, visibility, scale_height,
                                                           camera_y, pitch, sky_type, sun_elevation,
                                                           sun_azimuth, ground):
    sky = OVERCAST if sky_type == 0 else {"model": "cie", "type": sky_type, "zenith_radiance": [1, 1, 1]}
    sun = {"elevation": sun_elevation, "azimuth": sun_azimuth, "irradiance": [5.0, 5.0, 5.0]}
    scene = day_scene(sky=sky, sun=sun, atmosphere=atmosphere(visibility=visibility, rain=rain,
                                                                 scale_height=scale_height),
                      camera_y=camera_y, pitch=pitch, width=4, height=4, ground=0.4 if ground else None)
    finite_non_negative(renderer.render(scene), "random daytime scene")
