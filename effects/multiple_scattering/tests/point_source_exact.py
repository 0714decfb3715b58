"""The exact diffuse light around an isotropic point lamp in an infinite medium that scatters
isotropically (g = 0): an outside reference for the lamps' multiple-scattering table at every
optical distance, including the thick fog where the path tracer is noise-limited
(effects/multiple_scattering/physics.md section 11, eqs. 11.7 to 11.9).

It shares nothing with the table's builder (effects/multiple_scattering/point_source.cpp, a Monte
Carlo of the source J binned in (R, theta)): the fluence comes from the Fourier transform of the
transport equation, inverted by a contour integral (a pole and a branch cut, both real and
free of oscillation), then integrated along the view ray by adaptive quadrature. Optical units
(sigma_t = 1) and a lamp of unit intensity (4 pi of power), as the table."""

from __future__ import annotations

import functools
import math

from scipy import integrate, optimize


@functools.lru_cache(maxsize=64)
def diffusion_pole(albedo: float) -> float:
    """kappa_0 of eq. 11.8: the root in (0, 1) of albedo artanh(kappa) / kappa = 1 (the rate
    exp(-kappa_0 R) at which the diffuse light falls far from the lamp)."""
    if not 0.0 < albedo < 1.0:
        raise ValueError(f"albedo must lie in (0, 1), got {albedo}")
    return optimize.brentq(lambda k: albedo * math.atanh(k) / k - 1.0, 1e-12, 1.0 - 1e-15,
                           xtol=1e-16, rtol=1e-15)


def _collided_fourier(t: complex | float, albedo: float) -> complex | float:
    """Eq. 11.7: the transform of the fluence of scattered light, a T^2 / (1 - a T), from T."""
    return albedo * t * t / (1.0 - albedo * t)


def collided_fluence(r: float, albedo: float) -> float:
    """G_c(r): the fluence of light scattered at least once, at optical distance r from a lamp of
    unit power, by the contour form eq. 11.8 (the pole's diffusion mode less the branch cut)."""
    k0 = diffusion_pole(albedo)
    pole = k0 * k0 * math.exp(-k0 * r) / (albedo * albedo * (1.0 / (1.0 - k0 * k0) - 1.0 / albedo))

    def cut(kappa: float) -> float:
        t_plus = math.atanh(1.0 / kappa) / kappa - 0.5j * math.pi / kappa  # T just right of the cut
        return kappa * math.exp(-kappa * r) * _collided_fourier(t_plus, albedo).imag

    # Far out the cut is a vanishing part next to the pole's e^{-kappa_0 r}: its absolute tolerance.
    # e^{-kappa r} puts the cut's weight within ~1 / r of kappa = 1: integrate that part apart.
    split = 1.0 + 50.0 / max(r, 1e-3)
    branch = sum(integrate.quad(cut, lo, hi, epsabs=1e-13 * math.pi * pole, epsrel=1e-11, limit=400)[0]
                 for lo, hi in ((1.0, split), (split, math.inf)))
    return pole / (2.0 * math.pi * r) - branch / (2.0 * math.pi ** 2 * r)


def collided_fluence_fourier(r: float, albedo: float) -> float:
    """G_c(r) by the plain inverse transform of eq. 11.7, (1 / (2 pi^2 r)) int k sin(k r) G_c(k) dk
    (an oscillatory integral: a check of eq. 11.8 where r is a few mean free paths or less)."""
    def f(k: float) -> float:
        t = math.atan(k) / k if k > 0.0 else 1.0
        return k * _collided_fourier(t, albedo)

    value, _ = integrate.quad(f, 0.0, math.inf, weight="sin", wvar=r, limlst=200)
    return value / (2.0 * math.pi ** 2 * r)


