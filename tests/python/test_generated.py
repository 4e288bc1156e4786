"""The committed generated/json files re-evaluated in numpy on their verification grids, against
the integral computed independently (sf_reference: composite Gauss-Legendre of the defining
integral, Newton for the inverse; checked against quad in test_integrals.py):
their error claims (`verification`) must be what the file's own numbers give.

Verification grid (README): each axis `verify` uniform points over `range`, ends included, first
axis fastest. Fits: f = clamp(P/Q) from `model.coefficients` (f64) and from the f32 arrays.
Tables: linear interpolation of the f32 table, as the emitted code does it.

Tolerances:
* F64_TOL = 1e-9 on f64 error claims: the truth on each side -- shadefit's integrator
  (`eval` reports error estimates <= 2e-10 for these quantities) and ours (<= 1e-13, the
  inverse's conditioning included) -- plus f64 evaluation of the model (~1e-15).
* f32 fits: the f32 model is evaluated on the same f32 inputs in the order the emitted code's
  text reads. shadefit measures its claim in its expression tree's order, which can differ from
  the text by an ulp at some points (`c * x * y` is (c x) y as text, c (x y) as a tree), so the
  tolerance is the standard forward error bound of f32 sums and products, which bounds the
  difference between any two orders: 2 gamma_K (sum|p_j N_j| + |f| sum|q_j D_j|) / Q,
  gamma_K = K u / (1 - K u), u = 2^-24, K the longest chain of roundings.
* f32 tables: the lookup is replayed operation for operation in numpy float32 (IEEE single, no
  FMA, like the emitted Rust), so only F64_TOL (the truth) applies.

Two-stage fits (kind "fields", generated/json/fuzz_ps.json) are checked at the end of this file
against `shadefit eval` at a seeded subset of their verification grid.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import sf_cli
import sf_reference as ref
from sf_rational import Rational, model_inputs, model_pq, model_value, term_values

F64_TOL = 1e-9
KINDS = {p.stem: sf_cli.generated(p.stem)["kind"] for p in (sf_cli.ROOT / "generated" / "json").glob("*.json")}
# Fits and tables; skin LUTs (kind "skin-lut", RGB textures) are checked in test_skin.py, two-stage
# fits (kind "fields") at the end of this file.
NAMES = sorted(n for n, k in KINDS.items() if k in ("fit", "table"))
FIELDS = sorted(n for n, k in KINDS.items() if k == "fields")


@pytest.fixture(scope="module")
def inverse():
    return ref.VecInverse()


def axis_points(a, count):
    lo, hi = a["range"]
    if count == 1:
        return np.array([lo])
    i = np.arange(count, dtype=float)
    p = lo + (hi - lo) * i / (count - 1)
    p[-1] = hi
    return p


def grid(axes, key):
    """Points (n, d), first axis fastest."""
    pts = [axis_points(a, a[key]) for a in axes]
    mesh = np.meshgrid(*pts, indexing="ij")
    return np.stack([m.ravel(order="F") for m in mesh], axis=1)


REFERENCED = ("gloss-length", "gloss-from-length", "gloss-combine")


def load(name):
    g = sf_cli.generated(name)
    if g["quantity"] not in REFERENCED:
        pytest.skip(f"no independent reference for quantity {g['quantity']!r} in this suite "
                    "(its claim is checked against eval in test_fit_error_claim_bounds_eval)")
    return g


def plain_form(m):
    """The fits checked here have the plain form clamp(P/Q), Q = 1 + sum(den)."""
    assert m["offset"] == 0.0 and m["factor"] is None, "form with offset/factor not covered here"
    assert m.get("denominator_lead", "1") == "1" and not m.get("derived"), "lead/derived not covered"


def truth(quantity, x, inverse):
    if quantity == "gloss-length":
        return ref.length_vec(x[:, 0])
    if quantity == "gloss-from-length":
        return inverse(x[:, 0])
    if quantity == "gloss-combine":
        # L(x) L(y) == L(y) L(x) exactly: invert each unordered pair once.
        lx = ref.length_vec(x[:, 0])
        ly = ref.length_vec(x[:, 1])
        prod = lx * ly
        uniq, back = np.unique(prod, return_inverse=True)
        return inverse(uniq)[back]
    raise AssertionError(f"no independent reference for quantity {quantity!r}")


def errors(approx, want, x):
    e = np.abs(approx - want)
    return {"max": float(e.max()), "rms": float(np.sqrt(np.mean(e * e))), "worst": x[int(e.argmax())],
            "e": e}


def check_claims(ver, ours, ours32, x, tol32):
    assert ver["points"] == x.shape[0]
    assert abs(ver["max_abs_error"] - ours["max"]) <= F64_TOL, (ver["max_abs_error"], ours["max"])
    assert abs(ver["rms_error"] - ours["rms"]) <= F64_TOL, (ver["rms_error"], ours["rms"])
    # The claimed worst point is a point of the grid where our error is the maximum (ties allowed).
    k = np.flatnonzero(np.all(np.abs(x - np.array(ver["worst_point"])) <= 1e-15, axis=1))
    assert k.size == 1, ver["worst_point"]
    assert ours["e"][k[0]] >= ours["max"] - F64_TOL, (ver["worst_point"], ours["e"][k[0]], ours["max"])
    assert abs(ver["max_abs_error_f32"] - ours32["max"]) <= F64_TOL + tol32, (ver["max_abs_error_f32"], ours32["max"], tol32)
    assert abs(ver["rms_error_f32"] - ours32["rms"]) <= F64_TOL + tol32, (ver["rms_error_f32"], ours32["rms"], tol32)


def _power_chain(terms, first):
    """(feature, n) if the terms are feature^first, feature^(first+1), ... (one feature, one
    monomial each), else None: such sums are emitted in Horner form."""
    names, powers = set(), []
    for t in terms:
        if "+" in t or "*" in t:
            return None
        if t.strip() == "1":
            powers.append(0)
            continue
        name, _, pw = t.strip().partition("^")
        names.add(name)
        powers.append(int(pw) if pw else 1)
    if len(names) != 1 or powers != list(range(first, first + len(terms))):
        return None
    return names.pop()


def f32_model(model: Rational, num32, den32, x32):
    """clamp(P/Q) in float32 on float32 inputs, in the emitted code's order as its text reads
    (generated/src/NAME.rs): Horner for a chain of powers of one feature
    (c0 + x * (c1 + x * (c2 + ...))), otherwise c_j * term added left to right."""
    one = np.float32(1.0)
    n = x32.shape[0]

    def horner(coef, xi, lead):
        acc = np.full(n, np.float32(coef[-1]))
        for c in coef[-2::-1]:
            acc = np.float32(c) + xi * acc
        return acc if lead is None else lead + xi * acc

    def factors(mono):
        out = []
        for fac in mono.strip().split("*"):
            fac = fac.strip()
            if fac != "1":
                name, _, pw = fac.partition("^")
                out += [x32[:, model.features.index(name)]] * (int(pw) if pw else 1)
        return out

    def product(fs):
        v = fs[0]
        for f in fs[1:]:
            v = v * f
        return v

    def combo(terms, coef, start):
        # As the emitted text reads (left-associative): c * a * b is (c * a) * b; a sum of
        # monomials is parenthesised: c * (x * x + y * y); terms are added left to right.
        acc = start
        for t, c in zip(terms, coef):
            monos = [factors(m) for m in t.split("+")]
            c = np.float32(c)
            if len(monos) == 1:
                term = product([np.full(n, c)] + monos[0])
            else:
                sums = [product(fs) if fs else np.full(n, one) for fs in monos]
                term = c * product([sum(sums[1:], sums[0])])
            acc = term if acc is None else acc + term
        return acc

    fp = _power_chain(model.numerator, 0)
    p = horner(num32, x32[:, model.features.index(fp)], None) if fp else combo(model.numerator, num32, None)
    fq = _power_chain(model.denominator, 1) if model.denominator else None
    if fq:
        q = horner(den32, x32[:, model.features.index(fq)], np.full(n, one))
    else:
        q = combo(model.denominator, den32, np.full(n, one))
    f = p / q
    if model.clamp is not None:
        f = np.clip(f, np.float32(model.clamp[0]), np.float32(model.clamp[1]))
    assert f.dtype == np.float32
    return f


def monomial_degree(mono: str) -> int:
    deg = 0
    for fac in mono.strip().split("*"):
        fac = fac.strip()
        if fac != "1":
            deg += int(fac.partition("^")[2] or 1)
    return deg


def f32_bound(model: Rational, c, x):
    """Forward error bound of an f32 evaluation of P/Q (any order), see the module docstring."""
    n_, d_ = model.num_basis(x), model.den_basis(x)
    p, q = n_ @ c[: model.nn], 1.0 + d_ @ c[model.nn:]
    deg = max(monomial_degree(mono) for t in model.numerator + model.denominator for mono in t.split("+"))
    # roundings along the longest chain: one per term added, per factor multiplied, the division
    k = len(model.numerator) + len(model.denominator) + 2 * (deg + 1) + 4
    u = 2.0 ** -24
    gamma = k * u / (1 - k * u)
    sp = np.abs(n_) @ np.abs(c[: model.nn])
    sq = 1.0 + np.abs(d_) @ np.abs(c[model.nn:])
    return float(np.max(2.0 * gamma * (sp + np.abs(p / q) * sq) / np.abs(q)))


def table_lookup_f32(values32, counts, ranges, x):
    """The emitted lookup: t = (x - lo) * ((n - 1) / (hi - lo)), i = min(trunc t, n - 2),
    f = t - i, lerp (bilinear for two axes), all in f32 on x as f32 clamped to the domain."""
    idx, frac = [], []
    for d, (n, (lo, hi)) in enumerate(zip(counts, ranges)):
        lo32, hi32 = np.float32(lo), np.float32(hi)
        xd = np.clip(x[:, d].astype(np.float32), lo32, hi32)
        scale = (np.float32(n) - np.float32(1.0)) / (hi32 - lo32)
        t = (xd - lo32) * scale
        i = np.minimum(t.astype(np.uint32), n - 2)
        idx.append(i.astype(np.int64))
        frac.append(t - i.astype(np.float32))
    one = np.float32(1.0)
    if len(counts) == 1:
        i, f = idx[0], frac[0]
        return values32[i] * (one - f) + values32[i + 1] * f
    nx = counts[0]
    k = idx[1] * nx + idx[0]
    f0, f1 = frac
    a = values32[k] * (one - f0) + values32[k + 1] * f0
    b = values32[k + nx] * (one - f0) + values32[k + nx + 1] * f0
    return a * (one - f1) + b * f1


@pytest.mark.parametrize("name", NAMES)
def test_error_claims(name, inverse):
    g = load(name)
    assert g["name"] == name
    axes = g["axes"]
    x = grid(axes, "verify")
    want = truth(g["quantity"], x, inverse)
    assert inverse.max_last_step <= 1e-10, "reference inverse did not converge"
    ver = g["verification"]
    if g["kind"] == "fit":
        m = g["model"]
        plain_form(m)
        model = Rational(m["features"], m["numerator"], m["denominator"], m["clamp"])
        c = np.array(m["coefficients"], dtype=float)
        # The f32 arrays are the f64 coefficients rounded to f32.
        assert m["numerator_f32"] == [float(np.float32(v)) for v in c[: model.nn]]
        assert m["denominator_f32"] == [float(np.float32(v)) for v in c[model.nn:]]
        approx = model.bind(x).eval_c(c)
        x32 = np.stack([np.clip(x[:, d].astype(np.float32), np.float32(a["range"][0]), np.float32(a["range"][1]))
                        for d, a in enumerate(axes)], axis=1)
        approx32 = f32_model(model, m["numerator_f32"], m["denominator_f32"], x32).astype(float)
        c32 = np.array(m["numerator_f32"] + m["denominator_f32"])
        tol32 = f32_bound(model, c32, x32.astype(float))
    else:
        assert g["layout"] == "first axis fastest"
        values = np.array(g["values"], dtype=float)
        approx32 = table_lookup_f32(values.astype(np.float32), [a["count"] for a in axes],
                                    [a["range"] for a in axes], x).astype(float)
        approx, tol32 = approx32, 0.0
    ours, ours32 = errors(approx, want, x), errors(approx32, want, x)
    check_claims(ver, ours, ours32, x, tol32)
    if "max_abs_error_in_parameter" in ver and ver["max_abs_error_in_parameter"] is not None:
        # 1-D gloss-length: max |gloss_from_length(approx(g)) - g|, through our inverse.
        assert g["quantity"] == "gloss-length"
        back = inverse(approx)
        err = float(np.max(np.abs(back - x[:, 0])))
        # Both inverses are accurate to ~1e-10 in gloss (shadefit's eval error estimate for
        # gloss-from-length is 8.9e-11); the f64 model values differ by ulps, which the inverse
        # amplifies by at most 1/L'(1) ~ 2100 (~5e-13).
        assert abs(ver["max_abs_error_in_parameter"] - err) <= F64_TOL, (ver["max_abs_error_in_parameter"], err)


@pytest.mark.parametrize("name", [n for n in NAMES if sf_cli.generated(n)["kind"] == "table"])
def test_table_values_are_the_integral(name, inverse):
    g = load(name)
    x = grid(g["axes"], "count")
    values = np.array(g["values"], dtype=float)
    assert values.shape == (x.shape[0],)
    want = truth(g["quantity"], x, inverse)
    err = np.abs(values - want)
    assert err.max() <= F64_TOL, (x[int(err.argmax())], values[int(err.argmax())], want[int(err.argmax())])


def dense_grid(axes, n):
    mesh = np.meshgrid(*[np.linspace(*a["range"], n) for a in axes], indexing="ij")
    return np.stack([v.ravel() for v in mesh], axis=1)


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS[n] == "fit"])
def test_denominator_lower_bound_holds(name):
    """`denominator_lower_bound` is a proven lower bound of Q on the domain: it must be positive
    and not above Q's minimum on a dense grid (which is >= the true minimum)."""
    g = sf_cli.generated(name)
    m = g["model"]
    assert model_inputs(m) == [a["name"] for a in g["axes"]]
    x = dense_grid(g["axes"], 20001 if len(g["axes"]) == 1 else 513)
    # Q = denominator_lead + sum(den), derived features included (sf_rational.model_pq).
    qmin = float(np.min(model_pq(m, m["coefficients"], x)[1]))
    assert 0.0 < m["denominator_lower_bound"] <= qmin * (1 + 1e-12), (m["denominator_lower_bound"], qmin)


