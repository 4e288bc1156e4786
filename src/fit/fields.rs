//! Two-stage fits of a function f(x, u) ≈ Σ_k c_k(x) b_k(u): at every grid point x_g a linear
//! basis b_k in the inner variables u (stage 1), and every coefficient c_k(x) a rational field
//! over the grid (stage 2), refined jointly so that what is minimised is the error of f itself.
//!
//! Stage 1 at x_g is the linear least-squares system B_g c ≈ y_g (rows: inner samples u_j,
//! columns: b_k(u_j)). A thin Householder QR, B_g = Q_g R_g, reduces it exactly to k equations:
//! ```text
//! ‖B_g c − y_g‖² = ‖R_g c − z_g‖² + ‖y_g‖² − ‖z_g‖²,    z_g = Q_gᵀ y_g
//! ```
//! for every c, whether or not B_g has full rank. So fitting the fields c_k(x; θ_k) to
//! minimise Σ_g ‖R_g c(x_g; θ) − z_g‖² is exactly least squares of f over all (x_g, u_j)
//! samples, with k residuals per grid point instead of one per sample. Where the basis is
//! nearly collinear (the stage-1 condition number is large) the per-point optimum ĉ_g is
//! ill-determined along the near-null direction, but R_g gives that direction a weight as
//! small as its effect on f: the fields need not follow ĉ_g there, and stay smooth.
//!
//! Minimax (and Σr⁴) objectives reweight the samples (Lawson's iteration for minimax) and
//! recompute the reduced systems from the weighted B_g, y_g; the joint problem is then solved
//! again from the previous optimum.
//!
//! Stage 2 starts from independent fits of each field to the per-point coefficients ĉ_k(x_g)
//! (minimum-norm solutions, rank cut at [`RCOND`]) through [`super::fit`], on the grid points
//! whose stage-1 condition number is below [`START_COND`]; the joint Levenberg–Marquardt
//! solve (MINPACK, `levenberg-marquardt` crate) then moves all fields together.

use super::model::{Basis, RationalModel};
use super::positivity::{prove_denominator_positive, Positivity};
use super::solve::{linearised_starts, FitError, Objective};
use super::Data;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// Relative singular-value cut-off of the minimum-norm stage-1 coefficients.
pub const RCOND: f64 = 1e-12;
/// Grid points whose stage-1 condition number is not below this are left out of the starting fits
/// (their ĉ are not determined to better than ~1e-9·cond by data accurate to ~1e-9).
pub const START_COND: f64 = 1e5;

/// Smallest relative sample weight of the reweighted objectives: with weights far below it
/// the grid points away from the worst errors stop constraining the fields, which then run
/// away there (seen as max errors of 10³ after a few IRLS steps at floor 1e-12).
pub const WEIGHT_FLOOR: f64 = 1e-2;

/// Every denominator is kept ≥ Q_MIN at the grid points by a barrier residual
/// Q_PENALTY·(Q_MIN − Q) where it is below (a field with a pole between samples can fit the
/// samples and still be useless); positivity on the whole domain is then proven by interval
/// arithmetic.
pub const Q_MIN: f64 = 0.05;
pub const Q_PENALTY: f64 = 100.0;

/// Outer (reweighting) iterations in a row without a proven improvement that end the search.
/// An iterate that improves on the best but whose denominators are not proven positive counts
/// as one: it is skipped, and the search goes on from it.
pub const PATIENCE: usize = 6;

/// The stage-1 system of one grid point reduced to k equations (see the module doc).
#[derive(Debug, Clone)]
pub struct Reduced {
    pub r: DMatrix<f64>,
    pub z: DVector<f64>,
    /// ‖y‖² − ‖z‖²: what no coefficient vector can fit (weighted when weights were given).
    pub floor: f64,
    /// RᵀR, the k×k metric of the point's coefficients in the normal equations.
    pub rtr: DMatrix<f64>,
}

/// Reduce B c ≈ y (rows weighted by `sqrt_w` when given) by a thin QR.
pub fn reduce(b: &DMatrix<f64>, y: &DVector<f64>, sqrt_w: Option<&[f64]>) -> Reduced {
    let (mut b, mut y) = (b.clone(), y.clone());
    if let Some(w) = sqrt_w {
        for (i, &s) in w.iter().enumerate() {
            b.row_mut(i).scale_mut(s);
            y[i] *= s;
        }
    }
    let k = b.ncols();
    let qr = b.qr();
    let mut qty = y.clone();
    qr.q_tr_mul(&mut qty);
    let z = qty.rows(0, k).into_owned();
    let floor = (y.norm_squared() - z.norm_squared()).max(0.0);
    let r = qr.r();
    let rtr = r.tr_mul(&r);
    Reduced { r, z, floor, rtr }
}

/// Stage-1 result of one grid point: the minimum-norm least-squares coefficients and the
/// 2-norm condition number σ_max/σ_min of the column-unscaled basis (∞ when rank-deficient).
#[derive(Debug, Clone, Serialize)]
pub struct Stage1 {
    pub coefficients: Vec<f64>,
    pub condition: f64,
}

pub fn stage1(b: &DMatrix<f64>, y: &DVector<f64>) -> Stage1 {
    let svd = b.clone().svd(true, true);
    let s = &svd.singular_values;
    let smax = s.max();
    let smin = s.min();
    let condition = if smin > 0.0 { smax / smin } else { f64::INFINITY };
    let c = svd.solve(y, RCOND * smax).unwrap_or_else(|_| DVector::zeros(b.ncols()));
    Stage1 { coefficients: c.iter().copied().collect(), condition }
}

/// The joint stage-2 problem: residuals R_g c(x_g; θ) − z_g for all grid points.
#[derive(Debug, Clone)]
pub struct Fields<'a> {
    pub models: &'a [RationalModel],
    /// basis[k][g]: basis values of field k at grid point g.
    basis: Vec<Vec<Basis>>,
    pub systems: Vec<Reduced>,
    /// Offsets of θ_k in the concatenated parameter vector.
    starts: Vec<usize>,
    /// Whether field k's parameter map θ_k → c_k is the identity (no fixed coefficient or pin):
    /// then ∂c/∂θ_k is ∂c/∂c_k itself and the product with the map is skipped.
    identity: Vec<bool>,
    pub theta: DVector<f64>,
}

impl<'a> Fields<'a> {
    pub fn new(models: &'a [RationalModel], x: &[Vec<f64>], systems: Vec<Reduced>, theta: DVector<f64>) -> Self {
        let basis = models.iter().map(|m| x.iter().map(|p| m.basis(p)).collect()).collect();
        let mut starts = Vec::with_capacity(models.len() + 1);
        let mut s = 0;
        for m in models {
            starts.push(s);
            s += m.n_free();
        }
        starts.push(s);
        let identity = models.iter().map(|m| m.map().is_square() && m.map().is_identity(0.0)).collect();
        Fields { models, basis, systems, starts, identity, theta }
    }

    pub fn n_params(&self) -> usize {
        *self.starts.last().unwrap_or(&0)
    }

    /// Full coefficients of every field from the concatenated θ.
    pub fn full(&self, theta: &DVector<f64>) -> Vec<DVector<f64>> {
        self.models
            .iter()
            .enumerate()
            .map(|(k, m)| m.full(&theta.rows(self.starts[k], m.n_free()).into_owned()))
            .collect()
    }

    /// Field values c_k(x_g) at every grid point: values[g][k].
    pub fn values(&self, theta: &DVector<f64>) -> Vec<Vec<f64>> {
        let full = self.full(theta);
        let ng = self.systems.len();
        (0..ng)
            .into_par_iter()
            .map(|g| {
                self.models.iter().enumerate().map(|(k, m)| self.basis[k][g].value(&full[k], m.offset)).collect()
            })
            .collect()
    }

    fn residuals_at(&self, theta: &DVector<f64>) -> DVector<f64> {
        let nk = self.models.len();
        let vals = self.values(theta);
        let rows: Vec<DVector<f64>> = self
            .systems
            .par_iter()
            .zip(vals.par_iter())
            .map(|(s, c)| &s.r * DVector::from_column_slice(c) - &s.z)
            .collect();
        let mut out = DVector::zeros(self.systems.len() * nk);
        for (g, r) in rows.iter().enumerate() {
            out.rows_mut(g * nk, nk).copy_from(r);
        }
        out
    }

