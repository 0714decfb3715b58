"""Independent references for the falling rain's tests (effects/falling_rain/physics.md): the
literature's Marshall-Palmer distribution and Gunn-Kinzer fall speeds, a water sphere's Debye
orders in closed form (root-found per branch, not sampled), and a streak's energy on the film by
direct quadrature of the drop's solid angle over the exposure. None of it calls the renderer's code
for what it checks."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import integrate, optimize

# Marshall and Palmer (1948): N(D) = N0 exp(-Lambda D), N0 = 8000 m^-3 mm^-1, Lambda = 4.1 R^-0.21 mm^-1.
N0 = 8000.0
D_MIN, D_MAX = 0.1, 6.0  # mm: the cut the renderer documents (physics.md section 1)

# Gunn and Kinzer (1949), terminal speed of water drops in stagnant air at 1013 hPa, 20 C (m/s).
GUNN_KINZER = {
    0.1: 0.27,
    0.2: 0.72,
    0.3: 1.17,
    0.4: 1.62,
    0.5: 2.06,
    0.6: 2.47,
    0.8: 3.27,
    1.0: 4.03,
    1.5: 5.40,
    2.0: 6.49,
    2.5: 7.41,
    3.0: 8.06,
    3.5: 8.53,
    4.0: 8.83,
    4.5: 9.00,
    5.0: 9.09,
    5.5: 9.14,
}


def sphere_terminal_speed(d_mm: float) -> float:
    """A water sphere's terminal speed (m/s) in air at 20 C, 1013 hPa, where its weight less buoyancy
    equals the Schiller-Naumann drag 0.5 rho_a v^2 A C_D, C_D = 24 / Re (1 + 0.15 Re^0.687): the
    force balance itself, root-found (the renderer solves the equivalent v (1 + 0.15 Re^0.687) = v_S)."""
    rho_a, eta, rho_w, g = 1.204, 1.813e-5, 998.2, 9.80665
    d = 1e-3 * d_mm
    weight = (rho_w - rho_a) * g * math.pi * d**3 / 6.0

    def excess(v: float) -> float:
        re = rho_a * v * d / eta
        drag = 0.5 * rho_a * v * v * (math.pi * d * d / 4.0) * 24.0 / re * (1.0 + 0.15 * re**0.687)
        return drag - weight

    return optimize.brentq(excess, 1e-9, 50.0, xtol=1e-14, rtol=1e-13)


def slope(rate: float) -> float:
    return 4.1 * rate**-0.21


def number_density(rate: float) -> float:
    """Drops per m^3 with D in [D_MIN, D_MAX], by adaptive quadrature."""
    lam = slope(rate)
    return integrate.quad(lambda d: N0 * math.exp(-lam * d), D_MIN, D_MAX, epsabs=0, epsrel=1e-12)[0]


def water_content(rate: float) -> float:
    """Liquid water (g/m^3) in drops with D in [D_MIN, D_MAX]: pi/6 D^3 mm^3 at 1e-3 g/mm^3 each."""
    lam = slope(rate)
    return integrate.quad(
        lambda d: N0 * math.exp(-lam * d) * math.pi / 6 * d**3 * 1e-3, D_MIN, D_MAX, epsabs=0, epsrel=1e-12
    )[0]


def diameter_cdf(rate: float, d: np.ndarray) -> np.ndarray:
    """The truncated exponential's CDF: the diameters of the drops in a volume."""
    lam = slope(rate)
    d = np.clip(d, D_MIN, D_MAX)
    return (1 - np.exp(-lam * (d - D_MIN))) / (1 - math.exp(-lam * (D_MAX - D_MIN)))


# --- A water sphere's orders in closed form (Debye series, geometric optics) -------------------------


def fresnel(n: float, i: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reflectances (s, p) at incidence i from air onto water of index n."""
    ci = np.cos(i)
    ct = np.sqrt(1 - (np.sin(i) / n) ** 2)
    rs = ((ci - n * ct) / (ci + n * ct)) ** 2
    rp = ((ct - n * ci) / (ct + n * ci)) ** 2
    return rs, rp


def order_energy(n: float, p: int, i: np.ndarray) -> np.ndarray:
    """The share of a ray at incidence i leaving after p internal paths, s and p averaged."""
    out = 0.0
    for r in fresnel(n, i):
        out = out + (r if p == 0 else (1 - r) ** 2 * r ** (p - 1))
    return 0.5 * out


def scattering_angle(n: float, p: int, i: np.ndarray) -> np.ndarray:
    """The angle between the ray's direction before and after: the deviation, folded into [0, pi]."""
    r = np.arcsin(np.sin(i) / n)
    deviation = np.pi - 2 * i if p == 0 else 2 * (i - r) + (p - 1) * (np.pi - 2 * r)
    return np.arccos(np.cos(deviation))


def order_phase(n: float, p: int, theta: float) -> float:
    """f_p(theta) per steradian per unit incident power: the sum over the incidences i with
    scattering_angle(i) = theta of eps_p(i) b |db/dtheta| / (pi sin theta), b = sin i."""
    grid = np.linspace(1e-7, math.pi / 2 - 1e-7, 40001)
    g = scattering_angle(n, p, grid) - theta
    total = 0.0
    for k in np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]:
        i = optimize.brentq(
            lambda x: float(scattering_angle(n, p, np.array(x))) - theta, grid[k], grid[k + 1], xtol=1e-15
        )
        h = 1e-7
        dtheta = (
            float(scattering_angle(n, p, np.array(i + h))) - float(scattering_angle(n, p, np.array(i - h)))
        ) / (2 * h)
        b, db = math.sin(i), math.cos(i)
        total += float(order_energy(n, p, np.array(i))) * b * db / (math.pi * math.sin(theta) * abs(dtheta))
    return total


