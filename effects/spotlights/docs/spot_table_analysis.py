#!/usr/bin/env python3
"""Design study: spotlight airlight (effects/spotlights/physics.md) in float32 shaders.

Recommendation and explanation: effects/spotlights/docs/spot_table.md. Everything printed here is
quoted there. numpy + scipy only; about 1-2 minutes.

    python3 effects/spotlights/docs/spot_table_analysis.py            # full report
    python3 effects/spotlights/docs/spot_table_analysis.py --quick    # fewer cases (smoke test)

Model. Ray o + x d, light S (apex), unit axis a, half-angle A, c = cos A,
profile I(theta) = I0 [(1 - q)(cos theta - c)/(1 - c) + q] = alpha + beta cos theta
for theta <= A (else 0). With b = (S - o).d, h m = S - o - b d (|m| = 1) and
xi(x) = pi/4 + atan((x - b)/h)/2 (effects/lamp_airlight/physics.md):

    cos theta(xi) = -(d.a) cos 2xi - (m.a) sin 2xi,   x + d(x) = b + h tan xi,
    L = sigma_s/(2 pi h) exp(-sigma (x_a + d_a)) int_{xi_a}^{xi_b} I(xi) exp(-u (tan xi - tan xi_a)) dxi.

Expanding I about an end point v of the lit interval (Delta = xi - v):

    I(xi) = I_v - 2 beta cos(theta_v) sin^2(Delta) + beta g_v sin(2 Delta),
    g_v = d cos(theta)/d(2 xi) at v = [h (d.a) + (x_v - b)(m.a)] / d_v,

so the tail from v to pi/2 is Q(u, v) [I_v - 2 beta cos(theta_v) M2 + beta g_v M1] with
the LOCAL moments M1 = <sin 2 Delta>, M2 = <sin^2 Delta> of the weight
exp(-u (tan xi - tan v)) on [v, pi/2]. The recommended texel is RGBA32F
(S = Q/N, M1/N1, M2/N2, unused) on the airlight tail grid (X = sqrt(z/(1+z)),
z = u sec v, Y = v/(pi/2)); N1 = cv/(1 + lam cv/2), N2 = N1^2/2,
lam = u sec^2 v, cv = pi/2 - v.
"""
import argparse
import os
import sys
import time

import numpy as np
from scipy.integrate import quad

# The lamp airlight's analysis, whose table this one extends, lives with its effect.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "lamp_airlight", "docs"))
from airlight_table_analysis import Q_ref, bilinear_f32, build_S_table  # noqa: E402

f32 = np.float32
PI = np.pi
HALF_PI = np.pi / 2


# ---------------------------------------------------------------------------
# 1. Tables (double-precision build, stored float32)
# ---------------------------------------------------------------------------
GL10_X, GL10_W = np.polynomial.legendre.leggauss(10)


def weighted_moments(u, cv):
    """For arrays u >= 0, cv = pi/2 - v in (0, pi/2]: returns Q and the weighted
    averages <sin 2D>, <sin^2 D>, <cos^2 xi>, <sin xi cos xi> (D = xi - v) of the
    weight exp(-u (tan xi - tan v)) on [v, pi/2]. Composite 10-point Gauss-Legendre
    in D on panels graded geometrically from D = 0 (scale 1/lam) and from xi = pi/2
    (boundary layer of width ~u), plus 16 uniform panels."""
    u = np.asarray(u, float)[:, None]
    cv = np.asarray(cv, float)[:, None]
    sc = np.sin(cv)
    lam = u / sc ** 2
    with np.errstate(divide="ignore"):
        dl = np.where(lam > 0, 1 / lam, 1e300)
    k1 = 2.0 ** np.arange(-4, 44)
    k2 = 2.0 ** np.arange(-4, 36)
    edges = np.concatenate([cv * np.linspace(0, 1, 17)[None, :],
                            np.minimum(cv, dl * k1[None, :]),
                            cv - np.minimum(cv, u * k2[None, :])], axis=1)
    edges = np.sort(edges, axis=1)
    lo, hi = edges[:, :-1], edges[:, 1:]
    half = 0.5 * (hi - lo)
    mid = 0.5 * (hi + lo)
    acc = np.zeros((u.shape[0], 5))
    v = HALF_PI - cv
    for xk, wk in zip(GL10_X, GL10_W):
        D = mid + half * xk
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            ex = u * np.sin(D) / (sc * np.sin(cv - D))
            w = np.where(cv - D > 0, np.exp(-ex), 0.0) * wk * half
        xi = v + D
        acc[:, 0] += w.sum(1)
        acc[:, 1] += (w * np.sin(2 * D)).sum(1)
        acc[:, 2] += (w * np.sin(D) ** 2).sum(1)
        acc[:, 3] += (w * np.cos(xi) ** 2).sum(1)
        acc[:, 4] += (w * np.sin(xi) * np.cos(xi)).sum(1)
    Q = acc[:, 0]
    return Q, acc[:, 1] / Q, acc[:, 2] / Q, acc[:, 3] / Q, acc[:, 4] / Q


