"""Weather on real images (issue 26): a photograph with a depth map gets the
renderer's exact media and lamps along each pixel's ray up to its depth.

The photo's linear radiance and its depth end each camera ray in place of the
scene's surfaces (effects/photo/physics.md); the homogeneous ``medium``, its
constant ``atmospheric_light`` (Koschmieder's A), the daytime ``atmosphere``
with its ``sky`` and ``sun``, and the ``lights`` then apply to it exactly as
in a render. See :func:`apply_weather`; :func:`read_depth` reads the common
depth encodings.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._display import to_srgb8
from ._image_io import load_exr
from ._rendering import LAYERS, Renderer

WEATHER_KEYS = ("medium", "atmospheric_light", "atmosphere", "sky", "sun", "background", "quality")
"""The keys of ``weather``: the scene's own objects of these names."""

DEPTH_KINDS = ("ray", "z")
"""``"ray"``: metres along each pixel's ray; ``"z"``: along the optical axis (a z-buffer)."""

DEPTH_ENCODINGS = ("png16", "kitti", "exr", "npy")
"""The encodings :func:`read_depth` reads."""


@dataclass
class WeatheredImage:
    """What :func:`apply_weather` returns; arrays (H, W, 3) float32 unless said.

    ``linear``: the weathered radiance (the photo's units); ``display``: it as
    8-bit sRGB (uint8, times ``exposure``, clipped); ``transmittance``: the
    fraction of the photo's light that reaches the camera, per channel;
    ``inscattered``: the light the media and lamps add along the ray (``linear``
    is ``photo * transmittance + inscattered``); ``outputs``: every render output
    asked for, by name (``airlight.OUTPUTS``).
    """

    linear: np.ndarray
    display: np.ndarray
    transmittance: np.ndarray
    inscattered: np.ndarray
    outputs: dict[str, np.ndarray] = field(default_factory=dict)


def srgb8_to_linear(image: np.ndarray) -> np.ndarray:
    """Linear float32 values in [0, 1] of an 8-bit sRGB image (IEC 61966-2-1)."""
    c = np.asarray(image).astype(np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def read_depth(path: str | os.PathLike[str], encoding: str = "png16", *, scale: float = 1.0 / 256.0,
               invalid: float | None = 0.0, channel: str | None = None) -> np.ndarray:
    """Depth in metres, float32 (H, W), from a file; +inf where it is invalid.

    ``encoding``: ``"png16"``, a 16-bit PNG of ``value * scale`` metres;
    ``"kitti"``, the same with KITTI's scale 1/256; ``"exr"``, a float EXR
    (through :func:`airlight.load_exr`; ``channel`` names its channel, default
    the file's single one, ``depth`` or ``Z``); ``"npy"``, a NumPy array. Pixels
    equal to ``invalid`` (KITTI's and most 16-bit formats' 0: no measurement;
    None: none) become +inf, a ray that escapes (sky).
    """
    if encoding not in DEPTH_ENCODINGS:
        raise ValueError(f"encoding: unknown depth encoding {encoding!r}; "
                         f"one of {', '.join(DEPTH_ENCODINGS)}")
    if encoding == "kitti":
        encoding, scale = "png16", 1.0 / 256.0
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise ValueError(f"scale: must be finite and > 0, got {scale!r}")
    if encoding == "png16":
        from PIL import Image

        with Image.open(path) as im:
            raw = np.asarray(im)
        if raw.ndim != 2 or raw.dtype not in (np.uint16, np.int32, np.uint8):
            raise ValueError(f"path: {os.fspath(path)} is not a single-channel 16-bit PNG (mode {raw.dtype}, "
                             f"shape {raw.shape})")
        values = raw.astype(np.float64)
        depth = values * scale
    elif encoding == "npy":
        values = np.load(path).astype(np.float64)
        depth = values * 1.0
    else:
        images = load_exr(path)
        if channel is None:
            names: list[str] = [n for n in ("depth", "Z") if n in images]
            if not names and len(images) == 1:
                names = [*images]
            if not names:
                raise ValueError(f"channel: {os.fspath(path)} has {', '.join(images)}; "
                                 "say which holds the depth")
            channel = names[0]
        if channel not in images:
            raise ValueError(f"channel: no {channel!r} in {os.fspath(path)} (it has {', '.join(images)})")
        values = images[channel].astype(np.float64)
        depth = values * 1.0
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth, values = depth[:, :, 0], values[:, :, 0]
    if depth.ndim != 2:
        raise ValueError(f"path: expected a single-channel depth map, got shape {depth.shape}")
    if invalid is not None:
        depth = np.where(values == invalid, np.inf, depth)
    return depth.astype(np.float32)


def save_depth_png16(path: str | os.PathLike[str], depth: np.ndarray, scale: float = 1.0 / 256.0) -> None:
    """Writes depth (metres; +inf: none) as a 16-bit PNG of round(depth / scale), 0 where
    there is none or it exceeds the 16-bit range (the inverse of :func:`read_depth`)."""
    from PIL import Image

    d = np.asarray(depth, dtype=np.float64) / scale
    d = np.where(np.isfinite(d) & (d < 65535.5), np.round(d), 0)
    Image.fromarray(d.astype(np.uint16)).save(path)


def _image(image: Any) -> np.ndarray:
    a = np.asarray(image)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"image: expected shape (H, W, 3), got {a.shape}")
    if a.dtype == np.uint8:
        return srgb8_to_linear(a)
    if not np.issubdtype(a.dtype, np.floating):
        raise TypeError(f"image: expected uint8 (sRGB) or float (linear), got {a.dtype}")
    a = a.astype(np.float32)
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError("image: linear values must be finite and >= 0")
    return a


