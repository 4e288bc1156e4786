"""The integrals behind shadefit's default tables, computed the way a numpy/scipy user would
straightforwardly compute them, timed against converged reference values.

`shadefit bench` (the `tables` section, src/bench) runs

    PYTHON benches/numpy_tables.py IN.json OUT.json

with OMP_NUM_THREADS=OPENBLAS_NUM_THREADS=MKL_NUM_THREADS=1, and reports the speed of shadefit
against the rows written here at equal max error. Only numpy, scipy and the standard library are
used.

These are deliberately the *straightforward* methods, not tuned ones: the defining integral as
written (module docs of src/family/{gloss,fuzz,skin,ggx}/integrals.rs), handed to
`scipy.integrate.quad` / `dblquad` point by point, or to a vectorised Gauss–Legendre rule (or
Monte Carlo) over all points at once, with no change of variables, no splitting at features
beyond the obvious kinks, no closed-form inner integrals. Where scipy offers a closed form a user
would reach for (the exponential integrals of Q and G), that is a method too, and the GGX average
normal length has an elementary closed form written with numpy.

Input (IN.json):

    {"quick": true,            # quick mode: the whole run stays under 20 s; full mode: ~5 min
     "target_error": 1e-8,     # a method stops climbing its ladder once max_error <= this
     "tables": [{"name": "fuzz_ps", "quantity": "fuzz-ps",
                 "params": ["alpha", "theta_f", "theta_u", "phi_u"],   # coordinate order
                 "channels": 1,
                 "points": [[0.15, 0.0, 0.3, 0.5], ...],
                 "reference": [[0.1234...], ...],  # one list of `channels` values per point
                 "table_points": 627264}, ...]}    # size of the full table (default: the
                                                   # number of points); set-up is amortised over it

Output (OUT.json, written to a temporary name and renamed):

    {"versions": {"python": ..., "numpy": ..., "scipy": ...}, "quick": true,
     "tables": [{"name": "fuzz_ps",
                 "rows": [{"method": "scipy.integrate.dblquad", "setting": "epsabs=epsrel=1e-06",
                           "points": 12, "seconds_per_point": 0.0123, "max_error": 3.2e-07,
                           "note": ""}, ...]}]}

Measurement. Every table gets a time budget (quick ~1.6 s, full ~30 s, shrunk when earlier
tables ran over), shared among its methods. Each method climbs a ladder of settings from cheap to
accurate: tolerances for the adaptive scipy integrators, node counts for Gauss–Legendre, sample
counts for Monte Carlo. A rung is timed with time.perf_counter; per-point methods run on as many
points (at least 3, in a fixed shuffled order) as fit in the rung's share of the budget,
vectorised methods on all points (repeated when a call is too short to time). max_error is
max |value − reference| over the points run and all channels. Climbing stops when max_error <=
target_error, or when the next rung, estimated from the previous one's time, would not fit in
what is left of the method's budget (the last row's note says so); the first rung always runs.
A rung that runs past the method's budget by more than a grace period (quick 0.3 s, full 5 s) is
stopped by a timer (SIGALRM, where available): a per-point method reports the points it
finished, a vectorised one none.
Warnings (scipy's IntegrationWarning, numpy's RuntimeWarning) and exceptions are recorded in the
row's note; a rung that produced no usable value has "max_error": null.

Work that a table generator does once is not charged to every point: Gauss–Legendre nodes are
computed by an untimed first call, and their set-up time divided by table_points is added to
seconds_per_point; L(0) and L(1) of the gloss inverse are cached per tolerance. Everything is
deterministic (fixed seeds); only the times vary.

Exit status: 0 when OUT.json was written, 2 on malformed input (nothing written).
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import os
import platform
import signal
import sys
import tempfile
import threading
import time
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy
from scipy import integrate, optimize, special

TWO_PI = 2.0 * math.pi

# Time budgets in seconds. The whole quick run must stay under 20 s including start-up (importing
# scipy takes ~0.5 s), so quick mode plans 15 s and lets a rung overrun by at most GRACE.
TABLE_BUDGET = {True: 1.6, False: 30.0}
TOTAL_BUDGET = {True: 15.0, False: 270.0}
GRACE = {True: 0.3, False: 5.0}

MIN_POINTS = 3            # per-point methods run at least this many points per rung
MIN_TIMED_S = 0.02        # vectorised calls are repeated until this much time has passed ...
MAX_REPEATS = 50          # ... or this many calls
CHUNK = 1 << 21           # elements per array in the vectorised methods (bounds memory)
ORDER_SEED = 20240917     # order in which per-point methods visit the points
MC_SEED = 12345           # Monte Carlo samples


class InputError(Exception):
    """Malformed IN.json."""


# =============================================================================================
# Quadrature helpers


@functools.lru_cache(maxsize=None)
def gauss_legendre(n: int, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss–Legendre nodes and weights on [lo, hi], cached (a table generator computes
    them once). scipy.special.roots_legendre rather than numpy's leggauss: the same nodes (to
    2e-16 at n ≤ 4096), but O(n²) instead of leggauss's O(n³) companion-matrix eigenvalues
    (n = 4096: ~1 s against ~30 s)."""
    x, w = special.roots_legendre(n)
    half = 0.5 * (hi - lo)
    return lo + half * (x + 1.0), half * w


def quad(f, a, b, eps, **kw) -> float:
    """scipy.integrate.quad at absolute and relative tolerance eps. limit=200 subdivisions
    (the default 50 is what a user raises first when quad warns)."""
    return integrate.quad(f, a, b, epsabs=eps, epsrel=eps, limit=200, **kw)[0]


