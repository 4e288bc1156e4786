//! Gloss figures: the GGX average normal length ‖n_s‖(g), the published (COD: WWII) and
//! refitted rational approximations of it, and the gloss-combine table with the error maps of
//! its published and refitted rational fits.
//!
//! Inputs: `GENERATED/json/gloss_length.json`, `gloss_combine.json` (refit coefficients) and
//! `gloss_table.json` (table values), checked against the model forms evaluated here:
//! - 1-D: (c0 + c1 g + c2 g² + c3 g³) / (1 + c4 g + c5 g²);
//! - combine: clamp((p0 + p1(x+y) + p2(x²+y²) + p3 xy) / (1 + q1(x+y) + q2(x²+y²) + q3 xy), 0, 1)
//!   with coefficients [p0, p1, p2, p3, q1, q2, q3].
//!
//! Errors are signed, approximation − exact, with exact values from
//! [`crate::family::gloss::integrals`].

use crate::plot::{Panel, PlotError, Series, SeriesStyle};
use crate::family::gloss::integrals::{combine, length_from_gloss};
use crate::family::gloss::published::{PUBLISHED_ENDS, published_combine, published_fit_coefficients, rational_1d};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Samples of the 1-D curves (uniform on [0, 1]), fine enough to resolve the minimax ripple.
const CURVE_SAMPLES: usize = 513;
/// Every how many table entries is marked on the ‖n_s‖ plot (all are used in the error plot).
const TABLE_MARK_EVERY: usize = 8;

