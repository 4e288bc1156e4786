//! The normalisation of the Schlick fiber phase function of Ghost of Tsushima (Patry, SIGGRAPH
//! 2020 course "Samurai Shading", "Anisotropic Fuzz | Phase Function"):
//! ```text
//! p_V(k, h, t) = r · p_Schlick(k, sin∠(t, h)),   p_Schlick(k, x) = (1 − k²) / (4π (1 − k x)²)
//! h = (u + v)/|u + v|,   k = −0.99 (1 − spread)
//! ```
//! The course shipped "an approximate and conservative" r(k) (no formula is printed) because it
//! found no analytic form of the normalisation. Here it is computed: for light u,
//! ```text
//! N(k, u·t) = ∫_{S²} p_Schlick(k, sin∠(t, h)) dω_v,      r = 1/N,
//! N = (1 − k²) M,   M(k, u·t) = (1/4π) ∫_{S²} dω_v / (1 − k x)²,   x = sin∠(t, h) ∈ [0, 1].
//! ```
//! # Conventions (the contract)
//!
//! Unit vectors u (light), v (view), t (fiber). k ∈ [−0.99, 0], the image of spread ∈ [0, 1].
//! Positive k is integrable too (1 − kx ≥ 1 − k > 0 for k < 1) but puts the lobe's maximum on
//! the ring h ⟂ t (x = 1) instead of h ∥ t, with N growing like (1 − k)^{−1/2} as k → 1: a
//! different lobe than the one spread reaches, so it is outside the domain. At k = −1, N = 0.
//! Everything is f64; tolerances are absolute on M (M ∈ [0.3, 1]).
//!
//! # What N depends on
//!
//! N is invariant under any rotation applied to u, v, t together (dω_v is), so it depends on u
//! and t only through c = u·t. And x = sin∠(t, h) = sin∠(−t, h): t and −t give the same integrand,
//! so N(k, c) = N(k, −c). N depends on k and |u·t| only; `k` enters only through the factor
//! (1 − k x)^{−2} (M) and the prefactor (1 − k²).
//!
//! # Change of variables v → h
//!
//! v = 2(u·h) h − u maps the hemisphere u·h > 0 of half vectors one-to-one onto the sphere of
//! v (less v = −u, a null set), with dω_v = 4 (u·h) dω_h (the usual microfacet Jacobian
//! 1/(4 u·h) inverted). So
//! ```text
//! M = (1/π) ∫_{u·h>0} (u·h) / (1 − k x(h))² dω_h.
//! ```
//! Take t as the pole of h: h = (sin θ cos φ, sin θ sin φ, cos θ), x = sin θ, and u = (s, 0, c),
//! s = sqrt(1 − c²), c = |u·t| ≥ 0. With a = s sin θ ≥ 0, b = c cos θ, u·h = a cos φ + b and
//! the azimuth integral is closed:
//! ```text
//! A(θ) = ∫₀^{2π} (a cos φ + b)₊ dφ = 2π b                                   b ≥ a   (cap, θ small)
//!                                   = 0                                       b ≤ −a  (θ near π)
//!                                   = 2 (sqrt(a² − b²) + b arccos(−b/a))      |b| < a (belt)
//! M = (1/π) ∫₀^π A(θ) sin θ / (1 − k sin θ)² dθ,      a² − b² = sin²θ − c².
//! ```
//! The cap ends at sin θ = c, where A has a square-root kink (the rim u·h = 0 of the hemisphere
//! becomes tangent to the circle of latitude θ). Both pieces are written in variables where
//! they are analytic:
//!
//! - Cap (θ ∈ [0, arcsin c], x = sin θ, dx = cos θ dθ): M_cap = 2c ∫₀^c x/(1 − kx)² dx, in
//!   closed form with m = −k ≥ 0 and F(y) = ln(1 + y) − y/(1 + y) = Σ_{n≥2} (−1)ⁿ (n−1)/n yⁿ:
//!   M_cap = 2c F(mc)/m² (→ c³ at k = 0).
//! - Belt (w = cos θ ∈ [−s, s]): w = s sin ψ, ψ ∈ [−π/2, π/2], so sqrt(a² − b²) =
//!   sqrt(s² − w²) = s cos ψ, dw = s cos ψ dψ and sin θ = sqrt(1 − s² sin²ψ) =
//!   hypot(cos ψ, c sin ψ). Adding ψ and −ψ (b is odd in ψ, arccos(−z) + arccos(z) = π and
//!   arccos(−z) − π/2 = arcsin z, arcsin(c sin ψ / hypot(cos ψ, c sin ψ)) = atan2(c sin ψ, cos ψ)):
//!   ```text
//!   M_belt = (4 s²/π) ∫₀^{π/2} cos ψ [cos ψ + c sin ψ · atan2(c sin ψ, cos ψ)] / (1 − k x)² dψ,
//!   x = hypot(cos ψ, c sin ψ),
//!   ```
//!   analytic on [0, π/2] for c > 0 (at ψ = π/2 the belt meets the cap; for small c the
//!   integrand turns within ~c of π/2, where the integration starts graded panels).
//!
//! M = M_cap + M_belt. Checks: at k = 0 the integrand is the constant 1/4π and M = 1 for every c
//! (this tests the Jacobian and A); c = 1 is the cap alone, c = 0 the belt alone, both closed
//! (below). The belt integral runs on the one adaptive engine (G10/K21, raw |K21 − G10|
//! estimate); the cap's closed form is exact to a few ulps.
//!
//! # Closed forms on the edges
//!
//! ```text
//! M(k, 1) = 2 F(m)/m²                                             (u ∥ t)
//! M(k, 0) = (2/(π m²)) (π − 2 I₁ + I₂)                            (u ⟂ t)
//! I₁ = ∫₀^π dθ/(1 + m sin θ) = 2 arccos(m)/q,   I₂ = ∫₀^π dθ/(1 + m sin θ)² = 2 (arccos(m) − m q)/q³,
//! q = sqrt(1 − m²)
//! ```
//! (sin²θ/(1 + m sin θ)² = (1 − 2/(1 + m sin θ) + 1/(1 + m sin θ)²)/m²; I₂ = −∂_a ∫ dθ/(a + m sin θ)
//! at a = 1.) M(k, 0) cancels like 1/m², so it serves the tests at m ≥ 0.3 only.
//!
//! # The conservative r(k)
//!
//! N increases with |u·t| (checked on a dense grid in the tests), so the largest r(k) that
//! never makes r·N exceed 1 is r_c(k) = 1/N(k, 1) = m²/(2 (1 − k²) F(m)), in closed form. It
//! loses 1 − N(k, c)/N(k, 1) of the energy.

