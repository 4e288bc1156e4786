//! The GGX split-sum integrals: the environment BRDF ("DFG") scale and bias, the directional
//! albedo E(μ) and its cosine-weighted average E_avg, and the hemispherical Fresnel averages.
//!
//! # Conventions (the contract)
//!
//! Normal n = +z; the view v = (sin θv, 0, μv) lies in the xz-plane, μv = n·v ∈ [0, 1]; a light
//! direction l has μl = n·l. GGX (Trowbridge–Reitz) with α = perceptual roughness²:
//! ```text
//! D(h)   = α² / (π ((n·h)²(α² − 1) + 1)²)
//! Λ(μ)   = (−1 + sqrt(1 + α² tan²θ)) / 2,          tan²θ = (1 − μ²)/μ²
//! G2     = 1 / (1 + Λ(μv) + Λ(μl))                 (height-correlated Smith)
//! Fc     = (1 − v·h)⁵                              (Schlick's Fresnel weight)
//! f      = D G2 / (4 μv μl)
//! scale  = ∫_{μl ≥ c} (1 − Fc) f μl dω_l,    bias = ∫_{μl ≥ c} Fc f μl dω_l,    c = cos_cone
//! E(μv)  = scale + bias  (F = 1),            E_avg = 2 ∫₀¹ E(μ) μ dμ
//! ```
//! so that the split-sum specular of a Schlick F0 is F0·scale + bias (F90 = 1). c = 0 is the
//! hemisphere; c > 0 keeps the light directions in the visibility cone of half-angle acos c
//! about n (COD: WWII specular occlusion). A second shadowing model, [`Shadowing::Separable`],
//! is UE4's image-based-lighting G (Schlick–Smith G1(μ) = μ/(μ(1 − k) + k) for v and l,
//! multiplied, with k = α/2): the integral Karis's mobile fit was made against.
//!
//! # Integration
//!
//! Every integral here is the generic hemispherical operator of the shading layer
//! (`crate::shading::hemisphere`) over the GGX lobe (`crate::shading::trowbridge_reitz`): the
//! lobe's measure is the GGX sampler (ξ, φ), in which the spike at α = 10⁻³ unfolds into a
//! smooth weight G2 (v·h)/(μv μh) over the unit square; its switch angle θ* = atan(10α) and
//! its G2 pole below the horizon are the lobe's features, which the operator's breakpoints and
//! azimuth panels follow (both documented there).
//!
//! # Limits
//! - μv → 0: G2/μv stays finite (μv Λ(μv) → α/2), so the integrand is evaluated in the product
//!   form 1/(μv + μvΛ(μv) + μvΛ(μl)) and n·v = 0 gives the limit, not 0/0.
//! - α → 0: D → δ(h − n), l → mirror(v): E → 1 and bias → (1 − μv)⁵ (for μv ≥ c); α = 0 gives
//!   this limit exactly.
//! - c → 1: the cone closes: scale = bias = 0 (c = 1 exactly: empty region, exact 0).
//! - E(μ = 1, α = 1) = 1 − ln 2 (height-correlated G2), derived in [`albedo_normal_rough`].

use crate::integrate::Estimate;
use crate::shading::hemisphere::{self, split_sum_with};
use crate::shading::trowbridge_reitz::Ggx;

pub use crate::shading::fresnel::{f_avg_dielectric, f_avg_schlick, fresnel_dielectric};
pub use crate::shading::hemisphere::{Inner, DEFAULT_TOL};
pub use crate::shading::trowbridge_reitz::{lambda, Shadowing};

/// scale and bias with their error estimates.
pub type EnvEstimate = hemisphere::SplitSum;

/// The split-sum scale and bias (see the module doc) to absolute tolerance `tol` on each.
/// Parameters are taken as given (the caller checks domains): α ∈ [0, 1], μv, c ∈ [0, 1].
pub fn env(alpha: f64, mu_v: f64, cos_cone: f64, shadowing: Shadowing, tol: f64) -> EnvEstimate {
    env_with(alpha, mu_v, cos_cone, shadowing, tol, Inner::Nested)
}

/// [`env`] with a choice of the inner rule.
pub fn env_with(alpha: f64, mu_v: f64, cos_cone: f64, shadowing: Shadowing, tol: f64, inner: Inner) -> EnvEstimate {
    split_sum_with(&Ggx::new(alpha, shadowing), mu_v, cos_cone, tol, inner)
}

/// E(μv) = scale + bias with F = 1 (height-correlated), to absolute tolerance `tol`.
pub fn albedo(alpha: f64, mu_v: f64, tol: f64) -> Estimate {
    hemisphere::albedo(&Ggx::new(alpha, Shadowing::HeightCorrelated), mu_v, tol)
}

