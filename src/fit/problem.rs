//! The least-squares problem of a rational model on data, seen through argmin's problem
//! traits (`Operator` = residuals, `Jacobian`, `CostFunction`, `Gradient`) and through the
//! `levenberg-marquardt` crate's `LeastSquaresProblem`. Solvers live in `solve.rs`.
//!
//! Residuals: r_i(θ) = w_i · (clamp(f(x_i; c(θ))) − y_i), c = Mθ + m₀ (see `model.rs`).
//! Where the clamp is active the residual is constant in θ and its Jacobian row is zero.

use super::model::{Basis, RationalModel};
use argmin::core::{CostFunction, Error as ArgminError, Gradient, Jacobian, Operator};
use levenberg_marquardt::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Dyn, Owned};

/// Samples of a target function: feature vectors and values.
#[derive(Debug, Clone, Default)]
pub struct Data {
    pub x: Vec<Vec<f64>>,
    pub y: Vec<f64>,
}

impl Data {
    pub fn len(&self) -> usize {
        self.y.len()
    }

    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Bounding box of the features: (min, max) per feature.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        let nf = self.x.first().map_or(0, Vec::len);
        (0..nf)
            .map(|j| {
                self.x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p[j]), hi.max(p[j]))
                })
            })
            .collect()
    }
}

/// A rational model bound to data with per-sample weights.
#[derive(Debug, Clone)]
pub struct Residuals<'a> {
    pub model: &'a RationalModel,
    pub basis: Vec<Basis>,
    pub y: &'a [f64],
    /// Square roots of the sample weights.
    pub sqrt_w: Vec<f64>,
    pub theta: DVector<f64>,
    /// Solve for Σ r⁴ instead of Σ r²: residuals become s_i = r_i·|r_i| (so Σ s_i² = Σ r_i⁴),
    /// with Jacobian 2|r_i|·∂r_i.
    pub fourth_power: bool,
}

impl<'a> Residuals<'a> {
    pub fn new(model: &'a RationalModel, data: &'a Data, theta: DVector<f64>) -> Self {
        Residuals {
            model,
            basis: data.x.iter().map(|x| model.basis(x)).collect(),
            y: &data.y,
            sqrt_w: vec![1.0; data.len()],
            theta,
            fourth_power: false,
        }
    }

    pub fn set_weights(&mut self, w: &[f64]) {
        self.sqrt_w = w.iter().map(|w| w.sqrt()).collect();
    }

    /// Unweighted residuals f(x_i) − y_i at θ.
    pub fn raw(&self, theta: &DVector<f64>) -> DVector<f64> {
        let c = self.model.full(theta);
        DVector::from_iterator(
            self.y.len(),
            self.basis.iter().zip(self.y).map(|(b, y)| self.clamped(b.value(&c, self.model.offset)) - y),
        )
    }

    fn clamped(&self, v: f64) -> f64 {
        match self.model.clamp {
            Some((lo, hi)) => v.clamp(lo, hi),
            None => v,
        }
    }

    pub fn weighted(&self, theta: &DVector<f64>) -> DVector<f64> {
        let r = self.raw(theta).component_mul(&DVector::from_column_slice(&self.sqrt_w));
        if self.fourth_power { r.map(|v| v * v.abs()) } else { r }
    }

    /// Jacobian of the weighted residuals with respect to θ.
    pub fn jacobian_at(&self, theta: &DVector<f64>) -> DMatrix<f64> {
        let c = self.model.full(theta);
        let nn = self.model.numerator.len();
        let nfull = self.model.n_full();
        let mut jc = DMatrix::zeros(self.y.len(), nfull);
        for (i, b) in self.basis.iter().enumerate() {
            let (p, q) = b.pq(&c);
            let v = self.model.offset + b.factor * p / q;
            if let Some((lo, hi)) = self.model.clamp
                && (v < lo || v > hi)
            {
                continue;
            }
            let s = self.sqrt_w[i] * b.factor / q;
            for (j, phi) in b.phi.iter().enumerate() {
                jc[(i, j)] = s * phi;
            }
            for (j, psi) in b.psi.iter().enumerate() {
                jc[(i, nn + j)] = -s * p / q * psi;
            }
        }
        let mut j = jc * self.model.map();
        if self.fourth_power {
            let r = self.raw(theta).component_mul(&DVector::from_column_slice(&self.sqrt_w));
            for (i, ri) in r.iter().enumerate() {
                j.row_mut(i).scale_mut(2.0 * ri.abs());
            }
        }
        j
    }
}

