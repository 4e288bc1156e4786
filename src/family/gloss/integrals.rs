//! Gloss ↔ GGX average-normal-length relation and the gloss-combine table
//! (Call of Duty: WWII, "Mipmapping normal and gloss", "Combining gloss").
//!
//! # Conventions
//! - Gloss g ∈ [0, 1] maps to GGX roughness α = sqrt(2 / (1 + 2^(18·g))) (the WWII
//!   parameterisation, after the slides' own erratum: the exponent is 18·g, not a product
//!   18·g inside the sum). g = 0 gives α = 1; g = 1 gives α = sqrt(2/262145) ≈ 0.002762.
//! - The average ("shortened") normal length of an NDF is ‖n_s‖ = ‖E[h]‖ for microfacet normals
//!   h drawn with density D(h)(n·h) over solid angle. By symmetry E[h] = (0, 0, E[n·h]), so
//!   ‖n_s‖ = E[n·h] = ∫ D(h) (n·h)² dω_h.
//!
//! # Closed form
//! With t = n·h and GGX D(h) = α² / (π (1 + (α² − 1) t²)²):
//!
//!   L(α) = 2α² ∫₀¹ t² / (1 − k t²)² dt,   k = 1 − α²,
//!
//! which integrates to L = (1 − α² atanh(√k)/√k) / k. Two cancellation-free evaluations:
//! - k < ½ (α near 1): the power series L = Σ_{n≥0} 2kⁿ / ((2n+1)(2n+3)); k = 0 gives 2/3.
//! - otherwise: 1 − L = α² (atanh(√k)/√k − 1) / k with atanh(√k) = ln((1 + √k)/α), exact
//!   because (1 + √k)(1 − √k) = α². Both terms are positive, so small α loses nothing.
//!
//! The module also keeps an independent adaptive quadrature of the defining integral, used by
//! tests and by `validate` as a check on the closed form.
//!
//! # Inverse and combine
//! L increases strictly with g, so g(L) is found by Illinois regula falsi in g on the
//! cancellation-free ln(1 − L) (to about one ulp of g, in 9 to 17 closed-form evaluations; see
//! [`gloss_from_length`]), after clamping L to [L(0), L(1)] (the table ends). Combining two glosses with
//! Reoriented Normal Mapping multiplies their lengths (the slides' derivation), so
//! combine(x, y) = g(L(x)·L(y)), clamped at g = 0 where the product falls below 2/3.
//!
//! Fit specs: `fits/gloss_table.toml`, `fits/gloss_inverse_table.toml`,
//! `fits/gloss_length.toml`, `fits/gloss_combine.toml`, `fits/gloss_combine_lut.toml`.

use crate::integrate::{adaptive, Estimate, Tolerance};

/// GGX α for gloss g and back (WWII parameterisation), from the shading layer.
pub use crate::shading::roughness::{alpha_from_gloss, gloss_from_alpha};

/// 1 − L(α), accurate to a few ulps of itself for every α ∈ (0, 1].
pub fn one_minus_length(alpha: f64) -> f64 {
    let k = (1.0 - alpha) * (1.0 + alpha);
    if k < 0.5 {
        1.0 - length_series(k)
    } else {
        let s = k.sqrt();
        let atanh = ((1.0 + s) / alpha).ln();
        alpha * alpha * (atanh / s - 1.0) / k
    }
}

/// Average normal length L(α) = E[n·h] of GGX with roughness α ∈ (0, 1].
pub fn normal_length(alpha: f64) -> f64 {
    let k = (1.0 - alpha) * (1.0 + alpha);
    if k < -0.5 {
        // α > √1.5 (outside the gloss domain): atanh(√k)/√k = atan(√−k)/√−k, no cancellation.
        let s = (-k).sqrt();
        return (1.0 - alpha * alpha * s.atan() / s) / k;
    }
    if k < 0.5 { length_series(k) } else { 1.0 - one_minus_length(alpha) }
}

/// Σ 2kⁿ/((2n+1)(2n+3)) for 0 ≤ k < ½: terms fall at least 2× per step, so 60 terms
/// reach below 1e-18.
fn length_series(k: f64) -> f64 {
    let mut sum = 0.0;
    let mut kn = 1.0;
    for n in 0..64 {
        let nf = n as f64;
        let term = 2.0 * kn / ((2.0 * nf + 1.0) * (2.0 * nf + 3.0));
        sum += term;
        // |term|: for α > 1 (k < 0, outside the gloss domain) the terms alternate in sign.
        if term.abs() < 1e-18 * sum.abs() {
            break;
        }
        kn *= k;
    }
    sum
}