# ---------------------------------------------------------------------------------------------
# Fits of quantities with no scipy reference here (fuzz G, Q, R): their claims against
# `shadefit eval` (the integral), at a seeded subset of the verification grid and the claimed
# worst point, in f64 through the generated model form (sf_rational.model_value: derived
# features, denominator lead, offset, factor). Not independent of shadefit's integrator, but it
# ties the file's coefficients and error claim to the integral `eval` serves.

FIT_EVAL_POINTS = 12   # per file, + the worst point (fuzz-r: ~40 ms a point)


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS[n] == "fit"
                                  and sf_cli.generated(n)["quantity"] not in REFERENCED])
def test_fit_error_claim_bounds_eval(name):
    """As test_fields_error_claim_bounds_eval, for a kind "fit" file: the subset's errors are at
    most the claimed maximum (they are points of its grid), the worst point's is the maximum.
    Tolerance: the spec's integrator tolerance (the verification's truth), eval's error
    estimate, and 1e-12 for the f64 model sum's rounding."""
    g = sf_cli.generated(name)
    m, ver = g["model"], g["verification"]
    c = np.array(m["coefficients"], dtype=float)
    nn = len(m["numerator"])
    # The f32 arrays are the f64 coefficients rounded to f32.
    assert m["numerator_f32"] == [float(np.float32(v)) for v in c[:nn]]
    assert m["denominator_f32"] == [float(np.float32(v)) for v in c[nn:]]
    x_all = grid(g["axes"], "verify")
    assert ver["points"] == x_all.shape[0]
    worst = np.array(ver["worst_point"], dtype=float)
    assert np.any(np.all(np.abs(x_all - worst) <= 1e-15, axis=1)), worst
    rng = np.random.default_rng(20250612)
    x = np.vstack([x_all[rng.choice(x_all.shape[0], FIT_EVAL_POINTS, replace=False)], worst])
    approx = model_value(m, c, x)
    names = [a["name"] for a in g["axes"]]
    tol_spec = spec_tolerance(g)
    errs = []
    for p, a in zip(x, approx):
        out = sf_cli.eval_point(g["quantity"], **{k: float(v) for k, v in zip(names, p)})
        errs.append((abs(a - out["value"]), out["error_estimate"], p))
    for e, est, p in errs:
        assert e <= ver["max_abs_error"] + tol_spec + est + 1e-12, (p.tolist(), e, ver["max_abs_error"])
    e, est, _ = errs[-1]
    assert abs(e - ver["max_abs_error"]) <= tol_spec + est + 1e-12, (worst.tolist(), e, ver["max_abs_error"])


