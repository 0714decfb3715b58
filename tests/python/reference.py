"""Independent float64 NumPy reference renderer for airlight's direct-lighting model.

Written from the model's description, not from the shaders:

* pinhole camera, ``fov_y`` the full vertical field of view, aspect ratio from the film,
  one ray through each pixel centre, right-handed and y-up, row 0 the top row;
* Lambertian planes (two-sided), axis-aligned boxes and spheres, the shading normal
  turned to face the camera;
* isotropic point lights of radiant intensity ``I`` drawn as emitting spheres of radius
  ``r`` (radiance ``I / (pi r^2)``) and lighting a surface point at distance ``d`` with
  ``I cos(theta) / max(d^2, r^2) * exp(-sigma_t d)`` when no surface blocks the segment
  from the point to the lamp sphere's surface (length ``d - r``);
* a homogeneous medium attenuating everything seen at distance ``t`` by
  ``exp(-sigma_t t)``; rays that escape see ``background`` on channels with
  ``sigma_t == 0`` and nothing elsewhere.

Besides the radiance, :func:`render_reference` returns a per-pixel hit id (which
surface, box face, lamp or background the pixel's ray hits) and, per light, whether
the light reaches the hit point. :meth:`ReferenceImage.smooth_mask` uses them to pick
the pixels whose whole 3x3 neighbourhood sees the same thing, i.e. pixels away from
geometric edges and shadow boundaries, where a pixel-centre renderer must agree with
this one to float32 accuracy.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

BACKGROUND_ID = -1
SUBPIXEL_CORE_ID = -2  # pixels near a lamp core smaller than a pixel (not modelled here)
LAMP_ID_BASE = 1_000_000
_FACES_PER_SURFACE = 8  # surface id = index * 8 + box face (0..5; 0 for planes and spheres)
_DEFAULT_LAMP_RADIUS = 0.05
_DEFAULT_SURFACE_ALBEDO = 0.5


def _rgb(value: Any, default: float = 0.0) -> np.ndarray:
    if value is None:
        return np.full(3, default, dtype=np.float64)
    arr = np.asarray(value, dtype=np.float64)
    return np.broadcast_to(arr, (3,)).astype(np.float64)


def _vec(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=np.float64).reshape(3)


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@dataclass
class ReferenceImage:
    radiance: np.ndarray  # (H, W, 3) float64
    hit_id: np.ndarray  # (H, W) int64: BACKGROUND_ID, LAMP_ID_BASE + light, or surface * 8 + face
    lit: np.ndarray  # (L, H, W) bool: light l reaches the surface point seen by the pixel
    t_hit: np.ndarray  # (H, W) float64 distance to what the pixel sees (inf for background)

    def smooth_mask(self) -> np.ndarray:
        """Pixels whose 3x3 neighbourhood has one hit id and one lit state for every
        light, away from lamp cores smaller than a pixel (the 1-pixel image border is
        excluded)."""
        h, w = self.hit_id.shape
        keys = [self.hit_id] + [self.lit[i].astype(np.int64) for i in range(self.lit.shape[0])]
        mask = np.zeros((h, w), dtype=bool)
        inner = np.ones((h - 2, w - 2), dtype=bool)
        for key in keys:
            centre = key[1:-1, 1:-1]
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    inner &= key[1 + dy:h - 1 + dy, 1 + dx:w - 1 + dx] == centre
        mask[1:-1, 1:-1] = inner
        return mask & (self.hit_id != SUBPIXEL_CORE_ID)


@dataclass
class _Surface:
    kind: str
    albedo: np.ndarray
    a: np.ndarray  # plane: point, box: min, sphere: centre
    b: np.ndarray  # plane: unit normal, box: max
    radius: float = 0.0


@dataclass
class _Light:
    position: np.ndarray
    intensity: np.ndarray
    radius: float


def _parse(scene: Any) -> dict[str, Any]:
    if isinstance(scene, str):
        scene = json.loads(scene)
    assert isinstance(scene, Mapping)
    medium = scene.get("medium")
    sigma_t = _rgb(medium["sigma_t"]) if medium is not None else np.zeros(3)
    surfaces = []
    for s in scene.get("surfaces", []):
        albedo = _rgb(s.get("albedo"), _DEFAULT_SURFACE_ALBEDO)
        if s["type"] == "plane":
            surfaces.append(_Surface("plane", albedo, _vec(s["point"]), _normalize(_vec(s["normal"]))))
        elif s["type"] == "box":
            surfaces.append(_Surface("box", albedo, _vec(s["min"]), _vec(s["max"])))
        elif s["type"] == "sphere":
            surfaces.append(_Surface("sphere", albedo, _vec(s["center"]), np.zeros(3), float(s["radius"])))
        else:
            raise ValueError(f"reference: unknown surface type {s['type']!r}")
    lights = [
        _Light(_vec(light["position"]), _rgb(light["intensity"]),
               float(light.get("radius", _DEFAULT_LAMP_RADIUS)))
        for light in scene.get("lights", [])
    ]
    return {
        "film": (int(scene["film"]["width"]), int(scene["film"]["height"])),
        "camera": scene["camera"],
        "sigma_t": sigma_t,
        "surfaces": surfaces,
        "lights": lights,
        "background": _rgb(scene.get("background"), 0.0),
    }


def camera_rays(camera: Mapping[str, Any], width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Origin (3,) and unit directions (H, W, 3) of the rays through the pixel centres."""
    position = _vec(camera["position"])
    forward = _normalize(_vec(camera["look_at"]) - position)
    right = _normalize(np.cross(forward, _vec(camera["up"])))
    up = np.cross(right, forward)
    half_height = np.tan(np.radians(float(camera["fov_y"])) / 2.0)
    half_width = half_height * width / height
    # Normalised film coordinates of the pixel centres: x in (-1, 1) left to right,
    # y in (-1, 1) bottom to top; row 0 is the top row.
    u = (np.arange(width) + 0.5) / width * 2.0 - 1.0
    v = 1.0 - (np.arange(height) + 0.5) / height * 2.0
    dirs = (forward[None, None, :]
            + (u[None, :, None] * half_width) * right[None, None, :]
            + (v[:, None, None] * half_height) * up[None, None, :])
    return position, _normalize(dirs)


