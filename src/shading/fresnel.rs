//! Fresnel terms: Schlick's weight and its hemispherical average, the exact dielectric
//! reflectance and its average.

use super::hemisphere::{tolerance, MAX_PANELS};
use crate::integrate::{Estimate, Tolerance};

/// Hemispherical (cosine-weighted) average of Schlick's Fresnel, closed form:
/// 2∫₀¹ (F0 + (1 − F0)(1 − μ)⁵) μ dμ = F0 + (1 − F0)·2·B(2, 6) = F0 + (1 − F0)/21.
pub fn f_avg_schlick(f0: f64) -> f64 {
    f0 + (1.0 - f0) / 21.0
}

/// Unpolarised Fresnel reflectance of a dielectric interface of relative index η at incidence
/// cosine c (1 under total internal reflection).
pub fn fresnel_dielectric(c: f64, eta: f64) -> f64 {
    let g2 = eta * eta - 1.0 + c * c;
    if g2 <= 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// F_avg(η) = 2∫₀¹ F(μ, η) μ dμ (numerical: no closed form is used; the integrand has a
/// square-root kink at the critical angle μ = sqrt(1 − η²) when η < 1, a breakpoint here, and
/// each piece goes through the smoothstep map).
pub fn f_avg_dielectric(eta: f64, tol: f64) -> Estimate {
    let tol = tolerance(tol);
    let mut cuts = vec![0.0];
    if eta < 1.0 {
        cuts.push(((1.0 - eta) * (1.0 + eta)).sqrt());
    }
    cuts.push(1.0);
    let mut out = Estimate { value: 0.0, error: 0.0, evals: 0 };
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let r = crate::integrate::adaptive(0.0, 1.0, Tolerance { abs: 0.5 * tol, rel: 0.0, max_panels: MAX_PANELS }, |t| {
            let mu = a + (b - a) * t * t * (3.0 - 2.0 * t);
            2.0 * fresnel_dielectric(mu, eta) * mu * 6.0 * (b - a) * t * (1.0 - t)
        });
        out.value += r.value;
        out.error += r.error;
        out.evals += r.evals;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact Fresnel factor against the textbook s and p amplitudes, r_s = (c − η c_t)/(c +
    /// η c_t), r_p = (η c − c_t)/(η c + c_t), c_t from Snell's law, F = (r_s² + r_p²)/2, for
    /// external and internal incidence: the two are the same function written apart (Born &
    /// Wolf §1.5). Away from the critical angle (1e-3 in cosine, where both square roots
    /// amplify the rounding of their argument by up to 1/(2g), g ≥ 0.03) they agree to a few
    /// roundings: 1e-13. Below the critical cosine the reflection is total, exactly 1; at
    /// normal incidence ((η − 1)/(η + 1))².
    #[test]
    fn fresnel_dielectric_is_the_textbook_s_and_p_average() {
        let textbook = |c: f64, eta: f64| {
            let st = (1.0 - c * c).sqrt() / eta;
            let ct = (1.0 - st * st).sqrt();
            let rs = (c - eta * ct) / (c + eta * ct);
            let rp = (eta * c - ct) / (eta * c + ct);
            0.5 * (rs * rs + rp * rp)
        };
        for eta in [1.1f64, 1.5, 2.4, 0.7, 1.0 / 1.33] {
            let critical = if eta < 1.0 { (1.0 - eta * eta).sqrt() } else { 0.0 };
            for i in 0..400 {
                let c = (i as f64 + 0.5) / 400.0;
                let got = fresnel_dielectric(c, eta);
                if c < critical {
                    assert_eq!(got, 1.0, "η {eta}, c {c}: total internal reflection");
                } else if c > critical + 1e-3 {
                    let want = textbook(c, eta);
                    assert!((got - want).abs() < 1e-13, "η {eta}, c {c}: {got} vs {want}");
                }
            }
            let normal = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, eta) - normal).abs() < 1e-15, "η {eta}: {}", fresnel_dielectric(1.0, eta));
        }
    }

    /// F_avg(η) = 2∫₀¹ F μ dμ against its closed form for η > 1,
    ///   ½ + (η − 1)(3η + 1)/(6(η + 1)²) + η²(η² − 1)²/(η² + 1)³ · ln((η − 1)/(η + 1))
    ///   − 2η³(η² + 2η − 1)/((η² + 1)(η⁴ − 1)) + 8η⁴(η⁴ + 1)/((η² + 1)(η⁴ − 1)²) · ln η
    /// (the diffuse reflectance of a smooth dielectric lit from the rarer side, integrated term
    /// by term; it agrees with scipy's quad of the textbook F to 3e-16 at η = 1.1 … 3), and for
    /// η < 1 by reciprocity through the interface, F_avg(1/η) = 1 − (1 − F_avg(η))/η². The
    /// quadrature is asked for 1e-13; at η = 1.05 the closed form's terms reach 10 and cancel
    /// to 1e-2, 1e-14 of rounding: 1e-12 bounds both.
    #[test]
    fn dielectric_average_is_the_closed_form_and_reciprocal() {
        let closed = |n: f64| {
            let (n2, n4) = (n * n, n.powi(4));
            0.5 + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0).powi(2))
                + n2 * (n2 - 1.0).powi(2) / (n2 + 1.0).powi(3) * ((n - 1.0) / (n + 1.0)).ln()
                - 2.0 * n.powi(3) * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * (n4 - 1.0))
                + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * (n4 - 1.0).powi(2)) * n.ln()
        };
        for eta in [1.05, 1.33, 1.5, 2.0, 3.0] {
            let (got, want) = (f_avg_dielectric(eta, 1e-13).value, closed(eta));
            assert!((got - want).abs() < 1e-12, "η {eta}: {got} vs {want}");
            let inner = f_avg_dielectric(1.0 / eta, 1e-13).value;
            let want = 1.0 - (1.0 - want) / (eta * eta);
            assert!((inner - want).abs() < 1e-12, "η 1/{eta}: {inner} vs {want}");
        }
    }

    #[test]
    fn schlick_average_matches_quadrature() {
        // The closed form against the 1-D integral at 1e-14 (the integrator's requested tolerance).
        for &f0 in &[0.0, 0.04, 0.5, 1.0] {
            let r = crate::integrate::adaptive(0.0, 1.0, Tolerance { abs: 1e-15, rel: 0.0, max_panels: 100 }, |m| {
                2.0 * (f0 + (1.0 - f0) * (1.0 - m).powi(5)) * m
            });
            assert!((r.value - f_avg_schlick(f0)).abs() < 1e-14);
        }
        // η = 1: no reflection; η → ∞: total reflection.
        assert!(f_avg_dielectric(1.0, 1e-14).value.abs() < 1e-14);
        assert!(f_avg_dielectric(1e6, 1e-12).value > 0.999);
    }

    /// F_avg's estimate adds up its pieces (two for η < 1, split at the critical angle): at
    /// least one 21-point panel each, at most `MAX_PANELS` each (a bisection adds 42
    /// evaluations), and an error estimate that is positive (a quadrature of a non-polynomial
    /// is not certified exact) and within the tolerance.
    #[test]
    fn dielectric_average_adds_up_its_pieces_evaluations_and_errors() {
        for eta in [1.0 / 1.5, 1.5] {
            let pieces = if eta < 1.0 { 2 } else { 1 };
            let r = f_avg_dielectric(eta, 1e-10);
            assert!(r.evals >= 21 * pieces && r.evals <= pieces * (21 + 42 * MAX_PANELS as u64), "η {eta}: {r:?}");
            assert!(r.error > 0.0 && r.error <= 1e-10, "η {eta}: {r:?}");
        }
    }
}
