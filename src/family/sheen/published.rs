//! The published sheen curves measured against the integrals of `shading::charlie`, each in its
//! own roughness convention and against the BRDF its engine shades with, on the grid of
//! [`super::grid`], with shadefit's refit of the same form beside it ([`super::refit`]):
//!
//! - Estevez–Kulla's Λ curve (glTF KHR_materials_sheen; the Sample Viewer's `lambdaSheen`)
//!   against the exact Smith Λ of the Charlie distribution, through G1 = 1/(1 + Λ) (bounded;
//!   Λ itself grows like 1/μ), with Λ's relative error as an extra;
//! - glTF's sheen albedo E under that curve against E under the exact Λ (what the curve costs);
//! - the published E fits (three.js 2025 and 2021, MaterialX, Babylon, Filament's unused cloth
//!   fits), each against the integral its source's BRDF defines, and against every other
//!   candidate (four lobes × α = r or r²) as extras: the closest candidate says what a
//!   fit was made for when its source does not;
//! - Filament's DFG blue channel and the glTF IBL Sampler's Charlie LUT, regenerated with their
//!   own estimators ([`super::lut`]), as tables;
//! - the glTF Sample Viewer's shipped `lut_sheen_E.png`, decoded and measured as a table
//!   ([`super::viewer`]).

use super::grid::{self, Convention, Target};
use super::lambda_table;
use super::refit::{self, Form, REFITTED};
use crate::shading::charlie::lambda_estevez_kulla;
use crate::validate::Item;
use std::path::Path;

pub fn items(generated: &Path) -> Vec<Item> {
    let mut items = vec![lambda_curve(generated), gltf_albedo()];
    for (name, form) in &REFITTED[1..] {
        items.push(form_item(generated, name, form));
    }
    items.extend(super::lut::items(generated));
    items.push(super::viewer::item());
    items
}

/// The committed refit of `name` measured beside the published form.
fn add_refit(item: &mut Item, generated: &Path, name: &str, form: &Form) {
    match refit::committed(generated, name) {
        Ok(c) => {
            let e = form.errors(&crate::fit::published::as_emitted(&c));
            item.extra.push(("refit_max_abs_error".into(), e.max_abs_error));
            item.extra.push(("refit_rms_error".into(), e.rms_error));
            item.findings.push(format!(
                "shadefit's refit (same form, minimax, fits/{}.toml, f32 constants): max {:.3e} ({:.2}× the published), rms {:.3e} ({:.2}×).",
                refit::SPEC,
                e.max_abs_error,
                e.max_abs_error / item.max_abs_error,
                e.rms_error,
                e.rms_error / item.rms_error
            ));
        }
        Err(why) => item.findings.push(format!("shadefit's refit is not committed here: {why}.")),
    }
}

/// Max |form − E| against every candidate integral (saturated where the form saturates), as
/// extras `max_abs_error_vs_KEY`, and a finding naming the closest.
fn candidates(item: &mut Item, values: &[f64], saturates: bool) {
    let mut best = (f64::INFINITY, Target::ALL[0]);
    for t in Target::ALL {
        let truth: Vec<f64> = t.albedo().iter().map(|&e| if saturates { e.min(1.0) } else { e }).collect();
        let (m, _, _) = crate::validate::measure(grid::points(), &truth, values);
        item.extra.push((format!("max_abs_error_vs_{}", t.key()), m));
        if m < best.0 {
            best = (m, t);
        }
    }
    item.findings.push(format!(
        "Closest of the eight candidate integrals (Charlie's D with Ashikhmin's V, Estevez–Kulla's Λ curve or the exact Λ, and Ashikhmin's velvet D with Neubelt's V; α = r² or r{}): {} (max {:.3e}).",
        if saturates { "; saturated as the form is" } else { "" },
        best.1.describe(),
        best.0
    ));
}

