//! G, Q and the exponential integrals of the fuzz layer (conventions and closed forms in the
//! module doc of `super`).

use super::{clean_tol, invalid, MAX_PANELS};
use crate::integrate::{graded_unit_integral, Estimate};

/// G(d, μv) by adaptive quadrature of ∫₀¹ (1 − e^{−d(1/μv + 1/μ)}) μ/(μ + μv) dμ.
///
/// The range is split at μ = d and μ = μv (the scales of e^{−d/μ} and of μ/(μ + μv)) and
/// graded logarithmically above the first cut. G(d, 0) = 1 (the limit μv → 0, d > 0);
/// G(0, μv) = 0. NaN for d < 0 or μv < 0.
pub fn g(d: f64, mu_v: f64, tol: f64) -> Estimate {
    if !(d >= 0.0 && mu_v >= 0.0) {
        return invalid();
    }
    if d == 0.0 {
        return Estimate::exact(0.0);
    }
    if mu_v == 0.0 {
        return Estimate::exact(1.0);
    }
    // Subnormal arguments: the graded nodes would need 1/d or 1/μv, which overflow. Take the
    // limit with a bound on the distance to it. The integrand (1 − e^{−d(1/μv + 1/μ)})·μ/(μ + μv)
    // is at most d/μv, so G ≤ d/μv; and 1 − G ≤ c ln((1 + c)/c) + e^{−d/c} E₂(d) + c E₁(d(1 + c)/c)
    // from the closed form ([`g_exact`], c = μv; E₂ ≤ 1, E₁(x) ≤ e^{−x} ln(1 + 1/x)).
    if d < f64::MIN_POSITIVE || mu_v < f64::MIN_POSITIVE {
        let to_zero = (d / mu_v).min(1.0);
        let c = mu_v;
        let to_one = c * (1.0 - c.ln()) + (-d / c).exp() + c * expn(1, d * (1.0 + c) / c);
        return if to_zero <= to_one {
            Estimate { value: 0.0, error: to_zero, evals: 0 }
        } else {
            Estimate { value: 1.0, error: to_one.min(1.0), evals: 0 }
        };
    }
    let mut e = graded_unit_integral(&[d, mu_v], clean_tol(tol), MAX_PANELS, |mu| {
        if mu <= 0.0 {
            return 0.0;
        }
        -(-d * (1.0 / mu_v + 1.0 / mu)).exp_m1() * mu / (mu + mu_v)
    });
    // Rounding: the logarithmic pieces place their nodes through exp of values up to
    // ln(1/min(d, μv)), which perturbs the sample points by that many ulps (seen as G exceeding
    // 1 by 3e-14 at μv = 1e-300); the quadrature estimate does not include it.
    e.error += 8.0 * f64::EPSILON * (1.0 + d.min(mu_v).recip().ln().max(0.0));
    e
}

/// G(d, μv) in closed form (see the module doc), for d > 0, μv > 0:
/// 1 − c ln((1+c)/c) − e^{−d/c} E₂(d) + c e^{−d/c} E₁(d) − c E₁(d(1+c)/c), c = μv.
/// Absolute rounding error ≲ 1e-15·(1 + |ln d|); limits as in [`g`].
pub fn g_exact(d: f64, mu_v: f64) -> f64 {
    if !(d >= 0.0 && mu_v >= 0.0) {
        return f64::NAN;
    }
    if d == 0.0 {
        return 0.0;
    }
    if mu_v == 0.0 {
        return 1.0;
    }
    let c = mu_v;
    let ed = (-d / c).exp();
    1.0 - c * (1.0 / c).ln_1p() - ed * expn(2, d) + c * ed * expn(1, d)
        - c * expn(1, d * (1.0 + c) / c)
}

/// Q(d) = 2 ∫₀¹ e^{−d/μ} μ dμ by adaptive quadrature (split at μ = d, graded logarithmically
/// above it). NaN for d < 0 or NaN.
pub fn q(d: f64, tol: f64) -> Estimate {
    if d.is_nan() || d < 0.0 {
        return invalid();
    }
    let mut e = graded_unit_integral(&[d], clean_tol(tol), MAX_PANELS, |mu| {
        if mu <= 0.0 { 0.0 } else { 2.0 * (-d / mu).exp() * mu }
    });
    // Rounding of the logarithmic node placement, as in `g`: for d < 1 the nodes above μ = d come
    // from exp of values up to ln(1/d), perturbed by that many ulps (seen as Q(2e-205) off by
    // 1.6e-14 against an estimate of 1.2e-14); the quadrature estimate does not include it.
    if d > 0.0 && d < 1.0 {
        e.error += 8.0 * f64::EPSILON * (1.0 - d.ln());
    }
    e
}

/// Q(d) = 2 E₃(d) exactly.
pub fn q_exact(d: f64) -> f64 {
    2.0 * e3(d)
}

