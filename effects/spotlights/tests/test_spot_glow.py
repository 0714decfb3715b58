"""The light a spotlight scatters once in the fog onto a surface: the spot's surface glow
(effects/spotlights/physics.md with the glow of section 1, "surfaces lit through fog"). A Lambertian
point P (unit normal n) receives, per channel,

    E_glow(P) = sigma_s / (4 pi) int I(theta_y) exp(-sigma_t |y - S|) / |y - S|^2
                                    exp(-sigma_t |y - P|) max(n.(y - P), 0) / |y - P|^3 dV(y)

over all space (no occlusion; the lamp's sphere is fog like the rest), and leaves
albedo / pi * E_glow next to the spot's direct light, attenuated to the camera as usual.

The reference is spot_reference.spot_glow_unit: the hemisphere integral about P of the
spot's airlight along the rays leaving P, in polar coordinates about the direction to the
lamp (not the renderer's quadrature over the beam's directions with a table for the
radial integral). Its own tests here: doubling its nodes changes it by < 1e-6 relative
over in-beam, out-of-beam, near-wall, mirror-cone, lamp-behind-the-surface, lamp-a-few-cm
and grazing cases, sigma_t 0.001 to 2; two opposite 90-degree q = 1 spots are the point
lamp of airlight_reference.glow_unit (an independent 1-D reduction) within 1e-7; the ray
integrals equal spot_reference's view-ray airlight (lit intervals by bisection, x-space
quadrature) within 1e-8; and scipy nquad of the volume integral in spherical coordinates
about the lamp agrees within 1e-7 (for P in the beam with q = 1 through the point lamp's
glow minus the fog outside the cone).

Renderer against the reference (both backends, GL skipped where EGL is missing): a spot
above a large road (albedo 0.5, nothing else), the camera looking at the road; pixels
sampled inside the lit ellipse, near its edge on both sides (not within a pixel of it when
q > 0, where the direct light jumps), just outside and far outside; every channel value
above 1e-3 of the sampled maximum within 0.5 % (as for the spot airlight), and the surface
term alone (render minus render with a black road) within 0.5 % where it is above that
threshold. Sweeps: cone angle 2-90 degrees with q 0, 0.5, 1; sigma_t 0.001-2 (medium albedo
0.9); lamp heights 0.05-10 m; a coloured medium; the road outside the beam (glow and
airlight only); the lamp below the road shining up through it (the road's upper side sees
only the fog above it). GL and CPU within 0.5 %. Random spot-and-road scenes are finite and
non-negative; the road's radiance is continuous as the lamp comes down to the road and
across the lit ellipse's edge (q = 0). Culling is off (cull_fraction 0).
"""

from __future__ import annotations

