"""Self-test of the noise clouds' float64 reference (clouds_reference.py): texture sampling against
texel values, linear functions and scipy's own periodic interpolation; the height profile and the
density against hand-worked values; the view and light marches against closed forms for a slab of
constant extinction and against scipy quadrature of a layered density; convergence in the step
counts. No renderer: the textures are synthetic (seeded random or smooth periodic)."""

from __future__ import annotations

import math

import clouds_reference as ref
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, ndimage

# --------------------------------------------------------------------------------------------
# Synthetic textures and scenes
# --------------------------------------------------------------------------------------------


def random_texture(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).random((n, n, n, 4)).astype(np.float32)


def smooth_texture(n: int, phase: float) -> np.ndarray:
    """Periodic, smooth, in [0, 1]: each channel a sum of sines of the texel centre's position."""
    c = (np.arange(n) + 0.5) / n * 2.0 * math.pi
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    chans = [0.5 + 0.25 * np.sin(x + phase + k) * np.cos(y - 2 * k) + 0.2 * np.sin(z + 3 * k + phase)
             for k in range(4)]
    return np.stack(chans, axis=-1)


def constant_texture(n: int, value: float) -> np.ndarray:
    return np.full((n, n, n, 4), value)


SHAPE = ref.NoiseTexture(random_texture(16, 1))
DETAIL = ref.NoiseTexture(random_texture(8, 2))
SMOOTH_SHAPE = ref.NoiseTexture(smooth_texture(16, 0.3))
SMOOTH_DETAIL = ref.NoiseTexture(smooth_texture(8, 1.1))


def up_scene(**extra) -> dict:
    """A camera on the ground looking up into the sky at 45 degrees, a sun behind it."""
    scene = {"camera": {"position": [0.0, 2.0, 0.0], "look_at": [0.0, 1002.0, -1000.0], "up": [0, 1, 0],
                        "fov_y": 50.0},
             "sun": {"elevation": 40.0, "azimuth": 25.0, "irradiance": [1000.0, 900.0, 800.0]},
             "sky": {"model": "overcast", "zenith_radiance": [20.0, 25.0, 40.0]}}
    scene.update(extra)
    return scene


# --------------------------------------------------------------------------------------------
# Texture sampling (eq. 1.1)
# --------------------------------------------------------------------------------------------


def test_sample_periodic_reproduces_texels_at_their_centres():
    tex = random_texture(8, 3)
    k, j, i = np.meshgrid(np.arange(8), np.arange(8), np.arange(8), indexing="ij")
    u = (np.stack([i, j, k], axis=-1) + 0.5) / 8
    np.testing.assert_array_equal(ref.sample_periodic(tex, u), tex.astype(np.float64))


@settings(max_examples=60, deadline=None)
@given(st.tuples(*[st.floats(-3.0, 3.0) for _ in range(3)]), st.integers(-2, 2), st.integers(0, 2))
def test_sample_periodic_wraps_with_period_one(u, shift, axis):
    u = np.array(u)
    v = u.copy()
    v[axis] += shift
    np.testing.assert_allclose(ref.sample_periodic(SHAPE, v), ref.sample_periodic(SHAPE, u),
                               rtol=0, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.tuples(*[st.floats(0.5 / 8, 7.5 / 8) for _ in range(3)]))
def test_trilinear_is_exact_for_multilinear_texels(u):
    """Away from the wrapping cells, texels of a function linear in each index give that function."""
    n = 8
    k, j, i = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    tex = np.stack([0.1 + 0.02 * i + 0.03 * j - 0.01 * k, (1 + i) * (2 + j) * (3 + k) / 500.0,
                    0.5 + 0.0 * i, 0.01 * i * k], axis=-1)
    f = n * np.array(u) - 0.5  # index coordinates
    expected = [0.1 + 0.02 * f[0] + 0.03 * f[1] - 0.01 * f[2], (1 + f[0]) * (2 + f[1]) * (3 + f[2]) / 500.0,
                0.5, 0.01 * f[0] * f[2]]
    np.testing.assert_allclose(ref.sample_periodic(tex, np.array(u)), expected, rtol=1e-12, atol=1e-14)


