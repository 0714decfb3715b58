"""Both backends against the independent float64 reference (reference.py): direct
lighting of Lambertian surfaces by point lamps through a homogeneous medium.

Every medium here is purely absorbing (albedo 0, so sigma_s = 0): the fog's own glow
(airlight, single scattering) is not part of the direct-lighting model and is tested
elsewhere; with sigma_s = 0 the direct model is the whole image."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest
from reference import LAMP_ID_BASE, camera_rays, render_reference

import airlight

WIDTH, HEIGHT = 160, 120
REL_TOL = 5e-3
# Pixels dimmer than this fraction of the brightest surface pixel are not compared
# (lamp cores are orders of magnitude brighter than any surface, so they are left
# out of the maximum or they would hide every surface).
DIM_FRACTION = 1e-3
MIN_TESTED = 5000  # channel values compared per scene, so that no test passes vacuously

FILM = {"width": WIDTH, "height": HEIGHT}
FOG = {"sigma_t": 0.05, "albedo": 0.0, "phase": {"type": "isotropic"}}


def _camera(position, look_at, up=(0.0, 1.0, 0.0), fov_y=60.0) -> dict[str, Any]:
    return {"position": list(position), "look_at": list(look_at), "up": list(up), "fov_y": fov_y}


def _light(position, intensity, radius=0.05) -> dict[str, Any]:
    return {"type": "point", "position": list(position), "intensity": intensity, "radius": radius}


def _plane(point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0), albedo=0.5) -> dict[str, Any]:
    return {"type": "plane", "point": list(point), "normal": list(normal), "albedo": albedo}


def _box(lo, hi, albedo=0.5) -> dict[str, Any]:
    return {"type": "box", "min": list(lo), "max": list(hi), "albedo": albedo}


def _sphere(center, radius, albedo=0.5) -> dict[str, Any]:
    return {"type": "sphere", "center": list(center), "radius": radius, "albedo": albedo}


def _scene(camera, lights, surfaces, medium=FOG, background=(0.0, 0.0, 0.0)) -> dict[str, Any]:
    scene = {"film": dict(FILM), "camera": camera, "lights": lights, "surfaces": surfaces,
             "background": list(background)}
    if medium is not None:
        scene["medium"] = medium
    return scene


def _many_bounded_surfaces(count: int = 40, seed: int = 3) -> list[dict[str, Any]]:
    """A plane and `count` boxes and spheres scattered over it, so that the renderer's
    bounding volume hierarchy is several levels deep (camera and shadow rays)."""
    rng = np.random.default_rng(seed)
    surfaces = [_plane(albedo=0.4)]
    for k in range(count):
        x, z = rng.uniform(-8, 8), rng.uniform(-22, -3)
        size = rng.uniform(0.3, 1.2)
        if k % 2:
            surfaces.append(_sphere((x, size, z), size, float(rng.uniform(0.2, 0.9))))
        else:
            surfaces.append(_box((x - size, 0, z - size), (x + size, rng.uniform(0.5, 3), z + size),
                                 [float(v) for v in rng.uniform(0.2, 0.9, 3)]))
    return surfaces


SCENES: dict[str, dict[str, Any]] = {
    "forty_boxes_and_spheres_through_the_bvh": _scene(
        _camera((0, 5, 3), (0, 0, -12)),
        [_light((3, 6, -8), [90, 80, 70], 0.1), _light((-4, 4, -16), [50, 60, 70], 0.1)],
        _many_bounded_surfaces(),
    ),
    "plane_only": _scene(
        _camera((0, 2, 0), (0, 0, -8)),
        [_light((2, 3, -6), [40, 30, 20]), _light((-3, 1.5, -12), 25.0)],
        [_plane(albedo=[0.3, 0.5, 0.7])],
    ),
    "plane_and_boxes_with_shadows": _scene(
        _camera((0, 4, 2), (0, 0, -8)),
        [_light((4, 6, -4), [80, 70, 60], 0.1), _light((-5, 3, -14), [30, 40, 50], 0.1)],
        [
            _plane(albedo=0.4),
            _box((-2, 0, -8), (0, 2, -6), [0.8, 0.6, 0.4]),
            _box((1, 0.5, -12), (3, 1.5, -10), 0.6),
        ],
    ),
    "spheres_on_plane": _scene(
        _camera((0, 2, 3), (0, 1, -6)),
        [_light((3, 5, -2), [60, 60, 60], 0.2), _light((-4, 2, -9), [10, 20, 30])],
        [_plane(albedo=0.3), _sphere((0, 1.2, -6), 1.2, [0.9, 0.5, 0.2]), _sphere((-2.5, 0.5, -4), 0.5, 0.8)],
    ),
    "camera_inside_box_looking_at_walls": _scene(
        _camera((0.5, 1.6, 1.0), (-2, 0.5, -3), fov_y=90.0),
        [_light((0.5, 2.5, -1.0), [20, 18, 15], 0.1), _light((-2, 1, 2), [5, 5, 8], 0.05)],
        [_box((-3, 0, -4), (3, 3, 3), [0.7, 0.7, 0.6]), _sphere((-1, 0.6, -2), 0.6, 0.5)],
    ),
    "per_channel_extinction": _scene(
        _camera((0, 3, 4), (0, 0, -10)),
        [_light((2, 4, -5), [100, 100, 100], 0.1), _light((-3, 3, -18), [200, 200, 200], 0.1)],
        [_plane(albedo=0.5), _box((-1, 0, -9), (1, 3, -7), 0.7), _sphere((4, 1, -12), 1.0, 0.6)],
        medium={"sigma_t": [0.01, 0.05, 0.2], "albedo": 0.0, "phase": {"type": "isotropic"}},
    ),
    "no_medium": _scene(
        _camera((0, 3, 4), (0, 0, -10)),
        [_light((2, 4, -5), [30, 25, 20], 0.1), _light((-3, 3, -18), [60, 60, 80], 0.1)],
        [_plane(albedo=0.5), _box((-1, 0, -9), (1, 3, -7), 0.7), _sphere((4, 1, -12), 1.0, 0.6)],
        medium=None,
        background=(0.01, 0.02, 0.05),
    ),
    "lights_close_to_surfaces": _scene(
        _camera((0, 1.5, 2), (0, 0.3, -3)),
        [_light((0.3, 0.15, -2), [2, 2, 2], 0.05), _light((-1.0, 0.8, -2.9), [1, 1.5, 2], 0.02)],
        [_plane(albedo=0.5), _box((-2, 0, -4), (0, 1, -3), 0.6)],
    ),
    "surface_points_inside_lamp_radius": _scene(
        # The camera sits inside a large lamp (so it does not see that lamp's core)
        # and looks at floor points closer to the lamp's centre than its radius.
        _camera((0, 1.0, -1.5), (0, 0, -3)),
        [_light((0, 0.5, -3), [10, 8, 6], 2.0), _light((3, 2, -6), [20, 20, 20], 0.1)],
        # The small box lies wholly inside the big lamp, so it casts no shadow from
        # that lamp (shadow segments end on the lamp's sphere); the other box pokes
        # out of the lamp's sphere.
        [_plane(albedo=0.5), _box((1.5, 0, -4), (2.5, 0.5, -3), 0.5),
         _box((-0.2, 0, -4.4), (0.2, 0.4, -4.0), 0.8)],
    ),
    "grazing_view_along_plane": _scene(
        _camera((0, 0.05, 0), (0, 0.0, -10), fov_y=20.0),
        [_light((1, 2, -15), [200, 200, 200], 0.1), _light((-2, 0.5, -40), [300, 250, 200], 0.1)],
        [_plane(albedo=0.5), _box((1, 0, -30), (3, 0.4, -28), 0.7)],
        medium={"sigma_t": 0.02, "albedo": 0.0},
    ),
    "grazing_light_and_rolled_camera": _scene(
        _camera((1, 2, 3), (-1, 0.2, -5), up=(0.4, 1.0, 0.1), fov_y=50.0),
        [_light((-10, 0.3, -4), [400, 300, 200], 0.1), _light((2, 6, -3), [20, 20, 20], 0.1)],
        [_plane(albedo=0.6), _sphere((-1, 0.8, -4), 0.8, [0.5, 0.6, 0.7]),
         _plane(point=(0, 0, -9), normal=(0.2, 0.1, 1.0), albedo=0.4)],
    ),
}


def _compare(img: np.ndarray, ref_image, label: str) -> int:
    """Asserts the relative error bound on the comparable pixels; returns how many
    channel values were compared."""
    ref = ref_image.radiance
    surface = (ref_image.hit_id >= 0) & (ref_image.hit_id < LAMP_ID_BASE)
    assert surface.any(), f"{label}: the reference sees no surface"
    threshold = DIM_FRACTION * ref[surface].max()
    assert np.isfinite(img).all(), f"{label}: non-finite pixels"
    # Bright in either image: light where the reference has none is an error too.
    mask = ref_image.smooth_mask()[..., None] & (np.maximum(ref, img) > threshold)
    rel = np.abs(img.astype(np.float64) - ref) / np.where(mask, np.maximum(ref, threshold * 1e-3), 1.0)
    rel = np.where(mask, rel, 0.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    bad = int((rel > REL_TOL).sum())
    assert bad == 0, (
        f"{label}: {bad} of {int(mask.sum())} compared values off by more than {REL_TOL:.1%}; worst "
        f"{rel[worst]:.3%} at (row, col, channel) {worst}: got {img[worst]!r}, reference {ref[worst]!r}"
    )
    return int(mask.sum())


@pytest.mark.parametrize("name", sorted(SCENES))
def test_backend_matches_float64_reference_away_from_edges(name: str, renderer: airlight.Renderer) -> None:
    scene = SCENES[name]
    ref_image = render_reference(scene)
    img = renderer.render(scene)
    assert img.shape == (HEIGHT, WIDTH, 3)
    tested = _compare(img, ref_image, f"{name} [{renderer.backend}]")
    assert tested >= MIN_TESTED, f"{name}: only {tested} values compared; the scene tests too little"


@pytest.mark.parametrize("name", sorted(SCENES))
def test_gl_and_cpu_agree_away_from_edges(name: str, renderer_cache) -> None:
    scene = SCENES[name]
    cpu = renderer_cache("cpu").render(scene).astype(np.float64)
    gl = renderer_cache("gl").render(scene).astype(np.float64)
    assert np.isfinite(cpu).all() and np.isfinite(gl).all()
    ref_image = render_reference(scene)
    surface = (ref_image.hit_id >= 0) & (ref_image.hit_id < LAMP_ID_BASE)
    threshold = DIM_FRACTION * ref_image.radiance[surface].max()
    mask = ref_image.smooth_mask()[..., None] & (np.maximum(cpu, gl) > threshold)
    assert mask.sum() >= MIN_TESTED
    rel = np.abs(gl - cpu)[mask] / np.maximum(cpu, gl)[mask]
    assert rel.max() <= REL_TOL, f"{name}: GL and CPU differ by up to {rel.max():.3%}"


def test_shadow_scene_has_compared_shadowed_and_lit_pixels_for_every_light() -> None:
    """The shadow scene really contains shadows (pixels unlit by a light) inside the
    compared region, so that wrong shadows cannot pass unnoticed."""
    ref_image = render_reference(SCENES["plane_and_boxes_with_shadows"])
    mask = ref_image.smooth_mask() & (ref_image.hit_id >= 0) & (ref_image.hit_id < LAMP_ID_BASE)
    for light in range(ref_image.lit.shape[0]):
        shadowed = mask & ~ref_image.lit[light]
        lit = mask & ref_image.lit[light]
        assert shadowed.sum() >= 200, f"light {light}: too few shadowed pixels"
        assert lit.sum() >= 200, f"light {light}: too few lit pixels"


def test_inside_lamp_scene_has_floor_points_within_the_lamp_radius() -> None:
    """Guards the scene itself: many compared floor pixels lie closer to the big
    lamp's centre than its radius, where the falloff is clamped to 1/r^2."""
    scene = SCENES["surface_points_inside_lamp_radius"]
    ref_image = render_reference(scene)
    origin = np.array(scene["camera"]["position"], dtype=np.float64)
    _, dirs = camera_rays(scene["camera"], WIDTH, HEIGHT)
    points = origin + ref_image.t_hit[..., None] * dirs
    lamp = scene["lights"][0]
    inside = np.linalg.norm(points - np.array(lamp["position"]), axis=-1) < lamp["radius"]
    floor = ref_image.smooth_mask() & (ref_image.hit_id == 0)
    assert (inside & floor).sum() >= 2000


