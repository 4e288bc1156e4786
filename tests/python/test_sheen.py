"""The Charlie sheen quantities (`shadefit eval sheen-*`) against scipy computations written here
from the definitions only (Estevez & Kulla 2017; glTF KHR_materials_sheen):

    D(m) = (2 + 1/α) sin(θm)^(1/α) / (2π),         ∫_{H²} D(m) cos θm dω_m = 1
    (1 + Λ(ω)) μ = ∫_{H²} D(m) max(0, ω·m) dω_m,    μ = n·ω          (exact Smith Λ)
    E(μv) = ∫_{H²} D(h) Vis(μl, μv) μl dω_l,  h = (l + v)/|l + v|
        Vis = G2/(4 μl μv), G2 = 1/(1 + Λ(μv) + Λ(μl))   sheen-albedo     (exact Λ)
                                                        sheen-albedo-ek  (Estevez–Kulla's Λ curve)
        Vis = 1/(4 (μl + μv − μl μv))                    sheen-albedo-ashikhmin
    E_avg = 2 ∫₀¹ E(μ) μ dμ                             sheen-albedo-avg (exact Λ)

References (none calls shadefit or copies its formulas):

* Λ: nested scipy quad over microfacet normals, ω = (sin θ, 0, μ), m = (θm, φm), φm ∈ [0, π]
  doubled (mirror symmetry). The inner azimuth range is cut where ω·m = 0,
  cos φ0 = −cot θ cot θm, and the integrand a cos φ + b (a = sin θ sin θm, b = μ cos θm) is
  integrated numerically on [0, φ0] (on [0, π] when a ≤ b). The inner result has a kink
  (a (θm − θk)^{3/2} term) at θk = π/2 − θ, where φ0 reaches π: a break point of the outer quad,
  beside break points at π/2 − j√α, j = 1, 2, 4, where the lobe of D (width ~√α about the
  horizon) falls off. Its error: the quad estimate plus the change from epsrel 1e-10 to 1e-13.
* E: nested quad over light directions (μl, ψ), ψ = π − φl ∈ [0, π] doubled, with the exact Λ
  above evaluated at each μl node. ψ = 0 is the mirror direction (h = n, where sin^(1/α) θh has
  a cone point for α = 1), ψ = π the side where h is most horizontal (D's peak; for small μv it
  is the retro direction l ≈ v): both are ends of the inner range. The outer quad gets break
  points at μl = μv (the mirror direction), at 0.5 (where Estevez–Kulla's curve switches branch)
  and at α/16, α/4, α, 4α (the rise off grazing, steep for small α). h's horizontal component
  is written (μl² − μv²)/(sl + sv) + 2 sl sin²(ψ/2) (no cancellation when l ≈ −v near the
  horizon). Error: quad's estimate plus the change between two resolutions (outer epsabs
  1e-10 / exact Λ at epsrel 1e-13, and 1e-9 / 1e-10).
* E_avg: quad over μv of the same E, with Λ from a vectorised Gauss–Legendre rule instead of
  the nested quad (the three-fold nesting would take ~40 s with it): composite G–L in θm
  ([0, θk], then [θk, π/2] under θm = θk + (π/2 − θk) u², which removes the 3/2-power kink), and
  a 12-node G–L of a cos φ + b on [0, φ0]. test_gl_lambda_against_nested_quad checks that rule
  against the nested quad and against itself at half the nodes.

Any IntegrationWarning from a reference quad is an error (a reference that could not reach its
requested accuracy fails, never passes). Before comparing with shadefit, each test asserts the
reference's own error bound at 1% of the acceptance tolerance or below.

Run time: ~100 `eval` processes (a few ms each, E_avg's ~0.3 s) and the references: ~16 s in
all on one core.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import pytest
from scipy import integrate
from scipy.special import roots_legendre

import sf_cli

HALF_PI = 0.5 * math.pi
EPS = np.finfo(float).eps

# Acceptance tolerances: Λ relative to its value, E and E_avg absolute (E ≤ 1).
LAMBDA_RTOL = 1e-9
ALBEDO_ATOL = 1e-7


def _quad(f, a, b, **kw):
    """scipy quad, any IntegrationWarning (accuracy not reached, roundoff) raised as an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", integrate.IntegrationWarning)
        return integrate.quad(f, a, b, **kw)


def _d_norm(alpha: float) -> float:
    return (2.0 + 1.0 / alpha) / (2.0 * math.pi)


def _interior(points, lo=0.0, hi=1.0):
    pts = sorted({p for p in points if lo < p < hi})
    return pts or None


# ---------------------------------------------------------------------------------------------
# D