/// E₃(x) = ∫₁^∞ e^{−xt} t^{−3} dt.
pub fn e3(x: f64) -> f64 {
    expn(3, x)
}

/// Exponential integral E_n(x) = ∫₁^∞ e^{−xt} t^{−n} dt for x ≥ 0 (x > 0 when n ≤ 1), to a few
/// ulps relative: power series for x ≤ 1, modified-Lentz continued fraction beyond
/// (Numerical Recipes §6.3). E_n(0) = 1/(n − 1) for n ≥ 2. NaN outside the domain.
pub fn expn(n: u32, x: f64) -> f64 {
    const EULER: f64 = 0.577_215_664_901_532_9;
    const EPS: f64 = 1e-17;
    if x.is_nan() || x < 0.0 || (x == 0.0 && n <= 1) {
        return f64::NAN;
    }
    if x == f64::INFINITY {
        return 0.0;
    }
    if n == 0 {
        return (-x).exp() / x;
    }
    let nm1 = (n - 1) as f64;
    if x == 0.0 {
        return 1.0 / nm1;
    }
    if x > 1.0 {
        let tiny = 1e-300;
        let mut b = x + n as f64;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let fi = i as f64;
            let an = -fi * (nm1 + fi);
            b += 2.0;
            d = 1.0 / (an * d + b);
            c = b + an / c;
            let del = c * d;
            h *= del;
            if (del - 1.0).abs() < EPS {
                break;
            }
        }
        h * (-x).exp()
    } else {
        let mut ans = if n == 1 { -x.ln() - EULER } else { 1.0 / nm1 };
        let mut fact = 1.0;
        for i in 1..1000u32 {
            let fi = i as f64;
            fact *= -x / fi;
            let del = if i != n - 1 {
                -fact / (fi - nm1)
            } else {
                let psi = -EULER + (1..n).map(|k| 1.0 / k as f64).sum::<f64>();
                fact * (-x.ln() + psi)
            };
            ans += del;
            if del.abs() < ans.abs() * EPS {
                break;
            }
        }
        ans
    }
}

#[cfg(test)]
mod tests {
    use super::super::DEFAULT_TOL;
    use super::*;
    use crate::integrate::{Tolerance, adaptive};
    /// G at subnormal d (or μv) takes its limit with a bound instead of quadrature nodes that
    /// would need 1/d: G ≤ d/μv, so at d = 1e-310 the value is 0 within that bound, with μv
    /// = 0.5 and with μv = 1e-300 (where d/μv = 1e-10 is still far below 1); at μv = c =
    /// 1e-310 with d = 0.5, G → 1, and the error stated must cover 1 − G, which is at least
    /// ∫ (1 − μ/(μ + μv)) dμ = c ln((1 + c)/c) ≈ 7.1e-308 (the integrand's second factor alone;
    /// 1 − 1e-9 for the rounding of a subnormal c, 5e-14 relative).
    #[test]
    fn g_at_subnormal_arguments_is_its_limit() {
        for mu_v in [0.5, 1e-300] {
            let e = g(1e-310, mu_v, 1e-9);
            assert!(e.value == 0.0 && e.error <= 1e-310 / mu_v * (1.0 + 1e-12) && e.error > 0.0, "μv {mu_v:e}: {e:?}");
        }
        let c = 1e-310f64;
        let e = g(0.5, c, 1e-9);
        let least = c * ((1.0 + c).ln() - c.ln());
        assert!(least > 7e-308, "{least:e}");
        assert!(e.value == 1.0 && e.error >= least * (1.0 - 1e-9) && e.error <= 1.0, "{e:?}, 1 − G ≥ {least:e}");
    }

