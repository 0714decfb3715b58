"""A table that no effect uses is never built: scenes without lamps, or without a
scattering medium, build no scattering table; a scene with lamps in fog builds each
table once per process, and a second frame builds nothing new. Each case runs in a
fresh interpreter, because tables live for the whole process."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest

SCRIPT = textwrap.dedent("""
    import json, sys, airlight
    scenes = json.loads(sys.argv[1])
    seen = []
    for scene in scenes:
        airlight.render(scene, backend="cpu")
        seen.append(sorted(airlight.table_stats()))
    print(json.dumps({"seen": seen, "stats": airlight.table_stats()}))
""")


def base(**extra: object) -> dict:
    """A small scene; multiple scattering is off, as these tests count the single-scattering
    tables (the multiple-scattering field's: effects/multiple_scattering/tests)."""
    scene = {"film": {"width": 16, "height": 12},
             "camera": {"position": [0, 1.7, 0], "look_at": [0, 1.7, -10], "up": [0, 1, 0], "fov_y": 60},
             "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}],
             "quality": {"multiple_scattering": False}}
    scene.update(extra)
    return scene


LAMP = [{"type": "point", "position": [2, 5, -10], "intensity": 100}]
FOG = {"sigma_t": 0.05, "albedo": 0.9}


def run(scenes: list[dict]) -> dict:
    out = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(scenes)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout)


@pytest.mark.parametrize("scene", [
    base(),                                              # nothing at all
    base(medium=FOG),                                    # fog, no lamps
    base(lights=LAMP),                                   # lamps in clear air
    base(lights=LAMP, medium={"sigma_t": 0.05, "albedo": 0}),  # lamps in purely absorbing fog
], ids=["empty", "fog_without_lamps", "lamps_without_fog", "absorbing_fog"])
def test_scene_without_scattering_lamps_builds_no_table(scene):
    assert run([scene])["seen"] == [[]]


def test_lamps_in_fog_build_each_table_once():
    scene = base(lights=LAMP, medium=FOG)
    result = run([scene, scene, base(lights=LAMP * 3, medium=FOG)])
    assert result["seen"] == [["airlight_tail", "surface_glow"]] * 3
    stats = result["stats"]
    assert stats["airlight_tail"]["bytes"] == 256 * 64 * 4
    assert stats["surface_glow"]["bytes"] == 256 * 128 * 4


SPOT = [{"type": "spot", "position": [0, 6, -10], "direction": [0, -1, 0], "intensity": 500,
         "cone_angle": 30}]


def test_spot_moment_table_only_for_spots_in_fog():
    """Point lamps in fog build no spot table; spots in fog build it, and over surfaces the point
    lamps' glow table, which bounds a spot's glow for culling (effects/spotlights/physics.md
    section 5); spots in clear air nothing."""
    assert run([base(lights=LAMP, medium=FOG)])["seen"] == [["airlight_tail", "surface_glow"]]
    assert run([base(lights=SPOT, medium=FOG)])["seen"] == [["airlight_tail", "spot_moments", "surface_glow"]]
    assert run([base(lights=SPOT)])["seen"] == [[]]
    stats = run([base(lights=SPOT, medium=FOG)])["stats"]
    assert stats["spot_moments"]["bytes"] == 256 * 64 * 4 * 4


def test_ray_marched_airlight_builds_no_tail_table():
    scene = base(lights=LAMP, medium=FOG, quality={"airlight": "march", "march_steps": 16})
    # This quality object leaves multiple scattering on: the lamps' table
    # (effects/multiple_scattering/docs/lamps.md).
    assert run([scene])["seen"] == [["lamp_ms_glow", "surface_glow"]]


def fog_with(phase: dict) -> dict:
    return {**FOG, "phase": phase}


HG = {"type": "hg", "g": 0.85}


@pytest.mark.slow
def test_anisotropic_fog_builds_only_its_lobes_tables():
    """A phase function builds per-lobe slices instead of the isotropic tables: the moment
    slice for lamps' and spots' airlight, the glow slice only where surfaces receive a
    lamp's or a spot's glow (a lamp's glow bounds a spot's for culling); each once per
    distinct lobe; fog without lamps builds nothing."""
    assert run([base(medium=fog_with(HG))])["seen"] == [[]]
    with_glow = ["phase_glow g=0.85", "phase_moments g=0.85"]
    assert run([base(lights=LAMP, medium=fog_with(HG))])["seen"] == [with_glow]
    assert run([base(lights=LAMP, medium=fog_with(HG), surfaces=[])])["seen"] == [["phase_moments g=0.85"]]
    # spots: the moment slice serves their airlight and their glow on surfaces, the glow slice
    # their glow's culling bound; without surfaces, only the moment slice
    assert run([base(lights=SPOT, medium=fog_with(HG))])["seen"] == [with_glow]
    assert run([base(lights=SPOT, medium=fog_with(HG), surfaces=[])])["seen"] == [["phase_moments g=0.85"]]
    # a second frame builds nothing new; another g builds its own slices
    other = base(lights=LAMP, medium=fog_with({"type": "hg", "g": -0.3}))
    result = run([base(lights=LAMP, medium=fog_with(HG))] * 2 + [other])
    assert result["seen"][:2] == [with_glow] * 2
    assert result["seen"][2] == sorted(with_glow + ["phase_glow g=-0.3", "phase_moments g=-0.3"])
    stats = result["stats"]
    assert stats["phase_moments g=0.85"]["bytes"] == 256 * 64 * 4 * 4
    assert stats["phase_glow g=0.85"]["bytes"] == 256 * 128 * 4