def test_sample_periodic_matches_scipy_grid_wrap_interpolation():
    tex = random_texture(16, 4).astype(np.float64)
    u = np.random.default_rng(5).uniform(-4, 4, (2000, 3))
    f = 16 * (u - np.floor(u)) - 0.5
    scipy_vals = np.stack([ndimage.map_coordinates(tex[..., c], [f[:, 2], f[:, 1], f[:, 0]], order=1,
                                                   mode="grid-wrap") for c in range(4)], axis=-1)
    np.testing.assert_allclose(ref.sample_periodic(tex, u), scipy_vals, rtol=0, atol=1e-13)


def test_float32_texels_sample_like_their_float64_copy():
    tex = random_texture(16, 6)
    u = np.random.default_rng(7).uniform(-2, 2, (500, 3))
    np.testing.assert_array_equal(ref.sample_periodic(tex, u), ref.sample_periodic(tex.astype(np.float64), u))


# --------------------------------------------------------------------------------------------
# Height profile and density (section 2)
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cloud_type,corners", [(0.0, (0.05, 0.15, 0.3)), (0.5, (0.1, 0.4, 0.7)),
                                                (1.0, (0.05, 0.7, 1.0)), (0.25, (0.075, 0.275, 0.5))])
def test_height_profile_corners(cloud_type, corners):
    a, b, t = corners
    np.testing.assert_allclose(ref.profile_corners(cloud_type), corners, rtol=1e-14)
    h = np.array([-0.1, 0.0, a / 2, a, (a + b) / 2, b, (b + t) / 2, t, t + 0.01, 1.2])
    np.testing.assert_allclose(ref.height_profile(h, cloud_type),
                               [0, 0, 0.5, 1, 1, 1, 0.5, 0, 0, 0], rtol=1e-12, atol=1e-15)


@settings(max_examples=80, deadline=None)
@given(st.floats(-0.2, 1.2), st.floats(0.0, 1.0))
def test_height_profile_is_continuous_in_height_and_type(h, cloud_type):
    eps = 1e-7
    a, b, t = ref.profile_corners(cloud_type)
    slope = max(1.0 / a, 1.0 / (t - b))
    value = float(ref.height_profile(h, cloud_type))
    assert 0.0 <= value <= 1.0
    assert abs(float(ref.height_profile(h + eps, cloud_type)) - value) <= slope * eps * (1 + 1e-6)
    # The corners move at most 0.6 per unit of type, and H's derivatives in them are at most
    # 1.2 slope^2 (h in [-0.2, 1.2]): 2 slope^2 bounds the Lipschitz constant in type.
    other = float(ref.height_profile(h, min(cloud_type + eps, 1.0)))
    assert abs(other - value) <= 2 * slope * slope * eps + 1e-12


LAYER = {"base": 1000.0, "top": 3000.0, "coverage": 0.7, "type": 0.6, "erosion": 0.4, "shape_scale": 3000.0,
         "detail_scale": 400.0}


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-2e4, 2e4), st.floats(-500.0, 4000.0), st.floats(-2e4, 2e4)),
                min_size=1, max_size=20))
def test_density_lies_in_unit_interval_and_vanishes_outside_the_layer(points):
    p = np.array(points)
    d = ref.density(p, LAYER, SHAPE, DETAIL)
    assert d.shape == (len(p),)
    assert np.all((d >= 0.0) & (d <= 1.0))
    h = (p[:, 1] - 1000.0) / 2000.0
    assert np.all(d[(h <= 0.0) | (h >= ref.profile_corners(0.6)[2])] == 0.0)


def test_density_is_zero_at_zero_coverage():
    p = np.random.default_rng(8).uniform([-1e4, 900, -1e4], [1e4, 3100, 1e4], (5000, 3))
    assert np.any(ref.density(p, LAYER, SHAPE, DETAIL) > 0.0)
    assert not np.any(ref.density(p, {**LAYER, "coverage": 0.0}, SHAPE, DETAIL))


