#!/usr/bin/env python3
"""Design study: anisotropic phase functions (Henyey-Greenstein, Rayleigh, two-lobe HG)
for the point-light airlight, the spot airlight and the surface glow (issue 5).

Recommendation and explanation: effects/phase/docs/phase_table.md. Every table quoted there is
printed here (sections 0 and A to I). numpy + scipy only; it imports formulas from
effects/lamp_airlight/docs/airlight_table_analysis.py and effects/spotlights/docs/spot_table_analysis.py.

    .venv/bin/python effects/phase/docs/phase_table_analysis.py            # full report (about 2.5 minutes, 2 cores)
    .venv/bin/python effects/phase/docs/phase_table_analysis.py --quick    # fewer cases and sizes (about 30 s)

Model (effects/lamp_airlight/physics.md, "General phase function"). With P(t) = 4 pi p(cos 2t) the
airlight tail from xi to pi/2 is

    Q_p(u, xi) = int_xi^{pi/2} P(t) exp(-u (tan t - tan xi)) dt.

For HG, P = (1 - g^2) / (1 + g^2 - 2 g cos 2t)^{3/2}. With k = (1 - g)/(1 + g) and the
rescaled angle phi = atan(tan(t) / k) this is EXACTLY

    Q_p(u, xi) = 1/(1 - g) int_{phi0}^{pi/2} rho(phi) exp(-u k (tan phi - tan phi0)) dphi,
    rho(phi) = sqrt(cos^2 phi + k^2 sin^2 phi),   tan phi0 = tan(xi) / k,

i.e. the isotropic tail in phi (with u' = u k) times a smooth weight between k and 1: the
forward (g > 0) or backward (g < 0) peak of HG is absorbed by the change of variable.
The recommended table (design K) stores S = Q_p / N, one 256 x 64 float32 slice per g:

    z = sigma sqrt(c^2 h^2 + p^2), c = min(k, sqrt k);   X = sqrt(z / (1 + z))
    Y = 1 - 2/(3 pi) [atan2(h, p) + atan2(sqrt(k) h, p) + atan2(k h, p)]
    N = Ct / (1 + lam' Ct / rho(phi_e)) / (1 - g)
    cvp = atan2(k h, p), tau = k h / (R + p), R = sqrt(k^2 h^2 + p^2), Ct = cvp (tau + k)/(tau + 1),
    lam' = sigma R^2 / (k h), pi/2 - phi_e = cvp - cvp / (2 + lam' cvp)

where h is the closest distance of the ray to the light and p = d + x - b (tan xi = p / h).
Short segments (tail1 > tail0 / 2) use 4-point Gauss-Legendre in phi. At g = 0 every one of
these reduces to the isotropic design of effects/lamp_airlight/docs/airlight_table.md (the g = 0 slice is that table).
"""
import argparse
import os
import sys
import time
import warnings

import numpy as np
from scipy.integrate import quad
from scipy.special import ellipeinc

_EFFECTS = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
for _docs in ("lamp_airlight", "spotlights"):  # the analyses this one builds on live with their effects
    sys.path.insert(0, os.path.join(_EFFECTS, _docs, "docs"))
from airlight_table_analysis import Q_ref, bilinear_f32, build_S_table, geom_sets  # noqa: E402
from spot_table_analysis import build_moment_tables, weighted_moments  # noqa: E402

f32 = np.float32
PI = np.pi
HALF_PI = np.pi / 2


def kk(g):
    return (1 - g) / (1 + g)


# ---------------------------------------------------------------------------
# 1. Reference (double precision): the phi form, composite Gauss-Legendre
# ---------------------------------------------------------------------------
def rel_pattern(nlev=30, ratio=3.0, ng=10):
    """Nodes/weights on [0, 1]: panels graded geometrically (ratio) towards both ends
    down to ratio^-nlev, plus 8 uniform panels. With ng = 10 the tail is exact to 1e-11
    for every u >= 0, xi, |g| < 1 (checked below against quad, E1 and elliptic E)."""
    x, w = np.polynomial.legendre.leggauss(ng)
    e = float(ratio) ** -np.arange(1, nlev + 1.0)
    edges = np.unique(np.concatenate([[0, 1], e, 1 - e, np.linspace(0, 1, 9)]))
    lo, hi = edges[:-1], edges[1:]
    nodes = (0.5 * (lo + hi))[:, None] + (0.5 * (hi - lo))[:, None] * x[None, :]
    ww = (0.5 * (hi - lo))[:, None] * w[None, :]
    return nodes.ravel(), ww.ravel()


PAT_REF = rel_pattern(30, 3.0, 10)     # 680 nodes, 1e-11
PAT_BUILD = rel_pattern(30, 3.0, 8)    # 544 nodes, 2e-9 (table builds)


def phi_quad(up, cvp, k, span=None, weight="hg", pat=PAT_REF, moments=False):
    """int_0^span W(D) exp(-up sin D / (sin cvp sin(cvp - D))) dD, D = phi - phi0, cvp = pi/2 - phi0.
    W = rho(phi) = sqrt(sin^2(cvp - D) + k^2 cos^2(cvp - D)) ("hg"), or the Rayleigh weight
    3/4 (1 + cos^2 2t) with t = phi (k = 1) ("rayleigh"). span defaults to cvp (the tail).
    moments=True also returns the local moments <sin 2 Delta>, <sin^2 Delta> in xi
    (Delta = xi - xi0, tan xi = k tan phi), normalised by the integral (spots)."""
    up, cvp, k = [np.asarray(a, float) for a in np.broadcast_arrays(up, cvp, k)]
    span = cvp if span is None else np.broadcast_to(np.asarray(span, float), cvp.shape)
    x, w = pat
    out = np.empty(up.shape)
    m1 = np.empty(up.shape)
    m2 = np.empty(up.shape)
    fu, fc, fk, fs = up.ravel(), cvp.ravel(), k.ravel(), span.ravel()
    for i in range(0, fu.size, 1024):
        sl = slice(i, i + 1024)
        u_, c_, k_, s_ = fu[sl, None], fc[sl, None], fk[sl, None], fs[sl, None]
        D = s_ * x[None, :]
        c1 = c_ - D
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            ex = u_ * np.sin(D) / (np.sin(c_) * np.sin(c1))
            e = np.where(c1 > 0, np.exp(-ex), 0.0)
        if weight == "hg":
            W = np.sqrt(np.sin(c1) ** 2 + k_ ** 2 * np.cos(c1) ** 2)
        else:
            W = 0.75 * (1 + np.cos(2 * c1) ** 2)
        f = e * W * w[None, :]
        val = f.sum(1)
        out.ravel()[sl] = val * s_[:, 0]
        if moments:
            dl = np.arctan2(k_ * np.sin(D), np.sin(c1) * np.sin(c_) + k_ * k_ * np.cos(c1) * np.cos(c_))
            with np.errstate(invalid="ignore", divide="ignore"):
                m1.ravel()[sl] = (f * np.sin(2 * dl)).sum(1) / val
                m2.ravel()[sl] = (f * np.sin(dl) ** 2).sum(1) / val
    if moments:
        return out, m1, m2
    return out


def cvphi(cv, k):
    """pi/2 - phi0 from pi/2 - xi0: atan(k / tan xi0) = atan2(k sin cv, cos cv)."""
    return np.arctan2(k * np.sin(cv), np.cos(cv))


def hg_tail(u, cv, g, pat=PAT_REF):
    """Q_p(u, xi) for HG, xi = pi/2 - cv (exact to ~1e-11)."""
    u, cv, g = [np.asarray(a, float) for a in np.broadcast_arrays(u, cv, g)]
    k = kk(g)
    return phi_quad(u * k, cvphi(cv, k), k, pat=pat) / (1 - g)


def hg_tail_u0(cv, g):
    """Q_p(0, xi) = int_xi^{pi/2} P dt = k E(cvp | 1 - 1/k^2) / (1 - g) (incomplete elliptic E)."""
    k = kk(g)
    return k * ellipeinc(cvphi(cv, k), 1 - 1 / k ** 2) / (1 - g)


def P_hg(t, g):
    return (1 - g * g) / (1 + g * g - 2 * g * np.cos(2 * t)) ** 1.5


