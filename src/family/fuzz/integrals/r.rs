//! R: the whole sphere of light directions (conventions in the module doc of `super`).
//!
//! R is a 4-D integral over pairs (u, v). Two reductions make it 2-D with an elementary
//! integrand.
//!
//! 1. **Extend u to the whole sphere.** With Z = ∫_{S²} μu P_s(u) dω_u, the lower half is, by
//!    u → −u and P_s(−u) = 1 − P_s(u), ∫_{μu<0} μu P_s = −∫_Ω μu (1 − P_s) = −π + πR, so
//!    ```text
//!    R = ½ + Z/(2π)
//!    ```
//!    and Z has no horizon on u: for fixed u·t = a the light azimuth η_u runs over the whole
//!    circle.
//! 2. **Integrate both azimuths in closed form.** In fiber coordinates, u = (a, η_u),
//!    v = (w, η), μu = a cos θf − s_a sin θf cos η_u, D_F depends on Δ = η − η_u only (even in
//!    Δ), and v is below the horizon on |η| < η₀(w) (η₀ = π for w ≤ −sin θf, 0 for w ≥ sin θf).
//!    Substituting η_u = η − Δ, the full η_u-circle is the full Δ-circle, cos η_u =
//!    cos η cos Δ + sin η sin Δ, and the sin Δ part vanishes:
//!    ```text
//!    ∫ dη_u μu D_F = a cos θf F₀ − s_a sin θf cos η F₁,   F_j(a, w) = ∫₀^{2π} cos(jΔ) D_F dΔ
//!    ∫_{|η|<η₀} dη (…) = 2η₀ a cos θf F₀ − 2 sin η₀ s_a sin θf F₁
//!    ```
//!    so with P_s = (1/σ_F(a)) ∫_{v·n<0} D_F/4 dω_v,
//!    ```text
//!    Z = ½ ∫₋₁¹ da/σ_F(a) ∫₋₁¹ dw [a cos θf η₀(w) F₀ − s_a sin θf sin η₀(w) F₁].
//!    ```
//!    Under (a, w) → (−a, −w), F_j, σ_F, s_a and sin η₀ are unchanged and η₀ → π − η₀, so with
//!    ψ = η₀ − π/2 (odd) the integrand is even and a ≥ 0 suffices:
//!    ```text
//!    Z = 1/(πα) ∫₀^{π/2} sin A/σ_F(cos A) J̃(A) dA,   a = cos A,
//!    J̃(A) = ∫₋₁¹ [a cos θf ψ(w) f₀ − s_a sin θf sin η₀(w) f₁] dw,   f_j = πα F_j.
//!    ```
//!
//! The full-circle moments are elementary (z = R + S cos Δ as for P_s, now with the whole
//! circle: ∫dΔ/z = 2π/D, ∫dΔ/z² = 2πR/D³, ∫cos Δ dΔ/z = −2πS/(D(D + R)), ∫cos Δ dΔ/z² =
//! −2πS/D³, D = sqrt(R² − S²)). Since ε² = m² − ρ², D = |ε| r with
//! r² = (1−α²)²ε² + 4α²(1−α²)m + 4α⁴ (no cancellation anywhere, no division by m + ρ), and
//! with g = K/D = (1−α²)|ε|/r:
//! ```text
//! f₀ = 2π (1 − 2g + g (1−α²) R/r²),   f₁ = 2π g S (2/(D + R) − (1−α²)/r²)
//! ```
//! On the arc range w = −sin θf cos φ: η₀ = atan2(sin φ, −cos θf cos φ), sin η₀ = sin φ/s_w,
//! s_w = sqrt(sin²φ + cos²θf cos²φ), all analytic in φ; the whole-circle ranges use w = −cos χ
//! (s_w = sin χ, analytic at w = ±1). J̃ is split at the cone w = −a (the cusp of f_j at ε = 0)
//! and mapped by x = c + L_x tan ξ about it (P_s's pieces take sinh instead; here the tan map
//! is what the agreement below was measured with); nothing depends on a single light azimuth
//! any more, so no grazing bands. All pieces of J̃ share one adaptive G10/K21
//! integration. The A-integral is split at π/2 − θf, where the cone crosses w = −sin θf: J̃
//! is not analytic there, and beyond it, for θf near π/2, varies on the scale cos θf where the
//! cone runs into the arc's ends. So beyond the split the outer variable is the cone's own
//! φ₀ (a = sin θf cos φ₀; A − (π/2 − θf) ∝ φ₀² takes the singularity out, and the cone moves
//! through the arc range evenly). Both pieces by adaptive G10/K21; the inner tolerances follow
//! the outer weights (loose where sin A dA/dx is small) at 1/100 of their share
//! ([`R_INNER_SHARE`]). About 8·10³ evaluations per R at 1e-7 and 10⁴ at 1e-9, where the
//! previous formulation (u over Ω only: A, η_u by G7/K15 panels, w, around P_s's closed-form
//! arc integrals; kept as the test reference `r_horizon`) needed 0.1–1.5·10⁶; the two agree
//! to 1e-15.

