"""The committed generated/json files re-evaluated in numpy on their verification grids, against
the integral computed independently (sf_reference: composite Gauss-Legendre of the defining
integral, Newton for the inverse; checked against quad in test_integrals.py):
their error claims (`verification`) must be what the file's own numbers give.

Verification grid (README): each axis `verify` uniform points over `range`, ends included, first
axis fastest. Fits: f = clamp(P/Q) from `model.coefficients` (f64) and from the f32 arrays.
Tables: linear interpolation of the f32 table, as the emitted code does it.

References: the gloss quantities by sf_reference; fuzz-q = 2 E_3(d) (scipy.special.expn);
fuzz-g in closed form in E_1, E_2 (g_closed below, derived from the definition and checked here
against quad); fuzz-r by the tensor quadrature of test_fuzz.py at a seeded subset of the grid and
the claimed worst point (a point costs ~0.2 s there, the whole grid would take minutes).

Tolerances:
* F64_TOL = 2.5e-10 on f64 error claims of the gloss quantities: the truth on each side --
  shadefit's integrator (`eval` reports error estimates <= 2e-10 for these quantities, the
  inverse's included) and ours (<= 1e-13, the inverse's conditioning included) -- plus f64
  evaluation of the model (~1e-15). The fuzz quantities: the spec's integrator tolerance (the
  build's truth) plus the reference's error (1e-14 for G and Q) and 1e-14 of rounding.
* f32 fits of the plain form clamp(P/Q): the f32 model is evaluated on the same f32 inputs in the order the emitted code's
  text reads. shadefit measures its claim in its expression tree's order, which can differ from
  the text by an ulp at some points (`c * x * y` is (c x) y as text, c (x y) as a tree), so the
  tolerance is the standard forward error bound of f32 sums and products, which bounds the
  difference between any two orders: 2 gamma_K (sum|p_j N_j| + |f| sum|q_j D_j|) / Q,
  gamma_K = K u / (1 - K u), u = 2^-24, K the longest chain of roundings. Other forms (offset,
  factor, derived features) are replayed in shadefit's own order bit for bit (sf_f32), so only
  the truth's tolerance applies.
* f32 tables: the lookup is replayed operation for operation in numpy float32 (IEEE single, no
  FMA, like the emitted Rust), so only F64_TOL (the truth) applies.

Fits' f32 arrays are the f64 coefficients rounded to f32 and then re-optimised in f32 on the
fitting samples: each within the recorded `f32_rounding.max_ulps_allowed` of the rounded f64
coefficient, and `f32_rounding`'s errors (f64, rounded f32, re-optimised f32 on the fitting grid)
are re-measured here (test_f32_rounding_claims, tolerances there).

Two-stage fits (kind "fields", generated/json/fuzz_ps.json) are checked at the end of this file
against `shadefit eval` at a seeded subset of their verification grid.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy import special

import sf_cli
import sf_f32
import sf_reference as ref
from sf_rational import Rational, model_inputs, model_pq, model_value, term_values

F64_TOL = 2.5e-10
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


REFERENCED = ("gloss-length", "gloss-from-length", "gloss-combine", "fuzz-g", "fuzz-q")
GLOSS = ("gloss-length", "gloss-from-length", "gloss-combine")
# Reference error of the fuzz closed forms (scipy's expn/exp1 to ~1e-15 relative, values <= 1,
# checked against quad in test_fuzz_g_closed_form_matches_quad) and the rounding of their sums.
FUZZ_REF_TOL = 1e-14


def g_closed(mu_v, d):
    """G(d, mu_v) = int_0^1 (1 - exp(-d (mu + mu_v)/(mu mu_v))) mu/(mu + mu_v) dmu in closed form.
    With mu/(mu + mu_v) = 1 - mu_v/(mu + mu_v), s = 1/mu and int_0^1 e^{-d/mu} dmu = E_2(d):
      int_0^1 mu/(mu + mu_v) dmu                 = 1 - mu_v ln(1 + 1/mu_v),
      int_0^1 e^{-d/mu} / (mu + mu_v) dmu          = E_1(d) - e^{d/mu_v} E_1(d (1 + 1/mu_v)),
    so G = 1 - mu_v ln(1 + 1/mu_v) - e^{-d/mu_v} E_2(d) + mu_v (e^{-d/mu_v} E_1(d) - E_1(d (1 + 1/mu_v))),
    and G(0, mu_v) = 0 (the integrand vanishes; the E_1 terms are infinite there)."""
    mu_v, d = np.asarray(mu_v, dtype=float), np.asarray(d, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        e = np.exp(-d / mu_v)
        g = (1.0 - mu_v * np.log1p(1.0 / mu_v) - e * special.expn(2, d)
             + mu_v * (e * special.exp1(d) - special.exp1(d * (1.0 + 1.0 / mu_v))))
    return np.where(d == 0.0, 0.0, g)


def load(name):
    g = sf_cli.generated(name)
    if g["quantity"] not in REFERENCED:
        pytest.skip(f"no independent reference for quantity {g['quantity']!r} on the whole grid in this "
                    "suite (its claim is checked against eval in test_fit_error_claim_bounds_eval; "
                    "fuzz-r's also against a tensor quadrature at a subset in "
                    "test_fuzz_r_error_claim_against_tensor_quadrature)")
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
    if quantity == "fuzz-q":
        return 2.0 * special.expn(3, x[:, 0])
    if quantity == "fuzz-g":
        return g_closed(x[:, 0], x[:, 1])  # axes (mu_v, d), asserted in test_error_claims
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


def truth_tolerance(g):
    """What bounds the truth on both sides of a claim (module docstring)."""
    if g["quantity"] in GLOSS:
        return F64_TOL
    return spec_tolerance(g) + FUZZ_REF_TOL + 1e-14


def check_claims(ver, ours, ours32, x, tol32, tol=F64_TOL):
    assert ver["points"] == x.shape[0]
    assert abs(ver["max_abs_error"] - ours["max"]) <= tol, (ver["max_abs_error"], ours["max"])
    assert abs(ver["rms_error"] - ours["rms"]) <= tol, (ver["rms_error"], ours["rms"])
    # The claimed worst point is a point of the grid where our error is the maximum (ties allowed).
    k = np.flatnonzero(np.all(np.abs(x - np.array(ver["worst_point"])) <= 1e-15, axis=1))
    assert k.size == 1, ver["worst_point"]
    assert ours["e"][k[0]] >= ours["max"] - tol, (ver["worst_point"], ours["e"][k[0]], ours["max"])
    assert abs(ver["max_abs_error_f32"] - ours32["max"]) <= tol + tol32, (ver["max_abs_error_f32"], ours32["max"], tol32)
    assert abs(ver["rms_error_f32"] - ours32["rms"]) <= tol + tol32, (ver["rms_error_f32"], ours32["rms"], tol32)


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
    if g["quantity"] == "fuzz-g":
        assert [a["name"] for a in axes] == ["mu_v", "d"]
    x = grid(axes, "verify")
    want = truth(g["quantity"], x, inverse)
    assert inverse.max_last_step <= 1e-10, "reference inverse did not converge"
    ver = g["verification"]
    tol = truth_tolerance(g)
    if g["kind"] == "fit" and g["quantity"] not in GLOSS:
        # Offset, factor or derived features: f64 through the generated model form, f32 replayed
        # bit for bit in shadefit's order (no evaluation-order term).
        m = g["model"]
        check_f32_arrays(g)
        approx = model_value(m, np.array(m["coefficients"], dtype=float), x)
        approx32 = f32_function(g, np.array(m["numerator_f32"] + m["denominator_f32"], dtype=float), x)
        tol32 = 0.0
    elif g["kind"] == "fit":
        m = g["model"]
        plain_form(m)
        model = Rational(m["features"], m["numerator"], m["denominator"], m["clamp"])
        c = np.array(m["coefficients"], dtype=float)
        # The f32 arrays are the f64 coefficients rounded to f32, moved by at most the recorded cap.
        check_f32_arrays(g)
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
    check_claims(ver, ours, ours32, x, tol32, tol)
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
    assert err.max() <= truth_tolerance(g), (x[int(err.argmax())], values[int(err.argmax())], want[int(err.argmax())])


def dense_grid(axes, n):
    mesh = np.meshgrid(*[np.linspace(*a["range"], n) for a in axes], indexing="ij")
    return np.stack([v.ravel() for v in mesh], axis=1)


def dense_count(axes):
    """Points per axis of a dense check grid: 20001 in 1-D, 513 in 2-D (2.6e5 points), 129 in
    3-D and above (2.1e6; 513 would be 1.4e8). The checks below need points of the domain only:
    a coarser grid can only make them weaker, never wrong."""
    return {1: 20001, 2: 513}.get(len(axes), 129)


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS[n] == "fit"])
def test_denominator_lower_bound_holds(name):
    """`denominator_lower_bound` is a proven lower bound of Q on the domain: it must be positive
    and not above Q's minimum on a dense grid (which is >= the true minimum)."""
    g = sf_cli.generated(name)
    m = g["model"]
    assert model_inputs(m) == [a["name"] for a in g["axes"]]
    x = dense_grid(g["axes"], dense_count(g["axes"]))
    # Q = denominator_lead + sum(den), derived features included (sf_rational.model_pq).
    qmin = float(np.min(model_pq(m, m["coefficients"], x)[1]))
    assert 0.0 < m["denominator_lower_bound"] <= qmin * (1 + 1e-12), (m["denominator_lower_bound"], qmin)


