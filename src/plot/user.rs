//! Figures of the user's own specs, drawn from what their kinds hold (no family's data):
//!
//! - a form spec (`kind = "form"`): per output, the error (form − integral) of the published and of
//!   the committed refitted constants (as emitted: f32 values) on the form's grid, in its own
//!   arguments: two heatmaps on one colour scale for a 2-D grid, one line plot for a 1-D grid
//!   (`forms/NAME_OUTPUT.*`); a grid of more axes is drawn at the middle points of the axes past
//!   the second;
//! - a lobe spec (`kind = "lobe"`): E(μ) at the ends and the middle of its first parameter (the
//!   others at their middles), `lobes/NAME_albedo.*`.

use super::{PlotError, Series, SeriesStyle, data_err, heatmap_with_range, line_plot, symmetric_range};
use crate::fit::published::as_emitted;
use crate::pipeline::form::{Committed, Form};
use crate::pipeline::lobe::LobeDef;
use crate::shading::hemisphere::albedo;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Tolerance of the integrals a lobe's figure draws (far below a line's width).
const LOBE_TOL: f64 = 1e-7;

/// The form's figures (see the module doc) with its committed constants `committed`.
pub fn form_figures(form: &Form, committed: &Committed, out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let dir = out_dir.join("forms");
    std::fs::create_dir_all(&dir).map_err(super::io_err(&dir))?;
    let truth = form.truth();
    let refit: Vec<f64> = as_emitted(&committed.constants.iter().map(|k| k.refit).collect::<Vec<_>>());
    let error = |c: &[f64]| -> Vec<Vec<f64>> {
        truth.inputs.iter().zip(&truth.values).map(|(x, t)| form.program.eval_f64(x, c).iter().zip(t).map(|(a, t)| a - t).collect()).collect()
    };
    let (published, refitted) = (error(&form.published), error(&refit));
    let axes = &form.grid.axes;
    // The points of the first two grid axes at the middle index of every later one.
    let stride: Vec<usize> = axes.iter().scan(1, |s, a| { let here = *s; *s *= a.count; Some(here) }).collect();
    let base: usize = axes.iter().zip(&stride).skip(2).map(|(a, s)| (a.count / 2) * s).sum();
    let coord = |axis: usize, i: usize| truth.inputs[base + i * stride[axis]][axes[axis].param];
    let mut files = Vec::new();
    for (k, output) in form.outputs.iter().enumerate() {
        let stem = dir.join(format!("{}_{output}", form.name));
        let title = |which: &str| format!("{}: {output} − {} ({which})", form.name, form.quantity.name);
        if axes.len() == 1 {
            let x = |i: usize| coord(0, i);
            let series = [
                Series::new("published constants", (0..axes[0].count).map(|i| (x(i), published[i][k])).collect(), SeriesStyle::Line),
                Series::new("refitted constants (f32)", (0..axes[0].count).map(|i| (x(i), refitted[i][k])).collect(), SeriesStyle::Line),
            ];
            files.extend(line_plot(&stem, &title("published and refitted"), &form.args[axes[0].param], "error", &series, false)?);
            continue;
        }
        let (nx, ny) = (axes[0].count, axes[1].count);
        let xs: Vec<f64> = (0..nx).map(|i| coord(0, i)).collect();
        let ys: Vec<f64> = (0..ny).map(|j| coord(1, j)).collect();
        if xs.windows(2).any(|w| w[0] >= w[1]) || ys.windows(2).any(|w| w[0] >= w[1]) {
            return Err(data_err(&stem, "the grid's arguments do not increase along its axes"));
        }
        let (sx, sy) = (stride[0], stride[1]);
        let slice = |e: &[Vec<f64>]| -> Vec<f64> { (0..ny).flat_map(|j| (0..nx).map(move |i| base + i * sx + j * sy)).map(|p| e[p][k]).collect() };
        let (p, r) = (slice(&published), slice(&refitted));
        let range = symmetric_range(p.iter().chain(&r));
        let (xl, yl) = (&form.args[axes[0].param], &form.args[axes[1].param]);
        for (which, values) in [("published", &p), ("refit", &r)] {
            let stem = dir.join(format!("{}_{output}_{which}", form.name));
            files.extend(heatmap_with_range(&stem, &title(which), xl, yl, &xs, &ys, values, "form − integral", true, Some(range))?);
        }
    }
    Ok(files)
}

/// The lobe's figure (see the module doc).
pub fn lobe_figures(def: &LobeDef, out_dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let dir = out_dir.join("lobes");
    std::fs::create_dir_all(&dir).map_err(super::io_err(&dir))?;
    let mid: Vec<f64> = def.params.iter().map(|p| 0.5 * (p.range.0 + p.range.1)).collect();
    let (lo, hi) = def.params[0].range;
    let mus: Vec<f64> = (0..=32).map(|i| i as f64 / 32.0).collect();
    let series: Vec<Series> = [lo, 0.5 * (lo + hi), hi]
        .into_iter()
        .enumerate()
        .map(|(c, v)| {
            let mut p = mid.clone();
            p[0] = v;
            let lobe = def.lobe(&p);
            let points: Vec<(f64, f64)> = mus.par_iter().map(|&mu| (mu, albedo(&lobe, mu, LOBE_TOL).value)).collect();
            Series::new(format!("{} = {v}", def.params[0].name), points, SeriesStyle::Line).color(c)
        })
        .collect();
    let others: Vec<String> = def.params.iter().zip(&mid).skip(1).map(|(p, v)| format!("{} = {v}", p.name)).collect();
    let title = if others.is_empty() { format!("{}: directional albedo E(n·v)", def.name) } else { format!("{}: E(n·v) at {}", def.name, others.join(", ")) };
    line_plot(&dir.join(format!("{}_albedo", def.name)), &title, "n·v", "E(n·v)", &series, false)
}
