"""Running the shadefit binary and locating the repository's files."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("SHADEFIT_BIN", ROOT / "target" / "release" / "shadefit"))
# NIST StRD data, vendored with its headers (tests/data/nist/README.md).
NIST_DIR = Path(os.environ.get("SHADEFIT_NIST_DIR", ROOT / "tests" / "data" / "nist"))
OUT_DIR = Path(os.environ.get("SHADEFIT_PYTEST_OUT", ROOT / "tests" / "python" / "out"))


def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    if not BIN.is_file():
        raise FileNotFoundError(f"{BIN} is missing: run `cargo build --release` first")
    p = subprocess.run([str(BIN), *args], cwd=ROOT, capture_output=True, text=True, timeout=120)
    if check and p.returncode != 0:
        raise AssertionError(f"shadefit {' '.join(args)} exited {p.returncode}:\n{p.stderr}")
    return p


def run_json(*args: str):
    return json.loads(run(*args, "--json").stdout)


def eval_point(quantity: str, **params: float) -> dict:
    # repr() of a Python float round-trips exactly, so shadefit sees the same double.
    return run_json("eval", quantity, *(f"{k}={v!r}" for k, v in params.items()))


def samples(name: str) -> dict:
    return run_json("samples", name)


def generated(name: str) -> dict:
    return json.loads((ROOT / "generated" / "json" / f"{name}.json").read_text())