def glow(tau: float, gamma: float, albedo: float) -> float:
    """Eq. 11.9: the light scattered at least twice seen from optical distance tau of a lamp of unit
    intensity, looking gamma radians away from it; the table's L(tau, gamma) of eq. 11.4 for g = 0."""
    b, h = tau * math.cos(gamma), tau * math.sin(gamma)

    def integrand(s: float) -> float:
        return math.exp(-s) * albedo * collided_fluence(math.hypot(s - b, h), albedo)

    closest = max(b, 1e-12)  # the ray passes nearest to the lamp here (J ~ 1 / R)
    near, _ = integrate.quad(integrand, 0.0, closest, epsabs=0.0, epsrel=1e-9, limit=200)
    far, _ = integrate.quad(integrand, closest, math.inf, epsabs=0.0, epsrel=1e-9, limit=200)
    return near + far


def single(tau: float, gamma: float, albedo: float) -> float:
    """The light scattered once, a / (4 pi) int e^{-s} e^{-R} / R^2 ds along the same ray (the airlight
    of effects/lamp_airlight/physics.md for g = 0), with s = b + h sinh u (R = h cosh u, ds = R du) so
    that the integrand stays smooth where the ray passes the lamp."""
    b, h = tau * math.cos(gamma), tau * math.sin(gamma)

    def integrand(u: float) -> float:
        if u > 700.0:  # e^{-h e^u / 2}: nothing left, and cosh would overflow
            return 0.0
        r = h * math.cosh(u)
        return math.exp(-(b + h * math.sinh(u)) - r) / r

    if b <= 0.0:  # looking away from the lamp: R >= tau all along, a plain integral in s
        value, _ = integrate.quad(lambda s: math.exp(-s - math.hypot(s - b, h)) / ((s - b) ** 2 + h * h),
                                  0.0, math.inf, epsabs=0.0, epsrel=1e-10, limit=200)
    else:  # u = asinh(-b / h) at the camera, 0 where the ray passes nearest the lamp
        start = math.asinh(-b / h)
        value = sum(integrate.quad(integrand, lo, hi, epsabs=0.0, epsrel=1e-10, limit=200)[0]
                    for lo, hi in ((start, 0.0), (0.0, math.inf)))
    return albedo / (4.0 * math.pi) * value


def hemisphere_kernel(beta: float, gamma: float) -> float:
    """int_0^{2 pi} max(cos beta cos gamma + sin beta sin gamma cos phi, 0) dphi (physics.md eq. 13.3):
    the weight of light arriving gamma off the lamp's direction on a surface whose normal is beta off it."""
    a, b = math.cos(beta) * math.cos(gamma), abs(math.sin(beta) * math.sin(gamma))
    if b <= abs(a):
        return 2.0 * math.pi * a if a > 0.0 else 0.0
    phi0 = math.acos(-a / b)
    return 2.0 * (a * phi0 + b * math.sin(phi0))


def irradiance(tau: float, beta: float, albedo: float) -> float:
    """The irradiance of the light scattered at least twice on a surface element at optical distance tau,
    its normal beta off the lamp's direction: int_0^pi L(tau, gamma) sin gamma K(beta, gamma) dgamma
    (physics.md section 13) with L of eq. 11.9 (adaptive quadrature; tens of seconds a value)."""
    edge = math.pi / 2.0 + beta if beta < math.pi / 2.0 else None  # where K reaches 0 (beta < 90 deg)
    value, _ = integrate.quad(lambda g: glow(tau, g, albedo) * math.sin(g) * hemisphere_kernel(beta, g),
                              0.0, math.pi, epsabs=0.0, epsrel=1e-6, limit=200,
                              points=None if edge is None or edge >= math.pi else [edge])
    return value


def scattered_power(albedo: float, r_max: float = 200.0) -> float:
    """int G_c 4 pi r^2 dr over the ball of radius r_max, by quadrature of eq. 11.8; with the whole
    space it is the transform at k = 0, albedo / (1 - albedo) (each photon's mean number of
    scatterings times its mean free path)."""
    value, _ = integrate.quad(lambda r: 4.0 * math.pi * r * r * collided_fluence(r, albedo), 0.0, r_max,
                              epsabs=0.0, epsrel=1e-9, limit=400, points=[1.0, 10.0])
    return value


__all__ = ["collided_fluence", "collided_fluence_fourier", "diffusion_pole", "glow", "hemisphere_kernel",
           "irradiance", "scattered_power", "single"]
