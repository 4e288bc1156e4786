//! Restarted Nelder–Mead (argmin's solver) for small objectives without derivatives: the
//! kinked max-error objectives of published forms with a few constants.

use argmin::core::{CostFunction, Error, Executor, State};
use argmin::solver::neldermead::NelderMead;
use nalgebra::DVector;

struct Cost<F: Fn(&[f64]) -> f64>(F);

impl<F: Fn(&[f64]) -> f64> CostFunction for Cost<F> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, p: &DVector<f64>) -> Result<f64, Error> {
        Ok((self.0)(p.as_slice()))
    }
}

/// Nelder–Mead minimisation of `f` from `x0`: rounds with an axis simplex of relative step
/// 10 %, 3 %, 1 %, … (absolute for zero coordinates) around the best point so far.
pub fn nelder_mead(f: impl Fn(&[f64]) -> f64, x0: &[f64]) -> (Vec<f64>, f64) {
    let cost = Cost(f);
    let mut best = x0.to_vec();
    let mut best_cost = (cost.0)(&best);
    for step in [0.1, 0.03, 0.01, 0.003, 0.001, 0.1, 0.01, 0.001, 1e-4] {
        let x = DVector::from_vec(best.clone());
        let mut simplex = vec![x.clone()];
        for i in 0..x.len() {
            let mut v = x.clone();
            v[i] += if v[i] == 0.0 { step * 0.1 } else { step * v[i].abs() };
            simplex.push(v);
        }
        let solver = NelderMead::new(simplex).with_sd_tolerance(1e-15).expect("a non-negative tolerance");
        let Ok(res) = Executor::new(Cost(&cost.0), solver).configure(|s| s.max_iters(3000)).run() else { continue };
        let st = res.state();
        if let Some(p) = st.get_best_param()
            && st.get_best_cost() < best_cost
        {
            best = p.as_slice().to_vec();
            best_cost = st.get_best_cost();
        }
    }
    (best, best_cost)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The restarted Nelder–Mead finds the minimum of a scaled quadratic bowl from a start
    /// with a zero coordinate (whose simplex step is absolute) to 1e-6 (the simplex's spread
    /// tolerance is 1e-15 in cost; 1e-12 in cost is 1e-6 in a coordinate of weight 1), and the
    /// cost it returns is the function's at the point it returns. Started at the minimum it
    /// stays there: a round keeps its result only when it improves on the best so far.
    #[test]
    fn nelder_mead_finds_a_bowls_minimum_and_never_returns_worse() {
        let centre = [0.7, -1.3, 2.0];
        let bowl = |p: &[f64]| (p[0] - centre[0]).powi(2) + 3.0 * (p[1] - centre[1]).powi(2) + 0.5 * (p[2] - centre[2]).powi(2);
        let (x, cost) = nelder_mead(bowl, &[1.0, 0.0, 1.5]);
        assert_eq!(cost, bowl(&x));
        assert!(cost < 1e-12, "{cost:e} at {x:?}");
        for (got, want) in x.iter().zip(centre) {
            assert!((got - want).abs() < 2e-6, "{x:?}");
        }
        let (x, cost) = nelder_mead(bowl, &centre);
        assert_eq!((x, cost), (centre.to_vec(), 0.0));
    }

    /// Each round of the restarted Nelder–Mead starts from the axis simplex the doc states: the
    /// best point so far and, per coordinate, that point moved up by the round's step times the
    /// coordinate's magnitude, or by a tenth of the step where the coordinate is 0. From
    /// (2, 0, −4) the first round (step 10 %) evaluates (2.2, 0, −4), (2, 0.01, −4) and
    /// (2, 0, −3.6) before any other point (the start, then the simplex's vertices): here the
    /// points are built with the same f64 operations, so they compare exactly.
    #[test]
    fn each_round_starts_from_the_stated_axis_simplex() {
        let log = std::sync::Mutex::new(Vec::<Vec<f64>>::new());
        let bowl = |p: &[f64]| {
            log.lock().unwrap().push(p.to_vec());
            (p[0] - 1.0).powi(2) + (p[1] - 0.5).powi(2) + (p[2] + 3.0).powi(2)
        };
        let x0 = [2.0, 0.0, -4.0];
        nelder_mead(bowl, &x0);
        let log = log.into_inner().unwrap();
        let first: &[Vec<f64>] = &log[..5];
        let step = 0.1;
        let vertices = [vec![2.0 + step * 2.0, 0.0, -4.0], vec![2.0, 0.0 + step * 0.1, -4.0], vec![2.0, 0.0, -4.0 + step * 4.0]];
        assert_eq!(first[0], x0.to_vec());
        for v in &vertices {
            assert!(first.contains(v), "{v:?} not among the first evaluations {first:?}");
        }
    }
}
