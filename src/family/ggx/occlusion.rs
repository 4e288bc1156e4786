//! Specular occlusion by a visibility cone (Call of Duty: WWII, "cone-based indirect specular
//! occlusion"), and the occlusion approximations engines ship measured against it.
//!
//! # The cone model (COD: WWII material talk, "Converting occlusion to equivalent cone angle")
//! - Interreflected visibility: A′ = A / (1 − ρ + ρA) for ambient visibility A and albedo ρ
//!   ([`interreflected`]; the geometric series A Σ ((1 − A)ρ)^k of light bouncing inside a
//!   cavity whose walls take the fraction 1 − A of the view).
//! - Nusselt analog: the cosine-weighted visibility V of a cone of half-angle θ about the
//!   normal is the projected disk area sin²θ, so cos θ = sqrt(1 − V) ([`cone_of_visibility`]).
//! - The occluded split sum keeps the light directions inside the cone: `ggx-env` with
//!   `cos_cone` = cos θ. The specular occlusion it implies for a Schlick F0 is the ratio
//!   SO(α, n·v, V) = (F0·scale_c + bias_c) / (F0·scale + bias) ([`exact_so`]), the quantity the
//!   engines' scalar approximations multiply the unoccluded split sum by.
//!
//! # The talk's adjusted cone
//! Printed as cos θ′ = cos θ (1 − gloss²)(1 − (1 − (n·v)⁴)), which is cos θ (1 − gloss²)(n·v)⁴
//! ([`cod_adjust_printed`]); the reading with the grazing term of a Schlick-like falloff is
//! cos θ (1 − gloss²)(1 − (1 − n·v)⁴) ([`cod_adjust_corrected`]). See [`typo_item`] for which
//! one the talk describes.
//!
//! # Approximations measured ([`items`])
//! - Lagarde & de Rousiers 2014 ("Moving Frostbite to PBR", course notes, listing 26;
//!   Filament's `SPECULAR_AO_SIMPLE`): SO = saturate((n·v + V)^(2^(−16 α − 1)) − 1 + V), with
//!   Filament's roughness argument α (= perceptual roughness²).
//! - Jimenez et al. 2016 ("Practical Real-Time Strategies for Accurate Indirect Occlusion",
//!   cone–cone intersection): the solid angle shared by the visibility cone (axis n, cos α_v =
//!   sqrt(1 − V)) and a specular cone about the mirror direction (cos α_s = 2^(−3.321928 r²),
//!   r = perceptual roughness), over the specular cone's solid angle ([`cap_intersection`]).
//! - Both refitted in their own shape to the cone model ([`refits`]), and COD: WWII's 3-D table
//!   ([`lut`]) read trilinearly as a shader would ([`LutReader`]).
//! - Jimenez et al. 2016's multi-bounce AO, max(V, ((aV + b)V + c)V) with a, b, c linear in ρ
//!   ([`jimenez_multibounce`]), against the interreflection model above (not the data it was
//!   fitted to, which has no closed form), with the same cubic refitted to the model.
//!
//! # Layout
//! Here the cone model and the approximations' forms; `validation.rs` measures them against
//! the model on the validation grid (the items, the refits, the typo finding, the table audit),
//! `committed.rs` reads the committed 3-D tables as a shader does.

pub mod emit;
pub mod lut;
pub mod plot;
pub mod refit;
mod committed;
mod validation;

pub use committed::{LutReader, lut_readers, row_of_alpha};
pub use validation::{items, refits, typo_item};

use super::integrals::{self, EnvEstimate, Shadowing};
use std::f64::consts::PI;

/// COD: WWII's interreflection model: visibility A of a cavity with albedo ρ after bounces.
pub fn interreflected(a: f64, albedo: f64) -> f64 {
    a / (1.0 - albedo + albedo * a)
}

/// The Nusselt analog: cos of the half-angle of the cone with cosine-weighted visibility V.
pub fn cone_of_visibility(v: f64) -> f64 {
    (1.0 - v.clamp(0.0, 1.0)).sqrt()
}

/// The adjustment as printed: cos θ (1 − g²)(1 − (1 − (n·v)⁴)) = cos θ (1 − g²)(n·v)⁴.
pub fn cod_adjust_printed(cos_cone: f64, gloss: f64, n_dot_v: f64) -> f64 {
    cos_cone * (1.0 - gloss * gloss) * (1.0 - (1.0 - n_dot_v.powi(4)))
}

