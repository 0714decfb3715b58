"""Renders the preset scenes shown in the README into docs/images.

    .venv/bin/python benchmarks/render_figures.py [--backend auto]

- foggy_street.png, foggy_street_hg.png: 16 street lamps in isotropic fog
  (exposure 0.1) and in forward-scattering fog (Henyey-Greenstein g = 0.85,
  exposure 0.03), both saved by the demo program (airlight-demo);
- spotlights_crossing.png: the source paper's figure 8, two spotlights
  crossing in media of density 0, 0.01, 0.02 and 0.04 per metre (2 x 2);
- crane_searchlight.png: a crane's searchlight over the foggy street;
- foggy_street_eye.png: the foggy street as the eye sees it (issue 8): the
  display stage with automatic exposure, the double-logarithmic curve and the
  glare of a 4 mm pupil with eyelashes, by the demo;
- approaching_car.png: the headlight experiment (airlight-demo --sequence
  approaching-car), the middle of 9 frames from 2 km to 20 m side by side;
- day_weather.png: the source paper's figure 5 (issue 6): a town with a road,
  fields and buildings on a clear day, in heavy rain and in light rain
  (scenes/day_*.json, each saved by the demo with its own display settings:
  automatic exposure, filmic curve), side by side.
- heavy_rain_multiple_scattering.png: the heavy-rain day (scenes/day_heavy_rain.json, 320 x 180)
  at one fixed exposure (8, filmic curve) with single scattering only (left,
  ``quality.multiple_scattering`` false: what airlight rendered before issue 18) and with
  multiple scattering (right).
- rainbows.png: the source paper's figure 7 (issue 7): after heavy rain and
  after light rain (scenes/rainbow_after_*.json, saved by the demo), side by
  side; rain_ends.png: the end of the heavy shower (airlight-demo --sequence
  rain-ends, 6 frames at 320x200): the sun comes out, the bow appears and
  fades with the drops.
- falling_rain.png: the source paper's figure 6 (issue 23): the night street with the crane's
  searchlight in clear weather (scenes/falling_rain_night_light.json without its falling rain), in
  heavy rain and in light rain (scenes/falling_rain_night_*.json), 480 x 270 at one exposure (the
  clear street's automatic one), above the same frames' left lamp enlarged 3 times.
- light_shafts.png: the light shafts' presets (issue 20; scenes/shafts_*.json, 320 x 180 each):
  each with shafts (left) and with ``quality.shafts`` "off" (right), one row per preset, each
  shown with its scene's display settings.

The first figures use the linear curve (``--tonemap linear``) with the
exposures above, as before the display stage existed.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

import airlight

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"


def demo(scene: str, out: Path, backend: str, *flags: str) -> None:
    """Renders a preset with the demo program (the one next to this Python, else on PATH)."""
    exe = Path(sys.executable).parent / "airlight-demo"
    program = str(exe) if exe.exists() else shutil.which("airlight-demo")
    if program is None:
        raise SystemExit("airlight-demo not found: run scripts/setup.sh")
    subprocess.run([program, "--scene", str(ROOT / "scenes" / f"{scene}.json"), "--out", str(out),
                    "--backend", backend, *flags], check=True)


def approaching_car_strip(backend: str, out: Path) -> None:
    """The headlight experiment's 9 frames (128 x 40 pixels around the car, enlarged twice),
    side by side from 2 km (left) to 20 m (right)."""
    with tempfile.TemporaryDirectory() as tmp:
        demo("approaching_car", Path(tmp), backend, "--sequence", "approaching-car", "--frames", "9")
        tiles = []
        for path in sorted(Path(tmp).glob("frame_*.png")):
            with Image.open(path) as png:
                frame = np.asarray(png.convert("RGB"))
            h, w = frame.shape[:2]
            crop = frame[h // 2 - 20:h // 2 + 20, w // 2 - 64:w // 2 + 64]
            tiles.append(np.asarray(Image.fromarray(crop).resize((256, 80), Image.NEAREST)))
            tiles.append(np.full((80, 4, 3), 60, np.uint8))
    Image.fromarray(np.concatenate(tiles[:-1], axis=1)).save(out)


def day_weather_strip(backend: str, out: Path) -> None:
    """The three daytime presets (clear, heavy rain, light rain), side by side."""
    with tempfile.TemporaryDirectory() as tmp:
        tiles = []
        for name in ("day_clear", "day_heavy_rain", "day_light_rain"):
            demo(name, Path(tmp) / f"{name}.png", backend)
            with Image.open(Path(tmp) / f"{name}.png") as png:
                tiles.append(np.asarray(png.convert("RGB")))
            tiles.append(np.full((tiles[-1].shape[0], 6, 3), 255, np.uint8))
    Image.fromarray(np.concatenate(tiles[:-1], axis=1)).save(out)


def night_street_figures(backend: str) -> None:
    """The foggy street in isotropic and in forward-scattering fog, and as the eye sees it."""
    linear = ("--tonemap", "linear")
    demo("foggy_street", IMAGES / "foggy_street.png", backend, "--exposure", "0.1", *linear)
    demo("foggy_street_hg", IMAGES / "foggy_street_hg.png", backend, "--exposure", "0.03", *linear)
    demo("foggy_street", IMAGES / "foggy_street_eye.png", backend, "--exposure", "auto", "--tonemap",
         "loglog", "--glare", "--pupil", "4", "--eyelashes")


def heavy_rain_before_after(backend: str, out: Path) -> None:
    """day_heavy_rain without and with multiple scattering at the same fixed exposure."""
    tiles = []
    with airlight.Renderer(backend) as r:
        for multiple in (False, True):
            scene = airlight.preset("day_heavy_rain")
            scene["quality"] = {"multiple_scattering": multiple}
            radiance = r.render(scene, width=320, height=180)
            tiles.append(airlight.display(radiance, exposure=8.0, tonemap="filmic"))
            tiles.append(np.full((tiles[-1].shape[0], 6, 3), 255, np.uint8))
    Image.fromarray(np.concatenate(tiles[:-1], axis=1)).save(out)


def rainbow_figures(backend: str, out: Path, sequence_out: Path) -> None:
    """The two figure-7 presets side by side, and the rain-ends sequence as a strip."""
    with tempfile.TemporaryDirectory() as tmp:
        tiles = []
        for name in ("rainbow_after_heavy_rain", "rainbow_after_light_rain"):
            demo(name, Path(tmp) / f"{name}.png", backend)
            with Image.open(Path(tmp) / f"{name}.png") as png:
                tiles.append(np.asarray(png.convert("RGB")))
            tiles.append(np.full((tiles[-1].shape[0], 6, 3), 255, np.uint8))
        Image.fromarray(np.concatenate(tiles[:-1], axis=1)).save(out)
        frames = Path(tmp) / "frames"
        demo("rainbow_after_heavy_rain", frames, backend, "--sequence", "rain-ends", "--frames", "6",
             "--width", "320", "--height", "200")
        tiles = []
        for path in sorted(frames.glob("frame_*.png")):
            with Image.open(path) as png:
                tiles.append(np.asarray(png.convert("RGB")))
            tiles.append(np.full((tiles[-1].shape[0], 4, 3), 255, np.uint8))
        Image.fromarray(np.concatenate(tiles[:-1], axis=1)).save(sequence_out)


def light_shafts_figure(backend: str, out: Path) -> None:
    """Each light-shafts preset with and without shafts, a row each (the lamps' presets
    toggle their lights' volumetric_shadows)."""
    rows = []
    with airlight.Renderer(backend) as r:
        for name in ("shafts_low_sun", "shafts_sun_behind", "shafts_rain_rainbow", "shafts_lamp_alley"):
            tiles = []
            for shafts in ("analytic", "off"):
                scene = airlight.preset(name)
                scene.setdefault("quality", {})["shafts"] = shafts
                for light in scene.get("lights", []):
                    light["volumetric_shadows"] = shafts != "off" and light.get("volumetric_shadows", False)
                tiles.append(airlight.display_scene(r.render(scene, width=320, height=180), scene))
                tiles.append(np.full((tiles[-1].shape[0], 6, 3), 255, np.uint8))
            rows.append(np.concatenate(tiles[:-1], axis=1))
            rows.append(np.full((6, rows[-1].shape[1], 3), 255, np.uint8))
    Image.fromarray(np.concatenate(rows[:-1], axis=0)).save(out)


def clouds_figure(backend: str, out: Path) -> None:
    """Each noise-clouds preset, with multiple scattering's octaves (left) and single scattering
    (right), a row each."""
    rows = []
    with airlight.Renderer(backend) as r:
        for name in ("clouds_cumulus_town", "clouds_flythrough", "clouds_sunset_above",
                     "clouds_overcast_rain"):
            tiles = []
            for multiple in (True, False):
                scene = airlight.preset(name)
                scene.setdefault("quality", {})["multiple_scattering"] = multiple
                tiles.append(airlight.display_scene(r.render(scene, width=320, height=180), scene))
                tiles.append(np.full((tiles[-1].shape[0], 6, 3), 255, np.uint8))
            rows.append(np.concatenate(tiles[:-1], axis=1))
            rows.append(np.full((6, rows[-1].shape[1], 3), 255, np.uint8))
    Image.fromarray(np.concatenate(rows[:-1], axis=0)).save(out)


def falling_rain_figure(backend: str, out: Path) -> None:
    """Figure 6: the night street clear, in heavy rain and in light rain, one exposure; below, the
    region around the nearest left lamp of each, enlarged 3 times."""
    clear = airlight.preset("falling_rain_night_light")
    del clear["falling_rain"]
    scenes = [clear, airlight.preset("falling_rain_night_heavy"), airlight.preset("falling_rain_night_light")]
    with airlight.Renderer(backend) as r:
        images = [r.render(scene, width=480, height=270) for scene in scenes]
    exposure = airlight.auto_exposure(images[0])
    shown = [airlight.display(image, exposure=exposure, dither=False) for image in images]
    crops = [np.kron(s[30:120, 40:200], np.ones((3, 3, 1), np.uint8))[:, :480] for s in shown]
    gap = np.full((270, 6, 3), 255, np.uint8)
    top = np.concatenate([shown[0], gap, shown[1], gap, shown[2]], axis=1)
    gap = np.full((crops[0].shape[0], 6, 3), 255, np.uint8)
    bottom = np.concatenate([crops[0], gap, crops[1], gap, crops[2]], axis=1)
    between = np.full((6, top.shape[1], 3), 255, np.uint8)
    Image.fromarray(np.concatenate([top, between, bottom], axis=0)).save(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--backend", default="auto")
    ap.add_argument("--only", choices=["rainbows", "daytime", "night", "shafts", "clouds", "falling_rain"],
                    help="render only these figures")
    args = ap.parse_args()
    IMAGES.mkdir(parents=True, exist_ok=True)
    if args.only == "night":
        night_street_figures(args.backend)
        return
    if args.only == "shafts":
        light_shafts_figure(args.backend, IMAGES / "light_shafts.png")
        return
    if args.only == "falling_rain":
        falling_rain_figure(args.backend, IMAGES / "falling_rain.png")
        return
    if args.only == "clouds":
        clouds_figure(args.backend, IMAGES / "noise_clouds.png")
        return
    if args.only == "daytime":
        day_weather_strip(args.backend, IMAGES / "day_weather.png")
        heavy_rain_before_after(args.backend, IMAGES / "heavy_rain_multiple_scattering.png")
        return
    rainbow_figures(args.backend, IMAGES / "rainbows.png", IMAGES / "rain_ends.png")
    if args.only == "rainbows":
        return
    night_street_figures(args.backend)
    approaching_car_strip(args.backend, IMAGES / "approaching_car.png")
    day_weather_strip(args.backend, IMAGES / "day_weather.png")
    heavy_rain_before_after(args.backend, IMAGES / "heavy_rain_multiple_scattering.png")
    light_shafts_figure(args.backend, IMAGES / "light_shafts.png")
    clouds_figure(args.backend, IMAGES / "noise_clouds.png")
    with airlight.Renderer(args.backend) as r:
        tiles = []
        for density in ("000", "001", "002", "004"):
            radiance = r.render(airlight.preset(f"spotlights_crossing_{density}"), width=320, height=180)
            tiles.append(airlight.to_srgb8(radiance, 2.0))
        grid = np.concatenate([np.concatenate(tiles[:2], axis=1), np.concatenate(tiles[2:], axis=1)], axis=0)
        Image.fromarray(grid).save(IMAGES / "spotlights_crossing.png")
        crane = r.render(airlight.preset("crane_searchlight"))
        airlight.save_png(IMAGES / "crane_searchlight.png", crane, exposure=0.1)
    print(f"wrote {IMAGES}/foggy_street.png, foggy_street_hg.png, spotlights_crossing.png, "
          "crane_searchlight.png, foggy_street_eye.png, approaching_car.png, day_weather.png, "
          "heavy_rain_multiple_scattering.png, rainbows.png, "
          "rain_ends.png")


if __name__ == "__main__":
    main()