# --- ray / surface intersection -------------------------------------------------------
# Each takes origins (N, 3) and unit directions (N, 3) and returns the nearest distance
# t > 0 (inf when none), the face index (N,) and the geometric normal (N, 3).

def _intersect_plane(s: _Surface, o: np.ndarray, d: np.ndarray):
    n = s.b
    denom = d @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((s.a - o) @ n) / denom
    t = np.where((denom != 0) & (t > 0), t, np.inf)
    return t, np.zeros(len(o), dtype=np.int64), np.broadcast_to(n, o.shape)


def _intersect_box(s: _Surface, o: np.ndarray, d: np.ndarray):
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (s.a - o) / d
        t2 = (s.b - o) / d
    parallel = d == 0
    inside_slab = (o >= s.a) & (o <= s.b)
    lo = np.where(parallel, np.where(inside_slab, -np.inf, np.inf), np.minimum(t1, t2))
    hi = np.where(parallel, np.where(inside_slab, np.inf, -np.inf), np.maximum(t1, t2))
    t_near = lo.max(axis=1)
    t_far = hi.min(axis=1)
    entering = t_near > 0
    t = np.where(entering, t_near, t_far)
    hit = (t_near <= t_far) & (t > 0)
    axis = np.where(entering, lo.argmax(axis=1), hi.argmin(axis=1))
    idx = np.arange(len(o))
    sign = np.sign(d[idx, axis])
    face = axis * 2 + (sign > 0)
    normal = np.zeros_like(o)
    normal[idx, axis] = 1.0
    return np.where(hit, t, np.inf), face, normal


def _intersect_sphere(s: _Surface, o: np.ndarray, d: np.ndarray):
    oc = o - s.a
    b = np.einsum("ij,ij->i", oc, d)
    c = np.einsum("ij,ij->i", oc, oc) - s.radius ** 2
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t0 = -b - root
    t1 = -b + root
    t = np.where(t0 > 0, t0, np.where(t1 > 0, t1, np.inf))
    t = np.where(disc >= 0, t, np.inf)
    p = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
    return t, np.zeros(len(o), dtype=np.int64), (p - s.a) / s.radius


_INTERSECT = {"plane": _intersect_plane, "box": _intersect_box, "sphere": _intersect_sphere}


def _nearest_surface(surfaces: list[_Surface], o: np.ndarray, d: np.ndarray):
    n = len(o)
    best_t = np.full(n, np.inf)
    best_index = np.full(n, -1, dtype=np.int64)
    best_face = np.zeros(n, dtype=np.int64)
    best_normal = np.zeros((n, 3))
    for i, s in enumerate(surfaces):
        t, face, normal = _INTERSECT[s.kind](s, o, d)
        closer = t < best_t
        best_t = np.where(closer, t, best_t)
        best_index = np.where(closer, i, best_index)
        best_face = np.where(closer, face, best_face)
        best_normal = np.where(closer[:, None], normal, best_normal)
    return best_t, best_index, best_face, best_normal


