//! Filament's DFG LUT, regenerated with its own estimator (google/filament
//! `libs/ibl/src/CubemapIBL.cpp`, `DFV_Multiscatter` as called by `CubemapIBL::DFG`; the
//! formulas, not the code, are reproduced here):
//! ```text
//! per texel (x, y) of a w × h image:   coord = saturate((h − y + 0.5)/h),  α = coord²
//!                                      NoV = saturate((x + 0.5)/w),  V = (sqrt(1 − NoV²), 0, NoV)
//! for i < N = 1024:  u = (i/N, radical_inverse₂(i))                     (Hammersley)
//!   φ = 2π u.x,  cos²θ = (1 − u.y)/(1 + (α + 1)((α − 1) u.y))             (GGX D·cosθ sampling)
//!   L = 2 (V·H) H − V;   if N·L > 0:
//!     v = Vis(NoV, NoL, α) · NoL · (VoH/NoH),   Fc = (1 − VoH)⁵
//!     r.x += v·Fc,   r.y += v
//! r ·= 4/N               (r.x = bias, r.y = scale + bias = E: Filament's "multiscatter" layout)
//! Vis = 0.5/(NoL sqrt(NoV²(1 − α²) + α²) + NoV sqrt(NoL²(1 − α²) + α²))  (exact height-correlated)
//! ```
//! stored RGB16F, rows flipped for GL (`cmgen` writes image row size − 1 − y at row y), and
//! sampled in the shader at (u, v) = (NoV, perceptual roughness) without a half-texel remap.
//!
//! # The roughness axis is one texel off (derived from the formulas above)
//! GL row j holds image row y = h − 1 − j, so coord = (h − (h − 1 − j) + 0.5)/h = (j + 1.5)/h,
//! saturated at 1 for j = h − 1. The shader reads row j at v = (j + 0.5)/h: the value stored
//! there is that of roughness v + 1/h (1/128 on desktop), and the top two rows both hold values
//! near r = 1 ((h − 0.5)/h and 1). The n·v axis is at true texel centres.

use super::super::integrals::Shadowing;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Filament's desktop LUT size and sample count.
pub const SIZE: usize = 128;
pub const SAMPLES: u32 = 1024;

/// Filament's `Visibility`: exact height-correlated Smith V = G2/(4 NoL NoV).
fn visibility(nov: f64, nol: f64, a: f64) -> f64 {
    let a2 = a * a;
    let ggxl = nov * ((nol - nol * a2) * nol + a2).sqrt();
    let ggxv = nol * ((nov - nov * a2) * nov + a2).sqrt();
    0.5 / (ggxv + ggxl)
}

/// `DFV_Multiscatter(NoV, α, n)` (in f64): [bias, E].
pub fn dfv_multiscatter(nov: f64, a: f64, n: u32) -> [f64; 2] {
    dfv_multiscatter_in_cone(nov, a, n, 0.0)
}

/// The same estimator counting only lights with NoL ≥ `cos_cone` (0: Filament's own).
pub fn dfv_multiscatter_in_cone(nov: f64, a: f64, n: u32, cos_cone: f64) -> [f64; 2] {
    let v = [(1.0 - nov * nov).sqrt(), 0.0, nov];
    let (mut bias, mut e) = (0.0, 0.0);
    for i in 0..n {
        let ux = i as f64 / n as f64;
        let uy = i.reverse_bits() as f64 * (0.5 / 2147483648.0);
        let phi = 2.0 * PI * ux;
        let cos2 = (1.0 - uy) / (1.0 + (a + 1.0) * ((a - 1.0) * uy));
        let (ct, st) = (cos2.sqrt(), (1.0 - cos2).sqrt());
        let h = [st * phi.cos(), st * phi.sin(), ct];
        let voh_raw = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        let l_z = 2.0 * voh_raw * h[2] - v[2];
        let nol = l_z.clamp(0.0, 1.0);
        let noh = h[2].clamp(0.0, 1.0);
        let voh = voh_raw.clamp(0.0, 1.0);
        if nol > 0.0 && nol >= cos_cone {
            let w = visibility(nov, nol, a) * nol * (voh / noh);
            let fc = (1.0 - voh).powi(5);
            bias += w * fc;
            e += w;
        }
    }
    let k = 4.0 / n as f64;
    [bias * k, e * k]
}