/// Writes the gloss figures into `out_dir` (created if missing) and returns the files written:
/// `gloss_length`, `gloss_length_error`, `gloss_combine_table`, `gloss_combine_error_published`,
/// `gloss_combine_error_refit` and `gloss_combine_errors` (the two error maps side by side), each
/// as `.png` and `.svg`.
pub fn gloss_figures(out_dir: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let json = generated.join("json");
    let length = Json::read(&json.join("gloss_length.json"))?;
    let combine_fit = Json::read(&json.join("gloss_combine.json"))?;
    let table = Json::read(&json.join("gloss_table.json"))?;

    let refit_1d: [f64; 6] = length
        .model_coefficients(&["1", "gloss", "gloss^2", "gloss^3"], &["gloss", "gloss^2"])?
        .try_into()
        .map_err(|_| length.err("expected 6 coefficients"))?;
    let refit_2d: [f64; 7] = combine_fit
        .model_coefficients(&["1", "x + y", "x^2 + y^2", "x*y"], &["x + y", "x^2 + y^2", "x*y"])?
        .try_into()
        .map_err(|_| combine_fit.err("expected 7 coefficients"))?;
    if combine_fit.v["model"]["clamp"] != serde_json::json!([0.0, 1.0]) {
        return Err(combine_fit.err("model.clamp is not [0, 1]"));
    }
    let table_g = table.axis(0)?;
    let table_values = table.values()?;
    if table_values.len() != table_g.len() {
        return Err(table.err(format!("{} values for {} axis points", table_values.len(), table_g.len())));
    }
    let grid_x = combine_fit.axis(0)?;
    let grid_y = combine_fit.axis(1)?;

    let published_1d = published_fit_coefficients(PUBLISHED_ENDS.1);
    let mut out = Vec::new();

    // (1) ‖n_s‖(g) with both fits overlaid.
    let g = uniform(CURVE_SAMPLES);
    let curve = |f: &dyn Fn(f64) -> f64| g.iter().map(|&x| (x, f(x))).collect::<Vec<_>>();
    let marks: Vec<(f64, f64)> = table_g
        .iter()
        .zip(&table_values)
        .enumerate()
        .filter(|(i, _)| i % TABLE_MARK_EVERY == 0 || *i + 1 == table_g.len())
        .map(|(_, (&x, &v))| (x, v))
        .collect();
    out.extend(crate::plot::line_plot(
        &out_dir.join("gloss_length"),
        "GGX average normal length ‖n_s‖ against gloss",
        "gloss g",
        "‖n_s‖",
        &[
            Series::new("exact ‖n_s‖(g)", curve(&length_from_gloss), SeriesStyle::Line),
            Series::new("published fit (COD: WWII)", curve(&|x| rational_1d(&published_1d, x)), SeriesStyle::Dashed),
            Series::new("refit (gloss_length.json)", curve(&|x| rational_1d(&refit_1d, x)), SeriesStyle::Dashed),
            Series::new(
                format!("gloss_table.json (every {TABLE_MARK_EVERY}th of {})", table_g.len()),
                marks,
                SeriesStyle::Points,
            ),
        ],
        false,
    )?);

    // (2) Signed errors of the fits against g. (The table holds exact values at its nodes.)
    let exact: Vec<f64> = g.iter().map(|&x| length_from_gloss(x)).collect();
    let error_curve =
        |c: &[f64; 6]| -> Vec<(f64, f64)> { g.iter().zip(&exact).map(|(&x, &e)| (x, rational_1d(c, x) - e)).collect() };
    let published_err = error_curve(&published_1d);
    let refit_err = error_curve(&refit_1d);
    let max_abs = |s: &[(f64, f64)]| s.iter().fold(0.0_f64, |m, p| m.max(p.1.abs()));
    out.extend(crate::plot::line_plot(
        &out_dir.join("gloss_length_error"),
        "Error of the ‖n_s‖(g) fits (fit − exact)",
        "gloss g",
        "error in ‖n_s‖",
        &[
            Series::new(
                format!("published fit, max |err| {:.2e}", max_abs(&published_err)),
                published_err,
                SeriesStyle::Line,
            ),
            Series::new(format!("refit, max |err| {:.2e}", max_abs(&refit_err)), refit_err, SeriesStyle::Line),
        ],
        false,
    )?);

    // (3) The combine table on the refit's sample grid.
    let exact_2d: Vec<f64> = grid_y.iter().flat_map(|&y| grid_x.iter().map(move |&x| combine(x, y))).collect();
    let (x_label, y_label) = ("gloss x", "gloss y");
    out.extend(crate::plot::heatmap(
        &out_dir.join("gloss_combine_table"),
        &format!("Combined gloss g(L(x)·L(y)), {}×{} grid", grid_x.len(), grid_y.len()),
        x_label,
        y_label,
        &grid_x,
        &grid_y,
        &exact_2d,
        "combined gloss",
        false,
    )?);

    // (4) Signed error maps of the two combine fits on one colour scale.
    let error_map = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        grid_y
            .iter()
            .flat_map(|&y| grid_x.iter().map(move |&x| (x, y)))
            .zip(&exact_2d)
            .map(|((x, y), &e)| f(x, y) - e)
            .collect()
    };
    let published_map = error_map(&published_combine);
    let refit_map = error_map(&|x, y| refit_combine(&refit_2d, x, y));
    let range = crate::plot::symmetric_range(published_map.iter().chain(&refit_map));
    let stats = |m: &[f64]| {
        let max = m.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let rms = (m.iter().map(|v| v * v).sum::<f64>() / m.len() as f64).sqrt();
        format!("max |err| {max:.2e}, rms {rms:.2e}")
    };
    let published_title = format!("Published combine fit: {}", stats(&published_map));
    let refit_title = format!("Refit (gloss_combine.json): {}", stats(&refit_map));
    for (stem, title, map) in [
        ("gloss_combine_error_published", &published_title, &published_map),
        ("gloss_combine_error_refit", &refit_title, &refit_map),
    ] {
        out.extend(crate::plot::heatmap_with_range(
            &out_dir.join(stem),
            title,
            x_label,
            y_label,
            &grid_x,
            &grid_y,
            map,
            "fit − exact combined gloss",
            true,
            Some(range),
        )?);
    }
    out.extend(crate::plot::grid_of_heatmaps(
        &out_dir.join("gloss_combine_errors"),
        "Error of the gloss-combine fits (fit − exact)",
        x_label,
        y_label,
        &grid_x,
        &grid_y,
        &[
            Panel { title: &format!("published: {}", stats(&published_map)), values: &published_map },
            Panel { title: &format!("refit: {}", stats(&refit_map)), values: &refit_map },
        ],
        2,
        "fit − exact combined gloss",
        true,
        Some(range),
    )?);
    Ok(out)
}

/// The refitted combine model, coefficients [p0, p1, p2, p3, q1, q2, q3].
fn refit_combine(c: &[f64; 7], x: f64, y: f64) -> f64 {
    let (s, s2, xy) = (x + y, x * x + y * y, x * y);
    let p = c[0] + c[1] * s + c[2] * s2 + c[3] * xy;
    let q = 1.0 + c[4] * s + c[5] * s2 + c[6] * xy;
    (p / q).clamp(0.0, 1.0)
}