def _lamp_distance(light: _Light, o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance to the near side of the lamp sphere (inf when missed, behind, or when
    the ray starts inside the lamp)."""
    oc = o - light.position
    b = np.einsum("ij,ij->i", oc, d)
    c = np.einsum("ij,ij->i", oc, oc) - light.radius ** 2
    disc = b * b - c
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (c > 0) & (t > 0), t, np.inf)


def render_reference(scene: Any, width: int | None = None, height: int | None = None) -> ReferenceImage:
    """Renders ``scene`` (dict or JSON text, as accepted by airlight) in float64."""
    sc = _parse(scene)
    w, h = sc["film"]
    w = width if width is not None else w
    h = height if height is not None else h
    origin, dirs = camera_rays(sc["camera"], w, h)
    d = dirs.reshape(-1, 3)
    n = len(d)
    o = np.broadcast_to(origin, d.shape)
    sigma_t = sc["sigma_t"]
    surfaces: list[_Surface] = sc["surfaces"]
    lights: list[_Light] = sc["lights"]

    t_surf, index, face, normal = _nearest_surface(surfaces, o, d)
    t_lamp = np.full(n, np.inf)
    lamp = np.full(n, -1, dtype=np.int64)
    for j, light in enumerate(lights):
        t = _lamp_distance(light, o, d)
        closer = t < t_lamp
        t_lamp = np.where(closer, t, t_lamp)
        lamp = np.where(closer, j, lamp)

    sees_lamp = t_lamp < t_surf
    sees_surface = ~sees_lamp & np.isfinite(t_surf)
    t_hit = np.where(sees_lamp, t_lamp, t_surf)

    radiance = np.zeros((n, 3))
    lit = np.zeros((len(lights), n), dtype=bool)

    # Background: only where it reaches the camera through the medium.
    escaped = ~sees_lamp & ~sees_surface
    radiance[escaped] = np.where(sigma_t > 0, 0.0, sc["background"])

    for j, light in enumerate(lights):
        sel = sees_lamp & (lamp == j)
        radiance[sel] = light.intensity / (np.pi * light.radius ** 2)

    sel = np.nonzero(sees_surface)[0]
    if len(sel):
        p = origin + t_surf[sel, None] * d[sel]
        nrm = normal[sel]
        nrm = np.where((np.einsum("ij,ij->i", nrm, d[sel]) > 0)[:, None], -nrm, nrm)  # face the camera
        albedo = np.stack([surfaces[k].albedo for k in index[sel]])
        shadow_origin = p + (1e-7 * (1.0 + np.abs(p).max(axis=1)))[:, None] * nrm
        irradiance = np.zeros((len(sel), 3))
        for j, light in enumerate(lights):
            to_light = light.position - p
            dist = np.linalg.norm(to_light, axis=1)
            ldir = to_light / dist[:, None]
            cos = np.einsum("ij,ij->i", nrm, ldir)
            blocked = np.zeros(len(sel), dtype=bool)
            for s in surfaces:
                t, _, _ = _INTERSECT[s.kind](s, shadow_origin, ldir)
                blocked |= t < dist - light.radius
            reaches = (cos > 0) & ~blocked
            lit[j, sel] = reaches
            falloff = np.where(reaches, cos, 0.0) / np.maximum(dist ** 2, light.radius ** 2)
            irradiance += (falloff[:, None] * light.intensity[None, :]
                           * np.exp(-sigma_t[None, :] * dist[:, None]))
        radiance[sel] = albedo / np.pi * irradiance

    with np.errstate(invalid="ignore"):
        # t_hit = inf with sigma_t = 0 gives nan; those channels are not attenuated.
        transmittance = np.where(sigma_t[None, :] > 0, np.exp(-sigma_t[None, :] * t_hit[:, None]), 1.0)
    radiance *= transmittance

    hit_id = np.full(n, BACKGROUND_ID, dtype=np.int64)
    hit_id[sees_surface] = index[sees_surface] * _FACES_PER_SURFACE + face[sees_surface]
    hit_id[sees_lamp] = LAMP_ID_BASE + lamp[sees_lamp]
    # Lamps smaller than a pixel are drawn box-filtered around where their centre
    # projects (point_lights_pixel_cores, effects/lamp_airlight/lamp_terms.glsl), which this
    # reference does not model: the 5 x 5 pixels there get SUBPIXEL_CORE_ID, which smooth_mask
    # leaves out.
    hit_id = hit_id.reshape(h, w)
    pixel_angle = 2.0 * math.tan(math.radians(sc["camera"]["fov_y"]) / 2.0) / h
    for light in lights:
        to_lamp = light.position - origin
        best = int(np.argmax(d @ (to_lamp / np.linalg.norm(to_lamp))))
        if float(d[best] @ to_lamp) < np.linalg.norm(to_lamp) * math.cos(2.0 * pixel_angle):
            continue  # outside the picture
        row, col = divmod(best, w)
        hit_id[max(row - 2, 0):row + 3, max(col - 2, 0):col + 3] = SUBPIXEL_CORE_ID
    return ReferenceImage(
        radiance=radiance.reshape(h, w, 3),
        hit_id=hit_id,
        lit=lit.reshape(len(lights), h, w),
        t_hit=t_hit.reshape(h, w),
    )
