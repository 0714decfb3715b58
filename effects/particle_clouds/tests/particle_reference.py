"""An independent float64 compositor of a particle set (the issue's reference for rendered particle
clouds; physics.md section 6): every particle against every pixel's ray (no screen tiles, no early
stop), exact sphere-ray intersections in float64, the particles composited nearest centre first,
each one's light from the table in double precision (airlight._core.ParticleTable.lookup) and the
sky's irradiance of the CIE overcast sky in closed form. No atmosphere: the scene has none."""

from __future__ import annotations

from typing import Any

import numpy as np


def camera_rays(scene: dict[str, Any]) -> np.ndarray:
    """(H, W, 3) unit directions of the pixels' rays, as shaders/geometry.glsl forms them."""
    cam = scene["camera"]
    width, height = scene["film"]["width"], scene["film"]["height"]
    position = np.asarray(cam["position"], float)
    forward = np.asarray(cam["look_at"], float) - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(cam.get("up", [0, 1, 0]), float))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    tan_half = np.tan(0.5 * np.radians(cam.get("fov_y", 60.0)))
    sx = 2.0 * (np.arange(width) + 0.5) / width - 1.0
    sy = 1.0 - 2.0 * (np.arange(height) + 0.5) / height
    d = (forward[None, None, :] + sx[None, :, None] * (tan_half * width / height) * right[None, None, :]
         + sy[:, None, None] * tan_half * up[None, None, :])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def overcast_sky_irradiance(zenith_radiance: np.ndarray) -> np.ndarray:
    """The CIE overcast sky L = Lz (1 + 2 cos Z) / 3 on a horizontal surface: Lz pi (1/3 + 4/9)."""
    return zenith_radiance * np.pi * 7.0 / 9.0


def composite(scene: dict[str, Any], particles: dict[str, np.ndarray], table: Any,
              t_hit: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(the particles' light reaching the camera (H, W, 3), the fraction of the light behind them they
    pass (H, W)); t_hit (H, W): where each ray ends (inf: nowhere)."""
    dirs = camera_rays(scene)
    height, width = dirs.shape[:2]
    origin = np.asarray(scene["camera"]["position"], float)
    sun_dir = np.zeros(3)
    sun_irradiance = np.zeros(3)
    if "sun" in scene:
        el, az = np.radians(scene["sun"]["elevation"]), np.radians(scene["sun"]["azimuth"])
        sun_dir = np.array([np.cos(el) * np.sin(az), np.sin(el), -np.cos(el) * np.cos(az)])
        sun_irradiance = np.broadcast_to(np.asarray(scene["sun"].get("irradiance", 0.0), float), 3)
    sky = np.zeros(3)
    if "sky" in scene:
        assert scene["sky"]["model"] == "overcast"
        sky = overcast_sky_irradiance(np.broadcast_to(np.asarray(scene["sky"]["zenith_radiance"], float), 3))
    centers, radii, taus = particles["center"], particles["radius"], particles["tau"]
    distance = np.linalg.norm(centers - origin, axis=1)
    order = np.lexsort((centers[:, 2], centers[:, 1], centers[:, 0], distance))
    light = np.zeros((height, width, 3))
    through = np.ones((height, width))
    ends = np.full((height, width), np.inf) if t_hit is None else t_hit
    rays = dirs.reshape(-1, 3)
    ends_flat = ends.reshape(-1)
    light_flat = light.reshape(-1, 3)
    through_flat = through.reshape(-1)
    for i in order:
        c, r, tau = centers[i], radii[i], taus[i]
        oc = c - origin
        b = rays @ oc
        h2 = r * r - (oc @ oc - b * b)
        hit = h2 > 0.0
        if not hit.any():
            continue
        idx = np.nonzero(hit)[0]
        h = np.sqrt(h2[idx])
        a = np.maximum(b[idx] - h, 0.0)
        e = np.minimum(b[idx] + h, ends_flat[idx])
        keep = e > a
        idx, h, a, e = idx[keep], h[keep], a[keep], e[keep]
        if idx.size == 0:
            continue
        sigma = tau / r
        opacity = -np.expm1(-sigma * (e - a))
        share = opacity / -np.expm1(-sigma * 2.0 * h)
        own = np.zeros((idx.size, 3))
        if sun_dir[1] > 0 and particles["sun_transmittance"][i] > 0:
            entry = origin + (b[idx] - h)[:, None] * rays[idx]
            normals = (entry - c) / r
            values = table.lookup(np.full(idx.size, tau), normals, rays[idx], sun_dir).sum(axis=1)
            own += sun_irradiance[None, :] * (particles["sun_transmittance"][i] * share * values)[:, None]
        own += sky[None, :] * (particles["sky_visibility"][i] * opacity / (2.0 * np.pi))[:, None]
        light_flat[idx] += through_flat[idx, None] * own
        through_flat[idx] *= 1.0 - opacity
    return light, through
