"""The reference particle's solver against the float64 numpy path tracer, orders 1-3 and every order.

    .venv/bin/python effects/particle_clouds/bench/sphere_against_tracer.py \\
        [--taus 1 5 20 50] [--gs 0 0.5 0.9] [--paths 131072] [--total-paths 65536] \\
        [--out effects/particle_clouds/docs/sphere_against_tracer.txt]

Why a second outside reference beside Mitsuba (sphere_against_mitsuba.py). The total light of a
thick isotropic particle's shadowed side comes from paths of thousands of scatterings; the numpy
tracer of effects/particle_clouds/tests/sphere_paths.py follows every camera path until it leaves
(``radiance_all_orders``: no cut, no roulette, up to about 9000 orders at tau = 50, g = 0), where
Mitsuba with Russian roulette after 2000 vertices came out 30-50 % dark on those rays (a one-off
comparison, physics.md 2.6). It also
has lower noise per sample (next-event estimation with the exact transmittance, a forced first
collision), so orders 1-3 are resolved to about 1 % on 2^17 paths.

Per case (tau, g), on the 25 rays of sphere_against_mitsuba.sweep_rays (front-lit to back-lit, from
the centre to 0.98 radii):

* the solver with the default grid, orders 1-3 and, in one call with the orders beyond (eq. 2.11),
  the total; and the same orders 1-3 with uniform polar nodes (``graded_polar`` false: what
  physics.md eq. 2.14 fixed);
* sphere_paths.radiance_by_order (orders 1-3, --paths per ray) and radiance_all_orders (the total,
  --total-paths per ray), float64.

Columns as in sphere_against_mitsuba.py (rays above 1e-3 of the case's largest; rel = solver /
tracer - 1; fail = |difference| > max(2 %, 3 tracer standard errors)), plus ``uniform``: the failing
rays of the same order with uniform polar nodes. Failing rays are listed after the table. About
25 minutes with the defaults on two cores (the totals of tau = 50, g = 0 take the longest).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import airlight

HERE = Path(__file__).resolve().parent
for _dir in (HERE, HERE.parent / "tests", HERE.parents[2] / "tests" / "python"):  # the last: shared_results
    if str(_dir) not in sys.path:
        sys.path.insert(0, str(_dir))

import sphere_paths as sp  # noqa: E402
from sphere_against_mitsuba import (  # noqa: E402
    FLOOR,
    REL_TOL,
    SUN,
    Z_TOL,
    compare,
    failing_rays,
    finish,
    sweep_rays,
)

COLUMNS = ["k=1", "k=2", "k=3", "total"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--taus", type=float, nargs="+", default=[1.0, 5.0, 20.0, 50.0])
    ap.add_argument("--gs", type=float, nargs="+", default=[0.0, 0.5, 0.9])
    ap.add_argument("--paths", type=int, default=1 << 17, help="tracer paths per ray for orders 1-3")
    ap.add_argument("--total-paths", type=int, default=1 << 16, help="tracer paths per ray for the total")
    ap.add_argument("--steps", type=int, default=1024, help="solver samples per camera ray")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="write the table to this text file")
    args = ap.parse_args()

    t_start = time.perf_counter()
    origins, dirs, labels = sweep_rays()
    lines = [
        f"Solver (airlight particle_sphere_radiance, default grid, {args.steps} samples per camera ray) "
        f"against the numpy tracer (sphere_paths.py: orders 1-3 on {args.paths} paths per ray, every "
        f"order on {args.total_paths}), and the solver with uniform polar nodes (graded_polar false) "
        "for orders 1-3",
        f"per column: rays with the tracer above {FLOOR:g} of the case's largest (n); "
        f"rel = solver / tracer - 1; fail = |difference| > max({REL_TOL:.0%}, {Z_TOL:g} tracer se); "
        "uniform = failing rays with uniform polar nodes",
        "",
        f"{'tau':>5} {'g':>4} {'col':>6} {'n':>3} {'med rel':>8} {'max rel':>8} {'med|z|':>7} {'max|z|':>7} "
        f"{'fail':>4} {'uniform':>7}",
    ]
    print("\n".join(lines), flush=True)
    failures: list[str] = []
    totals = {c: [0, 0, 0] for c in COLUMNS}  # rays compared, failing, failing with uniform nodes
    t_solver = t_tracer = 0.0
    most_orders: dict[str, int] = {}
    for i_case, (tau, g) in enumerate((t, g) for t in args.taus for g in args.gs):
        t = time.perf_counter()
        solve = airlight._core.particle_sphere_radiance
        solved = np.asarray(solve(tau, g, SUN, origins, dirs, {"beyond": True}, args.steps))
        uniform_grid = {"orders": 3, "graded_polar": False}
        uniform = np.asarray(solve(tau, g, SUN, origins, dirs, uniform_grid, args.steps))
        t_solver += time.perf_counter() - t
        t = time.perf_counter()
        seed = args.seed + 1000 * i_case
        by_order, by_order_se = sp.radiance_by_order(tau, g, SUN, origins, dirs, orders=3, paths=args.paths,
                                                     seed=seed)
        total, total_se, most = sp.radiance_all_orders(tau, g, SUN, origins, dirs, paths=args.total_paths,
                                                       seed=seed + 1)
        t_tracer += time.perf_counter() - t
        most_orders[f"tau {tau:g} g {g:g}"] = most
        mine = np.concatenate([solved[:, :3], solved.sum(axis=1, keepdims=True)], axis=1)
        plain = np.concatenate([uniform, np.full((len(dirs), 1), np.nan)], axis=1)
        ref = np.concatenate([by_order, total[:, None]], axis=1)
        se = np.concatenate([by_order_se, total_se[:, None]], axis=1)
        for c, name in enumerate(COLUMNS):
            st = compare(mine[:, c], ref[:, c], se[:, c])
            if st["n"] == 0:
                continue
            n_uniform = int(compare(plain[:, c], ref[:, c], se[:, c])["fail"].sum()) if c < 3 else 0
            n_fail = int(st["fail"].sum())
            totals[name][0] += st["n"]
            totals[name][1] += n_fail
            totals[name][2] += n_uniform
            lines.append(f"{tau:5g} {g:4g} {name:>6} {st['n']:3d} {st['med_rel']:+8.2%} "
                         f"{st['max_rel']:+8.2%} {st['med_z']:7.2f} {st['max_z']:7.1f} {n_fail:4d} "
                         f"{n_uniform if c < 3 else '-':>7}")
            print(lines[-1], flush=True)
            case = f"tau {tau:g} g {g:g} {name:>6}"
            failures += failing_rays(case, labels, st, mine[:, c], ref[:, c], se[:, c], "tracer")
    elapsed = time.perf_counter() - t_start
    summary = ["over all cases: " + ", ".join(
        f"{c} {f}/{n} rays fail" + (f" ({u} with uniform polar nodes)" if c != "total" else "")
        for c, (n, f, u) in totals.items()),
        "most orders a tracer path took: " + ", ".join(f"{k} {v}" for k, v in most_orders.items())]
    finish(lines, summary, failures, f"timing: solver {t_solver:.0f} s, tracer {t_tracer:.0f} s, total "
           f"{elapsed:.0f} s ({elapsed / 60:.1f} min)", args.out)


if __name__ == "__main__":
    main()
