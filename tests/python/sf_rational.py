"""The rational model form of shadefit's fits, written from the README/spec contract:

    f(x) = clamp(P(x) / Q(x)),  P = sum_j p_j N_j(x),  Q = 1 + sum_j q_j D_j(x),

N_j, D_j the term labels ("1", "gloss^2", "x + y", "x*y": a term is a sum of monomials sharing one
coefficient). The full coefficient vector is c = [p..., q...] (the constant 1 of Q implicit).

Pins f(a) = v (on P/Q, before any clamp) are P(a) - v Q(a) = 0: linear in c. Each eliminates one
numerator coefficient, so c = M theta + b over the free parameters theta (the rest of c), exactly.
"""

from __future__ import annotations

import re

import numpy as np


def term_values(term: str, features: list[str], x: np.ndarray) -> np.ndarray:
    """Values of one term label at points x (shape (n, n_features))."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    total = np.zeros(x.shape[0])
    for mono in term.split("+"):
        v = np.ones(x.shape[0])
        for factor in mono.strip().split("*"):
            factor = factor.strip()
            if factor == "1":
                continue
            name, _, power = factor.partition("^")
            if name not in features:
                raise ValueError(f"term {term!r}: unknown feature {name!r} (features {features})")
            v = v * x[:, features.index(name)] ** (int(power) if power else 1)
        total += v
    return total


# Derived features, as generated/json writes their definitions: "OFFSET + SCALE*NAME", "cos(NAME)",
# "sin(NAME)" (numbers in round-trip decimal).
_AFFINE = re.compile(r"^(\S+) \+ (\S+)\*(\w+)$")
_TRIG = re.compile(r"^(sin|cos)\((\w+)\)$")


def derived_value(definition: str, cols: dict) -> np.ndarray:
    m = _AFFINE.match(definition.strip())
    if m:
        return float(m[1]) + float(m[2]) * cols[m[3]]
    m = _TRIG.match(definition.strip())
    if m:
        return (np.sin if m[1] == "sin" else np.cos)(cols[m[2]])
    raise ValueError(f"derived feature definition {definition!r} not understood")


def model_inputs(m: dict) -> list[str]:
    """The features of a generated/json model that are inputs (not derived), in order."""
    derived = {d["name"] for d in m.get("derived") or []}
    return [f for f in m["features"] if f not in derived]


def feature_matrix(m: dict, x) -> np.ndarray:
    """Values of every feature of a generated/json model (`features`, `derived`) at points x
    (shape (n, inputs)), columns in `features` order."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    inputs = model_inputs(m)
    assert x.shape[1] == len(inputs), (x.shape, inputs)
    cols = {name: x[:, i] for i, name in enumerate(inputs)}
    for d in m.get("derived") or []:
        cols[d["name"]] = derived_value(d["definition"], cols)
    return np.stack([cols[f] for f in m["features"]], axis=1)


def model_pq(m: dict, c, x) -> tuple[np.ndarray, np.ndarray]:
    """P and Q of a generated/json model (`form`: offset + factor * P / Q,
    Q = denominator_lead + sum(den)) with coefficients c = [p..., q...] at input points x."""
    c = np.asarray(c, dtype=float)
    f = feature_matrix(m, x)
    feats = m["features"]
    nn = len(m["numerator"])
    p = sum(cj * term_values(t, feats, f) for t, cj in zip(m["numerator"], c[:nn]))
    q = term_values(m.get("denominator_lead") or "1", feats, f)
    for t, cj in zip(m["denominator"], c[nn:]):
        q = q + cj * term_values(t, feats, f)
    return p + np.zeros(f.shape[0]), q


def model_value(m: dict, c, x, offset: float | None = None) -> np.ndarray:
    """offset + factor * P / Q, clamped if the model has a clamp (f64). `offset` overrides the
    model's (a field of a kind "fields" file carries its own)."""
    p, q = model_pq(m, c, x)
    f = feature_matrix(m, x)
    factor = term_values(m["factor"], m["features"], f) if m.get("factor") else 1.0
    v = (m.get("offset", 0.0) if offset is None else offset) + factor * p / q
    if m.get("clamp") is not None:
        v = np.clip(v, *m["clamp"])
    return v


