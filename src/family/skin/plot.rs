//! Skin figures: the pre-integrated skin LUTs as images and slices, the linear and radial ring
//! kernels side by side, and the SH band factors against curvature.
//!
//! Inputs: `GENERATED/json/skin_punctual_lut.json` and `skin_sh_lut.json` (texel values, axes
//! and the diffusion profile they were integrated with). The kernel comparison integrates the
//! same profile again with both kernels ([`crate::family::skin::integrals::punctual`]) on the LUT's grid.
//! Missing skin JSON files mean no skin figures (the family is optional); malformed ones are
//! errors naming the file.
//!
//! The RGB image shows linear values sRGB-encoded for viewing (no tonemapping: D ≤ 1).

use crate::plot::{Axis, DrawResult, FONT_FAMILY, Figure, Panel, PlotError, Series, SeriesStyle, TITLE_SIZE};
use crate::plot::{de, label_width, ticks, write_figure};
use crate::emit::texture::srgb8;
use crate::integrate::Tolerance;
use crate::family::skin::integrals::{DEFAULT_TOLERANCE, Gaussian, Kernel, Profile, punctual_grid_estimates};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// LUT rows drawn as slices (fractions of the curvature axis, nearest row).
const SLICE_FRACTIONS: [f64; 5] = [0.0, 0.1, 0.25, 0.5, 1.0];
/// n·l samples of the kernel slices.
const SLICE_SAMPLES: usize = 241;

/// Writes the skin figures into `out_dir` and returns the files written (PNG and SVG each):
/// from `skin_punctual_lut.json`: `skin_punctual_lut` (RGB image), `skin_punctual_lut_channels`
/// (one heatmap per channel), `skin_punctual_slices` (red rows at several κ),
/// `skin_punctual_slices_rgb` (the three channels at κ_max/2), `skin_kernels` (linear vs
/// radial, red), `skin_kernel_slices`; from `skin_sh_lut.json`: `skin_sh_bands`.
pub fn skin_figures(out_dir: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut out = Vec::new();
    let json = generated.join("json");
    let punctual = json.join("skin_punctual_lut.json");
    if punctual.exists() {
        out.extend(punctual_figures(out_dir, &Lut::read(&punctual)?)?);
    }
    let sh = json.join("skin_sh_lut.json");
    if sh.exists() {
        out.extend(sh_figures(out_dir, &Lut::read(&sh)?)?);
    }
    Ok(out)
}

/// A skin LUT JSON file: texture size, axes and texels.
struct Lut {
    path: PathBuf,
    v: Value,
    width: usize,
    height: usize,
    values: Vec<[f64; 3]>,
}