def check_reference(rng):
    """max relative differences of the phi-form reference against independent values."""
    out = {}
    n = 3000
    u = 10 ** rng.uniform(-6, 4, n)
    cv = 10 ** rng.uniform(-7, np.log10(HALF_PI), n)
    out["g = 0 vs complex E1 (3000 pts)"] = np.max(np.abs(hg_tail(u, cv, 0.0) / Q_ref(u, cv) - 1))
    e = 0.0
    for g in (-0.9999, -0.95, -0.5, 0.3, 0.9, 0.99, 0.9999):
        e = max(e, np.max(np.abs(hg_tail(0 * u, cv, g) / hg_tail_u0(cv, g) - 1)))
    out["u = 0 vs elliptic E, |g| <= 0.9999"] = e
    errs = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i in range(40):
            g = rng.uniform(-0.999, 0.999)
            uu = 10 ** rng.uniform(-4, 3)
            xi = rng.uniform(0, HALF_PI) if i % 2 else 10 ** rng.uniform(-5, 0)
            def f(t, g=g, uu=uu, xi=xi):
                return P_hg(t, g) * np.exp(-uu * (np.tan(t) - np.tan(xi)))
            k = kk(g)
            cand = [np.arctan(k * 2.0 ** j) for j in range(-20, 21)]
            cand += [xi + 2.0 ** -j * np.cos(xi) ** 2 / uu for j in range(-10, 30)]
            pts = sorted({xi, HALF_PI} | {q for q in cand if xi < q < HALF_PI})
            r = sum(quad(f, a, b, epsabs=0, epsrel=1e-12, limit=200)[0] for a, b in zip(pts[:-1], pts[1:]))
            errs.append(abs(hg_tail(uu, HALF_PI - xi, g) / r - 1))
    out["vs scipy quad in t, 40 random (u, xi, |g| < 0.999)"] = max(errs)
    return out


# ---------------------------------------------------------------------------
# 2. Table designs: coordinates (X, Y) and normaliser N of Q_p; S = Q_p / N is stored
# ---------------------------------------------------------------------------
# (z scale, Y warp, normaliser)
DESIGNS = {
    "A plain: N = P(xi) N_iso, iso grid": ("iso", "xi", "isoP"),
    "B phi-normaliser, iso grid": ("iso", "xi", "phi"),
    "C phi-norm., z_c, Y = phi (Cauchy CDF)": ("c", "phi", "phi"),
    "D phi-norm., z_c, Y = HG angle-CDF/xi mix": ("c", "cdfmix", "phi"),
    "E phi-norm., z_c, Y = atan(tan xi/sqrt k)": ("c", "sqrtk", "phi"),
    "F phi-norm., z_c, Y = (xi + phi)/2": ("c", "mix", "phi"),
    "G phi-norm., z_c, Y = mix3": ("c", "mix3", "phi"),
    "H plain N, z_c, Y = mix3": ("c", "mix3", "isoP"),
    "I shifted phi-norm., z = u sec xi, mix3": ("iso", "mix3", "phid"),
    "J shifted phi-norm., z_k, mix3": ("k", "mix3", "phid"),
    "K shifted phi-norm., z_c, mix3 (REC.)": ("c", "mix3", "phid"),
}
REC = DESIGNS["K shifted phi-norm., z_c, mix3 (REC.)"]


def coords(u, h, p, g, design, dt=float):
    """X, Y, N and cvp for the tail at a point with tan xi = p / h (any common scale of h, p:
    h = sin cv, p = cos cv in the (u, xi) form; h = closest distance, p = d + x - b from the
    geometry), u = sigma h. dt = f32 emulates the shader."""
    one = dt(1)
    u, h, p = (np.asarray(a, dt) for a in (u, h, p))
    g = np.asarray(g, dt)
    k = (one - g) / (one + g)
    nz, yw, nrm = design
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        R = np.sqrt(k * k * h * h + p * p)
        cvp = np.arctan2(k * h, p)                       # pi/2 - phi0
        cv = np.arctan2(h, p)                            # pi/2 - xi
        if nz == "iso":
            c = one
        elif nz == "k":
            c = k
        else:                                            # "c": min(k, sqrt k)
            c = np.minimum(k, np.sqrt(k))
        z = np.minimum(u * np.sqrt(c * c * h * h + p * p) / h, dt(1e20))
        X = np.sqrt(z / (z + one))
        if yw == "xi":
            Y = one - cv * dt(2 / PI)
        elif yw == "phi":
            Y = one - cvp * dt(2 / PI)
        elif yw == "mix":
            Y = one - (cv + cvp) * dt(1 / PI)
        elif yw == "sqrtk":
            Y = one - np.arctan2(np.sqrt(k) * h, p) * dt(2 / PI)
        elif yw == "mix3":
            Y = one - (cv + cvp + np.arctan2(np.sqrt(k) * h, p)) * dt(2 / (3 * PI))
        elif yw == "cdfmix":                             # 1/2 (xi/(pi/2) + HG angle-CDF, analytic approx.)
            tau = k * h / (R + p)
            Ct = cvp * (tau + k) / (tau + one)
            Y = dt(0.5) * (one - cv * dt(2 / PI)) + dt(0.5) * (one - Ct / (dt(PI / 4) * (one + k)))
        if nrm == "isoP":                                # P(xi) times the isotropic normaliser
            s2 = p * p / (h * h + p * p)                 # sin^2 xi
            c2 = h * h / (h * h + p * p)
            base = np.where(g >= 0, (one - g) ** 2 + dt(4) * g * s2, (one + g) ** 2 - dt(4) * g * c2)
            P = (one - g * g) / (base * np.sqrt(base))
            lam = u * (h * h + p * p) / (h * h)
            N = P * cv / (one + lam * cv)
        else:
            tau = k * h / (R + p)                        # tan(cvp / 2)
            Ct = cvp * (tau + k) / (tau + one)           # ~ int_{phi0}^{pi/2} rho dphi, exact at k = 1
            lamp = u * R * R / (k * h * h)               # u k sec^2 phi0
            if nrm == "phi":
                rho = k * np.sqrt(h * h + p * p) / R     # rho(phi0)
            else:                                        # "phid": rho at the weight's mean position
                ce = cvp - cvp / (dt(2) + lamp * cvp)
                rho = np.sqrt(np.sin(ce) ** 2 + k * k * np.cos(ce) ** 2)
            N = Ct / (one + lamp * Ct / rho) / (one - g)
    return X, Y, N, cvp


def cv_of_Y(Y, g, design):
    """Inverse of the Y map (vectorised bisection in cv; Y decreases with cv)."""
    Y = np.asarray(Y, float)
    lo = np.zeros_like(Y)
    hi = np.full_like(Y, HALF_PI)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        _, Ym, _, _ = coords(np.zeros_like(mid), np.sin(mid), np.cos(mid), g, design)
        big = Ym > Y
        lo = np.where(big, mid, lo)
        hi = np.where(big, hi, mid)
    return 0.5 * (lo + hi)


def zscale(k, design):
    nz = design[0]
    return 1.0 if nz == "iso" else (k if nz == "k" else min(k, np.sqrt(k)))


