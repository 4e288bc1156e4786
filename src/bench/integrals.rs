//! Integrators: method × tolerance (or resolution) → wall time, integrand evaluations and max
//! error against a converged reference, for every quantity a family benchmarks.
//!
//! Each quantity gets its own production integrator (the one `shadefit build` samples with) at
//! a ladder of tolerances, next to the straightforward alternatives a user would write: a fixed
//! Gauss–Legendre product rule, plain Monte Carlo, an unsplit adaptive rule. The reference of
//! every row is named in the row: a closed form where one exists (each checked elsewhere
//! against independent quadratures), otherwise the production integrator at a tolerance 2–4
//! orders below the tightest row. Everything runs on one thread, so the times compare methods
//! rather than thread counts. The tables themselves are the families' ([`IntegratorBench`]);
//! the helpers here time and measure their rows.

use super::{FamilyBench, Mode, time_it};
use crate::integrate::Estimate;
use serde::Serialize;

/// One quantity's integrator table: its rows, made and timed by `run`.
#[derive(Debug, Clone, Copy)]
pub struct IntegratorBench {
    /// Place in the section across families (see [`FamilyBench`]).
    pub order: u32,
    pub run: fn(&Mode) -> Vec<IntegratorRow>,
}

/// One (method, setting) of one quantity's integrator.
#[derive(Debug, Clone, Serialize)]
pub struct IntegratorRow {
    pub quantity: &'static str,
    pub method: String,
    pub setting: String,
    pub points: usize,
    /// Wall time per point (one thread).
    pub seconds_per_point: f64,
    /// Integrand evaluations per point (mean).
    pub evals_per_point: f64,
    pub max_error: f64,
    /// Largest error estimate the method reported (adaptive methods only).
    pub max_estimate: Option<f64>,
    pub reference: String,
}

/// Outcome of one method at one setting on all points: values, estimates, evaluations.
pub struct Run {
    pub values: Vec<f64>,
    pub estimates: Option<Vec<f64>>,
    pub evals: u64,
}

impl Run {
    /// An adaptive method's estimates: values, error estimates and evaluations.
    pub fn from_estimates(e: Vec<Estimate>) -> Run {
        Run {
            values: e.iter().map(|e| e.value).collect(),
            estimates: Some(e.iter().map(|e| e.error).collect()),
            evals: e.iter().map(|e| e.evals).sum(),
        }
    }

    /// A fixed rule's values, at `evals_per_point` integrand evaluations a point.
    pub fn fixed(values: Vec<f64>, evals_per_point: u64) -> Run {
        let evals = evals_per_point * values.len() as u64;
        Run {
            values,
            estimates: None,
            evals,
        }
    }
}

/// Time `run` over all points and compare with `reference` (its name, its values).
pub fn row(
    mode: &Mode,
    quantity: &'static str,
    method: &str,
    setting: String,
    reference: (&str, &[f64]),
    run: impl Fn() -> Run,
) -> IntegratorRow {
    let (seconds, r) = time_it(mode.min_seconds, run);
    let n = r.values.len();
    let max_error = r
        .values
        .iter()
        .zip(reference.1)
        .map(|(v, t)| (v - t).abs())
        .fold(0.0, f64::max);
    IntegratorRow {
        quantity,
        method: method.to_string(),
        setting,
        points: n,
        seconds_per_point: seconds / n as f64,
        evals_per_point: r.evals as f64 / n as f64,
        max_error,
        max_estimate: r.estimates.map(|e| e.iter().copied().fold(0.0, f64::max)),
        reference: reference.0.to_string(),
    }
}

/// The production integrator `eval` at each tolerance of `ladder`, against itself at `ref_tol`:
/// the reference values (for the other methods) and the rows.
pub fn self_ladder(
    mode: &Mode,
    quantity: &'static str,
    method: &str,
    ref_tol: f64,
    ladder: Vec<f64>,
    eval: impl Fn(f64) -> Vec<Estimate>,
) -> (Vec<f64>, Vec<IntegratorRow>) {
    let truth: Vec<f64> = eval(ref_tol).iter().map(|e| e.value).collect();
    let label = format!("adaptive at tol {ref_tol:.0e}");
    let rows = ladder
        .into_iter()
        .map(|tol| row(mode, quantity, method, format!("tol {tol:.0e}"), (&label, &truth), || Run::from_estimates(eval(tol))))
        .collect();
    (truth, rows)
}

/// Every family's integrator tables, by order.
pub fn all(mode: &Mode, families: &[&FamilyBench]) -> Vec<IntegratorRow> {
    super::ordered(families, |f| f.integrators, |t| t.order)
        .into_iter()
        .flat_map(|t| (t.run)(mode))
        .collect()
}

/// The quick or the full list of settings.
pub fn pick<T: Copy>(mode: &Mode, quick: &[T], full: &[T]) -> Vec<T> {
    if mode.quick { quick.to_vec() } else { full.to_vec() }
}