use crate::integrate::{Estimate, Options, Tolerance, gauss_legendre, integrate};
use std::f64::consts::{FRAC_PI_2, PI};

/// The most panels of the belt integral (it needs tens at 1e-14).
const MAX_PANELS: usize = 2000;

/// 1 − k², as (1 − k)(1 + k) (no cancellation near k = −1).
pub fn one_minus_k2(k: f64) -> f64 {
    (1.0 - k) * (1.0 + k)
}

/// F(y)/y² with F(y) = ln(1 + y) − y/(1 + y), y ≥ 0: the series below y = 1/2 (terms fall by
/// ≥ 2 each, 60 terms reach 1e-18 of the first), the logarithm above (cancellation ≤ 4 ulps
/// there, F(y)/y ≥ 0.06).
fn f_over_y2(y: f64) -> f64 {
    if y < 0.5 {
        // Σ_{n≥2} (−1)ⁿ (n−1)/n y^{n−2}, summed from the smallest term.
        let mut sum = 0.0;
        for n in (2..62).rev() {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            sum = sum * y + sign * (n - 1) as f64 / n as f64;
        }
        sum
    } else {
        (y.ln_1p() - y / (1.0 + y)) / (y * y)
    }
}

/// M_cap(k, c) = 2c ∫₀^c x/(1 − kx)² dx = 2c³ F(mc)/(mc)², m = −k ≥ 0, c ∈ [0, 1].
pub fn cap(k: f64, c: f64) -> f64 {
    2.0 * c * c * c * f_over_y2(-k * c)
}

/// The belt integrand of M (module doc) at ψ ∈ [0, π/2], without the factor 4 s²/π.
fn belt_integrand(k: f64, c: f64, psi: f64) -> f64 {
    let (sp, cp) = psi.sin_cos();
    let cp = cp.max(0.0);
    let x = cp.hypot(c * sp);
    let d = 1.0 - k * x;
    cp * (cp + c * sp * (c * sp).atan2(cp)) / (d * d)
}

