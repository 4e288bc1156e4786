//! Fuzz figures, after the appendices of the Ghost of Tsushima supplemental: the reference
//! integrals of [`crate::family::fuzz::integrals`] against the published approximations of
//! [`crate::family::fuzz::published`] and shadefit's committed refits.
//!
//! - App. B, P_s over the light direction (θu ∈ [0, π/2] × φu ∈ [0, π], cell midpoints) at
//!   α = 0.15, 0.35, 0.55, 0.75 and θf = 0.1, π/4, π/2: `fuzz_ps_alpha_A` (reference P_s and
//!   published P̃_s, one colour scale) and `fuzz_ps_error_alpha_A` (P̃_s − P_s). The published
//!   P̃_s is Eq. 1 with Listing 1's rows 3 and 4 exchanged
//!   ([`crate::family::fuzz::published::ps_from_coeffs_swapped`]): the table as printed puts c₄ before c₃
//!   (see `shadefit validate`). A refit of P̃_s, when given to [`fuzz_figures_with`], adds its
//!   panels to both figures.
//! - App. D, G(d, μv): `fuzz_g` (curves against μv for several d: reference, published G̃,
//!   refit) and `fuzz_g_errors` (G̃ − G over μv × d, published and refit).
//! - App. F, Q(d) = 2E₃(d): `fuzz_q` and `fuzz_q_error`.
//! - App. H, R(α, θf): `fuzz_r` (reference, published R̃ and refit on one colour scale),
//!   `fuzz_r_errors` and `fuzz_r_curves` (against θf for the α of App. B).
//!
//! Errors are signed, approximation − reference. Figure text names the approximations in words
//! ("published fit", "refit"): the embedded rasteriser draws no combining marks, so P̃ would
//! show a detached tilde. Angles are in radians, with the conventions of
//! [`crate::family::fuzz::integrals`] (normal +z, fiber t = (sin θf, 0, cos θf), φu from the fiber
//! azimuth). The refits are `GENERATED/json/fuzz_{g,q,r}.json`, evaluated through the model of
//! the spec each names, whose axis order is checked here: (μv, d) for G, (d) for Q, (α, θf)
//! for R. The cost is the reference P_s and R integrals ([`FuzzResolution`]).

use crate::plot::{Panel, PlotError, Series, SeriesStyle};
use crate::fit::RationalModel;
use crate::family::fuzz::integrals::{fitting_directions, g_exact, linspace, ps_grid, q_exact, r_grid};
use crate::family::fuzz::published::{
    ps_from_coeffs, ps_from_coeffs_swapped, published_g, published_ps_coeffs, published_q, published_r,
};
use nalgebra::DVector;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::path::{Path, PathBuf};

/// α of the P_s figures and of the R curves (those of the supplemental's Appendix B).
const ALPHAS: [f64; 4] = [0.15, 0.35, 0.55, 0.75];
/// θf of the P_s figures, with their labels.
const PS_THETA_F: [(f64, &str); 3] = [(0.1, "0.1"), (FRAC_PI_4, "π/4"), (FRAC_PI_2, "π/2")];
/// d of the G curves.
const G_DENSITIES: [f64; 6] = [0.01, 0.05, 0.1, 0.2, 0.3, 0.5];
/// Smallest μv plotted: that of fits/fuzz_g.toml (Listing 3 is 0/0 at μv = d = 0).
const G_MU_V_MIN: f64 = 0.001;
/// Reference points marked on each G curve (G itself is a closed form; the marks keep the
/// reference apart from the fitted lines).
const G_MARKS: usize = 26;
/// Published domain of the G̃ and Q̃ fits in d, and of the R̃ fit in α.
const D_MAX: f64 = 0.5;
const ALPHA_MIN: f64 = 0.15;
/// Absolute tolerances of the P_s and R integrals: below the smallest error plotted (the refit
/// of R, ~1e-4) by three orders and far below one colour step.
const PS_TOL: f64 = 1e-7;
const R_TOL: f64 = 1e-7;
/// Tab10 index of the grey legend keys that say what a line style stands for.
const KEY_COLOR: usize = 7;