impl Lut {
    fn read(path: &Path) -> Result<Lut, PlotError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlotError::Io { path: path.to_path_buf(), source })?;
        let v: Value = serde_json::from_str(&text).map_err(|source| PlotError::Json { path: path.to_path_buf(), source })?;
        let err = |m: &str| PlotError::Data { path: path.to_path_buf(), message: m.to_string() };
        let width = v["texture"]["width"].as_u64().ok_or_else(|| err("no texture.width"))? as usize;
        let height = v["texture"]["height"].as_u64().ok_or_else(|| err("no texture.height"))? as usize;
        let values: Vec<[f64; 3]> = v["values"]
            .as_array()
            .and_then(|a| {
                a.iter()
                    .map(|t| {
                        let t = t.as_array()?;
                        Some([t.first()?.as_f64()?, t.get(1)?.as_f64()?, t.get(2)?.as_f64()?])
                    })
                    .collect()
            })
            .ok_or_else(|| err("values is not an array of [r, g, b]"))?;
        if values.len() != width * height || width < 2 {
            return Err(err(&format!("{} values for a {width}×{height} texture", values.len())));
        }
        Ok(Lut { path: path.to_path_buf(), v, width, height, values })
    }

    fn err(&self, message: impl Into<String>) -> PlotError {
        PlotError::Data { path: self.path.clone(), message: message.into() }
    }

    /// The curvature samples (1/mm) listed in the axes.
    fn curvatures(&self) -> Result<Vec<f64>, PlotError> {
        let axis = self.v["axes"]
            .as_array()
            .and_then(|a| a.iter().find(|x| x["name"] == "curvature"))
            .ok_or_else(|| self.err("no curvature axis"))?;
        axis["values"]
            .as_array()
            .and_then(|a| a.iter().map(Value::as_f64).collect())
            .ok_or_else(|| self.err("curvature axis has no values"))
    }

    /// The diffusion profile recorded in the provenance.
    fn profile(&self) -> Result<Profile, PlotError> {
        let p = &self.v["profile"];
        let triple = |x: &Value| -> Option<[f64; 3]> {
            let a = x.as_array()?;
            Some([a.first()?.as_f64()?, a.get(1)?.as_f64()?, a.get(2)?.as_f64()?])
        };
        let profile = if let Some(gs) = p["gaussians"].as_array() {
            Profile::Gaussians(
                gs.iter()
                    .map(|g| Some(Gaussian { variance_mm2: g["variance_mm2"].as_f64()?, weight: triple(&g["weights"])? }))
                    .collect::<Option<Vec<_>>>()
                    .ok_or_else(|| self.err("profile.gaussians malformed"))?,
            )
        } else {
            let radius_mm: Vec<f64> = p["radius_mm"]
                .as_array()
                .and_then(|a| a.iter().map(Value::as_f64).collect())
                .ok_or_else(|| self.err("profile has neither gaussians nor radius_mm"))?;
            let value: Vec<[f64; 3]> = p["values"]
                .as_array()
                .and_then(|a| a.iter().map(triple).collect())
                .ok_or_else(|| self.err("profile.values malformed"))?;
            Profile::Tabulated { radius_mm, value }
        };
        profile.validate().map_err(|e| self.err(format!("profile: {e}")))?;
        Ok(profile)
    }
}

fn channel(values: &[[f64; 3]], c: usize) -> Vec<f64> {
    values.iter().map(|v| v[c]).collect()
}

fn n_dot_l_axis(n: usize) -> Vec<f64> {
    (0..n).map(|i| crate::family::skin::integrals::lut_n_dot_l(i, n)).collect()
}