/// The belt's initial panels: edges at ψ = π/2 − 4ʲ arcsin c (j ≥ 0, above π/4): for small c
/// the integrand turns within ~c of π/2 (near-singular at complex distance ~c), which a K21
/// panel spanning [0, π/2 − c] does not see (at c = 1e-4 its estimate was 10× below its error).
/// Below c = 1e-6 the feature holds O(c³) ≤ 1e-18 of M and is left ungraded.
fn belt_panels(c: f64) -> Vec<(f64, f64)> {
    let mut edges = vec![FRAC_PI_2];
    let mut d = if c >= 1e-6 { c.asin() } else { 0.0 };
    while d > 0.0 && d < 0.25 * PI {
        edges.push(FRAC_PI_2 - d);
        d *= 4.0;
    }
    edges.push(0.0);
    edges.reverse();
    edges.windows(2).map(|w| (w[0], w[1])).collect()
}

/// M(k, c) = N(k, c)/(1 − k²) to absolute tolerance `tol` (module doc); c = |u·t| is taken.
pub fn mean(k: f64, c: f64, tol: f64) -> Estimate {
    let c = c.abs().min(1.0);
    let s2 = (1.0 - c) * (1.0 + c);
    let cap_value = cap(k, c);
    // The cap's closed form: a few ulps of a value ≤ 1.
    let cap_error = 8.0 * f64::EPSILON * cap_value;
    if s2 == 0.0 {
        return Estimate { value: cap_value, error: cap_error, evals: 1 };
    }
    let scale = 4.0 * s2 / PI;
    let intervals = belt_panels(c);
    let opts = Options::scalar(Tolerance { abs: tol / scale, rel: 0.0, max_panels: MAX_PANELS });
    let r = integrate(&intervals, &opts, |psi| [belt_integrand(k, c, psi)]);
    Estimate { value: cap_value + scale * r.value[0], error: cap_error + scale * r.error, evals: r.evals + 1 }
}

/// N(k, c) = (1 − k²) M(k, c): ∫ p_Schlick(k, sin∠(t, h)) dω_v for u·t = c.
pub fn norm(k: f64, c: f64, tol: f64) -> Estimate {
    let f = one_minus_k2(k);
    let m = mean(k, c, tol / f.max(f64::MIN_POSITIVE));
    Estimate { value: f * m.value, error: f * m.error, evals: m.evals }
}

/// W(k, c) = 1/M = (1 − k²) r: the factor that normalises the Schlick lobe, p_V = W/(4π(1 − kx)²).
pub fn scale(k: f64, c: f64, tol: f64) -> Estimate {
    // |Δ(1/M)| = |ΔM|/M², M ≥ 0.3: ask M for tol·0.09.
    let m = mean(k, c, 0.09 * tol);
    Estimate { value: 1.0 / m.value, error: m.error / (m.value * m.value), evals: m.evals }
}

/// M(k, 1) = 2 F(m)/m² (u ∥ t), closed form.
pub fn mean_parallel(k: f64) -> f64 {
    cap(k, 1.0)
}

/// The conservative r(k) = 1/N(k, 1): the largest r(k) with r·N(k, c) ≤ 1 for every c.
pub fn conservative_r(k: f64) -> f64 {
    1.0 / (one_minus_k2(k) * mean_parallel(k))
}

/// M(k, 0) (u ⟂ t), closed form in I₁, I₂ (module doc); cancels like 1/m², m = −k > 0.
pub fn mean_perpendicular(k: f64) -> f64 {
    let m = -k;
    let q = ((1.0 - m) * (1.0 + m)).sqrt();
    let ac = m.acos();
    let i1 = 2.0 * ac / q;
    let i2 = 2.0 * (ac - m * q) / (q * q * q);
    2.0 / (PI * m * m) * (PI - 2.0 * i1 + i2)
}

