//! The GGX family's benchmark rows (`shadefit bench`, see `crate::bench`):
//! - integrators: `ggx-env` [scale, bias] over α ∈ [10⁻³, 1], n·v ∈ [10⁻⁴, 1] and cones
//!   cos_cone ∈ [0, 0.99] — the production integrator's tolerance ladder (the convergence
//!   study) against itself at 1e-12, beside the engines' estimator: GGX importance sampling
//!   with Hammersley points (Filament's cmgen uses 1024 per texel);
//! - fits and shader forms: the published forms, their refits and shadefit's own (`published`);
//! - tables against numpy: the DFG LUT (`lut`).

use super::integrals::{self as ggx, Shadowing};
use super::published::filament;
use super::{lut, published};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row, self_ladder};
use crate::bench::{FamilyBench, Mode};
use crate::integrate::Estimate;

/// Integrator ladders.
pub static INTEGRATORS: &[IntegratorBench] =
    &[IntegratorBench { order: 5, run: env_integrators }, IntegratorBench { order: 6, run: written_lobe_integrators }];

/// GGX written as a lobe spec (`kind = "lobe"`), the lobe of tests/lobe_cli.rs.
const GGX_WRITTEN: &str = include_str!("../../../tests/data/lobes/ggx_written.toml");

pub static BENCH: FamilyBench =
    FamilyBench { integrators: INTEGRATORS, fits: published::FITS, tables: lut::TABLES, builds: &[], forms: published::FORMS };

/// (α, n·v, cos_cone) of the study.
fn points(mode: &Mode) -> Vec<[f64; 3]> {
    let (alphas, mus, cones): (&[f64], &[f64], &[f64]) = if mode.quick {
        (&[1e-3, 0.1, 1.0], &[1e-4, 0.3, 1.0], &[0.0, 0.9])
    } else {
        (&[1e-3, 1e-2, 0.1, 0.3, 0.6, 1.0], &[1e-4, 1e-2, 0.1, 0.3, 0.6, 0.9, 1.0], &[0.0, 0.5, 0.9, 0.99])
    };
    let mut out = Vec::new();
    for &a in alphas {
        for &m in mus {
            for &c in cones {
                out.push([a, m, c]);
            }
        }
    }
    out
}

/// Scale and bias of every point, flattened (scale, bias, scale, …), with the error estimate
/// on both.
fn flat(e: Vec<ggx::EnvEstimate>) -> Vec<Estimate> {
    e.into_iter()
        .flat_map(|r| {
            [Estimate { value: r.scale, error: r.error, evals: r.evals }, Estimate { value: r.bias, error: r.error, evals: 0 }]
        })
        .collect()
}

fn env_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    const REF_TOL: f64 = 1e-12;
    let pts = points(mode);
    let eval = |tol: f64| -> Vec<Estimate> {
        flat(pts.iter().map(|p| ggx::env(p[0], p[1], p[2], Shadowing::HeightCorrelated, tol)).collect())
    };
    let (truth, mut rows) = self_ladder(
        mode,
        "ggx-env",
        "adaptive G10/K21 over (ξ, φ) of the GGX sampling measure, exact azimuth limits (shadefit)",
        REF_TOL,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]),
        eval,
    );
    let reference = ("adaptive at tol 1e-12", truth.as_slice());
    for n in pick(mode, &[1024, 16384], &[256, 1024, 4096, 16384, 65536]) {
        rows.push(row(
            mode,
            "ggx-env",
            "GGX importance sampling, Hammersley points (as Filament's cmgen)",
            format!("{n} samples"),
            reference,
            || Run::fixed(pts.iter().flat_map(|p| hammersley_env(p[0], p[1], p[2], n)).collect(), n as u64),
        ));
    }
    rows
}

