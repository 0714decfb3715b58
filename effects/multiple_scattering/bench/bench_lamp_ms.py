"""Benchmark of the lamps' multiple scattering (issue 18, night; effects/multiple_scattering/docs/lamps.md):

1. error against the stored Mitsuba 3 path-traced glows
   (effects/multiple_scattering/tests/data/night_reference.json) per case:
   the table method (airlight) against the brute force (the path tracer's own time per case);
2. the table's build time per (g, albedo);
3. the per-pixel cost the term adds, on both backends (the foggy street, 16 lamps).

    .venv/bin/python effects/multiple_scattering/bench/bench_lamp_ms.py [--skip-gl] [--width 320]
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

import numpy as np

import airlight

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import ms_cases  # noqa: E402


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
    args = parser.parse_args()
    with airlight.Renderer("cpu") as r:
        accuracy(r)
    build_times()
    backends = ["cpu"] if args.skip_gl or "gl" not in airlight.available_backends() else ["cpu", "gl"]
    per_pixel_cost(backends, args.width)


if __name__ == "__main__":
    main()