/// M(k, c) by an n×n Gauss–Legendre product over the sphere of v directly (no change of
/// variables): v in polar coordinates (β, γ) about u, v = u cos β + sin β (cos γ e₁ + sin γ e₂),
/// e₁ the direction of t's part across u. Then h = u cos(β/2) + (cos γ e₁ + sin γ e₂) sin(β/2),
/// h·t = c cos(β/2) + s cos γ sin(β/2), dω_v = sin β dβ dγ; γ ∈ [0, π] doubled (mirror in the
/// plane of u and t). The integrand has a conical point where h = ±t (β = 2 arccos|c|, γ = 0
/// or π): β is split there (`split`) and the rule converges algebraically in n.
pub fn mean_sphere_product(k: f64, c: f64, n: usize, split: bool) -> f64 {
    let s = ((1.0 - c) * (1.0 + c)).max(0.0).sqrt();
    let (gx, gw) = gauss_legendre(n);
    let beta_star = 2.0 * c.abs().min(1.0).acos();
    let panels: Vec<(f64, f64)> = if split && beta_star > 0.0 && beta_star < PI { vec![(0.0, beta_star), (beta_star, PI)] } else { vec![(0.0, PI)] };
    let mut sum = 0.0;
    for &(a, b) in &panels {
        let (hb, mb) = (0.5 * (b - a), 0.5 * (b + a));
        for (xb, wb) in gx.iter().zip(&gw) {
            let beta = mb + hb * xb;
            let (sh, ch) = (0.5 * beta).sin_cos();
            let mut inner = 0.0;
            for (xg, wg) in gx.iter().zip(&gw) {
                let gamma = FRAC_PI_2 * (1.0 + xg);
                let ht = c * ch + s * gamma.cos() * sh;
                let x = ((1.0 - ht) * (1.0 + ht)).max(0.0).sqrt();
                let d = 1.0 - k * x;
                inner += wg / (d * d);
            }
            sum += wb * hb * beta.sin() * FRAC_PI_2 * inner;
        }
    }
    // (1/4π) · 2 (mirror) · the integral over β ∈ [0, π], γ ∈ [0, π].
    sum / (2.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::adaptive;

    const TOL: f64 = 1e-13;

    fn grid(n: usize, lo: f64, hi: f64) -> Vec<f64> {
        (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect()
    }

    #[test]
    fn n_is_one_at_k_zero_for_every_u_dot_t() {
        // At k = 0 the integrand is 1/4π: M = 1 exactly, which checks the Jacobian 4(u·h) and the
        // azimuth integral A(θ). Bound: the requested tolerance plus the cap's few ulps.
        for c in grid(41, -1.0, 1.0).into_iter().chain([1e-9, 1e-4, 0.999_999]) {
            let e = norm(0.0, c, TOL);
            assert!((e.value - 1.0).abs() <= TOL + 1e-15, "c = {c}: {} ({:e})", e.value, e.error);
            assert!(e.error <= TOL, "c = {c}: estimate {:e}", e.error);
        }
    }

    #[test]
    fn cap_closed_form_matches_its_quadrature() {
        // 2c ∫₀^c x/(1 − kx)² dx by the scalar engine at 1e-15 (analytic integrand): the bound
        // is that tolerance plus ulps of the closed form (both sides of the series switch).
        for k in grid(12, -0.99, 0.0) {
            for c in [0.0, 1e-6, 0.1, 0.3, 0.5 / 0.99, 0.7, 1.0] {
                let q = adaptive(0.0, c, Tolerance { abs: 1e-15, rel: 0.0, max_panels: 100 }, |x| {
                    2.0 * c * x / ((1.0 - k * x) * (1.0 - k * x))
                });
                assert!((cap(k, c) - q.value).abs() <= 2e-15 + 1e-15, "k = {k}, c = {c}: {} vs {}", cap(k, c), q.value);
            }
        }
    }

    #[test]
    fn edges_match_their_closed_forms() {
        // u ∥ t: the belt vanishes and M is the cap (exact). u ⟂ t: the belt alone against the
        // I₁, I₂ closed form, whose 1/m² cancellation costs ≲ 1e-15/m² ≤ 1.2e-14 at m ≥ 0.3.
        for k in grid(14, -0.99, -0.3) {
            let e = mean(k, 0.0, TOL);
            assert!((e.value - mean_perpendicular(k)).abs() <= TOL + 1.2e-14, "k = {k}: {} vs {}", e.value, mean_perpendicular(k));
            assert_eq!(mean(k, 1.0, TOL).value, mean_parallel(k));
            assert_eq!(mean(k, -1.0, TOL).value, mean_parallel(k));
        }
    }

    #[test]
    fn agrees_with_a_product_rule_over_the_sphere_of_v() {
        // No change of variables there: v over the sphere about u, signed c (t and −t), the
        // conical point split. Its error falls like n^-2 or faster: the bound is twice the
        // difference of the n = 200 and 400 rules (measured ≤ 3e-8).
        for (k, c) in [(-0.5, 0.3), (-0.99, -0.7), (-0.2, 0.95), (-0.9, 0.05), (-0.99, 0.0)] {
            let a = mean_sphere_product(k, c, 200, true);
            let b = mean_sphere_product(k, c, 400, true);
            let e = mean(k, c, TOL).value;
            let bound = 2.0 * (a - b).abs() + 1e-13;
            assert!((b - e).abs() <= bound, "k = {k}, c = {c}: {e} vs {b} (bound {bound:e})");
        }
    }

    #[test]
    fn n_grows_with_u_dot_t_so_the_parallel_light_bounds_it() {
        // The conservative r(k) rests on this: N(k, c) ≤ N(k, 1). Checked as strict increase on
        // a 41×101 grid (neighbouring values differ by ≥ 1e-8, far above the 1e-13 tolerance).
        for k in grid(41, -0.99, -0.01) {
            let ns: Vec<f64> = grid(101, 0.0, 1.0).iter().map(|&c| mean(k, c, TOL).value).collect();
            assert!(ns.windows(2).all(|w| w[1] > w[0] + 1e-10), "k = {k}");
            assert!((conservative_r(k) * norm(k, 1.0, TOL).value - 1.0).abs() <= 1e-12, "k = {k}");
        }
    }

    #[test]
    fn estimates_bound_the_error_and_converge() {
        // The estimate at tolerance τ against the value at 1e-14 (the difference at 1e-14 is
        // itself ≤ 1e-14): the error is within the estimate, the estimate within τ.
        for (k, c) in [(-0.99, 0.01), (-0.7, 0.5), (-0.3, 0.999), (-0.99, 1e-5)] {
            let reference = mean(k, c, 1e-14).value;
            for tol in [1e-6, 1e-9, 1e-12] {
                let e = mean(k, c, tol);
                assert!(e.error <= tol, "k = {k}, c = {c}, tol = {tol:e}: {:e}", e.error);
                assert!((e.value - reference).abs() <= e.error + 1e-14, "k = {k}, c = {c}, tol = {tol:e}");
            }
        }
    }

    /// The shader factor W = 1/M: 1 at k = 0 for every u·t (N = M = 1 there), 1/M(k, 1) in
    /// closed form at c = 1 (to the integrator's 1e-12 relative, bound 4e-12); within τ of the
    /// reference 1/M at 1e-14 and within its own estimate; and that estimate is M's, carried
    /// by the derivative of 1/M, here a central difference of 1/x at M (its 1e-6 relative
    /// step: truncation 1e-12, rounding of two values 2e-6 apart ~1e-10, relative; bound 1e-9).
    #[test]
    fn scale_is_one_over_the_mean_with_its_error_carried() {
        for c in [0.0, 0.3, 1.0] {
            assert!((scale(0.0, c, 1e-12).value - 1.0).abs() <= 4e-12, "c = {c}");
        }
        for k in [-0.99, -0.5, -0.1] {
            assert!((scale(k, 1.0, 1e-12).value * mean_parallel(k) - 1.0).abs() <= 4e-12, "k = {k}");
        }
        for (k, c) in [(-0.99, 0.01), (-0.7, 0.5), (-0.3, 0.999)] {
            let reference = 1.0 / mean(k, c, 1e-14).value;
            for tol in [1e-6, 1e-9] {
                let w = scale(k, c, tol);
                assert!(w.error <= tol && (w.value - reference).abs() <= w.error + 1e-14, "k = {k}, c = {c}, tol = {tol:e}: {w:?}");
                let m = mean(k, c, 0.09 * tol);
                let h = 1e-6 * m.value;
                let slope = (1.0 / (m.value - h) - 1.0 / (m.value + h)) / (2.0 * h);
                assert!((w.error / (m.error * slope) - 1.0).abs() <= 1e-9, "k = {k}, c = {c}: {} vs {}", w.error, m.error * slope);
                assert_eq!(w.evals, m.evals);
            }
        }
    }

    #[test]
    fn small_k_follows_the_first_order_term() {
        // M = 1 + 2k ⟨x⟩ + O(k²), ⟨x⟩ the mean of sin∠(t, h) over v; at c = 1 that mean is
        // ∫₀¹ 2x·x dx = 2/3 (cap only, h's polar density 2 sinθ cosθ). Bound: the O(k²) term
        // 3⟨x²⟩k² ≤ 3k².
        let k = -1e-4;
        let m = mean(k, 1.0, TOL).value;
        assert!((m - (1.0 + 2.0 * k * 2.0 / 3.0)).abs() <= 3.0 * k * k, "{m}");
    }

    /// N = (1 − k²) M and r_c = 1/N(k, 1) at k = −1/2, by hand: m = 1/2, F(1/2) = ln 1.5 − 1/3
    /// = 0.405465108 − 0.333333333 = 0.0721317748, M(k, 1) = 2F/m² = 0.5770651, 1 − k² = 3/4, so
    /// N(k, 1) = 0.4327906 and r_c = 2.3105860; at u ⟂ t N = (3/4) M(k, 0), M(k, 0) from the
    /// I₁, I₂ closed form. Bounds: ln 1.5 − 1/3 to an ulp of 0.4 (1e-16 on F = 0.07, 2e-15
    /// relative), so 1e-14 relative on N and r_c; at c = 0 the 1e-13 tolerance (times 3/4)
    /// plus the closed form's 1.2e-14 (`edges_match_their_closed_forms`).
    #[test]
    fn norm_and_the_conservative_r_at_k_minus_one_half_by_hand() {
        let k = -0.5;
        assert_eq!(one_minus_k2(k), 0.75);
        let n_parallel = 0.75 * 2.0 * (1.5f64.ln() - 1.0 / 3.0) / 0.25;
        assert!((n_parallel - 0.4327906).abs() < 1e-7 && (1.0 / n_parallel - 2.3105860).abs() < 1e-7, "{n_parallel}");
        let e = norm(k, 1.0, TOL);
        assert!((e.value / n_parallel - 1.0).abs() <= 1e-14, "N(k, 1) = {}", e.value);
        assert!((conservative_r(k) * n_parallel - 1.0).abs() <= 1e-14, "r_c = {}", conservative_r(k));
        let e = norm(k, 0.0, TOL);
        assert!((e.value - 0.75 * mean_perpendicular(k)).abs() <= 0.75 * (TOL + 1.2e-14), "N(k, 0) = {}", e.value);
    }

    /// The belt's initial panels follow the rule of `belt_panels`: edges at π/2 − 4ʲ arcsin c
    /// while 4ʲ arcsin c < π/4, only for c ≥ 1e-6. At c = 1e-4: 4⁶ arcsin c = 0.4096 < π/4 <
    /// 4⁷ arcsin c = 1.64, seven edges and eight panels; c = 1/2: arcsin c = π/6 < π/4 < 4π/6,
    /// one edge at π/3; c = 0.9 (arcsin c = 1.12 > π/4) and c = 1e-7 (below 1e-6): one panel.
    /// (4ʲ d is exact in binary, so the edges are compared exactly.) And `mean` counts 21
    /// evaluations per K21 panel plus one for the cap's closed form: at tolerance 1e-2 no panel
    /// is bisected (a K21 panel of this analytic integrand is far within it), so the count is
    /// 21 × panels + 1; at c = 1 the cap alone, one.
    #[test]
    fn the_belt_starts_on_its_graded_panels_and_counts_the_cap_as_one_evaluation() {
        let a = 1e-4f64.asin();
        let mut edges = vec![0.0];
        edges.extend((0..7).rev().map(|j| FRAC_PI_2 - 4f64.powi(j) * a));
        edges.push(FRAC_PI_2);
        let want: Vec<(f64, f64)> = edges.windows(2).map(|w| (w[0], w[1])).collect();
        assert_eq!(belt_panels(1e-4), want);
        assert_eq!(belt_panels(0.5), vec![(0.0, FRAC_PI_2 - 0.5f64.asin()), (FRAC_PI_2 - 0.5f64.asin(), FRAC_PI_2)]);
        for c in [0.9, 1e-7, 0.0] {
            assert_eq!(belt_panels(c), vec![(0.0, FRAC_PI_2)], "c = {c}");
        }
        for (c, panels) in [(1e-4, 8), (0.5, 2), (0.9, 1), (0.0, 1)] {
            assert_eq!(mean(-0.9, c, 1e-2).evals, 21 * panels + 1, "c = {c}");
        }
        assert_eq!(mean(-0.9, 1.0, 1e-2).evals, 1);
    }

    /// The belt is asked for tol/scale (M's error is scale times the belt's, scale = 4s²/π =
    /// 4/π at u ⟂ t): at a tolerance 1/1.2 of an estimate the engine reported, the estimate
    /// must still be within it. Asking the belt for tol (or tol·scale) would accept the stage
    /// that reported E = 1.2 tol. Each estimate also bounds the error against the closed form
    /// M(k, 0) (whose cancellation costs ≤ 1.2e-14 at m = 0.9).
    #[test]
    fn mean_meets_a_tolerance_just_below_a_reported_estimate() {
        let k = -0.9;
        let mut tol = 1e-6;
        for _ in 0..6 {
            let e = mean(k, 0.0, tol);
            assert!(e.error <= tol, "tol {tol:e}: estimate {:e}", e.error);
            assert!((e.value - mean_perpendicular(k)).abs() <= e.error + 1.2e-14, "tol {tol:e}: {e:?}");
            tol = e.error / 1.2;
        }
    }

    /// M = M_cap + M_belt (module doc): the cap's closed form with its few ulps (8ε·M_cap), plus
    /// 4s²/π times the belt integral on its panels by the engine, value and estimate, and the
    /// engine's evaluations plus one for the cap. At k = −0.99, c = 0.3 and tolerance 1e-2
    /// nothing is bisected (two K21 panels, 43 evaluations), and the belt's raw |K21 − G10|
    /// is above 5e-13 (at 1e-12 `mean` bisects once), so a lost or negated belt estimate shows.
    /// The same operations in the same order: exact.
    #[test]
    fn mean_is_the_cap_plus_the_belt_with_both_estimates() {
        let (k, c) = (-0.99, 0.3);
        let scale = 4.0 * (1.0 - c) * (1.0 + c) / PI;
        let loose = Options::scalar(Tolerance { abs: 1.0, rel: 0.0, max_panels: MAX_PANELS });
        let belt = integrate(&belt_panels(c), &loose, |psi| [belt_integrand(k, c, psi)]);
        let e = mean(k, c, 1e-2);
        assert!(belt.evals == 42 && belt.error > 5e-13, "{belt:?}");
        assert_eq!(e.evals, belt.evals + 1);
        assert_eq!(e.value, cap(k, c) + scale * belt.value[0]);
        assert_eq!(e.error, 8.0 * f64::EPSILON * cap(k, c) + scale * belt.error);
    }

    /// N's tolerance is on N = (1 − k²) M: M is asked only for tol/(1 − k²), 50× looser at
    /// k = −0.99, so N costs fewer evaluations than M at the same tolerance (asking M for tol,
    /// or tol·(1 − k²), would cost as many or more), and still meets it.
    #[test]
    fn norm_asks_the_mean_only_for_what_n_needs() {
        let (k, c) = (-0.99, 0.3);
        let (n, m) = (norm(k, c, 1e-12), mean(k, c, 1e-12));
        assert!(n.error <= 1e-12 && n.evals < m.evals, "k = {k}, c = {c}: {n:?} vs {m:?}");
    }

    /// With one Gauss node (x = 0, weight 2) the product rule is the midpoint rule in β and γ
    /// (γ = π/2, inner sum 2): at k = 0 (integrand 1/4π) a β panel [a, b] contributes
    /// 2·((b − a)/2)·sin((a + b)/2)·(π/2)·2/(2π) = ((b − a)/2) sin((a + b)/2). At c = √3/2 the
    /// conical point is β* = 2 arccos c = π/3: unsplit (π/2) sin(π/2) = π/2 = 1.5708; split
    /// (π/6) sin(π/6) + (π/3) sin(2π/3) = π/12 + π√3/6 = 1.1687. Rounding: 1e-15.
    #[test]
    fn the_product_rule_with_one_node_is_the_midpoint_rule_split_at_the_conical_point() {
        let c = 3f64.sqrt() / 2.0;
        let unsplit = mean_sphere_product(0.0, c, 1, false);
        let split = mean_sphere_product(0.0, c, 1, true);
        assert!((unsplit - FRAC_PI_2).abs() <= 1e-15, "{unsplit}");
        assert!((split - (PI / 12.0 + PI * 3f64.sqrt() / 6.0)).abs() <= 1e-15, "{split}");
    }
}
