"""Spotlights and headlights (effects/spotlights/physics.md) against the independent float64
reference spot_reference.py (which reuses airlight_reference.py for everything that is
not specific to spots).

Model under test, per channel: profile I(theta) = I0 [(1 - q)(cos theta - cos A)/(1 - cos A)
+ q] inside the cone, 0 outside; airlight over the lit part of the visible ray; a ray that
hits a spot's sphere sees I(theta_c) / (pi r^2); surfaces get the spot's direct light
(hard shadows) and, in fog, its glow: the light the spot scatters once onto them, not
shadowed (the reference's spot_glow_unit, itself checked in test_spot_glow.py, where the
renderer's glow is tested on its own).

Accuracy: small films (48 x 32), about 40 pixels per image away from geometric edges,
shadow boundaries, beam edges on surfaces and lamp cores, brighter than 1e-3 of the image
maximum (estimated by the reference, not the renderer): every channel value within 0.5 %
of the reference. Near-degenerate pixels (rays almost tangent to a cone, lit slivers,
rays almost parallel to a cone wall, pixels next to a beam silhouette) are judged by
absolute error, 0.5 % of the image maximum: there the lit interval is ill-conditioned in
float32 (a direction error of 6e-8 moves the ends of a tangent ray's lit piece by
O(sqrt(6e-8)) of its length; effects/spotlights/docs/spot_table.md section 5, table E) while the radiance is
small and continuous. Culling is off (cull_fraction 0).

Stability: random spot scenes are finite and non-negative; the camera swept finely
across a cone wall gives values that vary smoothly; the camera inside a spot's sphere;
the q = 0 edge fading to zero smoothly on a wall and in the fog.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from airlight_reference import (
    DIM_FRACTION,
    LAMP_BASE,
    REL_TOL,
    airlight,
    airlight_log,
    box,
    camera_rays,
    get_renderer,
    light,
    make_scene,
    parse_scene,
    pixel_radiance,
    plane,
    smooth_pixels,
    sphere,
    subpixel_core_pixels,
    trace,
)
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from image_checks import finite_non_negative as _finite_non_negative
from image_checks import no_jumps as _no_jumps
from spot_reference import (
    lit_interval,
    make_spot,
    parse_spot_scene,
    profile,
    ray_frame,
    spot,
    spot_airlight,
    spot_airlight_log,
    spot_airlight_riemann,
    spot_compare,
    spot_geometry,
    spot_pixel_radiance,
    spot_samples,
)

BACKENDS = ("cpu", "gl")


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def _check(scene: dict, backend: str, label: str, min_values: int = 20) -> None:
    samples = spot_samples(scene)
    image = get_renderer(backend).render(scene)
    spot_compare(image, samples, min_values=min_values, label=f"{label} [{backend}]")


# ---- scenes --------------------------------------------------------------------------------------

def side_view(cone_angle: float, edge: float, sigma_t: float = 0.1, scale: float = 10.0,
              intensity=100.0, albedo=1.0) -> dict:
    """The beam seen from the side: a spot pointing along +x (tilted a little), the camera
    `scale` metres from the axis, looking at the axis `scale` metres from the lamp; the
    field of view is chosen so that the beam fills about 60 % of the image height (at
    most 60 degrees). Rays escape."""
    axis = _unit([1.0, 0.12, -0.15])
    lamp = np.array([0.0, 2.0, -scale])
    target = lamp + scale * axis
    half_width = scale * math.tan(math.radians(cone_angle))
    fov = min(60.0, 2.0 * math.degrees(math.atan(half_width / (0.6 * scale))))
    camera = target + np.array([0.0, 0.0, scale])
    return make_scene(camera, target, [spot(lamp, axis, intensity, cone_angle, edge)], [], sigma_t=sigma_t,
                      albedo=albedo, fov_y=fov)


def _inside_along_axis() -> dict:
    s, axis = np.array([0.0, 2.0, 0.0]), _unit([0.1, -0.05, -1.0])
    return make_scene(s + 3.0 * axis + [0.3, 0.2, 0.0], s + 20.0 * axis, [spot(s, axis, 100.0, 30.0, 0.3)],
                      [], sigma_t=0.05, fov_y=60.0)


def _back_at_lamp() -> dict:
    s, axis = np.array([0.0, 2.0, 0.0]), _unit([0.2, -0.1, -1.0])
    return make_scene(s + 8.0 * axis + [0.4, -0.2, 0.0], s, [spot(s, axis, 100.0, 25.0, 0.3)], [],
                      sigma_t=0.1, fov_y=50.0)


def _through_beam() -> dict:
    """A vertical beam from a lamp 4 m up, the camera outside it, looking through it."""
    beam = spot((0.0, 4.0, -10.0), (0.05, -1.0, 0.1), 100.0, 20.0, 0.3)
    return make_scene((-8.0, 1.5, 0.0), (0.0, 2.0, -10.0), [beam], [], sigma_t=0.1, fov_y=50.0)


def _mirror_cone() -> dict:
    """The camera 10 m behind a spot that points away from it, 0.5 m off the axis: it
    stands in the mirror cone, which must stay dark; the forward beam is beyond the lamp."""
    beam = spot((0.0, 2.0, -5.0), (0.05, 0.0, -1.0), 100.0, 30.0, 0.3)
    return make_scene((0.5, 2.3, 5.0), (0.0, 2.0, -5.0), [beam], [], sigma_t=0.1, fov_y=60.0)


VIEWS = {
    "beam_from_the_side": side_view(30.0, 0.3),
    "inside_along_axis": _inside_along_axis(),
    "inside_looking_back_at_lamp": _back_at_lamp(),
    "outside_through_beam": _through_beam(),
    "camera_in_mirror_cone": _mirror_cone(),
}


def wall_cuts_beam(sigma_t: float = 0.05) -> dict:
    """A wall 8 m ahead of a spot cuts its beam: the fog in front of the wall glows, the
    wall shows the lit disc (its direct light) and the spot's glow around and on it."""
    s, axis = np.array([0.0, 2.0, 0.0]), _unit([0.2, -0.1, -1.0])
    return make_scene((-4.0, 1.5, 2.0), (0.0, 1.8, -8.0), [spot(s, axis, [100.0, 90.0, 80.0], 25.0, 0.3)],
                      [plane((0, 0, -8.0), (0, 0, 1), 0.5)], sigma_t=sigma_t, albedo=1.0, fov_y=60.0)