def chunks(count: int, per_item: int):
    """Slices of range(count) with at most CHUNK elements of per_item each."""
    step = max(1, CHUNK // max(1, per_item))
    for start in range(0, count, step):
        yield slice(start, min(count, start + step))


# =============================================================================================
# Gloss (src/family/gloss/integrals.rs): L(g) = 2α² ∫₀¹ t² / (1 − (1 − α²) t²)² dt, α² = 2/(1 + 2^(18g))

L_FLAT = 2.0 / 3.0  # L at g = 0 (α = 1)


def alpha_sq(g):
    """α² for gloss g (scalar or array)."""
    return 2.0 / (1.0 + np.exp2(18.0 * np.asarray(g, dtype=float)))


def length_quad(g: float, eps: float) -> float:
    """L(g) by scipy.integrate.quad of the defining integral."""
    a2 = 2.0 / (1.0 + 2.0 ** (18.0 * g))
    k = 1.0 - a2
    return quad(lambda t: 2.0 * a2 * t * t / (1.0 - k * t * t) ** 2, 0.0, 1.0, eps)


def length_gl(g, n: int) -> np.ndarray:
    """L(g) for an array of glosses by n-point Gauss–Legendre on [0, 1]."""
    t, w = gauss_legendre(n, 0.0, 1.0)
    a2 = alpha_sq(g).reshape(-1, 1)
    out = np.empty(a2.shape[0])
    for s in chunks(a2.shape[0], n):
        f = 2.0 * a2[s] * t * t / (1.0 - (1.0 - a2[s]) * t * t) ** 2
        out[s] = f @ w
    return out


def length_closed_form(g) -> np.ndarray:
    """L = (1 − α² atanh(√k)/√k) / k with k = 1 − α², written directly with numpy (the k → 0
    cancellation is left as is; k = 0, i.e. g = 0, is set to 2/3)."""
    a2 = alpha_sq(g)
    k = 1.0 - a2
    with np.errstate(divide="ignore", invalid="ignore"):
        rk = np.sqrt(k)
        value = (1.0 - a2 * np.arctanh(rk) / rk) / k
    return np.where(k > 0.0, value, L_FLAT)


@functools.lru_cache(maxsize=None)
def length_ends_quad(eps: float) -> tuple[float, float]:
    """(L(0), L(1)) by quad, computed once per tolerance (a table generator does this once)."""
    return length_quad(0.0, eps), length_quad(1.0, eps)


@functools.lru_cache(maxsize=None)
def length_ends_gl(n: int) -> tuple[float, float]:
    """(L(0), L(1)) by the n-point rule, computed once per n."""
    ends = length_gl(np.array([0.0, 1.0]), n)
    return float(ends[0]), float(ends[1])


def gloss_from_length_brentq(length: float, eps: float) -> float:
    """The gloss with L(g) = length: scipy.optimize.brentq on quad's L, xtol = eps, clamped to
    [0, 1] outside [L(0), L(1)]."""
    l0, l1 = length_ends_quad(eps)
    if length <= l0:
        return 0.0
    if length >= l1:
        return 1.0
    return optimize.brentq(lambda g: length_quad(g, eps) - length, 0.0, 1.0, xtol=eps)


BISECTION_STEPS = 52  # halves [0, 1] down to 2^-52


def gloss_from_length_bisection(length: np.ndarray, n: int) -> np.ndarray:
    """The gloss with L(g) = length for an array of lengths: vectorised bisection on the
    n-point Gauss–Legendre L, clamped to [0, 1] outside [L(0), L(1)]."""
    l0, l1 = length_ends_gl(n)
    lo = np.zeros_like(length)
    hi = np.ones_like(length)
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        below = length_gl(mid, n) < length
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    g = 0.5 * (lo + hi)
    return np.where(length <= l0, 0.0, np.where(length >= l1, 1.0, g))


def combine_brentq(x: float, y: float, eps: float) -> float:
    """Gloss combine g(L(x)·L(y)): quad for both lengths, brentq for the inverse (clamped to
    g = 0 below L(0))."""
    return gloss_from_length_brentq(length_quad(x, eps) * length_quad(y, eps), eps)


def combine_bisection(x: np.ndarray, y: np.ndarray, n: int) -> np.ndarray:
    """Gloss combine for arrays: n-point Gauss–Legendre lengths, vectorised bisection."""
    return gloss_from_length_bisection(length_gl(x, n) * length_gl(y, n), n)


# =============================================================================================
# Skin (src/family/skin/integrals.rs): d'Eon–Luebke six Gaussians (GPU Gems 3 ch. 14), mm and mm²

SKIN_VARIANCES = np.array([0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41])
SKIN_WEIGHTS = np.array([  # (R, G, B) per Gaussian
    [0.233, 0.455, 0.649],
    [0.100, 0.336, 0.344],
    [0.118, 0.198, 0.0],
    [0.113, 0.007, 0.007],
    [0.358, 0.004, 0.0],
    [0.078, 0.0, 0.0],
])
# Per-channel (variance, weight / normalisation) pairs for the scalar integrands.
LINEAR_TERMS = [[(v, w[ch] / math.sqrt(2.0 * math.pi * v)) for v, w in zip(SKIN_VARIANCES, SKIN_WEIGHTS)]
                for ch in range(3)]
RADIAL_TERMS = [[(v, w[ch] / (2.0 * math.pi * v)) for v, w in zip(SKIN_VARIANCES, SKIN_WEIGHTS)]
                for ch in range(3)]


def gaussian_sum(s: float, terms) -> float:
    """One channel of a profile at distance s from its (variance, coefficient) terms."""
    return sum(c * math.exp(-s * s / (2.0 * v)) for v, c in terms)


def gaussian_sum_vec(s: np.ndarray, radial: bool) -> np.ndarray:
    """Linear profile P(s) = Σ w_i exp(−s²/2v_i)/√(2πv_i) or radial R(s) = Σ w_i exp(−s²/2v_i)/(2πv_i),
    all three channels: shape s.shape + (3,)."""
    norm = 2.0 * math.pi * SKIN_VARIANCES if radial else np.sqrt(2.0 * math.pi * SKIN_VARIANCES)
    e = np.exp(-(s[..., None] ** 2) / (2.0 * SKIN_VARIANCES)) / norm
    return e @ SKIN_WEIGHTS


def punctual_quad(n_dot_l: float, kappa: float, eps: float) -> list[float]:
    """D(θ, κ) = ∫ max(cos(θ + x), 0) P(2r sin(|x|/2)) dx / ∫ P(…) dx over [−π, π], r = 1/κ,
    one quad per channel for numerator and denominator, break points at the kinks of the clamped
    cosine and at the kernel's peak x = 0. κ = 0 gives max(n·l, 0)."""
    if kappa == 0.0:
        return [max(n_dot_l, 0.0)] * 3
    r = 1.0 / kappa
    theta = math.acos(min(1.0, max(-1.0, n_dot_l)))
    kinks = sorted(k for k in (-0.5 * math.pi - theta, 0.5 * math.pi - theta) if -math.pi < k < math.pi)
    out = []
    for terms in LINEAR_TERMS:
        def kernel(x):
            return gaussian_sum(2.0 * r * math.sin(0.5 * abs(x)), terms)
        num = quad(lambda x: max(math.cos(theta + x), 0.0) * kernel(x), -math.pi, math.pi, eps,
                   points=kinks + [0.0])
        den = quad(kernel, -math.pi, math.pi, eps, points=[0.0])
        out.append(num / den)
    return out


def punctual_gl(n_dot_l: np.ndarray, kappa: np.ndarray, n: int) -> np.ndarray:
    """D(θ, κ) for arrays of points by n-point Gauss–Legendre on x ∈ [−π, π], all channels."""
    x, w = gauss_legendre(n, -math.pi, math.pi)
    out = np.repeat(np.maximum(n_dot_l, 0.0)[:, None], 3, axis=1)  # κ = 0 rows
    curved = np.flatnonzero(kappa > 0.0)
    theta = np.arccos(np.clip(n_dot_l, -1.0, 1.0))
    for s in chunks(curved.size, 18 * n):
        i = curved[s]
        r = 1.0 / kappa[i, None]
        kern = gaussian_sum_vec(2.0 * r * np.sin(0.5 * np.abs(x)), radial=False)  # (p, n, 3)
        clamped = np.maximum(np.cos(theta[i, None] + x), 0.0)                    # (p, n)
        num = np.einsum("pn,pnc,n->pc", clamped, kern, w)
        den = np.einsum("pnc,n->pc", kern, w)
        out[i] = num / den
    return out


def sh_quad(kappa: float, eps: float) -> list[float]:
    """k_l(κ) = ∫ K(γ) P_l(cos γ) sin γ dγ / ∫ K(γ) sin γ dγ over [0, π], K = R(2r sin(γ/2)),
    l = 1, 2; one quad per channel and integral. κ = 0 gives 1."""
    if kappa == 0.0:
        return [1.0] * 6
    r = 1.0 / kappa
    k1, k2 = [], []
    for terms in RADIAL_TERMS:
        def weight(g):
            return gaussian_sum(2.0 * r * math.sin(0.5 * g), terms) * math.sin(g)
        den = quad(weight, 0.0, math.pi, eps)
        num1 = quad(lambda g: weight(g) * math.cos(g), 0.0, math.pi, eps)
        num2 = quad(lambda g: weight(g) * 0.5 * (3.0 * math.cos(g) ** 2 - 1.0), 0.0, math.pi, eps)
        k1.append(num1 / den)
        k2.append(num2 / den)
    return k1 + k2


def sh_gl(kappa: np.ndarray, n: int) -> np.ndarray:
    """k_1 (RGB) and k_2 (RGB) for an array of curvatures by n-point Gauss–Legendre on [0, π]."""
    g, w = gauss_legendre(n, 0.0, math.pi)
    c = np.cos(g)
    out = np.ones((kappa.size, 6))  # κ = 0 rows
    curved = np.flatnonzero(kappa > 0.0)
    for s in chunks(curved.size, 18 * n):
        i = curved[s]
        r = 1.0 / kappa[i, None]
        kern = gaussian_sum_vec(2.0 * r * np.sin(0.5 * g), radial=True) * (np.sin(g) * w)[:, None]
        den = kern.sum(axis=1)
        out[i, :3] = np.einsum("pnc,n->pc", kern, c) / den
        out[i, 3:] = np.einsum("pnc,n->pc", kern, 0.5 * (3.0 * c * c - 1.0)) / den
    return out


# =============================================================================================
# Fuzz (src/family/fuzz/integrals.rs): n = +z, t = (sin θf, 0, cos θf), u = (sin θu cos φu, sin θu sin φu, cos θu),
# D_F(h) = α³/(π((h·t)²(1 − α²) + α²)²), σ_F(u) = √(1 − (u·t)²(1 − α²)), p(u, v) = D_F(h)/(4σ_F(u)),
# h = (u + v)/|u + v|; P_s(u) = ∫_{v·n<0} p(u, v) dω_v.


def fiber(theta_f):
    """Fiber direction t for polar angle θf (array: shape + (3,))."""
    theta_f = np.asarray(theta_f, dtype=float)
    return np.stack([np.sin(theta_f), np.zeros_like(theta_f), np.cos(theta_f)], axis=-1)


def direction(theta, phi):
    """Unit vector (sin θ cos φ, sin θ sin φ, cos θ) (arrays: shape + (3,))."""
    theta, phi = np.asarray(theta, dtype=float), np.asarray(phi, dtype=float)
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def phase_vec(alpha, u_t, v_t, u_dot_v):
    """p(u, v) from u·t, v·t and u·v (broadcast): (h·t)² = (u·t + v·t)²/(2 + 2u·v)."""
    a2 = alpha * alpha
    h_t2 = (u_t + v_t) ** 2 / (2.0 + 2.0 * u_dot_v)
    den = h_t2 * (1.0 - a2) + a2
    sigma = np.sqrt(1.0 - u_t * u_t * (1.0 - a2))
    return alpha**3 / (math.pi * den * den) / (4.0 * sigma)


def ps_dblquad(alpha: float, theta_f: float, theta_u: float, phi_u: float, eps: float) -> float:
    """P_s by scipy.integrate.dblquad over the lower hemisphere in the standard coordinates of
    v: μv = cos θv ∈ [−1, 0] (outer), φv ∈ [0, 2π] (inner)."""
    t = (math.sin(theta_f), 0.0, math.cos(theta_f))
    st = math.sin(theta_u)
    u = (st * math.cos(phi_u), st * math.sin(phi_u), math.cos(theta_u))
    a2 = alpha * alpha
    u_t = u[0] * t[0] + u[2] * t[2]
    scale = alpha**3 / math.pi / (4.0 * math.sqrt(1.0 - u_t * u_t * (1.0 - a2)))

    def p(phi, mu):
        s = math.sqrt(1.0 - mu * mu)
        h = (u[0] + s * math.cos(phi), u[1] + s * math.sin(phi), u[2] + mu)
        h_t2 = (h[0] * t[0] + h[2] * t[2]) ** 2 / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2])
        den = h_t2 * (1.0 - a2) + a2
        return scale / (den * den)

    return integrate.dblquad(p, -1.0, 0.0, 0.0, TWO_PI, epsabs=eps, epsrel=eps)[0]