def test_density_of_constant_textures_by_hand():
    """Shape texels all 0.5: low = 0.5, s = (0.5 + 0.5) / 1.5 = 2/3. Detail texels all 0.2: high = 0.2.
    Coverage 0.9, erosion 0.35, cumulus (a = 0.1, b = 0.4, t = 0.7), layer 1000 m to 3000 m."""
    clouds = {"base": 1000.0, "top": 3000.0, "coverage": 0.9, "type": 0.5, "erosion": 0.35}
    shape, detail = constant_texture(4, 0.5), constant_texture(4, 0.2)
    # h = 0.25: H = 1, s_c = 2/3 - 0.1 = 17/30; 10 h > 1 so m = 1 - high = 0.8, e m = 0.28.
    # h = 0.05: H = 0.5, s_h = 1/3, s_c = 1/3 - 0.1 = 7/30; m = mix(0.2, 0.8, 0.5) = 0.5, e m = 0.175.
    # h = 0.6: H = (0.7 - 0.6) / 0.3 = 1/3, s_h = 2/9, s_c = 2/9 - 0.1 = 11/90 < e m = 0.28: d = 0.
    # h = 0.15: H = 1, s_c = 17/30, m = 0.8, d as at h = 0.25.
    y = 1000.0 + 2000.0 * np.array([0.25, 0.05, 0.6, 0.15])
    p = np.stack([np.full(4, 123.0), y, np.full(4, -77.0)], axis=-1)
    expected = [(17 / 30 - 0.28) / 0.72, (7 / 30 - 0.175) / 0.825, 0.0, (17 / 30 - 0.28) / 0.72]
    np.testing.assert_allclose(ref.density(p, clouds, shape, detail), expected, rtol=1e-13)
    np.testing.assert_allclose(ref.sigma_t(p, {**clouds, "extinction": 0.02}, shape, detail),
                               0.02 * np.array(expected), rtol=1e-13)


@settings(max_examples=30, deadline=None)
@given(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0), st.floats(-1e4, 1e4))
def test_wind_moves_the_field(vx, vz, time):
    p = np.random.default_rng(9).uniform([-1e4, 1000, -1e4], [1e4, 3000, 1e4], (200, 3))
    moved = {**LAYER, "wind": [vx, vz], "time": time}
    shifted = p - np.array([vx * time, 0.0, vz * time])
    np.testing.assert_array_equal(ref.density(p, moved, SHAPE, DETAIL),
                                  ref.density(shifted, LAYER, SHAPE, DETAIL))


def test_hg_phase_is_normalised():
    for g in (-0.5, 0.0, 0.2, 0.85):
        total = integrate.quad(lambda mu, g=g: 2 * math.pi * float(ref.hg_phase(mu, g)), -1, 1,
                               epsabs=0, epsrel=1e-12)[0]
        assert total == pytest.approx(1.0, rel=1e-10)


# --------------------------------------------------------------------------------------------
# Light transmittance (eq. 3.2)
# --------------------------------------------------------------------------------------------


def layered_clouds() -> tuple[dict, np.ndarray, np.ndarray]:
    """Constant textures: the density depends on the height only (plane-parallel layer)."""
    clouds = {"base": 1000.0, "top": 2000.0, "coverage": 0.9, "type": 0.5, "erosion": 0.35,
              "extinction": 0.01}
    return clouds, constant_texture(4, 0.5), constant_texture(4, 0.2)


def column(clouds, shape, detail, y0: float, y1: float) -> float:
    """int_{y0}^{y1} sigma_t dy of a plane-parallel layer by scipy quad, split at the kinks."""
    a, b, t = ref.profile_corners(clouds["type"])
    base, top = clouds["base"], clouds["top"]
    kinks = [base + (top - base) * h for h in (0.0, 0.1, a, b, t, 1.0)]

    def sigma(y: float) -> float:
        return float(ref.sigma_t(np.array([0.0, y, 0.0]), clouds, shape, detail))

    pts = sorted(k for k in kinks if y0 < k < y1)
    return integrate.quad(sigma, y0, y1, points=pts or None, epsabs=1e-13, epsrel=1e-11, limit=200)[0]


def test_light_transmittance_matches_quadrature_of_a_layered_density():
    clouds, shape, detail = layered_clouds()
    p = np.array([[10.0, 1150.0, 20.0], [0.0, 1500.0, 0.0], [0.0, 900.0, 0.0]])
    w = np.array([0.5, 0.7, -0.2])
    w /= np.linalg.norm(w)
    got = ref.transmittance_to_boundary(p, w, clouds, shape, detail, steps=4096)
    expected = [math.exp(-column(clouds, shape, detail, y, 2000.0) / w[1]) for y in p[:, 1]]
    np.testing.assert_allclose(got, expected, rtol=2e-6)
    # Downward from above the profile's top: the whole column.
    down = ref.transmittance_to_boundary(np.array([0.0, 2500.0, 0.0]), [0.0, -1.0, 0.0], clouds, shape,
                                         detail, steps=4096)
    assert float(down) == pytest.approx(math.exp(-column(clouds, shape, detail, 1000.0, 2000.0)), rel=2e-6)


