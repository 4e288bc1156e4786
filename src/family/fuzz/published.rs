//! Ghost of Tsushima fuzz constants (supplemental, Appendices A, C, E, G: Listings 1–5).

/// Listing 1: s_PsCoeffs[6][27] — per i: t, p[13] (numerator), q[13] (denominator).
pub const PS_COEFFS: [[f64; 27]; 6] = [
    [
        0.13756974, 0.089967924, -0.043263807, 0.012549466, -0.039043481, -0.18738464,
        0.019518992, -0.14037448, -0.018000072, 0.080983287, -0.12573283, 0.030190086,
        0.082546164, -0.067284671, -1.4158549, -0.8067329, -0.18696706, 0.85672806,
        0.73143116, 0.15639405, -0.3532818, -0.57225366, -0.12095449, 0.036308587,
        0.72092589, 0.60578342, -0.58250484,
    ],
    [
        -2.7184817, -5.8696774, 8.0163004, -3.1600727, 3.8612209, -5.1905628,
        -5.0022991, 10.047277, 0.18762356, 0.37025318, 2.4688789, -2.4440128,
        -4.838545, 8.5374892, -8.0595452, -17.180627, 1.0716076, 4.4852769,
        29.035032, 9.6089763, -0.85605057, -2.6545399, -7.9458921, 4.995542,
        5.0528634, 0.037475838, -13.311191,
    ],
    [
        -0.78639883, 1.5746798, 2.48243, 1.3541003, -0.95093934, -4.1094587,
        -2.463887, -1.4678292, 0.051742457, 2.3265071, -0.58747343, 0.95003155,
        0.80560378, 0.92021804, -0.62641789, -4.2275626, 1.2757363, -0.20707868,
        3.8802392, 2.9039937, -2.079426, -0.067985356, -0.73187572, 0.13138015,
        0.3012767, 1.0202816, -2.2280816,
    ],
    [
        -0.24041982, -0.13259461, -0.38462128, 0.026466062, 0.19445785, 1.0051305,
        0.48317105, 0.10568307, 0.012401867, -0.44645249, 0.22808668, -0.23192799,
        -0.19285076, -0.2408241, -1.5432125, -1.3051729, -0.056543476, 0.90136729,
        0.4311222, 1.6008327, 0.11762443, -0.17825185, 0.016131527, -0.11530679,
        -0.44470983, -0.074847149, -0.47874924,
    ],
    [
        0.24779292, 1.7000882, -2.1202227, 1.0560525, -1.8178813, 1.2658071,
        2.3142857, -3.0859394, 0.29918169, 0.30209918, -0.33373112, 0.11488872,
        1.8913286, -2.3312817, -10.140274, -14.579435, 1.7571963, 6.8424411,
        18.456914, 18.485136, 1.7617207, -0.36251123, -2.8078648, 2.7987085,
        -3.2621689, -4.0289481, -13.375577,
    ],
    [
        -1.7111756, 1.1697807, -1.3136888, 0.29216331, -2.4200667, 5.5264719,
        4.008041, -1.9572698, -0.0043264307, -2.5938981, 1.3983587, 0.29401827,
        2.7673798, -4.331847, 19.422409, -3.7802382, 5.591913, -17.588813,
        6.7184933, -19.919567, -18.57141, 0.13662077, -3.5379282, -1.3720354,
        15.545388, 14.697374, 2.0091252,
    ],
];

/// Listing 3: G̃ constants.
pub const G_COEFFS: [f64; 4] = [-0.94634516, 0.41691235, 0.70663116, -0.26154413];
/// Listing 4: Q̃ constants.
pub const Q_COEFFS: [f64; 2] = [-1.7280754, 1.2661427];
/// Listing 5: R̃ constants (t, p[13], q[3]).
pub const R_COEFFS: [f64; 17] = [
    -0.26805773, 0.30887989, 0.077007705, -0.12175263, -0.14202922, 0.7331539, 0.010009714,
    -0.25925012, -0.023091515, -0.31883099, 0.25857198, -0.0031055288, 0.20038139, -0.28705017,
    -0.37659157, -0.44286302, -0.35584712,
];

/// The 13 features of Eq. 2 in the listings' order: β γ δ β² γ² βγ βδ β³ γ³ δ³ β²γ β²δ βγ².
pub fn features(alpha: f64, theta_f: f64) -> [f64; 13] {
    let (b, g, d) = (1.0 - alpha, theta_f.cos(), theta_f.sin());
    [b, g, d, b * b, g * g, b * g, b * d, b * b * b, g * g * g, d * d * d, b * b * g, b * b * d, b * g * g]
}