@functools.lru_cache(maxsize=None)
def lower_hemisphere_gl(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor n × n Gauss–Legendre nodes (directions, shape (n², 3)) and weights over the lower
    hemisphere, dω = dμ dφ with μ ∈ [−1, 0], φ ∈ [0, 2π]."""
    mu, w_mu = gauss_legendre(n, -1.0, 0.0)
    phi, w_phi = gauss_legendre(n, 0.0, TWO_PI)
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - mu * mu)
    v = np.stack([s * np.cos(phi), s * np.sin(phi), mu], axis=-1).reshape(-1, 3)
    return v, np.outer(w_mu, w_phi).ravel()


def ps_of_directions(alpha: np.ndarray, t: np.ndarray, u: np.ndarray, v: np.ndarray,
                     w: np.ndarray) -> np.ndarray:
    """Σ_j w_j p(u_i, v_j) for each row i (alpha, t, u: (p,) and (p, 3); v: (m, 3), w: (m,))."""
    u_t = np.einsum("pk,pk->p", u, t)[:, None]
    v_t = t @ v.T
    return phase_vec(alpha[:, None], u_t, v_t, u @ v.T) @ w


def ps_gl(alpha, theta_f, theta_u, phi_u, n: int) -> np.ndarray:
    """P_s for arrays of points by tensor n × n Gauss–Legendre over the lower hemisphere."""
    v, w = lower_hemisphere_gl(n)
    t, u = fiber(theta_f), direction(theta_u, phi_u)
    out = np.empty(alpha.size)
    for s in chunks(alpha.size, v.shape[0]):
        out[s] = ps_of_directions(alpha[s], t[s], u[s], v, w)
    return out


def ps_monte_carlo(alpha, theta_f, theta_u, phi_u, samples: int) -> np.ndarray:
    """P_s for arrays of points by Monte Carlo: `samples` directions per point, uniform on the
    lower hemisphere (pdf 1/2π), fresh for every point from one seeded generator."""
    rng = np.random.default_rng(MC_SEED)
    t, u = fiber(theta_f), direction(theta_u, phi_u)
    u_t = np.einsum("pk,pk->p", u, t)
    out = np.empty(alpha.size)
    for s in chunks(alpha.size, samples):
        p = u_t[s].size
        mu = -rng.random((p, samples))
        phi = TWO_PI * rng.random((p, samples))
        sin_v = np.sqrt(1.0 - mu * mu)
        v = np.stack([sin_v * np.cos(phi), sin_v * np.sin(phi), mu], axis=-1)
        v_t = np.einsum("pmk,pk->pm", v, t[s])
        u_v = np.einsum("pmk,pk->pm", v, u[s])
        out[s] = TWO_PI * phase_vec(alpha[s, None], u_t[s, None], v_t, u_v).mean(axis=1)
    return out


def r_nested_gl(alpha: float, theta_f: float, n: int) -> float:
    """R = (1/π) ∫_{μu>0} P_s(u) μu dω_u by nested tensor Gauss–Legendre: n × n over u (μu ∈ [0, 1],
    φu ∈ [0, 2π]) and, for every u node, n × n over v on the lower hemisphere."""
    mu, w_mu = gauss_legendre(n, 0.0, 1.0)
    phi, w_phi = gauss_legendre(n, 0.0, TWO_PI)
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    u = direction(np.arccos(mu), phi).reshape(-1, 3)
    w_u = (np.outer(w_mu, w_phi) * mu).ravel() / math.pi
    v, w_v = lower_hemisphere_gl(n)
    t = fiber(theta_f)
    total = 0.0
    for s in chunks(u.shape[0], v.shape[0]):
        m = u[s].shape[0]
        ps = ps_of_directions(np.full(m, alpha), np.broadcast_to(t, (m, 3)), u[s], v, w_v)
        total += float(ps @ w_u[s])
    return total


def r_monte_carlo(alpha: float, theta_f: float, samples: int) -> float:
    """R by Monte Carlo: u cosine-weighted on the upper hemisphere (pdf μu/π, so R = E[P_s(u)]),
    v uniform on the lower one (pdf 1/2π), one pair per sample: R ≈ mean(2π p(u, v))."""
    rng = np.random.default_rng(MC_SEED)
    t = fiber(theta_f)
    total = 0.0
    step = CHUNK // 8
    for start in range(0, samples, step):
        m = min(step, samples - start)
        xi = rng.random((4, m))
        u = direction(np.arccos(np.sqrt(xi[0])), TWO_PI * xi[1])
        mu_v = -xi[2]
        sin_v = np.sqrt(1.0 - mu_v * mu_v)
        phi_v = TWO_PI * xi[3]
        v = np.stack([sin_v * np.cos(phi_v), sin_v * np.sin(phi_v), mu_v], axis=-1)
        p = phase_vec(alpha, u @ t, v @ t, np.einsum("mk,mk->m", u, v))
        total += float(p.sum())
    return TWO_PI * total / samples


# G(d, μv) = ∫₀¹ (1 − e^{−d/μv} e^{−d/μ}) μ/(μ + μv) dμ;  Q(d) = 2 ∫₀¹ e^{−d/μ} μ dμ = 2 E₃(d)


def g_quad(mu_v: float, d: float, eps: float) -> float:
    """G by scipy.integrate.quad of the μ-integral."""
    return quad(lambda mu: (1.0 - math.exp(-d / mu_v - d / mu)) * mu / (mu + mu_v), 0.0, 1.0, eps)


def g_gl(mu_v: np.ndarray, d: np.ndarray, n: int) -> np.ndarray:
    """G for arrays of points by n-point Gauss–Legendre on μ ∈ [0, 1]."""
    mu, w = gauss_legendre(n, 0.0, 1.0)
    out = np.empty(mu_v.size)
    for s in chunks(mu_v.size, n):
        c, dd = mu_v[s, None], d[s, None]
        out[s] = ((1.0 - np.exp(-dd / c - dd / mu)) * mu / (mu + c)) @ w
    return out


def g_closed_form(mu_v: np.ndarray, d: np.ndarray) -> np.ndarray:
    """G = 1 − c ln((1+c)/c) − e^{−d/c} E₂(d) + c e^{−d/c} E₁(d) − c E₁(d(1+c)/c), c = μv
    (fuzz.rs), with scipy.special.exp1 / expn; G(0, μv) = 0 set directly (E₁(0) = ∞)."""
    c = mu_v
    with np.errstate(divide="ignore", invalid="ignore"):
        damp = np.exp(-d / c)
        value = (1.0 - c * np.log((1.0 + c) / c) - damp * special.expn(2, d)
                 + c * damp * special.exp1(d) - c * special.exp1(d * (1.0 + c) / c))
    return np.where(d > 0.0, value, 0.0)


def q_closed_form(d: np.ndarray) -> np.ndarray:
    """Q = 2 E₃(d) with scipy.special.expn."""
    return 2.0 * special.expn(3, d)


def q_quad(d: float, eps: float) -> float:
    """Q by scipy.integrate.quad."""
    return quad(lambda mu: 2.0 * math.exp(-d / mu) * mu, 0.0, 1.0, eps)


def q_gl(d: np.ndarray, n: int) -> np.ndarray:
    """Q for an array of densities by n-point Gauss–Legendre on μ ∈ [0, 1]."""
    mu, w = gauss_legendre(n, 0.0, 1.0)
    out = np.empty(d.size)
    for s in chunks(d.size, n):
        out[s] = (2.0 * np.exp(-d[s, None] / mu) * mu) @ w
    return out


# =============================================================================================
# GGX split-sum DFG (src/family/ggx/integrals.rs): n = +z, v = (√(1 − μv²), 0, μv), GGX D with α,
# height-correlated Smith G2 = 1/(1 + Λ(v) + Λ(l)), Fc = (1 − v·h)⁵, over light directions with μl > 0:
# scale = ∫ (1 − Fc) f μl dω_l, bias = ∫ Fc f μl dω_l. Sampling h with pdf D μh (the GGX sampler) and
# l = 2(v·h)h − v (pdf D μh/(4 v·h)), the weight of a sample is G2 (v·h)/(μv μh).


def ggx_lambda(alpha, mu):
    """Smith Λ(μ) = (−1 + √(1 + α² tan²θ))/2 (μ > 0)."""
    return 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * (1.0 - mu * mu) / (mu * mu)))


def dfg_weights(alpha, mu_v, cos2_h, cos_phi):
    """(scale, bias) weights of half vectors at cos²θh and cos φ (arrays broadcasting against
    the points' α and μv), 0 where l is below the horizon."""
    mu_h = np.sqrt(cos2_h)
    sin_h = np.sqrt(np.maximum(1.0 - cos2_h, 0.0))
    sin_v = np.sqrt(1.0 - mu_v * mu_v)
    vh = sin_v * sin_h * cos_phi + mu_v * mu_h
    mu_l = 2.0 * vh * mu_h - mu_v
    ok = (mu_l > 0.0) & (vh > 0.0)
    mu_l_safe = np.where(ok, mu_l, 1.0)
    g2 = 1.0 / (1.0 + ggx_lambda(alpha, mu_v) + ggx_lambda(alpha, mu_l_safe))
    w = np.where(ok, g2 * vh / (mu_v * mu_h), 0.0)
    fc = (1.0 - vh) ** 5
    return w * (1.0 - fc), w * fc


def radical_inverse(i: np.ndarray) -> np.ndarray:
    """Van der Corput radical inverse in base 2 of 32-bit integers (Hammersley's second
    coordinate, as Filament's hammersley())."""
    b = i.astype(np.uint32)
    b = ((b << np.uint32(16)) | (b >> np.uint32(16))).astype(np.uint32)
    b = (((b & np.uint32(0x55555555)) << np.uint32(1)) | ((b & np.uint32(0xAAAAAAAA)) >> np.uint32(1))).astype(np.uint32)
    b = (((b & np.uint32(0x33333333)) << np.uint32(2)) | ((b & np.uint32(0xCCCCCCCC)) >> np.uint32(2))).astype(np.uint32)
    b = (((b & np.uint32(0x0F0F0F0F)) << np.uint32(4)) | ((b & np.uint32(0xF0F0F0F0)) >> np.uint32(4))).astype(np.uint32)
    b = (((b & np.uint32(0x00FF00FF)) << np.uint32(8)) | ((b & np.uint32(0xFF00FF00)) >> np.uint32(8))).astype(np.uint32)
    return b.astype(float) * 2.0 ** -32


def dfg_hammersley(n_dot_v, alpha, samples: int) -> np.ndarray:
    """(scale, bias) by Filament cmgen's estimator: `samples` Hammersley points (i/N, radical
    inverse), GGX importance sampling cos²θh = (1 − u)/(1 + (α² − 1)u), φ = 2π i/N."""
    i = np.arange(samples)
    u1 = i / samples
    u2 = radical_inverse(i)
    out = np.empty((n_dot_v.size, 2))
    for s in chunks(n_dot_v.size, samples):
        a = alpha[s, None]
        cos2_h = (1.0 - u2) / (1.0 + (a * a - 1.0) * u2)
        sc, bi = dfg_weights(a, n_dot_v[s, None], cos2_h, np.cos(TWO_PI * u1))
        out[s, 0] = sc.mean(axis=1)
        out[s, 1] = bi.mean(axis=1)
    return out


def dfg_gl(n_dot_v, alpha, n: int) -> np.ndarray:
    """(scale, bias) by an n × n Gauss–Legendre product in the sampler's variables: ξ ∈ [0, 1]
    (tan²θh = α² ξ/(1 − ξ)) and φ ∈ [0, π] (the integrand is even in φ), measure dξ dφ/π; the
    horizon cut is left inside the rule (no split at it)."""
    xi, w_xi = gauss_legendre(n, 0.0, 1.0)
    phi, w_phi = gauss_legendre(n, 0.0, math.pi)
    xi, phi = np.meshgrid(xi, phi, indexing="ij")
    w = (np.outer(w_xi, w_phi) / math.pi).ravel()
    xi, cos_phi = xi.ravel(), np.cos(phi.ravel())
    out = np.empty((n_dot_v.size, 2))
    for s in chunks(n_dot_v.size, xi.size):
        a = alpha[s, None]
        cos2_h = (1.0 - xi) / (1.0 - xi + a * a * xi)
        sc, bi = dfg_weights(a, n_dot_v[s, None], cos2_h, cos_phi)
        out[s, 0] = sc @ w
        out[s, 1] = bi @ w
    return out


# Once-per-table work, cleared before each table so that every table pays for its own set-up.
PER_TABLE_CACHES = (gauss_legendre, lower_hemisphere_gl, length_ends_quad, length_ends_gl)


# =============================================================================================
# Methods and ladders


@dataclass(frozen=True)
class Rung:
    setting: str
    arg: object
    cost: float   # relative cost per point, to estimate the next rung's time from this one's
    setup: float  # relative cost of the untimed set-up (Gauss–Legendre nodes: O(n²))


@dataclass(frozen=True)
class Method:
    name: str
    per_point: bool
    # per_point: fn(dict of floats, arg) -> sequence of `channels` values;
    # otherwise: fn(dict of arrays, arg) -> array (points,) or (points, channels)
    fn: Callable
    ladder: tuple[Rung, ...]


def eps_ladder(*exponents: int) -> tuple[Rung, ...]:
    """Tolerances 10^-e; an adaptive rule's cost grows roughly by 2× per two digits."""
    return tuple(Rung(f"epsabs=epsrel=1e-{e:02d}", 10.0 ** -e, 2.0 ** (e / 2), 0.0) for e in exponents)


def nodes_ladder(counts, dims: int = 1, label: str = "n={n}") -> tuple[Rung, ...]:
    """n-point rules (n^dims nodes per point); computing the n nodes costs O(n²)."""
    return tuple(Rung(label.format(n=n), n, float(n) ** dims, float(n) ** 2) for n in counts)


def samples_ladder(counts) -> tuple[Rung, ...]:
    return tuple(Rung(f"N={n:.0e}".replace("e+0", "e"), n, float(n), 0.0) for n in counts)


ONE_RUNG = (Rung("", None, 1.0, 0.0),)  # closed forms: nothing to climb

# 1-D Gauss–Legendre stops at 8192 nodes: computing them takes seconds beyond that, and
# roots_legendre's nodes and weights near ±1 lose accuracy as n grows: on the gloss integrand at
# g = 1 (a peak of width ~1e-5 at t = 1) its 8192-point rule is off by 4e-8 where Newton-polished
# nodes give 2e-11, so the gloss methods get worse, not better, from 4096 nodes on.
GL_1D = (8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192)
EPS_STEPS = (4, 6, 8, 10, 12)

GLOSS_INVERSE_EPS = eps_ladder(4, 6, 8, 10, 12, 13)
GLOSS_INVERSE_GL = nodes_ladder((16, 64, 256, 1024, 2048, 4096, 8192))

TABLES: dict[str, tuple[tuple[str, ...], int, tuple[Method, ...]]] = {
    # name: (params, channels, methods in the order they run)
    "gloss_table": (("g",), 1, (
        Method("closed form (numpy arctanh)", False, lambda p, _: length_closed_form(p["g"]),
               ONE_RUNG),
        Method("numpy Gauss-Legendre", False, lambda p, n: length_gl(p["g"], n), nodes_ladder(GL_1D)),
        Method("scipy.integrate.quad", True, lambda p, eps: [length_quad(p["g"], eps)],
               eps_ladder(*EPS_STEPS)),
    )),
    "gloss_inverse_table": (("length",), 1, (
        Method("numpy Gauss-Legendre + vectorised bisection", False,
               lambda p, n: gloss_from_length_bisection(p["length"], n), GLOSS_INVERSE_GL),
        Method("scipy.integrate.quad + scipy.optimize.brentq", True,
               lambda p, eps: [gloss_from_length_brentq(p["length"], eps)], GLOSS_INVERSE_EPS),
    )),
    "gloss_combine_lut": (("x", "y"), 1, (
        Method("numpy Gauss-Legendre + vectorised bisection", False,
               lambda p, n: combine_bisection(p["x"], p["y"], n), GLOSS_INVERSE_GL),
        Method("scipy.integrate.quad + scipy.optimize.brentq", True,
               lambda p, eps: [combine_brentq(p["x"], p["y"], eps)], GLOSS_INVERSE_EPS),
    )),
    "skin_punctual_lut": (("n_dot_l", "kappa"), 3, (
        Method("numpy Gauss-Legendre", False, lambda p, n: punctual_gl(p["n_dot_l"], p["kappa"], n),
               nodes_ladder(GL_1D)),
        Method("scipy.integrate.quad", True, lambda p, eps: punctual_quad(p["n_dot_l"], p["kappa"], eps),
               eps_ladder(*EPS_STEPS)),
    )),
    "skin_sh_lut": (("kappa",), 6, (
        Method("numpy Gauss-Legendre", False, lambda p, n: sh_gl(p["kappa"], n), nodes_ladder(GL_1D)),
        Method("scipy.integrate.quad", True, lambda p, eps: sh_quad(p["kappa"], eps),
               eps_ladder(*EPS_STEPS)),
    )),
    "fuzz_ps": (("alpha", "theta_f", "theta_u", "phi_u"), 1, (
        Method("numpy tensor Gauss-Legendre (mu_v, phi_v)", False,
               lambda p, n: ps_gl(p["alpha"], p["theta_f"], p["theta_u"], p["phi_u"], n),
               nodes_ladder((8, 16, 32, 64, 128, 256, 512, 1024), dims=2,
                            label="n={n} ({n}x{n} nodes)")),
        Method("scipy.integrate.dblquad", True,
               lambda p, eps: [ps_dblquad(p["alpha"], p["theta_f"], p["theta_u"], p["phi_u"], eps)],
               eps_ladder(4, 6, 8, 10)),
        Method("numpy Monte Carlo (uniform lower hemisphere)", False,
               lambda p, m: ps_monte_carlo(p["alpha"], p["theta_f"], p["theta_u"], p["phi_u"], m),
               samples_ladder((1000, 10000, 100000, 1000000))),
    )),
    "fuzz_r": (("alpha", "theta_f"), 1, (
        Method("numpy nested tensor Gauss-Legendre (u, v)", True,
               lambda p, n: [r_nested_gl(p["alpha"], p["theta_f"], n)],
               nodes_ladder((8, 16, 32, 48, 64, 96, 128), dims=4,
                            label="n={n} ({n}x{n} u, {n}x{n} v nodes)")),
        Method("numpy Monte Carlo (cosine-weighted u, uniform v)", True,
               lambda p, m: [r_monte_carlo(p["alpha"], p["theta_f"], m)],
               samples_ladder((1000, 10000, 100000, 1000000, 10000000))),
    )),
    "fuzz_g": (("mu_v", "d"), 1, (
        Method("closed form (scipy.special.exp1, expn)", False,
               lambda p, _: g_closed_form(p["mu_v"], p["d"]), ONE_RUNG),
        Method("numpy Gauss-Legendre", False, lambda p, n: g_gl(p["mu_v"], p["d"], n), nodes_ladder(GL_1D)),
        Method("scipy.integrate.quad", True, lambda p, eps: [g_quad(p["mu_v"], p["d"], eps)],
               eps_ladder(*EPS_STEPS)),
    )),
    "ggx_dfg_lut": (("n_dot_v", "alpha"), 2, (
        Method("numpy Monte Carlo, Hammersley GGX importance sampling (Filament cmgen)", False,
               lambda p, m: dfg_hammersley(p["n_dot_v"], p["alpha"], m),
               samples_ladder((256, 1024, 4096, 16384, 65536, 262144, 1048576))),
        Method("numpy tensor Gauss-Legendre (xi, phi)", False,
               lambda p, n: dfg_gl(p["n_dot_v"], p["alpha"], n),
               nodes_ladder((8, 16, 32, 64, 128, 256, 512, 1024), dims=2, label="n={n} ({n}x{n} nodes)")),
    )),
    "fuzz_q": (("d",), 1, (
        Method("closed form (scipy.special.expn)", False, lambda p, _: q_closed_form(p["d"]), ONE_RUNG),
        Method("numpy Gauss-Legendre", False, lambda p, n: q_gl(p["d"], n), nodes_ladder(GL_1D)),
        Method("scipy.integrate.quad", True, lambda p, eps: [q_quad(p["d"], eps)], eps_ladder(*EPS_STEPS)),
    )),
}


# =============================================================================================
# Measurement


class OutOfTime(Exception):
    """Raised by the SIGALRM timer when a rung runs past its hard limit."""


@contextlib.contextmanager
def hard_limit(seconds: float):
    """Raise OutOfTime in the main thread after `seconds` (no-op where SIGALRM is unavailable).
    Python integrands run between bytecodes, so quad/dblquad/brentq stop at their next call; a
    numpy call finishes first (the vectorised methods work in bounded chunks)."""
    if not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_alarm(signum, frame):
        raise OutOfTime

    previous = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, max(seconds, 1e-3))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


@dataclass
class Table:
    name: str
    params: tuple[str, ...]
    points: np.ndarray     # (points, len(params))
    reference: np.ndarray  # (points, channels)
    table_points: int      # size of the full table: set-up time is amortised over it

    def columns(self, idx) -> dict[str, np.ndarray]:
        return {name: np.ascontiguousarray(self.points[idx, k]) for k, name in enumerate(self.params)}

    def point(self, i: int) -> dict[str, float]:
        return {name: float(self.points[i, k]) for k, name in enumerate(self.params)}


def summarise_warnings(caught) -> list[str]:
    """'Category ×count: first line of the message' for each distinct warning."""
    counts: dict[tuple[str, str], int] = {}
    for w in caught:
        key = (w.category.__name__, str(w.message).strip().splitlines()[0][:120])
        counts[key] = counts.get(key, 0) + 1
    return [f"{cat} x{n}: {msg}" for (cat, msg), n in counts.items()]


def max_error(values: np.ndarray, reference: np.ndarray) -> tuple[float | None, str]:
    values = np.asarray(values, dtype=float).reshape(reference.shape)
    bad = ~np.isfinite(values).all(axis=1)
    if bad.any():
        return None, f"non-finite values at {int(bad.sum())} of {bad.size} points"
    return float(np.max(np.abs(values - reference))), ""


def run_rung(method: Method, rung: Rung, table: Table, order: np.ndarray, share_s: float,
             limit_s: float) -> tuple[dict, bool, float, float]:
    """One (method, setting) row; whether the rung failed (an exception or the time limit); the
    timed seconds per point; the set-up seconds. Per-point methods visit `order` until `share_s`
    has passed (at least MIN_POINTS points); vectorised ones take every point, after an untimed
    first call on one point that computes (and caches) their nodes when the rung has a set-up
    cost. `limit_s` is the hard stop for the whole rung."""
    notes: list[str] = []
    failed = False
    values: list = []
    done = calls = 0
    setup_s = 0.0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        start = time.perf_counter()
        try:
            with hard_limit(limit_s):
                if method.per_point:
                    for i in order:
                        values.append(method.fn(table.point(int(i)), rung.arg))
                        done += 1
                        if done >= MIN_POINTS and time.perf_counter() - start >= share_s:
                            break
                else:
                    if rung.setup > 0.0:
                        method.fn(table.columns(order[:1]), rung.arg)
                        setup_s = time.perf_counter() - start
                    cols = table.columns(order)
                    start = time.perf_counter()
                    while True:
                        result = method.fn(cols, rung.arg)
                        calls += 1
                        if time.perf_counter() - start >= MIN_TIMED_S or calls >= MAX_REPEATS:
                            break
                    values, done = result, len(order)
        except OutOfTime:
            failed = True
            notes.append(f"stopped at the {limit_s:.3g} s time limit")
        except Exception as exc:  # recorded, not fatal: the row says what went wrong
            failed = True
            text = str(exc).strip()
            name = type(exc).__name__
            notes.append(f"{name}: {text.splitlines()[0][:160]}" if text else name)
        elapsed = time.perf_counter() - start
    notes.extend(summarise_warnings(caught))

    if method.per_point:
        timed_spp = elapsed / max(done, 1)
    else:
        timed_spp = elapsed / max(calls, 1) / len(order)
    seconds_per_point = timed_spp + setup_s / table.table_points
    if setup_s >= 0.01:
        notes.append(f"node set-up {setup_s:.3g} s (once per table, amortised over "
                     f"{table.table_points} table points)")
    err = None
    if done > 0:
        err, why = max_error(values, table.reference[order[:done]])
        if why:
            notes.append(why)
    elif not notes:
        notes.append("no point finished")
    row = {
        "method": method.name,
        "setting": rung.setting,
        "points": int(done),
        "seconds_per_point": float(seconds_per_point),
        "max_error": err,
        "note": "; ".join(notes),
    }
    return row, failed, timed_spp, setup_s


def run_method(method: Method, table: Table, order: np.ndarray, target: float, budget_s: float,
               grace_s: float) -> list[dict]:
    """Climb the method's ladder within budget_s (see the module docstring)."""
    rows: list[dict] = []
    start = time.perf_counter()
    previous: tuple[Rung, float, float] | None = None  # (rung, timed s per point, set-up s)
    ladder = method.ladder
    for k, rung in enumerate(ladder):
        left = budget_s - (time.perf_counter() - start)
        if previous is not None:
            prev_rung, prev_spp, prev_setup = previous
            points = min(MIN_POINTS, len(order)) if method.per_point else len(order)
            estimate = prev_spp * rung.cost / prev_rung.cost * points
            if prev_rung.setup > 0.0:
                estimate += prev_setup * rung.setup / prev_rung.setup
            if estimate > left:
                skipped = (f"next rung ({rung.setting}) skipped: estimated {estimate:.3g} s > "
                           f"{max(left, 0.0):.3g} s left")
                rows[-1]["note"] = "; ".join(filter(None, [rows[-1]["note"], skipped]))
                break
        # Per-point rungs take half of what is left, the last rung all of it.
        share = left if k == len(ladder) - 1 else 0.5 * left
        row, failed, spp, setup_s = run_rung(method, rung, table, order, share, max(left, 0.0) + grace_s)
        rows.append(row)
        # A failed rung ends the method; non-finite values (an under-resolved rule dividing 0 by
        # 0, say) do not: the next rung may resolve them.
        if failed or (row["max_error"] is not None and row["max_error"] <= target):
            break
        previous = (rung, spp, setup_s)
    return rows


# =============================================================================================
# Input, output


def parse_input(doc) -> tuple[bool, float, list]:
    """Checked (quick, target_error, tables); tables are Table or (name, note) for unknown names."""
    if not isinstance(doc, dict):
        raise InputError("top level: expected a JSON object")
    quick = doc.get("quick", False)
    if not isinstance(quick, bool):
        raise InputError("'quick': expected true or false")
    target = doc.get("target_error")
    if isinstance(target, bool) or not isinstance(target, (int, float)) or not target > 0.0:
        raise InputError("'target_error': expected a positive number")
    tables = doc.get("tables")
    if not isinstance(tables, list):
        raise InputError("'tables': expected a list")
    out = []
    for i, t in enumerate(tables):
        where = f"tables[{i}]"
        if not isinstance(t, dict):
            raise InputError(f"{where}: expected an object")
        name = t.get("name")
        if not isinstance(name, str) or not name:
            raise InputError(f"{where}.name: expected a non-empty string")
        where = f"tables[{i}] ({name})"
        params = t.get("params")
        if not isinstance(params, list) or not params or not all(isinstance(p, str) for p in params):
            raise InputError(f"{where}.params: expected a non-empty list of strings")
        channels = t.get("channels")
        if isinstance(channels, bool) or not isinstance(channels, int) or channels < 1:
            raise InputError(f"{where}.channels: expected a positive integer")
        points = as_matrix(t.get("points"), len(params), f"{where}.points")
        reference = as_matrix(t.get("reference"), channels, f"{where}.reference")
        if points.shape[0] != reference.shape[0]:
            raise InputError(f"{where}: {points.shape[0]} points but {reference.shape[0]} reference values")
        if name not in TABLES:
            out.append((name, f"unknown table '{name}': not measured"))
            continue
        want_params, want_channels, _ = TABLES[name]
        if sorted(params) != sorted(want_params) or len(set(params)) != len(params):
            raise InputError(f"{where}.params: expected the names {list(want_params)} (any order), "
                             f"got {params}")
        if channels != want_channels:
            raise InputError(f"{where}.channels: expected {want_channels}, got {channels}")
        size = t.get("table_points", points.shape[0])
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise InputError(f"{where}.table_points: expected a positive integer")
        out.append(Table(name, tuple(params), points, reference, max(size, points.shape[0])))
    return quick, float(target), out


def as_matrix(rows, width: int, where: str) -> np.ndarray:
    if not isinstance(rows, list) or not rows:
        raise InputError(f"{where}: expected a non-empty list of lists")
    for j, row in enumerate(rows):
        if (not isinstance(row, list) or len(row) != width
                or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in row)):
            raise InputError(f"{where}[{j}]: expected a list of {width} numbers")
    m = np.array(rows, dtype=float)
    if not np.isfinite(m).all():
        raise InputError(f"{where}: values must be finite")
    return m


