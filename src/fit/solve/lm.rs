//! Least squares by Levenberg–Marquardt, watched for stalls (module doc of `super`, item 2).

use super::*;

/// The LM settings of every least-squares solve here.
pub(super) fn lm_solver() -> LevenbergMarquardt<f64> {
    LevenbergMarquardt::new().with_ftol(1e-15).with_xtol(1e-15).with_gtol(0.0).with_patience(LM_PATIENCE)
}

/// LM's evaluation cap is `LM_PATIENCE · (free parameters + 1)`.
pub(super) const LM_PATIENCE: usize = 400;

/// When a watched LM run counts as stalled: at an accepted step, its rss fell by Δ over the
/// last ≥ `WINDOW` evaluations, and at that rate the evaluations left before LM's cap would
/// lower it by less than `SHARE` of itself. The run is then stopped with `lower` = `REACH`·rss
/// as the least rss the full run is taken to reach, and [`fit`] runs it again in full unless a
/// finished valid start beats even that. A crawl can end (the bench's gloss_combine_3_2: a
/// start stopped under a 1e-3 share at 50 evaluations with its lower bound at 0.999 rss went
/// on to win), hence the strict share and the wide reach.
pub(super) struct Stall;

impl Stall {
    const WINDOW: usize = 200;
    const SHARE: f64 = 1e-6;
    const REACH: f64 = 0.1;
}

/// A [`Residuals`] problem that counts LM's evaluations and stops the run (its Jacobian
/// reports "none", which ends LM at the last accepted point) once it has [`Stall`]ed.
pub(super) struct Watched<'a> {
    inner: Residuals<'a>,
    max_evals: usize,
    evals: std::cell::Cell<usize>,
    /// rss of the last evaluation.
    last: std::cell::Cell<f64>,
    /// (evaluations, rss) at every accepted step.
    history: std::cell::RefCell<Vec<(usize, f64)>>,
    stalled: std::cell::Cell<Option<f64>>,
}

