"""Particle clouds: frame time against the number of particles, both backends, with the modelling's
parts (modelling, the lattice's shadows, sorting, binning into tiles), the table lookups' share,
the brute force (every pixel tests every particle) and the noise clouds on the same view; what a
scene without particle clouds pays; and the source document's comparison of the two methods (its
figures 7 to 9: the camera below, inside and above the layer), as a figure with times.

    .venv/bin/python effects/particle_clouds/bench/bench_particles.py [--width 640 --height 360]
        [--backends cpu gl] [--frames 1] [--max-brute 6000] [--max-gl 50000]
        [--out effects/particle_clouds/docs/bench_particles.txt]
        [--plot effects/particle_clouds/docs/bench_particles.png]
        [--figure docs/images/cloud_methods.png]

The particle count is set by the rings' cells (cell_size, ring_cells, rings) over the town preset's
cloud field (particle_clouds_town), from about 1e3 to 1e6 particles in view. A frame's time is
the renderer's (the modelling, run on the CPU for both backends, included); the modelling's parts
come from airlight._core.particle_frame. "Sun off" renders the same frame with no sunlight: no
table lookups, so the difference is their cost. Absolute times on a shared 2-core machine are noisy;
compare ratios. GL is Mesa's llvmpipe (software): its loop limiter cuts pixels whose lists run past
65535 iterations, which the renderer recomputes on the CPU.
"""

from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[3]
# (cell_size m, ring_cells, rings): from about 350 to 1.6e6 particles modelled (200 to 3.5e5 in view).
FIELDS = [(400, 8, 3), (200, 16, 4), (100, 24, 4), (60, 32, 4), (40, 48, 4), (25, 64, 4), (15, 96, 4)]


def town(width: int, height: int) -> dict[str, Any]:
    scene = json.loads((ROOT / "scenes" / "particle_clouds_town.json").read_text())
    scene["film"] = {"width": width, "height": height}
    return scene


def frame_time(renderer: airlight.Renderer, scene: dict[str, Any], frames: int) -> float:
    renderer.render(scene)  # warm: shader compiled, table loaded
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        renderer.render(scene)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def count_sweep(args: argparse.Namespace, renderers: dict[str, airlight.Renderer],
                lines: list[str]) -> list[dict]:
    lines.append(f"## Frame time against particles in view ({args.width}x{args.height}, town camera)\n")
    head = ("| cells (size m, per ring, rings) | particles (in view) | tile entries | memory MiB | model s "
            "| shadows s | sort s | bin s |")
    for b in renderers:
        head += f" {b} frame s | {b} sun off s | {b} brute force s |"
    lines.append(head)
    lines.append("|" + "---|" * (head.count("|") - 1))
    rows = []
    for cell, ring_cells, rings in FIELDS:
        scene = town(args.width, args.height)
        scene["particle_clouds"].update(cell_size=cell, ring_cells=ring_cells, rings=rings)
        info = airlight._core.particle_frame(scene)
        memory = (info["drawn"] * 32 + (info["tile_entries"] + 1) * 4) / 2**20
        counts = {k: v for k, v in info.items() if not hasattr(v, "shape") and k != "casters"}
        row: dict[str, Any] = {"field": (cell, ring_cells, rings), **counts}
        text = (f"| {cell}, {ring_cells}, {rings} | {info['particles']} ({info['drawn']}) "
                f"| {info['tile_entries']} "
                f"| {memory:.1f} | {info['model_seconds']:.3f} | {info['shadow_seconds']:.3f} "
                f"| {info['sort_seconds']:.4f} | {info['bin_seconds']:.4f} |")
        for b, r in renderers.items():
            t = frame_time(r, scene, args.frames)
            dark = copy.deepcopy(scene)
            dark["sun"]["irradiance"] = 0
            t_dark = frame_time(r, dark, args.frames)
            t_brute = float("nan")
            if b == "gl" and info["drawn"] > args.max_gl:
                row[b] = (float("nan"),) * 3
                text += " - | - | - |"
                continue
            if info["drawn"] <= args.max_brute:
                brute = copy.deepcopy(scene)
                brute.setdefault("quality", {})["particle_compositing"] = "all"
                t_brute = frame_time(r, brute, args.frames)
            row[b] = (t, t_dark, t_brute)
            text += f" {t:.2f} | {t_dark:.2f} | {'-' if np.isnan(t_brute) else f'{t_brute:.2f}'} |"
        print(text, flush=True)
        lines.append(text)
        rows.append(row)
    lines.append("")
    return rows


