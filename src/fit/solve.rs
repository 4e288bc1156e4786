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

/// Start candidates: the polynomial fit (Q ≡ 1 where the constraints allow), then Loeb's
/// linearisation and each of its Sanathanan–Koerner re-weightings, solved by SVD.
pub fn linearised_starts(model: &RationalModel, data: &Data, what: &str) -> Result<Vec<DVector<f64>>, FitError> {
    let nn = model.numerator.len();
    let nfull = model.n_full();
    let rows: Vec<usize> = (0..data.len())
        .filter(|&i| match model.clamp {
            // Samples at the clamp carry no information about P/Q beyond an inequality.
            Some((lo, hi)) => data.y[i] > lo && data.y[i] < hi,
            None => true,
        })
        .collect();
    if rows.len() < model.n_free() {
        return Err(FitError::Underdetermined { what: what.into(), n: rows.len(), p: model.n_free() });
    }
    let basis: Vec<_> = rows.iter().map(|&i| model.basis(&data.x[i])).collect();
    let mut inv_q = vec![1.0; rows.len()];
    let mut starts = Vec::new();
    for sk in 0..7 {
        let mut a = DMatrix::zeros(rows.len(), nfull);
        let mut rhs = DVector::zeros(rows.len());
        for (r, (&i, b)) in rows.iter().zip(&basis).enumerate() {
            let yv = data.y[i] - model.offset;
            for (j, phi) in b.phi.iter().enumerate() {
                a[(r, j)] = inv_q[r] * b.factor * phi;
            }
            for (j, psi) in b.psi.iter().enumerate() {
                a[(r, nn + j)] = -inv_q[r] * yv * psi;
            }
            rhs[r] = inv_q[r] * yv * b.lead;
        }
        let rhs = rhs - &a * model.map0();
        let mut a = a * model.map();
        if sk == 0 {
            // Polynomial start: free parameters that move the denominator are held at 0.
            let den_rows = model.map().rows(nn, nfull - nn).into_owned();
            for j in 0..a.ncols() {
                if den_rows.column(j).iter().any(|v| *v != 0.0) {
                    a.column_mut(j).fill(0.0);
                }
            }
        }
        // Column scaling makes the SVD's rank decision independent of feature units.
        let scale: Vec<f64> = (0..a.ncols()).map(|j| a.column(j).norm()).map(|n| if n > 0.0 { n } else { 1.0 }).collect();
        let mut a_s = a.clone();
        for (j, s) in scale.iter().enumerate() {
            a_s.column_mut(j).scale_mut(1.0 / s);
        }
        if !a_s.iter().chain(rhs.iter()).all(|v| v.is_finite()) {
            continue;
        }
        let Some(svd) = a_s.try_svd(true, true, f64::EPSILON, 10_000) else { continue };
        let Ok(t) = svd.solve(&rhs, 1e-13) else { continue };
        let t = DVector::from_iterator(t.len(), t.iter().zip(&scale).map(|(v, s)| v / s));
        if !t.iter().all(|v| v.is_finite()) {
            continue;
        }
        let c = model.full(&t);
        starts.push(t);
        if sk == 0 {
            continue;
        }
        for (r, &i) in rows.iter().enumerate() {
            let q = model.denominator_at(&c, &data.x[i]);
            // Stop re-weighting through a sign change of Q: keep the previous weights there.
            if q.abs() > 1e-8 {
                inv_q[r] = 1.0 / q.abs();
            }
        }
    }
    if starts.is_empty() {
        return Err(FitError::SingularStart { what: what.into() });
    }
    Ok(starts)
}

/// The LM settings of every least-squares solve here.
fn lm_solver() -> LevenbergMarquardt<f64> {
    LevenbergMarquardt::new().with_ftol(1e-15).with_xtol(1e-15).with_gtol(0.0).with_patience(LM_PATIENCE)
}

/// LM's evaluation cap is `LM_PATIENCE · (free parameters + 1)`.
const LM_PATIENCE: usize = 400;

/// When a watched LM run counts as stalled: at an accepted step, its rss fell by Δ over the
/// last ≥ `WINDOW` evaluations, and at that rate the evaluations left before LM's cap would
/// lower it by less than `SHARE` of itself. The run is then stopped with `lower` = `REACH`·rss
/// as the least rss the full run is taken to reach, and [`fit`] runs it again in full unless a
/// finished valid start beats even that. A crawl can end (the bench's gloss_combine_3_2: a
/// start stopped under a 1e-3 share at 50 evaluations with its lower bound at 0.999 rss went
/// on to win), hence the strict share and the wide reach.
struct Stall;

impl Stall {
    const WINDOW: usize = 200;
    const SHARE: f64 = 1e-6;
    const REACH: f64 = 0.1;
}

/// A [`Residuals`] problem that counts LM's evaluations and stops the run (its Jacobian
/// reports "none", which ends LM at the last accepted point) once it has [`Stall`]ed.
struct Watched<'a> {
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
fn least_squares_watched(problem: &mut Residuals<'_>, what: &str) -> Result<(DVector<f64>, usize, Option<f64>), FitError> {
    let (w, report) = lm_solver().minimize(Watched::new(problem.clone()));
    let theta = finite_lm_result(w.inner.theta.clone(), &report, what)?;
    problem.theta.copy_from(&theta);
    Ok((theta, report.number_of_evaluations, w.stalled.get()))
}