/// The reading with a grazing falloff: cos θ (1 − g²)(1 − (1 − n·v)⁴).
pub fn cod_adjust_corrected(cos_cone: f64, gloss: f64, n_dot_v: f64) -> f64 {
    cos_cone * (1.0 - gloss * gloss) * (1.0 - (1.0 - n_dot_v).powi(4))
}

/// Solid angle shared by two spherical caps of angular radii `a` and `b` whose axes are `d`
/// apart (all in [0, π]): 0 when apart, the smaller cap inside the larger, else the lens
/// 2[π − acos((cos d − cos a cos b)/(sin a sin b)) − cos a · acos((cos b − cos d cos a)/(sin d sin a))
///      − cos b · acos((cos a − cos d cos b)/(sin d sin b))]
/// (the area of a spherical lens from its two circular arcs by Gauss–Bonnet; Tovchigrechko &
/// Vakser 2001, and Jimenez et al. 2016's `SphericalCapIntersectionSolidArea`).
pub fn cap_intersection(a: f64, b: f64, d: f64) -> f64 {
    let cap = |r: f64| 2.0 * PI * (1.0 - r.cos());
    if d >= a + b {
        return 0.0;
    }
    if d <= (a - b).abs() {
        return cap(a.min(b));
    }
    let acos = |x: f64| x.clamp(-1.0, 1.0).acos();
    let (ca, cb, cd) = (a.cos(), b.cos(), d.cos());
    let (sa, sb, sd) = (a.sin(), b.sin(), d.sin());
    let omega = 2.0
        * (PI - acos((cd - ca * cb) / (sa * sb)) - ca * acos((cb - cd * ca) / (sd * sa)) - cb * acos((ca - cd * cb) / (sd * sb)));
    omega.clamp(0.0, cap(a.min(b)))
}

/// Lagarde & de Rousiers 2014's constants: the exponent 2^(a α + b) with (a, b) = (−16, −1).
pub const LAGARDE: [f64; 2] = [-16.0, -1.0];
/// Jimenez et al. 2016's specular cone: cos α_s = 2^(k r²), k = −3.321928 (−log₂ 10).
#[allow(clippy::approx_constant, reason = "the published constant, as printed (−log₂ 10 rounded to 7 digits)")]
pub const JIMENEZ: f64 = -3.321928;

/// Lagarde & de Rousiers 2014: SO at n·v, visibility V and GGX α (Filament's argument).
pub fn lagarde(n_dot_v: f64, v: f64, alpha: f64) -> f64 {
    lagarde_with(LAGARDE, n_dot_v, v, alpha)
}

/// Lagarde's shape with constants (a, b): saturate((n·v + V)^(2^(a α + b)) − 1 + V), the
/// form's program ([`refit::LAGARDE_FORM`]) in f64.
pub fn lagarde_with(c: [f64; 2], n_dot_v: f64, v: f64, alpha: f64) -> f64 {
    refit::LAGARDE_TAPE.eval::<1>(&[n_dot_v, v, alpha], &c)[0]
}

/// Jimenez et al. 2016: the visibility cone (axis n) ∩ the specular cone about the mirror
/// direction (θ_v from n), over the specular cone; r is perceptual roughness.
pub fn jimenez(n_dot_v: f64, v: f64, r: f64) -> f64 {
    jimenez_with(JIMENEZ, n_dot_v, v, r)
}

/// Jimenez's shape with the specular cone cos α_s = 2^(k r²).
pub fn jimenez_with(k: f64, n_dot_v: f64, v: f64, r: f64) -> f64 {
    let a_v = cone_of_visibility(v).acos();
    let a_s = (k * r * r).exp2().clamp(-1.0, 1.0).acos();
    let d = n_dot_v.clamp(0.0, 1.0).acos();
    let spec = 2.0 * PI * (1.0 - a_s.cos());
    if spec <= 0.0 {
        // A mirror: the direction is either inside the cone or not.
        return if d <= a_v { 1.0 } else { 0.0 };
    }
    cap_intersection(a_v, a_s, d) / spec
}

