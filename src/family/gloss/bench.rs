//! The gloss family's benchmark rows (`shadefit bench`, see `crate::bench`):
//! - integrators: the normal length L(g) in closed form (series / logarithm) against adaptive
//!   and Gauss–Legendre quadrature of its integral over t ∈ [0, 1];
//! - fits: `gloss_length` (quick and full), `gloss_combine` (full runs);
//! - tables against numpy/scipy: `gloss_table`, `gloss_inverse_table`, `gloss_combine_lut`,
//!   all closed forms on shadefit's side (numpy has artanh for the length: the second ratio
//!   leaves it out); the script names the gloss axis `g`;
//! - shader forms of `gloss-length` and `gloss-combine`: the COD: WWII constants, the refits,
//!   cheaper and richer rationals, tables at two resolutions.

use super::integrals as gloss;
use crate::bench::fits::FitBench;
use crate::bench::forms::{
    Ctx, FormRow, FormSet, Integral, PUBLISHED, committed_values, fit_row, pin, refit_row, set, strings, table_row, table_spec,
    table_values,
};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row};
use crate::bench::tables::{Ladder, Params, Shape, TableBench};
use crate::bench::{BenchError, FamilyBench, Mode};
use crate::integrate::gauss_legendre;
use crate::pipeline;
use nalgebra::DVector;

/// The gloss family's rows.
pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[IntegratorBench { order: 4, run: gloss_length_integrators }],
    fits: &[FitBench { spec: "gloss_length", order: 0, quick: true }, FitBench { spec: "gloss_combine", order: 3, quick: false }],
    tables: &[
        TableBench {
            spec: "gloss_table",
            order: 0,
            samples: (32, 128),
            ladder: Ladder::ClosedForm,
            reference_tolerance: 1e-14,
            // The script names gloss `g`.
            shape: Shape { params: Params::Axes { rename: &[("gloss", "g")] }, ..Shape::SCALAR },
        },
        TableBench {
            spec: "gloss_inverse_table",
            order: 1,
            samples: (32, 128),
            ladder: Ladder::ClosedForm,
            reference_tolerance: 1e-14,
            shape: Shape::SCALAR,
        },
        TableBench {
            spec: "gloss_combine_lut",
            order: 2,
            samples: (32, 128),
            ladder: Ladder::ClosedForm,
            reference_tolerance: 1e-14,
            shape: Shape::SCALAR,
        },
    ],
    builds: &[],
    forms: &[
        FormSet { quantity: "gloss-length", order: 0, forms: gloss_length },
        FormSet { quantity: "gloss-combine", order: 1, forms: gloss_combine },
    ],
};

// ---------------------------------------------------------------------------------------------
// Integrators

fn gloss_length_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let gs: Vec<f64> = (0..=32).map(|i| i as f64 / 32.0).collect();
    let closed: Vec<f64> = gs.iter().map(|&g| gloss::length_from_gloss(g)).collect();
    let quad_ref: Vec<f64> = gs
        .iter()
        .map(|&g| gloss::normal_length_quadrature(gloss::alpha_from_gloss(g), 1e-15).value)
        .collect();
    let mut rows = Vec::new();
    rows.push(row(
        mode,
        "gloss length",
        "closed form: series / logarithm (shadefit)",
        "-".into(),
        ("adaptive at tol 1e-15", &quad_ref),
        || Run::fixed(gs.iter().map(|&g| gloss::length_from_gloss(g)).collect(), 0),
    ));
    let reference = ("closed form", closed.as_slice());
    for tol in pick(mode, &[1e-6, 1e-9, 1e-12], &[1e-4, 1e-6, 1e-9, 1e-12]) {
        rows.push(row(
            mode,
            "gloss length",
            "adaptive G10/K21 on t ∈ [0, 1]",
            format!("tol {tol:.0e}"),
            reference,
            || {
                Run::from_estimates(
                    gs.iter()
                        .map(|&g| gloss::normal_length_quadrature(gloss::alpha_from_gloss(g), tol))
                        .collect(),
                )
            },
        ));
    }
    for n in pick(mode, &[16, 256], &[16, 64, 256, 1024]) {
        let rule = gauss_legendre(n);
        rows.push(row(
            mode,
            "gloss length",
            "Gauss–Legendre on t ∈ [0, 1]",
            format!("n = {n}"),
            reference,
            || {
                Run::fixed(
                    gs.iter()
                        .map(|&g| {
                            let a2 = gloss::alpha_from_gloss(g).powi(2);
                            rule.0
                                .iter()
                                .zip(&rule.1)
                                .map(|(x, w)| {
                                    let t = 0.5 * (1.0 + x);
                                    let den = (1.0 - t) * (1.0 + t) + a2 * t * t;
                                    w * 0.5 * 2.0 * a2 * t * t / (den * den)
                                })
                                .sum()
                        })
                        .collect(),
                    n as u64,
                )
            },
        ));
    }
    rows
}

