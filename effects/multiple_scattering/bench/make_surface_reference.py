"""Writes effects/multiple_scattering/tests/data/lamp_ms_surface_reference.json: the irradiance of a point
lamp's multiply scattered light on a surface element, by the independent photon tracer
effects/multiple_scattering/tests/surface_mc.py, over tau 0.1 to 20, beta 0 to 180 degrees, g 0 to 0.9
(effects/multiple_scattering/physics.md section 13; effects/multiple_scattering/docs/lamps.md
section 5), then prints the table's deviation from it. Usage:

    .venv/bin/python effects/multiple_scattering/bench/make_surface_reference.py [--photons N] [--print-only]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parent.parent / "tests"
sys.path.insert(0, str(TESTS))

import surface_mc  # noqa: E402

OUT = TESTS / "data" / "lamp_ms_surface_reference.json"
TAUS = [0.1, 0.3, 1.0, 3.0, 8.0, 20.0]
BETAS = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0]
# (g, albedo, photons x): albedo 0.5 traces 10 times more (its light at tau 20 is e^-25 of the lamp's,
# reached by few photons).
CASES = [(0.0, 0.9, 1), (0.5, 0.9, 1), (0.9, 0.9, 1), (0.0, 0.5, 10)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--photons", type=int, default=300000)
    parser.add_argument("--print-only", action="store_true",
                        help="compare the stored reference only")
    args = parser.parse_args()
    if not args.print_only:
        cases = []
        for g, albedo, factor in CASES:
            start = time.time()
            case = surface_mc.surface_irradiance_mc(g, albedo, TAUS, BETAS, factor * args.photons, batches=20,
                                                    seed=18)
            case["seconds"] = round(time.time() - start, 1)
            print(f"g {g} albedo {albedo}: {case['seconds']} s", flush=True)
            cases.append(case)
        generator = f"effects/multiple_scattering/bench/make_surface_reference.py --photons {args.photons}"
        OUT.write_text(json.dumps({"generator": generator, "cases": cases}, indent=1) + "\n")
    import test_lamp_ms_surfaces as t  # the table's lookup, as the tests do it

    cases = json.loads(OUT.read_text())["cases"]
    print("| g | albedo | tau | " + " | ".join(f"{b:g} deg" for b in BETAS) + " |")
    print("|---|---|---|" + "---|" * len(BETAS))
    within = []
    for case in cases:
        got, ref, err = t.compare_with_reference(case)
        within += list(t.fraction_within(got, ref, err).ravel())
        for i, tau in enumerate(case["taus"]):
            cells = [f"{100 * (got[i, j] / ref[i, j] - 1):+.1f} ({100 * err[i, j] / ref[i, j]:.1f})"
                     for j in range(len(case["betas_deg"]))]
            print(f"| {case['g']} | {case['albedo']} | {tau} | " + " | ".join(cells) + " |")
    print(f"within max(3 %, 3 stderr): {np.sum(within)} of {len(within)}; "
          f"table / reference - 1 in %, (reference stderr in %)")
    print(f"worst |dev| / stderr: {max_sigma(cases, t):.2f}")


def max_sigma(cases: list[dict], t: object) -> float:
    worst = 0.0
    for case in cases:
        got, ref, err = t.compare_with_reference(case)  # type: ignore[attr-defined]
        worst = max(worst, float(np.max(np.abs(got - ref) / err)))
    return worst if math.isfinite(worst) else float("inf")


if __name__ == "__main__":
    main()
