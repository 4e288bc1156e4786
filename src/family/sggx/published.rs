//! The course's comparisons, measured (`shadefit validate`):
//!
//! - NDF distances of three filters of a footprint to its true mixture NDF, per case: (a) the
//!   linear S filter with the normal by power iteration and the block normalised and stored as
//!   the pipeline does, (b) SGGX parameter estimation (Heitz et al. 2015), (c) LEAN mapping
//!   adapted to GGX (σ = α/√2). Cases: the course's two isotropic α = 0.2 lobes at ±45° from z,
//!   the fiber-like α_t = 1, α_b = 0.2 lobes at ±45° (anisotropy axis across the tilt plane),
//!   flat normals of different anisotropy (where LEAN is the linear filter), and seeded random
//!   footprints of 2–4 texels.
//! - The precision of the 8- and 16-bit encoding at the course's α pairs (0.29/0.04 without
//!   artefacts, 0.87/0.04 with, 0.87/0.1 without), worst over the axis angle.
//! - Hardware filtering of the stored channels then decoding, against filtering S.

use super::integrals::{
    ALPHA_MIN, Aniso, Distance, Lean, Lobe, M3, Mixture, Ndf, SphereRule, V3, decode_course, direction, distance, encode,
    estimate, extract, filter, quantize, sggx_from,
};
use crate::integrate::rng::SplitMix64;
use crate::validate::Item;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::path::Path;

const SOURCE: &str = "Patry 2020, Samurai Shading in Ghost of Tsushima, anisotropic specular filtering";

/// A footprint: weighted texels (normal, block).
#[derive(Debug, Clone)]
pub struct Case {
    pub name: String,
    pub texels: Vec<(f64, V3, Aniso)>,
}

/// The course's cases and a flat one.
pub fn course_cases() -> Vec<Case> {
    let tilt = |phi: f64, a: Aniso| (1.0, direction(FRAC_PI_4, phi), a);
    vec![
        Case { name: "two isotropic α = 0.2 lobes at ±45°".into(), texels: vec![tilt(0.0, Aniso::isotropic(0.2)), tilt(PI, Aniso::isotropic(0.2))] },
        Case {
            name: "fiber-like α_t = 1, α_b = 0.2 at ±45°".into(),
            texels: vec![tilt(0.0, Aniso::from_alphas(1.0, 0.2, FRAC_PI_2)), tilt(PI, Aniso::from_alphas(1.0, 0.2, FRAC_PI_2))],
        },
        Case {
            name: "flat normals, α 0.4/0.1 and 0.2".into(),
            texels: vec![(1.0, V3::z(), Aniso::from_alphas(0.4, 0.1, 0.3)), (1.0, V3::z(), Aniso::isotropic(0.2))],
        },
    ]
}

/// Seeded random footprints: 2–4 texels, normals within 60° of z, α ∈ [0.1, 0.8] (the sphere
/// rule resolves lobes that wide), weights in [0.2, 1].
pub fn random_cases(count: usize, seed: u64) -> Vec<Case> {
    let mut rng = SplitMix64(seed);
    (0..count)
        .map(|i| {
            let k = 2 + (rng.next_f64() * 3.0) as usize;
            let texels = (0..k)
                .map(|_| {
                    let n = direction(PI / 3.0 * rng.next_f64(), 2.0 * PI * rng.next_f64());
                    let a = Aniso::from_alphas(0.1 + 0.7 * rng.next_f64(), 0.1 + 0.7 * rng.next_f64(), PI * rng.next_f64());
                    (0.2 + 0.8 * rng.next_f64(), n, a)
                })
                .collect();
            Case { name: format!("random footprint {i}"), texels }
        })
        .collect()
}

/// One case measured.
#[derive(Debug, Clone)]
pub struct Comparison {
    pub case: String,
    /// (a) linear S filter, (b) parameter estimation, (c) LEAN.
    pub linear: Distance,
    pub estimation: Distance,
    pub lean: Distance,
    pub iterations: usize,
    /// The filtered normal and block as stored (before quantisation).
    pub normal: V3,
    pub block: Aniso,
    /// The block's largest eigenvalue: > 1 means the power iteration stopped on an axis that
    /// is not the one of largest projected area, and the block does not fit the encoding.
    pub block_max_eigen: f64,
}

