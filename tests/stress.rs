//! Property-based stress tests of the integrators' numerical stability (proptest, fixed seed).
//!
//! Every integrator of the families (`shadefit::family::*::integrals`) over its documented domain and beyond its edges:
//! results finite (or the documented NaN / panic for invalid input), inside the bounds theory
//! gives, monotone where theory says so, continuous across the seams where the code switches
//! formulas or splits its domain, and finite at extreme parameters (with a printed table of how
//! the error estimates grow there).
//!
//! Runs are reproducible: ChaCha with a fixed seed, no failure persistence, so CI draws the same
//! cases every time (`PROPTEST_RNG_SEED` is not read).

use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, RngSeed};
use shadefit::integrate::Tolerance;
use shadefit::family::fuzz::integrals::{self as fuzz, expn, g, g_exact, ps, q, q_exact, r};
use shadefit::family::gloss::integrals::{
    alpha_from_gloss, combine, gloss_from_length, length_from_gloss, length_range, normal_length,
    normal_length_quadrature, one_minus_length,
};
use shadefit::family::skin::integrals::{Kernel, default_skin_profile, punctual, sh_band};
use std::f64::consts::{FRAC_PI_2, PI};
use std::time::Instant;

const EPS: f64 = f64::EPSILON;

/// Deterministic proptest configuration: `cases` draws from a fixed ChaCha seed.
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x5AD3_F17E),
        failure_persistence: None,
        // Shrinking re-runs expensive integrals; a few dozen steps locate a failure well enough.
        max_shrink_iters: 64,
        ..ProptestConfig::default()
    }
}

/// 10^e for e uniform in [lo, hi]: log-uniform draws over many decades.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..=hi).prop_map(|e| 10f64.powf(e))
}

/// The two sides x·(1 ∓ 1e-12) of a seam at x.
fn sides(x: f64) -> (f64, f64) {
    (x * (1.0 - 1e-12), x * (1.0 + 1e-12))
}

// ---------------------------------------------------------------------------------------------
// gloss

proptest! {
    #![proptest_config(config(2000))]

    #[test]
    fn gloss_length_bounded_and_increasing(g0 in 0.0f64..=1.0, dg in 1e-6f64..=1.0) {
        let g1 = (g0 + dg).min(1.0);
        let (l0, l1) = (length_from_gloss(g0), length_from_gloss(g1));
        // L ∈ [2/3, 1] exactly: 2/3 at α = 1 (series, first term) and 1 − L > 0 computed
        // without cancellation, so no rounding slack is needed.
        prop_assert!((2.0 / 3.0..=1.0).contains(&l0), "L({g0}) = {l0}");
        // dL/dg ≥ ~1e-5 on [0, 1] (smallest at g = 1), so a gloss step ≥ 1e-6 moves L by
        // ≥ 1e-11, far above L's few-ulp rounding (1e-15): strict increase is required.
        if g1 > g0 {
            prop_assert!(l1 > l0, "L({g0}) = {l0} not < L({g1}) = {l1}");
        }
    }

    #[test]
    fn gloss_round_trip(g0 in 0.0f64..=1.0) {
        let back = gloss_from_length(length_from_gloss(g0));
        // L is a few ulps (≤ 4e-16) accurate and dL/dg ≥ 1e-5, so g is determined to
        // ≤ 4e-11; the root finder adds about one ulp of g.
        prop_assert!((back - g0).abs() <= 1e-10, "g = {g0} -> {back}");
    }

    #[test]
    fn gloss_inverse_then_forward(t in 0.0f64..=1.0) {
        let (lo, hi) = length_range();
        let l = lo + t * (hi - lo);
        let again = length_from_gloss(gloss_from_length(l));
        // g is the root to one ulp (≤ 1.1e-16), dL/dg ≤ 1, plus L's own rounding: 1e-15.
        prop_assert!((again - l).abs() <= 1e-15, "L = {l} -> {again}");
    }

    #[test]
    fn gloss_inverse_clamps_outside_the_table(t in 0.0f64..=1.0, big in 1.0f64..=1e300) {
        let (lo, hi) = length_range();
        // Documented: clamped to g = 0 below L(0) = 2/3 and to g = 1 above L(1), exactly.
        prop_assert_eq!(gloss_from_length(lo * t), 0.0);
        prop_assert_eq!(gloss_from_length(-big), 0.0);
        prop_assert_eq!(gloss_from_length(hi + (1.0 - hi) * t), 1.0);
        prop_assert_eq!(gloss_from_length(big), 1.0);
    }

    #[test]
    fn gloss_combine_in_range_and_no_glossier_than_inputs(x in 0.0f64..=1.0, y in 0.0f64..=1.0) {
        let c = combine(x, y);
        prop_assert!((0.0..=1.0).contains(&c));
        // L(x)·L(y) ≤ min(L(x), L(y)) and L increases, so the combination is at most the
        // smaller gloss; 1e-10 is the round-trip accuracy of the inverse (above).
        prop_assert!(c <= x.min(y) + 1e-10, "combine({x}, {y}) = {c}");
    }
}

