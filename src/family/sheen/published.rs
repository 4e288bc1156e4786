//! The published sheen curves measured against the integrals of `shading::charlie`, each in its
//! own roughness convention and against the visibility its engine's BRDF uses:
//!
//! - Estevez–Kulla's Λ curve (glTF KHR_materials_sheen; the glTF Sample Viewer's
//!   `lambdaSheen`) against the exact Smith Λ of the Charlie distribution, through
//!   G1 = 1/(1 + Λ) (bounded; Λ itself grows like 1/μ), with Λ's relative error as an extra;
//! - glTF's sheen albedo E under that curve against E under the exact Λ (what the curve costs);
//! - three.js's `IBLSheenBRDF` (r181+, PR #32397, and the 2021 form of PR #23069) against E
//!   under the BRDF three.js shades with, `D_Charlie(r²) · V_Neubelt` (Ashikhmin's V), at
//!   three.js's roughness r (α = r²). Constants re-read from three.js's
//!   `lights_physical_pars_fragment` (both versions).

use super::{lambda_table, QUANTITIES};
use crate::shading::charlie::lambda_estevez_kulla;
use crate::validate::Item;
use rayon::prelude::*;
use std::path::Path;

/// Integrator tolerance of the albedo measurements (absolute, on E ≤ 1): a thousandth of the
/// smallest error reported below.
const TOL: f64 = 1e-8;

/// The roughness axis of the measurements: r uniform on [0.1, 1] (α = r² from 0.01).
const NR: usize = 19;
/// n·v uniform on [0, 1] (from 1/32 for Λ, which is infinite at 0).
const NV: usize = 33;

fn roughness(i: usize) -> f64 {
    0.1 + 0.9 * i as f64 / (NR - 1) as f64
}

fn n_dot_v(j: usize) -> f64 {
    j as f64 / (NV - 1) as f64
}

/// The (r, n·v) grid, n·v from `first`.
fn grid(first: usize) -> Vec<Vec<f64>> {
    (0..NR).flat_map(|i| (first..NV).map(move |j| vec![roughness(i), n_dot_v(j)])).collect()
}

/// `quantity` (α, n·v) at every (r, n·v) point, α = r².
fn albedo(quantity: &str, pts: &[Vec<f64>]) -> Vec<f64> {
    let q = QUANTITIES.iter().find(|q| q.name == quantity).expect("a sheen quantity");
    pts.par_iter().map(|p| (q.eval)(&[p[0] * p[0], p[1].max(q.params[1].min)], TOL).value).collect()
}

/// three.js r181+ (PR #32397): E = saturate(exp(a n·v + b)).
pub fn threejs_2025(r: f64, mu: f64) -> f64 {
    let r2 = r * r;
    let r_inv = 1.0 / (r + 0.1);
    let a = -1.9362 + 1.0678 * r + 0.4573 * r2 - 0.8469 * r_inv;
    let b = -0.6014 + 0.5538 * r - 0.4670 * r2 - 0.1255 * r_inv;
    (a * mu + b).exp().clamp(0.0, 1.0)
}

/// three.js r13x–r180 (PR #23069): E = saturate(DG/π), piecewise in r at 0.25.
pub fn threejs_2021(r: f64, mu: f64) -> f64 {
    let r2 = r * r;
    let (a, b, c) = if r < 0.25 {
        (-339.2 * r2 + 161.4 * r - 25.9, 44.0 * r2 - 23.7 * r + 3.26, 0.0)
    } else {
        (-8.48 * r2 + 14.3 * r - 9.95, 1.97 * r2 - 3.27 * r + 0.72, 0.1 * (r - 0.25))
    };
    (((a * mu + b).exp() + c) / std::f64::consts::PI).clamp(0.0, 1.0)
}