def test_light_march_of_a_constant_slab_is_exact():
    sigma = 0.003
    pts = np.array([[0.0, 1200.0, 0.0], [5.0, 1990.0, 1.0], [0.0, 2500.0, 0.0]])
    w = np.array([0.0, 0.6, 0.8])
    tau = ref.optical_depth_march(pts, w, lambda x: np.full(len(x), sigma), 1000.0, 2000.0, steps=7)
    np.testing.assert_allclose(tau, [sigma * 800 / 0.6, sigma * 10 / 0.6, 0.0], rtol=1e-13)


def test_horizontal_light_march_is_cut_far_away():
    tau = ref.optical_depth_march(np.array([[0.0, 1500.0, 0.0]]), [1.0, 0.0, 0.0],
                                  lambda x: np.full(len(x), 1e-4), 1000.0, 2000.0, steps=16, far=5000.0)
    assert float(tau[0]) == pytest.approx(0.5, rel=1e-13)


# --------------------------------------------------------------------------------------------
# View march (eq. 3.3) against closed forms for a constant slab
# --------------------------------------------------------------------------------------------

SLAB = (1000.0, 1800.0)
SLAB_SIGMA = 0.002


def slab_sigma(x: np.ndarray) -> np.ndarray:
    return np.where((x[:, 1] >= SLAB[0]) & (x[:, 1] <= SLAB[1]), SLAB_SIGMA, 0.0)


def slab_closed_form(scene: dict, width: int, height: int, albedo: float, g: float):
    """Per pixel: int_{t_in}^{t_out} T(0, t) J dt for constant sigma in the slab [y0, y1], rays going
    up from below it. Toward a light w (w_y > 0) the optical depth from x(t) is sigma (y1 - y(t)) / w_y
    and T(0, t) = exp(-sigma_m t - sigma (t - t_in)), so each light's term is
    sigma_s E P int exp(C - k t) dt with k = sigma_m + sigma (1 - d_y / w_y),
    C = sigma t_in - sigma (y1 - o_y) / w_y: sigma_s E P exp(C - k t_in) L (1 - exp(-k L)) / (k L)."""
    origin, dirs, _ = ref.view_rays(scene, width, height)
    y0, y1 = SLAB
    s, e_sun = ref.sun_light(scene)
    e_sky = ref.sky_irradiance(scene)
    sig_m = ref.medium_sigma_t(scene)
    sigma = SLAB_SIGMA
    out = np.zeros((len(dirs), 3))
    tau = np.zeros(len(dirs))
    for i, d in enumerate(dirs):
        t_in, t_out = (y0 - origin[1]) / d[1], (y1 - origin[1]) / d[1]
        length = t_out - t_in
        tau[i] = sigma * length
        lights = ((s, e_sun, float(ref.hg_phase(s @ d, g))),
                  (np.array([0.0, 1.0, 0.0]), e_sky / (2 * math.pi), 1.0))
        for w, e, p in lights:
            k = sig_m + sigma * (1.0 - d[1] / w[1])
            c = sigma * t_in - sigma * (y1 - origin[1]) / w[1]
            phi = np.where(k * length != 0, -np.expm1(-k * length) / np.where(k != 0, k * length, 1.0), 1.0)
            out[i] += albedo * sigma * e * p * np.exp(c - k * t_in) * length * phi
    return out.reshape(height, width, 3), tau.reshape(height, width)


SLAB_SCENE = up_scene(medium={"sigma_t": [1e-4, 2e-4, 4e-4]})


def test_view_march_matches_the_closed_form_of_a_constant_slab():
    expected, tau = slab_closed_form(SLAB_SCENE, 5, 4, 0.9, 0.3)
    got, got_tau = ref.layer_radiance_with(SLAB_SCENE, 5, 4, slab_sigma, SLAB, 0.9, 0.3, steps=512,
                                           light_steps=3)
    np.testing.assert_allclose(got_tau, tau, rtol=1e-12)
    np.testing.assert_allclose(got, expected, rtol=2e-5)


