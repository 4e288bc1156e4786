"""The emitted f32 code of a generated/json model, replayed operation for operation in numpy float32.

The emitted functions (generated/src/NAME.rs, the WGSL alike) compute, in f32 and in this order:

* inputs: `x as f32` clamped to the f32 domain;
* derived features: `o + x`, `o - x` or `o + s * x` (o, s the definition's numbers as f32), or
  f32 `sin`/`cos` (Rust's f32 sin/cos: the C library's `sinf`/`cosf`, called here through ctypes);
* a sum of coefficients times terms (`P`, and `Q` after its lead): Horner's form
  `c0 + x * (c1 + x * (c2 + ...))`, times x^start, when the terms are consecutive powers of one
  feature; otherwise `c_j * term` added left to right, the term `1` as `c_j` alone, a term as its
  monomials added left to right (the constant monomials first, as one literal), a monomial as
  its features multiplied left to right in feature order (x^2 y = x * x * y);
* `Q = lead + (sum)`, `offset + factor * (P / Q)`, then the clamp.

IEEE single +, -, *, / are correctly rounded in numpy as in Rust (no FMA contraction in either),
so a replay on the same f32 inputs gives the same bits. The fields evaluator (kind "fields") is
replayed the same way: sum_k c_k * (args product), added left to right, clamped to the range.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import re

import numpy as np

_LIBM = ctypes.CDLL(ctypes.util.find_library("m"))
for _name, _t in (("sinf", ctypes.c_float), ("cosf", ctypes.c_float), ("sin", ctypes.c_double),
                  ("cos", ctypes.c_double)):
    getattr(_LIBM, _name).restype = _t
    getattr(_LIBM, _name).argtypes = [_t]

F32 = np.float32


def libm(name: str, x: np.ndarray) -> np.ndarray:
    """The C library's function `name` (sinf, cosf, sin, cos) elementwise, evaluated once per
    distinct value (grids repeat them)."""
    fn = getattr(_LIBM, name)
    dtype = np.float32 if name.endswith("f") else np.float64
    uniq, back = np.unique(np.asarray(x, dtype=dtype), return_inverse=True)
    out = np.array([fn(float(v)) for v in uniq], dtype=dtype)
    return out[back.ravel()].reshape(np.shape(x))


def _exps(term: str, features: list[str]) -> list[list[int]]:
    """Exponent vectors (one per monomial, in feature order) of a term label."""
    out = []
    for mono in term.split("+"):
        e = [0] * len(features)
        for fac in mono.strip().split("*"):
            fac = fac.strip()
            if fac == "1":
                continue
            name, _, pw = fac.partition("^")
            e[features.index(name)] += int(pw) if pw else 1
        out.append(e)
    return out


def _monomial(e: list[int], cols: list[np.ndarray]):
    out = None
    for i, k in enumerate(e):
        for _ in range(k):
            out = cols[i] if out is None else out * cols[i]
    return out


def _term(term: str, features, cols):
    """A term's value in f32 (None never: a constant term is a literal)."""
    out, const = None, F32(0.0)
    for e in _exps(term, features):
        v = _monomial(e, cols)
        if v is None:
            const = const + F32(1.0)
        else:
            out = v if out is None else out + v
    if out is None:
        return const
    return out if const == 0 else const + out


def _consecutive_powers(terms, features):
    """(feature, start) if the terms are x^start, x^(start+1), ... of one feature."""
    exps = [_exps(t, features) for t in terms]
    if any(len(e) != 1 for e in exps):
        return None
    first = exps[0][0]
    if not any(first):
        var = next((i for i, v in enumerate(exps[1][0]) if v > 0), 0) if len(exps) > 1 else 0
    else:
        var = next(i for i, v in enumerate(first) if v > 0)
    start = first[var]
    for k, (e,) in enumerate(exps):
        if any(v != (start + k if i == var else 0) for i, v in enumerate(e)):
            return None
    return var, start


