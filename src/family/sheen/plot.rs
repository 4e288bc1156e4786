//! sheen figures: the shadowing G1 = 1/(1 + Λ) of the exact Λ against Estevez–Kulla's curve and
//! its refit; E(n·v) at four roughnesses under the three visibilities with the published fits
//! of the Ashikhmin lobe (three.js 2025 and its refit); maps of E over (n·v, r) under the exact
//! Λ and Ashikhmin's V, and of three.js's error.

use super::forms::{EK_LAMBDA, EK_PUBLISHED, THREEJS_2025, THREEJS_2025_PUBLISHED};
use super::grid::{self, Convention, Target, Visibility};
use super::{lambda_table, refit};
use crate::plot::{PlotError, Series, SeriesStyle};
use std::path::{Path, PathBuf};

const CURVE: usize = 101;

fn mus() -> Vec<f64> {
    (0..CURVE).map(|i| i as f64 / (CURVE - 1) as f64).collect()
}

pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = Vec::new();
    let ek_refit = refit::committed(generated, refit::REFITTED[0].0).ok();
    let tj_refit = refit::committed(generated, refit::REFITTED[1].0).ok();
    // G1 curves.
    let mut series = Vec::new();
    for (c, r) in [0.1f64, 0.3, 0.6, 1.0].into_iter().enumerate() {
        let a = r * r;
        let g1 = |l: f64| 1.0 / (1.0 + l);
        let exact: Vec<(f64, f64)> = mus().iter().map(|&m| (m, if m == 0.0 { 0.0 } else { g1(lambda_table(a).lambda(m)) })).collect();
        let ek: Vec<(f64, f64)> = mus().iter().map(|&m| (m, g1(EK_LAMBDA.eval_f64(&[a, m], &EK_PUBLISHED)[0]))).collect();
        series.push(Series::new(format!("exact, r = {r}"), exact, SeriesStyle::Line).color(c));
        series.push(Series::new(format!("Estevez–Kulla, r = {r}"), ek, SeriesStyle::Dashed).color(c));
        if let Some(k) = &ek_refit {
            let rf: Vec<(f64, f64)> = mus().iter().map(|&m| (m, g1(EK_LAMBDA.eval_f64(&[a, m], k)[0]))).collect();
            series.push(Series::new(format!("refit, r = {r}"), rf, SeriesStyle::Points).color(c));
        }
    }
    files.extend(crate::plot::line_plot(
        &out.join("sheen_g1_curves"),
        "Charlie shadowing G1 = 1/(1 + Λ(μ)), α = r²: exact Λ, Estevez–Kulla's curve and its refit",
        "μ = cos θ",
        "G1",
        &series,
        false,
    )?);
    // E curves at fixed roughness from the grid.
    let pts = grid::points();
    let targets = [
        (Target::new(Visibility::Smith, Convention::Squared), "exact Λ"),
        (Target::new(Visibility::EstevezKulla, Convention::Squared), "Estevez–Kulla curve"),
        (Target::new(Visibility::Ashikhmin, Convention::Squared), "Ashikhmin V"),
    ];
    for ri in [0usize, 4, 9, 18] {
        let r = grid::roughness(ri);
        let rows = ri * grid::NV..(ri + 1) * grid::NV;
        let mut series: Vec<Series> = targets
            .iter()
            .enumerate()
            .map(|(c, (t, name))| Series::new(format!("E, {name}"), rows.clone().map(|k| (pts[k][1], t.albedo()[k])).collect(), SeriesStyle::Line).color(c))
            .collect();
        let tj = |c: &[f64]| rows.clone().map(|k| (pts[k][1], THREEJS_2025.eval_f64(&[r, pts[k][1]], c)[0])).collect::<Vec<_>>();
        series.push(Series::new("three.js IBLSheenBRDF (r181+)", tj(&THREEJS_2025_PUBLISHED), SeriesStyle::Dashed).color(2));
        if let Some(c) = &tj_refit {
            series.push(Series::new("three.js form refitted", tj(c), SeriesStyle::Points).color(2));
        }
        files.extend(crate::plot::line_plot(
            &out.join(format!("sheen_albedo_r{:.0}", 100.0 * r)),
            &format!("Charlie sheen albedo E(n·v) at r = {r:.2} (α = r²)"),
            "n·v",
            "E",
            &series,
            false,
        )?);
    }
    // Maps over (n·v, r).
    let xs: Vec<f64> = (0..grid::NV).map(grid::n_dot_v).collect();
    let ys: Vec<f64> = (0..grid::NR).map(grid::roughness).collect();
    for (t, stem, what) in [
        (targets[0].0, "sheen_albedo_map_smith", "E under the exact Λ"),
        (targets[2].0, "sheen_albedo_map_ashikhmin", "E under Ashikhmin's V (clamped at 2)"),
    ] {
        let values: Vec<f64> = t.albedo().iter().map(|e| e.min(2.0)).collect();
        files.extend(crate::plot::heatmap(&out.join(stem), &format!("Charlie sheen {what}, α = r²"), "n·v", "r", &xs, &ys, &values, "E", false)?);
    }
    let ash = targets[2].0.albedo();
    let err: Vec<f64> = pts.iter().zip(ash).map(|(p, e)| THREEJS_2025.eval_f64(&[p[0], p[1]], &THREEJS_2025_PUBLISHED)[0] - e.min(1.0)).collect();
    files.extend(crate::plot::heatmap(
        &out.join("sheen_threejs_error"),
        "three.js IBLSheenBRDF (r181+) − min(1, E) of its lobe (Charlie α = r² · Ashikhmin V)",
        "n·v",
        "r",
        &xs,
        &ys,
        &err,
        "error",
        true,
    )?);
    Ok(files)
}
