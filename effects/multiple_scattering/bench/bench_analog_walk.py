"""The daytime multiple scattering in rain against an independent analog Monte Carlo (issue 18):

    .venv/bin/python effects/multiple_scattering/bench/bench_analog_walk.py [--case day_rain40_overcast]
        [--paths 300000] [--out effects/multiple_scattering/docs/bench_analog_walk.txt]

Per view of an overcast stored case (green): the analog walk of
effects/multiple_scattering/tests/plane_parallel_mc.py (altitude and direction cosine only, no
next-event estimation) with its standard error, airlight through the aerial table (16 nodes) and
through the scattering volumes (16 levels), and the stored Mitsuba 3 value, each as a ratio to the
walk. This is the comparison that found the reference's rain fault
(effects/multiple_scattering/docs/reference.md section 3).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import airlight

ROOT = Path(__file__).resolve().parents[3]
for sub in ("effects/multiple_scattering/tests", "effects/daytime/tests", "tests/python"):
    sys.path.insert(0, str(ROOT / sub))

import ms_cases  # noqa: E402
import plane_parallel_mc  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", default="day_rain40_overcast")
    p.add_argument("--paths", type=int, default=300_000)
    p.add_argument("--out", type=Path)
    args = p.parse_args()
    case = ms_cases.load_cases("day")["cases"][args.case]
    renderer = airlight.Renderer("cpu")
    lines = [f"{args.case}, green, {args.paths} paths per view; ratios to the analog walk", "",
             "| elevation | azimuth from sun | walk | rel. stderr | table 16 / walk | volumes 16 / walk | "
             "Mitsuba / walk (its rel. stderr) |", "|---|---|---|---|---|---|---|"]
    for i, view in enumerate(case["views"]):
        walk = plane_parallel_mc.overcast_view_radiance(case["scene"], 1, view["direction"][1], args.paths,
                                                        seed=i)
        got = {}
        for name, nodes in (("table", 16), ("volumes", 0)):
            scene = ms_cases.view_scene(case, i)
            scene["quality"] = {**scene.get("quality", {}), "aerial_table": nodes}
            got[name] = float(renderer.render(scene)[0, 0, 1])
        mitsuba, err = view["radiance"][1], view["stderr"][1]
        lines.append(f"| {view['elevation']} | {view['azimuth_from_sun']} | {walk.mean:.5f} | "
                     f"{walk.stderr / walk.mean:.4f} | {got['table'] / walk.mean:.4f} | "
                     f"{got['volumes'] / walk.mean:.4f} | {mitsuba / walk.mean:.4f} ({err / mitsuba:.4f}) |")
        print(lines[-1], flush=True)
    renderer.close()
    if args.out:
        args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
