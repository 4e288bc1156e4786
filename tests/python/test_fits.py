"""Every fit spec (kind "fit") solved again: by shadefit from scratch and by scipy and nlopt on the
same samples and the same model form, each scored by the spec's objective.

For each fit spec: `shadefit samples NAME --json` gives the exact fitting samples, pins and fixed
coefficients, generated/json/NAME.json the model form (terms, derived features, denominator lead,
offset, factor, clamp) and the committed coefficients, and `shadefit build --only ... --generated
TMP` fits every spec from scratch into a scratch folder (~15 s for all ten). Every reference method
fits the same form (pins and fixed coefficients eliminated exactly, clamp applied inside the
residual), from independent starts: the published COD: WWII constants where there are some, and a
linearised (Loeb) least-squares start computed here; and from the committed coefficients (a
polish: any method that improves on them shows they are not an optimum). Scores:

* lsq:     rss = sum (f(x_i) - y_i)^2
* minimax: max |f(x_i) - y_i|
* l4:      sum (f(x_i) - y_i)^4

Methods: scipy.optimize.least_squares (lm, trf; they minimise rss), nlopt LN_BOBYQA / LN_SBPLX
(derivative-free), LD_LBFGS / LD_SLSQP (gradient-based), and for minimax the epigraph form
min t s.t. |r_i| <= t with LD_SLSQP and LN_COBYLA. A method's result only counts if its denominator
is positive on a dense grid of the whole domain (a pole between samples is no fit).

The claims tested: the fresh fit's objective and the committed one's are each <= the best
method's * (1 + REL). A solver that stops early (a minimax polish ending at 1e-4 relative) fails
the first. Objectives and wall times of every method go to tests/python/out/fit_comparison.json.
"""

from __future__ import annotations

import shutil
import subprocess
import time
import tomllib

import nlopt
import numpy as np
import pytest
from scipy.optimize import least_squares

import sf_cli
import sf_reference as ref
from sf_rational import feature_matrix, model_pq, term_values

# shadefit may be worse than the best method by at most this relative amount: 1e-9 for least
# squares and sum r^4 (LM/Gauss-Newton converge to rounding); 1e-8 for minimax, whose polish
# (src/fit/minimax.rs) solves LPs to an absolute feasibility tolerance of 1e-7 in units of the
# trust region's largest row change, and stalls where a clamp's kink is active: measured 1.9e-9
# relative on ggx_env_bias_rational (LN_SBPLX from the committed coefficients). A polish ending
# at 1e-4 relative still fails by four orders.
REL = {"lsq": 1e-9, "l4": 1e-9, "minimax": 1e-8}

# Published COD: WWII constants (slides "Rational function fitting"), keyed by term label
# ("den:" for denominator terms). The 1-D fit's c0 and c3 follow from its pins.
PUBLISHED = {
    "gloss_length": {"gloss": 0.0943995, "gloss^2": 7.42096, "den:gloss": -1.08778, "den:gloss^2": 8.837},
    "gloss_combine": {
        "1": -0.535580, "x + y": 1.002204, "x^2 + y^2": -0.223910, "x*y": 13.323150,
        "den:x + y": 8.259559, "den:x^2 + y^2": 9.896132, "den:x*y": -22.015902,
    },
}
SPECS = sorted(p.stem for p in (sf_cli.ROOT / "fits").glob("*.toml")
               if tomllib.loads(p.read_text()).get("kind") == "fit")
NLOPT_MAXTIME = 3.0  # seconds per nlopt run (a safety net; all but COBYLA finish far sooner)
COBYLA_MAX_SAMPLES = 200  # COBYLA's epigraph with 2 constraints per sample takes seconds beyond


