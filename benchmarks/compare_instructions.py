"""Instructions per CPU-backend frame of two builds of airlight, counted by valgrind's callgrind:
exact and repeatable whatever else the machine runs, where frame times on a shared 2-core
machine drift by tens of per cent. For a change that should not move the speed (the render
outputs, a restructuring), on the same presets.

    .venv/bin/python benchmarks/compare_instructions.py --before /path/to/old/.venv/bin/python
        [--after .venv/bin/python] [--scenes foggy_street day_clear ...] [--width 160 --height 90]

Per scene and build, the process runs 1 and then 3 frames on one CPU thread; the difference
of their totals over 2 is one frame's instructions (the set-up and table builds cancel).
Needs valgrind (Debian: valgrind).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

SCENES = ["default", "foggy_street", "day_clear", "rainbow_after_heavy_rain", "spotlights_crossing_002"]

FRAMES = """
import sys
import airlight
scene = airlight.preset(sys.argv[1])
renderer = airlight.Renderer("cpu", cpu_threads=1)
for _ in range(int(sys.argv[2])):
    renderer.render(scene, width=int(sys.argv[3]), height=int(sys.argv[4]))
"""


def instructions(python: str, scene: str, frames: int, width: int, height: int) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "frames.py"
        script.write_text(FRAMES)
        proc = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/out", python,
                               str(script), scene, str(frames), str(width), str(height)],
                              capture_output=True, text=True, check=True)
    match = re.search(r"I\s+refs:\s+([\d,]+)", proc.stderr)
    if match is None:
        raise RuntimeError(f"no instruction count in valgrind's output:\n{proc.stderr[-2000:]}")
    return int(match.group(1).replace(",", ""))


def per_frame(python: str, scene: str, width: int, height: int) -> float:
    return (instructions(python, scene, 3, width, height) - instructions(python, scene, 1, width, height)) / 2


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", required=True, metavar="PYTHON")
    ap.add_argument("--after", default=sys.executable, metavar="PYTHON")
    ap.add_argument("--scenes", nargs="+", default=SCENES)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=90)
    args = ap.parse_args()
    print(f"{'scene':28} {'before Minstr/frame':>20} {'after Minstr/frame':>19} {'after/before':>13}"
          f"   (CPU backend, 1 thread, {args.width}x{args.height})")
    for scene in args.scenes:
        before = per_frame(args.before, scene, args.width, args.height)
        after = per_frame(args.after, scene, args.width, args.height)
        print(f"{scene:28} {before / 1e6:20.1f} {after / 1e6:19.1f} {after / before:13.4f}", flush=True)


if __name__ == "__main__":
    main()
