//! Globally adaptive quadrature of vector integrands `f: f64 → [f64; N]` by bisection: the one
//! engine behind [`super::adaptive()`] (N = 1) and the families' vector integrals.
//!
//! All N components are integrated on shared panels (each integrand evaluation serves every
//! component). The run starts with one panel per given interval, then repeatedly bisects the
//! worst panel until the error test of its [`Control`] passes or the panel limit is reached.
//!
//! # Contract (tested in this module against closed forms)
//!
//! - **Estimates.** Every panel carries, per component, an error estimate from the difference
//!   of the rule's two quadratures ([`PanelError`]). For integrands smooth on the scale of the
//!   panels it is an upper estimate of the panel's true error (not a proven bound: the
//!   lower-order rule's error stands in for the higher-order one's; a feature no node sees is
//!   missed). The reported error is the sum over panels; the rounding of the sums (a few ulps of
//!   the value) is in QUADPACK's floor but not in the raw estimate.
//! - **Tolerance.** The run ends when the summed estimate meets the target of its [`Control`]
//!   (checked before every bisection), so a returned error is ≤ the target unless a limit below
//!   ended the run first.
//! - **Order.** The panel to bisect is the one with the largest error (for
//!   [`Control::PerComponent`]: largest relative to its component's target, over the components
//!   still above target); ties go to the panel further left. Final values are summed in position
//!   order. The bits of a result therefore depend only on the integrand and the options.
//! - **Panel limit.** Each bisection adds one panel; the run stops once the panel count reaches
//!   `max_panels` (or the number of initial intervals, if that is larger), whatever the error.
//!   With one interval that is at most `max_panels − 1` bisections. The estimate is returned
//!   with its (then unmet) error.
//! - **Unsplittable panels.** A panel whose midpoint is not strictly inside it in f64 is never
//!   split: its error moves to a "stuck" sum that stays in the reported error, and its own
//!   becomes 0. Should such a panel, error 0, still be the one picked (only possible without
//!   `stop_when_exhausted`, when no panel has error left), the run ends there rather than pick
//!   it forever.
//!
//! # Options, and who uses which
//!
//! The callers grew from three separate copies whose arithmetic is kept bit for bit; the
//! differences are options here ([`Options`], presets [`Options::scalar`],
//! [`Options::quadpack`], [`Options::per_component`]):
//!
//! | option | [`super::adaptive()`] (scalar integrals, tests) | [`Options::quadpack`] (mapped multi-node integrands) | [`Options::per_component`] (RGB on split intervals) |
//! |---|---|---|---|
//! | [`Rule`] | K21 | K21, or a GL32/GL24 pair (an outer integral) | K21 |
//! | [`PanelError`] | raw \|K − G\| | QUADPACK | raw \|K − G\| |
//! | [`Control`] | `Weighted([1])`, abs + rel | `Weighted(w)`, abs | `PerComponent`, abs[c] + rel |
//! | `stop_when_exhausted` | yes | no | yes |
//! | `stop_when_non_finite` | no | yes | no |
//! | `sum_from_negative_zero` | yes (`Iterator::sum`) | no | no |
//! | intervals | one | one | several (the kinks) |
//!
//! Why: the scalar rule is the plain QAG loop with the raw (generous) estimate. Mapped
//! integrands whose raw estimates are orders of magnitude too pessimistic use QUADPACK's; an
//! integrand that carries up to 15 nodes of an outer K15 rule at once controls their sum
//! weighted by the rule's weights (nodes with their own integration get weight 0), and an outer
//! integral can carry the inner error estimates as an unchecked component. RGB integrands take
//! each channel to its own tolerance, on intervals split at the integrand's kinks. Which family
//! integral uses which preset is said where it calls the engine.
//!
//! The stop and sum rows only matter in degenerate cases (every panel estimate 0, an infinite
//! or NaN estimate, every panel value −0.0) but change bits there, so they stay options.

// The QUADPACK constants keep their published digits.
#![allow(clippy::excessive_precision)]

use super::gauss_legendre;

/// Gauss–Kronrod 10/21 abscissae (QUADPACK qk21), the non-negative half of [-1, 1].
const XGK21: [f64; 11] = [
    0.995657163025808080735527280689003,
    0.973906528517171720077964012084452,
    0.930157491355708226001207180059508,
    0.865063366688984510732096688423493,
    0.780817726586416897063717578345042,
    0.679409568299024406234327365114874,
    0.562757134668604683339000099272694,
    0.433395394129247190799265943165784,
    0.294392862701460198131126603103866,
    0.148874338981631210884826001129720,
    0.000000000000000000000000000000000,
];
/// Kronrod 21-point weights for [`XGK21`].
const WGK21: [f64; 11] = [
    0.011694638867371874278064396062192,
    0.032558162307964727478818972459390,
    0.054755896574351996031381300244580,
    0.075039674810919952767043140916190,
    0.093125454583697605535065465083366,
    0.109387158802297641899210590325805,
    0.123491976262065851077208626368508,
    0.134709217311473325928054001771707,
    0.142775938577060080797094273138717,
    0.147739104901338491374841515972068,
    0.149445554002916905664936468389821,
];
/// Gauss 10-point weights for the odd-indexed Kronrod nodes 1, 3, 5, 7, 9.
const WG10: [f64; 5] = [
    0.066671344308688137593568809893332,
    0.149451349150580593145776339657697,
    0.219086362515982043995534934228163,
    0.269266719309996355091226921569469,
    0.295524224714752870173892994651338,
];

/// A pair of Gauss–Legendre rules (n_hi > n_lo points) on [-1, 1] used as a panel rule: the
/// value from the larger, the error from the difference of the two. For analytic integrands
/// this is conservative (the larger rule's error is far below |Q_hi − Q_lo|), and one panel of
/// a high-order pair often suffices where G10/K21 would need several bisections.
#[derive(Debug, Clone)]
pub struct GaussPair {
    hi: (Vec<f64>, Vec<f64>),
    lo: (Vec<f64>, Vec<f64>),
}

impl GaussPair {
    pub fn new(n_hi: usize, n_lo: usize) -> Self {
        GaussPair { hi: gauss_legendre(n_hi), lo: gauss_legendre(n_lo) }
    }
}

/// The quadrature pair applied to each panel.
#[derive(Debug, Clone, Copy)]
pub enum Rule<'r> {
    /// Gauss–Kronrod G10/K21 (QUADPACK qk21): value K21, 21 evaluations. Exact for polynomials
    /// of degree ≤ 31 (its Gauss part to degree 19).
    Kronrod21,
    /// A [`GaussPair`]: value from the larger rule, n_hi + n_lo evaluations.
    GaussPair(&'r GaussPair),
}

