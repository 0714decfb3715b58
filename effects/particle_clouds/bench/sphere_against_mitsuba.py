"""The reference particle's solver (physics.md section 2) against Mitsuba 3, order by order and in total.

    .venv/bin/python effects/particle_clouds/bench/sphere_against_mitsuba.py \\
        [--taus 0.1 1 5 20 50] [--gs 0 0.5 0.9] [--spp 1048576] [--quick] \\
        [--out effects/particle_clouds/docs/sphere_against_mitsuba.txt] \\
        [--plot effects/particle_clouds/docs/sphere_against_mitsuba.png] \\
        [--json effects/particle_clouds/tests/sphere_mitsuba_reference.json]

What it measures. The issue's acceptance for the particle table: against Mitsuba 3's volumetric path
tracer (a homogeneous HG sphere lit by a directional light), per scattering order and in total, the
exitant radiance agrees within 2 % (or within the path tracer's noise where that is larger) over
optical radii 0.1 to 50, g 0 to 0.9 and every view and sun angle. The table is checked against the
solver later; this measures the solver against Mitsuba. Per case (tau, g):

* the solver: ``airlight._core.particle_sphere_radiance`` with the default grid, 18 orders and every
  order beyond (eq. 2.11), ONE call per case for all rays, ``--steps`` (default 1024) samples per
  camera ray (physics.md 2.2: the ray march leaves 0.9 % at 256 samples on a ray entering at the
  terminator of a tau = 50 sphere, 0.13 % at 1024; the steps only set the camera rays' march, not
  the grid);
* Mitsuba (effects/particle_clouds/bench/sphere_mitsuba.py, whose ``_chunk_means`` and ``_stats``
  are used): max_depth 2, 3, 4, 19 and unlimited rendered with the same seeds and lanes (common
  random numbers; each ray its own seed), order 1 = L(2) (L(1) is exactly 0), order k = L(k + 1) -
  L(k) for k = 2, 3, the sum of orders 1..18 = L(19) and the total = L(-1); standard errors from 16
  batch means. The sphere has radius 100 in Mitsuba's world (sigma_t = tau / 100, the harness scales
  the ray origins by the radius, directions unchanged, so the optical geometry and the radiances are
  the same as for the unit sphere): its float32 single-scattering deficit at tau = 50 is 0.7 % there
  against 1.3 % at radius 1 (sphere_mitsuba.py's docstring).

The rays (the same 25 for every case; ``sweep_rays``): the sun is test_sphere_scattering.SUN
= (0, 0.6, 0.8); five orthographic views (test_sphere_scattering.orthographic_rays, imported) with
sun . v = -1 (front-lit, the sun behind the camera), -0.5, 0 (side-lit), 0.5 and 0.94 (back-lit, 20
degrees from the sun), each turned about the sun by a different azimuth; in each, five points of the
silhouette at (distance from the centre, angle from the sun's side of the image): (0, -), (0.5, 60),
(0.8, 180: the limb away from the sun), (0.93, 0: the limb toward the sun) and (0.98, 100: at the
edge, near the terminator). For the front-lit view the sun's side is undefined and the angle is
measured from the view's first image axis.

The statistics (per case and per order 1, 2, 3 and the sum of 18): over the rays whose Mitsuba value
is above 1e-3 of the case's largest for that order (``n``; the others are a thick sphere's dark
side, down to 1e-40, which Mitsuba barely samples): the median and the largest relative error
(solver / Mitsuba - 1; the largest by magnitude, signed), the median and largest |z| (z = difference
/ Mitsuba's standard error; the solver has none), the median relative standard error of Mitsuba,
``noisy`` (rays where 3 standard errors exceed 2 %: there the noise sets the bound) and ``fail``
(rays where |difference| > max(2 % of Mitsuba, 3 Mitsuba standard errors): the acceptance). Every
failing ray is listed after the table.

Reading the run (effects/particle_clouds/docs/sphere_against_mitsuba.txt, --spp 262144; a few failing
rays re-checked by hand against sphere_paths' closed-form single scattering and its float64 path
tracer): order 1's failures at tau 20 and 50 are Mitsuba's (the solver equals the closed form to 4
digits; Mitsuba is 2-12 % low on rays entering where the sun grazes, even at radius 100); at tau 0.1,
g 0.9 the failing orders 2 and 3 (radiances near the 1e-3 floor, front- and side-lit) agree with
sphere_paths, Mitsuba being low there with heavy tails its batch-means error misses. Mitsuba runs
without Russian roulette (sphere_mitsuba.RR_DEPTH): with roulette after 2000 vertices its total on a
tau = 50, g = 0 sphere's shadowed side was 30-50 % low against sphere_paths followed to the end
(a one-off comparison, physics.md 2.6; sphere_against_tracer.py). The total's remaining
failures (physics.md section 2.6): at tau = 50 the
deepest shadow, 1e-3 of the brightest, 12-24 % darker than Mitsuba (within the numpy tracer's larger
noise there), and g = 0.9 (the polar and direction grids:
effects/particle_clouds/docs/sphere_grid_g09.txt).

Runtime with --spp 262144 (15 cases, 25 rays, five depths): 74 minutes on 2 cores shared with other
benchmarks (solver 548 s, Mitsuba 3863 s: without roulette the thick spheres' paths run to thousands
of scatterings); the last line of the text file. Mitsuba's time is
proportional to --spp. --quick (tau 5, g 0.5, 65536 samples): about a minute. --stored FILE compares
with the values a --json run stored (the solver alone, about 10 minutes; no Mitsuba needed), and
--grid '{"radii": 24}' changes the solver's grid: together they try a grid against the path tracer.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

import airlight

HERE = Path(__file__).resolve().parent
for _dir in (HERE, HERE.parent / "tests", HERE.parents[2] / "tests" / "python"):  # the last: shared_results
    if str(_dir) not in sys.path:
        sys.path.insert(0, str(_dir))

import sphere_mitsuba as sm  # noqa: E402
from test_sphere_scattering import SUN, orthographic_rays  # noqa: E402

ORDERS = 18  # the source's orders; Mitsuba's max_depth ORDERS + 1 is their sum
RADIUS = 100.0  # the sphere's radius in Mitsuba's world (module docstring)
DEPTHS = [2, 3, 4, ORDERS + 1, -1]  # -1: unlimited, every order
COLUMNS = ["k=1", "k=2", "k=3", f"sum{ORDERS}", "total"]
FLOOR = 1e-3  # rays below this fraction of the case's largest Mitsuba value (per order) are left out
REL_TOL, Z_TOL = 0.02, 3.0  # the acceptance: |difference| <= max(2 %, 3 standard errors)

# (name, sun . v, azimuth of the view about the sun in degrees)
VIEWS = [("front", -1.0, 0.0), ("front45", -0.5, 70.0), ("side", 0.0, 140.0), ("back45", 0.5, 210.0),
         ("back", 0.94, 280.0)]
# (distance from the silhouette's centre, angle in degrees from the sun's side of the image)
OFFSETS = [(0.0, 0.0), (0.5, 60.0), (0.8, 180.0), (0.93, 0.0), (0.98, 100.0)]


def _view_dir(sun_dot_v: float, azimuth_deg: float) -> np.ndarray:
    """The unit view direction at cosine ``sun_dot_v`` from SUN, turned by ``azimuth_deg`` about it."""
    s = np.asarray(SUN, float) / np.linalg.norm(SUN)
    e1 = np.cross(s, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(s, e1)
    phi = math.radians(azimuth_deg)
    sin_t = math.sqrt(max(0.0, 1.0 - sun_dot_v * sun_dot_v))
    return sun_dot_v * s + sin_t * (math.cos(phi) * e1 + math.sin(phi) * e2)


def sweep_rays() -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The 25 rays of every case (module docstring): origins, directions (unit sphere) and labels."""
    s = np.asarray(SUN, float) / np.linalg.norm(SUN)
    origins, dirs, labels = [], [], []
    for name, cos_sv, azimuth in VIEWS:
        v = _view_dir(cos_sv, azimuth)
        # orthographic_rays' image axes (a, b), recovered from the rays through (1, 0), (0, 1), (0, 0)
        o, _ = orthographic_rays(list(v), [(1.0, 0.0), (0.0, 1.0), (0.0, 0.0)])
        a, b = o[0] - o[2], o[1] - o[2]
        toward = s - (s @ v) * v  # the sun's direction projected onto the image plane
        if np.linalg.norm(toward) < 1e-6:
            toward = a
        ux, uy = float(toward @ a), float(toward @ b)
        base = math.atan2(uy, ux)
        offs = [(rho * math.cos(base + math.radians(ang)), rho * math.sin(base + math.radians(ang)))
                for rho, ang in OFFSETS]
        o, d = orthographic_rays(list(v), offs)
        origins.append(o)
        dirs.append(d)
        labels += [f"{name}(s.v={cos_sv:+.2f}) r={rho:.2f}@{ang:.0f}" for rho, ang in OFFSETS]
    return np.concatenate(origins), np.concatenate(dirs), labels