# ---------------------------------------------------------------------------------------------
# Two-stage fits (kind "fields"): coefficient fields c_k(outer) = offset_k + factor * P_k / Q_k
# over the outer axes (fuzz_ps: alpha, theta_f), each the generated/json model form with its own
# offset and coefficients, combined by the inner basis (fuzz_ps: P~_s = c0 + c1 n.u + c2 t.u +
# c3 (n.u)^2 + c4 (n.u)(t.u) + c5 (t.u)^2) and clamped to the basis range.
#
# Reference: `shadefit eval QUANTITY` (the integral, one process per point; eval takes one point,
# so the subset is small). Light direction (theta_u, phi_u) -> arguments, from the spec's
# conventions (normal +z, fiber t = (sin theta_f, 0, cos theta_f), phi_u from the fiber azimuth):
#   n.u = cos theta_u,   t.u = sin theta_u cos phi_u sin theta_f + cos theta_u cos theta_f.

FIELD_OUTER_POINTS = 8   # seeded subset of the outer verification grid (fuzz_ps: 15 x 15)
FIELD_INNER_POINTS = 6   # light directions per outer point, of the inner grid (fuzz_ps: 25 x 25)
# 8 x 6 + the claimed worst point = 49 `eval` processes (a few ms each).


def fields_args(quantity, outer, inner):
    if quantity != "fuzz-ps":
        raise AssertionError(f"no light-direction convention for quantity {quantity!r} in this suite")
    theta_f, theta_u, phi_u = outer[:, 1], inner[:, 0], inner[:, 1]
    n_u = np.cos(theta_u)
    t_u = np.sin(theta_u) * np.cos(phi_u) * np.sin(theta_f) + np.cos(theta_u) * np.cos(theta_f)
    return np.stack([n_u, t_u], axis=1)