// ---------------------------------------------------------------------------------------------
// Shader forms

/// g → ‖n_s‖ (COD: WWII).
fn gloss_length(ctx: &Ctx) -> Result<Vec<FormRow>, BenchError> {
    let refit = ctx.spec("gloss_length")?;
    let table = ctx.spec("gloss_table")?;
    let mut integral = Integral::of(&refit);
    // The committed verification grid (16 points per step of the 256-entry table); quick: 4.
    let reference = integral.reference(pipeline::grid(&refit, &[ctx.pick(4081, 1021)]));
    let published_spec = ctx.variant(&refit, "gloss_length_published", |_| {})?;
    let published = super::published::published_fit_coefficients(super::published::PUBLISHED_ENDS.1);
    let cheaper = ctx.variant(&refit, "gloss_length_2_1", |t| {
        set(t, "model.numerator", strings(&["1", "gloss", "gloss^2"]));
        set(t, "model.denominator", strings(&["gloss"]));
        set(t, "model.pin", toml::Value::Array(vec![pin(0.0, "1"), pin(1.0, "gloss^2")]));
    })?;
    let richer = ctx.variant(&refit, "gloss_length_4_3", |t| {
        set(t, "model.numerator", strings(&["1", "gloss", "gloss^2", "gloss^3", "gloss^4"]));
        set(t, "model.denominator", strings(&["gloss", "gloss^2", "gloss^3"]));
        set(t, "model.pin", toml::Value::Array(vec![pin(0.0, "1"), pin(1.0, "gloss^4")]));
    })?;
    let small = table_spec(ctx, &table, "gloss_table_64", 64)?;
    let n = refit.file.axis[0].count;
    let fit_note = format!("ends pinned, minimax on {n} samples");
    Ok(vec![
        fit_row(&published_spec, DVector::from_row_slice(&published), &reference, PUBLISHED, "COD: WWII FindFit constants, pinned to the Monte Carlo ends")?,
        refit_row(&refit, ctx.generated, &reference, "fits/gloss_length.toml, committed")?,
        fit_row(&cheaper, integral.fit(&cheaper, &[n])?, &reference, "rational 2/1", &fit_note)?,
        fit_row(&richer, integral.fit(&richer, &[n])?, &reference, "rational 4/3", &fit_note)?,
        table_row(&table, committed_values(&table, ctx.generated)?, &reference, "table 256", "fits/gloss_table.toml, committed")?,
        table_row(&small, table_values(&mut integral, &small), &reference, "table 64", "")?,
    ])
}

/// Gloss of two combined normal maps (RNM of two GGX NDFs, COD: WWII).
fn gloss_combine(ctx: &Ctx) -> Result<Vec<FormRow>, BenchError> {
    let refit = ctx.spec("gloss_combine")?;
    let table = ctx.spec("gloss_combine_lut")?;
    let mut integral = Integral::of(&refit);
    // The committed table's grid (253 = 4·63 + 1: its nodes and midpoints; the 22-entry
    // table's too, 252 = 12·21); quick: 127 (the midpoints of both tables).
    let n = ctx.pick(253, 127);
    let reference = integral.reference(pipeline::grid(&refit, &[n, n]));
    let published_spec = ctx.variant(&refit, "gloss_combine_published", |_| {})?;
    let (p, q) = (super::published::PUBLISHED_COMBINE_P, super::published::PUBLISHED_COMBINE_Q);
    let published: Vec<f64> = p.iter().chain(&q[1..]).copied().collect();
    let cheaper = ctx.variant(&refit, "gloss_combine_3_2", |t| {
        set(t, "model.numerator", strings(&["1", "x + y", "x*y"]));
        set(t, "model.denominator", strings(&["x + y", "x*y"]));
    })?;
    let small = table_spec(ctx, &table, "gloss_combine_lut_22", 22)?;
    let m = ctx.pick(refit.file.axis[0].count, 33);
    let fit_note = format!("symmetric terms, clamp-aware lsq on {m}×{m}");
    Ok(vec![
        fit_row(&published_spec, DVector::from_vec(published), &reference, PUBLISHED, "COD: WWII rational fit constants")?,
        refit_row(&refit, ctx.generated, &reference, "fits/gloss_combine.toml, committed")?,
        fit_row(&cheaper, integral.fit(&cheaper, &[m, m])?, &reference, "rational, fewer terms", &fit_note)?,
        table_row(&table, committed_values(&table, ctx.generated)?, &reference, "table 64²", "fits/gloss_combine_lut.toml, committed")?,
        table_row(&small, table_values(&mut integral, &small), &reference, "table 22²", "")?,
    ])
}
