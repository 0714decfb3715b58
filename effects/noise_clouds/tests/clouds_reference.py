"""Independent float64 numpy reference for the noise clouds (effects/noise_clouds/physics.md
sections 1-3): the density field of two tiling noise textures, the clouds' transmittance toward a
light, and the sunlight and skylight the layer scatters once toward the camera.

Independent of the renderer: no ``airlight`` import. It reads the scene dict itself and takes the
two noise textures as arrays (shape (n, n, n, 4) indexed [k, j, i, channel], texel i along x, j
along y, k along z); the tests get them from ``airlight._core.cloud_noise_textures(seed)``. The
camera, the first surface hit, the sun's direction and the homogeneous medium are read by
effects/light_shafts/tests/shafts_reference.py, the CIE sky's radiance by
effects/daytime/tests/daytime_reference.py (both float64 references of their own).

What is computed (physics.md; none of section 4's shortcuts):

* Density d(p) by eqs. 2.1-2.4 exactly, the textures sampled by eq. 1.1 (periodic trilinear between
  texel centres) in float64; sigma_t = extinction d.
* Clouds' transmittance T_c(p, w) = exp(-int sigma_t(p + u w) du) (eq. 3.2) by a midpoint rule of
  ``light_steps`` EQUAL steps from p to where the half-line leaves the slab in which d can be
  nonzero.
* The layer's light (the second term of eq. 3.3 over the view ray's part inside the layer)

      L = int_{t_in}^{t_out} T(0, t) J(x(t)) dt,
      J = albedo sigma_t [E_sun T_c(x, s) p_HG(s . d, g) + E_sky / (2 pi) T_c(x, up)]   (eq. 3.1)

  by a midpoint rule of ``steps`` EQUAL steps over [t_in, t_out] (no adaptive steps, no skipping of
  empty space, no early stop). T(0, t) = exp(-sigma_m t) exp(-tau_c(t)) is the transmittance of
  the homogeneous medium (constant sigma_m, exact) and of the clouds, whose optical depth tau_c is
  the running sum of the samples: at the k-th sample (the middle of its step)
  tau_c = sum_{j<k} sigma_j dt + sigma_k dt / 2, and T drops by exactly exp(-sigma_k dt) per step.
  The integrand is taken at the step's middle (T(0, t_mid) J(t_mid) dt): a different rule from the
  renderer's energy-conserving step (eq. 4.1), converging to the same integral as O(dt^2).

Choices (each stated once here):

* The slab. d = 0 wherever the height profile H is 0, i.e. below the base and at or above the
  profile's top corner h = t(type) (1 for cumulonimbus, 0.7 for cumulus, 0.3 for stratus). Every
  march (view and light) runs over the part of its ray inside base <= y <= base + t (top - base),
  the "support slab": the same integral as over the whole layer (the rest has d = 0 identically),
  with the steps spread where the density can be nonzero.
* Far cut. A ray that never leaves the slab (horizontal, or nearly) is cut FAR = 200 km from its
  origin: view rays at t <= 200 km from the camera (as the renderer's CLOUD_VIEW_FAR) and light
  rays 200 km from p (the renderer's CLOUD_LIGHT_FAR is 100 km; behind 100 km of cloud layer the
  optical depth is about extinction * mean(d) * 1e5, hundreds, so the difference is invisible
  unless the coverage is tiny).
* Lights. s = the scene's `sun` direction (`direction`, or `elevation`/`azimuth` in degrees:
  (sin az cos el, sin el, -cos az cos el)); E_sun = `sun.irradiance` (RGB, default 0), zero when
  s_y <= 0 or without a sun. E_sky = the irradiance of the sky dome on an upward plane,
  int L_sky(w) w_y dw: the overcast sky's 7 pi Lz / 9 exactly, the CIE general sky by a
  Gauss-Legendre x uniform-azimuth quadrature of daytime_reference.Sky (relative error < 4e-7 at
  the default 256 x 512 nodes for types 7, 12, 15 and the sun 5 to 80 degrees high, measured
  against 1024 x 2048; the sun's cusp in the indicatrix limits it); absent sky: 0. Neither light is
  attenuated by the homogeneous `medium` on its way to the cloud (the renderer's sun and sky
  irradiances include only the `atmosphere`, which the tests' scenes do not have; the light
  shafts' reference treats the sun the same way); the medium attenuates only the view path.
* The phase function is Henyey-Greenstein p_HG(mu, g) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5),
  mu = s . d with d the view direction from the camera (looking toward the sun is forward
  scattering); g is not clamped.

Injectable pieces, for tests with a density known in closed form: ``march_view`` and
``optical_depth_march`` take the extinction as a function sigma(points (N, 3)) -> (N,), and
``layer_radiance_with`` runs the whole per-pixel computation of ``clouds_layer_radiance`` for any
such function and slab.

Convergence, measured with the renderer's textures (seed 0) on 32 x 18 images: A, cumulus
(defaults) seen from the ground looking 22 degrees up (fov 60, the lowest rows 2 degrees above the
horizon), sun 35 degrees high, overcast sky; B, type 0.8 and coverage 0.6 looking 8.5 degrees up
(fov 40), sun 12 degrees high behind the camera, CIE sky 12, fog of visibility 20 km. "Change"
is the largest change of a pixel, as a fraction of the image's maximum unless stated:

* view steps 1024 -> 2048: A 8.8e-4 (512 -> 1024: 3.6e-3), B 1.1e-3 (not monotone: the density's
  clamps and texel kinks make the midpoint rule's error irregular at this level). Per pixel,
  relative to its own value: below 1.6e-3 wherever the ray's part in the layer is under 16 km,
  7.7e-3 at 3 degrees above the horizon (25 km) and 0.1 at 2 degrees (a 50 km part in 50 m
  steps). ``max_step`` fixes that: max_step 10 -> 5 m changes every pixel of A by under 2.2e-3 of
  its own value (rows at 2 degrees included); 10 m costs little more than the plain 1024 steps
  here (only rows below about 6 degrees get more), 5 m about 1.7 times as much.
* light steps 256 -> 512: A 6.0e-5 (128 -> 256: 2.6e-4; per pixel 3.7e-4 of its value), B 1.4e-4.
* the clouds' transmittance: 1024 -> 2048 view steps change it by under 2.3e-6 (absolute).

Runtime: either image at 1024 view and 256 light steps takes 21-23 s (27-34 s of CPU) on 2 cores
(the light marches, over 90 % of it, run in threads); the self-tests' synthetic cases check the
trends (effects/noise_clouds/tests/test_clouds_reference.py).
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

import numpy as np

_EFFECTS = Path(__file__).resolve().parents[2]
for _sibling in ("light_shafts", "daytime"):
    _path = str(_EFFECTS / _sibling / "tests")
    if _path not in sys.path:
        sys.path.insert(0, _path)

import daytime_reference as daytime  # noqa: E402
import shafts_reference as shafts  # noqa: E402

FAR = 200_000.0  # m: where a march along a ray that never leaves the slab is cut (see above)
DEFAULT_STEPS = 1024  # view-ray steps over the layer's part of the ray
DEFAULT_LIGHT_STEPS = 256  # steps of each march toward the sun and upward

# Height-profile corners (a: rise end, b: fall start, t: top) of stratus, cumulus, cumulonimbus.
PROFILE_STRATUS = (0.05, 0.15, 0.3)
PROFILE_CUMULUS = (0.1, 0.4, 0.7)
PROFILE_CUMULONIMBUS = (0.05, 0.7, 1.0)

# Work sizes: samples per view chunk and points per light-march batch (bounds memory).
_VIEW_CHUNK_SAMPLES = 1 << 18
_LIGHT_BATCH_POINTS = 1 << 18
_THREADS = min(4, os.cpu_count() or 1)  # light-march batches in parallel (each writes its own rows)

# Channel combinations the density uses (eqs. 2.1 and 2.4): shape R and low; detail high.
_SHAPE_R_LOW = ((1.0, 0.0, 0.0, 0.0), (0.0, 0.625, 0.25, 0.125))
_DETAIL_HIGH = ((0.625, 0.25, 0.125, 0.0),)

SigmaFn = Callable[[np.ndarray], np.ndarray]
SourceFn = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


# --------------------------------------------------------------------------------------------
# Parameters and textures
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class WeatherMap:
    """The layer's weather map (physics.md section 8), read independently of the renderer (PIL for
    PNG, the OpenEXR bindings for EXR): texels (rows, cols, 3) float64 of R the coverage factor,
    G the type, B 1 where the image has colour; `size` and `center` (m) along x and z."""

    image: str
    texels: np.ndarray
    size: tuple[float, float]
    center: tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_dict(cls, m: dict) -> WeatherMap:
        path = str(m["image"])
        if path.lower().endswith(".exr"):
            import OpenEXR

            with OpenEXR.File(path) as f:
                channels = f.channels()
                if "RGB" in channels:
                    rgb = np.asarray(channels["RGB"].pixels, dtype=np.float64)
                    r, g, colour = rgb[..., 0], rgb[..., 1], True
                else:
                    r = np.asarray(next(iter(channels.values())).pixels, dtype=np.float64)
                    g, colour = np.zeros_like(r), False
        else:
            from PIL import Image

            with Image.open(path) as im:
                colour = im.mode not in ("L", "LA", "I", "I;16", "1")
                a = np.asarray(im.convert("RGB") if colour else im, dtype=np.float64)
                scale = 65535.0 if im.mode.startswith("I") else 255.0
            a = a / scale
            r, g = (a[..., 0], a[..., 1]) if colour else (a, np.zeros_like(a))
        texels = np.stack([r, g, np.full_like(r, 1.0 if colour else 0.0)], axis=-1)
        size = (float(m["size"][0]), float(m["size"][1]))
        center = (float(m["center"][0]), float(m["center"][1])) if "center" in m else (0.0, 0.0)
        return cls(path, texels, size, center)

    def sample(self, x: np.ndarray, z: np.ndarray) -> np.ndarray:
        """(..., 3): the texels bilinear between their centres and repeating (eq. 8.1) at ground
        points (x, z) of the still (wind-free) map."""
        rows, cols, _ = self.texels.shape
        u = (x - self.center[0]) / self.size[0] + 0.5
        v = (z - self.center[1]) / self.size[1] + 0.5
        fx = cols * (u - np.floor(u)) - 0.5
        fy = rows * (v - np.floor(v)) - 0.5
        i0, j0 = np.floor(fx), np.floor(fy)
        ax, ay = (fx - i0)[..., None], (fy - j0)[..., None]
        i0, j0 = i0.astype(np.int64) % cols, j0.astype(np.int64) % rows
        i1, j1 = (i0 + 1) % cols, (j0 + 1) % rows
        t = self.texels
        return ((1 - ay) * ((1 - ax) * t[j0, i0] + ax * t[j0, i1])
                + ay * ((1 - ax) * t[j1, i0] + ax * t[j1, i1]))


@dataclass(frozen=True)
class CloudParams:
    """The scene's `clouds` object with its defaults (README "Scene format"; physics.md)."""

    base: float = 1500.0
    top: float = 4000.0
    coverage: float = 0.5
    type: float = 0.5
    extinction: float = 0.05
    albedo: float = 1.0
    g: float = 0.2
    second_g: float = -0.3
    second_weight: float = 0.0
    powder: float = 0.0
    erosion: float = 0.35
    shape_scale: float = 8000.0
    detail_scale: float = 600.0
    wind: tuple[float, float] = (0.0, 0.0)
    time: float = 0.0
    seed: int = 0
    weather_map: WeatherMap | None = None

    @classmethod
    def from_dict(cls, clouds: dict) -> CloudParams:
        known = set(cls.__dataclass_fields__)
        unknown = set(clouds) - known
        if unknown:
            raise ValueError(f"unknown clouds keys {sorted(unknown)}")
        special = ("wind", "seed", "weather_map")
        kw: dict[str, Any] = {k: float(v) for k, v in clouds.items() if k not in special}
        if clouds.get("weather_map") is not None:
            kw["weather_map"] = WeatherMap.from_dict(clouds["weather_map"])
        if "wind" in clouds:
            vx, vz = clouds["wind"]
            kw["wind"] = (float(vx), float(vz))
        if "seed" in clouds:
            kw["seed"] = int(clouds["seed"])
        p = cls(**kw)
        if not p.top > p.base:
            raise ValueError("clouds.top must be above clouds.base")
        if not 0.0 <= p.erosion < 1.0:
            raise ValueError("clouds.erosion must be in [0, 1)")
        if not 0.0 <= p.coverage <= 1.0 or not 0.0 <= p.type <= 1.0:
            raise ValueError("clouds.coverage and clouds.type must be in [0, 1]")
        return p

    @property
    def offset(self) -> np.ndarray:
        """o = wind * time as a 3-vector (vx t, 0, vz t): the field at p is the still field at p - o."""
        return np.array([self.wind[0] * self.time, 0.0, self.wind[1] * self.time])

    @property
    def support(self) -> tuple[float, float]:
        """(y_lo, y_hi): the slab outside which d = 0 identically (H = 0 at h <= 0 and h >= t)."""
        t = profile_corners(self.highest_type)[2]
        return self.base, self.base + t * (self.top - self.base)

    @property
    def highest_type(self) -> float:
        """The largest type anywhere (the profile's top rises with the type)."""
        if self.weather_map is None:
            return self.type
        w = self.weather_map.texels
        return float(np.max(w[..., 2] * w[..., 1] + (1.0 - w[..., 2]) * self.type))


