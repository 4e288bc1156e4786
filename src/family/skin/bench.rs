//! The skin family's benchmark rows (`shadefit bench`, see `crate::bench`):
//! - integrators: the punctual diffusion D(n·l, κ) (adaptive, split at the kinks, against
//!   Gauss–Legendre over the ring angle) and the SH bands (adaptive over the chord), RGB, with
//!   the preset profile;
//! - tables against numpy/scipy: `skin_punctual_lut`, `skin_sh_lut` (the quantities integrate
//!   to min(tol, 1e-10), `quantity::skin_tolerance`: the tabulated tolerance is the only
//!   setting);
//! - shader forms of `skin-punctual`: the LUT texture at three resolutions and the const-array
//!   lookup.

use super::integrals as skin;
use crate::bench::forms::{Ctx, FormRow, FormSet, count_in, parse, row as form_row, set, wgsl_of};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row, self_ladder};
use crate::bench::tables::{Ladder, Params, Shape, TableBench};
use crate::bench::{BenchError, FamilyBench, Mode};
use crate::integrate::{Estimate, Tolerance, gauss_legendre};
use std::f64::consts::PI;

/// The skin family's rows.
pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[
        IntegratorBench { order: 5, run: skin_punctual_integrators },
        IntegratorBench { order: 6, run: skin_sh_integrators },
    ],
    fits: &[],
    tables: &[
        TableBench {
            spec: "skin_punctual_lut",
            order: 3,
            samples: (24, 96),
            ladder: Ladder::Tolerances(&[1e-10], &[1e-10]),
            reference_tolerance: 1e-14,
            // (curvature, n·l) → RGB; the script takes (n_dot_l, kappa).
            shape: Shape { params: Params::Pick(&[(1, "n_dot_l"), (0, "kappa")]), channels: 3, fold_last_axis: false },
        },
        TableBench {
            spec: "skin_sh_lut",
            order: 4,
            samples: (8, 32),
            ladder: Ladder::Tolerances(&[1e-10], &[1e-10]),
            reference_tolerance: 1e-14,
            // (curvature, band ∈ {1, 2}) → RGB; the script takes (kappa) → k₁ RGB, k₂ RGB.
            shape: Shape { params: Params::Pick(&[(0, "kappa")]), channels: 6, fold_last_axis: true },
        },
    ],
    builds: &[],
    forms: &[FormSet { quantity: "skin-punctual", order: 6, forms: skin_punctual }],
};

// ---------------------------------------------------------------------------------------------
// Integrators

fn skin_punctual_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let profile = skin::default_skin_profile();
    let mut pts = Vec::new();
    for kappa in [0.05, 0.25, 0.5, 1.0] {
        for nl in [-0.5, -0.1, 0.0, 0.3, 0.9] {
            pts.push([kappa, nl]);
        }
    }
    let eval = |tol: f64| -> Vec<[Estimate; 3]> {
        pts.iter()
            .map(|p| {
                skin::punctual(
                    &profile,
                    skin::Kernel::Linear,
                    p[0],
                    p[1],
                    ladder_tolerance(tol),
                )
                .expect("the preset profile is valid")
            })
            .collect()
    };
    // One value per point and channel, point-major.
    let flat = |e: Vec<[Estimate; 3]>| -> Vec<Estimate> { e.into_iter().flatten().collect() };
    let (truth, mut rows) = self_ladder(
        mode,
        "skin punctual (RGB)",
        "adaptive G10/K21 split at the kinks (shadefit)",
        1e-14,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
        |tol| flat(eval(tol)),
    );
    let reference = ("adaptive at tol 1e-14", truth.as_slice());
    // The straightforward ring integral: Gauss–Legendre over x ∈ [−π, π], unsplit.
    for n in pick(mode, &[64, 1024], &[64, 256, 1024, 4096]) {
        let (x, w) = gauss_legendre(n);
        rows.push(row(
            mode,
            "skin punctual (RGB)",
            "Gauss–Legendre over the ring angle x ∈ [−π, π]",
            format!("n = {n}"),
            reference,
            || {
                let values = pts
                    .iter()
                    .flat_map(|p| {
                        let (kappa, nl) = (p[0], p[1]);
                        let theta = nl.acos();
                        let r = 1.0 / kappa;
                        let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
                        for (xi, wi) in x.iter().zip(&w) {
                            let xa = PI * xi;
                            let k = profile.linear(2.0 * r * (0.5 * xa.abs()).sin());
                            let c = (theta + xa).cos().max(0.0);
                            for ch in 0..3 {
                                num[ch] += wi * c * k[ch];
                                den[ch] += wi * k[ch];
                            }
                        }
                        (0..3).map(move |ch| num[ch] / den[ch])
                    })
                    .collect();
                Run::fixed(values, 3 * n as u64)
            },
        ));
    }
    rows
}

