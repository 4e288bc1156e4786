//! Fits: solver × objective → time, iterations, max and rms error on the fitting samples.
//!
//! Each benchmarked spec is sampled once (the same grid `shadefit build` fits on) and fitted
//! with every combination of the least-squares solver (MINPACK Levenberg–Marquardt from the
//! `levenberg-marquardt` crate, argmin's Gauss–Newton with line search) and the objective
//! (least squares, minimax by Lawson + sequential LP, Σr⁴). The least-squares solver also runs
//! the multi-start and the starts of the other objectives. A failed fit is a row with its error.
//! The specs are the families' ([`FitBench`]; fit specs only: the two-stage fits of fields
//! specs are timed by `shadefit build`).

use super::{FamilyBench, Mode, time_it};
use crate::fit::{self, Data, FitOptions, LsqSolver, Objective};
use crate::pipeline;
use crate::spec::Spec;
use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct FitRow {
    pub spec: String,
    pub samples: usize,
    pub free_coefficients: usize,
    pub solver: &'static str,
    pub objective: Objective,
    pub seconds: f64,
    pub iterations: Option<usize>,
    pub evaluations: Option<usize>,
    pub max_error: Option<f64>,
    pub rms_error: Option<f64>,
    pub condition_number: Option<f64>,
    /// The fitter's error message when it failed.
    pub failure: Option<String>,
}

/// A fit spec (kind = "fit") a family has timed.
#[derive(Debug, Clone, Copy)]
pub struct FitBench {
    /// The spec's name in fits/ (skipped when absent).
    pub spec: &'static str,
    /// Place in the section across families (see [`FamilyBench`]).
    pub order: u32,
    /// Timed in quick mode too (else in full runs only).
    pub quick: bool,
}

/// Every family's fit specs of this mode, by order, with every solver and objective.
pub fn all(mode: &Mode, specs: &[Spec], families: &[&FamilyBench]) -> Vec<FitRow> {
    let mut rows = Vec::new();
    let names = super::ordered(families, |f| f.fits, |b| b.order).into_iter().filter(|b| b.quick || !mode.quick).map(|b| b.spec);
    for name in names {
        let Some(spec) = specs.iter().find(|s| s.file.name == name) else {
            continue;
        };
        let Some(model) = spec.model.as_ref() else {
            continue;
        };
        let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
        let x = pipeline::grid(spec, &counts);
        let y = pipeline::sample(spec, &x);
        let data = Data { x, y };
        for (solver, solver_name) in [
            (LsqSolver::Lm, "levenberg-marquardt (MINPACK)"),
            (LsqSolver::GaussNewton, "argmin Gauss–Newton (full steps)"),
        ] {
            for objective in objectives(solver) {
                let opts = FitOptions {
                    objective,
                    solver,
                    ..FitOptions::default()
                };
                let (seconds, result) =
                    time_it(mode.min_seconds, || fit::fit(model, &data, &opts, name));
                let mut r = FitRow {
                    spec: name.to_string(),
                    samples: data.len(),
                    free_coefficients: model.n_free(),
                    solver: solver_name,
                    objective,
                    seconds,
                    iterations: None,
                    evaluations: None,
                    max_error: None,
                    rms_error: None,
                    condition_number: None,
                    failure: None,
                };
                match result {
                    Ok(f) => {
                        r.iterations = Some(f.report.iterations);
                        r.evaluations = Some(f.report.evaluations);
                        r.max_error = Some(f.report.max_abs_error);
                        r.rms_error = Some(f.report.rms_error);
                        r.condition_number = Some(f.report.condition_number);
                    }
                    Err(e) => r.failure = Some(e.to_string()),
                }
                rows.push(r);
            }
        }
    }
    rows
}

fn objectives(solver: LsqSolver) -> Vec<Objective> {
    match solver {
        LsqSolver::Lm => vec![Objective::Lsq, Objective::Minimax, Objective::L4],
        LsqSolver::GaussNewton => vec![Objective::Lsq],
    }
}