fn punctual_figures(out_dir: &Path, lut: &Lut) -> Result<Vec<PathBuf>, PlotError> {
    let (w, h) = (lut.width, lut.height);
    let nls = n_dot_l_axis(w);
    let kappas = lut.curvatures()?;
    if kappas.len() != h {
        return Err(lut.err(format!("{} curvatures for {h} rows", kappas.len())));
    }
    let kernel = lut.v["kernel"].as_str().unwrap_or("linear").to_string();
    let mut out = Vec::new();

    // (1) The LUT as an image: n·l across, κ up.
    let fig = RgbImage {
        title: format!("Skin LUT D(n·l, κ), {w}×{h}, {kernel} kernel (sRGB display of linear values)"),
        x_label: "n·l",
        y_label: "curvature κ (1/mm)",
        xs: &nls,
        ys: &kappas,
        rgb: &lut.values,
    };
    out.extend(write_figure(&out_dir.join("skin_punctual_lut"), &fig)?);

    // (2) One heatmap per channel on a shared [0, 1] scale.
    let chans: Vec<Vec<f64>> = (0..3).map(|c| channel(&lut.values, c)).collect();
    out.extend(crate::plot::grid_of_heatmaps(
        &out_dir.join("skin_punctual_lut_channels"),
        &format!("Skin LUT D(n·l, κ) per channel ({kernel} kernel)"),
        "n·l",
        "curvature κ (1/mm)",
        &nls,
        &kappas,
        &[
            Panel { title: "red", values: &chans[0] },
            Panel { title: "green", values: &chans[1] },
            Panel { title: "blue", values: &chans[2] },
        ],
        3,
        "D",
        false,
        Some((0.0, 1.0)),
    )?);

    // (3) Slices: rows of the LUT (its texels) at several κ, red channel, and max(n·l, 0).
    let row = |f: f64| ((f * (h - 1) as f64).round() as usize).min(h - 1);
    let lambert: Vec<(f64, f64)> = nls.iter().map(|&x| (x, x.max(0.0))).collect();
    let mut series: Vec<Series> = SLICE_FRACTIONS
        .iter()
        .map(|&f| {
            let j = row(f);
            let pts = nls.iter().enumerate().map(|(i, &x)| (x, lut.values[j * w + i][0])).collect();
            Series::new(format!("κ = {:.3}/mm", kappas[j]), pts, SeriesStyle::Line)
        })
        .collect();
    series.push(Series::new("max(n·l, 0)", lambert.clone(), SeriesStyle::Dashed));
    out.extend(crate::plot::line_plot(
        &out_dir.join("skin_punctual_slices"),
        "Skin LUT rows: red D against n·l at several curvatures",
        "n·l",
        "D (red)",
        &series,
        false,
    )?);
    let j = row(0.5);
    let mut series: Vec<Series> = ["red", "green", "blue"]
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let pts = nls.iter().enumerate().map(|(i, &x)| (x, lut.values[j * w + i][c])).collect();
            Series::new(*name, pts, SeriesStyle::Line).channel(name)
        })
        .collect();
    series.push(Series::new("max(n·l, 0)", lambert, SeriesStyle::Dashed));
    out.extend(crate::plot::line_plot(
        &out_dir.join("skin_punctual_slices_rgb"),
        &format!("Skin LUT row κ = {:.3}/mm: D per channel", kappas[j]),
        "n·l",
        "D",
        &series,
        false,
    )?);

    // (4) Linear vs radial kernel on the LUT's grid, integrated again from the same profile.
    let profile = lut.profile()?;
    let tol = Tolerance { abs: lut.v["tolerance"].as_f64().unwrap_or(DEFAULT_TOLERANCE.abs), ..DEFAULT_TOLERANCE };
    let integrate = |kernel: Kernel, nl: &[f64], k: &[f64]| -> Result<Vec<[f64; 3]>, PlotError> {
        Ok(punctual_grid_estimates(&profile, kernel, nl, k, tol)
            .map_err(|e| lut.err(format!("profile: {e}")))?
            .iter()
            .map(|e| e.map(|x| x.value))
            .collect())
    };
    let linear = channel(&integrate(Kernel::Linear, &nls, &kappas)?, 0);
    let radial = channel(&integrate(Kernel::Radial, &nls, &kappas)?, 0);
    let diff: Vec<f64> = linear.iter().zip(&radial).map(|(a, b)| a - b).collect();
    let max_diff = diff.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    out.extend(crate::plot::grid_of_heatmaps(
        &out_dir.join("skin_kernels"),
        &format!("Ring kernels, red D(n·l, κ): linear profile vs radial profile (max |difference| {max_diff:.3})"),
        "n·l",
        "curvature κ (1/mm)",
        &nls,
        &kappas,
        &[
            Panel { title: "linear (line-source) profile", values: &linear },
            Panel { title: "radial profile (Penner 2011)", values: &radial },
        ],
        2,
        "D (red)",
        false,
        Some((0.0, 1.0)),
    )?);
    let fine = n_dot_l_axis(SLICE_SAMPLES);
    let kmax = *kappas.last().expect("h ≥ 2");
    let mut series = Vec::new();
    for kappa in [0.25 * kmax, kmax] {
        for (kernel, name, style) in [(Kernel::Linear, "linear", SeriesStyle::Line), (Kernel::Radial, "radial", SeriesStyle::Dashed)] {
            let d = integrate(kernel, &fine, &[kappa])?;
            let pts = fine.iter().zip(&d).map(|(&x, v)| (x, v[0])).collect();
            series.push(Series::new(format!("{name}, κ = {kappa:.3}/mm"), pts, style));
        }
    }
    out.extend(crate::plot::line_plot(
        &out_dir.join("skin_kernel_slices"),
        "Ring kernels: red D against n·l (solid: linear profile, dashed: radial)",
        "n·l",
        "D (red)",
        &series,
        false,
    )?);
    Ok(out)
}

