"""The notebooks in notebooks/ run headless, top to bottom, without an error in any cell.

Each notebook is executed with nbclient in a kernel of this interpreter (the venv scripts/test
makes): a kernel spec naming sys.executable is written to a temporary folder and only that
folder is searched, so no kernel installed elsewhere (~/.local/share/jupyter) is picked up. The
kernel inherits the environment ($SHADEFIT_BIN included) and runs in notebooks/, as Jupyter
would. Jupyter's and IPython's own state goes to the temporary folder too.

Committed notebooks carry no outputs (they are generated from generated/ and the binary on each
run); the executed copies go to out/notebooks/ with the time each took (out/notebooks.json).

NOTEBOOK_TIMEOUT bounds a whole notebook (each cell gets what is left of it): the slowest,
fuzz.ipynb, takes ~15 s on two cores (`shadefit samples fuzz_ps`, 627 264 integrals, and 54
`eval fuzz-r`), validate.ipynb ~10 s (`shadefit validate`); the limit leaves room for a busy
machine.
"""

from __future__ import annotations

import json
import sys
import time

import nbformat
import pytest
from jupyter_client.kernelspec import KernelSpecManager
from jupyter_client.manager import KernelManager
from nbclient import NotebookClient

import sf_cli

NB_DIR = sf_cli.ROOT / "notebooks"
NOTEBOOKS = sorted(NB_DIR.glob("*.ipynb"))
NOTEBOOK_TIMEOUT = 120.0
KERNEL = "shadefit-pytest"

TIMES: dict[str, float] = {}


@pytest.fixture(scope="module")
def kernel_dir(tmp_path_factory):
    base = tmp_path_factory.mktemp("jupyter")
    spec = base / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": f"Python ({sys.executable})",
        "language": "python",
    }))
    return base


@pytest.fixture(scope="module", autouse=True)
def write_times():
    yield
    out = sf_cli.OUT_DIR
    out.mkdir(parents=True, exist_ok=True)
    (out / "notebooks.json").write_text(json.dumps(
        {"seconds": TIMES, "total_seconds": sum(TIMES.values())}, indent=2, sort_keys=True) + "\n")


def test_there_are_notebooks():
    assert NOTEBOOKS, f"no notebooks in {NB_DIR}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_committed_without_outputs(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, \
                f"{path.name} cell {i} has outputs: strip them (python notebooks/strip_outputs.py)"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path, kernel_dir, monkeypatch):
    if not sf_cli.BIN.is_file():
        pytest.fail(f"{sf_cli.BIN} is missing: run `cargo build --release` first")
    for var, sub in (("JUPYTER_RUNTIME_DIR", "runtime"), ("JUPYTER_DATA_DIR", "data"),
                     ("JUPYTER_CONFIG_DIR", "config"), ("IPYTHONDIR", "ipython")):
        monkeypatch.setenv(var, str(kernel_dir / sub))
    monkeypatch.setenv("JUPYTER_PLATFORM_DIRS", "1")
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    monkeypatch.setenv("SHADEFIT_BIN", str(sf_cli.BIN))

    nb = nbformat.read(path, as_version=4)
    ksm = KernelSpecManager(kernel_dirs=[str(kernel_dir / "kernels")])
    km = KernelManager(kernel_name=KERNEL, kernel_spec_manager=ksm)
    start = time.monotonic()
    deadline = start + NOTEBOOK_TIMEOUT

    client = NotebookClient(
        nb, km=km, kernel_name=KERNEL, startup_timeout=60,
        # The notebook's time budget: each cell may use what the ones before it left.
        timeout_func=lambda cell: max(1, int(deadline - time.monotonic())),
        resources={"metadata": {"path": str(NB_DIR)}},
        allow_errors=False,
    )
    try:
        client.execute()
    finally:
        elapsed = time.monotonic() - start
        TIMES[path.name] = round(elapsed, 2)
        out = sf_cli.OUT_DIR / "notebooks"
        out.mkdir(parents=True, exist_ok=True)
        nbformat.write(nb, out / path.name)
    assert elapsed <= NOTEBOOK_TIMEOUT, f"{path.name} took {elapsed:.1f} s"
