"""The rainbow table's measurements (issue 7; docs/rainbow.md): how the bows change with the rain
rate, how many wavelengths the colours need, and what interpolating in rate costs.

    .venv/bin/python benchmarks/rainbow_analysis.py [--out docs/rainbow_analysis.txt]
        [--plot docs/images/rainbow_rates.png]

1. Rain-rate dependence: per rate, the primary bow's width (degrees of its luminance above half
   its height over the dark band), its largest saturation (max - min) / max of RGB, the angles of
   its red and blue maxima, and the secondary's contrast over the dark band.
2. Colour convergence in wavelengths: the RGB table from 3, 5 and 9 of the 17 spectral nodes
   against all 17, as the largest difference over 120-145 degrees relative to the luminance peak;
   and 17 against the 9 that it refines (the error estimate of the 17 themselves).
3. Interpolation in rate: the table's rates are a factor 2 apart and the renderer interpolates
   linearly in log rate. Interpolating node k from nodes k - 1 and k + 1 (a factor 4 apart)
   against node k bounds the error from above (linear interpolation's error grows as the square
   of the spacing: the factor-2 error is about a quarter of this).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import airlight
from airlight import _core

GRID = np.linspace(0.0, 180.0, 3601)
LUMA = np.array([0.2126, 0.7152, 0.0722])
RATES = (0.1, 0.3, 1.0, 3.0, 10.0, 25.0, 50.0, 100.0, 200.0)


def bow_measures(rate: float) -> dict:
    rgb = airlight.rainbow_phase(rate).astype(float)
    lum = rgb @ LUMA
    band_mask = (GRID > 130.0) & (GRID < 136.0)
    band = float(lum[band_mask].min())
    primary = (GRID > 132.0) & (GRID < 146.0)
    peak = float(lum[primary].max())
    width = float(np.count_nonzero(primary & (lum > band + 0.5 * (peak - band))) * (GRID[1] - GRID[0]))
    sat = (rgb.max(axis=1) - rgb.min(axis=1)) / np.maximum(rgb.max(axis=1), 1e-30)
    in_primary = (GRID > 134.0) & (GRID < 142.0)
    red = float(GRID[in_primary][np.argmax(rgb[in_primary, 0])])
    blue = float(GRID[in_primary][np.argmax(rgb[in_primary, 2])])
    secondary = (GRID > 124.0) & (GRID < 131.0)
    sec_peak = float(lum[secondary].max())
    return {"rate": rate, "width_deg": width, "saturation": float(sat[primary].max()), "red_max_deg": red,
            "blue_max_deg": blue, "primary_over_band": peak / band, "secondary_over_band": sec_peak / band}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--plot", type=Path)
    args = ap.parse_args()
    lines: list[str] = []

    def say(text: str = "") -> None:
        print(text, flush=True)
        lines.append(text)

    say("# Rainbow table measurements (benchmarks/rainbow_analysis.py)\n")
    say("## 1. Rain-rate dependence (Marshall-Palmer drops of 0.1-3.5 mm, seen through the sun's disc)\n")
    say("| rate (mm/h) | primary width (deg) | max saturation | red max (deg) | blue max (deg) | "
        "primary / band | secondary / band |")
    say("|---|---|---|---|---|---|---|")
    measures = [bow_measures(r) for r in RATES]
    for m in measures:
        say(f"| {m['rate']:g} | {m['width_deg']:.2f} | {m['saturation']:.3f} | {m['red_max_deg']:.2f} | "
            f"{m['blue_max_deg']:.2f} | {m['primary_over_band']:.2f} | {m['secondary_over_band']:.2f} |")

    say("\n## 2. Colour convergence in wavelengths (120-145 degrees; difference / luminance peak)\n")
    say("| rate (mm/h) | 3 vs 17 | 5 vs 17 | 9 vs 17 |")
    say("|---|---|---|---|")
    bow = (GRID >= 120.0) & (GRID <= 145.0)
    for rate in (1.0, 10.0, 50.0):
        full = airlight.rainbow_phase(rate, wavelengths=17).astype(float)
        peak = float((full[bow] @ LUMA).max())
        diffs = [float(np.abs(airlight.rainbow_phase(rate, wavelengths=n)[bow] - full[bow]).max()) / peak
                 for n in (3, 5, 9)]
        say(f"| {rate:g} | {diffs[0]:.3f} | {diffs[1]:.3f} | {diffs[2]:.3f} |")

    say("\n## 3. Interpolation in rate (node k from k - 1 and k + 1, factor 4 apart; 120-145 degrees)\n")
    t = _core.rainbow_spectral_table()
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
        ax.semilogx(rates, [m["width_deg"] for m in measures], "o-", label="primary width (deg)")
        ax2 = ax.twinx()
        ax2.semilogx(rates, [m["saturation"] for m in measures], "s--", color="C1", label="max saturation")
        ax.set_xlabel("rain rate (mm/h)")
        ax.set_ylabel("width (deg)")
        ax2.set_ylabel("saturation")
        ax.set_title("primary bow against rain rate")
        fig.tight_layout()
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(args.plot, dpi=90)
        args.plot.with_suffix(".json").write_text(json.dumps(measures, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