use super::atan::atan2_upper;
use super::{ERROR_FLOOR, Layer, MAX_PANELS, alpha_ok, clean_tol, invalid};
use crate::integrate::{Estimate, Options, integrate};
use std::f64::consts::{FRAC_PI_2, PI};

/// Part of R's inner budget its w-integrations get: their errors share one sign over the A
/// nodes (the same pieces, mapped alike), so they add up in the outer sum instead of
/// averaging out; at the full share the actual error of R at 1e-7 reached 5e-9 (θf near π/2,
/// small α), at 1/100 it stays below 5e-11 over the fuzz_r grid (as the previous formulation
/// did) for 25% more evaluations.
const R_INNER_SHARE: f64 = 0.01;

/// A light circle a = u·t = cos A of R's outer integral: A, a, s_a = sin A, sin and cos of A/2,
/// and φ₀ of the cone w = −a with sin, cos of φ₀/2 when the cone lies in the arc range.
#[derive(Debug, Clone, Copy)]
struct ZCone {
    angle: f64,
    a: f64,
    sa: f64,
    sh: f64,
    ch: f64,
    phi0: Option<(f64, f64, f64)>,
}

/// One piece of R's w-range, mapped from t ∈ [0, 1] by x = c + L tan ξ, ξ linear in t (the
/// peak about the cone, with its tails): x = χ with w = −cos χ on a whole-circle range, where
/// ψ = ±π/2 and sin η₀ = 0, or x = φ with w = −sin θf cos φ on the arc range (η₀ and the
/// square roots at w = ±sin θf are analytic in φ).
#[derive(Debug, Clone, Copy)]
struct ZPiece {
    arc: bool,
    /// ψ on a whole-circle piece: π/2 below the arc range (w < −sin θf), −π/2 above.
    psi: f64,
    center: f64,
    scale: f64,
    xa: f64,
    dx: f64,
}

impl ZPiece {
    /// Piece for x ∈ [lo, hi], not containing the map centre in its interior.
    fn new(arc: bool, psi: f64, lo: f64, hi: f64, center: f64, scale: f64) -> Self {
        let xa = ((lo - center) / scale).atan();
        let xb = ((hi - center) / scale).atan();
        ZPiece { arc, psi, center, scale, xa, dx: xb - xa }
    }

    /// (x, dx/dt) at t ∈ [0, 1].
    fn map(&self, t: f64) -> (f64, f64) {
        let tn = (self.xa + self.dx * t).tan();
        (self.center + self.scale * tn, self.scale * (1.0 + tn * tn) * self.dx)
    }
}

