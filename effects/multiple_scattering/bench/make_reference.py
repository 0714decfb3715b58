"""Regenerates the stored Mitsuba reference of multiple scattering (issue 18) and prints how far
airlight's current single scattering is from it.

    .venv/bin/python effects/multiple_scattering/bench/make_reference.py            # everything
    .venv/bin/python effects/multiple_scattering/bench/make_reference.py --kind day --cases 'day_rain*' \\
        --max-seconds 600 --target 0.003                                             # longer, some cases
    .venv/bin/python effects/multiple_scattering/bench/make_reference.py --table     # table of stored data

Each case is an airlight scene (effects/multiple_scattering/tests/ms_cases.py); each view is
rendered by Mitsuba's volpath with unlimited depth (mitsuba_reference.py), per RGB channel and,
for the daytime, the sky's and the sun's light separately (the transport is linear in the
sources; the components are stored and summed, their errors added in quadrature). Samples are
added in chunks until every view's standard error is below --target of its value or a render
has run --max-seconds; the stored files record the samples, seeds and times actually used.
Cases run replace those of the same name in effects/multiple_scattering/tests/data/*.json.
Needs the "reference" extra (pip install ".[reference]"); uses --threads Dr.Jit threads (1).
"""

from __future__ import annotations

import argparse
import datetime
import fnmatch
import json
import math
import re
import sys
import zlib
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
for sub in ("effects/multiple_scattering/tests", "effects/daytime/tests", "tests/python"):
    if str(ROOT / sub) not in sys.path:
        sys.path.insert(0, str(ROOT / sub))

import daytime_scenes as ds  # noqa: E402
import mitsuba_reference as mr  # noqa: E402
import ms_cases  # noqa: E402

import airlight  # noqa: E402

try:
    from tqdm import tqdm
except ImportError:  # plain prints instead
    tqdm = None


def _seed(base: int, *parts: Any) -> int:
    return (base + zlib.crc32("/".join(str(p) for p in parts).encode())) % (1 << 31)


class Progress:
    """tqdm over the renders when installed, else one printed line per render."""

    def __init__(self, total: int) -> None:
        self.bar = tqdm(total=total, unit="render") if tqdm is not None else None
        self.total, self.count = total, 0

    def step(self, label: str, est: mr.Estimate, worst: float) -> None:
        self.count += 1
        msg = f"{label}: {est.spp} spp, {est.seconds:.1f} s, worst rel. stderr {worst:.4f}"
        if self.bar is not None:
            self.bar.set_postfix_str(msg)
            self.bar.update(1)
        else:
            print(f"[{self.count}/{self.total}] {msg}", flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _worst(est: mr.Estimate, floor_fraction: float = 0.0) -> float:
    scale = np.maximum(est.mean, floor_fraction * float(np.max(est.mean)))
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.max(np.where(scale > 0, est.stderr / scale, np.inf)))


def _single_scattering(scene: dict) -> dict:
    """The scene with airlight's multiple scattering off: what the harness and ``airlight_single`` compare."""
    return dict(scene, quality={**scene.get("quality", {}), "multiple_scattering": False})


def _airlight_pixel(scene: dict) -> list[float]:
    return [float(x) for x in airlight.render(_single_scattering(scene), backend="cpu")[0, 0]]


# ----------------------------------------------------------------------------------------------
# Daytime


def _stored_case(args: argparse.Namespace, name: str) -> dict[str, Any] | None:
    path = args.out / "day_reference.json"
    if not path.exists():
        return None
    with open(path) as f:
        return json.load(f)["cases"].get(name)


