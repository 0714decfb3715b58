"""Particle clouds as a user meets them (physics.md sections 4-6): the scene key's validation, a
scene without particle clouds building nothing, a surface cutting particles exactly, no NaN, Inf or
negative light over wide parameters and in the nasty corners (camera inside a particle, particles
crossing the camera's plane, no particle, optical radii far beyond the table, the sun below the
horizon), and an image that changes continuously as the camera and the wind move."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import textwrap
from typing import Any

import numpy as np
import particle_reference as ref
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_particle_render import SCENE, table

import airlight


def with_particles(**keys: Any) -> dict[str, Any]:
    scene = copy.deepcopy(SCENE)
    scene["camera"] = {"position": [0, 2, 0], "look_at": [300, 1200, -2500], "up": [0, 1, 0], "fov_y": 70}
    scene["particle_clouds"].update(keys)
    return scene


# ---- The scene key -----------------------------------------------------------------------------

@pytest.mark.parametrize("key, value, message", [
    ("coverage", 1.5, "particle_clouds.coverage"),
    ("threshold", 1.0, "particle_clouds.threshold"),
    ("top", 500, "particle_clouds.top"),
    ("cell_size", 0, "particle_clouds.cell_size"),
    ("rings", 0, "particle_clouds.rings"),
    ("ring_cells", 1.5, "particle_clouds.ring_cells"),
    ("g", 0.99, "particle_clouds.g"),
    ("wind", [1], "particle_clouds.wind"),
    ("cell_sise", 100, "cell_size"),
])
def test_bad_keys_are_named_in_the_error(key, value, message):
    scene = with_particles()
    scene["particle_clouds"][key] = value
    with pytest.raises((ValueError, TypeError), match=message.replace(".", r"\.")):
        airlight.load_scene(scene)


def test_a_scene_has_one_cloud_method():
    scene = with_particles()
    scene["clouds"] = {"coverage": 0.5}
    with pytest.raises(ValueError, match="one cloud method"):
        airlight.load_scene(scene)


def test_written_scene_reloads_with_the_same_particle_clouds():
    scene = with_particles(wind=[3, -2], time=100, particle_size=0.9)
    first = airlight.load_scene(scene)
    assert airlight.load_scene(first) == first
    assert first["particle_clouds"]["wind"] == [3, -2] and first["quality"]["particle_table"] == "preview"


TABLES = textwrap.dedent("""
    import json, sys, airlight
    airlight.render(json.loads(sys.argv[1]), backend="cpu")
    print(json.dumps(sorted(airlight.table_stats())))
""")


@pytest.mark.parametrize("clouds", [None, {"coverage": 0}, {"extinction": 0}])
def test_scene_without_visible_particle_clouds_builds_nothing(clouds):
    scene = with_particles()
    if clouds is None:
        del scene["particle_clouds"]
    else:
        scene["particle_clouds"].update(clouds)
    out = subprocess.run([sys.executable, "-c", TABLES, json.dumps(scene)], capture_output=True, text=True,
                         check=True)
    assert not any(name.startswith("particle") for name in json.loads(out.stdout)), out.stdout


def test_scene_with_particle_clouds_builds_the_lighting_table():
    out = subprocess.run([sys.executable, "-c", TABLES, json.dumps(with_particles())], capture_output=True,
                         text=True, check=True)
    assert "particle_light" in json.loads(out.stdout)


# ---- Surfaces cut the particles ----------------------------------------------------------------

TOWER = {"type": "box", "min": [-150, 0, -1400], "max": [250, 1800, -1000], "albedo": 0.3}


def box_distance(scene: dict[str, Any], box: dict[str, Any]) -> np.ndarray:
    """Where each pixel's ray enters the box (inf: it misses), by the slab method in float64."""
    dirs = ref.camera_rays(scene)
    o = np.asarray(scene["camera"]["position"], float)
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (np.asarray(box["min"], float) - o) / dirs
        t1 = (np.asarray(box["max"], float) - o) / dirs
    near = np.nanmax(np.minimum(t0, t1), axis=-1)
    far = np.nanmin(np.maximum(t0, t1), axis=-1)
    return np.where((far >= near) & (far > 0), np.maximum(near, 0.0), np.inf)