impl Layer {
    /// πα ∫ D_F dΔ and πα ∫ cos Δ D_F dΔ over the whole circle (f₀, f₁ of the module doc), at
    /// ε = a + w, m = 1 + a w, ρ = s_a s_w.
    fn circle_moments(&self, eps: f64, m: f64, rho: f64) -> (f64, f64) {
        let e = eps.abs();
        if e == 0.0 || self.k2 == 0.0 {
            return (2.0 * PI, 0.0);
        }
        let (k2, a2) = (self.k2, self.a2);
        let kk = k2 * e * e;
        // (R² − S²)/ε² = (1−α²)²ε² + 4α²(1−α²)m + 4α⁴ = root²; D = |ε| root.
        let root2 = k2 * kk + 4.0 * a2 * (k2 * m + a2);
        let root = root2.sqrt();
        let r = kk + 2.0 * a2 * m;
        let s = 2.0 * a2 * rho;
        // g = K/D
        let g = k2 * e / root;
        let f0 = 2.0 * PI * (1.0 - 2.0 * g + g * k2 * r / root2);
        let f1 = 2.0 * PI * g * s * (2.0 / (e * root + r) - k2 / root2);
        (f0, f1)
    }

    /// The pieces of R's w-range [−1, 1] for the light circle a = cos A (see [`ZPiece`]): the
    /// whole-circle ranges in χ, the arc range in φ, each split at the cone w = −a.
    fn z_pieces(&self, cone: &ZCone) -> Vec<ZPiece> {
        let (st, a_s) = (self.st, FRAC_PI_2 - self.theta());
        let scale = self.peak_scale(cone.sa);
        let mut out = Vec::with_capacity(5);
        if a_s > 0.0 {
            // χ about the cone χ₀ = A: w + 1 ≈ χ²/2 near χ = 0.
            let (c, sa) = (cone.angle, cone.sa);
            let lchi = (scale / (sa * sa + 2.0 * scale).sqrt()).clamp(1e-12, 4.0);
            if c > 0.0 && c < a_s {
                out.push(ZPiece::new(false, FRAC_PI_2, 0.0, c, c, lchi));
                out.push(ZPiece::new(false, FRAC_PI_2, c, a_s, c, lchi));
            } else {
                out.push(ZPiece::new(false, FRAC_PI_2, 0.0, a_s, c, lchi));
            }
            out.push(ZPiece::new(false, -FRAC_PI_2, PI - a_s, PI, c, lchi));
        }
        if st > 0.0 {
            // As in `pieces`: the peak width in φ, about the cone or the nearer arc end.
            let (center, lphi) = match cone.phi0 {
                Some((p0, _, _)) => (p0, scale / (st * (p0.sin().powi(2) + 2.0 * scale / st).sqrt())),
                None => (0.0, (2.0 * (scale + cone.a - st) / st).sqrt()),
            };
            let lphi = lphi.clamp(1e-12, 4.0);
            match cone.phi0 {
                Some((p0, _, _)) if p0 > 0.0 && p0 < PI => {
                    out.push(ZPiece::new(true, 0.0, 0.0, p0, center, lphi));
                    out.push(ZPiece::new(true, 0.0, p0, PI, center, lphi));
                }
                _ => out.push(ZPiece::new(true, 0.0, 0.0, PI, center, lphi)),
            }
        }
        out
    }

    /// The w-integrand of R at t ∈ [0, 1] of a piece, times dw/dt:
    /// a cos θf ψ(w) f₀ − s_a sin θf sin η₀(w) f₁.
    fn z_integrand(&self, cone: &ZCone, piece: &ZPiece, t: f64) -> f64 {
        let (x, dxdt) = piece.map(t);
        let (hs, hc) = (0.5 * x).sin_cos();
        let (sx, cx) = (2.0 * hs * hc, (hc - hs) * (hc + hs));
        let (a, sa) = (cone.a, cone.sa);
        if !piece.arc {
            // χ = x: w = −cos χ, s_w = sin χ, ε = cos A − cos χ = 2 sin((χ+A)/2) sin((χ−A)/2).
            let eps = 2.0 * (hs * cone.ch + hc * cone.sh) * (hs * cone.ch - hc * cone.sh);
            let (f0, _) = self.circle_moments(eps, 1.0 - a * cx, sa * sx);
            return piece.psi * a * self.ct * f0 * sx * dxdt;
        }
        // φ = x: w = −sin θf cos φ, s_w = sqrt(sin²φ + cos²θf cos²φ), dw = sin θf sin φ dφ.
        let st = self.st;
        let w = -st * cx;
        let sw = (sx * sx + self.ct * self.ct * cx * cx).sqrt();
        let eps = match cone.phi0 {
            // sin θf (cos φ₀ − cos φ), without cancellation near the cone.
            Some((_, sp0, cp0)) => 2.0 * st * (hs * cp0 + hc * sp0) * (hs * cp0 - hc * sp0),
            None => a + w,
        };
        let (f0, f1) = self.circle_moments(eps, 1.0 + a * w, sa * sw);
        // η₀ = atan2(sin φ, −cos θf cos φ) (both over s_w), ψ = η₀ − π/2, sin η₀ = sin φ/s_w.
        let psi = atan2_upper(sx, -self.ct * cx) - FRAC_PI_2;
        let sin_eta0 = if sw > 0.0 { sx / sw } else { 1.0 };
        (a * self.ct * psi * f0 - sa * st * sin_eta0 * f1) * st * sx * dxdt
    }