/// Average normal length of gloss g.
pub fn length_from_gloss(g: f64) -> f64 {
    normal_length(alpha_from_gloss(g))
}

/// L(α) by adaptive Gauss–Kronrod quadrature of 2α² t²/(1 − k t²)² over t ∈ [0, 1];
/// independent of the closed form. For small α the integrand is a peak of width ~α² at t = 1.
pub fn normal_length_quadrature(alpha: f64, abs_tol: f64) -> Estimate {
    let a2 = alpha * alpha;
    let tol = Tolerance { abs: abs_tol, rel: 0.0, max_panels: 10_000 };
    adaptive(0.0, 1.0, tol, |t| {
        // 1 − k t² written as (1 − t)(1 + t) + α² t²: no cancellation at the peak t → 1.
        let den = (1.0 - t) * (1.0 + t) + a2 * t * t;
        2.0 * a2 * t * t / (den * den)
    })
}

/// Bounds of the length table: L(g = 0) = 2/3 and L(g = 1).
pub fn length_range() -> (f64, f64) {
    (length_from_gloss(0.0), length_from_gloss(1.0))
}

/// Gloss whose average normal length is `length`, clamped to g ∈ [0, 1] outside the table.
pub fn gloss_from_length(length: f64) -> f64 {
    if length.is_nan() {
        return f64::NAN;
    }
    let (lo, hi) = length_range();
    if length <= lo {
        return 0.0;
    }
    if length >= hi {
        return 1.0;
    }
    // Illinois (modified regula falsi) on h(g) = ln(1 − L(g)) − ln(1 − length). h decreases
    // strictly and is close to linear in g (1 − L ≈ α²(ln(2/α) − 1) with α² = 2/(1 + 2^(18g))),
    // so secant steps converge in a few evaluations; halving the stale end's value (Illinois)
    // keeps both ends moving, and a step that would not land inside the bracket bisects. It stops
    // when the bracket is down to adjacent f64 values or two spacings: the root to about one ulp,
    // like 64 bisection steps, in 9 to 17 closed-form evaluations (measured over the table).
    let target = (1.0 - length).ln();
    illinois(|g: f64| one_minus_length(alpha_from_gloss(g)).ln() - target).0
}

/// The root in [0, 1] of a decreasing `h` with h(0) > 0 > h(1), by the Illinois steps of
/// [`gloss_from_length`], and the evaluations of `h` it took.
fn illinois(h: impl Fn(f64) -> f64) -> (f64, usize) {
    let (mut a, mut b) = (0.0_f64, 1.0_f64);
    let (mut ha, mut hb) = (h(a), h(b));
    let mut evals = 2;
    let mut last = 0i8;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b || b - a <= 2.0 * f64::EPSILON * b {
            break;
        }
        let mut x = b - hb * (b - a) / (hb - ha);
        if !(x > a && x < b) {
            x = m;
        }
        let hx = h(x);
        evals += 1;
        if hx == 0.0 {
            return (x, evals);
        }
        if hx > 0.0 {
            (a, ha) = (x, hx);
            if last == 1 {
                hb *= 0.5;
            }
            last = 1;
        } else {
            (b, hb) = (x, hx);
            if last == -1 {
                ha *= 0.5;
            }
            last = -1;
        }
    }
    (0.5 * (a + b), evals)
}

