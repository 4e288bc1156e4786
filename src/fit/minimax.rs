//! Minimax polish by sequential linear programming with a trust region, as an argmin
//! [`Solver`] (argmin has no minimax solver).
//!
//! At θ with residuals r and Jacobian J, the linearised problem
//!
//!   min t   subject to   −t ≤ r_i + J_i δ ≤ t,   |δ_j| ≤ ρ·s_j
//!
//! is a small LP (solved with `microlp`). The step is accepted when the true max|r| falls by more
//! than a tenth of the predicted fall; ρ doubles (up to 1) after a step at the region's edge
//! whose fall is more than 3/4 of the prediction, and shrinks by 4 after a refused one.
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

/// Solve the linearised LP on the samples `rows`; returns δ and the linearised max at δ,
/// max_i |r_i + J_i δ| over `rows` (evaluated here in f64, not taken from the LP, whose
/// constraints hold only to its absolute feasibility tolerance).
///
/// The LP is posed in units where all its data are of order one, since the solver's
/// tolerances are absolute (1e-7) and its pivoting assumes entries within ~1e6 of each other:
/// - the step relative to its bound, u_j = δ_j / b_j ∈ [−1, 1] (columns a_ij = J_ij·b_j);
/// - the max as t = m + S·σ, m = max |r_i| and S = max_i Σ_j |a_ij| the largest change of a
///   row within the trust region; rows are divided by S. σ ≥ −m/S (t ≥ 0) and the objective
///   is σ.
///
/// Exact reductions, which leave the LP's optimal set unchanged:
/// - a side ±(r_i + a_i·u) ≤ t with ±r_i + Σ_j |a_ij| < m − S cannot bind: the sample with
///   |r_k| = m keeps t ≥ m − S, so it is left out;
/// - a term |a_ij| below the rounding error of evaluating its row (ε·(|r_i| + Σ_j |a_ij|))
///   cannot move the row's value in f64 and is left out. Such terms are rounding residues of a
///   feature that is exactly zero in the model (cos θ at θ = π/2 is 6e-17, its cube 2e-49):
///   kept, they make rows span 1e49 and most LPs then fail (a stalled or cycling dual simplex
///   after thousands of pivots), each failure shrinking the trust region.
fn lp_step(r: &DVector<f64>, j: &DMatrix<f64>, bounds: &[f64], rows: &[usize]) -> Option<(DVector<f64>, f64)> {
    let r_rows: Vec<f64> = rows.iter().map(|&i| r[i]).collect();
    let m = r_rows.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let a: Vec<Vec<(usize, f64)>> = rows
        .iter()
        .zip(&r_rows)
        .map(|(&i, ri)| {
            let row: Vec<(usize, f64)> = bounds.iter().enumerate().map(|(k, &b)| (k, j[(i, k)] * b)).filter(|(_, v)| *v != 0.0).collect();
            let size = ri.abs() + row.iter().map(|(_, v)| v.abs()).sum::<f64>();
            row.into_iter().filter(|(_, v)| v.abs() > f64::EPSILON * size).collect()
        })
        .collect();
    let reach: Vec<f64> = a.iter().map(|row| row.iter().map(|(_, v)| v.abs()).sum()).collect();
    let s = reach.iter().fold(0.0_f64, |x, &v| x.max(v));
    if !(s > 0.0 && s.is_finite() && m.is_finite()) {
        return None;
    }
    let mut lp = Lp::new(OptimizationDirection::Minimize);
    let units: Vec<_> = bounds.iter().map(|_| lp.add_var(0.0, (-1.0, 1.0))).collect();
    let sigma = lp.add_var(1.0, (-m / s, f64::INFINITY));
    for (k, sign) in sides_that_can_bind(&r_rows, &reach, m, s) {
        let mut c: Vec<(microlp::Variable, f64)> = a[k].iter().map(|&(col, v)| (units[col], sign * v / s)).collect();
        c.push((sigma, -1.0));
        lp.add_constraint(&c, ComparisonOp::Le, (m - sign * r_rows[k]) / s);
    }
    let outcome = lp.solve().ok()?;
    let sol = outcome.solution()?;
    let delta = DVector::from_iterator(units.len(), units.iter().zip(bounds).map(|(&u, &b)| sol[u].clamp(-1.0, 1.0) * b));
    let linearised = rows.iter().fold(0.0_f64, |x, &i| x.max((r[i] + j.row(i).dot(&delta.transpose())).abs()));
    Some((delta, linearised))
}