/// The three filters of `case` against its mixture on `rule`.
pub fn compare(case: &Case, rule: &SphereRule) -> Comparison {
    let lobes: Vec<(f64, M3)> = case.texels.iter().map(|(w, n, a)| (*w, sggx_from(*n, *a))).collect();
    let mix = Mixture { lobes: lobes.iter().map(|(w, s)| (*w, Lobe::new(*s).expect("α > 0 gives SPD lobes"))).collect() };
    let e = extract(&filter(&lobes));
    let linear = Lobe::new(sggx_from(e.n, e.aniso)).expect("a convex combination of SPD matrices is SPD");
    let est = Lobe::new(estimate(&mix, rule)).expect("squared projected areas are positive");
    let lean = Lean::filter(&case.texels).expect("the slopes' covariance is positive definite");
    Comparison {
        case: case.name.clone(),
        linear: distance(&mix, &linear, rule),
        estimation: distance(&mix, &est, rule),
        lean: distance(&mix, &lean as &dyn Ndf, rule),
        iterations: e.power.iterations,
        normal: e.n,
        block: e.aniso,
        block_max_eigen: e.aniso.alphas().0,
    }
}

/// The course's cases and 12 random footprints (seed 2020), measured on the standard rule.
pub fn comparisons() -> Vec<Comparison> {
    let rule = SphereRule::standard();
    course_cases().iter().chain(&random_cases(12, 2020)).map(|c| compare(c, &rule)).collect()
}

fn distance_item(method: &str, c: &Comparison, d: &Distance, rule_points: usize) -> Item {
    let mut it = Item {
        name: format!("SGGX filtering, {}: {method}", c.case),
        source: SOURCE.into(),
        domain: "sphere (product Gauss–Legendre rule); error = total variation ½∫|p − q| of the normalised NDFs, rms = √∫(p − q)², worst = (θ, φ) of max |p − q|".into(),
        points: rule_points,
        max_abs_error: d.tv,
        rms_error: d.l2,
        worst_point: vec![d.worst.0, d.worst.1],
        extra: vec![("max_density_difference".into(), d.max)],
        findings: vec![],
    };
    if method.starts_with("(a)") {
        it.extra.push(("power_iterations".into(), c.iterations as f64));
        it.extra.push(("block_max_eigenvalue".into(), c.block_max_eigen));
        if c.block_max_eigen > 1.0 + 1e-12 {
            it.findings.push(format!(
                "the power iteration from k stops at once on n′ = ({:.3}, {:.3}, {:.3}), an eigenvector of S′ that is not its dominant one: \
                 the normalised block has an eigenvalue {:.3} > 1, which the encoding [√Sxx, …, √Syy] ∈ [0, 1] cannot store. \
                 The NDF of S′ is still the linear filter's; the normal it implies is ambiguous here.",
                c.normal.x, c.normal.y, c.normal.z, c.block_max_eigen
            ));
        }
    }
    it
}

/// Per α pair: the α_b recovered by the course's decoder from `bits`-bit channels, worst over
/// the axis angle ψ ∈ [0, π) (361 angles).
fn encoding_item(alpha_t: f64, alpha_b: f64, bits: u32) -> Item {
    let psis: Vec<f64> = (0..361).map(|i| PI * i as f64 / 361.0).collect();
    let points: Vec<Vec<f64>> = psis.iter().map(|&p| vec![p]).collect();
    let decoded: Vec<(f64, f64)> = psis
        .iter()
        .map(|&psi| {
            let d = decode_course(quantize(encode(Aniso::from_alphas(alpha_t, alpha_b, psi)), bits), ALPHA_MIN);
            (d.alpha_t_sqr.sqrt(), d.alpha_b_sqr.sqrt())
        })
        .collect();
    let truth = vec![alpha_b; psis.len()];
    let approx: Vec<f64> = decoded.iter().map(|d| d.1).collect();
    let mut it = Item::measured(
        &format!("SGGX {bits}-bit encoding at α_t = {alpha_t}, α_b = {alpha_b}: α_b decoded"),
        SOURCE,
        "axis angle ψ ∈ [0, π); error in α_b",
        &points,
        &truth,
        &approx,
    );
    let worst_t = decoded.iter().map(|d| (d.0 - alpha_t).abs()).fold(0.0, f64::max);
    it.extra.push(("max_relative_alpha_b_error".into(), it.max_abs_error / alpha_b));
    it.extra.push(("max_alpha_t_error".into(), worst_t));
    it
}

