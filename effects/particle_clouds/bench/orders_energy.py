"""The energy the source's 18 scattering orders leave out, and what the solver's orders beyond bring back.

    .venv/bin/python effects/particle_clouds/bench/orders_energy.py [--orders 18] [--paths 262144]
        [--taus 0.1 ... 50] [--gs 0 0.5 0.85] [--solver-only]
        [--out effects/particle_clouds/docs/orders_energy.txt]

For the reference particle (physics.md section 2: a unit sphere of optical radius tau, albedo 1,
Henyey-Greenstein g, lit by the sun) the photon tracer of effects/particle_clouds/tests/sphere_paths.py
counts the share of the incident energy that leaves after each order. With albedo 1 everything that
is not transmitted directly (T_direct, closed form) leaves after some order, so the light still inside
after the last order summed is exactly what a table of that many orders misses: printed as a share of
the scattered light (1 - T_direct) and of the light the orders do carry.

Beside it, airlight's solver at its default grid with grid["beyond"] (physics.md eq. 2.11, every
order beyond N solved at once): its share beyond N, its total over 1 - T_direct (1 when nothing is
created or lost) and the time the solve and its flux integral took on this machine. With
--solver-only the photon tracer is skipped (its columns are blank): the solver's energy and time alone.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import sphere_flux  # noqa: E402
import sphere_paths  # noqa: E402

TAUS = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 50.0]
GS = [0.0, 0.5, 0.85]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--orders", type=int, default=18)
    ap.add_argument("--paths", type=int, default=1 << 18)
    ap.add_argument("--taus", type=float, nargs="+", default=TAUS)
    ap.add_argument("--gs", type=float, nargs="+", default=GS)
    ap.add_argument("--solver-only", action="store_true", help="skip the photon tracer")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    tracer = "photon tracer skipped" if args.solver_only else f"photon tracer, {args.paths} paths per case"
    lines = [f"Energy left beyond order {args.orders} ({tracer}; shares of "
             "the incident energy) and the solver's orders beyond (default grid)",
             f"{'tau':>6} {'g':>5} {'1 - T_direct':>13} {'orders 1..N':>12} {'beyond N':>10} "
             f"{'beyond / scattered':>19} {'missing vs sum':>15} {'solver beyond N':>16} "
             f"{'solver total / (1 - T)':>23} {'solver s':>9}"]
    for tau in args.taus:
        for g in args.gs:
            scattered = 1.0 - sphere_paths.direct_transmission(tau)
            if not args.solver_only:
                shares, _, beyond = sphere_paths.escaping_flux_by_order(tau, g, orders=args.orders,
                                                                        paths=args.paths, seed=1)
                carried = float(np.sum(shares))
            start = time.perf_counter()
            # g = 0.85's forward peak needs 24 Gauss nodes in the escape angle (12 miss 7 % of order 1)
            solver = sphere_flux.solver_flux_by_order(tau, g, {"orders": args.orders, "beyond": True},
                                                      nodes=24 if g > 0.6 else 12)
            seconds = time.perf_counter() - start
            photons = (" " * 58 if args.solver_only else
                       f" {carried:12.4f} {beyond:10.4f} {beyond / scattered:18.1%} {beyond / carried:14.1%}")
            lines.append(f"{tau:6.1f} {g:5.2f} {scattered:13.4f}{photons} {solver[-1]:16.4f} "
                         f"{solver.sum() / scattered:23.4f} {seconds:9.1f}")
            print(lines[-1], file=sys.stderr)
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