def test_a_tower_cuts_the_particles_where_it_stands(renderer):
    scene = with_particles()
    scene["surfaces"] = [TOWER]
    particles = airlight._core.particle_frame(scene)
    out = renderer.render(scene, outputs=["particle_clouds", "transmittance", "depth"])
    t_hit = box_distance(scene, TOWER)
    assert np.isfinite(t_hit).mean() > 0.1  # the tower fills part of the view
    light, through = ref.composite(scene, particles, table(), t_hit)
    uncut, _ = ref.composite(scene, particles, table())
    cut = np.isfinite(t_hit) & (np.abs(uncut - light).max(axis=-1) > 0.05 * uncut.max(axis=-1))
    assert cut.sum() >= 5  # some particles stand partly behind the tower's face
    mask = light.max(axis=-1) > 1e-3 * light.max()
    rel = np.abs(out["particle_clouds"] - light)[mask] / light[mask]
    assert np.median(rel) <= 5e-3 and np.percentile(rel, 99) <= 3e-2, (np.median(rel), np.percentile(rel, 99))
    np.testing.assert_allclose(out["transmittance"][..., 1], through, rtol=1e-3, atol=2e-4)


# ---- Robustness ---------------------------------------------------------------------------------

def assert_clean(image: np.ndarray, what: str) -> None:
    assert np.isfinite(image).all(), f"{what}: NaN or Inf"
    assert (image >= 0).all(), f"{what}: negative radiance {image.min()}"


def test_camera_inside_a_particle_sees_a_continuous_share_of_it(renderer):
    """Walking the camera into a particle and through its centre: the pixels match the float64
    reference at every step (the share of the chord's light the visible part gives, eq. 6.2), and
    nothing jumps as the camera crosses the surface. (Past the centre the chord's middle lies
    behind the camera: once that dropped the particle's light altogether.)"""
    scene = with_particles(extinction=0.005)
    particles = airlight._core.particle_frame(scene)
    c, r = particles["center"][0], particles["radius"][0]
    images = []
    for f in (1.02, 1.0005, 0.9995, 0.5, 0.0, -0.5, -0.9):
        eye = c + np.array([0.0, 0.0, f * r])
        scene["camera"] = {"position": eye.tolist(), "look_at": (c - np.array([0, 0, 2 * r])).tolist(),
                           "up": [0, 1, 0], "fov_y": 40}
        out = renderer.render(scene, outputs=["particle_clouds", "transmittance"])
        image = out["particle_clouds"]
        assert_clean(image, f"camera at {f} radii")
        light, through = ref.composite(scene, airlight._core.particle_frame(scene), table())
        assert light.max() > 0
        mask = light.max(axis=-1) > 1e-3 * light.max()
        rel = np.abs(image - light)[mask] / light[mask]
        assert np.median(rel) < 5e-3 and rel.max() < 3e-2, (f, np.median(rel), rel.max())
        images.append(image)
    across = np.abs(images[1] - images[2]).max() / max(images[1].max(), 1e-30)
    assert across < 0.02, across


@pytest.mark.parametrize("case", ["no particle", "one particle", "thick beyond the table", "sun below",
                                  "camera in the layer", "grazing"])