    /// Gauss–Newton normal equations at θ: (JᵀJ, Jᵀr, ‖r‖²). J is block-sparse: the rows of
    /// grid point g are R_g·D_g with D_g holding ∂c_k(x_g)/∂θ_k in row k, so
    /// (JᵀJ)[k, l] = Σ_g (R_gᵀR_g)[k, l] · d_k(g) d_l(g)ᵀ and (Jᵀr)[k] = Σ_g (R_gᵀ r_g)[k] d_k(g):
    /// k² small outer products per point instead of a dense product of J.
    ///
    /// A first pass over the points (in parallel, each point on its own) computes every d_k(g)
    /// and the residuals, the cost and Jᵀr are summed over them in grid order; then each block (k, l ≥ k) of JᵀJ is summed on its own ([`block`], in
    /// parallel), every entry over the points in grid order, so the result does not depend on
    /// the number of threads.
    fn normal_equations(&self, theta: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>, f64) {
        let nk = self.models.len();
        let full = self.full(theta);
        let np = self.n_params();
        let ng = self.systems.len();
        let mut grad = DVector::zeros(np);
        let mut cost = 0.0;
        // d_k(g) at dall[g·np + starts[k]..], the weights (R_gᵀR_g)[k, l] at w[g·nk² + k·nk + l],
        // and the barrier gradients of the fields whose denominator is below Q_MIN at g.
        let mut dall = vec![0.0; ng * np];
        let mut w = vec![0.0; ng * nk * nk];
        // Per point (in parallel, each writing its own rows of dall and w): d_k(g), the barrier
        // terms (k, residual, gradient) of the fields below Q_MIN, r_g and R_gᵀ r_g.
        type Pass = (Vec<(usize, f64, DVector<f64>)>, DVector<f64>, DVector<f64>);
        let per_point: Vec<Pass> = dall
            .par_chunks_mut(np)
            .zip(w.par_chunks_mut(nk * nk))
            .zip(self.systems.par_iter())
            .enumerate()
            .map(|(g, ((dg, wg), s))| {
                let mut bars = Vec::new();
                let mut c = DVector::zeros(nk);
                for (k, m) in self.models.iter().enumerate() {
                    let nn = m.numerator.len();
                    let b = &self.basis[k][g];
                    let (p, q) = b.pq(&full[k]);
                    c[k] = m.offset + b.factor * p / q;
                    let f = b.factor / q;
                    let mut df = DVector::zeros(m.n_full());
                    for (i, phi) in b.phi.iter().enumerate() {
                        df[i] = f * phi;
                    }
                    for (i, psi) in b.psi.iter().enumerate() {
                        df[nn + i] = -f * p / q * psi;
                    }
                    let (sk, nkf) = (self.starts[k], m.n_free());
                    let dk = &mut dg[sk..sk + nkf];
                    if self.identity[k] {
                        dk.copy_from_slice(df.as_slice());
                    } else {
                        dk.copy_from_slice(m.map().tr_mul(&df).as_slice());
                    }
                    if q < Q_MIN {
                        // Barrier residual Q_PENALTY·(Q_MIN − Q): ∂/∂den_i = −Q_PENALTY·ψ_i.
                        let mut dq = DVector::zeros(m.n_full());
                        for (i, psi) in b.psi.iter().enumerate() {
                            dq[nn + i] = -Q_PENALTY * psi;
                        }
                        bars.push((k, Q_PENALTY * (Q_MIN - q), m.map().tr_mul(&dq)));
                    }
                }
                let r = &s.r * &c - &s.z;
                let v = s.r.tr_mul(&r);
                wg.copy_from_slice(s.rtr.transpose().as_slice());
                (bars, r, v)
            })
            .collect();
        // The cost and Jᵀr summed over the points in grid order.
        let mut barrier: Vec<(usize, usize, DVector<f64>)> = Vec::new();
        for (g, (bars, r, v)) in per_point.into_iter().enumerate() {
            for (k, rq, dq) in bars {
                let (sk, nkf) = (self.starts[k], self.models[k].n_free());
                cost += rq * rq;
                grad.rows_mut(sk, nkf).axpy(rq, &dq, 1.0);
                barrier.push((g, k, dq));
            }
            cost += r.norm_squared();
            for k in 0..nk {
                let (sk, nkf) = (self.starts[k], self.models[k].n_free());
                let dk = DVector::from_column_slice(&dall[g * np + sk..g * np + sk + nkf]);
                grad.rows_mut(sk, nkf).axpy(v[k], &dk, 1.0);
            }
        }
        let pairs: Vec<(usize, usize)> = (0..nk).flat_map(|k| (k..nk).map(move |l| (k, l))).collect();
        let blocks: Vec<Vec<f64>> = pairs
            .par_iter()
            .map(|&(k, l)| {
                let rows = (self.starts[k], self.models[k].n_free());
                let cols = (self.starts[l], self.models[l].n_free());
                let bar: Vec<(usize, &[f64])> =
                    if k == l { barrier.iter().filter(|b| b.1 == k).map(|b| (b.0, b.2.as_slice())).collect() } else { Vec::new() };
                block(&dall, np, &w, nk, (k, l), rows, cols, &bar)
            })
            .collect();
        let mut a = DMatrix::zeros(np, np);
        for (&(k, l), blk) in pairs.iter().zip(&blocks) {
            let (sk, nkf) = (self.starts[k], self.models[k].n_free());
            let (sl, nlf) = (self.starts[l], self.models[l].n_free());
            let m = DMatrix::from_column_slice(nkf, nlf, blk);
            a.view_mut((sk, sl), (nkf, nlf)).copy_from(&m);
            if k != l {
                a.view_mut((sl, sk), (nlf, nkf)).copy_from(&m.transpose());
            }
        }
        (a, grad, cost)
    }

    pub fn cost(&self, theta: &DVector<f64>) -> f64 {
        let full = self.full(theta);
        let mut pen = 0.0;
        for (k, bk) in self.basis.iter().enumerate() {
            let qs: Vec<f64> = bk.par_iter().map(|b| b.pq(&full[k]).1).collect();
            for q in qs {
                if q < Q_MIN {
                    pen += (Q_PENALTY * (Q_MIN - q)).powi(2);
                }
            }
        }
        self.residuals_at(theta).norm_squared() + pen
    }
}

/// Block (k, l) of JᵀJ (column-major, rows d_k, columns d_l): Σ_g w_g[k, l]·d_k(g) d_l(g)ᵀ
/// plus, on a diagonal block, the barrier terms dq dqᵀ of the points in `barrier` (each before
/// the point's own term). Every entry is accumulated over the points in grid order as
/// (w·d_l[j])·d_k[i] + A[i, j], the operations of nalgebra's `ger` one point at a time, on a
/// block small enough to stay in the first-level cache.
///
/// The same loops are also compiled for AVX2 and taken where the processor has it: the
/// operations per entry and their order are the same (Rust does not contract a·b + c into a
/// fused multiply-add), only more entries go through one instruction, so the bits are the same.
#[allow(clippy::too_many_arguments)]
fn block(
    dall: &[f64],
    np: usize,
    w: &[f64],
    nk: usize,
    kl: (usize, usize),
    rows: (usize, usize),
    cols: (usize, usize),
    barrier: &[(usize, &[f64])],
) -> Vec<f64> {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: AVX2 is present (checked just above), the one requirement of `block_avx2`.
        return unsafe { block_avx2(dall, np, w, nk, kl, rows, cols, barrier) };
    }
    block_loops(dall, np, w, nk, kl, rows, cols, barrier)
}