# ---------------------------------------------------------------------------------------------
# Fits of quantities with no scipy reference here (fuzz G, Q, R): their claims against
# `shadefit eval` (the integral), at a seeded subset of the verification grid and the claimed
# worst point, in f64 through the generated model form (sf_rational.model_value: derived
# features, denominator lead, offset, factor). Not independent of shadefit's integrator, but it
# ties the file's coefficients and error claim to the integral `eval` serves.

FIT_EVAL_POINTS = 12   # per file, + the worst point (fuzz-r: a few ms a point)


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
    # The f32 arrays are the f64 coefficients rounded to f32, moved by at most the recorded cap.
    check_f32_arrays(g)
    x_all = grid(g["axes"], "verify")
    assert ver["points"] == x_all.shape[0]
    worst = np.array(ver["worst_point"], dtype=float)
    assert np.any(np.all(np.abs(x_all - worst) <= 1e-15, axis=1)), worst
    rng = np.random.default_rng(20250612)
    x = np.vstack([x_all[rng.choice(x_all.shape[0], FIT_EVAL_POINTS, replace=False)], worst])
    approx = model_value(m, c, x)
    names = [a["name"] for a in g["axes"]]
    check_claim_at(g, names, x, approx, worst)


# ---------------------------------------------------------------------------------------------
# f32 coefficients of kind "fit" files (`f32_rounding`): the f64 fit rounded to nearest f32, then
# re-optimised in f32 (coordinate moves of a few ulps, spec objective of the f32-evaluated
# function on the fitting samples). Checked here: where the arrays lie relative to the rounded
# f64 coefficients, and the errors the file claims for the three coefficient vectors, re-measured
# on the fitting grid.