def _depth(depth: Any, shape: tuple[int, int], mask: Any) -> np.ndarray:
    d = np.asarray(depth)
    if d.ndim == 3 and d.shape[2] == 1:
        d = d[:, :, 0]
    if not (np.issubdtype(d.dtype, np.floating) or np.issubdtype(d.dtype, np.integer)):
        raise TypeError(f"depth: expected a numeric array, got {d.dtype}")
    if d.shape != shape:
        raise ValueError(f"depth: shape {d.shape} does not match the image's {shape}")
    d = d.astype(np.float32)
    if np.any(np.isnan(d)):
        raise ValueError("depth: contains NaN (mark pixels without depth with +inf or `mask`)")
    if np.any(d < 0):
        raise ValueError("depth: must be >= 0 metres (+inf: no depth, the ray escapes)")
    if mask is not None:
        m = np.asarray(mask)
        if m.shape != shape:
            raise ValueError(f"mask: shape {m.shape} does not match the image's {shape}")
        d = np.where(m.astype(bool), np.inf, d).astype(np.float32)
    return d


def _camera(camera: Any, width: int, height: int) -> tuple[dict[str, Any], list[float] | None]:
    """(the scene's camera, the intrinsics fx, fy, cx, cy or None for the pinhole of fov_y)."""
    pose: dict[str, Any] = {"position": [0.0, 1.7, 0.0], "look_at": [0.0, 1.7, -10.0], "up": [0.0, 1.0, 0.0]}
    spec: Any = camera
    if isinstance(camera, dict):
        unknown = set(camera) - {"fov_y", "intrinsics", "position", "look_at", "up"}
        if unknown:
            raise ValueError(f"camera: unknown key {sorted(unknown)[0]!r}; expected fov_y or intrinsics, "
                             "position, look_at, up")
        pose.update({k: camera[k] for k in ("position", "look_at", "up") if k in camera})
        if ("fov_y" in camera) == ("intrinsics" in camera):
            raise ValueError("camera: needs exactly one of fov_y (degrees) and intrinsics (3x3)")
        spec = camera.get("fov_y", camera.get("intrinsics"))
    if isinstance(spec, bool) or spec is None:
        raise TypeError("camera: expected a vertical field of view in degrees, a 3x3 intrinsics matrix "
                        "or a dict")
    if isinstance(spec, (int, float)):
        if not (math.isfinite(spec) and 0 < spec < 180):
            raise ValueError(f"camera: the field of view must be in (0, 180) degrees, got {spec!r}")
        return {**pose, "fov_y": float(spec)}, None
    k = np.asarray(spec, dtype=np.float64)
    if k.shape != (3, 3):
        raise ValueError("camera: expected a vertical field of view or a 3x3 intrinsics matrix, "
                         f"got shape {k.shape}")
    fx, fy, cx, cy = k[0, 0], k[1, 1], k[0, 2], k[1, 2]
    if not np.all(np.isfinite(k)) or fx <= 0 or fy <= 0:
        raise ValueError("camera: intrinsics need finite fx, fy > 0")
    if k[0, 1] != 0 or k[1, 0] != 0 or k[2, 0] != 0 or k[2, 1] != 0 or k[2, 2] != 1:
        raise ValueError("camera: intrinsics must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)")
    fov_y = math.degrees(2.0 * math.atan(0.5 * height / fy))
    return {**pose, "fov_y": fov_y}, [float(fx), float(fy), float(cx), float(cy)]


