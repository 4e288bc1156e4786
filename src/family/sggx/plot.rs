//! The family's figures (`shadefit plot`): the course's comparison animation as stills, and the
//! precision of the stored encoding.
//!
//! - `sggx_filters`: the NDFs of the course's cases seen down the z axis (orthographic, upper
//!   hemisphere; D normalised to unit mass on the sphere): the true mixture, (a) the linear S
//!   filter, (b) SGGX parameter estimation, (c) LEAN adapted to GGX; one row per case.
//! - `sggx_encoding`: relative α_b error of the 8-bit encoding against the axis angle ψ at the
//!   course's α pairs (0.29/0.04, 0.87/0.04 with artefacts, 0.87/0.1), and at 16 bits.

use super::integrals::{ALPHA_MIN, Aniso, Lean, Lobe, M3, Mixture, Ndf, SphereRule, V3, decode_course, encode, estimate, extract, filter, quantize, sggx_from};
use super::published::course_cases;
use crate::plot::{Panel, PlotError, Series, SeriesStyle, grid_of_heatmaps, line_plot};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

const PIXELS: usize = 121;

pub fn figures(out_dir: &Path, _generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut out = filters_figure(out_dir)?;
    out.extend(encoding_figure(out_dir)?);
    Ok(out)
}

/// Values of `ndf` on the disk x² + y² < 1 (m = (x, y, √(1 − x² − y²))), NaN outside, divided
/// by its mass on `rule`.
fn disk(ndf: &dyn Ndf, rule: &SphereRule, xs: &[f64]) -> Vec<f64> {
    let mass = rule.integrate(|m| ndf.d(m));
    let mut v = Vec::with_capacity(xs.len() * xs.len());
    for &y in xs {
        for &x in xs {
            let r2 = x * x + y * y;
            v.push(if r2 < 1.0 { ndf.d(&V3::new(x, y, (1.0 - r2).sqrt())) / mass } else { f64::NAN });
        }
    }
    v
}

fn filters_figure(out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let rule = SphereRule::new(80, 160, 8);
    let xs: Vec<f64> = (0..PIXELS).map(|i| -1.0 + 2.0 * (i as f64 + 0.5) / PIXELS as f64).collect();
    let cases = &course_cases()[..2];
    let mut values: Vec<Vec<f64>> = Vec::new();
    let mut titles: Vec<String> = Vec::new();
    for case in cases {
        let lobes: Vec<(f64, M3)> = case.texels.iter().map(|(w, n, a)| (*w, sggx_from(*n, *a))).collect();
        let mix = Mixture { lobes: lobes.iter().map(|(w, s)| (*w, Lobe::new(*s).expect("SPD lobes"))).collect() };
        let e = extract(&filter(&lobes));
        let linear = Lobe::new(sggx_from(e.n, e.aniso)).expect("SPD filter");
        let est = Lobe::new(estimate(&mix, &rule)).expect("SPD estimate");
        let lean = Lean::filter(&case.texels).expect("positive definite slopes");
        let short = if case.name.starts_with("two") { "2 × α 0.2" } else { "fiber α_t 1" };
        for (label, ndf) in [("input", &mix as &dyn Ndf), ("linear S", &linear), ("param. est.", &est), ("LEAN", &lean)] {
            values.push(disk(ndf, &rule, &xs));
            titles.push(format!("{short}: {label}"));
        }
    }
    let panels: Vec<Panel> = titles.iter().zip(&values).map(|(t, v)| Panel { title: t, values: v }).collect();
    grid_of_heatmaps(
        &out_dir.join("sggx_filters"),
        "NDFs seen down z: mixtures of two lobes at ±45° and their filters",
        "x",
        "y",
        &xs,
        &xs,
        &panels,
        4,
        "D / ∫D",
        false,
        None,
    )
}

fn encoding_figure(out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let psis: Vec<f64> = (0..=360).map(|i| PI * i as f64 / 360.0).collect();
    let mut series = Vec::new();
    for (k, (at, ab)) in [(0.29, 0.04), (0.87, 0.04), (0.87, 0.1)].into_iter().enumerate() {
        for bits in [8u32, 16] {
            let pts = psis
                .iter()
                .map(|&psi| {
                    let d = decode_course(quantize(encode(Aniso::from_alphas(at, ab, psi)), bits), ALPHA_MIN);
                    (psi.to_degrees(), (d.alpha_b_sqr.sqrt() / ab - 1.0).abs().max(1e-9))
                })
                .collect();
            let style = if bits == 8 { SeriesStyle::Line } else { SeriesStyle::Dashed };
            series.push(Series::new(format!("α_t {at}, α_b {ab}, {bits}-bit"), pts, style).color(k));
        }
    }
    line_plot(&out_dir.join("sggx_encoding"), "Stored aniso map: α_b recovered by DecodeSggx", "axis angle ψ (degrees)", "|α_b′/α_b − 1|", &series, true)
}
