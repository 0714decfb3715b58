"""The rainbow table's measurements (issue 7; effects/rainbow/docs/rainbow.md): how the bows change with
the rain
rate, how many wavelengths the colours need, and what interpolating in rate costs.

    .venv/bin/python effects/rainbow/bench/rainbow_analysis.py [--out
    effects/rainbow/docs/rainbow_analysis.txt]
        [--plot docs/images/rainbow_rates.png]

1. Rain-rate dependence: per rate of the table, the primary bow's width and contrast at 550 nm,
   the secondary's contrast, the bow's saturation (excitation purity), the separation of the
   colours, the RGB table's red and blue maxima and saturation (bow_measures).
2. Colour convergence in wavelengths: the RGB table from 3, 5, 9 and 17 of the 33 spectral
   nodes against all 33, as the largest difference over 120-145 degrees relative to the luminance
   peak, and the error of the 33 themselves estimated from the rate of convergence.
3. Interpolation in rate: the table's rates are a factor 2 apart and the renderer interpolates
   linearly in log rate. Interpolating node k from nodes k - 1 and k + 1 (a factor 4 apart)
   against node k bounds the error from above (linear interpolation's error grows as the square
   of the spacing: the factor-2 error is about a quarter of this).
4. Below the rain's sizes (not rendered: the rain's drops are 0.1-3.5 mm): nearly uniform drops
   of 10 um to 0.5 mm (within a factor 1.25 of the diameter) by the deterministic size rule
   (mie_size_average_phase) through the sun's disc profile: the primary's contrast and position at
   450, 550 and 650 nm and the secondary's contrast: where the secondary fades and the bow turns
   white (fogbows).
5. Angular resolution of the spectral table: in each part of its angle grid, every other node
   interpolated linearly from its neighbours (twice the spacing) against its own value, over all
   rates and wavelengths; linear interpolation's error scales as the square of the spacing, so
   the table's own is about a quarter of this. And the same for the renderer's RGB table in the
   bows, relative to the primary's peak luminance.
6. Accuracy against independent references and the rendered geometry (the numbers behind the
   acceptance tests of effects/rainbow/tests/test_rainbow.py, which assert their bounds): one drop through
   the sun's disc against the numpy Mie series; the size-averaged table against the deterministic
   size quadrature; the table's sampling error by region; its normalisation; the renderer's
   table's per-channel normalisation; and the bows' angles in a rendered column, both backends.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import airlight
from airlight import _core

ROOT = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(ROOT / "tests" / "python"), *(str(d) for d in sorted(ROOT.glob("effects/*/tests")))]

GRID = np.linspace(0.0, 180.0, 3601)
LUMA = np.array([0.2126, 0.7152, 0.0722])
BOW_ANGLES = np.linspace(120.0, 146.0, 521)


def spectral_bow(table: dict, k: int, node: int) -> np.ndarray:
    """Rate k's phase at wavelength node `node` on BOW_ANGLES (0.05 degree)."""
    return np.interp(BOW_ANGLES, table["angles_deg"], table["phase"][k, node].astype(float))


def monochrome_bow(p: np.ndarray) -> tuple[float, float, float, float]:
    """Primary maximum's angle, width above half its height over the dark band's floor, its
    contrast peak / floor, and the secondary's contrast (maximum in 124-131 over the floor)."""
    floor = float(p[(BOW_ANGLES > 129.0) & (BOW_ANGLES < 136.0)].min())
    primary = BOW_ANGLES > 134.0
    peak = float(p[primary].max())
    width = float(np.count_nonzero(primary & (p > floor + 0.5 * (peak - floor))) * 0.05)
    at = float(BOW_ANGLES[primary][np.argmax(p[primary])])
    secondary = float(p[(BOW_ANGLES > 124.0) & (BOW_ANGLES < 131.0)].max())
    return at, width, peak / floor, secondary / floor


