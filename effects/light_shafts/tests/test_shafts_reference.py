"""Self-test of the light-shaft reference (shafts_reference.py): its shadow intervals against a
per-point shadow ray, its radiance against quadrature of the shadow indicator, and its closed
forms, camera and scene reading. Nothing here trusts the renderer but the camera/depth check."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shafts_reference as ref
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

# --------------------------------------------------------------------------------------------
# Brute force: an exact float64 shadow ray per point (independent of the interval algebra)
# --------------------------------------------------------------------------------------------


def point_in_shadow(points: np.ndarray, s: np.ndarray, surfaces: list[dict]) -> np.ndarray:
    """Whether the half-line x + u s, u > 0, meets any surface, per point x of (M, 3)."""
    shadow = np.zeros(len(points), dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        for sf in surfaces:
            if sf["type"] == "plane":
                n = np.asarray(sf["normal"], float)
                sn = s @ n
                if sn != 0.0:
                    shadow |= ((np.asarray(sf["point"], float) - points) @ n) / sn > 0.0
            elif sf["type"] == "box":  # slab method along the shadow ray
                lo, hi = np.asarray(sf["min"], float), np.asarray(sf["max"], float)
                u_near = np.zeros(len(points))  # u > 0 (the boundary u = 0 is measure zero)
                u_far = np.full(len(points), np.inf)
                ok = np.ones(len(points), dtype=bool)
                for i in range(3):
                    if s[i] == 0.0:
                        ok &= (lo[i] <= points[:, i]) & (points[:, i] <= hi[i])
                    else:
                        u1, u2 = (lo[i] - points[:, i]) / s[i], (hi[i] - points[:, i]) / s[i]
                        u_near = np.maximum(u_near, np.minimum(u1, u2))
                        u_far = np.minimum(u_far, np.maximum(u1, u2))
                shadow |= ok & (u_near <= u_far) & (u_far > 0.0)
            else:  # sphere: |w + u s|^2 = r^2, far root -b + sqrt(b^2 - c) > 0
                w = points - np.asarray(sf["center"], float)
                b = w @ s
                disc = b * b - (np.einsum("ij,ij->i", w, w) - sf["radius"] ** 2)
                shadow |= (disc >= 0.0) & (-b + np.sqrt(np.maximum(disc, 0.0)) > 0.0)
    return shadow


def random_unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_casters(rng: np.random.Generator, boxes: int, spheres: int, planes: int) -> list[dict]:
    surfaces = []
    for _ in range(boxes):
        lo = rng.uniform(-10, 8, size=3)
        hi = lo + rng.uniform(0.3, 5, size=3)
        surfaces.append({"type": "box", "min": lo.tolist(), "max": hi.tolist()})
    for _ in range(spheres):
        surfaces.append({"type": "sphere", "center": rng.uniform(-10, 10, size=3).tolist(),
                         "radius": float(rng.uniform(0.3, 4))})
    for _ in range(planes):
        surfaces.append({"type": "plane", "point": rng.uniform(-12, 12, size=3).tolist(),
                         "normal": random_unit(rng).tolist()})
    return surfaces


def snap_to_axes(v: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Zero one or two components (rays or sun parallel to faces: the degenerate slabs)."""
    v = v.copy()
    v[rng.choice(3, size=int(rng.integers(1, 3)), replace=False)] = 0.0
    if not np.any(v):
        v[int(rng.integers(3))] = 1.0
    return v / np.linalg.norm(v)


def in_intervals(t: np.ndarray, intervals: list[tuple[float, float]]) -> np.ndarray:
    inside = np.zeros(t.shape, dtype=bool)
    for a, b in intervals:
        inside |= (t >= a) & (t <= b)
    return inside


def near_ends(t: np.ndarray, intervals: list[tuple[float, float]], tol: float) -> np.ndarray:
    near = np.zeros(t.shape, dtype=bool)
    for a, b in intervals:
        near |= (np.abs(t - a) < tol) | (np.abs(t - b) < tol)
    return near


# --------------------------------------------------------------------------------------------
# (a) intervals against brute force
# --------------------------------------------------------------------------------------------

CASES = ["box", "sphere", "plane", "mixed", "axis_ray", "axis_sun", "ray_along_sun", "ray_against_sun",
         "origin_in_shadow"]


@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), case=st.sampled_from(CASES))
def test_shadow_intervals_match_per_point_shadow_rays(seed: int, case: str) -> None:
    rng = np.random.default_rng(seed)
    counts = {"box": (1, 0, 0), "sphere": (0, 1, 0), "plane": (0, 0, 1)}.get(case, (4, 2, 1))
    surfaces = random_casters(rng, *counts)
    s = random_unit(rng)
    origin = rng.uniform(-15, 15, size=3)
    d = rng.uniform(-8, 8, size=3) - origin  # toward the casters: shadows are met
    d /= np.linalg.norm(d)
    if case == "axis_ray":
        d = snap_to_axes(d, rng)
    elif case == "axis_sun":
        s = snap_to_axes(s, rng)
        surfaces.append({"type": "plane", "point": [0.0, -3.0, 0.0], "normal": [0.0, 1.0, 0.0]})
    elif case == "ray_along_sun":
        d = s.copy()
    elif case == "ray_against_sun":
        d = -s
    elif case == "origin_in_shadow":  # camera behind a box, looking back past it
        box = surfaces[0]
        centre = 0.5 * (np.asarray(box["min"]) + np.asarray(box["max"]))
        origin = centre - 12.0 * s
        d = random_unit(rng)

    intervals = ref.shadow_intervals(origin, d, s, surfaces)
    # Sorted, disjoint, merged, within [0, inf).
    flat = [x for iv in intervals for x in iv]
    assert all(a < b for a, b in intervals)
    assert flat == sorted(flat)
    assert all(left[1] < right[0] for left, right in zip(intervals, intervals[1:]))
    assert not intervals or intervals[0][0] >= 0.0

    t = np.linspace(0.0, 60.0, 20001)
    brute = point_in_shadow(origin[None, :] + t[:, None] * d[None, :], s, surfaces)
    mine = in_intervals(t, intervals)
    bad = (brute != mine) & ~near_ends(t, intervals, 1e-7 * (1.0 + t))
    assert not bad.any(), (f"{bad.sum()} points disagree, first t = {t[bad][:5]}, brute {brute[bad][:5]}, "
                           f"intervals {intervals}")


