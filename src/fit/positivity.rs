//! Proof that a denominator stays positive on a box, by interval arithmetic with bisection.
//!
//! Q(x) = 1 + Σ b_j ψ_j(x) is evaluated over a box with interval arithmetic (each monomial
//! an interval product of interval powers). If the lower bound is positive the box is done;
//! otherwise it is bisected along its widest side, down to a budget of boxes (200 000) or a
//! widest side below 1e-9, and stops at the first box whose centre is itself ≤ 1e-12. Interval
//! evaluation over-estimates the range, never under-estimates it, and every interval end is
//! rounded outward (`next_down`/`next_up`), so a lower bound on every leaf is a proof in f64.
//! Where the plain interval bound is not enough, the box also gets the mean-value form in the
//! features f (Q is a polynomial in them; the box of their ranges contains the image of the
//! region):
//! ```text
//! Q(F) ⊆ Q(m) + Σ_i ∂Q/∂f_i(F) · (F_i − m_i),   m = the centre of F
//! ```
//! whose over-estimate shrinks with the square of the box width (the plain one's only
//! linearly), so boxes near a small minimum are settled after far fewer bisections. A leaf's
//! bound is the larger of the two.
//! A denominator is accepted when that bound exceeds 1e-12: closer to zero is a pole for
//! shader arithmetic.

use super::model::RationalModel;
use nalgebra::DVector;

/// The largest f64 below `x` (below every real number `x` may have rounded from).
fn down(x: f64) -> f64 {
    if x.is_nan() { f64::NEG_INFINITY } else { x.next_down() }
}

/// The smallest f64 above `x`.
fn up(x: f64) -> f64 {
    if x.is_nan() { f64::INFINITY } else { x.next_up() }
}

/// A closed interval whose ends are rounded outward after every operation, so that it always
/// contains the exact real result: each operation's f64 result is within half an ulp of the
/// real one, and one step of `next_down`/`next_up` covers it (a NaN end becomes ∓∞).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Iv(f64, f64);

impl Iv {
    fn add(self, o: Iv) -> Iv {
        Iv(down(self.0 + o.0), up(self.1 + o.1))
    }

    fn mul(self, o: Iv) -> Iv {
        let p = [self.0 * o.0, self.0 * o.1, self.1 * o.0, self.1 * o.1];
        if p.iter().any(|v| v.is_nan()) {
            // 0 · ∞: no finite bound.
            return Iv(f64::NEG_INFINITY, f64::INFINITY);
        }
        Iv(down(p.iter().copied().fold(f64::INFINITY, f64::min)), up(p.iter().copied().fold(f64::NEG_INFINITY, f64::max)))
    }

    fn scale(self, b: f64) -> Iv {
        Iv(b, b).mul(self)
    }

    /// xᵉ by repeated outward-rounded products (`powi` is not correctly rounded); even powers
    /// are ≥ 0 whatever the interval. (The proof takes all powers at once by [`powers`].)
    #[cfg(test)]
    fn powi(self, e: u32) -> Iv {
        let mut r = Iv(1.0, 1.0);
        for _ in 0..e {
            r = r.mul(self);
        }
        if e % 2 == 0 {
            r.0 = r.0.max(0.0);
        }
        r
    }
}

/// Outcome of the positivity proof.
#[derive(Debug, Clone, PartialEq)]
pub enum Positivity {
    /// Proven: Q ≥ `lower` on the whole box.
    Proven { lower: f64, boxes: usize },
    /// Not proven: on `region`, the tightest bound is `lower` (negative or too small); `sample`
    /// is Q at the region's centre (negative there means a real pole or sign change).
    NotProven { lower: f64, region: Vec<(f64, f64)>, sample: f64 },
}

/// x⁰ … xⁿ into `out` (n + 1 entries), each equal to [`Iv::powi`]'s: the running product of
/// e factors (the same operations), with the clamp of even powers applied to the copy kept.
fn powers(x: Iv, out: &mut [Iv]) {
    let mut run = Iv(1.0, 1.0);
    for (e, slot) in out.iter_mut().enumerate() {
        if e > 0 {
            run = run.mul(x);
        }
        let mut v = run;
        if e % 2 == 0 {
            v.0 = v.0.max(0.0);
        }
        *slot = v;
    }
}

/// The smallest lower bound that proves a denominator positive: closer to zero is a pole for
/// shader arithmetic.
const MIN_BOUND: f64 = 1e-12;

/// Per-proof buffers of [`bound`] (a proof visits up to 200 000 boxes).
struct Scratch {
    feats: Vec<Iv>,
    /// Every feature's powers, flattened: feature i's e-th at `offs[i] + e`.
    pows: Vec<Iv>,
    offs: Vec<usize>,
    /// The same at the centre of the features' box (for the mean-value form).
    centre: Vec<Iv>,
}