def f32_ordinal(a) -> np.ndarray:
    """Position of each f32 on the line of finite f32s (+-0 both at 0): differences are ulps."""
    b = np.asarray(a, dtype=np.float32).view(np.int32).astype(np.int64)
    return np.where(b < 0, -(b & 0x7FFFFFFF), b)


def fixed_indices(g) -> list[int]:
    """Indices (in [numerator..., denominator...]) of the coefficients the spec fixes."""
    spec = tomllib.loads((sf_cli.ROOT / g["spec"]).read_text())
    m = g["model"]
    out = []
    for label in spec["model"].get("fixed", {}):
        if label.startswith("den:"):
            out.append(len(m["numerator"]) + m["denominator"].index(label[4:]))
        else:
            out.append(m["numerator"].index(label))
    return out


def check_f32_arrays(g) -> np.ndarray:
    """The f32 arrays: f32 values, each within the recorded cap of its rounded f64 coefficient,
    fixed coefficients not moved, the recorded moves (ulps) what the arrays give. Returns them."""
    m, rnd = g["model"], g["f32_rounding"]
    c = np.array(m["coefficients"], dtype=float)
    f32 = np.array(m["numerator_f32"] + m["denominator_f32"], dtype=float)
    assert f32.shape == c.shape
    assert np.array_equal(f32.astype(np.float32).astype(float), f32), "not f32 values"
    moves = f32_ordinal(f32) - f32_ordinal(c.astype(np.float32))
    assert np.abs(moves).max() <= rnd["max_ulps_allowed"], (moves, rnd["max_ulps_allowed"])
    assert moves.tolist() == rnd["moves_ulps"], (moves, rnd["moves_ulps"])
    assert rnd["coefficients_moved"] == int(np.count_nonzero(moves))
    assert rnd["max_move_ulps"] == int(np.abs(moves).max())
    for i in fixed_indices(g):
        assert moves[i] == 0, ("a fixed coefficient moved", i)
    return moves