def cloud_params(clouds: dict | CloudParams | None) -> CloudParams:
    """A CloudParams from the scene's `clouds` dict (None or {}: all defaults)."""
    if isinstance(clouds, CloudParams):
        return clouds
    return CloudParams.from_dict(clouds or {})


class NoiseTexture:
    """A tiling n^3 RGBA texture flattened to (n^3, 4), row (k n + j) n + i. float32 texels (the
    renderer's) are kept as float32, which holds them exactly (half the memory traffic of the
    gathers); everything else is converted to float64. Interpolation is always in float64.

    ``mixed(weights)`` caches float64 tables of fixed linear combinations of the channels: the
    density needs only R and the octave sums low = 0.625 G + 0.25 B + 0.125 A of the shape and
    high = 0.625 r + 0.25 g + 0.125 b of the detail, and trilinear interpolation is linear, so
    interpolating the combination equals combining the interpolated channels (to rounding)."""

    def __init__(self, texels: Any):
        a = np.asarray(texels)
        if a.dtype != np.float32:
            a = a.astype(np.float64)
        n = a.shape[0]
        if a.shape != (n, n, n, 4):
            raise ValueError(f"expected an (n, n, n, 4) texture, got {a.shape}")
        self.n = n
        self.flat = np.ascontiguousarray(a.reshape(n * n * n, 4))
        self._mixed: dict[tuple, np.ndarray] = {}

    def mixed(self, weights: tuple[tuple[float, ...], ...]) -> np.ndarray:
        """(n^3, len(weights)) float64: column c = sum_k weights[c][k] channel k."""
        if weights not in self._mixed:
            w = np.asarray(weights, dtype=np.float64)
            self._mixed[weights] = np.ascontiguousarray(self.flat.astype(np.float64) @ w.T)
        return self._mixed[weights]