class Rational:
    def __init__(self, features, numerator, denominator, clamp=None, pins=(), fixed=()):
        if fixed:
            raise NotImplementedError(f"fixed coefficients {fixed!r} (no spec under test has any)")
        self.features = list(features)
        self.numerator = list(numerator)
        self.denominator = list(denominator)
        self.clamp = tuple(clamp) if clamp is not None else None
        self.nn, self.nd = len(self.numerator), len(self.denominator)
        n = self.nn + self.nd
        elim = [self.numerator.index(p["eliminate"]) for p in pins]
        self.free = [j for j in range(n) if j not in elim]
        self.M = np.zeros((n, len(self.free)))
        self.b = np.zeros(n)
        self.M[self.free, np.arange(len(self.free))] = 1.0
        if pins:
            # G c = h: row per pin, P(a) - v * sum q_j D_j(a) = v.
            G = np.array([
                np.concatenate([self.num_basis(p["at"])[0], -p["value"] * self.den_basis(p["at"])[0]])
                for p in pins
            ])
            h = np.array([p["value"] for p in pins], dtype=float)
            ge, gf = G[:, elim], G[:, self.free]
            self.M[elim, :] = -np.linalg.solve(ge, gf)
            self.b[elim] = np.linalg.solve(ge, h)
        self.pins = list(pins)

    @classmethod
    def from_samples(cls, s: dict) -> "Rational":
        m = s["model"]
        assert not m.get("derived") and m.get("lead", "1") in (None, "1"), "lead/derived not covered"
        return cls(s["features"], m["numerator"], m["denominator"], m.get("clamp"), m.get("pins", []),
                   m.get("fixed", []))

    def num_basis(self, x):
        x = np.atleast_2d(np.asarray(x, dtype=float))
        return np.stack([term_values(t, self.features, x) for t in self.numerator], axis=1)

    def den_basis(self, x):
        x = np.atleast_2d(np.asarray(x, dtype=float))
        if not self.denominator:
            return np.zeros((x.shape[0], 0))
        return np.stack([term_values(t, self.features, x) for t in self.denominator], axis=1)

    def full(self, theta) -> np.ndarray:
        return self.M @ np.asarray(theta, dtype=float) + self.b

    def theta_of(self, c) -> np.ndarray:
        return np.asarray(c, dtype=float)[self.free]

    def bind(self, x) -> "Bound":
        return Bound(self, np.atleast_2d(np.asarray(x, dtype=float)))


class Bound:
    """A model with its basis evaluated at fixed points (residuals, Jacobians, objectives)."""

    def __init__(self, model: Rational, x: np.ndarray):
        self.m = model
        self.N = model.num_basis(x)
        self.D = model.den_basis(x)

    def pq(self, c):
        return self.N @ c[: self.m.nn], 1.0 + self.D @ c[self.m.nn:]

    def eval_c(self, c) -> np.ndarray:
        p, q = self.pq(np.asarray(c, dtype=float))
        f = p / q
        if self.m.clamp is not None:
            f = np.clip(f, *self.m.clamp)
        return f

    def q_min(self, c) -> float:
        return float(np.min(self.pq(np.asarray(c, dtype=float))[1]))

    def residuals(self, theta, y):
        return self.eval_c(self.m.full(theta)) - y

    def jacobian(self, theta):
        """d(clamp(P/Q))/d theta; rows where the clamp is active are zero."""
        c = self.m.full(theta)
        p, q = self.pq(c)
        f = p / q
        jc = np.hstack([self.N / q[:, None], -(f / q)[:, None] * self.D])
        if self.m.clamp is not None:
            lo, hi = self.m.clamp
            jc[(f < lo) | (f > hi)] = 0.0
        return jc @ self.m.M