/// The cone model's specular occlusion for a Schlick F0 (see the module doc), with the
/// integrals to `tol`.
pub fn exact_so(alpha: f64, n_dot_v: f64, v: f64, f0: f64, tol: f64) -> f64 {
    let (full, cone) = split_sums(alpha, n_dot_v, v, tol);
    so_ratio(&full, &cone, f0)
}

/// The split sums over the hemisphere and over the cone of visibility V.
fn split_sums(alpha: f64, n_dot_v: f64, v: f64, tol: f64) -> (EnvEstimate, EnvEstimate) {
    let full = integrals::env(alpha, n_dot_v, 0.0, Shadowing::HeightCorrelated, tol);
    let cone = integrals::env(alpha, n_dot_v, cone_of_visibility(v), Shadowing::HeightCorrelated, tol);
    (full, cone)
}

/// (F0·scale_c + bias_c)/(F0·scale + bias), 0 where the unoccluded sum is 0.
fn so_ratio(full: &EnvEstimate, cone: &EnvEstimate, f0: f64) -> f64 {
    let den = f0 * full.scale + full.bias;
    if den > 0.0 { (f0 * cone.scale + cone.bias) / den } else { 0.0 }
}

/// Integrator tolerance of the references: the SO ratios are measured to ~1e-6 (a ratio of
/// terms ≥ 1e-2 each known to 1e-8), far below the approximations' errors (≳ 1e-2).
const TOL: f64 = 1e-8;
/// F0 of the measured specular: a dielectric's 4 % (and F = 1 as an extra figure).
const F0: f64 = 0.04;

/// Jimenez et al. 2016's multi-bounce fit: a, b, c of ((aV + b)V + c)V, each linear in the
/// albedo ρ: [a₁, a₀, b₁, b₀, c₁, c₀] with a = a₁ρ + a₀ (their Eq. 10).
pub const JIMENEZ_MULTIBOUNCE: [f64; 6] = [2.0404, -0.3324, -4.7951, 0.6417, 2.7552, 0.6903];