TextureLike = Union[NoiseTexture, np.ndarray]


def _texture(tex: TextureLike) -> NoiseTexture:
    return tex if isinstance(tex, NoiseTexture) else NoiseTexture(tex)


def _trilinear(table: np.ndarray, n: int, u: np.ndarray) -> np.ndarray:
    """Eq. 1.1 on a flattened table (n^3, C): u (N, 3) -> (N, C) float64."""
    f = n * (u - np.floor(u)) - 0.5
    corner = np.floor(f)
    w = f - corner
    i0 = corner.astype(np.int64) % n
    i1 = i0 + 1
    i1[i1 == n] = 0
    x0, x1 = i0[:, 0], i1[:, 0]
    y0, y1 = i0[:, 1] * n, i1[:, 1] * n
    z0, z1 = i0[:, 2] * (n * n), i1[:, 2] * (n * n)
    wx, wy, wz = w[:, 0:1], w[:, 1:2], w[:, 2:3]

    def row(zy: np.ndarray) -> np.ndarray:  # lerp along x on the texel row z + y
        a = np.take(table, zy + x0, axis=0).astype(np.float64, copy=False)
        return a + (np.take(table, zy + x1, axis=0) - a) * wx

    r00, r10 = row(z0 + y0), row(z0 + y1)
    r01, r11 = row(z1 + y0), row(z1 + y1)
    near = r00 + (r10 - r00) * wy
    return near + (r01 + (r11 - r01) * wy - near) * wz


