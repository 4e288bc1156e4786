//! Minimax polish by sequential linear programming with a trust region, as an argmin
//! [`Solver`] (argmin has no minimax solver).
//!
//! At θ with residuals r and Jacobian J, the linearised problem
//!
//!   min t   subject to   −t ≤ r_i + J_i δ ≤ t,   |δ_j| ≤ ρ·s_j
//!
//! is a small LP (solved with `microlp`). The step is accepted when the true max|r| falls by at
//! least a tenth of the predicted fall; ρ grows after good steps and shrinks after bad ones.
//! Near a strongly unique minimax point (equioscillation) the iteration converges
//! quadratically; it stops when the predicted fall is below 1e-15 relative or ρ underflows.

use argmin::core::{Error, IterState, Jacobian, Operator, Problem, Solver, State, TerminationReason, TerminationStatus, KV};
use microlp::{ComparisonOp, OptimizationDirection, Problem as Lp};
use nalgebra::{DMatrix, DVector};

type St = IterState<DVector<f64>, (), DMatrix<f64>, (), DVector<f64>, f64>;

/// Sequential-LP minimax solver.
#[derive(Debug, Clone)]
pub struct SlpMinimax {
    rho: f64,
    converged: bool,
}

impl Default for SlpMinimax {
    fn default() -> Self {
        SlpMinimax { rho: 1e-2, converged: false }
    }
}

fn max_abs(r: &DVector<f64>) -> f64 {
    r.iter().fold(0.0_f64, |m, v| if v.is_nan() { f64::INFINITY } else { m.max(v.abs()) })
}

/// Samples in the LP: all of them up to [`FULL_LP`]; above, the `max(8·params, FULL_LP / 2)`
/// largest |r_i|. The minimax optimum is decided by its extremal samples, and every candidate
/// step is still judged on all samples (a sample left out that would become the largest makes
/// the step fail the ratio test and shrink), so this changes the cost, not the answer: the
/// simplex work grows faster than linearly in the rows.
const FULL_LP: usize = 512;

fn working_set(r: &DVector<f64>, n_params: usize) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..r.len()).collect();
    if r.len() <= FULL_LP {
        return idx;
    }
    let k = (8 * n_params).max(FULL_LP / 2).min(r.len());
    // Largest |r| first; ties by index, so the set is deterministic.
    idx.sort_by(|&a, &b| r[b].abs().total_cmp(&r[a].abs()).then(a.cmp(&b)));
    idx.truncate(k);
    idx.sort_unstable();
    idx
}

/// Solve the linearised LP on the samples `rows`; returns (δ, predicted max).
fn lp_step(r: &DVector<f64>, j: &DMatrix<f64>, bounds: &[f64], rows: &[usize]) -> Option<(DVector<f64>, f64)> {
    let mut lp = Lp::new(OptimizationDirection::Minimize);
    let deltas: Vec<_> = bounds.iter().map(|&b| lp.add_var(0.0, (-b, b))).collect();
    let t = lp.add_var(1.0, (0.0, f64::INFINITY));
    for &i in rows {
        let row: Vec<(microlp::Variable, f64)> =
            deltas.iter().enumerate().map(|(k, &d)| (d, j[(i, k)])).filter(|(_, v)| *v != 0.0).collect();
        let mut upper = row.clone();
        upper.push((t, -1.0));
        lp.add_constraint(&upper, ComparisonOp::Le, -r[i]);
        let mut lower: Vec<_> = row.iter().map(|&(d, v)| (d, -v)).collect();
        lower.push((t, -1.0));
        lp.add_constraint(&lower, ComparisonOp::Le, r[i]);
    }
    let outcome = lp.solve().ok()?;
    let sol = outcome.solution()?;
    let delta = DVector::from_iterator(deltas.len(), deltas.iter().map(|&d| sol[d]));
    Some((delta, sol[t]))
}

impl<O> Solver<O, St> for SlpMinimax
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>> + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn name(&self) -> &str {
        "SLP minimax"
    }

    fn init(&mut self, problem: &mut Problem<O>, mut state: St) -> Result<(St, Option<KV>), Error> {
        let p = state.take_param().ok_or_else(|| Error::msg("SLP minimax needs a start"))?;
        let r = problem.apply(&p)?;
        let m = max_abs(&r);
        Ok((state.param(p).residuals(r).cost(m), None))
    }

    fn next_iter(&mut self, problem: &mut Problem<O>, state: St) -> Result<(St, Option<KV>), Error> {
        let theta = state.get_param().cloned().ok_or_else(|| Error::msg("no parameter"))?;
        let r = problem.apply(&theta)?;
        let m = max_abs(&r);
        let j = problem.jacobian(&theta)?;
        let norm = theta.iter().fold(0.0_f64, |a, v| a.max(v.abs())).max(1e-12);
        let scale: Vec<f64> = theta.iter().map(|v| v.abs().max(1e-3 * norm)).collect();
        let rows = working_set(&r, theta.len());
        for _ in 0..40 {
            let bounds: Vec<f64> = scale.iter().map(|s| self.rho * s).collect();
            let Some((delta, predicted)) = lp_step(&r, &j, &bounds, &rows) else {
                self.rho *= 0.25;
                continue;
            };
            let pred = m - predicted;
            if pred <= 1e-15 * m {
                self.converged = true;
                return Ok((state.param(theta).cost(m), None));
            }
            let cand = &theta + &delta;
            let rc = problem.apply(&cand)?;
            let mc = max_abs(&rc);
            let ratio = (m - mc) / pred;
            if ratio > 0.1 {
                let at_bound = delta.iter().zip(&bounds).any(|(d, b)| d.abs() >= 0.99 * b);
                if ratio > 0.75 && at_bound {
                    self.rho = (self.rho * 2.0).min(1.0);
                }
                return Ok((state.param(cand).residuals(rc).cost(mc), None));
            }
            self.rho *= 0.25;
            if self.rho < 1e-15 {
                break;
            }
        }
        self.converged = true;
        Ok((state.param(theta).cost(m), None))
    }

    fn terminate(&mut self, _state: &St) -> TerminationStatus {
        if self.converged {
            TerminationStatus::Terminated(TerminationReason::SolverConverged)
        } else {
            TerminationStatus::NotTerminated
        }
    }
}