/// max(V, ((aV + b)V + c)V) with a, b, c linear in ρ (`p` as [`JIMENEZ_MULTIBOUNCE`]).
pub fn jimenez_multibounce(p: &[f64], v: f64, albedo: f64) -> f64 {
    refit::MULTIBOUNCE_TAPE.eval::<1>(&[v, albedo], p)[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With the specular cone centred on the visibility cone (n·v = 1, d = 0) the visible
    /// fraction is the ratio of cap areas (1 − cos a_v)/(1 − cos a_s) when the specular cone is
    /// the wider, and 1 when it is inside.
    #[test]
    fn jimenez_with_concentric_cones_is_the_ratio_of_cap_areas() {
        let k = JIMENEZ;
        for (v, r) in [(0.5, 0.9), (0.8, 0.7), (0.3, 0.2)] {
            let cos_v = cone_of_visibility(v);
            let cos_s = (k * r * r).exp2();
            let want = if cos_s >= cos_v { 1.0 } else { (1.0 - cos_v) / (1.0 - cos_s) };
            let got = jimenez_with(k, 1.0, v, r);
            // Cap areas through acos and back: 1e-12.
            assert!((got - want).abs() < 1e-12, "v = {v}, r = {r}: {got} vs {want}");
        }
        // Not vacuous: one case is partial.
        let (cos_v, cos_s) = (cone_of_visibility(0.5), (k * 0.81f64).exp2());
        assert!(cos_s < cos_v, "the first case's specular cone is the wider");
    }

    /// The shared solid angle by brute force: a midpoint grid in (cos θ, φ) over cap `b`
    /// (axis +z), counting the cells whose centres lie in cap `a` (axis tilted by d in xz).
    fn brute(a: f64, b: f64, d: f64, n: usize) -> f64 {
        let (ca, lo) = (a.cos(), b.cos());
        let mut inside = 0usize;
        for i in 0..n {
            let z = lo + (1.0 - lo) * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            for j in 0..n {
                let phi = 2.0 * PI * (j as f64 + 0.5) / n as f64;
                // Dot with the axis (sin d, 0, cos d).
                if s * phi.cos() * d.sin() + z * d.cos() >= ca {
                    inside += 1;
                }
            }
        }
        2.0 * PI * (1.0 - lo) * inside as f64 / (n * n) as f64
    }

    #[test]
    fn cap_intersection_matches_brute_force_and_its_limits() {
        // Midpoint counting on 2000² cells: the boundary cells misclassify, an error of about
        // (boundary length × cell size) ≲ 2π · 2π/2000 · 1/2000 ≈ 1e-5 of the cap; 2e-3 absolute
        // leaves a wide margin.
        for &(a, b, d) in &[(0.5, 0.3, 0.6), (1.2, 0.4, 1.0), (0.8, 0.8, 0.5), (1.5, 0.2, 1.6), (0.3, 1.0, 1.1)] {
            let (x, y) = (cap_intersection(a, b, d), brute(a, b, d, 2000));
            assert!((x - y).abs() < 2e-3, "({a}, {b}, {d}): {x} vs {y}");
        }
        let cap = |r: f64| 2.0 * PI * (1.0 - f64::cos(r));
        assert_eq!(cap_intersection(0.3, 0.4, 0.8), 0.0);
        assert_eq!(cap_intersection(1.0, 0.2, 0.5), cap(0.2));
        // Symmetric in the caps; continuous at the tangencies.
        assert!((cap_intersection(0.7, 0.4, 0.6) - cap_intersection(0.4, 0.7, 0.6)).abs() < 1e-14);
        assert!(cap_intersection(0.3, 0.4, 0.7 - 1e-9) < 1e-6);
        assert!((cap_intersection(1.0, 0.2, 0.8 + 1e-9) - cap(0.2)).abs() < 1e-6);
    }

    #[test]
    fn cone_model_limits() {
        // Nusselt analog: a cone of half-angle θ has cosine-weighted visibility sin²θ.
        for &t in &[0.2f64, 0.7, 1.3] {
            assert!((cone_of_visibility(t.sin().powi(2)) - t.cos()).abs() < 1e-15);
        }
        // Interreflection: black walls keep A; white walls see every bounce (A′ = 1).
        assert_eq!(interreflected(0.3, 0.0), 0.3);
        assert!((interreflected(0.3, 1.0) - 1.0).abs() < 1e-15);
        // SO = 1 with full visibility (the hemisphere), and SO → 0 as V → 0 (the cone closes).
        assert!((exact_so(0.25, 0.5, 1.0, F0, 1e-10) - 1.0).abs() < 1e-9);
        assert!(exact_so(0.25, 0.5, 1e-6, F0, 1e-10) < 1e-5);
        // The adjustments: both readings are a full cone at n·v = 0 and unchanged at 1.
        for f in [cod_adjust_printed, cod_adjust_corrected] {
            assert_eq!(f(0.6, 0.0, 0.0), 0.0);
            assert!((f(0.6, 0.0, 1.0) - 0.6).abs() < 1e-15);
            assert_eq!(f(0.6, 1.0, 0.5), 0.0);
        }
        assert!((cod_adjust_printed(1.0, 0.0, 0.5) - 0.0625).abs() < 1e-15);
        assert!((cod_adjust_corrected(1.0, 0.0, 0.5) - 0.9375).abs() < 1e-15);
    }

    #[test]
    fn scale_and_bias_fall_monotonically_as_the_cone_closes_and_vanish_at_its_end() {
        // Nested cones keep nested sets of light directions and the integrand is ≥ 0, so each
        // of scale and bias is non-increasing in cos θc; each value carries its error estimate
        // (≤ 1e-10 each), so a rise beyond the sum of the two would be a real violation.
        for &alpha in &[1e-3, 0.02, 0.3, 1.0] {
            for &mu in &[0.01, 0.2, 0.6, 1.0] {
                let mut last = integrals::env(alpha, mu, 0.0, Shadowing::HeightCorrelated, 1e-10);
                for k in 1..=40 {
                    let c = k as f64 / 40.0;
                    let e = integrals::env(alpha, mu, c, Shadowing::HeightCorrelated, 1e-10);
                    let slack = e.error + last.error;
                    assert!(e.scale <= last.scale + slack && e.bias <= last.bias + slack, "α {alpha}, μ {mu}, c {c}: {e:?} after {last:?}");
                    last = e;
                }
                // The closed cone keeps no direction: both exactly 0 (COD's last slice).
                assert_eq!((last.scale, last.bias), (0.0, 0.0));
            }
        }
    }

    #[test]
    fn multibounce_fit_and_model_limits() {
        // Jimenez's cubic at ρ = 0 is ((−0.3324V + 0.6417)V + 0.6903)V, 0.9996 at V = 1 (the sum of
        // its constants), so the max with V returns 1 there; at ρ = 1, V = 1/2 it is
        // ((1.708/2 − 4.1534)/2 + 3.4455)/2 = 0.8979 by hand (f64 rounding ≪ 1e-12).
        assert_eq!(jimenez_multibounce(&JIMENEZ_MULTIBOUNCE, 0.0, 0.7), 0.0);
        assert_eq!(jimenez_multibounce(&JIMENEZ_MULTIBOUNCE, 1.0, 0.0), 1.0);
        assert!((jimenez_multibounce(&JIMENEZ_MULTIBOUNCE, 0.5, 1.0) - 0.8979).abs() < 1e-12);
        // The COD model's limits: A′ = A with black walls, 1 with white ones.
        assert_eq!(interreflected(0.3, 0.0), 0.3);
        // Never below V (the max).
        for &(v, r) in &[(0.2, 0.0), (0.5, 0.5), (0.9, 1.0)] {
            assert!(jimenez_multibounce(&JIMENEZ_MULTIBOUNCE, v, r) >= v);
        }
    }

    /// The published constants at points worked by hand. Lagarde's exponent at α = 1/16 is
    /// 2^(−16/16 − 1) = 1/4, so SO(n·v = 1/4, V = 1/2) = (3/4)^(1/4) − 1/2 (n·v + V ≠ 1, so the
    /// exponent shows). Jimenez's k is −log₂ 10 to its 7 printed digits (half a unit of the
    /// sixth decimal, 5e-7). Jimenez's multi-bounce cubic at ρ = ½: a = 1.0202 − 0.3324 =
    /// 0.6878, b = −2.39755 + 0.6417 = −1.75585, c = 1.3776 + 0.6903 = 2.0679, so at V = ½
    /// ((0.3439 − 1.75585)/2 + 2.0679)/2 = 0.6809625 (ρ strictly between 0 and 1, so each
    /// coefficient's slope in ρ shows). f64 rounding of a few operations: 1e-15, 1e-12.
    #[test]
    fn published_constants_at_points_by_hand() {
        let want = 0.75f64.sqrt().sqrt() - 0.5;
        assert!((lagarde(0.25, 0.5, 1.0 / 16.0) - want).abs() < 1e-15, "{} vs {want}", lagarde(0.25, 0.5, 1.0 / 16.0));
        assert!((JIMENEZ + 10f64.log2()).abs() < 5e-7, "{JIMENEZ}");
        let m = jimenez_multibounce(&JIMENEZ_MULTIBOUNCE, 0.5, 0.5);
        assert!((m - 0.6809625).abs() < 1e-12, "{m}");
    }

    #[test]
    fn approximations_reach_their_limits() {
        // Lagarde: V = 1 gives 1; V = 0 and n·v < 1 give 0.
        assert_eq!(lagarde(0.5, 1.0, 0.3), 1.0);
        assert_eq!(lagarde(0.5, 0.0, 0.3), 0.0);
        // Jimenez: full visibility keeps the whole specular cone (it lies in the hemisphere
        // cone of half-angle π/2 when θv + α_s ≤ π/2); no visibility, none.
        assert!((jimenez(0.9, 1.0, 0.3) - 1.0).abs() < 1e-12);
        assert_eq!(jimenez(0.5, 0.0, 0.5), 0.0);
        // A mirror (r = 0, cos α_s = 2^0 = 1: no specular cone) keeps its one direction when it
        // lies in the visibility cone, θv ≤ θc = acos sqrt(1 − V), and none when it does not:
        // θv = 60° against θc = 90° (V = 1) and 71.6° (V = 0.9), then against θc = 18.4°
        // (V = 0.1) and 0° (V = 0).
        for v in [1.0, 0.9] {
            assert_eq!(jimenez(0.5, v, 0.0), 1.0, "V = {v}");
        }
        for v in [0.1, 0.0] {
            assert_eq!(jimenez(0.5, v, 0.0), 0.0, "V = {v}");
        }
    }
}