def test_sphere_shadow_is_the_ball_plus_the_cylinder_behind_it() -> None:
    """Sun overhead, unit sphere at the origin: a horizontal ray at height y crosses the ball at
    |x| <= sqrt(1 - y^2) above the centre and the whole cylinder |x| <= 1 below it."""
    sphere = [{"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0}]
    s = np.array([0.0, 1.0, 0.0])
    d = np.array([1.0, 0.0, 0.0])
    (a, b), = ref.shadow_intervals([-5.0, 0.6, 0.0], d, s, sphere)
    assert (a, b) == pytest.approx((5.0 - 0.8, 5.0 + 0.8), abs=1e-12)
    (a, b), = ref.shadow_intervals([-5.0, -7.0, 0.0], d, s, sphere)
    assert (a, b) == pytest.approx((4.0, 6.0), abs=1e-12)
    # A ray climbing toward the sun from below the sphere: shadowed until it leaves the ball.
    (a, b), = ref.shadow_intervals([0.0, -9.0, 0.0], s, s, sphere)
    assert (a, b) == pytest.approx((0.0, 10.0), abs=1e-12)


def test_box_shadow_of_a_slanted_sun_on_a_horizontal_ray() -> None:
    """Box [0,1]^2 x [-1,1] lit at 45 degrees from +x, +y: at height y < 0 the shadow on the line
    z = 0 is x in [y - 1, y + 1] (the box swept along -s: x + v in [0, 1] for v = -y .. 1 - y)."""
    box = [{"type": "box", "min": [0.0, 0.0, -1.0], "max": [1.0, 1.0, 1.0]}]
    s = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
    (a, b), = ref.shadow_intervals([-10.0, -3.0, 0.0], [1.0, 0.0, 0.0], s, box)
    assert (a, b) == pytest.approx((6.0, 8.0), abs=1e-12)
    # Above the box top nothing (no u > 0 brings a point with y > 1 down into it).
    assert ref.shadow_intervals([-10.0, 1.5, 0.0], [1.0, 0.0, 0.0], s, box) == []


def test_plane_shadows_the_half_space_away_from_the_sun() -> None:
    ground = [{"type": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 2.0, 0.0]}]
    s = ref.sun_direction({"elevation": 30.0, "azimuth": 0.0})
    down = np.array([0.0, -0.6, -0.8])
    (a, b), = ref.shadow_intervals([0.0, 3.0, 0.0], down, s, ground)
    assert (a, b) == (pytest.approx(5.0, abs=1e-12), math.inf)
    assert ref.shadow_intervals([0.0, 3.0, 0.0], -down, s, ground) == []
    # Sun in the plane: never shadowed.
    assert ref.shadow_intervals([0.0, 3.0, 0.0], down, [1.0, 0.0, 0.0], ground) == []


def test_overlapping_casters_merge_into_one_interval() -> None:
    s = np.array([0.0, 1.0, 0.0])
    boxes = [{"type": "box", "min": [1.0, 1.0, -1.0], "max": [3.0, 2.0, 1.0]},
             {"type": "box", "min": [2.0, 1.0, -1.0], "max": [5.0, 2.0, 1.0]},
             {"type": "box", "min": [5.0, 1.0, -1.0], "max": [6.0, 2.0, 1.0]},  # touches: merged
             {"type": "box", "min": [8.0, 1.0, -1.0], "max": [9.0, 2.0, 1.0]}]
    got = ref.shadow_intervals([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], s, boxes)
    assert got == [(1.0, 6.0), (8.0, 9.0)]
    clipped = ref.shadow_intervals([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], s, boxes, t_max=8.5)
    assert clipped == [(1.0, 6.0), (8.0, 8.5)]
    assert ref.lit_intervals([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], s, boxes, t_max=10.0) == [
        (0.0, 1.0), (6.0, 8.0), (9.0, 10.0)]


# --------------------------------------------------------------------------------------------
# first_hit and the camera
# --------------------------------------------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_first_hit_is_on_a_surface_with_free_space_before_it(seed: int) -> None:
    rng = np.random.default_rng(seed)
    surfaces = random_casters(rng, 4, 2, 1)
    origin = rng.uniform(-15, 15, size=3)
    solids = [sf for sf in surfaces if sf["type"] != "plane"]
    if point_inside(origin[None, :], solids).any():
        return
    d = rng.uniform(-8, 8, size=3) - origin
    d /= np.linalg.norm(d)
    t_hit = ref.first_hit(origin, d, surfaces)
    t_end = min(t_hit, 80.0)
    t = np.linspace(0.0, t_end, 4001)[:-1]
    x = origin[None, :] + t[:, None] * d[None, :]
    far = t < t_end - 1e-9 * (1 + t_end)
    assert not (point_inside(x, solids) & far).any()
    for sf in surfaces:
        if sf["type"] == "plane":
            side = (x - np.asarray(sf["point"])) @ np.asarray(sf["normal"])
            assert (np.sign(side[far]) == np.sign(side[0])).all()
    if math.isfinite(t_hit):
        assert min(surface_distance(origin + t_hit * d, sf) for sf in surfaces) < 1e-9 * (1 + t_hit)


def point_inside(x: np.ndarray, solids: list[dict]) -> np.ndarray:
    inside = np.zeros(len(x), dtype=bool)
    for sf in solids:
        if sf["type"] == "box":
            inside |= np.all((x > sf["min"]) & (x < sf["max"]), axis=1)
        else:
            inside |= np.linalg.norm(x - sf["center"], axis=1) < sf["radius"]
    return inside


def surface_distance(x: np.ndarray, sf: dict) -> float:
    if sf["type"] == "plane":
        n = np.asarray(sf["normal"], float)
        return abs((x - sf["point"]) @ n) / np.linalg.norm(n)
    if sf["type"] == "sphere":
        return abs(np.linalg.norm(x - sf["center"]) - sf["radius"])
    lo, hi = np.asarray(sf["min"]), np.asarray(sf["max"])
    outside = np.maximum(np.maximum(lo - x, x - hi), 0.0)
    if outside.any():
        return float(np.linalg.norm(outside))
    return float(np.min(np.minimum(x - lo, hi - x)))


def test_camera_rays_follow_the_pinhole_model() -> None:
    camera = {"position": [1.0, 2.0, 3.0], "look_at": [1.0, 2.0, -7.0], "up": [0, 1, 0], "fov_y": 60}
    scene = {"camera": camera}
    o, d = ref.camera_rays(scene, 5, 3)
    assert d.shape == (3, 5, 3) and np.allclose(o, [1, 2, 3])
    assert np.allclose(np.linalg.norm(d, axis=-1), 1.0)
    assert np.allclose(d[1, 2], [0, 0, -1])  # the centre pixel looks at look_at
    tan_half = math.tan(math.radians(30))
    # Top-left pixel centre: sx = -0.8, sy = 2/3 of the half-extents tan_half * 5/3 and tan_half.
    expected = np.array([-0.8 * tan_half * 5 / 3, 2 / 3 * tan_half, -1.0])
    assert np.allclose(d[0, 0], expected / np.linalg.norm(expected), rtol=0, atol=1e-15)


def test_camera_rays_and_first_hit_match_the_renderer_depth() -> None:
    airlight = pytest.importorskip("airlight")
    scene = {"camera": {"position": [0, 1.7, 0], "look_at": [1, 1.2, -10], "up": [0, 1, 0], "fov_y": 70},
             "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
                          {"type": "box", "min": [-8, 0, -40], "max": [-4, 12, -25]},
                          {"type": "box", "min": [2, 0, -20], "max": [5, 3, -15]},
                          {"type": "sphere", "center": [0, 4, -30], "radius": 3}]}
    w, h = 48, 36
    depth = airlight.render(scene, backend="cpu", width=w, height=h, outputs=["depth"])["depth"]
    o, d = ref.camera_rays(scene, w, h)
    mine = ref.first_hit(o, d, scene["surfaces"])
    assert mine.shape == (h, w)
    both_inf = np.isinf(depth) & np.isinf(mine)
    close = both_inf | np.isclose(mine, depth, rtol=1e-4, atol=0)
    assert close.mean() > 0.98  # float32 may flip a pixel grazing an edge
    assert (np.isinf(mine) == np.isinf(depth)).mean() > 0.98