/// E_avg(α) = 2 ∫₀¹ E(μ) μ dμ to absolute tolerance `tol` (height-correlated).
pub fn albedo_avg(alpha: f64, tol: f64) -> Estimate {
    hemisphere::albedo_avg(&Ggx::new(alpha, Shadowing::HeightCorrelated), tol)
}

/// E(1) at α = 1 in closed form: 1 − ln 2.
///
/// At α = 1, D = 1/π (uniform in n·h over the hemisphere) and Λ(μ) = (−1 + 1/μ)/2, so for
/// μv = 1 (Λ(v) = 0) G2 = 1/(1 + Λ(l)) = 2μl/(1 + μl) and
/// E = ∫ D G2/(4 μl) μl dω_l = (1/4π) ∫ 2μl/(1 + μl) dω_l = ∫₀¹ μ/(1 + μ) dμ = 1 − ln 2.
pub fn albedo_normal_rough() -> f64 {
    1.0 - std::f64::consts::LN_2
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    const HC: Shadowing = Shadowing::HeightCorrelated;

    /// E_avg's evaluation count is its outer rule's and every inner E's: at least one 21-point
    /// Kronrod panel outside, and at each of its nodes (all inside (0, 1), where the smoothstep's
    /// Jacobian is not 0) an E of at least one 21-point panel of its own: 21 + 21·21.
    #[test]
    fn albedo_avgs_evaluations_count_its_inner_integrals() {
        let e = albedo(0.5, 0.5, 1e-4);
        assert!(e.evals >= 21, "{e:?}");
        let avg = albedo_avg(0.5, 1e-4);
        assert!(avg.evals >= 21 + 21 * 21, "{avg:?}");
    }

    /// E_avg's error and count add its inner E's to the outer rule's. At α = 0 every E is the
    /// mirror limit, exact (error 0) with no evaluation, and the outer integrand 2·E·μ·dμ/dt is
    /// a degree-5 polynomial in t (E = 1 to rounding), which the first G10/K21 panel on [0, 1]
    /// integrates to rounding: 21 evaluations and E_avg = 2∫₀¹ μ dμ = 1. At α = ½ the first
    /// panel's centre t = ½ is a node, at μ = ½·½·(3 − 1) = ½, so the reported error is at least
    /// that inner E's own (the outer error is not negative).
    #[test]
    fn albedo_avgs_error_and_count_add_the_inner_integrals() {
        let exact = albedo_avg(0.0, 1e-6);
        // The 21-term Kronrod sum of values ≤ 3 rounds to a few ε.
        assert!(exact.evals == 21 && (exact.value - 1.0).abs() < 1e-14, "{exact:?}");
        let (avg, mid) = (albedo_avg(0.5, 1e-4), albedo(0.5, 0.5, 0.5e-4));
        assert!(mid.error > 0.0 && avg.error >= mid.error, "E_avg {avg:?}, E(½) {mid:?}");
    }

    /// Smith's Λ of GGX against two references of its own. The textbook form
    /// Λ = (−1 + sqrt(1 + α² tan²θ))/2 (Heitz 2014, "Understanding the masking-shadowing
    /// function", GGX's Λ), to 1e-13 relative away from μ = 1 (where the textbook form cancels).
    /// And the projected area of the microsurface, ∫ ⟨ω·m⟩ D(m) dm = μ (1 + Λ(μ)) (Heitz 2014,
    /// the normalisation of G1 = 1/(1 + Λ)): the azimuth integral of ⟨ω·m⟩ in closed form,
    /// 2π a when b ≤ a, else 2(a φ* + b sin φ*) with cos φ* = −a/b (a = μ cos θm,
    /// b = sin θ sin θm), the polar one by the midpoint rule on 20 000 cells of θm ∈ [0, π/2],
    /// where D sin θm is smooth (finite at π/2) and the kink where b = a costs O(h²) too. The
    /// same rule gives ∫ D cos θm dm = 1 within 5.8e-9 (α = 0.3; bound 2e-8), and the identity
    /// within 5.7e-9 relative at these nine points: 1e-7 leaves a margin of 17.
    #[test]
    fn lambda_is_smiths_and_gives_the_microsurfaces_projected_area() {
        for &alpha in &[0.1f64, 0.5, 1.0, 2.0] {
            for &mu in &[0.05f64, 0.3, 0.7] {
                let tan2 = (1.0 - mu * mu) / (mu * mu);
                let want = 0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0);
                assert!((lambda(alpha, mu) - want).abs() <= 1e-13 * want, "α {alpha}, μ {mu}: {} vs {want}", lambda(alpha, mu));
            }
        }
        let n = 20_000;
        let h = 0.5 * PI / n as f64;
        for &alpha in &[0.3, 0.7, 1.0] {
            let d = |t: f64| {
                let (s, c) = t.sin_cos();
                let x = (s / c).powi(2) / (alpha * alpha) + 1.0;
                1.0 / (PI * alpha * alpha * c.powi(4) * x * x)
            };
            let cells = || (0..n).map(|i| (i as f64 + 0.5) * h);
            let norm: f64 = cells().map(|t| d(t) * t.sin() * t.cos() * 2.0 * PI * h).sum();
            assert!((norm - 1.0).abs() < 2e-8, "α {alpha}: ∫ D cos = {norm}");
            for &mu in &[0.1f64, 0.5, 0.9] {
                let sin_o = (1.0 - mu * mu).sqrt();
                let area: f64 = cells()
                    .map(|t| {
                        let (a, b) = (mu * t.cos(), sin_o * t.sin());
                        let phi = if b <= a { 2.0 * PI * a } else {
                            let p = (-a / b).acos();
                            2.0 * (a * p + b * p.sin())
                        };
                        d(t) * t.sin() * phi * h
                    })
                    .sum();
                let want = mu * (1.0 + lambda(alpha, mu));
                assert!((area - want).abs() <= 1e-7 * want, "α {alpha}, μ {mu}: projected area {area} vs μ(1 + Λ) {want}");
            }
        }
    }

    #[test]
    fn normal_incidence_at_alpha_one_is_one_minus_ln2() {
        // The closed form of albedo_normal_rough; the tolerance is the integrator's requested 1e-12.
        let e = albedo(1.0, 1.0, 1e-12);
        assert!((e.value - albedo_normal_rough()).abs() < 2e-12, "{} vs {}", e.value, albedo_normal_rough());
    }

    #[test]
    fn albedo_never_exceeds_one_and_smooth_limit_holds() {
        for &alpha in &[1e-3, 1e-2, 0.1, 0.5, 1.0] {
            for &mu in &[0.0, 1e-4, 0.01, 0.3, 0.7, 1.0] {
                let e = albedo(alpha, mu, 1e-10);
                assert!(e.value <= 1.0 + e.error && e.value > 0.0, "α={alpha} μ={mu}: {e:?}");
            }
        }
        // α → 0: E → 1, bias → (1 − μ)⁵. At α = 1e-4 the deviation is O(α) at these μ (the
        // lobe's width); 1e-3 bounds it with margin.
        for &mu in &[0.2, 0.5, 0.9, 1.0] {
            let r = env(1e-4, mu, 0.0, HC, 1e-11);
            assert!((r.scale + r.bias - 1.0).abs() < 1e-3, "μ={mu}: {r:?}");
            assert!((r.bias - (1.0 - mu).powi(5)).abs() < 1e-3, "μ={mu}: {r:?}");
        }
    }

    #[test]
    fn the_closing_cone_removes_everything() {
        assert_eq!(env(0.3, 0.5, 1.0, HC, 1e-10).scale, 0.0);
        // Near c = 1 the region is a cap of solid angle 2π(1 − c): the integrals vanish with it.
        let r = env(0.3, 0.9, 0.9999, HC, 1e-12);
        assert!(r.scale < 1e-3 && r.bias < 1e-3, "{r:?}");
        let open = env(0.3, 0.9, 0.0, HC, 1e-12);
        let half = env(0.3, 0.9, 0.5, HC, 1e-12);
        assert!(half.scale < open.scale && half.bias <= open.bias);
    }

    #[test]
    fn nested_inner_rules_agree_with_adaptive_panels() {
        // The nested azimuth rules against the adaptive G10/K21 reference at 1e-12, over small
        // α, grazing n·v, cones and both shadowing models: each result is within its own error
        // estimate plus the reference's tolerance, and that estimate is within the requested
        // tolerance (the contract).
        for shadowing in [HC, Shadowing::Separable { k: 0.15 }] {
            for &alpha in &[1e-6, 1.5e-5, 1e-3, 0.05, 0.3, 0.8, 1.0] {
                for &mu in &[0.0, 1e-4, 0.004, 0.2, 0.7, 0.999, 1.0] {
                    for &c in &[0.0, 0.3, 0.9] {
                        for &tol in &[1e-7, 1e-10] {
                            let r = env(alpha, mu, c, shadowing, tol);
                            let t = env_with(alpha, mu, c, shadowing, 1e-12, Inner::Adaptive);
                            let err = (r.scale - t.scale).abs().max((r.bias - t.bias).abs());
                            assert!(r.error <= tol, "{shadowing:?} α={alpha} μ={mu} c={c} tol={tol}: {r:?}");
                            assert!(err <= r.error + 2e-12, "{shadowing:?} α={alpha} μ={mu} c={c} tol={tol}: {err:e} > {:e}", r.error);
                        }
                    }
                }
            }
        }
    }

    /// A non-positive or NaN tolerance means [`DEFAULT_TOL`] (its doc): the same estimate, bit
    /// for bit, as asking for it. A positive one is taken as given: 1e-4 is met with fewer
    /// evaluations than the default's 1e-10.
    #[test]
    fn non_positive_and_nan_tolerances_mean_the_default() {
        let at = |tol: f64| env(0.5, 0.5, 0.2, HC, tol);
        let default = at(DEFAULT_TOL);
        let loose = at(1e-4);
        assert!(loose.error <= 1e-4 && loose.evals < default.evals, "{loose:?} vs {default:?}");
        for tol in [f64::NAN, -1.0, 0.0] {
            assert_eq!(at(tol), default, "tol {tol}");
        }
    }

    /// E = scale + bias, each within env's error, so E's error is twice it, and `albedo` asks env
    /// for half its own tolerance: E is within `tol`, and within its error of the truth. At
    /// (α, μ) = (1, 1) the truth is 1 − ln 2 (`albedo_normal_rough`); at (0.1, 0.3) it is the
    /// integral with the adaptive azimuth rule at 1e-12 (independent of the nested rules), whose
    /// own 1e-12 (twice, for the sum) is added to the bound.
    #[test]
    fn albedo_is_within_its_tolerance_and_its_error_of_the_truth() {
        let reference = env_with(0.1, 0.3, 0.0, HC, 1e-12, Inner::Adaptive);
        for (alpha, mu, truth) in [(1.0, 1.0, albedo_normal_rough()), (0.1, 0.3, reference.scale + reference.bias)] {
            for tol in [1e-6, 1e-9] {
                let e = albedo(alpha, mu, tol);
                assert!(e.error <= tol, "α {alpha}, μ {mu}, tol {tol}: {e:?}");
                assert!((e.value - truth).abs() <= e.error + 2e-12, "α {alpha}, μ {mu}, tol {tol}: {e:?} vs {truth}");
            }
        }
    }

    /// α = 0 is the mirror limit exactly (module doc): l = mirror(v), μl = μv, Schlick's weight
    /// (1 − μv)⁵, so (scale, bias) = (1 − (1 − μv)⁵, (1 − μv)⁵) where the mirror direction is in
    /// the cone (μv ≥ c, its edge included), else nothing. By hand, exact in binary: μv = ½
    /// gives bias 1/32 and scale 31/32; μv = 0 at c = 0 (the horizon) bias 1 and scale 0.
    #[test]
    fn alpha_zero_is_the_mirror_limit_in_and_out_of_the_cone() {
        let mirror = |mu: f64, c: f64| {
            let r = env(0.0, mu, c, HC, 1e-10);
            (r.scale, r.bias, r.error)
        };
        assert_eq!(mirror(0.5, 0.0), (31.0 / 32.0, 1.0 / 32.0, 0.0));
        assert_eq!(mirror(0.5, 0.5), (31.0 / 32.0, 1.0 / 32.0, 0.0));
        assert_eq!(mirror(0.0, 0.0), (0.0, 1.0, 0.0));
        assert_eq!(mirror(0.5, 0.6), (0.0, 0.0, 0.0));
    }

    /// env counts every evaluation, the azimuth integrands' included. At μv = 1 (sin θv = 0)
    /// the azimuth integrand does not depend on φ and covers [0, π] at every outer node (all
    /// inside θh ∈ (0, π/4), where μl > 0 for every φ): the nested trapezoid takes N = 4 (5
    /// nodes) and N = 8 (4 new ones), which agree, so a node costs 1 + 9 evaluations and a
    /// 21-point Kronrod panel 210; with the adaptive azimuth rule one G10/K21 panel on [0, π]
    /// converges at once, 1 + 21 a node and 462 a panel. Both cover the same outer panels.
    #[test]
    fn env_counts_the_evaluations_of_its_inner_integrals() {
        for tol in [1e-3, 1e-10] {
            let nested = env(0.5, 1.0, 0.0, HC, tol).evals;
            let adaptive = env_with(0.5, 1.0, 0.0, HC, tol, Inner::Adaptive).evals;
            assert!(nested > 0 && nested % 210 == 0, "tol {tol}: {nested} evaluations (nested)");
            assert!(adaptive > 0 && adaptive % 462 == 0, "tol {tol}: {adaptive} evaluations (adaptive)");
            assert_eq!(nested / 210, adaptive / 462, "tol {tol}: outer panels");
        }
    }

}