def sample_periodic(tex: TextureLike, u: Any) -> np.ndarray:
    """Periodic trilinear sample of an n^3 RGBA texture (eq. 1.1): u (..., 3) in tile units
    (x, y, z), f = n fract(u) - 1/2, i0 = floor(f) mod n, i1 = (i0 + 1) mod n, weights
    f - floor(f); returns (..., 4) float64. Texel (i, j, k) is centred at u = ((i, j, k) + 1/2) / n."""
    tex = _texture(tex)
    u = np.asarray(u, dtype=np.float64)
    return _trilinear(tex.flat, tex.n, u.reshape(-1, 3)).reshape(u.shape[:-1] + (4,))


# --------------------------------------------------------------------------------------------
# Density (physics.md section 2)
# --------------------------------------------------------------------------------------------


def profile_corners(cloud_type: Any) -> tuple[Any, Any, Any]:
    """(a, b, t) of the height profile, linear in type between stratus (0), cumulus (0.5) and
    cumulonimbus (1); a float, or arrays for an array of types."""
    x = np.asarray(cloud_type, dtype=np.float64)
    lower = x < 0.5
    f = np.where(lower, 2.0 * x, 2.0 * x - 1.0)
    corners = []
    for i in range(3):
        lo = np.where(lower, PROFILE_STRATUS[i], PROFILE_CUMULUS[i])
        hi = np.where(lower, PROFILE_CUMULUS[i], PROFILE_CUMULONIMBUS[i])
        c = lo + (hi - lo) * f
        corners.append(float(c) if c.ndim == 0 else c)
    return corners[0], corners[1], corners[2]


def height_profile(h: Any, cloud_type: Any) -> np.ndarray:
    """The trapezoid H(h, type): 0 at h <= 0, rising linearly to 1 at h = a, 1 up to h = b,
    falling linearly to 0 at h = t, 0 above: max(0, min(h / a, 1, (t - h) / (t - b)))."""
    a, b, t = profile_corners(cloud_type)
    h = np.asarray(h, dtype=np.float64)
    return np.maximum(0.0, np.minimum(np.minimum(h / a, 1.0), (t - h) / (t - b)))


def density(p: Any, clouds: dict | CloudParams | None, shape: TextureLike, detail: TextureLike) -> np.ndarray:
    """d(p) in [0, 1] by eqs. 2.1-2.4 for points p (..., 3) in metres; shape (...).

    h = (p_y - base) / (top - base), q = p - o with o = (vx time, 0, vz time):
    (R, G, B, A) = shape(q / shape_scale), low = 0.625 G + 0.25 B + 0.125 A,
    s = clamp((R - (low - 1)) / (2 - low), 0, 1), s_h = s H(h), c = coverage (x the weather map's R),
    s_c = clamp((s_h - (1 - c)) / c, 0, 1) c (0 at c = 0), (r, g, b, _) = detail(q / detail_scale),
    high = 0.625 r + 0.25 g + 0.125 b, m = mix(high, 1 - high, clamp(10 h, 0, 1)),
    d = clamp((s_c - e m) / (1 - e m), 0, 1). Zero where H = 0 (outside the layer included); the
    textures are looked up only where they can matter (the result is the same). Pass
    NoiseTexture(shape), NoiseTexture(detail) when calling it repeatedly: raw arrays are converted
    on every call."""
    prm = cloud_params(clouds)
    p = np.asarray(p, dtype=np.float64)
    lead = p.shape[:-1]
    x = p.reshape(-1, 3)
    out = np.zeros(len(x))
    if prm.coverage <= 0.0 or len(x) == 0:
        return out.reshape(lead)
    h = (x[:, 1] - prm.base) / (prm.top - prm.base)
    c: Any = prm.coverage
    cloud_type: Any = prm.type
    if prm.weather_map is not None:  # eq. 8.1, the map drifting with the wind
        w = prm.weather_map.sample(x[:, 0] - prm.offset[0], x[:, 2] - prm.offset[2])
        c = prm.coverage * w[:, 0]
        cloud_type = w[:, 2] * w[:, 1] + (1.0 - w[:, 2]) * prm.type
    profile = np.where(c > 0.0, height_profile(h, cloud_type), 0.0)
    idx = np.flatnonzero(profile > 0.0)
    if idx.size == 0:
        return out.reshape(lead)
    if np.ndim(c):
        c = c[idx]
    shape, detail = _texture(shape), _texture(detail)
    q = x[idx] - prm.offset
    r_low = _trilinear(shape.mixed(_SHAPE_R_LOW), shape.n, q / prm.shape_scale)
    low = r_low[:, 1]
    s = np.clip((r_low[:, 0] - (low - 1.0)) / (2.0 - low), 0.0, 1.0)
    s_c = np.clip((s * profile[idx] - (1.0 - c)) / c, 0.0, 1.0) * c
    keep = s_c > 0.0  # d <= s_c: nothing to erode elsewhere
    idx, q, s_c = idx[keep], q[keep], s_c[keep]
    if idx.size == 0:
        return out.reshape(lead)
    high = _trilinear(detail.mixed(_DETAIL_HIGH), detail.n, q / prm.detail_scale)[:, 0]
    mix = np.clip(10.0 * h[idx], 0.0, 1.0)
    em = prm.erosion * (high + (1.0 - 2.0 * high) * mix)
    out[idx] = np.clip((s_c - em) / (1.0 - em), 0.0, 1.0)
    return out.reshape(lead)


