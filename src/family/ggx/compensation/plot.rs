//! Energy-compensation figures: E(μ) per roughness (after Kulla–Conty's figure), E_avg over
//! roughness (with the committed table's entries), and white-furnace maps of each scheme over
//! (n·v, roughness): albedo − 1 at F = 1, albedo − Kulla–Conty's at F0 = 0.5, and at F = 1 with
//! E, E_avg read from the committed tables.

use super::furnace::{tabulated, furnace_tabulated, Grid, Table, E_AVG_TABLE, E_TABLE};
use super::Scheme;
use crate::plot::{Panel, PlotError, Series, SeriesStyle};
use std::path::{Path, PathBuf};

/// Roughness of the E(μ) curves (Kulla–Conty plot a similar fan).
const CURVE_ROUGHNESS: [f64; 6] = [0.1, 0.25, 0.4, 0.6, 0.8, 1.0];
/// Samples of the E(μ) curves (uniform n·v; E varies on the scale n·v ~ α near grazing).
const CURVE_MU: usize = 257;
/// Map resolution: n·v × roughness.
const MAP_MU: usize = 33;
const MAP_R: usize = 20;

fn uniform(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect()
}

/// Writes `ggx_albedo_curves`, `ggx_albedo_avg`, `ggx_furnace_f1`, `ggx_furnace_f0_0.5` and
/// (with committed tables) `ggx_furnace_tables`, each as PNG and SVG.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = Vec::new();
    let curve_mu = uniform(0.0, 1.0, CURVE_MU);
    let curves = Grid::exact(&CURVE_ROUGHNESS, &curve_mu);
    let series: Vec<Series> = CURVE_ROUGHNESS
        .iter()
        .enumerate()
        .map(|(j, &r)| {
            let pts = curve_mu.iter().enumerate().map(|(i, &m)| (m, curves.at(j, i).e())).collect();
            Series::new(format!("r = {r} (α = {:.4})", r * r), pts, SeriesStyle::Line)
        })
        .collect();
    files.extend(crate::plot::line_plot(
        &out.join("ggx_albedo_curves"),
        "GGX directional albedo E(μ), F = 1 (height-correlated Smith; E(0) = 1 exactly)",
        "n·v",
        "E",
        &series,
        false,
    )?);

    let mu = uniform(0.0, 1.0, MAP_MU);
    let roughness = uniform(0.05, 1.0, MAP_R);
    let grid = Grid::exact(&roughness, &mu);
    let mut avg = vec![Series::new(
        "E_avg (integral)",
        roughness.iter().enumerate().map(|(j, &r)| (r, grid.at(j, 0).e_avg)).collect(),
        SeriesStyle::Line,
    )];
    let tables = Table::load(generated, E_TABLE).zip(Table::load(generated, E_AVG_TABLE));
    if let Some((_, a)) = &tables {
        let (lo, hi) = (a.domain[0].0 as f64, a.domain[0].1 as f64);
        let n = a.counts[0];
        // The table's axis is α; plotted at r = α^½.
        let marks = (0..n).map(|k| ((lo + (hi - lo) * k as f64 / (n - 1) as f64).sqrt(), a.values[k] as f64)).collect();
        avg.push(Series::new(format!("{E_AVG_TABLE}.json ({n} entries)"), marks, SeriesStyle::Points));
    }
    files.extend(crate::plot::line_plot(
        &out.join("ggx_albedo_avg"),
        "GGX average albedo E_avg = 2∫E(μ)μ dμ",
        "perceptual roughness r (α = r²)",
        "E_avg",
        &avg,
        false,
    )?);

    let titles: Vec<String> = Scheme::ALL.iter().map(|s| s.id().to_string()).collect();
    let f1: Vec<Vec<f64>> = Scheme::ALL.iter().map(|&s| grid.furnace(s, 1.0).iter().map(|v| v - 1.0).collect()).collect();
    let panels: Vec<Panel> = titles.iter().zip(&f1).map(|(t, v)| Panel { title: t, values: v }).collect();
    // bevy's gain is unbounded near (0, 0): the shared scale is clipped to ±1.
    files.extend(furnace_maps(out, "ggx_furnace_f1", "White furnace, F = 1: albedo − 1 (clipped to ±1)", &grid, &panels, "albedo − 1", Some((-1.0, 1.0)))?);

    let kc = grid.furnace(Scheme::KullaConty, 0.5);
    let f05: Vec<Vec<f64>> = Scheme::ALL
        .iter()
        .map(|&s| grid.furnace(s, 0.5).iter().zip(&kc).map(|(v, k)| v - k).collect())
        .collect();
    let panels: Vec<Panel> = titles.iter().zip(&f05).map(|(t, v)| Panel { title: t, values: v }).collect();
    let range = crate::plot::symmetric_range(f05[..5].iter().flatten());
    files.extend(furnace_maps(out, "ggx_furnace_f0_0.5", "White furnace, Schlick F0 = 0.5: albedo − Kulla–Conty's", &grid, &panels, "albedo − albedo(KC)", Some(range))?);

    if let Some((e, a)) = &tables {
        let tab: Vec<_> = roughness.iter().map(|&r| tabulated(e, a, r * r, &mu)).collect();
        let schemes = [Scheme::KullaConty, Scheme::Turquin, Scheme::Cycles];
        let maps: Vec<Vec<f64>> = schemes
            .iter()
            .map(|&s| {
                let mut v = Vec::with_capacity(mu.len() * roughness.len());
                for (j, t) in tab.iter().enumerate() {
                    for (i, &e_t) in t.e.iter().enumerate() {
                        let f = furnace_tabulated(s, 1.0, grid.at(j, i), e_t, t.e_avg, t.ms_integral).unwrap_or(f64::NAN);
                        v.push(f - 1.0);
                    }
                }
                v
            })
            .collect();
        let t: Vec<String> = schemes.iter().map(|s| s.id().to_string()).collect();
        let panels: Vec<Panel> = t.iter().zip(&maps).map(|(t, v)| Panel { title: t, values: v }).collect();
        files.extend(furnace_maps(out, "ggx_furnace_tables", "White furnace, F = 1, E and E_avg from the 32×32 and 32 tables: albedo − 1", &grid, &panels, "albedo − 1", None)?);
    }
    Ok(files)
}

/// Heat maps over the grid's (n·v, roughness), three to a row, one per scheme, on a shared
/// scale (or the given range).
fn furnace_maps(out: &Path, name: &str, title: &str, grid: &Grid, panels: &[Panel], label: &str, range: Option<(f64, f64)>) -> Result<Vec<PathBuf>, PlotError> {
    crate::plot::grid_of_heatmaps(&out.join(name), title, "n·v", "roughness", &grid.mu, &grid.roughness, panels, 3, label, true, range)
}