# --------------------------------------------------------------------------------------------
# (b) radiance against quadrature of the brute-force shadow indicator
# --------------------------------------------------------------------------------------------

SHAFT_SCENE = {  # a colonnade to the right, the sun low beside it: shafts across the view
    "camera": {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 4.0, -10.0], "up": [0, 1, 0], "fov_y": 70},
    "sun": {"elevation": 20.0, "azimuth": 70.0, "irradiance": [90.0, 100.0, 110.0]},
    "medium": {"sigma_t": [0.05, 0.03, 0.08], "albedo": [0.9, 1.0, 0.8], "phase": {"type": "hg", "g": 0.7}},
    "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
                 *({"type": "box", "min": [6 + i % 2, 0, -8 - 5 * i],
                    "max": [8 + i % 2, 9 + i % 3, -6 - 5 * i]} for i in range(6)),
                 {"type": "sphere", "center": [5, 8, -12], "radius": 1.5},
                 {"type": "box", "min": [-60, 0, -50], "max": [60, 40, -48]}],  # a back wall
}
W, H = 24, 18


@pytest.fixture(scope="module")
def shaft_pixels() -> list[tuple[int, int, np.ndarray, np.ndarray, float, np.ndarray]]:
    """Pixels whose ray ends on a surface and alternates lit/shadow several times:
    (row, col, origin, dir, t_hit, reference radiance)."""
    radiance = ref.medium_sun_radiance(SHAFT_SCENE, W, H)
    o, d = ref.camera_rays(SHAFT_SCENE, W, H)
    s = ref.sun_direction(SHAFT_SCENE["sun"])
    picked = []
    for row in range(H):
        for col in range(W):
            t_hit = ref.first_hit(o, d[row, col], SHAFT_SCENE["surfaces"])
            lit = ref.lit_intervals(o, d[row, col], s, SHAFT_SCENE["surfaces"])
            if math.isfinite(t_hit) and len(lit) >= 4:
                picked.append((row, col, o, d[row, col], t_hit, radiance[row, col]))
    assert len(picked) >= 4, "the scene should cast several shafts across some pixels"
    return picked[:: max(1, len(picked) // 4)][:4]


def scattering_factor(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_s p(s . d) E (3,), sigma_t (3,)) written out from the scene by hand."""
    sigma_t = np.array([0.05, 0.03, 0.08])
    sigma_s = np.array([0.9, 1.0, 0.8]) * sigma_t
    el, az = math.radians(20.0), math.radians(70.0)
    s = np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])
    g, mu = 0.7, float(s @ d)
    p = (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * mu) ** 1.5)
    return sigma_s * p * np.array([90.0, 100.0, 110.0]), sigma_t


def test_radiance_matches_a_fine_midpoint_sum_of_the_shadow_indicator(shaft_pixels) -> None:
    """Midpoint rule over [0, t_hit] of sigma_s p E exp(-sigma_t t) lit(t), lit by a shadow ray per
    node. Its error is at most h max f / 2 per cell holding a lit/shadow switch plus the smooth part's
    h^2 L max|f''| / 24: the bound the reference must fall within (about 1e-6 relative here)."""
    s = ref.sun_direction(SHAFT_SCENE["sun"])
    n = 2**20
    for _, _, o, d, t_hit, radiance in shaft_pixels:
        k, sigma_t = scattering_factor(d)
        h = t_hit / n
        t = (np.arange(n) + 0.5) * h
        lit = ~point_in_shadow(o[None, :] + t[:, None] * d[None, :], s, SHAFT_SCENE["surfaces"])
        weights = np.exp(-np.outer(t[lit], sigma_t))
        midpoint = k * h * weights.sum(axis=0)
        switches = np.count_nonzero(np.diff(lit.astype(np.int8))) + 2
        bound = k * (switches * h / 2 + h * h * t_hit * sigma_t**2 / 24) + 1e-12 * radiance
        assert np.all(np.abs(radiance - midpoint) <= bound), (radiance, midpoint, bound)
        assert np.all(bound / radiance < 1e-4)


def test_radiance_matches_quadrature_between_bisected_shadow_edges(shaft_pixels) -> None:
    """The lit/shadow switches located by bisection on the brute-force shadow test (not on the
    reference's intervals), then scipy quad of sigma_s p E exp(-sigma_t t) on each lit piece."""
    s = ref.sun_direction(SHAFT_SCENE["sun"])
    surfaces = SHAFT_SCENE["surfaces"]
    for _, _, o, d, t_hit, radiance in shaft_pixels:

        def lit_at(t, o=o, d=d) -> np.ndarray:
            return ~point_in_shadow(o[None, :] + np.atleast_1d(t)[:, None] * d[None, :], s, surfaces)

        grid = np.linspace(0.0, t_hit, 20001)
        lit = lit_at(grid)
        edges = [0.0]
        for i in np.flatnonzero(lit[1:] != lit[:-1]):
            a, b = grid[i], grid[i + 1]
            for _ in range(80):
                m = 0.5 * (a + b)
                if lit_at(m)[0] == lit[i]:
                    a = m
                else:
                    b = m
            edges.append(0.5 * (a + b))
        edges.append(t_hit)
        states = [bool(lit[0]) != (j % 2 == 1) for j in range(len(edges) - 1)]  # alternating
        k, sigma_t = scattering_factor(d)
        total = np.zeros(3)
        for (a, b), on in zip(zip(edges[:-1], edges[1:]), states):
            if on:
                for c, sigma in enumerate(sigma_t):
                    total[c] += integrate.quad(lambda t, sigma=sigma: math.exp(-sigma * t), a, b,
                                               epsabs=0, epsrel=1e-13)[0]
        np.testing.assert_allclose(radiance, k * total, rtol=1e-9, atol=0)


# --------------------------------------------------------------------------------------------
# (c) closed forms and scene reading
# --------------------------------------------------------------------------------------------


def base_scene(**over) -> dict:
    scene = {"camera": {"position": [0, 1.7, 0], "look_at": [0, 1.0, -10], "up": [0, 1, 0], "fov_y": 60},
             "sun": {"elevation": 40, "azimuth": -30, "irradiance": 100.0},
             "medium": {"sigma_t": 0.05, "albedo": 0.9, "phase": {"type": "isotropic"}},
             "surfaces": []}
    scene.update(over)
    return scene


def test_unshadowed_fog_is_the_closed_form_up_to_the_surface() -> None:
    """Without casters between the camera and the surface: sigma_s p E / sigma_t (1 - exp(-sigma_t t_hit)),
    and sigma_s p E / sigma_t for rays that escape."""
    ground = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]
    for surfaces in ([], ground):
        scene = base_scene(surfaces=surfaces)
        got = ref.medium_sun_radiance(scene, 9, 7)
        o, d = ref.camera_rays(scene, 9, 7)
        with np.errstate(divide="ignore"):
            t_hit = np.where(d[..., 1] < 0, 1.7 / -d[..., 1], np.inf) if surfaces else np.full((7, 9), np.inf)
        expected = 0.9 * 0.05 / (4 * math.pi) * 100.0 / 0.05 * -np.expm1(-0.05 * t_hit)
        np.testing.assert_allclose(got, np.repeat(expected[..., None], 3, axis=-1), rtol=1e-13, atol=0)


def test_phase_is_evaluated_at_the_angle_to_the_sun() -> None:
    """Looking straight at the sun through endless forward-scattering fog gives HG(1), away HG(-1)."""
    g = 0.8
    medium = {"sigma_t": [0.02, 0.04, 0.0], "phase": {"type": "hg", "g": g}}
    sun = {"direction": [0, 2, -2], "irradiance": [1.0, 2.0, 3.0]}
    toward = base_scene(medium=medium, sun=sun,
                        camera={"position": [0, 0, 0], "look_at": [0, 1, -1], "up": [0, 1, 0], "fov_y": 30})
    away = base_scene(medium=medium, sun=sun,
                      camera={"position": [0, 0, 0], "look_at": [0, -1, 1], "up": [0, 1, 0], "fov_y": 30})
    hg = [(1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * mu) ** 1.5) for mu in (1.0, -1.0)]
    for scene, p in zip((toward, away), hg):
        centre = ref.medium_sun_radiance(scene, 3, 3)[1, 1]
        np.testing.assert_allclose(centre, [p * 1.0, p * 2.0, 0.0], rtol=1e-13)  # sigma_s E p / sigma_t


def test_phase_functions_integrate_to_one() -> None:
    hg2 = {"type": "hg2", "forward_g": 0.8, "backward_g": -0.3, "forward_weight": 0.7}
    for phase in ({"type": "isotropic"}, {"type": "hg", "g": 0.85}, {"type": "hg", "g": -0.4},
                  {"type": "rayleigh"}, hg2):
        def density(mu: float, phase: dict = phase) -> float:
            return 2 * math.pi * float(ref.phase_value(phase, np.array(mu)))

        total = integrate.quad(density, -1, 1, epsabs=0, epsrel=1e-12, limit=200)[0]
        assert total == pytest.approx(1.0, rel=1e-9), phase


def test_scene_values_accept_numbers_or_rgb_and_visibility() -> None:
    by_number = ref.medium_sun_radiance(base_scene(medium={"visibility": 3.912 / 0.05, "albedo": 0.9}), 6, 4)
    by_rgb = ref.medium_sun_radiance(
        base_scene(medium={"sigma_t": [0.05] * 3, "albedo": [0.9] * 3},
                   sun={"elevation": 40, "azimuth": -30, "irradiance": [100.0] * 3}), 6, 4)
    np.testing.assert_allclose(by_number, by_rgb, rtol=1e-14)
    by_direction = ref.medium_sun_radiance(base_scene(sun={"direction": ref.sun_direction(
        {"elevation": 40, "azimuth": -30}).tolist(), "irradiance": 100.0}), 6, 4)
    np.testing.assert_allclose(by_direction, by_number, rtol=1e-14)
    with pytest.raises(ValueError):
        ref.medium_coefficients({"sigma_t": 0.1, "visibility": 100.0})


def test_no_light_without_medium_sun_extinction_or_above_horizon_sun() -> None:
    assert not ref.medium_sun_radiance(base_scene(medium=None), 4, 3).any()
    assert not ref.medium_sun_radiance({k: v for k, v in base_scene().items() if k != "sun"}, 4, 3).any()
    below = {"elevation": -5, "azimuth": 0, "irradiance": 1}
    assert not ref.medium_sun_radiance(base_scene(sun=below), 4, 3).any()
    zero_channel = ref.medium_sun_radiance(base_scene(medium={"sigma_t": [0.05, 0.0, 0.05]}), 4, 3)
    assert not zero_channel[..., 1].any() and (zero_channel[..., [0, 2]] > 0).all()


def test_sixty_four_by_forty_eight_with_ten_boxes_is_fast() -> None:
    import time

    boxes = [{"type": "box", "min": [-12 + 3 * i, 0, -40 + i], "max": [-10 + 3 * i, 5 + i, -30 + i]}
             for i in range(10)]
    scene = base_scene(surfaces=[{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}, *boxes])
    start = time.perf_counter()
    radiance = ref.medium_sun_radiance(scene, 64, 48)
    assert time.perf_counter() - start < 3.0
    assert radiance.shape == (48, 64, 3) and np.isfinite(radiance).all()


# ============================================================================================
# The point lamp: shadow intervals against a per-point segment test, radiance against quadrature
# ============================================================================================


def point_in_lamp_shadow(points: np.ndarray, lamp: np.ndarray, surfaces: list[dict]) -> np.ndarray:
    """Whether the segment from x to the lamp meets any surface, per point x of (M, 3)."""
    shadow = np.zeros(len(points), dtype=bool)
    seg = lamp[None, :] - points  # x + u seg, u in [0, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        for sf in surfaces:
            if sf["type"] == "plane":
                n = np.asarray(sf["normal"], float)
                lamp_side = (lamp - sf["point"]) @ n
                if lamp_side != 0.0:
                    shadow |= ((points - sf["point"]) @ n) * lamp_side <= 0.0
            elif sf["type"] == "box":  # slab method on u in [0, 1]
                lo, hi = np.asarray(sf["min"], float), np.asarray(sf["max"], float)
                u_near, u_far = np.zeros(len(points)), np.ones(len(points))
                ok = np.ones(len(points), dtype=bool)
                for i in range(3):
                    flat = seg[:, i] == 0.0
                    ok &= ~flat | ((lo[i] <= points[:, i]) & (points[:, i] <= hi[i]))
                    u1, u2 = (lo[i] - points[:, i]) / seg[:, i], (hi[i] - points[:, i]) / seg[:, i]
                    u_near = np.where(flat, u_near, np.maximum(u_near, np.minimum(u1, u2)))
                    u_far = np.where(flat, u_far, np.minimum(u_far, np.maximum(u1, u2)))
                shadow |= ok & (u_near <= u_far)
            else:  # sphere: the segment's point nearest the centre
                c = np.asarray(sf["center"], float)
                along = np.einsum("ij,ij->i", c - points, seg) / np.einsum("ij,ij->i", seg, seg)
                u = np.clip(along, 0.0, 1.0)
                nearest = points + u[:, None] * seg
                shadow |= np.linalg.norm(nearest - c, axis=1) <= sf["radius"]
    return shadow


def outside_solids(rng: np.random.Generator, surfaces: list[dict], low: float = -12, high: float = 12
                   ) -> np.ndarray:
    """A random point outside every box and sphere (with a margin: no grazing lamp)."""
    while True:
        x = rng.uniform(low, high, size=3)
        if not any(surface_distance(x, sf) < 0.05 or point_inside(x[None, :], [sf])[0]
                   for sf in surfaces if sf["type"] != "plane"):
            return x


LAMP_CASES = ["box", "sphere", "plane", "mixed", "axis_ray", "lamp_in_slab", "lamp_in_face_plane",
              "ray_through_lamp", "ray_from_near_lamp"]


@settings(max_examples=120, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), case=st.sampled_from(LAMP_CASES))
def test_lamp_shadow_intervals_match_per_point_segment_tests(seed: int, case: str) -> None:
    rng = np.random.default_rng(seed)
    counts = {"box": (1, 0, 0), "sphere": (0, 1, 0), "plane": (0, 0, 1), "lamp_in_slab": (1, 0, 0),
              "lamp_in_face_plane": (1, 0, 0)}.get(case, (4, 2, 1))
    surfaces = random_casters(rng, *counts)
    lamp = outside_solids(rng, surfaces)
    if case in ("lamp_in_slab", "lamp_in_face_plane"):  # beside a box: fewer front faces, other silhouettes
        lo, hi = np.asarray(surfaces[0]["min"]), np.asarray(surfaces[0]["max"])
        axes = rng.choice(3, size=2, replace=False)
        inside_axes = axes[: int(rng.integers(1, 3))]
        lamp[inside_axes] = rng.uniform(lo[inside_axes], hi[inside_axes])
        out = axes[-1] if len(inside_axes) == 1 else ({0, 1, 2} - set(axes.tolist())).pop()
        gap = rng.uniform(0.2, 4.0)
        lamp[out] = lo[out] - gap if rng.random() < 0.5 else hi[out] + gap
        if case == "lamp_in_face_plane":  # and exactly in the plane of a face of a remaining axis
            free = [i for i in range(3) if i not in inside_axes and i != out]
            i = free[0] if free else inside_axes[0]
            lamp[i] = lo[i] if rng.random() < 0.5 else hi[i]
    origin = outside_solids(rng, surfaces, -15, 15)
    d = rng.uniform(-8, 8, size=3) - origin  # toward the casters: shadows are met
    solid = surfaces[0]
    if solid["type"] != "plane" and rng.random() < 0.7:  # at a point of the first caster's shadow
        if solid["type"] == "box":
            inner = rng.uniform(solid["min"], solid["max"])
        else:
            inner = np.asarray(solid["center"]) + 0.9 * solid["radius"] * random_unit(rng)
        d = lamp + rng.uniform(1.0, 3.0) * (inner - lamp) - origin
    if case == "ray_through_lamp":
        d = lamp - origin
    elif case == "ray_from_near_lamp":
        origin = lamp + rng.normal(scale=0.5, size=3)
    d /= np.linalg.norm(d)
    if case == "axis_ray":
        d = snap_to_axes(d, rng)

    intervals = ref.lamp_shadow_intervals(origin, d, lamp, surfaces)
    flat = [x for iv in intervals for x in iv]
    assert all(a < b for a, b in intervals)
    assert flat == sorted(flat)
    assert all(left[1] < right[0] for left, right in zip(intervals, intervals[1:]))
    assert not intervals or intervals[0][0] >= 0.0

    t = np.linspace(0.0, 60.0, 20001)
    brute = point_in_lamp_shadow(origin[None, :] + t[:, None] * d[None, :], lamp, surfaces)
    mine = in_intervals(t, intervals)
    bad = (brute != mine) & ~near_ends(t, intervals, 1e-7 * (1.0 + t))
    assert not bad.any(), (f"{bad.sum()} points disagree, first t = {t[bad][:5]}, brute {brute[bad][:5]}, "
                           f"intervals {intervals}")