/// Sampling of the fuzz figures. The reference P_s (ALPHAS × 3 θf × the light directions) and
/// R (the α × θf grid, ~1 ms a point) cost nearly all of the time; G and Q are closed forms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FuzzResolution {
    /// Light directions of each P_s panel: θu × φu cell midpoints.
    pub ps_theta_u: usize,
    pub ps_phi_u: usize,
    /// The R grid: α uniform on [0.15, 1], θf uniform on [0, π/2].
    pub r_alpha: usize,
    pub r_theta_f: usize,
    /// The G error maps: μv uniform on [0.001, 1], d uniform on [0, 0.5].
    pub g_mu_v: usize,
    pub g_d: usize,
    /// Samples of the 1-D curves.
    pub curve: usize,
}

impl FuzzResolution {
    /// What `shadefit plot` draws: 24 × 48 light directions (square cells), R on 18 × 17
    /// (α in steps of 0.05, so the R curves' α lie on the grid), G maps 129 × 129, curves of
    /// 257 points.
    pub const FULL: Self =
        Self { ps_theta_u: 24, ps_phi_u: 48, r_alpha: 18, r_theta_f: 17, g_mu_v: 129, g_d: 129, curve: 257 };
}

/// Writes the fuzz figures into `out_dir` at [`FuzzResolution::FULL`] and returns the files
/// written (each figure as `.png` and `.svg`). No refit of P̃_s is committed yet, so none is
/// drawn; [`fuzz_figures_with`] takes one.
pub fn fuzz_figures(out_dir: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    // The committed two-stage refit of P̃_s (generated/json/fuzz_ps.json), when there is one.
    let fields = crate::pipeline::committed::Fields::load(generated, "fuzz_ps", crate::family::catalog()).ok();
    let refit = fields.as_ref().map(|f| {
        move |alpha: f64, theta_f: f64| -> [f64; 6] {
            let c = f.eval(&[alpha, theta_f]);
            std::array::from_fn(|k| c.get(k).copied().unwrap_or(f64::NAN))
        }
    });
    fuzz_figures_with(out_dir, generated, &FuzzResolution::FULL, refit.as_ref().map(|r| r as &dyn Fn(f64, f64) -> [f64; 6]))
}