def write_atomically(path: str, doc) -> None:
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".numpy_tables.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(doc, f, indent=1, allow_nan=False)
            f.write("\n")
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def measure(quick: bool, target: float, tables: list) -> list[dict]:
    start = time.perf_counter()
    out = []
    for k, table in enumerate(tables):
        if not isinstance(table, Table):
            name, note = table
            out.append({"name": name, "rows": [], "note": note})
            continue
        left_total = TOTAL_BUDGET[quick] - (time.perf_counter() - start)
        measured_left = sum(isinstance(t, Table) for t in tables[k:])
        table_budget = max(0.0, min(TABLE_BUDGET[quick], left_total / measured_left))
        for cache in PER_TABLE_CACHES:
            cache.cache_clear()
        table_start = time.perf_counter()
        order = np.random.default_rng(ORDER_SEED).permutation(table.points.shape[0])
        methods = TABLES[table.name][2]
        rows = []
        for m, method in enumerate(methods):
            left = table_budget - (time.perf_counter() - table_start)
            budget = max(0.0, left / (len(methods) - m))
            rows.extend(run_method(method, table, order, target, budget, GRACE[quick]))
        out.append({"name": table.name, "rows": rows})
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(f"usage: {os.path.basename(argv[0])} IN.json OUT.json", file=sys.stderr)
        return 2
    try:
        with open(argv[1]) as f:
            doc = json.load(f)
        quick, target, tables = parse_input(doc)
    except (OSError, json.JSONDecodeError, InputError) as exc:
        print(f"numpy_tables.py: bad input {argv[1]}: {exc}", file=sys.stderr)
        return 2
    result = {
        "versions": {"python": platform.python_version(), "numpy": np.__version__,
                     "scipy": scipy.__version__},
        "quick": quick,
        "tables": measure(quick, target, tables),
    }
    write_atomically(argv[2], result)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