def weather_scene(weather: dict[str, Any] | None, lights: list[dict[str, Any]] | None, camera: dict[str, Any],
                  width: int, height: int) -> dict[str, Any]:
    """The scene :func:`apply_weather` renders: the film and camera of the photo,
    no surfaces (the photo ends the rays), ``weather``'s objects and ``lights``."""
    weather = {} if weather is None else weather
    if not isinstance(weather, dict):
        raise TypeError(f"weather: expected a dict of {', '.join(WEATHER_KEYS)}, "
                        f"got {type(weather).__name__}")
    for key in weather:
        if key not in WEATHER_KEYS:
            raise ValueError(f"weather: unknown key {key!r}; expected some of {', '.join(WEATHER_KEYS)}")
    if lights is not None and not isinstance(lights, list):
        raise TypeError(f"lights: expected a list of lights, got {type(lights).__name__}")
    return {"film": {"width": width, "height": height}, "camera": camera, "surfaces": [],
            "lights": list(lights or []), **weather}


def apply_weather(image: Any, depth: Any, camera: Any, weather: dict[str, Any] | None = None,
                  lights: list[dict[str, Any]] | None = None, *, depth_kind: str = "ray", mask: Any = None,
                  backend: str = "auto", renderer: Renderer | None = None, exposure: float = 1.0,
                  outputs: list[str] | tuple[str, ...] = ()) -> WeatheredImage:
    """Weather on a photograph with its depth, with the renderer's exact models.

    ``image``: (H, W, 3), 8-bit sRGB (decoded to linear, in [0, 1]) or linear
    float. ``depth``: (H, W) metres, along each pixel's ray (``depth_kind="ray"``)
    or along the optical axis (``"z"``); +inf (or ``mask`` True) where there is
    none (sky): the ray escapes, e.g. through an endless fog. ``camera``: the
    vertical field of view in degrees, a 3x3 intrinsics matrix (fx, fy and the
    principal point used exactly, no skew), or a dict with one of ``fov_y`` and
    ``intrinsics`` and the pose ``position``, ``look_at``, ``up`` in the scene's
    frame (default: 1.7 m above the ground y = 0, looking along -z, as the scene
    format's camera). ``weather``: the scene's ``medium`` (with ``visibility`` or
    ``sigma_t``), ``atmospheric_light`` (Koschmieder's A: with a homogeneous
    medium and nothing else the result is ``I t + A (1 - t)``), ``atmosphere``,
    ``sky``, ``sun``, ``background``, ``quality``; ``lights``: the scene's
    ``lights`` in the camera's frame (their airlight ends at each pixel's depth;
    they do not light the photo's surfaces). ``outputs``: more render outputs to
    return (``airlight.OUTPUTS``, e.g. ``"lamps"``, ``"depth"``).
    Bad arguments raise ``TypeError``/``ValueError`` naming the argument.
    """
    linear_in = _image(image)
    height, width = linear_in.shape[:2]
    d = _depth(depth, (height, width), mask)
    if depth_kind not in DEPTH_KINDS:
        raise ValueError(f"depth_kind: expected 'ray' or 'z', got {depth_kind!r}")
    cam, intrinsics = _camera(camera, width, height)
    scene = weather_scene(weather, lights, cam, width, height)
    names = ["radiance", "transmittance", *LAYERS]
    names += [o for o in dict.fromkeys(outputs) if o not in names]
    backplate = np.ascontiguousarray(np.concatenate([linear_in, d[:, :, None]], axis=2), dtype=np.float32)
    own = renderer is None
    r = Renderer(backend) if renderer is None else renderer
    try:
        out = r._active().render_outputs(scene, names, backplate, depth_kind == "z", intrinsics)
    finally:
        if own:
            r.close()
    linear = out["radiance"]
    return WeatheredImage(linear=linear, display=to_srgb8(linear, exposure),
                          transmittance=out["transmittance"],
                          inscattered=sum((out[n] for n in LAYERS if n != "surfaces"), np.zeros_like(linear)),
                          outputs=out)