    #[test]
    fn exponential_integrals() {
        // Reference values (Abramowitz & Stegun 5.1, to 17 digits); a few ulps relative.
        let close = |a: f64, b: f64| (a - b).abs() <= 4.0 * f64::EPSILON * b.abs();
        assert!(close(expn(1, 1.0), 0.219_383_934_395_520_27));
        assert!(close(expn(2, 1.0), 0.148_495_506_775_922_05));
        assert!(close(e3(1.0), 0.109_691_967_197_760_13), "{}", e3(1.0));
        assert_eq!(e3(0.0), 0.5);
        assert!(expn(1, 0.0).is_nan() && expn(3, -1.0).is_nan());
        // NaN outside the domain for every n, also where the formulas would give a number: E₀'s
        // closed form e^{−x}/x at x = −1, and E₁₀'s series at x = −1e-3, which converges before
        // its ln x term; NaN in, NaN out.
        assert!(expn(0, -1.0).is_nan() && expn(10, -1e-3).is_nan() && expn(2, f64::NAN).is_nan());
        // Recurrence n E_{n+1}(x) = e^{−x} − x E_n(x), across the series/fraction switch at 1;
        // at n = 0 it is E₀(x) = e^{−x}/x, the integral ∫₁^∞ e^{−xt} dt in closed form.
        for &x in &[1e-8, 0.01, 0.3, 0.999, 1.0, 1.001, 2.5, 10.0, 50.0] {
            for n in 0..5u32 {
                let lhs = n as f64 * expn(n + 1, x);
                let rhs = (-x).exp() - x * expn(n, x);
                assert!((lhs - rhs).abs() <= 1e-14 * lhs.abs().max((-x).exp()), "n={n} x={x}");
            }
        }
        // Large x: E₃(x) x e^x = 1 − 3/x + 12/x² − 60/x³ + 360/x⁴ − …; at x = 500 the next term
        // is 2520/x⁵ = 8e-11.
        let x: f64 = 500.0;
        let s = e3(x) * x.exp() * x;
        let series = 1.0 - 3.0 / x + 12.0 / x.powi(2) - 60.0 / x.powi(3) + 360.0 / x.powi(4);
        assert!((s - series).abs() < 1e-10, "{s} vs {series}");
    }

    #[test]
    fn q_matches_two_e3() {
        // Quadrature at 1e-14: 1e-12 bounds quadrature plus rounding.
        // At d = 0 there are no logarithmic nodes (and ln d is −∞): the error stated is the
        // quadrature's alone, under the asked tolerance.
        let e = q(0.0, DEFAULT_TOL);
        assert!((e.value - 1.0).abs() < 1e-15);
        assert!(e.error <= DEFAULT_TOL, "{e:?}");
        assert_eq!(q_exact(0.0), 1.0);
        for &d in &[1e-9, 1e-6, 0.01, 0.1, 0.25, 0.5, 1.0, 2.0, 5.0, 30.0] {
            let e = q(d, 1e-14);
            assert!((e.value - q_exact(d)).abs() < 1e-12, "d={d}: {e:?} vs {}", q_exact(d));
            let dflt = q(d, DEFAULT_TOL);
            assert!(
                (dflt.value - q_exact(d)).abs() <= dflt.error.max(1e-15),
                "d={d}: {dflt:?} vs {}",
                q_exact(d)
            );
        }
    }

    #[test]
    fn g_matches_closed_form_and_limits() {
        // Quadrature at 1e-13 against the E₁/E₂ closed form: 1e-12 bounds both. The closed form
        // cancels terms of size ~|ln d|: its rounding allowance is 1e-15 (1 + |ln d|).
        for &d in &[1e-7, 1e-4, 0.01, 0.1, 0.3, 0.5] {
            for &mu in &[1e-6, 0.01, 0.2, 0.5, 0.9, 1.0] {
                let e = g(d, mu, 1e-13);
                let x = g_exact(d, mu);
                let rounding = 1e-15 * (1.0 + d.ln().abs());
                assert!((e.value - x).abs() < 1e-12, "d={d} μv={mu}: {e:?} vs {x}");
                let dflt = g(d, mu, DEFAULT_TOL);
                assert!(
                    (dflt.value - x).abs() <= dflt.error + rounding,
                    "d={d} μv={mu}: {dflt:?} vs {x}"
                );
                assert!(dflt.error <= DEFAULT_TOL);
            }
        }
        // μv → 0: 1 − G ≈ μv ln(1/μv) (the first two closed-form terms); 2μv(1 + ln(1/μv))
        // bounds it for d = 0.3.
        assert_eq!(g(0.3, 0.0, DEFAULT_TOL).value, 1.0);
        for &mu in &[1e-3, 1e-5, 1e-8] {
            let e = g(0.3, mu, 1e-13);
            assert!(
                1.0 - e.value >= 0.0 && 1.0 - e.value <= 2.0 * mu * (1.0 - mu.ln()),
                "μv={mu}: {e:?}"
            );
        }
        // d → 0: G = d/μv − (d²/2μv) ln(1/d) + O(d²): the remainder over d² stays bounded
        // (by (1 + 1/μv)/μv for these μv) while the log term grows.
        for &mu in &[0.2, 0.5, 1.0] {
            for &d in &[1e-3, 1e-4, 1e-5, 1e-6] {
                let x = g_exact(d, mu);
                let rem = (x - d / mu + d * d / (2.0 * mu) * (1.0 / d).ln()) / (d * d);
                assert!(rem.abs() <= (1.0 + 1.0 / mu) / mu, "μv={mu} d={d}: remainder/d² = {rem}");
            }
        }
    }

