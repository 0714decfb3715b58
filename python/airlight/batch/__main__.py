"""``airlight-batch SPEC --out DIR`` (also ``python -m airlight.batch``): renders a sweep
(README "Datasets: batch sweeps"). Exit status 0 when every item succeeded or was already
written, 1 when some failed (listed in DIR/failures.jsonl), 2 for a bad spec or option."""

from __future__ import annotations

import argparse
import sys

from . import load_spec, run


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="airlight-batch", description=__doc__)
    ap.add_argument("spec", help="the sweep: a JSON or YAML file")
    ap.add_argument("--out", required=True, help="the dataset's folder (created; an existing one is resumed)")
    ap.add_argument("--workers", type=int, default=None, help="Ray actors (default: one per core)")
    ap.add_argument("--address", default=None, help="a Ray cluster's address (default: a local one)")
    ap.add_argument("--cpu-threads", type=int, default=None,
                    help="CPU threads per worker (default: cores / workers)")
    ap.add_argument("--no-resume", action="store_true", help="render every item again")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    try:
        spec = load_spec(args.spec)
        summary = run(spec, args.out, workers=args.workers, address=args.address,
                      cpu_threads=args.cpu_threads, resume=not args.no_resume, progress=not args.no_progress)
    except (TypeError, ValueError, FileNotFoundError) as e:
        print(f"airlight-batch: {e}", file=sys.stderr)
        return 2
    print(f"airlight-batch: {summary}")
    for failure in summary.failures:
        print(f"airlight-batch: item {failure['id']} failed ({failure['failed']}): {failure['error']}",
              file=sys.stderr)
    return 1 if summary.failed else 0


if __name__ == "__main__":
    sys.exit(main())
