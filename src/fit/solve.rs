//! Solvers for rational fits, chosen by the caller:
//!
//! 1. **Linearised start** (no user start values): Loeb's linearisation
//!    (y − offset)·Q = factor·P is linear in the coefficients; a few Sanathanan–Koerner
//!    re-weightings by 1/Q of the previous iterate remove its bias. Solved by SVD.
//! 2. **Least squares**: Levenberg–Marquardt (MINPACK's, from the `levenberg-marquardt`
//!    crate) on the analytic Jacobian; or argmin's Gauss–Newton with a Moré–Thuente line search.
//! 3. **Minimax**: Lawson's iteratively re-weighted least squares (weights w_i ← w_i·|r_i|,
//!    each weighted problem solved by LM from the previous iterate, best iterate kept), then
//!    a sequential-LP trust-region polish ([`super::minimax::SlpMinimax`], an argmin Solver),
//!    kept only if it improves.
//! 4. **L4**: minimise Σ r⁴ by iteratively re-weighted least squares (w_i = r_i² of the previous
//!    iterate): between least squares and minimax, it lowers the max error without giving up
//!    the rms error (what a table fit is usually judged by: both).
//!
//! Here the options, the drivers and the choice among starts; `starts.rs` the linearised
//! starts, `lm.rs` the watched Levenberg–Marquardt least squares, `reweighted.rs` the Lawson
//! minimax and Σr⁴ iterations.

use super::model::RationalModel;
use super::minimax::SlpMinimax;
use super::problem::{Data, Residuals};
use super::positivity::{prove_denominator_positive, Positivity};
use super::report::FitReport;
use argmin::core::{Executor, State};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

mod lm;
mod reweighted;
mod starts;
pub use starts::linearised_starts;
use lm::*;
use reweighted::*;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Objective {
    Lsq,
    Minimax,
    L4,
}

impl Objective {
    /// The name `FromStr` and the specs take.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Lsq => "lsq",
            Objective::Minimax => "minimax",
            Objective::L4 => "l4",
        }
    }
}

impl std::str::FromStr for Objective {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "lsq" => Ok(Objective::Lsq),
            "minimax" => Ok(Objective::Minimax),
            "l4" => Ok(Objective::L4),
            other => Err(format!("unknown objective '{other}' (expected lsq, minimax or l4)")),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LsqSolver {
    /// MINPACK Levenberg–Marquardt (levenberg-marquardt crate).
    Lm,
    /// argmin Gauss–Newton with Moré–Thuente line search.
    GaussNewton,
}

#[derive(Debug, Clone, Copy)]
pub struct FitOptions {
    pub objective: Objective,
    pub solver: LsqSolver,
    /// Outer iterations of Lawson's algorithm (minimax).
    pub minimax_iters: usize,
    /// Iterations of the sequential-LP minimax polish (0 disables it).
    pub polish_iters: u64,
    /// Minimax under an rms cap: the Lawson iterate with the lowest max error among those
    /// whose rms error is at most this (the least-squares start is the fallback); no polish.
    pub max_rms: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions { objective: Objective::Lsq, solver: LsqSolver::Lm, minimax_iters: 300, polish_iters: 200, max_rms: None }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("{what}: no data to fit")]
    NoData { what: String },
    #[error("{what}: {n} samples cannot determine {p} free coefficients")]
    Underdetermined { what: String, n: usize, p: usize },
    #[error("{what}: the linearised start is singular (the basis is degenerate on these samples)")]
    SingularStart { what: String },
    #[error("{what}: the fit diverged after {iters} iterations (residual {residual:e})")]
    Diverged { what: String, iters: usize, residual: f64 },
    #[error("{what}: denominator not provably positive on the domain: Q ≥ {lower:e} on the box {region:?}")]
    PoleInDomain { what: String, lower: f64, region: Vec<(f64, f64)> },
    #[error("{what}: solver failed: {msg}")]
    Solver { what: String, msg: String },
    #[error("{what}: {source}")]
    Model {
        what: String,
        #[source]
        source: crate::fit::model::ModelError,
    },
}

/// A fitted model: free parameters, full coefficients and the report on the fitting data.
#[derive(Debug, Clone)]
pub struct Fit {
    pub theta: DVector<f64>,
    pub coefficients: DVector<f64>,
    pub report: FitReport,
}