def test_lamp_sphere_shadow_is_the_ball_and_the_tangent_cone_beyond_the_tangent_circle() -> None:
    """Lamp at the origin, unit sphere at depth 2 below (half-angle 30 degrees, tangent circle at
    depth 1.5): below the ball the cone (half-width depth / sqrt 3); through the ball above the
    tangent circle only the ball; above the ball nothing."""
    sphere = [{"type": "sphere", "center": [0.0, -2.0, 0.0], "radius": 1.0}]
    d = np.array([1.0, 0.0, 0.0])
    for depth in (4.0, 2.0):
        (a, b), = ref.lamp_shadow_intervals([-10.0, -depth, 0.0], d, [0, 0, 0], sphere)
        assert (a, b) == pytest.approx((10 - depth / math.sqrt(3), 10 + depth / math.sqrt(3)), abs=1e-12)
    (a, b), = ref.lamp_shadow_intervals([-10.0, -1.25, 0.0], d, [0, 0, 0], sphere)
    assert (a, b) == pytest.approx((10 - math.sqrt(0.4375), 10 + math.sqrt(0.4375)), abs=1e-12)
    assert ref.lamp_shadow_intervals([-10.0, -0.5, 0.0], d, [0, 0, 0], sphere) == []


def test_lamp_box_shadow_starts_at_the_faces_that_face_the_lamp() -> None:
    """Lamp 5 m above the top of the box [-1, 1] x [4, 5] x [-1, 1]: the top face's shadow widens
    to half-width 2 at the ground; at mid-height it is the box plus the sliver under the top face's
    rim (half-width 1.1); above the box nothing; between the lamp and the box nothing."""
    box = [{"type": "box", "min": [-1.0, 4.0, -1.0], "max": [1.0, 5.0, 1.0]}]
    lamp = [0.0, 10.0, 0.0]
    x = np.array([1.0, 0.0, 0.0])
    assert ref.lamp_shadow_intervals([-10.0, 0.0, 0.0], x, lamp, box) == [(8.0, 12.0)]
    (a, b), = ref.lamp_shadow_intervals([-10.0, 4.5, 0.0], x, lamp, box)
    assert (a, b) == pytest.approx((8.9, 11.1), abs=1e-12)
    assert ref.lamp_shadow_intervals([-10.0, 6.0, 0.0], x, lamp, box) == []
    (a, b), = ref.lamp_shadow_intervals([0.0, 12.0, 0.0], [0.0, -1.0, 0.0], lamp, box)  # through the lamp
    assert (a, b) == (7.0, math.inf)


