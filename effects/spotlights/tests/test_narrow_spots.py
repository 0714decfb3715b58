"""The narrowest spots (issue 27, item 7): a 0.01 degree cone lit nothing. float32
rounds cos A to 1 below about 0.02 degree, and the cone tests ax^2 >= cos^2 A |v|^2,
ct >= cos A and acos(cos A / R) then let no light through: a beam crossing a view ray
1.5 mm to 1 m from the camera gave 0 on both backends, its glow on a wall too. The
tests are now in sin^2 A (spot.glsl: spot_lit_at, spot_profile, the glow's arcs)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from spot_reference import make_spot, parse_spot_scene, spot_airlight_riemann, spot_pixel_radiance

SIGMA_T = 0.05


def crossing_spot(distance: float, crossing: float, angle_deg: float, cone: float) -> tuple[list, list]:
    """A spot `distance` from where its axis crosses the view ray (the -z axis) at `crossing`
    metres from the camera, the axis at `angle_deg` to the ray."""
    a = math.radians(angle_deg)
    axis = np.array([-math.sin(a), 0.0, math.cos(a)])
    position = np.array([0.0, 0.0, -crossing]) - distance * axis
    return position.tolist(), axis.tolist()


CASES = [case for case in itertools.product([0.5, 1.0, 10.0], [0.0015, 0.0032, 0.1, 1.0], [90.0, 30.0, 10.0],
                                            [0.01, 0.005])
         if math.sin(math.radians(case[2])) * case[1] > 2 * case[0] * math.tan(math.radians(case[3]))]


@pytest.mark.parametrize(("distance", "crossing", "angle_deg", "cone"), CASES)
def test_the_narrowest_cones_light_the_fog_they_cross(distance, crossing, angle_deg, cone, renderer):
    position, axis = crossing_spot(distance, crossing, angle_deg, cone)
    scene = {"film": {"width": 1, "height": 1},
             "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 10},
             "medium": {"sigma_t": SIGMA_T, "albedo": 1.0},
             "lights": [{"type": "spot", "position": position, "direction": axis, "intensity": 100,
                         "cone_angle": cone, "radius": 1e-4}]}
    got = float(renderer.render(scene)[0, 0, 0])
    # Brute force over an interval holding the whole lit chord (the cone's width there over the sine
    # of the crossing angle, doubled): the midpoint rule testing the cone at every point.
    half = 2.0 * distance * math.tan(math.radians(cone)) / math.sin(math.radians(angle_deg))
    x0, x1 = max(crossing - half, 0.0), crossing + half
    expected = spot_airlight_riemann(SIGMA_T, SIGMA_T, 100.0, [0, 0, 0], [0, 0, -1], position,
                                     make_spot(axis, cone), x0, x1, n=200_000)
    assert expected > 0
    assert got == pytest.approx(expected, rel=1e-2)


@pytest.mark.slow
def test_a_narrow_beam_glows_on_the_wall_beside_it(renderer):
    scene = {"film": {"width": 12, "height": 8},
             "camera": {"position": [0, 1, 0], "look_at": [0, 1, -5], "up": [0, 1, 0], "fov_y": 50},
             "medium": {"sigma_t": SIGMA_T, "albedo": 0.9},
             "lights": [{"type": "spot", "position": [-3, 1.2, -4], "direction": [1, 0, -0.05],
                         "intensity": 1e4, "cone_angle": 0.01, "radius": 1e-3}],
             "surfaces": [{"type": "plane", "point": [0, 0, -5], "normal": [0, 0, 1], "albedo": 0.7}]}
    image = renderer.render(scene)
    rows, cols = [2, 3, 5, 6], [2, 5, 6, 9]
    ref = spot_pixel_radiance(parse_spot_scene(scene), rows, cols)
    got = image[rows, cols].astype(np.float64)
    assert (ref > 0).all()
    np.testing.assert_allclose(got, ref, rtol=2e-2)