def f32_function(g, c32, x) -> np.ndarray:
    """The emitted f32 function with coefficients c32 at points x (float64 of the float32 values),
    replayed operation for operation (sf_f32): the same bits as shadefit's f32 evaluation."""
    x32 = sf_f32.inputs_f32(g["axes"], x)
    return sf_f32.model_value_f32(g["model"], c32, x32).astype(float)


def check_errors(claim, r, delta, objective, what):
    """A claimed {objective, max_abs_error, rms_error} against residuals r, each within delta
    (per point) of the residual shadefit measured. max and rms move by at most max(delta) (both
    are 1-Lipschitz in the max norm); sum r^4 by at most sum((|r| + delta)^4 - |r|^4). 1e-12
    more for the f64 sums' rounding in either program (values <= 1, <= 66 049 terms)."""
    a = np.abs(r)
    d = np.broadcast_to(np.asarray(delta, dtype=float), a.shape)
    dmax = float(d.max()) + 1e-12
    ours_max, ours_rms = float(a.max()), float(np.sqrt(np.mean(a * a)))
    assert abs(claim["max_abs_error"] - ours_max) <= dmax, (what, claim["max_abs_error"], ours_max, dmax)
    assert abs(claim["rms_error"] - ours_rms) <= dmax, (what, claim["rms_error"], ours_rms, dmax)
    if objective == "minimax":
        ours, tol = ours_max, dmax
    elif objective == "lsq":
        ours, tol = ours_rms, dmax
    else:
        ours, tol = float(np.sum(a ** 4)), float(np.sum((a + d) ** 4 - a ** 4)) + 1e-12
    assert abs(claim["objective"] - ours) <= tol, (what, claim["objective"], ours, tol)


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS[n] == "fit"])
def test_f32_rounding_claims(name, inverse):
    """`f32_rounding` re-measured on the fitting grid (each axis `count` points, first axis
    fastest). Truth: our reference for the gloss quantities (within F64_TOL of shadefit's
    samples), `shadefit samples NAME` for the fuzz ones (the very samples the build fitted, so no
    truth term; fuzz_r's take ~20 s). The f64 fit in numpy f64, the rounded and the re-optimised
    f32 vectors replayed bit for bit (f32_function): no tolerance beyond the truth's and 1e-12 for
    the sums (check_errors). The rounded and re-optimised errors differ by more than that where
    coefficients moved (6e-8 to 9e-6 in max or rms in the committed files), so a claim measured
    on the wrong vector fails."""
    g = sf_cli.generated(name)
    m, rnd = g["model"], g["f32_rounding"]
    assert rnd["objective"] == m["objective"]
    x = grid(g["axes"], "count")
    if g["quantity"] in GLOSS:
        y, tol_y = truth(g["quantity"], x, inverse), F64_TOL
    else:
        s = sf_cli.samples(name)
        sx = np.array(s["x"], dtype=float)
        assert sx.shape == x.shape and np.allclose(sx, x, rtol=0, atol=1e-15)
        x, y, tol_y = sx, np.array(s["y"], dtype=float), 0.0
    assert rnd["fitting_samples"] == y.size
    c = np.array(m["coefficients"], dtype=float)
    rounded = c.astype(np.float32).astype(float)
    moves = check_f32_arrays(g)
    c32 = np.array(m["numerator_f32"] + m["denominator_f32"], dtype=float)
    check_errors(rnd["f64"], model_value(m, c, x) - y, tol_y, rnd["objective"], "f64")
    check_errors(rnd["rounded_f32"], f32_function(g, rounded, x) - y, tol_y, rnd["objective"], "rounded f32")
    check_errors(rnd["reoptimised_f32"], f32_function(g, c32, x) - y, tol_y, rnd["objective"], "re-optimised f32")
    # The search accepts only strict improvements of this objective (same sums, same order).
    assert rnd["reoptimised_f32"]["objective"] <= rnd["rounded_f32"]["objective"]
    if not moves.any():
        assert rnd["reoptimised_f32"] == rnd["rounded_f32"]
    # The emitted coefficients' denominator, proven positive on the domain, is not above its
    # minimum on a dense grid (the proof is of the f64 evaluation of the f32 coefficients).
    xd = dense_grid(g["axes"], dense_count(g["axes"]))
    qmin = float(np.min(model_pq(m, c32, xd)[1]))
    assert 0.0 < rnd["denominator_lower_bound"] <= qmin * (1 + 1e-12), (rnd["denominator_lower_bound"], qmin)


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


