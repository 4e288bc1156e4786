//! f32 coefficients for emitted code: the f64 fit rounded to f32, then re-optimised in f32.
//!
//! Shaders evaluate the fitted form in f32 with f32 coefficients. Rounding each f64 coefficient
//! to the nearest f32 moves it by up to half an ulp; where the form has large coefficients that
//! cancel, those moves add up to more than the fit's own error, and the nearest f32 vector is no
//! longer the best one. [`round_and_reoptimise`] starts from the rounded vector and searches its
//! f32 neighbours:
//!
//! - **Objective**: the spec's, of the f32-*evaluated* function (exactly the emitted arithmetic:
//!   [`expr::eval_f32`] of [`expr::model_expr`] on [`expr::features_f32`], the clamp applied in
//!   f32), residuals against the fitting samples in f64: minimax max |r|, lsq rms, l4 Σ r⁴. On
//!   the fitting grid, not the verification grid, so the verification stays a measurement.
//! - **Moves**: coordinate sweeps. For each coefficient that is not fixed, in order, the
//!   candidates ±1, ±2, ±4, …, ±`max_ulps` ulps from its current value, each within `max_ulps`
//!   of the rounded value; the best strictly improving admissible one is taken (ties go to the
//!   earlier candidate). Sweeps repeat until one moves nothing or `max_sweeps` is reached.
//! - **Constraints**: with `max_rms`, an accepted vector's rms is at most max(cap, the rounded
//!   vector's rms); each pin f(at) = value holds in f32 within max(the rounded vector's error
//!   there, one ulp of the value in f32); the denominator stays provably positive: a move of a
//!   denominator coefficient is accepted only if [`prove_denominator_positive`] succeeds on the
//!   f32 values widened to f64. That proof is of the f64 evaluation of the f32 coefficients; the
//!   f32 evaluation of Q differs from it by its own rounding, a few ulps of Σ|q_j D_j|.
//! - **Deterministic**: sequential, in a fixed order, sums in sample order: the result does not
//!   depend on the thread count.
//!
//! Two-stage fits (`kind = "fields"`) are not re-optimised; see `pipeline::fields`.

use super::model::RationalModel;
use super::positivity::{prove_denominator_positive, Positivity};
use super::problem::Data;
use super::solve::{FitError, Objective};
use crate::fit::expr::{self, Expr};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

/// Search limits of the re-optimisation.
#[derive(Debug, Clone, Copy)]
pub struct RoundOptions {
    pub objective: Objective,
    /// Minimax under an rms cap (see the module doc).
    pub max_rms: Option<f64>,
    /// Largest move of one coefficient from its rounded value, in ulps.
    pub max_ulps: u32,
    /// Most coordinate sweeps.
    pub max_sweeps: usize,
}

/// Move cap of the committed fits: a coefficient may move at most this many ulps from its
/// rounded value (`build --check` rejects committed f32 arrays farther away).
pub const MAX_ULPS: u32 = 64;

impl RoundOptions {
    pub fn new(objective: Objective, max_rms: Option<f64>) -> Self {
        RoundOptions { objective, max_rms, max_ulps: MAX_ULPS, max_sweeps: 100 }
    }
}

/// Errors of one coefficient vector on the fitting samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    /// The spec's objective: max |r| (minimax), rms (lsq) or Σ r⁴ (l4).
    pub objective: f64,
    pub max_abs_error: f64,
    pub rms_error: f64,
}

impl Errors {
    /// Errors of residuals (non-finite ones count as infinite).
    pub fn of(residuals: impl Iterator<Item = f64>, objective: Objective) -> Errors {
        let (mut n, mut max, mut s2, mut s4) = (0usize, 0.0f64, 0.0f64, 0.0f64);
        for r in residuals {
            let a = if r.is_finite() { r.abs() } else { f64::INFINITY };
            n += 1;
            max = max.max(a);
            s2 += a * a;
            s4 += (a * a) * (a * a);
        }
        let rms = (s2 / n.max(1) as f64).sqrt();
        let objective = match objective {
            Objective::Minimax => max,
            Objective::Lsq => rms,
            Objective::L4 => s4,
        };
        Errors { objective, max_abs_error: max, rms_error: rms }
    }
}

/// The f32 coefficients and what rounding and re-optimisation did on the fitting samples.
#[derive(Debug, Clone)]
pub struct Rounding {
    pub num: Vec<f32>,
    pub den: Vec<f32>,
    pub f64: Errors,
    pub rounded: Errors,
    pub reoptimised: Errors,
    pub sweeps: usize,
    /// Objective evaluations (each over all samples, or stopped early once it cannot improve).
    pub evaluations: usize,
}