def test_corner_cases_give_clean_images(renderer, case):
    scene = with_particles()
    if case == "no particle":
        scene["particle_clouds"]["coverage"] = 0.01
    elif case == "one particle":
        scene["particle_clouds"].update(rings=1, ring_cells=2, coverage=0.45)
    elif case == "thick beyond the table":
        scene["particle_clouds"]["extinction"] = 50.0
    elif case == "sun below":
        scene["sun"]["elevation"] = -10
    elif case == "camera in the layer":
        scene["camera"]["position"] = [0, 1700, 0]
    elif case == "grazing":
        scene["camera"] = {"position": [0, 1000, 0], "look_at": [0, 1000, -100], "up": [0, 1, 0], "fov_y": 90}
    out = renderer.render(scene, outputs=["radiance", "particle_clouds", "transmittance"])
    for name, image in out.items():
        assert_clean(image, f"{case}: {name}")
    if case == "sun below":
        assert out["particle_clouds"].max() > 0  # the sky still lights them


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_no_nan_inf_or_negative_radiance_over_wide_parameters(renderer_cache, data):
    draw = data.draw
    base = draw(st.floats(0, 5000))
    top = base + draw(st.sampled_from([1.0, 80.0, 1500.0, 6000.0]))
    y = draw(st.sampled_from([0.5, base, top, 0.5 * (base + top), top + 100]))
    look = [draw(st.floats(-1, 1)), draw(st.floats(-1, 1)), draw(st.floats(-1, 1))]
    if np.linalg.norm(look) < 1e-3 or abs(look[1]) > 0.999 * np.linalg.norm(look):
        look = [0.0, 0.1, -1.0]
    # A unit offset: a camera 10 km up cannot aim at a point 2 mm away (float32, a clear scene error).
    look = [float(x) for x in np.asarray(look) / np.linalg.norm(look)]
    scene = with_particles(base=base, top=top, coverage=draw(st.sampled_from([0.0, 0.4, 1.0])),
                           threshold=draw(st.sampled_from([0.0, 0.5, 0.95])),
                           extinction=draw(st.sampled_from([0.0, 1e-5, 0.05, 1e3])),
                           g=draw(st.sampled_from([0.0, 0.85])),
                           cell_size=draw(st.sampled_from([50.0, 300.0, 3000.0])),
                           particle_size=draw(st.sampled_from([0.1, 0.75, 4.0])),
                           wind=[draw(st.floats(-50, 50)), 0.0], time=draw(st.floats(0, 1e5)))
    scene["film"] = {"width": 12, "height": 8}
    scene["camera"] = {"position": [0.0, y, 0.0], "look_at": [look[0], y + look[1], look[2]], "up": [0, 1, 0],
                       "fov_y": 60}
    scene["sun"]["elevation"] = draw(st.sampled_from([-5.0, 0.0, 0.5, 30.0, 90.0]))
    if draw(st.booleans()):
        scene["atmosphere"] = {"molecules": {"density_scale": 1}, "aerosol": {"visibility": 20000}}
    image = renderer_cache(draw(st.sampled_from(["cpu", "gl"]))).render(scene)
    assert_clean(image, json.dumps(scene))


# ---- Continuity ---------------------------------------------------------------------------------

def mean_frame_difference(renderer: airlight.Renderer, scenes: list[dict[str, Any]]) -> float:
    """The largest mean absolute change between consecutive frames, over the frames' mean radiance.
    (Not the largest pixel's change: a particle is a hard-edged sphere, and as its silhouette
    crosses a pixel's centre the chord grows like the square root of the distance, so a pixel's
    change shrinks only like the square root of the step; the mean, like the step.)"""
    images = [renderer.render(s) for s in scenes]
    mean = float(np.mean([im.mean() for im in images]))
    return max(float(np.abs(b - a).mean()) for a, b in zip(images, images[1:])) / mean


@pytest.mark.parametrize("motion", ["camera", "wind"])
def test_motion_changes_the_image_continuously(renderer_cache, motion):
    """Halving the step of a slow motion (the camera crossing ring boundaries, the wind carrying
    columns over the threshold) nearly halves the largest frame difference: nothing pops (a particle
    appearing whole would change a frame by the same amount at any step). The sun stands behind
    the camera: toward it the silver linings' thin bright rims dominate (physics.md section 6)."""
    renderer = renderer_cache("cpu")
    base = with_particles(ring_cells=3, rings=3)
    base["film"] = {"width": 24, "height": 14}
    base["sun"]["azimuth"] = 200

    def frames(step: float) -> list[dict[str, Any]]:
        out = []
        for k in range(int(320 / step) + 1):
            s = copy.deepcopy(base)
            if motion == "camera":
                s["camera"]["position"] = [k * step, 2, 0]
                s["camera"]["look_at"] = [300 + k * step, 1200, -2500]
            else:
                s["particle_clouds"].update(wind=[10.0, 0.0], time=k * step / 10.0)
            out.append(s)
        return out

    coarse = mean_frame_difference(renderer, frames(40.0))
    fine = mean_frame_difference(renderer, frames(10.0))
    assert coarse > 0  # it moves
    assert fine < 0.5 * coarse, (coarse, fine)