def test_view_march_converges_at_second_order():
    expected, _ = slab_closed_form(SLAB_SCENE, 3, 2, 1.0, 0.2)
    errors = [np.abs(ref.layer_radiance_with(SLAB_SCENE, 3, 2, slab_sigma, SLAB, 1.0, 0.2, steps=n,
                                             light_steps=2)[0] / expected - 1).max() for n in (32, 64, 128)]
    assert errors[0] > 1e-5
    for coarse, fine in zip(errors, errors[1:]):
        assert 3.5 < coarse / fine < 4.5


def test_view_march_chunks_and_per_ray_step_counts_do_not_change_the_result(monkeypatch):
    """Rays of different step counts (max_step) in chunks that split between them."""
    expected, _ = slab_closed_form(SLAB_SCENE, 4, 3, 1.0, 0.2)
    whole, _ = ref.layer_radiance_with(SLAB_SCENE, 4, 3, slab_sigma, SLAB, 1.0, 0.2, steps=64,
                                       light_steps=2, max_step=3.0)
    monkeypatch.setattr(ref, "_VIEW_CHUNK_SAMPLES", 1000)
    monkeypatch.setattr(ref, "_LIGHT_BATCH_POINTS", 64)
    chunked, _ = ref.layer_radiance_with(SLAB_SCENE, 4, 3, slab_sigma, SLAB, 1.0, 0.2, steps=64,
                                         light_steps=2, max_step=3.0)
    np.testing.assert_allclose(chunked, whole, rtol=1e-12)
    np.testing.assert_allclose(whole, expected, rtol=2e-5)


def test_view_march_stops_at_a_surface_inside_the_layer():
    """A wide box whose underside (y = 1300 m) lies inside the slab ends the rays there: the
    slab's part of each ray is [t_in, t_hit]."""
    roof = {"type": "box", "min": [-1e5, 1300.0, -1e5], "max": [1e5, 1400.0, 1e5]}
    scene = {**SLAB_SCENE, "surfaces": [roof], "sky": None}
    got, tau = ref.layer_radiance_with(scene, 2, 2, slab_sigma, SLAB, 1.0, 0.2, steps=256, light_steps=2)
    origin, dirs, t_end = ref.view_rays(scene, 2, 2)
    np.testing.assert_allclose(t_end, (1300.0 - origin[1]) / dirs[:, 1], rtol=1e-12)
    np.testing.assert_allclose(tau.ravel(), SLAB_SIGMA * 300.0 / dirs[:, 1], rtol=1e-12)
    assert np.all(got > 0.0)


# --------------------------------------------------------------------------------------------
# Whole pipeline with textures
# --------------------------------------------------------------------------------------------


def one_ray_scene(direction, clouds, **extra) -> dict:
    pos = np.array([0.0, 2.0, 0.0])
    return {"camera": {"position": pos.tolist(), "look_at": (pos + np.asarray(direction)).tolist(),
                       "up": [0, 1, 0], "fov_y": 30.0}, "clouds": clouds, **extra}


def test_layered_cloud_radiance_matches_its_closed_form():
    """Plane-parallel layer (constant textures), one pixel, sun and sky, no medium. With C(y) the
    column from the base and C_t the whole column, the integrand sigma exp(-C / d_y - (C_t - C) / w_y)
    is a derivative in C, so each light's term is exactly
        E P / d_y exp(-C_t / w_y) (1 - exp(-k C_t)) / k,   k = 1 / d_y - 1 / w_y,
    and only C_t needs a (scipy) quadrature."""
    clouds, shape, detail = layered_clouds()
    d = np.array([0.0, 0.8, -0.6])
    scene = one_ray_scene(d, clouds, sun={"elevation": 50.0, "azimuth": 10.0, "irradiance": [1.0, 2.0, 3.0]},
                          sky={"model": "overcast", "zenith_radiance": [0.1, 0.2, 0.4]})
    s, e_sun = ref.sun_light(scene)
    e_sky = ref.sky_irradiance(scene)
    c_t = column(clouds, shape, detail, 1000.0, 2000.0)
    assert c_t > 0.5

    def term(w_y: float) -> float:
        k = 1.0 / d[1] - 1.0 / w_y
        return math.exp(-c_t / w_y) * -math.expm1(-k * c_t) / k / d[1]

    expected = e_sun * float(ref.hg_phase(s @ d, 0.2)) * term(s[1]) + e_sky / (2 * math.pi) * term(1.0)
    got = ref.clouds_layer_radiance(scene, 1, 1, shape, detail, steps=1024, light_steps=256)[0, 0]
    np.testing.assert_allclose(got, expected, rtol=1e-5)