def day_case(weather: str, sun: str, args: argparse.Namespace, progress: Progress) -> dict[str, Any]:
    name = ms_cases.day_case_name(weather, sun)
    scene = ms_cases.day_scene(weather, sun)
    dirs = np.array([ms_cases.direction(az, el) for az, el in ms_cases.DAY_VIEWS])
    origin = scene["camera"]["position"]
    components = ["sky"] + (["sun"] if "sun" in scene else [])
    out_comp: dict[str, Any] = {}
    means: dict[str, np.ndarray] = {}
    errs: dict[str, np.ndarray] = {}
    disc: dict[str, Any] = {"layers": [], "texels": [], "column_error": []}
    atm = ds.reference_atmosphere(scene)
    previous = _stored_case(args, name) if args.parts != "all" else None
    for comp in components:
        if previous is not None and comp not in args.parts.split(","):
            # keep the stored part
            means[comp] = np.array([v[f"radiance_{comp}"] for v in previous["views"]])
            errs[comp] = np.array([v[f"stderr_{comp}"] for v in previous["views"]])
            out_comp[comp] = previous["components"][comp]
            if comp == "sky":
                disc = previous["discretisation"]
            continue
        part = json.loads(json.dumps(scene))
        if comp == "sky":
            # the sun stays where it is (it places the CIE sky's indicatrix) but gives no light
            if "sun" in part:
                part["sun"]["irradiance"] = [0.0, 0.0, 0.0]
        else:
            part["sky"]["zenith_radiance"] = [0.0, 0.0, 0.0]
        m = np.zeros((len(dirs), 3))
        e = np.zeros((len(dirs), 3))
        info: dict[str, list] = {"spp": [], "seconds": [], "seed": []}
        for c in range(3):
            built = mr.build_day_scene(part, c)
            if comp == "sky":
                disc["layers"].append(len(built.layers))
                disc["texels"].append(int(sum(la.sigma_t.size for la in built.layers)))
                disc["column_error"].append(mr.discretisation_column_error(atm, built.layers, c))
            seed = _seed(args.seed, name, comp, c)
            acc = mr.Accumulator(built.scene, built.camera_medium, origin, dirs, -1, seed, args.rr_depth)
            est = acc.run(args.target, args.max_seconds, args.min_spp, args.max_spp, args.chunk)
            m[:, c], e[:, c] = est.mean, est.stderr
            info["spp"].append(est.spp)
            info["seconds"].append(round(est.seconds, 2))
            info["seed"].append(seed)
            progress.step(f"{name} {comp} {'RGB'[c]}", est, _worst(est))
        means[comp], errs[comp] = m, e
        out_comp[comp] = info
    total = sum(means.values())
    total_err = np.sqrt(sum(np.square(v) for v in errs.values()))
    views = []
    for i, (az, el) in enumerate(ms_cases.DAY_VIEWS):
        cam = ms_cases.camera(origin, dirs[i])
        view_scene = dict(scene, camera=cam)
        v: dict[str, Any] = {"azimuth_from_sun": az, "elevation": el, "direction": dirs[i].tolist(),
                             "camera": cam, "radiance": total[i].tolist(), "stderr": total_err[i].tolist()}
        for comp in components:
            v[f"radiance_{comp}"] = means[comp][i].tolist()
            v[f"stderr_{comp}"] = errs[comp][i].tolist()
        v["airlight_single"] = _airlight_pixel(view_scene)
        views.append(v)
    return {"scene": scene, "weather": weather, "sun": sun, "components": out_comp,
            "discretisation": disc, "views": views}


# ----------------------------------------------------------------------------------------------
# Night


def night_case(tau: float, g: float, args: argparse.Namespace, progress: Progress) -> dict[str, Any]:
    name = ms_cases.night_case_name(tau, g)
    scene = ms_cases.night_scene(tau, g)
    sigma_t = tau / ms_cases.LAMP_DISTANCE
    radius = mr.fog_radius(sigma_t, ms_cases.NIGHT_ALBEDO, g, ms_cases.LAMP_DISTANCE)
    mscene, medium = mr.build_lamp_scene(sigma_t, ms_cases.NIGHT_ALBEDO, g, ms_cases.LAMP_INTENSITY,
                                         [0.0, 0.0, 0.0], radius)
    origin, dirs = mr.lamp_directions(ms_cases.LAMP_DISTANCE, ms_cases.GLOW_ANGLES)
    seed = _seed(args.seed, name)
    acc = mr.Accumulator(mscene, medium, origin, dirs, -1, seed, args.rr_depth)
    est = acc.run(args.target, args.max_seconds_night, args.min_spp, args.max_spp, args.chunk,
                  floor_fraction=1e-3)
    progress.step(name, est, _worst(est, 1e-3))
    views = []
    for i, a in enumerate(ms_cases.GLOW_ANGLES):
        cam = ms_cases.camera(origin, dirs[i])
        views.append({"angle_deg": a, "direction": dirs[i].tolist(), "camera": cam,
                      "radiance": float(est.mean[i]), "stderr": float(est.stderr[i]),
                      "airlight_single": _airlight_pixel(dict(scene, camera=cam))[1]})
    peak = float(est.mean[0])
    above = [v["angle_deg"] for v in views if v["radiance"] >= 1e-3 * peak]
    return {"scene": scene, "tau": tau, "g": g, "albedo": ms_cases.NIGHT_ALBEDO, "fog_radius_m": radius,
            "spp": est.spp, "seconds": round(est.seconds, 2), "seed": seed,
            "glow_above_1e-3_of_peak_to_deg": max(above) if above else None, "views": views}


