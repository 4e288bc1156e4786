//! Fiber figures: N(k, u·t) against u·t at several k with the conservative bound N(k, 1), the
//! shader factor W(k, |u·t|) as a heatmap, the energy lost by the conservative r(k) =
//! 1/N(k, 1), and the error map of the committed refit (`generated/json/fiber_phase_scale.json`,
//! evaluated through its spec's model). Errors are signed, fit − exact, exact values from
//! [`crate::family::fiber::integrals`].

use crate::family::fiber::integrals::{mean, mean_parallel, norm};
use crate::pipeline::committed::Refit;
use crate::plot::{PlotError, Series, SeriesStyle};
use std::path::{Path, PathBuf};

const TOL: f64 = 1e-12;
/// Heatmap resolution (k × |u·t|): finer than the fit's 33² grid, to show the minimax ripple.
const N_MAP: usize = 97;

fn uniform(n: usize, lo: f64, hi: f64) -> Vec<f64> {
    (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect()
}

/// Writes `fiber_norm`, `fiber_scale`, `fiber_energy_loss_conservative` and
/// `fiber_scale_error_refit` (`.png` + `.svg`) into `out_dir` and returns the files.
pub fn fiber_figures(out_dir: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut out = Vec::new();
    // (1) N against u·t (even: both signs drawn) at five k, relative to its bound N(k, 1) (the
    // energy the conservative r_c keeps; N spans 6e-3 to 1 over k, so absolute curves crowd).
    let cs = uniform(201, -1.0, 1.0);
    let mut series = Vec::new();
    for (i, k) in [-0.99, -0.75, -0.5, -0.25, -0.1].into_iter().enumerate() {
        let bound = norm(k, 1.0, TOL).value;
        series.push(
            Series::new(format!("k = {k}: N(k, 1) = {bound:.4e}"), cs.iter().map(|&c| (c, norm(k, c, TOL).value / bound)).collect(), SeriesStyle::Line)
                .color(i),
        );
    }
    out.extend(crate::plot::line_plot(
        &out_dir.join("fiber_norm"),
        "N(k, u·t) / N(k, 1) of the Schlick fiber phase function (r = 1/N)",
        "u·t",
        "N(k, u·t) / N(k, 1)",
        &series,
        false,
    )?);

    // (2) W(k, |u·t|) and (3) the energy lost by r_c over (k, |u·t|).
    let ks = uniform(N_MAP, -0.99, 0.0);
    let cs = uniform(N_MAP, 0.0, 1.0);
    let m: Vec<f64> = cs.iter().flat_map(|&c| ks.iter().map(move |&k| mean(k, c, TOL).value)).collect();
    let w: Vec<f64> = m.iter().map(|m| 1.0 / m).collect();
    out.extend(crate::plot::heatmap(
        &out_dir.join("fiber_scale"),
        "W = (1 − k²)/N: p_V = W / (4π (1 − k x)²) integrates to 1",
        "k",
        "|u·t|",
        &ks,
        &cs,
        &w,
        "W",
        false,
    )?);
    let loss: Vec<f64> = cs
        .iter()
        .enumerate()
        .flat_map(|(j, _)| ks.iter().enumerate().map(move |(i, &k)| (j, i, k)))
        .map(|(j, i, k)| 1.0 - m[j * N_MAP + i] / mean_parallel(k))
        .collect();
    out.extend(crate::plot::heatmap(
        &out_dir.join("fiber_energy_loss_conservative"),
        "Energy lost by the conservative r(k) = 1/N(k, 1): 1 − N(k, u·t)/N(k, 1)",
        "k",
        "|u·t|",
        &ks,
        &cs,
        &loss,
        "energy lost",
        false,
    )?);

    // (4) The committed refit's error map.
    let json = generated.join("json").join("fiber_phase_scale.json");
    let refit = Refit::load(generated, "fiber_phase_scale", crate::family::catalog())
        .map_err(|e| PlotError::Data { path: json.clone(), message: e.to_string() })?;
    let err: Vec<f64> = cs.iter().flat_map(|&c| ks.iter().map(move |&k| (k, c))).zip(&w).map(|((k, c), w)| refit.eval(&[k, c]) - w).collect();
    let max = err.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    out.extend(crate::plot::heatmap(
        &out_dir.join("fiber_scale_error_refit"),
        &format!("Refit W̃ − W (fits/fiber_phase_scale.toml), max |err| {max:.2e}"),
        "k",
        "|u·t|",
        &ks,
        &cs,
        &err,
        "W̃ − W",
        true,
    )?);
    Ok(out)
}
