"""Time against error for every effect: each quality preset and the effect's brute force, on
both backends, in one run (issue 24; docs/quality_presets.md).

    .venv/bin/python benchmarks/bench_quality.py [--sizes 640x360 1920x1080] [--backends gl cpu]
        [--frames 3] [--only lamps day ...] [--out docs/bench_quality.txt]
        [--plot docs/images/bench_quality.png] [--json docs/images/bench_quality.json]

One scene per effect (CASES; the lamp streets of 16 and 64 lamps and 64 headlights, the spots,
the three daytime weathers, the two rainbows, the light shafts, both kinds of cloud, the falling
rain). For each scene and film size:

- the reference image: the CPU backend at ``quality.preset: "reference"`` (every knob at its most
  accurate setting), rendered once;
- per backend and method (the presets ``fast``, ``default`` and ``reference``, and the effect's
  brute force where it has one: ray marching of the airlight, of the atmosphere, of the shafts or
  of the clouds, every particle tested by every pixel): the median time of ``--frames`` frames
  (``--brute-frames`` for the brute force; fewer, at least one, where ``--budget`` seconds would
  not hold them) after a first frame that pays the set-up (shader compilation, tables), and the
  frame's error against the reference image.

Error: per pixel, the largest channel of |x - ref| / (ref + floor), floor = 1e-3 x the reference
image's mean radiance (so that pixels a thousand times darker than the image's average do not
count); the table gives its 99th percentile and its maximum over pixels. The CPU reference row is
the reference itself (0); the GL reference row is the two backends' disagreement. The reference
preset's own error against the physics is each effect's stated one (its accuracy tests and
benchmarks), not measured here.

Times on a shared 2-core machine are noisy: compare ratios within one run ("x default").
"""

from __future__ import annotations

import argparse
import copy
import json
import statistics
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

import airlight

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from effects.lamp_airlight.bench.bench_airlight import street_scene  # noqa: E402
from tools.fuzz.compare import error_against_reference  # noqa: E402

PRESETS = ("fast", "default", "reference")


def _street(lights: int, light_type: str, surface_albedo: float) -> dict[str, Any]:
    """bench_airlight's street."""
    return street_scene(lights, 640, 360, surface_albedo, light_type)


def _preset(name: str) -> dict[str, Any]:
    return json.loads((ROOT / "scenes" / f"{name}.json").read_text())


AIRLIGHT_MARCH = {"airlight": "march", "march_steps": 256}

# (short name, what it shows, scene, the brute force's quality keys or None)
CASES: list[tuple[str, str, Any, dict[str, Any] | None]] = [
    ("lamps16", "16 lamps, 26 lit surfaces (foggy_street)", lambda: _preset("foggy_street"), AIRLIGHT_MARCH),
    (
        "lamps64",
        "64 lamps, 25 grey surfaces (bench_airlight's street)",
        lambda: _street(64, "point", 0.3),
        AIRLIGHT_MARCH,
    ),
    (
        "headlights64",
        "32 cars' headlights, black surfaces (bench_airlight's street: the airlight alone)",
        lambda: _street(64, "headlights", 0.0),
        AIRLIGHT_MARCH,
    ),
    (
        "spots",
        "spots crossing (spotlights_crossing_002)",
        lambda: _preset("spotlights_crossing_002"),
        AIRLIGHT_MARCH,
    ),
    ("day_clear", "clear day over a town (day_clear)", lambda: _preset("day_clear"), AIRLIGHT_MARCH),
    (
        "day_heavy_rain",
        "heavy rain by day (day_heavy_rain)",
        lambda: _preset("day_heavy_rain"),
        AIRLIGHT_MARCH,
    ),
    (
        "day_light_rain",
        "light rain by day (day_light_rain)",
        lambda: _preset("day_light_rain"),
        AIRLIGHT_MARCH,
    ),
    (
        "rainbow_heavy",
        "rainbow after heavy rain",
        lambda: _preset("rainbow_after_heavy_rain"),
        AIRLIGHT_MARCH,
    ),
    (
        "rainbow_light",
        "rainbow after light rain",
        lambda: _preset("rainbow_after_light_rain"),
        AIRLIGHT_MARCH,
    ),
    (
        "shafts",
        "light shafts, low sun (shafts_low_sun)",
        lambda: _preset("shafts_low_sun"),
        {"shafts": "march", "march_steps": 256},
    ),
    (
        "noise_clouds",
        "noise clouds over a town (clouds_cumulus_town)",
        lambda: _preset("clouds_cumulus_town"),
        {"clouds": "march", "march_steps": 256},
    ),
    (
        "particle_clouds",
        "particle clouds over a town (particle_clouds_town)",
        lambda: _preset("particle_clouds_town"),
        {"particle_compositing": "all"},
    ),
    (
        "falling_rain",
        "falling rain at night, 25 mm/h (falling_rain_night_heavy)",
        lambda: _preset("falling_rain_night_heavy"),
        None,
    ),
]


