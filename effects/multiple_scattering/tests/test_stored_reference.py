"""The stored Mitsuba reference values (effects/multiple_scattering/tests/data, made by
effects/multiple_scattering/bench/make_reference.py) are complete and consistent, and their
scenes are scenes airlight renders: what a multiple-scattering solver's tests will compare with.
Needs no Mitsuba."""

from __future__ import annotations

import daytime_scenes as ds
import mitsuba_reference as mr
import ms_cases
import numpy as np
import pytest
import reference

import airlight

DAY = ms_cases.load_cases("day")
NIGHT = ms_cases.load_cases("night")


def test_every_case_of_the_acceptance_grid_is_stored() -> None:
    want_day = {ms_cases.day_case_name(w, s) for w in ms_cases.WEATHERS for s in ms_cases.SUNS}
    want_night = {ms_cases.night_case_name(t, g) for t in ms_cases.NIGHT_TAUS for g in ms_cases.NIGHT_GS}
    assert set(DAY["cases"]) == want_day
    assert set(NIGHT["cases"]) == want_night


@pytest.mark.parametrize("name", sorted(DAY["cases"]))
def test_day_case_is_consistent(name: str) -> None:
    case = DAY["cases"][name]
    assert case["scene"] == ms_cases.day_scene(case["weather"], case["sun"])
    comps = list(case["components"])
    assert comps == (["sky", "sun"] if "sun" in case["scene"] else ["sky"])
    for comp in comps:
        assert min(case["components"][comp]["spp"]) >= case["settings"]["min_spp"]
    assert len(case["views"]) == len(ms_cases.DAY_VIEWS)
    for view in case["views"]:
        rad, err = np.array(view["radiance"]), np.array(view["stderr"])
        assert np.all(np.isfinite(rad)) and np.all(rad > 0.0) and np.all(err > 0.0)
        np.testing.assert_allclose(rad, sum(np.array(view[f"radiance_{c}"]) for c in comps), rtol=1e-9)
        quadrature = np.sqrt(sum(np.square(view[f"stderr_{c}"]) for c in comps))
        np.testing.assert_allclose(err, quadrature, rtol=1e-9)
        # the view's camera looks along the stored direction
        _, dirs = reference.camera_rays(view["camera"], 1, 1)
        np.testing.assert_allclose(dirs[0, 0], view["direction"], atol=1e-9)
        # multiple scattering only adds light to single scattering
        ss = np.array(view["airlight_single"])
        assert np.all(rad >= ss - ms_cases.HARNESS_SIGMAS * err - ms_cases.HARNESS_MODEL_TOLERANCE * ss), (
            view["azimuth_from_sun"], view["elevation"], rad, ss, err)


@pytest.mark.parametrize("name", sorted(DAY["cases"]))
def test_day_case_was_made_with_layers_mitsuba_can_hold(name: str) -> None:
    """The stored values come from today's discretisation (its layer and texel counts), and no
    layer of it is thinner than mr.MIN_LAYER_THICKNESS: at the rain's top a layer 0.55 m thin (the
    left-over of a break) made Mitsuba's float32 interfaces lose paths, and the rain cases came out
    2-3 % dark (effects/multiple_scattering/docs/reference.md section 3)."""
    case = DAY["cases"][name]
    atm = ds.reference_atmosphere(case["scene"])
    for channel in range(3):
        layers = mr.discretise(atm, channel)
        assert min(la.y1 - la.y0 for la in layers) >= mr.MIN_LAYER_THICKNESS
        assert case["discretisation"]["layers"][channel] == len(layers)
        assert case["discretisation"]["texels"][channel] == sum(la.sigma_t.size for la in layers)


@pytest.mark.parametrize("name", sorted(NIGHT["cases"]))
def test_night_case_is_consistent(name: str) -> None:
    case = NIGHT["cases"][name]
    assert case["scene"] == ms_cases.night_scene(case["tau"], case["g"])
    assert [v["angle_deg"] for v in case["views"]] == list(ms_cases.GLOW_ANGLES)
    rad = np.array([v["radiance"] for v in case["views"]])
    err = np.array([v["stderr"] for v in case["views"]])
    ss = np.array([v["airlight_single"] for v in case["views"]])
    assert np.all(np.isfinite(rad)) and np.all(rad >= 0.0) and np.all(err >= 0.0)
    assert np.all(rad >= ss - ms_cases.HARNESS_SIGMAS * err - ms_cases.HARNESS_MODEL_TOLERANCE * ss)


@pytest.mark.parametrize("kind", ["day", "night"])
def test_stored_scenes_render(kind: str) -> None:
    """One view of each stored case renders finite with airlight: the stored scenes are valid
    airlight scenes (the values themselves change once the solver lands)."""
    data = DAY if kind == "day" else NIGHT
    for case in data["cases"].values():
        scene = ms_cases.view_scene(case, 1)
        img = airlight.render(scene, backend="cpu")
        assert img.shape == (1, 1, 3) and np.all(np.isfinite(img))


def test_acceptance_tolerance_helpers() -> None:
    ref_v, err = np.array([1.0, 1.0]), np.array([0.001, 0.02])
    np.testing.assert_allclose(ms_cases.allowed_deviation(ref_v, err), [0.03, 0.06])
    assert ms_cases.fraction_within([1.029, 1.05], ref_v, err) == 1.0
    assert ms_cases.fraction_within([1.031, 1.07], ref_v, err) == 0.0