impl<'a> Watched<'a> {
    /// A fresh watch over `inner`, its cap that of the LM run it watches.
    fn new(inner: Residuals<'a>) -> Self {
        Watched {
            max_evals: LM_PATIENCE * (inner.theta.len() + 1),
            inner,
            evals: std::cell::Cell::new(0),
            last: std::cell::Cell::new(f64::NAN),
            history: std::cell::RefCell::new(Vec::new()),
            stalled: std::cell::Cell::new(None),
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Watched<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.inner.set_params(x);
    }
    fn params(&self) -> DVector<f64> {
        self.inner.params()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.inner.residuals();
        self.evals.set(self.evals.get() + 1);
        if let Some(r) = &r {
            self.last.set(r.norm_squared());
        }
        r
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        // LM asks for the Jacobian at each accepted point, right after evaluating it.
        let (n, rss) = (self.evals.get(), self.last.get());
        let mut history = self.history.borrow_mut();
        if let Some(&(n0, rss0)) = history.iter().rev().find(|&&(n0, _)| n0 + Stall::WINDOW <= n) {
            let rate = (rss0 - rss) / (n - n0) as f64;
            let left = self.max_evals.saturating_sub(n) as f64;
            if rate * left < Stall::SHARE * rss {
                self.stalled.set(Some(rss * Stall::REACH));
                return None;
            }
        }
        history.push((n, rss));
        self.inner.jacobian()
    }
}

/// LM from `problem.theta` as [`least_squares`] does, watched for a [`Stall`]: (θ,
/// evaluations, `Some(lower)` when stopped). Unstalled, the same bits as [`least_squares`].
pub(super) fn least_squares_watched(problem: &mut Residuals<'_>, what: &str) -> Result<(DVector<f64>, usize, Option<f64>), FitError> {
    let (w, report) = lm_solver().minimize(Watched::new(problem.clone()));
    let theta = finite_lm_result(w.inner.theta.clone(), &report, what)?;
    problem.theta.copy_from(&theta);
    Ok((theta, report.number_of_evaluations, w.stalled.get()))
}

/// An LM run's parameters, or `Diverged` when any is not finite.
pub(super) fn finite_lm_result(theta: DVector<f64>, report: &levenberg_marquardt::MinimizationReport<f64>, what: &str) -> Result<DVector<f64>, FitError> {
    if theta.iter().all(|v| v.is_finite()) {
        Ok(theta)
    } else {
        Err(FitError::Diverged { what: what.into(), iters: report.number_of_evaluations, residual: report.objective_function })
    }
}

pub(super) fn least_squares(
    problem: &mut Residuals<'_>,
    solver: LsqSolver,
    what: &str,
) -> Result<(DVector<f64>, usize, usize), FitError> {
    match solver {
        LsqSolver::Lm => {
            let (p, report) = lm_solver().minimize(problem.clone());
            let theta = finite_lm_result(p.theta.clone(), &report, what)?;
            problem.theta.copy_from(&theta);
            Ok((theta, report.number_of_evaluations, report.number_of_evaluations))
        }
        LsqSolver::GaussNewton => {
            use argmin::solver::gaussnewton::GaussNewton;
            // Plain Gauss–Newton, not argmin's GaussNewtonLS: that runs its line search with no
            // iteration cap, and from a start whose normal equations are singular (a NaN step)
            // neither More–Thuente nor backtracking ever returns (seen on fits/fuzz_g.toml's
            // multi-start). A full step per iteration, capped at 200 iterations, always ends;
            // a diverged result is caught below.
            let gn = GaussNewton::new();
            let res = Executor::new(problem.clone(), gn)
                .configure(|s| s.param(problem.theta.clone()).max_iters(200))
                .run()
                .map_err(|e| FitError::Solver { what: what.into(), msg: e.to_string() })?;
            let st = res.state();
            let theta = st.get_best_param().cloned().unwrap_or_else(|| problem.theta.clone());
            let iters = st.get_iter() as usize;
            if !theta.iter().all(|v| v.is_finite()) {
                return Err(FitError::Diverged { what: what.into(), iters, residual: st.get_best_cost() });
            }
            problem.theta.copy_from(&theta);
            Ok((theta, iters, iters))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::*;
    use super::*;

    /// The stall rule as documented on [`Stall`], decided at one accepted step: n = 300
    /// evaluations, rss 1, LM's cap 1300 (1000 left), the last entry ≥ WINDOW back at n0 = 0
    /// with rss 1 + δ. At the rate δ/300 the evaluations left lower the rss by δ·1000/300, so
    /// it stalls exactly when δ < 3e-7 (SHARE·rss·300/1000); an entry less than WINDOW back
    /// is not a measure of progress, however large its fall, and one exactly WINDOW back is.
    #[test]
    fn a_watched_run_stalls_where_its_rate_cannot_reach_a_share_of_its_rss() {
        let model = RationalModel::rational_1d("x", 1, 0);
        let x: Vec<Vec<f64>> = (0..4).map(|i| vec![i as f64]).collect();
        let data = Data { y: x.iter().map(|p| 1.0 + p[0]).collect(), x };
        let at = |history: Vec<(usize, f64)>, rss: f64, max_evals: usize| {
            let w = Watched {
                inner: Residuals::new(&model, &data, DVector::from_vec(vec![0.5, 0.5])),
                max_evals,
                evals: std::cell::Cell::new(300),
                last: std::cell::Cell::new(rss),
                history: std::cell::RefCell::new(history),
                stalled: std::cell::Cell::new(None),
            };
            let jacobian = w.jacobian();
            (jacobian.is_none(), w.stalled.get(), w.history.borrow().len())
        };
        let step = |history| at(history, 1.0, 1300);
        // Stopped: no Jacobian, REACH·rss as the lower bound, the step not recorded.
        assert_eq!(step(vec![(0, 1.0 + 2.9e-7)]), (true, Some(0.1), 1));
        assert_eq!(step(vec![(0, 1.0 + 3.1e-7)]), (false, None, 2));
        assert_eq!(step(vec![(0, 1.0 + 2.9e-7), (150, 1e9)]), (true, Some(0.1), 2));
        assert_eq!(step(vec![(150, 1.0)]), (false, None, 2));
        // An entry exactly WINDOW back (n0 = 100) is a measure: over 200 evaluations the
        // threshold is δ < 2e-7 (SHARE·rss·200/1000).
        assert_eq!(step(vec![(100, 1.0 + 1.9e-7)]), (true, Some(0.1), 1));
        assert_eq!(step(vec![(100, 1.0 + 2.1e-7)]), (false, None, 2));
        // "Less than" a share, strictly: rss 1e6 (SHARE·rss is 1 exactly in f64), a fall of 1
        // over 256 evaluations and 256 left reaches exactly that share (all powers of two and
        // 1e6 ± 1: exact), so the run goes on.
        assert_eq!(Stall::SHARE * 1e6, 1.0);
        assert_eq!(at(vec![(44, 1e6 + 1.0)], 1e6, 556), (false, None, 2));
        assert_eq!(at(vec![(44, 1e6 + 1.0 - 2f64.powi(-20))], 1e6, 556), (true, Some(1e5), 1));
    }

    /// The watch's cap is the LM run's own: an unwatched run that ends for lack of patience
    /// (levenberg-marquardt's `LostPatience`, after exactly patience · (n + 1) evaluations)
    /// has taken as many evaluations as `Watched::new` allows it, so the evaluations "left"
    /// in the stall rule are those the run really has. The unit step of the test above, whose
    /// crawling starts include ones that run out of patience.
    #[test]
    fn the_watchs_cap_is_the_lm_runs_own() {
        let data = unit_step();
        let mut out_of_patience = 0;
        for (m, n) in [(2, 3), (3, 3)] {
            let model = RationalModel::rational_1d("x", m, n);
            for start in linearised_starts(&model, &data, "step").unwrap() {
                let problem = Residuals::new(&model, &data, start);
                let cap = Watched::new(problem.clone()).max_evals;
                let (_, report) = lm_solver().minimize(problem);
                if matches!(report.termination, levenberg_marquardt::TerminationReason::LostPatience) {
                    assert_eq!(report.number_of_evaluations, cap, "[{m}/{n}]");
                    out_of_patience += 1;
                } else {
                    assert!(report.number_of_evaluations < cap, "[{m}/{n}]: {:?}", report.termination);
                }
            }
        }
        assert!(out_of_patience >= 1, "no start ran out of patience: the test does not measure the cap");
    }

    /// An LM run's parameters come back only when every one is finite; one NaN or infinite
    /// parameter among finite ones is a divergence, reported with the run's evaluations and
    /// its last objective.
    #[test]
    fn a_non_finite_lm_result_is_a_divergence() {
        let report = |objective_function: f64| levenberg_marquardt::MinimizationReport {
            termination: levenberg_marquardt::TerminationReason::Converged { ftol: true, xtol: false },
            number_of_evaluations: 17,
            objective_function,
        };
        let ok = DVector::from_vec(vec![1.0, -2.0, 0.0]);
        assert_eq!(finite_lm_result(ok.clone(), &report(0.5), "ok").unwrap(), ok);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            match finite_lm_result(DVector::from_vec(vec![1.0, bad, 0.0]), &report(3.0), "run") {
                Err(FitError::Diverged { what, iters, residual }) => assert_eq!((what.as_str(), iters, residual), ("run", 17, 3.0)),
                other => panic!("{bad}: {other:?}"),
            }
        }
    }
}