/// An LM run's parameters, or `Diverged` when any is not finite.
fn finite_lm_result(theta: DVector<f64>, report: &levenberg_marquardt::MinimizationReport<f64>, what: &str) -> Result<DVector<f64>, FitError> {
    if theta.iter().all(|v| v.is_finite()) {
        Ok(theta)
    } else {
        Err(FitError::Diverged { what: what.into(), iters: report.number_of_evaluations, residual: report.objective_function })
    }
}

fn least_squares(
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

fn l4(
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

fn minimax(
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
    fn unit_step() -> Data {
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

    use crate::fit::model::{ModelParts, Term};

    /// A vector's bit patterns, to compare results bit for bit.
    fn bits(v: &DVector<f64>) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn parts_1d(num: &[&str], den: &[&str]) -> ModelParts {
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
    fn remeasure(model: &RationalModel, f: &Fit, data: &Data) -> (f64, f64, f64) {
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

    fn done(valid: bool, rss: f64) -> Option<Outcome> {
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

    /// The first start is the least-squares polynomial (Q ≡ 1): on samples of a quadratic it is
    /// the quadratic itself, with the denominator coefficient 0.
    #[test]
    fn the_polynomial_start_is_the_polynomial() {
        let model = RationalModel::rational_1d("x", 2, 1);
        let x: Vec<Vec<f64>> = (0..=30).map(|i| vec![i as f64 / 10.0]).collect();
        let data = Data { y: x.iter().map(|p| 1.0 + 2.0 * p[0] - p[0] * p[0]).collect(), x };
        let starts = linearised_starts(&model, &data, "quadratic").unwrap();
        let s = model.full(&starts[0]);
        // An SVD solve of a 31×3 system with exact data: rounding, ~1e-14.
        for (c, w) in s.iter().zip([1.0, 2.0, -1.0, 0.0]) {
            assert!((c - w).abs() < 1e-12, "{s:?}");
        }
    }

    /// On samples of an exact rational the linearised problem P − y·Q = 0 is consistent, so
    /// every reweighted (Loeb, Sanathanan–Koerner) start is the rational itself, whatever the
    /// weights: x over [0, 30] makes the columns' norms span ~1e5, so the column scaling and
    /// its undoing are exercised too. Fixed coefficients enter the linearisation as a known
    /// part: with the numerator's constant and the denominator's x² fixed at their true values
    /// (nonzero, so the model's constant map is not zero) the system is still consistent in the
    /// free coefficients, and every start has the fixed ones exactly.
    #[test]
    fn every_reweighted_start_recovers_an_exact_rational() {
        let want = [1.0, 2.0, -0.05, 0.5, 0.01];
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![0.75 * i as f64]).collect();
        let y = x.iter().map(|p| {
            let t = p[0];
            (want[0] + want[1] * t + want[2] * t * t) / (1.0 + want[3] * t + want[4] * t * t)
        });
        let data = Data { y: y.collect(), x };
        let free = RationalModel::rational_1d("x", 2, 2);
        let fixed = RationalModel::new(ModelParts { fixed: vec![(0, want[0]), (4, want[4])], ..parts_1d(&["1", "x", "x^2"], &["x", "x^2"]) }).unwrap();
        assert_eq!((free.n_free(), fixed.n_free()), (5, 3));
        for (model, what) in [(&free, "exact"), (&fixed, "fixed")] {
            let starts = linearised_starts(model, &data, what).unwrap();
            assert_eq!(starts.len(), 7, "{what}: the polynomial start and six reweighted ones");
            for (k, s) in starts.iter().enumerate().skip(1) {
                let c = model.full(s);
                for &(i, v) in &model.fixed {
                    assert_eq!(c[i], v, "{what} start {k}: the fixed coefficient {i}");
                }
                // SVD solves of a 41×5 consistent system, condition ~1e5 after scaling: ~1e-11.
                for (j, (got, w)) in c.iter().zip(want).enumerate() {
                    assert!((got - w).abs() < 1e-8 * w.abs().max(1.0), "{what} start {k}, coefficient {j}: {got} vs {w}");
                }
            }
        }
    }

    /// Loeb's linearisation of f = offset + factor·P/(lead + D) is (y − offset)·(lead + D) =
    /// factor·P: on samples of such an exact rational (offset 0.5, factor 1 + x, lead 1 + x²,
    /// P = 1 + 2x, D = 0.5x, on 41 points of [0, 2]) it is consistent, so every reweighted
    /// start is the rational itself. Taken as y + offset, or with the lead dividing instead of
    /// multiplying, the system is inconsistent and its solution is not the rational.
    #[test]
    fn the_linearised_starts_take_the_offset_factor_and_lead_as_the_model_does() {
        let f = vec!["x".to_string()];
        let term = |t: &str| Term::parse(t, &f).unwrap();
        let model = RationalModel::new(ModelParts {
            offset: 0.5,
            factor: Some(term("1 + x")),
            lead: Some(term("1 + x^2")),
            ..parts_1d(&["1", "x"], &["x"])
        })
        .unwrap();
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![i as f64 / 20.0]).collect();
        let data = Data { y: x.iter().map(|p| 0.5 + (1.0 + p[0]) * (1.0 + 2.0 * p[0]) / (1.0 + p[0] * p[0] + 0.5 * p[0])).collect(), x };
        let starts = linearised_starts(&model, &data, "olf").unwrap();
        assert_eq!(starts.len(), 7);
        for (k, s) in starts.iter().enumerate().skip(1) {
            // SVD solves of a consistent 41×3 system, condition ~10 after scaling: ~1e-14.
            for (c, w) in model.full(s).iter().zip([1.0, 2.0, 0.5]) {
                assert!((c - w).abs() < 1e-9, "start {k}: {s:?}");
            }
        }
    }

    /// Sanathanan–Koerner: start k ≥ 2 minimises Σ ((P − y·Q)/|Q_{k−1}|)², the linearised
    /// residual weighted by the previous start's denominator. On data no [1/1] rational fits
    /// (exp on [0, 2]) the weights matter, so the test checks that start's normal equations with
    /// the weights computed here: the weighted residual is orthogonal to every weighted column.
    #[test]
    fn each_reweighted_start_solves_the_linearisation_weighted_by_the_last_denominator() {
        let model = RationalModel::rational_1d("x", 1, 1);
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![0.05 * i as f64]).collect();
        let data = Data { y: x.iter().map(|p| p[0].exp()).collect(), x };
        let starts = linearised_starts(&model, &data, "exp").unwrap();
        assert_eq!(starts.len(), 7);
        for k in 2..starts.len() {
            let (prev, c) = (model.full(&starts[k - 1]), model.full(&starts[k]));
            let mut rows = Vec::new();
            for (p, &y) in data.x.iter().zip(&data.y) {
                let b = model.basis(p);
                let w = 1.0 / b.pq(&prev).1.abs();
                // Columns: ∂(P − y·Q)/∂(a0, a1, b1) = (φ0, φ1, −y·ψ1), weighted.
                let col = [w * b.phi[0], w * b.phi[1], -w * y * b.psi[0]];
                let (num, den) = b.pq(&c);
                rows.push((col, w * (num - y * den)));
            }
            let e_norm = rows.iter().map(|r| r.1 * r.1).sum::<f64>().sqrt();
            // exp is no [1/1] rational: the weighted residual cannot vanish (‖e‖ ≈ 0.24 here).
            assert!(e_norm > 1e-4, "start {k}: residual {e_norm}");
            for j in 0..3 {
                let dot: f64 = rows.iter().map(|r| r.0[j] * r.1).sum();
                let col_norm = rows.iter().map(|r| r.0[j] * r.0[j]).sum::<f64>().sqrt();
                // An SVD least-squares solve of a 41×3 system (condition ≈ 16 after column
                // scaling) leaves Jᵀe at rounding, of order ε·16 ≈ 4e-15 of ‖J_j‖·‖e‖; weights
                // other than 1/|Q_{k−1}| leave it O(1e-1).
                assert!(dot.abs() < 1e-9 * col_norm * e_norm, "start {k}, column {j}: Jᵀe {dot:e} vs {:e}", col_norm * e_norm);
            }
        }
    }

    /// The linearised starts do not depend on the feature's units: x times 2³⁰ scales the
    /// columns of x^k by 2^(30k) exactly, the column scaling takes that out, and every start's
    /// coefficient of x^k comes back times 2^(−30k), bit for bit. Unscaled, the columns' norms
    /// would span ~1e18 and the SVD's rank decision (1e-13 relative) would drop x²'s.
    #[test]
    fn linearised_starts_are_equivariant_in_the_features_scale() {
        let model = RationalModel::rational_1d("x", 2, 2);
        let sx = 2f64.powi(30);
        let x: Vec<Vec<f64>> = (0..=40).map(|i| vec![0.075 * i as f64]).collect();
        let y: Vec<f64> = x.iter().map(|p| (1.0 + 2.0 * p[0]).ln() + 0.3).collect();
        let a = linearised_starts(&model, &Data { x: x.clone(), y: y.clone() }, "unit").unwrap();
        let b = linearised_starts(&model, &Data { x: x.iter().map(|p| vec![p[0] * sx]).collect(), y }, "scaled").unwrap();
        assert_eq!(a.len(), b.len());
        // Powers of x in the free parameters: numerator 1, x, x²; denominator x, x².
        let degree = [0, 1, 2, 1, 2];
        for (k, (sa, sb)) in a.iter().zip(&b).enumerate() {
            let want: Vec<f64> = sa.iter().zip(degree).map(|(v, d)| v * sx.powi(-d)).collect();
            assert_eq!(sb.as_slice(), want.as_slice(), "start {k}");
        }
    }

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

    /// A rational of degrees (2, 1) in x and eleven samples of zero on [0, 1].
    fn zero_data() -> (RationalModel, Data) {
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

