//! Start candidates of a fit: the polynomial fit and Loeb's linearisation with its
//! Sanathanan–Koerner re-weightings, solved by SVD (module doc of `super`, item 1).

use super::*;

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

#[cfg(test)]
mod tests {
    use super::super::tests::*;
    use super::*;
    use crate::fit::model::{ModelParts, Term};

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
}
