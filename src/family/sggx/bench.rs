//! The sggx family's benchmark rows (`shadefit bench`, see `crate::bench`):
//! - integrators: the projected area ∫⟨ω, m⟩₊ D(m) dm of SGGX lobes (`sggx-projected-area`)
//!   by the production nested adaptive rule about ω at a ladder of tolerances, and by the
//!   product Gauss–Legendre sphere rule the NDF comparisons use (whose ⟨·⟩₊ kink crosses its
//!   panels), against the closed form √(ωᵀSω).
//!
//! No shader forms yet: the emitted functions are exact formulas (see `family::tests::NO_FORMS`).

use super::integrals::{Aniso, Lobe, SphereRule, direction, sggx_from};
use crate::integrate::rng::SplitMix64;
use super::projected_area_quadrature;
use crate::bench::FamilyBench;
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row};
use crate::bench::Mode;
use std::f64::consts::PI;

pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[IntegratorBench { order: 7, run: projected_area_integrators }],
    fits: &[],
    tables: &[],
    builds: &[],
    forms: &[],
};

/// Seeded lobes (normals within 60° of z, α ∈ [0.05, 1]) and directions over the sphere.
fn points(n: usize) -> Vec<(Lobe, super::integrals::V3)> {
    let mut rng = SplitMix64(40);
    (0..n)
        .map(|_| {
            let s = sggx_from(direction(PI / 3.0 * rng.next_f64(), 2.0 * PI * rng.next_f64()), Aniso::from_alphas(0.05 + 0.95 * rng.next_f64(), 0.05 + 0.95 * rng.next_f64(), PI * rng.next_f64()));
            (Lobe::new(s).expect("α > 0 gives SPD lobes"), direction((2.0 * rng.next_f64() - 1.0).acos(), 2.0 * PI * rng.next_f64()))
        })
        .collect()
}

fn projected_area_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let pts = points(if mode.quick { 4 } else { 16 });
    let exact: Vec<f64> = pts.iter().map(|(l, w)| l.projected_area(w)).collect();
    let reference = ("closed form √(ωᵀSω)", exact.as_slice());
    let mut rows = Vec::new();
    for tol in pick(mode, &[1e-6, 1e-10], &[1e-6, 1e-8, 1e-10, 1e-12]) {
        rows.push(row(mode, "sggx-projected-area", "nested adaptive about ω (production)", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(pts.iter().map(|(l, w)| projected_area_quadrature(l, *w, tol)).collect())
        }));
    }
    for (t, p) in pick(mode, &[(40usize, 80usize)], &[(40, 80), (80, 160), (160, 320)]) {
        let rule = SphereRule::new(t, p, 8);
        let per_point = rule.points.len() as u64;
        rows.push(row(mode, "sggx-projected-area", "sphere product rule (θ × φ Gauss–Legendre)", format!("{t}×{p} panels of 8²"), reference, || {
            Run::fixed(pts.iter().map(|(l, w)| rule.integrate(|m| l.d(m) * m.dot(w).max(0.0))).collect(), per_point)
        }));
    }
    rows
}