/// Mean |relative error| over the points where the integral is at least 0.01 (below, relative
/// errors of a near-zero E say nothing), in percent.
fn mean_relative(truth: &[f64], values: &[f64]) -> f64 {
    let (s, n) = truth.iter().zip(values).filter(|(t, _)| **t >= 0.01).fold((0.0, 0), |(s, n), (t, v)| (s + (v - t).abs() / t, n + 1));
    100.0 * s / n.max(1) as f64
}

fn form_item(generated: &Path, name: &str, form: &Form) -> Item {
    let pts = grid::points();
    let truth = (form.truth)();
    let values = form.values(form.published);
    let convention = if name == "sheen-materialx" { Convention::Linear } else { Convention::Squared };
    let mut item = Item::measured(form.label, source_of(name), &grid::domain(convention), &pts, &truth, &values);
    let mean = mean_relative(&truth, &values);
    item.extra.push(("mean_relative_error_percent".into(), mean));
    item.findings.push(format!(
        "Against {}: max {:.4} at (r, n·v) = ({:.3}, {:.3}), rms {:.4}, mean relative error {mean:.1}% where E ≥ 0.01.",
        (form.against)(),
        item.max_abs_error,
        item.worst_point[0],
        item.worst_point[1],
        item.rms_error
    ));
    let saturates = matches!(name, "sheen-threejs" | "sheen-threejs-2021" | "sheen-materialx");
    candidates(&mut item, &values, saturates);
    if saturates {
        let over = Target::ALL[0].albedo().iter().filter(|&&e| e > 1.0).count();
        item.findings.push(format!(
            "The form saturates to [0, 1]; E exceeds 1 at grazing views of smooth sheen ({over} of {} grid points under Ashikhmin's V at α = r²), \
             where any saturated form is at least E − 1 off: it is measured against min(1, E).",
            pts.len()
        ));
    }
    item.findings.push(finding_of(name).into());
    add_refit(&mut item, generated, name, form);
    item
}

fn source_of(name: &str) -> &'static str {
    match name {
        "sheen-threejs" => "mrdoob/three.js PR #32397 (r181+), src/renderers/shaders/ShaderChunk/lights_physical_pars_fragment.glsl.js",
        "sheen-threejs-2021" => "mrdoob/three.js PR #23069 (r13x–r180), lights_physical_pars_fragment",
        "sheen-materialx" => "AcademySoftwareFoundation/MaterialX libraries/pbrlib/genglsl/lib/mx_microfacet_sheen.glsl (PR #691)",
        "sheen-babylon" => "BabylonJS/Babylon.js packages/dev/core/src/Shaders/ShadersInclude/pbrBRDFFunctions.fx (commented out: NOT USED)",
        "sheen-filament-cloth-ashikhmin" => "google/filament libs/ibl/src/CubemapIBL.cpp (prefilteredDFG_Cloth_Ashikhmin, marked __UNUSED)",
        _ => "google/filament libs/ibl/src/CubemapIBL.cpp (prefilteredDFG_Cloth_Charlie, marked __UNUSED)",
    }
}

fn finding_of(name: &str) -> &'static str {
    match name {
        "sheen-threejs" | "sheen-threejs-2021" => {
            "three.js shades sheen with BRDF_Sheen = D_Charlie(α = r²)·V_Neubelt (Ashikhmin's V) and scales the layer below by \
             1 − max3(sheenColor)·IBLSheenBRDF: this fit is that E. (three.js also saturates V_Neubelt at 1 and floors sin²θh \
             at 2⁻⁷ in D_Charlie, fp16 guards that change E only at grazing views of smooth sheen and near the normal as r → 1; \
             the integral here is the lobe without them.)"
        }
        "sheen-materialx" => {
            "MaterialX's sheen D takes its roughness as α (invRoughness = 1/roughness, clamped at 0.005) with Neubelt's smoother \
             denominator; the fit was made to its own 64-sample Monte Carlo (mx_imageworks_sheen_dir_albedo_monte_carlo) and is \
             saturated by mx_imageworks_sheen_dir_albedo."
        }
        "sheen-babylon" => {
            "Babylon keeps it under SHEEN_SOFTER, the branch that shades with Estevez–Kulla's visibility (visibility_CharlieSheen) at \
             α = r² (convertRoughnessToAverageSlope); the branch is commented out and Babylon reads E from its BRDF texture instead."
        }
        "sheen-filament-cloth-ashikhmin" => {
            "Named for Ashikhmin's velvet distribution, Filament's cloth D before Charlie's (a = linear roughness = r², as the \
             IBL Sampler's D_Ashikhmin), with Neubelt's V; its second channel is 0.03 times the first."
        }
        _ => {
            "Filament's cloth shades with D_Charlie and V_Ashikhmin (Neubelt) at α = r² (linear roughness = perceptual²); the fit's \
             second channel is 0.0095 times the first, and min(c, 18) caps it where E grows at grazing views of smooth cloth."
        }
    }
}