impl Operator for Residuals<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, theta: &Self::Param) -> Result<Self::Output, ArgminError> {
        Ok(self.weighted(theta))
    }
}

impl Jacobian for Residuals<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, theta: &Self::Param) -> Result<Self::Jacobian, ArgminError> {
        Ok(self.jacobian_at(theta))
    }
}

impl CostFunction for Residuals<'_> {
    type Param = DVector<f64>;
    type Output = f64;
    /// Weighted residual sum of squares.
    fn cost(&self, theta: &Self::Param) -> Result<f64, ArgminError> {
        Ok(self.weighted(theta).norm_squared())
    }
}

impl Gradient for Residuals<'_> {
    type Param = DVector<f64>;
    type Gradient = DVector<f64>;
    fn gradient(&self, theta: &Self::Param) -> Result<Self::Gradient, ArgminError> {
        Ok(2.0 * self.jacobian_at(theta).transpose() * self.weighted(theta))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Residuals<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
    }
    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.weighted(&self.theta);
        r.iter().all(|v| v.is_finite()).then_some(r)
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let j = self.jacobian_at(&self.theta);
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::model::{ModelParts, Term};

    fn model(fixed: Vec<(usize, f64)>, clamp: Option<(f64, f64)>) -> RationalModel {
        let f = vec!["x".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![t("1"), t("x"), t("x^2")],
            denominator: vec![t("x"), t("x^2")],
            offset: 0.25,
            fixed,
            clamp,
            ..ModelParts::default()
        })
        .unwrap()
    }

    /// The Jacobian of the weighted residuals (plain, weighted, Σr⁴'s s = r|r|, a fixed
    /// coefficient mapped out, samples at a clamp) against central differences of `weighted`.
    #[test]
    fn the_jacobian_is_that_of_the_weighted_residuals() {
        let x: Vec<Vec<f64>> = (0..25).map(|i| vec![i as f64 / 12.0]).collect();
        let data = Data { y: x.iter().map(|p| (1.3 * p[0]).sin() + 0.2).collect(), x };
        let cases = [(vec![], None), (vec![(1, 0.5)], None), (vec![], Some((0.0, 0.9)))];
        for (fixed, clamp) in cases {
            let m = model(fixed.clone(), clamp);
            let n = m.n_free();
            let theta = DVector::from_iterator(n, (0..n).map(|i| 0.4 * ((i as f64) * 2.3 + 0.5).cos()));
            let mut p = Residuals::new(&m, &data, theta.clone());
            if clamp.is_some() {
                let free = model(fixed.clone(), None);
                let v = Residuals::new(&free, &data, theta.clone()).raw(&theta) + DVector::from_column_slice(&data.y);
                // Samples on both sides of the clamp, none within the difference step of it.
                assert!(v.iter().any(|&v| v > 0.9 + 1e-3) && v.iter().any(|&v| v < 0.9 - 1e-3));
                assert!(v.iter().all(|&v| (v - 0.9).abs() > 1e-4 && v.abs() > 1e-4), "{v:?}");
            }
            for (weights, fourth) in [(false, false), (true, false), (false, true), (true, true)] {
                if weights {
                    p.set_weights(&(0..25).map(|i| 0.5 + (i % 3) as f64).collect::<Vec<_>>());
                } else {
                    p.set_weights(&[1.0; 25]);
                }
                p.fourth_power = fourth;
                let j = p.jacobian_at(&theta);
                let h = 1e-6;
                for k in 0..n {
                    let (mut tp, mut tm) = (theta.clone(), theta.clone());
                    tp[k] += h;
                    tm[k] -= h;
                    let fd = (p.weighted(&tp) - p.weighted(&tm)) / (2.0 * h);
                    // Central differences of smooth residuals (Q ≥ 0.6 here): truncation ~h²
                    // times third derivatives of O(10), rounding ~1e-16/h; r|r| is C¹ with a
                    // kink in its second derivative only at r = 0, none within h of a sample.
                    let err = (j.column(k) - &fd).amax();
                    assert!(err <= 1e-7 * fd.amax().max(1.0), "fixed {fixed:?}, clamp {clamp:?}, weights {weights}, r⁴ {fourth}, column {k}: off by {err:e}");
                }
            }
        }
    }

    /// argmin's cost and gradient of the residuals (for argmin's gradient solvers): the
    /// weighted residual sum of squares, summed here, and its central differences.
    #[test]
    fn the_cost_is_the_weighted_sum_of_squares_and_the_gradient_its_slope() {
        let x: Vec<Vec<f64>> = (0..25).map(|i| vec![i as f64 / 12.0]).collect();
        let data = Data { y: x.iter().map(|p| (1.3 * p[0]).sin() + 0.2).collect(), x };
        let m = model(vec![], None);
        let n = m.n_free();
        let theta = DVector::from_iterator(n, (0..n).map(|i| 0.4 * ((i as f64) * 2.3 + 0.5).cos()));
        let mut p = Residuals::new(&m, &data, theta.clone());
        p.set_weights(&(0..25).map(|i| 0.5 + (i % 3) as f64).collect::<Vec<_>>());
        let cost = |t: &DVector<f64>| p.weighted(t).iter().map(|r| r * r).sum::<f64>();
        let c = p.cost(&theta).unwrap();
        // Two summation orders of 25 positive terms: a few ulps of the sum.
        assert!((c - cost(&theta)).abs() <= 1e-14 * c, "{c} vs {}", cost(&theta));
        let g = p.gradient(&theta).unwrap();
        let h = 1e-6;
        for k in 0..n {
            let (mut tp, mut tm) = (theta.clone(), theta.clone());
            tp[k] += h;
            tm[k] -= h;
            let fd = (cost(&tp) - cost(&tm)) / (2.0 * h);
            // As in the Jacobian test: truncation ~h² times third derivatives of O(10^2) here
            // (a sum of 25 squares), rounding ~1e-16·cost/h.
            assert!((g[k] - fd).abs() <= 1e-6 * fd.abs().max(1.0), "component {k}: {} vs {fd}", g[k]);
        }
    }

    /// A sample whose model value lies exactly on a clamp limit keeps its Jacobian row: the
    /// derivative from inside the clamp, the side a descent that lowers its residual moves to.
    /// A zero row there would tell the solver that the residual cannot change. f = c₀ + c₁x
    /// with clamp [0, 1] at θ = (0, 1) meets 0 at x = 0 and 1 at x = 1; ∂f/∂c = (1, x), by hand.
    #[test]
    fn a_sample_on_a_clamp_limit_keeps_the_inside_derivative() {
        let f = vec!["x".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        let m = RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![t("1"), t("x")],
            clamp: Some((0.0, 1.0)),
            ..ModelParts::default()
        })
        .unwrap();
        let data = Data { x: vec![vec![0.0], vec![0.5], vec![1.0], vec![2.0]], y: vec![0.5; 4] };
        let theta = DVector::from_vec(vec![0.0, 1.0]);
        let p = Residuals::new(&m, &data, theta.clone());
        assert_eq!(p.raw(&theta).as_slice(), &[-0.5, 0.0, 0.5, 0.5], "on the limits at x = 0 and 1, clamped at x = 2");
        let j = p.jacobian_at(&theta);
        // Rows (1, x) on and inside the limits, zero where the clamp holds the value (x = 2).
        assert_eq!(j.row(0).iter().copied().collect::<Vec<_>>(), [1.0, 0.0], "x = 0, on the lower limit");
        assert_eq!(j.row(1).iter().copied().collect::<Vec<_>>(), [1.0, 0.5]);
        assert_eq!(j.row(2).iter().copied().collect::<Vec<_>>(), [1.0, 1.0], "x = 1, on the upper limit");
        assert_eq!(j.row(3).iter().copied().collect::<Vec<_>>(), [0.0, 0.0], "x = 2, clamped");
    }

    /// Σr⁴ through `weighted`: the squared norm of s = r|r| is Σr⁴ of the raw residuals, each
    /// weighted by w² (√w applied before squaring).
    #[test]
    fn the_fourth_power_residuals_sum_to_the_fourth_powers() {
        let m = model(vec![], None);
        let x: Vec<Vec<f64>> = (0..9).map(|i| vec![i as f64 / 8.0]).collect();
        let data = Data { y: x.iter().map(|p| p[0].exp()).collect(), x };
        let theta = DVector::from_vec(vec![0.9, 0.8, 0.1, -0.2, 0.05]);
        let mut p = Residuals::new(&m, &data, theta.clone());
        let w: Vec<f64> = (0..9).map(|i| 1.0 + i as f64).collect();
        p.set_weights(&w);
        p.fourth_power = true;
        let r = p.raw(&theta);
        let want: f64 = r.iter().zip(&w).map(|(r, w)| w * w * r.powi(4)).sum();
        // The same nine terms through sqrt and squares: a few ulps.
        assert!((p.weighted(&theta).norm_squared() - want).abs() <= 1e-14 * want, "{} vs {want}", p.weighted(&theta).norm_squared());
    }
}
