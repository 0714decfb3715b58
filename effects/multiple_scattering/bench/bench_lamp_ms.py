"""Benchmark of the lamps' multiple scattering (issue 18, night; effects/multiple_scattering/docs/lamps.md):

1. error against the stored Mitsuba 3 path-traced glows
   (effects/multiple_scattering/tests/data/night_reference.json) per case:
   the table method (airlight) against the brute force (the path tracer's own time per case);
2. the table's build time per (g, albedo);
3. the per-pixel cost the term adds, on both backends (the foggy street, 16 lamps);
4. (--parts exact) the stored path-traced glows of the isotropic cases against the exact solution for
   isotropic scattering (effects/multiple_scattering/tests/point_source_exact.py, physics.md eqs.
   11.7 to 11.9), and the renderer's error against it over albedo 0.5 to 0.999 and optical radius
   0.1 to 60, where the path tracer is noise-limited.

    .venv/bin/python effects/multiple_scattering/bench/bench_lamp_ms.py [--skip-gl] [--width 320]
    .venv/bin/python effects/multiple_scattering/bench/bench_lamp_ms.py --parts exact
"""

from __future__ import annotations

import argparse
import copy
import math
import sys
import time
from pathlib import Path

import numpy as np

import airlight

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import ms_cases  # noqa: E402
import point_source_exact  # noqa: E402


def with_ms(scene: dict, on: bool) -> dict:
    scene = copy.deepcopy(scene)
    scene.setdefault("quality", {})["multiple_scattering"] = on
    return scene


def accuracy(renderer: airlight.Renderer) -> None:
    cases = ms_cases.load_cases("night")["cases"]
    print("## Error against the path tracer (views down to 1e-3 of the peak; green channel)")
    print()
    print("| case | views | within max(3 %, 3 se) | median abs dev | worst abs dev | single scattering only: "
          "worst | Mitsuba time (s) | airlight table build + render (s) |")
    print("|---|---|---|---|---|---|---|---|")
    total, inside = 0, 0
    for name, case in cases.items():
        ref = np.array([v["radiance"] for v in case["views"]])
        err = np.array([v["stderr"] for v in case["views"]])
        ss = np.array([v["airlight_single"] for v in case["views"]])
        keep = ref >= 1e-3 * ref[0]
        t0 = time.perf_counter()
        got = np.array([float(renderer.render(ms_cases.view_scene(case, i))[0, 0, 1])
                        for i in range(len(ref))])
        seconds = time.perf_counter() - t0
        dev = np.abs(got - ref)[keep] / ref[keep]
        ok = (np.abs(got - ref) <= ms_cases.allowed_deviation(ref, err))[keep]
        total += int(keep.sum())
        inside += int(ok.sum()) if case["tau"] < 20 else 0
        ss_dev = np.abs(ss - ref)[keep] / ref[keep]
        print(f"| {name} | {int(keep.sum())} | {ok.mean():.2f} | {100 * np.median(dev):.1f} % | "
              f"{100 * dev.max():.1f} % | {100 * ss_dev.max():.0f} % | {case['seconds']:.0f} | "
              f"{seconds:.2f} |")
    print()
    measurable = sum(int((np.array([v['radiance'] for v in c['views']]) >=
                          1e-3 * c['views'][0]['radiance']).sum()) for c in cases.values() if c['tau'] < 20)
    print(f"tau 0.5 to 5: {inside} of {measurable} views within ({inside / measurable:.3f}); "
          f"all cases: {total}")
    print()


EXACT_ANGLES = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 150.0, 180.0)


def exact_isotropic(renderer: airlight.Renderer) -> None:
    print("## Error against the exact solution, isotropic scattering (13 angles, 0.5 to 180 degrees; green)")
    print()
    print("The glow (single scattering and the table) against the exact single plus multiple scattering; "
          "max and median |relative error| over the angles, and the angle of the max.")
    print()
    print("| albedo | tau | max abs error | at angle | median abs error | multiple / total at 90 degrees |")
    print("|---|---|---|---|---|---|")
    for albedo in (0.5, 0.9, 0.99, 0.999):
        for tau in (0.1, 0.5, 2.0, 5.0, 20.0, 40.0, 60.0):
            errors, share = [], 0.0
            for angle in EXACT_ANGLES:
                scene = ms_cases.night_scene(tau, 0.0)
                scene["medium"]["albedo"] = albedo
                scene["camera"] = ms_cases.camera([0.0, 0.0, ms_cases.LAMP_DISTANCE],
                                                  ms_cases.glow_direction(angle))
                got = float(renderer.render(scene)[0, 0, 1])
                gamma = math.radians(angle)
                single = point_source_exact.single(tau, gamma, albedo)
                multiple = point_source_exact.glow(tau, gamma, albedo)
                scale = ms_cases.LAMP_INTENSITY * scene["medium"]["sigma_t"] ** 2
                errors.append(got / (scale * (single + multiple)) - 1.0)
                if angle == 90.0:
                    share = multiple / (single + multiple)
            dev = np.abs(errors)
            worst = int(np.argmax(dev))
            print(f"| {albedo} | {tau} | {100 * dev[worst]:.2f} % ({100 * errors[worst]:+.1f} %) | "
                  f"{EXACT_ANGLES[worst]} | {100 * np.median(dev):.2f} % | {share:.3f} |", flush=True)
    print()