def test_lamp_inside_a_caster_darkens_everything_and_a_plane_the_far_side() -> None:
    lamp = np.array([0.0, 2.0, 0.0])
    d = np.array([0.0, -0.6, -0.8])
    for caster in ({"type": "box", "min": [-1, 1, -1], "max": [1, 3, 1]},
                   {"type": "sphere", "center": [0.5, 2, 0], "radius": 1.0}):
        assert ref.lamp_shadow_intervals([0.0, 3.0, 5.0], d, lamp, [caster]) == [(0.0, math.inf)]
        assert ref.lamp_shadow_intervals([0.0, 3.0, 5.0], d, lamp, [caster], t_max=7.5) == [(0.0, 7.5)]
    ground = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]
    assert ref.lamp_shadow_intervals([0.0, 3.0, 0.0], d, lamp, ground) == [(5.0, math.inf)]
    assert ref.lamp_shadow_intervals([0.0, 3.0, 0.0], -d, lamp, ground) == []
    assert ref.lamp_shadow_intervals([0.0, 3.0, 0.0], d, [1.0, 0.0, 0.0], ground) == []  # lamp in the plane


# --------------------------------------------------------------------------------------------
# Lamp radiance
# --------------------------------------------------------------------------------------------


def lamp_scene(**over) -> dict:
    scene = {"camera": {"position": [0, 1.7, 0], "look_at": [0.5, 2.0, -10], "up": [0, 1, 0], "fov_y": 60},
             "lights": [{"type": "point", "position": [1.0, 2.6, -8.0], "intensity": [300.0, 200.0, 100.0],
                         "radius": 0.4}],
             "medium": {"sigma_t": 1e-12, "albedo": 1.0},
             "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]}
    scene.update(over)
    return scene


def ray_span(o: np.ndarray, d: np.ndarray, light: dict, surfaces: list[dict]) -> tuple[float, float]:
    """(x0, t_hit) written out: the lamp's sphere (|o + t d - l|^2 = r^2) ends the ray where met ahead,
    and a camera inside it starts at the exit."""
    w = o - np.asarray(light["position"], float)
    b, c = float(w @ d), float(w @ w) - light.get("radius", 0.05) ** 2
    t_hit = ref.first_hit(o, d, surfaces)
    x0 = 0.0
    if b * b - c >= 0.0:
        near, far = -b - math.sqrt(b * b - c), -b + math.sqrt(b * b - c)
        if near > 0.0:
            t_hit = min(t_hit, near)
        elif far > 0.0:
            x0 = far
    return x0, t_hit


@pytest.mark.parametrize("camera_in_lamp", [False, True])
def test_lamp_radiance_in_thin_isotropic_fog_is_the_subtended_angle_over_the_miss_distance(
        camera_in_lamp: bool) -> None:
    """sigma_t -> 0, isotropic: L = sigma_s I / (4 pi h) [atan((t_hit - b) / h) - atan((x0 - b) / h)],
    h the ray's miss distance and b its closest approach (int dx / (h^2 + (x - b)^2)); rays to the sky,
    to the ground and into the lamp's sphere, and from a camera inside the sphere."""
    scene = lamp_scene()
    if camera_in_lamp:
        scene["lights"][0].update(position=[0.2, 1.9, -0.3], radius=1.0)
    light = scene["lights"][0]
    w, h = 24, 18
    got = ref.lamp_airlight_radiance(scene, w, h)
    o, dirs = ref.camera_rays(scene, w, h)
    lamp = np.asarray(light["position"], float)
    expected = np.zeros((h, w, 3))
    kinds = set()
    for row in range(h):
        for col in range(w):
            d = dirs[row, col]
            x0, t_hit = ray_span(o, d, light, scene["surfaces"])
            kinds.add(("sky" if math.isinf(t_hit) else "hit", x0 > 0))
            b, miss = float((lamp - o) @ d), float(np.linalg.norm(np.cross(lamp - o, d)))
            angle = math.atan((t_hit - b) / miss) - math.atan((x0 - b) / miss)
            expected[row, col] = 1e-12 * np.array(light["intensity"]) / (4 * math.pi * miss) * angle
    assert {("sky", camera_in_lamp), ("hit", camera_in_lamp)} <= kinds
    if not camera_in_lamp:
        hits_lamp = [ray_span(o, d, light, [])[1] < math.inf for d in dirs.reshape(-1, 3)]
        assert any(hits_lamp)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=0)