/// The sides ±(r_k + a_k·u) ≤ t of the LP that can bind, as (row, sign) in row order, + before
/// −: a side with ±r_k + reach_k < m − S is left out ([`lp_step`]'s first reduction), where
/// reach_k = Σ_j |a_kj|, m = max |r_k| and S = max reach_k.
fn sides_that_can_bind(r: &[f64], reach: &[f64], m: f64, s: f64) -> Vec<(usize, f64)> {
    let mut sides = Vec::with_capacity(2 * r.len());
    for (k, (&rk, &reach)) in r.iter().zip(reach).enumerate() {
        for sign in [1.0, -1.0] {
            if sign * rk + reach >= m - s {
                sides.push((k, sign));
            }
        }
    }
    sides
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::model::{Derived, ModelParts, RationalModel, Term};
    use crate::fit::{fit, Data, FitOptions, Objective};

    /// The LP's samples as documented at [`FULL_LP`]: all of them up to 512; above, the
    /// max(8·params, 256) largest |r|, in index order. Residuals |r_i| = ((i·7919) mod 1000)
    /// are distinct, so "the k largest" are the indices whose value is ≥ 1000 − k.
    #[test]
    fn the_working_set_is_the_largest_residuals_by_the_documented_count() {
        let r = DVector::from_fn(1000, |i, _| ((i * 7919) % 1000) as f64 * if i % 2 == 0 { 1.0 } else { -1.0 });
        for (params, k) in [(3, 256), (32, 256), (40, 320), (200, 1000)] {
            let want: Vec<usize> = (0..1000).filter(|&i| r[i].abs() >= (1000 - k) as f64).collect();
            assert_eq!(working_set(&r, params), want, "{params} parameters");
        }
        let small = DVector::from_fn(512, |i, _| i as f64);
        assert_eq!(working_set(&small, 40), (0..512).collect::<Vec<_>>());
    }

    /// r_i = θ₀ + θ₁x_i − |x_i| on 21 points of [−1, 1]: linear in θ, minimax optimum θ =
    /// (½, 0) with max |r| = ½ (by hand: the line must split the V evenly; at θ₁ ≠ 0 one arm's
    /// end is farther). From θ = (0.01, 0.005) the first trust region is 1e-2·|θ_j| = (1e-4,
    /// 5e-5); the documented growth of ρ after good steps taken at the region's edge is what
    /// reaches the optimum within 60 iterations: held at 1e-2, the region grows only with |θ|,
    /// by 1 % an iteration, and θ₀ would need ln 50 / ln 1.01 ≈ 390 of them.
    struct Vee(Vec<f64>);

    impl Operator for Vee {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, t: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_iterator(self.0.len(), self.0.iter().map(|x| t[0] + t[1] * x - x.abs())))
        }
    }

    impl Jacobian for Vee {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, _: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_fn(self.0.len(), 2, |i, j| if j == 0 { 1.0 } else { self.0[i] }))
        }
    }

    /// The LP keeps every side that can bind and only those: with m = 1 and S = ½, a side binds
    /// at most where ±r + reach reaches m − S = ½ (all values dyadic, so every sum is exact):
    /// r = (1, −¼, ⅝, −¼), reach = (¼, ½, ⅛, ¼) give +: 1¼, ¼, ¾, 0 and −: −¾, ¾, −½, ½ (the
    /// last exactly at the bound, kept).
    #[test]
    fn the_lp_keeps_exactly_the_sides_that_can_bind() {
        let sides = sides_that_can_bind(&[1.0, -0.25, 0.625, -0.25], &[0.25, 0.5, 0.125, 0.25], 1.0, 0.5);
        assert_eq!(sides, [(0, 1.0), (1, -1.0), (2, 1.0), (3, -1.0)]);
        // Nothing within reach of the largest residual is left out: with S ≥ m every side stays.
        assert_eq!(sides_that_can_bind(&[0.5, -1.0], &[1.0, 1.0], 1.0, 1.0).len(), 4);
    }

    #[test]
    fn the_trust_region_grows_to_reach_a_far_optimum() {
        let x: Vec<f64> = (0..21).map(|i| -1.0 + i as f64 / 10.0).collect();
        let res = argmin::core::Executor::new(Vee(x), SlpMinimax::default())
            .configure(|s| s.param(DVector::from_vec(vec![0.01, 0.005])).max_iters(60))
            .run()
            .unwrap();
        let st = res.state();
        let t = st.get_best_param().unwrap();
        assert_eq!(st.get_termination_status(), &TerminationStatus::Terminated(TerminationReason::SolverConverged), "after {} iterations at {t:?}", st.get_iter());
        // A linear minimax problem: the LP step lands on the optimum to its feasibility
        // tolerance once the region holds it.
        assert!((st.get_best_cost() - 0.5).abs() < 1e-9 && (t[0] - 0.5).abs() < 1e-9 && t[1].abs() < 1e-9, "{t:?}, max {}", st.get_best_cost());
    }

    /// The LP is posed in its own units (steps relative to their bounds, rows divided by the
    /// largest reach) and its reductions are relative to each row's size (a term below
    /// ε·(|r_i| + Σ_j |a_ij|) is left out), so residuals and a Jacobian scaled by a power of two
    /// give the same step bit for bit and the linearised max scaled by it, whatever the units
    /// of the fitted quantity: every product, sum and quotient scales exactly (no overflow or
    /// subnormal at 2^±40 here). A reduction taken against an absolute size would leave out
    /// every term of the 2^-30 problem (|a_ij| ≤ 5e-11 against ε/size ≥ 2e-7).
    #[test]
    fn the_lp_step_is_the_same_in_any_units() {
        let vee = Vee((0..21).map(|i| -1.0 + i as f64 / 10.0).collect());
        let theta = DVector::from_vec(vec![0.2, 0.1]);
        let (r, j) = (vee.apply(&theta).unwrap(), vee.jacobian(&theta).unwrap());
        let bounds = [0.05, 0.02];
        let rows: Vec<usize> = (0..r.len()).collect();
        let (delta, linearised) = lp_step(&r, &j, &bounds, &rows).expect("the LP solves");
        // Not a stationary point: the step descends (θ moves toward (½, 0)).
        assert!(linearised < max_abs(&r), "{linearised} at max {}", max_abs(&r));
        for k in [-40, -30, 30, 40] {
            let c = 2f64.powi(k);
            let (d, l) = lp_step(&(&r * c), &(&j * c), &bounds, &rows).unwrap_or_else(|| panic!("the LP scaled by 2^{k} solves"));
            assert_eq!(d, delta, "step at 2^{k}");
            assert_eq!(l, linearised * c, "linearised max at 2^{k}");
        }
    }

    /// Vee's residuals with the Jacobian's sign flipped: every LP step predicts a descent the
    /// residuals answer with a climb.
    struct Misled(Vee);

    impl Operator for Misled {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, t: &DVector<f64>) -> Result<DVector<f64>, Error> {
            self.0.apply(t)
        }
    }

    impl Jacobian for Misled {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, t: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(-self.0.jacobian(t)?)
        }
    }

    /// A step is taken only when the max residual falls by more than a tenth of what the LP
    /// predicted. With a Jacobian that points the wrong way every step climbs, so the trust
    /// region shrinks until the solver gives up, where it started, its max residual unchanged.
    #[test]
    fn a_step_the_linearisation_mispredicts_is_refused() {
        let x: Vec<f64> = (0..21).map(|i| -1.0 + i as f64 / 10.0).collect();
        let start = DVector::from_vec(vec![0.01, 0.005]);
        let m0 = max_abs(&Vee(x.clone()).apply(&start).unwrap());
        let res = argmin::core::Executor::new(Misled(Vee(x)), SlpMinimax::default())
            .configure(|s| s.param(start.clone()).max_iters(20))
            .run()
            .unwrap();
        let st = res.state();
        assert_eq!(st.get_termination_status(), &TerminationStatus::Terminated(TerminationReason::SolverConverged));
        assert_eq!(st.get_param(), Some(&start), "the solver moved to {:?}", st.get_param());
        assert_eq!(st.get_cost(), m0);
        // It stops when the predicted fall is below 1e-15 of m = 0.995 (at x = −1). The bounds
        // are ρ·(0.01, 0.005) and the LP's predicted fall lies between the first and their
        // sum: 1.5e-15 to 2.2e-15 at ρ = 1e-2/4^18, 3.6e-16 to 5.5e-16 at 1e-2/4^19. So it
        // stops after 19 refusals, each dividing ρ by 4 exactly (a power of two).
        assert_eq!(res.solver().rho, 1e-2 * 0.25f64.powi(19));
    }

    /// One steep residual r = 1e6·t − (1e6 − 1), max 1 at t = 1, with the Jacobian's sign
    /// flipped: the predicted fall is ρ·1e6 of m, above 1e-15 of it down to ρ = 1e-21, so what
    /// ends the refusals is ρ itself falling below 1e-15 ("ρ underflows"): 1e-2/4^k first does
    /// at k = 22 (4^22 ≈ 1.8e13). The solver stops where it started.
    #[test]
    fn refusals_end_when_the_trust_region_underflows() {
        let steep = Toy(|t: &DVector<f64>| DVector::from_element(1, 1e6 * t[0] - (1e6 - 1.0)), |_: &DVector<f64>| DMatrix::from_element(1, 1, -1e6));
        let res = argmin::core::Executor::new(steep, SlpMinimax::default())
            .configure(|s| s.param(DVector::from_element(1, 1.0)).max_iters(5))
            .run()
            .unwrap();
        let st = res.state();
        assert_eq!(st.get_termination_status(), &TerminationStatus::Terminated(TerminationReason::SolverConverged));
        assert_eq!((st.get_param().map(|t| t[0]), st.get_cost(), st.get_iter()), (Some(1.0), 1.0, 1));
        assert_eq!(res.solver().rho, 1e-2 * 0.25f64.powi(22));
    }

    /// A residual function and its Jacobian, as closures: a test problem for the solver.
    struct Toy<F, J>(F, J);

    impl<F: Fn(&DVector<f64>) -> DVector<f64>, J> Operator for Toy<F, J> {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, t: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok((self.0)(t))
        }
    }

    impl<F, J: Fn(&DVector<f64>) -> DMatrix<f64>> Jacobian for Toy<F, J> {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, t: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok((self.1)(t))
        }
    }

    /// The Jacobian 1 of one residual.
    fn unit(_: &DVector<f64>) -> DMatrix<f64> {
        DMatrix::from_element(1, 1, 1.0)
    }

    /// One residual with a cliff: t itself from 0.5 up, 10 below (the Jacobian 1 everywhere).
    fn cliff(t: &DVector<f64>) -> DVector<f64> {
        DVector::from_element(1, if t[0] >= 0.5 { t[0] } else { 10.0 })
    }

    /// A refused step shrinks the trust region by 4 and the step is tried again within one
    /// iteration. From t = 1 with the region at 1 (its bound ρ·|t| = 1), the LP steps to 0,
    /// over the cliff (max 10 against the predicted 0): refused. Within ρ = 1/4 it steps to
    /// 0.75 exactly, the max falling as predicted: taken, at the bound with a ratio above 3/4,
    /// so the region doubles to 1/2.
    #[test]
    fn a_refused_step_is_retried_in_a_smaller_region() {
        let (t, cost, rho) = one_iteration(cliff, 1.0, 1.0);
        assert_eq!((t, cost), (0.75, 0.75));
        assert_eq!(rho, 0.5);
    }

    /// One iteration of the solver on one residual `r` (Jacobian 1) from t = `t0` with ρ =
    /// `rho`: (t, max |r|, ρ) after it.
    fn one_iteration(r: impl Fn(&DVector<f64>) -> DVector<f64>, t0: f64, rho: f64) -> (f64, f64, f64) {
        let res = argmin::core::Executor::new(Toy(r, unit), SlpMinimax { rho, converged: false })
            .configure(|s| s.param(DVector::from_element(1, t0)).max_iters(1))
            .run()
            .unwrap();
        let st = res.state();
        (st.get_param().unwrap()[0], st.get_cost(), res.solver().rho)
    }

    /// One residual with a ledge: r = t from t = 9 up, `below` under it (the Jacobian 1).
    fn ledge(below: f64) -> impl Fn(&DVector<f64>) -> DVector<f64> {
        move |t: &DVector<f64>| DVector::from_element(1, if t[0] >= 9.0 { t[0] } else { below })
    }

    /// The ratio tests are strict, at exactly representable ties. From t = 10 (r = 10) with
    /// ρ = 1 the LP steps to t = 0 (a predicted fall of 10); r = 9 there is a fall of 1, a
    /// ratio of exactly 0.1: not more than a tenth, refused. Within ρ = 1/4 the step to 7.5
    /// (predicted fall 2.5) falls to r = 9, a ratio of 0.4: taken, ρ kept. With ρ = 1/2 the
    /// step to 5 predicts a fall of 5; r = 6.25 there is a fall of 3.75, a ratio of exactly
    /// 3/4 at the region's edge: taken, but not more than 3/4, so ρ stays 1/2. All values are
    /// dyadic or exact quotients (1/10 and 3.75/5 round to the literals 0.1 and 0.75).
    #[test]
    fn the_ratio_tests_are_strict() {
        assert_eq!(one_iteration(ledge(9.0), 10.0, 1.0), (7.5, 9.0, 0.25));
        assert_eq!(one_iteration(ledge(6.25), 10.0, 0.5), (5.0, 6.25, 0.5));
    }

    /// A good step inside the trust region leaves ρ as it is: r = t − 0.9 from t = 1 with
    /// ρ = 1/4 (a bound of 1/4) steps by −0.1 to the optimum, far from the edge (0.99 · 1/4),
    /// with the fall the LP predicted (a ratio of 1); ρ stays 1/4.
    #[test]
    fn a_good_step_inside_the_region_does_not_grow_it() {
        let (t, cost, rho) = one_iteration(|t: &DVector<f64>| DVector::from_element(1, t[0] - 0.9), 1.0, 0.25);
        // The LP's solution holds to its feasibility tolerance (1e-7 of data of order one).
        assert!((t - 0.9).abs() < 1e-6 && cost < 1e-6, "t {t}, max |r| {cost}");
        assert_eq!(rho, 0.25);
    }

    /// One residual r = t with its Jacobian 1: the minimax optimum is t = 0, reached by one
    /// step from any start whose trust region holds it.
    fn line(t: &DVector<f64>) -> DVector<f64> {
        t.clone()
    }

    /// ρ doubles after a good step at the region's edge, but never past 1 (a step at most as
    /// large as each parameter's own scale): from t = 4 with ρ = 1 the LP steps by −4 to the
    /// optimum exactly (ratio 1, at the bound), and ρ stays 1.
    #[test]
    fn the_trust_region_never_grows_past_one() {
        assert_eq!(one_iteration(line, 4.0, 1.0), (0.0, 0.0, 1.0));
    }

    /// max|r| counts a NaN residual as infinite (f64::max would skip it), so a step into a
    /// region where the model is undefined is never taken as an improvement.
    #[test]
    fn a_nan_residual_is_an_infinite_max() {
        assert_eq!(max_abs(&DVector::from_vec(vec![-2.0, 1.0])), 2.0);
        assert_eq!(max_abs(&DVector::from_vec(vec![1.0, f64::NAN, -2.0])), f64::INFINITY);
        assert_eq!(max_abs(&DVector::from_vec(vec![f64::NAN])), f64::INFINITY);
    }

    /// A Jacobian of zeros gives no LP (every row's reach is 0): each failure shrinks ρ by 4,
    /// and after the 40 tries of one iteration the solver stops where it started, converged.
    #[test]
    fn a_flat_problem_stops_where_it_started() {
        let flat = Toy(|_: &DVector<f64>| DVector::from_vec(vec![3.0, -1.0]), |_: &DVector<f64>| DMatrix::zeros(2, 1));
        let res = argmin::core::Executor::new(flat, SlpMinimax::default())
            .configure(|s| s.param(DVector::from_element(1, 0.5)).max_iters(5))
            .run()
            .unwrap();
        let st = res.state();
        assert_eq!(st.get_termination_status(), &TerminationStatus::Terminated(TerminationReason::SolverConverged));
        assert_eq!((st.get_param().map(|t| t[0]), st.get_cost(), st.get_iter()), (Some(0.5), 3.0, 1));
        assert_eq!(res.solver().rho, 1e-2 * 0.25f64.powi(40));
    }

    /// The solver needs a start, and says so.
    #[test]
    fn the_solver_needs_a_start() {
        let Err(err) = argmin::core::Executor::new(Toy(line, unit), SlpMinimax::default()).configure(|s| s.max_iters(1)).run() else {
            panic!("ran without a start")
        };
        assert!(err.to_string().contains("SLP minimax needs a start"), "{err}");
    }

    /// A parameter at 0 still moves: its trust region is 1e-3 of the largest |θ|, not of its
    /// own 0. r_i = θ₀ + θ₁x_i − x_i on 11 points of [0, 1] has its optimum θ = (0, 1) with
    /// max 0; from (0.5, 0) the solver reaches it.
    #[test]
    fn a_parameter_at_zero_has_a_trust_region() {
        let x: Vec<f64> = (0..11).map(|i| i as f64 / 10.0).collect();
        let ramp = Toy(
            |t: &DVector<f64>| DVector::from_iterator(x.len(), x.iter().map(|x| t[0] + t[1] * x - x)),
            |_: &DVector<f64>| DMatrix::from_fn(x.len(), 2, |i, j| if j == 0 { 1.0 } else { x[i] }),
        );
        let res = argmin::core::Executor::new(ramp, SlpMinimax::default())
            .configure(|s| s.param(DVector::from_vec(vec![0.5, 0.0])).max_iters(200))
            .run()
            .unwrap();
        let st = res.state();
        let t = st.get_best_param().unwrap();
        // A linear problem: once the region holds the optimum, the LP lands on it to its
        // feasibility tolerance (1e-7 absolute on data of order one; 1e-9 has not been needed).
        assert!(st.get_best_cost() < 1e-9 && t[0].abs() < 1e-9 && (t[1] - 1.0).abs() < 1e-9, "{t:?} after {} iterations, max {}", st.get_iter(), st.get_best_cost());
    }

    /// R̃'s form (fits/fuzz_r.toml) over α ∈ [0.15, 1], θ ∈ [0, π/2]: γ = cos θ is 6e-17 at the
    /// last grid column and γ³ is 2e-49 there, so the Jacobian's rows span ~1e49.
    fn r_form() -> RationalModel {
        let inputs = vec!["alpha".to_string(), "theta".to_string()];
        let derived = vec![
            Derived::parse("beta", "1 - alpha", &inputs).unwrap(),
            Derived::parse("gamma", "cos(theta)", &inputs).unwrap(),
            Derived::parse("delta", "sin(theta)", &inputs).unwrap(),
        ];
        let features: Vec<String> = inputs.iter().cloned().chain(derived.iter().map(|d| d.name.clone())).collect();
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &features).unwrap()).collect::<Vec<_>>();
        RationalModel::new(ModelParts {
            inputs,
            derived,
            numerator: terms(&["1", "beta", "gamma", "delta", "beta^2", "gamma^2", "beta*gamma", "gamma^3", "delta^3"]),
            denominator: terms(&["beta", "gamma"]),
            offset: 0.5,
            factor: Some(Term::parse("beta", &features).unwrap()),
            ..ModelParts::default()
        })
        .unwrap()
    }

    #[test]
    fn polish_ends_where_the_linearised_problem_has_no_descent() {
        let model = r_form();
        let n = 17;
        let x: Vec<Vec<f64>> = (0..n)
            .flat_map(|i| (0..n).map(move |j| vec![0.15 + 0.85 * i as f64 / (n - 1) as f64, std::f64::consts::FRAC_PI_2 * j as f64 / (n - 1) as f64]))
            .collect();
        // Smooth, not in the model's span: the minimax error stays well above rounding.
        let y: Vec<f64> = x.iter().map(|p| 0.5 + (1.0 - p[0]) * (0.3 * (-p[1]).exp() + 0.1 * (3.0 * p[0]).sin())).collect();
        let data = Data { x, y };
        let f = fit(&model, &data, &FitOptions { objective: Objective::Minimax, ..FitOptions::default() }, "R form").unwrap();
        let problem = crate::fit::problem::Residuals::new(&model, &data, f.theta.clone());
        let r = problem.raw(&f.theta);
        let j = problem.jacobian_at(&f.theta);
        let m = max_abs(&r);
        let norm = f.theta.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let bounds: Vec<f64> = f.theta.iter().map(|v| 1e-3 * v.abs().max(1e-3 * norm)).collect();
        let rows: Vec<usize> = (0..r.len()).collect();
        let (_, predicted) = lp_step(&r, &j, &bounds, &rows).expect("the LP at the optimum solves");
        // At a minimax point the linearised max cannot fall at first order; what is left is the
        // LP's own feasibility tolerance (1e-9 relative bounds it with room).
        assert!(predicted >= m * (1.0 - 1e-9), "the LP still predicts {predicted:e} below {m:e}");
        // And the polish moved past Lawson's iterate, which only approaches the optimum.
        let lawson = {
            let opts = FitOptions { objective: Objective::Minimax, polish_iters: 0, ..FitOptions::default() };
            fit(&model, &data, &opts, "R form").unwrap().report.max_abs_error
        };
        assert!(m < lawson, "polished {m:e}, Lawson {lawson:e}");
    }
}