def sigma_t(p: Any, clouds: dict | CloudParams | None, shape: TextureLike, detail: TextureLike) -> np.ndarray:
    """The clouds' extinction coefficient extinction * d(p) (1/m), shape (...) for p (..., 3)."""
    prm = cloud_params(clouds)
    return prm.extinction * density(p, prm, shape, detail)


def _sigma_function(prm: CloudParams, shape: TextureLike, detail: TextureLike) -> SigmaFn:
    shape, detail = _texture(shape), _texture(detail)
    return lambda x: prm.extinction * density(x, prm, shape, detail)


def hg_phase(mu: Any, g: float) -> np.ndarray:
    """Henyey-Greenstein (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5), per steradian."""
    mu = np.asarray(mu, dtype=np.float64)
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * mu) ** 1.5)


# --------------------------------------------------------------------------------------------
# Marches (the density injectable)
# --------------------------------------------------------------------------------------------


def slab_interval(origin: Any, dirs: Any, y_lo: float, y_hi: float, t_max: Any = math.inf,
                  far: float = FAR) -> tuple[np.ndarray, np.ndarray]:
    """[t0, t1] of o + t d inside y_lo <= y <= y_hi, within [0, min(t_max, far)], per ray.
    origin (3,) or (N, 3), dirs (3,) or (N, 3) (unit), t_max scalar or (N,); returns (N,) arrays
    with t1 = t0 where the ray misses (length 0). A horizontal ray is inside for all t when
    y_lo <= o_y <= y_hi, else never."""
    o = np.atleast_2d(np.asarray(origin, dtype=np.float64))
    d = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    n = max(len(o), len(d))
    oy = np.broadcast_to(o[:, 1], (n,))
    dy = np.broadcast_to(d[:, 1], (n,))
    inside = (y_lo <= oy) & (oy <= y_hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (y_lo - oy) / dy
        b = (y_hi - oy) / dy
    flat = dy == 0.0
    enter = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(a, b))
    leave = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(a, b))
    t0 = np.maximum(enter, 0.0)
    t1 = np.minimum(np.minimum(leave, np.broadcast_to(np.asarray(t_max, dtype=np.float64), (n,))), far)
    t1 = np.where(t1 > t0, t1, t0)
    t0 = np.where(np.isfinite(t0), t0, 0.0)
    t1 = np.where(np.isfinite(t1), t1, 0.0)
    return t0, t1