# ---- The shadow below --------------------------------------------------------------------------

def exact_sun_transmittance(points: np.ndarray, sun: np.ndarray,
                            casters: dict[str, np.ndarray]) -> np.ndarray:
    """exp(-sum of sigma x chord) over every particle the ray from each point toward the sun crosses."""
    depth = np.zeros(len(points))
    for c, r, tau in zip(casters["center"], casters["radius"], casters["tau"]):
        oc = c - points
        b = oc @ sun
        h2 = r * r - (np.einsum("ij,ij->i", oc, oc) - b * b)
        h = np.sqrt(np.maximum(h2, 0.0))
        chord = np.clip(b + h, 0.0, None) - np.clip(b - h, 0.0, None)
        depth += np.where(h2 > 0, tau / r * chord, 0.0)
    return np.exp(-depth)


def test_particles_shadow_the_ground_as_their_spheres_do(renderer):
    """The ground's sunlight through the shadow map (every sphere's chord toward the sun summed at the
    map's nodes on the plane below the particles, eq. 5.3) against the exact sum at each point seen:
    measured median absolute error 4e-4, 90th percentile 1e-2 (bilinear between nodes 36 m apart at
    the shadows' edges). Marching the lattice instead (cells of 300 m) gave 0.015 and 0.36."""
    scene = with_particles()
    del scene["sky"]
    scene["surfaces"] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": 0.5}]
    scene["camera"] = {"position": [0, 600, 0], "look_at": [0, 0, -700], "up": [0, 1, 0], "fov_y": 80}
    out = renderer.render(scene, outputs=["radiance", "depth"])
    clear = copy.deepcopy(scene)
    clear["particle_clouds"]["coverage"] = 0
    lit = renderer.render(clear)
    seen = (out["depth"] < 1e5) & (lit[..., 1] > 0)
    dirs = ref.camera_rays(scene)
    points = np.asarray(scene["camera"]["position"], float) + dirs[seen] * out["depth"][seen][:, None]
    el, az = np.radians(scene["sun"]["elevation"]), np.radians(scene["sun"]["azimuth"])
    sun = np.array([np.cos(el) * np.sin(az), np.sin(el), -np.cos(el) * np.cos(az)])
    exact = exact_sun_transmittance(points, sun, airlight._core.particle_frame(scene)["casters"])
    got = out["radiance"][..., 1][seen] / lit[..., 1][seen]
    assert exact.min() < 0.5 and exact.max() > 0.9  # shadow and light on the ground
    err = np.abs(got - exact)
    assert np.median(err) < 5e-3 and np.percentile(err, 90) < 0.05, (np.median(err), np.percentile(err, 90))


# ---- The shadow in the air ---------------------------------------------------------------------

def fog_under_particles(width: int, height: int) -> dict[str, Any]:
    """Fog of 1500 m visibility under the particle layer, no surfaces (the shadow map is built for the
    air alone), seen from 300 m looking a few degrees up, so that every ray crosses kilometres of fog
    below the lowest particle."""
    scene = copy.deepcopy(SCENE)
    del scene["sky"]
    scene["film"] = {"width": width, "height": height}
    scene["medium"] = {"visibility": 1500}
    scene["camera"] = {"position": [0, 300, 0], "look_at": [0, 450, -3000], "up": [0, 1, 0], "fov_y": 20}
    return scene


