"""Rainbows (issue 7; effects/rainbow/physics.md; effects/rainbow/docs/rainbow.md): the raindrops'
Mie phase table,
its colours, and the bows in rendered images on both backends."""

from __future__ import annotations

import functools
import math

import mie_reference as mie
import numpy as np
import pytest
from daytime_scenes import CLEAR, cie_sky, day_scene, reference_column, relative_error, scene_directions, sun
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from image_checks import finite_non_negative

import airlight
from airlight import _core

SUN_RADIUS = math.radians(0.2665)


# ---- Ingredients --------------------------------------------------------------------------------

def daimon_masumura_water_index(wavelength_nm: float) -> float:
    """Refractive index of distilled water at 21.5 C (Daimon & Masumura 2007, Appl. Opt. 46, 3811):
    a Sellmeier formula independent of the Quan & Fry fit the library uses."""
    lam2 = (wavelength_nm * 1e-3) ** 2
    terms = ((5.689093832e-1, 5.110301794e-3), (1.719708856e-1, 1.825180155e-2),
             (2.062501582e-2, 2.624158904e-2), (1.123965424e-1, 1.067505178e1))
    return math.sqrt(1.0 + sum(b * lam2 / (lam2 - c) for b, c in terms))


@pytest.mark.parametrize("wavelength", [400.0, 450.0, 500.0, 550.0, 589.0, 650.0, 700.0])
def test_water_refractive_index_agrees_with_an_independent_formula(wavelength):
    """Quan & Fry (20 C) against Daimon & Masumura (21.5 C): within 5e-4 over 400-700 nm (the
    temperatures differ by 1.5 C, about 1.5e-4)."""
    assert _core.water_refractive_index(wavelength) == pytest.approx(
        daimon_masumura_water_index(wavelength), abs=5e-4)


def test_cmf_table_is_the_cie_data_of_colour_science():
    """cpp/cie_tables.inc holds the CIE 1931 2-degree observer and D65 as the colour-science
    package has them (tools/make_cmf_table.py), 380-780 nm."""
    colour = pytest.importorskip("colour", reason="colour-science is not installed")
    from pathlib import Path
    rows = []
    text = (Path(__file__).resolve().parents[3] / "cpp" / "cie_tables.inc").read_text()
    for line in text.splitlines():
        if line.startswith("{"):
            rows.append([float(v) for v in line.strip("{},").split(",")])
    rows = np.array(rows)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().interpolate(colour.SpectralShape(300, 780, 1))
    assert rows.shape == (401, 5)
    for w, x, y, z, s in rows[::17]:
        assert np.allclose([x, y, z], cmfs[w], rtol=1e-6, atol=1e-9)
        assert s == pytest.approx(d65[w], rel=1e-6)


@pytest.mark.parametrize("count", [3, 5, 9, 17, 33])
@pytest.mark.parametrize("centre", [450.0, 530.0, 610.0])
def test_rgb_weights_reproduce_colour_science_on_smooth_spectra(count, centre):
    """A smooth spectral factor s(lambda) (a Gaussian of 60 nm width on a floor) under D65, through
    the node weights, gives the linear sRGB of the 1-nm CIE integral relative to D65's white
    (colour-science's XYZ -> sRGB matrix): within 1.5 % of the largest channel for 17 and 33 nodes, and
    only as well as the nodes resolve the spectrum for fewer (the colour-convergence measurement of
    effects/rainbow/docs/rainbow.md)."""
    colour = pytest.importorskip("colour", reason="colour-science is not installed")
    wl = np.arange(380, 721)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().interpolate(colour.SpectralShape(300, 780, 1))
    xyz = np.array([cmfs[w] for w in wl]) * np.array([d65[w] for w in wl])[:, None]
    m = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB

    def spectrum(lam):
        return 0.2 + np.exp(-0.5 * ((np.asarray(lam) - centre) / 60.0) ** 2)

    exact = (m @ (xyz * spectrum(wl)[:, None]).sum(axis=0)) / (m @ xyz.sum(axis=0))
    nodes = np.linspace(380.0, 720.0, count)
    ours = spectrum(nodes) @ _core.rainbow_rgb_weights(count)
    tolerance = {33: 0.015, 17: 0.015, 9: 0.05, 5: 0.2, 3: 0.6}[count]
    assert np.abs(ours - exact).max() <= tolerance * exact.max(), (ours, exact)