def solver_by_order(tau: float, g: float, origins: np.ndarray, dirs: np.ndarray, steps: int,
                    grid_keys: dict | None = None) -> np.ndarray:
    """The solver's radiance (n_rays, ORDERS + 1): orders 1..ORDERS and every order beyond (eq. 2.11),
    one call (the default grid, with ``grid_keys`` in place of its fields)."""
    grid = {**(grid_keys or {}), "orders": ORDERS, "beyond": True}
    return airlight._core.particle_sphere_radiance(tau, g, SUN, origins, dirs, grid, steps)


def mitsuba_columns(tau: float, g: float, origins: np.ndarray, dirs: np.ndarray, spp: int, seed: int,
                    chunks: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Mitsuba's orders 1, 2, 3, the sum of 1..ORDERS and every order (means, standard errors:
    (n_rays, 5)) and
    the seconds spent. Each ray is rendered with its own seed (``seed`` + its index): the harness seeds
    every origin alike, which would give all rays the same random numbers and make their errors move
    together (a case's median error would then be one draw of the noise, not an average)."""
    cols: list[list[tuple[np.ndarray, np.ndarray]]] = []
    seconds = 0.0
    for i in range(len(dirs)):
        means, sec, _ = sm._chunk_means(tau, g, SUN, origins[i : i + 1], dirs[i : i + 1], spp, DEPTHS, chunks,
                                        seed + i, RADIUS)
        seconds += sum(sec.values())
        cols.append([sm._stats(means[2]), sm._stats(means[3] - means[2]), sm._stats(means[4] - means[3]),
                     sm._stats(means[ORDERS + 1]), sm._stats(means[-1])])
    mean = np.array([[float(m[0]) for m, _ in row] for row in cols])
    se = np.array([[float(e[0]) for _, e in row] for row in cols])
    return mean, se, seconds


def compare(mine: np.ndarray, ref: np.ndarray, se: np.ndarray) -> dict:
    """The statistics of one case and column (module docstring)."""
    keep = ref > FLOOR * ref.max() if ref.max() > 0 else np.zeros_like(ref, bool)
    diff = mine - ref
    rel = np.where(keep, diff / np.where(keep, ref, 1.0), 0.0)
    z = np.where(keep & (se > 0), diff / np.where(se > 0, se, 1.0), np.inf)
    fail = keep & (np.abs(diff) > np.maximum(REL_TOL * np.abs(ref), Z_TOL * se))
    noisy = keep & (Z_TOL * se > REL_TOL * np.abs(ref))
    if not keep.any():
        return {"n": 0, "fail": fail, "keep": keep, "rel": rel, "z": z}
    r, zk = rel[keep], np.abs(z[keep])
    return {"n": int(keep.sum()), "med_rel": float(np.median(r)), "max_rel": float(r[np.argmax(np.abs(r))]),
            "med_z": float(np.median(zk)), "max_z": float(zk.max()),
            "med_se": float(np.median(se[keep] / ref[keep])), "noisy": int(noisy.sum()),
            "fail": fail, "keep": keep, "rel": rel, "z": z}


Point = tuple[int, int, np.ndarray, np.ndarray, np.ndarray]  # case, column, solver, Mitsuba, Mitsuba se


def plot(path: str, points: list[Point], cases: list[str]) -> None:
    """Solver against Mitsuba (log-log) and the relative errors per case with 3 Mitsuba standard errors,
    one colour per column."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(15, 6.5))
    lo = min(float(ref.min()) for _, _, _, ref, _ in points)  # compared rays are above the floor, so > 0
    for c, name in enumerate(COLUMNS):
        sel = [(mine, ref) for _, col, mine, ref, _ in points if col == c]
        if not sel:
            continue
        mine = np.concatenate([m for m, _ in sel])
        ref = np.concatenate([r for _, r in sel])
        ax0.scatter(ref, np.maximum(mine, lo * 1e-1), s=9, color=colours[c], label=name, alpha=0.7)
    hi = max(float(np.max(ref)) for _, _, _, ref, _ in points)
    ax0.plot([lo, hi], [lo, hi], "k-", lw=0.8)
    ax0.set_xscale("log")
    ax0.set_yscale("log")
    ax0.set_xlabel("Mitsuba 3 (volpath) radiance")
    ax0.set_ylabel("solver radiance")
    ax0.set_title(f"rays above {FLOOR:g} of their case's largest, {len(cases)} cases")
    ax0.legend()
    for case, col, mine, ref, se in points:
        rel = 100.0 * (mine / ref - 1.0)
        x = case + (col - 2.0) * 0.16 + np.linspace(-0.05, 0.05, len(rel))
        ax1.errorbar(x, np.clip(rel, -20.0, 20.0), yerr=100.0 * Z_TOL * se / ref, fmt="o", ms=2.5,
                     elinewidth=0.6, color=colours[col], alpha=0.7)
    ax1.axhspan(-100 * REL_TOL, 100 * REL_TOL, color="0.85", zorder=0)
    ax1.axhline(0.0, color="k", lw=0.6)
    ax1.set_ylim(-21.0, 21.0)
    ax1.set_xticks(range(len(cases)))
    ax1.set_xticklabels(cases, rotation=60, ha="right", fontsize=8)
    ax1.set_ylabel("solver / Mitsuba - 1 (%), clipped to +-20")
    ax1.set_title(f"relative error per case (grey: {REL_TOL:.0%}; bars: {Z_TOL:g} Mitsuba se)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def failing_rays(case: str, labels: list[str], st: dict, mine: np.ndarray, ref: np.ndarray, se: np.ndarray,
                 reference: str) -> list[str]:
    """One line per failing ray of a case's column (``st`` from ``compare``)."""
    return [f"{case} {labels[i]:<30} solver {mine[i]:.4e} {reference} {ref[i]:.4e} +- {se[i]:.1e}  "
            f"rel {st['rel'][i]:+.2%}  z {st['z'][i]:+.1f}" for i in np.nonzero(st["fail"])[0]]


def finish(lines: list[str], summary: list[str], failures: list[str], timing: str, out: str | None) -> None:
    """Appends the summary, the failing rays and the timing to the table's lines, prints them and writes
    the whole to ``out`` when given."""
    lines += ["", *summary, ""]
    lines.append(f"failing rays ({len(failures)}):" if failures else "failing rays: none")
    lines += ["  " + f for f in failures]
    lines += ["", timing]
    print("\n".join(lines[-(len(failures) + len(summary) + 5):]), flush=True)
    if out:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        Path(out).write_text("\n".join(lines) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--taus", type=float, nargs="+", default=[0.1, 1.0, 5.0, 20.0, 50.0])
    ap.add_argument("--gs", type=float, nargs="+", default=[0.0, 0.5, 0.9])
    ap.add_argument("--spp", type=int, default=1 << 20, help="Mitsuba samples per ray and max_depth")
    ap.add_argument("--steps", type=int, default=1024, help="solver samples per camera ray")
    ap.add_argument("--chunks", type=int, default=sm.CHUNKS, help="Mitsuba batch means per ray")
    ap.add_argument("--seed", type=int, default=0,
                    help="Mitsuba seeds: seed + 1000 case + ray (every ray and case its own random numbers)")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--libllvm", default=None, help="libLLVM for Dr.Jit (else DRJIT_LIBLLVM_PATH, or search)")
    ap.add_argument("--out", default=None, help="write the table to this text file")
    ap.add_argument("--plot", default=None, help="write a PNG of solver against Mitsuba")
    ap.add_argument("--json", default=None,
                    help="write Mitsuba's means and standard errors per case, column and ray (with the rays) "
                    "to this file: the stored reference of test_sphere_scattering's thick-sphere test")
    ap.add_argument("--quick", action="store_true", help="tau 5, g 0.5 only, 65536 samples")
    ap.add_argument("--stored", default=None,
                    help="compare with the Mitsuba values a --json run stored in this file instead of "
                    "rendering them (the solver alone: minutes, no Mitsuba needed; its cases and rays)")
    ap.add_argument("--grid", type=json.loads, default={},
                    help='solver grid fields in place of the defaults, as JSON (e.g. \'{"radii": 24}\')')
    args = ap.parse_args()
    if args.quick:
        args.taus, args.gs, args.spp = [5.0], [0.5], 65536
    if args.stored and args.json:
        ap.error("--json stores what Mitsuba rendered; with --stored nothing is rendered")

    t_start = time.perf_counter()
    origins, dirs, labels = sweep_rays()
    if args.stored:
        kept = json.loads(Path(args.stored).read_text())
        if not np.allclose(kept["origins"], origins) or not np.allclose(kept["dirs"], dirs):
            sys.exit(f"{args.stored}: its rays are not this script's sweep_rays()")
        stored_cases = {(c["tau"], c["g"]): c for c in kept["cases"]}
        missing = [(t, g) for t in args.taus for g in args.gs if (t, g) not in stored_cases]
        if missing:
            sys.exit(f"{args.stored}: no stored case for (tau, g) {missing}")
        reference = (f"Mitsuba {kept['mitsuba']} volpath ({kept['variant']}; stored in {args.stored}, "
                     f"{kept['spp']} samples per ray and max_depth in {kept['chunks']} batch means)")
    else:
        mi = sm.load(args.threads, args.libllvm)
        reference = (f"Mitsuba {mi.__version__} volpath ({mi.variant()}, sphere radius {RADIUS:g} in its "
                     f"world, {args.spp} samples per ray and max_depth in {args.chunks} batch means, common "
                     "random numbers)")
    grid_name = "default grid" + (f" with {json.dumps(args.grid)}" if args.grid else "")
    lines = [
        f"Solver (airlight particle_sphere_radiance, {grid_name}, {ORDERS} orders and every order beyond, "
        f"{args.steps} samples per camera ray) against {reference}",
        f"sun {tuple(float(x) for x in SUN)}; {len(dirs)} rays per case: views (sun . v) "
        + ", ".join(f"{n} {c:+.2f}" for n, c, _ in VIEWS)
        + "; offsets (r, degrees from the sun's side) " + ", ".join(f"({r:g}, {a:g})" for r, a in OFFSETS),
        f"per column: rays with Mitsuba above {FLOOR:g} of the case's largest (n); rel = solver / Mitsuba "
        "- 1 (median, largest magnitude); |z| = |difference| / Mitsuba se (median, max); se = Mitsuba "
        f"relative se (median); noisy = rays where {Z_TOL:g} se > {REL_TOL:.0%}; fail = |difference| > "
        f"max({REL_TOL:.0%}, {Z_TOL:g} se)",
        "",
        f"{'tau':>5} {'g':>4} {'col':>6} {'n':>3} {'med rel':>8} {'max rel':>8} {'med|z|':>7} {'max|z|':>7} "
        f"{'se':>7} {'noisy':>5} {'fail':>4}",
    ]
    print("\n".join(lines), flush=True)
    failures: list[str] = []
    points: list[Point] = []
    cases: list[str] = []
    t_solver = t_mitsuba = 0.0
    totals = {c: [0, 0] for c in COLUMNS}  # rays compared, rays failing
    stored: list[dict] = []
    for i_case, (tau, g) in enumerate((t, g) for t in args.taus for g in args.gs):
        t = time.perf_counter()
        mine_k = solver_by_order(tau, g, origins, dirs, args.steps, args.grid)
        t_solver += time.perf_counter() - t
        mine = np.concatenate([mine_k[:, :3], mine_k[:, :ORDERS].sum(axis=1, keepdims=True),
                               mine_k.sum(axis=1, keepdims=True)], axis=1)
        seed = args.seed + 1000 * i_case
        if args.stored:
            ref, se = (np.array(stored_cases[(tau, g)][k]) for k in ("mean", "se"))
        else:
            ref, se, sec = mitsuba_columns(tau, g, origins, dirs, args.spp, seed, args.chunks)
            t_mitsuba += sec
        cases.append(f"tau {tau:g} g {g:g}")
        stored.append({"tau": tau, "g": g, "mean": ref.tolist(), "se": se.tolist()})
        for c, name in enumerate(COLUMNS):
            st = compare(mine[:, c], ref[:, c], se[:, c])
            if st["n"] == 0:
                lines.append(f"{tau:5g} {g:4g} {name:>6} {0:3d}   (no ray above the floor)")
                print(lines[-1], flush=True)
                continue
            keep = st["keep"]
            points.append((len(cases) - 1, c, mine[keep, c], ref[keep, c], se[keep, c]))
            n_fail = int(st["fail"].sum())
            totals[name][0] += st["n"]
            totals[name][1] += n_fail
            lines.append(f"{tau:5g} {g:4g} {name:>6} {st['n']:3d} {st['med_rel']:+8.2%} "
                         f"{st['max_rel']:+8.2%} {st['med_z']:7.2f} {st['max_z']:7.1f} {st['med_se']:7.2%} "
                         f"{st['noisy']:5d} {n_fail:4d}")
            print(lines[-1], flush=True)
            case = f"tau {tau:g} g {g:g} {name:>6}"
            failures += failing_rays(case, labels, st, mine[:, c], ref[:, c], se[:, c], "Mitsuba")
    total = time.perf_counter() - t_start
    mitsuba_time = "stored" if args.stored else f"{t_mitsuba:.0f} s"
    finish(lines, ["over all cases: " + ", ".join(f"{c} {f}/{n} rays fail" for c, (n, f) in totals.items())],
           failures, f"timing: solver {t_solver:.0f} s, Mitsuba {mitsuba_time}, total {total:.0f} s "
           f"({total / 60:.1f} min, {args.threads} threads)", args.out)
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({
            "command": "effects/particle_clouds/bench/sphere_against_mitsuba.py " + " ".join(sys.argv[1:]),
            "mitsuba": mi.__version__, "variant": mi.variant(), "spp": args.spp, "chunks": args.chunks,
            "sun": [float(x) for x in SUN], "columns": COLUMNS, "labels": labels,
            "origins": origins.tolist(), "dirs": dirs.tolist(), "cases": stored}) + "\n")
    if args.plot and points:
        plot(args.plot, points, cases)


if __name__ == "__main__":
    main()
