//! The horizon-clipped form factor of a spherical cap: ltc_2's fourth channel.
//!
//! A shader that sums the edge terms of an LTC polygon gets the polygon's *vector* form
//! factor F (before the projection on the normal); ltc_code's shaders then replace the
//! horizon clipping of the polygon by a sphere of the same vector form factor: a cap of
//! angular radius σ with sin²σ = |F|, centred at elevation cos ω = F_z/|F|, whose cosine
//! integral clipped to the horizon is read from ltc_2.w at (x, y) = (cos ω · ½ + ½, |F|)
//! (texel nodes at i/63), scaled by |F|:
//! ```text
//! w(cos ω, s) = FF(ω, σ) / s,   s = sin²σ,
//! FF(ω, σ) = (1/π) ∫_cap max(0, n·l) dl.
//! ```
//! The closed form is Snyder's (1996, "Area light sources for real-time graphics", Microsoft
//! Research MSR-TR-96-11; restated as `illuminanceSphereOrDisk` in Lagarde and de Rousiers,
//! "Moving Frostbite to PBR", 2014, eq. 18): for a cap wholly above (cos ω ≥ sin σ) or below
//! (cos ω ≤ −sin σ) the horizon FF = s·max(cos ω, 0); otherwise, with x = cot σ and
//! y = −x cot ω,
//! ```text
//! π FF = (cos ω · acos y − x sin ω √(1 − y²)) s + atan(sin ω √(1 − y²) / x).
//! ```
//! Its two ends are the rows ltc_2 spells out: s → 0 gives max(cos ω, 0) (a point light) and
//! s = 1 (σ = π/2, x = 0) gives (1 + cos ω)/2 (half the sky).

use std::f64::consts::{FRAC_PI_2, PI};

/// FF(ω, σ) at cos ω = `z` ∈ [−1, 1] and sin²σ = `s` ∈ [0, 1] (clamped).
pub fn form_factor(z: f64, s: f64) -> f64 {
    let (z, s) = (z.clamp(-1.0, 1.0), s.clamp(0.0, 1.0));
    if z * z >= s {
        return s * z.max(0.0);
    }
    let sin_w = (1.0 - z * z).sqrt();
    if s >= 1.0 {
        return (1.0 + z) / 2.0;
    }
    // z² < s < 1 here, so sin ω > 0 and σ < π/2 (x > 0).
    let x = (1.0 / s - 1.0).sqrt();
    let y = (-x * z / sin_w).clamp(-1.0, 1.0);
    let r = sin_w * (1.0 - y * y).sqrt();
    (((z * y.acos() - x * r) * s + (r / x).atan()) / PI).max(0.0)
}

/// ltc_2.w: FF/s, and its limit max(z, 0) at s = 0.
pub fn clipped_ratio(z: f64, s: f64) -> f64 {
    if s <= 0.0 { z.clamp(-1.0, 1.0).max(0.0) } else { form_factor(z, s) / s.min(1.0) }
}

/// ltc_2.w on an `n` × `n` grid at ltc_code's nodes: x = i/(n − 1) = cos ω · ½ + ½,
/// y = j/(n − 1) = sin²σ; texel i + j·n.
pub fn table(n: usize) -> Vec<f64> {
    let at = |k: usize| k as f64 / (n - 1) as f64;
    (0..n * n).map(|k| clipped_ratio(2.0 * at(k % n) - 1.0, at(k / n))).collect()
}

/// The cap's angular radius σ ∈ [0, π/2] of a sin²σ.
pub fn radius(s: f64) -> f64 {
    s.clamp(0.0, 1.0).sqrt().asin().min(FRAC_PI_2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{Tolerance, adaptive};

    /// FF by quadrature over the cap in its own frame: polar t ∈ [0, σ] around the cap's axis,
    /// azimuth φ; the integrand max(0, cos ω cos t + sin ω sin t cos φ) is split where it
    /// reaches 0 (a kink the G10/K21 rule would otherwise resolve slowly).
    fn by_quadrature(z: f64, s: f64) -> f64 {
        let (cw, sw) = (z, (1.0 - z * z).max(0.0).sqrt());
        let tol = Tolerance { abs: 1e-13, rel: 1e-12, max_panels: 4000 };
        let sigma = radius(s);
        adaptive(0.0, sigma, tol, |t| {
            let (a, b) = (cw * t.cos(), sw * t.sin());
            let f = |phi: f64| (a + b * phi.cos()).max(0.0);
            // a + b cos φ = 0 at φ* = acos(−a/b) when |a| < b; the integrand is smooth on each side.
            let inner = if b > 0.0 && a.abs() < b {
                let cut = (-a / b).acos();
                adaptive(0.0, cut, tol, f).value + adaptive(cut, PI, tol, f).value
            } else {
                adaptive(0.0, PI, tol, f).value
            };
            2.0 * inner * t.sin()
        })
        .value
            / PI
    }

    /// The closed form agrees with the quadrature over the cap to 1e-9 (the quadrature's
    /// tolerance is 1e-12 relative; the closed form's rounding is ~1e-15) on a grid that
    /// crosses both branches and the rows ltc_2 spells out.
    #[test]
    fn the_closed_form_matches_quadrature_over_the_cap() {
        for &s in &[1e-6, 0.01, 0.1, 0.3, 0.5, 0.8, 0.99, 0.999999] {
            for k in 0..=20 {
                let z = -1.0 + 2.0 * k as f64 / 20.0;
                let (c, q) = (form_factor(z, s), by_quadrature(z, s));
                assert!((c - q).abs() < 1e-9, "z {z} s {s}: closed {c} quadrature {q}");
            }
        }
    }

    /// The ends of ltc_2.w: max(z, 0) at s = 0 and (1 + z)/2 at s = 1, exactly; between them
    /// continuous in s (the branch switch at z² = s is seamless: 1e-12 across it).
    #[test]
    fn the_rows_at_the_ends_and_the_branch_switch() {
        for k in 0..=10 {
            let z = -1.0 + 0.2 * k as f64;
            assert_eq!(clipped_ratio(z, 0.0), z.max(0.0));
            assert!((clipped_ratio(z, 1.0) - (1.0 + z) / 2.0).abs() < 1e-15);
        }
        for &z in &[0.3f64, -0.3, 0.7] {
            let s = z * z;
            let (below, above) = (form_factor(z, s * (1.0 - 1e-13)), form_factor(z, s * (1.0 + 1e-13)));
            assert!((below - above).abs() < 1e-12, "z {z}: {below} {above}");
        }
    }
}
