//! msdiffuse benchmark rows (`shadefit bench`): the random walk's error against its paths, the
//! study behind the default tables' path counts, and its throughput (seconds a point on one
//! thread; paths/s = paths / that):
//! - ms-diffuse (full walk) at 2^8…2^14 paths a point against 2^18 paths (the reference's own
//!   standard error is reported beside it), at (θh, θd) on a 4 × 4 grid at gloss 0 and 0.5;
//! - the walk's first event (single scattering) at the same ladder against the analytic f₁ by
//!   quadrature (an exact reference: the error is the Monte Carlo error alone).

use super::integrals::{Order, TALK_F0, brdf, directions, single_scattering, surface};
use super::walk::{Specular, key_of};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row};
use crate::bench::{FamilyBench, Mode};
use std::f64::consts::FRAC_PI_2;

pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[IntegratorBench { order: 12, run: walk_rows }],
    fits: &[],
    tables: &[],
    forms: &[],
};

fn points(quick: bool) -> Vec<(f64, [f64; 3], [f64; 3])> {
    let n = if quick { 2 } else { 4 };
    let mut out = Vec::new();
    for g in [0.0, 0.5] {
        for i in 0..n {
            for j in 0..n {
                let th = (i as f64 + 0.5) / n as f64 * FRAC_PI_2 * 0.9;
                let td = (j as f64 + 0.5) / n as f64 * FRAC_PI_2 * 0.9;
                let (l, v) = directions(th, td, FRAC_PI_2).expect("above the horizon");
                out.push((g, l, v));
            }
        }
    }
    out
}

fn walk_rows(mode: &Mode) -> Vec<IntegratorRow> {
    let pts = points(mode.quick);
    let key = key_of("ms-diffuse bench");
    let mut rows = Vec::new();
    let reference_paths: u64 = if mode.quick { 1 << 15 } else { 1 << 18 };
    let reference: Vec<f64> = pts
        .iter()
        .enumerate()
        .map(|(c, (g, l, v))| brdf(&surface(*g, TALK_F0, Specular::Gone), *l, *v, Order::All, key ^ 1, c as u64, reference_paths, true).value)
        .collect();
    let ref_name = format!("the walk at {reference_paths} paths (another key)");
    for paths in pick(mode, &[1u64 << 10], &[1 << 8, 1 << 10, 1 << 12, 1 << 14]) {
        rows.push(row(mode, "ms-diffuse", "Heitz 2016 walk, next-event estimates (shadefit)", format!("{paths} paths"), (&ref_name, &reference), || {
            Run::from_estimates(pts.iter().enumerate().map(|(c, (g, l, v))| brdf(&surface(*g, TALK_F0, Specular::Gone), *l, *v, Order::All, key, c as u64, paths, false)).collect())
        }));
    }
    let exact: Vec<f64> = pts.iter().map(|(g, l, v)| single_scattering(surface(*g, TALK_F0, Specular::Gone).alpha, TALK_F0, *l, *v, 1e-10).value).collect();
    for paths in pick(mode, &[1u64 << 10], &[1 << 8, 1 << 10, 1 << 12, 1 << 14]) {
        rows.push(row(mode, "ms-diffuse (single scattering)", "first event of the walk", format!("{paths} paths"), ("analytic f₁ by adaptive quadrature, tol 1e-10", &exact), || {
            Run::from_estimates(pts.iter().enumerate().map(|(c, (g, l, v))| brdf(&surface(*g, TALK_F0, Specular::Gone), *l, *v, Order::Single, key, c as u64, paths, false)).collect())
        }));
    }
    rows
}