/// How a panel's error is estimated from its two quadratures Q_hi, Q_lo (per component, all
/// quantities scaled by the half-width).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PanelError {
    /// |Q_hi − Q_lo|: the error of the lower-order rule, a generous bound for Q_hi.
    Raw,
    /// QUADPACK's [`quadpack_error`]: far closer to the true error of Q_hi on smooth
    /// integrands, and still above it.
    Quadpack,
}

/// QUADPACK's error estimate of one panel from raw = |Q_hi − Q_lo|, resasc = ∫|f − mean| and
/// resabs = ∫|f| (all by the higher rule, scaled by the half-width):
/// resasc · min(1, (200 raw / resasc)^{3/2}), floored at 50 ε resabs (ε = f64 epsilon).
pub fn quadpack_error(raw: f64, resasc: f64, resabs: f64) -> f64 {
    let mut err = raw;
    if resasc != 0.0 && err != 0.0 {
        err = resasc * (200.0 * err / resasc).powf(1.5).min(1.0);
    }
    err.max(50.0 * f64::EPSILON * resabs)
}

/// Which error is controlled, and against what.
#[derive(Debug, Clone, Copy)]
pub enum Control<const N: usize> {
    /// One error per panel: Σ_i w_i·e_i over the components with w_i ≠ 0 (the others are
    /// integrated along, unchecked, and get no estimate). The run stops when the sum over panels
    /// (plus stuck panels) is ≤ max(abs, rel·|Σ_i w_i·V_i|), V_i the current component values;
    /// the panel with the largest weighted error is bisected.
    Weighted { weights: [f64; N], abs: f64, rel: f64 },
    /// Every component on its own: component c is done when its summed error (stuck panels
    /// first, then the panels) is ≤ max(abs[c], rel·|V_c|); the run stops when all are. The
    /// panel bisected is the one with the largest e_c / target_c over the components not done
    /// (ties to the left). A component whose error is NaN counts as done.
    PerComponent { abs: [f64; N], rel: f64 },
}

/// Settings of [`integrate`]; see the module doc for which caller uses which.
#[derive(Debug, Clone, Copy)]
pub struct Options<'r, const N: usize> {
    pub rule: Rule<'r>,
    pub estimate: PanelError,
    pub control: Control<N>,
    /// Stop when this many panels exist (raised to the number of intervals).
    pub max_panels: usize,
    /// Stop when no panel has an error left to reduce (every weighted panel error is 0, or,
    /// per component, every score is 0), even if stuck panels keep the error above target.
    /// Without it such a run keeps bisecting (leftmost first) until the panel limit, or until
    /// the panel it picks cannot be split.
    pub stop_when_exhausted: bool,
    /// Stop as soon as the controlled error is infinite or NaN (for `PerComponent`: any
    /// component's). Without it the non-finite panel is bisected like any other (NaN sorts
    /// above every number).
    pub stop_when_non_finite: bool,
    /// Start the final position-order sums at −0.0, as `Iterator::sum` does (a result made of
    /// −0.0 panels is then −0.0), rather than at +0.0. Differs only when every panel value of a
    /// component is −0.0.
    pub sum_from_negative_zero: bool,
}

impl Options<'static, 1> {
    /// The scalar rule of [`super::adaptive()`]: K21 with the raw |K21 − G10| estimate, stop at
    /// max(tol.abs, tol.rel·|value|) or when every panel estimate is 0.
    pub fn scalar(tol: super::Tolerance) -> Self {
        Options {
            rule: Rule::Kronrod21,
            estimate: PanelError::Raw,
            control: Control::Weighted { weights: [1.0], abs: tol.abs, rel: tol.rel },
            max_panels: tol.max_panels,
            stop_when_exhausted: true,
            stop_when_non_finite: false,
            sum_from_negative_zero: true,
        }
    }
}

impl<const N: usize> Options<'static, N> {
    /// K21 with QUADPACK estimates, weighted by `weights`, to absolute `tol`; stops on a
    /// non-finite error (mapped multi-node integrands).
    pub fn quadpack(weights: [f64; N], tol: f64, max_panels: usize) -> Self {
        Options {
            rule: Rule::Kronrod21,
            estimate: PanelError::Quadpack,
            control: Control::Weighted { weights, abs: tol, rel: 0.0 },
            max_panels,
            stop_when_exhausted: false,
            stop_when_non_finite: true,
            sum_from_negative_zero: false,
        }
    }

    /// K21 with raw estimates, every component to max(abs[c], rel·|value_c|) (RGB integrands).
    pub fn per_component(abs: [f64; N], rel: f64, max_panels: usize) -> Self {
        Options {
            rule: Rule::Kronrod21,
            estimate: PanelError::Raw,
            control: Control::PerComponent { abs, rel },
            max_panels,
            stop_when_exhausted: true,
            stop_when_non_finite: false,
            sum_from_negative_zero: false,
        }
    }
}

/// Result of [`integrate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VecEstimate<const N: usize> {
    /// Component integrals, panels summed in position order.
    pub value: [f64; N],
    /// Per component: stuck panels' estimates, then every panel's, summed (unchecked components
    /// of [`Control::Weighted`]: 0).
    pub errors: [f64; N],
    /// The controlled error: for [`Control::Weighted`] the weighted sum the stop test compared;
    /// for [`Control::PerComponent`] the largest of `errors`.
    pub error: f64,
    /// Integrand evaluations.
    pub evals: u64,
}

#[derive(Clone, Copy)]
struct Panel<const N: usize> {
    a: f64,
    b: f64,
    value: [f64; N],
    error: [f64; N],
    /// Weighted error (Control::Weighted; 0 otherwise).
    weighted: f64,
}