@pytest.mark.slow
def test_two_lobes_rayleigh_and_g0_tables():
    """HG2 builds one slice per lobe, Rayleigh its own, and HG with g = 0 the isotropic tables."""
    hg2 = {"type": "hg2", "forward_g": 0.85, "backward_g": -0.3, "forward_weight": 0.9}
    assert run([base(lights=LAMP, medium=fog_with(hg2), surfaces=[])])["seen"] == [
        ["phase_moments g=-0.3", "phase_moments g=0.85"]]
    assert run([base(lights=LAMP, medium=fog_with({"type": "rayleigh"}), surfaces=[])])["seen"] == [
        ["phase_moments rayleigh"]]
    assert run([base(lights=LAMP, medium=fog_with({"type": "hg", "g": 0.0}))])["seen"] == [
        ["airlight_tail", "surface_glow"]]


# ---- Daytime (issue 6): the sky-phase table -------------------------------------------------
OVERCAST = {"model": "overcast", "zenith_radiance": [1, 1, 1]}
HAZE = {"molecules": {}, "aerosol": {"visibility": 5000}}


def test_sky_table_only_where_a_sky_lights_an_atmosphere_or_surfaces():
    """No atmosphere and no surfaces: sky pixels come from the formula, no table; an atmosphere
    lit only by the sun: no table; surfaces under a sky without an atmosphere: a one-column table
    (C = 0); a sky over an atmosphere: the full table."""
    sun = {"elevation": 30, "azimuth": 0, "irradiance": [5, 5, 5]}
    assert run([base(sky=OVERCAST, surfaces=[])])["seen"] == [[]]
    assert run([base(sun=sun, atmosphere=HAZE)])["seen"] == [[]]
    assert run([base(atmosphere=HAZE)])["seen"] == [[]]
    result = run([base(sky=OVERCAST)])
    assert result["seen"] == [["sky_phase"]]
    assert result["stats"]["sky_phase"]["width"] == 1
    result = run([base(sky=OVERCAST, atmosphere=HAZE)])
    assert result["seen"] == [["sky_phase"]]
    assert result["stats"]["sky_phase"]["bytes"] == 64 * 64 * 4 * 4  # C x elevation, RGBA, no azimuth


def test_sky_table_is_rebuilt_only_when_the_sky_or_the_phases_change():
    """The table depends on the sky's shape and the species' phase functions, not on densities:
    a fading rain re-uses it; a sun sky (with azimuth blocks) or another aerosol g builds anew."""
    rain = [base(sky=OVERCAST, atmosphere={**HAZE, "rain": {"rate": r}}) for r in (50, 10, 1)]
    clear = base(sky={"model": "cie", "type": 12, "zenith_radiance": [1, 1, 1]},
                 sun={"elevation": 30, "azimuth": 0, "irradiance": [5, 5, 5]}, atmosphere=HAZE)
    other_g = base(sky=OVERCAST, atmosphere={"molecules": {}, "aerosol": {"visibility": 5000, "g": 0.5}})
    result = run(rain + [clear, other_g, rain[0]])
    assert result["stats"]["sky_phase"]["builds"] == 3  # the rains (also the last frame): one; clear; other g
    assert result["stats"]["sky_phase"]["height"] == 64  # the last built: azimuth-free


# ---- Rainbows (issue 7): the rainbow table ------------------------------------------------------
SUN = {"elevation": 20, "azimuth": 180, "irradiance": [20, 20, 20]}


def test_rainbow_table_only_for_rain_lit_by_the_sun():
    """A scene without sun or without drops builds no Mie table: rain under an overcast sky,
    a sun over haze without rain, rain with "phase": "hg", and rain whose drops have gone
    (density_scale 0) build none; rain lit by the sun builds one (3601 RGBA texels)."""
    rain = {"rain": {"rate": 25, "density_scale": 0.3}}
    assert "rainbow_phase" not in run([base(sky=OVERCAST, atmosphere=rain)])["seen"][0]
    assert "rainbow_phase" not in run([base(sun=SUN, atmosphere=HAZE)])["seen"][0]
    hg = base(sun=SUN, atmosphere={"rain": {"rate": 25, "phase": "hg"}})
    assert "rainbow_phase" not in run([hg])["seen"][0]
    assert "rainbow_phase" not in run([base(sun=SUN, atmosphere={"rain": {"rate": 25, "density_scale": 0}})])[
        "seen"][0]
    result = run([base(sun=SUN, atmosphere=rain)])
    assert result["seen"] == [["rainbow_phase"]]
    assert result["stats"]["rainbow_phase"]["bytes"] == 3601 * 4 * 4


def test_rainbow_table_is_rebuilt_only_when_the_rate_or_the_wavelengths_change():
    """The table depends on the rain rate and the wavelength count, not on the drop density: a
    fading rain (density 1 -> 0.01) re-uses one table; another rate or wavelength count builds one."""
    fading = [base(sun=SUN, atmosphere={"rain": {"rate": 25, "density_scale": d}}) for d in (1, 0.3, 0.01)]
    other_rate = base(sun=SUN, atmosphere={"rain": {"rate": 5}})
    fewer = base(sun=SUN, atmosphere={"rain": {"rate": 5}}, quality={"rainbow_wavelengths": 5})
    assert run(fading)["stats"]["rainbow_phase"]["builds"] == 1
    assert run(fading + [other_rate, fewer, fading[0]])["stats"]["rainbow_phase"]["builds"] == 3
