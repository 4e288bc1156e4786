//! Multiple-scattering energy compensation built from E(μ) and E_avg, and the white-furnace
//! validator of each scheme.
//!
//! # Schemes (conventions of [`super::integrals`]: GGX, height-correlated Smith G2, Schlick F)
//!
//! With A(μ), B(μ) the split-sum scale and bias, E(μ) = A + B the F = 1 directional albedo of
//! single scattering, E_avg = 2∫₀¹ E(μ) μ dμ, a Schlick F0 and its cosine-weighted average
//! F_avg = F0 + (1 − F0)/21 (closed form, [`super::integrals::f_avg_schlick`]), the directional
//! albedo of the single-scattering lobe with Fresnel is E_F(μ) = F0·A(μ) + B(μ). The schemes:
//!
//! ```text
//! single       f = f_ss                                              albedo E_F(μo)
//! Kulla–Conty  f = f_ss + F_ms f_ms,  f_ms(μo, μi) = (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg))
//!              F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg))         albedo E_F(μo) + F_ms (1 − E(μo))
//! Turquin      f = f_ss (1 + F0 (1 − E(μo))/E(μo))                  albedo E_F(μo) (1 + F0 (1 − E)/E)
//! Fdez-Agüera  (image-based lighting) FssEss = E_F, Ems = 1 − E, Fms = FssEss F_avg/(1 − Ems F_avg)
//!                                                                    albedo FssEss + Fms Ems
//! Cycles       f = f_ss (1 + F'_ms (1 − E(μo))/E(μo)),  F'_ms = F_avg E_avg/(1 − F_avg (1 − E_avg))
//!              (Turquin's scaling with Kulla–Conty's tint, one F_avg cancelled: bsdf_microfacet.h)
//! bevy ≤ 0.18  f = f_ss (1 + F0 (1/A(μo) − 1))  (A where Turquin/Filament have E = A + B)
//! ```
//!
//! Kulla–Conty's lobe integrates to what single scattering misses, for any μo:
//! ∫ f_ms μi dωi = (1 − E(μo))·2∫₀¹(1 − E(μi)) μi dμi / (1 − E_avg) = 1 − E(μo), because
//! 2∫₀¹ μ dμ = 1. At F = 1 (F0 = 1: Schlick's F is 1 everywhere, F_avg = 1, F_ms = 1) every
//! scheme but the single-scattering baseline and bevy's variant gives albedo exactly 1:
//! Turquin E·(1 + (1 − E)/E) = 1; Fdez-Agüera: Fms = E/(1 − (1 − E)) = 1, E + (1 − E) = 1;
//! Cycles: F'_ms = E_avg/E_avg = 1. bevy's variant gives E/A = 1 + B/A > 1, which grows without
//! bound at grazing view and small α: as α → 0, A → 1 − (1 − μ)⁵ and B → (1 − μ)⁵, so
//! B/A → (1 − μ)⁵/(1 − (1 − μ)⁵) (≈ 1/(5μ) as μ → 0).
//!
//! E(0) = 1 exactly in this model: as μv → 0, G2/μv → 1/(μvΛ(μv)) → 2/α for every light (the
//! light's μlΛ(μl) term carries a factor μv), every visible microfacet reflects above the
//! horizon (μl = 2(v·h)μh), and ∫ D (v·h)⁺ dωh = μv(1 + Λ(μv)) → α/2, so E(0) = (2/α)(α/2).
//! Near mirrors E dips to ≈0.89 at n·v ~ α before it recovers towards 1: the structure a 32-wide
//! uniform n·v table cannot resolve (the tables' error, ≈0.1, sits there).
//!
//! # Reciprocity
//!
//! f_ss is symmetric in (o, i) (D, G2 and Schlick's F on v·h = l·h all are), and so is f_ms:
//! Kulla–Conty's BRDF is reciprocal. Turquin's, Cycles' and bevy's multiply f_ss by a factor
//! c(μo) of the view alone, so f(o, i)/f(i, o) = c(μo)/c(μi); the relative asymmetry
//! |f(o,i) − f(i,o)|/max(f(o,i), f(i,o)) = |c(μo) − c(μi)|/max(c(μo), c(μi)). Fdez-Agüera's term
//! is a lighting integral, not a BRDF; read as one, its extra lobe Fms(μo) Ems(μo)/π (the
//! irradiance term) is again a function of μo alone, and the same measure applies to it.
//!
//! # What is exact here
//!
//! [`exact_inputs`] evaluates A, B (one [`super::integrals::env`] call) and E_avg
//! ([`super::integrals::albedo_avg`]) to a stated tolerance; [`furnace`] combines them by the
//! formulas above. The tabulated versions (the committed `ggx_albedo_table` and
//! `ggx_albedo_avg_table`, through the emitted f32 bilinear lookup) are measured in
//! [`furnace::items`] against the same exact values.

