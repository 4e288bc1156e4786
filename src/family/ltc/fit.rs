//! The LTC fit of a lobe, cell by cell and as a whole table, by deterministic quadrature.
//!
//! # The metric
//!
//! At a view v = (sin θ, 0, cos θ) the lobe's normalised cosine-weighted BRDF
//! p(ω) = f(v, ω) max(0, ω_z) / E(v), E = ∫ f max(0, ω_z) dω (the magnitude), and an LTC D are
//! two probability densities on the sphere. The fit minimises their L1 distance
//! ```text
//! δ = ∫_{S²} |p − D| dω ∈ [0, 2],
//! ```
//! twice the total variation distance: sup over every light shape P of |∫_P p − ∫_P D| is δ/2,
//! so δ/2 bounds the relative error of the shaded result (before the magnitude and Fresnel)
//! for any light at this cell, and D's mass below the horizon (counted by the shader: see
//! `super::transform`) is part of δ (p is 0 there). ltc_code minimises ∫|f − D|³ instead.
//!
//! # The quadrature
//!
//! δ is split by the balance heuristic between two maps of [0, 1]² onto the sphere: the LTC's
//! own (the cosine hemisphere through M, density D) and the lobe's half-vector measure
//! (ξ, φ/2π) ↦ h ↦ l = 2(v·h)h − v (density p_h(h)/(4|v·h|), GGX's D·μh sampler):
//! ```text
//! δ = Σ_maps ∫_{[0,1]²} |p − D| / (q_LTC + q_lobe) du,
//! ```
//! each by an n × n Gauss–Legendre product — the estimator of ltc_code's `computeError` with
//! its 32 × 32 midpoints replaced by Gauss nodes, and no randomness. The integrand is bounded
//! (|p − D|/(q_LTC + q_lobe) ≤ p/q_lobe + 1) with kinks where p = D, so the rule converges at
//! O(n⁻²); the error of a reported δ is estimated from the rule at n and at 2n
//! ([`Cell::distance_with_error`]).

use super::transform::{Ltc, Vec3, dot, normalize};
use crate::integrate::gauss_legendre;
use crate::shading::Lobe;
use crate::shading::hemisphere::split_sum;
use std::f64::consts::PI;

/// The largest polar angle of a view: ltc_code's min(1.57, acos(cos θ)) (μv ≥ 7.96e-4); the
/// last row of the table, cos θ = 0, is fitted there.
pub const MAX_THETA: f64 = 1.57;
/// Gauss–Legendre nodes per axis and map in the fit's objective.
pub const FIT_NODES: usize = 24;
/// Quadrature tolerance of the magnitude and Fresnel integrals.
pub const MOMENT_TOLERANCE: f64 = 1e-9;

/// One view of a lobe: what the objective needs, precomputed.
pub struct Cell<'a, L: Lobe> {
    lobe: &'a L,
    view: L::View,
    v: Vec3,
    /// E = ∫ f max(0, ω_z) dω and ∫ f max(0, ω_z) (1 − v·h)⁵ dω.
    pub magnitude: f64,
    pub fresnel: f64,
    /// The lobe map's nodes: (weight, direction, p, q_lobe).
    lobe_nodes: Vec<(f64, Vec3, f64, f64)>,
    /// The cosine-hemisphere nodes of the LTC map: (weight, ω_o).
    cosine_nodes: Vec<(f64, Vec3)>,
}

/// Gauss–Legendre nodes and weights on [0, 1].
fn unit_rule(n: usize) -> Vec<(f64, f64)> {
    let (x, w) = gauss_legendre(n);
    x.iter().zip(&w).map(|(x, w)| (0.5 * (x + 1.0), 0.5 * w)).collect()
}