/// Combined gloss of two glosses under Reoriented Normal Mapping.
pub fn combine(x: f64, y: f64) -> f64 {
    gloss_from_length(length_from_gloss(x) * length_from_gloss(y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trips_on_a_fine_grid() {
        // 4095 glosses off the dyadic grid of `inverse_round_trips`: the Illinois steps must
        // close the bracket everywhere, not only at g = k/64. Bound as there: dL/dg ≥ ~1e-5 near
        // g = 1, so one ulp of L (1e-16) maps to ≤ 1e-11 in g; 1e-10 leaves 10×.
        for i in 1..4096 {
            let g = i as f64 / 4096.0 + 1e-5;
            let back = gloss_from_length(length_from_gloss(g));
            assert!((back - g).abs() < 1e-10, "g={g} back={back}");
        }
    }

    #[test]
    fn alpha_from_gloss_is_the_published_parameterisation() {
        // COD: WWII's gloss parameterisation (the module docs): α = sqrt(2 / (1 + 2^(18 g))),
        // 18·g inside the sum. At g = k/18 the power is the integer 2^k, so α² is the
        // exact rational 2/(1 + 2^k): 1 at g = 0, 2/3, 2/9, then 2/513 at g = ½ and
        // 2/262145 at g = 1. The square root of a rational in f64 is within an ulp or two of
        // the computed one (exp2 of an integer is exact): 4 ulps relative.
        for (k, two_over) in [(0.0, 2.0), (1.0, 3.0), (3.0, 9.0), (9.0, 513.0), (18.0, 262_145.0)] {
            let g = k / 18.0;
            let want = (2.0_f64 / two_over).sqrt();
            let a = alpha_from_gloss(g);
            assert!((a - want).abs() <= 4.0 * f64::EPSILON * want, "g = {k}/18: α = {a}, want {want}");
            // And back.
            assert!((gloss_from_alpha(want) - g).abs() <= 1e-14, "g = {k}/18");
        }
        // Through the published table (‖n_s‖ against gloss, a Monte Carlo estimate printed to 6
        // decimals): the closed form of L at α(g) lies within 3.6e-6 of every row (the table's
        // own bias, largest at small g), so 5e-6 holds; an exponent of 16 or 20 instead of 18
        // moves L by 3e-5 to 1e-3 at the table's glosses.
        for (g, published) in crate::family::gloss::published::PUBLISHED_TABLE {
            let l = normal_length(alpha_from_gloss(g));
            assert!((l - published).abs() < 5e-6, "g = {g}: L(α(g)) = {l}, published {published}");
        }
    }

    #[test]
    fn limits_from_theory() {
        // α = 1 is the uniform-cosine case: E[t] with density 2t... gives exactly 2/3.
        assert_eq!(normal_length(1.0), 2.0 / 3.0);
        // α → 0: 1 − L ≈ α² (ln(2/α) − 1); at α = 1e-6 that is 1.35e-11.
        let a = 1e-6_f64;
        let approx = a * a * ((2.0 / a).ln() - 1.0);
        // Next term of the expansion is O(α⁴ ln α): relative 1e-11 here.
        assert!((one_minus_length(a) - approx).abs() < 1e-9 * approx);
    }

    #[test]
    fn series_and_log_branches_meet() {
        // At the branch point k = ½ both formulas must agree to rounding (1e-15 absolute:
        // a few ulps of values near 0.7).
        let alpha = 0.5_f64.sqrt();
        let k = (1.0 - alpha) * (1.0 + alpha);
        let s = k.sqrt();
        let log_form = 1.0 - alpha * alpha * (((1.0 + s) / alpha).ln() / s - 1.0) / k;
        assert!((length_series(k) - log_form).abs() < 1e-15);
    }

    #[test]
    fn closed_form_matches_independent_quadrature_on_256_glosses() {
        // Quadrature asked for 1e-14 absolute; the acceptance bound is 1e-12, which leaves
        // room for the error estimate being an estimate (measured worst: see the message).
        let mut worst = 0.0_f64;
        for i in 0..256 {
            let g = i as f64 / 255.0;
            let a = alpha_from_gloss(g);
            let q = normal_length_quadrature(a, 1e-14);
            let d = (normal_length(a) - q.value).abs();
            worst = worst.max(d);
            assert!(d <= 1e-12, "g={g}: closed {} vs quadrature {} (diff {d:e})", normal_length(a), q.value);
        }
        eprintln!("gloss-length closed form vs quadrature, 256 glosses: max diff {worst:e}");
    }

    /// Beyond the gloss domain (α > √1.5, where L takes its atan form) the closed form still
    /// agrees with the quadrature of the definition; the integrand 2α²t²/(1 + (α² − 1)t²)² is
    /// smooth there. Asked for 1e-14, bound 1e-12 as on the gloss domain. At α = √1.5 the two
    /// forms meet (the series just below, the atan form just above).
    #[test]
    fn closed_form_matches_quadrature_beyond_the_gloss_domain() {
        for alpha in [1.2248, 1.5, 2.0, 5.0, 30.0] {
            let q = normal_length_quadrature(alpha, 1e-14);
            assert!((normal_length(alpha) - q.value).abs() <= 1e-12, "α = {alpha}: closed {} vs quadrature {}", normal_length(alpha), q.value);
        }
        let edge = 1.5f64.sqrt();
        let (below, above) = (normal_length(edge * (1.0 - 1e-15)), normal_length(edge * (1.0 + 1e-15)));
        assert!((below - above).abs() < 1e-14, "{below} vs {above}");
    }

    #[test]
    fn monotone_in_gloss() {
        let mut prev = 0.0;
        for i in 0..=1000 {
            let l = length_from_gloss(i as f64 / 1000.0);
            assert!(l > prev, "L must increase strictly with gloss");
            prev = l;
        }
    }

    /// The inverse's cost and result against the documented ones: on 256 lengths across the
    /// table, the Illinois steps take at most 20 evaluations of h (measured: 9 to 17, the two
    /// ends included; bisection to one ulp would take ~64) and land where 64 plain bisections
    /// of the same h close in.
    #[test]
    fn the_inverse_takes_few_evaluations_to_the_bisection_root() {
        let (lo, hi) = length_range();
        let mut most = 0;
        for i in 0..256 {
            let length = lo + (hi - lo) * (i as f64 + 0.5) / 256.0;
            let target = (1.0 - length).ln();
            let h = |g: f64| one_minus_length(alpha_from_gloss(g)).ln() - target;
            let (g, evals) = illinois(h);
            assert_eq!(g, gloss_from_length(length));
            most = most.max(evals);
            let (mut a, mut b) = (0.0_f64, 1.0_f64);
            for _ in 0..64 {
                let m = 0.5 * (a + b);
                if h(m) > 0.0 { a = m } else { b = m }
            }
            // h's own rounding (|h(g)| ≤ 2.5 ε (1 + |ln(1 − L)|) at the results, measured) lets
            // the two land on sign changes a few float spacings apart (1.1e-16 below 1):
            // measured ≤ 2.5e-16.
            assert!((g - 0.5 * (a + b)).abs() <= 1e-15, "L = {length}: g = {g}, bisection [{a}, {b}]");
        }
        assert!(most <= 20, "up to {most} evaluations");
    }

    #[test]
    fn inverse_round_trips() {
        for i in 0..=64 {
            let g = i as f64 / 64.0;
            let back = gloss_from_length(length_from_gloss(g));
            // dL/dg ≥ ~1e-5 near g = 1, so one ulp of L (1e-16) maps to ≤1e-11 in g.
            assert!((back - g).abs() < 1e-10, "g={g} back={back}");
        }
    }
    /// Where the secant step rounds onto an end of the bracket, the steps bisect. On a step
    /// function, h = 1 below 0.75 and −1e-17 from 0.75 on, every secant point
    /// b − h_b (b − a)/(h_b − h_a) is b less at most 1e-17 · (b − a), below half an ulp of b, so
    /// it rounds to b and each step is a plain bisection (traced by hand: 0.5, 0.75, then a
    /// climbs). The bracket [0.75 − 2⁻ʲ, 0.75] stops at the first width ≤ 2ε·0.75 = 3.3e-16,
    /// j = 52: 2 + 52 evaluations, the root 0.75 − 2⁻⁵³ (the midpoint, exact in binary). The
    /// mirror, h = 1e-17 below 0.25 and −1 from 0.25 on, rounds onto a: the bracket
    /// [0.25 − 2⁻ʲ, 0.25] stops at 2⁻ʲ ≤ 2ε·0.25 = 2⁻⁵³, 2 + 53 evaluations, root 0.25 − 2⁻⁵⁴.
    #[test]
    fn illinois_bisects_where_the_secant_rounds_onto_an_end() {
        let (g, evals) = illinois(|g: f64| if g < 0.75 { 1.0 } else { -1e-17 });
        assert_eq!((g, evals), (0.75 - 2f64.powi(-53), 54));
        let (g, evals) = illinois(|g: f64| if g < 0.25 { 1e-17 } else { -1.0 });
        assert_eq!((g, evals), (0.25 - 2f64.powi(-54), 55));
    }

    /// The Illinois steps against hand and traced counts. A linear h = 1/8 − g/2: the first
    /// secant point 1 − (−3/8)·1/(−1/2) = 1/4 is exact in binary and h(1/4) = 0: 3 evaluations,
    /// the root 1/4 exactly. On h = 1/4 − g² (root ½) and h = e^(−8g) − ½ (root ln 2 / 8, the
    /// other end goes stale) the steps, traced in IEEE double outside this crate, take 12 and 14
    /// evaluations; halving the wrong end, or not halving, or a stale end never halved takes 4
    /// to 186 instead. The roots: within 2 ulps of ½ and of ln 2 / 8 (the stop is at ≤ two
    /// float spacings, and h's rounding moves the sign change by about one).
    #[test]
    fn illinois_takes_the_traced_steps_on_closed_form_roots() {
        assert_eq!(illinois(|g: f64| 0.125 - 0.5 * g), (0.25, 3));
        let (g, evals) = illinois(|g: f64| 0.25 - g * g);
        assert!((g - 0.5).abs() <= 2.0 * f64::EPSILON * 0.5, "g = {g}");
        assert_eq!(evals, 12, "h = 1/4 − g²");
        let (g, evals) = illinois(|g: f64| (-8.0 * g).exp() - 0.5);
        let root = std::f64::consts::LN_2 / 8.0;
        assert!((g - root).abs() <= 2.0 * f64::EPSILON * root, "g = {g}, want {root}");
        assert_eq!(evals, 14, "h = e^(−8g) − ½");
    }
}
