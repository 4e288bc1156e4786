"""`shadefit eval fiber-phase-norm` (and `fiber-phase-scale`) against scipy, from the definition
only (src/family/fiber/integrals.rs module doc):

    p_Schlick(k, x) = (1 − k²) / (4π (1 − k x)²),   x = sin∠(t, h),   h = (u + v)/|u + v|
    N(k, u·t) = ∫_{S²} p_Schlick(k, sin∠(t, h)) dω_v,   W = (1 − k²)/N

Reference (it does not use shadefit's change of variables v → h, its closed azimuth or its cap
formula): v over the whole sphere in spherical coordinates (β, γ) about u,
    u = e_z,  t = (s, 0, c),  v = (sin β cos γ, sin β sin γ, cos β),  dω_v = sin β dβ dγ,
sin∠(t, h) = |(u + v) × t|/|u + v| from the vectors, and scipy's nested quad, γ ∈ [0, π] doubled
(the mirror in the plane of u and t). The integrand is continuous and bounded; its one non-smooth
point is the cone h = ±t (β* = 2 arccos|c|, γ = 0 for c > 0, π for c < 0), an end of the outer
quad; the inner quad gets break points at β* and graded ones at β* ± 4ʲ|sin γ| (without them, at
c = −0.95 and γ = π − 2e-4, quad stopped 1.3e-11 off with a roundoff warning). Any
IntegrationWarning is an error.

Tolerance: shadefit's own `error_estimate` (so the claim is checked), plus the nested quad's
requested accuracy (inner 1e-12 integrated over γ ∈ [0, π], outer 1e-11; both before the factor
(1 − k²)/2π ≤ 1/2π), plus a few ulps of the final roundings; and the issue's acceptance, 1e-9.

Run time: ~20 `eval` processes and ~15 nested quads (~0.3 s each).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate

import sf_cli

EPS8 = 8 * np.finfo(float).eps
ACCEPT = 1e-9
INNER, OUTER = 1e-12, 1e-11
rng = np.random.default_rng(20250611)


def _quad(f, a, b, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error", integrate.IntegrationWarning)
        return integrate.quad(f, a, b, limit=200, **kw)


def reference_norm(k: float, c: float) -> tuple[float, float]:
    """N(k, c) and the quads' error bound, over the sphere of v about u."""
    s = math.sqrt(max(0.0, 1.0 - c * c))
    beta_star = 2.0 * math.acos(min(1.0, abs(c)))

    def lobe(beta: float, gamma: float) -> float:
        sb = math.sin(beta)
        # u + v, with 1 + cos β as 2 cos²(β/2) (the sum cancels near v = −u).
        w0, w1, w2 = sb * math.cos(gamma), sb * math.sin(gamma), 2.0 * math.cos(0.5 * beta) ** 2
        n = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        if n == 0.0:
            return 0.0  # v = −u: a null set
        # sin∠(t, h) = |(u + v) × t| / |u + v| (1 − (h·t)² cancels near the cone h = ±t).
        cx, cy, cz = w1 * c, w2 * s - w0 * c, -w1 * s
        x = min(1.0, math.sqrt(cx * cx + cy * cy + cz * cz) / n)
        return sb / (1.0 - k * x) ** 2

    def inner(gamma: float) -> float:
        # Near the cone's γ the β-integrand turns within ~|sin γ| of β*: graded break points.
        pts = None
        if 0.0 < beta_star < math.pi:
            d = abs(math.sin(gamma))
            pts = sorted({beta_star} | {beta_star + sg * d * 4.0**j for j in range(8) for sg in (-1, 1) if 0.0 < beta_star + sg * d * 4.0**j < math.pi})
        return _quad(lambda b: lobe(b, gamma), 0.0, math.pi, points=pts, epsabs=INNER, epsrel=0.0)[0]

    value, err = _quad(inner, 0.0, math.pi, epsabs=OUTER, epsrel=0.0)
    scale = (1.0 - k) * (1.0 + k) * 2.0 / (4.0 * math.pi)
    return scale * value, scale * (err + math.pi * INNER)


POINTS = [(-0.99, 0.0), (-0.99, 1.0), (-0.99, -0.35), (-0.5, 0.3), (-0.2, -0.95), (-0.9, 1e-3)] + [
    (float(k), float(c)) for k, c in zip(rng.uniform(-0.99, 0.0, 9), rng.uniform(-1.0, 1.0, 9))
]


@pytest.mark.parametrize("point", POINTS, ids=[repr(p) for p in POINTS])
def test_norm_matches_scipy_over_the_sphere_of_v(point):
    k, c = point
    ref, ref_err = reference_norm(k, c)
    out = sf_cli.eval_point("fiber-phase-norm", k=k, u_dot_t=c)
    tol = out["error_estimate"] + ref_err + EPS8
    assert abs(out["value"] - ref) <= min(tol, ACCEPT), (out, ref, ref_err)


@pytest.mark.parametrize("point", POINTS[:4], ids=[repr(p) for p in POINTS[:4]])
def test_scale_is_one_minus_k2_over_norm(point):
    k, c = point
    ref, ref_err = reference_norm(k, c)
    out = sf_cli.eval_point("fiber-phase-scale", k=k, u_dot_t=c)
    w = (1.0 - k) * (1.0 + k) / ref
    # |Δ(1/N)| = |ΔN|/N²: the reference's error through W = (1 − k²)/N, N ≥ (1 − k²)·0.3.
    w_err = w * ref_err / ref
    assert abs(out["value"] - w) <= out["error_estimate"] + w_err + EPS8 * w, (out, w)


@pytest.mark.parametrize("c", [-1.0, -0.6, 0.0, 1e-7, 0.42, 1.0])
def test_norm_is_one_at_k_zero(c):
    # p = 1/4π: N = 1 exactly; bound: the claimed estimate plus ulps.
    out = sf_cli.eval_point("fiber-phase-norm", k=0.0, u_dot_t=c)
    assert abs(out["value"] - 1.0) <= out["error_estimate"] + EPS8


def test_spread_alias_is_the_course_mapping():
    # k = −0.99 (1 − spread): the alias and k give the same double.
    a = sf_cli.eval_point("fiber-phase-norm", spread=0.25, u_dot_t=0.5)
    b = sf_cli.eval_point("fiber-phase-norm", k=-0.99 * (1.0 - 0.25), u_dot_t=0.5)
    assert a["value"] == b["value"]


@pytest.mark.parametrize("args", [["k=0.5", "u_dot_t=0.2"], ["k=-1", "u_dot_t=0.2"], ["k=nan", "u_dot_t=0.2"], ["k=-0.5", "u_dot_t=1.5"], ["k=-0.5"]])
def test_out_of_domain_is_an_input_error(args):
    p = sf_cli.run("eval", "fiber-phase-norm", *args, check=False)
    assert p.returncode == 2, p
    assert "fiber-phase-norm" in p.stderr
