"""The seed's effective phase value against the exact sky-phase integral (effects/daytime/docs/daytime.md section 1).

    .venv/bin/python effects/daytime/docs/daytime_phase_analysis.py

The seed (effects/daytime/physics.md) uses one effective phase value D_i per species because skylight is
diffuse; with D_i = 1 / (4 pi) the in-scattered skylight is the isotropic F_iso(C). This prints the
ratio of the exact F_p(C, d) (effects/daytime/tests/daytime_reference.py, float64) to it over view
directions and columns: what the renderer's sky-phase table gains over the seed's approximation.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path[:0] = [str(ROOT / "tests" / "python"), *(str(d) for d in sorted(ROOT.glob("effects/*/tests")))]

import daytime_reference as ref  # noqa: E402

UP = np.array([0.0, 1.0, 0.0])
SKIES = {
    "overcast (1+2cosZ)/3": ref.Sky(0),
    "CIE 12 clear, sun 30 deg": ref.Sky(12, sun_elevation_deg=30.0),
    "CIE 12 clear, sun 60 deg": ref.Sky(12, sun_elevation_deg=60.0),
}
PHASES = {"rayleigh": "rayleigh", "HG g=0.7 (aerosol)": 0.7, "HG g=0.87 (rain)": 0.87}


def table(title, header, rows):
    print(f"\n{title}\n")
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" for _ in header) + "|")
    for r in rows:
        print("| " + " | ".join(str(x) for x in r) + " |")


# ----------------------------------------------------------------------------------------------
# 1. effective phase


def section_phase():
    columns = np.array([0.0, 0.3, 1.0, 3.0, 10.0])
    elevs = [-90.0, -30.0, -5.0, 0.0, 5.0, 30.0, 90.0]
    azs = [0.0, 90.0, 180.0]
    rows = []
    for sky_name, sky in SKIES.items():
        for pname, p in PHASES.items():
            ratios = []
            for el in elevs:
                for az in (azs if not sky.azimuth_symmetric else [0.0]):
                    v = ref.view_direction(az, el)
                    fp = ref.sky_phase_integral(sky, columns, v, [p, 0.0])
                    ratios.append(fp[:, 0] / fp[:, 1])
            r = np.array(ratios)
            rows.append([sky_name, pname, f"{r.min():.3f}", f"{r.max():.3f}",
                         f"{np.abs(r - 1).max() * 100:.0f}%"])
    table("Table P1. F_p / F_iso = exact in-scattered skylight / the seed's effective phase D_i = 1/(4 pi), "
          "over view elevations -90..90 deg (azimuths 0, 90, 180 deg from the sun) and columns "
          "C = 0, 0.3, 1, 3, 10", ["sky", "phase", "min", "max", "max |error|"], rows)
    # column dependence for HG 0.7 under overcast, per elevation
    rows = []
    sky = SKIES["overcast (1+2cosZ)/3"]
    for el in elevs:
        v = ref.view_direction(0.0, el)
        fp = ref.sky_phase_integral(sky, columns, v, [0.7, 0.0])
        rows.append([f"{el:g}"] + [f"{x:.3f}" for x in fp[:, 0] / fp[:, 1]])
    table("Table P2. HG g=0.7 under the overcast sky: F_HG / F_iso by view elevation (rows) and column C",
          ["elevation"] + [f"C={c:g}" for c in columns], rows)


# ----------------------------------------------------------------------------------------------
# 2. tables


FINE_RULE = ref.HemisphereRule(160, 320)



if __name__ == "__main__":
    section_phase()
