"""The road glows around each lamp: a surface in fog receives, besides the direct light,
the light scattered once by the fog around it (effects/lamp_airlight/physics.md, "surfaces lit
through fog"), unshadowed, even where the lamp is below the surface's horizon
(theta_s > 90 degrees). Rendered pixels against airlight_reference (direct + glow for
the surface, plus the airlight in front of it), within 0.5 %."""

from __future__ import annotations

import math

import numpy as np
import pytest
from airlight_reference import (
    REL_TOL,
    box,
    camera_rays,
    compare,
    get_renderer,
    glow_hemisphere_bruteforce,
    glow_unit,
    light,
    make_scene,
    parse_scene,
    pixel_radiance,
    plane,
    reference_samples,
    surface_radiance,
    trace,
)

BACKENDS = ("cpu", "gl")
SIGMAS = (0.01, 0.1, 1.0)
HEIGHTS = (1.0, 5.0, 20.0)
INTENSITY = [100.0, 80.0, 60.0]


# ---- the reference's own quadrature --------------------------------------------------------------

@pytest.mark.parametrize("sigma_t,dist,theta_deg", [
    (0.01, 1.0, 0.0), (0.1, 5.0, 30.0), (1.0, 5.0, 60.0), (1.0, 20.0, 89.0), (1.0, 20.0, 90.0),
    (0.1, 20.0, 95.0), (1.0, 3.0, 135.0), (1.0, 50.0, 180.0), (0.001, 1.0, 120.0)])
def test_glow_reference_converges(sigma_t, dist, theta_deg):
    """Doubling the Gauss-Legendre nodes of the reference changes the glow by < 1e-7."""
    c = math.cos(math.radians(theta_deg))
    coarse = glow_unit(sigma_t, dist, c)
    fine = glow_unit(sigma_t, dist, c, nodes=48)
    assert coarse > 0
    assert abs(coarse - fine) <= 1e-7 * fine


@pytest.mark.parametrize("sigma_t,dist,theta_deg", [(0.1, 5.0, 120.0), (1.0, 3.0, 150.0)])
def test_glow_reference_matches_plain_hemisphere_rule(sigma_t, dist, theta_deg):
    """The reduction to one polar integral around the light direction agrees with a
    plain product rule over the hemisphere around the normal (lamp below the horizon,
    where the latter converges)."""
    c = math.cos(math.radians(theta_deg))
    assert glow_hemisphere_bruteforce(sigma_t, dist, c, 16, 32) == pytest.approx(glow_unit(sigma_t, dist, c),
                                                                                 rel=1e-6)


# ---- a road under a lamp -------------------------------------------------------------------------------

def road(sigma_t: float, height: float, road_albedo=0.4) -> dict:
    """A lamp `height` metres above a road, seen from 2 m away at eye height, with a
    wall beside the road whose face towards the camera looks away from the lamp."""
    return make_scene(
        (2.5, 1.5, 2.0), (0.0, 0.0, -3.0),
        [light((0.0, height, -3.0), INTENSITY)],
        [plane((0, 0, 0), (0, 1, 0), road_albedo), box((1.0, 0.0, -8.0), (1.2, 2.5, -4.0), 0.6)],
        sigma_t=sigma_t, albedo=1.0, fov_y=70.0)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("height", HEIGHTS)
@pytest.mark.parametrize("sigma_t", SIGMAS)
def test_road_glow(sigma_t, height, backend):
    """Full pixel radiance of the road and wall against the reference."""
    scene = road(sigma_t, height)
    samples = reference_samples(scene, n=24)
    compare(get_renderer(backend).render(scene), samples,
            label=f"road, sigma_t={sigma_t}, lamp height {height} m [{backend}]")