def lamp_integrand(o: np.ndarray, d: np.ndarray, lamp: np.ndarray, g: float, sigma: float):
    """x -> p(cos theta) exp(-sigma (x + dist)) / dist^2, cos theta = unit(x - l) . (-d), HG(g) by hand."""
    w = o - lamp

    def f(x: float) -> float:
        v = w + x * d
        dist = math.sqrt(float(v @ v))
        mu = -float(v @ d) / dist
        p = (1 - g * g) / (4 * math.pi * (1 + g * g - 2 * g * mu) ** 1.5)
        return p * math.exp(-sigma * (x + dist)) / (dist * dist)

    return f


def quad_split_at_closest_approach(f, a: float, c: float, b: float) -> float:
    pieces = [(a, c)] if not a < b < c else [(a, b), (b, c)]
    return sum(integrate.quad(f, lo, hi, epsabs=0, epsrel=1e-12, limit=400)[0] for lo, hi in pieces)


def test_unshadowed_lamp_radiance_matches_quadrature_of_the_single_scattering_integral() -> None:
    """HG fog, coloured extinction, no shadows: scipy quad in x (split at the closest approach) of
    sigma_s I p exp(-sigma_t (x + d)) / d^2 on rays to the sky, grazing the lamp ((8, 13): 0.44 m from its
    centre), into it ((7, 13)) and to the ground."""
    g, sigma_t, albedo = 0.6, np.array([0.05, 0.1, 0.2]), np.array([0.9, 0.8, 1.0])
    scene = lamp_scene(medium={"sigma_t": sigma_t.tolist(), "albedo": albedo.tolist(),
                               "phase": {"type": "hg", "g": g}})
    light = scene["lights"][0]
    lamp = np.asarray(light["position"], float)
    w, h = 24, 18
    got = ref.lamp_airlight_radiance(scene, w, h)
    o, dirs = ref.camera_rays(scene, w, h)
    for row, col in [(0, 0), (5, 14), (7, 13), (8, 13), (9, 12), (17, 3), (17, 20)]:
        d = dirs[row, col]
        x0, t_hit = ray_span(o, d, light, scene["surfaces"])
        assert ref.lamp_shadow_intervals(o, d, lamp, scene["surfaces"], t_hit) == []
        b = float((lamp - o) @ d)
        total = [quad_split_at_closest_approach(lamp_integrand(o, d, lamp, g, s), x0, t_hit, b)
                 for s in sigma_t]
        expected = albedo * sigma_t * np.array(light["intensity"]) * np.array(total)
        np.testing.assert_allclose(got[row, col], expected, rtol=1e-9, atol=0)


