//! The re-weighted objectives: Lawson's minimax with its sequential-LP polish, and Σr⁴
//! (module doc of `super`, items 3 and 4).

use super::*;

pub(super) fn l4(
    problem: &mut Residuals<'_>,
    opts: &FitOptions,
    what: &str,
) -> Result<(DVector<f64>, usize, usize), FitError> {
    // From the least-squares optimum, LM on s_i = r_i·|r_i| minimises Σ r⁴ directly.
    let (_, it0, ev0) = least_squares(problem, opts.solver, what)?;
    problem.fourth_power = true;
    let result = least_squares(problem, opts.solver, what);
    problem.fourth_power = false;
    let (theta, it, ev) = result?;
    Ok((theta, it0 + it, ev0 + ev))
}

pub(super) fn minimax(
    problem: &mut Residuals<'_>,
    opts: &FitOptions,
    what: &str,
) -> Result<(DVector<f64>, usize, usize), FitError> {
    // Start from the least-squares optimum.
    let (mut theta, mut iters, mut evals) = least_squares(problem, opts.solver, what)?;
    let max_abs = |p: &Residuals<'_>, t: &DVector<f64>| {
        p.raw(t).iter().fold(0.0_f64, |m, v| if v.is_nan() { f64::INFINITY } else { m.max(v.abs()) })
    };
    let n = problem.y.len();
    let rms = |p: &Residuals<'_>, t: &DVector<f64>| (p.raw(t).norm_squared() / n as f64).sqrt();
    let admissible = |p: &Residuals<'_>, t: &DVector<f64>| opts.max_rms.is_none_or(|cap| rms(p, t) <= cap);
    let mut w = vec![1.0 / n as f64; n];
    let mut best = (max_abs(problem, &theta), theta.clone());
    let mut since_best = 0;
    for _ in 0..opts.minimax_iters {
        let r = problem.raw(&theta);
        let mut sum = 0.0;
        for (wi, ri) in w.iter_mut().zip(r.iter()) {
            *wi *= ri.abs();
            sum += *wi;
        }
        if !(sum > 0.0) || !sum.is_finite() {
            break;
        }
        w.iter_mut().for_each(|wi| *wi /= sum);
        // Keep every sample in play: a floor far below any weight that matters.
        w.iter_mut().for_each(|wi| *wi = wi.max(1e-14 / n as f64));
        problem.set_weights(&w);
        problem.theta.copy_from(&theta);
        let (t, it, ev) = match least_squares(problem, opts.solver, what) {
            Ok(v) => v,
            Err(_) => break,
        };
        iters += it;
        evals += ev;
        theta = t;
        let m = max_abs(problem, &theta);
        if m < best.0 * (1.0 - 1e-9) && admissible(problem, &theta) {
            best = (m, theta.clone());
            since_best = 0;
        } else {
            since_best += 1;
            if since_best >= 25 {
                break;
            }
        }
    }
    let mut theta = best.1.clone();
    problem.sqrt_w.iter_mut().for_each(|w| *w = 1.0);
    if opts.polish_iters > 0 && opts.max_rms.is_none() {
        // Sequential-LP polish (an argmin Solver of ours): converges to the equioscillating
        // optimum that Lawson's iteration only approaches linearly.
        let res = Executor::new(problem.clone(), SlpMinimax::default())
            .configure(|s| s.param(theta.clone()).max_iters(opts.polish_iters))
            .run();
        if let Ok(res) = res {
            let st = res.state();
            if let Some(p) = st.get_best_param()
                && st.get_best_cost() < best.0
            {
                theta = p.clone();
            }
            evals += st.get_iter() as usize;
        }
    }
    problem.theta.copy_from(&theta);
    Ok((theta, iters, evals))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimax fit's report counts the polish among its evaluations, one per iteration of the
    /// sequential-LP solver, and not among its iterations (Lawson's least-squares solves): the
    /// fit with the polish reports the evaluations of the fit without it (the same Lawson
    /// iterates, which do not depend on the polish) plus the iterations of the polish run again
    /// here on its own from Lawson's best iterate.
    #[test]
    fn a_minimax_fit_counts_the_polish_among_its_evaluations() {
        let model = RationalModel::rational_1d("x", 2, 1);
        let x: Vec<Vec<f64>> = (0..=30).map(|i| vec![i as f64 / 10.0]).collect();
        let data = Data { y: x.iter().map(|p| (0.7 * p[0]).exp()).collect(), x };
        let minimax = |polish_iters| FitOptions { objective: Objective::Minimax, polish_iters, ..FitOptions::default() };
        let lawson = fit(&model, &data, &minimax(0), "exp").unwrap();
        let polished = fit(&model, &data, &minimax(200), "exp").unwrap();
        let run = Executor::new(Residuals::new(&model, &data, lawson.theta.clone()), SlpMinimax::default())
            .configure(|s| s.param(lawson.theta.clone()).max_iters(200))
            .run()
            .unwrap();
        let k = run.state().get_iter() as usize;
        assert!(k >= 2 && lawson.report.evaluations > 2, "{k} polish iterations after {} evaluations", lawson.report.evaluations);
        assert_eq!(polished.report.iterations, lawson.report.iterations);
        assert_eq!(polished.report.evaluations, lawson.report.evaluations + k);
    }

    /// Lawson keeps the best iterate and stops 25 iterations after the last one that lowered
    /// the max error by more than 1e-9 of it. A constant fitted to y = ±1 alternating on 10
    /// points: the least-squares optimum is 0 exactly, every residual has |r| = 1, so every
    /// weighting is uniform and every weighted solve returns 0, max error 1: no iterate
    /// improves, and exactly 25 weighted solves follow the first. Each is LM from the optimum
    /// with uniform weights, counted here by running one; the report adds them all up.
    #[test]
    fn lawson_stops_25_iterations_after_its_last_improvement() {
        let model = RationalModel::rational_1d("x", 0, 0);
        let x: Vec<Vec<f64>> = (0..10).map(|i| vec![i as f64]).collect();
        let data = Data { y: (0..10).map(|i| if i % 2 == 0 { 1.0 } else { -1.0 }).collect(), x };
        let zero = DVector::from_element(1, 0.0);
        let opts = FitOptions { objective: Objective::Minimax, polish_iters: 0, ..FitOptions::default() };
        let mut p = Residuals::new(&model, &data, zero.clone());
        let (theta, iters, evals) = minimax(&mut p, &opts, "alternating").unwrap();
        assert_eq!(theta, zero);
        let mut q = Residuals::new(&model, &data, zero.clone());
        let (t0, it0, ev0) = least_squares(&mut q, LsqSolver::Lm, "alternating").unwrap();
        q.set_weights(&[0.1; 10]);
        let (t1, it1, ev1) = least_squares(&mut q, LsqSolver::Lm, "alternating").unwrap();
        assert_eq!((t0, t1), (zero.clone(), zero), "the optimum is 0 for every weighting");
        assert!(it1 >= 1 && ev1 >= 1);
        assert_eq!((iters, evals), (it0 + 25 * it1, ev0 + 25 * ev1));
    }

    /// An L4 fit is a least-squares solve followed by a solve of Σr⁴ from its optimum: it
    /// reports both stages' iterations and evaluations, each stage re-run here on its own, and
    /// its Σr⁴ is no higher than the least-squares optimum's.
    #[test]
    fn an_l4_fit_counts_both_stages() {
        let model = RationalModel::rational_1d("x", 2, 1);
        let x: Vec<Vec<f64>> = (0..=30).map(|i| vec![i as f64 / 10.0]).collect();
        let data = Data { y: x.iter().map(|p| (0.7 * p[0]).exp()).collect(), x };
        for solver in [LsqSolver::Lm, LsqSolver::GaussNewton] {
            let start = linearised_starts(&model, &data, "exp").unwrap().remove(0);
            let opts = FitOptions { objective: Objective::L4, solver, ..FitOptions::default() };
            let mut p = Residuals::new(&model, &data, start.clone());
            let (t4, iters, evals) = l4(&mut p, &opts, "exp").unwrap();
            let mut q = Residuals::new(&model, &data, start);
            let (t2, it0, ev0) = least_squares(&mut q, solver, "exp").unwrap();
            q.fourth_power = true;
            let (_, it, ev) = least_squares(&mut q, solver, "exp").unwrap();
            assert!(it0 >= 2 && it >= 2, "{solver:?}: stages of {it0} and {it} iterations");
            assert_eq!((iters, evals), (it0 + it, ev0 + ev), "{solver:?}");
            let s4 = |t: &DVector<f64>| p.raw(t).iter().map(|r| r.powi(4)).sum::<f64>();
            assert!(s4(&t4) <= s4(&t2), "{solver:?}: Σr⁴ {} vs least squares {}", s4(&t4), s4(&t2));
        }
    }
}