@dataclass
class Row:
    case: str
    size: str
    backend: str
    method: str
    frame_s: float
    first_s: float
    p99_error: float
    max_error: float


def with_quality(scene: dict[str, Any], size: tuple[int, int], keys: dict[str, Any]) -> dict[str, Any]:
    """The scene at that film size with those quality keys over its own."""
    out = copy.deepcopy(scene)
    out["film"] = {"width": size[0], "height": size[1]}
    out["quality"] = {**out.get("quality", {}), **keys}
    return out


def time_frames(
    renderer: airlight.Renderer, scene: dict[str, Any], frames: int, budget_s: float
) -> tuple[float, float, np.ndarray]:
    """(first frame's seconds, median of the later frames', the last image): ``frames`` timed
    frames, fewer (at least one) where the first took longer than ``budget_s`` over them. The
    renderer is shared by a case's methods, so a shader variant they share compiles once."""
    t0 = time.perf_counter()
    image = renderer.render(scene)
    first = time.perf_counter() - t0
    times = []
    for _ in range(max(1, min(frames, int(budget_s / first)))):
        t0 = time.perf_counter()
        image = renderer.render(scene)
        times.append(time.perf_counter() - t0)
    return first, statistics.median(times), np.asarray(image)


def parse_size(text: str) -> tuple[int, int]:
    w, _, h = text.partition("x")
    return int(w), int(h)


def run(args: argparse.Namespace) -> list[Row]:
    from tqdm import tqdm

    cases = [c for c in CASES if not args.only or any(c[0].startswith(o) for o in args.only)]
    cases = [c for c in cases if not any(c[0].startswith(o) for o in args.skip)]
    sizes = [parse_size(s) for s in args.sizes]
    backends = [b for b in args.backends if b in airlight.available_backends()]
    jobs = sum(1 + len(backends) * (len(PRESETS) + (brute is not None)) for *_, brute in cases) * len(sizes)
    rows: list[Row] = []
    with tqdm(total=jobs, desc="frames", unit="run") as bar:
        for size in sizes:
            label = f"{size[0]}x{size[1]}"
            for name, _, make, brute in cases:
                scene = make()
                bar.set_postfix_str(f"{name} {label} reference")
                reference = np.asarray(
                    airlight.render(with_quality(scene, size, {"preset": "reference"}), backend="cpu")
                )
                bar.update()
                methods = [(p, {"preset": p}) for p in PRESETS]
                if brute is not None:
                    methods.append(("brute force", {"preset": "reference", **brute}))
                for backend in backends:
                    renderer = airlight.Renderer(backend)
                    for method, keys in methods:
                        bar.set_postfix_str(f"{name} {label} {backend} {method}")
                        frames = args.brute_frames if method == "brute force" else args.frames
                        first, frame, image = time_frames(
                            renderer, with_quality(scene, size, keys), frames, args.budget
                        )
                        e = error_against_reference(image, reference)
                        rows.append(
                            Row(
                                name,
                                label,
                                backend,
                                method,
                                frame,
                                first,
                                float(np.percentile(e, 99)),
                                float(e.max()),
                            )
                        )
                        bar.update()
                    renderer.close()
    if "gl" in args.backends and "gl" not in backends:
        print(f"gl: skipped ({airlight.gl_unavailable_reason()})")
    return rows