impl Scratch {
    fn new(max_exp: &[u32]) -> Self {
        let mut offs = Vec::with_capacity(max_exp.len());
        let mut n = 0;
        for &top in max_exp {
            offs.push(n);
            n += top as usize + 1;
        }
        Scratch { feats: Vec::with_capacity(max_exp.len()), pows: vec![Iv(0.0, 0.0); n], offs, centre: vec![Iv(0.0, 0.0); n] }
    }
}

/// The range of a term from the ranges of its features' powers (see [`Scratch::pows`]).
fn term_range(t: &crate::fit::model::Term, sc: &Scratch) -> Iv {
    term_range_in(t, &sc.pows, &sc.offs)
}

/// A term's range from the powers `pows` (laid out as [`Scratch::pows`]).
fn term_range_in(t: &crate::fit::model::Term, pows: &[Iv], offs: &[usize]) -> Iv {
    let mut term = Iv(0.0, 0.0);
    for m in &t.monomials {
        let mut v = Iv(1.0, 1.0);
        for (e, off) in m.exps.iter().zip(offs) {
            if *e > 0 {
                v = v.mul(pows[off + *e as usize]);
            }
        }
        term = term.add(v);
    }
    term
}

/// The range of ∂t/∂f_i over the box: Σ over monomials e_i f_i^(e_i − 1) Π_(k≠i) f_k^(e_k).
fn term_derivative(t: &crate::fit::model::Term, i: usize, sc: &Scratch) -> Iv {
    let mut term = Iv(0.0, 0.0);
    for m in &t.monomials {
        let ei = m.exps[i];
        if ei == 0 {
            continue;
        }
        let mut v = Iv(ei as f64, ei as f64);
        for (k, (e, off)) in m.exps.iter().zip(&sc.offs).enumerate() {
            let e = if k == i { *e - 1 } else { *e };
            if e > 0 {
                v = v.mul(sc.pows[off + e as usize]);
            }
        }
        term = term.add(v);
    }
    term
}

