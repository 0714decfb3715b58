"""Run time against error: the analytic airlight versus brute-force ray marching.

    .venv/bin/python effects/lamp_airlight/bench/bench_airlight.py [--lamps 1 4 16 64] [--steps 8 16 ... 1024]
        [--width 640 --height 360] [--samples 300] [--plot docs/images/bench_airlight.png]
        [--light-type point|spot|headlights] [--phase isotropic|rayleigh|hg:G|hg2:G1,G2,W]

Scenes: a foggy street at night (sigma_t 0.04/m, albedo 0.9) with 1, 4, 16 and
64 lamps along both sides and buildings as boxes. The surfaces are black
(albedo 0), so that every pixel is airlight (plus the lamp cores) and the two
methods are compared on exactly what differs between them; both backends render
the same scenes in one run. Each method's error is measured against a
reference that shares none of their shortcuts: scipy's adaptive quadrature of
the defining integral (effects/lamp_airlight/physics.md) along each sampled pixel's ray, up
to the first surface or lamp sphere, computed here from the scene geometry.
Error = the largest relative error over the sampled pixels (half uniformly
random, half in the halos around the lamps' images) above 1e-3 of the largest
sampled value, pixels that see a lamp core excluded.

Prints a table (time, error, speed-up of the analytic method at equal error),
the cost of the same street with no lamps, the saving of culling, and writes
a plot of time against error and the raw numbers as JSON. Speed-ups are given
twice: on whole frames, and on the airlight alone (frame time minus the time of
the same frame with no lamps, which is the tracing both methods share).
Timings on a shared 2-core machine are noisy: compare ratios.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.integrate import quad

import airlight

SIGMA_T = 0.04
ALBEDO = 0.9
# The medium's phase function (--phase), in the scene format's medium.phase form.
PHASE: dict = {"type": "isotropic"}


def parse_phase(text: str) -> dict:
    """--phase isotropic | rayleigh | hg:G | hg2:G_FORWARD,G_BACKWARD,W_FORWARD."""
    kind, _, params = text.partition(":")
    values = [float(v) for v in params.split(",")] if params else []
    if kind == "hg" and len(values) == 1:
        return {"type": "hg", "g": values[0]}
    if kind == "hg2" and len(values) == 3:
        return {"type": "hg2", "forward_g": values[0], "backward_g": values[1], "forward_weight": values[2]}
    if kind in ("isotropic", "rayleigh") and not values:
        return {"type": kind}
    raise SystemExit(f"--phase: expected isotropic, rayleigh, hg:G or hg2:G1,G2,W, got {text!r}")


def phase_value(cos_theta: float) -> float:
    """4 pi p(cos theta) of PHASE, evaluated directly (docs/conventions.md)."""
    def hg(g: float) -> float:
        g = max(-0.999, min(0.999, g))  # the renderer's clamp
        return (1 - g * g) / (1 + g * g - 2 * g * cos_theta) ** 1.5
    kind = PHASE["type"]
    if kind == "hg":
        return hg(PHASE["g"])
    if kind == "hg2":
        w = PHASE["forward_weight"]
        return w * hg(PHASE["forward_g"]) + (1 - w) * hg(PHASE["backward_g"])
    if kind == "rayleigh":
        return 0.75 * (1 + cos_theta * cos_theta)
    return 1.0


def street_scene(lamps: int, width: int, height: int, surface_albedo: float = 0.0,
                 light_type: str = "point") -> dict:
    """A straight street along -z: lamps 6 m high every 15 m, alternating sides;
    with light_type "spot", each lamp is a 35-degree spot aimed down and across the road;
    with "headlights", the lights are lamps/2 cars' headlight pairs (airlight.headlights),
    oncoming in the left lane and driving away in the right one, 12 m apart."""
    if light_type == "headlights":
        lights = []
        for car in range(max(lamps // 2, 1)):
            oncoming = car % 2 == 0
            position = [-1.8 if oncoming else 1.8, 0.0, -15.0 - 12.0 * car]
            lights += airlight.headlights(position, 180.0 if oncoming else 0.0)
        scene = street_scene(0, width, height, surface_albedo)
        scene["lights"] = lights[:lamps]
        return scene
    lights = []
    for i in range(lamps):
        side = -1 if i % 2 == 0 else 1
        light = {"type": "point", "position": [side * 5.0, 6.0, -8.0 - 7.5 * i],
                 "intensity": [900.0, 700.0, 450.0], "radius": 0.15}
        if light_type == "spot":
            light.update(type="spot", direction=[-side * 0.5, -1.0, -0.2], cone_angle=35.0, edge=0.1,
                         intensity=[4000.0, 3200.0, 2200.0])
        lights.append(light)
    surfaces = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": surface_albedo}]
    for k in range(12):
        z0 = -20.0 - 45.0 * k
        surfaces.append({"type": "box", "min": [-22, 0, z0 - 30], "max": [-9, 10 + 4 * (k % 3), z0],
                         "albedo": surface_albedo})
        surfaces.append({"type": "box", "min": [9, 0, z0 - 25], "max": [20, 14 - 3 * (k % 2), z0 - 3],
                         "albedo": surface_albedo})
    return {
        "film": {"width": width, "height": height},
        "camera": {"position": [0.5, 1.6, 0.0], "look_at": [0.0, 3.0, -60.0], "up": [0, 1, 0], "fov_y": 55},
        "medium": {"sigma_t": SIGMA_T, "albedo": ALBEDO, "phase": PHASE},
        "lights": lights,
        "surfaces": surfaces,
    }


# ---- independent reference ---------------------------------------------------
def camera_basis(scene: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """Position, unit forward, right and up vectors, tan(fov_y / 2) of the pinhole camera."""
    cam = scene["camera"]
    pos = np.array(cam["position"], float)
    fwd = np.array(cam["look_at"], float) - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, cam["up"])
    right /= np.linalg.norm(right)
    return pos, fwd, right, np.cross(right, fwd), math.tan(math.radians(cam["fov_y"]) / 2)


def camera_rays(scene: dict, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    w, h = scene["film"]["width"], scene["film"]["height"]
    pos, fwd, right, up, th = camera_basis(scene)
    sx = 2 * (pixels[:, 0] + 0.5) / w - 1
    sy = 1 - 2 * (pixels[:, 1] + 0.5) / h
    d = fwd + (sx * th * w / h)[:, None] * right + (sy * th)[:, None] * up
    return pos, d / np.linalg.norm(d, axis=1)[:, None]


def first_hit(scene: dict, origin: np.ndarray, d: np.ndarray) -> tuple[float, bool]:
    """Distance to the first surface or lamp sphere, and whether it is a lamp."""
    best, lamp = math.inf, False
    for s in scene["surfaces"]:
        if s["type"] == "plane":
            n = np.array(s["normal"], float)
            den = n @ d
            if abs(den) > 1e-12:
                t = (n @ (np.array(s["point"], float) - origin)) / den
                if 0 < t < best:
                    best = t
        else:
            lo, hi = np.array(s["min"], float), np.array(s["max"], float)
            with np.errstate(divide="ignore", invalid="ignore"):
                t1, t2 = (lo - origin) / d, (hi - origin) / d
            tn = np.nanmax(np.minimum(t1, t2))
            tf = np.nanmin(np.maximum(t1, t2))
            if tn <= tf and 0 < tn < best:
                best = tn
    for light in scene["lights"]:
        oc = origin - np.array(light["position"], float)
        b = oc @ d
        disc = b * b - (oc @ oc - light["radius"] ** 2)
        if disc >= 0 and b < 0:
            t = -b - math.sqrt(disc)
            if 0 < t < best:
                best, lamp = t, True
    return best, lamp


def reference_airlight(scene: dict, origin: np.ndarray, d: np.ndarray, t_end: float) -> np.ndarray:
    """Adaptive quadrature of sigma_s/(4 pi) I e^{-sigma_t (x + |S - p(x)|)} / |S - p(x)|^2
    over [0, t_end]."""
    total = np.zeros(3)
    sigma_s = SIGMA_T * ALBEDO
    for light in scene["lights"]:
        s = np.array(light["position"], float)
        b = (s - origin) @ d
        h2 = max(float((s - origin) @ (s - origin)) - b * b, 0.0)
        spot = light["type"] == "spot"
        axis = np.array(light.get("direction", [0.0, -1.0, 0.0]), float)
        axis /= np.linalg.norm(axis)
        cos_a = math.cos(math.radians(light.get("cone_angle", 90.0)))
        q = light.get("edge", 0.0)

        def f(x: float, b: float = b, h2: float = h2, s: np.ndarray = s, spot: bool = spot,
              axis: np.ndarray = axis, cos_a: float = cos_a, q: float = q) -> float:
            r2 = h2 + (x - b) ** 2
            value = math.exp(-SIGMA_T * (x + math.sqrt(r2))) / r2
            if PHASE["type"] != "isotropic":  # scattering angle between (p(x) - S) and -d
                value *= phase_value(float((s - origin - x * d) @ d) / math.sqrt(r2))
            if spot:  # effects/spotlights/physics.md profile, zero outside the cone
                ct = ((origin + x * d - s) @ axis) / math.sqrt(r2)
                value *= 0.0 if ct < cos_a else (1 - q) * (ct - cos_a) / (1 - cos_a) + q
            return value

        far = t_end if math.isfinite(t_end) else max(b, 0.0) + 60.0 / SIGMA_T
        pieces = [0.0, far]
        if 0 < b < far:
            pieces.append(b)
        if spot:  # the cone wall crossings (textbook quadratic in double) as break points
            w = origin - s
            qa = (d @ axis) ** 2 - cos_a**2
            qb = 2 * ((d @ axis) * (w @ axis) - cos_a**2 * (d @ w))
            qc = (w @ axis) ** 2 - cos_a**2 * (w @ w)
            roots = np.roots([qa, qb, qc]) if abs(qa) > 1e-15 else np.array([-qc / qb])
            pieces += [float(r.real) for r in roots if abs(r.imag) < 1e-9 and 0 < r.real < far]
        pieces = sorted(pieces)
        value = sum(quad(f, a, c, epsabs=0, epsrel=1e-10, limit=400)[0] for a, c in zip(pieces, pieces[1:]))
        total += sigma_s / (4 * math.pi) * np.array(light["intensity"], float) * value
    return total


def sample_pixels(scene: dict, count: int, rng: np.random.Generator) -> np.ndarray:
    """Half uniformly random pixels, half in rings 2 to 60 pixels around the lamps'
    images (the halos, where the integrand is most peaked and marching is worst)."""
    width, height = scene["film"]["width"], scene["film"]["height"]
    uniform = np.stack([rng.integers(0, width, count // 2), rng.integers(0, height, count // 2)], axis=1)
    pos, fwd, right, up, th = camera_basis(scene)
    centres = []
    for light in scene["lights"]:
        v = np.array(light["position"], float) - pos
        if v @ fwd <= 0:
            continue
        sx = (v @ right) / (v @ fwd) / (th * width / height)
        sy = (v @ up) / (v @ fwd) / th
        centres.append(((sx + 1) * width / 2, (1 - sy) * height / 2))
    if not centres:
        return uniform
    k = rng.integers(0, len(centres), count - count // 2)
    radius = 2.0 * 30.0 ** rng.random(len(k))
    angle = rng.uniform(0, 2 * math.pi, len(k))
    ring = np.stack([np.array(centres)[k, 0] + radius * np.cos(angle),
                     np.array(centres)[k, 1] + radius * np.sin(angle)], axis=1).astype(int)
    inside = (ring[:, 0] >= 0) & (ring[:, 0] < width) & (ring[:, 1] >= 0) & (ring[:, 1] < height)
    return np.concatenate([uniform, ring[inside]])


def reference_for(scene: dict, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    origin, dirs = camera_rays(scene, pixels)
    values = np.zeros((len(pixels), 3))
    core = np.zeros(len(pixels), bool)
    for i, d in enumerate(dirs):
        t_end, lamp = first_hit(scene, origin, d)
        core[i] = lamp
        values[i] = reference_airlight(scene, origin, d, t_end)
    return values, core


def max_relative_error(image: np.ndarray, pixels: np.ndarray, ref: np.ndarray, core: np.ndarray) -> float:
    got = image[pixels[:, 1], pixels[:, 0]].astype(float)
    keep = ~core & (ref.max(axis=1) > 1e-3 * ref[~core].max())
    return float(np.max(np.abs(got[keep] - ref[keep]) / ref[keep]))


# ---- timing ------------------------------------------------------------------
def timed(renderer: airlight.Renderer, scene: dict, budget: float = 3.0) -> tuple[float, np.ndarray]:
    t0 = time.perf_counter()
    image = renderer.render(scene)  # warm-up: shader variant, tables
    first = time.perf_counter() - t0
    if first > budget:  # slow frames: the set-up in the first one (< 0.1 s) is negligible
        return first, image
    times = []
    while len(times) < 5 and sum(times) < budget:
        t0 = time.perf_counter()
        image = renderer.render(scene)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), image


def speedup_at(error: float, march: list[tuple[int, float, float]], analytic_time: float) -> str:
    """Time march needs to reach `error` (log-log interpolation), over the analytic time."""
    for (_s0, t0, e0), (_s1, t1, e1) in zip(march, march[1:]):
        if e0 > error >= e1:
            w = math.log(e0 / error) / math.log(e0 / e1)
            return f"{math.exp((1 - w) * math.log(t0) + w * math.log(t1)) / analytic_time:.0f}x"
    if march and march[0][2] <= error:
        return f"<{march[0][1] / analytic_time:.0f}x"
    return f">{march[-1][1] / analytic_time:.0f}x" if march else "-"


def extrapolated_speedup(error: float, march: list[tuple[int, float, float]], analytic_time: float) -> str:
    """When marching never reaches `error`: fit error ~ steps^-p and time ~ steps on the
    last two step counts and extrapolate (an estimate, marked with ~)."""
    if len(march) < 2 or march[-1][2] <= error:
        return ""
    (s0, _t0, e0), (s1, t1, e1) = march[-2], march[-1]
    if not e1 < e0:
        return "~n/a"
    p = math.log(e0 / e1) / math.log(s1 / s0)
    steps = s1 * (e1 / error) ** (1 / p)
    return f"~{t1 * steps / s1 / analytic_time:.0f}x"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lamps", type=int, nargs="+", default=[1, 4, 16, 64])
    ap.add_argument("--steps", type=int, nargs="+", default=[8, 16, 32, 64, 128, 256, 512, 1024])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--samples", type=int, default=300)
    ap.add_argument("--backends", nargs="+", default=airlight.available_backends())
    ap.add_argument("--light-type", choices=("point", "spot", "headlights"), default="point",
                    help="street lamps as point lights (effects/lamp_airlight/physics.md) or spots "
                         "(effects/spotlights/physics.md), "
                         "or cars' headlights (spots seen along their beams)")
    ap.add_argument("--phase", default="isotropic",
                    help="the fog's phase function: isotropic, rayleigh, hg:G (e.g. hg:0.85) or "
                         "hg2:G_FORWARD,G_BACKWARD,W_FORWARD")
    default_plot = Path(__file__).resolve().parents[3] / "docs/images/bench_airlight.png"
    ap.add_argument("--plot", default=str(default_plot))
    args = ap.parse_args()
    PHASE.clear()
    PHASE.update(parse_phase(args.phase))
    rng = np.random.default_rng(1)
    renderers = {b: airlight.Renderer(b) for b in args.backends}
    results: dict[tuple[str, int], dict] = {}

    print(f"street of {args.light_type} lights at {args.width}x{args.height}, sigma_t {SIGMA_T}/m, "
          f"albedo {ALBEDO}, phase {PHASE}; "
          f"error = max relative error over {args.samples} sampled pixels, half of them "
          "in the lamps' halos (cores excluded)")
    base = {b: timed(r, street_scene(0, args.width, args.height))[0] for b, r in renderers.items()}
    print("frame with no lamps (tracing only): " + ", ".join(f"{b} {1e3 * t:.1f} ms"
                                                             for b, t in base.items()))
    for lamps in args.lamps:
        scene = street_scene(lamps, args.width, args.height, light_type=args.light_type)
        pixels = sample_pixels(scene, args.samples, rng)
        t0 = time.perf_counter()
        ref, core = reference_for(scene, pixels)
        print(f"\n{lamps} lamp(s): reference by adaptive quadrature in {time.perf_counter() - t0:.1f} s")
        print(f"  {'backend':8} {'method':14} {'time ms':>9} {'max rel err':>12}")
        for backend, renderer in renderers.items():
            entry: dict = {"march": []}
            sc = copy.deepcopy(scene)
            t_an, img = timed(renderer, sc)
            entry["analytic"] = (t_an, max_relative_error(img, pixels, ref, core))
            sc["quality"] = {"cull_fraction": 0}
            t_nc, img = timed(renderer, sc)
            entry["analytic_nocull"] = (t_nc, max_relative_error(img, pixels, ref, core))
            print(f"  {backend:8} {'analytic':14} {1e3 * t_an:9.1f} {entry['analytic'][1]:12.2e}")
            err_nc = entry["analytic_nocull"][1]
            print(f"  {backend:8} {'  (no culling)':14} {1e3 * t_nc:9.1f} {err_nc:12.2e}")
            for steps in args.steps:
                sc["quality"] = {"airlight": "march", "march_steps": steps, "cull_fraction": 0}
                t_m, img = timed(renderer, sc, budget=1.0)
                err = max_relative_error(img, pixels, ref, core)
                entry["march"].append((steps, t_m, err))
                print(f"  {backend:8} {'march ' + str(steps):14} {1e3 * t_m:9.1f} {err:12.2e}")
            results[(backend, lamps)] = entry

    print("\nspeed-up of the analytic method over ray marching at equal error")
    print("  ('>N x': marching never got there, N = its slowest run over the analytic time;")
    print("   '~N x': extrapolated from the last two step counts, error ~ steps^-p, time ~ steps)")
    print("  whole frames | airlight only (time minus the no-lamp frame)")
    print(f"  {'lamps':>5} {'backend':8} {'analytic ms':>12} {'its error':>10} {'@ its error':>12} "
          f"{'@ 0.5%':>8} {'extrapolated':>13} | {'airlight ms':>11} {'@ 0.5%':>8} {'extrapolated':>13}")
    for (backend, lamps), e in results.items():
        t_an, err_an = e["analytic"]
        at_own = speedup_at(max(err_an, 1e-9), e["march"], t_an)
        at_half_percent = speedup_at(5e-3, e["march"], t_an)
        # Airlight-only times: subtract the shared tracing cost (floored at 5% of the frame).
        a_an = max(t_an - base[backend], 0.05 * t_an)
        a_march = [(st, max(tm - base[backend], 0.05 * tm), er) for st, tm, er in e["march"]]
        e["airlight_only"] = {"analytic": a_an, "march": a_march}
        print(f"  {lamps:5d} {backend:8} {1e3 * t_an:12.1f} {err_an:10.1e} {at_own:>12} {at_half_percent:>8} "
              f"{extrapolated_speedup(5e-3, e['march'], t_an):>13} | {1e3 * a_an:11.1f} "
              f"{speedup_at(5e-3, a_march, a_an):>8} {extrapolated_speedup(5e-3, a_march, a_an):>13}")
    raw = {f"{b}/{n}": e for (b, n), e in results.items()}
    raw["no_lamps"] = base
    Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
    Path(args.plot).with_suffix(".json").write_text(json.dumps(raw, indent=1))

    print("\ncost of the street with no lamps (no airlight work, no tables) and of culling")
    for backend in renderers:
        print(f"  {backend:8} 0 lamps {1e3 * base[backend]:8.1f} ms")
        for lamps in args.lamps:
            e = results[(backend, lamps)]
            saving = 1 - e["analytic"][0] / e["analytic_nocull"][0]
            print(f"  {backend:8} {lamps:3d} lamps: culling saves {saving:6.1%} "
                  f"(error {e['analytic'][1]:.1e} with, {e['analytic_nocull'][1]:.1e} without)")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot")
        return
    fig, axes = plt.subplots(1, len(args.lamps), figsize=(4.2 * len(args.lamps), 4), squeeze=False)
    for ax, lamps in zip(axes[0], args.lamps):
        for backend, colour in zip(args.backends, ("tab:blue", "tab:orange")):
            e = results[(backend, lamps)]
            ax.loglog([m[2] for m in e["march"]], [1e3 * m[1] for m in e["march"]], "o-", color=colour,
                      label=f"march 8..1024 ({backend})", alpha=0.8)
            ax.loglog([e["analytic"][1]], [1e3 * e["analytic"][0]], "*", color=colour, markersize=14,
                      label=f"analytic ({backend})")
        ax.axvline(5e-3, color="grey", lw=0.8, ls="--")
        ax.set_title(f"{lamps} lamp(s), {args.width}x{args.height}")
        ax.set_xlabel("max relative error")
        ax.set_ylabel("time per frame (ms)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.plot, dpi=110)
    print(f"\nplot: {args.plot}")


if __name__ == "__main__":
    main()