    /// R = ½ + (1/(2π²α)) ∫₀^{π/2} sin A/σ_F(cos A) J̃(A) dA (module doc): the outer integral
    /// in A up to the split π/2 − θf, in the cone's φ₀ beyond it, each by adaptive G10/K21; J̃
    /// by one adaptive G10/K21 integration over all its w-pieces.
    fn r(&self, tol: f64) -> Estimate {
        let split = FRAC_PI_2 - self.theta();
        let (st, ct) = (self.st, self.ct);
        // (range, in φ₀): A ∈ [0, split]; beyond, φ₀ ∈ [0, π/2] with a = sin θf cos φ₀,
        // s_a = sqrt(cos²θf + sin²θf sin²φ₀), dA = sin θf sin φ₀/s_a dφ₀.
        let mut pieces = Vec::with_capacity(2);
        if split > 0.0 {
            pieces.push((0.0, split, false));
        }
        if st > 0.0 {
            pieces.push((0.0, FRAC_PI_2, true));
        }
        let n = pieces.len() as f64;
        let (mut value, mut error, mut evals) = (0.5, 0.0, 0);
        let scale = 1.0 / (2.0 * PI * PI * self.alpha);
        for &(lo, hi, phi) in &pieces {
            // Component 1 carries the inner errors along (weight 0: integrated, not checked).
            let opts = Options::quadpack([1.0, 0.0], 0.1 * tol / n, 64);
            let est = integrate(&[(lo, hi)], &opts, |x| {
                let (cone, jac) = if phi {
                    let (sp, cp) = x.sin_cos();
                    let (a, sa) = (st * cp, (ct * ct + st * st * sp * sp).sqrt());
                    (self.z_cone(sa.atan2(a)), st * sp / sa)
                } else {
                    (self.z_cone(x), 1.0)
                };
                let wgt = scale * cone.sa / self.light_fiber(cone.a, cone.sa, 0.0).sigma * jac;
                if wgt == 0.0 {
                    return [0.0, 0.0];
                }
                // The propagated inner error ∫ wgt e_J stays below 0.9 tol/100 per piece.
                let tol_j = (R_INNER_SHARE * 0.9 * tol / n / wgt).min(1.0);
                let zp = self.z_pieces(&cone);
                let intervals: Vec<(f64, f64)> = (0..zp.len()).map(|k| (k as f64, (k + 1) as f64)).collect();
                let e = integrate(&intervals, &Options::quadpack([1.0], tol_j, MAX_PANELS), |x| {
                    let k = (x.floor() as usize).min(zp.len() - 1);
                    [self.z_integrand(&cone, &zp[k], x - k as f64)]
                });
                evals += e.evals;
                [wgt * e.value[0], wgt * e.error]
            });
            value += est.value[0];
            error += est.error + est.value[1];
        }
        Estimate { value, error: error.max(ERROR_FLOOR), evals }
    }