fn skin_sh_integrators(mode: &Mode) -> Vec<IntegratorRow> {
    let profile = skin::default_skin_profile();
    let mut pts = Vec::new();
    for kappa in [0.05, 0.25, 0.5, 1.0] {
        for band in [1u32, 2] {
            pts.push((kappa, band));
        }
    }
    let eval = |tol: f64| -> Vec<Estimate> {
        pts.iter()
            .flat_map(|&(kappa, band)| {
                skin::sh_band(
                    &profile,
                    kappa,
                    band,
                    ladder_tolerance(tol),
                )
                .expect("the preset profile is valid")
            })
            .collect()
    };
    self_ladder(
        mode,
        "skin SH bands (RGB)",
        "adaptive G10/K21 over the chord (shadefit)",
        1e-14,
        pick(mode, &[1e-6, 1e-8, 1e-10], &[1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
        eval,
    )
    .1
}

// ---------------------------------------------------------------------------------------------
// Shader forms

/// Pre-integrated skin diffusion D(n·l, κ) for punctual lights (RGB).
fn skin_punctual(ctx: &Ctx) -> Result<Vec<FormRow>, BenchError> {
    let committed = ctx.spec("skin_punctual_lut")?;
    let mut rows = Vec::new();
    for (w, h) in [(33, 32), (65, 64), (129, 128)] {
        let spec = if (w, h) == (65, 64) {
            committed.clone()
        } else {
            ctx.variant(&committed, &format!("skin_punctual_lut_{w}x{h}"), |t| {
                set(t, "resolution", toml::Value::Array(vec![(w as i64).into(), (h as i64).into()]))
            })?
        };
        let name = &spec.file.name;
        let (built, texture) = super::build::build_with_texture_error(&spec).map_err(BenchError::build(name))?;
        let source = parse(name, wgsl_of(&built)?)?;
        let f = &spec.file.emit.function;
        let committed_note = if (w, h) == (65, 64) { ", committed size" } else { "" };
        rows.push(form_row(
            &spec.file.quantity,
            &format!("texture {w}×{h}"),
            count_in(name, &source, &format!("{f}_sample"))?,
            8 * w * h,
            (&texture).into(),
            format!(
                "rgba16float texels, linear sampler (error with exact filter weights: 8-bit weights add up to 2⁻⁹ of a texel step){committed_note}; measured on the texel grid with every midpoint"
            ),
        ));
        if (w, h) == (65, 64) {
            let v = &built.verification;
            rows.push(form_row(
                &spec.file.quantity,
                &format!("const array {w}×{h}"),
                count_in(name, &source, f)?,
                12 * w * h,
                v.into(),
                "f32 RGB texels, bilinear in the shader; fits/skin_punctual_lut.toml".into(),
            ));
        }
    }
    Ok(rows)
}

/// The integrators' tolerance at one rung of a ladder: absolute only, a generous panel budget.
fn ladder_tolerance(abs: f64) -> Tolerance {
    Tolerance { abs, rel: 0.0, max_panels: 2000 }
}