def fields_value(g, x):
    """The two-stage form in f64 at points x = (outer..., inner...) (rows)."""
    m, basis = g["model"], g["basis"]
    n_outer = len(model_inputs(m))
    outer, inner = x[:, :n_outer], x[:, n_outer:]
    args = fields_args(g["quantity"], outer, inner)
    total = np.zeros(x.shape[0])
    assert len(g["fields"]) == len(basis["terms"])
    for f, term in zip(g["fields"], basis["terms"]):
        ck = model_value(m, f["coefficients"], outer, offset=f["offset"])
        total += ck * term_values(term, basis["arguments"], args)
    return np.clip(total, *basis["range"])


def spec_tolerance(g):
    """The integrator's absolute tolerance per sample of the spec the file came from."""
    spec = tomllib.loads((sf_cli.ROOT / g["spec"]).read_text())
    return float(spec.get("tolerance", 1e-12))   # the spec schema's default (README)


@pytest.mark.parametrize("name", FIELDS)
def test_fields_error_claim_bounds_eval(name):
    """At a seeded subset of the verification grid (plus the claimed worst point), P~ in numpy f64
    against `shadefit eval`. The subset's points are points of the grid the claim
    `verification.max_abs_error` was measured on, so that maximum bounds their error; at the
    claimed worst point the error must be the maximum itself.

    Tolerance: the verification's samples were integrated to the spec's `tolerance` (1e-9 for
    fuzz_ps), eval's to its reported `error_estimate` (1e-12); the model sum in f64 differs from
    shadefit's by rounding (~1e-15, within 1e-12)."""
    g = sf_cli.generated(name)
    ver = g["verification"]
    axes = g["axes"]
    n_outer = len(model_inputs(g["model"]))
    outer_grid = grid(axes[:n_outer], "verify")
    inner_grid = grid(axes[n_outer:], "verify")
    assert ver["points"] == outer_grid.shape[0] * inner_grid.shape[0]
    rng = np.random.default_rng(20250611)
    io = rng.choice(outer_grid.shape[0], FIELD_OUTER_POINTS, replace=False)
    pts = [np.concatenate([outer_grid[i], inner_grid[j]])
           for i in io for j in rng.choice(inner_grid.shape[0], FIELD_INNER_POINTS, replace=False)]
    worst = np.array(ver["worst_point"], dtype=float)
    # The claimed worst point is a point of the verification grid.
    assert np.any(np.all(np.abs(outer_grid - worst[:n_outer]) <= 1e-15, axis=1)), worst
    assert np.any(np.all(np.abs(inner_grid - worst[n_outer:]) <= 1e-15, axis=1)), worst
    x = np.array(pts + [worst])
    approx = fields_value(g, x)
    names = [a["name"] for a in axes]
    tol_spec = spec_tolerance(g)
    errs = []
    for p, a in zip(x, approx):
        out = sf_cli.eval_point(g["quantity"], **{k: float(v) for k, v in zip(names, p)})
        errs.append((abs(a - out["value"]), out["error_estimate"], p))
    for e, est, p in errs:
        assert e <= ver["max_abs_error"] + tol_spec + est + 1e-12, (p.tolist(), e, ver["max_abs_error"])
    e, est, _ = errs[-1]
    assert abs(e - ver["max_abs_error"]) <= tol_spec + est + 1e-12, (worst.tolist(), e, ver["max_abs_error"])