/// Perceptual roughness whose value GL row `j` of an `h`-row table holds: min((j + 1.5)/h, 1).
pub fn row_roughness(j: usize, h: usize) -> f64 {
    ((j as f64 + 1.5) / h as f64).min(1.0)
}

/// The regenerated table in GL order, texel (i, j) at `[j * SIZE + i]`: [bias, E] in f64 and
/// rounded to f16 as stored.
pub struct Table {
    pub f64s: Vec<[f64; 2]>,
    pub f16s: Vec<[f64; 2]>,
}

pub fn table() -> Table {
    let f64s: Vec<[f64; 2]> = (0..SIZE * SIZE)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % SIZE, k / SIZE);
            let r = row_roughness(j, SIZE);
            dfv_multiscatter((i as f64 + 0.5) / SIZE as f64, r * r, SAMPLES)
        })
        .collect();
    let f16s = f64s.iter().map(|v| v.map(|x| half::f16::from_f64(x).to_f64())).collect();
    Table { f64s, f16s }
}

/// [bias, E] of the integral (height-correlated) at (n·v, α).
pub fn exact(nov: f64, alpha: f64, tol: f64) -> [f64; 2] {
    let r = super::super::integrals::env(alpha, nov, 0.0, Shadowing::HeightCorrelated, tol);
    [r.bias, r.scale + r.bias]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The regenerated table, computed once for the tests that read it.
    fn shared_table() -> &'static Table {
        static T: std::sync::OnceLock<Table> = std::sync::OnceLock::new();
        T.get_or_init(table)
    }

    #[test]
    fn table_texel_estimates_the_integral_at_its_alpha() {
        // Texel (64, 62): n·v = 64.5/128, perceptual r = 63.5/128 (row_roughness), so α = r².
        // Against the height-correlated integral at that (n·v, α) to 1e-9. 5e-3: a 1024-point
        // Hammersley estimate of this smooth mid-range integrand (the mirror test above shows
        // the estimator's form is exact at α → 0); stored f64 before the f16 rounding.
        let t = shared_table();
        let (i, j) = (64, 62);
        let r = (j as f64 + 1.5) / SIZE as f64;
        let want = exact((i as f64 + 0.5) / SIZE as f64, r * r, 1e-9);
        let got = t.f64s[j * SIZE + i];
        assert!((got[0] - want[0]).abs() < 5e-3 && (got[1] - want[1]).abs() < 5e-3, "{got:?} vs {want:?}");
    }

    /// The table's layout as the module doc states it: texel (i, j) at `[j·128 + i]` is the
    /// estimator (1024 samples) at n·v = (i + ½)/128 and α = r², r = row_roughness(j), and
    /// its f16 value is that rounded to nearest. Exact: the same computation. Texels at the
    /// four corners and two inside (i ≠ j, so a swapped axis shows).
    #[test]
    fn table_texels_are_the_estimator_at_their_own_coordinates() {
        let t = shared_table();
        assert_eq!((t.f64s.len(), t.f16s.len()), (SIZE * SIZE, SIZE * SIZE));
        for (i, j) in [(0, 0), (127, 0), (0, 127), (127, 127), (37, 101), (90, 12)] {
            let r = row_roughness(j, SIZE);
            let want = dfv_multiscatter((i as f64 + 0.5) / SIZE as f64, r * r, SAMPLES);
            assert_eq!(t.f64s[j * SIZE + i], want, "texel ({i}, {j})");
            assert_eq!(t.f16s[j * SIZE + i], want.map(|x| half::f16::from_f64(x).to_f64()), "texel ({i}, {j})");
        }
    }

    /// The estimator with one and two Hammersley points, worked out from the module doc's
    /// formulas. Point 0, u = (0, 0): cos²θ = 1, so H = n, L is V's mirror, NoL = VoH = NoV,
    /// NoH = 1, and E = 4·Vis(NoV, NoV)·NoV², bias = E·(1 − NoV)⁵. Point 1 of two, u = (½, ½):
    /// φ = π, cos²θ = ½/(1 + (α + 1)(α − 1)/2) = 1/(1 + α²), H = (−sin θ, 0, cos θ); at
    /// NoV = 0.6, α = 0.3, VoH = 0.6 cos θ − 0.8 sin θ ≈ 0.345 and NoL = 2 VoH cos θ − 0.6
    /// ≈ 0.0606 > 0, so it counts, with weight Vis·NoL·VoH/NoH; the sum is scaled by 4/n. In a
    /// cone NoL ≥ 0.5 only point 0 counts. 1e-12: the same few operations in another order
    /// (and sin π ≈ 1.2e-16 in H's y, which V's zero y drops).
    #[test]
    fn one_and_two_point_estimates_are_their_samples_by_hand() {
        let vis = |nov: f64, nol: f64, a: f64| 0.5 / (nol * (nov * nov * (1.0 - a * a) + a * a).sqrt() + nov * (nol * nol * (1.0 - a * a) + a * a).sqrt());
        let (nov, a) = (0.6, 0.3);
        let fc = |voh: f64| (1.0 - voh).powi(5);
        let w0 = vis(nov, nov, a) * nov * nov;
        let (ct, st) = ((1.0 / (1.0 + a * a)).sqrt(), (a * a / (1.0 + a * a)).sqrt());
        let voh = nov * ct - 0.8 * st;
        let nol = 2.0 * voh * ct - nov;
        assert!(nol > 0.05 && nol < 0.5, "{nol}");
        let w1 = vis(nov, nol, a) * nol * voh / ct;
        let close = |got: [f64; 2], want: [f64; 2]| (got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12;
        for (n, cone, want) in [
            (1, 0.0, [4.0 * w0 * fc(nov), 4.0 * w0]),
            (2, 0.0, [2.0 * (w0 * fc(nov) + w1 * fc(voh)), 2.0 * (w0 + w1)]),
            (2, 0.5, [2.0 * w0 * fc(nov), 2.0 * w0]),
        ] {
            let got = dfv_multiscatter_in_cone(nov, a, n, cone);
            assert!(close(got, want), "{n} points, cone {cone}: {got:?} vs {want:?}");
        }
        assert_eq!(dfv_multiscatter(nov, a, 2), dfv_multiscatter_in_cone(nov, a, 2, 0.0));
    }

    #[test]
    fn hammersley_matches_the_radical_inverse() {
        // radical_inverse₂(1) = 0.5, (2) = 0.25, (3) = 0.75, (6) = 0.375: bit reversal, by hand.
        for (i, want) in [(1u32, 0.5), (2, 0.25), (3, 0.75), (6, 0.375)] {
            assert_eq!(i.reverse_bits() as f64 * (0.5 / 2147483648.0), want);
        }
    }

    #[test]
    fn estimator_is_exact_for_a_mirror() {
        // α → 0: every sample is H = n, L the mirror of V, Vis·NoL·VoH/NoH·4 = 1 (NoL = NoV):
        // E = 1 and bias = (1 − NoV)⁵ up to the O(α) spread at α = 1e-6.
        let r = dfv_multiscatter(0.5, 1e-6, 64);
        assert!((r[1] - 1.0).abs() < 1e-5 && (r[0] - 0.5f64.powi(5)).abs() < 1e-5, "{r:?}");
    }

    #[test]
    fn rows_are_one_texel_off() {
        // Row j holds roughness (j + 1.5)/h: the shader's v = (j + 0.5)/h plus one texel; the top
        // two rows hold (h − 0.5)/h and 1.
        assert_eq!(row_roughness(0, 128), 1.5 / 128.0);
        assert_eq!(row_roughness(126, 128), 127.5 / 128.0);
        assert_eq!(row_roughness(127, 128), 1.0);
    }
}