def normalisers(u, cv, variant="local"):
    """Normalisers of the two extra channels (double or float32 inputs)."""
    s = np.sin(cv)
    lam = u / (s * s)
    if variant == "local":
        N1 = cv / (1 + 0.5 * lam * cv)
        return N1, 0.5 * N1 * N1
    if variant == "localB":             # matches the 1/lam terms: M1 ~ 2/lam (1 - 4t/lam), M2 ~ 2/lam^2 (1 - 10t/lam)
        t = np.cos(cv) / s
        return 2 / (lam + 4 * t + PI), 2 / (lam + 5 * t + 2) ** 2
    if variant == "localC":
        t = np.cos(cv) / s
        N1 = cv / (1 + 0.5 * lam * cv + 2 * t * cv)
        return N1, 0.5 * cv * cv / (1 + 0.5 * lam * cv + 2.5 * t * cv) ** 2
    if variant == "local_raw":          # no normaliser (ratios M1, M2 stored as is)
        one = np.ones_like(cv)
        return one, one
    if variant == "global":             # brief: rho_c = <cos^2>/cos^2 v, rho_sc = <sin cos>/cos v
        return s * s, s
    raise ValueError(variant)


def build_moment_tables(nx, ny, variant="local"):
    """float32 arrays (ny, nx): channel 1 and 2 (see module doc), S from the airlight script."""
    X = np.linspace(0, 1, nx)
    Y = np.linspace(0, 1, ny)
    YY, XX = np.meshgrid(Y, X, indexing="ij")
    r = XX ** 2
    with np.errstate(divide="ignore"):
        z = r / (1 - r)
    cv = (1 - YY) * HALF_PI
    # end rows/columns: evaluate just inside (the functions are continuous there)
    zc = np.clip(z, 0, 1e9)
    cvc = np.maximum(cv, 1e-6)
    u = zc * np.sin(cvc)
    ch1 = np.empty(XX.size)
    ch2 = np.empty(XX.size)
    uf, cf = u.ravel(), cvc.ravel()
    for i0 in range(0, uf.size, 2048):
        sl = slice(i0, i0 + 2048)
        Q, m1, m2, c2, s2 = weighted_moments(uf[sl], cf[sl])
        N1, N2 = normalisers(uf[sl], cf[sl], variant)
        if variant == "global":
            ch1[sl], ch2[sl] = c2 / N1, s2 / N2
        else:
            ch1[sl], ch2[sl] = m1 / N1, m2 / N2
    return ch1.reshape(XX.shape).astype(f32), ch2.reshape(XX.shape).astype(f32)


def table_coords_f32(u, cv):
    u = np.asarray(u, f32)
    cv = np.asarray(cv, f32)
    s = np.sin(cv)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        z = np.minimum(u / s, f32(1e20))
        X = np.sqrt(z / (z + f32(1)))
    return X, f32(1) - cv * f32(2 / PI)