/// Adaptive integration of `f` over the union of `intervals` (one initial panel each, in the
/// order given; they should not overlap). See the module doc for the contract.
pub fn integrate<const N: usize>(
    intervals: &[(f64, f64)],
    opts: &Options<'_, N>,
    mut f: impl FnMut(f64) -> [f64; N],
) -> VecEstimate<N> {
    let checked: [bool; N] = match opts.control {
        Control::Weighted { weights, .. } => std::array::from_fn(|i| weights[i] != 0.0),
        Control::PerComponent { .. } => [true; N],
    };
    let mut panel = |a: f64, b: f64| -> (Panel<N>, u64) {
        let ((value, error), n) = match opts.rule {
            Rule::Kronrod21 => (kronrod21(a, b, opts.estimate, &checked, &mut f), 21),
            Rule::GaussPair(pair) => {
                (gauss_pair(pair, a, b, opts.estimate, &checked, &mut f), (pair.hi.0.len() + pair.lo.0.len()) as u64)
            }
        };
        let weighted = match opts.control {
            Control::Weighted { weights, .. } => {
                let mut w = 0.0;
                for i in (0..N).filter(|&i| checked[i]) {
                    w += weights[i] * error[i];
                }
                w
            }
            Control::PerComponent { .. } => 0.0,
        };
        (Panel { a, b, value, error, weighted }, n)
    };

    let mut panels: Vec<Panel<N>> = Vec::with_capacity(8);
    let mut evals = 0u64;
    for &(a, b) in intervals {
        let (p, n) = panel(a, b);
        panels.push(p);
        evals += n;
    }
    let max_panels = opts.max_panels.max(panels.len());
    let mut stuck = [0.0; N];
    let mut stuck_weighted = 0.0;
    loop {
        let (worst, error) = match opts.control {
            Control::Weighted { weights, abs, rel } => {
                let error = panels.iter().map(|p| p.weighted).sum::<f64>() + stuck_weighted;
                let (values, _) = totals(&panels, stuck);
                let mut value = 0.0;
                for i in (0..N).filter(|&i| checked[i]) {
                    value += weights[i] * values[i];
                }
                let done = error <= abs.max(rel * value.abs())
                    || panels.len() >= max_panels
                    || (opts.stop_when_exhausted && panels.iter().all(|p| p.weighted == 0.0))
                    || (opts.stop_when_non_finite && !error.is_finite());
                let worst = if done {
                    None
                } else {
                    panels
                        .iter()
                        .enumerate()
                        .max_by(|(_, p), (_, q)| p.weighted.total_cmp(&q.weighted).then(q.a.total_cmp(&p.a)))
                        .map(|(k, _)| k)
                };
                (worst, error)
            }
            Control::PerComponent { abs, rel } => {
                let (val, err) = totals(&panels, stuck);
                let error = err.iter().copied().fold(0.0, f64::max);
                let target: [f64; N] = std::array::from_fn(|i| abs[i].max(rel * val[i].abs()));
                let open: [bool; N] = std::array::from_fn(|i| err[i] > target[i]);
                let done = !open.iter().any(|&o| o)
                    || panels.len() >= max_panels
                    || (opts.stop_when_non_finite && err.iter().any(|e| !e.is_finite()));
                let worst = if done {
                    None
                } else {
                    let score = |p: &Panel<N>| -> f64 {
                        (0..N)
                            .filter(|&i| open[i])
                            .map(|i| p.error[i] / target[i].max(f64::MIN_POSITIVE))
                            .fold(0.0, f64::max)
                    };
                    panels
                        .iter()
                        .enumerate()
                        .map(|(k, p)| (k, score(p)))
                        .max_by(|(ka, sa), (kb, sb)| sa.total_cmp(sb).then(panels[*kb].a.total_cmp(&panels[*ka].a)))
                        .filter(|&(_, best)| !(opts.stop_when_exhausted && best == 0.0))
                        .map(|(k, _)| k)
                };
                (worst, error)
            }
        };
        // A panel that cannot be split and has no error left would be picked again forever.
        let worst = worst.filter(|&k| {
            let p = &panels[k];
            let mid = 0.5 * (p.a + p.b);
            !(mid <= p.a || mid >= p.b) || p.weighted != 0.0 || p.error.iter().any(|&e| e != 0.0)
        });
        let Some(worst) = worst else {
            let (_, errors) = totals(&panels, stuck);
            // Sum in position order for a result independent of the refinement history.
            panels.sort_by(|p, q| p.a.total_cmp(&q.a));
            let mut value = [if opts.sum_from_negative_zero { -0.0 } else { 0.0 }; N];
            for p in &panels {
                for (v, pv) in value.iter_mut().zip(p.value) {
                    *v += pv;
                }
            }
            return VecEstimate { value, errors, error, evals };
        };
        let p = panels.swap_remove(worst);
        let mid = 0.5 * (p.a + p.b);
        if mid <= p.a || mid >= p.b {
            // Too narrow to split in f64: keep its error in the estimate, never refine it.
            for (s, e) in stuck.iter_mut().zip(p.error) {
                *s += e;
            }
            stuck_weighted += p.weighted;
            panels.push(Panel { error: [0.0; N], weighted: 0.0, ..p });
            continue;
        }
        let (p1, n1) = panel(p.a, mid);
        let (p2, n2) = panel(mid, p.b);
        evals += n1 + n2;
        panels.push(p1);
        panels.push(p2);
    }
}

/// (Σ values from +0.0, stuck + Σ errors), both over the panels in their current order.
fn totals<const N: usize>(panels: &[Panel<N>], stuck: [f64; N]) -> ([f64; N], [f64; N]) {
    let mut val = [0.0; N];
    let mut err = stuck;
    for p in panels {
        for i in 0..N {
            val[i] += p.value[i];
            err[i] += p.error[i];
        }
    }
    (val, err)
}

/// One G10/K21 panel: (values, per-component errors; 0 for unchecked components).
fn kronrod21<const N: usize>(
    a: f64,
    b: f64,
    estimate: PanelError,
    checked: &[bool; N],
    f: &mut impl FnMut(f64) -> [f64; N],
) -> ([f64; N], [f64; N]) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let ha = h.abs();
    // Evaluation order: centre, then the pairs c ∓ dx from the outside in.
    let mut fv = [[0.0; N]; 21];
    fv[10] = f(c);
    for j in 0..10 {
        let dx = h * XGK21[j];
        fv[j] = f(c - dx);
        fv[20 - j] = f(c + dx);
    }
    let mut value = [0.0; N];
    let mut error = [0.0; N];
    for i in 0..N {
        let mut resk = WGK21[10] * fv[10][i];
        let mut resg = 0.0;
        for j in 0..10 {
            let s = fv[j][i] + fv[20 - j][i];
            resk += WGK21[j] * s;
            if j % 2 == 1 {
                resg += WG10[j / 2] * s;
            }
        }
        value[i] = resk * h;
        if !checked[i] {
            continue;
        }
        let raw = ((resk - resg) * ha).abs();
        error[i] = match estimate {
            PanelError::Raw => raw,
            PanelError::Quadpack => {
                let mut resabs = WGK21[10] * fv[10][i].abs();
                let mean = 0.5 * resk;
                let mut resasc = WGK21[10] * (fv[10][i] - mean).abs();
                for j in 0..10 {
                    resabs += WGK21[j] * (fv[j][i].abs() + fv[20 - j][i].abs());
                    resasc += WGK21[j] * ((fv[j][i] - mean).abs() + (fv[20 - j][i] - mean).abs());
                }
                quadpack_error(raw, resasc * ha, resabs * ha)
            }
        };
    }
    (value, error)
}