pub mod furnace;
pub mod plot;

use super::integrals::{self, Shadowing};
use crate::integrate::Estimate;
use std::f64::consts::PI;

pub use furnace::items;
pub use plot::figures;

/// An energy-compensation scheme (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    Single,
    KullaConty,
    Turquin,
    FdezAguera,
    Cycles,
    BevyOld,
}

impl Scheme {
    /// Every scheme, in the order of the `scheme` parameter of `ggx-furnace`.
    pub const ALL: [Scheme; 6] =
        [Scheme::Single, Scheme::KullaConty, Scheme::Turquin, Scheme::FdezAguera, Scheme::Cycles, Scheme::BevyOld];

    pub fn name(self) -> &'static str {
        match self {
            Scheme::Single => "single scattering",
            Scheme::KullaConty => "Kulla-Conty",
            Scheme::Turquin => "Turquin (= Filament, HDRP, bevy >= 0.19)",
            Scheme::FdezAguera => "Fdez-Aguera (IBL)",
            Scheme::Cycles => "Cycles (Turquin scaling, Kulla-Conty tint)",
            Scheme::BevyOld => "bevy <= 0.18 (1/A instead of 1/(A+B))",
        }
    }

    /// A short identifier (file names, item names).
    pub fn id(self) -> &'static str {
        match self {
            Scheme::Single => "single",
            Scheme::KullaConty => "kulla_conty",
            Scheme::Turquin => "turquin",
            Scheme::FdezAguera => "fdez_aguera",
            Scheme::Cycles => "cycles",
            Scheme::BevyOld => "bevy_old",
        }
    }

    pub fn source(self) -> &'static str {
        match self {
            Scheme::Single => "the single-scattering GGX BRDF (no compensation)",
            Scheme::KullaConty => "Kulla & Conty 2017, Revisiting Physically Based Shading at Imageworks (f_ms, F_ms)",
            Scheme::Turquin => {
                "Turquin 2019, Practical multiple scattering compensation for microfacet models; \
                 Filament surface_shading_lit.fs `1 + f0 (1/dfg.y - 1)`; HDRP Lit.hlsl; bevy PR #23514"
            }
            Scheme::FdezAguera => "Fdez-Aguera 2019, JCGT 8(1) (FssEss + Fms Ems; three.js, bevy environment_map)",
            Scheme::Cycles => "blender/cycles bsdf_microfacet.h (missing_factor, Fms with one Fss cancelled)",
            Scheme::BevyOld => "bevy <= 0.18 pbr_lighting.wgsl specular_multiscatter `1 + F0 (1/F_ab.x - 1)`",
        }
    }

    /// Whether the scheme's BRDF is symmetric in (o, i).
    pub fn reciprocal(self) -> bool {
        matches!(self, Scheme::Single | Scheme::KullaConty)
    }
}

/// What the schemes read at one (α, μo): the split-sum scale A and bias B of the view and the
/// average albedo E_avg(α).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    pub a: f64,
    pub b: f64,
    pub e_avg: f64,
}

impl Inputs {
    /// E(μo) = A + B.
    pub fn e(&self) -> f64 {
        self.a + self.b
    }
}

/// A, B at (α, μo) and E_avg(α) from the integrators, each to absolute tolerance `tol`.
pub fn exact_inputs(alpha: f64, mu_o: f64, e_avg: f64, tol: f64) -> Inputs {
    let r = integrals::env(alpha, mu_o, 0.0, Shadowing::HeightCorrelated, tol);
    Inputs { a: r.scale, b: r.bias, e_avg }
}

/// Kulla–Conty's Fresnel factor F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)) (1 at F_avg = 1).
pub fn kc_f_ms(f_avg: f64, e_avg: f64) -> f64 {
    f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))
}

/// Kulla–Conty's lobe f_ms(μo, μi) = (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg)) (F = 1).
pub fn kc_f_ms_lobe(e_o: f64, e_i: f64, e_avg: f64) -> f64 {
    (1.0 - e_o) * (1.0 - e_i) / (PI * (1.0 - e_avg))
}