pub fn items(_generated: &Path) -> Vec<Item> {
    let mut items = vec![lambda_curve()];
    let pts = grid(0);
    let domain = format!("sheen roughness r ∈ [0.1, 1] ({NR} uniform, α = r²), n·v ∈ [0, 1] ({NV} uniform)");
    let exact = albedo("sheen-albedo", &pts);
    let ek = albedo("sheen-albedo-ek", &pts);
    let mut item = Item::measured(
        "glTF sheen albedo E under Estevez–Kulla's Λ curve",
        "KHR_materials_sheen (V_Sheen with lambdaSheen); the exact Smith Λ of the Charlie distribution",
        &domain,
        &pts,
        &exact,
        &ek,
    );
    item.findings.push(format!(
        "E under the fitted curve against E under the exact Λ (height-correlated Smith in both; n·v = 0 taken at 1e-6 for the curve, \
         whose E is unbounded at n·v = 0): max {:.4}, rms {:.4} — the curve's error in G1 carried into the albedo.",
        item.max_abs_error, item.rms_error
    ));
    items.push(item);

    let ashikhmin = albedo("sheen-albedo-ashikhmin", &pts);
    for (name, source, form) in [
        ("three.js IBLSheenBRDF (r181+)", "mrdoob/three.js PR #32397, lights_physical_pars_fragment", threejs_2025 as fn(f64, f64) -> f64),
        ("three.js IBLSheenBRDF (2021)", "mrdoob/three.js PR #23069, lights_physical_pars_fragment", threejs_2021),
    ] {
        let approx: Vec<f64> = pts.iter().map(|p| form(p[0], p[1])).collect();
        let mut item = Item::measured(name, source, &domain, &pts, &ashikhmin, &approx);
        let rel: Vec<f64> = approx.iter().zip(&ashikhmin).map(|(a, e)| (a - e).abs() / e.max(1e-12)).collect();
        let mean_rel = rel.iter().sum::<f64>() / rel.len() as f64;
        item.extra.push(("mean_relative_error".into(), mean_rel));
        item.findings.push(format!(
            "Against E of three.js's own sheen BRDF (D_Charlie(α = r²) · V_Neubelt, unclamped): max {:.4} at (r, n·v) = ({:.3}, {:.3}), \
             rms {:.4}, mean relative error {:.1}%.",
            item.max_abs_error,
            item.worst_point[0],
            item.worst_point[1],
            item.rms_error,
            100.0 * mean_rel
        ));
        items.push(item);
    }
    items
}

/// Estevez–Kulla's Λ curve against the exact Λ, through G1 = 1/(1 + Λ).
fn lambda_curve() -> Item {
    let pts = grid(1);
    let (exact, curve): (Vec<f64>, Vec<f64>) = pts
        .par_iter()
        .map(|p| {
            let alpha = p[0] * p[0];
            (lambda_table(alpha).lambda(p[1]), lambda_estevez_kulla(alpha, p[1]))
        })
        .unzip();
    let g1 = |l: &[f64]| -> Vec<f64> { l.iter().map(|l| 1.0 / (1.0 + l)).collect() };
    let mut item = Item::measured(
        "Estevez–Kulla Λ curve (G1 = 1/(1 + Λ))",
        "Estevez & Kulla 2017; KHR_materials_sheen 'Sheen visibility'; glTF-Sample-Viewer lambdaSheen",
        &format!("sheen roughness r ∈ [0.1, 1] ({NR} uniform, α = r²), μ ∈ [1/32, 1] ({} uniform)", NV - 1),
        &pts,
        &g1(&exact),
        &g1(&curve),
    );
    let (mut worst, mut at) = (0.0f64, 0);
    for (k, (e, c)) in exact.iter().zip(&curve).enumerate() {
        let r = (c - e).abs() / e.max(1e-300);
        if *e > 0.0 && r > worst {
            worst = r;
            at = k;
        }
    }
    item.extra.push(("max_relative_error_lambda".into(), worst));
    let rel_at = |r: f64, mu: f64| {
        let a = r * r;
        let e = lambda_table(a).lambda(mu);
        (lambda_estevez_kulla(a, mu) - e) / e
    };
    item.findings = vec![
        format!(
            "Λ's largest relative error {:.1}% at (r, μ) = ({:.3}, {:.3}); at r = 1: {:+.1}% (μ = 0.5), at r = 0.5: {:+.1}%, at r = 0.1: {:+.1}%.",
            100.0 * worst,
            pts[at][0],
            pts[at][1],
            100.0 * rel_at(1.0, 0.5),
            100.0 * rel_at(0.5, 0.5),
            100.0 * rel_at(0.1, 0.5)
        ),
        "The curve is finite at μ = 0 (Λ(0) = e^L(0), L(0) = a + e ≈ 17–20) where the exact Λ grows like g(π/2)/μ, and its α = 0 end \
         (P0) is finite where the exact Λ grows without bound as α → 0 (D collapses onto the horizon): the fit interpolates \
         between two finite ends in (1 − α)², so it cannot follow the exact Λ at small α."
            .into(),
    ];
    item
}