/// `n` seeded pairs of flat-texel blocks: α_t and α_b uniform on [0.02, 1], the α_t axis at ψ
/// uniform on [0, π).
fn filter_pairs(n: usize) -> Vec<(Aniso, Aniso)> {
    let mut rng = SplitMix64(17);
    let mut block = || Aniso::from_alphas(0.02 + 0.98 * rng.next_f64(), 0.02 + 0.98 * rng.next_f64(), PI * rng.next_f64());
    (0..n).map(|_| (block(), block())).collect()
}

/// Hardware filtering of stored channels: two flat texels (random blocks), their channels
/// quantised to `bits`, averaged (a bilinear tap halfway), decoded, against the S filter (the
/// blocks averaged); error in the matrix entries, over 2000 seeded pairs.
fn hardware_filter_item(bits: u32) -> Item {
    let mut points = Vec::new();
    let mut truth = Vec::new();
    let mut approx = Vec::new();
    for (a, b) in filter_pairs(2000) {
        let (ea, eb) = (quantize(encode(a), bits), quantize(encode(b), bits));
        let mid = [0.5 * (ea[0] + eb[0]), 0.5 * (ea[1] + eb[1]), 0.5 * (ea[2] + eb[2])];
        let got = decode_course(mid, ALPHA_MIN).aniso();
        let want = Aniso { sxx: 0.5 * (a.sxx + b.sxx), sxy: 0.5 * (a.sxy + b.sxy), syy: 0.5 * (a.syy + b.syy) };
        for (t, g) in [(want.sxx, got.sxx), (want.sxy, got.sxy), (want.syy, got.syy)] {
            points.push(vec![a.sxx, a.sxy, a.syy, b.sxx, b.sxy, b.syy]);
            truth.push(t);
            approx.push(g);
        }
    }
    let mut it = Item::measured(
        &format!("SGGX {bits}-bit channels filtered by the texture unit, then decoded"),
        SOURCE,
        "2000 seeded pairs of flat texels, α ∈ [0.02, 1]; error in Sxx, Sxy, Syy against averaging the blocks; worst = both blocks",
        &points,
        &truth,
        &approx,
    );
    it.findings.push(
        "channels in [0, 1] always decode to a positive semi-definite block (|2y − 1| ≤ 1 gives Sxy² ≤ Sxx·Syy): filtering the \
         stored values gives singular, never indefinite, matrices; the decoder's clamp to α_min² covers the singular ones. The error \
         is the non-linearity of the encoding (square roots and a correlation), not the quantisation."
            .into(),
    );
    it
}

pub fn items(_generated: &Path) -> Vec<Item> {
    items_of(&comparisons())
}