def _read_image(path: str) -> np.ndarray:
    """An image file as apply_weather takes it: 8-bit sRGB (PNG, JPEG, ...) or linear float
    (the radiance of an EXR, a .npy array)."""
    if path.lower().endswith(".exr"):
        return load_exr(path)["radiance"]
    if path.lower().endswith(".npy"):
        return np.asarray(np.load(path))
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("RGB"))


def _read_json(path: str | None, what: str) -> Any:
    if path is None:
        return None
    import json

    try:
        with open(path) as f:
            return json.load(f)
    except OSError as e:
        raise ValueError(f"{what}: cannot read {path}: {e.strerror}") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"{what}: {path}: invalid JSON at line {e.lineno}, column {e.colno}: "
                         f"{e.msg}") from None


def main(argv: list[str] | None = None) -> int:
    """``airlight-photo IMAGE DEPTH --out OUT``: the command-line form of
    :func:`apply_weather`. OUT.png: the weathered image, displayed; OUT.exr: its linear
    radiance with the transmittance, the in-scattered light and the layers as channels.
    Exit status 2 and one line on stderr for bad input."""
    import argparse
    import sys

    ap = argparse.ArgumentParser(prog="airlight-photo", description=main.__doc__)
    ap.add_argument("image", help="the photo: 8-bit sRGB (PNG, JPEG) or linear float (EXR, NPY)")
    ap.add_argument("depth", help="its depth map (see --depth-encoding)")
    ap.add_argument("--out", required=True, help="OUT.png (displayed) or OUT.exr (linear, with the maps)")
    cam = ap.add_mutually_exclusive_group(required=True)
    cam.add_argument("--fov", type=float, help="vertical field of view, degrees")
    cam.add_argument("--intrinsics", help="fx,fy,cx,cy in pixels")
    ap.add_argument("--depth-encoding", default="png16", choices=DEPTH_ENCODINGS)
    ap.add_argument("--depth-scale", type=float, default=1.0 / 256.0, help="metres per unit of a 16-bit PNG")
    ap.add_argument("--depth-kind", default="ray", choices=DEPTH_KINDS)
    ap.add_argument("--weather", help="a JSON file of the scene's weather objects (WEATHER_KEYS)")
    ap.add_argument("--lights", help="a JSON file: a list of the scene's lights, in the camera's frame")
    ap.add_argument("--exposure", type=float, default=1.0, help="for the PNG")
    ap.add_argument("--backend", default="auto", choices=("auto", "gl", "cpu"))
    args = ap.parse_args(argv)
    try:
        if not args.out.lower().endswith((".png", ".exr")):
            raise ValueError(f"--out: must end in .png or .exr, got {args.out!r}")
        camera: Any = args.fov
        if args.intrinsics is not None:
            try:
                fx, fy, cx, cy = (float(v) for v in args.intrinsics.split(","))
            except ValueError:
                raise ValueError(f"--intrinsics: expected fx,fy,cx,cy, got {args.intrinsics!r}") from None
            camera = [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]
        image = _read_image(args.image)
        depth = read_depth(args.depth, args.depth_encoding, scale=args.depth_scale)
        out = apply_weather(image, depth, camera, _read_json(args.weather, "--weather"),
                            _read_json(args.lights, "--lights"), depth_kind=args.depth_kind,
                            backend=args.backend, exposure=args.exposure)
        if args.out.lower().endswith(".png"):
            from PIL import Image

            Image.fromarray(out.display, mode="RGB").save(args.out, format="PNG")
        else:
            from ._image_io import save_exr

            save_exr(args.out, {"radiance": out.linear, "transmittance": out.transmittance,
                                "inscattered": out.inscattered,
                                **{n: out.outputs[n] for n in LAYERS}})
    except (TypeError, ValueError, OSError) as e:
        print(f"airlight-photo: {e}", file=sys.stderr)
        return 2
    print(f"airlight-photo: {args.out} {out.linear.shape[1]}x{out.linear.shape[0]}")
    return 0


__all__ = ["DEPTH_ENCODINGS", "DEPTH_KINDS", "WEATHER_KEYS", "WeatheredImage", "apply_weather", "read_depth",
           "save_depth_png16", "srgb8_to_linear", "weather_scene"]