/// [`fuzz_figures`] at resolution `res`, with an optional refit of P̃_s: `ps_refit(α, θf)`
/// returns c₀…c₅ in the order of Eq. 1, c₀ + c₁ n·u + c₂ t·u + c₃ (n·u)² + c₄ (n·u)(t·u) +
/// c₅ (t·u)².
pub fn fuzz_figures_with(
    out_dir: &Path,
    generated: &Path,
    res: &FuzzResolution,
    ps_refit: Option<&dyn Fn(f64, f64) -> [f64; 6]>,
) -> Result<Vec<PathBuf>, PlotError> {
    // Read every input before integrating anything.
    let g_refit = Refit::load(generated, "fuzz_g", &["mu_v", "d"])?;
    let q_refit = Refit::load(generated, "fuzz_q", &["d"])?;
    let r_refit = Refit::load(generated, "fuzz_r", &["alpha", "theta_f"])?;
    if [res.ps_theta_u, res.ps_phi_u, res.r_alpha, res.r_theta_f, res.g_mu_v, res.g_d, res.curve].iter().any(|&n| n < 2)
    {
        return Err(PlotError::Data {
            path: out_dir.to_path_buf(),
            message: format!("every sample count of the fuzz figures must be at least 2: {res:?}"),
        });
    }
    let mut out = ps_figures(out_dir, res, ps_refit)?;
    out.extend(g_figures(out_dir, res, &g_refit)?);
    out.extend(q_figures(out_dir, res, &q_refit)?);
    out.extend(r_figures(out_dir, res, &r_refit)?);
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// App. B: P_s

/// (n·u, t·u) for the light (θu, φu) and fiber angle θf.
fn dots(theta_f: f64, theta_u: f64, phi_u: f64) -> (f64, f64) {
    let n_u = theta_u.cos();
    (n_u, theta_u.sin() * phi_u.cos() * theta_f.sin() + n_u * theta_f.cos())
}

fn ps_figures(
    out_dir: &Path,
    res: &FuzzResolution,
    refit: Option<&dyn Fn(f64, f64) -> [f64; 6]>,
) -> Result<Vec<PathBuf>, PlotError> {
    // θu-major, φu fastest: the heatmap layout with x = φu, y = θu.
    let dirs = fitting_directions(res.ps_theta_u, res.ps_phi_u);
    let phis: Vec<f64> = dirs[..res.ps_phi_u].iter().map(|d| d.1).collect();
    let thetas: Vec<f64> = dirs.iter().step_by(res.ps_phi_u).map(|d| d.0).collect();
    let tfs: Vec<f64> = PS_THETA_F.iter().map(|t| t.0).collect();
    let reference = ps_grid(&ALPHAS, &tfs, &dirs, PS_TOL);
    let (x_label, y_label) = ("light azimuth φu from the fiber (radians)", "light polar angle θu (radians)");
    let refit_note = if refit.is_some() { ", refit" } else { "" };

    let mut out = Vec::new();
    for (ia, &alpha) in ALPHAS.iter().enumerate() {
        // Rows of panels, one column per θf: values (reference, published, refit) and errors
        // (published, refit); each (title, values).
        let mut rows: [Vec<(String, Vec<f64>)>; 3] = Default::default();
        let mut error_rows: [Vec<(String, Vec<f64>)>; 2] = Default::default();
        for (it, &(tf, tf_label)) in PS_THETA_F.iter().enumerate() {
            let exact: Vec<f64> = reference[ia * tfs.len() + it].iter().map(|e| e.value).collect();
            let eq1 = |c: &[f64; 6], f: fn(&[f64; 6], f64, f64) -> f64| -> Vec<f64> {
                dirs.iter()
                    .map(|&(tu, pu)| {
                        let (n_u, t_u) = dots(tf, tu, pu);
                        f(c, n_u, t_u)
                    })
                    .collect()
            };
            let published = eq1(&published_ps_coeffs(alpha, tf), ps_from_coeffs_swapped);
            let err = difference(&published, &exact);
            error_rows[0].push((format!("published, θf = {tf_label}: {}", stats(&err)), err));
            rows[1].push((format!("published fit, θf = {tf_label}"), published));
            if let Some(f) = refit {
                let fitted = eq1(&f(alpha, tf), ps_from_coeffs);
                let err = difference(&fitted, &exact);
                error_rows[1].push((format!("refit, θf = {tf_label}: {}", stats(&err)), err));
                rows[2].push((format!("refit, θf = {tf_label}"), fitted));
            }
            rows[0].push((format!("reference P_s, θf = {tf_label}"), exact));
        }
        let values: Vec<(String, Vec<f64>)> = rows.into_iter().flatten().collect();
        let errors: Vec<(String, Vec<f64>)> = error_rows.into_iter().flatten().collect();

        let value_panels: Vec<Panel> = values.iter().map(|(t, v)| Panel { title: t, values: v }).collect();
        out.extend(crate::plot::grid_of_heatmaps(
            &out_dir.join(format!("fuzz_ps_alpha_{alpha:.2}")),
            &format!("P_s at α = {alpha:.2}: reference, published fit (Listing 1 with rows 3/4 swapped){refit_note}"),
            x_label,
            y_label,
            &phis,
            &thetas,
            &value_panels,
            PS_THETA_F.len(),
            "fraction scattered toward the base",
            false,
            None,
        )?);
        let error_panels: Vec<Panel> = errors.iter().map(|(t, v)| Panel { title: t, values: v }).collect();
        out.extend(crate::plot::grid_of_heatmaps(
            &out_dir.join(format!("fuzz_ps_error_alpha_{alpha:.2}")),
            &format!("Error of the P_s fits at α = {alpha:.2} (fit − reference): published (Listing 1 with rows 3/4 swapped){refit_note}"),
            x_label,
            y_label,
            &phis,
            &thetas,
            &error_panels,
            PS_THETA_F.len(),
            "fit − reference P_s",
            true,
            None,
        )?);
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// App. D: G

fn g_figures(out_dir: &Path, res: &FuzzResolution, refit: &Refit) -> Result<Vec<PathBuf>, PlotError> {
    let mut out = Vec::new();

    // Curves against μv, denser towards 0 where G changes on the scale of d.
    let mus: Vec<f64> = (0..res.curve)
        .map(|k| {
            let s = k as f64 / (res.curve - 1) as f64;
            G_MU_V_MIN + (1.0 - G_MU_V_MIN) * s * s
        })
        .collect();
    let marks = linspace(G_MU_V_MIN, 1.0, G_MARKS);
    let mut series = style_keys("reference G", "published fit (Listing 3)", "refit (fuzz_g.json)");
    for (i, &d) in G_DENSITIES.iter().enumerate() {
        series.push(
            Series::new(format!("d = {d}"), marks.iter().map(|&m| (m, g_exact(d, m))).collect(), SeriesStyle::Points)
                .color(i),
        );
        series.push(Series::new("", mus.iter().map(|&m| (m, published_g(m, d))).collect(), SeriesStyle::Line).color(i));
        series.push(
            Series::new("", mus.iter().map(|&m| (m, refit.eval(&[m, d]))).collect(), SeriesStyle::Dashed).color(i),
        );
    }
    out.extend(crate::plot::line_plot(
        &out_dir.join("fuzz_g"),
        "Fuzz layer hemispherical average G(d, μv): reference, published fit, refit",
        "μv = n·v (cosine of the view angle)",
        "G",
        &series,
        false,
    )?);

    // Error maps over μv × d.
    let mu_grid = linspace(G_MU_V_MIN, 1.0, res.g_mu_v);
    let d_grid = linspace(0.0, D_MAX, res.g_d);
    let over_grid = |f: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        d_grid.iter().flat_map(|&d| mu_grid.iter().map(move |&m| (m, d))).map(|(m, d)| f(m, d)).collect()
    };
    let exact = over_grid(&|m, d| g_exact(d, m));
    let published = difference(&over_grid(&|m, d| published_g(m, d)), &exact);
    let refitted = difference(&over_grid(&|m, d| refit.eval(&[m, d])), &exact);
    out.extend(crate::plot::grid_of_heatmaps(
        &out_dir.join("fuzz_g_errors"),
        "Error of the G fits (fit − reference G)",
        "μv = n·v",
        "density d (optical thickness)",
        &mu_grid,
        &d_grid,
        &[
            Panel { title: &format!("published (Listing 3): {}", stats(&published)), values: &published },
            Panel { title: &format!("refit (fuzz_g.json): {}", stats(&refitted)), values: &refitted },
        ],
        2,
        "fit − reference G",
        true,
        None,
    )?);
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// App. F: Q

fn q_figures(out_dir: &Path, res: &FuzzResolution, refit: &Refit) -> Result<Vec<PathBuf>, PlotError> {
    let ds = linspace(0.0, D_MAX, res.curve);
    let curve = |f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> { ds.iter().map(|&d| (d, f(d))).collect() };
    let mut out = crate::plot::line_plot(
        &out_dir.join("fuzz_q"),
        "Fuzz layer average penetration Q(d) = 2E₃(d): reference, published fit, refit",
        "density d (optical thickness)",
        "Q",
        &[
            Series::new("reference 2E₃(d)", curve(&q_exact), SeriesStyle::Line),
            Series::new("published fit (Listing 4)", curve(&published_q), SeriesStyle::Dashed),
            Series::new("refit (fuzz_q.json)", curve(&|d| refit.eval(&[d])), SeriesStyle::Dashed),
        ],
        false,
    )?;
    let published = curve(&|d| published_q(d) - q_exact(d));
    let refitted = curve(&|d| refit.eval(&[d]) - q_exact(d));
    let max_abs = |s: &[(f64, f64)]| s.iter().fold(0.0_f64, |m, p| m.max(p.1.abs()));
    out.extend(crate::plot::line_plot(
        &out_dir.join("fuzz_q_error"),
        "Error of the Q fits (fit − 2E₃(d))",
        "density d (optical thickness)",
        "fit − reference Q",
        &[
            Series::new(
                format!("published (Listing 4), max |err| {:.2e}", max_abs(&published)),
                published,
                SeriesStyle::Line,
            ),
            Series::new(
                format!("refit (fuzz_q.json), max |err| {:.2e}", max_abs(&refitted)),
                refitted,
                SeriesStyle::Line,
            ),
        ],
        false,
    )?);
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// App. H: R

fn r_figures(out_dir: &Path, res: &FuzzResolution, refit: &Refit) -> Result<Vec<PathBuf>, PlotError> {
    let alphas = linspace(ALPHA_MIN, 1.0, res.r_alpha);
    let tfs = linspace(0.0, FRAC_PI_2, res.r_theta_f);
    // α-major: the heatmap layout with x = θf, y = α.
    let exact: Vec<f64> = r_grid(&alphas, &tfs, R_TOL).iter().map(|e| e.value).collect();
    let points = || alphas.iter().flat_map(|&a| tfs.iter().map(move |&t| (a, t)));
    let published: Vec<f64> = points().map(|(a, t)| published_r(a, t)).collect();
    let refitted: Vec<f64> = points().map(|(a, t)| refit.eval(&[a, t])).collect();
    let (x_label, y_label) = ("fiber polar angle θf (radians)", "α (SGGX fiber projected area)");

    let mut out = crate::plot::grid_of_heatmaps(
        &out_dir.join("fuzz_r"),
        "Cosine-weighted average of P_s, R(α, θf): reference, published fit, refit",
        x_label,
        y_label,
        &tfs,
        &alphas,
        &[
            Panel { title: "reference R", values: &exact },
            Panel { title: "published fit (Listing 5)", values: &published },
            Panel { title: "refit (fuzz_r.json)", values: &refitted },
        ],
        3,
        "R",
        false,
        None,
    )?;
    let published_err = difference(&published, &exact);
    let refit_err = difference(&refitted, &exact);
    out.extend(crate::plot::grid_of_heatmaps(
        &out_dir.join("fuzz_r_errors"),
        &format!("Error of the R fits (fit − reference R), {}×{} grid", alphas.len(), tfs.len()),
        x_label,
        y_label,
        &tfs,
        &alphas,
        &[
            Panel { title: &format!("published (Listing 5): {}", stats(&published_err)), values: &published_err },
            Panel { title: &format!("refit (fuzz_r.json): {}", stats(&refit_err)), values: &refit_err },
        ],
        2,
        "fit − reference R",
        true,
        None,
    )?);

    // Curves against θf: the grid rows nearest the α of App. B (the same α at full resolution).
    let mut rows: Vec<usize> = ALPHAS
        .iter()
        .map(|&a| {
            (0..alphas.len()).min_by(|&i, &j| (alphas[i] - a).abs().total_cmp(&(alphas[j] - a).abs())).unwrap_or(0)
        })
        .collect();
    rows.dedup();
    let dense = linspace(0.0, FRAC_PI_2, res.curve);
    let mut series = style_keys("reference R", "published fit (Listing 5)", "refit (fuzz_r.json)");
    for (k, &i) in rows.iter().enumerate() {
        let a = alphas[i];
        let reference = tfs.iter().zip(&exact[i * tfs.len()..(i + 1) * tfs.len()]).map(|(&t, &r)| (t, r)).collect();
        series.push(Series::new(format!("α = {a:.2}"), reference, SeriesStyle::Points).color(k));
        series
            .push(Series::new("", dense.iter().map(|&t| (t, published_r(a, t))).collect(), SeriesStyle::Line).color(k));
        series.push(
            Series::new("", dense.iter().map(|&t| (t, refit.eval(&[a, t]))).collect(), SeriesStyle::Dashed).color(k),
        );
    }
    out.extend(crate::plot::line_plot(
        &out_dir.join("fuzz_r_curves"),
        "R against the fiber angle: reference, published fit, refit",
        x_label,
        "R",
        &series,
        false,
    )?);
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Shared pieces

/// Grey legend keys saying what the point, solid and dashed styles stand for (the colours
/// then stand for a parameter value).
fn style_keys(points: &str, solid: &str, dashed: &str) -> Vec<Series> {
    vec![
        Series::new(points, vec![], SeriesStyle::Points).color(KEY_COLOR),
        Series::new(solid, vec![], SeriesStyle::Line).color(KEY_COLOR),
        Series::new(dashed, vec![], SeriesStyle::Dashed).color(KEY_COLOR),
    ]
}

fn difference(approx: &[f64], exact: &[f64]) -> Vec<f64> {
    approx.iter().zip(exact).map(|(a, e)| a - e).collect()
}

/// "max |err| …, rms …" of an error map (non-finite entries left out).
fn stats(errors: &[f64]) -> String {
    let finite: Vec<f64> = errors.iter().copied().filter(|v| v.is_finite()).collect();
    let max = finite.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let rms = (finite.iter().map(|v| v * v).sum::<f64>() / finite.len().max(1) as f64).sqrt();
    format!("max |err| {max:.2e}, rms {rms:.2e}")
}

/// A committed refit, evaluated through the model of its spec.
struct Refit {
    model: RationalModel,
    coefficients: DVector<f64>,
}

impl Refit {
    /// `GENERATED/json/NAME.json` and its spec, whose axes must be named `axes` in this order
    /// (the order of the arguments to [`Refit::eval`]).
    fn load(generated: &Path, name: &str, axes: &[&str]) -> Result<Self, PlotError> {
        let path = generated.join("json").join(format!("{name}.json"));
        let data_err = |message: String| PlotError::Data { path: path.clone(), message };
        std::fs::metadata(&path).map_err(|source| PlotError::Io { path: path.clone(), source })?;
        let refit = crate::pipeline::committed::Refit::load(generated, name, crate::family::catalog())
            .map_err(|e| data_err(format!("not a readable refit of its spec: {e}")))?;
        let (spec, coefficients) = (refit.spec, refit.coefficients);
        let names: Vec<&str> = spec.file.axis.iter().map(|a| a.name.as_str()).collect();
        if names != axes {
            return Err(data_err(format!("its spec {} has axes {names:?}, expected {axes:?}", spec.path.display())));
        }
        let model = spec.model.ok_or_else(|| data_err("its spec has no model".into()))?;
        Ok(Self { model, coefficients })
    }

    fn eval(&self, x: &[f64]) -> f64 {
        self.model.eval_clamped(&self.coefficients, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small enough to render in a few seconds; every figure and panel is still drawn.
    const TINY: FuzzResolution =
        FuzzResolution { ps_theta_u: 4, ps_phi_u: 6, r_alpha: 3, r_theta_f: 3, g_mu_v: 9, g_d: 9, curve: 17 };

    fn generated() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")
    }

    #[test]
    fn renders_deterministic_figures_from_committed_refits() {
        let dir = tempfile::tempdir().unwrap();
        let first = fuzz_figures_with(dir.path(), &generated(), &TINY, None).unwrap();
        // 4 α × (values, errors) for P_s, then fuzz_g, fuzz_g_errors, fuzz_q, fuzz_q_error,
        // fuzz_r, fuzz_r_errors, fuzz_r_curves; PNG and SVG each.
        assert_eq!(first.len(), 2 * (8 + 7));
        let bytes: Vec<Vec<u8>> = first.iter().map(|p| std::fs::read(p).unwrap()).collect();
        for (p, b) in first.iter().zip(&bytes) {
            assert!(b.len() > 5_000, "{} is only {} bytes", p.display(), b.len());
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), first.len());
        let second = fuzz_figures_with(dir.path(), &generated(), &TINY, None).unwrap();
        assert_eq!(first, second);
        for (p, b) in second.iter().zip(&bytes) {
            assert!(std::fs::read(p).unwrap() == *b, "{} differs between renders", p.display());
        }
    }

    #[test]
    fn ps_refit_adds_panels() {
        // The published coefficients reordered into Eq. 1's order: the refit panels then
        // repeat the published ones, and the figures grow by a row.
        let reordered = |a: f64, tf: f64| {
            let c = published_ps_coeffs(a, tf);
            [c[0], c[1], c[2], c[4], c[3], c[5]]
        };
        let dir = tempfile::tempdir().unwrap();
        let without = ps_figures(&dir.path().join("a"), &TINY, None).unwrap();
        let with = ps_figures(&dir.path().join("b"), &TINY, Some(&reordered)).unwrap();
        assert_eq!(with.len(), without.len());
        for (a, b) in without.iter().zip(&with) {
            let (a, b) = (std::fs::metadata(a).unwrap().len(), std::fs::metadata(b).unwrap().len());
            assert!(b > a, "{b} bytes with the refit, {a} without");
        }
    }

    #[test]
    fn missing_refit_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let e = fuzz_figures_with(dir.path(), dir.path(), &TINY, None).unwrap_err();
        assert!(e.to_string().contains("fuzz_g.json"), "{e}");
    }

    #[test]
    fn dots_match_the_fiber_frame() {
        // t = (sin θf, 0, cos θf), u = (sin θu cos φu, sin θu sin φu, cos θu).
        let (tf, tu, pu) = (0.7_f64, 1.1_f64, 2.3_f64);
        let u = [tu.sin() * pu.cos(), tu.sin() * pu.sin(), tu.cos()];
        let (n_u, t_u) = dots(tf, tu, pu);
        assert_eq!(n_u, u[2]);
        // Rounding of a 3-term dot product.
        assert!((t_u - (tf.sin() * u[0] + tf.cos() * u[2])).abs() < 1e-15);
    }
}