# Monte Carlo quantities: a spec's tolerance t means 1/t² paths a point (the standard error at
# unit per-path deviation, not a bound), and `eval` runs this many paths (msdiffuse's
# integrals::eval_paths caps at 2^20; eval's default tolerance is below 2^-10). The build's
# reference at a point then has standard error est·sqrt(paths_eval)·t, est being eval's.
MONTE_CARLO_EVAL_PATHS = {"ms-diffuse-cosines": 2**20}


def check_claim_at(g, names, x, approx, worst):
    """The error of `approx` at points `x` (named `names`; the last is the claimed worst point)
    against `shadefit eval`: at most the claimed maximum everywhere (they are points of the grid it
    was measured on), the maximum itself at the worst point. Slack: the spec's integrator
    tolerance, eval's error estimate and 1e-12 of rounding."""
    ver = g["verification"]
    tol_spec = spec_tolerance(g)
    errs = []
    for p, a in zip(x, approx):
        out = sf_cli.eval_point(g["quantity"], **{k: float(v) for k, v in zip(names, p)})
        # A fit of one channel of a vector quantity names it ("channel"); eval gives them all.
        value = out["value"][out["channels"].index(g["channel"])] if "channel" in g else out["value"]
        errs.append((abs(a - value), out["error_estimate"], p))
    for e, est, p in errs:
        assert e <= ver["max_abs_error"] + tol_spec + est + 1e-12, (p.tolist(), e, ver["max_abs_error"])
    e, est, _ = errs[-1]
    # The claim was measured against the build's reference: for a Monte Carlo quantity 4 of its
    # standard errors at the worst point (the worst point of a noisy grid is picked partly by
    # the noise), else the spec's tolerance.
    paths = MONTE_CARLO_EVAL_PATHS.get(g["quantity"])
    ref_err = 4.0 * est * math.sqrt(paths) * tol_spec if paths else tol_spec
    assert abs(e - ver["max_abs_error"]) <= ref_err + est + 1e-12, (worst.tolist(), e, ver["max_abs_error"])


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
    check_claim_at(g, names, x, approx, worst)


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