def headlights_on_road() -> dict:
    """Two headlights on a road, the driver's view, a street lamp ahead, a box by the road:
    the road and the box get the lamps' direct light and the glow of all three."""
    axis = (0.0, -0.08, -1.0)
    return make_scene((0.35, 1.25, 1.0), (0.35, 0.8, -20.0),
                      [spot((-0.7, 0.7, 0.0), axis, 300.0, 20.0, 0.3),
                       spot((0.7, 0.7, 0.0), axis, 300.0, 20.0, 0.3), light((3.0, 5.0, -25.0), 200.0)],
                      [plane((0, 0, 0), (0, 1, 0), 0.3), box((2.5, 0.0, -14.0), (4.0, 1.5, -11.0), 0.5)],
                      sigma_t=0.03, albedo=1.0, fov_y=50.0)


def lit_surfaces_absorbing(edge: float, cone_angle: float = 40.0) -> dict:
    """A spot over a road, a box and a ball casting hard shadows, in a medium that only
    absorbs (albedo 0): the image is the spot's direct light alone, attenuated."""
    return make_scene((0.0, 3.5, 0.0), (0.5, 0.0, -6.5), [spot((0.5, 4.5, -6.0), (0.1, -1.0, 0.05), 200.0,
                                                                 cone_angle, edge)],
                      [plane((0, 0, 0), (0, 1, 0), 0.6), box((-2.5, 0.0, -8.0), (-1.0, 1.5, -6.5), 0.5),
                       sphere((1.5, 0.8, -5.0), 0.8, [0.7, 0.4, 0.2])], sigma_t=0.05, albedo=0.0, fov_y=60.0)


# ---- the reference itself (no renderer) ----------------------------------------------------------------