/// The items of [`comparisons`]: the course's cases, then the random footprints.
fn items_of(comparisons: &[Comparison]) -> Vec<Item> {
    let rule_points = SphereRule::standard().points.len();
    let mut out = Vec::new();
    for c in &comparisons[..course_cases().len()] {
        out.push(distance_item("(a) linear S filter", c, &c.linear, rule_points));
        out.push(distance_item("(b) SGGX parameter estimation", c, &c.estimation, rule_points));
        out.push(distance_item("(c) LEAN adapted to GGX", c, &c.lean, rule_points));
    }
    // The random footprints: one item per method, the worst footprint's distance as the error.
    let random = &comparisons[course_cases().len()..];
    for (method, pick) in [
        ("(a) linear S filter", (|c: &Comparison| c.linear) as fn(&Comparison) -> Distance),
        ("(b) SGGX parameter estimation", |c| c.estimation),
        ("(c) LEAN adapted to GGX", |c| c.lean),
    ] {
        let tvs: Vec<f64> = random.iter().map(|c| pick(c).tv).collect();
        let worst = tvs.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |w| w.0);
        let mean = tvs.iter().sum::<f64>() / tvs.len() as f64;
        let mut it = Item {
            name: format!("SGGX filtering, {} random footprints: {method}", random.len()),
            source: SOURCE.into(),
            domain: "seeded footprints of 2–4 texels, normals within 60° of z, α ∈ [0.1, 0.8]; error = largest total-variation distance, rms = rms over footprints; worst = footprint index".into(),
            points: random.len(),
            max_abs_error: tvs[worst],
            rms_error: (tvs.iter().map(|t| t * t).sum::<f64>() / tvs.len() as f64).sqrt(),
            worst_point: vec![worst as f64],
            extra: vec![("mean_tv".into(), mean)],
            findings: vec![],
        };
        if method.starts_with("(a)") {
            let iters = random.iter().map(|c| c.iterations).max().unwrap_or(0);
            it.extra.push(("max_power_iterations".into(), iters as f64));
            let better = random.iter().filter(|c| c.linear.tv <= c.lean.tv).count();
            it.findings.push(format!("the linear S filter is at least as close as LEAN on {better} of {} footprints", random.len()));
        }
        out.push(it);
    }
    for bits in [8, 16] {
        for (t, b) in [(0.29, 0.04), (0.87, 0.04), (0.87, 0.1)] {
            out.push(encoding_item(t, b, bits));
        }
    }
    if let Some(it) = out.iter_mut().find(|i| i.name.contains("8-bit encoding at α_t = 0.87, α_b = 0.04")) {
        it.findings.push(format!(
            "the course's artefact case: α_b comes back as much as {:.0}% off at 8 bits (the correlation channel ½Sxy/√(SxxSyy) + ½ sits near 1, \
             where one 8-bit step is a large share of 1 − ρ, and α_b² ≈ Sxx(1 − ρ) at ψ = 45°)",
            100.0 * it.extra[0].1
        ));
    }
    out.push(hardware_filter_item(8));
    out.push(hardware_filter_item(16));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The random footprints keep their documented ranges: 2–4 texels, normals within 60° of
    /// z, both α ∈ [0.1, 0.8] (read back as the square roots of the eigenvalues), weights in
    /// [0.2, 1].
    #[test]
    fn random_cases_stay_in_their_documented_ranges() {
        for case in random_cases(64, 7) {
            assert!((2..=4).contains(&case.texels.len()), "{}", case.name);
            for (w, n, a) in &case.texels {
                assert!((0.2..=1.0).contains(w), "{}: weight {w}", case.name);
                // cos 60° = 0.5, and unit length (1e-15: rounding of sin² + cos²).
                assert!(n.z >= 0.5 - 1e-15 && (n.norm() - 1.0).abs() < 1e-15, "{}: normal {n:?}", case.name);
                let (t2, b2, _) = a.alphas();
                // Eigenvalues of a 2×2 built from the alphas: a few ulps.
                for al in [t2.sqrt(), b2.sqrt()] {
                    assert!(al >= 0.1 - 1e-12 && al <= 0.8 + 1e-12, "{}: α {al}", case.name);
                }
            }
        }
    }

    #[test]
    fn filter_pairs_sample_the_axis_angle_uniformly() {
        // The larger eigenvalue's axis of each block, ½·atan2(2 Sxy, Sxx − Syy) mod π, is ψ or
        // ψ + π/2: uniform on [0, π) when ψ is. Kolmogorov–Smirnov distance of the 2000 draws
        // against uniform: below 1.63/√2000 = 0.0364 (the 1% critical value) for a fair sample.
        // The eigenvalues stay in [0.02², 1] (to 1e-15 of rounding).
        let pairs = filter_pairs(2000);
        for (which, name) in [(0, "first"), (1, "second")] {
            let mut u: Vec<f64> = pairs
                .iter()
                .map(|p| {
                    let m = if which == 0 { p.0 } else { p.1 };
                    let disc = (4.0 * m.sxy * m.sxy + (m.sxx - m.syy).powi(2)).sqrt();
                    let (hi, lo) = (0.5 * (m.sxx + m.syy + disc), 0.5 * (m.sxx + m.syy - disc));
                    assert!(lo >= 0.0004 - 1e-15 && hi <= 1.0 + 1e-15, "{m:?}");
                    (0.5 * (2.0 * m.sxy).atan2(m.sxx - m.syy)).rem_euclid(PI) / PI
                })
                .collect();
            u.sort_by(f64::total_cmp);
            let n = u.len() as f64;
            let d = u.iter().enumerate().map(|(i, &x)| ((i + 1) as f64 / n - x).max(x - i as f64 / n)).fold(0.0, f64::max);
            assert!(d < 1.63 / n.sqrt(), "{name} block: KS distance {d}");
        }
    }

    /// The random-footprint items report, per method, the largest distance over the
    /// footprints, its index, the rms and the mean of the distances, re-measured here from
    /// the comparisons themselves (same sums: equal to rounding).
    #[test]
    fn random_footprint_items_report_their_distances() {
        let comparisons = comparisons();
        let random = &comparisons[course_cases().len()..];
        // The family's items as validate lists them (they read nothing from `generated`).
        let items = items(Path::new("generated"));
        let picks: [(&str, fn(&Comparison) -> f64); 3] =
            [("(a)", |c| c.linear.tv), ("(b)", |c| c.estimation.tv), ("(c)", |c| c.lean.tv)];
        for (method, pick) in picks {
            let it = items.iter().find(|i| i.name.contains("random footprints") && i.name.contains(method)).unwrap();
            let tv: Vec<f64> = random.iter().map(pick).collect();
            let max = tv.iter().copied().fold(0.0, f64::max);
            let rms = (tv.iter().map(|t| t * t).sum::<f64>() / tv.len() as f64).sqrt();
            let mean = tv.iter().sum::<f64>() / tv.len() as f64;
            assert_eq!(it.max_abs_error, max, "{method}");
            assert_eq!(tv[it.worst_point[0] as usize], max, "{method}");
            assert!((it.rms_error - rms).abs() <= 1e-15 * rms, "{method}: rms {} vs {rms}", it.rms_error);
            assert!((it.extra[0].1 - mean).abs() <= 1e-15 * mean, "{method}: mean");
            // Not a degenerate sample: the three differ (power means of unequal values).
            assert!(mean < rms && rms < max, "{method}: {mean} {rms} {max}");
        }
        // The linear filter's item: the most power iterations any footprint took, and on how
        // many footprints it is at least as close as LEAN, counted here.
        let a = items.iter().find(|i| i.name.contains("random footprints") && i.name.contains("(a)")).unwrap();
        let iters = random.iter().map(|c| c.iterations).max().unwrap();
        assert!(iters > 0);
        assert_eq!(a.extra[1], ("max_power_iterations".to_string(), iters as f64));
        let better = random.iter().filter(|c| c.linear.tv <= c.lean.tv).count();
        assert_eq!(a.findings, [format!("the linear S filter is at least as close as LEAN on {better} of {} footprints", random.len())]);
        // The course's artefact pair: its finding prints the 8-bit item's relative α_b error,
        // re-measured here as the error over α_b, as a whole percent.
        let listed = items.iter().find(|i| i.name.contains("8-bit encoding at α_t = 0.87, α_b = 0.04")).unwrap();
        let rel = listed.max_abs_error / 0.04;
        let f = listed.findings.iter().find(|f| f.starts_with("the course's artefact case")).unwrap();
        assert!(rel > 0.2 && (crate::validate::number_after(f, "as much as ") - 100.0 * rel).abs() <= 0.5 + 1e-9, "{f}: {rel}");
    }

    #[test]
    fn course_cases_rank_the_filters_as_the_course_shows() {
        // A coarser rule (nodes every ~5 mrad, ≥ 20 per lobe width): the distances it gives are
        // within 1e-3 of the standard rule's (the check below), enough to rank methods whose
        // distances differ by > 0.05.
        let coarse = SphereRule::new(80, 160, 8);
        let cases = course_cases();
        let c = compare(&cases[0], &coarse);
        // Two isotropic lobes at ±45°: LEAN over-blurs (the course), the SGGX filters do not.
        assert!(c.lean.tv > c.linear.tv + 0.05 && c.lean.tv > c.estimation.tv + 0.05, "{c:?}");
        // Flat normals: LEAN is the linear filter (1e-9: both are evaluated from equal
        // matrices in different arithmetic; the rule's sums round alike).
        let flat = compare(&cases[2], &coarse);
        assert!((flat.lean.tv - flat.linear.tv).abs() < 1e-9, "{flat:?}");
        assert_eq!(flat.iterations, 0);
        // The quadrature: the standard rule changes the first case's distances by < 1e-3.
        let fine = compare(&cases[0], &SphereRule::standard());
        for (a, b) in [(c.linear.tv, fine.linear.tv), (c.estimation.tv, fine.estimation.tv), (c.lean.tv, fine.lean.tv)] {
            assert!((a - b).abs() < 1e-3, "{a} vs {b}");
        }
    }

    #[test]
    fn the_course_s_artefact_pair_loses_alpha_b_at_8_bits_only() {
        // Expected from the encoding's algebra at ψ = 45° (Sxx = Syy = (α_t² + α_b²)/2):
        // ρ = (α_t² − α_b²)/(α_t² + α_b²), stored y = ½ρ + ½ rounded to 8 bits, α_b² = Sxx(1 − ρ′).
        let (at, ab): (f64, f64) = (0.87, 0.04);
        let sxx = 0.5 * (at * at + ab * ab);
        let rho = (at * at - ab * ab) / (at * at + ab * ab);
        let y = ((0.5 * rho + 0.5) * 255.0).round() / 255.0;
        let predicted = (sxx * (1.0 - (2.0 * y - 1.0))).sqrt();
        let i8 = encoding_item(at, ab, 8);
        // The worst ψ is at least as bad as ψ = 45° (up to the ψ grid's rounding of √Sxx).
        assert!(i8.max_abs_error >= (predicted - ab).abs() * 0.9, "{} vs {}", i8.max_abs_error, predicted - ab);
        assert!(i8.max_abs_error / ab > 0.2);
        // The relative figure is the error over α_b (one division: 1e-15).
        let rel = crate::validate::extra(&i8, "max_relative_alpha_b_error");
        assert!((rel * ab - i8.max_abs_error).abs() <= 1e-15, "{rel} × {ab} vs {}", i8.max_abs_error);
        // 16 bits: each step is 2^-16, α_b stays within 1%; 0.29/0.04 within 10% at 8 bits.
        let i16 = encoding_item(at, ab, 16);
        assert!(i16.max_abs_error / ab < 0.01);
        assert!(encoding_item(0.29, 0.04, 8).max_abs_error / ab < 0.1);
        // α_t, the large eigenvalue's root, stays close at both depths. Each channel moves by
        // δ ≤ 2^-(b+1); Sxx, Syy by ≤ 2δ + δ², Sxy by ≤ 4δ(1 + δ)² (encode_decode_round_trip),
        // so the eigenvalue α_t² by ≤ their Frobenius norm, ≤ 6.4δ (Weyl), and α_t by ≤ 6.4δ/α_t.
        for (bits, item) in [(8, &i8), (16, &i16)] {
            let worst_t = item.extra.iter().find(|(k, _)| k == "max_alpha_t_error").map(|e| e.1).unwrap();
            let delta = 0.5f64.powi(bits + 1);
            assert!(worst_t > 0.0 && worst_t <= 6.4 * delta / at, "{bits} bits: α_t off by {worst_t}");
        }
    }

    /// The hardware-filter items against the closed form of filtering the stored channels: the
    /// texture unit averages x = √Sxx, y = ½ρ + ½ (ρ = Sxy/√(Sxx·Syy)) and z = √Syy of the two
    /// blocks, and decoding gives (x̄², x̄(2ȳ − 1)z̄, z̄²); Sxx comes back as ((√a + √b)/2)²,
    /// short of the average (a + b)/2 by (√a − √b)²/4. Each item's largest error is the closed
    /// form's over the same 2000 pairs, within what quantisation moves an entry: a channel moves
    /// by δ ≤ 2^-(b+1), an entry by ≤ 4δ(1 + δ)² (the bound of the test above). The decoder
    /// clamps the eigenvalues to [α_min², 1] (the larger one passes 1 for some pairs): the
    /// closed form does too, through the spectral projectors (M − λ₋I)/(λ₊ − λ₋) and
    /// (λ₊I − M)/(λ₊ − λ₋), not through the decoder's angle.
    #[test]
    fn hardware_filtering_errs_by_the_encodings_closed_form() {
        let pairs = filter_pairs(2000);
        let (mut closed, mut clamped) = (0.0f64, 0);
        for (a, b) in &pairs {
            let (xa, xb, za, zb) = (a.sxx.sqrt(), b.sxx.sqrt(), a.syy.sqrt(), b.syy.sqrt());
            let (x, z) = (0.5 * (xa + xb), 0.5 * (za + zb));
            let r = 0.5 * (a.sxy / (xa * za) + b.sxy / (xb * zb));
            let m = [x * x, x * r * z, z * z];
            let (tr, det) = (m[0] + m[2], m[0] * m[2] - m[1] * m[1]);
            let disc = (tr * tr - 4.0 * det).sqrt();
            let (hi, lo) = (0.5 * (tr + disc), 0.5 * (tr - disc));
            let (dhi, dlo) = (hi.clamp(ALPHA_MIN * ALPHA_MIN, 1.0) - hi, lo.clamp(ALPHA_MIN * ALPHA_MIN, 1.0) - lo);
            clamped += usize::from(dhi != 0.0 || dlo != 0.0);
            // M + Δ₊ P₊ + Δ₋ P₋, entry by entry (the identity's off-diagonal is 0).
            let entry = |k: usize, id: f64| m[k] + (dhi * (m[k] - lo * id) + dlo * (hi * id - m[k])) / disc;
            let d = [entry(0, 1.0), entry(1, 0.0), entry(2, 1.0)];
            let errs = [d[0] - 0.5 * (a.sxx + b.sxx), d[1] - 0.5 * (a.sxy + b.sxy), d[2] - 0.5 * (a.syy + b.syy)];
            closed = errs.iter().fold(closed, |m, e| m.max(e.abs()));
        }
        assert!(clamped > 0, "the clamp is exercised");
        for bits in [8u32, 16] {
            let item = hardware_filter_item(bits);
            let delta = 0.5f64.powi(bits as i32 + 1);
            let bound = 4.0 * delta * (1.0 + delta).powi(2);
            eprintln!("{bits} bits: item {:e}, closed form {closed:e} ({clamped} pairs clamped), bound {bound:e}", item.max_abs_error);
            assert_eq!(item.points, 3 * pairs.len());
            assert!((item.max_abs_error - closed).abs() <= bound, "{bits} bits: {} against {closed}", item.max_abs_error);
            assert!(item.rms_error > 0.0 && item.rms_error <= item.max_abs_error);
        }
    }

    /// The course cases' items carry each method's distance as `compare` measured it (total
    /// variation, L2, the worst node, the largest density difference, the rule's node count);
    /// only the linear filter's carry the power iterations and the stored block's largest
    /// eigenvalue, which is the closed form (Sxx + Syy + √((Sxx − Syy)² + 4Sxy²))/2 (1e-12:
    /// rounding); the finding that the block does not fit the encoding appears exactly where
    /// that eigenvalue passes 1, and prints it.
    #[test]
    fn course_case_items_carry_each_methods_distance() {
        let comparisons = comparisons();
        let items = items_of(&comparisons);
        let nodes = SphereRule::standard().points.len();
        let mut passes_one = 0;
        for c in &comparisons[..course_cases().len()] {
            for (method, d) in [("(a) linear S filter", c.linear), ("(b) SGGX parameter estimation", c.estimation), ("(c) LEAN adapted to GGX", c.lean)] {
                let name = format!("SGGX filtering, {}: {method}", c.case);
                let it = items.iter().find(|i| i.name == name).unwrap_or_else(|| panic!("no item {name}"));
                assert_eq!((it.max_abs_error, it.rms_error, it.points), (d.tv, d.l2, nodes), "{name}");
                assert_eq!(it.worst_point, [d.worst.0, d.worst.1], "{name}");
                assert_eq!(it.extra[0], ("max_density_difference".to_string(), d.max), "{name}");
                if !method.starts_with("(a)") {
                    assert_eq!((it.extra.len(), it.findings.len()), (1, 0), "{name}");
                    continue;
                }
                let b = c.block;
                let eigen = 0.5 * (b.sxx + b.syy + ((b.sxx - b.syy).powi(2) + 4.0 * b.sxy * b.sxy).sqrt());
                assert!((c.block_max_eigen - eigen).abs() <= 1e-12, "{name}: {} vs {eigen}", c.block_max_eigen);
                assert_eq!(it.extra[1], ("power_iterations".to_string(), c.iterations as f64), "{name}");
                assert_eq!(it.extra[2], ("block_max_eigenvalue".to_string(), c.block_max_eigen), "{name}");
                let finding = it.findings.iter().find(|f| f.contains("cannot store"));
                assert_eq!(finding.is_some(), eigen > 1.0 + 1e-9, "{name}: eigenvalue {eigen}");
                if let Some(f) = finding {
                    passes_one += 1;
                    assert!((crate::validate::number_after(f, "has an eigenvalue ") - eigen).abs() <= 5e-4, "{f}");
                }
            }
        }
        eprintln!("{passes_one} course cases with a block eigenvalue above 1");
    }

    /// The random footprints spread over their ranges, not just stay inside them: 2, 3 and 4
    /// texels each on about a third of 4096 cases (binomial: 1365 ± 30; at least 1200 each),
    /// and the tilt θ/(π/3), the azimuth φ/2π and the larger α's axis mod π over π (ψ uniform
    /// on [0, π), the axis ψ or ψ + π/2) each within the Kolmogorov–Smirnov distance of
    /// uniform that a fair sample stays under at the 1% level, 1.63/√N (N ≈ 12 000 texels:
    /// 0.015, small enough to see a skew of ψ that the mix of ψ and ψ + π/2 halves).
    #[test]
    fn random_cases_spread_over_their_ranges() {
        let cases = random_cases(4096, 7);
        for k in 2..=4 {
            let count = cases.iter().filter(|c| c.texels.len() == k).count();
            assert!(count >= 1200, "{count} footprints of {k} texels");
        }
        let texels: Vec<&(f64, V3, Aniso)> = cases.iter().flat_map(|c| &c.texels).collect();
        let ks = |name: &str, mut u: Vec<f64>| {
            u.sort_by(f64::total_cmp);
            let n = u.len() as f64;
            let d = u.iter().enumerate().map(|(i, &x)| ((i + 1) as f64 / n - x).max(x - i as f64 / n)).fold(0.0, f64::max);
            assert!(d < 1.63 / n.sqrt(), "{name}: KS distance {d} over {n} texels");
        };
        ks("tilt", texels.iter().map(|t| t.1.z.acos() / (PI / 3.0)).collect());
        ks("azimuth", texels.iter().map(|t| t.1.y.atan2(t.1.x).rem_euclid(2.0 * PI) / (2.0 * PI)).collect());
        ks("axis", texels.iter().map(|t| t.2.alphas().2.rem_euclid(PI) / PI).collect());
    }

    /// The encoding items sample ψ on the 361 angles πi/361 (the doc: ψ ∈ [0, π), 361 angles),
    /// and the worst point is such an angle whose α_b, decoded here from its quantised
    /// channels, is off by the item's largest error.
    #[test]
    fn encoding_items_sample_their_361_angles_and_state_the_worst() {
        for (at, ab, bits) in [(0.87, 0.04, 8u32), (0.29, 0.04, 16)] {
            let it = encoding_item(at, ab, bits);
            assert_eq!(it.points, 361);
            let psi = it.worst_point[0];
            let i = psi * 361.0 / PI;
            // An integer to a few roundings of a product ≈ 361 (1e-12).
            assert!((i - i.round()).abs() < 1e-12 && (0.0..361.0).contains(&i), "worst ψ {psi}: i = {i}");
            let d = decode_course(quantize(encode(Aniso::from_alphas(at, ab, psi)), bits), ALPHA_MIN);
            assert_eq!((d.alpha_b_sqr.sqrt() - ab).abs(), it.max_abs_error, "{at}/{ab}, {bits} bits");
        }
    }

    /// The linear filter's finding that the block does not fit the encoding starts above 1:
    /// a flat texel of α_t = 1, α_b = 0.5 (S = diag(1, 0.25, 1); the iteration stops on z at
    /// once, the block's eigenvalue is exactly 1 and is stored as √1 = 1) has none; one of
    /// α_t = 1.2 (eigenvalue α_t² = 1.44 in the plane, above z's 1) has it, printing 1.440.
    /// A coarse rule: only the block matters here.
    #[test]
    fn the_block_finding_starts_above_an_eigenvalue_of_one() {
        let rule = SphereRule::new(4, 8, 4);
        for (alpha_t, want) in [(1.0, None), (1.2, Some(1.44))] {
            let case = Case { name: format!("flat, α_t = {alpha_t}"), texels: vec![(1.0, V3::z(), Aniso::from_alphas(alpha_t, 0.5, 0.0))] };
            let c = compare(&case, &rule);
            assert_eq!(c.iterations, 0, "{}", case.name);
            let it = distance_item("(a) linear S filter", &c, &c.linear, rule.points.len());
            let finding = it.findings.iter().find(|f| f.contains("cannot store"));
            match (finding, want) {
                (None, None) => {}
                // Printed to three decimals.
                (Some(f), Some(e)) => assert!((crate::validate::number_after(f, "has an eigenvalue ") - e).abs() <= 5e-4, "{f}"),
                _ => panic!("{}: eigenvalue {}, finding {finding:?}", case.name, c.block_max_eigen),
            }
        }
    }
}