fn sh_figures(out_dir: &Path, lut: &Lut) -> Result<Vec<PathBuf>, PlotError> {
    let w = lut.width;
    if lut.height != 2 {
        return Err(lut.err(format!("an SH LUT has 2 rows, found {}", lut.height)));
    }
    let kappas = lut.curvatures()?;
    if kappas.len() != w {
        return Err(lut.err(format!("{} curvatures for {w} columns", kappas.len())));
    }
    let mut series = Vec::new();
    for (c, name) in ["red", "green", "blue"].iter().enumerate() {
        for (band, style) in [(1, SeriesStyle::Line), (2, SeriesStyle::Dashed)] {
            let pts = kappas.iter().enumerate().map(|(i, &k)| (k, lut.values[(band - 1) * w + i][c])).collect();
            series.push(Series::new(format!("k_{band} {name}"), pts, style).channel(name));
        }
    }
    crate::plot::line_plot(
        &out_dir.join("skin_sh_bands"),
        "SH band factors of skin scattering (solid: k_1, dashed: k_2; k_0 = 1)",
        "curvature κ (1/mm)",
        "k_l",
        &series,
        false,
    )
}

/// An RGB image over a grid (`rgb[j * xs.len() + i]` at (xs[i], ys[j])), each value filling
/// the cell halfway to its neighbours, sRGB-encoded.
struct RgbImage<'a> {
    title: String,
    x_label: &'a str,
    y_label: &'a str,
    xs: &'a [f64],
    ys: &'a [f64],
    rgb: &'a [[f64; 3]],
}

impl Figure for RgbImage<'_> {
    fn size(&self) -> (u32, u32) {
        (720, 680)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult {
        root.fill(&WHITE).map_err(de)?;
        let body = root.margin(8, 0, 0, 0).titled(&self.title, (FONT_FAMILY, TITLE_SIZE - 6)).map_err(de)?;
        let xe = crate::plot::cell_edges(self.xs);
        let ye = crate::plot::cell_edges(self.ys);
        let (x0, x1) = (xe[0], xe[xe.len() - 1]);
        let (y0, y1) = (ye[0], ye[ye.len() - 1]);
        let xt = ticks::linear(x0, x1, 5);
        let yt = ticks::linear(y0, y1, 5);
        let mut chart = ChartBuilder::on(&body)
            .margin(14)
            .x_label_area_size(58)
            .y_label_area_size(label_width(&yt) + 12 + 44)
            .build_cartesian_2d(Axis::new((x0, x1), &xt), Axis::new((y0, y1), &yt))
            .map_err(de)?;
        let nx = self.xs.len();
        chart
            .draw_series(self.rgb.iter().enumerate().map(|(k, v)| {
                let (i, j) = (k % nx, k / nx);
                let c = RGBColor(srgb8(v[0]), srgb8(v[1]), srgb8(v[2]));
                Rectangle::new([(xe[i], ye[j]), (xe[i + 1], ye[j + 1])], c.filled())
            }))
            .map_err(de)?;
        let xf = |v: &f64| xt.label(*v);
        let yf = |v: &f64| yt.label(*v);
        crate::plot::axes_style(chart.configure_mesh().disable_mesh(), self.x_label, self.y_label)
            .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .draw()
            .map_err(de)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_from_committed_json() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let dir = tempfile::tempdir().unwrap();
        let files = skin_figures(&dir.path().join("figures"), &generated).unwrap();
        assert_eq!(files.len(), 14);
        for f in &files {
            assert!(std::fs::metadata(f).unwrap().len() > 5_000, "{}", f.display());
        }
        // Deterministic: a second rendering is byte-identical.
        let again = skin_figures(&dir.path().join("again"), &generated).unwrap();
        for (a, b) in files.iter().zip(&again) {
            assert!(std::fs::read(a).unwrap() == std::fs::read(b).unwrap(), "{}", a.display());
        }
    }

    #[test]
    fn no_skin_json_means_no_figures_and_bad_json_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        assert!(skin_figures(dir.path(), dir.path()).unwrap().is_empty());
        std::fs::create_dir(dir.path().join("json")).unwrap();
        std::fs::write(dir.path().join("json/skin_sh_lut.json"), "{\"texture\": {}}").unwrap();
        let e = skin_figures(dir.path(), dir.path()).unwrap_err();
        assert!(e.to_string().contains("skin_sh_lut.json"), "{e}");
    }
}
