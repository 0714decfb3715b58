"""Large spheres as ground (issue 27, item 5): a lamp over a ground sphere of radius 1e4
(centre 1e4 below) left 622 of 1152 ground pixels black, with R = 1000 131, with
R = 6.4e6 55 (a plane: 0), and GL and CPU disagreed there: the shadow rays met
their own sphere again at t ~ 0 where float rounding of about 6e-8 (|c| + r) put
their origin inside it. Shadow rays now treat the surface they start on exactly
(a convex surface is met again only by a ray entering it, at the far root), and
the sphere test forms its discriminant as (r - d)(r + d), so a sphere of radius
1e20 neither overflows nor vanishes."""

from __future__ import annotations

import numpy as np
import pytest
from reference import render_reference

SIZE = 48


def ground_sphere_scene(radius: float, box: bool = True) -> dict:
    scene = {"film": {"width": SIZE, "height": SIZE},
            "camera": {"position": [0, 1.7, 0], "look_at": [0, 0, -10], "up": [0, 1, 0], "fov_y": 60},
            "lights": [{"type": "point", "position": [0, 5, -10], "intensity": 100}],
            "surfaces": [{"type": "sphere", "center": [0, -radius, 0], "radius": radius, "albedo": 0.5},
                         {"type": "box", "min": [1, 0, -9], "max": [2, 1, -8], "albedo": 0.5}]}
    if not box:
        del scene["surfaces"][1]
    return scene


@pytest.mark.parametrize("radius", [1e3, 1e4])
def test_a_large_ground_sphere_is_lit_as_the_float64_reference(radius, renderer):
    scene = ground_sphere_scene(radius)
    image = renderer.render(scene).astype(np.float64)
    ref = render_reference(scene)
    lit = ref.smooth_mask() & (ref.radiance.sum(-1) > 1e-3 * ref.radiance.sum(-1).max())
    assert lit.sum() > 0.3 * SIZE * SIZE
    rel = np.abs(image - ref.radiance)[lit] / ref.radiance[lit]
    assert rel.max() < 0.01, f"R = {radius}: {int((rel > 0.01).sum())} off by > 1 %, worst {rel.max():.3g}"


@pytest.mark.parametrize("radius", [1e3, 1e4, 6.4e6])
def test_no_shadow_acne_on_a_large_ground_sphere(radius, renderer):
    """Where the reference's ground is lit no pixel is black (no box: at R = 6.4e6 the sphere's
    float32 coordinates move the ground by up to 0.25 m, and its shadow with it; only the acne is
    tested there, not the values)."""
    scene = ground_sphere_scene(radius, box=False)
    image = renderer.render(scene)
    ref = render_reference(scene)
    lit = ref.smooth_mask() & (ref.radiance.sum(-1) > 1e-3 * ref.radiance.sum(-1).max())
    black = lit & (image.sum(-1) <= 0.0)
    assert not black.any(), f"R = {radius}: {int(black.sum())} of {int(lit.sum())} lit ground pixels black"


def test_a_sphere_of_radius_1e20_around_the_camera_hides_the_background(renderer):
    scene = {"film": {"width": 8, "height": 8},
             "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_y": 60},
             "background": [1, 1, 1],
             "surfaces": [{"type": "sphere", "center": [0, 0, 0], "radius": 1e20, "albedo": 0.5}]}
    image = renderer.render(scene)
    assert np.isfinite(image).all()
    assert image.max() == 0.0  # the unlit inner face, not the background