def build_slice(nx, ny, g, design=REC, moments=False, pat=PAT_BUILD):
    """float32 table S[iy, ix] (and, with moments, the spot channels M1/N1, M2/N2) for one g.
    The quadrature nodes of a row (fixed xi) are shared by all u: one matrix exponential per row."""
    g = float(g)
    k = kk(g)
    Y = np.linspace(0, 1, ny)
    cv = np.maximum(cv_of_Y(Y, np.full(ny, g), design), 1e-9)
    h, p = np.sin(cv), np.cos(cv)
    c = zscale(k, design)
    X = np.linspace(0, 1, nx)
    r = X ** 2
    with np.errstate(divide="ignore"):
        z = np.where(X < 1, r / (1 - r), 0.0)
    u = z[None, :] * (h / np.sqrt(c * c * h * h + p * p))[:, None]
    cvp = cvphi(cv, k)
    x, w = pat
    Q = np.empty((ny, nx))
    M1 = np.empty((ny, nx))
    M2 = np.empty((ny, nx))
    for j in range(ny):
        cj = cvp[j]
        D = cj * x
        c1 = cj - D
        G = np.sin(D) / (np.sin(cj) * np.sin(c1))
        rho = np.sqrt(np.sin(c1) ** 2 + k * k * np.cos(c1) ** 2) * w * cj
        with np.errstate(over="ignore"):
            E = np.exp(-np.outer(u[j] * k, G))
        Q[j] = E @ rho
        if moments:
            dl = np.arctan2(k * np.sin(D), np.sin(c1) * np.sin(cj) + k * k * np.cos(c1) * np.cos(cj))
            M1[j] = (E @ (rho * np.sin(2 * dl))) / Q[j]
            M2[j] = (E @ (rho * np.sin(dl) ** 2)) / Q[j]
    Q /= (1 - g)
    hh = np.broadcast_to(h[:, None], u.shape)
    pp = np.broadcast_to(p[:, None], u.shape)
    _, _, N, _ = coords(u, hh, pp, g, design)
    S = Q / N
    S[:, -1] = 1.0
    if not moments:
        return S.astype(f32)
    N1, N2 = spot_normalisers(u, hh, pp, g, design)
    r1, r2 = M1 / N1, M2 / N2
    r1[:, -1] = 1.0
    r2[:, -1] = 1.0
    return S.astype(f32), r1.astype(f32), r2.astype(f32)


def spot_normalisers(u, h, p, g, design=REC, dt=float):
    """N1 = 2 eps / (1 + eps / cv), N2 = N1^2 / 2 with eps = N_p / P(xi), the width of the
    HG-weighted tail (N_p the tail normaliser, P(xi) the phase function at the end point).
    At g = 0, eps = cv / (1 + lam cv) and these are exactly the spot table's N1, N2."""
    one = dt(1)
    u, h, p, g = (np.asarray(a, dt) for a in (u, h, p, g))
    _, _, Np, _ = coords(u, h, p, g, design, dt)
    s2 = p * p / (h * h + p * p)
    c2 = h * h / (h * h + p * p)
    base = np.where(g >= 0, (one - g) ** 2 + dt(4) * g * s2, (one + g) ** 2 - dt(4) * g * c2)
    P = (one - g * g) / (base * np.sqrt(base))
    cv = np.arctan2(h, p)
    eps = Np / P
    N1 = dt(2) * eps / (one + eps / cv)
    return N1, dt(0.5) * N1 * N1


def lookup_uv(tab, u, cv, g, design=REC):
    """float32 Q_p from (u, cv) through a 2-D slice."""
    cv = np.asarray(cv, f32)
    X, Y, N, _ = coords(u, np.sin(cv), np.cos(cv), g, design, f32)
    return N * bilinear_f32(tab, X, Y)


# 3-D table: slices at nodes of a g coordinate G in [0, 1]
def g_of_G(G, kind, gmax):
    G = np.asarray(G, float)
    if kind == "g":
        return (2 * G - 1) * gmax
    if kind == "log(1-g)":
        a, b = np.log(1 + gmax), np.log(1 - gmax)
        return 1 - np.exp(a + (b - a) * G)
    A = np.arctanh(gmax)
    return np.tanh((2 * G - 1) * A)


def G_of_g(g, kind, gmax):
    """float32, clamped to [0, 1] (beyond the range the table is clamped, the normaliser is not)."""
    g = np.asarray(g, f32)
    if kind == "g":
        G = (g / f32(gmax) + f32(1)) * f32(0.5)
    elif kind == "log(1-g)":
        a, b = f32(np.log(1 + gmax)), f32(np.log(1 - gmax))
        G = (np.log(f32(1) - g) - a) / (b - a)
    else:
        G = (np.arctanh(g) / f32(np.arctanh(gmax)) + f32(1)) * f32(0.5)
    return np.clip(G, f32(0), f32(1)).astype(f32)


def build3(nx, ny, ng, kind, gmax, design=REC):
    return np.stack([build_slice(nx, ny, g_of_G(G, kind, gmax), design) for G in np.linspace(0, 1, ng)])


def trilinear_f32(tab3, X, Y, G):
    """manual trilinear (8 texelFetch + 7 mix in a shader), float32."""
    ng = tab3.shape[0]
    fg = np.clip(np.asarray(G, f32), f32(0), f32(1)) * f32(ng - 1)
    ig = np.minimum(fg.astype(np.int32), ng - 2)
    ag = fg - ig.astype(f32)
    out = np.empty(np.shape(X), f32)
    for i in np.unique(ig):
        m = ig == i
        a = bilinear_f32(tab3[i], X[m], Y[m])
        b = bilinear_f32(tab3[i + 1], X[m], Y[m])
        out[m] = a + (b - a) * ag[m]
    return out