def fields_args_f32(quantity, outer, inner):
    """The evaluator's arguments as the build computes them: in f64 in the order of
    src/family/fuzz/mod.rs (fuzz_ps_args: t.u = sin theta_u cos phi_u sin theta_f + cos theta_u cos
    theta_f, with the C library's sin and cos, as Rust's), then to f32, clamped to [-1, 1]."""
    if quantity != "fuzz-ps":
        raise AssertionError(f"no light-direction convention for quantity {quantity!r} in this suite")
    st, ct = sf_f32.libm("sin", outer[:, 1]), sf_f32.libm("cos", outer[:, 1])
    su, cu = sf_f32.libm("sin", inner[:, 0]), sf_f32.libm("cos", inner[:, 0])
    t_u = su * sf_f32.libm("cos", inner[:, 1]) * st + cu * ct
    args = np.stack([cu, t_u], axis=1).astype(np.float32)
    return np.clip(args, np.float32(-1.0), np.float32(1.0))


@pytest.mark.parametrize("name", FIELDS)
def test_fields_f32_rounding_claims(name):
    """A two-stage fit's f32 arrays are not re-optimised (`reoptimised: false`, see
    src/pipeline/fields.rs); its `f32_rounding` errors of the f64 fields and of the f32 code on the
    fitting grid, re-measured against `shadefit samples NAME` (fuzz_ps: 627 264 integrals, ~20 s).
    The f32 code is replayed bit for bit: each field with sf_f32 at the outer points, the
    evaluator on the arguments as the build computes them (fields_args_f32).

    Tolerance: the samples and the build's may come from different integration paths (per point
    vs per outer point), each within the spec's `tolerance` of the integral: 2 tolerance, and
    1e-12 for the sums (check_errors)."""
    g = sf_cli.generated(name)
    rnd = g["f32_rounding"]
    assert rnd["reoptimised"] is False
    m, basis = g["model"], g["basis"]
    axes = g["axes"]
    n_outer = len(model_inputs(m))
    s = sf_cli.samples(name)
    x, y = np.array(s["x"], dtype=float), np.array(s["y"], dtype=float)
    assert rnd["fitting_samples"] == y.size == int(np.prod([a["count"] for a in axes]))
    tol_y = 2.0 * spec_tolerance(g)
    objective = rnd["objective"]
    check_errors(rnd["f64"], fields_value(g, x) - y, tol_y, objective, "f64")
    outer, back = np.unique(x[:, :n_outer], axis=0, return_inverse=True)
    back = back.ravel()
    outer32 = sf_f32.inputs_f32(axes[:n_outer], outer)
    c = [sf_f32.model_value_f32(m, f["numerator_f32"] + f["denominator_f32"], outer32, offset=f["offset"])[back]
         for f in g["fields"]]
    args32 = fields_args_f32(g["quantity"], x[:, :n_outer], x[:, n_outer:])
    lo, hi = (np.float32(v) for v in basis["range"])
    v32 = np.clip(sf_f32.basis_sum_f32(basis["terms"], basis["arguments"], c, args32), lo, hi).astype(float)
    check_errors(rnd["rounded_f32"], v32 - y, tol_y, objective, "rounded f32")


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


# ---------------------------------------------------------------------------------------------
# The fuzz references of this file, themselves checked; fuzz-r's claim at a subset of its grid.


def test_fuzz_g_closed_form_matches_quad():
    """g_closed against scipy quad of the defining integral (test_fuzz.g_reference: graded break
    points, 1e-13 requested) over the fuzz_g domain's corners and inside: within quad's error
    estimate and FUZZ_REF_TOL. Also G(0, mu_v) = 0 and the grid's smallest d."""
    from test_fuzz import g_reference

    pts = [(1e-3, 0.5 / 256), (1e-3, 0.5), (1.0, 0.5 / 256), (1.0, 0.5), (0.01, 0.01), (0.1, 0.1),
           (0.37, 0.23), (0.002, 0.3), (0.8, 0.004), (1.0, 0.0)]
    for mu_v, d in pts:
        want, err = g_reference(mu_v, d)
        got = float(g_closed(mu_v, d))
        assert abs(got - want) <= err + FUZZ_REF_TOL, (mu_v, d, got, want, err)