def mitsuba_against_exact() -> None:
    """The stored path-traced glows of the isotropic cases against the exact solution: how often the
    reference itself misses the criterion, and by how many of its standard errors."""
    cases = ms_cases.load_cases("night")["cases"]
    print("## The stored Mitsuba glows of the isotropic cases against the exact solution")
    print()
    print("| case | views | outside max(3 %, 3 se) of the exact value | "
          "z = (Mitsuba - exact) / se: min, max | deviation: min, max |")
    print("|---|---|---|---|---|")
    outside_thin, views_thin = 0, 0
    for name, case in sorted(cases.items(), key=lambda kv: kv[1]["tau"]):
        if case["g"] != 0.0:
            continue
        tau, albedo = case["tau"], case["albedo"]
        scale = case["scene"]["lights"][0]["intensity"] * case["scene"]["medium"]["sigma_t"] ** 2
        ref = np.array([v["radiance"] for v in case["views"]])
        err = np.array([v["stderr"] for v in case["views"]])
        exact = np.array([scale * (point_source_exact.single(tau, math.radians(v["angle_deg"]), albedo) +
                                   point_source_exact.glow(tau, math.radians(v["angle_deg"]), albedo))
                          for v in case["views"]])
        keep = ref >= 1e-3 * ref[0]
        out = (np.abs(ref - exact) > ms_cases.allowed_deviation(exact, err))[keep]
        z = ((ref - exact) / err)[keep]
        dev = (ref / exact - 1.0)[keep]
        if tau < 20:
            outside_thin += int(out.sum())
            views_thin += int(keep.sum())
        print(f"| {name} | {int(keep.sum())} | {int(out.sum())} | {z.min():+.1f}, {z.max():+.1f} | "
              f"{100 * dev.min():+.1f} %, {100 * dev.max():+.1f} % |")
    print()
    print(f"tau 0.5 to 5: the reference is outside on {outside_thin} of {views_thin} views "
          f"({outside_thin / views_thin:.3f})")
    print()


def build_times() -> None:
    print("## Table build time per (g, albedo) (this process's first build of each)")
    print()
    print("| g | albedo | build (s) |")
    print("|---|---|---|")
    with airlight.Renderer("cpu") as r:
        for g in (0.0, 0.5, 0.9, 0.95):
            for albedo in (0.5, 0.9, 0.99, 1.0):
                scene = ms_cases.night_scene(2.0, g)
                scene["medium"]["albedo"] = albedo
                scene["medium"]["phase"] = {"type": "hg", "g": g + 1e-7}  # a fresh table key
                r.render(scene)
                seconds = airlight.table_stats()["lamp_ms_glow"]["build_seconds"]  # the last build's
                print(f"| {g} | {albedo} | {seconds:.2f} |")
    print()


def frame_seconds(renderer: airlight.Renderer, scene: dict, repeats: int) -> float:
    renderer.render(scene)  # table, shader variant
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        renderer.render(scene)
        best = min(best, time.perf_counter() - t0)
    return best


def per_pixel_cost(backends: list[str], width: int) -> None:
    scene = airlight.preset("foggy_street")
    height = round(width * scene["film"]["height"] / scene["film"]["width"])
    scene["film"] = {"width": width, "height": height}
    lamps = sum(1 for light in scene["lights"] if light["type"] == "point")
    print(f"## Per-pixel cost (foggy_street, {width}x{height}, {lamps} point lamps; best of 3)")
    print()
    print("| backend | single scattering (ms) | with multiple scattering (ms) | added per pixel (ns) | "
          "added per pixel and lamp (ns) |")
    print("|---|---|---|---|---|")
    for backend in backends:
        with airlight.Renderer(backend) as r:
            off = frame_seconds(r, with_ms(scene, False), 3)
            on = frame_seconds(r, with_ms(scene, True), 3)
        added = (on - off) / (width * height) * 1e9
        print(f"| {backend} | {1e3 * off:.1f} | {1e3 * on:.1f} | {added:.1f} | {added / lamps:.2f} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--skip-gl", action="store_true")
    parser.add_argument("--width", type=int, default=320)
    parser.add_argument("--parts", nargs="+", choices=["accuracy", "exact", "build", "cost"],
                        default=["accuracy", "build", "cost"])
    args = parser.parse_args()
    with airlight.Renderer("cpu") as r:
        if "accuracy" in args.parts:
            accuracy(r)
        if "exact" in args.parts:
            mitsuba_against_exact()
            exact_isotropic(r)
    if "build" in args.parts:
        build_times()
    if "cost" in args.parts:
        backends = ["cpu"] if args.skip_gl or "gl" not in airlight.available_backends() else ["cpu", "gl"]
        per_pixel_cost(backends, args.width)


if __name__ == "__main__":
    main()