def fog_light_through_particles(scene: dict[str, Any], steps: int = 2048) -> np.ndarray:
    """The float64 reference: the share of the fog's sunlight along each pixel's ray that the particles
    let through, the integral of e^{-sigma t} T(t) dt over that of e^{-sigma t} dt, T the exact sum of
    every sphere's chord toward the sun (exact_sun_transmittance), in `steps` equal steps out to 40
    optical depths, each weighted exactly."""
    sigma = 3.912 / scene["medium"]["visibility"]
    el, az = np.radians(scene["sun"]["elevation"]), np.radians(scene["sun"]["azimuth"])
    sun = np.array([np.cos(el) * np.sin(az), np.sin(el), -np.cos(el) * np.cos(az)])
    dirs = ref.camera_rays(scene).reshape(-1, 3)
    origin = np.asarray(scene["camera"]["position"], float)
    edges = np.linspace(0.0, 40.0 / sigma, steps + 1)
    weights = np.exp(-sigma * edges[:-1]) - np.exp(-sigma * edges[1:])
    points = origin + dirs[:, None, :] * (0.5 * (edges[1:] + edges[:-1]))[None, :, None]
    casters = airlight._core.particle_frame(scene)["casters"]
    through = exact_sun_transmittance(points.reshape(-1, 3), sun, casters).reshape(len(dirs), steps)
    return ((through * weights).sum(axis=1) / weights.sum()).reshape(ref.camera_rays(scene).shape[:2])


def test_particles_shadow_the_fog_below_them_like_the_exact_chord_sums(renderer):
    """The fog's sunlight (the medium_sun layer) with the particles' shadow over the same without it,
    against the float64 reference's share (physics.md section 5): each piece of the ray
    (quality.cloud_shadow_steps) lit through the shadow map where its middle's ray toward the sun
    crosses the map's plane. Measured on both backends (72 pixels, the reference's share spanning
    0.78 to 0.996): 16 pieces (default) median 0.0032, max 0.013; 128 pieces median 0.00057,
    max 0.0094 (the map's nodes 36 m apart)."""
    scene = fog_under_particles(12, 6)
    through = fog_light_through_particles(scene)
    assert through.min() < 0.85 and through.max() > 0.95  # shadowed and lit fog

    def share(shadow_steps: int) -> np.ndarray:
        shadowed = copy.deepcopy(scene)
        shadowed["quality"] = {**scene["quality"], "cloud_shadow_steps": shadow_steps}
        free = copy.deepcopy(shadowed)
        free["quality"]["cloud_shadow_steps"] = 0
        return (renderer.render(shadowed, outputs=["medium_sun"])["medium_sun"][..., 1] /
                renderer.render(free, outputs=["medium_sun"])["medium_sun"][..., 1])

    for steps, (median, largest) in {16: (0.006, 0.03), 128: (0.0015, 0.02)}.items():
        err = np.abs(share(steps) - through)
        assert np.median(err) <= median and err.max() <= largest, (steps, np.median(err), err.max())


@pytest.mark.parametrize("medium", ["atmosphere", "fog"])
def test_particles_shadow_the_air_below_them(renderer, medium):
    """The sunlight the atmosphere (the sky layer) or the fog (medium_sun) scatters under the particles
    is dimmed by their shadow: never brighter than without it, darker under dense cover, unchanged by
    particles too thin to matter and by cloud_shadow_steps 0 (the light of the unshadowed frame)."""
    layer = "sky" if medium == "atmosphere" else "medium_sun"

    def air(coverage: float, extinction: float, shadow_steps: int) -> np.ndarray:
        scene = with_particles(coverage=coverage, extinction=extinction)
        scene["film"] = {"width": 24, "height": 12}
        if medium == "atmosphere":
            scene["atmosphere"] = {"molecules": {"density_scale": 1}, "aerosol": {"visibility": 20000}}
        else:
            del scene["sky"]
            scene["medium"] = {"visibility": 5000}
        scene["camera"] = {"position": [0, 2, 0], "look_at": [0, 300, -3000], "up": [0, 1, 0], "fov_y": 60}
        scene["quality"] = {**scene["quality"], "cloud_shadow_steps": shadow_steps}
        return renderer.render(scene, outputs=[layer])[layer]

    free = air(0.9, 0.05, 0)
    assert free.max() > 0.0
    covered = air(0.9, 0.05, 16)
    assert np.all(covered <= free * (1 + 1e-5) + 1e-9)
    assert covered.sum() < 0.8 * free.sum(), covered.sum() / free.sum()
    # Cut into pieces, the atmosphere's volumes integrate the same light a little differently; the
    # fog's exact integral only by float32 rounding.
    rtol = 5e-3 if medium == "atmosphere" else 1e-4
    np.testing.assert_allclose(air(0.9, 1e-9, 16), air(0.9, 1e-9, 0), rtol=rtol, atol=1e-9)