    /// G at the smallest normal arguments is integrated to the asked tolerance; only subnormal
    /// ones take the limit (`g`'s comment: there the nodes would need 1/d or 1/μv). At
    /// μv = 2⁻¹⁰²², d = 2μv (d/μv = 2), G = 1 − e^{−2}E₂(d) + … ≈ 1 − e^{−2} by the closed form,
    /// which has no cancellation here (rounding ~1e-15, and the O(c ln c) terms ~1e-305): the
    /// default tolerance bounds the difference, where the limit would give 1, off by
    /// e^{−2} ≈ 0.135. At d = 2⁻¹⁰²², μv = ½, G = (d/μv)(1 − (d/2) ln(1/d) + O(d)) (module
    /// doc) ≈ 2d: integrated (evaluations spent), within its estimate of it in absolute terms.
    #[test]
    fn g_at_the_smallest_normal_arguments_is_integrated() {
        let c = f64::MIN_POSITIVE;
        let e = g(2.0 * c, c, DEFAULT_TOL);
        let want = g_exact(2.0 * c, c);
        assert!((want - (1.0 - (-2f64).exp())).abs() < 1e-12, "closed form {want}");
        assert!((e.value - want).abs() <= DEFAULT_TOL && e.error <= DEFAULT_TOL, "{e:?} vs {want}");
        let d = f64::MIN_POSITIVE;
        let e = g(d, 0.5, DEFAULT_TOL);
        assert!(e.evals > 0 && (e.value - 2.0 * d).abs() <= e.error && e.error <= DEFAULT_TOL, "{e:?}");
    }

    /// With both arguments subnormal and equal, d = μv = c = 1e-310, G → 1 − e^{−1} as c → 0
    /// (closed form: e^{−d/c} E₂(d) → e^{−1}, the other terms are O(c ln c) ≈ 7e-308). The limit
    /// returned is 1, the nearer of 0 and 1, and its error is the bound of `g`'s comment,
    /// c (1 − ln c) + e^{−d/c} + c E₁(d (1 + c)/c) = e^{−1} + 7e-308: at least 1 − G = e^{−1}
    /// and, e^{−1} being the whole of it in f64, no more (2 ulps for exp's rounding).
    #[test]
    fn g_with_both_arguments_subnormal_states_the_documented_bound() {
        let c = 1e-310;
        let e = g(c, c, DEFAULT_TOL);
        let bound = (-1f64).exp();
        assert!(e.value == 1.0, "{e:?}");
        assert!((e.error - bound).abs() <= 2.0 * f64::EPSILON * bound, "{e:?}, 1 − G = e⁻¹ = {bound}");
    }

    /// Q's error covers the rounding of its logarithmic node placement: at d = 2e-205 (the case
    /// of `q`'s comment) the nodes above μ = d come from exp of values down to ln d ≈ −471, each
    /// perturbed by ~471 ulps, and the quadrature estimate alone was below the actual error
    /// against 2E₃(d) (E₃ by its series: a few ulps of Q ≈ 1, 1e-15).
    #[test]
    fn q_error_covers_the_node_rounding_at_tiny_density() {
        for d in [2e-205, 1e-100, 1e-30] {
            let e = q(d, DEFAULT_TOL);
            let want = q_exact(d);
            assert!((e.value - want).abs() <= e.error + 1e-15 && e.error <= DEFAULT_TOL, "d = {d:e}: {e:?} vs {want}");
            assert!(e.error >= 8.0 * f64::EPSILON * (1.0 - d.ln()), "d = {d:e}: {e:?}");
        }
    }

    /// `graded_unit_integral` splits at interior cuts only: cuts at 0 and 1 are no cuts, and
    /// with none the one piece is `crate::integrate::adaptive` over [0, 1] at the whole
    /// tolerance (tol / number of pieces), the same bits and evaluations. The integrand
    /// 1/(μ + 0.01) needs bisections, and over tolerances 1e-6 … 1e-13 halving any of them
    /// changes the panels taken at least once (the direct counts must differ between the two).
    #[test]
    fn graded_unit_integral_cuts_only_inside_the_unit_interval() {
        let f = |mu: f64| 1.0 / (mu + 0.01);
        let mut halving_shows = false;
        for tol in [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13] {
            let tl = Tolerance { abs: tol, rel: 0.0, max_panels: MAX_PANELS };
            let direct = adaptive(0.0, 1.0, tl, f);
            halving_shows |= adaptive(0.0, 1.0, Tolerance { abs: 0.5 * tol, ..tl }, f).evals != direct.evals;
            for cuts in [&[][..], &[0.0], &[1.0], &[0.0, 1.0, 0.0]] {
                let e = crate::integrate::graded_unit_integral(cuts, tol, MAX_PANELS, f);
                assert_eq!((e.value.to_bits(), e.error.to_bits(), e.evals), (direct.value.to_bits(), direct.error.to_bits(), direct.evals), "tol {tol:e}, cuts {cuts:?}");
            }
        }
        assert!(halving_shows, "no tolerance here tells a halved share from the whole");
    }
}