# ---- The phase function seen through the sun's disc, against an independent Lorenz-Mie series ----

def disc_profile_rule(k: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """The sun's disc projected on the scattering angle: offsets (degrees) and weights of k
    Gauss-Chebyshev nodes of the second kind for the semicircle profile sqrt(1 - u^2)."""
    j = np.arange(1, k + 1)
    w = np.sin(j * np.pi / (k + 1)) ** 2
    return math.degrees(SUN_RADIUS) * np.cos(j * np.pi / (k + 1)), w / w.sum()


def numpy_disc_phase(n: float, diameter_mm: float, wavelength_nm: float, angles_deg) -> np.ndarray:
    """mie_reference's phase function averaged over the sun's disc by the profile rule: a
    different rule from the library's 2-D product rule, exact to O(rho^2 cot theta) ~ 1e-5 rad."""
    offsets, weights = disc_profile_rule()
    x = math.pi * diameter_mm * 1e-3 / (wavelength_nm * 1e-9)
    theta = np.radians(np.asarray(angles_deg)[:, None] + offsets[None, :])
    p = mie.phase_function(complex(n, 0.0), x, theta.ravel()).reshape(theta.shape)
    return p @ weights


@pytest.mark.slow
@pytest.mark.parametrize("diameter, wavelength", [(0.1, 450.0), (0.1, 650.0), (0.3, 450.0), (0.3, 650.0),
                                                  (1.0, 550.0)])
def test_sun_disc_phase_matches_independent_mie_in_the_bow_region(diameter, wavelength):
    """Acceptance: one drop's phase function seen through the sun's disc (what the table averages
    over sizes), from the library's Mie series and disc rule, against the independent numpy series
    with its own disc rule: within 2 % over 120-145 degrees."""
    angles = np.arange(120.0, 145.01, 0.25)
    n = _core.water_refractive_index(wavelength)
    ours = _core.mie_sun_disc_phase(n, diameter, wavelength, angles.tolist(), 16)
    theirs = numpy_disc_phase(n, diameter, wavelength, angles)
    assert relative_error(ours, theirs, floor_fraction=0.0) < 0.02


# ---- The size-averaged spectral table --------------------------------------------------------

@functools.cache
def spectral() -> dict:
    return _core.rainbow_spectral_table()


def bow_mask(t: dict) -> np.ndarray:
    a = t["angles_deg"]
    return (a >= 120.0) & (a <= 145.0)


def test_spectral_table_grids():
    t = spectral()
    assert t["wavelengths_nm"][0] == 380.0 and t["wavelengths_nm"][-1] == 720.0
    assert len(t["wavelengths_nm"]) == 33 and np.allclose(np.diff(t["wavelengths_nm"]), 10.625)
    assert np.allclose(t["rates"], 0.1 * 2.0 ** np.arange(14))
    a = t["angles_deg"]
    assert a[0] == 0.0 and a[-1] == 180.0 and np.all(np.diff(a) > 0)
    assert np.diff(a[bow_mask(t)]).max() <= 0.05 + 1e-9
    assert np.diff(a[a >= 178.0]).max() <= 0.05 + 1e-9  # the glory
    assert np.all(np.isfinite(t["phase"])) and np.all(t["phase"] > 0.0)


def test_spectral_table_sampling_error_is_small_in_the_bow_region():
    """The table's own Monte-Carlo standard error (batch means, stored with it) over 120-145
    degrees: below 1.2 % at any angle and wavelength for rates up to 102.4 mm/h, below 2 % at the
    cloudburst rates above (few large drops carry the bow there), 0.5 % in the median."""
    t = spectral()
    err = t["rel_error"][:, :, bow_mask(t)]
    ordinary = t["rates"] <= 102.5
    assert err[ordinary].max() < 0.012, err[ordinary].max()
    assert err.max() < 0.02, err.max()
    assert np.median(err) < 0.005


@pytest.mark.slow
def test_spectral_table_agrees_with_an_independent_sampling():
    """A new table from other random numbers (1024 samples, node 16 = 550 nm) differs from the
    embedded one by what their standard errors allow: the error estimate is honest."""
    t = spectral()
    other = _core.rainbow_spectral_table(1024, 12345, [16])
    mask = bow_mask(t)
    a, b = t["phase"][:, 16, mask], other["phase"][:, 0, mask]
    sigma = np.hypot(t["rel_error"][:, 16, mask] * a, other["rel_error"][:, 0, mask] * b)
    z = np.abs(a - b) / sigma
    assert np.mean(z < 2.0) > 0.9, np.mean(z < 2.0)
    assert z.max() < 6.0


@pytest.mark.slow
@pytest.mark.parametrize("wavelength_node", [4, 28])
def test_size_averaged_table_matches_a_deterministic_size_quadrature(wavelength_node):
    """Acceptance, after the size average: the embedded table at 25.6 mm/h against an independent
    route to the same smoothed phase function: the Mie series (checked above against the numpy
    series) summed over 1600 drop sizes evenly spaced in log D (a midpoint rule, not the table's
    Monte Carlo), then seen through the sun's disc by the 1-D profile rule (not the table's 2-D
    disc sampling). Within 2 % over 120-145 degrees (every 0.5 degree), at 422.5 and 677.5 nm."""
    t = spectral()
    k = int(np.argmin(np.abs(t["rates"] - 25.6)))
    wavelength = float(t["wavelengths_nm"][wavelength_node])
    angles = np.arange(120.0, 145.01, 0.5)
    offsets, weights = disc_profile_rule()
    points = (angles[:, None] + offsets[None, :]).ravel()
    point_phase = _core.mie_size_average_phase(float(t["rates"][k]), wavelength, points.tolist(), 1600)
    theirs = point_phase.reshape(len(angles), -1) @ weights
    ours = np.interp(angles, t["angles_deg"], t["phase"][k, wavelength_node].astype(float))
    assert relative_error(ours, theirs, floor_fraction=0.0) < 0.02


def sphere_integral(angles_deg: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Trapezoid integral of a phase function over the sphere (angle on the last axis)."""
    a = np.radians(angles_deg)
    f = 2.0 * np.pi * phase.astype(float) * np.sin(a)
    return np.sum(0.5 * (f[..., 1:] + f[..., :-1]) * np.diff(a), axis=-1)


def test_spectral_table_is_normalised():
    """Each rate's and wavelength's phase function integrates to 1 over the sphere (the forward
    aureole, which holds about half of the light and nearly all of the sampling noise, is rescaled
    to make it so), and the part beyond 3 degrees, which is not rescaled, holds 49-51 % of it:
    half the light of a large drop is diffracted."""
    t = spectral()
    assert np.all(np.abs(sphere_integral(t["angles_deg"], t["phase"]) - 1.0) < 1e-4)
    beyond = t["angles_deg"] >= 3.0
    rest = sphere_integral(t["angles_deg"][beyond], t["phase"][..., beyond])
    assert np.all((rest > 0.49) & (rest < 0.51)), (rest.min(), rest.max())


@pytest.mark.parametrize("rate", [0.1, 1.0, 25.0, 819.2])
@pytest.mark.parametrize("wavelengths", [3, 33])
def test_renderer_table_is_normalised_in_every_channel(rate, wavelengths):
    """The renderer's RGB table (colour weights, gamut desaturation, uniform resampling) keeps
    each channel's phase normalised within 0.1 %: rain scatters the light it removes."""
    p = airlight.rainbow_phase(rate, wavelengths=wavelengths)
    total = sphere_integral(np.linspace(0.0, 180.0, 3601), p.T)
    assert np.all(np.abs(total - 1.0) < 1e-3), total


def primary_maximum(rate: float, channel: int) -> float:
    """Scattering angle (degrees) of the largest value of one RGB channel in 134-142 degrees."""
    grid = np.linspace(0.0, 180.0, 3601)
    p = airlight.rainbow_phase(rate)
    mask = (grid > 134.0) & (grid < 142.0)
    return float(grid[mask][np.argmax(p[mask, channel])])


@pytest.mark.parametrize("rate", [5.0, 25.0, 100.0])
def test_table_bow_positions(rate):
    """The table's primary red maximum lies in 137.3-138.7 degrees and its blue maximum inside the
    bow (at a larger scattering angle)."""
    red, blue = primary_maximum(rate, 0), primary_maximum(rate, 2)
    assert 137.3 <= red <= 138.7
    assert blue > red


def spectral_phase(rate: float, node: int) -> np.ndarray:
    """The spectral table's phase at one of its rates and wavelength nodes."""
    t = spectral()
    return t["phase"][int(np.argmin(np.abs(t["rates"] - rate))), node].astype(float)


def monochrome_bow(rate: float, node: int = 16) -> tuple[float, float]:
    """The primary bow at one wavelength (node 16: 550 nm) of the spectral table: its width
    (degrees) above half its height over the dark band's floor, and its contrast (peak over
    floor)."""
    angles = np.linspace(120.0, 146.0, 521)
    p = np.interp(angles, spectral()["angles_deg"], spectral_phase(rate, node))
    floor = float(p[(angles > 129.0) & (angles < 136.0)].min())
    region = angles > 134.0
    peak = float(p[region].max())
    return float(np.sum(region & (p > floor + 0.5 * (peak - floor))) * 0.05), peak / floor


def bow_chroma(rate: float) -> float:
    """Colourfulness of the bow (before any gamut clipping): the spread of the wavelengths'
    primary maxima, each relative to its own band floor, measured as the standard deviation of the
    scattering angle of their peaks (degrees) weighted by peak height over floor. A pale bow is one
    whose colours overlap: each colour's peak is wide compared with their separation."""
    angles = np.linspace(120.0, 146.0, 521)
    t = spectral()
    widths, peaks = [], []
    for node in range(33):
        w, _ = monochrome_bow(rate, node)
        p = np.interp(angles, t["angles_deg"], spectral_phase(rate, node))
        peaks.append(angles[angles > 134.0][np.argmax(p[angles > 134.0])])
        widths.append(w)
    return float((max(peaks) - min(peaks)) / np.mean(widths))


def bow_purity(rate: float) -> float:
    """The bow's saturation: the largest excitation purity (CIE 1931 xy against D65, computed by
    colour-science) of the spectral table's colours where the primary is above half its height
    over the dark band, before any gamut mapping."""
    colour = pytest.importorskip("colour", reason="colour-science is not installed")
    t = spectral()
    cmfs, d65 = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"], colour.SDS_ILLUMINANTS["D65"]
    nm = np.arange(380, 721)
    weights = np.array([cmfs[w] * d65[w] for w in nm])
    angles = np.linspace(120.0, 146.0, 521)
    phase = np.stack([np.interp(angles, t["angles_deg"], spectral_phase(rate, i)) for i in range(33)])
    xyz = np.stack([np.interp(nm, t["wavelengths_nm"], phase[:, j]) for j in range(len(angles))]) @ weights
    floor = xyz[(angles > 129.0) & (angles < 136.0), 1].min()
    primary = angles > 134.0
    bright = primary & (xyz[:, 1] > floor + 0.5 * (xyz[primary, 1].max() - floor))
    white = weights.sum(axis=0)
    return max(float(colour.excitation_purity(c[:2] / c.sum(), white[:2] / white.sum())) for c in xyz[bright])


@pytest.mark.slow
def test_light_rain_gives_wider_paler_bows():
    """From heavy to light rain the primary bow widens (its width at one wavelength) and loses
    saturation (excitation purity), contrast and colour separation (the spread of the colours'
    maxima in units of their widths).
    effects/rainbow/docs/rainbow.md plots it (effects/rainbow/bench/rainbow_analysis.py)."""
    rates = [819.2, 102.4, 25.6, 6.4, 1.6, 0.4, 0.1]
    widths, contrasts = zip(*[monochrome_bow(r) for r in rates])
    chroma = [bow_chroma(r) for r in rates]
    purity = [bow_purity(r) for r in rates]
    assert all(b >= a for a, b in zip(widths, widths[1:])) and widths[-1] > 1.3 * widths[0], widths
    assert all(b < a for a, b in zip(purity, purity[1:])) and purity[-1] < purity[0] - 0.1, purity
    assert all(b < a for a, b in zip(contrasts, contrasts[1:])), contrasts
    assert all(b < a for a, b in zip(chroma, chroma[1:])), chroma


def small_drop_bow(diameter: float, wavelength: float) -> tuple[float, float]:
    """Drops within a factor 1.25 of one diameter (mm) through the sun's disc: the primary's
    maximum (degrees) and the secondary's contrast over the dark band."""
    offsets, weights = disc_profile_rule()
    angles = np.arange(110.0, 160.01, 0.1)
    points = (angles[:, None] + offsets[None, :]).ravel().tolist()
    p = _core.mie_size_average_phase(0.0, wavelength, points, 200, 0.0, diameter / 1.25, diameter * 1.25)
    p = p.reshape(len(angles), -1) @ weights
    band = p[(angles > 129.0) & (angles < 136.0)].min()
    primary = (angles > 134.0) & (angles < 150.0)
    secondary = p[(angles > 120.0) & (angles < 131.0)].max()
    return float(angles[primary][np.argmax(p[primary])]), float(secondary / band)


@pytest.mark.slow
def test_small_drops_lose_the_secondary_and_the_colours():
    """effects/rainbow/physics.md: small drops give pale bows and the secondary fades away. Below the
    rain's sizes (drops of 10 um, fog; not rendered): the secondary is gone (its maximum within 25 %
    of the band's floor, against 7 times it at 0.2 mm), and the primary is white (its blue and red
    maxima within 0.3 degree, against 1 degree apart at 0.2 mm) and moved inward (fogbow)."""
    fog = {w: small_drop_bow(0.01, w) for w in (450.0, 650.0)}
    rain = {w: small_drop_bow(0.2, w) for w in (450.0, 650.0)}
    assert fog[450.0][1] < 1.25 and rain[450.0][1] > 5.0, (fog, rain)
    assert abs(fog[450.0][0] - fog[650.0][0]) < 0.3 and rain[450.0][0] - rain[650.0][0] > 0.8, (fog, rain)
    assert fog[650.0][0] > rain[650.0][0] + 3.0


def test_rainbow_table_is_continuous_and_non_negative():
    """No NaN, no negative channel, and no jump between neighbouring texels larger than the bows'
    own steepest slopes allow (the spectral grid's steps at 3, 118, 146 and 178 degrees do not
    show)."""
    for rate in (0.1, 0.3, 25.0, 1000.0):
        p = airlight.rainbow_phase(rate).astype(float)
        assert np.all(np.isfinite(p)) and p.min() >= 0.0
        rel = np.abs(np.diff(p, axis=0)) / np.maximum(np.maximum(p[1:], p[:-1]), 1e-12)
        grid = np.linspace(0.0, 180.0, 3601)[1:]
        for edge in (3.0, 118.0, 146.0, 178.0):
            near = np.abs(grid - edge) < 0.2
            around = (np.abs(grid - edge) >= 0.2) & (np.abs(grid - edge) < 1.5)
            assert rel[near].max() <= 1.5 * rel[around].max() + 1e-3, (rate, edge, rel[near].max())


def test_rainbow_phase_interpolates_in_rate():
    """Between the table's rates (a factor 2 apart) the phase is interpolated in log rate: the
    value at a rate between two nodes lies between theirs."""
    lo, mid, hi = (airlight.rainbow_phase(r) for r in (12.8, 18.1, 25.6))
    assert np.all(mid >= np.minimum(lo, hi) - 1e-7) and np.all(mid <= np.maximum(lo, hi) + 1e-7)


@pytest.mark.parametrize("bad, error", [(0.0, ValueError), (-1.0, ValueError), (math.nan, ValueError),
                                        ("heavy", TypeError)])
def test_rainbow_phase_rejects_bad_rates(bad, error):
    with pytest.raises(error, match="rate"):
        airlight.rainbow_phase(bad)


def test_rainbow_phase_rejects_bad_wavelength_counts():
    with pytest.raises(ValueError, match="wavelengths"):
        airlight.rainbow_phase(10.0, wavelengths=4)
    with pytest.raises(ValueError, match="angles_deg"):
        airlight.rainbow_phase(10.0, [190.0])


# ---- Rendered bows ---------------------------------------------------------------------------

def bow_scene(rate: float = 25.0, density: float = 0.05, height: int = 401, **extra) -> dict:
    """The sun 20 degrees up behind the camera; one image column in the antisolar vertical plane
    from 5 to 40 degrees of elevation (scattering angle 180 - 20 - elevation), in a thin curtain of
    rain under a dim clear sky (zenith 0.1 against the sun's 20: the sun has come out after the
    rain)."""
    return day_scene(sky=cie_sky(12, lz=(0.1, 0.1, 0.1)), sun=sun(20.0, azimuth=180.0, irradiance=20.0),
                     atmosphere={"rain": {"rate": rate, "density_scale": density}},
                     pitch=22.5, fov=35.0, width=1, height=height, **extra)


def scattering_angles(scene: dict) -> np.ndarray:
    d = scene_directions(scene)[:, 0]
    s = np.array(scene["sun"]["direction"]) if "direction" in scene["sun"] else None
    if s is None:
        el, az = math.radians(scene["sun"]["elevation"]), math.radians(scene["sun"]["azimuth"])
        s = np.array([math.sin(az) * math.cos(el), math.sin(el), -math.cos(az) * math.cos(el)])
    return np.degrees(np.arccos(np.clip(d @ s, -1.0, 1.0)))


def test_rendered_bow_geometry(renderer):
    """Acceptance, from rendered pixels: sun 20 degrees up, 25 mm/h drops: the primary's red
    maximum at 137.3-138.7 degrees of scattering angle (41.3-42.7 from the antisolar point), its
    blue maximum inside; the secondary's maximum at 128-130 degrees (50-52 from the antisolar
    point) with red outside blue (reversed); the band between them darker than the sky inside the
    primary."""
    scene = bow_scene()
    img = renderer.render(scene)[:, 0, :].astype(float)
    finite_non_negative(img, "bow column")
    angle = scattering_angles(scene)

    def arg_max(lo, hi, channel):
        m = (angle > lo) & (angle < hi)
        return float(angle[m][np.argmax(img[m, channel])])

    red, blue = arg_max(134.0, 142.0, 0), arg_max(134.0, 142.0, 2)
    assert 137.3 <= red <= 138.7, red
    assert blue > red
    lum = img @ np.array([0.2126, 0.7152, 0.0722])
    in_secondary = (angle > 126.0) & (angle < 131.0)
    secondary = float(angle[in_secondary][np.argmax(lum[in_secondary])])
    assert 128.0 <= secondary <= 130.0, secondary
    assert arg_max(124.0, 132.0, 0) > arg_max(124.0, 132.0, 2)
    band = lum[(angle > 131.0) & (angle < 135.5)].mean()
    inside = lum[(angle > 140.5) & (angle < 145.0)].mean()
    assert band < inside


@pytest.mark.slow
@pytest.mark.parametrize("case", ["in_bow", "fading_rain", "light_rain", "over_ground"])
def test_rendered_rainbow_matches_reference(renderer, case):
    """The rainbow term in the scattering volumes (seed equation 7): rendered pixels against the
    float64 reference integral with the same phase table, within 1 %, both backends."""
    scene = {
        "in_bow": bow_scene(height=41),
        "fading_rain": bow_scene(rate=25.0, density=0.02, height=41),
        "light_rain": bow_scene(rate=1.0, density=1.0, height=41),
        "over_ground": day_scene(sky=CLEAR, sun=sun(20.0, azimuth=180.0, irradiance=20.0),
                                 atmosphere={"molecules": {"density_scale": 1},
                                             "rain": {"rate": 10.0, "density_scale": 0.5}},
                                 pitch=10.0, fov=60.0, width=1, height=31, ground=0.2),
    }[case]
    expected = reference_column(scene)
    img = renderer.render(scene)[:, 0, :]
    assert relative_error(img, expected) < 0.01


def test_no_drops_no_rainbow(renderer):
    """density_scale 0: the image equals the rain-free one (no bow, no table needed)."""
    a = renderer.render(bow_scene(density=0.0, height=21))
    scene = bow_scene(height=21)
    del scene["atmosphere"]["rain"]
    b = renderer.render(scene)
    assert np.array_equal(a, b)


def test_backends_agree_on_a_rainbow(renderer_cache):
    """GL and the CPU run the same shader code over the same table: within 0.2 %."""
    scene = bow_scene(height=101)
    gl = renderer_cache("gl").render(scene)
    cpu = renderer_cache("cpu").render(scene)
    assert relative_error(gl, cpu) < 2e-3


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.floats(1e-3, 1000.0), density=st.floats(0.0, 1e3), elevation=st.floats(0.5, 89.0),
       pitch=st.floats(-30.0, 60.0), wavelengths=st.sampled_from([3, 5, 9, 17, 33]))
def test_random_rainbow_scenes_are_finite(renderer, rate, density, elevation, pitch, wavelengths):
    scene = day_scene(sky=CLEAR, sun=sun(elevation, azimuth=180.0, irradiance=20.0),
                      atmosphere={"rain": {"rate": rate, "density_scale": density}}, pitch=pitch, fov=60.0,
                      width=4, height=9, ground=0.3, quality={"rainbow_wavelengths": wavelengths})
    finite_non_negative(renderer.render(scene), f"rate {rate} density {density}")