import copy
import json
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from airlight_reference import (
    LAMP_BASE,
    REL_TOL,
    camera_rays,
    get_renderer,
    glow_hemisphere_bruteforce,
    glow_unit,
    make_scene,
    plane,
    trace,
    transmittance,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from image_checks import finite_non_negative as _finite_non_negative
from image_checks import no_jumps as _no_jumps
from scipy.ndimage import distance_transform_edt
from spot_reference import (
    GLOW_NODES,
    ISOTROPIC,
    SpotScene,
    direction_profile,
    glow_directions,
    glow_frame,
    glow_ray_units,
    make_spot,
    parse_spot_scene,
    spot,
    spot_direct,
    spot_geometry,
    spot_glow_irradiance,
    spot_glow_radiance,
    spot_glow_unit,
    spot_glow_volume_nquad,
    spot_pixel_radiance,
    spot_unit_logs,
)

BACKENDS = ("cpu", "gl")
DIM_FRACTION = 1e-3  # values below this fraction of the sampled maximum are not compared


def _unit(v: Any) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


# ---- the reference itself (no renderer) ----------------------------------------------------------------

UP = np.array([0.0, 1.0, 0.0])


def _tan(degrees: float) -> float:
    return math.tan(math.radians(degrees))


# name: (sigma_t, lamp position, axis, cone angle, q, surface point, normal); the road is y = 0
GLOW_CASES: dict[str, tuple[float, Any, Any, float, float, Any, Any]] = {
    "in_beam_on_axis": (0.04, (0, 4, 0), (0, -1, 0), 30.0, 0.0, (0, 0, 0), UP),
    "in_beam_off_axis_thick": (1.0, (0, 2, 0), (0.2, -1, 0.1), 40.0, 0.5, (0.6, 0, 0.3), UP),
    "in_beam_near_wall": (0.2, (0, 3, 0), (0, -1, 0), 30.0, 1.0, (3 * _tan(29.5), 0, 0), UP),
    "on_the_wall": (0.1, (0, 2, 0), (0, -1, 0), 35.0, 0.5, (2 * _tan(35.0), 0, 0), UP),
    "just_outside_wall_q0": (0.2, (0, 3, 0), (0, -1, 0), 30.0, 0.0, (3 * _tan(30.5), 0, 0), UP),
    "just_outside_wall_q05": (0.04, (0, 3, 0), (0, -1, 0), 30.0, 0.5, (3 * _tan(31.0), 0, 0), UP),
    "far_outside": (0.04, (0, 3, 0), (0.1, -1, 0), 20.0, 0.5, (9.0, 0, -4.0), UP),
    "narrow_beam_far_outside": (0.01, (0, 10, 0), (0.05, -1, 0), 2.0, 0.0, (6.0, 0, 2.0), UP),
    "behind_the_spot_mirror_cone": (0.1, (0, 2, 0), (0, 1, 0.1), 25.0, 0.5, (0.1, 0, 0), UP),
    "aimed_up_wide": (0.04, (0, 1, 0), (0.3, 1, 0), 80.0, 1.0, (2.0, 0, 1.0), UP),
    "lamp_3cm_above_aimed_down": (0.04, (0, 0.03, 0), (0.2, -1, 0), 30.0, 0.5, (0.2, 0, 0.05), UP),
    "lamp_3cm_above_along_road": (0.2, (0, 0.03, 0), (1, -0.05, 0), 10.0, 0.0, (1.5, 0, 0.1), UP),
    "lamp_behind_surface_in_beam": (0.2, (0, -1, 0), (0.2, 1, 0), 40.0, 0.5, (0.3, 0, 0), UP),
    "lamp_behind_surface_outside_beam": (0.5, (0, -1, 0), (0.2, 1, 0), 20.0, 1.0, (2.5, 0, 0), UP),
    "grazing_normal": (0.04, (0, 2, 0), (0, -1, 0.2), 45.0, 0.5, (0.5, 0, 0), _unit([1, 0.02, 0.3])),
    "thin_fog_90deg": (0.001, (0, 2, 0), (0.1, -1, 0), 90.0, 0.0, (3.0, 0, 0), UP),
    "thick_fog_far_in_beam": (2.0, (0, 5, 0), (0, -1, 0), 60.0, 1.0, (1.0, 0, 0), UP),
    "axis_across_the_direction_to_P": (0.2, (0, 1.0, 0), (1, 0.27, 0), 80.0, 1.0, (0.3, 0, 0.1), UP),
}


def _glow_case(name: str, nodes: tuple[int, int, int] = GLOW_NODES) -> float:
    sigma, position, axis, cone, edge, point, normal = GLOW_CASES[name]
    return spot_glow_unit(sigma, position, make_spot(axis, cone, edge), point, normal, nodes)


@pytest.mark.parametrize("name", sorted(GLOW_CASES))
def test_reference_glow_converges(name):
    """Doubling every node count of the reference (alpha, beta, along the ray) changes the
    glow by < 1e-6 relative; the glow is finite and positive (also with the lamp behind the
    surface: the fog in front of it is lit where the beam crosses). The default rule takes
    well under a second (about 30 ms typically)."""
    start = time.perf_counter()
    value = _glow_case(name)
    elapsed = time.perf_counter() - start
    fine = _glow_case(name, tuple(2 * k for k in GLOW_NODES))  # type: ignore[arg-type]
    assert math.isfinite(value) and value > 0, f"{name}: glow {value}"
    assert abs(value - fine) <= 1e-6 * fine, f"{name}: {value:.12e} vs doubled nodes {fine:.12e}"
    assert elapsed < 1.0, f"{name}: {elapsed:.2f} s"


@pytest.mark.parametrize("sigma_t", [0.001, 0.04, 0.5, 2.0])
@pytest.mark.parametrize("theta_deg", [0.0, 40.0, 89.0, 120.0, 170.0])
def test_reference_two_half_space_spots_are_a_point_lamp(theta_deg, sigma_t):
    """I(theta) = I0 on the forward half-space (A = 90 degrees, q = 1) plus the same spot
    pointing the other way is an isotropic point lamp: the two glows add up to the point
    lamp's glow, 4 pi * airlight_reference.glow_unit (a 1-D reduction about the lamp
    direction with the azimuth in closed form), within 1e-7, for the lamp above and below
    the surface's horizon, the axis in a general direction."""
    dist = 2.5
    th = math.radians(theta_deg)
    position = dist * np.array([math.sin(th), math.cos(th), 0.0])
    axis = _unit([0.3, -0.5, 0.8])
    total = sum(spot_glow_unit(sigma_t, position, make_spot(a, 90.0, 1.0), (0, 0, 0), UP)
                for a in (axis, -axis))
    point = 4.0 * math.pi * glow_unit(sigma_t, dist, math.cos(th), nodes=48)
    assert total == pytest.approx(point, rel=1e-7)
    if theta_deg > 90.0:  # the plain product rule over the hemisphere converges there
        brute = glow_hemisphere_bruteforce(sigma_t, dist, math.cos(th), 16, 32)
        assert total == pytest.approx(4.0 * math.pi * brute, rel=1e-6)


@pytest.mark.parametrize("name", ["in_beam_off_axis_thick", "just_outside_wall_q05",
                                  "behind_the_spot_mirror_cone", "lamp_3cm_above_aimed_down",
                                  "lamp_behind_surface_in_beam", "thin_fog_90deg",
                                  "axis_across_the_direction_to_P"])
def test_reference_ray_integrals_are_the_spot_airlight(name):
    """The innermost integral (closed-form lit arc in the angle at the lamp, exponent
    break points, graded towards infinity) is the spot's airlight along the ray leaving P,
    as spot_reference's view-ray airlight computes it (lit interval by bisection, adaptive
    quadrature in another variable): 200 random directions of the hemisphere and the
    sphere, within 1e-8 relative (1e-12 of the largest where the airlight is tiny)."""
    sigma, position, axis, cone, edge, point, normal = GLOW_CASES[name]
    sp = make_spot(axis, cone, edge)
    fr = glow_frame(position, sp, point, normal)
    rng = np.random.default_rng(len(name))
    alpha = np.concatenate([np.arccos(rng.uniform(-1.0, 1.0, 150)), 10.0 ** rng.uniform(-4, -0.5, 50)])
    beta = rng.uniform(-math.pi, math.pi, len(alpha))
    got = math.exp(-sigma * fr.dist) / (fr.dist * np.sin(alpha)) * glow_ray_units(fr, sigma, alpha, beta)
    dirs = glow_directions(fr, alpha, beta)
    expect = np.exp(spot_unit_logs(sigma, point, dirs, position, sp, 0.0, math.inf))
    assert (expect > 0).sum() >= 20
    err = np.abs(got - expect)
    assert np.all(err <= 1e-8 * expect + 1e-12 * expect.max()), (
        f"{name}: worst at alpha {alpha[np.argmax(err)]:.4g}: {got[np.argmax(err)]:.10e} vs "
        f"{expect[np.argmax(err)]:.10e}")


NQUAD_OUTSIDE = {  # P outside the beam: the integrand is bounded
    "beside_the_beam": (0.1, (0, 3, 0), _unit([0.3, -1, 0.1]), 30.0, 0.5, (4, 0, 0), UP),
    "lamp_behind_the_surface": (0.2, (0, -1, 0), _unit([0.2, 1, 0]), 40.0, 0.5, (3, 0, 0), UP),
    "lamp_5cm_above": (0.05, (0, 0.05, 0), _unit([1, -1, 0]), 20.0, 0.5, (0.3, 0, 0.2), UP),
}


@pytest.mark.parametrize("name", sorted(NQUAD_OUTSIDE))
def test_reference_matches_volume_nquad_outside_the_beam(name):
    """For P outside the beam the reference equals scipy nquad of the volume integral in
    spherical coordinates about the lamp (polar axis: the spot's axis), within 1e-7."""
    sigma, position, axis, cone, edge, point, normal = NQUAD_OUTSIDE[name]
    sp = make_spot(axis, cone, edge)
    expect = spot_glow_volume_nquad(sigma, position, sp, point, normal, ISOTROPIC,
                                    (0.0, math.radians(cone)), eps=1e-8)
    assert expect > 0
    assert spot_glow_unit(sigma, position, sp, point, normal) == pytest.approx(expect, rel=1e-7)


@pytest.mark.parametrize("sigma_t,point", [(1.0, (0.5, 0.0, 0.2)), (0.1, (1.0, 0.0, 0.0))])
def test_reference_matches_volume_nquad_in_the_beam(sigma_t, point):
    """For P in the beam (q = 1) the integrand peaks at P, so the check goes through the
    complement: the spot's glow is the isotropic lamp's (airlight_reference.glow_unit)
    minus the glow of the fog outside the cone, which nquad integrates in spherical
    coordinates about the lamp (bounded there). Within 1e-7."""
    position, axis, cone = np.array([0.0, 3.0, 0.0]), _unit([0.3, -1, 0.1]), 60.0 if sigma_t > 0.5 else 30.0
    sp = make_spot(axis, cone, 1.0)
    assert float(direction_profile(sp, position, np.asarray(point, dtype=np.float64))) > 0
    rel = position - np.asarray(point)
    dist = float(np.linalg.norm(rel))
    outside = spot_glow_volume_nquad(sigma_t, position, sp, point, UP, ISOTROPIC,
                                     (math.radians(cone), math.pi), uniform=True, eps=1e-8)
    expect = 4.0 * math.pi * glow_unit(sigma_t, dist, float(rel @ UP) / dist, nodes=48) - outside
    assert spot_glow_unit(sigma_t, position, sp, point, UP) == pytest.approx(expect, rel=1e-7)


def test_reference_glow_is_continuous_and_linear_in_edge():
    """The glow is linear in q (the profile is), tends to a limit as the lamp comes down to
    the surface (3 cm to 2 mm above it: steps shrinking with the height) and is continuous
    across the cone's wall (q = 0 and q = 0.5: no step above 3x the median step)."""
    position, axis = np.array([0.0, 2.0, 0.0]), _unit([0.1, -1.0, 0.0])
    values = [spot_glow_unit(0.1, position, make_spot(axis, 35.0, q), (0.4, 0, 0.3), UP)
              for q in (0.0, 0.4, 1.0)]
    assert values[1] == pytest.approx(0.6 * values[0] + 0.4 * values[2], rel=1e-10)
    heights = np.geomspace(0.03, 0.002, 12)
    low_spot = make_spot((1.0, -0.3, 0.0), 30.0, 0.5)
    lows = np.array([spot_glow_unit(0.1, (0.0, h, 0.0), low_spot, (0.5, 0, 0), UP) for h in heights])
    assert np.all(np.isfinite(lows)) and np.all(lows > 0)
    steps = np.abs(np.diff(lows))  # the lamp's height shrinks by a constant factor: so do the steps
    assert np.all(steps[1:] <= steps[:-1]) and steps[-1] <= 0.01 * lows[-1], f"lamp coming down: {lows}"
    wall = 2.0 * math.tan(math.radians(35.0))
    for q in (0.0, 0.5):
        xs = wall + np.linspace(-1e-3, 1e-3, 9)
        across = np.array([spot_glow_unit(0.1, (0.0, 2.0, 0.0), make_spot((0, -1, 0), 35.0, q), (x, 0, 0), UP)
                           for x in xs])
        steps = np.abs(np.diff(across))
        assert steps.max() <= 3.0 * np.median(steps) + 1e-9 * across.max(), f"q = {q}: {across}"


# ---- the renderer against the reference: a spot over a road -----------------------------------------

def road_scene(height: float, cone_angle: float, edge: float, sigma_t: Any = 0.04, medium_albedo: Any = 1.0,
               aim: Any = (0.25, -1.0, 0.15), intensity: Any = 100.0, road_albedo: Any = 0.5,
               radius: float = 0.01, width: int = 120, film_height: int = 90,
               footprint: float | None = None) -> dict:
    """A spot `height` metres above a road (y = 0, nothing else in the scene), aimed along
    `aim`; the camera looks at the road from about 3 footprints away and 2.5 footprints up,
    the footprint being the size of the lit ellipse (at most that of a 60-degree cone; a
    narrow cone's three times over, up to 0.3 of the height), so that the view shows the
    ellipse, its surroundings and road far outside it."""
    axis = _unit(aim)
    lamp = np.array([0.0, height, 0.0])
    if footprint is None:
        spread = math.tan(math.radians(min(cone_angle, 60.0)))
        footprint = height * max(spread, min(3.0 * spread, 0.3))
    if axis[1] < 0:
        centre = lamp + axis * (height / -axis[1])
    else:
        centre = np.array([axis[0], 0.0, axis[2]]) * height
    camera = centre + footprint * np.array([0.8, 2.5, 3.0])
    lamp_dict = spot(lamp.tolist(), axis.tolist(), intensity, cone_angle, edge, radius)
    return make_scene(camera, centre, [lamp_dict],
                      [plane((0, 0, 0), (0, 1, 0), road_albedo)], sigma_t=sigma_t, albedo=medium_albedo,
                      fov_y=60.0, width=width, height=film_height)


@dataclass
class RoadSamples:
    rows: np.ndarray
    cols: np.ndarray
    labels: list[str]  # which class each pixel was drawn from
    reference: np.ndarray  # (N, 3) whole pixel
    surface: np.ndarray  # (N, 3) the road's own radiance (direct + glow) times the transmittance
    glow: np.ndarray  # (N, 3) its glow part
    threshold: float


_ROAD_CACHE: dict[str, RoadSamples] = {}


def road_samples(scene: dict, per_class: int = 4, seed: int = 0) -> RoadSamples:
    """Road pixels away from the lamp's core, drawn per class: deep inside the lit ellipse,
    inside near its edge, outside near its edge (2-3 pixels from it; 1-3 when q = 0, whose
    direct light fades to zero there), just outside (4-12 pixels) and far outside (beyond
    25 pixels); plus the pixel with the most direct light. Reference radiance of each
    (cached per scene). The threshold is 1e-3 of the largest sampled value."""
    key = json.dumps(scene, sort_keys=True) + f"/{per_class}/{seed}"
    if key in _ROAD_CACHE:
        return _ROAD_CACHE[key]
    ss = parse_spot_scene(scene)
    sc = ss.sc
    hh, ww = sc.height, sc.width
    tr = trace(sc, camera_rays(sc))
    on_road = (tr.hit_id == 0).reshape(hh, ww)
    near_lamp = ((tr.min_lamp_gap < 3.0) | (tr.hit_id >= LAMP_BASE)).reshape(hh, ww)
    ok = np.zeros((hh, ww), dtype=bool)
    inner = np.ones((hh - 2, ww - 2), dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            window = (slice(1 + dy, hh - 1 + dy), slice(1 + dx, ww - 1 + dx))
            inner &= on_road[window] & ~near_lamp[window]
    ok[1:-1, 1:-1] = inner
    lit_flat = np.zeros(hh * ww, dtype=bool)
    for j in ss.spot_indices:
        sp = ss.spots[j]
        assert sp is not None
        road = np.nonzero(on_road.ravel())[0]
        lit_flat[road] |= direction_profile(sp, sc.lights[j].position, tr.point[road]) > 0
    in_beam = lit_flat.reshape(hh, ww)
    to_outside = distance_transform_edt(~(on_road & ~in_beam))  # pixels to the nearest lit-less road pixel
    to_inside = distance_transform_edt(~in_beam) if in_beam.any() else np.full((hh, ww), np.inf)
    gap = np.where(in_beam, to_outside, to_inside)
    edges = [float(ss.spots[j].edge) for j in ss.spot_indices]  # type: ignore[union-attr]
    min_gap = 1.0 if max(edges) == 0.0 else 2.0
    classes = {
        "inside": ok & in_beam & (gap > 6),
        "inside_edge": ok & in_beam & (gap >= min_gap) & (gap <= 3),
        "outside_edge": ok & ~in_beam & (gap >= min_gap) & (gap <= 3),
        "outside_near": ok & ~in_beam & (gap >= 4) & (gap <= 12),
        "outside_far": ok & ~in_beam & (gap > 25),
    }
    rng = np.random.default_rng(seed)
    rows: list[int] = []
    cols: list[int] = []
    labels: list[str] = []
    for label, mask in classes.items():
        r, c = np.nonzero(mask)
        for k in rng.choice(len(r), size=min(per_class, len(r)), replace=False):
            rows.append(int(r[k]))
            cols.append(int(c[k]))
            labels.append(label)
    if in_beam.any():  # the brightest direct light
        r, c = np.nonzero(ok & in_beam)
        if len(r):
            direct = [spot_direct(ss, tr.point[i * ww + j], tr.normal[i * ww + j], np.ones(3),
                                  tr.lit[:, i * ww + j])[0] for i, j in zip(r, c)]
            k = int(np.argmax(direct))
            rows.append(int(r[k]))
            cols.append(int(c[k]))
            labels.append("brightest")
    assert rows, "no road pixel to compare: fix the scene"
    rr, cc = np.array(rows), np.array(cols)
    reference = spot_pixel_radiance(ss, rows, cols)
    surface, glow = _surface_terms(ss, rr, cc)
    samples = RoadSamples(rr, cc, labels, reference, surface, glow, DIM_FRACTION * float(reference.max()))
    _ROAD_CACHE[key] = samples
    return samples


def _surface_terms(ss: SpotScene, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(surface, glow) (N, 3): the road's own radiance (the spots' direct light and glow,
    effects/lamp_airlight/physics.md and effects/spotlights/physics.md) and its glow part, both times
    the transmittance to the camera."""
    sc = ss.sc
    tr = trace(sc, camera_rays(sc, rows, cols))
    surface, glow = np.zeros((len(rows), 3)), np.zeros((len(rows), 3))
    for k in range(len(rows)):
        albedo = sc.surfaces[int(tr.hit_id[k]) // 8].albedo
        t = transmittance(sc.sigma_t, float(tr.t_hit[k]))
        g = spot_glow_radiance(ss, tr.point[k], tr.normal[k], albedo) * t
        surface[k] = spot_direct(ss, tr.point[k], tr.normal[k], albedo, tr.lit[:, k]) * t + g
        glow[k] = g
    return surface, glow


def _black_road(scene: dict) -> dict:
    dark = copy.deepcopy(scene)
    for s in dark["surfaces"]:
        s["albedo"] = 0.0
    return dark


def check_road(scene: dict, backend: str, label: str, min_values: int = 12,
               min_glow: float = 0.0) -> dict[str, float]:
    """Whole pixels and the surface term alone against the reference (0.5 %); returns the
    worst relative error per pixel class (whole pixels)."""
    samples = road_samples(scene)
    r = get_renderer(backend)
    image = np.asarray(r.render(scene), dtype=np.float64)
    _finite_non_negative(image, f"{label} [{backend}]")
    got = image[samples.rows, samples.cols]
    ref = samples.reference
    use = ref > samples.threshold
    assert use.sum() >= min_values, f"{label}: only {use.sum()} channel values compared"
    rel = np.where(use, np.abs(got - ref) / np.where(use, ref, 1.0), 0.0)
    worst: dict[str, float] = {}
    for i, name in enumerate(samples.labels):
        worst[name] = max(worst.get(name, 0.0), float(rel[i].max()))
    k, c = np.unravel_index(np.argmax(rel), rel.shape)
    assert rel[k, c] <= REL_TOL, (
        f"{label} [{backend}]: relative error {rel[k, c]:.3e} at pixel (row {samples.rows[k]}, col "
        f"{samples.cols[k]}, {samples.labels[k]}) channel {c}: rendered {got[k, c]:.7e}, reference "
        f"{ref[k, c]:.7e} (glow {samples.glow[k, c]:.4e}); {int((rel > REL_TOL).sum())} of {int(use.sum())} "
        f"values fail; worst per class {worst}")
    # the surface term alone: render minus render with a black road
    black = np.asarray(r.render(_black_road(scene)), dtype=np.float64)[samples.rows, samples.cols]
    term = got - black
    expect = samples.surface
    allowance = REL_TOL * expect + 4 * np.spacing(np.float32(np.maximum(got, black).max(axis=1)))[:, None]
    use_s = expect > samples.threshold
    bad = use_s & (np.abs(term - expect) > allowance)
    if bad.any():
        k, c = np.argwhere(bad)[0]
        raise AssertionError(
            f"{label} [{backend}]: surface term at pixel (row {samples.rows[k]}, col {samples.cols[k]}, "
            f"{samples.labels[k]}) channel {c}: rendered {term[k, c]:.7e}, reference {expect[k, c]:.7e} "
            f"(glow {samples.glow[k, c]:.4e}, {term[k, c] / expect[k, c] - 1:+.3e}); {int(bad.sum())} values "
            "fail")
    if min_glow > 0:  # the scene really tests the glow
        share = samples.glow[use] / ref[use]
        assert share.max() >= min_glow, f"{label}: the glow is at most {share.max():.2e} of a compared pixel"
    return worst


CONE_EDGE = [(2.0, 0.0), (2.0, 1.0), (10.0, 0.5), (30.0, 0.0), (30.0, 0.5), (30.0, 1.0), (60.0, 1.0),
             (60.0, 0.0), (80.0, 0.5), (90.0, 0.0), (90.0, 1.0)]


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("cone_angle,edge", CONE_EDGE)
def test_road_glow_cone_angle_and_edge(cone_angle, edge, backend):
    """A spot 3 m above the road (sigma_t 0.04), cone angle 2-90 degrees, q 0, 0.5, 1."""
    check_road(road_scene(3.0, cone_angle, edge), backend, f"A = {cone_angle}, q = {edge}", min_glow=0.05)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.001, 0.01, 0.04, 0.2, 1.0, 2.0])
def test_road_glow_sigma_t(sigma_t, backend):
    """Medium albedo 0.9, sigma_t 0.001 to 2 per metre; in thick fog the lamp comes down
    (height min(3, 2 / sqrt(sigma_t)) m, so the thick scenes differ in optical size too)
    so that the road stays above 1e-3 of the maximum."""
    height = min(3.0, 2.0 / math.sqrt(sigma_t))
    check_road(road_scene(height, 40.0, 0.5, sigma_t=sigma_t, medium_albedo=0.9), backend,
               f"sigma_t = {sigma_t}", min_glow=1e-3)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("height", [0.05, 0.3, 2.0, 10.0])
def test_road_glow_lamp_height(height, backend):
    """The lamp 5 cm to 10 m above the road (radius 1 cm), sigma_t 0.1. (At 5 cm the glow
    stays below 1e-3 of the lit disc, so there the whole pixels test the direct light and
    the airlight; test_lamp_coming_down_to_the_road tests the glow of low lamps.)"""
    check_road(road_scene(height, 35.0, 0.3, sigma_t=0.1), backend, f"lamp {height} m up",
               min_glow=0.01 if height >= 0.3 else 0.0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_road_glow_coloured_medium(backend):
    """Per-channel sigma_t, medium albedo, lamp intensity and road albedo."""
    scene = road_scene(2.0, 30.0, 0.5, sigma_t=[0.02, 0.1, 0.4], medium_albedo=[1.0, 0.8, 0.5],
                       intensity=[100.0, 60.0, 30.0], road_albedo=[0.6, 0.5, 0.3])
    check_road(scene, backend, "coloured medium", min_glow=0.01)


def away_scene(kind: str, sigma_t: float = 0.1) -> dict:
    """The road outside the beam entirely: its radiance is the glow plus the airlight of
    the view ray. Thick fog shrinks the scene (by min(1, 0.3 / sigma_t))."""
    f = min(1.0, 0.3 / sigma_t)
    if kind == "aimed_up":
        camera, target, fov = (4.0 * f, 2.5 * f, 6.0 * f), (0.5 * f, 0.0, 0.5 * f), 60.0
        lamp = spot((0, 1.5 * f, 0), (0.1, 1.0, 0.0), 200.0, 30.0, 0.5, 0.02)
    else:  # a narrow beam aimed horizontally away from the part of the road in view
        camera, target, fov = (0.0, 2.0 * f, 4.0 * f), (0.0, 0.0, -1.0 * f), 50.0
        lamp = spot((0, 1.0 * f, -2.0 * f), (0.0, 0.1, -1.0), 500.0, 5.0, 0.0, 0.02)
    return make_scene(camera, target, [lamp], [plane((0, 0, 0), (0, 1, 0), 0.5)], sigma_t=sigma_t, albedo=1.0,
                      fov_y=fov, width=120, height=90)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.001, 0.1, 1.0])
@pytest.mark.parametrize("kind", ["aimed_up", "narrow_aimed_away"])
def test_road_outside_the_beam_glow_only(kind, sigma_t, backend):
    """No direct light on the visible road (checked): every road pixel is the glow (at
    least half of some pixels) plus airlight; thin to thick fog."""
    scene = away_scene(kind, sigma_t)
    samples = road_samples(scene)
    assert samples.surface.max() > 0 and np.allclose(samples.surface, samples.glow, rtol=1e-12, atol=0)
    check_road(scene, backend, f"road outside the beam, {kind}, sigma_t = {sigma_t}", min_glow=0.5)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("sigma_t", [0.001, 0.05, 0.5])
def test_lamp_below_the_road_shining_up(sigma_t, backend):
    """The lamp 0.5 m below the road plane, aimed up through it: the road's upper side gets
    no direct light, only the glow of the fog above the plane, strongest where the beam
    comes through."""
    lamp = spot((0, -0.5, 0), (0.2, 1.0, 0.1), 200.0, 35.0, 0.5, 0.02)
    scene = make_scene((0.5, 2.0, 3.5), (0.2, 0.0, 0.0), [lamp], [plane((0, 0, 0), (0, 1, 0), 0.5)],
                       sigma_t=sigma_t, albedo=1.0, fov_y=70.0, width=120, height=90)
    samples = road_samples(scene)
    assert np.allclose(samples.surface, samples.glow, rtol=1e-12, atol=0) and samples.glow.max() > 0
    check_road(scene, backend, f"lamp below the road, sigma_t = {sigma_t}", min_glow=0.5)


GL_CPU_SCENES = {
    "cone_30_q05": road_scene(3.0, 30.0, 0.5),
    "wide_90_q0_thick": road_scene(1.0, 90.0, 0.0, sigma_t=1.0, medium_albedo=0.9),
    "lamp_5cm_up": road_scene(0.05, 35.0, 0.3, sigma_t=0.1),
    "aimed_up": away_scene("aimed_up"),
}


@pytest.mark.parametrize("name", sorted(GL_CPU_SCENES))
def test_gl_matches_cpu(name):
    """GL and CPU within 0.5 % on every road pixel above 1e-3 of the maximum that is away
    from the lamp's core and from the edge of the lit ellipse."""
    scene = GL_CPU_SCENES[name]
    gl = np.asarray(get_renderer("gl").render(scene), dtype=np.float64)
    cpu = np.asarray(get_renderer("cpu").render(scene), dtype=np.float64)
    _finite_non_negative(gl, f"{name} [gl]")
    _finite_non_negative(cpu, f"{name} [cpu]")
    geo = spot_geometry(parse_spot_scene(scene), lamp_gap=3.0)
    peak = cpu[geo.smooth].max()
    use = (geo.smooth & ~geo.degenerate)[:, :, None] & (cpu > DIM_FRACTION * peak)
    assert use.sum() >= 200
    rel = np.where(use, np.abs(gl - cpu) / np.where(use, cpu, 1.0), 0.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    assert rel[worst] <= REL_TOL, f"{name}: GL {gl[worst]:.7e} vs CPU {cpu[worst]:.7e} at {worst}"


# ---- stability --------------------------------------------------------------------------------------------

@st.composite
def road_spot_scenes(draw: Any) -> dict:
    grey = draw(st.booleans())
    sig = draw(st.floats(0.0, 2.0)) if grey else [draw(st.floats(0.0, 2.0)) for _ in range(3)]
    alb = draw(st.floats(0.0, 1.0)) if grey else [draw(st.floats(0.0, 1.0)) for _ in range(3)]
    lights = []
    for _ in range(draw(st.integers(1, 2))):
        radius = draw(st.floats(0.001, 0.3))
        side = draw(st.sampled_from([1.0, -1.0]))  # above or below the road
        height = side * 10.0 ** draw(st.floats(-3.0, 1.0))
        if abs(height) < 1.5 * radius:
            height = math.copysign(1.5 * radius, height)
        if draw(st.integers(0, 7)) == 0:  # mounted on the road
            height = 0.0
        aim = [draw(st.floats(-1, 1)) for _ in range(3)]
        if np.linalg.norm(aim) < 1e-3:
            aim = [0.0, -1.0, 0.0]
        position = [draw(st.floats(-3, 3)), height, draw(st.floats(-3, 3))]
        lights.append(spot(position, aim, draw(st.floats(0.0, 1e3)), draw(st.floats(0.01, 90.0)),
                           draw(st.sampled_from([0.0, 1.0, draw(st.floats(0.0, 1.0))])), radius))
    cam_height = 10.0 ** draw(st.floats(-1.5, 1.0))
    cam = [draw(st.floats(-3, 3)), cam_height, draw(st.floats(-3, 3)) + 3.0]
    target = [draw(st.floats(-2, 2)), 0.0, draw(st.floats(-2, 2))]
    if math.hypot(cam[0] - target[0], cam[2] - target[2]) < 1e-3 * cam_height:
        target[2] -= 0.1 * cam_height  # straight down is parallel to the camera's up: an invalid scene
    road = plane((0, 0, 0), (0, 1, 0), draw(st.floats(0.0, 1.0)))
    fov_y = draw(st.floats(10.0, 120.0))
    cull = draw(st.sampled_from([0.0, None]))
    return make_scene(cam, target, lights, [road], sigma_t=sig, albedo=alb, fov_y=fov_y, width=16, height=12,
                      cull_fraction=cull)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=road_spot_scenes())
def test_random_spots_over_a_road_are_finite_and_non_negative(scene):
    """Random spots (any cone angle, q, height 0 or from 1 mm to 10 m above or below the road,
    any aim, radius 1 mm to 30 cm) over a road in fog: no NaN, no Inf, no negative
    radiance on any available backend."""
    import airlight

    for backend in airlight.available_backends():
        image = np.asarray(get_renderer(backend).render(scene))
        assert image.shape == (12, 16, 3)
        _finite_non_negative(image, f"[{backend}]")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("where", ["in_the_beam", "beside_the_beam"])
def test_lamp_coming_down_to_the_road(where, backend):
    """One road point seen from above while a spot (radius 2 mm, aimed 20 degrees below
    the horizon along the road) comes down from 1 m to 1 cm above the road: every value
    within 0.5 % of the reference, and no jumps."""
    heights = np.geomspace(1.0, 0.01, 15)
    point = np.array([2.0, 0.0, 0.0]) if where == "in_the_beam" else np.array([0.3, 0.0, 0.6])
    axis = _unit([1.0, -math.tan(math.radians(20.0)), 0.0])
    r = get_renderer(backend)
    got, ref = [], []
    for h in heights:
        scene = make_scene(point + [0.0, 0.2, 0.0], point, [spot((0, h, 0), axis, 100.0, 25.0, 0.5, 0.002)],
                           [plane((0, 0, 0), (0, 1, 0), 0.5)], sigma_t=0.1, albedo=1.0, fov_y=1e-3, width=1,
                           height=1, up=(0.0, 0.0, -1.0))
        got.append(float(r.render(scene)[0, 0, 0]))
        ref.append(float(spot_pixel_radiance(parse_spot_scene(scene), [0], [0])[0, 0]))
    g, e = np.array(got), np.array(ref)
    assert np.all(np.isfinite(g)) and np.all(g > 0)
    bad = np.abs(g - e) > REL_TOL * e
    assert not bad.any(), (f"{where} [{backend}]: heights {heights[bad]}: rendered {g[bad]}, reference "
                           f"{e[bad]} ({(g[bad] / e[bad] - 1)})")
    _no_jumps(np.log(g), f"{where} [{backend}]", floor=1e-3)


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("cone_angle,edge", [(30.0, 0.5), (90.0, 0.0), (90.0, 1.0)])
def test_spot_mounted_on_the_surface_it_lights(cone_angle, edge, backend):
    """A spot whose centre lies on the road (a lamp set into the ground, aimed up and
    along it): no direct light on the road, only the glow of the beam above it; a 90-degree
    cone's wall then runs along the road, where the profile formula was once 0/0 (Inf).
    Within 0.5 % of the reference."""
    lamp = spot((0.0, 0.0, 0.0), (1.0, 0.6, 0.2), 200.0, cone_angle, edge, 0.02)
    scene = make_scene((1.5, 2.0, 3.0), (1.0, 0.0, 0.0), [lamp], [plane((0, 0, 0), (0, 1, 0), 0.5)],
                       sigma_t=0.2, albedo=1.0, fov_y=60.0, width=120, height=90)
    samples = road_samples(scene)
    assert np.allclose(samples.surface, samples.glow, rtol=1e-12, atol=0) and samples.glow.max() > 0
    check_road(scene, backend, f"spot on the road, A = {cone_angle}, q = {edge}", min_glow=0.3)


@pytest.mark.parametrize("backend", BACKENDS)
def test_road_across_the_lit_edge_q0(backend):
    """q = 0 in fog: a row of 41 pixels across the edge of the lit ellipse on the road.
    The direct light fades to zero at the edge and the glow goes on smoothly: within 0.5 %
    of the reference, and no jumps."""
    s, axis, cone = np.array([0.0, 3.0, 0.0]), np.array([0.0, -1.0, 0.0]), 30.0
    edge_point = np.array([3.0 * math.tan(math.radians(cone)), 0.0, 0.0])
    # a 41 x 1 film spanning +-0.1 m around the edge point, seen from 1 m above it
    fov_y = 2.0 * math.degrees(math.atan(0.1 / 41))
    scene = make_scene(edge_point + [0.0, 1.0, 0.0], edge_point, [spot(s, axis, 100.0, cone, 0.0, 0.02)],
                       [plane((0, 0, 0), (0, 1, 0), 0.5)], sigma_t=0.1, albedo=1.0, fov_y=fov_y, width=41,
                       height=1, up=(0.0, 0.0, -1.0))
    image = np.asarray(get_renderer(backend).render(scene), dtype=np.float64)[0, :, 0]
    _finite_non_negative(image, f"q = 0 edge on the road [{backend}]")
    ss = parse_spot_scene(scene)
    ref = spot_pixel_radiance(ss, np.zeros(41, dtype=int), np.arange(41))[:, 0]
    tr = trace(ss.sc, camera_rays(ss.sc))
    inside = direction_profile(ss.spots[0], s, tr.point) > 0  # type: ignore[arg-type]
    assert 10 <= inside.sum() <= 31, "fix the scene: the row does not cross the edge"
    bad = np.abs(image - ref) > REL_TOL * ref
    assert not bad.any(), (f"[{backend}] columns {np.nonzero(bad)[0]}: rendered {image[bad]}, "
                           f"reference {ref[bad]}")
    _no_jumps(image, f"q = 0 edge on the road [{backend}]", floor=1e-5 * ref.max())


def test_spot_glow_irradiance_per_channel():
    """spot_glow_irradiance is sigma_s I0 / (4 pi) times the unit glow per channel, zero
    where sigma_s or I0 is zero."""
    sp = make_spot((0.1, -1, 0), 30.0, 0.5)
    e = spot_glow_irradiance([0.1, 0.1, 0.3], [0.1, 0.0, 0.2], [50.0, 50.0, 0.0], (0, 2, 0), sp, (0.3, 0, 0),
                             UP)
    unit = spot_glow_unit(0.1, (0, 2, 0), sp, (0.3, 0, 0), UP)
    assert e[0] == pytest.approx(0.1 * 50.0 / (4 * math.pi) * unit, rel=1e-12)
    assert e[1] == 0.0 and e[2] == 0.0