@pytest.fixture(scope="session")
def fresh(tmp_path_factory):
    """generated/json of every fit spec built from scratch (`shadefit build --only`) in a scratch
    folder, from a copy of fits/."""
    root = tmp_path_factory.mktemp("fresh")
    shutil.copytree(sf_cli.ROOT / "fits", root / "fits")
    (root / "generated").mkdir()
    p = subprocess.run([str(sf_cli.BIN), "build", "--only", ",".join(SPECS), "--fits", str(root / "fits"),
                        "--generated", str(root / "generated")], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    import json
    return {n: json.loads((root / "generated" / "json" / f"{n}.json").read_text()) for n in SPECS}


class Form:
    """The generated/json model form at fixed points: f = clamp(offset + factor * P/Q),
    P = N c_p, Q = lead + D c_q, with c = M theta + b (pins and fixed coefficients eliminated)."""

    def __init__(self, m: dict, samples: dict, x: np.ndarray):
        self.m = m
        feats = m["features"]
        f = feature_matrix(m, x)
        n = x.shape[0]
        self.N = np.stack([term_values(t, feats, f) for t in m["numerator"]], axis=1)
        self.D = (np.stack([term_values(t, feats, f) for t in m["denominator"]], axis=1)
                  if m["denominator"] else np.zeros((n, 0)))
        self.lead = term_values(m.get("denominator_lead") or "1", feats, f) + np.zeros(n)
        self.factor = term_values(m["factor"], feats, f) + np.zeros(n) if m.get("factor") else np.ones(n)
        self.offset = float(m.get("offset", 0.0))
        self.clamp = tuple(m["clamp"]) if m.get("clamp") is not None else None
        self.nn, self.nd = self.N.shape[1], self.D.shape[1]
        self.labels = list(m["numerator"]) + ["den:" + t for t in m["denominator"]]
        sm = samples["model"]
        assert sm["numerator"] == m["numerator"] and sm["denominator"] == m["denominator"]
        # Affine map: fixed coefficients ("num[LABEL]" / "den[LABEL]") and pins (P(a) - v Q(a) = 0
        # on the plain form, each eliminating one numerator coefficient).
        size = self.nn + self.nd
        fixed = {}
        for fx in sm.get("fixed", []):
            side, label = fx["coefficient"][:3], fx["coefficient"][4:-1]
            j = m["numerator"].index(label) if side == "num" else self.nn + m["denominator"].index(label)
            fixed[j] = float(fx["value"])
        pins = sm.get("pins", [])
        elim = [m["numerator"].index(p["eliminate"]) for p in pins]
        self.free = [j for j in range(size) if j not in elim and j not in fixed]
        self.M = np.zeros((size, len(self.free)))
        self.b = np.zeros(size)
        self.M[self.free, np.arange(len(self.free))] = 1.0
        for j, v in fixed.items():
            self.b[j] = v
        if pins:
            assert self.offset == 0.0 and not m.get("factor") and (m.get("denominator_lead") or "1") == "1"
            at = Form(dict(m), {"model": {**sm, "pins": [], "fixed": []}}, np.array([p["at"] for p in pins]))
            v = np.array([p["value"] for p in pins], dtype=float)
            G = np.hstack([at.N, -v[:, None] * at.D])
            h = v * at.lead
            rest = G @ self.b  # fixed coefficients' share
            ge, gf = G[:, elim], G[:, self.free]
            self.M[elim, :] = -np.linalg.solve(ge, gf)
            self.b[elim] = np.linalg.solve(ge, h - rest)

    def full(self, theta):
        return self.M @ np.asarray(theta, dtype=float) + self.b

    def pq(self, c):
        c = np.asarray(c, dtype=float)
        return self.N @ c[: self.nn], self.lead + self.D @ c[self.nn:]

    def value(self, c):
        p, q = self.pq(c)
        with np.errstate(divide="ignore", invalid="ignore"):  # a pole: inf/nan, scored as such
            f = self.offset + self.factor * p / q
        return np.clip(f, *self.clamp) if self.clamp is not None else f

    def jacobian(self, theta):
        """d f / d theta; rows where the clamp is active are zero."""
        c = self.full(theta)
        p, q = self.pq(c)
        ratio = p / q
        jc = np.hstack([(self.factor / q)[:, None] * self.N, -(self.factor * ratio / q)[:, None] * self.D])
        if self.clamp is not None:
            f = self.offset + self.factor * ratio
            jc[(f < self.clamp[0]) | (f > self.clamp[1])] = 0.0
        return jc @ self.M

    def q_min(self, c) -> float:
        return float(np.min(self.pq(c)[1]))


class Problem:
    def __init__(self, name: str):
        self.name = name
        self.samples = sf_cli.samples(name)
        self.gen = sf_cli.generated(name)
        m = self.gen["model"]
        self.x = np.array(self.samples["x"], dtype=float)
        self.y = np.array(self.samples["y"], dtype=float)
        self.form = Form(m, self.samples, self.x)
        self.kind = self.samples["objective"]
        assert self.kind in ("lsq", "minimax", "l4"), self.kind
        assert m["objective"] == self.kind
        # Dense grid of the domain for the pole check (Q through the generated form).
        axes = self.gen["axes"]
        # Points per axis: ~2e4 in 1-D, ~1.6e5 in 2-D, ~2e6 in 3-D (a 3-D grid at 401 per axis
        # is 6.4e7 points, re-evaluated by every method's positivity check). The check needs
        # only points of the domain: a coarser grid can miss a pole, never invent one.
        n = {1: 20001, 2: 401}.get(len(axes), 129)
        grids = np.meshgrid(*[np.linspace(*a["range"], n) for a in axes], indexing="ij")
        self.dense = np.stack([g.ravel() for g in grids], axis=1)
        self.starts = {"linearised": self.loeb_start()}
        if name in PUBLISHED:
            pub = PUBLISHED[name]
            self.starts["published"] = np.array([pub[self.form.labels[j]] for j in self.form.free])
        self.starts["committed"] = self.theta_of(m["coefficients"])

    def theta_of(self, c):
        return np.asarray(c, dtype=float)[self.form.free]

    def loeb_start(self):
        """Least squares of the linearised residual P - g Q = 0, g = (y - offset)/factor, over
        theta (rows with a vanishing factor left out): independent of shadefit's starts."""
        fm = self.form
        ok = np.abs(fm.factor) > 1e-12
        g = (self.y[ok] - fm.offset) / fm.factor[ok]
        A = np.hstack([fm.N[ok], -g[:, None] * fm.D[ok]])
        rhs = g * fm.lead[ok] - A @ fm.b
        theta, *_ = np.linalg.lstsq(A @ fm.M, rhs, rcond=None)
        return theta

    def res(self, theta):
        return self.form.value(self.form.full(theta)) - self.y

    def jac(self, theta):
        return self.form.jacobian(theta)

    def objective_c(self, c) -> float:
        r = self.form.value(c) - self.y
        if self.kind == "lsq":
            return float(r @ r)
        if self.kind == "minimax":
            return float(np.max(np.abs(r)))
        return float(np.sum(r ** 4))

    def objective(self, theta) -> float:
        return self.objective_c(self.form.full(theta))

    def valid(self, theta) -> bool:
        c = self.form.full(theta)
        return bool(np.all(np.isfinite(c))) and float(np.min(model_pq(self.gen["model"], c, self.dense)[1])) > 0.0


# ---------------------------------------------------------------------------------------------
# Methods: each runs from a start theta0 and returns (theta, status)


def _least_squares(method):
    def run(p: Problem, theta0):
        r = least_squares(p.res, theta0, jac=p.jac, method=method, xtol=1e-15, ftol=1e-15,
                          gtol=1e-15, max_nfev=20000)
        return r.x, f"status {r.status}, nfev {r.nfev}"
    return run


class _Best:
    """Best point an nlopt run evaluated (by the spec objective, poles on the samples excluded):
    kept so that a run ending in RoundoffLimited still reports the point it reached."""

    def __init__(self, p: Problem):
        self.p, self.value, self.theta = p, np.inf, None

    def see(self, theta):
        c = self.p.form.full(theta)
        if self.p.form.q_min(c) <= 0:
            return
        v = self.p.objective_c(c)
        if v < self.value:
            self.value, self.theta = v, np.array(theta, dtype=float)


# nlopt >= 2.10 raises its own exception classes (nlopt.exception); older ones raise RuntimeError.
NLOPT_ERRORS = (getattr(nlopt, "exception", RuntimeError), RuntimeError, ValueError)


def _finish(opt, start, best):
    try:
        opt.optimize(start)
        status = f"nlopt result {opt.last_optimize_result()}"
    except nlopt.RoundoffLimited:
        status = "nlopt RoundoffLimited (best point kept)"
    except NLOPT_ERRORS as e:  # nlopt's generic failure: keep the best point seen
        status = f"nlopt failed: {type(e).__name__} {e} (best point kept)"
    return status + f", {opt.get_numevals()} evaluations"


def _nlopt_direct(alg):
    """Minimise the spec objective itself (rss or sum r^4 with analytic gradient, or max|r|)."""
    def run(p: Problem, theta0):
        best = _Best(p)
        opt = nlopt.opt(alg, len(theta0))

        def f(theta, grad):
            best.see(theta)
            r = p.res(theta)
            if p.kind == "lsq":
                if grad.size:
                    grad[:] = 2.0 * p.jac(theta).T @ r
                return float(r @ r)
            if p.kind == "l4":
                if grad.size:
                    grad[:] = 4.0 * p.jac(theta).T @ (r ** 3)
                return float(np.sum(r ** 4))
            assert grad.size == 0, "max|r| is only given to derivative-free algorithms"
            return float(np.max(np.abs(r)))

        opt.set_min_objective(f)
        opt.set_ftol_rel(1e-15)
        opt.set_xtol_rel(1e-15)
        opt.set_maxeval(200000)
        opt.set_maxtime(NLOPT_MAXTIME)
        status = _finish(opt, np.array(theta0, dtype=float), best)
        return best.theta, status
    return run


def _nlopt_epigraph(alg):
    """Minimax as min t s.t. -t <= r_i(theta) <= t (residuals scaled by the start's max|r| so
    that t starts at 1)."""
    def run(p: Problem, theta0):
        best = _Best(p)
        n = len(theta0)
        scale = 1.0 / np.max(np.abs(p.res(theta0)))
        opt = nlopt.opt(alg, n + 1)

        def f(z, grad):
            if grad.size:
                grad[:] = 0.0
                grad[-1] = 1.0
            return float(z[-1])

        def cons(result, z, grad):
            theta, t = z[:-1], z[-1]
            best.see(theta)
            r = p.res(theta) * scale
            m = r.size
            result[:m] = r - t
            result[m:] = -r - t
            if grad.size:
                j = p.jac(theta) * scale
                grad[:m, :-1] = j
                grad[m:, :-1] = -j
                grad[:, -1] = -1.0

        opt.set_min_objective(f)
        opt.add_inequality_mconstraint(cons, np.zeros(2 * p.y.size))
        opt.set_ftol_rel(1e-14)
        opt.set_xtol_rel(1e-14)
        opt.set_maxeval(20000)
        opt.set_maxtime(NLOPT_MAXTIME)
        status = _finish(opt, np.append(theta0, 1.0), best)
        return best.theta, status
    return run


# (label, method, starts it runs from: "independent" = the published and linearised starts).
# From the independent starts the gradient methods (fast, and they find the optimum where the
# start is in its basin: gloss, fuzz); from the committed coefficients every method, as a polish.
METHODS = {
    "lsq": [
        ("scipy least_squares lm", _least_squares("lm"), "all"),
        ("scipy least_squares trf", _least_squares("trf"), "all"),
        ("nlopt LN_BOBYQA (rss)", _nlopt_direct(nlopt.LN_BOBYQA), "all"),
        ("nlopt LD_LBFGS (rss)", _nlopt_direct(nlopt.LD_LBFGS), "all"),
        ("nlopt LD_SLSQP (rss)", _nlopt_direct(nlopt.LD_SLSQP), "all"),
    ],
    "minimax": [
        # least_squares minimises rss, not max|r|: listed for comparison, scored by max|r|.
        ("scipy least_squares lm (rss)", _least_squares("lm"), "all"),
        ("nlopt LN_SBPLX (max|r|)", _nlopt_direct(nlopt.LN_SBPLX), "all"),
        ("nlopt LD_SLSQP (epigraph minimax)", _nlopt_epigraph(nlopt.LD_SLSQP), "all"),
        ("nlopt LN_COBYLA (epigraph minimax)", _nlopt_epigraph(nlopt.LN_COBYLA), "small"),
    ],
    "l4": [
        ("nlopt LN_BOBYQA (sum r^4)", _nlopt_direct(nlopt.LN_BOBYQA), "committed"),
        ("nlopt LD_LBFGS (sum r^4)", _nlopt_direct(nlopt.LD_LBFGS), "all"),
        ("nlopt LD_SLSQP (sum r^4)", _nlopt_direct(nlopt.LD_SLSQP), "all"),
    ],
}


def _runs(where: str, start: str, samples: int) -> bool:
    if where == "small":
        return samples <= COBYLA_MAX_SAMPLES
    return where == "all" or where == start


_cache: dict = {}


@pytest.fixture(scope="module", params=SPECS)
def comparison(request, fit_report, fresh):
    name = request.param
    if name not in _cache:
        p = Problem(name)
        c_sf = np.array(p.gen["model"]["coefficients"], dtype=float)
        c_fresh = np.array(fresh[name]["model"]["coefficients"], dtype=float)
        entry = {
            "objective": p.kind,
            "samples": int(p.y.size),
            "starts": {k: {"theta": t.tolist(), "objective": p.objective(t)} for k, t in p.starts.items()},
            "shadefit": {"objective": p.objective_c(c_sf), "coefficients": c_sf.tolist(),
                         "source": f"generated/json/{name}.json"},
            "shadefit_fresh": {"objective": p.objective_c(c_fresh), "coefficients": c_fresh.tolist(),
                               "source": "shadefit build --only, from scratch"},
            "methods": {},
        }
        for start, theta0 in p.starts.items():
            for label, method, where in METHODS[p.kind]:
                if not _runs(where, start, p.y.size):
                    continue
                t0 = time.perf_counter()
                theta, status = method(p, theta0)
                wall = time.perf_counter() - t0
                row = {"wall_s": wall, "status": status, "start": start}
                if theta is not None:
                    r = p.res(theta)
                    row.update(objective=p.objective(theta), rss=float(r @ r), max_abs=float(np.max(np.abs(r))),
                               valid=p.valid(theta), coefficients=p.form.full(theta).tolist())
                else:
                    row.update(objective=None, valid=False)
                entry["methods"][f"{label} from {start}"] = row
        valid = {k: v for k, v in entry["methods"].items() if v["valid"]}
        best = min(valid, key=lambda k: valid[k]["objective"]) if valid else None
        entry["best_method"] = best
        if best:
            b = valid[best]["objective"]
            entry["shadefit_minus_best_relative"] = (entry["shadefit"]["objective"] - b) / b
            entry["fresh_minus_best_relative"] = (entry["shadefit_fresh"]["objective"] - b) / b
        fit_report[name] = entry
        _cache[name] = (p, entry)
    return _cache[name]


def test_committed_form_matches_spec(comparison):
    p, _ = comparison
    m = p.gen["model"]
    sm = p.samples["model"]
    assert m["numerator"] == sm["numerator"] and m["denominator"] == sm["denominator"]
    assert (m["clamp"] is None and sm["clamp"] is None) or m["clamp"] == sm["clamp"]
    assert len(m["coefficients"]) == p.form.nn + p.form.nd
    assert m["objective"] == p.kind
    # Fixed coefficients hold their values in the committed vector.
    c = np.array(m["coefficients"], dtype=float)
    fixed_rows = [j for j in range(c.size) if j not in p.form.free and not np.any(p.form.M[j])]
    assert np.array_equal(c[fixed_rows], p.form.b[fixed_rows])


def test_committed_coefficients_satisfy_pins(comparison):
    p, _ = comparison
    c = np.array(p.gen["model"]["coefficients"])
    for pin in p.samples["model"].get("pins", []):
        num, den = model_pq(p.gen["model"], c, np.array([pin["at"]], dtype=float))
        # f(at) = P/Q to rounding: a few ulps of the terms summed.
        assert abs(num[0] / den[0] - pin["value"]) <= 1e-14, (pin, num, den)


def test_samples_are_the_integral(comparison):
    """The fitting samples lie on the spec's grid, first axis fastest, ends included; for the
    gloss quantities they are the integral there (a few points, sf_reference)."""
    p, _ = comparison
    axes = p.gen["axes"]
    assert p.y.size == int(np.prod([a["count"] for a in axes]))
    for k, a in enumerate(axes):
        stride = int(np.prod([b["count"] for b in axes[:k]]))
        pts = p.x[::stride, k][: a["count"]]
        assert np.allclose(pts, np.linspace(*a["range"], a["count"]), rtol=0, atol=1e-15)
    if p.samples["quantity"] not in ("gloss-length", "gloss-combine"):
        return  # the other quantities' samples are judged in test_generated.py / test_fuzz.py
    idx = np.random.default_rng(7).choice(p.y.size, 8, replace=False)
    inverse = ref.VecInverse()
    for i in idx:
        if p.samples["quantity"] == "gloss-length":
            want = ref.length_vec(p.x[i, 0])[0]
        else:
            want = inverse(ref.length_vec(p.x[i, 0]) * ref.length_vec(p.x[i, 1]))[0]
        # 2.5e-10: shadefit's integrator (eval's error estimates are <= 2e-10 for these
        # quantities, the inverse's included) plus the reference (agrees with quad to ~1e-15,
        # see test_integrals.py).
        assert abs(p.y[i] - want) <= 2.5e-10, (p.x[i], p.y[i], want)


def test_methods_reached_an_optimum(comparison):
    """Guard against a vacuous comparison: the best must be matched by a second, different method
    or start (so it is an optimum, not luck), and improve on the independent starts."""
    p, entry = comparison
    rows = {k: v for k, v in entry["methods"].items() if v["valid"]}
    assert entry["best_method"] is not None
    best = rows[entry["best_method"]]["objective"]
    for k in ("linearised", "published"):
        if k in entry["starts"]:
            assert best < entry["starts"][k]["objective"], k
    close = [k for k, v in rows.items() if v["objective"] <= best * (1 + 1e-6)]
    assert len(close) >= 2, {k: v["objective"] for k, v in rows.items()}


def _not_beaten(p, entry, which):
    sf = entry[which]["objective"]
    rows = {k: v["objective"] for k, v in entry["methods"].items() if v["valid"]}
    best_label = entry["best_method"]
    best = rows[best_label]
    assert sf <= best * (1 + REL[p.kind]), (
        f"{p.name} ({p.kind}): {entry[which]['source']} gives {sf!r}, "
        f"{best_label} reaches {best!r} (shadefit worse by {(sf - best) / best:.3e} relative); "
        f"all: {rows}"
    )


def test_shadefit_is_not_beaten(comparison):
    p, entry = comparison
    _not_beaten(p, entry, "shadefit")


def test_a_fresh_fit_is_not_beaten(comparison):
    """The solver as it is now, from scratch: what a rebuild would commit."""
    p, entry = comparison
    _not_beaten(p, entry, "shadefit_fresh")
