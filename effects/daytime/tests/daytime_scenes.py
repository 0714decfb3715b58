"""Daytime scene builders for the render tests (issue 6) and their translation into the independent
float64 reference of daytime_reference.py (the same model: the sky dome enters at the top of the
atmosphere, single scattering, flat ground at y = 0)."""

from __future__ import annotations

import math

import daytime_reference as ref
import numpy as np
import reference

import airlight

OVERCAST = {"model": "overcast", "zenith_radiance": [1.0, 1.0, 1.0]}
CLEAR = {"model": "cie", "type": 12, "zenith_radiance": [0.5, 0.75, 1.2]}
SUN30 = {"elevation": 30.0, "azimuth": 20.0, "irradiance": [3.0, 3.0, 3.0]}

# Gauss-Legendre nodes per panel of the reference's view-ray rule (its default is 24). On the
# graded panels (each 1.5 times the previous) 8 nodes gave the same pixels as 24 to 3e-7 relative
# (mostly 1e-14) on every ray of the sweeps of test_daytime_render.py, at half the cost.
REFERENCE_NODES = 8


def cie_sky(sky_type: int, lz=(1.0, 1.0, 1.0)) -> dict:
    return {"model": "cie", "type": sky_type, "zenith_radiance": list(lz)}


def sun(elevation: float, azimuth: float = 0.0, irradiance: float = 5.0) -> dict:
    return {"elevation": elevation, "azimuth": azimuth, "irradiance": [irradiance] * 3}


def atmosphere(molecules: bool = True, visibility: float | None = None, rain: float = 0.0,
               scale_height: float = 1000.0) -> dict:
    """The scene's "atmosphere": molecules at density 1, an aerosol of that visibility (g 0.7,
    albedo 0.9) and rain at that rate (default top and g)."""
    out: dict = {}
    if molecules:
        out["molecules"] = {"density_scale": 1}
    if visibility is not None:
        out["aerosol"] = {"visibility": visibility, "scale_height": scale_height, "g": 0.7, "albedo": 0.9}
    if rain > 0.0:
        out["rain"] = {"rate": rain, "phase": "hg"}
    return out


def day_scene(*, sky: dict | None = OVERCAST, sun: dict | None = None, atmosphere: dict | None = None,
              camera_y: float = 1.7, pitch: float = 0.0, fov: float = 90.0, width: int = 1, height: int = 12,
              ground: float | None = None, multiple_scattering: bool = False, **extra) -> dict:
    """A camera at altitude camera_y looking along -z tilted up by `pitch` degrees (straight up or
    down: the film's up is -z). `ground`: the albedo of a Lambertian plane at y = 0 (None: no
    surface, rays below the horizon end on the black ground). With pitch 0 and an odd height the
    middle row is exactly horizontal. These scenes check single scattering against its quadrature
    reference, so multiple scattering is off unless asked for (``quality`` in ``extra`` adds to it)."""
    p = math.radians(pitch)
    up = [0.0, 0.0, -1.0] if abs(pitch) > 89.9 else [0.0, 1.0, 0.0]
    camera = {"position": [0.0, camera_y, 0.0], "look_at": [0.0, camera_y + math.sin(p), -math.cos(p)],
              "up": up, "fov_y": fov}
    scene = {"film": {"width": width, "height": height}, "camera": camera}
    if sky is not None:
        scene["sky"] = sky
    if sun is not None:
        scene["sun"] = sun
    if atmosphere is not None:
        scene["atmosphere"] = atmosphere
    if ground is not None:
        scene["surfaces"] = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "albedo": ground}]
    quality = {"multiple_scattering": multiple_scattering, **extra.pop("quality", {})}
    scene.update(extra)
    scene["quality"] = quality
    return scene