def table(rows: list[Row]) -> str:
    """The rows as a Markdown table, with each row's time over its default preset's."""
    default = {(r.case, r.size, r.backend): r.frame_s for r in rows if r.method == "default"}
    lines = [
        "| case | size | backend | method | frame ms | x default | p99 error | max error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = r.frame_s / default[(r.case, r.size, r.backend)]
        lines.append(
            f"| {r.case} | {r.size} | {r.backend} | {r.method} | {1e3 * r.frame_s:.1f} | {ratio:.2f} "
            f"| {r.p99_error:.2e} | {r.max_error:.2e} |"
        )
    return "\n".join(lines)


def summary(rows: list[Row]) -> str:
    """One line per case, size and backend: the default preset's frame, the others' times over it
    and every method's 99th-percentile error."""
    by = {(r.case, r.size, r.backend, r.method): r for r in rows}
    keys = list(dict.fromkeys((r.case, r.size, r.backend) for r in rows))
    methods = [*PRESETS, "brute force"]
    lines = [
        "| case | size | backend | default ms | time x default: fast / reference / brute | "
        "p99 error: fast / default / reference / brute |",
        "|---|---|---|---|---|---|",
    ]
    for case, size, backend in keys:
        got = {m: by.get((case, size, backend, m)) for m in methods}
        base = got["default"]
        if base is None:
            continue
        ratios = " / ".join(
            f"{r.frame_s / base.frame_s:.2f}" if r else "-" for m, r in got.items() if m != "default"
        )
        errors = " / ".join(f"{r.p99_error:.1e}" if r else "-" for r in got.values())
        lines.append(f"| {case} | {size} | {backend} | {1e3 * base.frame_s:.0f} | {ratios} | {errors} |")
    return "\n".join(lines)


def plot(rows: list[Row], path: Path) -> None:
    """Frame time against the 99th-percentile error, one panel per case and size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = list(dict.fromkeys((r.case, r.size) for r in rows))
    cols = 4
    rows_n = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(4 * cols, 3.2 * rows_n), squeeze=False)
    markers = {"fast": "v", "default": "o", "reference": "^", "brute force": "s"}
    colours = {"gl": "tab:orange", "cpu": "tab:blue"}
    floor = 1e-7  # where an error of 0 (the CPU reference itself) is drawn
    for ax, (case, size) in zip(axes.flat, panels):
        for r in rows:
            if (r.case, r.size) != (case, size):
                continue
            ax.loglog(
                1e3 * r.frame_s,
                max(r.p99_error, floor),
                markers[r.method],
                color=colours[r.backend],
                label=f"{r.backend} {r.method}",
            )
        ax.set_title(f"{case} {size}", fontsize=9)
        ax.set_xlabel("frame ms")
        ax.set_ylabel("p99 error")
        ax.axhline(5e-3, color="grey", lw=0.5, ls="--")
        ax.grid(True, which="both", lw=0.2)
    for ax in list(axes.flat)[len(panels) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower right", fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", nargs="+", default=["640x360"], help="film sizes WxH (default 640x360)")
    parser.add_argument("--backends", nargs="+", choices=("gl", "cpu"), default=["gl", "cpu"])
    parser.add_argument("--frames", type=int, default=3, help="timed frames after the first (median)")
    parser.add_argument("--brute-frames", type=int, default=1, help="timed frames of the brute force")
    parser.add_argument(
        "--budget",
        type=float,
        default=20.0,
        help="seconds of timed frames per method: slower methods time fewer (at least 1)",
    )
    parser.add_argument("--skip", nargs="+", default=[], help="leave out cases whose names start with these")
    parser.add_argument("--only", nargs="+", default=[], help="cases whose names start with these")
    parser.add_argument("--out", type=Path, help="also write the report here")
    parser.add_argument("--plot", type=Path, help="write the time-against-error chart here (PNG)")
    parser.add_argument("--json", type=Path, help="write the raw rows here")
    parser.add_argument(
        "--from-json",
        type=Path,
        nargs="+",
        default=[],
        help="render nothing: report the rows of these --json files (runs of other cases) together",
    )
    args = parser.parse_args()
    if args.frames < 1 or args.brute_frames < 1:
        parser.error("--frames and --brute-frames must be at least 1")
    if args.from_json:
        rows = [Row(**r) for path in args.from_json for r in json.loads(path.read_text())]
    else:
        rows = run(args)
    info = airlight.backend_info()
    if args.from_json:
        how = "the rows of " + ", ".join(f"`{p}`" for p in args.from_json) + " (their runs' settings)"
    else:
        how = (
            f"frame: median of {args.frames} frames after the first ({args.brute_frames} for the brute "
            f"force; fewer where they would take over {args.budget:g} s)"
        )
    header = [
        f"# Time against error per effect (`benchmarks/bench_quality.py {' '.join(_argv_shown(args))}`)",
        "",
        f"Backends: {info}. Error: per pixel, the largest channel of |x - ref| / (ref + 1e-3 x mean(ref)),",
        f"ref the CPU backend at the reference preset; {how}.",
        "",
        "Cases: " + "; ".join(f"{n}: {what}" for n, what, *_ in CASES if any(r.case == n for r in rows)),
        "",
    ]
    report = "\n".join(header) + summary(rows) + "\n\nEvery row:\n\n" + table(rows) + "\n"
    print(report)
    if args.out:
        args.out.write_text(report)
    if args.plot:
        plot(rows, args.plot)
    if args.json:
        args.json.write_text(json.dumps([asdict(r) for r in rows], indent=1))


def _argv_shown(args: argparse.Namespace) -> list[str]:
    shown = [
        "--sizes",
        *args.sizes,
        "--backends",
        *args.backends,
        "--frames",
        str(args.frames),
        "--brute-frames",
        str(args.brute_frames),
    ]
    if args.from_json:
        return ["--from-json", *map(str, args.from_json)]
    shown += ["--budget", str(args.budget)]
    shown += ["--only", *args.only] if args.only else []
    return shown + (["--skip", *args.skip] if args.skip else [])


if __name__ == "__main__":
    main()
