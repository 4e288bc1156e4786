//! Proof that a denominator stays positive on a box, by interval arithmetic with bisection.
//!
//! Q(x) = 1 + Σ b_j ψ_j(x) is evaluated over a box with interval arithmetic (each monomial
//! an interval product of interval powers). If the lower bound is positive the box is done;
//! otherwise it is bisected along its widest side, down to a budget of boxes. Interval
//! evaluation over-estimates the range, never under-estimates it, so a positive lower bound
//! on every leaf is a proof (up to f64 rounding of the bound itself, which we absorb by
//! requiring the bound to exceed 1e-12).

use super::model::RationalModel;
use nalgebra::DVector;

#[derive(Debug, Clone, Copy)]
struct Iv(f64, f64);

impl Iv {
    fn mul(self, o: Iv) -> Iv {
        let p = [self.0 * o.0, self.0 * o.1, self.1 * o.0, self.1 * o.1];
        Iv(p.iter().cloned().fold(f64::INFINITY, f64::min), p.iter().cloned().fold(f64::NEG_INFINITY, f64::max))
    }
    fn powi(self, e: u32) -> Iv {
        if e == 0 {
            return Iv(1.0, 1.0);
        }
        let a = self.0.powi(e as i32);
        let b = self.1.powi(e as i32);
        if e % 2 == 0 && self.0 <= 0.0 && self.1 >= 0.0 {
            Iv(0.0, a.max(b))
        } else {
            Iv(a.min(b), a.max(b))
        }
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

fn term_range(t: &crate::fit::model::Term, feats: &[(f64, f64)]) -> Iv {
    let mut term = Iv(0.0, 0.0);
    for m in &t.monomials {
        let mut v = Iv(1.0, 1.0);
        for (e, r) in m.exps.iter().zip(feats) {
            v = v.mul(Iv(r.0, r.1).powi(*e));
        }
        term = Iv(term.0 + v.0, term.1 + v.1);
    }
    term
}

fn bound(model: &RationalModel, c: &DVector<f64>, region: &[(f64, f64)]) -> f64 {
    let nn = model.numerator.len();
    // Feature ranges: the inputs' box, then each derived feature's exact range over it.
    let mut feats = region.to_vec();
    feats.extend(model.derived.iter().map(|d| d.range(region)));
    let mut lo = model.lead.as_ref().map_or(1.0, |t| term_range(t, &feats).0);
    for (j, t) in model.denominator.iter().enumerate() {
        let term = term_range(t, &feats);
        let b = c[nn + j];
        lo += if b >= 0.0 { b * term.0 } else { b * term.1 };
    }
    lo
}

/// Prove Q > 0 on the box `domain` (one (min, max) per feature).
pub fn prove_denominator_positive(
    model: &RationalModel,
    c: &DVector<f64>,
    domain: &[(f64, f64)],
) -> Positivity {
    const MIN_BOUND: f64 = 1e-12;
    const BUDGET: usize = 200_000;
    let mut stack = vec![domain.to_vec()];
    let mut boxes = 0;
    let mut lowest = f64::INFINITY;
    while let Some(region) = stack.pop() {
        boxes += 1;
        let lo = bound(model, c, &region);
        if lo > MIN_BOUND {
            lowest = lowest.min(lo);
            continue;
        }
        let centre: Vec<f64> = region.iter().map(|r| 0.5 * (r.0 + r.1)).collect();
        let sample = model.denominator_at(c, &centre);
        let widest = region
            .iter()
            .enumerate()
            .max_by(|a, b| (a.1.1 - a.1.0).total_cmp(&(b.1.1 - b.1.0)))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let w = region[widest].1 - region[widest].0;
        if sample <= MIN_BOUND || boxes + stack.len() >= BUDGET || w < 1e-9 {
            return Positivity::NotProven { lower: lo, region, sample };
        }
        let mid = 0.5 * (region[widest].0 + region[widest].1);
        let mut a = region.clone();
        let mut b = region;
        a[widest].1 = mid;
        b[widest].0 = mid;
        stack.push(b);
        stack.push(a);
    }
    Positivity::Proven { lower: lowest, boxes }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_pole_and_proves_positive() {
        let m = RationalModel::rational_1d("x", 0, 1);
        // Q = 1 − 2x has a root at ½ inside [0, 1].
        let c = DVector::from_vec(vec![1.0, -2.0]);
        assert!(matches!(prove_denominator_positive(&m, &c, &[(0.0, 1.0)]), Positivity::NotProven { .. }));
        // Q = 1 − 0.9x ≥ 0.1 on [0, 1].
        let c = DVector::from_vec(vec![1.0, -0.9]);
        match prove_denominator_positive(&m, &c, &[(0.0, 1.0)]) {
            Positivity::Proven { lower, .. } => assert!(lower > 0.0 && lower <= 0.1 + 1e-12),
            other => panic!("{other:?}"),
        }
    }
}