/// The mean-value form's lower bound of Q over the features' box in `sc` (see the module doc);
/// −∞ when a feature's range is unbounded.
fn mean_value_bound(model: &RationalModel, c: &DVector<f64>, max_exp: &[u32], sc: &mut Scratch) -> f64 {
    let nn = model.numerator.len();
    let mut q = Iv(0.0, 0.0);
    for (i, (f, &top)) in sc.feats.iter().zip(max_exp).enumerate() {
        if top == 0 {
            continue;
        }
        if !(f.0.is_finite() && f.1.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let m = 0.5 * f.0 + 0.5 * f.1;
        powers(Iv(m, m), &mut sc.centre[sc.offs[i]..=sc.offs[i] + top as usize]);
        // F_i − m, rounded outward.
        let dev = Iv(down(f.0 - m), up(f.1 - m));
        let mut g = model.lead.as_ref().map_or(Iv(0.0, 0.0), |t| term_derivative(t, i, sc));
        for (j, t) in model.denominator.iter().enumerate() {
            g = g.add(term_derivative(t, i, sc).scale(c[nn + j]));
        }
        q = q.add(g.mul(dev));
    }
    let mut at = model.lead.as_ref().map_or(Iv(1.0, 1.0), |t| term_range_in(t, &sc.centre, &sc.offs));
    for (j, t) in model.denominator.iter().enumerate() {
        at = at.add(term_range_in(t, &sc.centre, &sc.offs).scale(c[nn + j]));
    }
    at.add(q).0
}

/// A lower bound of Q on `region`, rigorous in f64: interval arithmetic rounded outward, the
/// derived features' ranges widened by two ulps each side (their cos, sin and affine maps are
/// within an ulp or two of exact).
fn bound(model: &RationalModel, c: &DVector<f64>, region: &[(f64, f64)], max_exp: &[u32], sc: &mut Scratch) -> f64 {
    let nn = model.numerator.len();
    sc.feats.clear();
    sc.feats.extend(region.iter().map(|&(a, b)| Iv(a, b)));
    sc.feats.extend(model.derived.iter().map(|d| {
        let (a, b) = d.range(region);
        Iv(down(down(a)), up(up(b)))
    }));
    for (i, (f, &top)) in sc.feats.iter().zip(max_exp).enumerate() {
        powers(*f, &mut sc.pows[sc.offs[i]..=sc.offs[i] + top as usize]);
    }
    let mut q = model.lead.as_ref().map_or(Iv(1.0, 1.0), |t| term_range(t, sc));
    for (j, t) in model.denominator.iter().enumerate() {
        q = q.add(term_range(t, sc).scale(c[nn + j]));
    }
    if q.0 > MIN_BOUND {
        return q.0;
    }
    q.0.max(mean_value_bound(model, c, max_exp, sc))
}

/// The boxes a proof may take: it gives up (not proven) at a bisection where the boxes visited
/// and those waiting on the stack reach it.
const BUDGET: usize = 200_000;

/// Prove Q > 0 on the box `domain` (one (min, max) per feature).
///
/// Depth first, the lower half of a bisected box before the upper; the boxes live on one flat
/// stack (`dim` (min, max) pairs each).
pub fn prove_denominator_positive(
    model: &RationalModel,
    c: &DVector<f64>,
    domain: &[(f64, f64)],
) -> Positivity {
    prove_within(model, c, domain, BUDGET)
}

/// [`prove_denominator_positive`] with a budget of `budget` boxes (see [`BUDGET`]).
fn prove_within(model: &RationalModel, c: &DVector<f64>, domain: &[(f64, f64)], budget: usize) -> Positivity {
    // The highest power of each feature in the denominator's terms (the powers a box needs).
    let mut max_exp = vec![0u32; model.features.len()];
    for t in model.lead.iter().chain(&model.denominator) {
        for m in &t.monomials {
            for (top, &e) in max_exp.iter_mut().zip(&m.exps) {
                *top = (*top).max(e);
            }
        }
    }
    let mut sc = Scratch::new(&max_exp);
    let dim = domain.len();
    if dim == 0 {
        // A constant: one box, nothing to bisect.
        let lo = bound(model, c, domain, &max_exp, &mut sc);
        if lo > MIN_BOUND {
            return Positivity::Proven { lower: lo, boxes: 1 };
        }
        return Positivity::NotProven { lower: lo, region: vec![], sample: model.denominator_at(c, &[]) };
    }
    let mut stack: Vec<(f64, f64)> = domain.to_vec();
    let mut region: Vec<(f64, f64)> = vec![(0.0, 0.0); dim];
    let mut centre = vec![0.0; dim];
    let mut boxes = 0;
    let mut lowest = f64::INFINITY;
    while stack.len() >= dim {
        let top = stack.len() - dim;
        region.copy_from_slice(&stack[top..]);
        stack.truncate(top);
        boxes += 1;
        let lo = bound(model, c, &region, &max_exp, &mut sc);
        if lo > MIN_BOUND {
            lowest = lowest.min(lo);
            continue;
        }
        for (x, r) in centre.iter_mut().zip(&region) {
            *x = 0.5 * (r.0 + r.1);
        }
        let sample = model.denominator_at(c, &centre);
        let widest = region
            .iter()
            .enumerate()
            .max_by(|a, b| (a.1.1 - a.1.0).total_cmp(&(b.1.1 - b.1.0)))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let w = region[widest].1 - region[widest].0;
        if sample <= MIN_BOUND || boxes + stack.len() / dim >= budget || w < 1e-9 {
            return Positivity::NotProven { lower: lo, region, sample };
        }
        let mid = 0.5 * (region[widest].0 + region[widest].1);
        // Upper half pushed first, so the lower half is taken next.
        stack.extend_from_slice(&region);
        stack[top + widest].0 = mid;
        stack.extend_from_slice(&region);
        stack[top + dim + widest].1 = mid;
    }
    Positivity::Proven { lower: lowest, boxes }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prove(n_den: u32, den: &[f64], domain: (f64, f64)) -> Positivity {
        let m = RationalModel::rational_1d("x", 0, n_den);
        let mut c = vec![1.0];
        c.extend_from_slice(den);
        prove_denominator_positive(&m, &DVector::from_vec(c), &[domain])
    }

    fn proven(p: &Positivity) -> Option<f64> {
        match p {
            Positivity::Proven { lower, .. } => Some(*lower),
            Positivity::NotProven { .. } => None,
        }
    }

    #[test]
    fn powers_equal_powi() {
        // The same products in the same order: bit for bit, also across zero and with ∞ ends.
        for x in [Iv(-0.3, 0.7), Iv(0.2, 1.9), Iv(-2.5, -0.1), Iv(-1.0, f64::INFINITY), Iv(0.0, 0.0)] {
            let mut out = [Iv(0.0, 0.0); 8];
            powers(x, &mut out);
            for (e, v) in out.iter().enumerate() {
                let r = x.powi(e as u32);
                assert!(v.0.to_bits() == r.0.to_bits() && v.1.to_bits() == r.1.to_bits(), "{x:?}^{e}: {v:?} vs {r:?}");
            }
        }
    }

    #[test]
    fn a_small_minimum_inside_is_proven_by_the_mean_value_form() {
        // Q = 1 − 4x + 4x² + 4e-6 = 4(x − ½)² + 4e-6 (as 1 + b₁x + b₂x² scaled by 1/(1 + 4e-6))
        // on [0, 1]: minimum 4e-6/(1 + 4e-6) at x = ½. The plain interval form over-estimates
        // by ~8w on a box of width w about ½ (−4x and 4x² apart), so it needs w ~ 5e-7 there
        // (8 527 boxes alone, measured); the mean-value form's excess is ~2w² (39 boxes).
        let k = 1.0 / (1.0 + 4e-6);
        let p = prove(2, &[-4.0 * k, 4.0 * k], (0.0, 1.0));
        let Positivity::Proven { lower, boxes } = p else { panic!("not proven: {p:?}") };
        // Sound: no higher than the true minimum (the ulp-level rounding of k aside: 1e-15).
        assert!(lower > 1e-12 && lower <= 4e-6 * k + 1e-15, "{lower}");
        assert!(boxes < 400, "{boxes} boxes");
        // And a minimum just below zero is still a pole: Q = 4(x − ½)² − 4e-6.
        let k = 1.0 / (1.0 - 4e-6);
        assert!(proven(&prove(2, &[-4.0 * k, 4.0 * k], (0.0, 1.0))).is_none());
    }

    #[test]
    fn detects_pole_and_proves_positive() {
        // Q = 1 − 2x has a root at ½ inside [0, 1].
        assert!(proven(&prove(1, &[-2.0], (0.0, 1.0))).is_none());
        // Q = 1 − 0.9x ≥ 0.1 on [0, 1].
        let lower = proven(&prove(1, &[-0.9], (0.0, 1.0))).expect("proven");
        assert!(lower > 0.0 && lower <= 0.1 + 1e-12, "{lower}");
    }

    #[test]
    fn the_threshold_is_kept_exactly() {
        // Q = 1 − (1 − t)x on [0, 1]: its minimum is t, at the box edge x = 1.
        // t = 2e-12 is above the 1e-12 threshold: proven, with a bound no higher than t.
        let t = 2e-12;
        let lower = proven(&prove(1, &[-(1.0 - t)], (0.0, 1.0))).expect("2e-12 above the threshold");
        assert!(lower > 1e-12 && lower <= t * (1.0 + 1e-3), "{lower}");
        // Just below the threshold, at zero (a root on the box edge), and below zero (a root
        // inside, 5e-10 from the edge): never proven.
        for t in [5e-13, 0.0, -5e-10, -1e-9] {
            assert!(proven(&prove(1, &[-(1.0 - t)], (0.0, 1.0))).is_none(), "min {t} proven");
        }
    }

    /// The model 1 / (x + b·x²): a lead term x and one denominator term x².
    fn lead_x_over_x2() -> RationalModel {
        use crate::fit::model::{ModelParts, Term};
        let f = vec!["x".to_string()];
        RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![Term::parse("1", &f).unwrap()],
            denominator: vec![Term::parse("x^2", &f).unwrap()],
            lead: Some(Term::parse("x", &f).unwrap()),
            ..ModelParts::default()
        })
        .unwrap()
    }

    /// The threshold is strict where the bound lands on it exactly: Q = x (a lead term x, and
    /// x² at coefficient 0) on [a, 1], with a a few ulps above 1e-12, has the rigorous bound
    /// a rounded down a few times, so one a in the first 64 ulps gives a bound equal to the
    /// f64 1e-12. That bound is not above the threshold, and the box is bisected on towards its
    /// width limit: not proven. The next a whose bound is above it is proven. (Without a lead
    /// term Q's bound is 1 + Σ…, a multiple of 2⁻⁵³, which 1e-12 is not.)
    #[test]
    fn a_bound_exactly_at_the_threshold_is_no_proof() {
        let m = lead_x_over_x2();
        let c = DVector::from_vec(vec![1.0, 0.0]);
        let whole_box = |a: f64| bound(&m, &c, &[(a, 1.0)], &[2], &mut Scratch::new(&[2]));
        let ends: Vec<f64> = std::iter::successors(Some(MIN_BOUND), |a| Some(a.next_up())).take(64).collect();
        let at = ends.iter().position(|&a| whole_box(a) == MIN_BOUND).expect("no a in 64 ulps bounds Q at exactly 1e-12: the test does not reach the threshold");
        assert!(proven(&prove_denominator_positive(&m, &c, &[(ends[at], 1.0)])).is_none(), "a bound of exactly 1e-12 proven");
        let above = ends[at..].iter().find(|&&a| whole_box(a) > MIN_BOUND).expect("a bound above 1e-12 within 64 ulps");
        let lower = proven(&prove_denominator_positive(&m, &c, &[(*above, 1.0)])).expect("a bound above 1e-12 is a proof");
        assert!(lower > MIN_BOUND && lower <= *above, "{lower:e}");
    }

    /// A box whose plain interval bound lands exactly on the threshold still takes the
    /// mean-value form (the module doc: a leaf's bound is the larger of the two). Q = x − k·x²
    /// (a lead term x, x² at coefficient −k) on [2e-12, 3e-12] is concave, so its minimum is at
    /// an end: about 1.556e-12 at 2e-12 (2e-12 at 3e-12) for the k ≈ 1.11e11 that puts the
    /// plain bound x_lo − k·x_hi² at 1e-12. The mean-value form, Q(m) + Q′(F)·(F − m) with
    /// Q(m) ≈ 1.806e-12, Q′ = 1 − 2k·x ∈ [⅓, 5⁄9] on the box and |F − m| ≤ 5e-13, is about
    /// 1.528e-12 less its roundings: above the threshold and below the minimum. So the box is
    /// settled at once, with that bound. One k within a few ulps of (x_lo − 1e-12)/x_hi² gives
    /// a plain bound equal to the f64 1e-12 (each ulp of k moves k·x_hi² by under an ulp of
    /// 1e-12, and the outward roundings by a few).
    #[test]
    fn a_plain_bound_exactly_at_the_threshold_still_takes_the_mean_value_form() {
        let m = lead_x_over_x2();
        let (lo, hi) = (2e-12, 3e-12);
        // The plain interval bound: the lead term's range plus the x² term's range times −k,
        // each from the box's outward-rounded powers of x (the same for every k).
        let mut pows = [Iv(0.0, 0.0); 3];
        powers(Iv(lo, hi), &mut pows);
        let lead = term_range_in(m.lead.as_ref().unwrap(), &pows, &[0]);
        let square = term_range_in(&m.denominator[0], &pows, &[0]);
        let plain = |k: f64| lead.add(square.scale(-k)).0;
        let k0 = (lo - MIN_BOUND) / (hi * hi);
        let start = (0..64).fold(k0, |k, _| k.next_down());
        let k = std::iter::successors(Some(start), |k: &f64| Some(k.next_up()))
            .take(129)
            .find(|&k| plain(k) == MIN_BOUND)
            .expect("no k within 64 ulps of k0 puts the plain bound at exactly 1e-12: the test does not reach the threshold");
        let c = DVector::from_vec(vec![1.0, -k]);
        let q = |x: f64| x - k * x * x;
        let minimum = q(lo).min(q(hi));
        let b = bound(&m, &c, &[(lo, hi)], &[2], &mut Scratch::new(&[2]));
        // Above the threshold by the mean-value form (≈ 1.528e-12 less roundings of a few ulps,
        // ~1e-27 each); below Q's minimum, ≈ 1.556e-12 at x_lo, by 2.8e-14, where Q's f64
        // values are within ~1e-27 of the real ones.
        assert!(b > 1.5e-12 && b < minimum, "bound {b:e}, minimum {minimum:e}");
        match prove_denominator_positive(&m, &c, &[(lo, hi)]) {
            Positivity::Proven { lower, boxes } => assert!(boxes == 1 && lower == b, "{boxes} boxes, lower {lower:e}"),
            p => panic!("not proven: {p:?}"),
        }
    }

    #[test]
    fn tangent_roots_and_near_tangents() {
        // Q = (4(x − ½)² + ε)/(1 + ε) = 1 − 4x/(1+ε) + 4x²/(1+ε): minimum ε/(1+ε) at x = ½.
        let q = |eps: f64| prove(2, &[-4.0 / (1.0 + eps), 4.0 / (1.0 + eps)], (0.0, 1.0));
        let lower = proven(&q(1e-6)).expect("min 1e-6 is proven after bisection");
        assert!(lower > 1e-12 && lower <= 1e-6, "{lower}");
        for eps in [1e-13, 0.0, -1e-9] {
            assert!(proven(&q(eps)).is_none(), "ε = {eps} proven");
        }
    }

    #[test]
    fn huge_and_tiny_coefficients() {
        // Q = 1 + 1e300·x ≥ 1 on [0, 1]; Q = 1 − 1e-300·x ≈ 1; Q = 1 − 1e300·x has its root at
        // 1e-300, inside; Q = 1 − 1e-300·x on [0, 2e300] has its root at 1e300.
        assert!(proven(&prove(1, &[1e300], (0.0, 1.0))).is_some_and(|l| l > 0.99));
        assert!(proven(&prove(1, &[-1e-300], (0.0, 1.0))).is_some_and(|l| l > 0.99));
        assert!(proven(&prove(1, &[-1e300], (0.0, 1.0))).is_none());
        assert!(proven(&prove(1, &[-1e-300], (0.0, 2e300))).is_none());
        // An overflowing bound is no proof.
        assert!(proven(&prove(2, &[1e300, -1e300], (0.0, 1e10))).is_none());
    }

    #[test]
    fn intervals_round_outward() {
        // 0.1 + 0.2 is not 0.3 in f64; the interval must contain the real sum on both sides.
        let s = Iv(0.1, 0.1).add(Iv(0.2, 0.2));
        assert!(s.0 < 0.1 + 0.2 && s.1 > 0.1 + 0.2);
        let p = Iv(-1.0, 2.0).powi(2);
        assert_eq!(p.0, 0.0, "even powers are non-negative");
        assert!(p.1 >= 4.0);
        assert_eq!(Iv(0.0, f64::INFINITY).mul(Iv(-1.0, 1.0)), Iv(f64::NEG_INFINITY, f64::INFINITY));
    }

    #[test]
    fn a_proof_is_never_contradicted_by_dense_sampling() {
        // 3000 random cubic denominators 1 + b₁x + b₂x² + b₃x³ on random boxes inside [−2, 2]:
        // whenever the proof holds, Q at 4001 points of the box (evaluated in f64, to ~1e-15)
        // stays above its bound, and the bound is above the threshold.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut yes, mut no) = (0, 0);
        for _ in 0..3000 {
            let b = [uniform(-3.0, 3.0), uniform(-3.0, 3.0), uniform(-3.0, 3.0)];
            let (a, w) = (uniform(-2.0, 1.5), uniform(0.01, 2.0));
            let dom = (a, (a + w).min(2.0));
            let q = |x: f64| 1.0 + b[0] * x + b[1] * x * x + b[2] * x * x * x;
            let min = (0..=4000).map(|i| q(dom.0 + (dom.1 - dom.0) * i as f64 / 4000.0)).fold(f64::INFINITY, f64::min);
            match proven(&prove(3, &b, dom)) {
                Some(lower) => {
                    yes += 1;
                    assert!(lower > 1e-12 && min >= lower - 1e-14, "b = {b:?} on {dom:?}: bound {lower}, sampled min {min}");
                }
                None => no += 1,
            }
        }
        // Both outcomes occur, so the property was exercised both ways.
        assert!(yes > 300 && no > 300, "{yes} proven, {no} not");
    }

    #[test]
    fn two_dimensional_proofs_with_a_derived_feature_hold_under_dense_sampling() {
        // Q = 1 + b₁x + b₂y + b₃xy + b₄x² + b₅c² with c = cos(y) a derived feature, on random
        // boxes inside [−1.5, 1.5]²: whenever the proof holds, Q at the 161 × 161 points of the
        // box (f64, to ~1e-15) stays above the bound; a NotProven region with a negative sample
        // at its centre really has Q < 0 there (checked independently).
        use crate::fit::model::{Derived, ModelParts, Term};
        let inputs = vec!["x".to_string(), "y".to_string()];
        let derived = vec![Derived::parse("c", "cos(y)", &inputs).unwrap()];
        let features = vec!["x".to_string(), "y".to_string(), "c".to_string()];
        let term = |t: &str| Term::parse(t, &features).unwrap();
        let model = RationalModel::new(ModelParts {
            inputs: inputs.clone(),
            derived,
            numerator: vec![term("1")],
            denominator: ["x", "y", "x*y", "x^2", "c^2"].into_iter().map(term).collect(),
            ..ModelParts::default()
        })
        .unwrap();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = |lo: f64, hi: f64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            lo + (hi - lo) * (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut yes, mut no) = (0, 0);
        for _ in 0..300 {
            let b: Vec<f64> = (0..5).map(|_| uniform(-1.2, 1.2)).collect();
            let q = |x: f64, y: f64| 1.0 + b[0] * x + b[1] * y + b[2] * x * y + b[3] * x * x + b[4] * y.cos() * y.cos();
            let (x0, y0) = (uniform(-1.5, 1.0), uniform(-1.5, 1.0));
            let dom = [(x0, (x0 + uniform(0.05, 1.5)).min(1.5)), (y0, (y0 + uniform(0.05, 1.5)).min(1.5))];
            let mut c = vec![1.0];
            c.extend_from_slice(&b);
            let n = 160;
            let at = |k: usize, (a, b): (f64, f64)| a + (b - a) * k as f64 / n as f64;
            let min = (0..=n)
                .flat_map(|i| (0..=n).map(move |j| (i, j)))
                .map(|(i, j)| q(at(i, dom[0]), at(j, dom[1])))
                .fold(f64::INFINITY, f64::min);
            match prove_denominator_positive(&model, &DVector::from_vec(c), &dom) {
                Positivity::Proven { lower, .. } => {
                    yes += 1;
                    assert!(lower > 1e-12 && min >= lower - 1e-14, "b = {b:?} on {dom:?}: bound {lower}, sampled min {min}");
                }
                Positivity::NotProven { region, sample, .. } => {
                    no += 1;
                    let centre = [0.5 * (region[0].0 + region[0].1), 0.5 * (region[1].0 + region[1].1)];
                    // The reported sample is Q at the region's centre.
                    assert!((sample - q(centre[0], centre[1])).abs() <= 1e-14, "{sample} vs {}", q(centre[0], centre[1]));
                }
            }
        }
        assert!(yes > 30 && no > 30, "{yes} proven, {no} not");
    }

    /// Q = 1 + b₁x + b₂x² + 0·y (x, y): the 2-D model of the bisection tests, and its
    /// coefficients.
    fn model_xy(b: [f64; 2]) -> (RationalModel, DVector<f64>) {
        use crate::fit::model::{ModelParts, Term};
        let features = vec!["x".to_string(), "y".to_string()];
        let term = |t: &str| Term::parse(t, &features).unwrap();
        let model = RationalModel::new(ModelParts {
            inputs: features.clone(),
            numerator: vec![term("1")],
            denominator: vec![term("x"), term("x^2"), term("y")],
            ..ModelParts::default()
        })
        .unwrap();
        (model, DVector::from_vec(vec![1.0, b[0], b[1], 0.0]))
    }

    /// [`model_xy`]'s Q proven on `domain`.
    fn prove_xy(b: [f64; 2], domain: [(f64, f64); 2]) -> Positivity {
        let (model, c) = model_xy(b);
        prove_denominator_positive(&model, &c, &domain)
    }

    /// The budget counts the boxes visited and those waiting. Each bisection adds one to that
    /// count (one box taken off the stack, two put on) and a proven box none, so it is largest
    /// at the last bisection, where it is N − 2 for a proof of N boxes (everything waiting, and
    /// the two halves, is then proven without bisection): the proof holds within a budget of
    /// N − 1 and stops at N − 2. In two dimensions, with boxes waiting at the last bisection,
    /// counting each waiting box's two (min, max) pairs as two boxes would stop it at N − 1.
    #[test]
    fn the_budget_counts_the_boxes_visited_and_waiting() {
        // Q = 4(x − ¼)² + ε scaled to Q(0) = 1 (ε = 1e-4) on [0, 1]²: bisected in x about ¼
        // and in y wherever y is the widest side, the upper halves waiting meanwhile.
        let eps = 1e-4;
        let k = 1.0 / (0.25 + eps);
        let (model, c) = model_xy([-2.0 * k, 4.0 * k]);
        let dom = [(0.0, 1.0), (0.0, 1.0)];
        let Positivity::Proven { boxes: n, lower } = prove_within(&model, &c, &dom, usize::MAX) else { panic!("not proven") };
        assert!(n > 20 && lower > 1e-12, "{n} boxes, lower {lower}");
        assert_eq!(prove_denominator_positive(&model, &c, &dom), Positivity::Proven { boxes: n, lower });
        assert_eq!(prove_within(&model, &c, &dom, n - 1), Positivity::Proven { boxes: n, lower });
        assert!(matches!(prove_within(&model, &c, &dom, n - 2), Positivity::NotProven { .. }));
    }

    /// The budget counts the waiting boxes too where the last bisection leaves some: Q =
    /// (x − 0.3)² + 2.5e-5 scaled to Q(0) = 1 on [0, 1], bisected down to 0.3 (lower halves
    /// first), then across [0.5, 1], whose last bisection, of [0.5, 0.75], leaves [0.75, 1]
    /// waiting (41 boxes, traced). Every budget above N − 2 proves it and none at or below it
    /// does: the count is N − 2 at the last bisection whatever waits then. A count of the
    /// visited boxes less the waiting ones is N − 4 there.
    #[test]
    fn every_budget_above_the_last_count_proves_and_none_below() {
        let k = 1.0 / (0.09 + 2.5e-5);
        let model = RationalModel::rational_1d("x", 0, 2);
        let c = DVector::from_vec(vec![1.0, -0.6 * k, k]);
        let dom = [(0.0, 1.0)];
        let Positivity::Proven { boxes: n, .. } = prove_within(&model, &c, &dom, usize::MAX) else { panic!("not proven") };
        assert!(n > 10, "{n} boxes");
        for budget in 1..=n + 1 {
            let p = prove_within(&model, &c, &dom, budget);
            assert_eq!(matches!(p, Positivity::Proven { .. }), budget > n - 2, "budget {budget} of {n} boxes: {p:?}");
        }
    }

    #[test]
    fn a_constant_denominator_is_one_box() {
        // No feature in the box (dim 0): Q = 1, proven at once with the bound 1.
        let m = RationalModel::rational_1d("x", 0, 0);
        assert_eq!(prove_denominator_positive(&m, &DVector::from_vec(vec![1.0]), &[]), Positivity::Proven { lower: 1.0, boxes: 1 });
        // A linear Q is bounded exactly on one box (monotone: no overestimation), so no
        // bisection: Q = 1 − 0.9x on [0, 1] in one box.
        assert!(matches!(prove(1, &[-0.9], (0.0, 1.0)), Positivity::Proven { boxes: 1, .. }));
        // The near-tangent quadratic needs bisection: more than one box.
        let q = prove(2, &[-4.0 / (1.0 + 1e-6), 4.0 / (1.0 + 1e-6)], (0.0, 1.0));
        assert!(matches!(q, Positivity::Proven { boxes, .. } if boxes > 1), "{q:?}");
    }

    #[test]
    fn a_sign_change_is_reported_where_first_seen() {
        // Q = 1 − 2x on [0, 1]: the first box's bound is −1 and its centre is the root itself,
        // so the proof stops there: the whole box, Q(½) = 0, the bound of the box.
        match prove(1, &[-2.0], (0.0, 1.0)) {
            Positivity::NotProven { lower, region, sample } => {
                assert_eq!(region, vec![(0.0, 1.0)]);
                assert_eq!(sample, 0.0);
                // A rigorous bound of the exact minimum −1, within a few ulps of it.
                assert!((-1.0 - 1e-14..=-1.0).contains(&lower), "{lower}");
            }
            p => panic!("{p:?}"),
        }
    }

    #[test]
    fn bisection_takes_the_widest_side() {
        // Q = 4(x ∓ ½)² + ε (scaled to Q(0) = 1, ε = 1e-3) needs x bisected; y has a zero
        // coefficient and a narrower side: far from zero, or starting at zero (end ratio ∞),
        // or beside an x side of negative ends. The proof holds only if the side bisected is
        // the widest, not the one with the largest ends, sum or ratio (bisecting y alone runs
        // into the 1e-9 width limit).
        let eps = 1e-3;
        let right = [-4.0 / (1.0 + eps), 4.0 / (1.0 + eps)]; // minimum at x = ½
        let left = [4.0 / (1.0 + eps), 4.0 / (1.0 + eps)]; // minimum at x = −½
        for (b, dom) in [
            (right, [(0.0, 1.0), (10.0, 10.001)]),
            (right, [(0.25, 1.25), (0.0, 0.001)]),
            (left, [(-1.0, 0.0), (0.0, 0.001)]),
        ] {
            let p = prove_xy(b, dom);
            assert!(matches!(p, Positivity::Proven { lower, .. } if lower > 1e-12 && lower <= eps / (1.0 + eps)), "{dom:?}: {p:?}");
        }
    }

    #[test]
    fn a_root_on_the_box_edge_stops_at_the_width_limit() {
        // Q = 1 − x on [0, 1]: zero at the edge x = 1, which no centre reaches (Q at a centre is
        // half the box width). Lower halves are proven, upper halves [1 − 2⁻ᵏ, 1] bisected until
        // the widest side is below 1e-9: k = 30 (2⁻³⁰ ≈ 9.3e-10, 2⁻²⁹ ≈ 1.9e-9). The region
        // reported is that box, its centre's Q 2⁻³¹, its bound at most the exact minimum 0.
        let k30 = (2.0f64).powi(-30);
        match prove(1, &[-1.0], (0.0, 1.0)) {
            Positivity::NotProven { lower, region, sample } => {
                assert_eq!(region, vec![(1.0 - k30, 1.0)]);
                assert_eq!(sample, k30 / 2.0);
                assert!(lower <= 0.0 && lower > -1e-15, "{lower}");
            }
            p => panic!("{p:?}"),
        }
    }

    #[test]
    fn the_width_limit_is_strict() {
        // Q = 1 − u with the derived feature u = 1 − x, i.e. Q = x, on [0, W], W = 1024·1e-9
        // (1e-9 scaled by a power of two: exact): zero at the edge x = 0, so the boxes
        // [0, W/2ᵏ] are bisected, their widths exact. [0, W/1024] is exactly 1e-9 wide, not
        // below it, so it is bisected once more and the proof stops at [0, W/2048].
        use crate::fit::model::{Derived, ModelParts, Term};
        let inputs = vec!["x".to_string()];
        let features = vec!["x".to_string(), "u".to_string()];
        let model = RationalModel::new(ModelParts {
            inputs: inputs.clone(),
            derived: vec![Derived::parse("u", "1 - x", &inputs).unwrap()],
            numerator: vec![Term::parse("1", &features).unwrap()],
            denominator: vec![Term::parse("u", &features).unwrap()],
            ..ModelParts::default()
        })
        .unwrap();
        let w = 1024.0 * 1e-9;
        assert_eq!(w / 1024.0, 1e-9);
        match prove_denominator_positive(&model, &DVector::from_vec(vec![1.0, -1.0]), &[(0.0, w)]) {
            Positivity::NotProven { region, .. } => assert_eq!(region, vec![(0.0, w / 2048.0)]),
            p => panic!("{p:?}"),
        }
    }

}