def _random_rays(seed: int, n: int, spread: float = 1.0):
    """Rays that mostly meet the beam: (origin, direction, lamp position, axis); the ray
    aims at a point about `spread` times its distance down the axis off the axis."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        lamp = rng.normal(size=3) * 3.0
        axis = _unit(rng.normal(size=3))
        down = rng.uniform(1.0, 8.0)
        target = lamp + axis * down + rng.normal(size=3) * spread * down / 3.0
        origin = lamp + rng.normal(size=3) * 5.0
        yield origin, _unit(target - origin), lamp, axis


@pytest.mark.parametrize("cone_angle", [2.0, 10.0, 30.0, 60.0, 80.0, 90.0])
def test_reference_lit_interval_matches_ray_cone_quadratic(cone_angle):
    """The numerically found lit interval (concave g, bisection) equals the exact ray-cone
    intersection of effects/spotlights/physics.md (roots of A t^2 + B t + C, kept where the midpoint
    lies in the forward nappe), and every point tested inside/outside agrees."""
    checked = 0
    spread = math.tan(math.radians(min(cone_angle, 60.0)))
    for origin, d, lamp, axis in _random_rays(int(cone_angle), 40, spread):
        sp = make_spot(axis, cone_angle)
        x1 = 25.0
        lo, hi, meets = lit_interval(origin, d[None, :], lamp, sp, 0.0, x1)
        c2 = sp.cos_a ** 2
        w = origin - lamp
        qa = (d @ axis) ** 2 - c2
        qb = 2.0 * ((d @ axis) * (w @ axis) - c2 * (d @ w))
        qc = (w @ axis) ** 2 - c2 * (w @ w)
        if cone_angle == 90.0:  # a double root: np.roots would only find it to sqrt(eps)
            roots = [-(w @ axis) / (d @ axis)]
        else:
            roots = [r.real for r in np.roots([qa, qb, qc]) if abs(r.imag) < 1e-12]
        breaks = sorted([0.0, x1] + [r for r in roots if 0.0 < r < x1])
        pieces = []
        for a, b in zip(breaks[:-1], breaks[1:]):
            p = origin + 0.5 * (a + b) * d - lamp
            if p @ axis >= sp.cos_a * np.linalg.norm(p):
                pieces.append((a, b))
        merged = []  # a double root (A = 90 degrees) splits one piece in two
        for piece in pieces:
            if merged and piece[0] == merged[-1][1]:
                merged[-1] = (merged[-1][0], piece[1])
            else:
                merged.append(piece)
        pieces = merged
        assert len(pieces) <= 1
        if pieces and pieces[0][1] - pieces[0][0] > 1e-9:
            assert meets[0]
            assert lo[0] == pytest.approx(pieces[0][0], abs=1e-9)
            assert hi[0] == pytest.approx(pieces[0][1], abs=1e-9)
            checked += 1
        else:
            assert not meets[0] or hi[0] - lo[0] < 1e-9
    assert checked >= 10


@pytest.mark.parametrize("cone_angle,edge,sigma_t", [
    (2.0, 0.0, 0.05), (10.0, 0.3, 2.0), (30.0, 1.0, 0.001), (60.0, 0.0, 0.5), (80.0, 0.3, 0.05),
    (90.0, 0.0, 0.5)])
def test_reference_matches_brute_force_riemann_sum(cone_angle, edge, sigma_t):
    """The psi-space quadrature over the lit interval agrees with a 1-million-point midpoint
    rule in x over the whole ray piece, the cone tested pointwise (no clipping logic)."""
    spread = math.tan(math.radians(min(cone_angle, 60.0)))
    for origin, d, lamp, axis in _random_rays(int(cone_angle * 10 + edge * 10), 40, spread):
        sp = make_spot(axis, cone_angle, edge)
        x1 = 12.0
        ref = spot_airlight(sigma_t, sigma_t, 100.0, origin, d, lamp, sp, 0.0, x1)
        lo, hi, _ = lit_interval(origin, d[None, :], lamp, sp, 0.0, x1)
        if ref < 1e-12 or hi[0] - lo[0] < 0.5:
            continue
        brute = spot_airlight_riemann(sigma_t, sigma_t, 100.0, origin, d, lamp, sp, 0.0, x1, n=1_000_000)
        # the midpoint rule has an O(dx) error where the profile jumps at the wall (q > 0)
        assert ref == pytest.approx(brute, rel=1e-5)
        return
    pytest.fail("no ray met the beam")


@pytest.mark.parametrize("sigma_t", [0.001, 0.05, 0.5, 2.0])
def test_reference_q1_is_point_airlight_on_lit_interval(sigma_t):
    """q = 1 (uniform inside the cone): the spot's airlight is the point light's over the
    lit interval, computed by airlight_reference's x-space quadrature (independent code);
    escaping rays included."""
    done = 0
    for origin, d, lamp, axis in _random_rays(7, 24):
        sp = make_spot(axis, 25.0, 1.0)
        for x1 in (12.0, math.inf):
            lo, hi, meets = lit_interval(origin, d[None, :], lamp, sp, 0.0, x1)
            if not meets[0]:
                continue
            b = float((lamp - origin) @ d)
            h = float(np.linalg.norm(lamp - origin - b * d))
            expect = airlight_log(sigma_t, sigma_t, 50.0, b, h, float(lo[0]), float(hi[0]))
            got = spot_airlight_log(sigma_t, sigma_t, 50.0, origin, d, lamp, sp, 0.0, x1)
            assert got == pytest.approx(expect, abs=1e-8)
            done += 1
    assert done >= 10


@pytest.mark.parametrize("sigma_t", [0.001, 0.1, 1.0])
def test_reference_half_space_spot_is_point_light_forward_half(sigma_t):
    """A = 90 degrees, q = 1: the spot is the point light on the forward half-space
    (p - S).a >= 0 (crossing found in closed form here), and two such spots pointing
    opposite ways add up to the point light, over the whole ray."""
    for origin, d, lamp, axis in _random_rays(11, 25):
        fwd, back = make_spot(axis, 90.0, 1.0), make_spot(-axis, 90.0, 1.0)
        b = float((lamp - origin) @ d)
        h = float(np.linalg.norm(lamp - origin - b * d))
        if h < 1e-3:
            continue
        da, wa = float(d @ axis), float((origin - lamp) @ axis)
        cross = -wa / da  # where the ray crosses the plane through S normal to the axis
        if da > 0:
            lo, hi = max(0.0, cross), math.inf
        else:
            lo, hi = 0.0, (cross if cross > 0 else 0.0)
        got = spot_airlight(sigma_t, sigma_t, 30.0, origin, d, lamp, fwd)
        expect = airlight(sigma_t, sigma_t, 30.0, b, h, lo, hi) if hi > lo else 0.0
        assert got == pytest.approx(expect, rel=1e-8, abs=1e-300)
        total = got + spot_airlight(sigma_t, sigma_t, 30.0, origin, d, lamp, back)
        assert total == pytest.approx(airlight(sigma_t, sigma_t, 30.0, b, h), rel=1e-8)


@pytest.mark.slow
def test_reference_half_space_spots_make_a_point_light_image():
    """The same at the pixel level (airlight, direct light and glow: black surfaces in fog,
    white ones in an absorbing medium, within 1e-8, and white ones in fog, where the two
    spots' glow (spot_reference's hemisphere quadrature) meets the point lamp's
    (airlight_reference's 1-D reduction), within 1e-6): two opposite A = 90, q = 1 spots
    render, in the reference, the point light's image."""
    lamp = (0.5, 3.0, -6.0)
    axis = _unit([0.3, -1.0, 0.2])
    cases = ((0.1, 1.0, 0.0, 1e-8), (0.1, 0.0, 0.6, 1e-8), (0.1, 1.0, 0.6, 1e-6))
    for sigma_t, albedo, surf_albedo, rtol in cases:
        surfaces = [plane((0, 0, 0), (0, 1, 0), surf_albedo), box((-3, 0, -9), (-1.5, 2, -7), surf_albedo)]
        point_scene = make_scene((0, 1.7, 2), (0, 1.0, -6), [light(lamp, 80.0)], surfaces, sigma_t=sigma_t,
                                 albedo=albedo, width=12, height=8)
        spot_scene = copy.deepcopy(point_scene)
        spot_scene["lights"] = [spot(lamp, axis, 80.0, 90.0, 1.0), spot(lamp, -axis, 80.0, 90.0, 1.0)]
        sc = parse_scene(point_scene)
        mask, _ = smooth_pixels(sc)
        rows, cols = np.nonzero(mask)
        expect = pixel_radiance(sc, rows, cols)
        got = spot_pixel_radiance(parse_spot_scene(spot_scene), rows, cols)
        np.testing.assert_allclose(got, expect, rtol=rtol, atol=1e-300)


@pytest.mark.parametrize("edge", [0.0, 0.3, 1.0])
def test_reference_matches_no_extinction_closed_form(edge):
    """sigma_t = 0 with sigma_s = 1: on the lit interval [lo, hi],
    int (alpha cos theta + beta) / d^2 dx with cos theta = ((x - b)(d.a) - h (m.a)) / d,
    alpha = (1 - q)/(1 - cos A), beta = (q - cos A)/(1 - cos A), is
    alpha [-(d.a)/d - (m.a)(x - b)/(h d)] + beta atan((x - b)/h)/h between the ends."""
    done = 0
    for origin, d, lamp, axis in _random_rays(21, 50):
        sp = make_spot(axis, 40.0, edge)
        lo, hi, meets = lit_interval(origin, d[None, :], lamp, sp, 0.0, 30.0)
        if not meets[0]:
            continue
        fr = ray_frame(origin, d[None, :], lamp, axis)
        b, h, da, ma = float(fr.b[0]), float(fr.h[0]), float(fr.da[0]), float(fr.ma[0])
        alpha = (1.0 - edge) / (1.0 - sp.cos_a)
        beta = (edge - sp.cos_a) / (1.0 - sp.cos_a)

        ends = []
        for x in (float(lo[0]), float(hi[0])):
            dist = math.hypot(h, x - b)
            ends.append(alpha * (-da / dist - ma * (x - b) / (h * dist)) + beta * math.atan((x - b) / h) / h)
        closed = (ends[1] - ends[0]) / (4.0 * math.pi)
        got = spot_airlight(0.0, 1.0, 1.0, origin, d, lamp, sp, 0.0, 30.0)
        assert got == pytest.approx(closed, rel=1e-8)
        done += 1
    assert done >= 10


def test_reference_linear_in_edge_and_continuous_at_90_degrees():
    """The airlight is linear in q (the profile is), and A -> 90 degrees is continuous."""
    for origin, d, lamp, axis in _random_rays(31, 10):
        values = [spot_airlight(0.2, 0.2, 10.0, origin, d, lamp, make_spot(axis, 50.0, q))
                  for q in (0.0, 0.4, 1.0)]
        assert values[1] == pytest.approx(0.6 * values[0] + 0.4 * values[2], rel=1e-8, abs=1e-300)
        near = spot_airlight(0.2, 0.2, 10.0, origin, d, lamp, make_spot(axis, 90.0 - 1e-7, 0.0))
        at = spot_airlight(0.2, 0.2, 10.0, origin, d, lamp, make_spot(axis, 90.0, 0.0))
        assert near == pytest.approx(at, rel=1e-6, abs=1e-300)


def test_reference_profile():
    sp = make_spot((0, 0, 1), 30.0, 0.25)
    c = math.cos(math.radians(30.0))
    assert profile(1.0, sp) == pytest.approx(1.0)
    assert profile(c, sp) == pytest.approx(0.25)
    assert profile(c - 1e-9, sp) == 0.0
    assert profile(0.5 * (1 + c), sp) == pytest.approx(0.25 + 0.75 * 0.5)


# ---- accuracy against the reference -------------------------------------------------------------------

@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("cone_angle", [2.0, 10.0, 30.0, 60.0, 80.0])
def test_cone_angle_and_edge_sweep(cone_angle, backend):
    for edge in (0.0, 0.3, 1.0):
        _check(side_view(cone_angle, edge), backend, f"side view, A = {cone_angle}, q = {edge}")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.001, 0.05, 0.5, 2.0])