def check_tables(rng, tabs, variant, n=40000):
    """max relative error of the sampled channels (as moments) at random (u, v)."""
    u = 10 ** rng.uniform(-5, 4, n)
    u[: n // 20] = 0.0
    cv = np.where(rng.random(n) < 0.5, 10 ** rng.uniform(-6, 0, n), rng.uniform(0, HALF_PI, n))
    cv = np.clip(cv, 1e-6, HALF_PI)
    Q, m1, m2, c2, s2 = weighted_moments(u, cv)
    X, Y = table_coords_f32(u, cv)
    N1, N2 = normalisers(u.astype(f32), cv.astype(f32), variant)
    a1 = bilinear_f32(tabs[1], X, Y) * N1
    a2 = bilinear_f32(tabs[2], X, Y) * N2
    e_q = np.abs(bilinear_f32(tabs[0], X, Y) / (Q_ref(u, cv) * (1 + u * cv / np.sin(cv) ** 2) / cv) - 1)
    if variant == "global":
        r1, r2 = c2, s2
        a1 = a1.astype(float); a2 = a2.astype(float)
    else:
        r1, r2 = m1, m2
    return e_q.max(), np.abs(a1 / r1 - 1).max(), np.abs(a2 / r2 - 1).max()


# ---------------------------------------------------------------------------
# 2. Geometry: ray-cone intersection (effects/spotlights/physics.md)
# ---------------------------------------------------------------------------
def dot(a, b):
    return (a * b).sum(-1)


def cone_interval(o, d, S, a, c, thit, dt=float, disc_form="robust"):
    """Lit interval [x0, x1] of the ray o + x d, x in [0, thit], inside the forward
    nappe of the cone (apex S, unit axis a, cos half-angle c). Vectorised, computed
    in precision dt. Returns x0, x1, lit(bool), wall0, wall1 (end point is a root).
    disc_form: "robust" disc/4 = c^2 (A h^2 + (w_perp.a)^2); "naive" (B/2)^2 - A C."""
    o, d, S, a = (np.asarray(v, dt) for v in (o, d, S, a))
    c = np.asarray(c, dt)
    thit = np.asarray(thit, dt)
    one = dt(1)
    w = o - S
    da, wa, dw, ww = dot(d, a), dot(w, a), dot(w, d), dot(w, w)
    A = (da - c) * (da + c) if dt is f32 else da * da - c * c * dot(d, d)   # double: |d| != 1 exactly
    hB = da * wa - c * c * dw
    nw = np.sqrt(ww)
    C = (wa - c * nw) * (wa + c * nw)
    wp = w - dw[:, None] * d                       # = -(h m)
    if disc_form == "robust" and dt is f32:
        disc = c * c * (A * dot(wp, wp) + dot(wp, a) ** 2)
    else:
        disc = hB * hB - A * C
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        sq = np.sqrt(np.maximum(disc, dt(0)))
        qq = -(hB + np.where(hB >= 0, sq, -sq))
        r1 = np.where(disc >= 0, qq / A, np.nan)
        r2 = np.where(disc >= 0, C / qq, np.nan)
    r1 = np.where(np.isfinite(r1), r1, np.nan).astype(dt)
    r2 = np.where(np.isfinite(r2), r2, np.nan).astype(dt)
    lo_r = np.fmin(r1, r2)
    hi_r = np.fmax(r1, r2)
    # break points 0 <= p1 <= p2 <= thit (roots outside (0, thit) are dropped)
    inb = lambda r: np.isfinite(r) & (r > 0) & (r < thit)  # noqa: E731
    p1 = np.where(inb(lo_r), lo_r, np.where(inb(hi_r), hi_r, thit))
    p2 = np.where(inb(lo_r) & inb(hi_r), hi_r, thit)
    brk = [np.zeros_like(p1), p1, p2, thit]
    x0 = np.full_like(p1, np.inf)
    x1 = np.full_like(p1, -np.inf)
    for k in range(3):
        lo, hi = brk[k], brk[k + 1]
        with np.errstate(invalid="ignore", over="ignore"):
            mid = np.where(np.isfinite(hi), dt(0.5) * (lo + hi), lo + np.maximum(one, lo))
            pm = w + mid[:, None] * d
            inside = (dot(pm, a) >= c * np.sqrt(dot(pm, pm))) & (hi > lo)
        x0 = np.where(inside, np.minimum(x0, lo), x0)
        x1 = np.where(inside, np.maximum(x1, hi), x1)
    lit = x1 > x0
    wall0 = lit & (x0 > 0)
    wall1 = lit & (x1 < thit)
    return x0, x1, lit, wall0, wall1


# ---------------------------------------------------------------------------
# 3. Reference: adaptive quadrature of the defining integral in x (double)
# ---------------------------------------------------------------------------
def reference_log(g, i, x0, x1):
    """log of sigma_s/(4 pi) int_{x0}^{x1} I(theta(x)) exp(-sigma (x + d)) / d^2 dx,
    profile and clipping (theta <= A) evaluated directly; sigma_s = sigma, I0 = 1."""
    o, d, S, a = g["o"][i], g["d"][i], g["S"][i], unit(g["a"][i])
    c, q, sig = g["c"][i], g["q"][i], g["sigma"][i]
    omc = g["omc"][i]
    w = o - S
    b = -w @ d
    h = np.linalg.norm(w + b * d)
    xa = x0
    da0 = np.linalg.norm(w + xa * d)
    ref = xa + da0

    def f(x):
        p = w + x * d
        dist = np.sqrt(p @ p)
        ct = (p @ a) / dist
        if ct < c:
            return 0.0
        prof = (1 - q) * (ct - c) / omc + q
        return prof * np.exp(-sig * (x + dist - ref)) / dist ** 2

    kw = dict(epsabs=0, epsrel=1e-11, limit=200)
    xe = x1 if np.isfinite(x1) else max(x0, b) + 1e4 * h + 40 / sig
    cand = [b] + [b + s * h * 10.0 ** k for k in range(-1, 12) for s in (-1, 1)]
    cand += [x0 + (xe - x0) * f for f in (0.25, 0.5, 0.75)]
    edges = np.array(sorted({x0, xe} | {p for p in cand if x0 < p < xe}))
    val = sum(quad(f, lo, hi, **kw)[0] for lo, hi in zip(edges[:-1], edges[1:]))
    if not np.isfinite(x1):
        val += quad(f, xe, np.inf, **kw)[0]
    return np.log(sig / (4 * PI) * val) - sig * ref


# ---------------------------------------------------------------------------
# 4. float32 emulation of the proposed shader evaluation
# ---------------------------------------------------------------------------
def end_point_f32(P, xb, wall, tabs, variant):
    """Per end point tau = xb = x - b of the lit interval: exponent arg = -sigma (x + d),
    tail/E = Q <I>, abs/E (sum of magnitudes), and the quantities the fallback needs."""
    sig, b, h, da, ma, beta, q = P["sig"], P["b"], P["h"], P["da"], P["ma"], P["beta"], P["q"]
    dd = np.sqrt(h * h + xb * xb)
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(xb >= 0, dd + xb, h * h / (dd - xb))
    t = p / h
    cv = f32(0.5) * np.arctan2(h, xb)
    z = np.minimum(sig * np.sqrt(f32(2) * dd * p), f32(1e20))
    X = np.sqrt(z / (z + f32(1)))
    Y = f32(1) - cv * f32(2 / PI)
    lam = f32(2) * sig * dd * t                       # u sec^2 xi
    N = cv / (f32(1) + lam * cv)
    S = bilinear_f32(tabs[0], X, Y)
    c1 = bilinear_f32(tabs[1], X, Y)
    c2 = bilinear_f32(tabs[2], X, Y)
    Q = N * S
    # cos(theta) and g = d cos(theta)/d(2 xi) at the end point; (p - S) = xb d - h m
    ct = (xb * da - h * ma) / dd
    gg = (h * da + xb * ma) / dd
    # I at the end point: q on a wall (exact), else from sin^2 (no cos - cos A cancellation)
    st2 = P["an"] * P["an"] + gg * gg                  # sin^2 theta = |(p - S) x a|^2 / d^2
    Iv = (f32(1) - q) * (P["sinA2"] - st2) / ((ct + P["c"]) * P["omc"]) + q
    Iv = np.where(wall, q, np.maximum(Iv, f32(0)))
    if variant == "global":
        N1, N2 = normalisers(sig * h, cv, "global")   # cos^2 xi, cos xi
        C2, SC = c1 * N1, c2 * N2                      # <cos^2 xi>, <sin xi cos xi>
        alpha = q - beta * P["c"]
        A2, A1, A0 = alpha + beta * da, f32(-2) * beta * ma, alpha - beta * da
        tl = A2 * (f32(1) - C2) + A1 * SC + A0 * C2
        ab = np.abs(A2) * (f32(1) - C2) + np.abs(A1) * SC + np.abs(A0) * C2
    else:
        N1, N2 = normalisers(sig * h, cv, variant)
        M1, M2 = c1 * N1, c2 * N2
        tl = Iv - f32(2) * beta * ct * M2 + beta * gg * M1
        ab = np.abs(Iv) + f32(2) * beta * np.abs(ct) * M2 + beta * np.abs(gg) * M1
    arg = -sig * ((b + xb) + dd)
    return dict(arg=arg, tail=Q * tl, abs=Q * ab, cv=cv, ct=ct, g=gg, I=Iv, xb=xb)


GL = {n: tuple(np.asarray(v, f32) for v in np.polynomial.legendre.leggauss(n)) for n in (2, 3, 4, 5, 6, 8)}


def fallback_f32(P, ea, x0, x1, esc, n, graded, seg=None):
    """J/E_a = int_{xi_a}^{xi_b} I(xi) exp(-u (tan xi - tan xi_a)) dxi by n-point
    Gauss-Legendre in xi (graded: in the variable that absorbs exp(-k (xi - xi_a)),
    k = lam_ab / dxi, lam_ab = u (tan xi_b - tan xi_a)), I expanded about xi_a."""
    sig, b, h, beta = P["sig"], P["b"], P["h"], P["beta"]
    u = sig * h
    cva = ea["cv"]
    with np.errstate(invalid="ignore", over="ignore"):
        seg = (x1 - x0) if seg is None else seg           # x1 - x0 (kept exact for clip ends)
        dv = np.where(esc, cva, f32(0.5) * np.arctan2(h * seg, h * h + x0 * x1))   # x = tau here
    sa = np.sin(cva)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        lam = np.where(esc, f32(np.inf), u * np.sin(dv) / (sa * np.sin(cva - dv)))
    xs, ws = GL[n]
    J = np.zeros_like(dv)
    use_g = graded & (lam > f32(0.5)) & np.isfinite(lam)
    om = -np.expm1(-lam.astype(np.float64)).astype(f32)      # 1 - e^{-lam} (well conditioned here)
    for xk, wk in zip(xs, ws):
        fk = f32(0.5) * (f32(1) + xk)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ek = f32(1) - fk * om
            Dg = -np.log(ek) / lam * dv
            wg = om / (lam * ek) * dv                       # dDelta/df
            Dk = np.where(use_g, Dg, fk * dv)
            wj = np.where(use_g, wg, dv)
            ex = u * np.sin(Dk) / (sa * np.sin(cva - Dk))
            Ik = ea["I"] - f32(2) * beta * ea["ct"] * np.sin(Dk) ** 2 + beta * ea["g"] * np.sin(f32(2) * Dk)
            J = J + f32(0.5) * wk * wj * Ik * np.where(Dk < cva, np.exp(-ex), f32(0))
    return J


def cross_f32_fma(u, v):
    """cross product of float32 vectors with each component a difference of two
    products rounded once (what Kahan's fma-based difference of products gives)."""
    return np.cross(u.astype(float), v.astype(float)).astype(f32)


def prep_f32(g, idx, hm_form="cross"):
    """Per-(ray, light) constants in float32 (what the shader has per pixel):
    b = (S - o).d, h m = S - o - b d, h, d.a, m.a, n.a with n = d x m."""
    o, d, S, a = (g[k][idx].astype(f32) for k in ("o", "d", "S", "a"))
    w = o - S
    b = -dot(w, d)
    if hm_form == "cross":                      # c1 = (S - o) x d (fma), h m = d x c1, n = -c1/h
        c1 = cross_f32_fma(-w, d)
        hm = np.cross(d, c1).astype(f32)
        h = np.sqrt(dot(c1, c1))
    else:                                       # naive: h m = (S - o) - b d (cancels for h << |w|)
        hm = -w - b[:, None] * d
        h = np.sqrt(dot(hm, hm))
        c1 = np.cross(-w, d).astype(f32)
    h = np.maximum(h, f32(1e-6) * np.sqrt(dot(w, w)))
    P = dict(sig=g["sigma"][idx].astype(f32), b=b, h=h, da=dot(d, a), ma=dot(hm, a) / h,
             an=-dot(c1, a) / h,
             beta=((1 - g["q"][idx]) / g["omc"][idx]).astype(f32), q=g["q"][idx].astype(f32),
             c=g["c"][idx].astype(f32), omc=g["omc"][idx].astype(f32),
             sinA2=g["sinA2"][idx].astype(f32), w=w, d=d, a=a)
    return P


def cone_interval_tau(P, thit):
    """Recommended float32 ray-cone intersection in the closest-point frame
    (tau = x - b; d, m, n orthonormal; a = da d + ma m + an n; s2 = sin^2 A):
        A  = s2 - ma^2 - an^2            (= (d.a)^2 - c^2)
        B0 = -h da ma                    (half the linear coefficient)
        C0 = h^2 (s2 - da^2 - an^2)      (= h^2 ((m.a)^2 - c^2))
        disc0 = c^2 h^2 (s2 - an^2)      (no cancellation except for tangent rays)
    Roots in the stable form, intervals clipped to [-b, thit - b], forward-nappe
    midpoint test (p - S).a = tau da - h ma >= c |p - S|."""
    h, b, da, ma, an, c, s2 = P["h"], P["b"], P["da"], P["ma"], P["an"], P["c"], P["sinA2"]
    A = s2 - ma * ma - an * an
    C0 = h * h * (s2 - da * da - an * an)
    rad = s2 - an * an
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        sq = c * h * np.sqrt(np.maximum(rad, f32(0)))
        hb = h * da * ma                                   # = -B0
        qq = hb + np.where(hb >= 0, sq, -sq)
        r1 = np.where(rad >= 0, qq / A, np.nan).astype(f32)
        r2 = np.where(rad >= 0, C0 / qq, np.nan).astype(f32)
    r1 = np.where(np.isfinite(r1), r1, np.nan)
    r2 = np.where(np.isfinite(r2), r2, np.nan)
    lo_r, hi_r = np.fmin(r1, r2), np.fmax(r1, r2)
    t0 = -b
    t3 = thit - b                                      # inf for escaping rays
    inb = lambda r: np.isfinite(r) & (r > t0) & (r < t3)  # noqa: E731
    p1 = np.where(inb(lo_r), lo_r, np.where(inb(hi_r), hi_r, t3))
    p2 = np.where(inb(lo_r) & inb(hi_r), hi_r, t3)
    brk = [t0, p1, p2, t3]
    x0 = np.full_like(p1, np.inf)
    x1 = np.full_like(p1, -np.inf)
    for k in range(3):
        lo, hi = brk[k], brk[k + 1]
        with np.errstate(invalid="ignore", over="ignore"):
            mid = np.where(np.isfinite(hi), f32(0.5) * (lo + hi), lo + np.maximum(h, np.abs(lo)))
            ax = mid * da - h * ma
            inside = (ax >= 0) & (ax * ax >= c * c * (mid * mid + h * h)) & (hi > lo)
        x0 = np.where(inside, np.minimum(x0, lo), x0)
        x1 = np.where(inside, np.maximum(x1, hi), x1)
    lit = x1 > x0
    return x0, x1, lit, lit & (x0 > t0), lit & (x1 < t3)


def spot_f32(g, idx, tabs, variant="local", Kmax=4.0, n=4, graded=False, iv=None, mode="hybrid",
             isect="tau", hm_form="cross"):
    """log L (float32 pipeline; the exponent is kept as a log so that no underflow
    hides the comparison) and the fallback flag. iv: optional (x0, x1, wall0, wall1)
    (e.g. double-precision intervals) instead of the float32 intersection;
    isect: "tau" (recommended closest-point form) or "models" (A, B, C of the source paper (effects/spotlights/physics.md))."""
    P = prep_f32(g, idx, hm_form)
    thit = g["thit"][idx].astype(f32)
    b = P["b"]
    if iv is not None:
        x0, x1, w0, w1 = (np.asarray(v) for v in iv)
        lit = x1 > x0
        bb = -dot(g["o"][idx] - g["S"][idx], g["d"][idx])
        t0 = (x0 - bb).astype(f32)
        t1 = (x1 - bb).astype(f32)
    elif isect == "models":
        x0, x1, lit, w0, w1 = cone_interval(g["o"][idx], g["d"][idx], g["S"][idx], g["a"][idx],
                                            g["c"][idx], thit, dt=f32)
        t0, t1 = x0 - b, x1 - b
    else:
        t0, t1, lit, w0, w1 = cone_interval_tau(P, thit)
    t0 = np.where(lit, t0, f32(0))
    esc = lit & ~np.isfinite(t1)
    t1s = np.where(esc | ~lit, t0 + f32(1), t1)
    ea = end_point_f32(P, t0, w0, tabs, variant)
    eb = end_point_f32(P, t1s, w1, tabs, variant)
    rel = np.where(esc, f32(0), np.exp(eb["arg"] - ea["arg"]))
    Jt = ea["tail"] - rel * eb["tail"]
    with np.errstate(divide="ignore", invalid="ignore"):
        K = (ea["abs"] + rel * eb["abs"]) / np.abs(Jt)
    use_fb = (K > f32(Kmax)) | ~np.isfinite(K)
    if mode == "table":
        use_fb = np.zeros_like(use_fb)
    if mode == "quad":
        use_fb = np.ones_like(use_fb)
    # segment length from each end's own representation: clip ends (0, thit) are exact in x,
    # wall ends are exact in tau; x1 - x0 then has no eps |b| error when both ends are clips
    xe0 = np.where(w0, b + t0, f32(0))
    xe1 = np.where(w1, b + t1s, thit)
    seg = np.where(w0 | w1, t1s - t0, xe1 - xe0)
    Jf = fallback_f32(P, ea, t0, t1s, esc, n, graded, seg)
    J = np.where(use_fb, Jf, Jt)
    with np.errstate(divide="ignore", invalid="ignore"):
        logL = (np.log(P["sig"].astype(float) / (2 * PI * P["h"].astype(float)))
                + ea["arg"].astype(float) + np.log(J.astype(float)))
    logL = np.where(lit & (J > 0), logL, -np.inf)
    return logL, use_fb, lit, (t0 + b, t1 + b, w0, w1)


# ---------------------------------------------------------------------------
# 5. Test geometries
# ---------------------------------------------------------------------------
def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def perp_basis(a, rng):
    r = unit(rng.normal(size=a.shape))
    e1 = unit(np.cross(a, r))
    e2 = np.cross(a, e1)
    return e1, e2


def rot_towards(a, e, ang):
    """rotate unit a by angle ang towards unit e (e perpendicular to a)."""
    return np.cos(ang)[:, None] * a + np.sin(ang)[:, None] * e


def in_cone_dir(a, A, rng, frac=1.0):
    e1, e2 = perp_basis(a, rng)
    n = a.shape[0]
    ct = 1 - rng.random(n) * (1 - np.cos(frac * A))
    ph = rng.uniform(0, 2 * PI, n)
    st = np.sqrt(1 - ct * ct)
    return ct[:, None] * a + st[:, None] * (np.cos(ph)[:, None] * e1 + np.sin(ph)[:, None] * e2)


def make_family(name, n, rng):
    """Returns a dict of double arrays describing n (ray, spotlight) cases."""
    lu = lambda lo, hi, k=n: 10 ** rng.uniform(np.log10(lo), np.log10(hi), k)  # noqa: E731
    A = np.radians(np.where(rng.random(n) < 0.5, lu(2, 80), rng.uniform(2, 80, n)))
    q = rng.random(n)
    r = rng.random(n)
    q = np.where(r < 0.4, 0.0, np.where(r < 0.5, 1.0, q))
    sigma = lu(1e-3, 2)
    a = unit(rng.normal(size=(n, 3)))
    S = rng.uniform(-100, 100, (n, 3))
    D = lu(0.5, 500)
    thit = np.where(rng.random(n) < 0.5, np.inf, lu(0.5, 1000))
    e1, e2 = perp_basis(a, rng)
    if name == "random":
        rdir = np.where((rng.random(n) < 0.4)[:, None], in_cone_dir(a, A, rng), unit(rng.normal(size=(n, 3))))
        o = S + D[:, None] * rdir
        tgt = S + (D * lu(0.1, 3))[:, None] * in_cone_dir(a, A, rng)
        k = rng.random(n)
        d = np.where((k < 0.35)[:, None], unit(tgt - o),
                     np.where((k < 0.5)[:, None], unit(a + 0.3 * rng.normal(size=(n, 3))),
                              unit(rng.normal(size=(n, 3)))))
    elif name == "narrow_thick":         # 2 degrees, q = 0, thick fog, aimed through the beam
        A[:] = np.radians(2.0)
        q[:] = 0.0
        sigma = lu(0.05, 2)
        o = S + D[:, None] * unit(rng.normal(size=(n, 3)))
        tgt = S + (D * lu(0.05, 3))[:, None] * in_cone_dir(a, A, rng)
        d = unit(tgt - o)
    elif name == "inside_axis":          # camera inside the cone looking along the axis
        o = S + D[:, None] * in_cone_dir(a, A, rng, 0.9)
        d = in_cone_dir(a, A, rng, rng.uniform(0, 0.5, n)[:, None] if False else 0.5)
        d = np.where((rng.random(n) < 0.3)[:, None], a, d)
    elif name == "inside_back":          # camera inside the cone looking back towards the lamp
        o = S + D[:, None] * in_cone_dir(a, A, rng, 0.9)
        off = (D * lu(1e-3, 0.3))[:, None] * e1
        d = unit(S + off - o)
        thit = np.where(rng.random(n) < 0.5, np.inf, D * rng.uniform(0.2, 1.5, n))
    elif name == "grazing_parallel":     # ray (nearly) parallel to a wall generator: A ~ 0
        gen = rot_towards(a, e1, A)
        nrm = rot_towards(a, e1, A + PI / 2)         # outward normal in the (a, e1) plane
        eps = lu(1e-7, 1e-2) * np.where(rng.random(n) < 0.5, 1, -1)
        d = unit(rot_towards(gen, nrm, eps))
        s0 = D * rng.uniform(0.05, 1, n)
        o = S + s0[:, None] * gen + (D * lu(1e-6, 0.05) * np.where(rng.random(n) < 0.5, 1, -1))[:, None] * nrm
        d = np.where((rng.random(n) < 0.3)[:, None], -d, d)
    elif name == "grazing_tangent":      # ray touching the cone from outside, slightly inside
        gen = rot_towards(a, e1, A)
        nrm = rot_towards(a, e1, A + PI / 2)
        P0 = S + (D * rng.uniform(0.1, 1, n))[:, None] * gen
        dep = lu(1e-7, 3e-2) * np.linalg.norm(P0 - S, axis=1) * np.sin(A)
        d = e2
        o = P0 - dep[:, None] * nrm - (D * rng.uniform(0.05, 2, n))[:, None] * d
    elif name == "short_hit":            # surface just behind the entry point
        o = S + D[:, None] * unit(rng.normal(size=(n, 3)))
        tgt = S + (D * lu(0.1, 3))[:, None] * in_cone_dir(a, A, rng)
        d = unit(tgt - o)
        thit = np.full(n, np.inf)         # set below, after the entry point is known
    elif name == "mirror":               # camera in the mirror cone, ray through the apex region
        o = S - D[:, None] * in_cone_dir(a, A, rng, 0.9)
        tgt = S + (D * lu(0.01, 2))[:, None] * in_cone_dir(a, A, rng)
        d = unit(tgt - o)
    elif name == "wide_inside":          # 80 degrees, camera inside, any direction
        A[:] = np.radians(80.0)
        o = S + D[:, None] * in_cone_dir(a, A, rng, 0.95)
        d = unit(rng.normal(size=(n, 3)))
    else:
        raise ValueError(name)
    # what the shader receives: camera-relative light position, float32 unit vectors
    w32 = (o - S).astype(f32).astype(float)
    S = np.zeros_like(S)
    o = w32
    # float32 values taken as exact; the reference normalises a (its direction is what
    # matters) and parametrises the ray by d as given (|d| = 1 +- 6e-8)
    d = d.astype(f32).astype(float)
    a = a.astype(f32).astype(float)
    g = dict(S=S, a=a, A=A, q=q, sigma=sigma, o=o, d=d, thit=thit)
    g["c"] = np.cos(A)
    g["omc"] = 2 * np.sin(A / 2) ** 2
    g["sinA2"] = np.sin(A) ** 2
    if name == "short_hit":
        x0, x1, lit, _, _ = cone_interval(o, d, S, a, g["c"], thit)
        ent = np.where(lit, x0, 1.0)
        g["thit"] = ent + np.maximum(ent, 1.0) * lu(1e-6, 1e-1)
    return g


def with_reference(g, tmax=None):
    """Double-precision lit intervals and reference log L; drops unlit cases."""
    x0, x1, lit, w0, w1 = cone_interval(g["o"], g["d"], g["S"], unit(g["a"]), g["c"], g["thit"])
    # drop cases whose lit interval is shorter than float32 can place (2 ulp of x0)
    ok = lit & ((x1 - x0) > 4e-7 * np.maximum(np.abs(x0), 1e-30))
    idx = np.nonzero(ok)[0]
    ref = np.array([reference_log(g, i, x0[i], x1[i]) for i in idx])
    fin = np.isfinite(ref)
    idx = idx[fin]
    g = {k: v[idx] for k, v in g.items()}
    g["ref"] = ref[fin]
    g["iv64"] = (x0[idx], x1[idx], w0[idx], w1[idx])
    return g


# ---------------------------------------------------------------------------
# 6. Report
# ---------------------------------------------------------------------------
FAMILIES = ["random", "narrow_thick", "inside_axis", "inside_back", "mirror", "wide_inside",
            "grazing_parallel", "grazing_tangent", "short_hit"]
WELL = FAMILIES[:6]                 # families without near-degenerate intersections


def errors(g, logL):
    """relative errors; cases whose true value underflows float32 (optical depth of
    the lit start > 80) are left out; an unlit/zero result counts as error 1."""
    rel = -g["ref"] < 80
    e = np.abs(np.expm1(logL - g["ref"]))
    e[~np.isfinite(e)] = np.where(np.isneginf(logL[~np.isfinite(e)]), 1.0, np.inf)
    return e[rel]


def fmt(e):
    return f"{e.max():.1e}" if e.size else "-"


def rel_length(g):
    x0, x1 = g["iv64"][:2]
    b = -dot(g["o"] - g["S"], g["d"])
    h = np.linalg.norm(np.cross(g["o"] - g["S"], g["d"]), axis=1)
    return np.where(np.isfinite(x1), (x1 - x0) / (np.abs(x0) + np.abs(b) + h), 1.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--n", type=int, default=1500, help="cases per family")
    args = ap.parse_args()
    n = 300 if args.quick else args.n
    t_start = time.time()
    rng = np.random.default_rng(2024)
    import warnings
    warnings.filterwarnings("ignore")

    print("A. Extra table channels: max relative error of the bilinear float32 lookup")
    print("   (u log-uniform 1e-5..1e4 plus u = 0; half of v within 1e-6..1 of pi/2)")
    print("| channels | normalisers | texels | S = Q/N | ch1 | ch2 |")
    print("|---|---|---|---|---|---|")
    tabs_by = {}
    for variant, label in [("local", "M1/N1, M2/N2 (recommended)"), ("localB", "M1, M2 / 2/(lam+4t+pi), 2/(lam+5t+2)^2"),
                           ("global", "brief: <cos^2>/cos^2 v, <sin cos>/cos v")]:
        for nx, ny in [(128, 64), (256, 64), (512, 64), (512, 128)]:
            if variant != "local" and (nx, ny) not in [(256, 64), (512, 64)]:
                continue
            S = build_S_table(nx, ny)
            c1, c2 = build_moment_tables(nx, ny, variant)
            tabs_by[(variant, nx, ny)] = (S, c1, c2)
            eq, e1, e2 = check_tables(np.random.default_rng(1), (S, c1, c2), variant, 20000 if args.quick else 40000)
            print(f"| {'M1, M2' if variant != 'global' else 'rho_c, rho_sc'} | {label} | {nx}x{ny} | {eq:.1e} | {e1:.1e} | {e2:.1e} |")
    print(f"   [{time.time() - t_start:.0f} s]")

    fams = {}
    for name in FAMILIES:
        t0 = time.time()
        fams[name] = with_reference(make_family(name, n, rng))
        fams[name]["t_ref"] = time.time() - t0
    print(f"\nreference ready: {sum(len(g['ref']) for g in fams.values())} lit cases "
          f"[{time.time() - t_start:.0f} s]")

    rec = tabs_by[("local", 256, 64)]

    def run(g, tabs=rec, **kw):
        idx = np.arange(len(g["ref"]))
        lL, fb, lit, _ = spot_f32(g, idx, tabs, **kw)
        return errors(g, lL), fb

    print("\nB. End to end, float32 emulation, max relative error per family "
          "(256x64 RGBA32F table, closest-point intersection)")
    configs = [("table only", dict(mode="table")),
               ("K>4: GL3 in xi", dict(Kmax=4, n=3, graded=False)),
               ("**K>4: GL4 in xi (rec.)**", dict(Kmax=4, n=4, graded=False)),
               ("K>4: GL6 in xi", dict(Kmax=4, n=6, graded=False)),
               ("K>2: GL4 in xi", dict(Kmax=2, n=4, graded=False)),
               ("K>8: GL4 in xi", dict(Kmax=8, n=4, graded=False)),
               ("K>16: GL4 in xi", dict(Kmax=16, n=4, graded=False)),
               ("K>64: GL4 in xi", dict(Kmax=64, n=4, graded=False)),
               ("K>4: GL4 graded (exp-absorbing variable)", dict(Kmax=4, n=4, graded=True)),
               ("K>4: GL6 graded", dict(Kmax=4, n=6, graded=True)),
               ("always GL8 in xi (no table)", dict(mode="quad", n=8, graded=False)),
               ("always GL8 graded (no table)", dict(mode="quad", n=8, graded=True))]
    print("| evaluation | " + " | ".join(WELL) + " | fallback share (random) |")
    print("|---|" + "---|" * (len(WELL) + 1))
    for label, kw in configs:
        cols, share = [], None
        for name in WELL:
            e, fb = run(fams[name], **kw)
            cols.append(fmt(e))
            if name == "random":
                share = fb.mean()
        print(f"| {label} | " + " | ".join(cols) + f" | {share:.2f} |")
    print(f"   [{time.time() - t_start:.0f} s]")

    print("\nC. Table size and channel choice (evaluation: K > 4 -> GL4 in xi)")
    print("| table | " + " | ".join(WELL) + " |")
    print("|---|" + "---|" * len(WELL))
    for key in [("local", 128, 64), ("local", 256, 64), ("local", 512, 64), ("local", 512, 128),
                ("localB", 256, 64), ("global", 256, 64), ("global", 512, 64)]:
        cols = [fmt(run(fams[nm], tabs=tabs_by[key], variant=key[0], Kmax=4, n=4, graded=False)[0]) for nm in WELL]
        print(f"| {key[0]} {key[1]}x{key[2]} | " + " | ".join(cols) + " |")
    cols = [fmt(run(fams[nm], tabs=tabs_by[("global", 256, 64)], variant="global", mode="table")[0]) for nm in WELL]
    print("| global 256x64, table only | " + " | ".join(cols) + " |")

    print("\nD. Intersection and frame variants (evaluation: K > 4 -> GL4 in xi, 256x64)")
    print("| variant | " + " | ".join(FAMILIES) + " |")
    print("|---|" + "---|" * len(FAMILIES))
    for label, kw in [("source A,B,C in float32 (robust disc), naive h m", dict(isect="models", hm_form="naive")),
                      ("closest-point form, naive h m = (S-o) - b d", dict(hm_form="naive")),
                      ("closest-point form, h m from fma cross (rec.)", dict())]:
        cols = [fmt(run(fams[nm], Kmax=4, n=4, graded=False, **kw)[0]) for nm in FAMILIES]
        print(f"| {label} | " + " | ".join(cols) + " |")

    print("\nE. Near-degenerate intersections (recommended pipeline), by relative lit length")
    print("   l = (x1 - x0) / (|x0| + |b| + h) (grazing_parallel: l = |(d.a)^2 - c^2|);")
    print("   share of cases above 1e-3 and 5e-3 and the max")
    print("| family | l range | cases | > 1e-3 | > 5e-3 | max |")
    print("|---|---|---|---|---|---|")
    for name in ["grazing_parallel", "grazing_tangent", "short_hit"]:
        g = fams[name]
        idx = np.arange(len(g["ref"]))
        lL, fb, lit, _ = spot_f32(g, idx, rec, Kmax=4, n=4, graded=False)
        keep = -g["ref"] < 80
        e = np.abs(np.expm1(lL - g["ref"]))
        e = np.where(np.isfinite(e), e, 1.0)[keep]
        ell = rel_length(g)[keep]
        if name == "grazing_parallel":   # conditioning: |A| = |(d.a)^2 - c^2| ~ sin 2A x angle to the wall
            ell = np.abs(dot(g["d"], unit(g["a"])) ** 2 - g["c"] ** 2)[keep]
        for lo, hi in [(1e-2, 2), (1e-3, 1e-2), (1e-4, 1e-3), (1e-5, 1e-4), (0, 1e-5)]:
            m = (ell >= lo) & (ell < hi)
            if m.sum():
                print(f"| {name} | {lo:g}-{hi:g} | {m.sum()} | {np.mean(e[m] > 1e-3):.3f} | "
                      f"{np.mean(e[m] > 5e-3):.3f} | {e[m].max():.1e} |")
    print(f"\ntotal {time.time() - t_start:.0f} s")


if __name__ == "__main__":
    main()