@pytest.mark.parametrize("alpha", [0.05, 0.3, 1.0])
def test_charlie_d_is_normalised(alpha):
    # ∫ D cos θm dω = 2π ∫ D(θm) cos θm sin θm dθm, requested to relative 1e-13 (and its estimate
    # asserted under that): the tolerance 1e-12 is 10× over it.
    k = 1.0 / alpha
    v, err = _quad(
        lambda t: 2.0 * math.pi * _d_norm(alpha) * math.sin(t) ** k * math.cos(t) * math.sin(t),
        0.0, HALF_PI, epsabs=0.0, epsrel=1e-13, limit=200,
    )
    assert err <= 1e-13
    assert abs(v - 1.0) <= 1e-12, (alpha, v)


# ---------------------------------------------------------------------------------------------
# Exact Smith Λ


def lambda_quad(alpha: float, mu: float, epsrel: float = 1e-13) -> tuple[float, float]:
    """(Λ(μ), quad's absolute error estimate for it) by nested quad over (θm, φm)."""
    k = 1.0 / alpha
    c = 2.0 * _d_norm(alpha)  # the factor 2 for φm ∈ [−π, 0]
    s = math.sqrt(max(0.0, 1.0 - mu * mu))
    theta_k = math.atan2(mu, s)  # π/2 − θ: beyond it part of the azimuth circle is unlit
    inner_err = [0.0]

    def inner(tm):
        a, b = s * math.sin(tm), mu * math.cos(tm)
        top = math.pi if a <= b else math.acos(-b / a)
        # a cos φ + b ≥ 0 on [0, top]: no cancellation, a relative tolerance is reachable.
        v, e = _quad(lambda p: a * math.cos(p) + b, 0.0, top, epsabs=0.0, epsrel=1e-13)
        inner_err[0] = max(inner_err[0], e)
        return v

    def outer(tm):
        st = math.sin(tm)
        return c * st**k * st * inner(tm)

    w = 1.0 / math.sqrt(k)
    pts = _interior([theta_k, HALF_PI - w, HALF_PI - 2.0 * w, HALF_PI - 4.0 * w], 0.0, HALF_PI)
    g, e = _quad(outer, 0.0, HALF_PI, points=pts, epsabs=0.0, epsrel=epsrel, limit=500)
    # The inner estimates integrated over the outer range (≤ π/2 of weight c·sin^(k+1) ≤ c).
    e += c * HALF_PI * inner_err[0]
    return g / mu - 1.0, e / mu


def lambda_reference(alpha: float, mu: float) -> tuple[float, float]:
    """(Λ, error bound): the epsrel-1e-13 value, bounded by its estimate plus its change from 1e-10."""
    fine, e = lambda_quad(alpha, mu, 1e-13)
    coarse, _ = lambda_quad(alpha, mu, 1e-10)
    return fine, e + abs(fine - coarse)


LAMBDA_POINTS = [
    (alpha, mu)
    for alpha in (0.01, 0.05, 0.25, 0.5, 1.0)
    for mu in (1e-4, 1e-3, 0.1, 0.5, 0.9, 0.999, 1.0)
]


@pytest.mark.parametrize("alpha,mu", LAMBDA_POINTS, ids=[repr(p) for p in LAMBDA_POINTS])
def test_lambda_against_nested_quad(alpha, mu):
    want, ref_err = lambda_reference(alpha, mu)
    # The reference computes (1 + Λ)μ and subtracts: its absolute error scales with 1 + Λ, not Λ
    # (near μ = 1, Λ → 0 while 1 + Λ → 1). Its bound is asserted under 1e-11 (1 + Λ) (measured
    # ≤ 2e-12 (1 + Λ)).
    assert ref_err <= 1e-2 * LAMBDA_RTOL * (1.0 + want), (want, ref_err)
    out = sf_cli.eval_point("sheen-lambda", alpha=alpha, n_dot_v=mu)
    # 1e-9 relative to Λ (which grows like 1/μ at grazing), plus the reference's error bound and
    # a few ulps of 1 + Λ for the subtraction of 1 (the only bound where Λ itself is ~0: μ = 1).
    tol = LAMBDA_RTOL * abs(want) + ref_err + 8.0 * EPS * (1.0 + want)
    assert abs(out["value"] - want) <= tol, (out, want, tol)


# ---------------------------------------------------------------------------------------------
# Directional albedo

P0 = (25.3245, 3.32435, 0.16801, -1.27393, -4.85967)  # Estevez–Kulla's curve at α = 0
P1 = (21.5473, 3.82987, 0.19823, -1.97760, -4.32054)  # ... and at α = 1


def lambda_ek(alpha: float, mu: float) -> float:
    t = (1.0 - alpha) ** 2
    a, b, c, d, e = (t * p0 + (1.0 - t) * p1 for p0, p1 in zip(P0, P1))

    def curve(x):
        return a / (1.0 + b * x**c) + d * x + e

    return math.exp(curve(mu)) if mu < 0.5 else math.exp(2.0 * curve(0.5) - curve(1.0 - mu))


