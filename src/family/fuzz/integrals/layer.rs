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