impl<'a, L: Lobe> Cell<'a, L> {
    /// The cell at view angle θ (clamped to [`MAX_THETA`]) with `n` nodes per axis and map.
    pub fn new(lobe: &'a L, theta: f64, n: usize) -> Self {
        let theta = theta.clamp(0.0, MAX_THETA);
        let (s, mu_v) = theta.sin_cos();
        let v = [s, 0.0, mu_v];
        let view = lobe.view(mu_v);
        let ss = split_sum(lobe, mu_v, 0.0, MOMENT_TOLERANCE);
        let mut cell = Cell { lobe, view, v, magnitude: ss.scale + ss.bias, fresnel: ss.bias, lobe_nodes: Vec::new(), cosine_nodes: Vec::new() };
        let rule = unit_rule(n);
        for &(xi, wx) in &rule {
            let (s2, c2) = lobe.half_angle(xi);
            let (sh, ch) = (s2.max(0.0).sqrt(), c2.max(0.0).sqrt());
            for &(u, wu) in &rule {
                let (sp, cp) = (2.0 * PI * u).sin_cos();
                let h = [sh * cp, sh * sp, ch];
                let vh = dot(v, h);
                let l = [2.0 * vh * h[0] - v[0], 2.0 * vh * h[1] - v[1], 2.0 * vh * h[2] - v[2]];
                let p = cell.normalised(l);
                let q = cell.lobe_density(l);
                if q > 0.0 && q.is_finite() {
                    cell.lobe_nodes.push((wx * wu, l, p, q));
                }
            }
        }
        for &(u1, w1) in &rule {
            let r = u1.sqrt();
            for &(u2, w2) in &rule {
                let (sp, cp) = (2.0 * PI * u2).sin_cos();
                cell.cosine_nodes.push((w1 * w2, [r * cp, r * sp, (1.0 - u1).sqrt()]));
            }
        }
        cell
    }

    /// p(ω) = f max(0, ω_z)/E.
    pub fn normalised(&self, l: Vec3) -> f64 {
        self.normalised_at(l, self.half(l))
    }

    /// h = (v + l)/|v + l|.
    fn half(&self, l: Vec3) -> Vec3 {
        normalize([self.v[0] + l[0], self.v[1] + l[1], self.v[2] + l[2]])
    }

    /// [`Cell::normalised`] at l with its half vector h.
    fn normalised_at(&self, l: Vec3, h: Vec3) -> f64 {
        if l[2] <= 0.0 || self.magnitude <= 0.0 {
            return 0.0;
        }
        let vh = dot(self.v, h);
        if vh <= 0.0 {
            return 0.0;
        }
        self.lobe.eval(&self.view, vh, h[2], l[2]) * l[2] / self.magnitude
    }

    /// The lobe map's density at l: p_h(h)/(4|v·h|), h = ±(v + l)/|v + l| in the upper half.
    fn lobe_density(&self, l: Vec3) -> f64 {
        self.density_at(self.half(l))
    }

    /// [`Cell::lobe_density`] with l's half vector h.
    fn density_at(&self, h: Vec3) -> f64 {
        let h = if h[2] < 0.0 { [-h[0], -h[1], -h[2]] } else { h };
        let vh = dot(self.v, h).abs();
        if !(vh > 0.0) {
            return f64::INFINITY;
        }
        self.lobe.pdf(h[2]) / (4.0 * vh)
    }

    /// δ = ∫ |p − D| (see the module doc).
    pub fn distance(&self, ltc: &Ltc) -> f64 {
        if !ltc.is_valid() {
            return f64::INFINITY;
        }
        let mut sum = 0.0;
        for &(w, l, p, q) in &self.lobe_nodes {
            let d = ltc.eval(l);
            sum += w * (p - d).abs() / (q + d);
        }
        for &(w, o) in &self.cosine_nodes {
            let l = normalize(ltc.from_cosine(o));
            let d = ltc.eval(l);
            if !(d > 0.0) {
                continue;
            }
            // p and q of one half vector (the cosine map's hot loop).
            let h = self.half(l);
            sum += w * (self.normalised_at(l, h) - d).abs() / (self.density_at(h) + d);
        }
        if sum.is_finite() { sum } else { f64::INFINITY }
    }

    /// The LTC's average direction of p (∫ p ω dω, by the lobe map alone: p/q_lobe is the
    /// lobe's bounded weight), the start of ltc_code's frame.
    pub fn average_direction(&self) -> Vec3 {
        let mut s = [0.0; 3];
        for &(w, l, p, q) in &self.lobe_nodes {
            for k in 0..3 {
                s[k] += w * p / q * l[k];
            }
        }
        normalize([s[0], 0.0, s[2]])
    }
}

/// δ of `ltc` at a cell of `lobe` with `n` nodes and with 2n: (value at 2n, |difference|).
pub fn distance_with_error<L: Lobe>(lobe: &L, theta: f64, ltc: &Ltc, n: usize) -> (f64, f64) {
    let (coarse, fine) = (Cell::new(lobe, theta, n).distance(ltc), Cell::new(lobe, theta, 2 * n).distance(ltc));
    (fine, (fine - coarse).abs())
}