/// One panel of a Gauss–Legendre pair: (values, per-component errors).
fn gauss_pair<const N: usize>(
    pair: &GaussPair,
    a: f64,
    b: f64,
    estimate: PanelError,
    checked: &[bool; N],
    f: &mut impl FnMut(f64) -> [f64; N],
) -> ([f64; N], [f64; N]) {
    let (xh, wh) = &pair.hi;
    let (xl, wl) = &pair.lo;
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let ha = h.abs();
    let fh: Vec<[f64; N]> = xh.iter().map(|x| f(c + h * x)).collect();
    let fl: Vec<[f64; N]> = xl.iter().map(|x| f(c + h * x)).collect();
    let mut value = [0.0; N];
    let mut error = [0.0; N];
    for i in 0..N {
        let qh: f64 = fh.iter().zip(wh).map(|(fx, w)| w * fx[i]).sum();
        value[i] = qh * h;
        if !checked[i] {
            continue;
        }
        let ql: f64 = fl.iter().zip(wl).map(|(fx, w)| w * fx[i]).sum();
        let raw = ((qh - ql) * ha).abs();
        error[i] = match estimate {
            PanelError::Raw => raw,
            PanelError::Quadpack => {
                let mean = 0.5 * qh;
                let resasc: f64 = fh.iter().zip(wh).map(|(fx, w)| w * (fx[i] - mean).abs()).sum();
                let resabs: f64 = fh.iter().zip(wh).map(|(fx, w)| w * fx[i].abs()).sum();
                quadpack_error(raw, resasc * ha, resabs * ha)
            }
        };
    }
    (value, error)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::integrate::{Tolerance, adaptive};

    /// ∫_a^b dx/(x² + ε²) = (atan(b/ε) − atan(a/ε))/ε: a peak of width ε at 0.
    fn peak(eps: f64) -> impl Fn(f64) -> f64 {
        move |x| 1.0 / (x * x + eps * eps)
    }
    fn peak_exact(eps: f64, a: f64, b: f64) -> f64 {
        ((b / eps).atan() - (a / eps).atan()) / eps
    }

    /// Each estimate with each control on one component, and the scalar preset, at absolute `tol`.
    fn variants(tol: f64, max_panels: usize) -> Vec<(&'static str, Options<'static, 1>)> {
        let w = Options::quadpack([1.0], tol, max_panels);
        let c = Options::per_component([tol], 0.0, max_panels);
        vec![
            ("weighted raw", Options { estimate: PanelError::Raw, ..w }),
            ("weighted quadpack", w),
            ("per-component raw", c),
            ("per-component quadpack", Options { estimate: PanelError::Quadpack, ..c }),
            ("scalar", Options::scalar(Tolerance { abs: tol, rel: 0.0, max_panels })),
        ]
    }

    #[test]
    fn one_kronrod_panel_is_exact_for_polynomials_to_degree_31() {
        // ∫_0^1 x^d dx = 1/(d+1). K21 is exact to degree 31, G10 to 19: above 19 the estimate
        // is the G10 error and must cover the (rounding-level) K21 error; to 31 the value is
        // the closed form to rounding.
        for d in 0..=31 {
            for (name, opts) in variants(0.0, 1) {
                let est = integrate(&[(0.0, 1.0)], &opts, |x| [x.powi(d)]);
                let exact = 1.0 / (d + 1) as f64;
                let err = (est.value[0] - exact).abs();
                assert_eq!(est.evals, 21, "{name} d={d}: one panel");
                assert!(err <= 16.0 * f64::EPSILON * exact, "{name} d={d}: {} vs {exact}", est.value[0]);
                if d >= 20 {
                    assert!(est.error >= err, "{name} d={d}: estimate {} < error {err}", est.error);
                    assert!(est.error > 16.0 * f64::EPSILON * exact, "{name} d={d}: the G10 error shows ({})", est.error);
                }
            }
        }
        // Beyond degree 31 one panel is no longer exact; the estimate still covers the error.
        for (name, opts) in variants(0.0, 1) {
            for d in [32, 40, 60] {
                let est = integrate(&[(0.0, 1.0)], &opts, |x| [x.powi(d)]);
                let err = (est.value[0] - 1.0 / (d + 1) as f64).abs();
                assert!(est.error >= err, "{name} d={d}: {} vs {err}", est.error);
            }
        }
    }

    #[test]
    fn gauss_pair_is_exact_to_its_degrees() {
        // GL32 is exact to degree 63, GL24 to 47: the estimate (difference) is rounding below 48.
        let pair = GaussPair::new(32, 24);
        for (name, opts) in variants(0.0, 1) {
            let opts = Options { rule: Rule::GaussPair(&pair), ..opts };
            for d in [0, 10, 47, 60, 63] {
                let est = integrate(&[(0.0, 1.0)], &opts, |x| [x.powi(d)]);
                let exact = 1.0 / (d + 1) as f64;
                let err = (est.value[0] - exact).abs();
                assert_eq!(est.evals, 56, "{name}");
                assert!(err <= 16.0 * f64::EPSILON * exact, "{name} d={d}: {} vs {exact}", est.value[0]);
                if d >= 48 {
                    // GL24's error is tiny here too: covered up to rounding.
                    assert!(err <= est.error + 16.0 * f64::EPSILON * exact, "{name} d={d}: {}", est.error);
                } else {
                    // Rounding, or QUADPACK's floor 50 ε ∫|f|.
                    assert!(est.error <= 64.0 * f64::EPSILON * exact, "{name} d={d}: {}", est.error);
                }
            }
            // On a panel that does not start at 0 (centre and half-width differ): exact too,
            // ∫_a^b x^d = (b^(d+1) − a^(d+1)) / (d+1), to rounding of sums of terms ≤ 2^47.
            for (a, b) in [(0.5, 2.0), (-3.0, -1.0)] {
                for d in [0, 7, 30, 47] {
                    let est = integrate(&[(a, b)], &opts, |x| [x.powi(d)]);
                    let exact = (b.powi(d + 1) - a.powi(d + 1)) / (d + 1) as f64;
                    assert!((est.value[0] - exact).abs() <= 64.0 * f64::EPSILON * exact.abs(), "{name} [{a}, {b}] d={d}: {} vs {exact}", est.value[0]);
                }
            }
        }
    }

    /// The Gauss pair's QUADPACK estimate from its definition: raw = |Q32 − Q24|, resasc =
    /// ∫|f − mean| and resabs = ∫|f| by the 32-point rule, all times the half-width, worked out
    /// here from the nodes of `gauss_legendre`, on two panels: [1, 3] of f(x) = x^60 / 3^60,
    /// where the estimate is the roundoff floor, and [0, 1] of √x, where it is
    /// resasc·(200 raw/resasc)^1.5 (both asserted, so each term of the definition is used).
    #[test]
    fn gauss_pair_quadpack_estimate_is_qk_from_its_parts() {
        type F = fn(f64) -> f64;
        let cases: [(F, f64, f64, bool); 2] = [(|x| (x / 3.0).powi(60), 2.0, 1.0, true), (|x| x.sqrt(), 0.5, 0.5, false)];
        for (f, c, h, floored) in cases {
            gauss_pair_estimate_from_parts(f, c, h, floored);
        }
    }

    fn gauss_pair_estimate_from_parts(f: fn(f64) -> f64, c: f64, h: f64, floored: bool) {
        let pair = GaussPair::new(32, 24);
        let rule = |n: usize| {
            let (x, w) = crate::integrate::gauss_legendre(n);
            x.iter().zip(&w).map(|(x, w)| w * f(c + h * x)).sum::<f64>()
        };
        let (q32, q24) = (rule(32), rule(24));
        let (x, w) = crate::integrate::gauss_legendre(32);
        let mean = 0.5 * q32;
        let resasc: f64 = x.iter().zip(&w).map(|(x, w)| w * (f(c + h * x) - mean).abs()).sum();
        let resabs: f64 = x.iter().zip(&w).map(|(x, w)| w * f(c + h * x).abs()).sum();
        let raw = ((q32 - q24) * h).abs();
        let want = quadpack_error(raw, resasc * h, resabs * h);
        let floor = 50.0 * f64::EPSILON * resabs * h;
        assert_eq!(want == floor, floored, "the estimate is the floor: {want:e} vs {floor:e}");
        assert!(floored || 200.0 * raw < resasc * h, "the estimate scales resasc by (200 raw/resasc)^1.5 < 1");
        let opts = Options { rule: Rule::GaussPair(&pair), ..Options::quadpack([1.0], 0.0, 1) };
        let est = integrate(&[(c - h, c + h)], &opts, |x| [f(x)]);
        // The same sums in the same order: equal to rounding.
        assert!(want > 0.0 && (est.error - want).abs() <= 1e-12 * want, "{} vs {want}", est.error);
        assert!((est.value[0] - q32 * h).abs() <= 1e-15 * est.value[0]);
    }

    /// One K21 panel with QUADPACK's estimate against QUADPACK itself: `scipy.integrate.quad(f,
    /// a, b, limit=1, full_output=1)` (scipy 1.17.1, the pinned version, QUADPACK's dqagse: one dqk21 panel,
    /// neval 21) gave these values and error estimates.
    #[test]
    fn one_kronrod_panel_gives_quadpacks_value_and_estimate() {
        type F = fn(f64) -> f64;
        let cases: [(&str, F, f64, f64, f64, f64, f64); 3] = [
            // The estimate is resasc itself ((200 raw / resasc)^1.5 > 1): the same sums as
            // QUADPACK in another order, so equal to a few ulps (1e-12 leaves room).
            ("1/(x²+0.01)", |x| 1.0 / (x * x + 0.01), -1.0, 1.0, 30.381916895831775, 34.74494563251439, 1e-12),
            // resasc·(200 raw/resasc)^1.5 with raw = |K21 − G10| ≈ 3e-3 of the value: raw's
            // rounding (~1e-16/3e-3 relative) enters at the power 1.5: 1e-9 leaves room.
            ("√x", |x: f64| x.sqrt(), 0.0, 1.0, 0.6666714560647555, 0.004949759040028709, 1e-9),
            // raw ≈ 1e-11 of the value, so its rounding is ~1e-5 relative, 1.5× in the
            // estimate: 1e-3. A wrong term of resasc moves it by more than 10 %.
            ("eˣ·cos 10x", |x: f64| x.exp() * (10.0 * x).cos(), 0.0, 1.0, -0.178899602876759, 1.8389000683061663e-12, 1e-3),
        ];
        for (name, f, a, b, value, error, tol) in cases {
            let est = integrate(&[(a, b)], &Options::quadpack([1.0], 0.0, 1), |x| [f(x)]);
            assert!((est.value[0] - value).abs() <= 1e-14 * value.abs(), "{name}: value {} vs QUADPACK {value}", est.value[0]);
            assert!((est.error - error).abs() <= tol * error, "{name}: estimate {:e} vs QUADPACK {error:e}", est.error);
        }
    }

    /// A constant integrand: K21 and the Gauss pair are exact to rounding, so raw and resasc
    /// are rounding noise and the estimate is QUADPACK's floor 50 ε ∫|f| = 50 ε · 3 · 2.
    #[test]
    fn a_constant_integrands_estimate_is_the_roundoff_floor() {
        let pair = GaussPair::new(32, 24);
        let floor = 50.0 * f64::EPSILON * 6.0;
        for (name, rule) in [("K21", Rule::Kronrod21), ("G32/G24", Rule::GaussPair(&pair))] {
            let opts = Options { rule, ..Options::quadpack([1.0], 0.0, 1) };
            let est = integrate(&[(0.0, 2.0)], &opts, |_| [3.0]);
            // ∫|f| is a weight sum times 3: its rounding is a few ulps.
            assert!((est.error - floor).abs() <= 1e-14 * floor, "{name}: estimate {:e} vs 50 ε ∫|f| = {floor:e}", est.error);
            assert!((est.value[0] - 6.0).abs() <= 1e-14, "{name}: value {}", est.value[0]);
        }
    }

    /// QUADPACK's qk21 rescales the raw difference only when both it and resasc are non-zero
    /// (`if (resasc /= 0 .and. abserr /= 0)`), then floors the estimate at 50 ε resabs; the
    /// values worked out by hand.
    #[test]
    fn quadpack_error_rescales_only_when_both_parts_are_non_zero() {
        // resasc = 0: the raw difference stands (above the floor 50 ε · 1 ≈ 1.1e-14).
        assert_eq!(quadpack_error(1e-3, 0.0, 1.0), 1e-3);
        // raw = 0: nothing to rescale, the floor alone.
        assert_eq!(quadpack_error(0.0, 1.0, 1.0), 50.0 * f64::EPSILON);
        // Both non-zero: 1 · (200 · 2e-4 / 1)^1.5 = 0.04^1.5 = 0.008, to the rounding of the
        // product and of powf (a few ulps of 0.008, each 1.7e-18).
        assert!((quadpack_error(2e-4, 1.0, 1.0) - 0.008).abs() <= 1e-17);
    }

    /// Per component, a component is done when its summed error is ≤ its target: an error of
    /// exactly 0 meets a target of 0, so a zero integrand (K21 and G10 both exactly 0) is one
    /// panel even where error-free panels would be bisected (without stop_when_exhausted).
    /// And stop_when_non_finite stops on a non-finite error only: a finite run goes on to its
    /// tolerance.
    #[test]
    fn per_component_targets_are_met_at_equality_and_finite_errors_do_not_stop() {
        let zero = Options { stop_when_exhausted: false, ..Options::per_component([0.0], 0.0, 10) };
        let est = integrate(&[(0.0, 1.0)], &zero, |_| [0.0]);
        assert_eq!((est.evals, est.value[0], est.error), (21, 0.0, 0.0));
        let f = peak(1e-3);
        let opts = Options { stop_when_non_finite: true, ..Options::per_component([1e-9], 0.0, 5000) };
        let est = integrate(&[(0.0, 1.0)], &opts, |x| [f(x)]);
        assert!(est.error <= 1e-9 && est.evals > 21, "{est:?}");
        assert!((est.value[0] - peak_exact(1e-3, 0.0, 1.0)).abs() <= est.error, "{est:?}");
    }

    /// A power-of-two scale of the integrand scales every node value, panel value and error
    /// estimate by the same power exactly (QUADPACK's ratio 200 raw/resasc is unchanged), so a
    /// run to a relative tolerance alone, whose target rel·|V| scales the same way, takes the
    /// same decisions: the same evaluations, the value and error scaled bit for bit. For each
    /// control: weighted (raw and QUADPACK estimates) and per component.
    #[test]
    fn a_power_of_two_scale_changes_no_decision_of_a_relative_run() {
        let f = peak(1e-3);
        let s = 2f64.powi(40);
        let weighted = |estimate| Options { estimate, control: Control::Weighted { weights: [1.0], abs: 0.0, rel: 1e-10 }, ..Options::quadpack([1.0], 0.0, 5000) };
        let runs = [
            ("scalar", Options::scalar(Tolerance { abs: 0.0, rel: 1e-10, max_panels: 5000 })),
            ("weighted raw", weighted(PanelError::Raw)),
            ("weighted quadpack", weighted(PanelError::Quadpack)),
            ("per-component raw", Options::per_component([0.0], 1e-10, 5000)),
        ];
        for (name, opts) in runs {
            let one = integrate(&[(0.0, 1.0)], &opts, |x| [f(x)]);
            let scaled = integrate(&[(0.0, 1.0)], &opts, |x| [s * f(x)]);
            assert!(one.evals > 21 && one.error <= 1e-10 * one.value[0], "{name}: {one:?}");
            assert_eq!(scaled.evals, one.evals, "{name}");
            assert_eq!((scaled.value[0], scaled.error), (s * one.value[0], s * one.error), "{name}");
        }
    }

    #[test]
    fn peaked_integrands_meet_the_tolerance_and_the_estimate_bounds_the_error() {
        for eps in [1e-1, 1e-2, 1e-3, 1e-4] {
            for (a, b) in [(0.0, 1.0), (-0.3, 1.0), (-1.0, 1.0)] {
                let exact = peak_exact(eps, a, b);
                for rel_tol in [1e-6, 1e-9, 1e-12] {
                    let tol = rel_tol * exact;
                    for (name, opts) in variants(tol, 100_000) {
                        let f = peak(eps);
                        let est = integrate(&[(a, b)], &opts, |x| [f(x)]);
                        let err = (est.value[0] - exact).abs();
                        let what = format!("{name} ε={eps} [{a}, {b}] tol={rel_tol}");
                        assert!(est.error <= tol, "{what}: estimate {} above tol {tol}", est.error);
                        assert!(err <= est.error, "{what}: error {err} above estimate {}", est.error);
                        assert_eq!(est.errors[0], est.error, "{what}");
                        assert!(est.evals < 21 * 2000, "{what}: {} evaluations", est.evals);
                    }
                }
            }
        }
    }

    #[test]
    fn relative_tolerance_of_the_scalar_rule() {
        // ∫_0^1 1/(x² + ε²) dx = atan(1/ε)/ε; abs 1e-9 alone would stop far earlier.
        let eps = 1e-3_f64;
        let exact = peak_exact(eps, 0.0, 1.0);
        let est = adaptive(0.0, 1.0, Tolerance { abs: 1e-9, rel: 1e-13, max_panels: 5000 }, peak(eps));
        assert!((est.value - exact).abs() <= est.error, "{} vs {exact}", est.value);
        assert!(est.error <= 1e-13 * exact && est.error > 1e-9 * 1e-6);
        // The same through the engine, and a == b without evaluations.
        let tol = Tolerance { abs: 1e-9, rel: 1e-13, max_panels: 5000 };
        let f = peak(eps);
        let v = integrate(&[(0.0, 1.0)], &Options::scalar(tol), |x| [f(x)]);
        assert_eq!((v.value[0].to_bits(), v.error.to_bits(), v.evals), (est.value.to_bits(), est.error.to_bits(), est.evals));
        assert_eq!(adaptive(2.0, 2.0, tol, |_| panic!("evaluated")), crate::integrate::Estimate::exact(0.0));
    }

    #[test]
    fn components_of_different_scales_each_meet_their_tolerance() {
        // [1e6/(x² + 1e-4), 1e-6·cos 30x, e^x] on [0, 2].
        let f = |x: f64| [1e6 / (x * x + 1e-4), 1e-6 * (30.0 * x).cos(), x.exp()];
        let exact = [1e6 * peak_exact(1e-2, 0.0, 2.0), 1e-6 * (60.0f64).sin() / 30.0, 2.0f64.exp() - 1.0];
        // Per component: each to its own absolute tolerance (relative 1e-10 of its scale).
        let abs = [1e-10 * exact[0], 1e-10 * 1e-6, 1e-10 * exact[2]];
        for estimate in [PanelError::Raw, PanelError::Quadpack] {
            let opts = Options { estimate, ..Options::per_component(abs, 0.0, 10_000) };
            let est = integrate(&[(0.0, 2.0)], &opts, f);
            for c in 0..3 {
                let err = (est.value[c] - exact[c]).abs();
                assert!(est.errors[c] <= abs[c], "{estimate:?} c={c}: {} > {}", est.errors[c], abs[c]);
                assert!(err <= est.errors[c], "{estimate:?} c={c}: error {err} > estimate {}", est.errors[c]);
            }
            assert_eq!(est.error, est.errors.iter().copied().fold(0.0, f64::max));
            // Relative: the same through rel = 1e-10 (the tiny cosine component included).
            let rel = integrate(&[(0.0, 2.0)], &Options { estimate, ..Options::per_component([0.0; 3], 1e-10, 10_000) }, f);
            for c in 0..3 {
                assert!(rel.errors[c] <= 1e-10 * rel.value[c].abs(), "{estimate:?} c={c}");
                assert!((rel.value[c] - exact[c]).abs() <= rel.errors[c], "{estimate:?} c={c}");
            }
        }
        // Weighted: Σ_c w_c·err_c ≤ tol with weights that undo the scales; a zero weight leaves
        // its component integrated along but unchecked (no estimate).
        for estimate in [PanelError::Raw, PanelError::Quadpack] {
            let weights = [1.0 / exact[0], 1e6, 1.0 / exact[2]];
            let opts = Options { estimate, ..Options::quadpack(weights, 1e-10, 10_000) };
            let est = integrate(&[(0.0, 2.0)], &opts, f);
            assert!(est.error <= 1e-10, "{estimate:?}: {}", est.error);
            let weighted: f64 = (0..3).map(|c| weights[c] * est.errors[c]).sum();
            assert!((weighted - est.error).abs() <= 1e-12 * est.error, "{weighted} vs {}", est.error);
            for c in 0..3 {
                assert!((est.value[c] - exact[c]).abs() <= est.errors[c], "{estimate:?} c={c}");
            }
            let unchecked = Options { estimate, ..Options::quadpack([weights[0], 0.0, weights[2]], 1e-10, 10_000) };
            let est = integrate(&[(0.0, 2.0)], &unchecked, f);
            assert_eq!(est.errors[1], 0.0);
            assert!((est.value[1] - exact[1]).abs() < 1e-6, "integrated along");
            // Relative: the weighted error against rel·|Σ_c w_c·V_c| (≈ 1.99: the scaled first and
            // last components are 1), which the run must meet; a target scaled by a sum of the
            // weights and the values instead (≈ 1.6e8) would let it stop at once.
            let opts = Options { estimate, control: Control::Weighted { weights, abs: 0.0, rel: 1e-10 }, ..Options::quadpack(weights, 0.0, 10_000) };
            let est = integrate(&[(0.0, 2.0)], &opts, f);
            let scaled: f64 = (0..3).map(|c| weights[c] * est.value[c]).sum();
            let want: f64 = (0..3).map(|c| weights[c] * exact[c]).sum();
            // Each scaled component is within its estimate (≤ 1e-10 together) of its exact value.
            assert!((scaled - want).abs() <= 1e-9, "{scaled} vs {want}");
            assert!(est.error <= 1e-10 * scaled, "{estimate:?}: {} > {}", est.error, 1e-10 * scaled);
            for c in 0..3 {
                assert!((est.value[c] - exact[c]).abs() <= est.errors[c], "{estimate:?} c={c}");
            }
        }
    }

    #[test]
    fn per_component_nan_channel_counts_as_done() {
        let f = peak(1e-3);
        let est = integrate(&[(0.0, 1.0)], &Options::per_component([1e-9, 1e-9], 0.0, 5000), |x| [f64::NAN, f(x)]);
        assert!(est.value[0].is_nan());
        assert!(est.errors[1] <= 1e-9 && (est.value[1] - peak_exact(1e-3, 0.0, 1.0)).abs() <= est.errors[1]);
    }

    /// The evaluation points of one run.
    fn trace(opts: &Options<'_, 1>, a: f64, b: f64, f: impl Fn(f64) -> f64) -> (VecEstimate<1>, Vec<f64>) {
        let mut xs = Vec::new();
        let est = integrate(&[(a, b)], opts, |x| {
            xs.push(x);
            [f(x)]
        });
        (est, xs)
    }

    #[test]
    fn split_order_is_largest_error_first_with_ties_to_the_left() {
        for (name, opts) in variants(0.0, 3) {
            // Even integrand on [-1, 1]: after the first bisection both halves have the same
            // estimate (mirrored nodes, same sums), and the left one is split.
            let (est, xs) = trace(&opts, -1.0, 1.0, peak(0.1));
            assert_eq!((est.evals, xs.len()), (105, 105), "{name}: 3 panels");
            assert!(xs[21..42].iter().all(|&x| x < 0.0) && xs[42..63].iter().all(|&x| x > 0.0), "{name}");
            assert!(xs[63..].iter().all(|&x| x < 0.0), "{name}: the left of two equal panels first");
            assert!(xs[63..84].iter().all(|&x| x < -0.5) && xs[84..].iter().all(|&x| x > -0.5), "{name}");
            // Smooth (exact) on the left half, a peak on the right: the right half is split.
            let f = |x: f64| if x < 0.5 { x * x } else { 1.0 / ((x - 0.75).powi(2) + 1e-3) };
            let (_, xs) = trace(&opts, 0.0, 1.0, f);
            assert!(xs[63..].iter().all(|&x| x > 0.5), "{name}: the larger error first");
        }
    }

    #[test]
    fn results_are_deterministic() {
        let f = |x: f64| (10.0 * x).sin() * (-x).exp() + peak(1e-3)(x - 1.3);
        for (name, opts) in variants(1e-11, 5000) {
            let (a, xa) = trace(&opts, 0.0, 3.0, f);
            let (b, xb) = trace(&opts, 0.0, 3.0, f);
            assert_eq!(a.value[0].to_bits(), b.value[0].to_bits(), "{name}");
            assert_eq!(a.error.to_bits(), b.error.to_bits(), "{name}");
            assert_eq!(xa.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), xb.iter().map(|x| x.to_bits()).collect::<Vec<_>>());
        }
    }

    #[test]
    fn panel_limit_stops_the_run_with_the_estimate() {
        // Tolerance 0 is not met by this integrand with so few panels: the limit decides.
        let f = peak(0.1);
        let exact = peak_exact(0.1, 0.0, 1.0);
        for (name, opts) in variants(0.0, 0) {
            for max_panels in [0, 1, 2, 5, 9] {
                let opts = Options { max_panels, ..opts };
                let est = integrate(&[(0.0, 1.0)], &opts, |x| [f(x)]);
                let bisections = max_panels.max(1) as u64 - 1;
                assert_eq!(est.evals, 21 + 42 * bisections, "{name} max_panels={max_panels}");
                let err = (est.value[0] - exact).abs();
                let rounding = 4.0 * f64::EPSILON * exact;
                assert!(est.error > 0.0 && err <= est.error + rounding, "{name}: the unmet estimate is returned");
            }
            // Several intervals: the limit is at least their number (no bisection below it).
            let thirds = [(0.0, 0.25), (0.25, 0.5), (0.5, 1.0)];
            let est = integrate(&thirds, &Options { max_panels: 2, ..opts }, |x| [f(x)]);
            assert_eq!(est.evals, 63, "{name}");
            let est = integrate(&thirds, &Options { max_panels: 4, ..opts }, |x| [f(x)]);
            assert_eq!(est.evals, 63 + 42, "{name}");
        }
    }

    #[test]
    fn unsplittable_panels_keep_their_error() {
        // Tolerance 0 on 8 ulps: bisection goes down to 8 panels one ulp wide, which cannot be
        // split; their (rounding-level, non-zero) estimates stay in the error and the run ends
        // (by stop_when_exhausted, or because the picked panel cannot be split).
        let (a, b) = (1.0, 1.0 + 8.0 * f64::EPSILON);
        for (name, opts) in variants(0.0, 1000) {
            let est = integrate(&[(a, b)], &opts, |_| [1.0 / 3.0]);
            assert_eq!(est.evals, 21 + 42 * 7, "{name}: 7 bisections");
            assert!(est.error > 0.0 && est.errors[0] == est.error, "{name}: the stuck error stays");
            assert!((est.value[0] - (b - a) / 3.0).abs() <= 1e-15 * (b - a), "{name}");
        }
    }

    #[test]
    fn without_stop_when_exhausted_error_free_panels_are_bisected_leftmost_first_to_the_limit() {
        // The contract (Options::stop_when_exhausted): a run whose error is all stuck keeps
        // bisecting, leftmost first, until the panel limit. Intervals: [0, 1/4], where the
        // integrand is 0 (every estimate exactly 0), and [1, 1 + ε], one ulp wide, where it is
        // 1/3 + x (an estimate above 0 that gets stuck). Tolerance 0 is never met, so after the
        // stuck panel every bisection falls on the left interval's leftmost panel, which stays
        // splittable (its width halves from 1/4, far above the smallest subnormal).
        let f = |x: f64| [if x >= 1.0 { 1.0 / 3.0 + x } else { 0.0 }];
        let intervals = [(0.0, 0.25), (1.0, 1.0 + f64::EPSILON)];
        for (name, opts) in variants(0.0, 0) {
            let opts = Options { stop_when_exhausted: false, ..opts };
            // The one-ulp panel's own estimate, from a run that never bisects.
            let alone = integrate(&intervals[1..], &Options { max_panels: 1, ..opts }, f);
            for max_panels in [2usize, 3, 10, 40] {
                let est = integrate(&intervals, &Options { max_panels, ..opts }, f);
                assert!(est.error > 0.0, "{name}: the one-ulp panel's estimate is stuck, not 0");
                // Two initial panels, then max_panels − 2 bisections of 42 evaluations each.
                assert_eq!(est.evals, 42 + 42 * (max_panels as u64 - 2), "{name} max_panels={max_panels}");
                // The error is the stuck panel's alone: bisecting zeros adds none.
                assert_eq!(est.error.to_bits(), alone.error.to_bits(), "{name} max_panels={max_panels}");
            }
        }
    }

    #[test]
    fn degenerate_stops() {
        // An infinite value at the centre node: stop_when_non_finite ends the run at once; the
        // scalar rule bisects it (the halves do not evaluate x = 0.5 and are exact).
        let f = |x: f64| [if x == 0.5 { f64::INFINITY } else { 1.0 }];
        let w = integrate(&[(0.0, 1.0)], &Options::quadpack([1.0], 1e-12, 100), f);
        assert_eq!((w.evals, w.error), (21, f64::INFINITY));
        let s = integrate(&[(0.0, 1.0)], &Options::scalar(Tolerance { rel: 0.0, ..Tolerance::default() }), f);
        assert_eq!(s.evals, 63);
        assert!((s.value[0] - 1.0).abs() < 1e-15 && s.error < 1e-15);
        // Per component: one infinite component's error ends the run at once with
        // stop_when_non_finite (the other is finite), and is bisected away without it.
        let g = |x: f64| [if x == 0.5 { f64::INFINITY } else { 1.0 }, x];
        let c = Options::per_component([1e-12; 2], 0.0, 100);
        let stopped = integrate(&[(0.0, 1.0)], &Options { stop_when_non_finite: true, ..c }, g);
        assert_eq!((stopped.evals, stopped.error, stopped.errors[0]), (21, f64::INFINITY, f64::INFINITY));
        assert!(stopped.errors[1].is_finite(), "{stopped:?}");
        let bisected = integrate(&[(0.0, 1.0)], &c, g);
        assert_eq!(bisected.evals, 63);
        // K21 is exact for constants and x: the halves' value to rounding, error 0 or rounding.
        assert!((bisected.value[0] - 1.0).abs() < 1e-15 && (bisected.value[1] - 0.5).abs() < 1e-15 && bisected.error < 1e-15, "{bisected:?}");
        // The sign of a sum of −0.0 panels.
        let s = integrate(&[(0.0, 1.0)], &Options::scalar(Tolerance::default()), |_| [-0.0]);
        assert!(s.value[0] == 0.0 && s.value[0].is_sign_negative());
        let c = integrate(&[(0.0, 1.0)], &Options::per_component([1e-12], 0.0, 100), |_| [-0.0]);
        assert!(c.value[0] == 0.0 && c.value[0].is_sign_positive());
        // No intervals: zero, no evaluations.
        let e = integrate(&[], &Options::per_component([1e-12; 2], 0.0, 100), |_| panic!("evaluated"));
        assert_eq!((e.value, e.errors, e.evals), ([0.0; 2], [0.0; 2], 0));
    }
}
