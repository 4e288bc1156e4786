"""`shadefit eval skin-punctual` / `skin-sh` against an independent scipy implementation.

The reference is written from the definitions only (d'Eon & Luebke's six Gaussians, GPU Gems 3
ch. 14, variances in mm² and RGB weights; the seed's ring integral with the *linear* profile):

    D(θ, κ) = ∫_{−π}^{π} max(cos(θ + x), 0) P(2r sin(x/2)) dx / ∫_{−π}^{π} P(2r sin(x/2)) dx,  r = 1/κ
    P(s) = Σ w_i exp(−s²/(2 v_i)) / sqrt(2π v_i)

    k_l(κ) = ∫ K(γ) P_l(cos γ) sin γ dγ / ∫ K(γ) sin γ dγ,  K = radial profile of the chord 2r sin(γ/2)

Tolerance: shadefit's own error estimate plus quad's abserr (both below 1e-10 here) plus QUAD_SLACK
= 1e-12 for quad's estimate being an estimate (it was asked for 1e-13, and agrees with the
brute-force rules of the Rust tests to that); a wrong weight, variance or kernel changes values by
>1e-3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

import sf_cli

QUAD_SLACK = 1e-12  # quad's error estimate being an estimate (module docstring)
VARIANCES = [0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41]
WEIGHTS = [  # (R, G, B) per Gaussian
    (0.233, 0.455, 0.649),
    (0.100, 0.336, 0.344),
    (0.118, 0.198, 0.0),
    (0.113, 0.007, 0.007),
    (0.358, 0.004, 0.0),
    (0.078, 0.0, 0.0),
]

rng = np.random.default_rng(7)
POINTS = [(0.5, 0.0), (1.0, -0.3), (0.05, 0.9), (3.0, 0.2)] + [
    (float(k), float(nl)) for k, nl in zip(rng.uniform(0.02, 2.0, 6), rng.uniform(-1.0, 1.0, 6))
]


def linear_profile(s: float, ch: int) -> float:
    return sum(w[ch] * math.exp(-s * s / (2 * v)) / math.sqrt(2 * math.pi * v) for v, w in zip(VARIANCES, WEIGHTS))


def radial_profile(s: float, ch: int) -> float:
    return sum(w[ch] * math.exp(-s * s / (2 * v)) / (2 * math.pi * v) for v, w in zip(VARIANCES, WEIGHTS))


def ring(kappa: float, n_dot_l: float, ch: int) -> tuple[float, float]:
    r = 1.0 / kappa
    theta = math.acos(n_dot_l)
    kernel = lambda x: linear_profile(2 * r * math.sin(x / 2), ch)
    # Kinks of max(cos(θ + x), 0) at θ + x = ±π/2.
    kinks = sorted(k for k in (-math.pi / 2 - theta, math.pi / 2 - theta) if -math.pi < k < math.pi)
    num, e1 = integrate.quad(lambda x: max(math.cos(theta + x), 0.0) * kernel(x), -math.pi, math.pi,
                             points=kinks + [0.0], limit=400, epsabs=1e-13, epsrel=1e-13)
    den, e2 = integrate.quad(kernel, -math.pi, math.pi, points=[0.0], limit=400, epsabs=1e-13, epsrel=1e-13)
    return num / den, (e1 + e2 * num / den) / den


@pytest.mark.parametrize("kappa,n_dot_l", POINTS)
def test_skin_punctual_matches_scipy(kappa, n_dot_l):
    got = sf_cli.eval_point("skin-punctual", curvature=kappa, n_dot_l=n_dot_l)
    for ch in range(3):
        ref, err = ring(kappa, n_dot_l, ch)
        tol = got["error_estimate"] + err + QUAD_SLACK
        assert abs(got["value"][ch] - ref) <= tol, (kappa, n_dot_l, ch, got["value"][ch], ref)


def test_skin_punctual_flat_limit_is_lambert():
    # κ = 0: no scattering across the surface, D = max(n·l, 0) exactly.
    for nl in (-0.5, 0.0, 0.3, 1.0):
        got = sf_cli.eval_point("skin-punctual", curvature=0.0, n_dot_l=nl)["value"]
        assert got == [max(nl, 0.0)] * 3


@pytest.mark.parametrize("kappa,band", [(0.5, 1), (1.0, 2), (2.0, 1)])
def test_skin_sh_matches_scipy(kappa, band):
    r = 1.0 / kappa
    got = sf_cli.eval_point("skin-sh", curvature=kappa, band=band)
    for ch in range(3):
        k = lambda g: radial_profile(2 * r * math.sin(g / 2), ch) * math.sin(g)
        num, e1 = integrate.quad(lambda g: k(g) * special.eval_legendre(band, math.cos(g)), 0, math.pi,
                                 limit=400, epsabs=1e-13, epsrel=1e-13)
        den, e2 = integrate.quad(k, 0, math.pi, limit=400, epsabs=1e-13, epsrel=1e-13)
        ref = num / den
        tol = got["error_estimate"] + (e1 + e2) / den + QUAD_SLACK
        assert abs(got["value"][ch] - ref) <= tol, (kappa, band, ch, got["value"][ch], ref)


# --- The committed skin LUTs (generated/json/skin_*_lut.json, generated/data/*.ktx2) -----------

LUT_POINTS = 12  # texels per LUT checked against scipy, chosen by a seeded generator


def lut(name: str):
    g = sf_cli.generated(name)
    w, h = g["texture"]["width"], g["texture"]["height"]
    values = np.array(g["values"], dtype=float)
    assert values.shape == (w * h, 3)
    return g, w, h, values


def test_punctual_lut_texels_match_scipy():
    g, w, h, values = lut("skin_punctual_lut")
    assert g["kernel"] == "linear" and g["profile"]["preset"] == "deon-luebke"
    kappas = g["axes"][1]["values"]
    pick = np.random.default_rng(11).integers(0, w * h, LUT_POINTS)
    for k in pick:
        i, j = int(k) % w, int(k) // w
        nl, kappa = -1.0 + 2.0 * i / (w - 1), kappas[j]
        for ch in range(3):
            if kappa == 0.0:
                assert values[k, ch] == max(nl, 0.0)
                continue
            ref, err = ring(kappa, nl, ch)
            # The LUT's tolerance per texel, quad's estimate, and QUAD_SLACK.
            assert abs(values[k, ch] - ref) <= g["tolerance"] + err + QUAD_SLACK, (i, j, ch, values[k, ch], ref)


def test_sh_lut_texels_match_scipy():
    g, w, h, values = lut("skin_sh_lut")
    assert h == 2
    kappas = g["axes"][0]["values"]
    for k in np.random.default_rng(12).integers(0, w * h, LUT_POINTS):
        i, band = int(k) % w, int(k) // w + 1
        kappa = kappas[i]
        for ch in range(3):
            if kappa == 0.0:
                assert values[k, ch] == 1.0
                continue
            r = 1.0 / kappa
            kern = lambda gam: radial_profile(2 * r * math.sin(gam / 2), ch) * math.sin(gam)
            num, e1 = integrate.quad(lambda gam: kern(gam) * special.eval_legendre(band, math.cos(gam)), 0, math.pi,
                                     limit=400, epsabs=1e-13, epsrel=1e-13)
            den, e2 = integrate.quad(kern, 0, math.pi, limit=400, epsabs=1e-13, epsrel=1e-13)
            assert abs(values[k, ch] - num / den) <= g["tolerance"] + (e1 + e2) / den + QUAD_SLACK, (i, band, ch)


@pytest.mark.parametrize("name", ["skin_punctual_lut", "skin_sh_lut"])
def test_ktx2_holds_the_texels(name):
    """Header fields read with struct (KTX 2.0 layout), texels against the JSON values rounded
    as the generator rounds them (f64 → f32 → f16, each round-to-nearest-even): bit for bit."""
    import struct

    g, w, h, values = lut(name)
    data = (sf_cli.ROOT / "generated" / "data" / f"{name}.ktx2").read_bytes()
    assert data[:12] == b"\xabKTX 20\xbb\r\n\x1a\n"
    vk, type_size, pw, ph, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", data, 12)
    fmt = g["texture"]["format"]
    assert (vk, type_size) == {"rgba16float": (97, 2), "rgba32float": (109, 4)}[fmt]
    assert (pw, ph, depth, layers, faces, levels, scheme) == (w, h, 0, 0, 1, 1, 0)
    offset, length, _ = struct.unpack_from("<3Q", data, 80)
    dtype = np.dtype("<f2") if fmt == "rgba16float" else np.dtype("<f4")
    texels = np.frombuffer(data[offset:offset + length], dtype=dtype).reshape(w * h, 4)
    want = values.astype(np.float32).astype(dtype)
    assert np.array_equal(texels[:, :3], want)
    assert np.all(texels[:, 3] == 1.0)


# --- The LUT files' verification claims, re-measured -------------------------------------------
#
# `verification` claims the error of bilinear interpolation of the texels (f64, and the emitted f32
# lookup) against the integral, on the grid with every midpoint added (2n − 1 points per axis of
# the mapped coordinate). Here the interpolation is this file's own and the integral is the scipy
# reference above. The SH LUT's grid (2 × 127 points) is re-measured whole; the punctual LUT's
# (129 × 127 points) at the claimed worst point and a seeded subset (a point costs 6 quads here).
#
# Tolerance: the build's truth (the LUT's `tolerance` per point), quad's estimate and QUAD_SLACK; for the f32 claims 1e-5 more: the emitted lookup computes its
# texel coordinates in f32 (a few ulps of coordinates below 64: 3e-5 of a texel, times texel steps
# below 0.05) and interpolates in f32 (three roundings of values <= 1), while this file
# interpolates the f32 texels in f64.

F32_LOOKUP_TOL = 1e-5
CLAIM_POINTS = 8


def unit_coordinate(kappa, axis):
    """The mapped coordinate t in [0, 1] of curvature kappa on a LUT axis (`mapping`)."""
    t = kappa / axis["range"][1]
    return {"linear": t, "sqrt": math.sqrt(t)}[axis["mapping"]]


def lerp_row(row, x):
    i = min(int(math.floor(x)), len(row) - 2)
    f = x - i
    return row[i] * (1.0 - f) + row[i + 1] * f


def punctual_lookup(values, w, h, g, kappa, nl):
    """Bilinear interpolation of the texels (rows: curvature, columns: n·l) at (κ, n·l)."""
    x = (nl + 1.0) / 2.0 * (w - 1)
    y = unit_coordinate(kappa, g["axes"][1]) * (h - 1)
    j = min(int(math.floor(y)), h - 2)
    a = lerp_row(values[j * w:(j + 1) * w], x)
    b = lerp_row(values[(j + 1) * w:(j + 2) * w], x)
    return a * (1.0 - (y - j)) + b * (y - j)


def sh_reference(kappa, band, ch):
    if kappa == 0.0:
        return 1.0, 0.0
    r = 1.0 / kappa
    kern = lambda gam: radial_profile(2 * r * math.sin(gam / 2), ch) * math.sin(gam)
    num, e1 = integrate.quad(lambda gam: kern(gam) * special.eval_legendre(band, math.cos(gam)), 0, math.pi,
                             limit=400, epsabs=1e-13, epsrel=1e-13)
    den, e2 = integrate.quad(kern, 0, math.pi, limit=400, epsabs=1e-13, epsrel=1e-13)
    return num / den, (e1 + e2) / den


def test_punctual_lut_verification_claims():
    g, w, h, values = lut("skin_punctual_lut")
    ver = g["verification"]
    assert ver["points"] == (2 * w - 1) * (2 * h - 1)
    kappa_max = g["axes"][1]["range"][1]
    fine_t = np.arange(2 * h - 1) / (2 * h - 2)
    fine_kappa = kappa_max * {"linear": fine_t, "sqrt": fine_t**2}[g["axes"][1]["mapping"]]
    fine_kappa[-1] = kappa_max
    fine_nl = -1.0 + 2.0 * np.arange(2 * w - 1) / (2 * w - 2)
    worst = tuple(ver["worst_point"])
    assert np.any(np.abs(fine_kappa - worst[0]) <= 1e-15) and np.any(np.abs(fine_nl - worst[1]) <= 1e-15), worst
    rng = np.random.default_rng(20260413)
    pts = [(float(fine_kappa[rng.integers(1, 2 * h - 1)]), float(fine_nl[rng.integers(0, 2 * w - 1)]))
           for _ in range(CLAIM_POINTS)] + [worst]
    values32 = values.astype(np.float32).astype(float)
    for k, (kappa, nl) in enumerate(pts):
        errs, errs32, tol = [], [], 0.0
        for ch in range(3):
            ref, err = ring(kappa, nl, ch)
            tol = max(tol, g["tolerance"] + err + QUAD_SLACK)
            errs.append(abs(punctual_lookup(values[:, ch], w, h, g, kappa, nl) - ref))
            errs32.append(abs(punctual_lookup(values32[:, ch], w, h, g, kappa, nl) - ref))
        e, e32 = max(errs), max(errs32)
        assert e <= ver["max_abs_error"] + tol, ((kappa, nl), e, ver["max_abs_error"])
        assert e32 <= ver["max_abs_error_f32"] + tol + F32_LOOKUP_TOL, ((kappa, nl), e32, ver["max_abs_error_f32"])
        if k == len(pts) - 1:
            # The claimed worst point: its error is the claimed maximum.
            assert abs(e - ver["max_abs_error"]) <= tol, (worst, e, ver["max_abs_error"])
            assert abs(e32 - ver["max_abs_error_f32"]) <= tol + F32_LOOKUP_TOL, (worst, e32, ver["max_abs_error_f32"])


def test_sh_lut_verification_claims():
    g, w, h, values = lut("skin_sh_lut")
    ver = g["verification"]
    assert ver["points"] == 2 * (2 * w - 1)
    kappa_max = g["axes"][0]["range"][1]
    fine_t = np.arange(2 * w - 1) / (2 * w - 2)
    fine_kappa = kappa_max * {"linear": fine_t, "sqrt": fine_t**2}[g["axes"][0]["mapping"]]
    fine_kappa[-1] = kappa_max
    values32 = values.astype(np.float32).astype(float)
    e, e32, where, tol = [], [], [], 0.0
    for band in (1, 2):
        rows = slice((band - 1) * w, band * w)
        for a, kappa in enumerate(fine_kappa):
            for ch in range(3):
                ref, err = sh_reference(float(kappa), band, ch)
                tol = max(tol, g["tolerance"] + err + QUAD_SLACK)
                e.append(abs(lerp_row(values[rows, ch], a / 2.0) - ref))
                e32.append(abs(lerp_row(values32[rows, ch], a / 2.0) - ref))
                where.append((float(kappa), float(band)))
    e, e32 = np.array(e), np.array(e32)
    assert abs(ver["max_abs_error"] - e.max()) <= tol, (ver["max_abs_error"], e.max())
    assert abs(ver["rms_error"] - math.sqrt(np.mean(e * e))) <= tol, (ver["rms_error"], math.sqrt(np.mean(e * e)))
    assert abs(ver["max_abs_error_f32"] - e32.max()) <= tol + F32_LOOKUP_TOL
    assert abs(ver["rms_error_f32"] - math.sqrt(np.mean(e32 * e32))) <= tol + F32_LOOKUP_TOL
    # The claimed worst point is where our error is largest (ties within the tolerance).
    at = [i for i, p in enumerate(where) if abs(p[0] - ver["worst_point"][0]) <= 1e-15 and p[1] == ver["worst_point"][1]]
    assert at and max(e[i] for i in at) >= e.max() - tol, ver["worst_point"]
