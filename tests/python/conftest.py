"""Python cross-validation suite for shadefit (run by scripts/test: `pytest tests/python -q`).

Checks the release binary (target/release/shadefit, or $SHADEFIT_BIN) and the committed
generated/json files against independent scipy/nlopt computations:

* test_integrals.py  -- `shadefit eval` against quad/brentq of the defining integrals;
* test_fits.py       -- every fit spec, fresh (`build --only` in a scratch folder) and committed, against scipy least_squares and nlopt on the same
                        samples and model form (objective and wall time of every method go to
                        out/fit_comparison.json);
* test_nist.py       -- `shadefit fit` on NIST StRD MGH09 and Kirby2 (certified RSS), beside scipy;
* test_generated.py  -- the generated JSON files (fits and tables) re-evaluated in numpy on their
                        verification grids: their error claims confirmed; the f32 coefficients'
                        `f32_rounding` claims on the fitting grid (emitted f32 code replayed in
                        numpy float32, sf_f32.py); the two-stage fit (fuzz_ps.json) against
                        `shadefit eval` at a subset of its grid;
* test_skin.py       -- `shadefit eval` of the skin quantities against scipy, the skin LUT files;
* test_fuzz.py       -- `shadefit eval` of the fuzz quantities (P_s, G, Q, R) against scipy/numpy;
* test_sheen.py      -- `shadefit eval` of the Charlie sheen quantities (Λ, E under three
                        visibilities, E_avg) against nested scipy quad of their definitions;
* test_notebooks.py  -- every notebook in notebooks/ executed headless without a cell error.

Artefacts go to tests/python/out/ (gitignored; $SHADEFIT_PYTEST_OUT overrides).
"""

from __future__ import annotations

import json

import pytest

import sf_cli


@pytest.fixture(scope="session")
def fit_report():
    """A dict the fit and NIST tests fill; written to out/fit_comparison.json at the end (also when
    a test fails, so the numbers behind a failure are on disk)."""
    report: dict = {}
    yield report
    sf_cli.OUT_DIR.mkdir(parents=True, exist_ok=True)
    path = sf_cli.OUT_DIR / "fit_comparison.json"
    path.write_text(json.dumps(report, indent=2, sort_keys=True) + "\n")