/// The factor c(μo) by which Turquin, Cycles and bevy ≤ 0.18 scale f_ss (1 for the others).
pub fn scale_factor(scheme: Scheme, f0: f64, x: &Inputs) -> f64 {
    let e = x.e();
    match scheme {
        Scheme::Turquin => 1.0 + f0 * (1.0 - e) / e,
        Scheme::Cycles => {
            let f_avg = integrals::f_avg_schlick(f0);
            let f_ms = f_avg * x.e_avg / (1.0 - f_avg * (1.0 - x.e_avg));
            1.0 + f_ms * (1.0 - e) / e
        }
        Scheme::BevyOld => 1.0 + f0 * (1.0 / x.a - 1.0),
        Scheme::Single | Scheme::KullaConty | Scheme::FdezAguera => 1.0,
    }
}

/// The directional albedo of a scheme in a white furnace at one view (see the module doc):
/// Schlick F0 (F0 = 1: F = 1), with `x` the inputs at that view. `ms_integral` is
/// 2∫₀¹(1 − E(μi)) μi dμi as the renderer's f_ms integrates it (1 − E_avg exactly; a table's
/// own value when E and E_avg come from tables); only Kulla–Conty reads it.
pub fn furnace(scheme: Scheme, f0: f64, x: &Inputs, ms_integral: f64) -> f64 {
    let e = x.e();
    let e_f = f0 * x.a + x.b;
    let f_avg = integrals::f_avg_schlick(f0);
    match scheme {
        Scheme::Single => e_f,
        Scheme::KullaConty => e_f + kc_f_ms(f_avg, x.e_avg) * (1.0 - e) * ms_integral / (1.0 - x.e_avg),
        Scheme::FdezAguera => {
            let ems = 1.0 - e;
            let fms = e_f * f_avg / (1.0 - ems * f_avg);
            e_f + fms * ems
        }
        Scheme::Turquin | Scheme::Cycles | Scheme::BevyOld => e_f * scale_factor(scheme, f0, x),
    }
}

/// The view-only factor of a scheme's BRDF whose ratio at (μo, μi) and (μi, μo) measures its
/// asymmetry: c(μ) for the scaling schemes, the extra lobe Fms Ems for Fdez-Agüera; None for the
/// reciprocal ones.
pub fn view_factor(scheme: Scheme, f0: f64, x: &Inputs) -> Option<f64> {
    match scheme {
        Scheme::Single | Scheme::KullaConty => None,
        Scheme::FdezAguera => {
            let ems = 1.0 - x.e();
            let f_avg = integrals::f_avg_schlick(f0);
            let e_f = f0 * x.a + x.b;
            Some(e_f * f_avg / (1.0 - ems * f_avg) * ems)
        }
        _ => Some(scale_factor(scheme, f0, x)),
    }
}

/// |f(o,i) − f(i,o)| / max(f(o,i), f(i,o)) for a BRDF f(o,i) = g(o,i)·c(μo) with g symmetric.
pub fn asymmetry(c_o: f64, c_i: f64) -> f64 {
    let m = c_o.max(c_i);
    if m > 0.0 { (c_o - c_i).abs() / m } else { 0.0 }
}

// ---------------------------------------------------------------------------------------------
// Quantities (`shadefit eval`; listed in the family's QUANTITIES)

/// `ggx-kc-fms` (alpha, n_dot_v, n_dot_l): Kulla–Conty's f_ms at F = 1. Error: first-order
/// propagation of the three integrals' errors through the formula.
pub fn eval_kc_fms(p: &[f64], tol: f64) -> Estimate {
    let (alpha, mu_o, mu_i) = (p[0], p[1], p[2]);
    let eo = integrals::albedo(alpha, mu_o, tol);
    let ei = integrals::albedo(alpha, mu_i, tol);
    let ea = integrals::albedo_avg(alpha, tol);
    let value = kc_f_ms_lobe(eo.value, ei.value, ea.value);
    let d = 1.0 - ea.value;
    let error = ((1.0 - ei.value) * eo.error + (1.0 - eo.value) * ei.error) / (PI * d) + value * ea.error / d;
    Estimate { value, error, evals: eo.evals + ei.evals + ea.evals }
}