def test_sigma_t_sweep(sigma_t, backend):
    """Thick fog shrinks the scene so that the beam stays above 1e-3 of the maximum."""
    scale = min(10.0, 3.0 / sigma_t)
    for cone_angle in (10.0, 45.0):
        _check(side_view(cone_angle, 0.3, sigma_t, scale), backend, f"sigma_t = {sigma_t}, A = {cone_angle}")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("scale", [0.5, 5.0, 50.0, 500.0])
def test_distance(scale, backend):
    _check(side_view(20.0, 0.3, sigma_t=0.2 / scale, scale=scale), backend, f"side view at {scale} m")


@pytest.mark.parametrize("backend", BACKENDS)
def test_per_channel_medium_and_intensity(backend):
    scene = side_view(30.0, 0.3, sigma_t=[0.02, 0.1, 0.5], scale=4.0, intensity=[100.0, 60.0, 30.0],
                      albedo=[1.0, 0.7, 0.4])
    _check(scene, backend, "per-channel medium and intensity")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("view", sorted(VIEWS))
def test_viewing_direction(view, backend):
    _check(VIEWS[view], backend, view)


@pytest.mark.parametrize("backend", BACKENDS)
def test_mirror_cone_stays_dark(backend):
    """Pixels whose visible ray never meets the forward cone (it passes through the mirror
    cone behind the lamp only) get no spot airlight at all."""
    scene = _mirror_cone()
    ss = parse_spot_scene(scene)
    geo = spot_geometry(ss)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)
    _finite_non_negative(image, f"mirror cone [{backend}]")
    dark = ~geo.meets[0] & geo.smooth
    # rays that cross the mirror cone: their midpoint-tested piece lies behind the lamp
    dirs = camera_rays(ss.sc)
    sp = ss.spots[0]
    flipped = make_spot(-sp.axis, sp.cone_angle, sp.edge)
    _, _, in_mirror = lit_interval(ss.sc.position, dirs, ss.sc.lights[0].position, flipped, 0.0, np.inf)
    dark_mirror = dark & in_mirror.reshape(dark.shape)
    assert dark_mirror.sum() >= 20, "fix the scene: too few rays through the mirror cone alone"
    peak = image[geo.meets[0] & geo.smooth].max()
    assert image[dark_mirror].max() <= 1e-6 * peak, (
        f"[{backend}] light in the mirror cone: {image[dark_mirror].max():.3e} (peak {peak:.3e})")


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.05, 0.5])
def test_wall_cuts_beam(sigma_t, backend):
    _check(wall_cuts_beam(sigma_t), backend, f"wall cuts the beam, sigma_t = {sigma_t}")


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
def test_headlights_on_road(backend):
    _check(headlights_on_road(), backend, "headlights on a road with a street lamp")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("edge", [0.0, 0.3, 1.0])