/// Minimise `f` over `x` from `x0` by Nelder–Mead (argmin's), with a simplex of relative steps
/// `step` (absolute `step`·`scale` for zero coordinates), then once more from the result with
/// a tenth of the step: the best point found and its value.
pub fn minimise(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: f64, scale: f64, iters: u64) -> (Vec<f64>, f64) {
    use argmin::core::{CostFunction, Error, Executor, State};
    use argmin::solver::neldermead::NelderMead;
    use nalgebra::DVector;
    struct Cost<'f>(&'f dyn Fn(&[f64]) -> f64);
    impl CostFunction for Cost<'_> {
        type Param = DVector<f64>;
        type Output = f64;
        fn cost(&self, p: &DVector<f64>) -> Result<f64, Error> {
            Ok((self.0)(p.as_slice()))
        }
    }
    let mut best = x0.to_vec();
    let mut best_cost = f(&best);
    for s in [step, 0.1 * step] {
        let x = DVector::from_vec(best.clone());
        let mut simplex = vec![x.clone()];
        for i in 0..x.len() {
            let mut v = x.clone();
            v[i] += if v[i] == 0.0 { s * scale } else { s * v[i].abs() };
            simplex.push(v);
        }
        let Ok(solver) = NelderMead::new(simplex).with_sd_tolerance(1e-12) else { continue };
        let Ok(res) = Executor::new(Cost(f), solver).configure(|st| st.max_iters(iters)).run() else { continue };
        let st = res.state();
        if let Some(p) = st.get_best_param()
            && st.get_best_cost() < best_cost
        {
            best = p.as_slice().to_vec();
            best_cost = st.get_best_cost();
        }
    }
    (best, best_cost)
}

/// Nelder–Mead iterations per round of a cell's fit.
pub const ITERATIONS: u64 = 120;

/// The fit of one cell from `start`: isotropic (a = 1, b = c = 0, only d free) at normal
/// incidence, the four entries otherwise.
pub fn fit_cell<L: Lobe>(cell: &Cell<'_, L>, start: Ltc, isotropic: bool) -> (Ltc, f64) {
    if isotropic {
        let f = |x: &[f64]| cell.distance(&Ltc { a: 1.0, b: 0.0, c: 0.0, d: x[0] });
        let (x, e) = minimise(&f, &[start.d], 0.1, 1.0, ITERATIONS);
        return (Ltc { a: 1.0, b: 0.0, c: 0.0, d: x[0] }, e);
    }
    let scale = start.a.abs().max(start.d.abs());
    let f = |x: &[f64]| cell.distance(&Ltc { a: x[0], b: x[1], c: x[2], d: x[3] });
    let (x, e) = minimise(&f, &[start.a, start.b, start.c, start.d], 0.1, 0.1 * scale, ITERATIONS);
    (Ltc { a: x[0], b: x[1], c: x[2], d: x[3] }, e)
}

/// `ltc` turned about y so that the direction of its peak, M·z, points along `target` (in the
/// xz-plane): M⁻¹·R(φ) keeps the table's form (y decoupled, middle element 1).
pub fn aim(ltc: Ltc, target: Vec3) -> Ltc {
    let angle = |w: Vec3| w[0].atan2(w[2]);
    let goal = angle(target);
    let delta = goal - angle(normalize(ltc.from_cosine([0.0, 0.0, 1.0])));
    let turn = |phi: f64| {
        let (s, c) = phi.sin_cos();
        Ltc { a: ltc.a * c - ltc.b * s, b: ltc.a * s + ltc.b * c, c: ltc.c * c - ltc.d * s, d: ltc.c * s + ltc.d * c }
    };
    let miss = |l: &Ltc| (angle(normalize(l.from_cosine([0.0, 0.0, 1.0]))) - goal).abs();
    let (p, m) = (turn(delta), turn(-delta));
    if !p.is_valid() || (m.is_valid() && miss(&m) < miss(&p)) { m } else { p }
}

/// One fitted cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fitted {
    pub ltc: Ltc,
    pub magnitude: f64,
    pub fresnel: f64,
    /// δ at the fit's nodes.
    pub distance: f64,
}

/// The table's cell (i, j) of `n`: roughness r = i/(n − 1) (α = max(r², `min_alpha`)) and
/// x = j/(n − 1) = sqrt(1 − cos θ) (ltc_code's nodes): (α, θ).
pub fn cell_parameters(i: usize, j: usize, n: usize, min_alpha: f64) -> (f64, f64) {
    let r = i as f64 / (n - 1) as f64;
    let x = j as f64 / (n - 1) as f64;
    ((r * r).max(min_alpha), (1.0 - x * x).clamp(-1.0, 1.0).acos().min(MAX_THETA))
}

