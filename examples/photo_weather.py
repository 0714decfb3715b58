"""Weather on an image with its depth (airlight.photo, issue 26).

The pair in examples/photo/ is made by the project itself (make_pair): a
160x90 clear-air render of the foggy_street preset, as an 8-bit sRGB PNG, and
its depth along each ray as a 16-bit PNG of depth * 256 (KITTI's encoding; 0:
no depth, the sky). This script reads them back as any photo would be read,
adds a night fog of 120 m visibility with a faint atmospheric light and the
street's lamps, and writes the before/after picture docs/images/photo_weather.png.

    .venv/bin/python examples/photo_weather.py [--make-pair]
"""

import sys
from pathlib import Path

import numpy as np
from PIL import Image

import airlight
from airlight import photo

HERE = Path(__file__).resolve().parent / "photo"
EXPOSURE = 0.3
ROOT = Path(__file__).resolve().parents[1]


def make_pair() -> None:
    scene = airlight.preset("foggy_street")
    scene["medium"] = None
    out = airlight.render(scene, "cpu", width=160, height=90, outputs=["radiance", "depth"])
    Image.fromarray(airlight.to_srgb8(out["radiance"], exposure=EXPOSURE)).save(HERE / "street.png")
    photo.save_depth_png16(HERE / "street_depth.png", out["depth"], scale=1.0 / 256.0)


def main() -> None:
    if "--make-pair" in sys.argv:
        make_pair()
    image = np.asarray(Image.open(HERE / "street.png").convert("RGB"))
    depth = photo.read_depth(HERE / "street_depth.png", "kitti")  # 0 (no depth) -> +inf
    scene = airlight.preset("foggy_street")
    # The photo was shown at EXPOSURE: its linear values are radiance * EXPOSURE, so the lamps are too.
    lights = [{**light, "intensity": [EXPOSURE * c for c in light["intensity"]]} for light in scene["lights"]]
    weather = {"medium": {"visibility": 120.0, "albedo": 0.9},
               "atmospheric_light": [0.02, 0.02, 0.025]}
    out = photo.apply_weather(image, depth, scene["camera"], weather, lights, backend="cpu")
    before_after = np.concatenate([image, out.display], axis=1)
    picture = Image.fromarray(before_after).resize((2 * 320, 180), Image.NEAREST)
    picture.save(ROOT / "docs/images/photo_weather.png")
    print("mean transmittance", float(out.transmittance.mean()),
          "mean in-scattered", float(out.inscattered.mean()))


if __name__ == "__main__":
    main()
