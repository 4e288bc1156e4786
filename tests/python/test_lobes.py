"""Lobe specs (`kind = "lobe"`) against integrals computed here from the BRDF's definition, over
light directions with scipy's adaptive quadrature — not shadefit's half-vector measure, its
change of variables or its azimuth cuts:

    E(μv) = ∫_{H²} f(v, l) (n·l) dω_l = 2 ∫₀^{π/2} ∫₀^π f (cos θl) sin θl dφ dθl

* fits/studio_cloth.toml, the committed cloth example: the Charlie distribution
  D = (2 + 1/α) sin^{1/α}θh / (2π) (Estevez & Kulla 2017) with Neubelt's visibility
  V = 1/(4(n·l + n·v − n·l n·v)), α = roughness²;
* tests/data/lobes/ggx_written.toml (GGX written out) against test_ggx.reference_env, the light-space
  tensor Gauss–Legendre quadrature of the GGX split sum (E = scale + bias);
* tests/data/lobes/lambert_written.toml: E = ρ.

Tolerances: shadefit's error estimate plus scipy's (dblquad is asked for 1e-10 absolute and 1e-10
relative; its estimate is not returned, so 1e-9 covers it at these smooth points) plus
rounding.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import sf_cli
from test_ggx import reference_env

ROUNDING = 1e-12
SCIPY = 1e-9


def cloth_brdf(alpha: float, mu_v: float, theta_l: float, phi: float) -> float:
    sv = math.sqrt(1.0 - mu_v * mu_v)
    v = np.array([sv, 0.0, mu_v])
    l = np.array([math.sin(theta_l) * math.cos(phi), math.sin(theta_l) * math.sin(phi), math.cos(theta_l)])
    h = v + l
    h /= np.linalg.norm(h)
    sin2_h = max(1.0 - h[2] * h[2], 0.0)
    d = (2.0 + 1.0 / alpha) * sin2_h ** (0.5 / alpha) / (2.0 * math.pi)
    mu_l = l[2]
    vis = 1.0 / (4.0 * (mu_l + mu_v - mu_l * mu_v))
    return d * vis


def cloth_albedo(alpha: float, mu_v: float) -> float:
    value, _ = integrate.dblquad(
        lambda phi, th: cloth_brdf(alpha, mu_v, th, phi) * math.cos(th) * math.sin(th),
        0.0,
        0.5 * math.pi,
        0.0,
        math.pi,
        epsabs=1e-10,
        epsrel=1e-10,
    )
    return 2.0 * value


CLOTH = [(r, mu) for r in (0.4, 0.7, 1.0) for mu in (0.2, 0.5, 0.9)]


@pytest.mark.parametrize("roughness,mu_v", CLOTH, ids=[repr(p) for p in CLOTH])
def test_cloth_example_albedo_against_light_space_quadrature(roughness, mu_v):
    out = sf_cli.eval_point("studio_cloth-albedo", roughness=roughness, n_dot_v=mu_v)
    want = cloth_albedo(roughness * roughness, mu_v)
    assert abs(out["value"] - want) <= out["error_estimate"] + SCIPY + ROUNDING, (out, want)


def lobe_eval(quantity: str, **params: float) -> dict:
    args = [f"{k}={v!r}" for k, v in params.items()]
    return sf_cli.run_json("--fits", "tests/data/lobes", "eval", quantity, *args)


GGX = [(a, mu) for a in (0.1, 0.5, 1.0) for mu in (0.05, 0.5, 1.0)]


@pytest.mark.parametrize("alpha,mu_v", GGX, ids=[repr(p) for p in GGX])
def test_written_ggx_albedo_against_light_space_quadrature(alpha, mu_v):
    out = lobe_eval("ggx_written-albedo", alpha=alpha, n_dot_v=mu_v)
    env, ref_err = reference_env(alpha, mu_v, 0.0)
    assert abs(out["value"] - float(env.sum())) <= out["error_estimate"] + ref_err + ROUNDING, (out, env)


@pytest.mark.parametrize("rho", [0.0, 0.3, 1.0])
def test_written_lambert_albedo_is_rho(rho):
    for mu in (0.0, 0.6, 1.0):
        out = lobe_eval("lambert_written-albedo", rho=rho, n_dot_v=mu)
        assert abs(out["value"] - rho) <= out["error_estimate"] + ROUNDING, out
