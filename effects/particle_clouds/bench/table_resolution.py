"""The particle lighting table's resolution chosen by its error against the solver it is built from.

    .venv/bin/python effects/particle_clouds/bench/table_resolution.py [--g 0.85]
        [--parts angles taus build] [--out effects/particle_clouds/docs/table_resolution.txt]

The table (effects/particle_clouds/physics.md section 3) interpolates the reference particle's light
in four coordinates: the entry point's angle from the sun, the ray's zenith and azimuth there, and
the optical radius. Its error against the solver evaluated directly at the same rays (which is
checked against path tracers separately: test_sphere_scattering.py, sphere_against_mitsuba.py) is
measured in two parts:

1. the angles: tables of two optical radii (the tested radius and one above it) at several angular
   resolutions, with entry angles uniform or dense across the terminator (eq. 3.2), looked up at the
   tested radius (a node in tau, so only the angles interpolate), for random rays over the whole
   sphere and random sun directions;
2. the optical radius: tables over [0.1, 50] with several numbers of radii, looked up at the
   geometric midpoints between their nodes (the worst place), against the solver at those radii.

Errors are relative errors of the total radiance (every order, as the renderer's tables hold: the
orders beyond 18 light a thick particle's shadowed side) over the rays above 1e-3 of the largest:
median, 99th percentile and maximum. Build time and size per table.

3. the build: the tables the renderer builds for quality.particle_table "full" and "preview"
   (every order, eq. 2.11), timed at --g (the presets' particles have g = 0.7).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import airlight

core = airlight._core


def random_rays(count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rays entering the unit sphere (origins 3 radii out, dirs), their entry normals, and a sun per ray."""
    rng = np.random.default_rng(seed)
    dirs = rng.normal(size=(count, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    helper = np.where(np.abs(dirs[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    a = np.cross(dirs, helper)
    a /= np.linalg.norm(a, axis=1)[:, None]
    b = np.cross(dirs, a)
    rho, phi = np.sqrt(rng.uniform(0.0, 1.0, count)), rng.uniform(0.0, 2.0 * np.pi, count)
    origins = (rho * np.cos(phi))[:, None] * a + (rho * np.sin(phi))[:, None] * b - 3.0 * dirs
    along = -(origins * dirs).sum(axis=1) - np.sqrt(np.maximum(0.0, 1.0 - rho**2))
    normals = origins + along[:, None] * dirs
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    suns = rng.normal(size=(count, 3))
    suns /= np.linalg.norm(suns, axis=1)[:, None]
    return origins, dirs, normals, suns


def direct(tau: float, g: float, origins: np.ndarray, dirs: np.ndarray, suns: np.ndarray,
           grid: dict) -> np.ndarray:
    """The solver's total radiance along each ray, each with its own sun (rays rotated to one sun)."""
    sun = np.array([0.0, 0.0, 1.0])
    # Every ray rotated so that its sun is +z: one solve for all.
    rot_o, rot_d = np.empty_like(origins), np.empty_like(dirs)
    for i, s in enumerate(suns):
        e1 = np.cross(s, [1.0, 0.0, 0.0] if abs(s[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(s, e1)
        m = np.array([e1, e2, s])
        rot_o[i], rot_d[i] = m @ origins[i], m @ dirs[i]
    return core.particle_sphere_radiance(tau, g, sun, rot_o, rot_d, grid, 128).sum(axis=1)


def stats(mine: np.ndarray, exact: np.ndarray) -> tuple[float, float, float]:
    keep = exact > 1e-3 * exact.max()
    rel = np.abs(mine[keep] - exact[keep]) / exact[keep]
    return float(np.median(rel)), float(np.percentile(rel, 99)), float(rel.max())


def lookup(table: object, tau: float, normals: np.ndarray, dirs: np.ndarray, suns: np.ndarray) -> np.ndarray:
    out = np.empty(len(dirs))
    for i in range(len(dirs)):  # one sun per ray
        out[i] = table.lookup(np.array([tau]), normals[i:i + 1], dirs[i:i + 1], suns[i]).sum()  # type: ignore
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--g", type=float, default=0.85)
    ap.add_argument("--rays", type=int, default=400)
    ap.add_argument("--taus", type=float, nargs="+", default=[0.5, 5.0, 30.0, 50.0])
    parts = ["angles", "taus", "build"]
    ap.add_argument("--parts", nargs="+", default=parts, choices=parts)
    ap.add_argument("--slices", type=int, nargs="+", default=[12], help="numbers of optical radii (part 2)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    grid = {"orders": 18, "beyond": True}
    origins, dirs, normals, suns = random_rays(args.rays, seed=1)
    lines = [f"Particle lighting table against the solver (g = {args.g}, {args.rays} random rays and suns, "
             "relative error of the total radiance over rays above 1e-3 of the largest)"]
    if "angles" in args.parts:
        lines += ["", "1. the angles (tables at the tested optical radius: only the angles interpolate; "
                  "entry angles uniform or dense across the terminator)",
                  f"{'tau':>6} {'entry x zenith x azimuth':>25} {'entry':>8} {'median':>9} {'p99':>9} "
                  f"{'max':>9} {'build s':>8}"]
        shapes = [((32, 16, 32), False), ((32, 16, 32), True), ((64, 16, 32), False), ((64, 16, 32), True),
                  ((64, 32, 32), True)]
        for tau in args.taus:
            exact = direct(tau, args.g, origins, dirs, suns, grid)
            for shape, dense in shapes:
                t0 = time.perf_counter()
                keys = {"entry": shape[0], "view_zenith": shape[1], "view_azimuth": shape[2], "taus": 2,
                        "tau_min": tau, "tau_max": tau * 1.5, "dense_terminator": dense, "grid": grid}
                table = core.ParticleTable(args.g, keys)
                build = time.perf_counter() - t0
                med, p99, mx = stats(lookup(table, tau, normals, dirs, suns), exact)
                layout = "dense" if dense else "uniform"
                lines.append(f"{tau:6.1f} {'x'.join(map(str, shape)):>25} {layout:>8} "
                             f"{med:9.2e} {p99:9.2e} {mx:9.2e} {build:8.1f}")
                print(lines[-1], file=sys.stderr)
    if "taus" in args.parts:
        lines += ["", "2. the optical radius (tables over [0.1, 50], looked up halfway between nodes, "
                  "in log)",
                  f"{'radii':>6} {'median':>9} {'p99':>9} {'max':>9} {'build s':>8} {'MiB':>6} "
                  f"{'worst p99 at tau':>17}"]
        for count in args.slices:
            t0 = time.perf_counter()
            table = core.ParticleTable(args.g, {"taus": count, "grid": grid})
            build = time.perf_counter() - t0
            nodes = 0.1 * (50.0 / 0.1) ** (np.arange(count) / (count - 1))
            mids = np.sqrt(nodes[:-1] * nodes[1:])[:: max(1, (count - 1) // 4)]
            errs, worst = [], (0.0, 0.0)
            for tau in mids:
                exact = direct(float(tau), args.g, origins, dirs, suns, grid)
                keep = exact > 1e-3 * exact.max()
                looked_up = lookup(table, float(tau), normals, dirs, suns)
                errs.append(np.abs(looked_up - exact)[keep] / exact[keep])
                worst = max(worst, (float(np.percentile(errs[-1], 99)), float(tau)))
            rel = np.concatenate(errs)
            lines.append(f"{count:6d} {np.median(rel):9.2e} {np.percentile(rel, 99):9.2e} {rel.max():9.2e} "
                         f"{build:8.1f} {table.bytes / 2**20:6.2f} {worst[0]:8.2e} at {worst[1]:5.2f}")
            print(lines[-1], file=sys.stderr)
    if "build" in args.parts:
        lines += ["", f"3. the renderer's tables at g = {args.g} (every order)",
                  f"{'quality':>8} {'build s':>8} {'MiB':>6}"]
        for quality in ["full", "preview"]:
            table = core.ParticleTable.for_quality(args.g, quality)
            lines.append(f"{quality:>8} {table.build_seconds:8.1f} {table.bytes / 2**20:6.2f}")
            print(lines[-1], file=sys.stderr)
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
