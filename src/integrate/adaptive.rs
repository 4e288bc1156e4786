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
//! | option | [`super::adaptive()`] (gloss, fuzz G/Q, tests) | fuzz P_s, R | skin |
//! |---|---|---|---|
//! | [`Rule`] | K21 | K21; GL32/GL24 pair (outer A of R) | K21 |
//! | [`PanelError`] | raw \|K − G\| | QUADPACK | raw \|K − G\| |
//! | [`Control`] | `Weighted([1])`, abs + rel | `Weighted(w)`, abs | `PerComponent`, abs[c] + rel |
//! | `stop_when_exhausted` | yes | no | yes |
//! | `stop_when_non_finite` | no | yes | no |
//! | `sum_from_negative_zero` | yes (`Iterator::sum`) | no | no |
//! | intervals | one | one | several (the kinks) |
//!
//! Why: the scalar rule is the plain QAG loop with the raw (generous) estimate. Fuzz integrates
//! mapped integrands whose raw estimates are orders of magnitude too pessimistic, so it uses
//! QUADPACK's; it integrates up to 15 η_u nodes of one K15 rule at once and controls their sum
//! weighted by the rule's weights (nodes with their own integration get weight 0), and R's outer
//! integral carries the inner error estimates as an unchecked component. Skin integrates RGB,
//! each channel to its own tolerance (scaled by that channel's denominator), on intervals split
//! at the kinks of the clamped cosine and the profile.
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
    /// non-finite error (fuzz: P_s and the inner integrals of R).
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

    /// K21 with raw estimates, every component to max(abs[c], rel·|value_c|) (skin).
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