def _linear_combination(terms, coef, features, cols, n):
    if not terms:
        return np.zeros(n, dtype=np.float32)
    chain = _consecutive_powers(terms, features)
    if chain is not None:
        var, start = chain
        x = cols[var]
        acc = np.full(n, F32(coef[-1]))
        for c in coef[-2::-1]:
            acc = F32(c) + x * acc
        for _ in range(start):
            acc = x * acc
        return acc
    out = None
    for t, c in zip(terms, coef):
        tv = _term(t, features, cols)
        v = np.full(n, F32(c)) if (np.isscalar(tv) or np.ndim(tv) == 0) and tv == 1 else F32(c) * tv
        out = v if out is None else out + v
    return out


_AFFINE = re.compile(r"^(\S+) \+ (\S+)\*(\w+)$")
_TRIG = re.compile(r"^(sin|cos)\((\w+)\)$")


def inputs_f32(axes: list[dict], x) -> np.ndarray:
    """Inputs as emitted code sees them: f32, clamped to the f32 domain of each axis."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    return np.stack([np.clip(x[:, d].astype(np.float32), F32(a["range"][0]), F32(a["range"][1]))
                     for d, a in enumerate(axes)], axis=1)


def features_f32(m: dict, x32: np.ndarray) -> list[np.ndarray]:
    """Every feature of the model (inputs, then derived, in `features` order) in f32."""
    derived = {d["name"]: d["definition"] for d in m.get("derived") or []}
    inputs = [f for f in m["features"] if f not in derived]
    cols = {name: x32[:, i] for i, name in enumerate(inputs)}
    for name, definition in derived.items():
        a = _AFFINE.match(definition.strip())
        if a:
            o, s, v = F32(float(a[1])), F32(float(a[2])), cols[a[3]]
            cols[name] = o + v if s == 1 else (o - v if s == -1 else o + s * v)
            continue
        t = _TRIG.match(definition.strip())
        if not t:
            raise ValueError(f"derived feature definition {definition!r} not understood")
        cols[name] = libm(t[1] + "f", cols[t[2]])
    return [cols[f] for f in m["features"]]


def model_value_f32(m: dict, c32, x32: np.ndarray, offset: float | None = None) -> np.ndarray:
    """The emitted function with f32 coefficients c32 = [numerator..., denominator...] on f32
    inputs x32 (see inputs_f32), as float32. `offset` overrides the model's (fields)."""
    feats = m["features"]
    cols = features_f32(m, x32)
    n = x32.shape[0]
    nn = len(m["numerator"])
    c32 = [F32(v) for v in c32]
    p = _linear_combination(m["numerator"], c32[:nn], feats, cols, n)
    lead = m.get("denominator_lead") or "1"
    lead_v = _term(lead, feats, cols)
    q = lead_v + _linear_combination(m["denominator"], c32[nn:], feats, cols, n) if m["denominator"] else lead_v
    v = p / q
    if m.get("factor"):
        v = _term(m["factor"], feats, cols) * v
    off = m.get("offset", 0.0) if offset is None else offset
    if off != 0.0:
        v = F32(off) + v
    if m.get("clamp") is not None:
        v = np.clip(v, F32(m["clamp"][0]), F32(m["clamp"][1]))
    v = np.broadcast_to(v, (n,)).astype(np.float32)
    return v


def basis_sum_f32(terms: list[str], arguments: list[str], c: list[np.ndarray], args32: np.ndarray) -> np.ndarray:
    """The fields evaluator before its clamp: c_0 b_0 + c_1 b_1 + ... left to right, b_k the
    product of its arguments left to right (the constant term: c_k alone)."""
    cols = [args32[:, i] for i in range(args32.shape[1])]
    total = None
    for ck, t in zip(c, terms):
        (e,) = _exps(t, arguments)
        b = _monomial(e, cols)
        v = ck if b is None else ck * b
        total = v if total is None else total + v
    return total