def order_power(n: float, p: int) -> float:
    """The share of the light on the cross-section leaving by order p: eps_p integrated over b^2 = sin^2 i."""
    return integrate.quad(
        lambda i: float(order_energy(n, p, np.array(i))) * math.sin(2 * i),
        0,
        math.pi / 2,
        epsabs=0,
        epsrel=1e-12,
        limit=200,
    )[0]


def drop_phase(n: float, theta: float, orders: int) -> float:
    """f(theta) summed over the orders the renderer keeps."""
    return sum(order_phase(n, p, theta) for p in range(orders))


# --- A streak on the film ---------------------------------------------------------------------------


def camera_frame(scene: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Camera position and its right, up and forward axes scaled as the film's (tan of half the field)."""
    cam = scene["camera"]
    o = np.array(cam["position"], float)
    f = np.array(cam["look_at"], float) - o
    f /= np.linalg.norm(f)
    r = np.cross(f, np.array(cam.get("up", [0, 1, 0]), float))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    h = math.tan(math.radians(cam["fov_y"]) / 2)
    aspect = scene["film"]["width"] / scene["film"]["height"]
    return o, r * h * aspect, u * h, f


def film_position(scene: dict[str, Any], q: np.ndarray) -> np.ndarray:
    """Pixel coordinates (x, row), row 0 on top, of world points q (..., 3)."""
    o, r, u, f = camera_frame(scene)
    d = q - o
    z = d @ f
    x = 0.5 * ((d @ r) / (r @ r) / z + 1) * scene["film"]["width"]
    y = 0.5 * (1 - (d @ u) / (u @ u) / z) * scene["film"]["height"]
    return np.stack([x, y], axis=-1)


def pixel_solid_angles(scene: dict[str, Any]) -> np.ndarray:
    """Each pixel's solid angle, by 2-D Gauss-Legendre quadrature of cos^3 over its area at unit distance."""
    w, h = scene["film"]["width"], scene["film"]["height"]
    _, r, u, _ = camera_frame(scene)
    sx, sy = 2 * np.linalg.norm(r) / w, 2 * np.linalg.norm(u) / h
    nodes, weights = np.polynomial.legendre.leggauss(6)
    xs = (np.arange(w)[:, None] + 0.5 + 0.5 * nodes[None, :]).ravel() * sx - np.linalg.norm(r)
    ys = (np.arange(h)[:, None] + 0.5 + 0.5 * nodes[None, :]).ravel() * sy - np.linalg.norm(u)
    wx = np.tile(0.5 * weights, w) * sx
    wy = np.tile(0.5 * weights, h) * sy
    X, Y = np.meshgrid(xs, ys)
    integrand = (1 + X**2 + Y**2) ** -1.5 * np.outer(wy, wx)
    return integrand.reshape(h, 6, w, 6).sum(axis=(1, 3))


def streak_solid_angle_time(
    scene: dict[str, Any],
    position: np.ndarray,
    velocity: np.ndarray,
    diameter_mm: float,
    sigma_t: float = 0.0,
    samples: int = 4001,
) -> float:
    """The drop's solid angle pi a^2 / d^2, times the medium's transmittance exp(-sigma_t d) to the camera,
    averaged over the exposure (the streak's centre from position - v T / 2 to position + v T / 2)."""
    o = np.array(scene["camera"]["position"], float)
    t = scene["camera"].get("exposure_time", 1 / 60)
    tau = np.linspace(-0.5, 0.5, samples)
    q = position[None, :] + tau[:, None] * t * velocity[None, :]
    d = np.linalg.norm(q - o, axis=1)
    a = 0.5e-3 * diameter_mm
    return float(integrate.simpson(math.pi * a * a / d**2 * np.exp(-sigma_t * d), x=tau))


def drawn_optical_depth(rate: float, radius: float, full_diameter: float, near: float = 0.05) -> float:
    """The drawn drops' expected coverage of a ray from the camera to beyond `radius`: the double integral
    over distance r and diameter D of N(D) w(D, r) pi D^2 / 4 (physics.md eqs. 2.1-2.3), by adaptive
    quadrature, with w the smoothstep fade over the outer quarter of r(D) = radius min(1, D / full_diameter).
    """
    lam = slope(rate)

    def weight(d: float, r: float) -> float:
        reach = radius * min(1.0, d / full_diameter)
        x = min(max((reach - r) / (0.25 * reach), 0.0), 1.0)
        return x * x * (3 - 2 * x)

    def sigma(r: float) -> float:
        return integrate.quad(
            lambda d: N0 * math.exp(-lam * d) * weight(d, r) * math.pi / 4 * d * d * 1e-6,
            D_MIN,
            D_MAX,
            limit=200,
            points=[full_diameter],
        )[0]

    return integrate.quad(sigma, near, radius, limit=200)[0]
