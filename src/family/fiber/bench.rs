//! The fiber family's benchmark rows (`shadefit bench`, see `crate::bench`):
//! - integrators: N(k, u·t) by the production formulation (cap closed, belt adaptive) at a
//!   ladder of tolerances, against Gauss–Legendre products over the sphere of v (no change of
//!   variables; split at the cone h = ±t or not), on a 9×9 grid of (k, u·t);
//! - fits: `fiber_phase_scale` (quick);
//! - shader forms of `fiber-phase-scale`: the refit, a cheaper rational even in u·t, a mid-size
//!   one, tables at two resolutions. (No default table spec: nothing for numpy.)

use super::integrals as fiber;
use crate::bench::fits::FitBench;
use crate::bench::forms::{Ctx, FormRow, FormSet, Integral, fit_row, refit_row, set, strings, table_row, table_spec, table_values};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row};
use crate::bench::{BenchError, FamilyBench, Mode};
use crate::pipeline;

/// The fiber family's rows.
pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[IntegratorBench { order: 10, run: norm_integrators }],
    fits: &[FitBench { spec: "fiber_phase_scale", order: 10, quick: true }],
    tables: &[],
    builds: &[],
    forms: &[FormSet { quantity: "fiber-phase-scale", order: 10, forms: fiber_phase_scale }],
};

fn points() -> Vec<(f64, f64)> {
    let ks = (0..9).map(|i| -0.99 + 0.99 * i as f64 / 8.0);
    ks.flat_map(|k| (0..9).map(move |j| (k, -1.0 + 2.0 * j as f64 / 8.0))).collect()
}

fn norm_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let pts = points();
    let reference: Vec<f64> = pts.iter().map(|&(k, c)| fiber::norm(k, c, 1e-15).value).collect();
    let reference = ("cap closed + belt adaptive at tol 1e-15", reference.as_slice());
    let mut rows = Vec::new();
    for tol in pick(mode, &[1e-6, 1e-12], &[1e-6, 1e-9, 1e-12, 1e-14]) {
        rows.push(row(mode, "fiber-phase-norm", "cap closed + belt G10/K21 adaptive (shadefit)", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(pts.iter().map(|&(k, c)| fiber::norm(k, c, tol)).collect())
        }));
    }
    for n in pick(mode, &[16, 64], &[16, 64, 256]) {
        rows.push(row(mode, "fiber-phase-norm", "Gauss–Legendre product over v, split at the cone", format!("n = {n}"), reference, || {
            Run::fixed(pts.iter().map(|&(k, c)| fiber::one_minus_k2(k) * fiber::mean_sphere_product(k, c, n, true)).collect(), 2 * (n * n) as u64)
        }));
    }
    for n in pick(mode, &[64], &[64, 256]) {
        rows.push(row(mode, "fiber-phase-norm", "Gauss–Legendre product over v, unsplit", format!("n = {n}"), reference, || {
            Run::fixed(pts.iter().map(|&(k, c)| fiber::one_minus_k2(k) * fiber::mean_sphere_product(k, c, n, false)).collect(), (n * n) as u64)
        }));
    }
    rows
}

/// W(k, |u·t|), the factor that normalises the Schlick fiber lobe.
fn fiber_phase_scale(ctx: &Ctx) -> Result<Vec<FormRow>, BenchError> {
    let refit = ctx.spec("fiber_phase_scale")?;
    let mut integral = Integral::of(&refit);
    // The committed verification grid (129²: 4 per fitting step); quick: 65².
    let n = ctx.pick(129, 65);
    let reference = integral.reference(pipeline::grid(&refit, &[n, n]));
    let even = ctx.variant(&refit, "fiber_phase_scale_even", |t| {
        set(t, "model.numerator", strings(&["1", "k", "k^2", "k*u_dot_t^2", "k^2*u_dot_t^2"]));
        set(t, "model.denominator", strings(&["k", "k*u_dot_t^2"]));
    })?;
    let mid = ctx.variant(&refit, "fiber_phase_scale_mid", |t| {
        set(t, "model.numerator", strings(&["1", "k", "k^2", "k*u_dot_t^2", "k^2*u_dot_t^2", "k*u_dot_t^3", "k^2*u_dot_t^3"]));
        set(t, "model.denominator", strings(&["k", "k*u_dot_t^2", "k*u_dot_t^3"]));
    })?;
    let small = table_spec(ctx, &refit, "fiber_phase_scale_table_9", 9)?;
    let large = table_spec(ctx, &refit, "fiber_phase_scale_table_33", 33)?;
    let m = ctx.pick(refit.file.axis[0].count, 17);
    let note = format!("W = 1 at k = 0, minimax on {m}×{m}");
    Ok(vec![
        refit_row(&refit, ctx.generated, &reference, "fits/fiber_phase_scale.toml, committed")?,
        fit_row(&even, integral.fit(&even, &[m, m])?, &reference, "rational, even in u·t (4 + 2 terms)", &note)?,
        fit_row(&mid, integral.fit(&mid, &[m, m])?, &reference, "rational, 6 + 3 terms", &note)?,
        table_row(&small, table_values(&mut integral, &small), &reference, "table 9²", "")?,
        table_row(&large, table_values(&mut integral, &large), &reference, "table 33²", "")?,
    ])
}