def test_transmittance_combines_clouds_and_medium():
    clouds, shape, detail = layered_clouds()
    d = np.array([0.0, 0.6, -0.8])
    ground = {"type": "plane", "point": [0, 2100.0, 0], "normal": [0, 1, 0]}
    scene = one_ray_scene(d, clouds, medium={"visibility": 39120.0}, surfaces=[ground])
    tau_c = column(clouds, shape, detail, 1000.0, 2000.0) / d[1]
    t_end = (2100.0 - 2.0) / d[1]
    got = ref.clouds_transmittance(scene, 1, 1, shape, detail, steps=2048)
    np.testing.assert_allclose(got[0, 0], np.exp(-tau_c - 1e-4 * t_end), rtol=5e-6)
    clouds_only = ref.clouds_transmittance(scene, 1, 1, shape, detail, steps=2048, include_medium=False)
    np.testing.assert_allclose(clouds_only[0, 0], np.exp(-tau_c), rtol=5e-6)
    escaping = ref.clouds_transmittance({**scene, "surfaces": []}, 1, 1, shape, detail, steps=64)
    np.testing.assert_array_equal(escaping, 0.0)


def test_no_clouds_no_light_and_full_transmittance():
    scene = up_scene()
    assert not ref.clouds_layer_radiance(scene, 3, 2, SHAPE, DETAIL).any()
    np.testing.assert_array_equal(ref.clouds_transmittance(scene, 3, 2, SHAPE, DETAIL), 1.0)


def test_grazing_and_horizontal_rays_give_finite_results():
    """Camera inside the layer looking exactly horizontally (the middle row of an odd film), and a
    sun just above and at the horizon."""
    clouds = {**LAYER, "extinction": 0.002}
    for sun_el in (0.0, 1e-6, 3.0):
        scene = {"camera": {"position": [0.0, 1500.0, 0.0], "look_at": [0.0, 1500.0, -10.0], "up": [0, 1, 0],
                            "fov_y": 2.0}, "clouds": clouds,
                 "sun": {"elevation": sun_el, "azimuth": 30.0, "irradiance": 1000.0},
                 "sky": {"model": "overcast", "zenith_radiance": 30.0}}
        _, dirs, _ = ref.view_rays(scene, 3, 3)
        assert np.all(dirs.reshape(3, 3, 3)[1, :, 1] == 0.0)
        got = ref.clouds_layer_radiance(scene, 3, 3, SMOOTH_SHAPE, SMOOTH_DETAIL, steps=128, light_steps=16)
        trans = ref.clouds_transmittance(scene, 3, 3, SMOOTH_SHAPE, SMOOTH_DETAIL, steps=128)
        assert np.all(np.isfinite(got)) and np.all(got >= 0.0) and got.any()
        assert np.all(np.isfinite(trans)) and np.all((trans >= 0.0) & (trans <= 1.0))
    # Below the layer looking horizontally: the ray never reaches it.
    scene["camera"]["position"] = [0.0, 500.0, 0.0]
    scene["camera"]["look_at"] = [0.0, 500.0, -10.0]
    got = ref.clouds_layer_radiance(scene, 3, 3, SMOOTH_SHAPE, SMOOTH_DETAIL, steps=64, light_steps=8)
    assert np.all(got[1] == 0.0) and np.all(np.isfinite(got))


def test_texture_image_converges_in_the_step_counts():
    """Smooth synthetic textures: the error against a much finer march falls with the view steps
    (the density's kinks make it irregular: 1.5e-2, 5e-4, 2e-5 of the maximum at 32, 128, 512 steps)
    and with the light steps (6e-3, 1.4e-4, 7e-6 at 8, 32, 128)."""
    clouds = {"base": 1000.0, "top": 2500.0, "coverage": 0.8, "type": 0.8, "extinction": 0.01,
              "shape_scale": 4000.0, "detail_scale": 800.0}
    scene = up_scene(clouds=clouds)

    def image(steps, light_steps):
        return ref.clouds_layer_radiance(scene, 3, 2, SMOOTH_SHAPE, SMOOTH_DETAIL, steps, light_steps)

    fine = image(4096, 128)
    view = [np.abs(image(n, 128) - fine).max() / fine.max() for n in (32, 128, 512)]
    assert view[0] > view[1] > view[2] and view[2] < 5e-5
    fine = image(256, 1024)
    light = [np.abs(image(256, n) - fine).max() / fine.max() for n in (8, 32, 128)]
    assert light[0] > light[1] > light[2] and light[2] < 2e-5