    /// The light circle a = cos A about the fiber, for R.
    fn z_cone(&self, angle: f64) -> ZCone {
        let (sa, a) = angle.sin_cos();
        let (sh, ch) = (0.5 * angle).sin_cos();
        let st = self.st;
        // The cone w = −a inside the arc range: φ₀ with sin θf cos φ₀ = a.
        let phi0 = if st > 0.0 && a < st {
            let p0 = (a / st).clamp(-1.0, 1.0).acos();
            let (s, c) = (0.5 * p0).sin_cos();
            Some((p0, s, c))
        } else {
            None
        };
        ZCone { angle, a, sa, sh, ch, phi0 }
    }
}


/// R(θf, α) = (1/π) ∫_Ω P_s(u) μu dω_u, to absolute tolerance `tol` (raised to 1e-13 if
/// smaller: R is a nested integral and tighter requests only burn time). About 10⁴
/// evaluations of the closed-form azimuth integrals (about a millisecond) at the default
/// tolerance.
pub fn r(alpha: f64, theta_f: f64, tol: f64) -> Estimate {
    if !alpha_ok(alpha) || !theta_f.is_finite() {
        return invalid();
    }
    Layer::new(alpha, theta_f).r(clean_tol(tol).max(1e-13))
}

#[cfg(test)]
mod tests {
    use super::super::tests::Lcg;
    use super::super::{DEFAULT_TOL, ps, sggx_phase};
    use super::*;
    use crate::integrate::{Tolerance, adaptive};

    #[test]
    fn r_special_values() {
        // α = 1: R = ½ up to rounding.
        for tf in [0.0, 0.4, FRAC_PI_2] {
            assert!((r(1.0, tf, DEFAULT_TOL).value - 0.5).abs() < 1e-12);
        }
        // θf = 0: P_s depends on μ only, so R = 2 ∫₀¹ μ P_s(μ) dμ (independent 1-D check;
        // nested error ≤ 1e-11 + 1e-11, R's ≤ 1e-9).
        for al in [0.05, 0.15, 0.6] {
            let direct =
                adaptive(0.0, 1.0, Tolerance { abs: 1e-11, rel: 0.0, max_panels: 2000 }, |mu| {
                    2.0 * mu * ps(al, 0.0, mu.acos(), 0.0, 1e-12).value
                });
            let e = r(al, 0.0, DEFAULT_TOL);
            assert!((e.value - direct.value).abs() < 1e-9, "α={al}: {e:?} vs {direct:?}");
        }
    }

    #[test]
    fn circle_moments_match_quadrature() {
        // f₀ = πα ∫ D_F dΔ and f₁ = πα ∫ cos Δ D_F dΔ over the whole circle against adaptive
        // quadrature of D_F from `sggx_phase` (p = D_F/(4σ_F)) over the v-circle about t, at
        // 1e-13: 1e-11 bounds quadrature and rounding of values up to 2π/α.
        let mut rng = Lcg(5);
        for i in 0..60 {
            let al = if i % 4 == 0 { 0.05 + 0.1 * rng.next() } else { 0.05 + 0.95 * rng.next() };
            let layer = Layer::new(al, 0.0);
            let (a, w) = (2.0 * rng.next() - 1.0, 2.0 * rng.next() - 1.0);
            // Every third point near the cone w = −a.
            let w = if i % 3 == 0 { (-a + 1e-3 * (rng.next() - 0.5)).clamp(-1.0, 1.0) } else { w };
            let (sa, sw) = ((1.0 - a * a).sqrt(), (1.0 - w * w).sqrt());
            let (f0, f1) = layer.circle_moments(a + w, 1.0 + a * w, sa * sw);
            let t = [0.0, 0.0, 1.0];
            let u = [sa, 0.0, a];
            let sigma = (1.0 - a * a * (1.0 - al * al)).sqrt();
            let tl = Tolerance { abs: 1e-13, rel: 0.0, max_panels: 2000 };
            let moment = |j: f64| {
                adaptive(-PI, PI, tl, |d| {
                    let v = [sw * d.cos(), sw * d.sin(), w];
                    4.0 * sigma * sggx_phase(al, t, u, v) * PI * al * (j * d).cos()
                })
                .value
            };
            let (q0, q1) = (moment(0.0), moment(1.0));
            assert!((f0 - q0).abs() < 1e-11, "α={al} a={a} w={w}: f0 {f0} vs {q0}");
            assert!((f1 - q1).abs() < 1e-11, "α={al} a={a} w={w}: f1 {f1} vs {q1}");
        }
    }