/// [`block_loops`] compiled with AVX2 enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
unsafe fn block_avx2(
    dall: &[f64],
    np: usize,
    w: &[f64],
    nk: usize,
    kl: (usize, usize),
    rows: (usize, usize),
    cols: (usize, usize),
    barrier: &[(usize, &[f64])],
) -> Vec<f64> {
    block_loops(dall, np, w, nk, kl, rows, cols, barrier)
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn block_loops(
    dall: &[f64],
    np: usize,
    w: &[f64],
    nk: usize,
    (k, l): (usize, usize),
    (sk, nkf): (usize, usize),
    (sl, nlf): (usize, usize),
    barrier: &[(usize, &[f64])],
) -> Vec<f64> {
    let mut out = vec![0.0; nkf * nlf];
    let mut next_barrier = 0;
    for (g, dg) in dall.chunks_exact(np).enumerate() {
        if let Some(&(gb, dq)) = barrier.get(next_barrier)
            && gb == g
        {
            next_barrier += 1;
            // ger(1.0, dq, dq): (1·dq[j])·dq[i], and 1·dq[j] is dq[j] exactly.
            for (col, &t) in out.chunks_exact_mut(nkf).zip(dq) {
                for (x, &dqi) in col.iter_mut().zip(dq) {
                    *x += t * dqi;
                }
            }
        }
        let wg = w[g * nk * nk + k * nk + l];
        if wg == 0.0 {
            continue;
        }
        let dk = &dg[sk..sk + nkf];
        let dl = &dg[sl..sl + nlf];
        for (col, &dlj) in out.chunks_exact_mut(nkf).zip(dl) {
            let t = wg * dlj;
            for (x, &dki) in col.iter_mut().zip(dk) {
                *x += t * dki;
            }
        }
    }
    out
}

/// The samples of one grid point: the stage-1 design matrix (inner samples × basis) and the
/// values of f there.
#[derive(Debug, Clone)]
pub struct PointData {
    pub design: DMatrix<f64>,
    pub y: DVector<f64>,
}

/// Options of a two-stage fit.
#[derive(Debug, Clone, Copy)]
pub struct FieldOptions {
    pub objective: Objective,
    /// Outer reweighting iterations (minimax, l4; l4 at most 12).
    pub outer_iters: usize,
    /// LM iterations per outer iteration (each starts from the previous optimum, and the
    /// reweighting only needs to move it, not converge it).
    pub inner_iters: usize,
    /// Minimax under a cap on the rms error: the iterate with the lowest max error among
    /// those whose rms is at most this.
    pub max_rms: Option<f64>,
}

impl Default for FieldOptions {
    fn default() -> Self {
        FieldOptions { objective: Objective::Lsq, outer_iters: 60, inner_iters: 25, max_rms: None }
    }
}

/// Result of a two-stage fit.
#[derive(Debug, Clone)]
pub struct FieldsFit {
    /// Full coefficients of every field.
    pub coefficients: Vec<DVector<f64>>,
    pub stage1: Vec<Stage1>,
    /// Max and rms error of f over all samples of the fitting grid.
    pub max_abs_error: f64,
    pub rms_error: f64,
    /// Same for the per-point stage-1 optimum (the floor of the inner basis in the rms sense).
    pub stage1_max_abs_error: f64,
    pub stage1_rms_error: f64,
    pub lm_evaluations: usize,
    pub outer_iterations: usize,
}

/// Errors of the fields at θ over all samples: (max abs, rms, per-sample residuals).
fn sample_errors(fields: &Fields<'_>, theta: &DVector<f64>, data: &[PointData]) -> (f64, f64, Vec<DVector<f64>>) {
    let vals = fields.values(theta);
    let res: Vec<DVector<f64>> =
        data.par_iter().zip(vals.par_iter()).map(|(d, c)| &d.design * DVector::from_column_slice(c) - &d.y).collect();
    let (mut max, mut ss, mut n) = (0.0f64, 0.0, 0usize);
    for e in &res {
        for v in e.iter() {
            max = if v.is_nan() { f64::INFINITY } else { max.max(v.abs()) };
            ss += v * v;
        }
        n += e.len();
    }
    (max, (ss / n.max(1) as f64).sqrt(), res)
}

/// One reweighting step of [`fit_fields`]'s outer loop from the residuals `res` of the current
/// θ: Lawson's weights (L4: a damped step towards e²), the weighted systems, a warm-started joint solve. `None` when
/// the weights degenerate (all 0, or one not finite) or the solve fails (the loop stops); otherwise (residual
/// evaluations, max error, rms error, residuals) at the new θ.
fn outer_step(
    fields: &mut Fields<'_>,
    w: &mut [Vec<f64>],
    res: &[DVector<f64>],
    data: &[PointData],
    opts: &FieldOptions,
    what: &str,
) -> Option<(usize, f64, f64, Vec<DVector<f64>>)> {
    // Lawson: w ← w·|e|; L4: w ← √(w·e²), a damped step towards the IRLS weights e² of Σe⁴
    // (taken whole, e² makes the iterates oscillate and grow: on the noisy test problem Σe⁴
    // rose 3× and 12× in 4 steps); scaled to max 1 and floored.
    for (wg, eg) in w.iter_mut().zip(res) {
        for (wi, ei) in wg.iter_mut().zip(eg.iter()) {
            *wi = match opts.objective {
                Objective::L4 => (*wi * ei * ei).sqrt(),
                _ => *wi * ei.abs(),
            };
        }
    }
    let top = w.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
    if !(top > 0.0) || !top.is_finite() {
        return None;
    }
    w.iter_mut().flatten().for_each(|wi| *wi = (*wi / top).max(WEIGHT_FLOOR));
    fields.systems = data
        .par_iter()
        .zip(w.par_iter())
        .map(|(d, wg)| {
            let s: Vec<f64> = wg.iter().map(|v| v.sqrt()).collect();
            reduce(&d.design, &d.y, Some(&s))
        })
        .collect();
    let evals = solve_joint(fields, opts.inner_iters, what).ok()?;
    let (m, rr, r) = sample_errors(fields, &fields.theta, data);
    Some((evals, m, rr, r))
}

/// Levenberg–Marquardt on the normal equations (JᵀJ + λ·diag(JᵀJ)) δ = −Jᵀr, solved by
/// Cholesky. The joint system is small in parameters (a few hundred) and tall in residuals;
/// forming JᵀJ with a blocked product is far cheaper than a column-pivoted QR of J each
/// iteration, and the Marquardt scaling keeps the solve well-posed. A trial is taken only when
/// it lowers the cost; each refused trial multiplies λ (from 1e-4) by 4, and a point no trial
/// improves before λ reaches 1e16 ends the solve, as do three steps taken in a row that each
/// lower the cost by less than 1e-10 of it. Returns the number of residual evaluations
/// (the start's and every trial's).
fn solve_joint(fields: &mut Fields<'_>, max_iters: usize, what: &str) -> Result<usize, FitError> {
    let mut theta = fields.theta.clone();
    let mut cost = fields.cost(&theta);
    if !cost.is_finite() {
        return Err(FitError::Diverged { what: what.into(), iters: 0, residual: cost });
    }
    let mut lambda = 1e-4;
    let mut evals = 1;
    let mut small_steps = 0;
    for _ in 0..max_iters {
        let (a, g, _) = fields.normal_equations(&theta);
        let d: Vec<f64> = (0..a.nrows()).map(|i| a[(i, i)].max(1e-300)).collect();
        let mut accepted = false;
        while lambda < 1e16 {
            let mut m = a.clone();
            for (i, di) in d.iter().enumerate() {
                m[(i, i)] += lambda * di;
            }
            let Some(ch) = m.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let step = ch.solve(&(-&g));
            let trial = &theta + &step;
            evals += 1;
            let ct = fields.cost(&trial);
            if ct.is_finite() && ct < cost {
                let gain = (cost - ct) / cost.max(f64::MIN_POSITIVE);
                theta = trial;
                cost = ct;
                lambda = (lambda / 3.0).max(1e-12);
                accepted = true;
                small_steps = if gain < 1e-10 { small_steps + 1 } else { 0 };
                break;
            }
            lambda *= 4.0;
        }
        if !accepted || small_steps >= 3 {
            break;
        }
    }
    fields.theta.copy_from(&theta);
    Ok(evals)
}

/// The joint start of index `c`: every field's candidate `c`, or its last one when it has fewer
/// (a start whose solve was not finite is dropped, so fields can have different counts),
/// concatenated in field order. Every field has at least one candidate.
fn start_set(per_field: &[Vec<DVector<f64>>], c: usize) -> DVector<f64> {
    DVector::from_vec(per_field.iter().flat_map(|s| s[c.min(s.len() - 1)].iter().copied()).collect())
}

/// Fit the fields `models` (one per basis function) over the grid points `x` to the samples
/// `data` (one [`PointData`] per grid point, same order).
pub fn fit_fields(
    models: &[RationalModel],
    x: &[Vec<f64>],
    data: &[PointData],
    opts: &FieldOptions,
    what: &str,
) -> Result<FieldsFit, FitError> {
    if data.is_empty() || data.len() != x.len() {
        return Err(FitError::NoData { what: what.into() });
    }
    // Stage 1.
    // Per-point work (stage 1, the reduced systems, residuals) runs in parallel and is
    // collected in grid order; every sum over points stays sequential in that order.
    let stage1: Vec<Stage1> = data.par_iter().map(|d| stage1(&d.design, &d.y)).collect();
    let (mut s1max, mut s1ss, mut s1n) = (0.0f64, 0.0, 0usize);
    for (d, s) in data.iter().zip(&stage1) {
        let e = &d.design * DVector::from_column_slice(&s.coefficients) - &d.y;
        s1max = s1max.max(e.amax());
        s1ss += e.norm_squared();
        s1n += e.len();
    }
    // Starting fields: each fitted alone to the well-conditioned ĉ_k.
    let good: Vec<usize> = (0..x.len()).filter(|&g| stage1[g].condition < START_COND).collect();
    let systems: Vec<Reduced> = data.par_iter().map(|d| reduce(&d.design, &d.y, None)).collect();
    // Candidate starts per field: the linearised ones (polynomial, Loeb, Sanathanan–Koerner)
    // of the field fitted alone; every field takes the candidate of the same index (or its
    // last one), and the joint cost picks the set (of sets of equal cost the first: the
    // polynomial start, every denominator 1, before the rational ones).
    let mut per_field = Vec::with_capacity(models.len());
    for (k, m) in models.iter().enumerate() {
        let d = Data {
            x: good.iter().map(|&g| x[g].clone()).collect(),
            y: good.iter().map(|&g| stage1[g].coefficients[k]).collect(),
        };
        per_field.push(linearised_starts(m, &d, &format!("{what} (start of field {k})"))?);
    }
    let n_cand = per_field.iter().map(Vec::len).max().unwrap_or(0);
    let probe = Fields::new(models, x, systems.clone(), DVector::zeros(0));
    let mut theta = DVector::zeros(0);
    let mut best_cost = f64::INFINITY;
    for c in 0..n_cand {
        let t = start_set(&per_field, c);
        let cost = probe.cost(&t);
        if cost < best_cost {
            best_cost = cost;
            theta = t;
        }
    }
    if !best_cost.is_finite() {
        return Err(FitError::SingularStart { what: what.into() });
    }
    let mut fields = Fields::new(models, x, systems, theta);
    let domain = Data { x: x.to_vec(), y: vec![] }.bounds();
    // The fields' proofs are independent: in parallel (the answer is the same either way).
    let positive = |full: &[DVector<f64>]| {
        full.par_iter()
            .zip(models.par_iter())
            .all(|(c, m)| matches!(prove_denominator_positive(m, c, &domain), Positivity::Proven { .. }))
    };
    let mut evals = solve_joint(&mut fields, 500, what)?;
    let mut outer = 0;
    // Whether fields.theta is known to have every denominator proven positive (the outer loop
    // keeps only proven iterates).
    let mut proven = false;
    if opts.objective != Objective::Lsq {
        // IRLS for Σ|e|^p: weights |e|^(p−2) at the previous optimum. Minimax continues p
        // upward (the L_p optimum tends to the minimax one as p → ∞); jumping straight to
        // Lawson's multiplicative weights concentrates them on a few grid points and lets
        // the fields run away elsewhere. The iterate with the lowest max error (for L4, the
        // lowest Σe⁴: plain IRLS for p = 4 need not descend, and may end above its least-squares
        // start) is kept; with an rms cap, only iterates under it qualify.
        //
        // PATIENCE iterations in a row without a proven improvement end the search.
        //
        // An iterate that qualifies by its errors still needs its denominators proven; that
        // proof runs beside the next iteration, which does not depend on it. When the proof's
        // answer ends the loop, the next iteration is dropped uncounted, so the iterates,
        // counts and result are those of doing each step after the previous proof.
        let n_outer = match opts.objective {
            // The damped L4 steps settle Σe⁴ to 1e-6 relative in ~10.
            Objective::L4 => opts.outer_iters.min(12),
            _ => opts.outer_iters,
        };
        let rms_ok = |rms: f64| opts.max_rms.is_none_or(|cap| rms <= cap);
        // What the objective ranks iterates by (a NaN residual ranks last).
        let score = |max: f64, res: &[DVector<f64>]| match opts.objective {
            Objective::L4 => res.iter().flat_map(|e| e.iter()).map(|v| (v * v) * (v * v)).sum::<f64>(),
            _ => max,
        };
        let (m0, r0, mut res) = sample_errors(&fields, &fields.theta, data);
        let ok0 = rms_ok(r0) && positive(&fields.full(&fields.theta));
        let mut best = (if ok0 { score(m0, &res) } else { f64::INFINITY }, fields.theta.clone());
        let mut w: Vec<Vec<f64>> = data.iter().map(|d| vec![1.0; d.y.len()]).collect();
        let mut since_best = 0;
        // (score, θ, full coefficients) of an iterate awaiting its proof.
        let mut pending: Option<(f64, DVector<f64>, Vec<DVector<f64>>)> = None;
        loop {
            let more = outer < n_outer;
            let (answer, step) = rayon::join(
                || pending.as_ref().map(|(_, _, full)| positive(full)),
                || more.then(|| outer_step(&mut fields, &mut w, &res, data, opts, what)),
            );
            if let (Some((m, theta, _)), Some(ok)) = (pending.take(), answer) {
                if ok {
                    best = (m, theta);
                    since_best = 0;
                } else {
                    since_best += 1;
                    if since_best >= PATIENCE {
                        break;
                    }
                }
            }
            let Some(step) = step else { break };
            outer += 1;
            let Some((e, m, rr, r)) = step else { break };
            evals += e;
            let s = score(m, &r);
            res = r;
            if s < best.0 && rms_ok(rr) {
                pending = Some((s, fields.theta.clone(), fields.full(&fields.theta)));
            } else {
                since_best += 1;
                if since_best >= PATIENCE {
                    break;
                }
            }
        }
        if !best.0.is_finite() {
            return Err(FitError::Solver {
                what: what.into(),
                msg: format!(
                    "no iterate had every denominator proven positive{}",
                    opts.max_rms.map_or(String::new(), |c| format!(" and rms ≤ {c:e}"))
                ),
            });
        }
        fields.theta = best.1;
        proven = true;
    }
    let (max, rms, _) = sample_errors(&fields, &fields.theta, data);
    if !proven && !positive(&fields.full(&fields.theta)) {
        let full = fields.full(&fields.theta);
        let (k, lower, region) = models
            .iter()
            .zip(&full)
            .enumerate()
            .find_map(|(k, (m, c))| match prove_denominator_positive(m, c, &domain) {
                Positivity::NotProven { lower, region, .. } => Some((k, lower, region)),
                Positivity::Proven { .. } => None,
            })
            .unwrap_or((0, f64::NAN, vec![]));
        return Err(FitError::PoleInDomain { what: format!("{what} (field {k})"), lower, region });
    }
    if !max.is_finite() {
        return Err(FitError::Diverged { what: what.into(), iters: evals, residual: max });
    }
    Ok(FieldsFit {
        coefficients: fields.full(&fields.theta),
        stage1,
        max_abs_error: max,
        rms_error: rms,
        stage1_max_abs_error: s1max,
        stage1_rms_error: (s1ss / s1n.max(1) as f64).sqrt(),
        lm_evaluations: evals,
        outer_iterations: outer,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::model::{ModelParts, Term};

    fn field(offset: f64) -> RationalModel {
        let f = vec!["x".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![t("1"), t("x"), t("x^2")],
            denominator: vec![t("x")],
            offset,
            factor: Some(t("x")),
            ..ModelParts::default()
        })
        .unwrap()
    }

    /// Exact fields c_k(x) = s_k + x·(a0 + a1 x + a2 x²)/(1 + b x).
    const TRUE: [[f64; 4]; 3] = [[1.0, -0.5, 0.25, 0.4], [-0.3, 0.8, 0.1, -0.2], [0.6, 0.2, -0.7, 0.3]];
    const OFFSETS: [f64; 3] = [0.5, 0.0, 0.0];

    fn truth(k: usize, x: f64) -> f64 {
        let a = TRUE[k];
        OFFSETS[k] + x * (a[0] + a[1] * x + a[2] * x * x) / (1.0 + a[3] * x)
    }

    /// Basis [1, u, v] with v = x·w + (1 − x)·u over inner samples (u, w): at x = 0 the
    /// columns u and v coincide (rank 2), like u·t → u·n as θf → 0.
    fn problem() -> (Vec<Vec<f64>>, Vec<PointData>) {
        problem_on(20, |x| truth(0, x), |_, _| 0.0)
    }

    /// The basis of [`problem`] on n + 1 uniform points of [0, 1], with `first(x)` as the first
    /// field and `noise(x, r)` added to sample r.
    fn problem_on(n: usize, first: impl Fn(f64) -> f64, noise: impl Fn(f64, usize) -> f64) -> (Vec<Vec<f64>>, Vec<PointData>) {
        let xs: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        let inner: Vec<(f64, f64)> =
            (0..6).flat_map(|i| (0..6).map(move |j| (i as f64 / 5.0 - 0.5, (j as f64 * 0.37).sin()))).collect();
        let data = xs
            .iter()
            .map(|&x| {
                let mut b = DMatrix::zeros(inner.len(), 3);
                let mut y = DVector::zeros(inner.len());
                for (r, &(u, w)) in inner.iter().enumerate() {
                    let v = x * w + (1.0 - x) * u;
                    b[(r, 0)] = 1.0;
                    b[(r, 1)] = u;
                    b[(r, 2)] = v;
                    y[r] = first(x) + truth(1, x) * u + truth(2, x) * v + noise(x, r);
                }
                PointData { design: b, y }
            })
            .collect();
        (xs.iter().map(|&x| vec![x]).collect(), data)
    }

    /// A least-squares fields fit is returned only with every denominator proven positive on
    /// the data's domain. Exact fields whose first denominator is 1 − 1.5x, zero at x = 2/3
    /// inside [0, 1] (between the samples 0.65 and 0.7), are refused with a pole in field 0:
    /// whatever the fit found, its first denominator was not proven positive.
    #[test]
    fn a_least_squares_fit_with_a_pole_in_the_domain_is_refused() {
        let a = TRUE[0];
        let (x, data) = problem_on(20, |x| OFFSETS[0] + x * (a[0] + a[1] * x + a[2] * x * x) / (1.0 - 1.5 * x), |_, _| 0.0);
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        match fit_fields(&models, &x, &data, &FieldOptions::default(), "pole") {
            Err(FitError::PoleInDomain { what, lower, .. }) => assert!(what == "pole (field 0)" && !(lower > 1e-12), "{what}: lower {lower}"),
            other => panic!("expected a pole in field 0, got {other:?}"),
        }
    }

    /// Start set c takes candidate c of every field that has one and the last candidate of
    /// each field that has fewer, in field order.
    #[test]
    fn a_field_with_fewer_candidates_lends_its_last_to_later_start_sets() {
        let v = |s: &[f64]| DVector::from_row_slice(s);
        let per_field = vec![vec![v(&[1.0, 2.0]), v(&[3.0, 4.0]), v(&[5.0, 6.0])], vec![v(&[-1.0])], vec![v(&[7.0]), v(&[8.0])]];
        assert_eq!(start_set(&per_field, 0).as_slice(), [1.0, 2.0, -1.0, 7.0]);
        assert_eq!(start_set(&per_field, 1).as_slice(), [3.0, 4.0, -1.0, 8.0]);
        assert_eq!(start_set(&per_field, 2).as_slice(), [5.0, 6.0, -1.0, 8.0]);
    }

    /// One field a₀/(1 + b·x) on ĉ = 1/(1 + x) at x = 0, ¼, ½, ¾, 1 (a basis of one column of
    /// ones), and a grid point whose basis is 0 (condition ∞, so it takes no part in the starts)
    /// with the sample 2⁴⁰: no field reaches it, and its 2⁸⁰ in every cost absorbs the other
    /// points' squares (< 1, below half its ulp 2²⁸), so every start set and every trial of a
    /// joint solve cost the same, bit for bit. Returns the model, the grid and the data, and the
    /// five ĉ as data of the field alone.
    fn absorbed() -> ([RationalModel; 1], Vec<Vec<f64>>, Vec<PointData>, Data) {
        let xs = [0.0, 0.25, 0.5, 0.75, 1.0];
        let point = |b: f64, y: f64| PointData { design: DMatrix::from_element(1, 1, b), y: DVector::from_element(1, y) };
        let mut data: Vec<PointData> = xs.iter().map(|&x| point(1.0, 1.0 / (1.0 + x))).collect();
        data.push(point(0.0, 2f64.powi(40)));
        let x: Vec<Vec<f64>> = xs.iter().chain(&[0.5]).map(|&v| vec![v]).collect();
        let alone = Data { x: x[..5].to_vec(), y: xs.iter().map(|x| 1.0 / (1.0 + x)).collect() };
        ([RationalModel::rational_1d("x", 0, 1)], x, data, alone)
    }

    /// (a₀, b) is the least-squares constant of [`absorbed`]'s ĉ: a₀ their mean, b = 0.
    fn is_the_least_squares_constant(c: &DVector<f64>, alone: &Data) {
        let mean = alone.y.iter().sum::<f64>() / 5.0;
        // The SVD solve of a column of ones: rounding of a five-term mean, ~1e-16 of values ~0.7.
        assert!((c[0] - mean).abs() < 1e-14 && c[1].abs() < 1e-14, "({}, {}), expected ({mean}, 0)", c[0], c[1]);
    }

    /// Of start sets whose joint costs tie, the first is kept: the polynomial start (every
    /// denominator 1) before the rational ones. On [`absorbed`] every trial of the joint solve is
    /// refused, so the fit is the start set chosen: the least-squares constant, a₀ the mean of
    /// the ĉ and b = 0, where the rational starts, (a₀, b) ≈ (1, 1), fit the ĉ exactly.
    #[test]
    fn of_start_sets_of_equal_joint_cost_the_first_is_kept() {
        let (model, x, data, alone) = absorbed();
        let fit = fit_fields(&model, &x, &data, &FieldOptions::default(), "tie").unwrap();
        is_the_least_squares_constant(&fit.coefficients[0], &alone);
        // Not vacuous: the last start set is another, (a₀, b) ≈ (1, 1), at the same cost, bit for bit.
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let probe = Fields::new(&model, &x, systems, DVector::zeros(0));
        let starts = linearised_starts(&model[0], &alone, "tie").unwrap();
        let last = starts.last().unwrap();
        // 1/(1 + x) is the model itself: the linearised solve recovers it to rounding.
        assert!((last[0] - 1.0).abs() < 1e-9 && (last[1] - 1.0).abs() < 1e-9, "{last}");
        assert_eq!(probe.cost(last), probe.cost(&starts[0]));
    }

    /// Minimax on [`absorbed`]: every joint solve refuses each trial (1 + 34 evaluations, λ from
    /// 1e-4 by 4 a refusal up to 1e16), the max error stays 2⁴⁰, so no outer iteration improves
    /// on the start and the search ends after PATIENCE of them, with the start (the first set)
    /// kept. The evaluations are those of the first solve and of each outer one.
    #[test]
    fn outer_iterations_that_do_not_improve_end_the_search_after_the_patience() {
        let (model, x, data, alone) = absorbed();
        let opts = FieldOptions { objective: Objective::Minimax, ..FieldOptions::default() };
        let fit = fit_fields(&model, &x, &data, &opts, "tie").unwrap();
        let trials = std::iter::successors(Some(1e-4f64), |l| Some(l * 4.0)).take_while(|&l| l < 1e16).count();
        assert_eq!(trials, 34);
        assert_eq!((fit.outer_iterations, fit.lm_evaluations), (PATIENCE, (1 + PATIENCE) * (1 + trials)));
        assert_eq!(fit.max_abs_error, 2f64.powi(40));
        is_the_least_squares_constant(&fit.coefficients[0], &alone);
    }

    /// The small-step stop of [`solve_joint`]: three accepted steps in a row that each lower
    /// the cost by less than 1e-10 of it end the solve. Two constant fields c = (c₀, c₁) at a
    /// point with R = [[1, b], [b, 1]], z = 0, b = 1 − h, h = 2⁻¹⁰, and a point with R = 0,
    /// z = (S, 0), S = 128, that no field reaches. From c = t·(1, −1) the cost is 2h²t² + S²
    /// (R c = t·h·(1, −1)), and (1, −1) is an eigenvector of JᵀJ = RᵀR (eigenvalue
    /// 1 + b² − 2b = h²) with the diagonal D = 1 + b², so the step solving
    /// (JᵀJ + λD) δ = −Jᵀr keeps c on the line and scales t by λ/(μ + λ), μ = h²/(1 + b²)
    /// ≈ 4.77e-7. λ = 1e-4, 1e-4/3, 1e-4/9 give 1 − (λ/(μ + λ))² ≈ 9.5e-3, 2.8e-2, 8.1e-2 of
    /// the soft part 2h² = 2⁻¹⁹, itself 2⁻³³ ≈ 1.2e-10 of the cost: gains ≈ 1.1e-12, 3.3e-12,
    /// 9e-12, each below 1e-10 and far above the cost's rounding (1.1e-16), so each trial is
    /// taken. The solve stops after the third: 1 + 3 evaluations, of 11 iterations allowed,
    /// with t = Π λ/(μ + λ).
    #[test]
    fn three_small_gains_in_a_row_end_the_joint_solve() {
        let models = [RationalModel::rational_1d("x", 0, 0), RationalModel::rational_1d("x", 0, 0)];
        let h = 2f64.powi(-10);
        let b = 1.0 - h;
        let point = |r: DMatrix<f64>, z: [f64; 2]| Reduced { rtr: r.tr_mul(&r), r, z: DVector::from_row_slice(&z), floor: 0.0 };
        let systems = vec![point(DMatrix::from_row_slice(2, 2, &[1.0, b, b, 1.0]), [0.0, 0.0]), point(DMatrix::zeros(2, 2), [128.0, 0.0])];
        let x = vec![vec![0.0], vec![0.0]];
        let mut fields = Fields::new(&models, &x, systems, DVector::from_row_slice(&[1.0, -1.0]));
        assert_eq!(solve_joint(&mut fields, 11, "small steps").unwrap(), 4);
        let mu = h * h / (1.0 + b * b);
        let t: f64 = [1e-4, 1e-4 / 3.0, 1e-4 / 9.0].iter().map(|l| l / (mu + l)).product();
        let c = &fields.theta;
        // Cholesky of JᵀJ + λD, condition ≈ 2/(h² + 2λ) ≤ 1e4, on entries ~2 rounded to ε:
        // ~1e-12 of t a step; 1e-9 bounds three (and t ≈ 0.94).
        assert!((c[0] - t).abs() < 1e-9 && (c[1] + t).abs() < 1e-9, "{c}, expected ±{t}");
    }

    /// Lawson's weights degenerate where every residual is 0 (all weights 0) or one is infinite:
    /// the outer step gives up (None) rather than dividing by the top weight.
    #[test]
    fn an_outer_step_on_degenerate_weights_gives_up() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let theta = DVector::from_vec(TRUE.iter().flatten().copied().collect());
        let opts = FieldOptions { objective: Objective::Minimax, ..FieldOptions::default() };
        for bad in [0.0, f64::INFINITY] {
            let mut fields = Fields::new(&models, &x, systems.clone(), theta.clone());
            let mut res: Vec<DVector<f64>> = data.iter().map(|d| DVector::zeros(d.y.len())).collect();
            res[3][5] = bad;
            let mut w: Vec<Vec<f64>> = data.iter().map(|d| vec![1.0; d.y.len()]).collect();
            assert!(outer_step(&mut fields, &mut w, &res, &data, &opts, "degenerate").is_none(), "a residual {bad}");
        }
    }

    #[test]
    fn reduction_is_exact_for_rank_deficient_systems() {
        let (_, data) = problem();
        let d = &data[0];
        let s = reduce(&d.design, &d.y, None);
        for c in [[0.1, 0.2, 0.3], [-1.0, 4.0, 2.5], [3.0, 0.0, -7.0]] {
            let c = DVector::from_row_slice(&c);
            let direct = (&d.design * &c - &d.y).norm_squared();
            let reduced = (&s.r * &c - &s.z).norm_squared() + s.floor;
            // Householder QR is backward stable: agreement to rounding of sums of ~40 O(10) terms.
            assert!((direct - reduced).abs() <= 1e-12 * direct.max(1.0), "{direct} vs {reduced}");
        }
        assert!(stage1(&d.design, &d.y).condition > 1e12, "x = 0 must be reported singular");
    }

    /// A fields fit needs grid points, and one point of data per grid point: none, or a count
    /// that differs from the grid's, is refused as no data.
    #[test]
    fn a_fields_fit_needs_one_point_of_data_per_grid_point() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let opts = FieldOptions::default();
        for (xs, ds) in [(&x[..0], &data[..0]), (&x[..], &data[..x.len() - 1]), (&x[..x.len() - 1], &data[..])] {
            match fit_fields(&models, xs, ds, &opts, "grid") {
                Err(FitError::NoData { what }) => assert_eq!(what, "grid"),
                other => panic!("{} points, {} data: {:?}", xs.len(), ds.len(), other.err()),
            }
        }
    }

    /// Weighted, the reduction is exact for the weighted sum: Σ w_i (B_i c − y_i)² =
    /// ‖R c − z‖² + floor for every c, with √w given per row, at a rank-deficient point (x = 0)
    /// and a full-rank one alike (the reduction rests on no inverse).
    #[test]
    fn a_weighted_reduction_is_exact_for_the_weighted_sum() {
        let (_, data) = problem();
        for d in [&data[0], &data[3]] {
            let n = d.y.len();
            let w: Vec<f64> = (0..n).map(|i| 0.1 + (i % 7) as f64).collect();
            let sqrt_w: Vec<f64> = w.iter().map(|v| v.sqrt()).collect();
            let s = reduce(&d.design, &d.y, Some(&sqrt_w));
            for c in [[0.1, 0.2, 0.3], [-1.0, 4.0, 2.5], [3.0, 0.0, -7.0]] {
                let c = DVector::from_row_slice(&c);
                let r = &d.design * &c - &d.y;
                let direct: f64 = r.iter().zip(&w).map(|(ri, wi)| wi * ri * ri).sum();
                let reduced = (&s.r * &c - &s.z).norm_squared() + s.floor;
                // As above: backward-stable QR, sums of ~40 terms of O(100) (weights up to 6.1).
                assert!((direct - reduced).abs() <= 1e-12 * direct.max(1.0), "{direct} vs {reduced}");
            }
            assert!(s.floor >= 0.0);
        }
    }

    /// Stage 1 solves each point's least squares: for orthogonal columns of norms 2 and ½ the
    /// condition is exactly 4 and the coefficients are the projections; for two equal columns
    /// (rank 1) the minimum-norm solution splits the weight evenly, (½, ½) for y equal to the
    /// column, and the condition is ∞ or beyond any START_COND.
    #[test]
    fn stage1_gives_the_minimum_norm_coefficients_and_the_condition() {
        let b = DMatrix::from_row_slice(4, 2, &[1.0, 0.25, 1.0, -0.25, 1.0, 0.25, 1.0, -0.25]);
        let y = DVector::from_vec(vec![3.0, 1.0, 2.0, 0.0]);
        let s = stage1(&b, &y);
        // Projections: (Σy)/4 = 1.5 on the first column, (3 − 1 + 2 − 0)·¼ / ¼ = 4 on the second.
        assert!((s.condition - 4.0).abs() < 1e-14, "{}", s.condition);
        assert!((s.coefficients[0] - 1.5).abs() < 1e-14 && (s.coefficients[1] - 4.0).abs() < 1e-14, "{:?}", s.coefficients);
        let twin = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, 2.0, 2.0, -1.0, -1.0]);
        let s = stage1(&twin, &DVector::from_vec(vec![1.0, 2.0, -1.0]));
        assert!(s.condition > START_COND, "{}", s.condition);
        // The SVD's rounding (ε-relative) bounds the distance from (½, ½).
        assert!(s.coefficients.iter().all(|c| (c - 0.5).abs() < 1e-14), "{:?}", s.coefficients);
        // The cut is relative to σmax: columns of norms 1e3 and 1e-12 (σ ratio 1e-15, below
        // RCOND = 1e-12) leave the second out, whatever σmax's own size, so y = (1, 1, 0, 0)
        // gives (1e-3, 0), not the 1e12 that solving along σ = 1e-12 would (an absolute or
        // inverted cut, 1e-12 or 1e-15, keeps it). Its condition is the ratio, 1e15.
        let b = DMatrix::from_row_slice(4, 2, &[1e3, 0.0, 0.0, 1e-12, 0.0, 0.0, 0.0, 0.0]);
        let s = stage1(&b, &DVector::from_vec(vec![1.0, 1.0, 0.0, 0.0]));
        // (1/σ to rounding on the kept direction; exactly 0 on the cut one.)
        assert!((s.coefficients[0] - 1e-3).abs() < 1e-18 && s.coefficients[1] == 0.0, "the direction of σ = 1e-12 is not cut: {:?}", s.coefficients);
        assert!((s.condition / 1e15 - 1.0).abs() < 1e-14, "{}", s.condition);
    }

    /// A grid point where every basis value is 0 (all of σ zero) is rank-deficient like any
    /// other: its condition is ∞, as documented on [`Stage1`], not σmax/σmin = 0/0, and its
    /// minimum-norm coefficients are 0. A zero column alone (σmin = 0 < σmax) is ∞ as well.
    #[test]
    fn a_basis_of_zeros_is_infinitely_conditioned() {
        let y = DVector::from_vec(vec![1.0, -2.0, 3.0, 0.5]);
        let s = stage1(&DMatrix::zeros(4, 3), &y);
        assert_eq!((s.condition, s.coefficients.as_slice()), (f64::INFINITY, [0.0; 3].as_slice()));
        let one_zero_column = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 2.0, 0.0, 0.5, 0.0, -1.0, 0.0]);
        assert_eq!(stage1(&one_zero_column, &y).condition, f64::INFINITY);
    }

    #[test]
    fn joint_fit_recovers_exact_fields_through_a_singular_point() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let f = fit_fields(&models, &x, &data, &FieldOptions::default(), "synthetic").unwrap();
        // The data are exactly representable: the fit reaches rounding level.
        assert!(f.max_abs_error < 1e-9, "max {}", f.max_abs_error);
        // Where the basis is well conditioned the fields themselves are recovered (their
        // sensitivity to the data is ~cond ≤ 1e2 for x ≥ 0.1, on residuals ≤ 1e-9).
        for xv in [0.1, 0.35, 0.6, 0.95] {
            for k in 0..3 {
                let v = models[k].eval_full(&f.coefficients[k], &[xv]);
                assert!((v - truth(k, xv)).abs() < 1e-6, "c{k}({xv}) = {v}, expected {}", truth(k, xv));
            }
        }
        // Minimax on exact data stays at rounding level too.
        let opts = FieldOptions { objective: Objective::Minimax, ..FieldOptions::default() };
        let m = fit_fields(&models, &x, &data, &opts, "synthetic").unwrap();
        assert!(m.max_abs_error < 1e-8, "minimax max {}", m.max_abs_error);
    }

    /// The Jacobian of `r` at θ by central differences of step 1e-6.
    fn central_jacobian(r: impl Fn(&DVector<f64>) -> DVector<f64>, theta: &DVector<f64>) -> DMatrix<f64> {
        let h = 1e-6;
        let mut j = DMatrix::zeros(r(theta).len(), theta.len());
        for p in 0..theta.len() {
            let (mut tp, mut tm) = (theta.clone(), theta.clone());
            tp[p] += h;
            tm[p] -= h;
            j.set_column(p, &((r(&tp) - r(&tm)) / (2.0 * h)));
        }
        j
    }

    /// Fields with two denominator terms, and a denominator exactly at Q_MIN: the normal
    /// equations are still the dense products of the residuals, extended by a barrier row
    /// Q_PENALTY·(Q_MIN − Q) only where Q is below Q_MIN. Field 0 is P2/Q2 with
    /// Q = 1 − 0.97x², below Q_MIN at x = 1 only (0.03; 0.12 at x = 0.95); field 1 is
    /// (a₀ + a₁x)/(x + b·x²) at b = 0, whose Q = x is Q_MIN itself at the grid point 1/20 = 0.05
    /// (both rounded to the same double), so no barrier row there. Grid: problem's, without x = 0.
    #[test]
    fn normal_equations_hold_for_two_denominator_terms_and_no_barrier_at_q_min() {
        let f = vec!["x".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        let parts = |numerator: Vec<Term>, denominator: Vec<Term>, lead: Option<Term>| {
            RationalModel::new(ModelParts { inputs: f.clone(), numerator, denominator, lead, ..ModelParts::default() }).unwrap()
        };
        let models = vec![
            parts(vec![t("1"), t("x"), t("x^2")], vec![t("x"), t("x^2")], None),
            parts(vec![t("1"), t("x")], vec![t("x^2")], Some(t("x"))),
            field(0.0),
        ];
        let (x, data) = problem();
        let (x, data) = (&x[1..], &data[1..]);
        assert_eq!(x[0][0], Q_MIN);
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let theta = DVector::from_vec(vec![0.01, 0.0, 0.0, 0.0, -0.97, 0.1, 0.2, 0.0, 0.3, -0.2, 0.1, 0.4]);
        let fl = Fields::new(&models, x, systems, theta.clone());
        // The barrier row of field 0 at x = 1, its Q written out from the model's form.
        let extended = |t: &DVector<f64>| {
            let mut r: Vec<f64> = fl.residuals_at(t).iter().copied().collect();
            r.push(Q_PENALTY * (Q_MIN - (1.0 + t[3] + t[4])));
            DVector::from_vec(r)
        };
        let r0 = extended(&theta);
        let j = central_jacobian(extended, &theta);
        let (a, g, cost) = fl.normal_equations(&theta);
        let (dense, grad) = (j.tr_mul(&j), j.tr_mul(&r0));
        // Central differences of rationals whose denominators stay ≥ 0.03 at the grid (the
        // barrier row is linear, exact): truncation ~h²·f‴ and rounding ~1e-16/h of entries up to
        // ~5e4, far below 1e-6 of the entries' scale.
        assert!((&a - &dense).amax() <= 1e-6 * dense.amax(), "JᵀJ off by {:e} of {:e}", (&a - &dense).amax(), dense.amax());
        assert!((&g - &grad).amax() <= 1e-6 * grad.amax(), "Jᵀr off by {:e} of {:e}", (&g - &grad).amax(), grad.amax());
        assert!((cost - r0.norm_squared()).abs() <= 1e-12 * cost, "cost {cost} vs {}", r0.norm_squared());
        // Field 1's b–b entry on its own scale (Σ_g Σ_j u_j²·(a₀ + a₁x)² ≈ 3): a barrier row at Q = Q_MIN would add
        // (Q_PENALTY·0.05²)² = 0.0625 to it.
        let b = 7;
        assert!((a[(b, b)] - dense[(b, b)]).abs() <= 1e-6 * dense[(b, b)], "b–b entry {} vs {}", a[(b, b)], dense[(b, b)]);
    }

    #[test]
    fn normal_equations_are_the_dense_product_at_any_thread_count() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let theta = DVector::from_iterator(12, (0..12).map(|i| 0.3 * ((i as f64) * 1.7).sin()));
        let f = Fields::new(&models, &x, systems, theta.clone());
        // Dense J by central differences of the residuals R_g c(x_g; θ) − z_g.
        let r0 = f.residuals_at(&theta);
        let j = central_jacobian(|t| f.residuals_at(t), &theta);
        let (a, g, cost) = f.normal_equations(&theta);
        let dense = j.tr_mul(&j);
        let grad = j.tr_mul(&r0);
        // Central differences of a smooth rational: error ~h²·f''' plus rounding ~1e-16/h, both
        // far below 1e-7 of the entries' scale (Q stays ≥ 0.5 here, so no barrier term).
        assert!((&a - &dense).amax() <= 1e-7 * dense.amax(), "JᵀJ off by {:e}", (&a - &dense).amax());
        assert!((&g - &grad).amax() <= 1e-7 * grad.amax(), "Jᵀr off by {:e}", (&g - &grad).amax());
        // The same squares summed per point then over points: rounding of a 63-term sum.
        assert!((cost - r0.norm_squared()).abs() <= 1e-13 * cost, "cost {cost} vs {}", r0.norm_squared());
        // The blocks are summed in grid order whatever the thread count: bit-identical.
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| f.normal_equations(&theta));
        let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| f.normal_equations(&theta));
        assert_eq!(one.0.as_slice(), two.0.as_slice());
        assert_eq!(one.0.as_slice(), a.as_slice());
    }

    /// A peaked first field, (ε/((x − 0.35)² + ε) with ε = 1.5e-3) plus small noise, on a
    /// seven-point grid of [0, 1], by P2/Q2 over [1, x, x²] / [1, x, x²]: the reweighted
    /// iterates that fit the peak better dip their denominator below zero between grid points,
    /// so none is proven. The search must count each as a miss and go on to PATIENCE of them,
    /// and keep the least-squares start.
    #[test]
    fn unproven_iterates_count_against_the_patience_and_do_not_end_the_search() {
        let f = vec!["x".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        let (x, data) = problem_on(
            6,
            |x| 1.5e-3 / ((x - 0.35).powi(2) + 1.5e-3),
            |x, r| 0.01 * (r as f64 * 1.3 + x * 7.0).sin(),
        );
        let peaked = RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![t("1"), t("x"), t("x^2")],
            denominator: vec![t("x"), t("x^2")],
            ..ModelParts::default()
        })
        .unwrap();
        let models = vec![peaked, field(0.0), field(0.0)];
        let lsq = fit_fields(&models, &x, &data, &FieldOptions::default(), "peaked").unwrap();
        let opts = FieldOptions { objective: Objective::Minimax, ..FieldOptions::default() };
        let mm = fit_fields(&models, &x, &data, &opts, "peaked").unwrap();
        assert_eq!(mm.max_abs_error, lsq.max_abs_error, "a proven iterate improved on the start");
        assert_eq!(mm.outer_iterations, PATIENCE);
        // Not vacuous: of the reweighted steps from the start, replayed, one improves the max
        // error with a first denominator that is not proven positive on [0, 1].
        let theta = DVector::from_vec(lsq.coefficients.iter().flat_map(|c| c.iter().copied()).collect());
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let mut fields = Fields::new(&models, &x, systems, theta.clone());
        assert_eq!(fields.full(&theta), lsq.coefficients);
        let (_, _, mut res) = sample_errors(&fields, &theta, &data);
        let mut w: Vec<Vec<f64>> = data.iter().map(|d| vec![1.0; d.y.len()]).collect();
        let unproven_improvement = (0..PATIENCE).any(|_| {
            let (_, m, _, r) = outer_step(&mut fields, &mut w, &res, &data, &opts, "peaked").unwrap();
            res = r;
            let full = fields.full(&fields.theta);
            m < lsq.max_abs_error && matches!(prove_denominator_positive(&models[0], &full[0], &[(0.0, 1.0)]), Positivity::NotProven { .. })
        });
        assert!(unproven_improvement);
    }

    /// Each point's reduced system with its residuals scaled by s (R and z by s, the floor by s²).
    fn scaled_systems(data: &[PointData], s: f64) -> Vec<Reduced> {
        data.iter()
            .map(|d| {
                let e = reduce(&d.design, &d.y, None);
                let r = &e.r * s;
                Reduced { rtr: r.tr_mul(&r), r, z: &e.z * s, floor: e.floor * s * s }
            })
            .collect()
    }

    /// A joint solve whose damped normal matrix cannot be factored at any damping stops and
    /// keeps its start: the damping grows until it gives up, without evaluating a trial.
    /// The systems are the exact problem's scaled by s = 1e160, so the cost at the true
    /// coefficients (rounding residuals ~1e-15·s, squared) is finite while RᵀR (~s²) and so
    /// JᵀJ overflow.
    #[test]
    fn a_normal_matrix_that_cannot_be_factored_leaves_the_start_unchanged() {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let (x, data) = problem();
            let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
            let systems = scaled_systems(&data, 1e160);
            let theta = DVector::from_vec(TRUE.iter().flatten().copied().collect());
            let mut f = Fields::new(&models, &x, systems, theta.clone());
            let cost = f.cost(&theta);
            let (a, _, _) = f.normal_equations(&theta);
            let evals = solve_joint(&mut f, 500, "overflowing");
            tx.send((cost, a.iter().all(|v| v.is_finite()), evals.ok(), f.theta == theta)).unwrap();
        });
        // The solve takes microseconds; this bound only turns a damping loop that never ends
        // (one that shrinks λ on a failed factorisation) into a failure instead of a hang.
        let (cost, a_finite, evals, unchanged) =
            rx.recv_timeout(std::time::Duration::from_secs(120)).expect("the solve did not return");
        assert!(cost.is_finite(), "the start's cost must be finite for the solve to begin: {cost}");
        assert!(!a_finite, "JᵀJ was expected to overflow");
        assert_eq!(evals, Some(1), "no trial can be evaluated without a factorisation");
        assert!(unchanged, "the start must be kept");
    }

    /// A trial is taken only when it lowers the cost. With every system zero (the exact
    /// problem's scaled by 0) the cost at the true coefficients is exactly 0 (no denominator is
    /// near Q_MIN) and so is the gradient: every trial is the start itself, at the same cost, and
    /// is refused. λ grows from 1e-4 by 4 a refusal; the solve ends when it reaches 1e16, having
    /// evaluated the start and each trial below that (counted here from the documented
    /// schedule), with the start kept bit for bit. A solver that took equal-cost trials as
    /// progress would stop after a few "steps" of gain 0 instead.
    #[test]
    fn a_trial_that_does_not_lower_the_cost_is_refused() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let systems = scaled_systems(&data, 0.0);
        let theta = DVector::from_vec(TRUE.iter().flatten().copied().collect());
        let mut f = Fields::new(&models, &x, systems, theta.clone());
        assert_eq!(f.cost(&theta), 0.0);
        let trials = std::iter::successors(Some(1e-4f64), |l| Some(l * 4.0)).take_while(|&l| l < 1e16).count();
        assert_eq!(solve_joint(&mut f, 500, "flat").unwrap(), 1 + trials);
        assert_eq!(f.theta, theta);
    }

    /// With a denominator driven below Q_MIN the barrier residuals join the normal equations:
    /// (JᵀJ, Jᵀr, cost) equal the dense products of the residuals extended by
    /// Q_PENALTY·(Q_MIN − Q) at the points where Q = 1 + b·x < Q_MIN, Q written out here from
    /// the model's form (not the fitter's basis), and the cost equals `cost`'s own penalty sum.
    #[test]
    fn barrier_terms_enter_only_their_own_fields_diagonal_block() {
        let (x, data) = problem();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let systems: Vec<Reduced> = data.iter().map(|d| reduce(&d.design, &d.y, None)).collect();
        let mut theta = DVector::from_iterator(12, (0..12).map(|i| 0.3 * ((i as f64) * 1.7).sin()));
        // Field 0's b = −1.02: Q = 1 − 1.02x < Q_MIN for x > 0.931, i.e. x = 0.95 and 1 (Q =
        // 0.031, −0.02), each ≥ 0.01 from Q_MIN so a difference step of 1e-6 never crosses it;
        // field 2's b = −0.97: Q < Q_MIN at x = 1 only (Q = 0.03). Field 1 stays ≥ 0.5.
        theta[3] = -1.02;
        theta[7] = 0.2;
        theta[11] = -0.97;
        let f = Fields::new(&models, &x, systems, theta.clone());
        let xs: Vec<f64> = x.iter().map(|p| p[0]).collect();
        let extended = |t: &DVector<f64>| {
            let mut r: Vec<f64> = f.residuals_at(t).iter().copied().collect();
            for k in 0..3 {
                for &xv in &xs {
                    let q = 1.0 + t[4 * k + 3] * xv;
                    if q < Q_MIN {
                        r.push(Q_PENALTY * (Q_MIN - q));
                    }
                }
            }
            DVector::from_vec(r)
        };
        let r0 = extended(&theta);
        assert_eq!(r0.len(), 21 * 3 + 3, "three barrier residuals");
        let j = central_jacobian(extended, &theta);
        let (a, g, cost) = f.normal_equations(&theta);
        let (dense, grad) = (j.tr_mul(&j), j.tr_mul(&r0));
        // Central differences of rationals whose poles stay ≥ 0.02 from the grid (the barrier
        // rows are linear, exact): truncation ~h²·f‴ with f‴ ≲ 1e6 near the pole, plus
        // rounding ~1e-16/h, both far below 1e-6 of the entries' scale.
        assert!((&a - &dense).amax() <= 1e-6 * dense.amax(), "JᵀJ off by {:e} of {:e}", (&a - &dense).amax(), dense.amax());
        assert!((&g - &grad).amax() <= 1e-6 * grad.amax(), "Jᵀr off by {:e} of {:e}", (&g - &grad).amax(), grad.amax());
        // The penalty rows hold b_0 alone or b_2 alone: the b_0–b_2 entry is the data rows'
        // coupling only, which a barrier term placed off the diagonal blocks would change.
        assert!((a[(3, 11)] - dense[(3, 11)]).abs() <= 1e-6 * dense.amax(), "b0–b2 coupling {} vs {}", a[(3, 11)], dense[(3, 11)]);
        // The same squares summed in another order: rounding of a 66-term sum.
        assert!((cost - r0.norm_squared()).abs() <= 1e-12 * cost, "cost {cost} vs {}", r0.norm_squared());
        assert!((cost - f.cost(&theta)).abs() <= 1e-12 * cost, "cost {cost} vs cost() {}", f.cost(&theta));
    }

    /// The synthetic problem with samples off the model, so that the objectives disagree: the
    /// first field moved by 0.05·sin(9x), which its rational form cannot follow, and a ±1e-3
    /// ripple outside every point's basis.
    fn noisy() -> (Vec<Vec<f64>>, Vec<PointData>) {
        let (x, mut data) = problem();
        for (g, (xg, d)) in x.iter().zip(data.iter_mut()).enumerate() {
            for r in 0..d.y.len() {
                d.y[r] += 0.05 * (9.0 * xg[0]).sin() * d.design[(r, 0)] + 1e-3 * ((17 * r + 5 * g) as f64 * 0.61).sin();
            }
        }
        (x, data)
    }

    /// Max, rms and Σe⁴ of the fitted fields' residuals, recomputed from the coefficients
    /// through `eval_full` (not the fitter's own evaluation).
    fn errors(models: &[RationalModel], coefficients: &[DVector<f64>], x: &[Vec<f64>], data: &[PointData]) -> (f64, f64, f64) {
        let (mut max, mut ss, mut s4, mut n) = (0.0f64, 0.0, 0.0, 0);
        for (xg, d) in x.iter().zip(data) {
            let c = DVector::from_iterator(models.len(), models.iter().zip(coefficients).map(|(m, c)| m.eval_full(c, xg)));
            for e in (&d.design * c - &d.y).iter() {
                max = max.max(e.abs());
                ss += e * e;
                s4 += e.powi(4);
                n += 1;
            }
        }
        (max, (ss / n as f64).sqrt(), s4)
    }

    /// On samples the fields cannot represent: the reported errors are those of the returned
    /// coefficients; stage 1's are those of each point's own least-squares solve (by SVD here);
    /// minimax has the lowest max error and least squares the lowest rms, L4 the lowest Σe⁴ of
    /// the three (each is the optimum of its own objective, reached to well within the gaps).
    #[test]
    fn each_objective_wins_its_own_measure_and_reports_its_own_errors() {
        let (x, data) = noisy();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let fit = |objective| fit_fields(&models, &x, &data, &FieldOptions { objective, ..FieldOptions::default() }, "noisy").unwrap();
        let (lsq, mm, l4) = (fit(Objective::Lsq), fit(Objective::Minimax), fit(Objective::L4));
        let mut measured = vec![];
        for (name, f) in [("lsq", &lsq), ("minimax", &mm), ("l4", &l4)] {
            let (max, rms, s4) = errors(&models, &f.coefficients, &x, &data);
            // The same residuals summed in another order: rounding of sums of ~800 terms.
            assert!((f.max_abs_error - max).abs() <= 1e-12 && (f.rms_error - rms).abs() <= 1e-12, "{name}: reported ({}, {}), measured ({max}, {rms})", f.max_abs_error, f.rms_error);
            measured.push((max, rms, s4));
        }
        let [(lsq_max, lsq_rms, lsq4), (mm_max, mm_rms, mm4), (_, l4_rms, l44)] = measured[..] else { unreachable!() };
        // Minimax lowers the max error by 41 % here (0.0319 against 0.0536 when this was
        // written); a bound of 1 % only says it does not lose, the compass-search test below
        // judges how close it gets.
        assert!(mm_max < 0.99 * lsq_max, "minimax max {mm_max} vs least squares {lsq_max}");
        assert!(lsq_rms < mm_rms && lsq_rms < l4_rms, "rms: lsq {lsq_rms}, minimax {mm_rms}, l4 {l4_rms}");
        assert!(l44 < lsq4 && l44 < mm4, "Σe⁴: l4 {l44}, lsq {lsq4}, minimax {mm4}");
        assert!(mm.outer_iterations > 0 && l4.outer_iterations > 0 && lsq.outer_iterations == 0);
        // L4's outer iterations are capped at 12 (its damped steps settle within about 10).
        assert!(l4.outer_iterations <= 12, "L4: {} outer iterations", l4.outer_iterations);
        // Each LM solve evaluates the cost at its start and at one trial step at least: the
        // first solve, then one an outer iteration.
        for (name, f) in [("lsq", &lsq), ("minimax", &mm), ("l4", &l4)] {
            assert!(f.lm_evaluations >= 2 * (1 + f.outer_iterations), "{name}: {} evaluations, {} outer iterations", f.lm_evaluations, f.outer_iterations);
        }
        // Stage 1: the least-squares optimum of each point alone (the floor of the basis).
        let (mut s1max, mut ss, mut n) = (0.0f64, 0.0, 0);
        for d in &data {
            let c = d.design.clone().svd(true, true).solve(&d.y, 1e-12).unwrap();
            let e = &d.design * c - &d.y;
            s1max = s1max.max(e.amax());
            ss += e.norm_squared();
            n += e.len();
        }
        let s1rms = (ss / n as f64).sqrt();
        // QR and SVD solves of 36×3 systems: residuals agree to ~1e-15 of values ~1.
        assert!((lsq.stage1_max_abs_error - s1max).abs() < 1e-12, "{} vs {s1max}", lsq.stage1_max_abs_error);
        assert!((lsq.stage1_rms_error - s1rms).abs() < 1e-12, "{} vs {s1rms}", lsq.stage1_rms_error);
        assert!(s1max > 1e-3 && s1max < lsq.max_abs_error, "the ripple is partly outside the basis: {s1max}");
    }

    /// Every objective is equivariant in the data's scale: the samples times 2⁻⁴⁰ (a power of
    /// two, so every product, quotient and square root of the fit scales exactly) give the
    /// numerators times 2⁻⁴⁰, the same denominators and the errors times 2⁻⁴⁰. The fields here
    /// have no offset (a constant that would not scale), and their denominators stay far above
    /// the barrier's Q_MIN, the fit's one absolute constant. Any stopping rule or weight that
    /// compares an absolute quantity (a cost, a gain, a residual) breaks it: at this scale the
    /// cost is ~1e-25.
    #[test]
    fn every_objective_is_equivariant_in_the_datas_scale() {
        let (x, data) = noisy();
        let s = 2f64.powi(-40);
        let scaled: Vec<PointData> = data.iter().map(|d| PointData { design: d.design.clone(), y: &d.y * s }).collect();
        let models: Vec<RationalModel> = (0..3).map(|_| field(0.0)).collect();
        for objective in [Objective::Lsq, Objective::Minimax, Objective::L4] {
            let opts = FieldOptions { objective, ..FieldOptions::default() };
            let a = fit_fields(&models, &x, &data, &opts, "unit").unwrap();
            let b = fit_fields(&models, &x, &scaled, &opts, "scaled").unwrap();
            for (k, (ca, cb)) in a.coefficients.iter().zip(&b.coefficients).enumerate() {
                // Numerator a0..a2 (scaled), denominator b (not): exact, bit for bit.
                let expect = DVector::from_vec(vec![ca[0] * s, ca[1] * s, ca[2] * s, ca[3]]);
                assert_eq!(cb.as_slice(), expect.as_slice(), "{objective:?}: field {k}");
            }
            assert_eq!((b.max_abs_error, b.rms_error), (a.max_abs_error * s, a.rms_error * s), "{objective:?}");
            assert_eq!((b.lm_evaluations, b.outer_iterations), (a.lm_evaluations, a.outer_iterations), "{objective:?}");
        }
    }

    /// Minimax under an rms cap between least squares' rms and the uncapped minimax's: the
    /// result keeps its rms under the cap (re-measured from the coefficients) and still lowers
    /// the max error below least squares'; the uncapped fit, above the cap, has the lowest max.
    #[test]
    fn fields_minimax_under_an_rms_cap_keeps_the_cap() {
        let (x, data) = noisy();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let fit = |objective, max_rms| fit_fields(&models, &x, &data, &FieldOptions { objective, max_rms, ..FieldOptions::default() }, "noisy").unwrap();
        let (lsq, free) = (fit(Objective::Lsq, None), fit(Objective::Minimax, None));
        let (lsq_max, lsq_rms, _) = errors(&models, &lsq.coefficients, &x, &data);
        let (free_max, free_rms, _) = errors(&models, &free.coefficients, &x, &data);
        // The cap binds: half way from least squares' rms to the uncapped minimax's.
        let cap = lsq_rms + 0.5 * (free_rms - lsq_rms);
        assert!(free_rms > cap, "uncapped rms {free_rms} vs cap {cap}");
        let capped = fit(Objective::Minimax, Some(cap));
        let (max, rms, _) = errors(&models, &capped.coefficients, &x, &data);
        assert!(rms <= cap, "rms {rms} above the cap {cap}");
        // Strict improvements: the first reweighting steps lower the max error while the rms is
        // still near least squares'; the uncapped search can only do better.
        assert!(max < lsq_max, "capped max {max} vs least squares {lsq_max}");
        assert!(free_max <= max, "uncapped max {free_max} vs capped {max}");
    }

    /// An rms cap no fit can meet, half least squares' rms (least squares is the smallest rms
    /// of this shape, to its solver's convergence): the start does not qualify, nor does any
    /// iterate, so minimax refuses with an error naming the cap instead of returning a fit
    /// above it.
    #[test]
    fn fields_minimax_under_an_unreachable_rms_cap_is_an_error() {
        let (x, data) = noisy();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let lsq = fit_fields(&models, &x, &data, &FieldOptions::default(), "noisy").unwrap();
        let cap = 0.5 * errors(&models, &lsq.coefficients, &x, &data).1;
        let opts = FieldOptions { objective: Objective::Minimax, max_rms: Some(cap), ..FieldOptions::default() };
        match fit_fields(&models, &x, &data, &opts, "noisy") {
            Err(FitError::Solver { msg, .. }) => assert!(msg.contains(&format!("rms ≤ {cap:e}")), "{msg}"),
            Ok(fit) => panic!("a fit returned with rms {:e} above the cap {cap:e}", fit.rms_error),
            Err(e) => panic!("another error: {e:?}"),
        }
    }

    /// The minimax fit cannot be improved by a compass search on its max error (each
    /// coefficient moved ± a step, the step halved from 1e-2 to 1e-9 when no move helps): the
    /// search, started from the returned coefficients, lowers the max error by less than 3 %,
    /// while from the least-squares fit it lowers it by more than 10 %.
    #[test]
    fn the_minimax_fields_fit_is_not_improved_by_a_compass_search() {
        let (x, data) = noisy();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let max = |c: &[DVector<f64>]| errors(&models, c, &x, &data).0;
        let search = |c0: &[DVector<f64>]| {
            let (f0, mut c, mut step) = (max(c0), c0.to_vec(), 1e-2);
            let mut f = f0;
            while step > 1e-9 {
                let mut moved = false;
                for k in 0..c.len() {
                    for i in 0..c[k].len() {
                        for sign in [1.0, -1.0] {
                            let mut t = c.clone();
                            t[k][i] += sign * step;
                            let ft = max(&t);
                            if ft < f {
                                (c, f, moved) = (t, ft, true);
                            }
                        }
                    }
                }
                if !moved {
                    step *= 0.5;
                }
            }
            (f0 - f) / f0
        };
        let fit = |objective| fit_fields(&models, &x, &data, &FieldOptions { objective, ..FieldOptions::default() }, "noisy").unwrap();
        let (lsq, mm) = (search(&fit(Objective::Lsq).coefficients), search(&fit(Objective::Minimax).coefficients));
        // Lawson's reweighting stops near, not at, the minimax optimum: the search gained 1.1 %
        // from it when this was written, 15 % from least squares (compass search stalls on a
        // max's kinks, so it finds only part of the 41 % minimax gains). 3 % sits between the
        // 1.1 % and the 8 % it gains from a fit reweighted by w + |e| instead of w·|e|.
        assert!(mm < 0.03, "a compass search lowers the minimax fit's max error by {mm}");
        assert!(lsq > 0.1, "a compass search lowers the least-squares fit's max error by only {lsq}");
    }

    /// The L4 fit is a stationary point of Σe⁴ (its errors recomputed through `eval_full`, not
    /// the fitter's weights): along the steepest descent direction of Σe⁴ from the returned
    /// coefficients no step lowers it by more than 1e-6 of its value, while from the
    /// least-squares fit the same search gains more than 1e-3.
    #[test]
    fn the_l4_fields_fit_is_a_stationary_point_of_the_fourth_power_sum() {
        let (x, data) = noisy();
        let models: Vec<RationalModel> = OFFSETS.iter().map(|&o| field(o)).collect();
        let s4 = |c: &[DVector<f64>]| errors(&models, c, &x, &data).2;
        // The best fraction of Σe⁴ a line search along −∇Σe⁴ (central differences, h = 1e-6)
        // removes: steps 2^-j · 0.1/‖∇‖ for j = 0..40 (the coefficients are O(1)).
        let descent = |c0: &[DVector<f64>]| {
            let f0 = s4(c0);
            let mut g: Vec<DVector<f64>> = c0.iter().map(|c| DVector::zeros(c.len())).collect();
            for k in 0..c0.len() {
                for i in 0..c0[k].len() {
                    let (mut p, mut m) = (c0.to_vec(), c0.to_vec());
                    p[k][i] += 1e-6;
                    m[k][i] -= 1e-6;
                    g[k][i] = (s4(&p) - s4(&m)) / 2e-6;
                }
            }
            let norm = g.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
            let mut best = 0.0f64;
            for j in 0..40 {
                let t = 0.1 / norm * 2f64.powi(-j);
                let c: Vec<DVector<f64>> = c0.iter().zip(&g).map(|(c, g)| c - g * t).collect();
                best = best.max((f0 - s4(&c)) / f0);
            }
            best
        };
        let fit = |objective| fit_fields(&models, &x, &data, &FieldOptions { objective, ..FieldOptions::default() }, "noisy").unwrap();
        let (lsq, l4) = (descent(&fit(Objective::Lsq).coefficients), descent(&fit(Objective::L4).coefficients));
        // The damped reweighting settles Σe⁴ to ~1e-6 relative (the outer loop's comment): a
        // descent step from the L4 fit gained 6e-9 when this was written, from the
        // least-squares fit 8e-3. The bounds sit a factor ~100 and ~8 from those.
        assert!(l4 < 1e-6, "a descent step lowers the L4 fit's Σe⁴ by {l4}");
        assert!(lsq > 1e-3, "a descent step lowers the least-squares fit's Σe⁴ by only {lsq}");
    }
}