def test_sun_below_the_horizon_leaves_only_the_sky_term():
    clouds = {"base": 1000.0, "top": 2500.0, "coverage": 0.8, "extinction": 0.01}
    lit = up_scene(clouds=clouds)
    night_sun = {**lit, "sun": {**lit["sun"], "elevation": -5.0}}
    no_sun = {k: v for k, v in lit.items() if k != "sun"}
    a = ref.clouds_layer_radiance(night_sun, 3, 2, SMOOTH_SHAPE, SMOOTH_DETAIL, 64, 16)
    b = ref.clouds_layer_radiance(no_sun, 3, 2, SMOOTH_SHAPE, SMOOTH_DETAIL, 64, 16)
    c = ref.clouds_layer_radiance(lit, 3, 2, SMOOTH_SHAPE, SMOOTH_DETAIL, 64, 16)
    np.testing.assert_array_equal(a, b)
    assert np.all(c >= b) and np.any(c > b) and b.any()


# --------------------------------------------------------------------------------------------
# Scene reading
# --------------------------------------------------------------------------------------------


def test_sky_irradiance_overcast_closed_form_and_cie_quadrature():
    lz = np.array([1.0, 2.0, 3.0])
    overcast = ref.sky_irradiance({"sky": {"model": "overcast", "zenith_radiance": lz.tolist()}})
    np.testing.assert_allclose(overcast, 7 * math.pi / 9 * lz, rtol=1e-15)
    # CIE type 5 (gradation 3: a = 0, so uniform; indicatrix 1): L = Lz everywhere, E = pi Lz.
    uniform = ref.sky_irradiance({"sky": {"model": "cie", "type": 5, "zenith_radiance": lz.tolist()}})
    np.testing.assert_allclose(uniform, math.pi * lz, rtol=1e-12)
    sun = {"elevation": 35.0, "azimuth": 20.0}
    cie12 = {"model": "cie", "type": 12, "zenith_radiance": 1.0}
    coarse = ref.sky_irradiance({"sky": cie12, "sun": sun})
    fine = ref.sky_irradiance({"sky": cie12, "sun": sun}, 512, 1024)
    np.testing.assert_allclose(coarse, fine, rtol=1e-6)
    direction = ref.sun_light({"sun": {"direction": ref.shafts.sun_direction(sun).tolist()}})[0]
    by_dir = ref.sky_irradiance({"sky": {"model": "cie", "type": 12, "zenith_radiance": 1.0},
                                 "sun": {"direction": direction.tolist()}})
    np.testing.assert_allclose(by_dir, coarse, rtol=1e-12)
    with pytest.raises(ValueError):
        ref.sky_irradiance({"sky": {"model": "cie", "type": 12, "zenith_radiance": 1.0}})


def test_scene_reading_defaults_and_medium():
    p = ref.cloud_params({})
    assert (p.base, p.top, p.coverage, p.type, p.extinction) == (1500.0, 4000.0, 0.5, 0.5, 0.05)
    assert (p.albedo, p.g, p.erosion, p.shape_scale, p.detail_scale) == (1.0, 0.2, 0.35, 8000.0, 600.0)
    assert p.wind == (0.0, 0.0) and p.time == 0.0 and p.seed == 0
    np.testing.assert_array_equal(ref.cloud_params({"wind": [3, -4], "time": 10}).offset, [30.0, 0.0, -40.0])
    with pytest.raises(ValueError):
        ref.cloud_params({"base": 3000.0, "top": 2000.0})
    np.testing.assert_allclose(ref.medium_sigma_t({"medium": {"visibility": 100.0}}), 0.03912)
    np.testing.assert_array_equal(ref.medium_sigma_t({"medium": None}), 0.0)
    s, e = ref.sun_light({"sun": {"elevation": 0.0, "azimuth": 0.0, "irradiance": 5.0}})
    assert not e.any()
    s, e = ref.sun_light({"sun": {"elevation": 30.0, "azimuth": 90.0, "irradiance": [1, 2, 3]}})
    np.testing.assert_allclose(s, [math.cos(math.radians(30)), 0.5, 0.0], atol=1e-15)
    np.testing.assert_array_equal(e, [1, 2, 3])