/// The cost of generality: E(μ) and E_avg of GGX through the built-in lobe (its weight in a
/// cancelled closed form, its horizon pole declared) and through the same lobe written as a
/// lobe spec (the expression's tape, the cautious azimuth fallback), at the same tolerances,
/// against the built-in at 1e-12: the rows' times at equal error are the price of a user lobe.
fn written_lobe_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    use crate::pipeline::lobe::LobeDef;
    use crate::shading::hemisphere;
    let def = LobeDef::parse(std::path::Path::new("tests/data/lobes/ggx_written.toml"), GGX_WRITTEN).expect("the written GGX lobe spec is valid");
    let alphas: Vec<f64> = pick(mode, &[1e-3, 0.1, 0.5, 1.0], &[1e-3, 1e-2, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0]);
    let mus: Vec<f64> = pick(mode, &[0.0, 0.3, 1.0], &[0.0, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0]);
    let pts: Vec<[f64; 2]> = alphas.iter().flat_map(|&a| mus.iter().map(move |&m| [a, m])).collect();
    let truth: Vec<f64> = pts.iter().map(|p| ggx::albedo(p[0], p[1], 1e-12).value).collect();
    let reference = ("built-in lobe, adaptive at tol 1e-12", truth.as_slice());
    let mut rows = Vec::new();
    for tol in pick(mode, &[1e-8], &[1e-6, 1e-8, 1e-10]) {
        rows.push(row(mode, "ggx-albedo", "built-in GGX lobe (shadefit)", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(pts.iter().map(|p| ggx::albedo(p[0], p[1], tol)).collect())
        }));
        rows.push(row(mode, "ggx-albedo", "GGX written as a lobe spec (kind = \"lobe\")", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(pts.iter().map(|p| hemisphere::albedo(&def.lobe(&p[..1]), p[1], tol)).collect())
        }));
    }
    let avg_alphas = pick(mode, &[0.1], &[1e-3, 0.1, 0.5, 1.0]);
    let avg_truth: Vec<f64> = avg_alphas.iter().map(|&a| ggx::albedo_avg(a, 1e-12).value).collect();
    let reference = ("built-in lobe, adaptive at tol 1e-12", avg_truth.as_slice());
    for tol in pick(mode, &[1e-6], &[1e-6, 1e-8]) {
        rows.push(row(mode, "ggx-albedo-avg", "built-in GGX lobe (shadefit)", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(avg_alphas.iter().map(|&a| ggx::albedo_avg(a, tol)).collect())
        }));
        rows.push(row(mode, "ggx-albedo-avg", "GGX written as a lobe spec (kind = \"lobe\")", format!("tol {tol:.0e}"), reference, || {
            Run::from_estimates(avg_alphas.iter().map(|&a| hemisphere::albedo_avg(&def.lobe(&[a]), tol)).collect())
        }));
    }
    rows
}

/// The engines' estimator of [scale, bias]: Filament's (n Hammersley points mapped to half
/// vectors through the GGX D·cos θh CDF, height-correlated V), lights outside μl ≥ c counted
/// as 0.
pub fn hammersley_env(alpha: f64, mu_v: f64, cos_cone: f64, n: usize) -> [f64; 2] {
    let [bias, e] = filament::dfv_multiscatter_in_cone(mu_v, alpha, n as u32, cos_cone);
    [e - bias, bias]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sampling_estimator_converges_to_the_integral() {
        // Quasi-Monte Carlo error ~ (log n)²/n for this smooth (after the CDF map) integrand;
        // at α = 0.3, n·v = 0.6, 65536 points, 1e-4 bounds it with margin, and the 256-point
        // estimate must be further off than the 65536-point one.
        let exact = ggx::env(0.3, 0.6, 0.0, Shadowing::HeightCorrelated, 1e-12);
        let coarse = hammersley_env(0.3, 0.6, 0.0, 256);
        let fine = hammersley_env(0.3, 0.6, 0.0, 65536);
        let err = |e: [f64; 2]| (e[0] - exact.scale).abs().max((e[1] - exact.bias).abs());
        assert!(err(fine) < 1e-4, "{fine:?} vs {exact:?}");
        assert!(err(fine) < err(coarse));
    }
}