/// Position of an f32 on the line of all finite f32s (±0 both at 0): consecutive floats differ
/// by one, so the difference of two positions is their distance in ulps.
fn ordinal(x: f32) -> i64 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 { -((b & 0x7fff_ffff) as i64) } else { b as i64 }
}

/// The f32 at position `k` of [`ordinal`]'s line; position 0 is +0.
fn from_ordinal(k: i64) -> f32 {
    if k < 0 { f32::from_bits((-k) as u32 | 0x8000_0000) } else { f32::from_bits(k as u32) }
}

/// Signed distance from `a` to `b` in f32 ulps (number of f32s stepped over, ±0 counted once).
pub fn ulps_between(a: f32, b: f32) -> i64 {
    ordinal(b) - ordinal(a)
}

/// The f32 `k` ulps above (k < 0: below) `x`, if it is finite.
pub fn step_ulps(x: f32, k: i64) -> Option<f32> {
    let o = ordinal(x) + k;
    if o.unsigned_abs() > 0x7f7f_ffff {
        return None;
    }
    Some(from_ordinal(o))
}

/// The f64 coefficients rounded to nearest f32: (numerator, denominator).
pub fn rounded(model: &RationalModel, c: &DVector<f64>) -> (Vec<f32>, Vec<f32>) {
    expr::f32_arrays(model, c)
}

/// The f32 coefficients widened to one f64 vector [num; den].
pub fn widen(num: &[f32], den: &[f32]) -> DVector<f64> {
    DVector::from_iterator(num.len() + den.len(), num.iter().chain(den).map(|&v| v as f64))
}

/// The emitted f32 function on fixed samples.
struct F32Function<'a> {
    expr: Expr,
    features: Vec<Vec<f32>>,
    y: &'a [f64],
    clamp: Option<(f32, f32)>,
}

impl F32Function<'_> {
    fn value(&self, num: &[f32], den: &[f32], i: usize) -> f32 {
        let v = expr::eval_f32(&self.expr, &self.features[i], num, den);
        match self.clamp {
            Some((lo, hi)) => v.clamp(lo, hi),
            None => v,
        }
    }

    fn residual(&self, num: &[f32], den: &[f32], i: usize) -> f64 {
        self.value(num, den, i) as f64 - self.y[i]
    }

    fn errors(&self, num: &[f32], den: &[f32], objective: Objective) -> Errors {
        Errors::of((0..self.y.len()).map(|i| self.residual(num, den, i)), objective)
    }

    /// The objective in comparable form (max |r|, Σ r², Σ r⁴), or None as soon as it reaches
    /// `bound` (every partial value is a lower bound of the total).
    fn score(&self, num: &[f32], den: &[f32], objective: Objective, bound: f64) -> Option<f64> {
        let mut acc = 0.0f64;
        for i in 0..self.y.len() {
            let r = self.residual(num, den, i);
            if !r.is_finite() {
                return None;
            }
            let a = r.abs();
            acc = match objective {
                Objective::Minimax => acc.max(a),
                Objective::Lsq => acc + a * a,
                Objective::L4 => acc + (a * a) * (a * a),
            };
            if acc >= bound {
                return None;
            }
        }
        Some(acc)
    }

    fn rms(&self, num: &[f32], den: &[f32]) -> f64 {
        let s: f64 = (0..self.y.len()).map(|i| self.residual(num, den, i).powi(2)).sum();
        (s / self.y.len().max(1) as f64).sqrt()
    }
}

