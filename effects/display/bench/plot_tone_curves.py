"""Plots the display stage's tone curves (airlight.display, effects/display/display.glsl)
into docs/images/tone_curves.png.

    .venv/bin/python effects/display/bench/plot_tone_curves.py [--out PATH]

Left: the curve's display value f(L) (linear light, before sRGB encoding)
against log10 of the exposed luminance L, for each curve at its default white
point (linear 1, loglog 100, reinhard 16, filmic 7.24); the dotted line is the
auto-exposure key 0.18, the markers each curve's white (f = 1). Right: the
same after the sRGB OETF, i.e. the 8-bit code / 255 a pixel of grey luminance
L is shown with. The values come from the native code itself
(airlight.tone_curve), not a re-implementation.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import airlight  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
OUT = ROOT / "docs" / "images" / "tone_curves.png"

LABELS = {
    "linear": "linear (clip at W)",
    "loglog": "loglog: ln(1+ln(1+L)) / ln(1+ln(1+W))  (source paper)",
    "reinhard": "reinhard: L (1 + L/W²) / (1 + L)  (Reinhard 2002)",
    "filmic": "filmic: ACES fit (Narkowicz 2015)",
}


def srgb(v: np.ndarray) -> np.ndarray:
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()

    log_l = np.linspace(-4, 4, 2001)
    lum = 10.0**log_l
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6), constrained_layout=True)
    for name in airlight.TONEMAPS:
        v = airlight.tone_curve(lum, name).astype(np.float64)
        white = float(airlight._core.default_white(name))
        for ax, values in zip(axes, (v, srgb(v))):
            (line,) = ax.plot(log_l, values, label=LABELS[name], lw=1.8)
            ax.plot([np.log10(white)], [1.0], "o", color=line.get_color(), ms=5)
    ylabels = ("display value f(L) (linear light)", "sRGB-encoded display value (8-bit code / 255)")
    for ax, ylabel in zip(axes, ylabels):
        ax.axvline(np.log10(0.18), color="0.5", ls=":", lw=1)
        ax.set_xlabel("log10 exposed luminance L   (auto exposure puts the log-average at 0.18)")
        ax.set_ylabel(ylabel)
        ax.set_xlim(log_l[0], log_l[-1])
        ax.set_ylim(-0.02, 1.04)
        ax.grid(alpha=0.3)
    axes[1].legend(loc="lower right", fontsize=8)
    axes[0].set_title("Tone curves at their default white points (dots: f(W) = 1)")
    axes[1].set_title("After the sRGB OETF (IEC 61966-2-1)")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