def bow_purity(table: dict, k: int) -> float:
    """Saturation as colour science defines it: the largest excitation purity (CIE 1931 xy,
    D65 white; colour-science) of the bow's colours before any gamut mapping, over the angles
    where the primary's luminance is above half its height over the dark band."""
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"]
    nm = np.arange(380, 721)
    weights = np.array([cmfs[w] * d65[w] for w in nm])
    white = weights.sum(axis=0)
    phase = np.stack([spectral_bow(table, k, i) for i in range(len(table["wavelengths_nm"]))])  # (33, angles)
    spectra = np.array([np.interp(nm, table["wavelengths_nm"], phase[:, j]) for j in range(phase.shape[1])])
    xyz = spectra @ weights
    y = xyz[:, 1]
    floor = y[(BOW_ANGLES > 129.0) & (BOW_ANGLES < 136.0)].min()
    primary = BOW_ANGLES > 134.0
    bright = primary & (y > floor + 0.5 * (y[primary].max() - floor))
    xy = xyz[bright, :2] / xyz[bright].sum(axis=1, keepdims=True)
    return float(max(colour.excitation_purity(p, white[:2] / white.sum()) for p in xy))


def bow_measures(table: dict, k: int) -> dict:
    """Rate k's bows: at 550 nm (node 16) the primary's width and contrast and the secondary's
    contrast; its saturation (bow_purity); the colours' separation (spread of the 33 wavelengths'
    primary maxima in units of their mean width: below about 2 the colours overlap into a pale
    bow); and from the RGB table the
    red and blue maxima and the largest saturation (max - min) / max (1 where the bow's colour
    leaves the sRGB gamut)."""
    rate = float(table["rates"][k])
    per_node = [monochrome_bow(spectral_bow(table, k, i)) for i in range(len(table["wavelengths_nm"]))]
    peaks = [m[0] for m in per_node]
    _, width, contrast, secondary = per_node[16]
    rgb = airlight.rainbow_phase(rate).astype(float)
    in_primary = (GRID > 134.0) & (GRID < 142.0)
    red = float(GRID[in_primary][np.argmax(rgb[in_primary, 0])])
    blue = float(GRID[in_primary][np.argmax(rgb[in_primary, 2])])
    sat = (rgb.max(axis=1) - rgb.min(axis=1)) / np.maximum(rgb.max(axis=1), 1e-30)
    return {"rate": rate, "width_deg": width, "contrast": contrast, "secondary_contrast": secondary,
            "colour_separation": (max(peaks) - min(peaks)) / float(np.mean([m[1] for m in per_node])),
            "purity": bow_purity(table, k), "red_max_deg": red, "blue_max_deg": blue,
            "rgb_saturation": float(sat[in_primary].max())}


def small_drop_bows() -> list[dict]:
    """Section 4: drops of one size (within a factor 1.25) seen through the sun's disc (the
    profile rule of effects/rainbow/tests/test_rainbow.py, 48 nodes)."""
    k = 48
    j = np.arange(1, k + 1)
    offsets = 0.2665 * np.cos(j * np.pi / (k + 1))
    weights = np.sin(j * np.pi / (k + 1)) ** 2
    weights /= weights.sum()
    angles = np.arange(110.0, 160.01, 0.1)
    points = (angles[:, None] + offsets[None, :]).ravel().tolist()
    rows = []
    for d in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5):
        row: dict = {"diameter": d, "contrast": [], "at": [], "secondary": []}
        for wavelength in (450.0, 550.0, 650.0):
            p = _core.mie_size_average_phase(0.0, wavelength, points, 200, 0.0, d / 1.25, d * 1.25)
            p = p.reshape(len(angles), -1) @ weights
            band = p[(angles > 129.0) & (angles < 136.0)].min()
            primary = (angles > 134.0) & (angles < 150.0)
            row["contrast"].append(float(p[primary].max() / band))
            row["at"].append(float(angles[primary][np.argmax(p[primary])]))
            row["secondary"].append(float(p[(angles > 120.0) & (angles < 131.0)].max() / band))
        rows.append(row)
    return rows


def halving_errors(table: dict, lo: float, hi: float) -> tuple[float, float, float]:
    """Section 5: relative error of every other node of the grid in [lo, hi] interpolated from its
    neighbours: largest, 99th percentile and median over rates, wavelengths and angles."""
    a = table["angles_deg"]
    nodes = np.where((a >= lo - 1e-9) & (a <= hi + 1e-9))[0]
    kept, dropped = nodes[::2], nodes[1::2]
    dropped = dropped[a[dropped] < a[kept][-1]]
    phase = table["phase"].astype(float)
    rows = phase.reshape(-1, phase.shape[-1])
    estimate = np.stack([np.interp(a[dropped], a[kept], row[kept]) for row in rows])
    rel = np.abs(estimate - rows[:, dropped]) / rows[:, dropped]
    return float(rel.max()), float(np.percentile(rel, 99)), float(np.median(rel))