def optical_depth_march(points: Any, w: Any, sigma_fn: SigmaFn, y_lo: float, y_hi: float,
                        steps: int = DEFAULT_LIGHT_STEPS, far: float = FAR) -> np.ndarray:
    """int_0^inf sigma(p + u w) du for points (M, 3) and one unit direction w (3,), sigma zero
    outside y_lo <= y <= y_hi: a midpoint rule of `steps` equal steps over the part of the
    half-line inside the slab (cut at u = far). Returns (M,)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    w = np.asarray(w, dtype=np.float64)
    out = np.zeros(len(pts))
    if len(pts) == 0:
        return out
    u0, u1 = slab_interval(pts, w, y_lo, y_hi, math.inf, far)
    du = (u1 - u0) / steps
    mid = np.arange(steps) + 0.5
    batch = max(1, _LIGHT_BATCH_POINTS // steps)

    def run(i: int) -> None:
        sl = slice(i, i + batch)
        u = u0[sl, None] + mid[None, :] * du[sl, None]  # (B, steps)
        x = pts[sl, None, :] + u[..., None] * w
        out[sl] = sigma_fn(x.reshape(-1, 3)).reshape(u.shape).sum(axis=1) * du[sl]

    starts = range(0, len(pts), batch)
    if _THREADS > 1 and len(starts) > 1:  # numpy releases the GIL: batches run side by side
        with ThreadPoolExecutor(_THREADS) as pool:
            list(pool.map(run, starts))
    else:
        for i in starts:
            run(i)
    return out


def transmittance_to_boundary(p: Any, w: Any, clouds: dict | CloudParams | None, shape: TextureLike,
                              detail: TextureLike, steps: int = DEFAULT_LIGHT_STEPS,
                              far: float = FAR) -> np.ndarray:
    """T_c(p, w) = exp(-int_0^inf sigma_t(p + u w) du) (eq. 3.2) for points p (..., 3) and one
    direction w (3,) (normalised here): `steps` equal midpoint steps over the half-line's part in
    the support slab (where it leaves base <= y <= top, or the profile's top, which is the same
    integral), cut at u = far for a horizontal w. Returns (...)."""
    prm = cloud_params(clouds)
    p = np.asarray(p, dtype=np.float64)
    w = shafts._unit(w)
    sigma_fn = _sigma_function(prm, shape, detail)
    tau = optical_depth_march(p.reshape(-1, 3), w, sigma_fn, *prm.support, steps, far)
    return np.exp(-tau).reshape(p.shape[:-1])


def sample_chunks(counts: np.ndarray, chunk: int):
    """Splits the samples of rays with counts[i] samples each into chunks of about `chunk` samples
    (whole rays): yields (rays, n, ray, k): the chunk's ray indices, their counts, each sample's
    ray (global index) and its index k within its ray."""
    cum = np.cumsum(counts)
    start = 0
    while start < len(counts):
        base = cum[start - 1] if start else 0
        stop = max(int(np.searchsorted(cum, base + chunk, side="right")), start + 1)
        rays = np.arange(start, stop)
        n = counts[rays]
        start = stop
        total = int(n.sum())
        if total == 0:
            continue
        ray = np.repeat(rays, n)
        yield rays, n, ray, np.arange(total) - np.repeat(np.cumsum(n) - n, n)


def march_view(origin: Any, dirs: Any, t0: Any, t1: Any, sigma_fn: SigmaFn, source_fn: SourceFn | None,
               sigma_medium: Any = 0.0, steps: int = DEFAULT_STEPS,
               max_step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The layer's part of eq. 3.3 along rays o + t d over [t0, t1] (per ray), by a midpoint rule
    of equal steps: n = steps per ray (or max(steps, ceil((t1 - t0) / max_step)) with max_step).

    sigma_fn(x (N, 3)) -> (N,) is the clouds' extinction; source_fn(x (M, 3), ray (M,), sigma (M,))
    -> (M, 3) the source J (eq. 3.1, sigma_s included) at the samples with sigma > 0, `ray` the
    index of each sample's ray in `dirs`. sigma_medium: the homogeneous medium's extinction (number
    or RGB), attenuating from the camera (t = 0) on.

    Returns (radiance (N, 3), tau (N,)): int T(0, t) J dt, T = exp(-sigma_m t - tau_c(t)), and the
    clouds' optical depth over [t0, t1]."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.atleast_2d(np.asarray(dirs, dtype=np.float64))
    nrays = len(d)
    t0 = np.broadcast_to(np.asarray(t0, dtype=np.float64), (nrays,))
    t1 = np.broadcast_to(np.asarray(t1, dtype=np.float64), (nrays,))
    sig_m = shafts.rgb(sigma_medium)
    length = np.maximum(t1 - t0, 0.0)
    counts = np.where(length > 0.0, steps, 0).astype(np.int64)
    if max_step is not None:
        counts = np.where(length > 0.0, np.maximum(counts, np.ceil(length / max_step)), 0).astype(np.int64)
    radiance = np.zeros((nrays, 3))
    tau = np.zeros(nrays)
    for rays, n, ray, k in sample_chunks(counts, _VIEW_CHUNK_SAMPLES):
        total = len(ray)
        first = np.cumsum(n) - n  # each ray's first sample within the chunk
        with np.errstate(divide="ignore", invalid="ignore"):
            dt_ray = np.where(n > 0, length[rays] / np.maximum(n, 1), 0.0)
        dt = dt_ray[ray - rays[0]]
        t = t0[ray] + (k + 0.5) * dt
        x = o + t[:, None] * d[ray]
        sig = np.asarray(sigma_fn(x), dtype=np.float64).reshape(total)
        step_tau = sig * dt
        tau[rays] += np.bincount(ray - rays[0], weights=step_tau, minlength=len(rays))
        nz = np.flatnonzero(sig > 0.0)
        if source_fn is None or nz.size == 0:
            continue
        # Optical depth from t0 to the sample's middle: the ray's earlier steps, then half its own.
        before = np.cumsum(step_tau) - step_tau
        before -= before[np.repeat(first, n)]
        tau_mid = before[nz] + 0.5 * step_tau[nz]
        j = np.asarray(source_fn(x[nz], ray[nz], sig[nz]), dtype=np.float64).reshape(-1, 3)
        trans = np.exp(-tau_mid)[:, None] * np.exp(-np.outer(t[nz], sig_m))
        contrib = trans * j * dt[nz, None]
        local = ray[nz] - rays[0]
        for ch in range(3):
            radiance[rays, ch] += np.bincount(local, weights=contrib[:, ch], minlength=len(rays))
    return radiance, tau


# --------------------------------------------------------------------------------------------
# Scene: lights, medium, rays
# --------------------------------------------------------------------------------------------


def sun_light(scene: dict) -> tuple[np.ndarray, np.ndarray]:
    """(s, E_sun): the unit direction toward the sun (zeros without a sun) and its irradiance RGB,
    zero with the sun at or below the horizon (s_y <= 0) or absent (no atmosphere: the sun's
    irradiance reaches the layer unattenuated)."""
    sun = scene.get("sun")
    if not sun:
        return np.zeros(3), np.zeros(3)
    s = shafts.sun_direction(sun)
    e = shafts.rgb(sun.get("irradiance"), 0.0)
    return s, (e if s[1] > 0.0 else np.zeros(3))


def _cie_sky(sky_type: int, sun: dict | None) -> daytime.Sky:
    if sun:
        s = shafts.sun_direction(sun)
        el = math.degrees(math.asin(max(-1.0, min(1.0, float(s[1])))))
        az = math.degrees(math.atan2(float(s[0]), float(-s[2])))
    elif daytime.cie_parameters(sky_type)[2:] == (0.0, -1.0, 0.0):
        el, az = 90.0, 0.0  # the indicatrix is 1: no sun needed
    else:
        raise ValueError(f"CIE sky type {sky_type} depends on the sun's position: the scene needs a sun")
    return daytime.Sky(cie_type=sky_type, lz=(1.0, 1.0, 1.0), sun_azimuth_deg=az, sun_elevation_deg=el)


def sky_irradiance(scene: dict, n_mu: int = 256, n_phi: int = 512) -> np.ndarray:
    """E_sky (RGB): int over the upper hemisphere of L_sky(w) w_y dw, the dome's irradiance on an
    upward-facing plane. Overcast ((1 + 2 cos Z) / 3 Lz): 7 pi Lz / 9 exactly; CIE general sky:
    quadrature of daytime_reference.Sky (Gauss-Legendre in w_y split around the sun's height,
    uniform in azimuth starting at the sun's); no sky: 0."""
    sky = scene.get("sky")
    if not sky:
        return np.zeros(3)
    lz = shafts.rgb(sky["zenith_radiance"])
    model = sky.get("model", "overcast")
    if model == "overcast":
        return 7.0 * math.pi / 9.0 * lz
    if model != "cie":
        raise ValueError(f"unknown sky model {model!r}")
    dome = _cie_sky(int(sky["type"]), scene.get("sun"))
    ms = float(dome.sun[1])
    rule = daytime.HemisphereRule(n_mu, n_phi, [ms - 0.1, ms - 0.02, ms, ms + 0.02, ms + 0.1],
                                  phi0=math.radians(dome.sun_azimuth_deg))
    return float(np.sum(rule.weights * dome.shape(rule.dirs) * rule.mu)) * lz


def medium_sigma_t(scene: dict) -> np.ndarray:
    """The homogeneous medium's sigma_t (RGB): `sigma_t`, or 3.912 / `visibility`; 0 without."""
    medium = scene.get("medium")
    return shafts.medium_coefficients(medium)[0] if medium else np.zeros(3)


def view_rays(scene: dict, width: int, height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(origin (3,), unit dirs (H*W, 3) row 0 on top, t_end (H*W,)): the pinhole camera of
    shafts_reference.camera_rays and the first surface hit (+inf if none)."""
    origin, dirs = shafts.camera_rays(scene, width, height)
    flat = dirs.reshape(-1, 3)
    t_end = shafts.first_hit(origin, flat, scene.get("surfaces") or [])
    return origin, flat, np.asarray(t_end, dtype=np.float64).reshape(-1)


# --------------------------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------------------------


def layer_radiance_with(scene: Any, width: int, height: int, sigma_fn: SigmaFn, slab: tuple[float, float],
                        albedo: float = 1.0, g: float = 0.2, steps: int = DEFAULT_STEPS,
                        light_steps: int = DEFAULT_LIGHT_STEPS, max_step: float | None = None,
                        far: float = FAR, second_g: float = -0.3, second_weight: float = 0.0,
                        powder: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``clouds_layer_radiance`` for any cloud extinction sigma_fn (zero outside `slab` = (y_lo,
    y_hi)), albedo, g, the second lobe (eq. 3.4) and the powder term (eq. 3.5): the scene gives
    the camera, surfaces, medium, sun and sky.

    Returns (radiance (H, W, 3), clouds' optical depth tau (H, W)) along [t_in, t_out], the view
    ray's part in the slab within [0, min(t_end, far)]."""
    scene = shafts._load(scene)
    y_lo, y_hi = slab
    origin, dirs, t_end = view_rays(scene, width, height)
    t0, t1 = slab_interval(origin, dirs, y_lo, y_hi, t_end, far)
    s, e_sun = sun_light(scene)
    e_sky = sky_irradiance(scene)
    sig_m = medium_sigma_t(scene)
    phase = (1.0 - second_weight) * hg_phase(dirs @ s, g) + second_weight * hg_phase(dirs @ s, second_g)
    up = np.array([0.0, 1.0, 0.0])
    use_sun, use_sky = bool(e_sun.any()), bool(e_sky.any())

    def source(x: np.ndarray, ray: np.ndarray, sig: np.ndarray) -> np.ndarray:
        j = np.zeros((len(x), 3))
        if use_sun:
            tau_sun = optical_depth_march(x, s, sigma_fn, y_lo, y_hi, light_steps, far)
            t_sun = np.exp(-tau_sun) * (1.0 - powder * np.exp(-2.0 * tau_sun))
            j += np.outer(t_sun * phase[ray], e_sun)
        if use_sky:
            t_up = np.exp(-optical_depth_march(x, up, sigma_fn, y_lo, y_hi, light_steps, far))
            j += np.outer(t_up, e_sky / (2.0 * math.pi))
        return (albedo * sig)[:, None] * j

    source_fn = source if use_sun or use_sky else None
    radiance, tau = march_view(origin, dirs, t0, t1, sigma_fn, source_fn, sig_m, steps, max_step)
    return radiance.reshape(height, width, 3), tau.reshape(height, width)


def clouds_layer_radiance(scene: Any, width: int, height: int, shape: TextureLike, detail: TextureLike,
                          steps: int = DEFAULT_STEPS, light_steps: int = DEFAULT_LIGHT_STEPS,
                          max_step: float | None = None, far: float = FAR) -> np.ndarray:
    """The light the cloud layer scatters toward the camera, per pixel (H, W, 3) float64, row 0 on
    top (W/(m^2 sr)): int over the view ray's part in the layer of T(0, t) J(x(t)) dt with T the
    clouds' and the medium's transmittance from the camera and J eq. 3.1 (sun with the clouds'
    shadow, sky attenuated straight up). Zeros without `clouds`.

    `steps` equal view steps over the layer's part of each ray (with `max_step`, at least
    ceil(length / max_step) of them: 10 m keeps rays within a few degrees of the horizon, whose
    part in the layer is tens of km long, at about 2e-3 relative), `light_steps` equal steps per
    light march; the measured convergence is in the module's docstring."""
    scene = shafts._load(scene)
    if scene.get("clouds") is None:
        return np.zeros((height, width, 3))
    prm = cloud_params(scene["clouds"])
    radiance, _ = layer_radiance_with(scene, width, height, _sigma_function(prm, shape, detail), prm.support,
                                      prm.albedo, prm.g, steps, light_steps, max_step, far, prm.second_g,
                                      prm.second_weight, prm.powder)
    return radiance


def clouds_optical_depth(scene: Any, width: int, height: int, shape: TextureLike, detail: TextureLike,
                         steps: int = DEFAULT_STEPS, max_step: float | None = None,
                         far: float = FAR) -> np.ndarray:
    """The clouds' optical depth along each pixel's ray up to its end (H, W): the same view march
    as ``clouds_layer_radiance`` (its samples, its far cut)."""
    scene = shafts._load(scene)
    if scene.get("clouds") is None:
        return np.zeros((height, width))
    prm = cloud_params(scene["clouds"])
    origin, dirs, t_end = view_rays(scene, width, height)
    t0, t1 = slab_interval(origin, dirs, *prm.support, t_end, far)
    _, tau = march_view(origin, dirs, t0, t1, _sigma_function(prm, shape, detail), None, 0.0, steps, max_step)
    return tau.reshape(height, width)


def clouds_transmittance(scene: Any, width: int, height: int, shape: TextureLike, detail: TextureLike,
                         steps: int = DEFAULT_STEPS, include_medium: bool = True,
                         max_step: float | None = None, far: float = FAR) -> np.ndarray:
    """T(0, t_end) per pixel and channel (H, W, 3): exp(-tau_clouds) times, with include_medium,
    the homogeneous medium's exp(-sigma_m t_end) (0 for an escaping ray on a channel with
    sigma_m > 0; 1 with sigma_m = 0). include_medium=False: the clouds' alone (equal channels)."""
    scene = shafts._load(scene)
    tau = clouds_optical_depth(scene, width, height, shape, detail, steps, max_step, far)
    out = np.repeat(np.exp(-tau)[..., None], 3, axis=-1)
    if include_medium:
        sig_m = medium_sigma_t(scene)
        _, _, t_end = view_rays(scene, width, height)
        with np.errstate(invalid="ignore"):
            path = np.where(sig_m[None, :] > 0.0, np.outer(t_end, sig_m), 0.0)
        out *= np.exp(-path).reshape(height, width, 3)
    return out


def medium_sun_through_clouds(scene: Any, width: int, height: int, shape: TextureLike, detail: TextureLike,
                              steps: int = 2048, light_steps: int = DEFAULT_LIGHT_STEPS) -> np.ndarray:
    """(H, W): the fraction of the homogeneous medium's sunlight below the layer that the clouds
    let through (physics.md section 9), for a camera below the layer's base:
    int_0^t0 e^{-sigma t} T_c(o + t d, s) dt / int_0^t0 e^{-sigma t} dt, t0 where the ray meets the
    base (or its first surface, or CLOUD_VIEW_FAR); `steps` equal steps, each weighted exactly by
    its e^{-sigma t} and lit at its middle. Needs a grey medium (sigma_t one number) and a sun; NaN
    for rays that do not go up."""
    prm = cloud_params(scene["clouds"])
    origin, dirs, t_end = view_rays(scene, width, height)
    sigma = float(medium_sigma_t(scene)[0])
    s, _ = sun_light(scene)
    if origin[1] >= prm.base:
        raise ValueError("the camera must be below the layer")
    up = dirs[:, 1] > 0.0
    t0 = np.where(up, (prm.base - origin[1]) / np.where(up, dirs[:, 1], 1.0), 0.0)
    t0 = np.minimum(np.minimum(t0, t_end), 200000.0)
    edges = t0[:, None] * (np.arange(steps + 1) / steps)[None, :]
    weight = np.exp(-sigma * edges[:, :-1]) - np.exp(-sigma * edges[:, 1:])
    mid = 0.5 * (edges[:, :-1] + edges[:, 1:])
    points = origin + mid[..., None] * dirs[:, None, :]
    lit = transmittance_to_boundary(points.reshape(-1, 3), s, prm, shape, detail, light_steps)
    lit = lit.reshape(mid.shape)
    out = np.sum(weight * lit, axis=1) / np.maximum(np.sum(weight, axis=1), 1e-300)
    return np.where(up, out, np.nan).reshape(height, width)