/// [`fit`] of data in any units: values and inputs far from 1 are divided by powers of two
/// before solving (exactly, so nothing is rounded) and the coefficients and the report are
/// returned in the data's units. Values or inputs near 1e±300 otherwise overflow (or underflow)
/// the residual sums and the monomials: a singular start, or an rss of 0.
///
/// - Values: divided by 2^k near their largest magnitude when |k| ≥ 64, with the model's
///   offset, fixed numerator coefficients, pins and clamp; numerator coefficients and the
///   report are multiplied back.
/// - Inputs: input i is divided by 2^{k_i} near its largest magnitude when |k_i| ≥ 64. A
///   monomial Π x_i^{e_i} then scales by S = 2^{Σ k_i e_i}, and its coefficient by 1/S. This
///   is done only where it is exact: every monomial of a term scales alike (terms tie
///   monomials under one coefficient) and the model has no derived
///   features, denominator lead term or factor (they do not scale by a power of two). Where it
///   is not, the inputs are fitted as given.
///
/// Data within 2^±64 of 1 is fitted unscaled, exactly as by [`fit`]. `theta` and the condition
/// number are the scaled problem's.
pub fn fit_rescaled(model: &RationalModel, data: &Data, opts: &FitOptions, what: &str) -> Result<Fit, FitError> {
    let exponent = |top: f64| -> i32 {
        let k = if top > 0.0 && top.is_finite() { top.log2().round() as i32 } else { 0 };
        if k.abs() < 64 { 0 } else { k }
    };
    let ky = exponent(data.y.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    let n_in = model.n_inputs;
    let mut kx: Vec<i32> =
        (0..n_in).map(|i| exponent(data.x.iter().fold(0.0f64, |m, x| m.max(x[i].abs())))).collect();
    let term_scale = |t: &crate::fit::model::Term, kx: &[i32]| -> Option<i32> {
        let mut scales = t.monomials.iter().map(|m| m.exps.iter().zip(kx).map(|(&e, &k)| e as i32 * k).sum::<i32>());
        let first = scales.next().unwrap_or(0);
        scales.all(|s| s == first).then_some(first)
    };
    let x_scalable = kx.iter().any(|&k| k != 0)
        && model.derived.is_empty()
        && model.lead.is_none()
        && model.factor.is_none()
        && model.numerator.iter().chain(&model.denominator).all(|t| term_scale(t, &kx).is_some());
    if !x_scalable {
        kx.iter_mut().for_each(|k| *k = 0);
    }
    if ky == 0 && kx.iter().all(|&k| k == 0) {
        return fit(model, data, opts, what);
    }
    let yscale = 2f64.powi(ky);
    let nn = model.numerator.len();
    // Power-of-two scale exponent of each coefficient's term: numerator terms, then
    // denominator terms (2^t itself may be past f64's range; coefficients times it are not).
    let s: Vec<i32> = model.numerator.iter().chain(&model.denominator).map(|t| term_scale(t, &kx).unwrap_or(0)).collect();
    let xscale: Vec<f64> = kx.iter().map(|&k| 2f64.powi(k)).collect();
    let parts = crate::fit::model::ModelParts {
        inputs: model.features[..model.n_inputs].to_vec(),
        derived: model.derived.clone(),
        numerator: model.numerator.clone(),
        denominator: model.denominator.clone(),
        lead: model.lead.clone(),
        offset: model.offset / yscale,
        factor: model.factor.clone(),
        fixed: model.fixed.iter().map(|&(i, v)| (i, if i < nn { times_pow2(v, s[i]) / yscale } else { times_pow2(v, s[i]) })).collect(),
        pins: model
            .pins
            .iter()
            .map(|p| crate::fit::model::Pin {
                at: p.at.iter().zip(&xscale).map(|(a, sc)| a / sc).collect(),
                value: p.value / yscale,
                ..p.clone()
            })
            .collect(),
        clamp: model.clamp.map(|(a, b)| (a / yscale, b / yscale)),
    };
    let scaled = RationalModel::new(parts).map_err(|e| FitError::Model { what: what.into(), source: e })?;
    let y: Vec<f64> = data.y.iter().map(|v| v / yscale).collect();
    let x: Vec<Vec<f64>> = data.x.iter().map(|row| row.iter().zip(&xscale).map(|(v, sc)| v / sc).collect()).collect();
    let mut f = fit(&scaled, &Data { x, y }, opts, what)?;
    for (j, c) in f.coefficients.iter_mut().enumerate() {
        *c = if j < nn { times_pow2(*c * yscale, -s[j]) } else { times_pow2(*c, -s[j]) };
    }
    let r = &mut f.report;
    r.rss *= yscale * yscale;
    r.max_abs_error *= yscale;
    r.rms_error *= yscale;
    r.worst_residual *= yscale;
    for (w, sc) in r.worst_point.iter_mut().zip(&xscale) {
        *w *= sc;
    }
    Ok(f)
}

/// v·2^e in steps that stay inside f64's exponent range (exact unless the result is
/// subnormal, over- or underflows).
fn times_pow2(mut v: f64, mut e: i32) -> f64 {
    while e != 0 {
        let step = e.clamp(-1000, 1000);
        v *= 2f64.powi(step);
        e -= step;
    }
    v
}

/// Fit `model` to `data` from no start values.
pub fn fit(model: &RationalModel, data: &Data, opts: &FitOptions, what: &str) -> Result<Fit, FitError> {
    if data.is_empty() {
        return Err(FitError::NoData { what: what.into() });
    }
    if data.len() < model.n_free() {
        return Err(FitError::Underdetermined { what: what.into(), n: data.len(), p: model.n_free() });
    }
    // Multi-start: LM from every linearised candidate; keep the best least-squares optimum
    // whose denominator is provably positive on the data's bounding box (a rational with a pole
    // between samples can fit the samples and still be useless), else the best one.
    let starts = linearised_starts(model, data, what)?;
    let lsq = FitOptions { objective: Objective::Lsq, ..*opts };
    let (best, _) = multi_start(model, data, &lsq, what, &starts, true);
    let (_, best) = best.ok_or_else(|| FitError::SingularStart { what: what.into() })?;
    // The least-squares optimum is the answer for lsq; other objectives start from it.
    match opts.objective {
        Objective::Lsq => Ok(best),
        _ => fit_from(model, data, best.theta, opts, what),
    }
}

/// The least-squares multi-start of [`fit`]: (the chosen start and its validity, the number
/// of starts left stopped for stalling). `watch = false` runs every start in full.
fn multi_start(
    model: &RationalModel,
    data: &Data,
    lsq: &FitOptions,
    what: &str,
    starts: &[DVector<f64>],
    watch: bool,
) -> (Option<(bool, Fit)>, usize) {
    let domain = data.bounds();
    // The starts are independent: solved in parallel, then compared in their order. A start
    // whose LM run stalls (see `Stall`) is stopped there; it is run again in full unless a
    // finished valid start already beats the least-squares error its progress allows it, so
    // the choice is that of full runs while a start stuck far above the best costs ~100
    // evaluations instead of LM's cap (fits/gloss_combine.toml: one of seven starts crawls at
    // rss 4.854 against the winner's 0.102 until the cap of 3200).
    let run = |theta0: &DVector<f64>, first: bool| -> Option<Outcome> {
        let (f, stalled) = fit_start(model, data, theta0.clone(), lsq, what, watch && first).ok()?;
        Some(match stalled {
            Some(lower) => Outcome::Stalled { lower },
            None => {
                let valid =
                    matches!(prove_denominator_positive(model, &f.coefficients, &domain), Positivity::Proven { .. });
                Outcome::Done(valid, f)
            }
        })
    };
    let mut outcomes: Vec<Option<Outcome>> = starts.par_iter().map(|t| run(t, true)).collect();
    loop {
        let beaten = match best_done(&outcomes) {
            Some((true, b)) => b.report.rss,
            _ => f64::NEG_INFINITY,
        };
        let again: Vec<usize> = (0..outcomes.len())
            .filter(|&k| matches!(outcomes[k], Some(Outcome::Stalled { lower }) if !(lower > beaten)))
            .collect();
        if again.is_empty() {
            break;
        }
        let redone: Vec<Option<Outcome>> = again.par_iter().map(|&k| run(&starts[k], false)).collect();
        for (k, o) in again.into_iter().zip(redone) {
            outcomes[k] = o;
        }
    }
    let best = best_done(&outcomes).map(|(v, f)| (v, f.clone()));
    (best, outcomes.iter().filter(|o| matches!(o, Some(Outcome::Stalled { .. }))).count())
}

/// Fit from given free parameters.
pub fn fit_from(
    model: &RationalModel,
    data: &Data,
    theta0: DVector<f64>,
    opts: &FitOptions,
    what: &str,
) -> Result<Fit, FitError> {
    fit_start(model, data, theta0, opts, what, false).map(|(f, _)| f)
}

/// A refit of a published rational: [`fit`] (its linearised starts), else [`fit_from`] the
/// published coefficients `start`, with `opts`; the first whose denominator is proven positive on
/// `domain` (interval arithmetic), or `None` when neither is.
pub fn fit_proven_positive(model: &RationalModel, data: &Data, start: &[f64], opts: &FitOptions, domain: &[(f64, f64)], what: &str) -> Option<DVector<f64>> {
    let positive = |c: &DVector<f64>| matches!(prove_denominator_positive(model, c, domain), Positivity::Proven { .. });
    fit(model, data, opts, what)
        .ok()
        .map(|f| f.coefficients)
        .filter(|c| positive(c))
        .or_else(|| fit_from(model, data, DVector::from_vec(start.to_vec()), opts, what).ok().map(|f| f.coefficients).filter(|c| positive(c)))
}

/// A start of [`fit`]'s multi-start: a full run, or one stopped by [`Stall`] with the lowest
/// rss its progress allows it.
enum Outcome {
    Done(bool, Fit),
    Stalled { lower: f64 },
}

/// The best finished start by [`fit`]'s rule (valid before invalid, then the lower rss, the
/// earlier start on a tie), with its validity.
fn best_done(outcomes: &[Option<Outcome>]) -> Option<(bool, &Fit)> {
    let mut best: Option<(bool, &Fit)> = None;
    for o in outcomes {
        let Some(Outcome::Done(valid, f)) = o else { continue };
        let better = match best {
            None => true,
            Some((bv, b)) => (*valid && !bv) || (*valid == bv && f.report.rss < b.report.rss),
        };
        if better {
            best = Some((*valid, f));
        }
    }
    best
}

/// [`fit_from`], for a least-squares LM run optionally watched by [`Stall`]: with `Some(lower)`
/// when the run was stopped for stalling (the fit is then that of the point it stopped at).
fn fit_start(
    model: &RationalModel,
    data: &Data,
    theta0: DVector<f64>,
    opts: &FitOptions,
    what: &str,
    watch: bool,
) -> Result<(Fit, Option<f64>), FitError> {
    let mut problem = Residuals::new(model, data, theta0);
    let mut stalled = None;
    let (theta, iters, evals) = match opts.objective {
        // (the report below is always on plain, unweighted residuals)
        Objective::Lsq if watch && opts.solver == LsqSolver::Lm => {
            let (t, ev, lower) = least_squares_watched(&mut problem, what)?;
            stalled = lower;
            (t, ev, ev)
        }
        Objective::Lsq => {
            let (t, it, ev) = least_squares(&mut problem, opts.solver, what)?;
            (t, it, ev)
        }
        Objective::Minimax => minimax(&mut problem, opts, what)?,
        Objective::L4 => l4(&mut problem, opts, what)?,
    };
    problem.sqrt_w.iter_mut().for_each(|w| *w = 1.0);
    let report = FitReport::measure(&problem, data, &theta, opts, iters, evals);
    if !report.rss.is_finite() {
        return Err(FitError::Diverged { what: what.into(), iters, residual: report.rss });
    }
    Ok((Fit { coefficients: model.full(&theta), theta, report }, stalled))
}
#[cfg(test)]
mod tests {
    use super::*;

    /// The objective names `fit --objective` takes (`FromStr`) are the specs' (serde's
    /// lowercase variant names), and each parses back to its objective; another name is
    /// refused with the list.
    #[test]
    fn objective_names_parse_back() {
        for o in [Objective::Lsq, Objective::Minimax, Objective::L4] {
            assert_eq!(o.name().parse::<Objective>(), Ok(o));
            assert_eq!(serde_json::to_value(o).unwrap(), o.name());
        }
        let e = "l2".parse::<Objective>().unwrap_err();
        assert!(["'l2'", "lsq", "minimax", "l4"].iter().all(|w| e.contains(w)), "{e}");
    }

    /// A unit step at x = 0.3 sampled at 200 points of [0, 1]: some linearised starts of a
    /// rational fitted to it crawl.
    pub(super) fn unit_step() -> Data {
        let x: Vec<Vec<f64>> = (0..200).map(|i| vec![i as f64 / 199.0]).collect();
        Data { y: x.iter().map(|p| if p[0] < 0.3 { 0.0 } else { 1.0 }).collect(), x }
    }

    /// Starts stopped for stalling change nothing: the chosen fit is bit for bit the one of
    /// running every start in full. A unit step at x = 0.3 by a 2/3 and a 3/3 rational: some of
    /// the linearised starts crawl and are stopped. A stopped start is run again in full unless
    /// the chosen valid fit already beats the lower bound its own stopped run gives: the starts
    /// left stopped are exactly those whose bound is above the chosen rss (each start's watched
    /// run, alone, gives its bound). At 2/3 every stopped start is left so; at 3/3 three bounds
    /// (~0.26–0.29) are under the chosen rss (~1.02), so those starts must have been rerun.
    #[test]
    fn stalled_starts_do_not_change_the_choice() {
        let data = unit_step();
        let lsq = FitOptions::default();
        let (mut left_seen, mut rerun_seen) = (0, 0);
        for (m, n) in [(2, 3), (3, 3)] {
            let model = RationalModel::rational_1d("x", m, n);
            let starts = linearised_starts(&model, &data, "step").unwrap();
            let (watched, left) = multi_start(&model, &data, &lsq, "step", &starts, true);
            let (full, none) = multi_start(&model, &data, &lsq, "step", &starts, false);
            assert_eq!(none, 0);
            let ((wv, w), (fv, f)) = (watched.unwrap(), full.unwrap());
            assert!(wv, "[{m}/{n}]: the chosen fit is not proven valid: the bound rule below does not apply");
            assert_eq!(wv, fv);
            assert_eq!(bits(&w.theta), bits(&f.theta));
            assert_eq!(w.report.rss.to_bits(), f.report.rss.to_bits());
            let bounds: Vec<f64> = starts
                .iter()
                .filter_map(|t| fit_start(&model, &data, t.clone(), &lsq, "step", true).ok().and_then(|(_, lower)| lower))
                .collect();
            let above = bounds.iter().filter(|&&b| b > w.report.rss).count();
            assert_eq!(left, above, "[{m}/{n}]: stopped starts' bounds {bounds:?}, chosen rss {}", w.report.rss);
            left_seen += left;
            rerun_seen += bounds.len() - above;
            // The public entry point is the watched multi-start, and for least squares its
            // answer is the chosen run itself, no further run from it: the same parameters, and
            // the report counts that run's iterations and evaluations (a run restarted at the
            // optimum would report its own few).
            let public = fit(&model, &data, &lsq, "step").unwrap();
            assert_eq!(bits(&public.theta), bits(&f.theta));
            assert_eq!(
                (public.report.iterations, public.report.evaluations, public.report.rss.to_bits()),
                (w.report.iterations, w.report.evaluations, w.report.rss.to_bits())
            );
        }
        assert!(left_seen >= 1, "no start was left stopped: the test does not exercise the stop");
        assert!(rerun_seen >= 1, "no stopped start was rerun: the test does not exercise the rerun");
    }

    use crate::fit::model::{ModelParts, Term};

    /// A vector's bit patterns, to compare results bit for bit.
    pub(super) fn bits(v: &DVector<f64>) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    pub(super) fn parts_1d(num: &[&str], den: &[&str]) -> ModelParts {
        let f = vec!["x".to_string()];
        ModelParts {
            inputs: f.clone(),
            numerator: num.iter().map(|t| Term::parse(t, &f).unwrap()).collect(),
            denominator: den.iter().map(|t| Term::parse(t, &f).unwrap()).collect(),
            ..ModelParts::default()
        }
    }

    /// (rss, max abs, rms) of the fit's residuals, recomputed from its coefficients through
    /// `eval_full` in the data's own units.
    pub(super) fn remeasure(model: &RationalModel, f: &Fit, data: &Data) -> (f64, f64, f64) {
        let r: Vec<f64> = data.x.iter().zip(&data.y).map(|(x, y)| model.eval_full(&f.coefficients, x) - y).collect();
        let rss: f64 = r.iter().map(|v| v * v).sum();
        (rss, r.iter().fold(0.0f64, |m, v| m.max(v.abs())), (rss / r.len() as f64).sqrt())
    }

    /// Data 2^80 in value and 2^70 in input (both rescaled before solving): an exact rational
    /// with a fixed denominator coefficient is recovered, the fixed one exactly, and the report
    /// (in the data's units) is that of the returned coefficients.
    #[test]
    fn data_far_from_one_is_fitted_in_its_own_units() {
        let (ys, xs) = (2f64.powi(80), 2f64.powi(70));
        // P/Q = (1 + 2t − 0.5t²)/(1 + 0.3t + 0.2t²) of t = x/2^70, written in x: the coefficient
        // of x^k is that of t^k over 2^(70k), and the numerator's times 2^80.
        let want = [ys, 2.0 * ys / xs, -0.5 * ys / (xs * xs), 0.3 / xs, 0.2 / (xs * xs)];
        let model = RationalModel::new(ModelParts { fixed: vec![(3, want[3])], ..parts_1d(&["1", "x", "x^2"], &["x", "x^2"]) }).unwrap();
        let x: Vec<Vec<f64>> = (0..=60).map(|i| vec![xs * i as f64 / 20.0]).collect();
        let exact = |x: f64| {
            let t = x / xs;
            ys * (1.0 + 2.0 * t - 0.5 * t * t) / (1.0 + 0.3 * t + 0.2 * t * t)
        };
        let data = Data { y: x.iter().map(|p| exact(p[0])).collect(), x: x.clone() };
        let f = fit_rescaled(&model, &data, &FitOptions::default(), "scaled").unwrap();
        assert_eq!(f.coefficients[3], want[3], "the fixed coefficient");
        for (c, w) in f.coefficients.iter().zip(&want) {
            // Exact data, condition ~1e3 in the scaled problem: recovered to ~1e-12.
            assert!((c - w).abs() <= 1e-9 * w.abs(), "{c:e} vs {w:e}");
        }
        // Off the model (a ripple of 1 % of the values): the report is the returned fit's.
        let data = Data { y: x.iter().map(|p| exact(p[0]) * (1.0 + 0.01 * (7.0 * p[0] / xs).sin())).collect(), x };
        let f = fit_rescaled(&model, &data, &FitOptions::default(), "scaled").unwrap();
        let (rss, max, rms) = remeasure(&model, &f, &data);
        let r = &f.report;
        // Residuals of the scaled problem times exact powers of two: rounding of 61-term sums.
        assert!((r.rss - rss).abs() <= 1e-9 * rss && rss > 0.0, "rss {} vs {rss}", r.rss);
        assert!((r.max_abs_error - max).abs() <= 1e-9 * max, "max {} vs {max}", r.max_abs_error);
        assert!((r.worst_residual.abs() - max).abs() <= 1e-9 * max, "worst residual {} vs {max}", r.worst_residual);
        assert!((r.rms_error - rms).abs() <= 1e-9 * rms, "rms {} vs {rms}", r.rms_error);
    }

    /// Rescaling is by exact powers of two (of the data's largest magnitudes, rounded in log2:
    /// here 1 and 0.84, so 2^kx and 2^ky), so the fit of data 2^ky in value and 2^kx in input
    /// is the fit of the same data in units of one, its coefficients times 2^(ky − kx·k) for
    /// x^k in the numerator and 2^(−kx·k) in the denominator, bit for bit (off the model: a 1 %
    /// ripple), and so is its report. Values of 2^±1000 with inputs in units of one scale the
    /// values alone: fitted as given, their squares would overflow or underflow the residual
    /// sums (their sum of squares, 2^±2000 times the unit one, is outside f64 itself and is
    /// not compared). Inputs far from one with values of order one scale the inputs alone. The
    /// threshold is 2^64 either way: values 2^±64 (0.84 · 2^±64 rounds to ±64 in log2) are
    /// rescaled, so θ (the scaled problem's) is the unit fit's bit for bit; values 2^±63 are
    /// fitted as given, bit for bit [`fit`]'s fit of them, θ in their own units.
    #[test]
    fn rescaled_fits_are_the_unit_fit_times_powers_of_two() {
        let model = RationalModel::new(parts_1d(&["1", "x", "x^2"], &["x", "x^2"])).unwrap();
        let t: Vec<f64> = (0..=60).map(|i| i as f64 / 60.0).collect();
        let y = |t: f64| 0.5 * (1.0 + 2.0 * t - 0.5 * t * t) / (1.0 + 0.3 * t + 0.2 * t * t) * (1.0 + 0.01 * (7.0 * t).sin());
        let unit = Data { x: t.iter().map(|&t| vec![t]).collect(), y: t.iter().map(|&t| y(t)).collect() };
        let p2 = |k: i32| 2f64.powi(k);
        for objective in [Objective::Lsq, Objective::Minimax] {
            let opts = FitOptions { objective, ..FitOptions::default() };
            let a = fit(&model, &unit, &opts, "unit").unwrap();
            for (ky, kx) in [(80, 70), (1000, 0), (-1000, 0), (0, 70), (64, 0), (-64, 0)] {
                let scaled = Data { x: t.iter().map(|&t| vec![t * p2(kx)]).collect(), y: unit.y.iter().map(|v| v * p2(ky)).collect() };
                let b = fit_rescaled(&model, &scaled, &opts, "scaled").unwrap();
                assert_eq!(bits(&b.theta), bits(&a.theta), "2^{ky}, 2^{kx}: {objective:?} θ is the scaled problem's");
                let powers = [ky, ky - kx, ky - 2 * kx, -kx, -2 * kx];
                for (k, p) in powers.iter().enumerate() {
                    assert_eq!(b.coefficients[k], a.coefficients[k] * p2(*p), "2^{ky}, 2^{kx}: {objective:?} coefficient {k}");
                }
                // The report likewise: errors times 2^ky, the sum of squares times 2^(2ky), the
                // worst point times 2^kx; relative errors unchanged.
                let (ra, rb) = (&a.report, &b.report);
                assert_eq!(
                    (rb.max_abs_error, rb.rms_error, rb.worst_residual),
                    (ra.max_abs_error * p2(ky), ra.rms_error * p2(ky), ra.worst_residual * p2(ky)),
                    "2^{ky}, 2^{kx}: {objective:?}"
                );
                if ky.abs() < 500 {
                    assert_eq!(rb.rss, ra.rss * p2(2 * ky), "2^{ky}, 2^{kx}: {objective:?}");
                }
                assert_eq!(rb.worst_point, vec![ra.worst_point[0] * p2(kx)], "2^{ky}, 2^{kx}: {objective:?}");
                assert_eq!(rb.max_rel_error, ra.max_rel_error, "2^{ky}, 2^{kx}: {objective:?}");
            }
            for ky in [63, -63] {
                let near = Data { x: unit.x.clone(), y: unit.y.iter().map(|v| v * p2(ky)).collect() };
                let (b, c) = (fit_rescaled(&model, &near, &opts, "near").unwrap(), fit(&model, &near, &opts, "near").unwrap());
                assert_eq!((bits(&b.theta), bits(&b.coefficients)), (bits(&c.theta), bits(&c.coefficients)), "2^{ky}: {objective:?}");
                // θ in the data's units: the constant coefficient is of order 2^ky, not of one
                // (the unit fit's is 0.5 · 1, so a factor 2 either way is far from both).
                let ratio = b.theta[0] / a.theta[0] / p2(ky);
                assert!((0.5..2.0).contains(&ratio), "2^{ky}: {objective:?} θ₀ {:e} vs unit {:e}", b.theta[0], a.theta[0]);
            }
        }
    }

    /// For a polynomial (no denominator) the Jacobian is the design matrix [1, x, x²]: the
    /// report's condition number is its σmax/σmin, computed here by nalgebra's SVD of the matrix
    /// built by hand.
    #[test]
    fn the_condition_number_is_that_of_the_jacobian() {
        let model = RationalModel::rational_1d("x", 2, 0);
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![-1.0 + i as f64 / 10.0]).collect();
        let data = Data { y: x.iter().map(|p| (2.0 * p[0]).cos()).collect(), x: x.clone() };
        let f = fit(&model, &data, &FitOptions::default(), "poly").unwrap();
        let design = DMatrix::from_fn(x.len(), 3, |i, j| x[i][0].powi(j as i32));
        let sv = design.singular_values();
        let cond = sv.max() / sv.min();
        // Two SVDs of one 41×3 matrix: agreement to ~1e-14 of a condition number ~10.
        assert!(cond > 2.0 && (f.report.condition_number - cond).abs() <= 1e-10 * cond, "{} vs {cond}", f.report.condition_number);
    }

    pub(super) fn done(valid: bool, rss: f64) -> Option<Outcome> {
        let report = FitReport {
            objective: Objective::Lsq,
            samples: 1,
            rss,
            max_abs_error: 0.0,
            rms_error: 0.0,
            max_rel_error: 0.0,
            worst_point: vec![],
            worst_residual: 0.0,
            condition_number: 1.0,
            iterations: 0,
            evaluations: 0,
        };
        Some(Outcome::Done(valid, Fit { theta: DVector::from_element(1, rss), coefficients: DVector::zeros(0), report }))
    }

    /// The choice among finished starts, as documented: valid first, then the lower rss, the
    /// earlier start on a tie; stalled and missing starts are skipped.
    #[test]
    fn the_best_start_is_valid_then_lowest_rss_then_first() {
        let pick = |o: &[Option<Outcome>]| best_done(o).map(|(v, f)| (v, f.report.rss, f.theta[0]));
        assert_eq!(pick(&[done(true, 2.0), done(true, 1.0), done(true, 3.0)]), Some((true, 1.0, 1.0)));
        assert_eq!(pick(&[done(false, 0.5), done(true, 3.0), done(false, 0.1)]), Some((true, 3.0, 3.0)));
        assert_eq!(pick(&[done(false, 0.5), done(false, 0.2), None, Some(Outcome::Stalled { lower: 0.0 })]), Some((false, 0.2, 0.2)));
        assert_eq!(pick(&[done(true, 1.0), done(true, 3.0), done(true, 2.0)]), Some((true, 1.0, 1.0)));
        assert_eq!(pick(&[None, Some(Outcome::Stalled { lower: 0.0 })]), None);
        // A tie in rss and validity goes to the earlier start (θ tells the two apart).
        let mut later = done(true, 1.0);
        if let Some(Outcome::Done(_, f)) = &mut later {
            f.theta[0] = 7.0;
        }
        assert_eq!(pick(&[done(false, 0.5), done(true, 1.0), later]), Some((true, 1.0, 1.0)));
    }

    /// A rational of degrees (2, 1) in x and eleven samples of zero on [0, 1].
    pub(super) fn zero_data() -> (RationalModel, Data) {
        let x: Vec<Vec<f64>> = (0..=10).map(|i| vec![i as f64 / 10.0]).collect();
        (RationalModel::rational_1d("x", 2, 1), Data { y: vec![0.0; x.len()], x })
    }

    /// Lawson's weights are w_i·|r_i| normalised: on data the least-squares fit reproduces
    /// exactly (all zeros, fitted by the zero rational: its residuals are exactly 0) there is
    /// nothing to weight, and the iteration stops before any weighted solve. The minimax fit
    /// without polish then reports the one least-squares run it starts with: that of
    /// [`fit_from`] from the least-squares optimum.
    #[test]
    fn exact_zeros_take_no_lawson_step() {
        let (model, data) = zero_data();
        let lsq = fit(&model, &data, &FitOptions::default(), "zero").unwrap();
        assert_eq!(lsq.report.max_abs_error, 0.0, "the residuals are exactly zero: {:?}", lsq.coefficients);
        let again = fit_from(&model, &data, lsq.theta.clone(), &FitOptions::default(), "zero").unwrap();
        let minimax = fit(&model, &data, &FitOptions { objective: Objective::Minimax, polish_iters: 0, ..FitOptions::default() }, "zero").unwrap();
        assert_eq!((minimax.report.iterations, minimax.report.evaluations), (again.report.iterations, again.report.evaluations));
    }

    /// No samples at all is its own error, not an underdetermined fit, for every objective.
    #[test]
    fn no_data_is_refused_as_such() {
        let model = RationalModel::rational_1d("x", 1, 1);
        for objective in [Objective::Lsq, Objective::Minimax, Objective::L4] {
            let e = fit(&model, &Data { x: vec![], y: vec![] }, &FitOptions { objective, ..FitOptions::default() }, "empty").unwrap_err();
            assert!(matches!(e, FitError::NoData { .. }), "{objective:?}: {e}");
            assert_eq!(e.to_string(), "empty: no data to fit");
        }
    }

    /// As many samples as free parameters are enough: the fit interpolates them (here the
    /// rational (1 + x)/(1 + x/2) through three of its points, [1/1] having three free
    /// coefficients); one sample fewer is refused as underdetermined, naming both counts.
    #[test]
    fn as_many_samples_as_parameters_are_interpolated_and_fewer_refused() {
        let model = RationalModel::rational_1d("x", 1, 1);
        assert_eq!(model.n_free(), 3);
        let data = |xs: &[f64]| Data { x: xs.iter().map(|&x| vec![x]).collect(), y: xs.iter().map(|&x| (1.0 + x) / (1.0 + 0.5 * x)).collect() };
        let f = fit(&model, &data(&[0.0, 1.0, 2.0]), &FitOptions::default(), "three").unwrap();
        // Three equations in three unknowns, consistent: solved to rounding (condition ~10).
        for (got, want) in f.coefficients.iter().zip([1.0, 1.0, 0.5]) {
            assert!((got - want).abs() < 1e-12, "{:?}", f.coefficients);
        }
        match fit(&model, &data(&[0.0, 1.0]), &FitOptions::default(), "two") {
            Err(FitError::Underdetermined { what, n: 2, p: 3 }) => assert_eq!(what, "two"),
            other => panic!("{other:?}"),
        }
    }

    /// Data that is all zero has no scale to take out: the fit is the zero rational (the
    /// numerator 0, the denominator free but finite), and the report says zero error.
    #[test]
    fn all_zero_data_fits_the_zero_rational() {
        let (model, data) = zero_data();
        let f = fit_rescaled(&model, &data, &FitOptions::default(), "zero").unwrap();
        assert!(f.coefficients.iter().all(|c| c.is_finite()), "{:?}", f.coefficients);
        // Exact data: the numerator's least-squares solution is 0 to rounding.
        assert!(f.coefficients.rows(0, 3).amax() < 1e-12, "{:?}", f.coefficients);
        assert!(f.report.max_abs_error < 1e-12, "{:?}", f.report);
    }

    /// A pin given in the data's own units (x = 2^70 · 0.5, values of order 1, 2^-90 and 2^90)
    /// holds after the inputs and the values are rescaled: the fitted rational takes the pinned
    /// value there, to the rounding of the scaled problem.
    #[test]
    fn pins_far_from_one_hold_in_the_datas_units() {
        use crate::fit::model::Pin;
        let xs = 2f64.powi(70);
        for ys in [1.0, 2f64.powi(-90), 2f64.powi(90)] {
            let target = |x: f64| {
                let t = x / xs;
                ys * ((1.0 + 2.0 * t) / (1.0 + 0.5 * t) + 0.02 * (5.0 * t).sin())
            };
            let at = 0.5 * xs;
            let pinned = target(at) + 0.01 * ys;
            let model = RationalModel::new(ModelParts {
                pins: vec![Pin { at: vec![at], value: pinned, eliminate: 0 }],
                ..parts_1d(&["1", "x", "x^2"], &["x"])
            })
            .unwrap();
            let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![xs * i as f64 / 20.0]).collect();
            let data = Data { y: x.iter().map(|p| target(p[0])).collect(), x };
            let f = fit_rescaled(&model, &data, &FitOptions::default(), "pinned").unwrap();
            let v = model.eval_full(&f.coefficients, &[at]);
            // The pin eliminates a coefficient exactly; evaluation rounding of terms ~10 (times
            // the values' scale, a power of two): 1e-13.
            assert!((v - pinned).abs() < 1e-13 * ys, "values × {ys:e}: f({at:e}) = {v:e} vs pin {pinned:e}");
        }
    }

    /// With an rms cap the minimax iterates are kept only while their rms (√(Σr²/n)) is within
    /// it, and the polish (which knows no cap) is skipped: a cap 1.05× the least-squares rms
    /// still lets minimax lower the max error well below the least-squares one, and the result
    /// honours the cap.
    #[test]
    fn minimax_under_an_rms_cap_lowers_the_max_error_within_the_cap() {
        let model = RationalModel::rational_1d("x", 2, 1);
        let x: Vec<Vec<f64>> = (0..=100).map(|i| vec![i as f64 / 100.0]).collect();
        let data = Data { y: x.iter().map(|p| (3.0 * p[0]).sin()).collect(), x };
        let lsq = fit(&model, &data, &FitOptions::default(), "sin").unwrap();
        let minimax = FitOptions { objective: Objective::Minimax, ..FitOptions::default() };
        let free = remeasure(&model, &fit(&model, &data, &minimax, "sin").unwrap(), &data);
        let cap = 1.05 * lsq.report.rms_error;
        // The cap binds: the unconstrained minimax fit (Lawson then the LP polish) is above it
        // (measured: its rms is 1.105× the least-squares rms).
        assert!(free.2 > cap, "unconstrained minimax rms {} within the cap {cap}", free.2);
        let f = fit(&model, &data, &FitOptions { max_rms: Some(cap), ..minimax }, "sin").unwrap();
        let (_, max, rms) = remeasure(&model, &f, &data);
        assert!(rms <= cap, "rms {rms} over the cap {cap}");
        // Within 1.05× the least-squares rms, Lawson's iterates still lower the max error well
        // below least squares' (measured 0.73×); 0.9× is far from both the stopping tolerance
        // and a fit that never left the start.
        assert!(max < 0.9 * lsq.report.max_abs_error, "max {max} vs least squares {} (unconstrained {})", lsq.report.max_abs_error, free.1);
    }

    /// A clamped model is fitted on the samples strictly inside the clamp: y = clamp(P/Q, 0.5, 1)
    /// with P/Q below 0.5 at x ≤ 0.2 and above 1 past x = 0.8 recovers P/Q.
    #[test]
    fn a_clamped_model_recovers_the_rational_inside_the_clamp() {
        let model = RationalModel::new(ModelParts { clamp: Some((0.5, 1.0)), ..parts_1d(&["1", "x"], &["x"]) }).unwrap();
        let exact = |x: f64| (0.2 + 1.5 * x) / (1.0 + 0.5 * x);
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![i as f64 / 20.0]).collect();
        let data = Data { y: x.iter().map(|p| exact(p[0]).clamp(0.5, 1.0)).collect(), x };
        assert!(data.y.iter().filter(|&&y| y == 1.0).count() > 10, "part of the samples is at the upper clamp");
        // x = 0, 0.05, …, 0.2: P/Q(0.2) = 0.5/1.1 < 0.5 < P/Q(0.25) = 0.575/1.125.
        assert_eq!(data.y.iter().filter(|&&y| y == 0.5).count(), 5, "samples at the lower clamp");
        let f = fit(&model, &data, &FitOptions::default(), "clamped").unwrap();
        // Exact data on the rows that carry information: rounding level.
        for (c, w) in f.coefficients.iter().zip([0.2, 1.5, 0.5]) {
            assert!((c - w).abs() < 1e-9, "{:?}", f.coefficients);
        }
        // The reweighted linearised starts leave the samples at the clamp out (they are not
        // P/Q), so on the rest they are the rational itself: SVD rounding, ~1e-14.
        let starts = linearised_starts(&model, &data, "clamped").unwrap();
        for (k, st) in starts.iter().enumerate().skip(1) {
            for (c, w) in model.full(st).iter().zip([0.2, 1.5, 0.5]) {
                assert!((c - w).abs() < 1e-9, "start {k}: {st:?}");
            }
        }
    }

    /// Inputs far from one are rescaled only where every monomial of a term scales alike: a
    /// term x + x² (one coefficient, the monomials scaling by 2^70 and 2^140) is not, so data
    /// 2^70 in input is fitted as given, bit for bit [`fit`]'s fit, and an exact rational
    /// (1 + 2^-141·(x + x²))/(1 + 0.3·2^-70·x) is recovered in the data's units. Scaling x
    /// there would fit (1 + 2^-71·t + ½t²)/(1 + 0.3t) of t = x/2^70 by a single coefficient on
    /// t + t², which it cannot represent.
    #[test]
    fn a_term_whose_monomials_scale_unlike_is_fitted_unscaled() {
        let xs = 2f64.powi(70);
        let want = [1.0, 0.5 / (xs * xs), 0.3 / xs];
        let model = RationalModel::new(parts_1d(&["1", "x + x^2"], &["x"])).unwrap();
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![xs * i as f64 / 20.0]).collect();
        let y = |x: f64| (want[0] + want[1] * (x + x * x)) / (1.0 + want[2] * x);
        let data = Data { y: x.iter().map(|p| y(p[0])).collect(), x };
        let opts = FitOptions::default();
        let f = fit_rescaled(&model, &data, &opts, "unlike").unwrap();
        let g = fit(&model, &data, &opts, "unlike").unwrap();
        assert_eq!(bits(&f.coefficients), bits(&g.coefficients));
        for (c, w) in f.coefficients.iter().zip(&want) {
            // Exact data; LM scales its columns, so the raw units cost it little: 1e-9 relative
            // is far inside the misfit of the scaled model (order one in the values).
            assert!((c - w).abs() <= 1e-9 * w.abs(), "{c:e} vs {w:e}");
        }
    }

    /// A model with a derived feature is fitted as given, whatever its inputs' units: u = b·x is
    /// not scaled by a power of two with x (b is fixed in the model), so inputs 2^70 are not
    /// rescaled and the fit is bit for bit [`fit`]'s. Here u = 1e-21·x puts u in [0, 2.4] and
    /// the data is the exact rational (1 + 2u)/(1 + 0.5u), recovered. Rescaling x would leave u
    /// of order 1e-21 and (1 + a·u)/(1 + b·u) nearly constant: the data could not be fitted.
    #[test]
    fn a_model_with_a_derived_feature_is_fitted_in_its_inputs_units() {
        let xs = 2f64.powi(70);
        let inputs = vec!["x".to_string()];
        let derived = vec![crate::fit::model::Derived::parse("u", "1e-21*x", &inputs).unwrap()];
        let features = vec!["x".to_string(), "u".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|t| Term::parse(t, &features).unwrap()).collect::<Vec<_>>();
        let model = RationalModel::new(ModelParts { inputs, derived, numerator: terms(&["1", "u"]), denominator: terms(&["u"]), ..ModelParts::default() }).unwrap();
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![xs * i as f64 / 20.0]).collect();
        let data = Data { y: x.iter().map(|p| (1.0 + 2e-21 * p[0]) / (1.0 + 0.5e-21 * p[0])).collect(), x };
        let opts = FitOptions::default();
        let (f, g) = (fit_rescaled(&model, &data, &opts, "derived").unwrap(), fit(&model, &data, &opts, "derived").unwrap());
        assert_eq!((bits(&f.theta), bits(&f.coefficients)), (bits(&g.theta), bits(&g.coefficients)));
        // Exact data, condition ~10 in u: recovered to rounding (1e-9 is far inside the misfit
        // of a fit on rescaled inputs, order one).
        for (c, w) in f.coefficients.iter().zip([1.0, 2.0, 0.5]) {
            assert!((c - w).abs() < 1e-9, "{:?}", f.coefficients);
        }
    }

    /// An offset of data far from one (values 2⁻⁹⁰ and 2⁸⁰) is in the data's units: y = ys·(0.5 +
    /// (0.2 + 1.5x)/(1 + 0.5x)) with the model's offset 0.5·ys recovers P/Q with P times ys.
    /// The scaled problem's offset is 0.5 (the offset over the same power of two as the data);
    /// left in the data's units it would be off by a factor 2^±80 or more, and no P/Q fits.
    #[test]
    fn an_offset_far_from_one_holds_in_the_datas_units() {
        for ys in [2f64.powi(-90), 2f64.powi(80)] {
            let model = RationalModel::new(ModelParts { offset: 0.5 * ys, ..parts_1d(&["1", "x"], &["x"]) }).unwrap();
            let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![i as f64 / 20.0]).collect();
            let data = Data { y: x.iter().map(|p| ys * (0.5 + (0.2 + 1.5 * p[0]) / (1.0 + 0.5 * p[0]))).collect(), x };
            let f = fit_rescaled(&model, &data, &FitOptions::default(), "offset").unwrap();
            // Exact data, condition ~10: rounding, relative 1e-9 of each coefficient's units.
            for (c, w) in f.coefficients.iter().zip([0.2 * ys, 1.5 * ys, 0.5]) {
                assert!((c - w).abs() < 1e-9 * w.abs(), "values × {ys:e}: {:?}", f.coefficients);
            }
        }
    }

    /// y = (0.2 + 1.5x)/(1 + 0.5x)·ys on 41 points of [0, 2], clamped to `clamp`·ys when given,
    /// fitted by [`fit_rescaled`] with P's constant fixed at 0.2·ys (and the clamp in the data's
    /// units): the data, and the fit checked to hold the fixed coefficient exactly and recover
    /// the free ones to rounding (exact data on the rows inside any clamp: relative 1e-9 of
    /// their units).
    fn fit_the_fixed_rational(ys: f64, clamp: Option<(f64, f64)>) -> Data {
        let parts = ModelParts { fixed: vec![(0, 0.2 * ys)], clamp: clamp.map(|(a, b)| (a * ys, b * ys)), ..parts_1d(&["1", "x"], &["x"]) };
        let model = RationalModel::new(parts).unwrap();
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![i as f64 / 20.0]).collect();
        let y = |x: f64| {
            let v = (0.2 + 1.5 * x) / (1.0 + 0.5 * x);
            ys * clamp.map_or(v, |(a, b)| v.clamp(a, b))
        };
        let data = Data { y: x.iter().map(|p| y(p[0])).collect(), x };
        let f = fit_rescaled(&model, &data, &FitOptions::default(), "fixed").unwrap();
        assert_eq!(f.coefficients[0], 0.2 * ys, "the fixed coefficient, exactly");
        assert!((f.coefficients[1] - 1.5 * ys).abs() < 1e-9 * ys && (f.coefficients[2] - 0.5).abs() < 1e-9, "{:?}", f.coefficients);
        data
    }

    /// A fixed numerator coefficient of data far from one (values 2⁻⁹⁰ and 2⁸⁰, past the 2^±64
    /// that is fitted unscaled) holds in the data's units: the scaled problem fixes it divided
    /// by the same power of two as the data, so the fit of an exact rational reports the fixed
    /// value and recovers the others.
    #[test]
    fn fixed_coefficients_far_from_one_hold_in_the_datas_units() {
        for ys in [2f64.powi(-90), 2f64.powi(80)] {
            fit_the_fixed_rational(ys, None);
        }
    }

    /// A clamp of data far from one (2⁻⁹⁰ and 2⁸⁰) is in the data's units: the scaled problem
    /// clamps at the clamp divided by the data's power of two. y = clamp(P/Q, 0.25, 1)·2^k with
    /// P/Q = (0.2 + 1.5x)/(1 + 0.5x) below the clamp at x = 0 and above it past x = 0.8, and
    /// P's constant fixed, recovers P/Q. A clamp left in the data's units would be empty, or take
    /// the clamped samples for P/Q.
    #[test]
    fn a_clamp_far_from_one_holds_in_the_datas_units() {
        for ys in [2f64.powi(-90), 2f64.powi(80)] {
            let data = fit_the_fixed_rational(ys, Some((0.25, 1.0)));
            assert_eq!(data.y[0], 0.25 * ys, "the first sample is at the lower clamp");
            assert!(data.y.iter().filter(|&&y| y == ys).count() > 10, "part of the samples is at the upper clamp");
        }
    }
}
