"""`shadefit eval` against independent scipy computations of the defining integrals.

Seeded random points across each quantity's domain, edges included; every point is one `eval`
subprocess (~90 in all, a few ms each). References: sf_reference (quad of the hemisphere integral,
brentq for the inverse, both for the combine).

Tolerances are the sum of what bounds each side's error:
* shadefit's own `error_estimate` (its claim, so the test also checks the claim is honest);
* the reference's error: quad's absolute error estimate (abserr) for L; for a gloss obtained by
  inverting L, that error divided by the slope dL/dg (a length error e moves the root by e/L'),
  plus brentq's xtol;
* a few ulps for the final roundings (EPS4 = 4 * 2^-52 relative).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import sf_cli
import sf_reference as ref

EPS4 = 4 * np.finfo(float).eps
rng = np.random.default_rng(20240917)

GLOSS_POINTS = [0.0, 1.0, 0.5] + sorted(rng.uniform(0.0, 1.0, 17).tolist())
# log-uniform in (alpha(1), 1), plus alpha = 1 (gloss 0); alpha(1) itself is its own test below.
ALPHA_POINTS = [1.0] + sorted(np.exp(rng.uniform(math.log(ref.ALPHA_MIN), 0.0, 9)).tolist())
LENGTH_POINTS = (
    [0.0, ref.L0, ref.L1, 1.0, ref.L0 + 1e-9, ref.L1 - 1e-9]
    + rng.uniform(0.0, ref.L0, 3).tolist()          # below L(0): clamped to gloss 0
    + rng.uniform(ref.L0, ref.L1, 15).tolist()
    + rng.uniform(ref.L1, 1.0, 2).tolist()          # above L(1): clamped to gloss 1
)
COMBINE_POINTS = (
    [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]
    + [(1.0, float(v)) for v in rng.uniform(0, 1, 2)]
    + [(float(v), 1.0) for v in rng.uniform(0, 1, 2)]
    + [(0.0, float(v)) for v in rng.uniform(0, 1, 1)]
    + [tuple(p) for p in rng.uniform(0, 1, (21, 2)).tolist()]
)


def _ids(points):
    return [repr(p) for p in points]


@pytest.mark.parametrize("g", GLOSS_POINTS, ids=_ids(GLOSS_POINTS))
def test_gloss_length(g):
    out = sf_cli.eval_point("gloss-length", gloss=g)
    assert out["quantity"] == "gloss-length" and out["params"] == {"gloss": g}
    want, quad_err = ref.length_quad(g)
    tol = out["error_estimate"] + quad_err + EPS4
    assert abs(out["value"] - want) <= tol, (out, want, tol)


@pytest.mark.parametrize("a", ALPHA_POINTS, ids=_ids(ALPHA_POINTS))
def test_gloss_length_by_alpha(a):
    out = sf_cli.eval_point("gloss-length", alpha=a)
    want, quad_err = ref.length_quad_alpha(a)
    tol = out["error_estimate"] + quad_err + EPS4
    assert abs(out["value"] - want) <= tol, (out, want, tol)


def test_alpha_domain_includes_gloss_one():
    """alpha = alpha(gloss 1) = sqrt(2/262145) is the smallest alpha of the gloss range, so the
    alpha parameter's domain must include it (and give L(gloss = 1))."""
    a = ref.ALPHA_MIN
    p = sf_cli.run("eval", "gloss-length", f"alpha={a!r}", "--json", check=False)
    assert p.returncode == 0, f"alpha={a!r} (= alpha at gloss 1) rejected: {p.stderr.strip()}"
    want, quad_err = ref.length_quad_alpha(a)
    assert abs(json.loads(p.stdout)["value"] - want) <= 1e-13 + quad_err


def _gloss_tolerance(out, g_ref, length_err):
    """Tolerance on a gloss obtained by inverting L: see the module docstring."""
    slope = ref.dlength_dg(g_ref)
    return out["error_estimate"] + ref.BRENTQ_XTOL + EPS4 + length_err / slope


@pytest.mark.parametrize("length", LENGTH_POINTS, ids=_ids(LENGTH_POINTS))
def test_gloss_from_length(length):
    out = sf_cli.eval_point("gloss-from-length", length=length)
    g_ref = ref.gloss_from_length_brentq(length)
    if length < ref.L0 - EPS4 or length > ref.L1 + EPS4:
        # Clearly outside [L(0), L(1)]: the documented clamp, exactly.
        assert out["value"] == g_ref, (out, g_ref)
        return
    # Error of the reference L at the root: quad's abserr (same order over the whole range).
    length_err = ref.length_quad(g_ref)[1] + EPS4
    tol = _gloss_tolerance(out, g_ref, length_err)
    assert abs(out["value"] - g_ref) <= tol, (out, g_ref, tol)


@pytest.mark.parametrize("xy", COMBINE_POINTS, ids=_ids(COMBINE_POINTS))
def test_gloss_combine(xy):
    x, y = xy
    out = sf_cli.eval_point("gloss-combine", x=x, y=y)
    (lx, ex), (ly, ey) = ref.length_quad(x), ref.length_quad(y)
    product = lx * ly
    product_err = ex * ly + ey * lx + EPS4  # first-order error of the product, plus its rounding
    g_ref = ref.gloss_from_length_brentq(product)
    if product < ref.L0 - product_err:
        assert out["value"] == 0.0, (out, product)  # the documented clamp at gloss 0
        return
    tol = _gloss_tolerance(out, g_ref, product_err)
    assert abs(out["value"] - g_ref) <= tol, (out, g_ref, tol)


def test_combine_is_symmetric():
    for x, y in COMBINE_POINTS[-5:]:
        a = sf_cli.eval_point("gloss-combine", x=x, y=y)["value"]
        b = sf_cli.eval_point("gloss-combine", x=y, y=x)["value"]
        assert a == b, (x, y, a, b)


@pytest.mark.parametrize(
    "args",
    [
        ["gloss-length", "gloss=1.5"],
        ["gloss-length", "gloss=-0.1"],
        ["gloss-length", "gloss=nan"],
        ["gloss-length", "gloss=abc"],
        ["gloss-length"],
        ["gloss-length", "gloss=0.5", "alpha=0.5"],
        ["gloss-length", "alpha=1.5"],
        ["gloss-from-length", "length=1.01"],
        ["gloss-combine", "x=0.5"],
        ["gloss-combine", "x=0.5", "y=2"],
        ["no-such-quantity", "x=0.5"],
    ],
    ids=lambda a: " ".join(a),
)
def test_bad_input_exits_2(args):
    p = sf_cli.run("eval", *args, "--json", check=False)
    assert p.returncode == 2, (args, p.returncode, p.stdout, p.stderr)
    assert p.stdout == ""