# ---------------------------------------------------------------------------
# 3. Test points in (u, xi)
# ---------------------------------------------------------------------------
def uv_points(rng, n, g):
    """(u, cv) float32-representable; u log-uniform 1e-7..1e4 plus 5 % u = 0; a third of
    cv log-uniform in 1e-7..1 (back-scattering end), a third uniform, a third around the
    HG peak (xi = min(k, 1/k) x 1e-3..1e2 from the peak's end)."""
    g = np.broadcast_to(np.asarray(g, float), (n,))
    k = kk(g)
    u = 10 ** rng.uniform(-7, 4, n)
    u[: n // 20] = 0
    cv = np.where(rng.random(n) < 0.5, 10 ** rng.uniform(-7, 0, n), rng.uniform(0, HALF_PI, n))
    xi = np.minimum(k, 1 / k) * 10 ** rng.uniform(-3, 2, n)
    peak = rng.random(n) < 1 / 3
    cv = np.where(peak & (g > 0), HALF_PI - np.minimum(xi, HALF_PI - 1e-7), cv)
    cv = np.where(peak & (g < 0), np.minimum(xi, HALF_PI), cv)
    u = u.astype(f32).astype(float)
    cv = np.clip(cv, 1e-7, HALF_PI).astype(f32).astype(float)
    return u, cv


def max_rel(a, ref):
    m = ref > 1e-30
    with np.errstate(invalid="ignore", divide="ignore"):
        e = np.abs(np.asarray(a, float)[m] / ref[m] - 1)
    return np.max(np.where(np.isfinite(e), e, np.inf)) if e.size else 0.0


# ---------------------------------------------------------------------------
# 4. Segments from the ray geometry (float32 shader emulation) and their reference
# ---------------------------------------------------------------------------
GLN = {n: tuple(np.asarray(v, f32) for v in np.polynomial.legendre.leggauss(n)) for n in (3, 4, 6)}


def endpoint_f32(sample, g, st, b, h, x, design=REC):
    """tail at ray point x: exp(-st (x + d)) N S, as in airlight_tail, plus what the
    fallback needs. sample(X, Y) -> S."""
    xb = x - b
    d = np.sqrt(h * h + xb * xb)
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(xb >= 0, d + xb, h * h / (d - xb))
    u = st * h
    X, Y, N, cvp = coords(u, h, p, g, design, f32)
    E = np.exp(-st * (x + d))
    return E * N * sample(X, Y), dict(E=E, d=d, p=p, cvp=cvp, u=u, xb=xb)


def segment_f32(sample, g, st, b, h, x0, x1, fb="phi", nfb=4, thr=0.5, design=REC):
    """E0 Q0 - E1 Q1 on [x0, x1] (x1 = inf: escaping), in units of sigma_s I / (2 pi h).
    Where tail1 > thr * tail0 the difference is replaced by nfb-point Gauss-Legendre:
    fb = "phi": in phi (integrand rho(phi) exp(-u k (tan phi - tan phi0)) / (1 - g)),
    fb = "xi": in xi with P(t) in the integrand (the isotropic rule times P), fb = None: none."""
    g = f32(g)
    st, b, h, x0, x1 = (np.asarray(a, f32) for a in (st, b, h, x0, x1))
    k = (f32(1) - g) / (f32(1) + g)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        inf = ~np.isfinite(x1)
        x1f = np.where(inf, x0 + f32(1), x1).astype(f32)
        t0, e0 = endpoint_f32(sample, g, st, b, h, x0, design)
        t1, e1 = endpoint_f32(sample, g, st, b, h, x1f, design)
        t1 = np.where(inf, f32(0), t1)
        diff = t0 - t1
        use = (~inf) & (t1 > f32(thr) * t0)
        if fb is None or not np.any(use):
            return diff, use
        xs, ws = GLN[nfb]
        J = np.zeros_like(diff)
        if fb == "phi":
            kh = k * h
            dp = (x1f - x0) * (e0["p"] + e1["p"]) / (e0["d"] + e1["d"])     # p1 - p0, no cancellation
            dphi = np.arctan2(kh * dp, kh * kh + e0["p"] * e1["p"])
            up = e0["u"] * k
            c0 = e0["cvp"]
            s0 = np.sin(c0)
            for xk, wk in zip(xs, ws):
                D = dphi * f32(0.5) * (f32(1) + xk)
                c1 = c0 - D
                rho = np.sqrt(np.sin(c1) ** 2 + k * k * np.cos(c1) ** 2)
                J = J + f32(0.5) * wk * rho * np.exp(-up * np.sin(D) / (s0 * np.sin(c1)))
            J = J * dphi / (f32(1) - g)
        else:
            xb0 = e0["xb"]
            dv = f32(0.5) * np.arctan2(h * (x1f - x0), h * h + xb0 * (x1f - b))
            cv0 = np.arctan2(h, e0["p"])
            s0 = np.sin(cv0)
            for xk, wk in zip(xs, ws):
                D = dv * f32(0.5) * (f32(1) + xk)
                c1 = cv0 - D
                sn2, cs2 = np.cos(c1) ** 2, np.sin(c1) ** 2                 # sin^2 xi, cos^2 xi
                if g >= 0:
                    base = (f32(1) - g) ** 2 + f32(4) * g * sn2
                else:
                    base = (f32(1) + g) ** 2 - f32(4) * g * cs2
                P = (f32(1) - g * g) / (base * np.sqrt(base))
                J = J + f32(0.5) * wk * P * np.exp(-e0["u"] * np.sin(D) / (s0 * np.sin(c1)))
            J = J * dv
        return np.where(use, e0["E"] * J, diff), use


def segment_ref_log(st, b, h, x0, x1, g, weight="hg"):
    """log of the exact segment value in double (difference of exact tails, or direct
    quadrature of the segment in phi when the tails would cancel). weight="rayleigh": the
    Rayleigh phase function (g ignored, phi = xi)."""
    hg = weight == "hg"
    k = kk(g) if hg else 1.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        xb0 = x0 - b
        d0 = np.hypot(h, xb0)
        p0 = np.where(xb0 >= 0, d0 + xb0, h * h / (d0 - xb0))
        c0 = np.arctan2(k * h, p0)
        up = st * h * k
        Q0 = phi_quad(up, c0, k, weight=weight)
        inf = ~np.isfinite(x1)
        x1f = np.where(inf, x0 + 1, x1)
        xb1 = x1f - b
        d1 = np.hypot(h, xb1)
        p1 = np.where(xb1 >= 0, d1 + xb1, h * h / (d1 - xb1))
        c1 = np.arctan2(k * h, p1)
        dp = (x1f - x0) * (p0 + p1) / (d0 + d1)              # p1 - p0 = (x1 + d1) - (x0 + d0)
        dphi = np.arctan2(k * h * dp, k * k * h * h + p0 * p1)
        Q1 = phi_quad(up, c1, k, weight=weight)
        r = np.where(inf, 0.0, np.exp(-st * dp) * Q1)
        J = Q0 - r
        short = r > 0.25 * Q0
        if np.any(short):
            J[short] = phi_quad(up[short], c0[short], k, span=dphi[short], weight=weight)
        return -st * (x0 + d0) + np.log(J / (1 - g) if hg else J)


def rayleigh_segment_f32(spot_tabs, st, b, h, x0, x1, thr=0.5):
    """Rayleigh airlight on [x0, x1] from the geometry, float32: isotropic grid, the spot
    table's (S, M1/N1, M2/N2) at each end, the exact factor 9/8 + 3/8 <cos 4t>; where
    tail1 > thr * tail0, 3-point Gauss-Legendre in xi of 3/4 (1 + cos^2 2t) exp(-u (tan t - tan xi0))."""
    from spot_table_analysis import normalisers
    S, c1t, c2t = spot_tabs
    st, b, h, x0, x1 = (np.asarray(a, f32) for a in (st, b, h, x0, x1))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        inf = ~np.isfinite(x1)
        x1f = np.where(inf, x0 + f32(1), x1).astype(f32)

        def end(x):
            xb = x - b
            d = np.sqrt(h * h + xb * xb)
            p = np.where(xb >= 0, d + xb, h * h / (d - xb))
            u = st * h
            cv = np.arctan2(h, p)
            z = np.minimum(st * np.sqrt(h * h + p * p), f32(1e20))
            X = np.sqrt(z / (z + f32(1)))
            Y = f32(1) - cv * f32(2 / PI)
            N = cv / (f32(1) + u * (h * h + p * p) / (h * h) * cv)
            N1, N2 = normalisers(u, cv)
            fac, _ = rayleigh_factor(u, cv, N1 * bilinear_f32(c1t, X, Y), N2 * bilinear_f32(c2t, X, Y))
            E = np.exp(-st * (x + d))
            return E * N * bilinear_f32(S, X, Y) * f32(fac), E, cv, u, xb

        t0, E0, cv0, u, xb0 = end(x0)
        t1 = np.where(inf, f32(0), end(x1f)[0])
        use = (~inf) & (t1 > f32(thr) * t0)
        dv = f32(0.5) * np.arctan2(h * (x1f - x0), h * h + xb0 * (x1f - b))
        s0 = np.sin(cv0)
        J = np.zeros_like(t0)
        xs, ws = GLN[3]
        for xk, wk in zip(xs, ws):
            D = dv * f32(0.5) * (f32(1) + xk)
            c1 = cv0 - D
            W = f32(0.75) * (f32(1) + np.cos(f32(2) * c1) ** 2)
            J = J + f32(0.5) * wk * W * np.exp(-u * np.sin(D) / (s0 * np.sin(c1)))
        return np.where(use, E0 * J * dv, t0 - t1), use


def seg_errors(val, lr):
    ok = lr > np.log(1e-35)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        e = np.abs(val[ok].astype(float) / np.exp(lr[ok]) - 1)
    bad = int(np.sum(~np.isfinite(val)) + np.sum(val < 0))
    return (np.max(np.where(np.isfinite(e), e, np.inf)) if e.size else 0.0), bad


# ---------------------------------------------------------------------------
# 5. Rayleigh through the spot table's local moments (no new table)
# ---------------------------------------------------------------------------
def rayleigh_factor(u, cv, M1, M2):
    """Rayleigh tail / Q (the isotropic Q) = 9/8 + 3/8 <cos 4t>, exact, with
    <cos 4t> = -c2 - s2^2 + (u c2 + 2 s2 sin^2 v) M1 + 2 (c2 + s2^2 - u s2) M2,
    c2 = cos 2v, s2 = sin 2v, v = pi/2 - cv; M1 = <sin 2 Delta>, M2 = <sin^2 Delta> (spot table)."""
    c2 = -np.cos(2 * cv)
    s2 = np.sin(2 * cv)
    sv2 = np.cos(cv) ** 2
    c4 = -c2 - s2 * s2 + (u * c2 + 2 * s2 * sv2) * M1 + 2 * (c2 + s2 * s2 - u * s2) * M2
    return 9 / 8 + 3 / 8 * c4, c4


def rayleigh_tail_ref(u, cv):
    return phi_quad(u, cv, 1.0, weight="rayleigh")


# ---------------------------------------------------------------------------
# 6. Surface glow with HG
# ---------------------------------------------------------------------------
GL8X, GL8W = np.polynomial.legendre.leggauss(8)


def clamped_cosine_ring(gam, theta_s):
    """Phi(gamma, theta_s) of effects/lamp_airlight/docs/airlight_table.md section 7 (vectorised)."""
    a = np.cos(theta_s) * np.cos(gam)
    b = np.sin(theta_s) * np.sin(gam)
    with np.errstate(invalid="ignore", divide="ignore"):
        phi0 = np.arccos(np.clip(-a / b, -1, 1))
        mid = 2 * (a * phi0 + b * np.sin(phi0))
    return np.where(b <= np.abs(a), np.where(a > 0, 2 * PI * a, 0.0), mid)


def glow_nodes(theta_list=()):
    edges = [0.0, HALF_PI, PI]
    e = 1e-6
    while e < 0.5:
        edges.append(e)
        e *= 1.5
    edges += list(np.linspace(0.5, PI, 25))
    for th in theta_list:
        edges += [HALF_PI - th, th - HALF_PI, HALF_PI + th, 3 * HALF_PI - th]
    edges = np.unique([x for x in edges if 0 <= x <= PI])
    lo, hi = edges[:-1], edges[1:]
    x = (0.5 * (lo + hi))[:, None] + (0.5 * (hi - lo))[:, None] * GL8X[None, :]
    w = (0.5 * (hi - lo))[:, None] * GL8W[None, :]
    return x.ravel(), w.ravel()


def glow_exact(T, thetas, g, pat=PAT_BUILD, theta_edges=True):
    """G_p(T, theta_s) = int_0^pi Q_p(T sin gam, gam/2) Phi(gam, theta_s) dgam for the list
    thetas (one Q_p profile per T, reused for every theta_s). theta_edges: panel edges at the
    kinks of Phi (pi/2 +- theta_s); the table build omits them, as effects/phase/phase_tables.cpp does."""
    gam, w = glow_nodes(thetas if theta_edges else ())
    q = hg_tail(T * np.sin(gam), HALF_PI - gam / 2, np.full(gam.shape, g), pat=pat)
    return np.array([np.sum(w * q * clamped_cosine_ring(gam, th)) for th in thetas])


def glow_X(T):
    t0, tm = 0.05, 200.0
    return np.sqrt(np.log1p(T / t0) / np.log1p(tm / t0))


def glow_T(X):
    t0, tm = 0.05, 200.0
    return t0 * np.expm1(X * X * np.log1p(tm / t0))


GLOW_KA = 2.0


def glow_Kw(T, g, warp):
    """Y-warp scale: the isotropic table uses K = T; "hg" uses K = max(T, 2/(1-g)) for g > 0
    (the HG forward lobe sharpens the terminator to a width ~ (1 - g))."""
    T = np.maximum(T, 1e-4)
    if warp == "iso" or g <= 0:
        return T
    return np.maximum(T, GLOW_KA / (1 - g))


def glow_c_of_Y(Y, K):
    return np.clip(np.sinh((2 * Y - 1) * np.arcsinh(K)) / K, -1, 1)


def build_glow_slice(nx, ny, g, warp):
    tab = np.empty((ny, nx))
    Ys = np.linspace(0, 1, ny)
    for ix, X in enumerate(np.linspace(0, 1, nx)):
        T = glow_T(X)
        K = glow_Kw(T, g, warp)
        th = np.arccos(glow_c_of_Y(Ys, K))
        tab[:, ix] = np.log(glow_exact(T, th, g, theta_edges=False))
    return tab.astype(f32)


def glow_lookup(tab, T, c, g, warp):
    T = np.asarray(T, f32)
    K = glow_Kw(T.astype(float), g, warp).astype(f32)
    Y = f32(0.5) + f32(0.5) * np.arcsinh(K * c) / np.arcsinh(K)
    X = glow_X(np.minimum(T, f32(200))).astype(f32)
    return np.exp(bilinear_f32(tab, X, Y))


# ---------------------------------------------------------------------------
# 7. Report
# ---------------------------------------------------------------------------
def fmt(x):
    return "%.1e" % x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer cases and table sizes (< 1 minute)")
    args = ap.parse_args()
    quick = args.quick
    warnings.filterwarnings("ignore")
    t_start = time.time()
    rng = np.random.default_rng(2025)
    npts = 6000 if quick else 20000

    def stamp():
        return "   [%.0f s]" % (time.time() - t_start)

    print("0. Reference (phi form, composite Gauss-Legendre): max relative difference")
    for k, v in check_reference(np.random.default_rng(1)).items():
        print("   %-52s %.1e" % (k, v))

    # ---------------- A: candidates
    G_COLS = [-0.95, -0.9, -0.5, 0.0, 0.5, 0.85, 0.9, 0.95, 0.99, 0.999]
    pts = {}
    for g in G_COLS:
        g = float(f32(g))
        u, cv = uv_points(rng, npts, g)
        pts[g] = (u, cv, hg_tail(u, cv, g))
    print("\nA. Tail Q_p(u, xi) through one 256x64 slice per g (exact g): max relative error")
    print("   of the float32 lookup N * bilinear(S) over %d random (u, xi) per g" % npts)
    print("| candidate (normaliser, X scale, Y warp) | " + " | ".join("g=%g" % g for g in G_COLS) + " |")
    print("|---|" + "---|" * len(G_COLS))
    cand = list(DESIGNS.items())
    if quick:
        cand = [c for c in cand if c[0][0] in "ABFGK"]
    srange, srange_g = {}, {}
    for name, d in cand:
        row = []
        for g in pts:
            tab = build_slice(256, 64, g, d)
            u, cv, Q = pts[g]
            row.append(max_rel(lookup_uv(tab, u, cv, g, d), Q))
            if d == REC:
                srange[g] = (tab.min(), tab.max(), tab[:, 0].min(), tab[:, 0].max(), tab[-1])
            if d == DESIGNS["G phi-norm., z_c, Y = mix3"]:
                srange_g[g] = (tab.min(), tab.max())
        print("| %s | " % name + " | ".join(fmt(e) for e in row) + " |")
    print("   S range of the recommended slices (K): "
          + ", ".join("g=%g: %.2f..%.2f" % (g, v[0], v[1]) for g, v in srange.items()))
    print("   its X = 0 column (C / Ct): "
          + ", ".join("g=%g: %.2f..%.2f" % (g, v[2], v[3]) for g, v in srange.items()))
    S_iso_row = build_S_table(256, 64)[-1].astype(float)
    print("   its Y = 1 row against the isotropic table's: max relative difference %.1e over all g"
          % max(np.max(np.abs(v[4] / S_iso_row - 1)) for v in srange.values()))
    if srange_g:
        print("   S range with rho(phi0) instead (design G): "
              + ", ".join("g=%g: %.2f..%.2f" % (g, a, b) for g, (a, b) in srange_g.items()))
    print(stamp())

    # ---------------- B: resolution
    print("\nB. Recommended design (K), one slice per g: max relative error of the tail vs size")
    print("| texels | KiB | " + " | ".join("g=%g" % g for g in G_COLS) + " |")
    print("|---|---|" + "---|" * len(G_COLS))
    sizes = [(64, 32), (128, 32), (128, 64), (256, 32), (256, 64), (256, 128), (512, 128)]
    if quick:
        sizes = [(128, 64), (256, 64), (512, 128)]
    tbuild = []
    for nx, ny in sizes:
        row = []
        for g in pts:
            t0 = time.time()
            tab = build_slice(nx, ny, g)
            if (nx, ny) == (256, 64):
                tbuild.append(time.time() - t0)
            u, cv, Q = pts[g]
            row.append(max_rel(lookup_uv(tab, u, cv, g), Q))
        print("| %dx%d | %d | " % (nx, ny, nx * ny * 4 // 1024) + " | ".join(fmt(e) for e in row) + " |")
    print("   build time of one 256x64 slice in numpy (544 nodes per texel): %.3f s" % np.median(tbuild))
    print(stamp())

    # ---------------- C: g axis
    print("\nC. 3-D table (256x64 x Ng slices, trilinear), g random in [-0.95, 0.95]: max relative error")
    n3 = 20000 if quick else 60000
    g3 = rng.uniform(-0.95, 0.95, n3).astype(f32).astype(float)
    u3, cv3 = uv_points(rng, n3, g3)
    Q3 = hg_tail(u3, cv3, g3)
    X3, Y3, N3, _ = coords(u3, np.sin(cv3.astype(f32)), np.cos(cv3.astype(f32)), g3, REC, f32)
    print("| g coordinate | range | Ng | KiB (R32F) | all g | g in [0, 0.95] | g in [-0.95, 0) |")
    print("|---|---|---|---|---|---|---|")
    configs = [("g", 0.95, 17), ("g", 0.95, 33), ("g", 0.95, 65),
               ("log(1-g)", 0.95, 33), ("log(1-g)", 0.95, 65),
               ("atanh g", 0.95, 9), ("atanh g", 0.95, 17), ("atanh g", 0.95, 33), ("atanh g", 0.95, 49),
               ("atanh g", 0.95, 65), ("atanh g", 0.999, 33), ("atanh g", 0.999, 65)]
    if quick:
        configs = [("g", 0.95, 33), ("atanh g", 0.95, 17), ("atanh g", 0.95, 33)]
    configs.append(("atanh g, design G (rho(phi0))", 0.95, 33))
    XG, YG, NG, _ = coords(u3, np.sin(cv3.astype(f32)), np.cos(cv3.astype(f32)), g3,
                           DESIGNS["G phi-norm., z_c, Y = mix3"], f32)
    tabs3 = {}
    for kind, gm, ng in configs:
        if "design G" in kind:
            tab3 = build3(256, 64, ng, "atanh", gm, DESIGNS["G phi-norm., z_c, Y = mix3"])
            a = NG * trilinear_f32(tab3, XG, YG, G_of_g(g3, "atanh", gm))
        else:
            tab3 = build3(256, 64, ng, kind.split()[0], gm)
            tabs3[(kind, gm, ng)] = tab3
            a = N3 * trilinear_f32(tab3, X3, Y3, G_of_g(g3, kind.split()[0], gm))
        e = np.abs(a / Q3 - 1)
        pos = g3 >= 0
        print("| %s | +-%g | %d | %d | %s | %s | %s |" % (kind, gm, ng, 256 * 64 * ng * 4 // 1024,
                                                       fmt(e.max()), fmt(e[pos].max()), fmt(e[~pos].max())))
    print(stamp())

    # ---------------- D: beyond the range
    print("\nD. Extreme g. (a) one slice built at that g (256x64); (b) the 3-D table atanh, +-0.95, 33")
    print("   slices, clamped at |g| = 0.95 (the normaliser keeps the true g); non-finite results counted")
    tab3 = tabs3.get(("atanh g", 0.95, 33))
    if tab3 is None:
        tab3 = build3(256, 64, 33, "atanh", 0.95)
    print("| g | slice at g | 3-D table clamped | non-finite |")
    print("|---|---|---|---|")
    for g in [-0.9999, -0.999, -0.99, -0.97, 0.97, 0.99, 0.999, 0.9999, 0.99999]:
        g = float(f32(g))
        u, cv = uv_points(rng, 4000, g)
        Q = hg_tail(u, cv, g)
        tab = build_slice(256, 64, g)
        a = lookup_uv(tab, u, cv, g)
        X, Y, N, _ = coords(u, np.sin(cv.astype(f32)), np.cos(cv.astype(f32)), g, REC, f32)
        b = N * trilinear_f32(tab3, X, Y, G_of_g(np.full(u.shape, g), "atanh", 0.95))
        bad = int(np.sum(~np.isfinite(a)) + np.sum(~np.isfinite(b)))
        print("| %g | %s | %s | %d |" % (g, fmt(max_rel(a, Q)), fmt(max_rel(b, Q)), bad))
    print(stamp())

    # ---------------- E: segments from geometry
    print("\nE. Segments from the ray geometry, float32 shader emulation (the pixel's quantity):")
    print("   max relative error against double quadrature; sets of effects/lamp_airlight/docs/airlight_table.md table B")
    print("   (sigma_t 1e-5..2, D_sv 0.1..1000, 20 % gamma -> pi, 20 % gamma -> 0, segments len ~ x")
    print("   .. 1e-6 x, hazards). Fallback where tail1 > tail0/2, as named; last column: the share of len~x")
    print("   segments that take it.")
    ng_seg = 3000 if quick else 8000
    gsets = geom_sets(np.random.default_rng(99), ng_seg)
    labels = list(gsets)
    g_seg = [-0.95, -0.9, -0.5, 0.5, 0.85, 0.95, 0.99] if not quick else [-0.9, -0.5, 0.85, 0.95]
    seg_refs, seg_tabs = {}, {}
    print("| g | table | fallback | " + " | ".join(labels) + " | fallback share (len~x) |")
    print("|---|---|---|" + "---|" * (len(labels) + 1))
    for g in g_seg:
        g = float(f32(g))
        refs = {lab: segment_ref_log(*[a.astype(float) for a in s[:5]], g) for lab, s in gsets.items()}
        tab = build_slice(256, 64, g)
        seg_refs[g], seg_tabs[g] = refs, tab
        variants = [("slice", tab, None, 3), ("slice", tab, "xi", 3), ("slice", tab, "phi", 3),
                    ("slice", tab, "phi", 4)]
        if g in (float(f32(-0.9)), float(f32(0.95))) and not quick:
            variants.append(("slice", tab, "phi", 6))
        if g in (float(f32(0.85)), float(f32(-0.9))):
            variants.append(("3-D atanh 33", tab3, "phi", 4))
        if g == float(f32(0.99)):
            variants = [("slice", tab, "phi", 4)]
        for tname, tb, fb, nfb in variants:
            if tb.ndim == 3:
                Gc = G_of_g(np.array([g]), "atanh", 0.95)[0]
                sample = lambda X, Y, tb=tb, Gc=Gc: trilinear_f32(tb, X, Y, np.full(X.shape, Gc, f32))  # noqa: E731
            else:
                sample = lambda X, Y, tb=tb: bilinear_f32(tb, X, Y)  # noqa: E731
            row, share, nbad = [], 0.0, 0
            for lab, s in gsets.items():
                val, use = segment_f32(sample, g, *s[:5], fb=fb, nfb=nfb)
                e, bad = seg_errors(val, refs[lab])
                row.append(e)
                nbad += bad
                if lab == "len~x":
                    share = use.mean()
            fbn = "none" if fb is None else "GL%d in %s" % (nfb, fb)
            print("| %g | %s | %s | " % (g, tname, fbn) + " | ".join(fmt(e) for e in row)
                  + " | %.2f |" % share + ("" if nbad == 0 else " NON-FINITE/NEGATIVE %d" % nbad))
    print(stamp())

    # ---------------- F: g = 0
    print("\nF. g = 0 against the isotropic table (airlight_table.md)")
    S_iso = build_S_table(256, 64)
    S_hg0 = build_slice(256, 64, 0.0)
    dif = np.abs(S_hg0.astype(float) - S_iso.astype(float))
    ulp = dif / np.spacing(S_iso.astype(f32)).astype(float)
    print("   HG slice at g = 0 vs isotropic S: max |dS| = %.1e (%.0f ulp), texels differing: %d of %d"
          % (dif.max(), ulp.max(), int(np.sum(dif > 0)), dif.size))
    u, cv, Q = pts[0.0]
    a = lookup_uv(S_hg0, u, cv, 0.0)
    uf, cf = u.astype(f32), cv.astype(f32)
    sn = np.sin(cf)
    with np.errstate(all="ignore"):
        z = np.minimum(uf / sn, f32(1e20))
        Xi, Yi = np.sqrt(z / (z + f32(1))), f32(1) - cf * f32(2 / PI)
        iso = cf / (f32(1) + uf * cf / (sn * sn)) * bilinear_f32(S_iso, Xi, Yi)
    print("   lookup at g = 0 through the HG code path and slice vs exact Q: %.1e;"
          " vs the isotropic code path: %.1e"
          % (max_rel(a, Q), max_rel(a, iso.astype(float))))
    for kind, gm, ng in [("atanh g", 0.95, 33), ("atanh g", 0.95, 17), ("g", 0.95, 33)]:
        t3 = tabs3.get((kind, gm, ng))
        if t3 is None:
            continue
        row = []
        for g0 in (0.0, 1e-3, -1e-3, 0.02):
            g0 = float(f32(g0))
            Qg = hg_tail(u, cv, g0) if g0 != 0 else Q
            X, Y, N, _ = coords(u, np.sin(cv.astype(f32)), np.cos(cv.astype(f32)), g0, REC, f32)
            b = N * trilinear_f32(t3, X, Y, G_of_g(np.full(u.shape, g0), kind.split()[0], gm))
            row.append("g=%g: %s" % (g0, fmt(max_rel(b, Qg))))
        print("   3-D table %s %d slices: " % (kind, ng) + ", ".join(row)
              + ("  (g = 0 is a node)" if ng % 2 else ""))

    cb = [-0.95, -0.9, -0.5, 0.0, 0.5, 0.85, 0.95, 0.99, 0.999]
    print("   airlight culling factor int_0^{pi/2} P dt = Q_p(0, 0) (pi/2 = 1.571 for isotropic): "
          + ", ".join("g=%g: %.3g" % (g, hg_tail_u0(np.array([HALF_PI]), g)[0]) for g in cb))
    print(stamp())

    # ---------------- G: Rayleigh and HG2
    print("\nG. Rayleigh through the existing spot table (S, M1/N1, M2/N2; no new table) and two-lobe HG")
    t0 = time.time()
    spot = {}
    for nx, ny in ([(256, 64)] if quick else [(256, 64), (512, 128)]):
        S = build_S_table(nx, ny)
        c1, c2 = build_moment_tables(nx, ny)
        spot[(nx, ny)] = (S, c1, c2)
    nr = npts
    ur = 10 ** rng.uniform(-7, 4, nr)
    ur[: nr // 20] = 0
    cvr = np.where(rng.random(nr) < 0.5, 10 ** rng.uniform(-7, 0, nr), rng.uniform(0, HALF_PI, nr))
    ur = ur.astype(f32).astype(float)
    cvr = np.clip(cvr, 1e-7, HALF_PI).astype(f32).astype(float)
    Rref = rayleigh_tail_ref(ur, cvr)
    Qiso = Q_ref(ur, cvr)
    _, M1x, M2x, _, _ = weighted_moments(ur[:2000], cvr[:2000])
    fac, _ = rayleigh_factor(ur[:2000], cvr[:2000], M1x, M2x)
    print("   identity check (double, exact moments): max |Q (9/8 + 3/8 <cos 4t>) / Rayleigh tail - 1| = %.1e"
          % max_rel(Qiso[:2000] * fac, Rref[:2000]))
    print("| spot table | Rayleigh tail, identity | <cos 4t> abs. error |"
          " Rayleigh tail, exact 4th channel <cos 4t> |")
    print("|---|---|---|---|")
    from spot_table_analysis import normalisers
    for (nx, ny), (S, c1, c2) in spot.items():
        uf, cf = ur.astype(f32), cvr.astype(f32)
        s = np.sin(cf)
        with np.errstate(all="ignore"):
            z = np.minimum(uf / s, f32(1e20))
            X = np.sqrt(z / (z + f32(1)))
        Y = f32(1) - cf * f32(2 / PI)
        N = cf / (f32(1) + uf * cf / (s * s))
        N1, N2 = normalisers(uf, cf)
        Qf = N * bilinear_f32(S, X, Y)
        M1 = N1 * bilinear_f32(c1, X, Y)
        M2 = N2 * bilinear_f32(c2, X, Y)
        facf, c4f = rayleigh_factor(uf, cf, M1, M2)
        # reference <cos 4t>
        c4ref = (Rref / Qiso - 9 / 8) * 8 / 3
        # a dedicated channel storing <cos 4t> (bilinear of the exact values on the same grid)
        Xg = np.linspace(0, 1, nx)
        Yg = np.linspace(0, 1, ny)
        YY, XX = np.meshgrid(Yg, Xg, indexing="ij")
        cvg = np.maximum((1 - YY) * HALF_PI, 1e-7)
        rr = XX ** 2
        with np.errstate(divide="ignore"):
            ug = np.where(XX < 1, rr / (1 - rr), 0) * np.sin(cvg)
        ch = (rayleigh_tail_ref(ug.ravel(), cvg.ravel()) / Q_ref(ug.ravel(), cvg.ravel()) - 9 / 8) * 8 / 3
        ch = ch.reshape(ug.shape)
        ch[:, -1] = np.cos(4 * cvg[:, -1])                   # u -> inf: <cos 4t> -> cos 4v
        ch4 = bilinear_f32(ch.astype(f32), X, Y)
        print("| %dx%d | %s | %s | %s |" % (nx, ny, fmt(max_rel(Qf * facf, Rref)),
                                          fmt(np.max(np.abs(c4f - c4ref))),
                                          fmt(max_rel(Qf * (f32(9 / 8) + f32(3 / 8) * ch4), Rref))))
    print("   (build of the spot table for this check: %.1f s)" % (time.time() - t0))
    print("   Rayleigh segments from the geometry (256x64 spot table, GL3-in-xi fallback),"
          " max relative error:")
    print("| " + " | ".join(labels) + " |")
    print("|" + "---|" * len(labels))
    row = []
    for sg in gsets.values():
        val, _ = rayleigh_segment_f32(spot[(256, 64)], *sg[:5])
        ref = segment_ref_log(*[a.astype(float) for a in sg[:5]], 0.0, weight="rayleigh")
        row.append(seg_errors(val, ref)[0])
    print("| " + " | ".join(fmt(e) for e in row) + " |")
    # HG2: w HG(g1) + (1 - w) HG(g2), tails and segments
    print("| HG2 (w, g1, g2) | tail, two slices | segment ray->inf | len~x | len~1e-2x | len~1e-4x"
          " | hazards |")
    print("|---|---|---|---|---|---|---|")
    hg2 = [(0.9, 0.85, -0.5), (0.7, 0.95, -0.5), (0.5, 0.95, -0.9)]
    if quick:
        hg2 = hg2[:1]
    gsub = ["ray->inf", "len~x", "len~1e-2x", "len~1e-4x", "hazards"]
    for w, g1, g2 in hg2:
        g1, g2 = float(f32(g1)), float(f32(g2))
        t1, t2 = seg_tabs[g1], seg_tabs[g2]
        u, cv = uv_points(rng, npts, g1)
        ref = w * hg_tail(u, cv, g1) + (1 - w) * hg_tail(u, cv, g2)
        a = f32(w) * lookup_uv(t1, u, cv, g1) + f32(1 - w) * lookup_uv(t2, u, cv, g2)
        row = [max_rel(a, ref)]
        for lab in gsub:
            s = gsets[lab]
            r = w * np.exp(seg_refs[g1][lab]) + (1 - w) * np.exp(seg_refs[g2][lab])
            v1, _ = segment_f32(lambda X, Y, t=t1: bilinear_f32(t, X, Y), g1, *s[:5])
            v2, _ = segment_f32(lambda X, Y, t=t2: bilinear_f32(t, X, Y), g2, *s[:5])
            val = f32(w) * v1 + f32(1 - w) * v2
            with np.errstate(divide="ignore"):
                e, _ = seg_errors(val, np.log(r))
            row.append(e)
        print("| (%g, %g, %g) | " % (w, g1, g2) + " | ".join(fmt(e) for e in row) + " |")
    print(stamp())

    # ---------------- H: glow
    print("\nH. Surface glow G_p(T, theta_s; g) = int_0^pi Q_p(T sin gam, gam/2) Phi(gam, theta_s) dgam")
    Ts = [0.01, 0.3, 1.0, 3.0, 10.0, 30.0, 80.0]
    ths = np.radians([0, 45, 80, 90, 100, 135, 180])
    gvals = [-0.9, -0.5, 0.0, 0.5, 0.85, 0.95, 0.99, 0.999]
    print("   (a) G_p / G_iso at a few points (G_iso = g = 0 column);"
          " the g -> 1 limit is 2 pi max(cos theta_s, 0)")
    print("| T | theta_s | G_iso | " + " | ".join("g=%g" % g for g in gvals if g != 0) + " |")
    print("|---|---|---|" + "---|" * (len(gvals) - 1))
    Gtab = {}
    for T in (Ts if not quick else [0.3, 3.0, 30.0]):
        for g in gvals:
            Gtab[(T, g)] = glow_exact(T, ths, g)
        for i, th in enumerate(ths):
            if i in (0, 3, 5) or not quick:
                base = Gtab[(T, 0.0)][i]
                print("| %g | %.0f | %.4g | " % (T, np.degrees(th), base)
                      + " | ".join("%.3f" % (Gtab[(T, g)][i] / base) for g in gvals if g != 0) + " |")
    gb = [-0.95, -0.9, -0.5, 0.0, 0.5, 0.9, 0.99, 0.999]
    vals = [glow_exact(0.0, np.array([0.0, PI]), g) for g in gb]
    print("   culling bound: G_p(0, theta_s = 0) and G_p(0, 180 deg) per g"
          " (isotropic SURFACE_GLOW_G_BOUND = 8.08):")
    print("   " + ", ".join("g=%g: %.2f / %.2f" % (g, v[0], v[1]) for g, v in zip(gb, vals)))
    print(stamp())
    # (b) smoothness in g: linear interpolation in atanh g between nodes
    print("   (b) linear interpolation of log G_p in atanh(g) over [-0.95, 0.95] with Ng nodes: max relative")
    print("       error over T in {0.01, 0.3, 3, 30, 80}, theta_s in {0, 45, 80, 90, 100, 135, 180 deg},")
    print("       at the off-node g of a finer grid")
    Tg = [0.01, 0.3, 3.0, 30.0, 80.0] if not quick else [0.3, 3.0, 30.0]
    thg = np.radians([0, 45, 80, 90, 100, 135, 180])
    A = np.arctanh(0.95)
    nfine = 33 if quick else 129
    gg = np.tanh(np.linspace(-A, A, nfine))
    logG = np.array([[np.log(glow_exact(T, thg, g)) for g in gg] for T in Tg])   # (T, g, theta)
    print("| Ng | KiB (256x128 slices) | all | g >= 0 | g < 0 |")
    print("|---|---|---|---|---|")
    for step in ((8, 4, 2) if quick else (16, 8, 4, 2)):
        nodes = np.arange(0, nfine, step)
        ngn = nodes.size
        interp = np.empty_like(logG)
        for j in range(nfine):
            i0 = min(j // step, ngn - 2)
            a = (j - nodes[i0]) / step
            interp[:, j] = (1 - a) * logG[:, nodes[i0]] + a * logG[:, nodes[i0 + 1]]
        e = np.abs(np.expm1(interp - logG))
        print("| %d | %d | %s | %s | %s |" % (ngn, 128 * ngn, fmt(e.max()), fmt(e[:, gg >= 0].max()),
                                             fmt(e[:, gg < 0].max())))
    print(stamp())
    # (c) per-g slice accuracy vs resolution and row warp
    print("   (c) one glow slice per g (log G stored, X as the isotropic table): max relative error at")
    print("       random (T, theta_s), T in [0, 88], glow values below 1e-6 G(0, 0) excluded")
    nT = 30 if quick else 80
    gl_g = [-0.5, 0.85, 0.95, 0.99] if not quick else [0.95]
    gl_sizes = [(128, 64, "iso"), (128, 64, "hg"), (256, 128, "hg")]
    if quick:
        gl_sizes = [(128, 64, "iso"), (128, 64, "hg")]
    print("| size | row warp | " + " | ".join("g=%g" % g for g in gl_g) + " |")
    print("|---|---|" + "---|" * len(gl_g))
    rg = np.random.default_rng(4)
    Tl = np.concatenate([10 ** rg.uniform(-3, 0, nT // 2), rg.uniform(1, 88, nT - nT // 2)])
    cl = [np.where(rg.random(8) < 0.5, rg.uniform(-1, 1, 8),
                   np.sign(rg.uniform(-1, 1, 8)) * 10 ** rg.uniform(-4, 0, 8)) for _ in Tl]
    Tt = np.repeat(Tl, 8)
    ct = np.concatenate(cl)
    refs = {g: np.concatenate([glow_exact(T, np.arccos(c), g) for T, c in zip(Tl, cl)]) for g in gl_g}
    g00 = glow_exact(0.0, np.array([0.0]), 0.0)[0]
    dk = 0.0
    for g in (0.0, 0.95, 0.999, -0.9):
        for T in (0.001, 0.3, 5.0, 80.0):
            th = np.radians([0, 30, 80, 90, 100, 150, 180])
            dk = max(dk, np.max(np.abs(glow_exact(T, th, g, theta_edges=False) / glow_exact(T, th, g) - 1)))
    print("   quadrature of the table build (no panel edges at the kinks of Phi) against the reference:"
          " %.1e" % dk)
    for nx, ny, warp in gl_sizes:
        row = []
        for g in gl_g:
            t0 = time.time()
            tab = build_glow_slice(nx, ny, g, warp)
            tb = time.time() - t0
            a = glow_lookup(tab, Tt, ct.astype(f32), g, warp)
            keep = refs[g] * np.exp(-Tt) > 1e-6 * g00
            row.append(max_rel(a[keep], refs[g][keep]))
        print("| %dx%d | %s | " % (nx, ny, "K = T" if warp == "iso" else "K = max(T, 2/(1-g)) for g > 0")
              + " | ".join(fmt(e) for e in row) + " |")
    print("   (numpy build of the last glow slice: %.1f s)" % tb)
    if not quick:
        global GLOW_KA
        ka0 = GLOW_KA
        row = []
        for ka in (0.5, 1.0, 2.0, 4.0):
            GLOW_KA = ka
            tab = build_glow_slice(128, 64, 0.95, "hg")
            a = glow_lookup(tab, Tt, ct.astype(f32), 0.95, "hg")
            keep = refs[0.95] * np.exp(-Tt) > 1e-6 * g00
            row.append("a=%g: %s" % (ka, fmt(max_rel(a[keep], refs[0.95][keep]))))
        GLOW_KA = ka0
        print("   row-warp scale K = max(T, a/(1-g)), 128x64, g = 0.95: " + ", ".join(row))
    print(stamp())

    # ---------------- I: spots
    print("\nI. Spot channels with HG: local moments of the HG-weighted tail on the HG grid (256x64 per g),")
    print("   M1 = <sin 2 Delta>, M2 = <sin^2 Delta>, stored / N1, N2 (spot_normalisers); max relative and")
    print("   absolute error of the looked-up moments (spot_table.md's table: 1.8e-4 and 7.6e-4 relative)")
    print("| g | texels | S | M1 rel. | M2 rel. | M1 abs. | M2 abs. | M1/N1 range | M2/N2 range"
          " | build (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    spot_cases = [(g, 256, 64) for g in [-0.9, -0.5, 0.0, 0.5, 0.85, 0.95]]
    spot_cases += [(-0.9, 512, 128), (0.95, 512, 128)]
    if quick:
        spot_cases = [(-0.9, 256, 64), (0.85, 256, 64)]
    for g, nx, ny in spot_cases:
        g = float(f32(g))
        t0 = time.time()
        S, r1, r2 = build_slice(nx, ny, g, moments=True)
        tb = time.time() - t0
        u, cv = uv_points(np.random.default_rng(11), 4000 if quick else 10000, g)
        cv = np.maximum(cv, 1e-6)
        k = kk(g)
        Qx, m1, m2 = phi_quad(u * k, cvphi(cv, k), k, moments=True)
        Qx /= (1 - g)
        cf = cv.astype(f32)
        h, p = np.sin(cf), np.cos(cf)
        X, Y, N, _ = coords(u, h, p, g, REC, f32)
        N1, N2 = spot_normalisers(u, h, p, g, REC, f32)
        a1 = N1 * bilinear_f32(r1, X, Y)
        a2 = N2 * bilinear_f32(r2, X, Y)
        e0 = max_rel(N * bilinear_f32(S, X, Y), Qx)
        print("| %g | %dx%d | %s | %s | %s | %s | %s | %.2f..%.2f | %.2f..%.2f | %.2f |" % (
            g, nx, ny, fmt(e0), fmt(max_rel(a1, m1)), fmt(max_rel(a2, m2)), fmt(np.max(np.abs(a1 - m1))),
            fmt(np.max(np.abs(a2 - m2))), r1.min(), r1.max(), r2.min(), r2.max(), tb))
    print("\ntotal %.0f s" % (time.time() - t_start))


if __name__ == "__main__":
    main()
