//! Fit reports: every fit comes back with its errors, worst point and conditioning.

use super::problem::{Data, Residuals};
use super::solve::{FitOptions, Objective};
use nalgebra::DVector;
use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    pub objective: Objective,
    pub samples: usize,
    /// Residual sum of squares on the fitting samples.
    pub rss: f64,
    pub max_abs_error: f64,
    pub rms_error: f64,
    /// Max |residual| / |y| over samples with y ≠ 0.
    pub max_rel_error: f64,
    pub worst_point: Vec<f64>,
    pub worst_residual: f64,
    /// σ_max/σ_min of the Jacobian in the free parameters at the solution.
    pub condition_number: f64,
    pub iterations: usize,
    pub evaluations: usize,
}

impl FitReport {
    pub fn measure(
        problem: &Residuals<'_>,
        data: &Data,
        theta: &DVector<f64>,
        opts: &FitOptions,
        iterations: usize,
        evaluations: usize,
    ) -> FitReport {
        let r = problem.raw(theta);
        let n = r.len();
        let rss = r.norm_squared();
        let (worst, worst_residual) = r
            .iter()
            .enumerate()
            .fold((0, 0.0_f64), |(wi, wv), (i, &v)| if v.abs() > wv.abs() || v.is_nan() { (i, v) } else { (wi, wv) });
        let max_rel_error = r
            .iter()
            .zip(problem.y)
            .filter(|(_, y)| **y != 0.0)
            .map(|(r, y)| (r / y).abs())
            .fold(0.0, f64::max);
        let j = problem.jacobian_at(theta);
        // nalgebra's SVD can loop forever on non-finite entries: check first, and cap the
        // iterations (no convergence ⇒ report an infinite condition number).
        let sv = if j.iter().all(|v| v.is_finite()) {
            j.try_svd(false, false, f64::EPSILON, 10_000).map(|s| s.singular_values)
        } else {
            None
        };
        let (smax, smin) = match &sv {
            Some(sv) => (sv.iter().cloned().fold(0.0, f64::max), sv.iter().cloned().fold(f64::INFINITY, f64::min)),
            None => (f64::INFINITY, 0.0),
        };
        FitReport {
            objective: opts.objective,
            samples: n,
            rss,
            max_abs_error: worst_residual.abs(),
            rms_error: (rss / n as f64).sqrt(),
            max_rel_error,
            worst_point: data.x.get(worst).cloned().unwrap_or_default(),
            worst_residual,
            condition_number: if smin > 0.0 { smax / smin } else { f64::INFINITY },
            iterations,
            evaluations,
        }
    }
}