LAMP_SHADOW_SCENE = {  # a lamp among pillars over the ground: shadow spokes across the view
    "camera": {"position": [0.0, 1.7, 0.0], "look_at": [1.0, 2.0, -12.0], "up": [0, 1, 0], "fov_y": 70},
    "lights": [{"type": "point", "position": [1.0, 4.0, -12.0], "intensity": [500.0, 400.0, 300.0]}],
    "medium": {"sigma_t": [0.05, 0.03, 0.08], "albedo": [0.9, 1.0, 0.8], "phase": {"type": "hg", "g": 0.7}},
    "surfaces": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
                 *({"type": "box", "min": [1 + 3 * math.cos(k), 0, -12 + 3 * math.sin(k)],
                    "max": [1.6 + 3 * math.cos(k), 6, -11.4 + 3 * math.sin(k)]} for k in range(6)),
                 {"type": "sphere", "center": [-1.0, 5.5, -11.0], "radius": 0.7},
                 {"type": "box", "min": [-60, 0, -40], "max": [60, 40, -38]}],  # a back wall
}


def test_shadowed_lamp_radiance_matches_quadrature_between_bisected_shadow_edges() -> None:
    """Lit/shadow switches located by bisection on the brute-force segment test (not the reference's
    intervals), then scipy quad in x of the lamp's integrand on each lit piece, rtol 1e-8."""
    scene = LAMP_SHADOW_SCENE
    light, surfaces = scene["lights"][0], scene["surfaces"]
    lamp = np.asarray(light["position"], float)
    w, h = 24, 18
    radiance = ref.lamp_airlight_radiance(scene, w, h)
    o, dirs = ref.camera_rays(scene, w, h)
    picked = []
    for row in range(h):
        for col in range(w):
            d = dirs[row, col]
            x0, t_hit = ray_span(o, d, light, surfaces)
            if math.isfinite(t_hit) and len(ref.lamp_shadow_intervals(o, d, lamp, surfaces, t_hit)) >= 2:
                picked.append((row, col))
    assert len(picked) >= 4, "the pillars should cast several shadows across some pixels"
    sigma_t, albedo = np.array([0.05, 0.03, 0.08]), np.array([0.9, 1.0, 0.8])
    for row, col in picked[:: max(1, len(picked) // 4)][:4]:
        d = dirs[row, col]
        x0, t_hit = ray_span(o, d, light, surfaces)

        def lit_at(t, d=d) -> np.ndarray:
            return ~point_in_lamp_shadow(o[None, :] + np.atleast_1d(t)[:, None] * d[None, :], lamp, surfaces)

        grid = np.linspace(x0, t_hit, 20001)
        lit = lit_at(grid)
        edges = [x0]
        for i in np.flatnonzero(lit[1:] != lit[:-1]):
            a, b = grid[i], grid[i + 1]
            for _ in range(80):
                m = 0.5 * (a + b)
                if lit_at(m)[0] == lit[i]:
                    a = m
                else:
                    b = m
            edges.append(0.5 * (a + b))
        edges.append(t_hit)
        assert len(edges) >= 4
        b = float((lamp - o) @ d)
        total = np.zeros(3)
        for j, (a, c) in enumerate(zip(edges[:-1], edges[1:])):
            if bool(lit[0]) != (j % 2 == 1):
                total += [quad_split_at_closest_approach(lamp_integrand(o, d, lamp, 0.7, s), a, c, b)
                          for s in sigma_t]
        expected = albedo * sigma_t * np.array(light["intensity"]) * total
        np.testing.assert_allclose(radiance[row, col], expected, rtol=1e-8, atol=0)


def test_no_lamp_light_without_medium_or_lights_and_spot_lights_are_refused() -> None:
    assert not ref.lamp_airlight_radiance(lamp_scene(medium=None), 4, 3).any()
    assert not ref.lamp_airlight_radiance(lamp_scene(lights=[]), 4, 3).any()
    spot = {"type": "spot", "position": [0, 3, -5], "direction": [0, -1, 0], "intensity": 1, "cone_angle": 30}
    with pytest.raises(ValueError):
        ref.lamp_airlight_radiance(lamp_scene(lights=[spot]), 4, 3)