# ----------------------------------------------------------------------------------------------
# Files and tables


def _header(args: argparse.Namespace, kind: str) -> dict[str, Any]:
    import mitsuba

    return {
        "description": f"Mitsuba 3 volpath reference of multiple scattering ({kind}), issue 18; "
                       "effects/multiple_scattering/docs/reference.md. Radiance in the scene's units "
                       "(W/(m^2 sr) per channel); stderr: one standard error of the mean.",
        "generator": "effects/multiple_scattering/bench/make_reference.py",
        "mitsuba": mitsuba.__version__, "variant": mr.MITSUBA_VARIANT,
        "settings": {"max_depth": -1, "rr_depth": args.rr_depth, "target_rel": args.target,
                     "chunk_spp": args.chunk,
                     "min_spp": args.min_spp, "max_seconds_per_render": args.max_seconds if kind == "day"
                     else args.max_seconds_night, "base_seed": args.seed, "threads": args.threads,
                     "half_width_m": mr.HALF_WIDTH, "envmap_height": mr.ENVMAP_HEIGHT,
                     "texel_scale_fraction": mr.TEXEL_SCALE_FRACTION, "thin_layer_depth": mr.THIN_LAYER_DEPTH,
                     "density_floor": mr.DENSITY_FLOOR},
    }