/// Estevez–Kulla's Λ curve against the exact Λ, through G1 = 1/(1 + Λ).
fn lambda_curve(generated: &Path) -> Item {
    let pts = grid::points();
    let (exact, curve) = (grid::g1_exact(), grid::g1_estevez_kulla());
    let mut item = Item::measured(
        "Estevez–Kulla Λ curve (G1 = 1/(1 + Λ))",
        "Estevez & Kulla 2017; KHR_materials_sheen 'Sheen visibility'; glTF-Sample-Viewer lambdaSheen",
        &grid::domain(Convention::Squared),
        &pts,
        exact,
        &curve,
    );
    // Λ's relative error where Λ ≥ 1e-3 (Λ → 0 at normal incidence, where its relative error
    // says nothing about G1).
    let (mut worst, mut at) = (0.0f64, 0);
    for (k, p) in pts.iter().enumerate().filter(|(_, p)| p[1] > 0.0) {
        let a = p[0] * p[0];
        let e = lambda_table(a).lambda(p[1]);
        let r = (lambda_estevez_kulla(a, p[1]) - e).abs() / e;
        if e >= 1e-3 && r > worst {
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
            "Λ's largest relative error (where Λ ≥ 1e-3) {:.1}% at (r, μ) = ({:.3}, {:.3}); at μ = 0.5: {:+.1}% at r = 1, {:+.1}% at r = 0.5, {:+.1}% at r = 0.1.",
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
    add_refit(&mut item, generated, REFITTED[0].0, REFITTED[0].1);
    item
}

/// glTF's E under Estevez–Kulla's curve against E under the exact Λ.
fn gltf_albedo() -> Item {
    let ek = Target::new(grid::Visibility::EstevezKulla, Convention::Squared).albedo();
    let exact = Target::new(grid::Visibility::Smith, Convention::Squared).albedo();
    let mut item = Item::measured(
        "glTF sheen albedo E under Estevez–Kulla's Λ curve",
        "KHR_materials_sheen (V_Sheen with lambdaSheen); the exact Smith Λ of the Charlie distribution",
        &grid::domain(Convention::Squared),
        grid::points(),
        exact,
        ek,
    );
    item.findings.push(format!(
        "E under the fitted curve against E under the exact Λ (height-correlated Smith in both; n·v = 0 taken at 1e-6 for the curve, \
         whose E is unbounded at n·v = 0): max {:.4}, rms {:.4} — the curve's error in G1 carried into the albedo. The exact \
         lobe's E(0) is 1 at every α (at a horizontal view G2/(4 n·v) → 1/(4 n·v Λ(n·v)), and n·v Λ(n·v) is the projected area \
         the integral over h then cancels), which no finite Λ(0) gives.",
        item.max_abs_error, item.rms_error
    ));
    item.findings.push(
        "No same-form refit: this row is the cost of a definition (glTF's E is by definition E under the curve), not a fitted \
         approximation; the curve's own refit is the previous row, and E under the exact Λ is what `sheen-albedo` and \
         fits/sheen_albedo_table.toml give."
            .into(),
    );
    item
}