def noise_and_nothing(args: argparse.Namespace, renderers: dict[str, airlight.Renderer],
                      lines: list[str]) -> None:
    lines.append("## The same view: noise clouds, and no clouds\n")
    lines.append("| scene | " + " | ".join(f"{b} frame s" for b in renderers) + " |")
    lines.append("|---|" + "---|" * len(renderers))
    scene = town(args.width, args.height)
    noise = json.loads((ROOT / "scenes" / "clouds_cumulus_town.json").read_text())
    noise["film"] = scene["film"]
    none = copy.deepcopy(scene)
    none["particle_clouds"] = None
    empty = copy.deepcopy(scene)
    empty["particle_clouds"]["coverage"] = 0
    for name, s in [("particle clouds (default keys)", scene), ("noise clouds (clouds_cumulus_town)", noise),
                    ("particle_clouds: null", none), ("particle_clouds coverage 0", empty)]:
        times = [f"{frame_time(r, s, args.frames):.3f}" for r in renderers.values()]
        lines.append(f"| {name} | " + " | ".join(times) + " |")
    probe = ("import json, sys, airlight; airlight.render(json.loads(sys.argv[1]), backend='cpu', width=64, "
             "height=36); print(json.dumps(sorted(airlight.table_stats())))")
    for name, s in [("particle_clouds: null", none), ("coverage 0", empty), ("particle clouds", scene)]:
        out = subprocess.run([sys.executable, "-c", probe, json.dumps(s)], capture_output=True, text=True,
                             check=True)
        built = [t for t in json.loads(out.stdout) if t.startswith("particle")]
        lines.append(f"\nTables built by a fresh process rendering {name}: {built or 'none'}")
    lines.append("")


VIEWS = {"below": "particle_clouds_town", "inside": "particle_clouds_flythrough",
         "above": "particle_clouds_sunset_above"}
NOISE = {"below": "clouds_cumulus_town", "inside": "clouds_flythrough", "above": "clouds_sunset_above"}


def methods_figure(args: argparse.Namespace, lines: list[str]) -> None:
    """The source's figures 7-9: each view by both methods (particles left, noise right), with times."""
    from PIL import Image, ImageDraw

    lines.append(f"## The two methods on the same fields (the source's figures 7-9; "
                 f"{args.width}x{args.height}, {args.figure_backend})\n")
    lines.append("| view | particle clouds s | noise clouds s |")
    lines.append("|---|---|---|")
    rows = []
    with airlight.Renderer(args.figure_backend) as r:
        for view in VIEWS:
            tiles = []
            times = []
            for preset in (VIEWS[view], NOISE[view]):
                scene = airlight.preset(preset)
                scene["film"] = {"width": args.width, "height": args.height}
                r.render(scene)
                start = time.perf_counter()
                image = r.render(scene)
                times.append(time.perf_counter() - start)
                tile = Image.fromarray(airlight.display_scene(image, scene))
                ImageDraw.Draw(tile).text((6, 4), f"{preset}  {times[-1]:.1f} s", fill=(255, 255, 255))
                tiles.append(np.asarray(tile))
                tiles.append(np.full((args.height, 6, 3), 255, np.uint8))
            rows.append(np.concatenate(tiles[:-1], axis=1))
            rows.append(np.full((6, rows[-1].shape[1], 3), 255, np.uint8))
            lines.append(f"| {view} | {times[0]:.2f} | {times[1]:.2f} |")
    Path(args.figure).parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.concatenate(rows[:-1], axis=0)).save(args.figure)
    lines.append(f"\nFigure: {args.figure}\n")


def plot(rows: list[dict], backends: list[str], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    counts = [r["drawn"] for r in rows]
    for b, style in zip(backends, ["o-", "s-"]):
        ax.loglog(counts, [r[b][0] for r in rows], style, label=f"{b}: frame")  # NaN (not run): gaps
        ax.loglog(counts, [r[b][1] for r in rows], style.replace("-", "--"),
                  label=f"{b}: sun off (no lookups)")
        brute = [(c, r[b][2]) for c, r in zip(counts, rows) if not np.isnan(r[b][2])]
        if brute:
            ax.loglog(*zip(*brute), style.replace("-", ":"), label=f"{b}: brute force")
    model = [r["model_seconds"] + r["shadow_seconds"] + r["sort_seconds"] + r["bin_seconds"] for r in rows]
    ax.loglog(counts, model, "k^-", label="modelling (CPU)")
    ax.set_xlabel("particles in view")
    ax.set_ylabel("seconds per frame")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--backends", nargs="+", default=["cpu", "gl"])
    ap.add_argument("--frames", type=int, default=1)
    ap.add_argument("--max-brute", type=int, default=6000,
                    help="the most particles in view for the brute force")
    ap.add_argument("--max-gl", type=int, default=50000,
                    help="the most particles in view on GL (llvmpipe: long lists go to the CPU)")
    parts = ["count", "noise", "figure"]
    ap.add_argument("--parts", nargs="+", default=parts, choices=parts)
    ap.add_argument("--figure-backend", default="cpu")
    ap.add_argument("--out")
    ap.add_argument("--plot")
    ap.add_argument("--figure", default=str(ROOT / "docs" / "images" / "cloud_methods.png"))
    args = ap.parse_args()
    backends = [b for b in args.backends if b in airlight.available_backends()]
    renderers = {b: airlight.Renderer(b) for b in backends}
    lines = [f"# Particle clouds benchmark\n\n`{' '.join(sys.argv)}`\n"]
    if "count" in args.parts:
        rows = count_sweep(args, renderers, lines)
        if args.plot:
            plot(rows, backends, args.plot)
            lines.append(f"Plot: {args.plot}\n")
    if "noise" in args.parts:
        noise_and_nothing(args, renderers, lines)
    if "figure" in args.parts:
        methods_figure(args, lines)
    text = "\n".join(lines)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
