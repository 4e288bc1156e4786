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
    /// The first sample of the largest |residual| (the first NaN residual, if any), and its
    /// residual.
    pub worst_point: Vec<f64>,
    pub worst_residual: f64,
    /// σ_max/σ_min of the Jacobian in the free parameters at the solution (∞ when σ_min is 0,
    /// a Jacobian of zeros included).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::model::RationalModel;

    /// Every figure of a report, by hand: c₀ + c₁x at θ = (1, 1) on x = 0…4 against
    /// y = (1, 2, 5, 12, 0) leaves r = f − y = (0, 0, −2, −8, 5): Σr² = 93, rms √(93/5), the
    /// worst residual −8 (its sign kept) at x = 3, max |r/y| = 8/12 over the samples with
    /// y ≠ 0; J = [1, x] gives JᵀJ = [[5, 10], [10, 30]], eigenvalues (35 ± √1025)/2, so
    /// σmax/σmin = √((35 + √1025)/(35 − √1025)). A NaN residual is the worst.
    #[test]
    fn a_report_holds_the_figures_of_its_residuals() {
        let model = RationalModel::rational_1d("x", 1, 0);
        let data = Data { x: (0..5).map(|i| vec![i as f64]).collect(), y: vec![1.0, 2.0, 5.0, 12.0, 0.0] };
        let theta = DVector::from_vec(vec![1.0, 1.0]);
        let p = Residuals::new(&model, &data, theta.clone());
        let opts = FitOptions::default();
        let r = FitReport::measure(&p, &data, &theta, &opts, 7, 11);
        assert_eq!((r.objective, r.samples, r.iterations, r.evaluations), (opts.objective, 5, 7, 11));
        assert_eq!((r.rss, r.max_abs_error, r.worst_residual, r.worst_point.clone()), (93.0, 8.0, -8.0, vec![3.0]));
        assert_eq!(r.rms_error, (93.0f64 / 5.0).sqrt());
        assert_eq!(r.max_rel_error, 8.0 / 12.0);
        let s = 1025f64.sqrt();
        // Two ways to a condition number ~12: agreement to ~1e-14 relative.
        let cond = ((35.0 + s) / (35.0 - s)).sqrt();
        assert!((r.condition_number - cond).abs() <= 1e-12 * cond, "{} vs {cond}", r.condition_number);
        let nan = Data { y: vec![1.0, f64::NAN, 5.0, 12.0, 0.0], ..data.clone() };
        let p = Residuals::new(&model, &nan, theta.clone());
        let r = FitReport::measure(&p, &nan, &theta, &opts, 0, 0);
        assert!(r.worst_residual.is_nan() && r.max_abs_error.is_nan() && r.worst_point == vec![1.0], "{r:?}");
    }

    /// Two residuals of the largest size, 8 and −8 (r = f − y with f = 1 + x on x = 0…4 and
    /// y = (1, −6, 5, 12, 0): r = (0, 8, −2, −8, 5)): the worst is the first, at x = 1. A model
    /// c·x on samples at x = 0 has a Jacobian of zeros (every σ is 0): its condition is ∞.
    #[test]
    fn the_worst_point_is_the_first_of_a_tie_and_a_zero_jacobian_is_infinitely_conditioned() {
        let model = RationalModel::rational_1d("x", 1, 0);
        let data = Data { x: (0..5).map(|i| vec![i as f64]).collect(), y: vec![1.0, -6.0, 5.0, 12.0, 0.0] };
        let theta = DVector::from_vec(vec![1.0, 1.0]);
        let r = FitReport::measure(&Residuals::new(&model, &data, theta.clone()), &data, &theta, &FitOptions::default(), 0, 0);
        assert_eq!((r.worst_point.clone(), r.worst_residual), (vec![1.0], 8.0));
        let f = vec!["x".to_string()];
        let cx = RationalModel::new(crate::fit::model::ModelParts {
            inputs: f.clone(),
            numerator: vec![crate::fit::model::Term::parse("x", &f).unwrap()],
            ..Default::default()
        })
        .unwrap();
        let at0 = Data { x: vec![vec![0.0], vec![0.0]], y: vec![1.0, 2.0] };
        let theta = DVector::from_vec(vec![3.0]);
        let r = FitReport::measure(&Residuals::new(&cx, &at0, theta.clone()), &at0, &theta, &FitOptions::default(), 0, 0);
        assert_eq!(r.condition_number, f64::INFINITY);
    }
}
