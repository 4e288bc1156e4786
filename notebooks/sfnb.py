"""What the notebooks share: the repository and the shadefit binary, the files shadefit writes in
generated/, and the approximations they hold evaluated in numpy (f64).

The binary and the repository root are located as the Python suite does it (tests/python/sf_cli.py,
imported from there): $SHADEFIT_BIN, else ROOT/target/release/shadefit. Build it first with
`cargo build --release`. Model forms are those of tests/python/sf_rational.py (generated/json
`model`: offset + factor * P / Q, Q = denominator_lead + sum(den), derived features).
"""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))

import sf_cli  # noqa: E402  (after the path insert)
from sf_rational import model_inputs, model_value, term_values  # noqa: E402

BIN = sf_cli.BIN
GENERATED = ROOT / "generated"


def check_binary() -> str:
    """The binary's version line; a clear error if it is missing."""
    return sf_cli.run("--version").stdout.strip()


def run_json(*args: str):
    return sf_cli.run_json(*args)


def samples(name: str) -> dict:
    """`shadefit samples NAME --json`: the spec's fitting grid `x` (first axis fastest) and the
    integral `y` there, as arrays."""
    s = sf_cli.samples(name)
    s["x"] = np.array(s["x"], dtype=float)
    s["y"] = np.array(s["y"], dtype=float)
    return s


def eval_point(quantity: str, **params: float) -> dict:
    """`shadefit eval QUANTITY k=v ... --json` (one process per call)."""
    return sf_cli.eval_point(quantity, **params)


def generated(name: str) -> dict:
    return sf_cli.generated(name)


def generated_names(kind: str | None = None) -> list[str]:
    names = sorted(p.stem for p in (GENERATED / "json").glob("*.json"))
    return [n for n in names if kind is None or generated(n)["kind"] == kind]


def header(path: Path) -> list[str]:
    """The provenance header of a generated text file (its leading comment lines)."""
    out = []
    for line in Path(path).read_text().splitlines():
        if not line.startswith(("#", "//")):
            break
        out.append(line.lstrip("#/ ").rstrip())
    return out


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    """A generated CSV table: '#' header lines, a column line, numbers."""
    lines = [ln for ln in Path(path).read_text().splitlines() if ln and not ln.startswith("#")]
    cols = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    return cols, data


# ---------------------------------------------------------------------------------------------
# Approximations of generated/json, in f64.

def fit_value(g: dict, x) -> np.ndarray:
    """A kind "fit" file at input points x (rows, axis order)."""
    m = g["model"]
    return model_value(m, m["coefficients"], x)


def table_value(g: dict, x) -> np.ndarray:
    """A kind "table" file interpolated as the emitted lookup does it (linear, bilinear for two
    axes, inputs clamped to the domain), here in f64 on the f32-rounded values."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    axes = g["axes"]
    values = np.array(g["values"], dtype=np.float32).astype(float)
    idx, frac = [], []
    for d, a in enumerate(axes):
        n, (lo, hi) = a["count"], a["range"]
        t = (np.clip(x[:, d], lo, hi) - lo) * ((n - 1) / (hi - lo))
        i = np.minimum(t.astype(int), n - 2)
        idx.append(i)
        frac.append(t - i)
    if len(axes) == 1:
        i, f = idx[0], frac[0]
        return values[i] * (1 - f) + values[i + 1] * f
    nx = axes[0]["count"]
    k = idx[1] * nx + idx[0]
    f0, f1 = frac
    a = values[k] * (1 - f0) + values[k + 1] * f0
    b = values[k + nx] * (1 - f0) + values[k + nx + 1] * f0
    return a * (1 - f1) + b * f1


def fuzz_ps_args(theta_f, theta_u, phi_u):
    """(n·u, t·u) for the light (θu, φu) and the fiber angle θf: normal +z, fiber
    t = (sin θf, 0, cos θf), φu from the fiber azimuth (src/family/fuzz/integrals.rs)."""
    n_u = np.cos(theta_u)
    t_u = np.sin(theta_u) * np.cos(phi_u) * np.sin(theta_f) + np.cos(theta_u) * np.cos(theta_f)
    return n_u, t_u


def fields_coefficients(g: dict, outer) -> np.ndarray:
    """The coefficient fields c_k of a kind "fields" file at outer points (rows): shape (n, K)."""
    m = g["model"]
    return np.stack([model_value(m, f["coefficients"], outer, offset=f["offset"]) for f in g["fields"]], axis=1)


def fields_value(g: dict, outer, args) -> np.ndarray:
    """sum_k c_k(outer) b_k(args), clamped to the basis range; `args` (n, 2) are the basis
    arguments (fuzz_ps: n·u, t·u)."""
    c = fields_coefficients(g, outer)
    b = g["basis"]
    basis = np.stack([term_values(t, b["arguments"], args) for t in b["terms"]], axis=1)
    return np.clip(np.sum(c * basis, axis=1), *b["range"])


# ---------------------------------------------------------------------------------------------
# KTX2 (the skin LUT textures): KTX 2.0, one level, no supercompression.

KTX2_ID = b"\xabKTX 20\xbb\r\n\x1a\n"
VK_FORMATS = {97: np.float16, 109: np.float32}  # R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT


def read_ktx2(path: Path) -> tuple[np.ndarray, dict]:
    """Texels as an array (height, width, 4) and the key/value data (strings)."""
    data = Path(path).read_bytes()
    if data[:12] != KTX2_ID:
        raise ValueError(f"{path}: not a KTX 2.0 file")
    vk, type_size, w, h, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", data, 12)
    if vk not in VK_FORMATS or scheme != 0 or faces != 1 or max(levels, 1) != 1 or depth > 1 or layers > 1:
        raise ValueError(f"{path}: vkFormat {vk}, supercompression {scheme}, {faces} faces, {levels} levels: not read here")
    _dfd_off, _dfd_len, kvd_off, kvd_len = struct.unpack_from("<4I", data, 48)
    level_off, level_len, _ = struct.unpack_from("<3Q", data, 80)
    dtype = VK_FORMATS[vk]
    texels = np.frombuffer(data, dtype=np.dtype(dtype).newbyteorder("<"), count=level_len // type_size,
                           offset=level_off).reshape(h, w, 4)
    kv, p = {}, kvd_off
    while p < kvd_off + kvd_len:
        (n,) = struct.unpack_from("<I", data, p)
        key, _, value = data[p + 4:p + 4 + n].partition(b"\0")
        kv[key.decode()] = value.rstrip(b"\0").decode()
        p += 4 + n + (-n % 4)
    return texels, kv


def skin_lut(name: str) -> tuple[dict, np.ndarray]:
    """A skin LUT's JSON and its f64 texels as an array (height, width, 3)."""
    g = generated(name)
    w, h = g["texture"]["width"], g["texture"]["height"]
    return g, np.array(g["values"], dtype=float).reshape(h, w, 3)


# ---------------------------------------------------------------------------------------------
# Tables for display.

def html_table(rows: list[dict], columns: list[str], fmt: dict | None = None) -> str:
    """A small HTML table (rows of dicts); `fmt` maps a column to a format spec."""
    fmt = fmt or {}

    def cell(v, c):
        if v is None:
            return ""
        if c in fmt and isinstance(v, (int, float)):
            return format(v, fmt[c])
        return str(v)

    head = "".join(f"<th>{c}</th>" for c in columns)
    body = "".join("<tr>" + "".join(f"<td style='text-align:left'>{cell(r.get(c), c)}</td>" for c in columns) + "</tr>"
                   for r in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def dumps(v) -> str:
    return json.dumps(v, ensure_ascii=False)
