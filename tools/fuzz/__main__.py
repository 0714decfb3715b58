"""The fuzzing harness's command line: ``.venv/bin/python -m tools.fuzz --help``."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from . import harness
from .generate import REGIONS, GeneratorConfig


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m tools.fuzz",
        description="Renders random valid scenes on each backend (in a worker process, with a timeout) and "
                    "validates random bad inputs; shrinks every distinct failure to a minimal scene file.")
    p.add_argument("--scenes", type=int, default=100, help="valid scenes to render (default 100)")
    p.add_argument("--bad-inputs", type=int, default=0,
                   help="mutated (invalid) scenes to validate (default 0)")
    p.add_argument("--seed", type=int, default=0, help="the run's seed: the same seed, the same scenes")
    p.add_argument("--backends", default="gl,cpu",
                   help="comma-separated: gl, cpu (both: also compared); with --demo: demo (default gl,cpu)")
    p.add_argument("--duration", type=float, default=None,
                   help="stop starting valid scenes after this many seconds (the bad inputs get 120 s more)")
    p.add_argument("--timeout", type=float, default=180.0,
                   help="seconds a render may take before it is a hang (default 180: a cold GL shader "
                        "variant compiles in 5-25 s on llvmpipe)")
    p.add_argument("--out", type=Path, default=Path("fuzz-out"), help="directory for findings and the report")
    p.add_argument("--film", default="48x32", help="largest film WxH (corner films aside; default 48x32)")
    p.add_argument("--fixed-film", default=None, help="every film WxH (e.g. 8x6)")
    p.add_argument("--max-lights", type=int, default=8)
    p.add_argument("--max-surfaces", type=int, default=8)
    p.add_argument("--exclude", default="", help="generator regions to leave out, comma-separated: "
                                                 + ", ".join(sorted(REGIONS)))
    p.add_argument("--no-display", action="store_true", help="do not run the display stage on the renders")
    p.add_argument("--shrink-seconds", type=float, default=120.0, help="time to shrink each finding")
    p.add_argument("--tolerance", type=float, default=harness.compare.TOLERANCE,
                   help="GL/CPU relative error tolerance (default %(default)g)")
    p.add_argument("--demo", default=None, help="render through this airlight-demo binary (CPU backend, a "
                                                "process per scene; the sanitizer run)")
    p.add_argument("--fresh", action="store_true", help="a new worker process for every render")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--replay", nargs="+", type=Path, help="check these scene files instead of a run")
    p.add_argument("--replay-bad", nargs="+", type=Path, help="replay these bad-input reproducers")
    p.add_argument("--calibrate", action="store_true",
                   help="print the GL/CPU disagreement metric of every shipped preset")
    return p


def _size(text: str) -> tuple[int, int]:
    w, _, h = text.lower().partition("x")
    return int(w), int(h)


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status (1 when something was found)."""
    args = _parser().parse_args(argv)
    backends = tuple(b for b in args.backends.split(",") if b)
    allowed = {"demo"} if args.demo else {"gl", "cpu"}
    if not backends or not set(backends) <= allowed:
        print(f"--backends: must be a comma-separated subset of {', '.join(sorted(allowed))}",
              file=sys.stderr)
        return 2
    exclude = frozenset(x for x in args.exclude.split(",") if x)
    unknown = exclude - set(REGIONS)
    if unknown:
        print(f"--exclude: unknown regions {', '.join(sorted(unknown))}", file=sys.stderr)
        return 2
    width, height = _size(args.film)
    config = GeneratorConfig(max_width=width, max_height=height,
                             fixed_film=_size(args.fixed_film) if args.fixed_film else None,
                             max_lights=args.max_lights, max_surfaces=args.max_surfaces, exclude=exclude)
    options = harness.FuzzOptions(scenes=args.scenes, seed=args.seed, backends=backends, timeout=args.timeout,
                                  out=args.out, bad_inputs=args.bad_inputs, display=not args.no_display,
                                  shrink_seconds=args.shrink_seconds, generator=config, demo=args.demo,
                                  fresh=args.fresh, progress=not args.quiet, tolerance=args.tolerance,
                                  deadline=time.monotonic() + args.duration if args.duration else None)
    if args.calibrate:
        return harness.calibrate(options)
    if args.replay:
        return harness.replay(args.replay, options)
    if args.replay_bad:
        return harness.replay_bad(args.replay_bad, options)
    print(f"airlight fuzz: seed {args.seed}, backends {','.join(backends)} "
          f"(here: {harness.environment_note()}), "
          f"out {args.out}", file=sys.stderr)
    report = harness.run(options)
    print(harness.summary(report))
    return 0 if report.ok() else 1


if __name__ == "__main__":
    sys.exit(main())
