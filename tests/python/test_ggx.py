"""The GGX split-sum quantities (`shadefit eval ggx-*`) against an independent numpy/scipy
computation.

shadefit integrates over the half vector in the GGX sampling variable with adaptive G10/K21
rules. The reference here integrates over the *light* directions (μl, φl) directly, with the
BRDF written out from the contract (GGX D, height-correlated Smith G2, Schlick Fc), on a
composite tensor Gauss–Legendre rule from scipy.special.roots_legendre whose panels are split
around the mirror direction (μl = μv, φ = π) where the lobe peaks. Its error estimate is the
difference between n and 2n nodes per panel (the 2n value is used), which for these analytic
integrands is far above the 2n rule's true error.

Tolerances: shadefit's own `error_estimate` (so the test also checks that claim) plus the
reference's estimate plus 1e-13 for the roundings of sums of ~10⁵ terms of size ≤ 1/n².
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import roots_legendre

import sf_cli

ROUNDING = 1e-13


def _lambda(alpha: float, mu: np.ndarray) -> np.ndarray:
    tan2 = (1.0 - mu * mu) / (mu * mu)
    return 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * tan2))


def _integrand(alpha: float, mu_v: float, mu_l: np.ndarray, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(1 − Fc)·f·μl and Fc·f·μl with f = D G2 / (4 μv μl), at light (μl, φ)."""
    s_v = math.sqrt(max(0.0, 1.0 - mu_v * mu_v))
    s_l = np.sqrt(np.maximum(0.0, 1.0 - mu_l * mu_l))
    v_dot_l = s_v * s_l * np.cos(phi) + mu_v * mu_l
    half = np.sqrt(np.maximum(0.0, 2.0 * (1.0 + v_dot_l)))
    v_dot_h = 0.5 * half  # (1 + v·l)/|v + l|
    n_dot_h = (mu_v + mu_l) / half
    a2 = alpha * alpha
    d = a2 / (math.pi * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0) ** 2)
    g2 = 1.0 / (1.0 + _lambda(alpha, np.asarray(mu_v)) + _lambda(alpha, mu_l))
    f_mu_l = d * g2 / (4.0 * mu_v)
    fc = (1.0 - v_dot_h) ** 5
    return (1.0 - fc) * f_mu_l, fc * f_mu_l


def _cuts(lo: float, hi: float, centre: float, widths: list[float]) -> list[float]:
    pts = {lo, hi}
    for w in widths:
        for p in (centre - w, centre + w):
            if lo < p < hi:
                pts.add(p)
    if lo < centre < hi:
        pts.add(centre)
    return sorted(pts)


def _tensor_gauss(alpha: float, mu_v: float, cos_cone: float, n: int) -> np.ndarray:
    x, w = roots_legendre(n)
    # Cuts at geometric distances from the mirror direction, from α/16 to 64α: the lobe's
    # width is ~α, and its tails decay over decades of distance.
    scales = (0.0625, 0.25, 1.0, 4.0, 16.0, 64.0)
    widths = [s * alpha for s in scales]
    mu_cuts = _cuts(cos_cone, 1.0, mu_v, [s * max(alpha, 1e-3) for s in scales])
    phi_cuts = _cuts(0.0, math.pi, math.pi, widths)
    total = np.zeros(2)
    for a, b in zip(mu_cuts, mu_cuts[1:]):
        mu = 0.5 * (b - a) * x + 0.5 * (a + b)
        wm = 0.5 * (b - a) * w
        for c, d in zip(phi_cuts, phi_cuts[1:]):
            ph = 0.5 * (d - c) * x + 0.5 * (c + d)
            wp = 0.5 * (d - c) * w
            mm, pp = np.meshgrid(mu, ph, indexing="ij")
            s, bias = _integrand(alpha, mu_v, mm, pp)
            wt = np.outer(wm, wp)
            # φ over [0, π] counts twice (the integrand is even in φ).
            total += 2.0 * np.array([(s * wt).sum(), (bias * wt).sum()])
    return total


