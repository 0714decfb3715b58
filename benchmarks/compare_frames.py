"""Frame times of two checkouts of airlight on the same presets, run in turn (A B A B ...), with the
median of the per-pair ratios: for a change that should not move the speed (a restructuring).

    .venv/bin/python benchmarks/compare_frames.py --before /path/to/old/venv/bin/python /path/to/old/checkout
        [--after .venv/bin/python .] [--pairs 3] [--scenes scenes/default.json ...]

Each run is benchmarks/bench_frame.py of that checkout at 320x180, 5 frames, both backends.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = ["scenes/default.json", "scenes/foggy_street.json", "scenes/day_clear.json",
          "scenes/rainbow_after_heavy_rain.json", "scenes/spotlights_crossing_002.json"]


def frame_ms(python: str, root: str, scene: str) -> dict[str, float]:
    out = subprocess.run([python, f"{root}/benchmarks/bench_frame.py", "--scene", f"{root}/{scene}",
                          "--frames", "5", "--width", "320", "--height", "180"],
                         capture_output=True, text=True, cwd=root, check=True).stdout
    return {m.group(1): float(m.group(2)) for m in re.finditer(r"^(gl|cpu)\s+([\d.]+)", out, re.M)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", nargs=2, metavar=("PYTHON", "CHECKOUT"), required=True)
    ap.add_argument("--after", nargs=2, metavar=("PYTHON", "CHECKOUT"), default=[sys.executable, str(ROOT)])
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    args = ap.parse_args()
    print(f"{'scene':36} {'backend':7} {'before ms':>10} {'after ms':>10} {'after/before':>13} "
          f"(median of {args.pairs} pairs)")
    for scene in args.scenes:
        before: dict[str, list[float]] = {}
        after: dict[str, list[float]] = {}
        for _ in range(args.pairs):
            a, b = frame_ms(*args.before, scene), frame_ms(*args.after, scene)
            for k in a.keys() & b.keys():
                before.setdefault(k, []).append(a[k])
                after.setdefault(k, []).append(b[k])
        for k in sorted(before):
            ratio = statistics.median(y / x for x, y in zip(before[k], after[k]))
            b_ms, a_ms = statistics.median(before[k]), statistics.median(after[k])
            print(f"{scene:36} {k:7} {b_ms:10.1f} {a_ms:10.1f} {ratio:13.3f}")


if __name__ == "__main__":
    main()