def test_surfaces_lit_by_spot_in_absorbing_medium(edge, backend):
    _check(lit_surfaces_absorbing(edge), backend, f"surfaces lit by a spot, q = {edge}")


@pytest.mark.parametrize("backend", BACKENDS)
def test_half_space_spots_render_as_point_light(backend):
    """Two A = 90, q = 1 spots at one place pointing opposite ways render the point
    light's image, airlight and road alike (the road's glow: the spots' quadrature over
    the beam against the point lamp's G0 table)."""
    lamp = (0.5, 3.0, -6.0)
    axis = _unit([0.3, -1.0, 0.2])
    road = plane((0, 0, 0), (0, 1, 0), 0.5)
    point_scene = make_scene((0, 1.7, 2), (0, 1.0, -6), [light(lamp, 80.0)], [road], sigma_t=0.1)
    spot_scene = copy.deepcopy(point_scene)
    spot_scene["lights"] = [spot(lamp, axis, 80.0, 90.0, 1.0), spot(lamp, -axis, 80.0, 90.0, 1.0)]
    r = get_renderer(backend)
    point_image = np.asarray(r.render(point_scene), dtype=np.float64)
    spot_image = np.asarray(r.render(spot_scene), dtype=np.float64)
    _finite_non_negative(spot_image, f"half-space spots [{backend}]")
    mask, _ = smooth_pixels(parse_scene(point_scene))
    rel = np.abs(spot_image - point_image)[mask] / point_image[mask]
    assert rel.max() <= REL_TOL, f"[{backend}] half-space spots are off the point light by {rel.max():.3e}"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("where", ["inside_beam_on_axis", "inside_beam_off_axis", "outside_beam", "behind"])
def test_lamp_core_radiance(where, backend):
    """Looking straight at a spot's sphere: I(theta_c) / (pi r^2) attenuated, plus the
    airlight in front of it; theta_c is the angle of the camera from the axis (a headlight
    is bright only from inside its beam; outside, the sphere is black but still hides what
    is behind it)."""
    s, axis, cone = np.array([0.0, 1.0, -8.0]), _unit([0.0, 0.0, 1.0]), 30.0
    camera = {"inside_beam_on_axis": (0.0, 1.0, 0.0), "inside_beam_off_axis": (2.0, 1.5, 0.0),
              "outside_beam": (6.0, 1.0, -2.0), "behind": (0.5, 1.0, -16.0)}[where]
    scene = make_scene(camera, s, [spot(s, axis, 50.0, cone, 0.2, 0.1)], [], sigma_t=0.05, albedo=1.0,
                       fov_y=0.01, width=1, height=1)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)
    _finite_non_negative(image, f"core [{backend}]")
    ss = parse_spot_scene(scene)
    tr = trace(ss.sc, camera_rays(ss.sc))
    assert tr.hit_id[0] == LAMP_BASE
    ref = spot_pixel_radiance(ss, [0], [0])[0]
    core = 50.0 * float(profile(_unit(np.asarray(camera) - s) @ axis, ss.spots[0])) / (math.pi * 0.01)
    core *= math.exp(-0.05 * (np.linalg.norm(np.asarray(camera) - s) - 0.1))
    assert ref[0] >= core
    floor = 1e-6 * 50.0 / (math.pi * 0.01)
    assert np.all(np.abs(image[0, 0] - ref) <= REL_TOL * ref + floor), (
        f"{where} [{backend}]: rendered {image[0, 0]}, reference {ref}")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("edge", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("camera", ["outside_aimed_at_centre", "at_the_centre"])
def test_rays_through_the_lamp_centre(camera, edge, backend):
    """Rays through the spot's centre exactly (closest distance h = 0, where the frame
    around the ray is undefined): from a camera outside aimed at the centre (the pixel
    sees the core, I(theta_c) / (pi r^2) attenuated, plus the airlight in front of it,
    about 6 % of the pixel here), and from a camera at the centre looking 30 degrees off
    the axis (the whole ray is lit with the constant profile I(30 deg)). One pixel each,
    reference within 0.5 %."""
    s, axis = np.array([0.0, 1.0, -10.0]), _unit([0.2, 0.0, 1.0])
    if camera == "outside_aimed_at_centre":
        position, target, radius, sigma_t = np.array([3.0, 1.0, -6.0]), s, 1.0, 0.5
    else:
        off_axis = math.radians(30.0)
        side = _unit(np.cross(axis, [0.0, 1.0, 0.0]))
        position, radius, sigma_t = s, 0.5, 0.1
        target = s + math.cos(off_axis) * axis + math.sin(off_axis) * side
    scene = make_scene(position, target, [spot(s, axis, 100.0, 50.0, edge, radius)], [], sigma_t=sigma_t,
                       fov_y=1e-3, width=1, height=1)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)
    _finite_non_negative(image, f"ray through the centre [{backend}]")
    ref = spot_pixel_radiance(parse_spot_scene(scene), [0], [0])[0]
    assert ref[0] > 0
    got = image[0, 0]
    assert np.all(np.abs(got - ref) <= REL_TOL * ref), (
        f"{camera}, q = {edge} [{backend}]: rendered {got[0]:.7e}, reference {ref[0]:.7e} "
        f"({got[0] / ref[0] - 1:+.3e})")


