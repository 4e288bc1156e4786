"""`shadefit eval` of the sggx quantities against numpy/scipy computations written here from the
definitions only (src/family/sggx/integrals.rs module doc):

    texel: normal n = (sin θ cos φ, sin θ sin φ, cos θ), roughness α_t along the direction at
           angle ψ from t_n in the normal-mapped frame (t_n, b_n, n), α_b across it; the frame is
           the minimal rotation taking z onto n (about z × n).
    S = F diag(α_t², α_b², 1) Fᵀ with F = [t, b, n] the lobe's frame.
    D(m) = 1 / (π α_t α_b ((t·m/α_t)² + (b·m/α_b)² + (n·m)²)²)   (Burley's form, on the sphere)

* sggx-filter: S′ = (1 − w) S₁ + w S₂; n′ = numpy.linalg.eigh's eigenvector of the largest
  eigenvalue (oriented to z ≥ 0), the block [[Sxx, Sxy], [Sxy, Syy]] = the upper-left of
  F′ᵀ S′ F′ / (F′ᵀ S′ F′)₃₃ with F′ the minimal rotation z → n′ (Rodrigues' formula, not the
  slide's matrix). shadefit finds n′ by power iteration instead; the two agree to the power
  iteration's residual over the eigenvalue gap (its error_estimate) plus f64 rounding of 3×3
  products (1e-13). The iteration count is checked against the rate λ₂/λ₁.
* sggx-projected-area: ∫⟨ω, m⟩₊ D(m) dm by nested scipy quad in polar coordinates about the lobe's
  normal n (the peak at the pole; break points in θ graded by α·4^j), the clamp ⟨·⟩₊ handled
  by the inner φ range's kink angles as break points. shadefit integrates about ω instead.
  Both against the closed form √(ωᵀ S ω) too. Tolerance: 1e-9 plus shadefit's estimate.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import sf_cli


def direction(theta: float, phi: float) -> np.ndarray:
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])


def minimal_rotation(n: np.ndarray) -> np.ndarray:
    """Rodrigues: the rotation about z × n by the angle between z and n."""
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, n)
    s = np.linalg.norm(axis)
    c = float(n[2])
    if s < 1e-300:
        return np.eye(3)
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1 - c) * kx @ kx


def lobe_frame(theta, phi, psi) -> np.ndarray:
    """Columns t, b, n of the lobe: the normal-mapped frame turned by ψ about n."""
    f = minimal_rotation(direction(theta, phi))
    r = np.array([[math.cos(psi), -math.sin(psi), 0], [math.sin(psi), math.cos(psi), 0], [0, 0, 1]])
    return f @ r


def sggx(theta, phi, at, ab, psi) -> np.ndarray:
    f = lobe_frame(theta, phi, psi)
    return f @ np.diag([at * at, ab * ab, 1.0]) @ f.T


FILTER_CASES = [
    # (θ1, φ1, αt1, αb1, ψ1, θ2, φ2, αt2, αb2, ψ2, w)
    (0.3, 0.2, 0.4, 0.1, 0.5, 0.9, -1.0, 0.2, 0.2, 0.0, 0.5),
    (0.0, 0.0, 0.6, 0.05, 1.2, 1.2, 2.5, 0.3, 0.1, -0.7, 0.25),
    (0.7, 1.0, 0.9, 0.8, 0.1, 0.7, -2.1, 0.05, 0.02, 2.0, 0.8),
    (1.4, -3.0, 0.15, 0.15, 0.0, 0.2, 0.4, 0.5, 0.3, 1.0, 0.1),
]
NAMES = ["theta1", "phi1", "alpha_t1", "alpha_b1", "psi1", "theta2", "phi2", "alpha_t2", "alpha_b2", "psi2", "weight"]


@pytest.mark.parametrize("case", FILTER_CASES)
def test_filter_against_numpy_eigh(case):
    out = sf_cli.eval_point("sggx-filter", **dict(zip(NAMES, case)))
    v = dict(zip(out["channels"], out["value"]))
    w = case[10]
    s = (1 - w) * sggx(case[0], case[1], case[2], case[3], case[4]) + w * sggx(case[5], case[6], case[7], case[8], case[9])
    lam, vec = np.linalg.eigh(s)
    n = vec[:, 2] * (1 if vec[2, 2] >= 0 else -1)
    f = minimal_rotation(n)
    b = f.T @ s @ f
    b /= b[2, 2]
    tol = 1e-13 + out["error_estimate"]
    got_n = np.array([v["nx"], v["ny"], v["nz"]])
    assert np.max(np.abs(got_n - n)) <= tol, (got_n, n)
    for name, want in [("sxx", b[0, 0]), ("sxy", b[0, 1]), ("syy", b[1, 1])]:
        assert abs(v[name] - want) <= tol, (name, v[name], want)
    # Residual 1e-14 is reached after ≈ ln(1e-14)/ln(λ₂/λ₁) steps (factor 2 for the start's
    # projection on the other axes); a start already on n′ stops at once.
    rate = lam[1] / lam[2]
    predicted = math.log(1e-14) / math.log(rate)
    assert v["iterations"] <= 2 * predicted + 2, (v["iterations"], predicted)


def d_burley(m, f, at, ab):
    t, b, n = f[:, 0], f[:, 1], f[:, 2]
    q = (m @ t / at) ** 2 + (m @ b / ab) ** 2 + (m @ n) ** 2
    return 1.0 / (math.pi * at * ab * q * q)


def projected_area_scipy(theta, phi, at, ab, psi, w):
    """∫⟨ω,m⟩₊ D dm in polar coordinates (β, γ) about the lobe's normal."""
    f = lobe_frame(theta, phi, psi)
    wl = f.T @ w  # ω in the lobe frame: m = (sin β cos γ, sin β sin γ, cos β) there
    a, rho, g0 = wl[2], math.hypot(wl[0], wl[1]), math.atan2(wl[1], wl[0])
    fl = np.eye(3)

    def inner(beta):
        sb, cb = math.sin(beta), math.cos(beta)
        # ω·m = a cos β + ρ sin β cos(γ − γ0) > 0: an arc of γ around γ0.
        if rho * sb <= abs(a * cb):
            if a * cb <= 0:
                return 0.0
            lo, hi = g0 - math.pi, g0 + math.pi
        else:
            half = math.acos(max(-1.0, min(1.0, -a * cb / (rho * sb))))
            lo, hi = g0 - half, g0 + half

        def g(gamma):
            m = np.array([sb * math.cos(gamma), sb * math.sin(gamma), cb])
            return max(0.0, m @ wl) * d_burley(m, fl, at, ab)

        v, err = integrate.quad(g, lo, hi, epsabs=1e-13, epsrel=1e-13, limit=200, points=[g0] if hi - lo < 2 * math.pi else None)
        return v * sb

    amin = min(at, ab)
    pts = sorted({min(math.pi - 1e-9, amin * 4**j) for j in range(-2, 4)} | {math.pi - min(math.pi - 1e-9, amin * 4**j) for j in range(-2, 4)})
    v, err = integrate.quad(inner, 0.0, math.pi, epsabs=1e-12, epsrel=1e-12, limit=400, points=pts)
    return v, err