/// `ggx-furnace` (alpha, n_dot_v, f0, scheme): the furnace albedo of a scheme (index into
/// [`Scheme::ALL`]). Error: the inputs' errors times a bound on the formula's sensitivity
/// (each scheme's albedo moves by at most a few times the change of A, B or E_avg away from
/// E → 0; reported as 4·(error of A, B + error of E_avg)/min(E, 1 − E_avg), and 4·error/A² for
/// bevy's 1/A); Kulla–Conty's, whose sensitivity is bounded without that divisor, as twice its
/// first-order propagation.
pub fn eval_furnace(p: &[f64], tol: f64) -> Estimate {
    let (alpha, mu, f0) = (p[0], p[1], p[2]);
    let scheme = Scheme::ALL[(p[3] as usize).min(Scheme::ALL.len() - 1)];
    let needs_avg = matches!(scheme, Scheme::KullaConty | Scheme::Cycles);
    let avg = if needs_avg { integrals::albedo_avg(alpha, tol) } else { Estimate::exact(0.5) };
    let r = integrals::env(alpha, mu, 0.0, Shadowing::HeightCorrelated, tol);
    let x = Inputs { a: r.scale, b: r.bias, e_avg: avg.value };
    let value = furnace(scheme, f0, &x, 1.0 - x.e_avg);
    if scheme == Scheme::KullaConty {
        // v = f0 A + B + F_ms (1 − A − B), F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)): its
        // partial derivatives are f0 − F_ms, 1 − F_ms and (1 − E) F_avg² (1 − F_avg)/(1 − F_avg
        // (1 − E_avg))², all bounded (at F0 = 1 all vanish: v is 1 whatever the inputs), twice the
        // first-order propagation for what the linearisation leaves out, plus the rounding.
        let f_avg = integrals::f_avg_schlick(f0);
        let f_ms = kc_f_ms(f_avg, x.e_avg);
        let d_avg = (1.0 - x.e()) * f_avg * f_avg * (1.0 - f_avg) / (1.0 - f_avg * (1.0 - x.e_avg)).powi(2);
        let first = ((f0 - f_ms).abs() + (1.0 - f_ms).abs()) * r.error + d_avg.abs() * avg.error;
        return Estimate { value, error: 2.0 * first + 4.0 * f64::EPSILON * value.abs(), evals: r.evals + avg.evals };
    }
    let denom = match scheme {
        Scheme::BevyOld => x.a * x.a,
        _ => x.e().min(1.0 - x.e_avg.min(1.0 - 1e-300)).max(1e-300),
    };
    Estimate { value, error: 4.0 * (r.error + avg.error) / denom, evals: r.evals + avg.evals }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kulla–Conty's F_ms as the series it sums: light that misses the single-scattering lobe
    /// (share 1 − E_avg) meets the surface again, each bounce keeping F_avg of it, and leaves with
    /// share E_avg: F_ms = (F_avg E_avg/(1 − E_avg)) Σ_{k≥1} (F_avg (1 − E_avg))^k, summed here to
    /// 200 terms (the ratio is ≤ 0.81: the tail is below 1e-18, and 1e-12 bounds
    /// it with the rounding). At F_avg = 1 it is 1, at E_avg = 1 it is F_avg², without Fresnel 0.
    #[test]
    fn kulla_contys_fresnel_factor_sums_the_bounces() {
        for f in [0.04f64, 0.3, 0.9] {
            for e in [0.1, 0.5, 0.95] {
                let x = f * (1.0 - e);
                let series: f64 = (1..=200).map(|k| x.powi(k)).sum::<f64>() * f * e / (1.0 - e);
                assert!((kc_f_ms(f, e) - series).abs() < 1e-12, "F_avg {f}, E_avg {e}: {} vs {series}", kc_f_ms(f, e));
            }
            assert_eq!(kc_f_ms(f, 1.0), f * f);
            // 1 − (1 − E_avg) gives E_avg back to half an ulp of 1: relative ε/(2 E_avg).
            assert!((kc_f_ms(1.0, f) - 1.0).abs() < f64::EPSILON / f + 4.0 * f64::EPSILON, "E_avg {f}: {}", kc_f_ms(1.0, f));
            assert_eq!(kc_f_ms(0.0, f), 0.0);
        }
    }

    /// bevy's old scheme at F0 = 1 is v = (A + B)/A, so the reported error must cover
    /// |∂v/∂A| + |∂v/∂B| = B/A² + 1/A times the error of A and B (here both the env
    /// integral's estimate). At grazing views of smooth surfaces B exceeds A three times over
    /// (α = 0.02, n·v = 0.01) and the 1/A² sensitivity dominates: a bound through 1/min(E, …)
    /// instead falls short there.
    #[test]
    fn bevy_olds_error_covers_its_one_over_a_sensitivity() {
        let bevy = Scheme::ALL.iter().position(|&s| s == Scheme::BevyOld).unwrap() as f64;
        let mut widest = 0.0f64;
        for alpha in [0.02, 0.1, 0.5, 1.0] {
            for mu in [0.01, 0.05, 0.5] {
                let r = integrals::env(alpha, mu, 0.0, Shadowing::HeightCorrelated, 1e-8);
                let (a, b) = (r.scale, r.bias);
                assert!(r.error > 0.0, "({alpha}, {mu}): an error estimate to scale");
                let est = eval_furnace(&[alpha, mu, 1.0, bevy], 1e-8);
                // The value by hand, to rounding.
                assert!((est.value - (a + b) / a).abs() <= 1e-12 * est.value, "({alpha}, {mu}): {} vs {}", est.value, (a + b) / a);
                let need = (b / (a * a) + 1.0 / a) * r.error;
                assert!(est.error >= need, "({alpha}, {mu}): error {:e} below the sensitivity's {need:e} (A {a}, B {b})", est.error);
                widest = widest.max(b / a);
            }
        }
        // Some point is in the regime that tells the bounds apart.
        assert!(widest > 2.0, "largest B/A {widest}");
    }

    /// Each scheme's name, id and source name the same work (its authors, renderer or the
    /// baseline), the ids are distinct lower-case file-name words, and `ALL` lists every
    /// scheme once, in the order of the `scheme` parameter: single, Kulla–Conty, Turquin,
    /// Fdez-Agüera, Cycles, bevy's old one.
    #[test]
    fn each_scheme_names_its_own_work() {
        let keys = ["single", "kulla", "turquin", "fdez", "cycles", "bevy"];
        for (s, key) in Scheme::ALL.iter().zip(keys) {
            for text in [s.name(), s.id(), s.source()] {
                assert!(text.to_lowercase().contains(key), "{s:?}: '{text}' does not name {key}");
            }
            assert!(s.id().chars().all(|c| c.is_ascii_lowercase() || c == '_'), "{}", s.id());
        }
        let mut ids: Vec<&str> = Scheme::ALL.iter().map(|s| s.id()).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), 6);
    }

    #[test]
    fn furnace_error_estimate_covers_a_loose_evaluation() {
        // At tol 1e-4 the reported error must cover the distance to the same albedo at 1e-11
        // (plus that one's own reported error); every scheme integrates A and B, so the
        // estimate is positive.
        for scheme in 0..Scheme::ALL.len() {
            for &(alpha, mu, f0) in &[(0.1, 0.3, 0.04), (0.5, 0.8, 1.0), (1.0, 0.1, 0.5)] {
                let p = [alpha, mu, f0, scheme as f64];
                let a = eval_furnace(&p, 1e-4);
                let b = eval_furnace(&p, 1e-11);
                assert!(a.error > 0.0, "{p:?}: error {}", a.error);
                assert!((a.value - b.value).abs() <= a.error + b.error, "{p:?}: |Δ| {:e} > {:e}", (a.value - b.value).abs(), a.error);
            }
        }
    }
    use crate::integrate::gauss_legendre;

    fn inputs(alpha: f64, mu: f64) -> Inputs {
        let e_avg = integrals::albedo_avg(alpha, 1e-10).value;
        exact_inputs(alpha, mu, e_avg, 1e-11)
    }

    #[test]
    fn kulla_conty_lobe_restores_what_single_scattering_loses() {
        // ∫ f_ms μi dωi = 1 − E(μo) analytically; here the μi integral is an independent
        // 48-point Gauss–Legendre rule in μ = t² (clusters nodes at grazing, where E(μ) varies
        // fastest) over E values at 1e-11, against E_avg from its own adaptive integrator.
        let (x, w) = gauss_legendre(48);
        for &alpha in &[0.1, 0.4, 1.0] {
            let e_avg = integrals::albedo_avg(alpha, 1e-11).value;
            // 2∫(1 − E(μ)) μ dμ with μ = t², dμ = 2t dt.
            let ms: f64 = x
                .iter()
                .zip(&w)
                .map(|(&xi, &wi)| {
                    let t = 0.5 * (xi + 1.0);
                    let mu = t * t;
                    let e = integrals::albedo(alpha, mu, 1e-11).value;
                    0.5 * wi * 2.0 * (1.0 - e) * mu * 2.0 * t
                })
                .sum();
            for &mu_o in &[0.0, 0.3, 1.0] {
                let e_o = integrals::albedo(alpha, mu_o, 1e-11).value;
                // ∫ f_ms μi dωi = 2π ∫ f_ms μi dμi = (1 − E(μo)) ms / (1 − E_avg).
                let lobe = (1.0 - e_o) * ms / (1.0 - e_avg);
                // The rule's error on a function smooth in t (E is smooth in μ inside (0, 1]
                // and has an integrable kink in slope at μ = 0 only at small α): 2e-7 covers it
                // at α ≥ 0.1, where 1 − E_avg ≥ 0.05 keeps the division from amplifying it.
                assert!((e_o + lobe - 1.0).abs() < 2e-7, "α={alpha} μo={mu_o}: {}", e_o + lobe);
            }
        }
    }

    /// `ggx-kc-fms`'s error is the first-order propagation of its three integrals' errors:
    /// Σ |∂f_ms/∂x|·error(x) over E(μo), E(μi) and E_avg, the partials here by central
    /// differences of the lobe formula (linear in E(μo) and E(μi), so exact there; in E_avg
    /// their truncation is h²/(1 − E_avg)² ≈ 3e-9 relative at h = 1e-5, their rounding ~ε/h ≈
    /// 2e-11: well inside 1e-6).
    #[test]
    fn kc_fms_error_propagates_each_integrals_error() {
        let (alpha, mo, mi, tol) = (0.5, 0.3, 0.8, 1e-7);
        let (eo, ei, ea) = (integrals::albedo(alpha, mo, tol), integrals::albedo(alpha, mi, tol), integrals::albedo_avg(alpha, tol));
        let x = [eo.value, ei.value, ea.value];
        let h = 1e-5;
        let partial = |k: usize| {
            let (mut up, mut down) = (x, x);
            up[k] += h;
            down[k] -= h;
            (kc_f_ms_lobe(up[0], up[1], up[2]) - kc_f_ms_lobe(down[0], down[1], down[2])) / (2.0 * h)
        };
        let want: f64 = [eo.error, ei.error, ea.error].iter().enumerate().map(|(k, e)| partial(k).abs() * e).sum();
        let got = eval_kc_fms(&[alpha, mo, mi], tol);
        assert_eq!(got.value, kc_f_ms_lobe(x[0], x[1], x[2]));
        assert!(want > 0.0 && (got.error - want).abs() <= 1e-6 * want, "error {} vs {want}", got.error);
        // E_avg's share is a large part of the sum (measured 0.63), so its term is checked too.
        assert!(partial(2).abs() * ea.error > 0.3 * want, "{} of {want}", partial(2).abs() * ea.error);
    }

    #[test]
    fn kulla_conty_lobe_is_symmetric() {
        let p = [0.5, 0.2, 0.9];
        let a = eval_kc_fms(&p, 1e-10).value;
        let b = eval_kc_fms(&[0.5, 0.9, 0.2], 1e-10).value;
        // The formula is symmetric term by term; the two products differ only in rounding.
        assert!((a - b).abs() <= 4.0 * f64::EPSILON * a, "{a} vs {b}");
        assert!(a > 0.0);
    }

    #[test]
    fn every_scheme_but_two_conserves_energy_at_f_equal_one() {
        // Exact algebraic identities: the residuals are rounding of a few operations on values
        // ≤ ~3 (1e-14), except bevy's variant (E/A) and the baseline (E).
        for &alpha in &[0.01, 0.3, 1.0] {
            for &mu in &[0.0, 0.05, 0.5, 1.0] {
                let x = inputs(alpha, mu);
                for s in [Scheme::KullaConty, Scheme::Turquin, Scheme::FdezAguera, Scheme::Cycles] {
                    let v = furnace(s, 1.0, &x, 1.0 - x.e_avg);
                    assert!((v - 1.0).abs() < 1e-13, "{s:?} α={alpha} μ={mu}: {v}");
                }
                assert!((furnace(Scheme::Single, 1.0, &x, 1.0 - x.e_avg) - x.e()).abs() < 1e-15);
                let bevy = furnace(Scheme::BevyOld, 1.0, &x, 1.0 - x.e_avg);
                assert!((bevy - (1.0 + x.b / x.a)).abs() < 1e-12 * bevy, "α={alpha} μ={mu}: {bevy}");
            }
        }
    }

    #[test]
    fn bevy_gain_matches_its_smooth_limit() {
        // Hand derivation (module doc): as α → 0, A → 1 − (1 − μ)⁵ and B → (1 − μ)⁵, so
        // bevy's furnace gain at F0 = 1 is B/A → (1 − μ)⁵/(1 − (1 − μ)⁵): 1/31 at μ = 1/2.
        // At α = 1e-4 the integrals are within O(α) of their limits (integrals.rs test: 1e-3);
        // the ratio at μ ≥ 0.2 (A ≥ 0.67) moves by less than 3e-3.
        for &mu in &[0.2f64, 0.5, 0.9] {
            let r = integrals::env(1e-4, mu, 0.0, Shadowing::HeightCorrelated, 1e-11);
            let x = Inputs { a: r.scale, b: r.bias, e_avg: 1.0 };
            let gain = furnace(Scheme::BevyOld, 1.0, &x, 0.0) / furnace(Scheme::Turquin, 1.0, &x, 0.0) - 1.0;
            let c = (1.0 - mu).powi(5);
            assert!((gain - c / (1.0 - c)).abs() < 3e-3, "μ={mu}: {gain} vs {}", c / (1.0 - c));
        }
    }

    #[test]
    fn turquin_breaks_reciprocity_by_the_ratio_of_its_factors() {
        // At α = 1, F0 = 1: c(μ) = 1/E(μ); E(1) = 1 − ln 2 in closed form (integrals.rs), so the
        // asymmetry between μ = 1 and μ = 0.5 is 1 − E(1)/E(0.5) with only E(0.5) numerical.
        let x1 = inputs(1.0, 1.0);
        let xh = inputs(1.0, 0.5);
        let c1 = scale_factor(Scheme::Turquin, 1.0, &x1);
        let ch = scale_factor(Scheme::Turquin, 1.0, &xh);
        let want = 1.0 - integrals::albedo_normal_rough() / xh.e();
        // Integrator tolerance 1e-11 on E, through a ratio of values ≥ 0.3: ≤ 1e-10.
        assert!((asymmetry(c1, ch) - want).abs() < 1e-10, "{} vs {want}", asymmetry(c1, ch));
        assert!(want > 0.1);
    }

    /// The view-only factors by hand at A = 0.6, B = 0.2 (E = 0.8, E_ms = 0.2), F0 = 0.5
    /// (F_avg = 0.5 + 0.5/21 = 11/21, F_ss E_ss = 0.5·0.6 + 0.2 = 0.5). Fdez-Agüera 2019's extra
    /// lobe F_ms E_ms = F_ss E_ss·F_avg·E_ms/(1 − E_ms F_avg) = (1.1/21)/(18.8/21) = 1.1/18.8;
    /// the furnace adds it to F_ss E_ss. Turquin's c = 1 + F0 (1 − E)/E = 1.125; the reciprocal
    /// schemes have none. 1e-15: a few roundings of values below 2.
    #[test]
    fn view_factors_by_hand() {
        let x = Inputs { a: 0.6, b: 0.2, e_avg: 0.7 };
        let fdez = view_factor(Scheme::FdezAguera, 0.5, &x).unwrap();
        assert!((fdez - 1.1 / 18.8).abs() < 1e-15, "{fdez}");
        assert!((furnace(Scheme::FdezAguera, 0.5, &x, 0.3) - (0.5 + 1.1 / 18.8)).abs() < 1e-15);
        assert!((view_factor(Scheme::Turquin, 0.5, &x).unwrap() - 1.125).abs() < 1e-15);
        assert_eq!((view_factor(Scheme::Single, 0.5, &x), view_factor(Scheme::KullaConty, 0.5, &x)), (None, None));
    }

    /// The relative asymmetry by hand: factors 0.5 and 1 differ by half the larger, in either
    /// order; two vanishing factors (Fdez-Agüera's lobe where E = 1) are equal, so symmetric: 0,
    /// not 0/0.
    #[test]
    fn asymmetry_by_hand_and_of_two_vanishing_factors() {
        assert_eq!((asymmetry(0.5, 1.0), asymmetry(1.0, 0.5)), (0.5, 0.5));
        assert_eq!(asymmetry(0.0, 0.0), 0.0);
    }

    /// The quantities count the evaluations of the integrals they call: `ggx-kc-fms` those of
    /// E(μo), E(μi) and E_avg; `ggx-furnace` those of A, B and, for the schemes that read it,
    /// E_avg (each integral re-run here: the integrators are deterministic).
    #[test]
    fn quantities_count_their_integrals_evaluations() {
        let (alpha, mo, mi, tol) = (0.5, 0.3, 0.8, 1e-7);
        let avg = integrals::albedo_avg(alpha, tol).evals;
        let want = integrals::albedo(alpha, mo, tol).evals + integrals::albedo(alpha, mi, tol).evals + avg;
        assert_eq!(eval_kc_fms(&[alpha, mo, mi], tol).evals, want);
        let env = integrals::env(alpha, mo, 0.0, Shadowing::HeightCorrelated, tol).evals;
        assert!(env > 0 && avg > 0);
        for (k, s) in Scheme::ALL.iter().enumerate() {
            let want = env + if matches!(s, Scheme::KullaConty | Scheme::Cycles) { avg } else { 0 };
            assert_eq!(eval_furnace(&[alpha, mo, 0.04, k as f64], tol).evals, want, "{s:?}");
        }
    }

    /// A scheme index past the end of `Scheme::ALL` reads the last scheme (bevy's old one).
    #[test]
    fn furnace_scheme_index_clamps_to_the_last() {
        let last = eval_furnace(&[0.5, 0.3, 0.5, 5.0], 1e-8);
        assert_eq!(Scheme::ALL[5], Scheme::BevyOld);
        for k in [6.0, 9.0] {
            assert_eq!(eval_furnace(&[0.5, 0.3, 0.5, k], 1e-8).value, last.value, "index {k}");
        }
    }

    /// `ggx-furnace`'s error is the stated 4·(error of A, B + error of E_avg) over the smaller
    /// of E and 1 − E_avg, and 4·error/A² for bevy's 1/A, with the errors those the integrals
    /// themselves report (re-run here). At α = 0.1 the smaller divisor is 1 − E_avg, at α = 1 it
    /// is E: both are exercised. Rounding of a few operations: 1e-12 relative.
    #[test]
    fn furnace_error_is_four_times_the_inputs_errors_over_the_smaller_divisor() {
        let tol = 1e-8;
        let mut divisors = Vec::new();
        for (alpha, mu) in [(0.1, 0.5), (1.0, 0.9)] {
            let r = integrals::env(alpha, mu, 0.0, Shadowing::HeightCorrelated, tol);
            let avg = integrals::albedo_avg(alpha, tol);
            let e = r.scale + r.bias;
            divisors.push((e, 1.0 - avg.value));
            assert!(r.error > 0.0 && avg.error > 0.0, "α {alpha}: {r:?} {avg:?}");
            for s in [Scheme::KullaConty, Scheme::Cycles, Scheme::BevyOld] {
                let k = Scheme::ALL.iter().position(|&x| x == s).unwrap() as f64;
                let got = eval_furnace(&[alpha, mu, 0.04, k], tol);
                let want = match s {
                    Scheme::BevyOld => 4.0 * r.error / (r.scale * r.scale),
                    // Kulla–Conty's partial derivatives written out by hand (F0 = 0.04).
                    Scheme::KullaConty => {
                        let f = integrals::f_avg_schlick(0.04);
                        let fms = f * f * avg.value / (1.0 - f * (1.0 - avg.value));
                        let d = (1.0 - e) * f * f * (1.0 - f) / (1.0 - f + f * avg.value).powi(2);
                        2.0 * ((0.04 - fms).abs() + (1.0 - fms).abs()) * r.error + 2.0 * d * avg.error + 4.0 * f64::EPSILON * got.value
                    }
                    _ => 4.0 * (r.error + avg.error) / e.min(1.0 - avg.value),
                };
                assert!((got.error - want).abs() <= 1e-12 * want, "{s:?} α {alpha}: {:e} vs {want:e}", got.error);
            }
        }
        assert!(divisors[0].1 < divisors[0].0 && divisors[1].0 < divisors[1].1, "(E, 1 − E_avg): {divisors:?}");
    }

    #[test]
    fn furnace_quantity_matches_the_formula() {
        let x = inputs(0.5, 0.3);
        for (k, s) in Scheme::ALL.iter().enumerate() {
            let q = eval_furnace(&[0.5, 0.3, 0.04, k as f64], 1e-10);
            let want = furnace(*s, 0.04, &x, 1.0 - x.e_avg);
            // Both at tolerances ≤ 1e-10 on A, B, E_avg; the formulas amplify by ≤ 1/E(0.3) ≈ 1.4.
            assert!((q.value - want).abs() < 1e-9, "{s:?}: {} vs {want}", q.value);
        }
    }
}