#[test]
fn gloss_outside_its_domain() {
    // NaN stays NaN (it used to bisect to ≈ 3e-20).
    assert!(shadefit::family::gloss::integrals::gloss_from_length(f64::NAN).is_nan());
    // α slightly above 1 (k < 0): the series' terms alternate, and L stays continuous through
    // α = 1 (L = 2/3 exactly there): the first-order change is dL/dα·Δα with |dL/dα| < 1.
    for da in [1e-12, 1e-9, 1e-6] {
        let l = shadefit::family::gloss::integrals::normal_length(1.0 + da);
        assert!((l - 2.0 / 3.0).abs() <= da, "L(1 + {da:e}) = {l}");
    }
    // Well above 1 the series must keep summing its alternating terms (it used to stop at the
    // first negative one: 1e-2 off at α = 1.2); the quadrature is accurate to ~1e-14.
    for a in [1.05, 1.2, 1.4] {
        let (l, quad) = (shadefit::family::gloss::integrals::normal_length(a), normal_length_quadrature(a, 1e-14).value);
        assert!((l - quad).abs() < 1e-12, "L({a}) = {l}, quadrature {quad}");
    }
}

#[test]
fn gloss_series_switch_is_continuous() {
    // The closed form switches from the power series to the logarithmic form at k = 1 − α² = ½.
    let a0 = 0.5f64.sqrt();
    let (lo, hi) = sides(a0);
    let jump = (normal_length(lo) - normal_length(hi)).abs();
    // Same-side slope far enough from the switch that rounding does not matter.
    let slope = (normal_length(a0 * 0.999) - normal_length(a0 * 0.998)).abs() / (0.001 * a0);
    // The exact change over the 2e-12·α step, doubled, plus 4 ulps of rounding in each branch.
    let bound = 2.0 * slope * 2e-12 * a0 + 8.0 * EPS;
    assert!(jump <= bound, "L jumps by {jump:e} at k = 1/2 (bound {bound:e})");
    let jump_oml = (one_minus_length(lo) - one_minus_length(hi)).abs();
    assert!(jump_oml <= bound, "1 − L jumps by {jump_oml:e} at k = 1/2 (bound {bound:e})");
}