/// Listing 2: the six c_i(α, θf), with the listing's clamps (θf ∈ [0.1, π/2], α ∈ [0.15, 1]).
pub fn published_ps_coeffs(alpha: f64, theta_f: f64) -> [f64; 6] {
    let theta_f = theta_f.clamp(0.1, std::f64::consts::FRAC_PI_2);
    let alpha = alpha.clamp(0.15, 1.0);
    let x = features(alpha, theta_f);
    let b = 1.0 - alpha;
    let mut c = [0.0; 6];
    for (i, p) in PS_COEFFS.iter().enumerate() {
        let num = p[0] + (0..13).map(|k| p[1 + k] * x[k]).sum::<f64>();
        let den = 1.0 + (0..13).map(|k| p[14 + k] * x[k]).sum::<f64>();
        c[i] = if i == 0 { 0.5 } else { 0.0 } + b * num / den;
    }
    c
}

/// Eq. 1: P̃_s from the six coefficients.
pub fn ps_from_coeffs(c: &[f64; 6], n_dot_u: f64, t_dot_u: f64) -> f64 {
    c[0] + c[1] * n_dot_u + c[2] * t_dot_u + c[3] * n_dot_u * n_dot_u + c[4] * n_dot_u * t_dot_u + c[5] * t_dot_u * t_dot_u
}

/// Listing 3: G̃ (density clamped to ≤ 0.5 as published).
pub fn published_g(n_dot_v: f64, density: f64) -> f64 {
    let d = density.min(0.5);
    let c = G_COEFFS;
    (d * (1.0 + n_dot_v * (c[0] + n_dot_v * c[1]))) / (d + n_dot_v * (c[2] + n_dot_v * n_dot_v * c[3]))
}

/// Listing 4: Q̃.
pub fn published_q(density: f64) -> f64 {
    let d = density.min(0.5);
    1.0 + d * (Q_COEFFS[0] + d * Q_COEFFS[1])
}

/// Listing 5: R̃ (θf clamped to [0, π/2], α to [0.15, 1]).
pub fn published_r(alpha: f64, theta_f: f64) -> f64 {
    let theta_f = theta_f.clamp(0.0, std::f64::consts::FRAC_PI_2);
    let alpha = alpha.clamp(0.15, 1.0);
    let x = features(alpha, theta_f);
    let c = R_COEFFS;
    let b = 1.0 - alpha;
    let num = c[0] + (0..13).map(|k| c[1 + k] * x[k]).sum::<f64>();
    let den = 1.0 + c[14] * x[0] + c[15] * x[1] + c[16] * x[2];
    0.5 + b * num / den
}

use crate::validate::{measure, Item};
use super::integrals as fuzz;
use rayon::prelude::*;
use std::path::Path;

/// Eq. 1 with the published table's rows 3 and 4 exchanged: row 3 multiplying (u·n)(u·t) and
/// row 4 (u·n)² (what the symmetry of P_s at θf = π/2 and the integrals both say).
pub fn ps_from_coeffs_swapped(c: &[f64; 6], n_dot_u: f64, t_dot_u: f64) -> f64 {
    let s = [c[0], c[1], c[2], c[4], c[3], c[5]];
    ps_from_coeffs(&s, n_dot_u, t_dot_u)
}

fn grid(lo0: f64, hi0: f64, n0: usize, lo1: f64, hi1: f64, n1: usize) -> Vec<Vec<f64>> {
    let a = fuzz::linspace(lo0, hi0, n0);
    let b = fuzz::linspace(lo1, hi1, n1);
    b.iter().flat_map(|&y| a.iter().map(move |&x| vec![x, y])).collect()
}

