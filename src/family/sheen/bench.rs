//! The sheen family's benchmark rows (`shadefit bench`, see `crate::bench`): the albedo
//! integrators' tolerance ladders against themselves at 1e-12 (exact Smith, Estevez–Kulla's
//! curve, Ashikhmin's V) over α ∈ [0.01, 1], n·v ∈ [0, 1], beside the engines' estimator of the
//! Ashikhmin lobe: Filament cmgen's `DFV_Charlie_Uniform` (uniform hemisphere H, Hammersley
//! points; 4096 a texel), and the exact Λ's Chebyshev table against its quadrature.

use super::lut::filament_dfv_charlie;
use super::{Ashikhmin, EstevezKulla, Smith, lambda_table};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row, self_ladder};
use crate::bench::{FamilyBench, Mode};
use crate::integrate::Estimate;
use crate::shading::charlie::lambda_exact;
use crate::shading::hemisphere::{LobeParams, albedo};

pub static BENCH: FamilyBench = FamilyBench { integrators: &[IntegratorBench { order: 14, run: albedo_integrators }], fits: &[], tables: &[], builds: &[], forms: &[] };

/// (α, n·v) of the study.
fn points(mode: &Mode) -> Vec<[f64; 2]> {
    let (alphas, mus): (&[f64], &[f64]) =
        if mode.quick { (&[0.01, 0.25, 1.0], &[0.0, 0.3, 1.0]) } else { (&[0.01, 0.03, 0.1, 0.25, 0.5, 1.0], &[0.0, 0.01, 0.1, 0.3, 0.6, 0.9, 1.0]) };
    alphas.iter().flat_map(|&a| mus.iter().map(move |&m| [a, m])).collect()
}

fn ladder<P: LobeParams<Lobe = crate::shading::charlie::Charlie>>(mode: &Mode, quantity: &'static str, what: &str, floor: f64) -> (Vec<f64>, Vec<IntegratorRow>) {
    let pts = points(mode);
    self_ladder(
        mode,
        quantity,
        &format!("adaptive G10/K21 over (ξ = sin^(1/α) θh, φ) of the Charlie sampling measure, exact azimuth limits ({what})"),
        1e-12,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]),
        |tol| pts.iter().map(|p| albedo(&P::lobe(&[p[0]]), p[1].max(floor), tol)).collect::<Vec<Estimate>>(),
    )
}

fn albedo_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let (_, mut rows) = ladder::<Smith>(mode, "sheen-albedo", "exact Λ from its table", 0.0);
    rows.extend(ladder::<EstevezKulla>(mode, "sheen-albedo-ek", "Estevez–Kulla's Λ curve; n·v from 1e-6", 1e-6).1);
    let (truth, ashikhmin) = ladder::<Ashikhmin>(mode, "sheen-albedo-ashikhmin", "Ashikhmin's V", 0.0);
    rows.extend(ashikhmin);
    let pts = points(mode);
    for n in pick(mode, &[1024, 4096], &[256, 1024, 4096, 16384, 65536]) {
        rows.push(row(
            mode,
            "sheen-albedo-ashikhmin",
            "uniform hemisphere H, Hammersley points (Filament cmgen's DFV_Charlie_Uniform)",
            format!("{n} samples"),
            ("adaptive at tol 1e-12", truth.as_slice()),
            || Run::fixed(pts.iter().map(|p| filament_dfv_charlie(p[1], p[0], n)).collect(), n as u64),
        ));
    }
    // The exact Λ: its Chebyshev table (built once per α) against the quadrature at 1e-14.
    let mus: Vec<f64> = pick(mode, &[0.01, 0.3, 0.9], &[1e-3, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99]);
    let alphas: Vec<f64> = pick(mode, &[0.01, 0.25, 1.0], &[3e-3, 0.01, 0.05, 0.25, 0.5, 1.0]);
    let lp: Vec<[f64; 2]> = alphas.iter().flat_map(|&a| mus.iter().map(move |&m| [a, m])).collect();
    let quad: Vec<f64> = lp.iter().map(|p| lambda_exact(p[0], p[1], 1e-14).value).collect();
    rows.push(row(
        mode,
        "sheen-lambda",
        "Chebyshev interpolant of μΛ in θ (nodes doubled until it meets the quadrature to 1e-13)",
        "per-α table".into(),
        ("quadrature at tol 1e-14", quad.as_slice()),
        || Run::fixed(lp.iter().map(|p| lambda_table(p[0]).lambda(p[1])).collect(), 1),
    ));
    rows
}