def reference_env(alpha: float, mu_v: float, cos_cone: float) -> tuple[np.ndarray, float]:
    lo = _tensor_gauss(alpha, mu_v, cos_cone, 40)
    hi = _tensor_gauss(alpha, mu_v, cos_cone, 80)
    return hi, float(np.max(np.abs(hi - lo)))


ENV_POINTS = [
    (alpha, mu_v, c)
    for alpha in (0.1, 0.3, 0.6, 1.0)
    for mu_v in (0.05, 0.3, 0.7, 1.0)
    for c in (0.0, 0.5)
]


@pytest.mark.parametrize("alpha,mu_v,c", ENV_POINTS, ids=[repr(p) for p in ENV_POINTS])
def test_env_against_light_space_quadrature(alpha, mu_v, c):
    out = sf_cli.eval_point("ggx-env", alpha=alpha, n_dot_v=mu_v, cos_cone=c)
    want, ref_err = reference_env(alpha, mu_v, c)
    tol = out["error_estimate"] + ref_err + ROUNDING
    got = np.array(out["value"])
    assert np.all(np.abs(got - want) <= tol), (out, want.tolist(), tol)


def test_albedo_at_normal_incidence_and_alpha_one_is_one_minus_ln2():
    # Closed form of E(1) at α = 1 (derived in integrals.rs): ∫₀¹ μ/(1 + μ) dμ = 1 − ln 2.
    out = sf_cli.eval_point("ggx-albedo", alpha=1.0, n_dot_v=1.0)
    assert abs(out["value"] - (1.0 - math.log(2.0))) <= out["error_estimate"] + ROUNDING


def test_roughness_alias_is_alpha_squared():
    a = sf_cli.eval_point("ggx-albedo", roughness=0.5, n_dot_v=0.4)
    b = sf_cli.eval_point("ggx-albedo", alpha=0.25, n_dot_v=0.4)
    assert a["value"] == b["value"]


def test_albedo_average_against_nested_reference():
    # E_avg = 2∫ E(μ) μ dμ with E from the reference quadrature, integrated by Gauss–Legendre in
    # μ (48 nodes, vs 24 for the estimate; E(μ) is smooth at α = 0.6).
    alpha = 0.6

    def e_avg(n: int) -> float:
        x, w = roots_legendre(n)
        mu = 0.5 * x + 0.5
        e = [float(reference_env(alpha, float(m), 0.0)[0].sum()) for m in mu]
        return float(np.sum(0.5 * w * 2.0 * np.array(e) * mu))

    want, coarse = e_avg(48), e_avg(24)
    out = sf_cli.eval_point("ggx-albedo-avg", alpha=alpha)
    assert abs(out["value"] - want) <= out["error_estimate"] + abs(want - coarse) + 1e-10, (out, want, coarse)


@pytest.mark.parametrize("eta", [0.5, 0.8, 1.0, 1.33, 1.5, 2.5, 5.0])
def test_dielectric_fresnel_average_against_quad(eta):
    def fresnel(c: float) -> float:
        g2 = eta * eta - 1.0 + c * c
        if g2 <= 0.0:
            return 1.0
        g = math.sqrt(g2)
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
        return 0.5 * a * a * (1.0 + b * b)

    points = [math.sqrt(1.0 - eta * eta)] if eta < 1.0 else None
    want, err = integrate.quad(lambda m: 2.0 * fresnel(m) * m, 0.0, 1.0, points=points, epsabs=1e-14, epsrel=0.0, limit=200)
    out = sf_cli.eval_point("fresnel-avg-dielectric", eta=eta)
    assert abs(out["value"] - want) <= out["error_estimate"] + err + ROUNDING, (out, want, err)


@pytest.mark.parametrize("f0", [0.0, 0.04, 0.5, 1.0])
def test_schlick_fresnel_average_against_quad(f0):
    want, err = integrate.quad(lambda m: 2.0 * (f0 + (1.0 - f0) * (1.0 - m) ** 5) * m, 0.0, 1.0, epsabs=1e-15)
    out = sf_cli.eval_point("fresnel-avg-schlick", f0=f0)
    assert abs(out["value"] - want) <= out["error_estimate"] + err + ROUNDING


