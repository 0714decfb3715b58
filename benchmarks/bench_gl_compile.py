"""A new user's first frame: what each preset's first GL frame costs (shader compilation and
tables) against its second frame, with the driver's shader cache off, and the CPU backend's
first frame beside it.

    .venv/bin/python benchmarks/bench_gl_compile.py [--only clouds_sunset_above ...]
        [--size 16x9] [--out docs/bench_gl_compile.txt]

Each preset is rendered in a fresh process (``MESA_SHADER_CACHE_DISABLE=true``, so that Mesa's
on-disk cache of compiled shaders cannot hide the compile), at a tiny film so that the frame's
own work is negligible: first frame minus second frame is what the shader variant's compilation
(and the per-process tables) cost. On llvmpipe the compiler is single-threaded and its time grows
with how many times the shader inlines each function and unrolls each loop: a function called
from several places is compiled once per call site (docs/architecture.md, "GL compile time", under Passes).
This is also most of the test suite's time on a machine with a cold cache, as CI's is.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import airlight

ROOT = Path(__file__).resolve().parents[1]

# Run in the child process: two frames on one renderer, their wall times as JSON.
_CHILD = """
import json, sys, time
import airlight
name, backend, width, height = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
renderer = airlight.Renderer(backend)
times = []
for _ in range(2):
    start = time.perf_counter()
    renderer.render(airlight.preset(name), width=width, height=height)
    times.append(time.perf_counter() - start)
print(json.dumps(times))
"""


def frame_times(name: str, backend: str, width: int, height: int,
                timeout: float) -> tuple[float, float] | str:
    """(first, second) frame times of preset `name` in a fresh process, or why there are none."""
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true")
    try:
        done = subprocess.run([sys.executable, "-c", _CHILD, name, backend, str(width), str(height)],
                              env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"over {timeout:.0f} s"
    if done.returncode != 0:
        return (done.stderr.strip().splitlines() or ["failed"])[-1]
    first, second = json.loads(done.stdout.strip().splitlines()[-1])
    return first, second


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", nargs="*", default=None, help="preset names (default: every preset)")
    ap.add_argument("--size", default="16x9", help="film WxH (default 16x9: negligible frame work)")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per preset and backend")
    ap.add_argument("--out", type=Path, default=None, help="also write the table here")
    args = ap.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    names = args.only or airlight.preset_names()
    backends = [b for b in ("gl", "cpu") if b in airlight.available_backends()]
    if "gl" not in backends:
        print(f"no GL backend here ({airlight.gl_unavailable_reason()}): only the CPU column is measured")
    lines = [f"First frame (compile + tables) and second frame, {width}x{height}, Mesa shader cache off, "
             "each preset in a fresh process; seconds of wall time",
             f"{'preset':32s}" + "".join(f" {b + ' first':>10s} {b + ' second':>10s}" for b in backends)]
    print("\n".join(lines), flush=True)
    started = time.perf_counter()
    for name in names:
        row = f"{name:32s}"
        for backend in backends:
            measured = frame_times(name, backend, width, height, args.timeout)
            row += (f" {measured[0]:10.2f} {measured[1]:10.2f}" if isinstance(measured, tuple)
                    else f" {measured[:21]:>21s}")
        print(row, flush=True)
        lines.append(row)
    lines.append(f"total {time.perf_counter() - started:.0f} s")
    print(lines[-1])
    if args.out:
        args.out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
