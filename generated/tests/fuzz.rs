//! The emitted fuzz-layer functions (feature `fuzz`): finite and in range for every f32 input
//! (special values, just outside the domain, a dense grid), clamped like the published
//! listings, and the f32 coefficient function against the f64 one built from the unrounded fit.

use shadefit_runtime::{fuzz_g, fuzz_ps, fuzz_q, fuzz_r};

fn specials() -> Vec<f32> {
    let mut v = vec![
        0.0, -0.0, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-45, -1e-45, f32::INFINITY,
        f32::NEG_INFINITY, f32::NAN, -f32::NAN, f32::MAX, f32::MIN, 1.0, -1.0,
        1.0 + f32::EPSILON, -f32::EPSILON, 0.15, 0.1499999, 1.5707964, 1.5707965, std::f32::consts::PI,
    ];
    v.extend((0..=64).map(|i| i as f32 / 64.0 * 1.6));
    v
}

#[test]
fn ps_coefficients_and_evaluator_are_finite_and_in_range() {
    let mut n = 0;
    for a in specials() {
        for t in specials() {
            let c = fuzz_ps::fuzz_ps_coeffs(a, t);
            assert!(c.iter().all(|v| v.is_finite()), "fuzz_ps_coeffs({a:e}, {t:e}) = {c:?}");
            for nu in [-1.5f32, -1.0, 0.0, 0.3, 1.0, f32::NAN, f32::INFINITY] {
                for tu in [-1.0f32, -0.2, 0.0, 0.7, 1.0, f32::NAN, f32::NEG_INFINITY] {
                    let v = fuzz_ps::fuzz_ps(&c, nu, tu);
                    // P_s is a fraction: the evaluator clamps to [0, 1] (NaN → 0).
                    assert!((0.0..=1.0).contains(&v), "fuzz_ps({c:?}, {nu}, {tu}) = {v}");
                    n += 1;
                }
            }
        }
    }
    assert!(n > 100_000);
    // Coefficients that are themselves NaN or infinite still give a value in [0, 1].
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 1.0, f32::MAX];
    assert!((0.0..=1.0).contains(&fuzz_ps::fuzz_ps(&bad, 0.5, 0.5)));
    // Inputs clamp like CalcFuzzPsCoeffs (α to [0.15, 1]) and to the fit's θf ∈ [0, π/2].
    assert_eq!(fuzz_ps::fuzz_ps_coeffs(0.01, 0.5), fuzz_ps::fuzz_ps_coeffs(0.15, 0.5));
    assert_eq!(fuzz_ps::fuzz_ps_coeffs(0.5, -1.0), fuzz_ps::fuzz_ps_coeffs(0.5, 0.0));
    assert_eq!(fuzz_ps::fuzz_ps_coeffs(0.5, 3.0), fuzz_ps::fuzz_ps_coeffs(0.5, std::f32::consts::FRAC_PI_2));
    assert_eq!(fuzz_ps::fuzz_ps_coeffs(f32::NAN, f32::NAN), fuzz_ps::fuzz_ps_coeffs(0.15, 0.0));
}

/// |c_f32 − c_f64| is bounded by the rounding of the f32 path: coefficients rounded to f32
/// (relative 2⁻²⁴ each) and ~30 f32 operations on each of P and Q, so with S_P = Σ|a_j φ_j|,
/// S_Q = 1 + Σ|b_j ψ_j|: |Δc| ≤ |β|·32·2⁻²³·(S_P + |P/Q|·S_Q)/|Q| + a few ulps of c, derived
/// here from the f64 constants, not from the code under test.
#[test]
fn f32_coefficients_agree_with_the_f64_build_time_function() {
    use fuzz_ps::*;
    let num = [FUZZ_PS_NUM0_F64, FUZZ_PS_NUM1_F64, FUZZ_PS_NUM2_F64, FUZZ_PS_NUM3_F64, FUZZ_PS_NUM4_F64, FUZZ_PS_NUM5_F64];
    let den = [FUZZ_PS_DEN0_F64, FUZZ_PS_DEN1_F64, FUZZ_PS_DEN2_F64, FUZZ_PS_DEN3_F64, FUZZ_PS_DEN4_F64, FUZZ_PS_DEN5_F64];
    let eps = f32::EPSILON as f64;
    let mut worst = 0.0f64;
    for i in 0..=40 {
        for j in 0..=40 {
            let alpha = 0.15 + 0.85 * i as f64 / 40.0;
            let theta = std::f64::consts::FRAC_PI_2 * j as f64 / 40.0;
            let c64 = fuzz_ps_coeffs_f64(alpha, theta);
            let c32 = fuzz_ps_coeffs(alpha as f32, theta as f32);
            let (b, g, d) = (1.0 - alpha, theta.cos(), theta.sin());
            let x = [1.0, b, g, d, b * b, g * g, b * g, b * d, b * b * b, g * g * g, d * d * d, b * b * g, b * b * d, b * g * g];
            for k in 0..6 {
                let sp: f64 = num[k].iter().zip(&x).map(|(a, v)| (a * v).abs()).sum();
                let p: f64 = num[k].iter().zip(&x).map(|(a, v)| a * v).sum();
                let sq: f64 = 1.0 + den[k].iter().zip(&x[1..]).map(|(a, v)| (a * v).abs()).sum::<f64>();
                let q: f64 = 1.0 + den[k].iter().zip(&x[1..]).map(|(a, v)| a * v).sum::<f64>();
                assert!(q > 0.0, "denominator {k} at ({alpha}, {theta}) = {q}");
                let bound = b * 32.0 * eps * (sp + (p / q).abs() * sq) / q + 4.0 * eps * c64[k].abs().max(1.0);
                let diff = (c32[k] as f64 - c64[k]).abs();
                assert!(diff <= bound, "c{k}({alpha}, {theta}): f32 {} vs f64 {} (|Δ| {diff:e} > {bound:e})", c32[k], c64[k]);
                worst = worst.max(diff);
            }
        }
    }
    assert!(worst > 0.0, "the two paths cannot agree bit for bit in every coefficient");
}

#[test]
fn ambient_functions_are_finite_and_in_range() {
    for x in specials() {
        // Q̃ and R̃ are fractions of light; their fits stay within their measured error
        // (< 0.01 in the headers) of [0, 1].
        let q = fuzz_q::fuzz_average_penetration(x);
        assert!(q.is_finite() && (-0.01..=1.01).contains(&q), "Q̃({x}) = {q}");
        for y in specials() {
            let r = fuzz_r::fuzz_average_ps(x, y);
            assert!(r.is_finite() && (-0.01..=1.01).contains(&r), "R̃({x}, {y}) = {r}");
            // G̃ ∈ [0, 1] up to its fit error (max 0.11 in its header).
            let g = fuzz_g::fuzz_g(x, y);
            assert!(g.is_finite() && (-0.12..=1.12).contains(&g), "G̃({x}, {y}) = {g}");
        }
    }
}