def dump(data: dict[str, Any]) -> str:
    """JSON with one key per line and every list of numbers on one line (small, diff-friendly)."""
    text = json.dumps(data, indent=1)
    return re.sub(r"\[\s*([-+0-9.eE]+(?:,\s*[-+0-9.eE]+)*)\s*\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text) + "\n"


def _merge(path: Path, header: dict[str, Any], cases: dict[str, Any]) -> dict[str, Any]:
    data: dict[str, Any] = {"cases": {}}
    if path.exists():
        with open(path) as f:
            data = json.load(f)
    for name, case in cases.items():
        case["settings"] = header["settings"]
        case["generated"] = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%MZ")
        data.setdefault("cases", {})[name] = case
    data.update({k: v for k, v in header.items() if k != "settings"})
    data["cases"] = dict(sorted(data["cases"].items()))
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        f.write(dump(data))
    return data


def day_table(data: dict[str, Any]) -> str:
    """Per case, green channel: Mitsuba's multiple scattering (MS) against airlight's single
    scattering (SS) at the zenith, 5 degrees up across the sun and the ground 30 degrees down."""
    lines = ["| case | spp (G, sky/sun) | worst rel. stderr | zenith MS | SS | MS/SS | 5 deg up MS | SS "
             "| MS/SS | ground MS | SS | MS/SS |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, case in data["cases"].items():
        views = case["views"]
        pick = {(v["azimuth_from_sun"], v["elevation"]): v for v in views}
        worst = max(max(e / m for e, m in zip(v["stderr"], v["radiance"]) if m > 0) for v in views)
        spp = "/".join(str(c["spp"][1]) for c in case["components"].values())
        row = [name, spp, f"{worst:.4f}"]
        for key in ((0, 90), (90, 5), (90, -30)):
            v = pick[key]
            ms, ss = v["radiance"][1], v["airlight_single"][1]
            row += [f"{ms:.4g}", f"{ss:.4g}", f"{ms / ss:.4g}" if ss > 0 else "inf"]
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def noise_table(data: dict[str, Any]) -> str:
    """Per daytime case: the relative standard error over its views and channels."""
    lines = ["| case | median rel. stderr | 90 % | max | column error (max) | layers | rr_depth |",
             "|---|---|---|---|---|---|---|"]
    for name, case in data["cases"].items():
        rel = np.array([[e / m for e, m in zip(v["stderr"], v["radiance"])] for v in case["views"]])
        disc = case["discretisation"]
        lines.append(f"| {name} | {np.median(rel):.4f} | {np.quantile(rel, 0.9):.4f} | {rel.max():.4f} | "
                     f"{max(disc['column_error']):.1e} | {max(disc['layers'])} | "
                     f"{case['settings']['rr_depth']} |")
    return "\n".join(lines)


def night_table(data: dict[str, Any]) -> str:
    lines = ["| case | spp | worst rel. stderr (above 1e-3 of peak) | glow >= 1e-3 peak to (deg) "
             "| MS/SS at 1 deg | 10 deg | 45 deg | 90 deg |", "|---|---|---|---|---|---|---|---|"]
    for name, case in data["cases"].items():
        views = case["views"]
        peak = views[0]["radiance"]
        worst = max((v["stderr"] / max(v["radiance"], 1e-3 * peak)) if peak > 0 else math.inf for v in views)
        ratio = {v["angle_deg"]: (v["radiance"] / v["airlight_single"] if v["airlight_single"] > 0
                                  else math.inf) for v in views}
        lines.append(f"| {name} | {case['spp']} | {worst:.4f} | {case['glow_above_1e-3_of_peak_to_deg']} | "
                     + " | ".join(f"{ratio[a]:.4g}" for a in (1.0, 10.0, 45.0, 90.0)) + " |")
    return "\n".join(lines)


def validate(args: argparse.Namespace) -> str:
    """The harness check of test_reference_harness.py as a table: Mitsuba at max_depth 2 (single
    scattering) against airlight's render, per scene and channel, over the 9 pixels of a column."""
    lines = ["| scene | channel | spp | rel. stderr (range) | max abs(MS2 - SS) / SS "
             "| max abs(MS2 - SS) / stderr | max deviation / allowed | depth 3: pixels failing |",
             "|---|---|---|---|---|---|---|---|"]
    for name, kwargs, channels, spp in ms_cases.HARNESS_SCENES:
        scene = ms_cases.harness_column_scene(kwargs)
        want = airlight.render(scene, backend="cpu")[:, 0].astype(float)
        dirs = ds.scene_directions(scene)[:, 0]
        est = mr.estimate_day(scene, dirs, spp, max_depth=2, seed=11, channels=channels)
        deeper = mr.estimate_day(scene, dirs, spp, max_depth=3, seed=12, channels=channels)
        for c in channels:
            m, e, w = est.mean[:, c], est.stderr[:, c], want[:, c]
            dev3 = ms_cases.harness_agreement(deeper.mean[:, c], deeper.stderr[:, c], w)
            fail3 = int(np.count_nonzero(dev3 > 1))
            lines.append(f"| {name} | {'RGB'[c]} | {spp} | {np.min(e / m):.4f}-{np.max(e / m):.4f} | "
                         f"{np.max(np.abs(m - w) / w):.4f} | {np.max(np.abs(m - w) / e):.2f} | "
                         f"{np.max(ms_cases.harness_agreement(m, e, w)):.2f} | {fail3} of 9 |")
    for tau, g in ms_cases.HARNESS_NIGHT:
        scene = ms_cases.night_scene(tau, g)
        want_l = []
        for a in ms_cases.HARNESS_NIGHT_ANGLES:
            cam = ms_cases.camera(scene["camera"]["position"], ms_cases.glow_direction(a))
            single = _single_scattering(dict(scene, camera=cam))
            want_l.append(float(airlight.render(single, backend="cpu")[0, 0, 1]))
        w = np.array(want_l)
        args_ = (tau / ms_cases.LAMP_DISTANCE, ms_cases.NIGHT_ALBEDO, g, ms_cases.LAMP_INTENSITY,
                 ms_cases.LAMP_DISTANCE, ms_cases.HARNESS_NIGHT_ANGLES, ms_cases.HARNESS_NIGHT_SPP)
        est = mr.estimate_lamp(*args_, max_depth=2, seed=13)
        deeper = mr.estimate_lamp(*args_, max_depth=3, seed=14)
        m, e = est.mean, est.stderr
        fail3 = int(np.count_nonzero(ms_cases.harness_agreement(deeper.mean, deeper.stderr, w) > 1))
        lines.append(f"| lamp tau {tau:g} g {g:g} (1, 5, 20, 90 deg) | grey | {ms_cases.HARNESS_NIGHT_SPP} | "
                     f"{np.min(e / m):.4f}-{np.max(e / m):.4f} | {np.max(np.abs(m - w) / w):.4f} | "
                     f"{np.max(np.abs(m - w) / e):.2f} | {np.max(ms_cases.harness_agreement(m, e, w)):.2f} | "
                     f"{fail3} of 4 |")
    return "\n".join(lines)


def refresh_airlight(path: Path) -> None:
    """Rebuilds every stored view's camera from its direction and re-renders airlight's value
    (``airlight_single``) without touching the Mitsuba values."""
    if not path.exists():
        return
    with open(path) as f:
        data = json.load(f)
    for case in data["cases"].values():
        origin = case["scene"]["camera"]["position"]
        case["scene"]["camera"] = ms_cases.camera(origin, np.array(case["views"][0]["direction"]))
        for view in case["views"]:
            view["camera"] = ms_cases.camera(origin, np.array(view["direction"]))
            pixel = _airlight_pixel(dict(case["scene"], camera=view["camera"]))
            view["airlight_single"] = pixel if isinstance(view["radiance"], list) else pixel[1]
    with open(path, "w") as f:
        f.write(dump(data))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--kind", choices=("day", "night", "all"), default="all")
    p.add_argument("--cases", default="*", help="fnmatch pattern(s) of case names, comma separated")
    p.add_argument("--target", type=float, default=0.005, help="relative standard error to stop at")
    p.add_argument("--max-seconds", type=float, default=25.0, help="per daytime render (case, part, channel)")
    p.add_argument("--max-seconds-night", type=float, default=45.0, help="per night case")
    p.add_argument("--min-spp", type=int, default=4096)
    p.add_argument("--max-spp", type=int, default=1 << 26)
    p.add_argument("--chunk", type=int, default=8192, help="samples per view between checks")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--parts", default="all",
                   help="daytime parts to render, 'sky', 'sun' or 'all'; the others are kept from the file")
    p.add_argument("--rr-depth", type=int, default=5,
                   help="volpath's Russian roulette depth (5: Mitsuba's default; 1000 for fog: RR from "
                        "depth 5 kills the long paths of thick, nearly conservative media, 15 times less "
                        "efficient for fog50)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--out", type=Path, default=ms_cases.DATA_DIR)
    p.add_argument("--table", action="store_true", help="only print the tables of the stored data")
    p.add_argument("--refresh-airlight", action="store_true",
                   help="only re-render the stored airlight values (and view cameras), no Mitsuba")
    p.add_argument("--validate", action="store_true",
                   help="only the single-scattering check against airlight (a table), nothing stored")
    args = p.parse_args(argv)
    patterns = [s.strip() for s in args.cases.split(",")]

    def wanted(name: str) -> bool:
        return any(fnmatch.fnmatch(name, pat) for pat in patterns)

    day_names = [(w, s) for w in ms_cases.WEATHERS for s in ms_cases.SUNS
                 if wanted(ms_cases.day_case_name(w, s))] if args.kind in ("day", "all") else []
    night_names = [(t, g) for t in ms_cases.NIGHT_TAUS for g in ms_cases.NIGHT_GS
                   if wanted(ms_cases.night_case_name(t, g))] if args.kind in ("night", "all") else []
    if args.refresh_airlight:
        for kind in ("day", "night"):
            if args.kind in (kind, "all"):
                refresh_airlight(args.out / f"{kind}_reference.json")
        return 0
    if args.validate:
        mr.load_mitsuba(args.threads)
        print(validate(args))
        return 0
    if not args.table:
        mr.load_mitsuba(args.threads)
        parts = 2 if args.parts == "all" else len(args.parts.split(","))
        renders = sum(3 * (parts if s != "overcast" else 1) for _w, s in day_names) + len(night_names)
        progress = Progress(renders)
        # one case at a time, so that an interrupted run keeps what it finished
        for t, g in night_names:
            _merge(args.out / "night_reference.json", _header(args, "night"),
                   {ms_cases.night_case_name(t, g): night_case(t, g, args, progress)})
        for w, s in day_names:
            _merge(args.out / "day_reference.json", _header(args, "day"),
                   {ms_cases.day_case_name(w, s): day_case(w, s, args, progress)})
        progress.close()
    for kind, table in (("day", day_table), ("night", night_table), ("day", noise_table)):
        path = args.out / f"{kind}_reference.json"
        if path.exists() and args.kind in (kind, "all"):
            with open(path) as f:
                title = ("noise of the daytime cases" if table is noise_table else
                         f"{kind}: Mitsuba multiple scattering (MS) vs airlight single scattering (SS), "
                         "green")
                print(f"\n{title}\n")
                print(table(json.load(f)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