AREA_CASES = [
    (0.6, 0.3, 0.5, 0.1, 0.4, 1.0, -0.5),
    (0.6, 0.3, 0.5, 0.1, 0.4, 0.6, 0.3),  # ω = n: the GGX normalisation, 1
    (1.1, -2.0, 0.2, 0.2, 0.0, 0.3, 2.0),
    (0.2, 1.0, 0.05, 0.3, -1.0, 2.5, 0.7),  # ω below the horizon of n
]


@pytest.mark.parametrize("case", AREA_CASES)
def test_projected_area_against_scipy_and_closed_form(case):
    theta, phi, at, ab, psi, tw, pw = case
    out = sf_cli.eval_point("sggx-projected-area", theta=theta, phi=phi, alpha_t=at, alpha_b=ab, psi=psi, theta_w=tw, phi_w=pw)
    w = direction(tw, pw)
    closed = math.sqrt(w @ sggx(theta, phi, at, ab, psi) @ w)
    ref, err = projected_area_scipy(theta, phi, at, ab, psi, w)
    tol = 1e-9 + out["error_estimate"]
    assert abs(ref - closed) <= 1e-9, (ref, closed, err)
    assert abs(out["value"] - closed) <= tol, (out["value"], closed)
    assert abs(out["value"] - ref) <= tol + 1e-9, (out["value"], ref)
