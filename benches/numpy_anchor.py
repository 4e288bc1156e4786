"""The timing anchor: a vectorised numpy DFG LUT as engines build it offline.

Filament's cmgen layout (Romain Guy et al., "Physically Based Rendering in Filament", section
on the DFG term): 128 x 128 texels at texel centres, n.v = (i + 0.5) / 128, alpha = coord^2
with coord = (j + 0.5) / 128, and 1024 GGX importance samples per texel from a Hammersley
set; each texel holds the split-sum scale and bias of the Smith height-correlated GGX lobe.
The anchor computes each texel in one vectorised numpy pass over its 1024 samples (the way an
offline LUT script is usually written, and the reference of the project's timing targets); the
same table vectorised over a whole row of n.v at once is timed too and printed beside it.

Machines differ in speed; timings elsewhere are quoted as a ratio to this one, run in the same
session (`scripts/perf`). Prints the best of `--repeat` wall times in seconds on one line as
JSON, with a checksum of the table so that an accidental change of the work is visible.
"""

import argparse
import json
import time

import numpy as np

N = 128
SAMPLES = 1024


def hammersley(n):
    i = np.arange(n, dtype=np.uint32)
    bits = i.copy()
    bits = ((bits << 16) | (bits >> 16)) & 0xFFFFFFFF
    bits = ((bits & 0x55555555) << 1) | ((bits & 0xAAAAAAAA) >> 1)
    bits = ((bits & 0x33333333) << 2) | ((bits & 0xCCCCCCCC) >> 2)
    bits = ((bits & 0x0F0F0F0F) << 4) | ((bits & 0xF0F0F0F0) >> 4)
    bits = ((bits & 0x00FF00FF) << 8) | ((bits & 0xFF00FF00) >> 8)
    return (i + 0.5) / n, bits.astype(np.float64) / 2.0**32


def texel_values(nv, a2, u, v):
    """Split-sum scale and bias at one texel (or at a column of n.v: `nv` of shape (k, 1))."""
    # GGX half vectors: cos(theta_h)^2 = (1 - v) / (1 + (a^2 - 1) v).
    cos_h = np.sqrt((1.0 - v) / (1.0 + (a2 - 1.0) * v))
    sin_h = np.sqrt(1.0 - cos_h * cos_h)
    phi = 2.0 * np.pi * u
    hx, hz = sin_h * np.cos(phi), cos_h
    # View in the x-z plane.
    vx = np.sqrt(1.0 - nv * nv)
    vz = nv
    vh = vx * hx + vz * hz
    nl = 2.0 * vh * hz - vz
    ok = (nl > 0.0) & (vh > 0.0)
    nl = np.clip(nl, 0.0, 1.0)
    # Height-correlated Smith visibility times 4 n.l v.h / (n.h) over the pdf.
    lv = nl * np.sqrt(vz * vz * (1.0 - a2) + a2)
    ll = vz * np.sqrt(nl * nl * (1.0 - a2) + a2)
    vis = 0.5 / np.maximum(lv + ll, 1e-30)
    g = np.where(ok, vis * 4.0 * nl * vh / hz, 0.0)
    fc = (1.0 - vh) ** 5
    return np.mean(g * (1.0 - fc), axis=-1), np.mean(g * fc, axis=-1)


def lut(by_row=False):
    """The table: one numpy pass over the 1024 samples per texel (the reference figure), or,
    with `by_row`, per row of alpha over all n.v at once."""
    u, v = hammersley(SAMPLES)
    nv = (np.arange(N) + 0.5) / N
    out = np.zeros((N, N, 2))
    for j in range(N):
        a2 = ((j + 0.5) / N) ** 4
        if by_row:
            out[:, j, 0], out[:, j, 1] = texel_values(nv[:, None], a2, u, v)
        else:
            for i in range(N):
                out[i, j, 0], out[i, j, 1] = texel_values(nv[i], a2, u, v)
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    timings = {}
    for by_row in (False, True):
        best = float("inf")
        for _ in range(args.repeat):
            t = time.perf_counter()
            table = lut(by_row)
            best = min(best, time.perf_counter() - t)
        timings["by_row" if by_row else "by_texel"] = (best, float(table.sum()))
    print(json.dumps({
        "anchor": "numpy DFG LUT 128x128 texels x 1024 GGX samples, one vectorised pass per texel",
        "seconds": timings["by_texel"][0],
        "checksum": timings["by_texel"][1],
        "seconds_vectorised_by_row": timings["by_row"][0],
        "checksum_by_row": timings["by_row"][1],
    }))


if __name__ == "__main__":
    main()
