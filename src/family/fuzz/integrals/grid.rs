//! Data sets for the published fits.
//!
//! [`ps_grid`] (P_s on an α × θf grid for each light direction of [`fitting_directions`]) and
//! [`r_grid`] parallelise over grid points with rayon; results are deterministic (the same
//! bits for any thread count).

use super::{ps_directions, r};
use crate::integrate::Estimate;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// `n` equally spaced values from `lo` to `hi` inclusive (the fitting grids).
pub fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    match n {
        0 => vec![],
        1 => vec![lo],
        _ => (0..n).map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64).collect(),
    }
}

/// Light directions for the per-(α, θf) least-squares fit of the published 6-term P̃_s:
/// midpoints of an n_theta × n_phi grid over θu ∈ (0, π/2), φu ∈ (0, π) (P_s is even in φu,
/// so the half range carries all information). 16 × 16 = 256 directions give a well-posed,
/// stable 6-parameter fit for every θf ≥ 0.1 (u·n and u·t are spread over their ranges).
pub fn fitting_directions(n_theta: usize, n_phi: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n_theta * n_phi);
    for i in 0..n_theta {
        let tu = FRAC_PI_2 * (i as f64 + 0.5) / n_theta as f64;
        for j in 0..n_phi {
            out.push((tu, PI * (j as f64 + 0.5) / n_phi as f64));
        }
    }
    out
}

/// P_s at every (α, θf) grid point (α-major: index i·thetas.len() + j) and every direction,
/// in parallel over grid points. Deterministic: the same bits for any thread count.
pub fn ps_grid(
    alphas: &[f64],
    thetas: &[f64],
    dirs: &[(f64, f64)],
    tol: f64,
) -> Vec<Vec<Estimate>> {
    let points: Vec<(f64, f64)> =
        alphas.iter().flat_map(|&a| thetas.iter().map(move |&t| (a, t))).collect();
    points.par_iter().map(|&(a, t)| ps_directions(a, t, dirs, tol)).collect()
}

/// R at every (α, θf) grid point (α-major), in parallel over grid points.
pub fn r_grid(alphas: &[f64], thetas: &[f64], tol: f64) -> Vec<Estimate> {
    let points: Vec<(f64, f64)> =
        alphas.iter().flat_map(|&a| thetas.iter().map(move |&t| (a, t))).collect();
    points.par_iter().map(|&(a, t)| r(a, t, tol)).collect()
}
#[cfg(test)]
mod tests {
    use super::super::{DEFAULT_TOL, PUBLISHED_ALPHA_MIN, PUBLISHED_THETA_F_MIN};
    use super::*;

    /// The fitting directions are the midpoints of the n_theta × n_phi cells of (0, π/2) × (0, π),
    /// θu-major: for 2 × 3, θu ∈ {π/8, 3π/8} and φu ∈ {π/6, π/2, 5π/6}.
    #[test]
    fn fitting_directions_are_cell_midpoints() {
        let d = fitting_directions(2, 3);
        let want = [(1.0, 1.0), (1.0, 3.0), (1.0, 5.0), (3.0, 1.0), (3.0, 3.0), (3.0, 5.0)];
        assert_eq!(d.len(), 6);
        for (&(t, p), &(i, j)) in d.iter().zip(&want) {
            // One product and one quotient of π: 1 ulp.
            assert!((t - i * PI / 8.0).abs() < 1e-15 && (p - j * PI / 6.0).abs() < 1e-15, "{d:?}");
        }
    }

    /// `n` values from `lo` to `hi`: none, the start alone, or both ends and equal steps.
    #[test]
    fn linspace_gives_its_ends_and_equal_steps() {
        assert!(linspace(0.2, 0.8, 0).is_empty());
        assert_eq!(linspace(0.2, 0.8, 1), [0.2]);
        let v = linspace(0.2, 0.8, 4);
        // (hi − lo)·i/3 rounds once or twice: a few ulps of 1.
        for (a, b) in v.iter().zip([0.2, 0.4, 0.6, 0.8]) {
            assert!((a - b).abs() < 1e-15, "{v:?}");
        }
    }

    /// Time the data sets of the published fitting method: 65 × 65 (α, θf) grids, P_s at 16 × 16
    /// light directions per grid point, and R. `cargo test --release -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn timing_published_data_sets() {
        let alphas = linspace(PUBLISHED_ALPHA_MIN, 1.0, 65);
        let dirs = fitting_directions(16, 16);
        let t0 = std::time::Instant::now();
        let ps_set =
            ps_grid(&alphas, &linspace(PUBLISHED_THETA_F_MIN, FRAC_PI_2, 65), &dirs, DEFAULT_TOL);
        let t_ps = t0.elapsed();
        let t1 = std::time::Instant::now();
        let r_set = r_grid(&alphas, &linspace(0.0, FRAC_PI_2, 65), DEFAULT_TOL);
        let t_r = t1.elapsed();
        let max_ps = ps_set.iter().flatten().map(|e| e.error).fold(0.0, f64::max);
        let max_r = r_set.iter().map(|e| e.error).fold(0.0, f64::max);
        let ev_ps: u64 = ps_set.iter().flatten().map(|e| e.evals).sum();
        let ev_r: u64 = r_set.iter().map(|e| e.evals).sum();
        println!(
            "threads {}: P_s 65x65x{} in {:.2?} (max error {max_ps:.1e}, {} evals/P_s); \
             R 65x65 in {:.2?} (max error {max_r:.1e}, {} evals/R)",
            rayon::current_num_threads(),
            dirs.len(),
            t_ps,
            ev_ps / ps_set.len() as u64 / dirs.len() as u64,
            t_r,
            ev_r / r_set.len() as u64
        );
    }
}