# Random points with narrow lobes and narrow cones (seeded): α down to 0.003, cones up to
# cos θc = 0.999, n·v over (0, 1]. The agreement is required to 1e-9 absolute: the sum of the
# two quadratures' error estimates is below that at every point drawn (checked first).
_rng = np.random.default_rng(20261124)
CONE_POINTS = [
    (float(a), float(m), float(c))
    for a, m, c in zip(
        np.concatenate([[0.003, 0.008, 0.01], 10.0 ** _rng.uniform(-2.5, 0.0, 9)]),
        _rng.uniform(0.02, 1.0, 12),
        np.concatenate([[0.9, 0.99, 0.999], _rng.uniform(0.0, 0.999, 9)]),
    )
]


@pytest.mark.parametrize("alpha,mu_v,c", CONE_POINTS, ids=[f"{a:.4g},{m:.4g},{c:.4g}" for a, m, c in CONE_POINTS])
def test_env_with_narrow_lobes_and_cones_to_1e_9(alpha, mu_v, c):
    out = sf_cli.eval_point("ggx-env", alpha=alpha, n_dot_v=mu_v, cos_cone=c)
    want, ref_err = reference_env(alpha, mu_v, c)
    assert out["error_estimate"] + ref_err <= 1e-9, (out, ref_err)
    got = np.array(out["value"])
    assert np.all(np.abs(got - want) <= 1e-9), (out, want.tolist())


# The committed cone LUT (fits/ggx_cone_lut.toml, COD: WWII's 3-D table): seeded texels against
# the light-space quadrature above, at the texel's own (n·v, gloss → α, cos θc). Each texel is
# shadefit's integral to the spec's tolerance (per texel, each channel); the bound adds the
# reference's estimate and the rounding allowance. The KTX2 file holds each texel rounded to f16
# (numpy's float16 conversion is round-to-nearest-even, as the writer's).
def _cone_lut_texels():
    g = sf_cli.generated("ggx_cone_lut")
    t = g["texture"]
    w, h, d = t["width"], t["height"], t["depth"]
    rng = np.random.default_rng(20261125)
    picks = [(0, 0, 0), (w - 1, h - 1, d - 2), (w // 2, 0, d - 1)]
    picks += [tuple(int(v) for v in (rng.integers(w), rng.integers(h), rng.integers(d - 1))) for _ in range(9)]
    return g, picks


_CONE_G, _CONE_PICKS = _cone_lut_texels()


@pytest.mark.parametrize("i,j,k", _CONE_PICKS, ids=[f"{i},{j},{k}" for i, j, k in _CONE_PICKS])
def test_cone_lut_texels_against_light_space_quadrature(i, j, k):
    g = _CONE_G
    t = g["texture"]
    w, h, d = t["width"], t["height"], t["depth"]
    assert g["axes"][1]["mapping"] == "gloss"
    mu = (i + 0.5) / w
    gloss = (j + 0.5) / h
    alpha = math.sqrt(2.0 / (1.0 + 2.0 ** (18.0 * gloss)))
    c = k / (d - 1)
    got = np.array(g["values"][(k * h + j) * w + i])
    if k == d - 1:
        assert np.all(got == 0.0)
        return
    want, ref_err = reference_env(alpha, mu, c)
    tol = g["quadrature"]["tolerance"] + ref_err + ROUNDING
    assert np.all(np.abs(got - want) <= tol), (got.tolist(), want.tolist(), tol)
    ktx = (sf_cli.ROOT / "generated" / t["ktx2"]).read_bytes()
    assert int.from_bytes(ktx[28:32], "little") == d  # pixelDepth: a 3-D texture
    offset = int.from_bytes(ktx[80:88], "little")
    texels = np.frombuffer(ktx, dtype="<f2", offset=offset, count=w * h * d * 2).reshape(d, h, w, 2)
    assert np.array_equal(texels[k, j, i], got.astype(np.float32).astype(np.float16))