@pytest.mark.parametrize("name", FIELDS)
def test_fields_f32_arrays_are_rounded_coefficients(name):
    g = sf_cli.generated(name)
    nn = len(g["model"]["numerator"])
    for k, f in enumerate(g["fields"]):
        c = np.array(f["coefficients"], dtype=float)
        assert len(c) == nn + len(g["model"]["denominator"]), k
        # The f32 arrays are the f64 coefficients rounded to nearest f32 (exact comparison).
        assert f["numerator_f32"] == [float(np.float32(v)) for v in c[:nn]], k
        assert f["denominator_f32"] == [float(np.float32(v)) for v in c[nn:]], k


@pytest.mark.parametrize("name", FIELDS)
def test_fields_denominator_lower_bounds_hold(name):
    """Each field's `denominator_lower_bound` is a proven lower bound of its Q on the outer domain:
    positive and not above Q's minimum on a dense grid (which is >= the true minimum)."""
    g = sf_cli.generated(name)
    m = g["model"]
    n_outer = len(model_inputs(m))
    x = dense_grid(g["axes"][:n_outer], 513)
    for k, f in enumerate(g["fields"]):
        qmin = float(np.min(model_pq(m, f["coefficients"], x)[1]))
        assert 0.0 < f["denominator_lower_bound"] <= qmin * (1 + 1e-12), (k, f["denominator_lower_bound"], qmin)