def accuracy_section(t: dict, say) -> None:
    """Section 6 (see the module's docstring)."""
    import test_rainbow as tr  # the acceptance tests' own helpers and references

    say("\n## 6. Against independent references, and the rendered geometry\n")
    angles = np.arange(120.0, 145.01, 0.25)
    say("One drop through the sun's disc, library (Mie series, 2-D disc rule) against numpy "
        "(mie_reference.py, 1-D disc profile rule), 120-145 degrees:\n")
    say("| diameter (mm) | wavelength (nm) | largest relative difference |")
    say("|---|---|---|")
    for d, w in ((0.1, 450.0), (0.1, 650.0), (0.3, 450.0), (0.3, 650.0), (1.0, 550.0)):
        n = _core.water_refractive_index(w)
        ours = _core.mie_sun_disc_phase(n, d, w, angles.tolist(), 16)
        theirs = tr.numpy_disc_phase(n, d, w, angles)
        say(f"| {d:g} | {w:g} | {np.max(np.abs(ours - theirs) / theirs):.4f} |")
    say("\nThe embedded table at 25.6 mm/h against 1600 sizes evenly spaced in log D (midpoint rule) "
        "through the disc profile, 120-145 degrees every 0.5:\n")
    say("| wavelength (nm) | largest relative difference | median |")
    say("|---|---|---|")
    k = int(np.argmin(np.abs(t["rates"] - 25.6)))
    coarse = np.arange(120.0, 145.01, 0.5)
    offsets, weights = tr.disc_profile_rule()
    points = (coarse[:, None] + offsets[None, :]).ravel().tolist()
    for node in (4, 16, 28):
        wavelength = float(t["wavelengths_nm"][node])
        point_phase = _core.mie_size_average_phase(25.6, wavelength, points, 1600)
        theirs = point_phase.reshape(len(coarse), -1) @ weights
        ours = np.interp(coarse, t["angles_deg"], t["phase"][k, node].astype(float))
        rel = np.abs(ours - theirs) / theirs
        say(f"| {wavelength:g} | {rel.max():.4f} | {np.median(rel):.4f} |")

    a, err, phase = t["angles_deg"], t["rel_error"], t["phase"]
    say("\nStored sampling error (relative standard error) by region:\n")
    say("| angles (deg) | largest | median |")
    say("|---|---|---|")
    for lo, hi in ((0.0, 0.3), (0.3, 1.0), (1.0, 118.0), (120.0, 145.0), (146.0, 180.0)):
        m = (a >= lo) & (a <= hi)
        say(f"| {lo:g}-{hi:g} | {err[:, :, m].max():.4f} | {np.median(err[:, :, m]):.4f} |")
    bows = (a >= 120.0) & (a <= 145.0)
    worst = np.unravel_index(np.argmax(err[:, :, bows]), err[:, :, bows].shape)
    prim = (a > 134.0) & (a < 145.0)
    at_max = [float(err[r, w][prim][np.argmax(phase[r, w][prim])]) for r in range(len(t["rates"]))
              for w in range(len(t["wavelengths_nm"]))]
    say(f"\nlargest in 120-145 degrees at {a[bows][worst[2]]:.2f} degrees ({t['rates'][worst[0]]:g} mm/h); "
        f"at each rate's and wavelength's primary maximum: {min(at_max):.4f}-{max(at_max):.4f}")
    total = tr.sphere_integral(a, phase)
    beyond = tr.sphere_integral(a[a >= 3.0], phase[..., a >= 3.0])
    say(f"integral over the sphere: {total.min():.6f}-{total.max():.6f}; beyond 3 degrees: "
        f"{beyond.min():.4f}-{beyond.max():.4f}")
    grid = np.linspace(0.0, 180.0, 3601)
    channel_totals = np.concatenate([tr.sphere_integral(grid, airlight.rainbow_phase(r).T)
                                     for r in (0.1, 1.0, 25.0, 819.2)])
    say(f"renderer's RGB table, each channel over the sphere (0.1-819.2 mm/h): "
        f"{channel_totals.min():.5f}-{channel_totals.max():.5f}")

    def descartes_primary(n: float) -> float:
        """Scattering angle (degrees) of the primary's minimum deviation (geometric optics)."""
        i = np.arccos(np.sqrt((n * n - 1.0) / 3.0))
        r = np.arcsin(np.sin(i) / n)
        return float(np.degrees(np.pi + 2.0 * i - 4.0 * r))

    qf, dm = _core.water_refractive_index(700.0), tr.daimon_masumura_water_index(700.0)
    say(f"\nwater at 700 nm: Quan & Fry {qf:.5f}, Daimon & Masumura {dm:.5f}, "
        f"the source paper 1.3311; "
        f"Descartes primary at {descartes_primary(qf):.3f} / {descartes_primary(dm):.3f} / "
        f"{descartes_primary(1.3311):.3f} degrees")

    say("\nRendered column through the antisolar point (sun 20 degrees up, 25 mm/h; tests' bow_scene):\n")
    say("| backend | red max | blue max | secondary (luminance) | secondary red / blue | band / inside |")
    say("|---|---|---|---|---|---|")
    scene = tr.bow_scene()
    angle = tr.scattering_angles(scene)
    for backend in airlight.available_backends():
        with airlight.Renderer(backend) as r:
            img = r.render(scene)[:, 0, :].astype(float)

        def arg_max(lo: float, hi: float, values: np.ndarray) -> float:
            m = (angle > lo) & (angle < hi)
            return float(angle[m][np.argmax(values[m])])

        lum = img @ LUMA
        band = lum[(angle > 131.0) & (angle < 135.5)].mean() / lum[(angle > 140.5) & (angle < 145.0)].mean()
        say(f"| {backend} | {arg_max(134, 142, img[:, 0]):.2f} | {arg_max(134, 142, img[:, 2]):.2f} | "
            f"{arg_max(126, 131, lum):.2f} | {arg_max(124, 132, img[:, 0]):.2f} / "
            f"{arg_max(124, 132, img[:, 2]):.2f} | {band:.3f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--plot", type=Path)
    args = ap.parse_args()
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    say("# Rainbow table measurements (effects/rainbow/bench/rainbow_analysis.py)\n")
    say("## 1. Rain-rate dependence (Marshall-Palmer drops of 0.1-3.5 mm, seen through the sun's disc)\n")
    say("| rate (mm/h) | width at 550 nm (deg) | primary / band | secondary / band | purity | "
        "colour separation | red max (deg) | blue max (deg) | RGB saturation |")
    say("|---|---|---|---|---|---|---|---|---|")
    t = _core.rainbow_spectral_table()
    measures = [bow_measures(t, k) for k in range(len(t["rates"]))]
    for m in measures:
        say(f"| {m['rate']:g} | {m['width_deg']:.2f} | {m['contrast']:.1f} | {m['secondary_contrast']:.1f} | "
            f"{m['purity']:.3f} | {m['colour_separation']:.2f} | {m['red_max_deg']:.2f} | "
            f"{m['blue_max_deg']:.2f} | {m['rgb_saturation']:.3f} |")

    say("\n## 2. Colour convergence in wavelengths (RGB table over 120-145 degrees against the one from "
        "all 33 "
        "nodes; largest channel difference / luminance peak, and the mean in parentheses)\n")
    say("| rate (mm/h) | 3 vs 33 | 5 vs 33 | 9 vs 33 | 17 vs 33 | estimated error of 33 |")
    say("|---|---|---|---|---|---|")
    bow = (GRID >= 120.0) & (GRID <= 145.0)
    for rate in (1.0, 10.0, 50.0):
        full = airlight.rainbow_phase(rate, wavelengths=33).astype(float)[bow]
        peak = float((full @ LUMA).max())
        diffs = [np.abs(airlight.rainbow_phase(rate, wavelengths=n)[bow] - full) / peak
                 for n in (3, 5, 9, 17)]
        # Each halving of the spacing divides the error E by q. Against 33: e(17) = (q - 1) E(33)
        # and e(9) = (q^2 - 1) E(33), so q = e(9) / e(17) - 1 and E(33) = e(17) / (q - 1).
        q = diffs[2].max() / diffs[3].max() - 1.0
        cells = " | ".join(f"{d.max():.3f} ({d.mean():.4f})" for d in diffs)
        say(f"| {rate:g} | {cells} | {diffs[3].max() / (q - 1.0):.3f} (q = {q:.1f}) |")

    say("\n## 3. Interpolation in rate (node k from k - 1 and k + 1, factor 4 apart; 120-145 degrees)\n")
    mask = (t["angles_deg"] >= 120.0) & (t["angles_deg"] <= 145.0)
    say("| rate (mm/h) | largest relative error over wavelengths and angles | median |")
    say("|---|---|---|")
    for k in range(1, len(t["rates"]) - 1):
        mid = 0.5 * (t["phase"][k - 1] + t["phase"][k + 1])[:, mask]
        rel = np.abs(mid - t["phase"][k][:, mask]) / t["phase"][k][:, mask]
        say(f"| {t['rates'][k]:g} | {rel.max():.3f} | {np.median(rel):.4f} |")
    say(f"\nstored Monte-Carlo standard error in 120-145 degrees: largest "
        f"{t['rel_error'][:, :, mask].max():.4f}, median {np.median(t['rel_error'][:, :, mask]):.4f} "
        f"({t['samples_per_wavelength']} samples per wavelength)")

    say("\n## 4. Small drops (nearly uniform sizes, within a factor 1.25; not rendered)\n")
    say("| diameter (mm) | primary / band at 450, 550, 650 nm | primary at 450, 550, 650 nm (deg) | "
        "blue - red maximum (deg) | secondary / band (550 nm) |")
    say("|---|---|---|---|---|")
    for row in small_drop_bows():
        say(f"| {row['diameter']:g} | " + ", ".join(f"{c:.1f}" for c in row["contrast"]) + " | "
            + ", ".join(f"{a:.1f}" for a in row["at"]) + f" | {row['at'][0] - row['at'][2]:+.1f} | "
            f"{row['secondary'][1]:.2f} |")

    say("\n## 5. Angular resolution (every other node from its neighbours: twice the table's spacing)\n")
    say("| angles (deg) | table spacing (deg) | largest | 99th percentile | median |")
    say("|---|---|---|---|---|")
    for lo, hi, step in ((0.0, 3.0, 0.05), (3.0, 118.0, 0.5), (118.0, 146.0, 0.05), (146.0, 178.0, 0.5),
                         (178.0, 180.0, 0.05)):
        worst, p99, median = halving_errors(t, lo, hi)
        say(f"| {lo:g}-{hi:g} | {step:g} | {worst:.3f} | {p99:.4f} | {median:.4f} |")
    weights = _core.rainbow_rgb_weights(33).astype(float)
    a = t["angles_deg"]
    bows = np.where((a >= 118.0) & (a <= 146.0))[0]
    kept, dropped = bows[::2], bows[1::2][:-1]
    worst_rgb = 0.0
    for k in range(len(t["rates"])):
        rgb = t["phase"][k].astype(float).T @ weights
        peak = float((rgb[(a > 134.0) & (a < 142.0)] @ LUMA).max())
        estimate = np.stack([np.interp(a[dropped], a[kept], rgb[kept, c]) for c in range(3)], axis=1)
        worst_rgb = max(worst_rgb, float(np.abs(estimate - rgb[dropped]).max()) / peak)
    say(f"\nRGB in the bows (118-146 degrees) at twice the spacing: largest channel error "
        f"{worst_rgb:.4f} of the primary's peak luminance (over all rates)")

    accuracy_section(t, say)

    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(15, 4))
        sel = (GRID >= 120.0) & (GRID <= 145.0)
        for rate, ax in zip((50.0, 1.0), axes[:2]):
            rgb = airlight.rainbow_phase(rate).astype(float)
            for c, colour in enumerate(("r", "g", "b")):
                ax.plot(GRID[sel], rgb[sel, c], colour, lw=1)
            ax.set_title(f"{rate:g} mm/h: RGB phase (sr^-1)")
            ax.set_xlabel("scattering angle (degrees)")
        ax = axes[2]
        rates = [m["rate"] for m in measures]
        ax.semilogx(rates, [m["width_deg"] for m in measures], "o-", label="primary width at 550 nm (deg)")
        ax.semilogx(rates, [m["colour_separation"] for m in measures], "^-", label="colour separation")
        ax2 = ax.twinx()
        ax2.semilogx(rates, [m["purity"] for m in measures], "s--", color="C2", label="saturation (purity)")
        ax.set_xlabel("rain rate (mm/h)")
        ax.set_ylabel("width (deg), separation")
        ax2.set_ylabel("largest excitation purity in the primary")
        ax.legend(loc="upper left", fontsize=8)
        ax2.legend(loc="lower right", fontsize=8)
        ax.set_title("primary bow against rain rate")
        fig.tight_layout()
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(args.plot, dpi=90)
        args.plot.with_suffix(".json").write_text(json.dumps(measures, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