/// The whole table of `n` × `n` cells (roughness fastest), for a lobe built per α by `lobe`.
/// Continuation: the normal-incidence column from roughness 1 down, each cell started from the
/// one above it; every roughness row then from normal incidence towards grazing, each cell
/// from the previous one (rows in parallel, each sequential: byte-identical at any thread
/// count). Then one repair pass: each interior cell is refitted from the mean of its
/// neighbours' matrices along each axis where that mean is closer to the lobe than its own
/// fit, and keeps the better of the two ([`Table::repaired`] counts them).
pub fn fit_table<L: Lobe + Send>(n: usize, min_alpha: f64, nodes: usize, lobe: &(dyn Fn(f64) -> L + Sync)) -> Table {
    use rayon::prelude::*;
    // The normal-incidence column, roughness 1 → 0.
    let mut column = vec![Fitted { ltc: Ltc::IDENTITY, magnitude: 0.0, fresnel: 0.0, distance: 0.0 }; n];
    let mut start = Ltc::IDENTITY;
    for i in (0..n).rev() {
        let (alpha, theta) = cell_parameters(i, 0, n, min_alpha);
        let l = lobe(alpha);
        let cell = Cell::new(&l, theta, nodes);
        let (ltc, distance) = fit_cell(&cell, start, true);
        column[i] = Fitted { ltc, magnitude: cell.magnitude, fresnel: cell.fresnel, distance };
        start = ltc;
    }
    let rows: Vec<Vec<Fitted>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let (alpha, _) = cell_parameters(i, 0, n, min_alpha);
            let l = lobe(alpha);
            let mut row = vec![column[i]];
            for j in 1..n {
                let (_, theta) = cell_parameters(i, j, n, min_alpha);
                let cell = Cell::new(&l, theta, nodes);
                // The previous cell's LTC, or the same turned onto this lobe's average direction
                // where that starts closer (a narrow lobe moves by more than its width a cell).
                let previous = row[j - 1].ltc;
                let turned = aim(previous, cell.average_direction());
                let start = if cell.distance(&turned) < cell.distance(&previous) { turned } else { previous };
                let (ltc, distance) = fit_cell(&cell, start, false);
                row.push(Fitted { ltc, magnitude: cell.magnitude, fresnel: cell.fresnel, distance });
            }
            row
        })
        .collect();
    // Storage order: roughness fastest (texel i + j n).
    let mut cells: Vec<Fitted> = (0..n * n).map(|k| rows[k % n][k / n]).collect();
    let candidates: Vec<Option<Fitted>> = (0..n * n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % n, k / n);
            let mut best: Option<Fitted> = None;
            let (alpha, theta) = cell_parameters(i, j, n, min_alpha);
            let l = lobe(alpha);
            let cell = Cell::new(&l, theta, nodes);
            let mut own = cells[k].distance;
            let pairs = [(i > 0 && i + 1 < n).then(|| (k - 1, k + 1)), (j > 0 && j + 1 < n).then(|| (k - n, k + n))];
            for (x, y) in pairs.into_iter().flatten() {
                let (p, q) = (cells[x].ltc, cells[y].ltc);
                let mean = Ltc { a: 0.5 * (p.a + q.a), b: 0.5 * (p.b + q.b), c: 0.5 * (p.c + q.c), d: 0.5 * (p.d + q.d) };
                if cell.distance(&mean) < own {
                    let (ltc, distance) = fit_cell(&cell, mean, j == 0);
                    if distance < own {
                        own = distance;
                        best = Some(Fitted { ltc, magnitude: cells[k].magnitude, fresnel: cells[k].fresnel, distance });
                    }
                }
            }
            best
        })
        .collect();
    let mut repaired = 0;
    for (c, r) in cells.iter_mut().zip(candidates) {
        if let Some(r) = r {
            *c = r;
            repaired += 1;
        }
    }
    Table { n, min_alpha, nodes, cells, repaired }
}