def _albedo(alpha, mu_v, vis, eps, lam):
    """(E(μv), error estimate) for vis in {"smith", "ek", "ashikhmin"}; `lam(μ)` the exact Λ
    (used by "smith" only)."""
    k = 1.0 / alpha
    norm = _d_norm(alpha)
    sv = math.sqrt(max(0.0, 1.0 - mu_v * mu_v))
    lam_v = lam(mu_v) if vis == "smith" else lambda_ek(alpha, mu_v) if vis == "ek" else None
    inner_eps = 1e-2 * eps
    inner_err = [0.0]

    def outer(mu_l):
        if mu_l == 0.0:
            return 0.0
        sl = math.sqrt(max(0.0, 1.0 - mu_l * mu_l))
        # Vis·μl, and the factor 2 for φl ∈ [π, 2π].
        if vis == "ashikhmin":
            w = 2.0 * mu_l / (4.0 * (mu_l + mu_v - mu_l * mu_v))
        else:
            lam_l = lam(mu_l) if vis == "smith" else lambda_ek(alpha, mu_l)
            w = 2.0 / ((1.0 + lam_v + lam_l) * 4.0 * mu_v)
        hz = mu_l + mu_v
        hx0 = (mu_l - mu_v) * (mu_l + mu_v) / (sl + sv) if sl + sv > 0.0 else 0.0

        def inner(psi):
            sh = math.sin(0.5 * psi)
            hx = hx0 + 2.0 * sl * sh * sh  # sv − sl cos ψ
            hy = sl * math.sin(psi)
            r2 = hx * hx + hy * hy
            return norm * (r2 / (r2 + hz * hz)) ** (0.5 * k)

        v, e = _quad(inner, 0.0, math.pi, epsabs=inner_eps, epsrel=1e-12, limit=200)
        inner_err[0] = max(inner_err[0], w * e)
        return w * v

    pts = _interior([mu_v, 0.5, alpha / 16.0, alpha / 4.0, alpha, 4.0 * alpha])
    v, e = _quad(outer, 0.0, 1.0, points=pts, epsabs=eps, epsrel=0.0, limit=200)
    return v, e + inner_err[0]  # the inner estimates times the outer range (1)


def albedo_reference(alpha: float, mu_v: float, vis: str) -> tuple[float, float]:
    """(E, error bound) at two resolutions (the finer returned; bound: its estimate plus the change)."""
    fine, e = _albedo(alpha, mu_v, vis, 1e-10, lambda m: lambda_quad(alpha, m, 1e-13)[0])
    coarse, _ = _albedo(alpha, mu_v, vis, 1e-9, lambda m: lambda_quad(alpha, m, 1e-10)[0])
    return fine, e + abs(fine - coarse)


ALBEDO_POINTS = [(alpha, mu_v) for alpha in (0.05, 0.25, 0.5, 1.0) for mu_v in (0.1, 0.4, 0.8, 1.0)]
ALBEDO_QUANTITIES = {"smith": "sheen-albedo", "ek": "sheen-albedo-ek", "ashikhmin": "sheen-albedo-ashikhmin"}


@pytest.mark.parametrize("vis", list(ALBEDO_QUANTITIES))
@pytest.mark.parametrize("alpha,mu_v", ALBEDO_POINTS, ids=[repr(p) for p in ALBEDO_POINTS])
def test_albedo_against_light_space_quadrature(vis, alpha, mu_v):
    want, ref_err = albedo_reference(alpha, mu_v, vis)
    # The reference's bound (≤ ~1e-10 measured) is kept under 1% of the acceptance tolerance.
    assert ref_err <= 1e-2 * ALBEDO_ATOL, (want, ref_err)
    out = sf_cli.eval_point(ALBEDO_QUANTITIES[vis], alpha=alpha, n_dot_v=mu_v)
    assert abs(out["value"] - want) <= ALBEDO_ATOL, (out, want, ref_err)


@pytest.mark.parametrize("alpha", [0.05, 0.5, 1.0])
def test_albedo_at_grazing_view_is_one(alpha):
    # With the exact Λ, E(μv) → 1 as μv → 0: G2/μv → 1/((1 + Λ)μ)|_{μv→0} = 1/∫ D max(0, v·m),
    # and over half vectors (dω_l = 4 (v·h) dω_h) E(0) = ∫_{v·h>0} D(h)(v·h) dω_h / ∫ D max(0, v·m)
    # dω_m = 1, since a horizontal v reflects every h with v·h > 0 into the upper hemisphere.
    # Tolerance: shadefit's error estimate plus a few ulps.
    out = sf_cli.eval_point("sheen-albedo", alpha=alpha, n_dot_v=0.0)
    assert abs(out["value"] - 1.0) <= out["error_estimate"] + 16.0 * EPS, out