# ---- the two backends agree ----------------------------------------------------------------------------

AGREEMENT_SCENES = {
    **VIEWS,
    "narrow_2deg_q0": side_view(2.0, 0.0),
    "wide_80deg_q1": side_view(80.0, 1.0),
    "thick_fog": side_view(30.0, 0.3, 2.0, 1.5),
    "wall_cuts_beam": wall_cuts_beam(),
    "headlights_on_road": headlights_on_road(),
    "absorbing_lit_surfaces": lit_surfaces_absorbing(0.3),
}


@pytest.mark.parametrize("name", sorted(AGREEMENT_SCENES))
def test_gl_matches_cpu(name):
    """GL and CPU within 0.5 % on every pixel away from edges and lamps that is above 1e-3
    of the image maximum, near-degenerate pixels within 0.5 % of the maximum."""
    scene = AGREEMENT_SCENES[name]
    gl = np.asarray(get_renderer("gl").render(scene), dtype=np.float64)
    cpu = np.asarray(get_renderer("cpu").render(scene), dtype=np.float64)
    _finite_non_negative(gl, f"{name} [gl]")
    _finite_non_negative(cpu, f"{name} [cpu]")
    geo = spot_geometry(parse_spot_scene(scene))
    peak = cpu[geo.smooth].max()
    regular = (geo.smooth & ~geo.degenerate)[:, :, None] & (cpu > DIM_FRACTION * peak)
    assert regular.sum() >= 60
    rel = np.where(regular, np.abs(gl - cpu) / np.where(regular, cpu, 1.0), 0.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    assert rel[worst] <= REL_TOL, f"{name}: GL {gl[worst]:.7e} vs CPU {cpu[worst]:.7e} at {worst}"
    degenerate = geo.smooth & geo.degenerate
    if degenerate.any():
        err = np.abs(gl - cpu)[degenerate].max() / peak
        assert err <= REL_TOL, f"{name}: GL and CPU differ by {err:.3e} of the maximum at degenerate pixels"


# ---- stability ------------------------------------------------------------------------------------------

@st.composite
def spot_scenes(draw):
    grey = draw(st.booleans())
    sig = draw(st.floats(0.0, 2.0)) if grey else [draw(st.floats(0.0, 2.0)) for _ in range(3)]
    alb = draw(st.floats(0.0, 1.0)) if grey else [draw(st.floats(0.0, 1.0)) for _ in range(3)]
    cam = np.array([draw(st.floats(-5, 5)), draw(st.floats(0.1, 5)), draw(st.floats(-5, 5))])
    forward = np.array([draw(st.floats(-1, 1)), draw(st.floats(-0.5, 0.5)), draw(st.floats(-1, 1))])
    if np.linalg.norm(forward) < 1e-3 or abs(_unit(forward)[1]) > 0.95:
        forward = np.array([0.0, 0.0, -1.0])
    forward = _unit(forward)
    lights = []
    for _ in range(draw(st.integers(1, 3))):
        radius = draw(st.floats(0.01, 1.0))
        direction = [draw(st.floats(-1, 1)) for _ in range(3)]
        if np.linalg.norm(direction) < 1e-3:
            direction = [0.0, -1.0, 0.0]
        where = draw(st.integers(0, 4))
        if where == 0:  # the camera inside this lamp's sphere
            pos = cam + draw(st.floats(0.0, 0.95)) * radius * _unit(direction)
        elif where == 1:  # the camera on (or next to) the cone's axis or wall
            axis = _unit(direction)
            pos = cam - draw(st.floats(0.5, 50.0)) * axis
        else:
            away = [draw(st.floats(-1, 1)) for _ in range(3)]
            away = _unit(away) if np.linalg.norm(away) > 1e-3 else np.array([0.0, 0.0, -1.0])
            pos = cam + 10.0 ** draw(st.floats(-1.0, 3.0)) * away
        aim = [draw(st.floats(-1, 1)) for _ in range(3)]
        if np.linalg.norm(aim) < 1e-3:
            aim = [0.0, -1.0, 0.0]
        lights.append(spot(pos, aim, draw(st.floats(0.0, 1e4)), draw(st.floats(0.01, 90.0)),
                           draw(st.sampled_from([0.0, 1.0, draw(st.floats(0.0, 1.0))])), radius))
    if draw(st.booleans()):
        lights.append(light(cam + 10.0 ** draw(st.floats(-1.0, 2.0)) * np.array([0.3, 0.5, -0.8]),
                            draw(st.floats(0.0, 1e3))))
    surfaces = [plane((0, 0, 0), (0, 1, 0), draw(st.floats(0.0, 1.0)))]
    for _ in range(draw(st.integers(0, 2))):
        away = [draw(st.floats(-1, 1)) for _ in range(3)]
        away = _unit(away) if np.linalg.norm(away) > 1e-3 else np.array([1.0, 0.0, 0.0])
        centre = cam + (10.0 ** draw(st.floats(-0.5, 2.0))) * away
        if draw(st.booleans()):
            surfaces.append(box(centre - 0.5, centre + 0.5, draw(st.floats(0, 1))))
        else:
            surfaces.append(sphere(centre, 10.0 ** draw(st.floats(-1, 1)), draw(st.floats(0, 1))))
    return make_scene(cam, cam + forward, lights, surfaces, sigma_t=sig, albedo=alb,
                      fov_y=draw(st.floats(10.0, 120.0)), width=24, height=16,
                      cull_fraction=draw(st.sampled_from([0.0, None])))


# Found by CI: the camera and a 5-degree spot on a sphere's surface, the sphere lit by
# the spot's glow (a 90-degree receiver cone through the spot's centre gave 0/0).
SPOT_ON_A_SPHERE = {
    "film": {"width": 24, "height": 16},
    "camera": {"position": [1.0, 1.0, 0.0], "look_at": [1.0, 1.0, -1.0], "up": [0.0, 1.0, 0.0],
               "fov_y": 10.0},
    "lights": [{"type": "spot", "position": [1.0, 1.0, 0.0], "direction": [0.0, 0.0, -1.0], "intensity": 1.0,
                "cone_angle": 5.0, "edge": 0.0, "radius": 0.96875}],
    "surfaces": [{"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0], "albedo": 0.0},
                 {"type": "sphere", "center": [2.0, 1.0, 0.0], "radius": 1.0, "albedo": 1.0}],
    "medium": {"sigma_t": 1.0, "albedo": 1.0},
    "quality": {"cull_fraction": 0.0},
}


@pytest.mark.slow
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=spot_scenes())
@example(scene=SPOT_ON_A_SPHERE)
def test_random_spot_scenes_are_finite_and_non_negative(scene):
    """Random valid scenes with spots (any cone angle in (0, 90], q in [0, 1], some around
    the camera, some aimed at it), a point lamp sometimes, fog, surfaces: no NaN, no Inf,
    no negative radiance, on every available backend."""
    import airlight

    for backend in airlight.available_backends():
        image = np.asarray(get_renderer(backend).render(scene))
        assert image.shape == (16, 24, 3)
        _finite_non_negative(image, f"[{backend}]")


WALL_VIEWS = {  # directions of the camera, relative to (axis, outward normal of the wall)
    "across_the_beam": (0.0, -1.0),
    "along_the_axis": (1.0, 0.0),
    "back_towards_lamp": (-1.0, -0.4),
    "out_of_the_beam": (0.3, 1.0),
}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("edge", [0.0, 0.3])
@pytest.mark.parametrize("view", sorted(WALL_VIEWS))
def test_camera_crossing_cone_wall_is_continuous(view, edge, backend):
    """The camera moved in 0.25 mm steps across a cone wall, 10 m from the lamp (one
    pixel, fixed direction): the value matches the reference (0.5 %, or 1e-4 of the
    sweep's maximum where the reference is that small) and changes smoothly (no step
    larger than 4x the steps around it), whether the ray enters the cone later, starts
    inside it, or leaves it."""
    cone = 30.0
    s = np.array([0.0, 2.0, 0.0])
    axis = _unit([0.1, 0.0, -1.0])
    side = _unit(np.cross(axis, [0.0, 1.0, 0.0]))  # perpendicular to the axis
    # a point on the wall 10 m down the axis, and the wall's outward normal there
    t = math.radians(cone)
    on_wall = s + 10.0 * axis + 10.0 * math.tan(t) * side
    normal = _unit(math.cos(t) * side - math.sin(t) * axis)
    a, n = WALL_VIEWS[view]
    direction = _unit(a * axis + n * normal + 0.05 * np.array([0.0, 1.0, 0.0]))
    offsets = np.linspace(-0.01, 0.01, 81)
    beam = [spot(s, axis, 100.0, cone, edge)]
    scenes = [make_scene(on_wall + o * normal, on_wall + o * normal + 100.0 * direction, beam, [],
                         sigma_t=0.1, fov_y=1e-3, width=1, height=1) for o in offsets]
    r = get_renderer(backend)
    got = np.array([float(r.render(sc)[0, 0, 0]) for sc in scenes])
    assert np.all(np.isfinite(got)) and np.all(got >= 0)
    ref = np.array([spot_pixel_radiance(parse_spot_scene(sc), [0], [0])[0, 0] for sc in scenes])
    label = f"{view}, q = {edge} [{backend}]"
    peak = ref.max()
    assert peak > 0
    bad = np.abs(got - ref) > REL_TOL * ref + 1e-4 * peak
    assert not bad.any(), f"{label}: offsets {offsets[bad]}: rendered {got[bad]}, reference {ref[bad]}"
    _no_jumps(got, label, floor=1e-5 * peak)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("look", ["along_axis", "sideways", "back"])
@pytest.mark.parametrize("offset", [0.0, 0.2, 0.45])
def test_camera_inside_spot_sphere(offset, look, backend):
    """The camera inside a spot's sphere (radius 0.5), `offset` metres from its centre:
    no NaN or Inf, the lamp's own core is not seen, and the fog counts from where each
    ray leaves the sphere (reference within 0.5 %)."""
    s, axis = np.array([0.0, 1.5, 0.0]), _unit([0.0, -0.2, -1.0])
    cam = s + offset * _unit([1.0, 0.5, 0.3])
    target = {"along_axis": cam + axis, "sideways": cam + [1.0, 0.0, -0.3], "back": cam - axis}[look]
    scene = make_scene(cam, target, [spot(s, axis, 100.0, 40.0, 0.3, 0.5), light((2, 3, -6), 50.0)],
                       [plane((0, 0, 0), (0, 1, 0), 0.3)], sigma_t=0.1, albedo=1.0, fov_y=90.0, width=24,
                       height=16)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)
    _finite_non_negative(image, f"camera inside a spot [{backend}]")
    ss = parse_spot_scene(scene)
    other_lamp = subpixel_core_pixels(ss.sc, [np.array([2.0, 3.0, -6.0])])  # the point lamp: below a pixel
    assert image[~other_lamp].max() < 100.0 / (math.pi * 0.25), \
        "the camera sees the core of the lamp it is inside"
    geo = spot_geometry(ss, lamp_gap=0.0)
    ok = geo.smooth & ~geo.degenerate
    rows, cols = np.nonzero(ok)
    pick = np.random.default_rng(1).choice(len(rows), size=min(30, len(rows)), replace=False)
    rows, cols = rows[pick], cols[pick]
    ref = spot_pixel_radiance(ss, rows, cols)
    got = image[rows, cols]
    use = ref > DIM_FRACTION * ref.max()
    assert use.sum() >= 30
    bad = np.abs(got - ref) > REL_TOL * ref
    bad &= use
    assert not bad.any(), (f"camera inside a spot [{backend}]: {int(bad.sum())} values off; rendered "
                           f"{got[bad][:4]}, reference {ref[bad][:4]}")