def test_fuzz_q_reference_is_the_integral():
    """2 E_3(d) against quad of Q(d) = 2 int_0^1 e^{-d/mu} mu dmu (the definition)."""
    from scipy import integrate

    for d in (0.0, 0.5 / 128, 0.1, 0.5):
        want, err = integrate.quad(lambda mu: 2.0 * np.exp(-d / mu) * mu if mu > 0 else 0.0, 0.0, 1.0,
                                   epsabs=1e-13, epsrel=1e-13)
        got = float(truth("fuzz-q", np.array([[d]]), None)[0])
        assert abs(got - want) <= err + FUZZ_REF_TOL, (d, got, want, err)


R_CLAIM_POINTS = 6  # seeded points of fuzz_r's 25 x 25 verification grid, + the claimed worst point


@pytest.mark.parametrize("name", [n for n in NAMES if KINDS[n] == "fit"
                                  and sf_cli.generated(n)["quantity"] == "fuzz-r"])
def test_fuzz_r_error_claim_against_tensor_quadrature(name):
    """fuzz-r's claim judged by an independent reference (test_fuzz.r_reference: tensor
    Gauss-Legendre over u and v, never shadefit's formulation) at a seeded subset of the
    verification grid and the claimed worst point: every point's error is at most the claimed
    maximum, the worst point's is the maximum, in f64 and in the f32 code (replayed bit for bit).

    Tolerance: the build's truth (the spec's tolerance, 1e-7), the reference's coarse-to-fine
    difference (its error bound while it converges geometrically: <= 2e-7 at alpha = 0.15, the
    narrowest lobe of the grid) and 1e-14 of rounding."""
    from test_fuzz import R_COARSE, R_FINE, r_reference

    g = sf_cli.generated(name)
    m, ver = g["model"], g["verification"]
    axes = g["axes"]
    assert [a["name"] for a in axes] == ["alpha", "theta_f"]
    x_all = grid(axes, "verify")
    assert ver["points"] == x_all.shape[0]
    worst = np.array(ver["worst_point"], dtype=float)
    assert np.any(np.all(np.abs(x_all - worst) <= 1e-15, axis=1)), worst
    rng = np.random.default_rng(20260412)
    x = np.vstack([x_all[rng.choice(x_all.shape[0], R_CLAIM_POINTS, replace=False)], worst])
    approx = model_value(m, np.array(m["coefficients"], dtype=float), x)
    approx32 = f32_function(g, np.array(m["numerator_f32"] + m["denominator_f32"], dtype=float), x)
    tol_spec = spec_tolerance(g)
    for k, (p, a, a32) in enumerate(zip(x, approx, approx32)):
        fine = r_reference(p[0], p[1], *R_FINE)
        spread = abs(fine - r_reference(p[0], p[1], *R_COARSE))
        assert spread <= 1e-6, (p, spread)  # the reference has converged well below the claim
        tol = tol_spec + spread + 1e-14
        e, e32 = abs(a - fine), abs(a32 - fine)
        assert e <= ver["max_abs_error"] + tol, (p.tolist(), e, ver["max_abs_error"])
        assert e32 <= ver["max_abs_error_f32"] + tol, (p.tolist(), e32, ver["max_abs_error_f32"])
        if k == len(x) - 1:
            assert abs(e - ver["max_abs_error"]) <= tol, (worst.tolist(), e, ver["max_abs_error"])
            assert abs(e32 - ver["max_abs_error_f32"]) <= tol, (worst.tolist(), e32, ver["max_abs_error_f32"])