def _scaled(scene: dict[str, Any], k: float) -> dict[str, Any]:
    """The same scene with every length multiplied by k, intensities by k^2 and
    extinction divided by k: every pixel's radiance is unchanged."""
    s = copy.deepcopy(scene)
    for key in ("position", "look_at"):
        s["camera"][key] = [x * k for x in s["camera"][key]]
    for light in s["lights"]:
        light["position"] = [x * k for x in light["position"]]
        light["radius"] *= k
        light["intensity"] = (np.asarray(light["intensity"], dtype=np.float64) * k * k).tolist()
    for surface in s["surfaces"]:
        for key in ("point", "min", "max", "center"):
            if key in surface:
                surface[key] = [x * k for x in surface[key]]
        if "radius" in surface:
            surface["radius"] *= k
    if s.get("medium") is not None:
        s["medium"]["sigma_t"] = (np.asarray(s["medium"]["sigma_t"], dtype=np.float64) / k).tolist()
    return s


@pytest.mark.parametrize("scale", [1e-3, 1e3])
@pytest.mark.parametrize("name", ["plane_and_boxes_with_shadows", "spheres_on_plane"])
def test_direct_lighting_is_independent_of_the_scene_scale(
        name: str, scale: float, renderer: airlight.Renderer) -> None:
    """Millimetre and kilometre versions of a scene render like the metre one
    (shadow-ray offsets and tolerances must follow the scene's scale)."""
    scene = _scaled(SCENES[name], scale)
    ref_image = render_reference(scene)
    np.testing.assert_allclose(ref_image.radiance, render_reference(SCENES[name]).radiance, rtol=1e-9, atol=0)
    tested = _compare(renderer.render(scene), ref_image, f"{name} x{scale:g} [{renderer.backend}]")
    assert tested >= MIN_TESTED
