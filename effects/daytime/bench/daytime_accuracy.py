"""Per-case errors of the daytime scattering volumes against the independent reference (issue 6).

    .venv/bin/python effects/daytime/bench/daytime_accuracy.py [--segments 8 16 32]
    .venv/bin/python effects/daytime/bench/daytime_accuracy.py --aerial-nodes 16 32 64

For every sweep case of effects/daytime/tests/test_daytime_render.py (a 90-degree column of pixels; the test
asserts 1 %), prints the largest relative error over values above 1e-3 of the column's maximum
against effects/daytime/tests/daytime_reference.py, on both backends, at the default 16 segments, and then
the CPU error at each of --segments: the numbers quoted in effects/daytime/docs/daytime.md sections 3 and 5.
With --aerial-nodes, the CPU error through the aerial table at each distance-node count instead
(effects/daytime/docs/aerial_table.md section 3; output in effects/daytime/docs/aerial_accuracy.txt).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(ROOT / "tests" / "python"), *(str(d) for d in sorted(ROOT.glob("effects/*/tests")))]

from test_daytime_render import CASES, case_scene, expected_column, relative_error  # noqa: E402

import airlight  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--segments", type=int, nargs="+", default=[8, 16, 32])
    ap.add_argument("--aerial-nodes", type=int, nargs="+", default=[])
    args = ap.parse_args()
    if args.aerial_nodes:
        aerial_table_errors(args.aerial_nodes)
        return
    backends = airlight.available_backends()
    header = ["case", *[f"{b} (16)" for b in backends], *[f"cpu ({n})" for n in args.segments]]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for case in CASES:
        expected = expected_column(case)
        row = [case]
        for b in backends:
            row.append(f"{relative_error(airlight.render(case_scene(case), backend=b)[:, 0], expected):.2e}")
        for n in args.segments:
            image = airlight.render(case_scene(case, quality={"sky_segments": n}), backend="cpu")
            row.append(f"{relative_error(image[:, 0], expected):.2e}")
        print("| " + " | ".join(row) + " |", flush=True)


def aerial_table_errors(node_counts: list[int]) -> None:
    """Per case, the largest relative error of the CPU column through the aerial table."""
    header = ["case", "camera altitude m", *[f"table {n} nodes" for n in node_counts]]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for case in CASES:
        expected = expected_column(case)
        altitude = case_scene(case)["camera"]["position"][1]
        row = [case, f"{altitude:g}"]
        for n in node_counts:
            image = airlight.render(case_scene(case, quality={"aerial_table": n}), backend="cpu")
            row.append(f"{relative_error(image[:, 0], expected):.2e}")
        print("| " + " | ".join(row) + " |", flush=True)


if __name__ == "__main__":
    main()