@pytest.mark.parametrize("backend", BACKENDS)
def test_q0_edge_fades_to_zero_on_a_wall(backend):
    """q = 0 in an absorbing medium: a row of 241 pixels across the edge of the lit disc
    on a wall. The direct light falls linearly to zero at the edge: within 0.5 % of the
    reference where above 1 % of the disc's maximum, within 1e-4 of it elsewhere, zero
    beyond the edge, and no jumps."""
    s, axis, cone = np.array([0.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.0]), 20.0
    radius_on_wall = 10.0 * math.tan(math.radians(cone))
    # the camera looks at the wall point on the disc's edge from 5 m in front
    edge_point = np.array([radius_on_wall, 0.0, -10.0])
    # a 241 x 1 film spanning +-0.3 m around the edge point (fov_y is one pixel's height)
    fov_y = 2.0 * math.degrees(math.atan(0.3 / 5.0 / 241))
    scene = make_scene(edge_point + [0.0, 0.0, 5.0], edge_point, [spot(s, axis, 100.0, cone, 0.0)],
                       [plane((0, 0, -10.0), (0, 0, 1), 0.8)], sigma_t=0.05, albedo=0.0, fov_y=fov_y,
                       width=241, height=1)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)[0, :, 0]
    _finite_non_negative(image, f"q = 0 edge on a wall [{backend}]")
    ss = parse_spot_scene(scene)
    ref = spot_pixel_radiance(ss, np.zeros(241, dtype=int), np.arange(241), airlight_on=False)[:, 0]
    centre = 100.0 * 0.8 / math.pi / 125.0  # order of the disc's brightness
    assert ref[0] > 0 and ref[-1] == 0.0
    big = ref > 1e-2 * ref.max()
    assert big.sum() >= 20
    assert np.all(np.abs(image - ref)[big] <= REL_TOL * ref[big])
    assert np.all(np.abs(image - ref)[~big] <= 1e-4 * ref.max()), "q = 0 edge: not fading to zero"
    assert np.all(np.diff(image) <= 1e-6 * centre), "q = 0 edge: the brightness rises towards the edge"
    _no_jumps(image, f"q = 0 edge on a wall [{backend}]", floor=1e-6 * ref.max())


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("edge", [0.0, 0.3])
def test_beam_silhouette_fades_smoothly(edge, backend):
    """A row of 241 pixels sweeping across the silhouette of a beam seen from the side
    (q = 0: the airlight goes to zero like depth^1.5; q = 0.3: like depth^0.5): within
    0.5 % of the reference where well inside, within 0.5 % of the row's maximum
    everywhere, zero outside, and no jumps."""
    s, axis, cone = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), 15.0
    # the camera 10 m from the axis, looking at the upper wall of the beam 10 m from the lamp
    wall = np.array([10.0, 10.0 * math.tan(math.radians(cone)), 0.0])
    scene = make_scene(wall + [0.0, 0.0, 10.0], wall, [spot(s, axis, 100.0, cone, edge)], [], sigma_t=0.1,
                       fov_y=2.0 * math.degrees(math.atan(0.05)), width=3, height=241)
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)[:, 1, 0]
    _finite_non_negative(image, f"silhouette [{backend}]")
    ss = parse_spot_scene(scene)
    rows = np.arange(241)
    ref = spot_pixel_radiance(ss, rows, np.ones(241, dtype=int))[:, 0]
    peak = ref.max()
    assert (ref == 0).sum() >= 20 and (ref > 0.1 * peak).sum() >= 20
    regular = ~spot_geometry(ss).degenerate[:, 1] & (ref > 0.05 * peak)
    assert regular.sum() >= 20
    assert np.all(np.abs(image - ref)[regular] <= REL_TOL * ref[regular])
    assert np.all(np.abs(image - ref) <= REL_TOL * peak)
    assert np.all(image[ref == 0] <= 1e-6 * peak)
    _no_jumps(image, f"silhouette, q = {edge} [{backend}]", floor=1e-5 * peak)
