"""Writes effects/multiple_scattering/tests/disort_reference.json: PythonicDISORT's
fluxes and radiances for the comparison cases (effects/multiple_scattering/tests/disort_cases.py), so that
test_plane_parallel_solver.py compares against them without PythonicDISORT.

    .venv/bin/pip install PythonicDISORT   # 1.8; numpy and scipy only
    .venv/bin/python effects/multiple_scattering/bench/make_disort_reference.py
"""

from __future__ import annotations

import json
import sys
from importlib.metadata import version
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

import disort_cases  # noqa: E402


def main() -> None:
    out = {"solver": f"PythonicDISORT {version('PythonicDISORT')}", "streams": disort_cases.STREAMS,
           "phis": list(disort_cases.PHIS), "cases": {}}
    for case in disort_cases.CASES:
        out["cases"][case["name"]] = disort_cases.run_pythonic_disort(case)
        print(case["name"], "done")
    path = HERE.parent / "tests" / "disort_reference.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    main()