def _check_surface_term(scene: dict, dark: dict, backend: str, label: str, min_values: int = 10) -> None:
    """The surfaces' own radiance (direct + glow), isolated from the airlight in front
    of them: `dark` is `scene` with every surface albedo 0, so the difference of the two
    renders is the surfaces' radiance times the transmittance to the camera."""
    samples = reference_samples(scene, n=24)
    r = get_renderer(backend)
    bright = np.asarray(r.render(scene), dtype=np.float64)[samples.rows, samples.cols]
    black = np.asarray(r.render(dark), dtype=np.float64)[samples.rows, samples.cols]
    sc = parse_scene(scene)
    tr = trace(sc, camera_rays(sc, samples.rows, samples.cols))
    checked = 0
    for k in np.nonzero((tr.hit_id >= 0) & (tr.hit_id < 1_000_000))[0]:
        albedo = sc.surfaces[tr.hit_id[k] // 8].albedo
        leaving = surface_radiance(sc, tr.point[k], tr.normal[k], albedo, tr.lit[:, k])
        expected = leaving * np.exp(-sc.sigma_t * tr.t_hit[k])
        got = bright[k] - black[k]
        # float32 rounding of the two renders, in which the airlight may dominate
        allowance = REL_TOL * expected + 4 * np.spacing(np.float32(bright[k].max()))
        use = expected > samples.threshold
        bad = use & (np.abs(got - expected) > allowance)
        assert not bad.any(), (f"{label}: surface term at pixel ({samples.rows[k]}, {samples.cols[k]}), "
                               f"hit id {tr.hit_id[k]}: rendered {got}, reference {expected} [{backend}]")
        checked += int(use.sum())
    assert checked >= min_values


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("height", HEIGHTS)
@pytest.mark.parametrize("sigma_t", SIGMAS)
def test_road_surface_term(sigma_t, height, backend):
    _check_surface_term(road(sigma_t, height), road(sigma_t, height, 0.0), backend,
                        f"road, sigma_t={sigma_t}, lamp height {height} m")


def shadowed_road(sigma_t: float, height: float, albedo=0.5) -> dict:
    """A wide roof 0.25 m under the lamp shadows the whole road: the road and the roof's
    underside (lamp behind it, theta_s near 180 degrees) are lit by the glow alone."""
    eye = min(1.5, 0.5 * height)
    return make_scene(
        (0.0, eye, 3.0), (0.0, 0.0, -4.0),
        [light((0.0, height, -3.0), INTENSITY)],
        [plane((0, 0, 0), (0, 1, 0), albedo), box((-60, height - 0.3, -60), (60, height - 0.25, 60), albedo)],
        sigma_t=sigma_t, albedo=1.0, fov_y=80.0)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("height", HEIGHTS)
@pytest.mark.parametrize("sigma_t", SIGMAS)
def test_shadowed_road_glow_only(sigma_t, height, backend):
    """Surfaces in the lamp's shadow glow all the same (the glow is not shadowed): full
    pixels, and the surface term alone, against the reference."""
    scene = shadowed_road(sigma_t, height)
    samples = reference_samples(scene, n=24)
    sc = parse_scene(scene)
    assert not trace(sc, camera_rays(sc, samples.rows, samples.cols)).lit.any(), "a sampled point is lit"
    compare(get_renderer(backend).render(scene), samples,
            label=f"shadowed road, sigma_t={sigma_t}, lamp height {height} m [{backend}]")
    _check_surface_term(scene, shadowed_road(sigma_t, height, 0.0), backend,
                        f"shadowed road, sigma_t={sigma_t}, lamp height {height} m")


# ---- the glow across the surface's horizon ----------------------------------------------------------

def probe(sigma_t: float, dist: float, theta_s_deg: float, albedo=0.5) -> dict:
    """A 1x1 image of one point of a plane, seen from 5 cm along its normal, lit by a
    lamp at `dist` metres at angle theta_s from the normal."""
    th = math.radians(theta_s_deg)
    return make_scene((0.0, 0.05, 0.0), (0.0, 0.0, 0.0),
                      [light((dist * math.sin(th), dist * math.cos(th), 0.0), 100.0)],
                      [plane((0, 0, 0), (0, 1, 0), albedo)],
                      sigma_t=sigma_t, albedo=1.0, fov_y=1.0, width=1, height=1, up=(0.0, 0.0, -1.0))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t,dist", [(0.1, 5.0), (1.0, 3.0), (1.0, 10.0), (1.0, 30.0)])
def test_glow_across_the_horizon(sigma_t, dist, backend):
    """theta_s from 0 to 180 degrees, finely around 90 where the direct light ends and
    the glow alone lights the surface: each pixel within 0.5 % of the reference."""
    r = get_renderer(backend)
    failures = []
    angles = (0, 30, 60, 80, 85, 88, 89, 90, 91, 92, 95, 100, 120, 150, 180)
    for theta in angles:
        scene = probe(sigma_t, dist, theta)
        got = float(r.render(scene)[0, 0, 0])
        ref = float(pixel_radiance(parse_scene(scene), [0], [0])[0, 0])
        if not abs(got - ref) <= REL_TOL * ref:
            failures.append(f"theta_s={theta}: rendered {got:.6e}, reference {ref:.6e} "
                            f"({got / ref - 1:+.2%})")
    assert not failures, f"sigma_t={sigma_t}, D={dist} m [{backend}]:\n" + "\n".join(failures)