def reference_sky(scene: dict) -> ref.Sky:
    sky, sun_ = scene.get("sky"), scene.get("sun") or {}
    cie = 0 if sky is None or sky["model"] == "overcast" else sky["type"]
    lz = tuple(sky["zenith_radiance"]) if sky is not None else (0.0, 0.0, 0.0)
    return ref.Sky(cie, lz, sun_.get("azimuth", 0.0), sun_.get("elevation", 30.0),
                   tuple(sun_.get("irradiance", (0.0, 0.0, 0.0))))


def reference_atmosphere(scene: dict) -> ref.Atmosphere:
    a = scene.get("atmosphere") or {}
    molecules = a.get("molecules")
    if molecules is not None:
        assert molecules.get("density_scale", 1) == 1, "the reference has molecules at density 1 only"
    aerosol = a.get("aerosol")
    rain = a.get("rain")
    if aerosol is not None:
        assert "coefficient" not in aerosol, "the reference takes the aerosol by its visibility"
    return ref.make_atmosphere(
        rain_rate=rain["rate"] if rain else 0.0,
        visibility=aerosol["visibility"] if aerosol else None, molecules=molecules is not None,
        aerosol_g=aerosol.get("g", ref.AEROSOL_G) if aerosol else ref.AEROSOL_G,
        aerosol_albedo=aerosol.get("albedo", ref.AEROSOL_ALBEDO) if aerosol else ref.AEROSOL_ALBEDO,
        aerosol_scale_height=aerosol.get("scale_height", ref.AEROSOL_SCALE_HEIGHT) if aerosol
        else ref.AEROSOL_SCALE_HEIGHT,
        rain_top=rain.get("top", ref.RAIN_TOP) if rain else ref.RAIN_TOP,
        rain_g=rain.get("g", ref.RAIN_G) if rain else ref.RAIN_G,
        rain_density_scale=rain.get("density_scale", 1.0) if rain else 1.0,
        rain_sun_phase=_rainbow_sun_phase(scene) if rain and rain.get("phase", "mie") == "mie" else None)


def _rainbow_sun_phase(scene: dict):
    """The rain's phase for sunlight that a "mie" rain uses: the library's rainbow table (an
    input of the reference, like the scene; its accuracy is tested in test_rainbow.py)."""
    rain = scene["atmosphere"]["rain"]
    n = (scene.get("quality") or {}).get("rainbow_wavelengths", 33)

    def sun_phase(cos_theta: float) -> np.ndarray:
        angle = math.degrees(math.acos(max(-1.0, min(1.0, cos_theta))))
        return airlight.rainbow_phase(rain["rate"], [angle], wavelengths=n)[0].astype(float)

    return sun_phase


def scene_directions(scene: dict) -> np.ndarray:
    """Unit directions (H, W, 3) of the scene's pixel centres (reference.camera_rays)."""
    return reference.camera_rays(scene["camera"], scene["film"]["width"], scene["film"]["height"])[1]


def reference_column(scene: dict, column: int = 0) -> np.ndarray:
    """Reference radiance (H, 3) of one image column (ref.view_ray_gauss per pixel)."""
    dirs = scene_directions(scene)[:, column]
    sky, atm = reference_sky(scene), reference_atmosphere(scene)
    ground = float(scene["surfaces"][0]["albedo"]) if "surfaces" in scene else 0.0
    camera_y = float(scene["camera"]["position"][1])
    return np.array([ref.view_ray_gauss(atm, sky, camera_y, d, ground_albedo=ground, nodes=REFERENCE_NODES)
                     for d in dirs])


def relative_error(image: np.ndarray, expected: np.ndarray, floor_fraction: float = 1e-3) -> float:
    """Largest relative error over the channel values above floor_fraction of the expected maximum."""
    image = np.asarray(image, dtype=float)
    expected = np.asarray(expected, dtype=float)
    assert image.shape == expected.shape, (image.shape, expected.shape)
    floor = floor_fraction * float(expected.max())
    mask = expected > floor
    assert mask.any()
    return float((np.abs(image - expected)[mask] / expected[mask]).max())