/// Round `c` to f32 and re-optimise the f32 vector (see the module doc). `domain` is the box the
/// emitted code clamps its inputs to (and the positivity proof covers); `data` the fitting
/// samples. Fails only if the rounded vector's denominator is not provably positive.
pub fn round_and_reoptimise(
    model: &RationalModel,
    c: &DVector<f64>,
    data: &Data,
    domain: &[(f64, f64)],
    opts: &RoundOptions,
    what: &str,
) -> Result<Rounding, FitError> {
    let objective = opts.objective;
    let d32: Vec<(f32, f32)> = domain.iter().map(|&(a, b)| (a as f32, b as f32)).collect();
    let f = F32Function {
        expr: expr::model_expr(model),
        features: data.x.iter().map(|x| expr::features_f32(model, x, &d32)).collect(),
        y: &data.y,
        clamp: model.clamp.map(|(a, b)| (a as f32, b as f32)),
    };
    let f64_errors = Errors::of(data.x.iter().zip(&data.y).map(|(x, y)| model.eval_clamped(c, x) - y), objective);
    let (num0, den0) = rounded(model, c);
    if let Positivity::NotProven { lower, region, .. } = prove_denominator_positive(model, &widen(&num0, &den0), domain) {
        return Err(FitError::PoleInDomain { what: format!("{what} (f32 coefficients)"), lower, region });
    }
    let rounded_errors = f.errors(&num0, &den0, objective);

    // Pins: f32 value at each pin point (before the clamp) and its allowed error.
    let expr_ = &f.expr;
    let pins: Vec<(Vec<f32>, f64, f64)> = model
        .pins
        .iter()
        .map(|p| {
            let xs = expr::features_f32(model, &p.at, &d32);
            let e0 = (expr::eval_f32(expr_, &xs, &num0, &den0) as f64 - p.value).abs();
            let v32 = p.value as f32;
            let ulp = step_ulps(v32.abs(), 1).map_or(f64::INFINITY, |u| (u - v32.abs()) as f64);
            (xs, p.value, e0.max(ulp))
        })
        .collect();
    let pins_hold = |num: &[f32], den: &[f32]| {
        pins.iter().all(|(xs, v, tol)| (expr::eval_f32(expr_, xs, num, den) as f64 - v).abs() <= *tol)
    };
    let rms_cap = opts.max_rms.map(|cap| cap.max(rounded_errors.rms_error));

    let nn = num0.len();
    let movable: Vec<usize> = (0..model.n_full()).filter(|i| !model.fixed.iter().any(|f| f.0 == *i)).collect();
    let start: Vec<f32> = num0.iter().chain(&den0).copied().collect();
    let mut cur = start.clone();
    let split = |v: &[f32]| (v[..nn].to_vec(), v[nn..].to_vec());
    let mut evaluations = 1usize;
    let mut best = f.score(&num0, &den0, objective, f64::INFINITY).unwrap_or(f64::INFINITY);
    let steps: Vec<i64> = std::iter::successors(Some(1i64), |s| Some(s * 2))
        .take_while(|&s| s <= opts.max_ulps as i64)
        .flat_map(|s| [s, -s])
        .collect();
    let mut sweeps = 0;
    while sweeps < opts.max_sweeps {
        sweeps += 1;
        let mut moved = false;
        for &j in &movable {
            let mut choice: Option<(f32, f64)> = None;
            for &k in &steps {
                let Some(v) = step_ulps(cur[j], k) else { continue };
                if ulps_between(start[j], v).unsigned_abs() > opts.max_ulps as u64 {
                    continue;
                }
                let mut cand = cur.clone();
                cand[j] = v;
                let (num, den) = split(&cand);
                let bound = choice.map_or(best, |c| c.1);
                evaluations += 1;
                let Some(s) = f.score(&num, &den, objective, bound) else { continue };
                let admissible = rms_cap.is_none_or(|cap| f.rms(&num, &den) <= cap)
                    && pins_hold(&num, &den)
                    && (j < nn
                        || matches!(
                            prove_denominator_positive(model, &widen(&num, &den), domain),
                            Positivity::Proven { .. }
                        ));
                if admissible {
                    choice = Some((v, s));
                }
            }
            if let Some((v, s)) = choice {
                cur[j] = v;
                best = s;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    let (num, den) = split(&cur);
    let reoptimised = f.errors(&num, &den, objective);
    Ok(Rounding { num, den, f64: f64_errors, rounded: rounded_errors, reoptimised, sweeps, evaluations })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::model::{ModelParts, Pin, Term};
    use crate::fit::{fit, FitOptions};

    #[test]
    fn ulp_steps_cross_zero_and_count_floats() {
        assert_eq!(step_ulps(1.0, 1), Some(1.0 + f32::EPSILON));
        assert_eq!(step_ulps(1.0, -1), Some(1.0 - f32::EPSILON / 2.0));
        assert_eq!(ulps_between(1.0, 1.0 + 4.0 * f32::EPSILON), 4);
        // ±0 are one position: the smallest subnormals are one step either side.
        let tiny = f32::from_bits(1);
        assert_eq!(step_ulps(0.0, 1), Some(tiny));
        assert_eq!(step_ulps(-0.0, -1), Some(-tiny));
        assert_eq!(ulps_between(-tiny, tiny), 2);
        // Zero's one position is +0, reached from either side: a coefficient stepped onto zero
        // is printed `0.0` in emitted code, never `-0.0` (bits, since -0.0 == 0.0).
        for (from, k) in [(tiny, -1), (-tiny, 1), (-0.0, 0), (0.0, 0)] {
            assert_eq!(step_ulps(from, k).map(f32::to_bits), Some(0), "{from:e} stepped {k}");
        }
        assert_eq!(step_ulps(f32::MAX, 1), None);
        assert_eq!(step_ulps(f32::MIN, -1), None);
        // The largest finite floats themselves are reachable, from either side.
        let below_max = f32::from_bits(f32::MAX.to_bits() - 1);
        assert_eq!((step_ulps(below_max, 1), step_ulps(-below_max, -1)), (Some(f32::MAX), Some(f32::MIN)));
        assert_eq!((step_ulps(f32::MAX, 0), step_ulps(f32::MIN, 0)), (Some(f32::MAX), Some(f32::MIN)));
    }

    /// Residuals (3, −4, 0, 12): max 12; Σr² = 169, rms = √(169/4) = 6.5; Σr⁴ =
    /// 81 + 256 + 20736 = 21073, all exact in f64. A NaN residual counts as infinite.
    #[test]
    fn errors_are_the_max_rms_and_fourth_power_sum() {
        let r = [3.0, -4.0, 0.0, 12.0];
        for (objective, want) in [(Objective::Minimax, 12.0), (Objective::Lsq, 6.5), (Objective::L4, 21073.0)] {
            let e = Errors::of(r.iter().copied(), objective);
            assert_eq!(e, Errors { objective: want, max_abs_error: 12.0, rms_error: 6.5 }, "{objective:?}");
        }
        let e = Errors::of([1.0, f64::NAN].into_iter(), Objective::Lsq);
        assert_eq!((e.max_abs_error, e.rms_error), (f64::INFINITY, f64::INFINITY));
        assert_eq!(Errors::of(std::iter::empty(), Objective::Lsq).rms_error, 0.0);
    }

    /// The search's score is max |r|, Σr², Σr⁴ of the emitted f32 function's residuals, each
    /// recomputed here from the f32 value through `eval_f32`, and None once it reaches the bound.
    #[test]
    fn the_search_scores_the_objective_of_the_f32_function() {
        let model = RationalModel::rational_1d("x", 1, 1);
        let x: Vec<Vec<f64>> = (0..5).map(|i| vec![i as f64 / 4.0]).collect();
        let y: Vec<f64> = x.iter().map(|p| 0.3 + 0.9 * p[0] * p[0]).collect();
        let f = f32_function_1d(&model, &x, &y);
        let (num, den) = ([0.25f32, 1.0], [0.5f32]);
        let r: Vec<f64> = x.iter().zip(&y).map(|(p, y)| expr::eval_f32(&f.expr, &[p[0] as f32], &num, &den) as f64 - y).collect();
        assert!(r.iter().all(|v| v.abs() > 1e-3), "residuals away from 0: {r:?}");
        let max = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let s2: f64 = r.iter().map(|v| v * v).sum();
        let s4: f64 = r.iter().map(|v| v.powi(4)).sum();
        // The same terms summed in the same order, (a·a)·(a·a) against powi(4): a few ulps.
        for (objective, want) in [(Objective::Minimax, max), (Objective::Lsq, s2), (Objective::L4, s4)] {
            let got = f.score(&num, &den, objective, f64::INFINITY).unwrap();
            assert!((got - want).abs() <= 1e-14 * want, "{objective:?}: {got} vs {want}");
            assert_eq!(f.score(&num, &den, objective, want * (1.0 - 1e-9)), None, "{objective:?} reaches its bound");
        }
        assert!((f.rms(&num, &den) - (s2 / 5.0).sqrt()).abs() <= 1e-15, "rms");
    }

    /// The emitted f32 function of a one-input model on samples `x` (no clamp).
    fn f32_function_1d<'a>(model: &RationalModel, x: &[Vec<f64>], y: &'a [f64]) -> F32Function<'a> {
        F32Function { expr: expr::model_expr(model), features: x.iter().map(|p| vec![p[0] as f32]).collect(), y, clamp: None }
    }

    fn samples(lo: f64, hi: f64, n: usize, f: impl Fn(f64) -> f64) -> Data {
        let x: Vec<Vec<f64>> = (0..n).map(|i| vec![lo + (hi - lo) * i as f64 / (n - 1) as f64]).collect();
        let y = x.iter().map(|p| f(p[0])).collect();
        Data { x, y }
    }

    /// A quartic fitted to ln x on [8, 9]: on a narrow interval far from 0 the monomial terms
    /// cancel (Σ|c_j x^j| ≈ 9.6 at x = 9 for values ≈ 2.2), so rounding the coefficients to f32
    /// costs far more than the fit's own error.
    fn cancelling(objective: Objective) -> (RationalModel, DVector<f64>, Data) {
        let model = RationalModel::rational_1d("x", 4, 0);
        let data = samples(8.0, 9.0, 201, f64::ln);
        let f = fit(&model, &data, &FitOptions { objective, ..FitOptions::default() }, "quartic").unwrap();
        (model, f.coefficients, data)
    }

    #[test]
    fn reoptimised_objective_is_at_most_the_rounded_one() {
        // The search accepts only strict decreases of the objective it reports (the same sums in
        // the same order), so no tolerance: ≤ exactly, for every objective and a rational form.
        let rational = RationalModel::rational_1d("x", 3, 2);
        let data = samples(0.0, 1.0, 129, |x| (1.0 + 3.0 * x).sqrt() / (1.0 + x * x));
        for objective in [Objective::Lsq, Objective::Minimax, Objective::L4] {
            let opts = FitOptions { objective, ..FitOptions::default() };
            let f = fit(&rational, &data, &opts, "rational").unwrap();
            let ro = RoundOptions::new(objective, None);
            let r = round_and_reoptimise(&rational, &f.coefficients, &data, &[(0.0, 1.0)], &ro, "rational").unwrap();
            assert!(r.reoptimised.objective <= r.rounded.objective, "{objective:?}: {r:?}");
            let (m, c, d) = cancelling(objective);
            let r = round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &ro, "quartic").unwrap();
            assert!(r.reoptimised.objective <= r.rounded.objective, "{objective:?}: {r:?}");
        }
    }

    #[test]
    fn reoptimisation_repairs_rounding_of_cancelling_coefficients() {
        let (m, c, d) = cancelling(Objective::Minimax);
        let r = round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &RoundOptions::new(Objective::Minimax, None), "quartic")
            .unwrap();
        // The case is one where rounding dominates: the f64 fit is good to ~1e-8, while rounding
        // each coefficient by up to 2^-24 relative moves the value by up to Σ|c_j x^j|·2^-24 ≈
        // 5.7e-7 at x = 9; require 10× the fit error.
        assert!(r.rounded.max_abs_error > 10.0 * r.f64.max_abs_error, "{r:?}");
        // What rounding adds is a quartic δ(x) = Σ δc_j x^j that moves of the coefficients can
        // cancel; what they cannot is the f32 evaluation's own rounding, about an ulp of the
        // value (2^-22 ≈ 2.4e-7 for values in [2, 4)). The search must get the max error at least
        // 20% below the rounded one (from ~4.4e-7 toward that floor).
        assert!(r.reoptimised.max_abs_error < 0.8 * r.rounded.max_abs_error, "{r:?}");
    }

    /// An rms cap constrains the search and nothing else: a cap no candidate comes near (1.0,
    /// against errors ~1e-7) leaves the uncapped result, bit for bit; a cap of 0 (raised to the
    /// rounded vector's rms, as documented) keeps every accepted vector's rms at or below the
    /// rounded one's, measured by the f32 evaluation the search uses.
    #[test]
    fn an_rms_cap_binds_only_where_it_is_reached() {
        let (m, c, d) = cancelling(Objective::Minimax);
        let run = |max_rms| round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &RoundOptions::new(Objective::Minimax, max_rms), "quartic").unwrap();
        let free = run(None);
        let (start, _) = rounded(&m, &c);
        assert_ne!(free.num, start, "the uncapped search moves");
        let loose = run(Some(1.0));
        assert_eq!((&loose.num, loose.sweeps, loose.evaluations), (&free.num, free.sweeps, free.evaluations));
        let tight = run(Some(0.0));
        let f = f32_function_1d(&m, &d.x, &d.y);
        assert!(f.rms(&tight.num, &[]) <= tight.rounded.rms_error, "{tight:?}");
        assert!(tight.reoptimised.max_abs_error <= tight.rounded.max_abs_error, "{tight:?}");
    }

    /// `max_sweeps` caps the sweeps exactly: 0 keeps the nearest f32 vector (no sweep, the one
    /// evaluation of the start), and a cap of k below the uncapped run's sweep count stops after
    /// k sweeps, with a result no worse than the start's and no better than the uncapped one's
    /// (the same first k sweeps; each sweep only accepts improvements).
    #[test]
    fn the_sweep_cap_is_held_exactly() {
        let (m, c, d) = cancelling(Objective::Minimax);
        let run = |max_sweeps| {
            let opts = RoundOptions { max_sweeps, ..RoundOptions::new(Objective::Minimax, None) };
            round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &opts, "quartic").unwrap()
        };
        let free = run(100);
        assert!(free.sweeps >= 2, "the uncapped search needs more than one sweep here: {free:?}");
        let none = run(0);
        let (start, _) = rounded(&m, &c);
        assert_eq!((none.num.as_slice(), none.sweeps, none.evaluations), (start.as_slice(), 0, 1));
        assert_eq!(none.reoptimised, none.rounded);
        for k in 1..free.sweeps {
            let capped = run(k);
            assert_eq!(capped.sweeps, k);
            let e = capped.reoptimised.max_abs_error;
            assert!(e <= none.rounded.max_abs_error && e >= free.reoptimised.max_abs_error, "{k} sweeps: {capped:?}");
        }
    }

    /// The search tries the moves the module documents and no others (one coefficient by ±1,
    /// ±2, ±4, …, ±max_ulps ulps, within max_ulps of its rounded value: its evaluation count
    /// is bounded by theirs), and where the sweeps stop before `max_sweeps`, none of those
    /// moves lowers the score: the result is a coordinate-wise optimum over them, checked here
    /// move by move for each objective on the cancelling quartic (no pins, no cap, no
    /// denominator: every move admissible). Its report's errors are those of the f64 fit, the
    /// nearest f32 vector and the result, each re-measured here.
    #[test]
    fn the_search_stops_where_no_documented_move_improves() {
        for objective in [Objective::Lsq, Objective::Minimax, Objective::L4] {
            let (m, c, d) = cancelling(objective);
            let opts = RoundOptions::new(objective, None);
            let r = round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &opts, "quartic").unwrap();
            assert!(r.sweeps < opts.max_sweeps, "{objective:?}: stopped by the sweep cap");
            // The documented moves: ±2^e ulps up to MAX_ULPS, 2·(log2(64) + 1) = 14 of them.
            let steps: Vec<i64> = (0..=MAX_ULPS.ilog2()).map(|e| 1i64 << e).flat_map(|s| [s, -s]).collect();
            // The search's cost: the rounded vector, then at most those candidates a
            // coefficient a sweep (fewer where the cap or f32's range cuts them).
            assert!(r.evaluations <= 1 + r.sweeps * r.num.len() * steps.len(), "{objective:?}: {} evaluations in {} sweeps", r.evaluations, r.sweeps);
            let f = f32_function_1d(&m, &d.x, &d.y);
            let best = f.score(&r.num, &[], objective, f64::INFINITY).unwrap();
            let (start, _) = rounded(&m, &c);
            // The report's three error sets, each of its own vector: the f64 fit (its f64
            // evaluation), the nearest f32 vector and the result (their f32 evaluation).
            let e = expr::model_expr(&m);
            let of = |v: &dyn Fn(f64) -> f64| Errors::of(d.x.iter().zip(&d.y).map(|(x, y)| v(x[0]) - y), objective);
            let (c64, r32) = (c.clone(), r.num.clone());
            assert_eq!(r.f64, of(&|x| m.eval_clamped(&c64, &[x])), "{objective:?}");
            assert_eq!(r.rounded, of(&|x| expr::eval_f32(&e, &[x as f32], &start, &[]) as f64), "{objective:?}");
            assert_eq!(r.reoptimised, of(&|x| expr::eval_f32(&e, &[x as f32], &r32, &[]) as f64), "{objective:?}");
            for j in 0..r.num.len() {
                for &k in &steps {
                    let Some(v) = step_ulps(r.num[j], k) else { continue };
                    if ulps_between(start[j], v).unsigned_abs() > MAX_ULPS as u64 {
                        continue;
                    }
                    let mut num = r.num.clone();
                    num[j] = v;
                    // The same sums in the same order as the search: no tolerance.
                    let s = f.score(&num, &[], objective, f64::INFINITY).unwrap();
                    assert!(s >= best, "{objective:?}: coefficient {j} moved {k} ulps scores {s:e} < {best:e}");
                }
            }
        }
    }

    #[test]
    fn moves_stay_within_the_cap_and_only_free_coefficients_move() {
        let (m, c, d) = cancelling(Objective::Lsq);
        for cap in [2u32, 8, MAX_ULPS] {
            let opts = RoundOptions { max_ulps: cap, ..RoundOptions::new(Objective::Lsq, None) };
            let r = round_and_reoptimise(&m, &c, &d, &[(8.0, 9.0)], &opts, "quartic").unwrap();
            let (n0, d0) = rounded(&m, &c);
            let moves: Vec<i64> =
                n0.iter().chain(&d0).zip(r.num.iter().chain(&r.den)).map(|(&a, &b)| ulps_between(a, b)).collect();
            assert!(moves.iter().all(|k| k.unsigned_abs() <= cap as u64), "cap {cap}: {moves:?}");
            assert!(moves.iter().any(|k| *k != 0), "cap {cap}: nothing moved");
        }
        // A fixed coefficient keeps its rounded value.
        let feats = vec!["x".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &feats).unwrap()).collect::<Vec<_>>();
        let fixed = RationalModel::new(ModelParts {
            inputs: feats.clone(),
            numerator: terms(&["1", "x", "x^2", "x^3", "x^4"]),
            fixed: vec![(0, -0.6)],
            ..ModelParts::default()
        })
        .unwrap();
        let f = fit(&fixed, &d, &FitOptions::default(), "fixed").unwrap();
        let r = round_and_reoptimise(&fixed, &f.coefficients, &d, &[(8.0, 9.0)], &RoundOptions::new(Objective::Lsq, None), "fixed")
            .unwrap();
        assert_eq!(r.num[0], -0.6f32);
        assert!(r.num[1..].iter().zip(&rounded(&fixed, &f.coefficients).0[1..]).any(|(a, b)| a != b));
    }

    /// c/(1 + Σ d_j·t_j(x)) of one input x, the denominator terms t_j given, with `fixed`
    /// coefficients (c first).
    fn over_denominator(den: &[&str], fixed: Vec<(usize, f64)>) -> RationalModel {
        let feats = vec!["x".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &feats).unwrap()).collect::<Vec<_>>();
        RationalModel::new(ModelParts { inputs: feats.clone(), numerator: terms(&["1"]), denominator: terms(den), fixed, ..ModelParts::default() }).unwrap()
    }

    /// The search never takes a denominator coefficient the proof cannot pass, the first one
    /// and a later one alike: c/(1 + d·x^p) on the box [0, 1], for p = 1 (d the first
    /// denominator coefficient) and p = 2 (d the second, the first, of x, fixed at 0), from
    /// d = −1 + 2^-24 (denominator ≥ 2^-24 there), with data of d = −1 − 2^-23 sampled where
    /// x^p ∈ [0, ½] only. Two ulps down, d = −1 − 2^-23, fits the data exactly but has a pole
    /// inside the box (at x = (1 + 2^-23)^(−1/p) < 1); d = −1 reaches 0 at x = 1. So d must stay
    /// where it is, though the objective pulls it down.
    #[test]
    fn the_search_keeps_every_denominator_coefficient_provable() {
        let pole = -1.0 - 2f64.powi(-23);
        let d0 = -1.0 + 2f64.powi(-24);
        for (den, fixed, p, start) in [(&["x"][..], vec![], 1, vec![1.0, d0]), (&["x", "x^2"][..], vec![(1, 0.0)], 2, vec![1.0, 0.0, d0])] {
            let m = over_denominator(den, fixed);
            let d = samples(0.0, 0.5f64.powf(1.0 / p as f64), 65, |x| 1.0 / (1.0 + pole * x.powi(p)));
            let start = DVector::from_vec(start);
            for objective in [Objective::Minimax, Objective::Lsq] {
                let r = round_and_reoptimise(&m, &start, &d, &[(0.0, 1.0)], &RoundOptions::new(objective, None), "pole").unwrap();
                let last = *r.den.last().unwrap();
                assert!(last > -1.0, "x^{p}, {objective:?}: d = {last} leaves no positive denominator on [0, 1]");
                assert!(matches!(prove_denominator_positive(&m, &widen(&r.num, &r.den), &[(0.0, 1.0)]), Positivity::Proven { .. }));
                // Not vacuous: the data would rather have the pole's coefficient (measured: with
                // the proof skipped, the least-squares search takes d = −1 for x²).
                let f = |dd: f32| (0..d.y.len()).map(|i| (1.0 / (1.0 + dd as f64 * d.x[i][0].powi(p)) - d.y[i]).abs()).fold(0.0, f64::max);
                assert!(f(pole as f32) < f(last), "x^{p}, {objective:?}");
            }
        }
    }

    /// A denominator coefficient moves where that improves the fit and the proof passes, as far
    /// as the move cap and no farther, and every candidate is counted. 1/(1 + d·x) with the
    /// numerator fixed at 1, from d = 0.5, on 33 samples of d* = 0.5 + 2^-10 over [0, 1]
    /// (denominator ≥ 1 on the box for every candidate): d* is 2^14 ulps (2^-24 each in
    /// [0.5, 1)) above the start, and each step up lowers every residual, so the search takes
    /// the largest, +64 ulps = 2^-18, in its first sweep (its 14 candidates ±1, ±2, …, ±64 all
    /// within the cap) and nothing in its second, where of the moves from there only the 7
    /// down (−1 … −64 ulps, back to at most the start) are within the cap: 1 + 14 + 7
    /// evaluations in 2 sweeps, counted by hand.
    #[test]
    fn a_denominator_coefficient_moves_to_the_cap_and_every_candidate_counts() {
        let m = over_denominator(&["x"], vec![(0, 1.0)]);
        let target = 0.5 + 2f64.powi(-10);
        let d = samples(0.0, 1.0, 33, |x| 1.0 / (1.0 + target * x));
        let r = round_and_reoptimise(&m, &DVector::from_vec(vec![1.0, 0.5]), &d, &[(0.0, 1.0)], &RoundOptions::new(Objective::Lsq, None), "cap")
            .unwrap();
        assert_eq!((r.num.as_slice(), r.den.as_slice()), (&[1.0f32][..], &[0.5 + 2f32.powi(-18)][..]), "{r:?}");
        assert_eq!((r.sweeps, r.evaluations), (2, 22));
    }

    #[test]
    fn pins_and_positivity_survive_the_search() {
        // A rational with both ends pinned (as gloss_length is), fitted minimax.
        let feats = vec!["x".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &feats).unwrap()).collect::<Vec<_>>();
        let target = |x: f64| 0.3 + x.powf(1.5) / (0.4 + x);
        let m = RationalModel::new(ModelParts {
            inputs: feats.clone(),
            numerator: terms(&["1", "x", "x^2", "x^3"]),
            denominator: terms(&["x", "x^2"]),
            pins: vec![Pin { at: vec![0.0], value: target(0.0), eliminate: 0 }, Pin { at: vec![1.0], value: target(1.0), eliminate: 3 }],
            ..ModelParts::default()
        })
        .unwrap();
        let d = samples(0.0, 1.0, 257, target);
        let f = fit(&m, &d, &FitOptions { objective: Objective::Minimax, ..FitOptions::default() }, "pinned").unwrap();
        let r = round_and_reoptimise(&m, &f.coefficients, &d, &[(0.0, 1.0)], &RoundOptions::new(Objective::Minimax, None), "pinned")
            .unwrap();
        let e = expr::model_expr(&m);
        for p in &m.pins {
            let x = [p.at[0] as f32];
            let got = expr::eval_f32(&e, &x, &r.num, &r.den) as f64;
            let (n0, d0) = rounded(&m, &f.coefficients);
            let start = expr::eval_f32(&e, &x, &n0, &d0) as f64;
            // The pin's tolerance: the rounded vector's error there, or one ulp of the value
            // (2^-23 for values in [1, 2), 2^-25 in [0.25, 0.5)).
            let ulp = (step_ulps(p.value as f32, 1).unwrap() - p.value as f32) as f64;
            assert!((got - p.value).abs() <= (start - p.value).abs().max(ulp), "pin at {:?}: {got} vs {}", p.at, p.value);
        }
        // Not vacuous: the search moved something (measured: one numerator coefficient).
        assert_ne!((r.num.clone(), r.den.clone()), rounded(&m, &f.coefficients));
        assert!(matches!(prove_denominator_positive(&m, &widen(&r.num, &r.den), &[(0.0, 1.0)]), Positivity::Proven { .. }));
    }

    /// A pin the data pull against holds to one ulp of its value. The line c0 + c1 x pinned to
    /// f(0) = 1.001 over samples of 1 + x: the least-squares fit keeps the pin and leaves a
    /// positive mean residual (0.001 − 0.0015·x averages 2.5e-4), so lowering c0 lowers the
    /// objective for hundreds of ulps. The search may move c0 only as far as the pin allows:
    /// max(the rounded vector's error there, one ulp of 1.001 in f32, 2^-23).
    #[test]
    fn a_pin_against_the_data_holds_to_one_ulp() {
        let feats = vec!["x".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &feats).unwrap()).collect::<Vec<_>>();
        let m = RationalModel::new(ModelParts {
            inputs: feats.clone(),
            numerator: terms(&["1", "x"]),
            pins: vec![Pin { at: vec![0.0], value: 1.001, eliminate: 0 }],
            ..ModelParts::default()
        })
        .unwrap();
        let d = samples(0.0, 1.0, 129, |x| 1.0 + x);
        let f = fit(&m, &d, &FitOptions { objective: Objective::Lsq, ..FitOptions::default() }, "against").unwrap();
        let r = round_and_reoptimise(&m, &f.coefficients, &d, &[(0.0, 1.0)], &RoundOptions::new(Objective::Lsq, None), "against")
            .unwrap();
        let (n0, _) = rounded(&m, &f.coefficients);
        let ulp = 2f64.powi(-23);
        let start = (n0[0] as f64 - 1.001).abs();
        assert!((r.num[0] as f64 - 1.001).abs() <= start.max(ulp), "c0 = {} moved off the pin (rounded {})", r.num[0], n0[0]);
        // Not vacuous: the rms with c0 lowered by 64 ulps (the move cap) is below that of the
        // rounded vector, so an unpinned search would take it.
        let rms = |c0: f32| {
            let s: f64 = d.x.iter().zip(&d.y).map(|(x, y)| (c0 as f64 + n0[1] as f64 * x[0] - y).powi(2)).sum();
            (s / d.y.len() as f64).sqrt()
        };
        assert!(rms(step_ulps(n0[0], -64).unwrap()) < rms(n0[0]));
    }
}