# ---------------------------------------------------------------------------------------------
# Albedo average


def lambda_gl(alpha: float, mu: float, n: int = 40, n_phi: int = 12) -> float:
    """Λ(μ) by a tensor Gauss–Legendre rule over (θm, φm) (see the module docstring)."""
    k = 1.0 / alpha
    s = math.sqrt(max(0.0, 1.0 - mu * mu))
    theta_k = math.atan2(mu, s)
    x, w = roots_legendre(n)
    xp, wp = roots_legendre(n_phi)
    u, wu = 0.5 * (x + 1.0), 0.5 * w
    span = HALF_PI - theta_k
    t = np.concatenate([theta_k * u, theta_k + span * u * u])
    wt = np.concatenate([theta_k * wu, 2.0 * span * u * wu])
    a, b = s * np.sin(t), mu * np.cos(t)
    ratio = np.divide(-b, a, out=np.full_like(a, -2.0), where=a > 0.0)
    top = np.where(a <= b, math.pi, np.arccos(np.clip(ratio, -1.0, 1.0)))
    ph = 0.5 * top[:, None] * (xp[None, :] + 1.0)
    az = (0.5 * top[:, None] * wp[None, :] * (a[:, None] * np.cos(ph) + b[:, None])).sum(axis=1)
    g = 2.0 * _d_norm(alpha) * np.sum(wt * np.sin(t) ** (k + 1.0) * az)
    return float(g / mu - 1.0)


AVG_ALPHA = 0.5
GL_CHECK_MU = [1e-6, 1e-4, 1e-2, 0.05, 0.2, 0.5, 0.7, 0.9, 0.99, 0.9999]


def test_gl_lambda_against_nested_quad():
    # The G–L Λ used by the E_avg reference: against the nested quad (bound 1e-11 relative to
    # 1 + Λ, over 10× the quad's bound) and against itself at half the nodes (same bound). E_avg
    # depends on Λ through G2 ≤ 1, so 1e-11 in Λ moves it by < 1e-11.
    for mu in GL_CHECK_MU:
        ref, ref_err = lambda_reference(AVG_ALPHA, mu)
        g40, g20 = lambda_gl(AVG_ALPHA, mu), lambda_gl(AVG_ALPHA, mu, 20, 8)
        assert abs(g40 - ref) <= 1e-11 * (1.0 + ref), (mu, g40, ref, ref_err)
        assert abs(g40 - g20) <= 1e-11 * (1.0 + ref), (mu, g40, g20)


def albedo_avg(alpha: float, eps_outer: float, eps_e: float) -> tuple[float, float]:
    lam = functools.lru_cache(maxsize=None)(lambda m: lambda_gl(alpha, m))
    e_err = [0.0]

    def f(mu):
        v, e = _albedo(alpha, mu, "smith", eps_e, lam)
        e_err[0] = max(e_err[0], e)
        return 2.0 * mu * v

    v, e = _quad(f, 0.0, 1.0, epsabs=eps_outer, epsrel=0.0, limit=100)
    return v, e + e_err[0]  # E's estimates times the weight ∫ 2μ dμ = 1


def test_albedo_average_against_nested_quadrature():
    # At α = 0.5 (one α: each E costs ~70 inner quads). Error bound of the reference: the finer
    # run's estimate plus its change from a run at 10× looser tolerances; kept under 1% of 1e-7.
    fine, e = albedo_avg(AVG_ALPHA, 1e-9, 1e-10)
    coarse, _ = albedo_avg(AVG_ALPHA, 1e-8, 1e-9)
    ref_err = e + abs(fine - coarse)
    assert ref_err <= 1e-2 * ALBEDO_ATOL, (fine, coarse, e)
    out = sf_cli.eval_point("sheen-albedo-avg", alpha=AVG_ALPHA)
    assert abs(out["value"] - fine) <= ALBEDO_ATOL, (out, fine, ref_err)


# ---------------------------------------------------------------------------------------------
# roughness = √α alias


@pytest.mark.parametrize("quantity", ["sheen-lambda", "sheen-albedo", "sheen-albedo-ek", "sheen-albedo-ashikhmin"])
def test_roughness_alias_is_alpha_squared(quantity):
    # 0.5² = 0.25 exactly, so both calls integrate at the same double α: equal bit for bit.
    a = sf_cli.eval_point(quantity, roughness=0.5, n_dot_v=0.4)
    b = sf_cli.eval_point(quantity, alpha=0.25, n_dot_v=0.4)
    assert a["value"] == b["value"], (a, b)


def test_roughness_alias_of_albedo_average():
    # As above (exact equality).
    a = sf_cli.eval_point("sheen-albedo-avg", roughness=0.5)
    b = sf_cli.eval_point("sheen-albedo-avg", alpha=0.25)
    assert a["value"] == b["value"], (a, b)