#[test]
fn gloss_near_one_matches_the_small_alpha_expansion() {
    // g → 1: α → 0.00276 and L → 1; 1 − L is computed directly (no 1 − ‖n‖ cancellation).
    for g0 in [0.9, 0.99, 0.999, 1.0, 1.0 - 1e-12] {
        let a = alpha_from_gloss(g0);
        let oml = one_minus_length(a);
        let approx = a * a * ((2.0 / a).ln() - 1.0);
        // Next term of the expansion is O(α⁴ ln α): relative α² ln(2/α) ≤ 1e-3 for α ≤ 0.02.
        let rel = (oml - approx).abs() / approx;
        assert!(rel <= 4.0 * a * a * (2.0 / a).ln(), "g={g0} α={a}: 1−L={oml:e} vs {approx:e}");
        // Independent quadrature of L to 1e-14 (the unit test's acceptance bound 1e-12).
        let quad = normal_length_quadrature(a, 1e-14);
        assert!((normal_length(a) - quad.value).abs() <= 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------
// fuzz: P_s

/// The light polar angles θu ∈ (0.01, π − 0.01) at which u·t = ±sin θf for this (θf, φu): the
/// specular cone w = −u·t then crosses a square-root point w = ∓sin θf of the 1-D integrand
/// (where the horizon arc opens/closes) and the code's piece layout changes. θu = π/2 with
/// φu = 0 or π is the horizon itself.
fn cone_breakpoints(theta_f: f64, phi_u: f64) -> Vec<f64> {
    let (a, b) = (theta_f.cos(), theta_f.sin() * phi_u.cos());
    let (rr, base) = (a.hypot(b), b.atan2(a));
    let mut out = Vec::new();
    for s in [theta_f.sin(), -theta_f.sin()] {
        if s.abs() < rr {
            let c = (s / rr).acos();
            for t in [base + c, base - c, base + c - 2.0 * PI, base - c + 2.0 * PI] {
                if t > 0.01 && t < PI - 0.01 {
                    out.push(t);
                }
            }
        }
    }
    out
}

/// Bound on the exact change of P_s between two light directions δ radians apart: P_s varies
/// on the angular scale of the scattering band width α (module doc), so |∂P_s/∂θu| ≤ 10/α
/// holds with room.
fn ps_change_bound(alpha: f64, delta: f64) -> f64 {
    10.0 / alpha * delta
}

/// Factor on P_s's error estimate where it serves as a tolerance: near grazing, where a cone
/// breakpoint approaches the horizon, the estimate was measured ~5x below the true error
/// (`ps_error_estimates_bound_the_jump_at_seams`, ignored, with the case); 10 leaves a factor 2.
const PS_ESTIMATE_SLACK: f64 = 10.0;

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn ps_is_a_probability_anywhere(
        alpha in 0.05f64..=1.0,
        theta_f in 0.0f64..=FRAC_PI_2,
        theta_u in 0.0f64..=PI,
        phi_u in -PI..=PI,
    ) {
        let e = ps(alpha, theta_f, theta_u, phi_u, fuzz::DEFAULT_TOL);
        prop_assert!(e.value.is_finite() && e.error.is_finite() && e.error >= 0.0, "{e:?}");
        // P_s ∈ [0, 1]; the computed value may leave it by its own error (the estimate times
        // PS_ESTIMATE_SLACK: it can be ~5x low near grazing).
        let slack = PS_ESTIMATE_SLACK * e.error;
        prop_assert!(e.value >= -slack && e.value <= 1.0 + slack, "{e:?}");
        // P_s(−u) = 1 − P_s(u) (p(−u, −v) = p(u, v)): −u is (π − θu, φu + π). Both values
        // carry their errors; 1e-15 covers the rounding of the sum.
        let m = ps(alpha, theta_f, PI - theta_u, phi_u + PI, fuzz::DEFAULT_TOL);
        let s = e.value + m.value - 1.0;
        prop_assert!(s.abs() <= PS_ESTIMATE_SLACK * (e.error + m.error) + 1e-15, "P_s(u) + P_s(−u) − 1 = {s:e}, {e:?} {m:?}");
    }

    #[test]
    fn ps_folds_fibers_outside_the_quarter(
        alpha in 0.05f64..=1.0,
        theta_f in 0.0f64..=FRAC_PI_2,
        theta_u in 0.0f64..=PI,
        phi_u in 0.0f64..=PI,
    ) {
        // (θf, φu) → (π − θf, π − φu) is the mirror x → −x with t ≡ −t (module doc), and
        // θf → −θf with φu → π − φu is the same mirror without the sign flip of t.
        let e = ps(alpha, theta_f, theta_u, phi_u, fuzz::DEFAULT_TOL);
        for (tf, pu) in [(PI - theta_f, PI - phi_u), (-theta_f, PI - phi_u)] {
            let f = ps(alpha, tf, theta_u, pu, fuzz::DEFAULT_TOL);
            // Two estimates of the same exact value (errors as above).
            prop_assert!((e.value - f.value).abs() <= PS_ESTIMATE_SLACK * (e.error + f.error),
                "θf={tf} φu={pu}: {e:?} vs {f:?}");
        }
    }

    #[test]
    fn ps_continuous_across_horizon_and_cone_breakpoints(
        alpha in 0.05f64..=1.0,
        theta_f in 0.02f64..=(FRAC_PI_2 - 0.02),
        phi_u in -PI..=PI,
    ) {
        let mut seams = cone_breakpoints(theta_f, phi_u);
        seams.push(FRAC_PI_2); // the light crosses the horizon
        for t in seams {
            let (lo, hi) = sides(t);
            let a = ps(alpha, theta_f, lo, phi_u, fuzz::DEFAULT_TOL);
            let b = ps(alpha, theta_f, hi, phi_u, fuzz::DEFAULT_TOL);
            // Each side within the requested absolute tolerance of the exact value, plus the
            // exact change over the 2e-12·θu step. (The error estimates are not used here: near
            // grazing they can under-estimate, see the ignored test below.)
            let bound = 2.0 * fuzz::DEFAULT_TOL + ps_change_bound(alpha, hi - lo);
            prop_assert!((a.value - b.value).abs() <= bound,
                "θu = {t}: {:e} vs {:e} (jump {:e}, bound {bound:e})",
                a.value, b.value, (a.value - b.value).abs());
        }
    }

    #[test]
    #[ignore = "P_s error estimate under-estimates by up to ~5x where a cone breakpoint u·t = ±sin θf \
        lies near the horizon (α=0.7313235413475364, θf=0.7591197175920795, φu=0.0210058222942479, \
        θu=1.570586992275441·(1−1e-12): tol 1e-9 gives 0.65132623178518, error estimate 3.1e-11, \
        tol 1e-13 gives 0.65132623162713: off by 1.58e-10); within the requested tolerance"]
    fn ps_error_estimates_bound_the_jump_at_seams(
        alpha in 0.05f64..=1.0,
        theta_f in 0.02f64..=(FRAC_PI_2 - 0.02),
        phi_u in -PI..=PI,
    ) {
        let mut seams = cone_breakpoints(theta_f, phi_u);
        seams.push(FRAC_PI_2);
        for t in seams {
            let (lo, hi) = sides(t);
            let a = ps(alpha, theta_f, lo, phi_u, fuzz::DEFAULT_TOL);
            let b = ps(alpha, theta_f, hi, phi_u, fuzz::DEFAULT_TOL);
            // Both error estimates (documented as upper estimates of |value − exact|) plus the
            // exact change over the 2e-12·θu step.
            let bound = a.error + b.error + ps_change_bound(alpha, hi - lo);
            prop_assert!((a.value - b.value).abs() <= bound,
                "θu = {t}: {:e} vs {:e} (jump {:e}, bound {bound:e})",
                a.value, b.value, (a.value - b.value).abs());
        }
    }
}

#[test]
fn ps_special_values() {
    // α = 1: the phase function is isotropic, P_s ≡ ½ (up to the estimate).
    for (tf, tu, pu) in [(0.0, 0.3, 0.0), (1.0, 1.5, 2.0), (FRAC_PI_2, 2.5, -1.0)] {
        let e = ps(1.0, tf, tu, pu, fuzz::DEFAULT_TOL);
        assert!((e.value - 0.5).abs() <= e.error, "α=1: {e:?}");
    }
    // θf = 0: u·t = u·n, P_s does not depend on φu.
    let a = ps(0.3, 0.0, 0.7, 0.0, fuzz::DEFAULT_TOL);
    let b = ps(0.3, 0.0, 0.7, 2.1, fuzz::DEFAULT_TOL);
    assert!((a.value - b.value).abs() <= a.error + b.error);
    // θf → 0 is continuous: the fiber leaves the normal by 1e-12 rad, P_s moves by ≤ 10/α·1e-12.
    let c = ps(0.3, 1e-12, 0.7, 2.1, fuzz::DEFAULT_TOL);
    assert!((c.value - b.value).abs() <= b.error + c.error + ps_change_bound(0.3, 1e-12));
}

#[test]
fn ps_documented_invalid_input() {
    // Documented: NaN estimate (error ∞) for α outside (0, 1] or non-finite angles.
    for (a, tf, tu, pu) in [
        (0.0, 0.5, 0.5, 0.5),
        (-0.1, 0.5, 0.5, 0.5),
        (1.0 + 1e-15, 0.5, 0.5, 0.5),
        (f64::NAN, 0.5, 0.5, 0.5),
        (0.5, f64::NAN, 0.5, 0.5),
        (0.5, 0.5, f64::INFINITY, 0.5),
        (0.5, 0.5, 0.5, f64::NEG_INFINITY),
    ] {
        let e = ps(a, tf, tu, pu, fuzz::DEFAULT_TOL);
        assert!(e.value.is_nan() && e.error == f64::INFINITY, "ps({a}, {tf}, {tu}, {pu}) = {e:?}");
    }
    for (a, tf) in [(0.0, 0.5), (1.5, 0.5), (0.5, f64::INFINITY)] {
        let e = r(a, tf, fuzz::DEFAULT_TOL);
        assert!(e.value.is_nan() && e.error == f64::INFINITY, "r({a}, {tf}) = {e:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// fuzz: R (≈ 1 ms each at tolerance 1e-8)

const R_TOL: f64 = 1e-8;

proptest! {
    #![proptest_config(config(24))]

    #[test]
    fn r_is_a_probability(alpha in 0.05f64..=1.0, theta_f in 0.0f64..=FRAC_PI_2) {
        let e = r(alpha, theta_f, R_TOL);
        prop_assert!(e.value.is_finite() && e.error.is_finite(), "{e:?}");
        // R is a cosine-weighted mean of P_s ∈ [0, 1]; the value may leave it by its estimate.
        prop_assert!(e.value >= -e.error && e.value <= 1.0 + e.error, "{e:?}");
    }
}

#[test]
fn r_seams_in_theta_f() {
    // R splits the fiber-polar integral at A = π/2 − θf; that piece vanishes as θf → π/2 and
    // the fold t ≡ −t takes over beyond it; at θf → 0 the arc range vanishes.
    let alpha = 0.4;
    let (lo, hi) = sides(FRAC_PI_2);
    let a = r(alpha, lo, R_TOL);
    let b = r(alpha, hi, R_TOL);
    // The two estimates; R's exact change over 3e-12 rad is below 1e-10 (|∂R/∂θf| ≤ 10/α as
    // for P_s, R being a mean of it).
    let change = ps_change_bound(alpha, hi - lo);
    assert!((a.value - b.value).abs() <= a.error + b.error + change, "θf=π/2: {a:?} {b:?}");
    let c = r(alpha, 0.0, R_TOL);
    let d = r(alpha, 1e-12, R_TOL);
    assert!((c.value - d.value).abs() <= c.error + d.error + ps_change_bound(alpha, 1e-12), "θf=0: {c:?} {d:?}");
    // α = 1 gives R = ½ (isotropic phase function).
    let h = r(1.0, 0.7, R_TOL);
    assert!((h.value - 0.5).abs() <= h.error, "α=1: {h:?}");
}

// ---------------------------------------------------------------------------------------------
// fuzz: G and Q

/// Documented absolute rounding bound of `g_exact`: 1e-15·(1 + |ln d|).
fn g_round(d: f64) -> f64 {
    1e-15 * (1.0 + d.ln().abs())
}

proptest! {
    #![proptest_config(config(2000))]

    #[test]
    fn g_bounded_monotone_and_matching_closed_form(
        d in log_uniform(-300.0, 2.0),
        mu_v in log_uniform(-300.0, 0.0),
        fd in 1.0f64..=4.0,
        fm in 1.0f64..=4.0,
    ) {
        let mu_v = mu_v.min(1.0);
        let e = g(d, mu_v, fuzz::DEFAULT_TOL);
        let x = g_exact(d, mu_v);
        prop_assert!(e.value.is_finite() && e.error.is_finite() && x.is_finite(), "{e:?} {x}");
        // G ∈ [0, 1]: the quadrature within its estimate, the closed form within its rounding.
        prop_assert!(e.value >= -e.error && e.value <= 1.0 + e.error, "G({d:e}, {mu_v:e}) = {e:?}");
        prop_assert!(x >= -g_round(d) && x <= 1.0 + g_round(d), "G_exact({d:e}, {mu_v:e}) = {x:e}");
        // Quadrature against closed form: estimate plus the closed form's rounding.
        prop_assert!((e.value - x).abs() <= e.error + g_round(d),
            "G({d:e}, {mu_v:e}): quad {e:?} vs exact {x:e}");
        // Both factors of the integrand, (1 − e^{−d/μv} e^{−d/μ}) and μ/(μ + μv), grow with d
        // and shrink with μv: G increases in d and decreases in μv, up to rounding on each side.
        let (d2, m2) = (d * fd, (mu_v * fm).min(1.0));
        let xd = g_exact(d2, mu_v);
        prop_assert!(xd >= x - g_round(d) - g_round(d2), "G not increasing in d: {x:e} -> {xd:e} at d {d:e} -> {d2:e}");
        let xm = g_exact(d, m2);
        prop_assert!(xm <= x + 2.0 * g_round(d), "G not decreasing in μv: {x:e} -> {xm:e} at μv {mu_v:e} -> {m2:e}");
    }

    #[test]
    fn g_continuous_where_mu_v_meets_d(d in log_uniform(-12.0, 0.0)) {
        // The quadrature is split at μ = d and μ = μv; at μv = d the two cuts merge.
        let (lo, hi) = sides(d);
        let a = g(d, lo, fuzz::DEFAULT_TOL);
        let b = g(d, hi, fuzz::DEFAULT_TOL);
        // Estimates, plus the exact change (closed form, with its rounding on both sides).
        let change = (g_exact(d, lo) - g_exact(d, hi)).abs() + 2.0 * g_round(d);
        prop_assert!((a.value - b.value).abs() <= a.error + b.error + change, "{a:?} {b:?}");
    }

    #[test]
    fn q_bounded_decreasing_and_matching_closed_form(d in log_uniform(-300.0, 2.5), f in 1.0f64..=4.0) {
        let x = q_exact(d);
        // Q ∈ (0, 1] (Q(0) = 1, Q = 2E₃ > 0 while representable: d ≤ 316 here).
        prop_assert!(x > 0.0 && x <= 1.0, "Q({d:e}) = {x:e}");
        // Q decreasing in d: E_n is a few ulps relative accurate (its doc), so allow 8 ulps.
        let x2 = q_exact(d * f);
        prop_assert!(x2 <= x * (1.0 + 8.0 * EPS), "Q({d:e}) = {x:e} < Q({:e}) = {x2:e}", d * f);
        let e = q(d, fuzz::DEFAULT_TOL);
        // Quadrature within its estimate of the closed form (plus its 8 ulps).
        prop_assert!((e.value - x).abs() <= e.error + 8.0 * EPS * x, "Q({d:e}): {e:?} vs {x:e}");
    }
}

#[test]
fn expn_continuous_at_the_series_fraction_switch() {
    // E_n switches from its power series to the continued fraction at x = 1.
    let (lo, hi) = sides(1.0);
    for n in 1..=4u32 {
        let jump = (expn(n, lo) - expn(n, hi)).abs();
        // Exact change: |E_n'| = E_{n−1}(1) ≤ E_0(1) = 1/e over 2e-12, plus a few ulps
        // relative on each side (E_n(1) ≤ E_1(1) = 0.22).
        let bound = 2e-12 / std::f64::consts::E + 8.0 * EPS * expn(n, 1.0);
        assert!(jump <= bound, "E_{n} jumps by {jump:e} at x = 1 (bound {bound:e})");
    }
    // Q = 2E₃ and G's E₁(d(1 + μv)/μv) cross the same switch at d = 1.
    let jump = (q_exact(lo) - q_exact(hi)).abs();
    assert!(jump <= 2.0 * (2e-12 / std::f64::consts::E + 8.0 * EPS * 0.2), "Q jumps by {jump:e}");
    let jump = (g_exact(lo, 0.3) - g_exact(hi, 0.3)).abs();
    // |∂G/∂d| ≤ 1/μv (the integrand's d-derivative is ≤ (1/μv + 1/μ)·μ/(μ + μv) ≤ 1/μv).
    assert!(jump <= 2e-12 / 0.3 + 2.0 * g_round(1.0), "G jumps by {jump:e} at d = 1");
    let d_seam = 0.3 / 1.3; // d(1 + μv)/μv = 1
    let (lo, hi) = sides(d_seam);
    let jump = (g_exact(lo, 0.3) - g_exact(hi, 0.3)).abs();
    assert!(jump <= 2e-12 * d_seam / 0.3 + 2.0 * g_round(d_seam), "G jumps by {jump:e} at d = {d_seam}");
}

#[test]
fn g_and_q_documented_limits_and_invalid_input() {
    // Documented exact values: G(0, μv) = 0, G(d, 0) = 1, Q(0) = 1.
    assert_eq!(g(0.0, 0.5, 0.0).value, 0.0);
    assert_eq!(g(0.5, 0.0, 0.0).value, 1.0);
    assert_eq!(g_exact(0.0, 0.5), 0.0);
    assert_eq!(g_exact(0.5, 0.0), 1.0);
    assert_eq!(q_exact(0.0), 1.0);
    // Documented: NaN for d < 0, μv < 0 or NaN.
    for (d, m) in [(-1e-300, 0.5), (0.5, -1e-300), (f64::NAN, 0.5), (0.5, f64::NAN)] {
        let e = g(d, m, 0.0);
        assert!(e.value.is_nan() && e.error == f64::INFINITY, "g({d}, {m}) = {e:?}");
        assert!(g_exact(d, m).is_nan(), "g_exact({d}, {m})");
    }
    for d in [-1e-300, -1.0, f64::NAN] {
        let e = q(d, 0.0);
        assert!(e.value.is_nan() && e.error == f64::INFINITY, "q({d}) = {e:?}");
    }
    // E_n documented NaN outside its domain; E_n(∞) = 0.
    assert!(expn(1, 0.0).is_nan() && expn(2, -1.0).is_nan() && expn(3, f64::NAN).is_nan());
    assert_eq!(expn(3, f64::INFINITY), 0.0);
}

// ---------------------------------------------------------------------------------------------
// skin

fn skin_tol() -> Tolerance {
    Tolerance { abs: 1e-10, rel: 0.0, max_panels: 2000 }
}

proptest! {
    #![proptest_config(config(500))]

    #[test]
    fn skin_punctual_bounded_and_increasing_in_n_dot_l(
        kappa in log_uniform(-6.0, 2.0),
        nl in -1.0f64..=1.0,
        dnl in 1e-3f64..=2.0,
        radial in any::<bool>(),
    ) {
        let kernel = if radial { Kernel::Radial } else { Kernel::Linear };
        let profile = default_skin_profile();
        let nl2 = (nl + dnl).min(1.0);
        let a = punctual(&profile, kernel, kappa, nl, skin_tol()).unwrap();
        let b = punctual(&profile, kernel, kappa, nl2, skin_tol()).unwrap();
        for c in 0..3 {
            let (x, y) = (a[c], b[c]);
            prop_assert!(x.value.is_finite() && x.error.is_finite());
            // D ∈ [0, 1] per channel, up to its estimate.
            prop_assert!(x.value >= -x.error && x.value <= 1.0 + x.error, "channel {c}: {x:?}");
            // D is a kernel-weighted mean of max(cos(θ ± κu), 0), each non-decreasing in n·l:
            // D is non-decreasing, up to both estimates.
            prop_assert!(y.value >= x.value - x.error - y.error,
                "channel {c}: D({nl}) = {:e} > D({nl2}) = {:e}", x.value, y.value);
        }
    }

    #[test]
    fn skin_sh_bands_bounded(kappa in log_uniform(-6.0, 3.0), band in 1u32..=4) {
        let k = sh_band(&default_skin_profile(), kappa, band, skin_tol()).unwrap();
        for e in k {
            prop_assert!(e.value.is_finite() && e.error.is_finite());
            // |k_l| ≤ 1 (|P_l| ≤ 1 under a normalised positive kernel), up to the estimate.
            prop_assert!(e.value.abs() <= 1.0 + e.error, "κ={kappa:e} l={band}: {e:?}");
        }
    }
}

#[test]
fn skin_documented_limits_and_invalid_input() {
    let p = default_skin_profile();
    // κ = 0: max(n·l, 0) exactly; k_0 = 1 exactly.
    for nl in [-1.0, -0.3, 0.0, 0.6, 1.0] {
        let d = punctual(&p, Kernel::Linear, 0.0, nl, skin_tol()).unwrap();
        assert!(d.iter().all(|e| e.value == f64::max(nl, 0.0)));
    }
    assert!(sh_band(&p, 3.0, 0, skin_tol()).unwrap().iter().all(|e| e.value == 1.0));
    // Documented panics: κ < 0, non-finite κ, NaN n·l, n·l outside [−1, 1] beyond 1e-12.
    // (Each caught panic prints its message; the hook is left alone so that other tests
    // running meanwhile keep theirs.)
    for (k, nl) in [(-1e-9, 0.5), (f64::NAN, 0.5), (f64::INFINITY, 0.5), (0.5, f64::NAN), (0.5, 1.0 + 1e-9), (0.5, -1.0 - 1e-9)] {
        let r = std::panic::catch_unwind(|| punctual(&default_skin_profile(), Kernel::Linear, k, nl, skin_tol()));
        assert!(r.is_err(), "punctual(κ={k}, n·l={nl}) did not panic");
    }
    for k in [-1e-9, f64::NAN, f64::INFINITY] {
        let r = std::panic::catch_unwind(|| sh_band(&default_skin_profile(), k, 1, skin_tol()));
        assert!(r.is_err(), "sh_band(κ={k}) did not panic");
    }
    // n·l within 1e-12 outside [−1, 1] is rounding: clamped, no panic.
    let d = punctual(&p, Kernel::Linear, 0.5, 1.0 + 1e-13, skin_tol()).unwrap();
    let e = punctual(&p, Kernel::Linear, 0.5, 1.0, skin_tol()).unwrap();
    assert_eq!(d, e);
}

// ---------------------------------------------------------------------------------------------
// Extreme parameters: finiteness and bounds, with a table of the error estimates.

fn row(quantity: &str, params: String, value: f64, error: f64, evals: u64, t: Instant) {
    eprintln!(
        "{quantity:<14} {params:<34} {value:>22.15e} {error:>10.2e} {evals:>9} {:>9.2}",
        t.elapsed().as_secs_f64() * 1e3
    );
}

#[test]
fn extreme_parameters_table() {
    eprintln!("\n{:<14} {:<34} {:>22} {:>10} {:>9} {:>9}", "quantity", "parameters", "value", "error est", "evals", "ms");
    let in_unit = |v: f64, e: f64| v.is_finite() && e.is_finite() && v >= -e && v <= 1.0 + e;
    // P_s, α → 0 (published minimum 0.15) at a grazing light and at one across the fiber.
    for alpha in [0.15, 0.05, 0.02, 0.01, 0.005, 0.001] {
        for (tu, pu) in [(FRAC_PI_2 - 1e-3, 0.4), (1.0, 2.0)] {
            let t = Instant::now();
            let e = ps(alpha, 0.6, tu, pu, fuzz::DEFAULT_TOL);
            row("P_s", format!("α={alpha} θf=0.6 θu={tu:.4} φu={pu}"), e.value, e.error, e.evals, t);
            assert!(in_unit(e.value, e.error), "{e:?}");
        }
    }
    // P_s, θf → 0.
    for tf in [0.1, 1e-3, 1e-8, 1e-12, 0.0] {
        let t = Instant::now();
        let e = ps(0.15, tf, 1.2, 0.5, fuzz::DEFAULT_TOL);
        row("P_s", format!("α=0.15 θf={tf:e} θu=1.2 φu=0.5"), e.value, e.error, e.evals, t);
        assert!(in_unit(e.value, e.error), "{e:?}");
    }
    // R, α below the published 0.15 and θf → 0.
    for (alpha, tf) in [(0.15, 0.6), (0.05, 0.6), (0.02, 0.6), (0.15, 1e-8), (0.05, 0.0)] {
        let t = Instant::now();
        let e = r(alpha, tf, R_TOL);
        row("R", format!("α={alpha} θf={tf:e} (tol 1e-8)"), e.value, e.error, e.evals, t);
        assert!(in_unit(e.value, e.error), "{e:?}");
    }
    // G, d → 0, d large, μv → 0.
    for (d, mv) in [(1e-300, 0.5), (1e-12, 0.5), (1e-3, 1e-300), (0.5, 1e-300), (1e-300, 1e-300), (30.0, 0.5), (700.0, 1e-3), (1e5, 1.0)] {
        let t = Instant::now();
        let e = g(d, mv, fuzz::DEFAULT_TOL);
        row("G", format!("d={d:e} μv={mv:e}"), e.value, e.error, e.evals, t);
        let x = g_exact(d, mv);
        assert!(in_unit(e.value, e.error) && (e.value - x).abs() <= e.error + g_round(d), "{e:?} vs {x:e}");
    }
    // Q, d → 0 and d large.
    for d in [1e-300, 1e-12, 1.0, 30.0, 300.0, 700.0] {
        let t = Instant::now();
        let e = q(d, fuzz::DEFAULT_TOL);
        row("Q", format!("d={d:e}"), e.value, e.error, e.evals, t);
        let x = q_exact(d);
        assert!(x > 0.0 && x <= 1.0 && (e.value - x).abs() <= e.error + 8.0 * EPS * x, "{e:?} vs {x:e}");
    }
    // gloss → 1: 1 − L without cancellation.
    for g0 in [0.5, 0.9, 0.99, 1.0] {
        let t = Instant::now();
        let a = alpha_from_gloss(g0);
        let quad = normal_length_quadrature(a, 1e-14);
        let diff = (normal_length(a) - quad.value).abs();
        row("1 − L", format!("g={g0} α={a:.6e} (err = |L − quad|)"), one_minus_length(a), diff, quad.evals, t);
        assert!(diff <= 1e-12);
    }
    // skin, κ → 0 and large κ (red channel, which has the widest profile).
    let p = default_skin_profile();
    for kappa in [1e-12, 1e-6, 1e-2, 1.0, 1e2, 1e4] {
        let t = Instant::now();
        let d = punctual(&p, Kernel::Linear, kappa, 0.3, skin_tol()).unwrap();
        row("skin D (R)", format!("κ={kappa:e} n·l=0.3"), d[0].value, d[0].error, d[0].evals, t);
        assert!(d.iter().all(|e| in_unit(e.value, e.error)));
        let t = Instant::now();
        let k = sh_band(&p, kappa, 1, skin_tol()).unwrap();
        row("skin k_1 (R)", format!("κ={kappa:e}"), k[0].value, k[0].error, k[0].evals, t);
        assert!(k.iter().all(|e| e.value.is_finite() && e.value.abs() <= 1.0 + e.error));
    }
    // Limits the module doc states: κ → ∞ gives the ring average 1/π, κ → 0 gives n·l.
    let d = punctual(&p, Kernel::Linear, 1e4, 0.3, skin_tol()).unwrap();
    eprintln!("skin D at κ = 1e4: {:?} (ring average 1/π = {:.6})", d.map(|e| e.value), 1.0 / PI);
}

