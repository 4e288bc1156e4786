"""`shadefit eval skin-punctual` / `skin-sh` against an independent scipy implementation.

The reference is written from the definitions only (d'Eon & Luebke's six Gaussians, GPU Gems 3
ch. 14, variances in mm² and RGB weights; the seed's ring integral with the *linear* profile):

    D(θ, κ) = ∫_{−π}^{π} max(cos(θ + x), 0) P(2r sin(x/2)) dx / ∫_{−π}^{π} P(2r sin(x/2)) dx,  r = 1/κ
    P(s) = Σ w_i exp(−s²/(2 v_i)) / sqrt(2π v_i)

    k_l(κ) = ∫ K(γ) P_l(cos γ) sin γ dγ / ∫ K(γ) sin γ dγ,  K = radial profile of the chord 2r sin(γ/2)

Tolerance: shadefit's own error estimate plus quad's abserr (both below 1e-9 here) plus 1e-9
for quad's estimate being an estimate; a wrong weight, variance or kernel changes values by
>1e-3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

import sf_cli

VARIANCES = [0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41]
WEIGHTS = [  # (R, G, B) per Gaussian
    (0.233, 0.455, 0.649),
    (0.100, 0.336, 0.344),
    (0.118, 0.198, 0.0),
    (0.113, 0.007, 0.007),
    (0.358, 0.004, 0.0),
    (0.078, 0.0, 0.0),
]

rng = np.random.default_rng(7)
POINTS = [(0.5, 0.0), (1.0, -0.3), (0.05, 0.9), (3.0, 0.2)] + [
    (float(k), float(nl)) for k, nl in zip(rng.uniform(0.02, 2.0, 6), rng.uniform(-1.0, 1.0, 6))
]


def linear_profile(s: float, ch: int) -> float:
    return sum(w[ch] * math.exp(-s * s / (2 * v)) / math.sqrt(2 * math.pi * v) for v, w in zip(VARIANCES, WEIGHTS))


def radial_profile(s: float, ch: int) -> float:
    return sum(w[ch] * math.exp(-s * s / (2 * v)) / (2 * math.pi * v) for v, w in zip(VARIANCES, WEIGHTS))


def ring(kappa: float, n_dot_l: float, ch: int) -> tuple[float, float]:
    r = 1.0 / kappa
    theta = math.acos(n_dot_l)
    kernel = lambda x: linear_profile(2 * r * math.sin(x / 2), ch)
    # Kinks of max(cos(θ + x), 0) at θ + x = ±π/2.
    kinks = sorted(k for k in (-math.pi / 2 - theta, math.pi / 2 - theta) if -math.pi < k < math.pi)
    num, e1 = integrate.quad(lambda x: max(math.cos(theta + x), 0.0) * kernel(x), -math.pi, math.pi,
                             points=kinks + [0.0], limit=400, epsabs=1e-13, epsrel=1e-13)
    den, e2 = integrate.quad(kernel, -math.pi, math.pi, points=[0.0], limit=400, epsabs=1e-13, epsrel=1e-13)
    return num / den, (e1 + e2 * num / den) / den


@pytest.mark.parametrize("kappa,n_dot_l", POINTS)
def test_skin_punctual_matches_scipy(kappa, n_dot_l):
    got = sf_cli.eval_point("skin-punctual", curvature=kappa, n_dot_l=n_dot_l)
    for ch in range(3):
        ref, err = ring(kappa, n_dot_l, ch)
        tol = got["error_estimate"] + err + 1e-9
        assert abs(got["value"][ch] - ref) <= tol, (kappa, n_dot_l, ch, got["value"][ch], ref)


def test_skin_punctual_flat_limit_is_lambert():
    # κ = 0: no scattering across the surface, D = max(n·l, 0) exactly.
    for nl in (-0.5, 0.0, 0.3, 1.0):
        got = sf_cli.eval_point("skin-punctual", curvature=0.0, n_dot_l=nl)["value"]
        assert got == [max(nl, 0.0)] * 3


@pytest.mark.parametrize("kappa,band", [(0.5, 1), (1.0, 2), (2.0, 1)])
def test_skin_sh_matches_scipy(kappa, band):
    r = 1.0 / kappa
    got = sf_cli.eval_point("skin-sh", curvature=kappa, band=band)
    for ch in range(3):
        k = lambda g: radial_profile(2 * r * math.sin(g / 2), ch) * math.sin(g)
        num, e1 = integrate.quad(lambda g: k(g) * special.eval_legendre(band, math.cos(g)), 0, math.pi,
                                 limit=400, epsabs=1e-13, epsrel=1e-13)
        den, e2 = integrate.quad(k, 0, math.pi, limit=400, epsabs=1e-13, epsrel=1e-13)
        ref = num / den
        tol = got["error_estimate"] + (e1 + e2) / den + 1e-9
        assert abs(got["value"][ch] - ref) <= tol, (kappa, band, ch, got["value"][ch], ref)
