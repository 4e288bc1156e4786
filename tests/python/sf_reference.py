"""Independent scipy computations of the quantities `shadefit eval` serves.

Nothing here calls shadefit or copies its formulas: every value comes from numerical quadrature of
the defining integral (scipy.integrate) and root finding (scipy.optimize).

Definitions (README, "Quantities served by eval"):

* WWII gloss -> GGX alpha:   alpha(g) = sqrt(2 / (1 + 2^(18 g)))
* GGX NDF:                   D(theta) = alpha^2 / (pi (1 + (alpha^2 - 1) cos^2 theta)^2)
* average normal length:     L = E[n.h] for h with density D(h)(n.h) over the hemisphere
                               = 2 pi * int_0^{pi/2} D(theta) cos^2(theta) sin(theta) dtheta
* gloss-from-length:         the g in [0, 1] with L(g) = length, 0 below L(0) = 2/3 and 1 above L(1)
* gloss-combine(x, y):       gloss_from_length(L(x) * L(y))

Two evaluators of L:

* `length_quad` -- scipy.integrate.quad of the hemisphere integral above, point by point (the
  reference for `eval`). For glossy surfaces D is a spike of width ~alpha at theta = 0, so quad is
  given break points at a few multiples of alpha. 1 + (alpha^2 - 1) cos^2 is written
  sin^2 + alpha^2 cos^2 (no cancellation).
* `length_vec` -- composite Gauss-Legendre (scipy.integrate.fixed_quad, vectorised over points)
  of the same integral after the exact changes of variables tan(theta) = alpha u,
  w = 1 / (1 + u^2), w = v^2:
      L(alpha) = int_0^1 sqrt(w / (alpha^2 + (1 - alpha^2) w)) dw
               = int_0^1 2 v^2 / sqrt(alpha^2 + (1 - alpha^2) v^2) dv,
  smooth on [0, 1] with complex singularities at distance ~alpha from v = 0, resolved by
  geometrically graded panels (used for the tens of thousands of points of the generated-file
  grids). test_integrals.py checks it against `length_quad`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, optimize

LN2 = math.log(2.0)
L0 = 2.0 / 3.0  # L at alpha = 1 (gloss 0): 2 * int_0^1 t^2 dt


def alpha_sq(g):
    """alpha^2 for gloss g (scalar or array)."""
    return 2.0 / (1.0 + np.exp2(18.0 * np.asarray(g, dtype=float)))


def alpha(g):
    return np.sqrt(alpha_sq(g))


ALPHA_MIN = float(alpha(1.0))


# --------------------------------------------------------------------------------------------
# Point-by-point: quad + brentq


def length_quad_alpha(a: float) -> tuple[float, float]:
    """(L, quad's absolute error estimate) for GGX alpha `a`, by quad of the hemisphere integral."""
    a2 = a * a

    def integrand(th):
        s, c = math.sin(th), math.cos(th)
        den = s * s + a2 * c * c
        d = a2 / (math.pi * den * den)
        return 2.0 * math.pi * d * c * c * s

    brk = [k * a for k in (1.0, 4.0, 16.0, 64.0) if k * a < 0.5 * math.pi]
    v, err = integrate.quad(integrand, 0.0, 0.5 * math.pi, points=brk or None,
                            epsabs=1e-14, epsrel=1e-13, limit=200)
    return v, err


def length_quad(g: float) -> tuple[float, float]:
    return length_quad_alpha(float(alpha(g)))


def dlength_dg(g: float, h: float = 1e-6) -> float:
    """dL/dg by a central difference of the quad reference (only used to scale tolerances)."""
    lo, hi = max(0.0, g - h), min(1.0, g + h)
    return (length_quad(hi)[0] - length_quad(lo)[0]) / (hi - lo)


L1 = length_quad(1.0)[0]  # the largest length a gloss in [0, 1] reaches

BRENTQ_XTOL = 1e-15


def gloss_from_length_brentq(length: float) -> float:
    """Gloss with average normal length `length` (brentq on quad), clamped to [0, 1]."""
    if length <= L0:
        return 0.0
    if length >= L1:
        return 1.0
    return optimize.brentq(lambda g: length_quad(g)[0] - length, 0.0, 1.0,
                           xtol=BRENTQ_XTOL, rtol=4 * np.finfo(float).eps, maxiter=200)


# --------------------------------------------------------------------------------------------
# Vectorised: composite Gauss-Legendre (scipy.integrate.fixed_quad) + Newton

# Panels [0, 2^-12], [2^-12, 2^-11], ..., [1/2, 1] in v. The integrand's nearest singularities
# are at v = +-i alpha / sqrt(1 - alpha^2), |v| >= alpha >= 0.00276 > 2^-12 * 10, so on every
# panel 20 Gauss-Legendre nodes converge like rho^-40 with rho >= 5.8 (Bernstein ellipse):
# rounding-level accuracy for every gloss in [0, 1].
_PANELS = [0.0] + [2.0 ** -k for k in range(12, -1, -1)]
_NODES = 20


def _composite(f, a2):
    a2 = a2[:, None]
    total = np.zeros(a2.shape[0])
    for lo, hi in zip(_PANELS[:-1], _PANELS[1:]):
        total += integrate.fixed_quad(lambda v: f(v[None, :], a2), lo, hi, n=_NODES)[0]
    return total


def length_vec(g) -> np.ndarray:
    """L(g) for an array of glosses: the v-form of the module docstring, v = sqrt(w):
    L = int_0^1 2 v^2 / sqrt(alpha^2 + (1 - alpha^2) v^2) dv."""
    a2 = np.atleast_1d(alpha_sq(g))
    return _composite(lambda v, a2: 2.0 * v * v / np.sqrt(a2 + (1.0 - a2) * v * v), a2)


def dlength_dg_vec(g) -> np.ndarray:
    """dL/dg: d/d(alpha^2) under the integral sign, times d(alpha^2)/dg."""
    a2 = np.atleast_1d(alpha_sq(g))
    dl_da2 = _composite(lambda v, a2: -v * v * (1.0 - v * v) / (a2 + (1.0 - a2) * v * v) ** 1.5, a2)
    da2_dg = -a2 * 18.0 * LN2 * (1.0 - 0.5 * a2)
    return dl_da2 * da2_dg


class VecInverse:
    """gloss_from_length for arrays: table look-up for a start, then chord-Newton on `length_vec`."""

    def __init__(self, nodes: int = 4097):
        self.g = np.linspace(0.0, 1.0, nodes)
        self.L = length_vec(self.g)
        assert np.all(np.diff(self.L) > 0), "L(g) must be increasing"
        self.l1 = float(self.L[-1])
        self.max_last_step = 0.0  # |last Newton step|: the convergence evidence

    def __call__(self, length) -> np.ndarray:
        length = np.asarray(length, dtype=float)
        out = np.where(length >= self.l1, 1.0, 0.0)
        inside = (length > L0) & (length < self.l1)
        ell = length[inside]
        if ell.size:
            g = np.interp(ell, self.L, self.g)
            d = dlength_dg_vec(g)
            for _ in range(3):
                step = (length_vec(g) - ell) / d
                g = np.clip(g - step, 0.0, 1.0)
            self.max_last_step = max(self.max_last_step, float(np.max(np.abs(step))))
            out[inside] = g
        return out