pub fn items(generated: &Path) -> Vec<Item> {
    let mut out = Vec::new();

    // Q̃ on d ∈ [0, 0.5].
    let pts: Vec<Vec<f64>> = fuzz::linspace(0.0, 0.5, 2049).into_iter().map(|d| vec![d]).collect();
    let truth: Vec<f64> = pts.iter().map(|p| fuzz::q_exact(p[0])).collect();
    let approx: Vec<f64> = pts.iter().map(|p| published_q(p[0])).collect();
    let mut item = Item::measured("fuzz_q (Listing 4)", "Ghost of Tsushima supplemental, Eq. 4", "d ∈ [0, 0.5], 2049 points", &pts, &truth, &approx);
    item.findings = vec!["Q = 2·E₃(d) exactly; Q̃ is a quadratic fit of it (convention agrees).".to_string()];
    item.add_refit(generated, "fuzz_q", crate::family::catalog(), &pts, &truth);
    out.push(item);

    // G̃ on μv ∈ [0.001, 1], d ∈ [0, 0.5] (the grid of fits/fuzz_g.toml's verification).
    let pts = grid(0.001, 1.0, 257, 0.0, 0.5, 257);
    let truth: Vec<f64> = pts.par_iter().map(|p| fuzz::g(p[1], p[0], 1e-12).value).collect();
    let approx: Vec<f64> = pts.iter().map(|p| published_g(p[0], p[1])).collect();
    let mut item = Item::measured("fuzz_g (Listing 3)", "Ghost of Tsushima supplemental, Eq. 3", "μv ∈ [0.001, 1] × d ∈ [0, 0.5], 257×257", &pts, &truth, &approx);
    item.findings = vec![
        "The supplemental's G exponent is garbled ((u+v)·n/(u+v)·n); the Koenderink–Pont form \
         d(μu+μv)/(μu μv) is what G̃ fits (a refit of the same form from it reproduces the published error)."
            .to_string(),
        "At d = 0, μv = 0 Listing 3 evaluates 0/0 (NaN); the largest errors sit at small μv, where G \
         depends on d/μv and the form cannot follow it."
            .to_string(),
    ];
    item.add_refit(generated, "fuzz_g", crate::family::catalog(), &pts, &truth);
    out.push(item);

    // R̃ on α ∈ [0.15, 1], θf ∈ [0, π/2].
    let pts = grid(0.15, 1.0, 25, 0.0, std::f64::consts::FRAC_PI_2, 25);
    let truth: Vec<f64> = pts.par_iter().map(|p| fuzz::r(p[0], p[1], 1e-9).value).collect();
    let approx: Vec<f64> = pts.iter().map(|p| published_r(p[0], p[1])).collect();
    let mut item = Item::measured("fuzz_r (Listing 5)", "Ghost of Tsushima supplemental, Eq. 5", "α ∈ [0.15, 1] × θf ∈ [0, π/2], 25×25", &pts, &truth, &approx);
    item.findings = vec![
        "Listing 5 redeclares `alpha` from an undefined `uSpread` (GSggxAlphaFromFuzzSpread): a leftover \
         of engine code; evaluated here with the function's alpha."
            .to_string(),
    ];
    item.add_refit(generated, "fuzz_r", crate::family::catalog(), &pts, &truth);
    out.push(item);

    // P̃_s (Listings 1–2 with Eq. 1) on a 17×17 (α, θf) grid × 256 light directions.
    let alphas = fuzz::linspace(0.15, 1.0, 17);
    let thetas = fuzz::linspace(0.1, std::f64::consts::FRAC_PI_2, 17);
    let dirs = fuzz::fitting_directions(16, 16);
    let ps = fuzz::ps_grid(&alphas, &thetas, &dirs, 1e-9);
    let mut pts = Vec::new();
    let (mut truth, mut printed, mut swapped, mut best) = (vec![], vec![], vec![], vec![]);
    let refit_fn = crate::pipeline::committed::Fields::load(generated, "fuzz_ps", crate::family::catalog()).ok();
    let mut refit = vec![];
    for (k, row) in ps.iter().enumerate() {
        let (a, tf) = (alphas[k / thetas.len()], thetas[k % thetas.len()]);
        let c = published_ps_coeffs(a, tf);
        let rc: Option<[f64; 6]> = refit_fn.as_ref().and_then(|f| f.eval(&[a, tf]).try_into().ok());
        // Best 6-term least-squares fit at this (α, θf): the floor for any c_i(α, θf).
        let mut basis = nalgebra::DMatrix::zeros(dirs.len(), 6);
        let mut y = nalgebra::DVector::zeros(dirs.len());
        for (i, (&(tu, pu), e)) in dirs.iter().zip(row).enumerate() {
            let (nu, tdu) = (tu.cos(), tu.sin() * pu.cos() * tf.sin() + tu.cos() * tf.cos());
            for (j, v) in [1.0, nu, tdu, nu * nu, nu * tdu, tdu * tdu].iter().enumerate() {
                basis[(i, j)] = *v;
            }
            y[i] = e.value;
        }
        let fitted = basis.clone().svd(true, true).solve(&y, 1e-12).unwrap_or_else(|_| nalgebra::DVector::zeros(6));
        for (i, (&(tu, pu), e)) in dirs.iter().zip(row).enumerate() {
            let (nu, tdu) = (tu.cos(), tu.sin() * pu.cos() * tf.sin() + tu.cos() * tf.cos());
            pts.push(vec![a, tf, tu, pu]);
            truth.push(e.value);
            printed.push(ps_from_coeffs(&c, nu, tdu));
            swapped.push(ps_from_coeffs_swapped(&c, nu, tdu));
            best.push((basis.row(i) * &fitted)[0]);
            if let Some(rc) = &rc {
                refit.push(ps_from_coeffs(rc, nu, tdu).clamp(0.0, 1.0));
            }
        }
    }
    let (max, rms, worst) = measure(&pts, &truth, &printed);
    let (smax, srms, _) = measure(&pts, &truth, &swapped);
    let (bmax, brms, _) = measure(&pts, &truth, &best);
    let mut extra = vec![
        ("rows_3_4_swapped_max_abs_error".into(), smax),
        ("rows_3_4_swapped_rms_error".into(), srms),
        ("best_6_term_fit_max_abs_error".into(), bmax),
        ("best_6_term_fit_rms_error".into(), brms),
    ];
    let mut refit_finding = vec![];
    if refit.len() == truth.len() {
        let (rmax, rrms, rworst) = measure(&pts, &truth, &refit);
        extra.push(("refit_max_abs_error".into(), rmax));
        extra.push(("refit_rms_error".into(), rrms));
        refit_finding.push(format!(
            "shadefit's refit (fits/fuzz_ps.toml, same two-stage form fitted on θf ∈ [0, π/2], joint minimax): \
             max {rmax:.3e} ({:.2}× the corrected table's {smax:.3e}; worst at {rworst:?}), rms {rrms:.3e} ({:.2}×).",
            rmax / smax,
            rrms / srms
        ));
    }
    out.push(Item {
        name: "fuzz_ps (Listings 1–2, Eq. 1 as printed)".into(),
        source: "Ghost of Tsushima supplemental, Eq. 1–2".into(),
        domain: "α ∈ [0.15, 1] × θf ∈ [0.1, π/2] (17×17) × 256 light directions".into(),
        points: pts.len(),
        max_abs_error: max,
        rms_error: rms,
        worst_point: worst,
        extra,
        findings: std::iter::once(format!(
            "As printed (row 3 on (u·n)², row 4 on (u·n)(u·t)) the table disagrees with P_s by max {max:.3}, \
             rms {rms:.4}: far beyond the form's own floor (best 6-term fit per (α, θf): max {bmax:.3}, rms {brms:.4}). \
             With rows 3 and 4 exchanged it gives max {smax:.3}, rms {srms:.4}, at the floor. The table's rows 3 and 4 \
             are in the order c4, c3 of Eq. 1: at θf = π/2 odd powers of u·t must vanish, and row 3 (≈0 there) is the \
             (u·n)(u·t) coefficient. The integrand is unchanged; the ordering is the finding."
        ))
        .chain(refit_finding)
        .collect(),
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validate::number_after;

    /// The items of the committed outputs, computed once for the tests that read them (seconds).
    fn committed_items() -> &'static [Item] {
        static ITEMS: std::sync::OnceLock<Vec<Item>> = std::sync::OnceLock::new();
        ITEMS.get_or_init(|| items(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")))
    }

    /// E₃(d) = ∫₀¹ u·e^(−d/u) du (after t = 1/u) by Simpson's rule on 4000 panels: the
    /// integrand is smooth on [0, 1], the error below 1e-12 for d ∈ [0, 0.5].
    fn e3(d: f64) -> f64 {
        let n = 4000;
        let f = |u: f64| if u == 0.0 { 0.0 } else { u * (-d / u).exp() };
        let h = 1.0 / n as f64;
        (0..=n).map(|i| f(i as f64 * h) * if i == 0 || i == n { 1.0 } else if i % 2 == 1 { 4.0 } else { 2.0 }).sum::<f64>() * h / 3.0
    }

    /// Listing 3's G̃ against the integral G it fits, away from the small μv where its error
    /// sits: within 0.02 at three points across the domain (a fit of a quantity in [0, 1]
    /// whose stated largest error is at μv → 0), and G̃ itself below 1 there.
    #[test]
    fn listing_3_follows_the_integral_g() {
        for (mu_v, d) in [(0.2, 0.1), (0.5, 0.25), (0.9, 0.5)] {
            let (got, want) = (published_g(mu_v, d), fuzz::g(d, mu_v, 1e-12).value);
            assert!((got - want).abs() <= 0.02 && got < 1.0, "μv = {mu_v}, d = {d}: G̃ = {got}, G = {want}");
        }
    }

    /// The validation items of the committed outputs: one for each listing, in order; Q̃'s
    /// error re-measured against E₃ by the test's own quadrature (Q = 2·E₃(d), E₃(d) =
    /// ∫₀¹ u·e^(−d/u) du after t = 1/u); P̃_s's least-squares floor below every other
    /// 6-term table in rms (per (α, θf) it is the rms optimum of the 256 directions, so over
    /// the grid too), the exchanged table's max at or below the floor's as the finding says,
    /// and the committed refit's max and rms re-measured from its fields with the finding's
    /// figures.
    #[test]
    fn published_items_are_each_listing_re_measured() {
        let items = committed_items();
        let names: Vec<&str> = items.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["fuzz_q (Listing 4)", "fuzz_g (Listing 3)", "fuzz_r (Listing 5)", "fuzz_ps (Listings 1–2, Eq. 1 as printed)"]);
        // E₃ by Simpson's rule (error below 1e-12): the max of 2049 differences agrees to that.
        let q = &items[0];
        let want = (0..2049).map(|i| 0.5 * i as f64 / 2048.0).map(|d| (published_q(d) - 2.0 * e3(d)).abs()).fold(0.0f64, f64::max);
        assert!((q.max_abs_error - want).abs() < 1e-9, "Q̃: reported {}, re-measured {want}", q.max_abs_error);
        assert_eq!(q.points, 2049);
        let ps = &items[3];
        let extra = |k: &str| ps.extra.iter().find(|(n, _)| n == k).unwrap().1;
        let floor = extra("best_6_term_fit_rms_error");
        assert!(floor > 0.0 && floor <= extra("rows_3_4_swapped_rms_error") && floor <= ps.rms_error, "floor {floor}");
        assert!(extra("rows_3_4_swapped_max_abs_error") < ps.max_abs_error, "the exchange is the finding");
        assert_eq!(ps.points, 17 * 17 * 256);
        // The floor re-measured: at each (α, θf) the least-squares fit of the six Eq. 1 terms
        // 1, u·n, u·t, (u·n)², (u·n)(u·t), (u·t)², u·t = sin θu cos φu sin θf + cos θu cos θf,
        // solved here by the normal equations (Cholesky) rather than the item's SVD. At the
        // optimum the residuals move only to second order in the coefficients' solver error
        // (~1e-10 relative here), so both measures agree to 1e-9 of themselves.
        let (alphas, thetas, dirs) = (fuzz::linspace(0.15, 1.0, 17), fuzz::linspace(0.1, std::f64::consts::FRAC_PI_2, 17), fuzz::fitting_directions(16, 16));
        let (mut max, mut ss, mut n) = (0.0f64, 0.0, 0usize);
        // And the table's own errors, as printed and with rows 3 and 4 exchanged, and those of
        // the committed refit's coefficients (Eq. 1's six terms in order, clamped to [0, 1] as
        // the item evaluates them): (max, Σ r²).
        let (mut printed, mut swapped, mut refit) = ((0.0f64, 0.0), (0.0f64, 0.0), (0.0f64, 0.0));
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let fields = crate::pipeline::committed::Fields::load(&generated, "fuzz_ps", crate::family::catalog()).expect("generated/json/fuzz_ps.json");
        for (k, row) in fuzz::ps_grid(&alphas, &thetas, &dirs, 1e-9).iter().enumerate() {
            let (a, tf) = (alphas[k / thetas.len()], thetas[k % thetas.len()]);
            let table = published_ps_coeffs(a, tf);
            let committed = nalgebra::DVector::from_vec(fields.eval(&[a, tf]));
            assert_eq!(committed.len(), 6);
            let terms = |tu: f64, pu: f64| {
                let (un, ut) = (tu.cos(), tu.sin() * pu.cos() * tf.sin() + tu.cos() * tf.cos());
                nalgebra::DVector::from_vec(vec![1.0, un, ut, un * un, un * ut, ut * ut])
            };
            let (mut gram, mut rhs) = (nalgebra::DMatrix::<f64>::zeros(6, 6), nalgebra::DVector::<f64>::zeros(6));
            for (&(tu, pu), e) in dirs.iter().zip(row) {
                let t = terms(tu, pu);
                gram += &t * t.transpose();
                rhs += &t * e.value;
            }
            let c = gram.cholesky().expect("six independent terms").solve(&rhs);
            for (&(tu, pu), e) in dirs.iter().zip(row) {
                let t = terms(tu, pu);
                let r = t.dot(&c) - e.value;
                (max, ss, n) = (max.max(r.abs()), ss + r * r, n + 1);
                let fitted = t.dot(&committed).clamp(0.0, 1.0);
                for (acc, v) in [(&mut printed, ps_from_coeffs(&table, t[1], t[2])), (&mut swapped, ps_from_coeffs_swapped(&table, t[1], t[2])), (&mut refit, fitted)] {
                    let r = v - e.value;
                    *acc = (acc.0.max(r.abs()), acc.1 + r * r);
                }
            }
        }
        // The same residuals summed in the same order as the item: to rounding (1e-12).
        let close = |what: &str, reported: f64, want: f64| assert!((reported - want).abs() <= 1e-12 * want, "{what}: reported {reported:e}, re-measured {want:e}");
        close("printed max", ps.max_abs_error, printed.0);
        close("printed rms", ps.rms_error, (printed.1 / n as f64).sqrt());
        close("swapped max", extra("rows_3_4_swapped_max_abs_error"), swapped.0);
        close("swapped rms", extra("rows_3_4_swapped_rms_error"), (swapped.1 / n as f64).sqrt());
        let rms = (ss / n as f64).sqrt();
        assert!((floor - rms).abs() <= 1e-9 * rms, "floor: reported {floor:e}, re-measured {rms:e}");
        let bmax = extra("best_6_term_fit_max_abs_error");
        assert!((bmax - max).abs() <= 1e-9 * max, "floor max: reported {bmax:e}, re-measured {max:e}");
        // "At the floor": the exchanged table's worst error over the grid is no larger than the
        // worst of the per-(α, θf) least-squares fits (0.148 against 0.154; a sign lost in
        // Listing 1, c₀'s denominator's included, takes it to 0.18 and beyond).
        assert!(swapped.0 <= max, "rows 3 and 4 exchanged: max {:e} above the floor's {max:e}", swapped.0);
        // The committed refit's errors and the finding that states them beside the table's.
        let (rmax, rrms, smax, srms) = (refit.0, (refit.1 / n as f64).sqrt(), swapped.0, (swapped.1 / n as f64).sqrt());
        close("refit max", crate::validate::extra(ps, "refit_max_abs_error"), rmax);
        close("refit rms", crate::validate::extra(ps, "refit_rms_error"), rrms);
        let f = ps.findings.iter().find(|f| f.starts_with("shadefit's refit")).expect("the refit's finding");
        // Printed to 4 significant digits ({:.3e}, 5e-4 relative) and ratios to hundredths.
        let tail = &f[f.find("max ").unwrap()..];
        assert!((number_after(tail, "max ") - rmax).abs() <= 5e-4 * rmax && (number_after(tail, " (") - rmax / smax).abs() <= 5e-3, "{f}");
        let tail = &f[f.find(", rms ").unwrap()..];
        assert!((number_after(tail, ", rms ") - rrms).abs() <= 5e-4 * rrms && (number_after(tail, " (") - rrms / srms).abs() <= 5e-3, "{f}");
    }

    /// R̃ (Listing 5) follows the integral R it was fitted to: on a 5×5 (α, θf) grid, R
    /// integrated to 1e-9, within 2e-3. Bound: the listing's error over the validation item's
    /// 25×25 grid is 1.24e-3 (`shadefit validate`), and the minimax refit of its form
    /// reaches 6.9e-4, so 2e-3 is the listing's own error with room for the
    /// quadrature and no more (one denominator sign flipped puts it 0.37 off).
    #[test]
    fn listing_5_follows_r() {
        let mut worst = 0.0f64;
        for i in 0..5 {
            for j in 0..5 {
                let (alpha, theta_f) = (0.15 + 0.85 * i as f64 / 4.0, std::f64::consts::FRAC_PI_2 * j as f64 / 4.0);
                let truth = fuzz::r(alpha, theta_f, 1e-9).value;
                worst = worst.max((published_r(alpha, theta_f) - truth).abs());
            }
        }
        assert!(worst <= 2e-3, "Listing 5 off R by {worst:e}");
    }

    #[test]
    fn listing_1_with_rows_3_and_4_exchanged_follows_p_s() {
        // P̃_s (Listings 1–2, rows 3 and 4 exchanged as the validation item finds) against P_s
        // integrated to 1e-9 on the 16 × 16 fitting directions at (α, θf) = (0.5, 0.8), against
        // the best 6-term least-squares fit there (the form's floor, re-measured here).
        let (alpha, theta_f) = (0.5, 0.8);
        let c = published_ps_coeffs(alpha, theta_f);
        let dirs = fuzz::fitting_directions(16, 16);
        let mut basis = nalgebra::DMatrix::zeros(dirs.len(), 6);
        let mut y = nalgebra::DVector::zeros(dirs.len());
        let mut worst = 0.0f64;
        for (i, &(tu, pu)) in dirs.iter().enumerate() {
            let (nu, tdu) = (tu.cos(), tu.sin() * pu.cos() * theta_f.sin() + tu.cos() * theta_f.cos());
            let truth = fuzz::ps(alpha, theta_f, tu, pu, 1e-9).value;
            worst = worst.max((ps_from_coeffs_swapped(&c, nu, tdu) - truth).abs());
            for (j, v) in [1.0, nu, tdu, nu * nu, nu * tdu, tdu * tdu].iter().enumerate() {
                basis[(i, j)] = *v;
            }
            y[i] = truth;
        }
        let fitted = basis.clone().svd(true, true).solve(&y, 1e-12).unwrap();
        let floor = (&basis * &fitted - &y).amax();
        // Listing 1 fits the c_i jointly over (α, θf), so at one (α, θf) it sits near the
        // per-point least-squares floor (the validation item's finding: "at the floor"); 1.5×
        // the floor leaves room for the joint fit's compromise (measured 1.02×).
        assert!(worst <= 1.5 * floor, "published max {worst:e}, floor {floor:e}, c {c:?}, fitted {fitted:?}");
    }

    #[test]
    fn features_are_the_eq_2_monomials() {
        // β = 1 − α, γ = cos θf, δ = sin θf, and the listing's order β γ δ β² γ² βγ βδ β³ γ³ δ³
        // β²γ β²δ βγ², recomputed with powi (1e-15: a few roundings on values ≤ 1).
        let (alpha, theta_f) = (0.5f64, std::f64::consts::FRAC_PI_3);
        let (b, g, d) = (0.5f64, 0.5f64, 0.75f64.sqrt());
        let want = [
            b, g, d, b.powi(2), g.powi(2), b * g, b * d, b.powi(3), g.powi(3), d.powi(3),
            b.powi(2) * g, b.powi(2) * d, b * g.powi(2),
        ];
        let got = features(alpha, theta_f);
        for k in 0..13 {
            assert!((got[k] - want[k]).abs() < 1e-15, "feature {k}: {} vs {}", got[k], want[k]);
        }
    }

    /// Listing 3's G̃ at μv = 0.3, d = 0.2, by hand from the listing: c₀ + 0.3·c₁ = −0.821271455,
    /// numerator 0.2·(1 + 0.3·(−0.821271455)) = 0.1507237127; c₂ + 0.09·c₃ = 0.6830921883,
    /// denominator 0.2 + 0.3·0.6830921883 = 0.40492765649; G̃ = 0.372223804139. And past the
    /// published d ≤ 0.5, d = 0.9 reads d = 0.5: 0.37680928175/0.70492765649 = 0.534536102082.
    #[test]
    fn listing_3_at_a_hand_computed_point() {
        // The digits kept by hand: 1e-12.
        assert!((published_g(0.3, 0.2) - 0.372223804139).abs() <= 1e-12, "{}", published_g(0.3, 0.2));
        assert!((published_g(0.3, 0.9) - 0.534536102082).abs() <= 1e-12, "{}", published_g(0.3, 0.9));
    }

    /// Listing 4's Q̃ against Q = 2·E₃(d), E₃ by the test's own quadrature, at 11 points of
    /// d ∈ [0, 0.5]: within 0.01. Bound: the listing's error over the validation item's 2049
    /// points is 9.3e-3, at d = 0.5 (`shadefit validate`), so 0.01 is its own error with 7 %
    /// room (Q = 1 exactly at d = 0, where Q̃ = 1 by its form).
    #[test]
    fn listing_4_follows_two_e3() {
        for i in 0..=10 {
            let d = 0.05 * i as f64;
            let (got, want) = (published_q(d), 2.0 * e3(d));
            assert!((got - want).abs() <= 0.01, "d = {d}: Q̃ = {got}, 2·E₃ = {want}");
        }
        assert!((published_q(0.0) - 1.0).abs() <= 1e-15);
    }

    /// The G̃ and R̃ items state their own grids and worst points: 257 × 257 (μv, d) and 25 × 25
    /// (α, θf) points, the worst of each a node of its grid whose error, re-measured there (G
    /// to 1e-12), is the item's max; no node of a 9 × 9 subgrid of G's (every 32nd) errs more.
    /// R̃'s max and rms re-measured over all 625 nodes with R to 1e-8 (the item's R is to
    /// 1e-9): bound 2e-8.
    #[test]
    fn g_and_r_items_state_their_grids_and_worst_points() {
        let items = committed_items();
        let (g, r) = (&items[1], &items[2]);
        assert_eq!((g.points, r.points), (257 * 257, 25 * 25));
        let g_err = |mu_v: f64, d: f64| (published_g(mu_v, d) - fuzz::g(d, mu_v, 1e-12).value).abs();
        let node = |lo: f64, hi: f64, n: usize, x: f64| (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).any(|v| (v - x).abs() <= 1e-15);
        let [mu_v, d] = g.worst_point[..] else { panic!("G's worst point {:?}", g.worst_point) };
        assert!(node(0.001, 1.0, 257, mu_v) && node(0.0, 0.5, 257, d), "({mu_v}, {d}) is no node");
        // Two G integrals to 1e-12 each.
        assert!((g_err(mu_v, d) - g.max_abs_error).abs() <= 2e-12, "at ({mu_v}, {d}): {} vs {}", g_err(mu_v, d), g.max_abs_error);
        for i in (0..257).step_by(32) {
            for j in (0..257).step_by(32) {
                let (m, dd) = (0.001 + 0.999 * i as f64 / 256.0, 0.5 * j as f64 / 256.0);
                assert!(g_err(m, dd) <= g.max_abs_error + 2e-12, "({m}, {dd}) errs more than the max {}", g.max_abs_error);
            }
        }
        let (mut max, mut ss, mut worst) = (0.0f64, 0.0, vec![]);
        for j in 0..25 {
            for i in 0..25 {
                let (alpha, theta_f) = (0.15 + 0.85 * i as f64 / 24.0, std::f64::consts::FRAC_PI_2 * j as f64 / 24.0);
                let e = (published_r(alpha, theta_f) - fuzz::r(alpha, theta_f, 1e-8).value).abs();
                ss += e * e;
                if e > max {
                    (max, worst) = (e, vec![alpha, theta_f]);
                }
            }
        }
        assert!((r.max_abs_error - max).abs() <= 2e-8 && (r.rms_error - (ss / 625.0).sqrt()).abs() <= 2e-8, "R̃: max {} rms {}, re-measured {max} {}", r.max_abs_error, r.rms_error, (ss / 625.0).sqrt());
        assert_eq!(r.worst_point.len(), 2);
        assert!((r.worst_point[0] - worst[0]).abs() <= 1e-15 && (r.worst_point[1] - worst[1]).abs() <= 1e-15, "{:?} vs {worst:?}", r.worst_point);
    }

    /// Listings 1, 3, 4 and 5 as held here against the transcription of the supplemental that
    /// the integrals' tests keep (one value a line, made separately): equal to the bit. A sign
    /// or digit lost in either shows here also where P̃_s cannot show it: row 5's β³
    /// coefficient −0.0043 moves c₅ by at most 0.005, under the table's own error of 0.15.
    #[test]
    fn the_listings_match_the_integrals_tests_transcription() {
        use super::super::integrals::tests::{PUB_G, PUB_PS, PUB_Q, PUB_R};
        for (i, (held, printed)) in PS_COEFFS.iter().zip(&PUB_PS).enumerate() {
            assert_eq!(held, printed, "Listing 1, row {i}");
        }
        assert_eq!((G_COEFFS, Q_COEFFS, R_COEFFS), (PUB_G, PUB_Q, PUB_R));
    }
}