fn uniform(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 / (n - 1) as f64).collect()
}

/// One generated JSON file and its path, for error messages.
struct Json {
    path: PathBuf,
    v: Value,
}

impl Json {
    fn read(path: &Path) -> Result<Self, PlotError> {
        let text =
            std::fs::read_to_string(path).map_err(|source| PlotError::Io { path: path.to_path_buf(), source })?;
        let v = serde_json::from_str(&text).map_err(|source| PlotError::Json { path: path.to_path_buf(), source })?;
        Ok(Self { path: path.to_path_buf(), v })
    }

    fn err(&self, message: impl Into<String>) -> PlotError {
        PlotError::Data { path: self.path.clone(), message: message.into() }
    }

    fn numbers(&self, v: &Value, what: &str) -> Result<Vec<f64>, PlotError> {
        v.as_array()
            .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
            .ok_or_else(|| self.err(format!("{what} is not an array of numbers")))
    }

    /// `model.coefficients`, after checking that the model is exactly
    /// (Σ num) / (1 + Σ den) over the given term labels, with no offset or factor.
    fn model_coefficients(&self, numerator: &[&str], denominator: &[&str]) -> Result<Vec<f64>, PlotError> {
        let m = &self.v["model"];
        let labels = |key: &str| -> Option<Vec<&str>> { m[key].as_array()?.iter().map(Value::as_str).collect() };
        if labels("numerator").as_deref() != Some(numerator) || labels("denominator").as_deref() != Some(denominator) {
            return Err(self.err(format!(
                "model terms {} / {} differ from the expected {numerator:?} / {denominator:?}",
                m["numerator"], m["denominator"]
            )));
        }
        if m["denominator_lead"].as_str() != Some("1")
            || !(m["offset"].is_null() || m["offset"].as_f64() == Some(0.0))
            || !(m["factor"].is_null() || m["factor"].as_f64() == Some(1.0))
        {
            return Err(self.err("model has a denominator lead other than 1, an offset or a factor"));
        }
        let c = self.numbers(&m["coefficients"], "model.coefficients")?;
        if c.len() != numerator.len() + denominator.len() {
            return Err(self.err(format!(
                "{} coefficients for {} terms",
                c.len(),
                numerator.len() + denominator.len()
            )));
        }
        Ok(c)
    }

    /// Uniform sample positions of axis `i`: `count` points over `range`.
    fn axis(&self, i: usize) -> Result<Vec<f64>, PlotError> {
        let a = &self.v["axes"][i];
        let range = self.numbers(&a["range"], "axis range")?;
        let count = a["count"]
            .as_u64()
            .filter(|&n| n >= 2)
            .ok_or_else(|| self.err(format!("axes[{i}].count missing or < 2")))?;
        let [lo, hi] = range[..] else { return Err(self.err(format!("axes[{i}].range is not [lo, hi]"))) };
        Ok((0..count).map(|k| lo + (hi - lo) * k as f64 / (count - 1) as f64).collect())
    }

    fn values(&self) -> Result<Vec<f64>, PlotError> {
        self.numbers(&self.v["values"], "values")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_from_committed_json() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let dir = tempfile::tempdir().unwrap();
        let files = gloss_figures(&dir.path().join("figures"), &generated).unwrap();
        assert_eq!(files.len(), 12);
        for f in &files {
            assert!(std::fs::metadata(f).unwrap().len() > 10_000, "{}", f.display());
        }
    }

    #[test]
    fn missing_input_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let e = gloss_figures(dir.path(), dir.path()).unwrap_err();
        assert!(e.to_string().contains("gloss_length.json"), "{e}");
    }

    #[test]
    fn refit_combine_matches_published_form() {
        // With the published coefficients (q0 = 1) the two evaluations coincide.
        use crate::family::gloss::published::{PUBLISHED_COMBINE_P as P, PUBLISHED_COMBINE_Q as Q};
        let c = [P[0], P[1], P[2], P[3], Q[1], Q[2], Q[3]];
        for &(x, y) in &[(0.1, 0.9), (0.5, 0.5), (0.95, 0.3), (0.0, 1.0)] {
            assert_eq!(refit_combine(&c, x, y), published_combine(x, y));
        }
    }
}