/// A fitted table.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub n: usize,
    pub min_alpha: f64,
    pub nodes: usize,
    /// Roughness fastest.
    pub cells: Vec<Fitted>,
    /// Cells the repair pass refitted from their neighbours' mean.
    pub repaired: usize,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lambert::Lambert;
    use crate::shading::trowbridge_reitz::{Ggx, Shadowing};

    /// A Lambertian lobe is a clamped cosine: the identity LTC is at distance 0 from it at
    /// every view (each node's |p − D| is a rounding), and the fit from a distorted start
    /// returns to it (δ < 1e-4: Nelder–Mead's stopping spread in a kinked objective).
    #[test]
    fn a_clamped_cosine_is_its_own_ltc() {
        let lambert = Lambert;
        for theta in [0.0, 0.7, 1.5] {
            let cell = Cell::new(&lambert, theta, 16);
            assert!((cell.magnitude - 1.0).abs() < 1e-9, "{}", cell.magnitude);
            assert!(cell.distance(&Ltc::IDENTITY) < 1e-12, "{}", cell.distance(&Ltc::IDENTITY));
            let (ltc, d) = fit_cell(&cell, Ltc { a: 1.3, b: 0.2, c: -0.1, d: 0.8 }, false);
            assert!(d < 1e-3, "θ {theta}: {ltc:?} at {d}");
        }
    }

    /// Turning an LTC onto a direction moves its peak there and keeps its mass (the
    /// determinant of M⁻¹ is unchanged by a rotation).
    #[test]
    fn aim_turns_the_peak_onto_the_target() {
        let l = Ltc { a: 0.9, b: 0.05, c: 0.02, d: 0.01 };
        for t in [0.3f64, -0.2, 1.2] {
            let a = aim(l, [t.sin(), 0.0, t.cos()]);
            let peak = normalize(a.from_cosine([0.0, 0.0, 1.0]));
            assert!((peak[0].atan2(peak[2]) - t).abs() < 1e-12, "{t}: {peak:?}");
            assert!((a.det_inv() - l.det_inv()).abs() < 1e-15);
        }
    }

    /// δ's quadrature converges: the n- and 2n-node rules agree within 2 % of δ (1e-3 where
    /// δ < 0.05) for a GGX cell at a grazing view and a rough and a glossy α against a fitted
    /// LTC (kinks: O(n⁻²) error), and δ lies in [0, 2]. (tests/python/test_ltc.py checks the
    /// reported δ against an independent rule aligned with the kinks.)
    #[test]
    fn the_distance_converges_with_the_nodes() {
        for (alpha, theta) in [(0.5, 1.2), (0.05, 0.8), (0.01, 0.3)] {
            let g = Ggx::new(alpha, Shadowing::HeightCorrelated);
            let cell = Cell::new(&g, theta, FIT_NODES);
            let start = Ltc { a: 1.0, b: 0.0, c: 0.0, d: alpha };
            let (ltc, d) = fit_cell(&cell, start, false);
            let (fine, err) = distance_with_error(&g, theta, &ltc, FIT_NODES);
            assert!((0.0..=2.0).contains(&fine) && err < 2e-2 * fine.max(0.05), "α {alpha} θ {theta}: {d} vs {fine} ± {err}");
        }
    }
}
/// The table fit's timing and bits, printed: `LTC_N=64 RAYON_NUM_THREADS=2 cargo test --release
/// --lib ltc_fit_table_report -- --ignored --nocapture` (the SHA-256 of every cell's f64 bits,
/// to compare across thread counts).
#[cfg(test)]
mod report {
    use sha2::{Digest, Sha256};

    #[test]
    #[ignore]
    fn ltc_fit_table_report() {
        let t0 = std::time::Instant::now();
        let n: usize = std::env::var("LTC_N").ok().and_then(|s| s.parse().ok()).unwrap_or(16);
        let t = super::fit_table(n, crate::family::ltc::published::MIN_ALPHA, super::FIT_NODES, &crate::family::ltc::published::ggx);
        let elapsed = t0.elapsed();
        let mut h = Sha256::new();
        for c in &t.cells {
            for x in [c.ltc.a, c.ltc.b, c.ltc.c, c.ltc.d, c.magnitude, c.fresnel, c.distance] {
                h.update(x.to_le_bytes());
            }
        }
        let ds: Vec<f64> = t.cells.iter().map(|c| c.distance).collect();
        let rms = (ds.iter().map(|d| d * d).sum::<f64>() / ds.len() as f64).sqrt();
        eprintln!("{n}x{n} GGX LTC table: {elapsed:?}, delta max {:.4} rms {:.4}, repaired {}, sha256 {:x}", ds.iter().cloned().fold(0.0, f64::max), rms, t.repaired, h.finalize());
    }
}