    #[test]
    fn r_matches_horizon_reference() {
        // The whole-sphere R against the previous formulation (`r_horizon`: u over the upper
        // hemisphere, η_u by G7/K15 panels, P_s's arc integrals) at 1e-11 each: the difference
        // must stay within the sum of the two error estimates (each ≤ 1e-11, floored at 1e-12).
        // `cargo test --release --lib r_matches_horizon -- --nocapture` prints them.
        for &(al, tf) in &[
            (0.05, 0.8),
            (0.15, 0.0),
            (0.15, 0.1),
            (0.15, FRAC_PI_2),
            (0.3, 1.17),
            (0.6, 0.24),
            (0.9, 1.3),
            (1.0, 0.7),
        ] {
            let layer = Layer::new(al, tf);
            let new = layer.r(1e-11);
            let old = layer.r_horizon(1e-11);
            println!(
                "α={al:<5} θf={tf:.4}: R {:.15}  |new − old| {:.1e}  estimates {:.1e} + {:.1e}  evals {} vs {}",
                new.value,
                (new.value - old.value).abs(),
                new.error,
                old.error,
                new.evals,
                old.evals
            );
            assert!(new.error <= 1e-11 && old.error <= 1e-11, "{new:?} {old:?}");
            assert!(
                (new.value - old.value).abs() <= new.error + old.error,
                "α={al} θf={tf}: {new:?} vs {old:?}"
            );
        }
    }

    #[test]
    fn r_matches_nested_quadrature() {
        // Independent nesting over (μ, φ) of P_s (adaptive from crate::integrate):
        // outer 1e-9, inner 1e-9·π, P_s 1e-11 → error ≲ 2e-9; R at 1e-10; 5e-9 bounds both.
        for &(al, tf) in &[(0.5, 0.3), (0.2, 1.1)] {
            let tl = Tolerance { abs: 1e-9, rel: 0.0, max_panels: 2000 };
            let nested = adaptive(0.0, 1.0, tl, |mu| {
                let inner = adaptive(0.0, PI, Tolerance { abs: 1e-9 * PI, ..tl }, |phi| {
                    ps(al, tf, mu.acos(), phi, 1e-11).value
                });
                2.0 / PI * mu * inner.value
            });
            let e = r(al, tf, 1e-10);
            assert!((e.value - nested.value).abs() < 5e-9, "α={al} θf={tf}: {e:?} vs {nested:?}");
        }
    }

    #[test]
    fn r_default_tolerance_is_honest() {
        for &(al, tf) in &[
            (0.05, 0.8),
            (0.15, 0.1),
            (0.15, FRAC_PI_2),
            (0.4, 0.6),
            (0.9, 1.3),
            (0.07, 1.57),
            (0.3, 1.17),
            (0.6, 0.24),
        ] {
            let d = r(al, tf, DEFAULT_TOL);
            let t = r(al, tf, 1e-12);
            assert!(d.error <= DEFAULT_TOL, "{d:?}");
            assert!(
                (d.value - t.value).abs() <= d.error + t.error,
                "α={al} θf={tf}: {d:?} vs {t:?}"
            );
            assert!(d.value > 0.0 && d.value < 1.0);
        }
    }

    /// R's error estimate bounds its actual error at a loose tolerance too: at 1e-5 against
    /// 1e-12 the difference stays within the two estimates (the 1e-12 floor alone would not
    /// cover it), and the estimate itself meets the asked tolerance.
    #[test]
    fn r_estimates_are_honest_at_a_loose_tolerance() {
        for &(al, tf) in &[(0.15, 0.1), (0.35, 0.8), (0.6, 1.5), (0.05, 1.2)] {
            let (d, t) = (r(al, tf, 1e-5), r(al, tf, 1e-12));
            assert!(d.error <= 1e-5 && (d.value - t.value).abs() <= d.error + t.error, "α={al} θf={tf}: {d:?} vs {t:?}");
        }
    }
}
