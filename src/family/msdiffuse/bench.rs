//! msdiffuse benchmark rows (`shadefit bench`): the random walk's error against its paths, the
//! study behind the default tables' path counts, and its throughput (seconds a point on one
//! thread; paths/s = paths / that):
//! - ms-diffuse (full walk) at 2^8…2^14 paths a point against 2^18 paths (the reference's own
//!   standard error is reported beside it), at (θh, θd) on a 4 × 4 grid at gloss 0 and 0.5;
//! - the walk's first event (single scattering) at the same ladder against the analytic f₁ by
//!   quadrature (an exact reference: the error is the Monte Carlo error alone);
//! - shader forms of `ms-diffuse-cosines` (π f/ρ in α, n·h, l·h on the φd = π/2 slice): the
//!   committed `ms_diffuse_rational` (quadratic in n·h, l·h, coefficients linear in α), a
//!   cheaper bilinear one and the talk's cubic form with coefficients linear in α, each fitted
//!   by least squares on the committed fitting grid (quick: 5 × 7 × 7) and measured on the
//!   committed verification grid (quick: 5 × 7 × 7); the reference is the walk at the spec's
//!   4096 paths a point, whose rms standard error every note gives (errors below it are noise).

use super::integrals::{Order, TALK_F0, brdf, directions, single_scattering, surface};
use super::walk::{Specular, key_of};
use crate::bench::integrals::{IntegratorBench, IntegratorRow, Run, pick, row};
use crate::bench::forms::{Ctx, FormRow, FormSet, Integral, fit_row, refit_row, set, strings};
use crate::bench::{BenchError, FamilyBench, Mode};
use crate::pipeline;
use std::f64::consts::FRAC_PI_2;

pub const BENCH: FamilyBench = FamilyBench {
    integrators: &[IntegratorBench { order: 12, run: walk_rows }],
    fits: &[],
    tables: &[],
    builds: &[],
    forms: &[FormSet { quantity: "ms-diffuse-cosines", order: 12, forms: rational_forms }],
};

/// Quadratic and cubic terms in (n·h, l·h), each also times α.
#[cfg(test)]
const QUADRATIC: [&str; 6] = ["1", "n_dot_h", "l_dot_h", "n_dot_h^2", "l_dot_h^2", "n_dot_h*l_dot_h"];
const BILINEAR: [&str; 4] = ["1", "n_dot_h", "l_dot_h", "n_dot_h*l_dot_h"];
const CUBIC: [&str; 8] = ["1", "n_dot_h", "l_dot_h", "n_dot_h^2", "l_dot_h^2", "n_dot_h*l_dot_h", "n_dot_h^3", "l_dot_h^3"];

/// `terms` and `terms`·α as numerator and denominator terms (the denominator without its lead 1).
fn linear_in_alpha(terms: &[&str]) -> (Vec<String>, Vec<String>) {
    let num: Vec<String> = terms.iter().map(|t| t.to_string()).chain(terms.iter().map(|t| if *t == "1" { "alpha".to_string() } else { format!("alpha*{t}") })).collect();
    let den = num.iter().filter(|t| *t != "1").cloned().collect();
    (num, den)
}

/// π f/ρ in (α, n·h, l·h): the committed rational and two other sizes.
fn rational_forms(ctx: &Ctx) -> Result<Vec<FormRow>, BenchError> {
    let refit = ctx.spec("ms_diffuse_rational")?;
    let mut integral = Integral::of(&refit);
    let verify: Vec<usize> = refit.file.axis.iter().map(|a| ctx.pick(a.verify_count(), if a.name == "alpha" { 5 } else { 7 })).collect();
    let points = pipeline::grid(&refit, &verify);
    let sampler = refit.sampler();
    let se: Vec<f64> = {
        use rayon::prelude::*;
        points.par_iter().map(|p| sampler.eval(p).error).collect()
    };
    let rms_se = (se.iter().map(|e| e * e).sum::<f64>() / se.len() as f64).sqrt();
    let reference = integral.reference(points);
    let fit: Vec<usize> = refit.file.axis.iter().map(|a| ctx.pick(a.count, if a.name == "alpha" { 5 } else { 7 })).collect();
    let grid = fit.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(" × ");
    let note = format!("least squares on {grid}; reference rms standard error {rms_se:.2e}");
    let variant = |name: &str, terms: &[&str]| {
        let (num, den) = linear_in_alpha(terms);
        let num: Vec<&str> = num.iter().map(String::as_str).collect();
        let den: Vec<&str> = den.iter().map(String::as_str).collect();
        ctx.variant(&refit, name, |t| {
            set(t, "model.numerator", strings(&num));
            set(t, "model.denominator", strings(&den));
        })
    };
    let bilinear = variant("ms_diffuse_rational_bilinear", &BILINEAR)?;
    let cubic = variant("ms_diffuse_rational_cubic", &CUBIC)?;
    Ok(vec![
        refit_row(&refit, ctx.generated, &reference, &format!("fits/ms_diffuse_rational.toml, committed; reference rms standard error {rms_se:.2e}"))?,
        fit_row(&bilinear, integral.fit(&bilinear, &fit)?, &reference, "rational, bilinear in (n·h, l·h) × (1, α)", &note)?,
        fit_row(&cubic, integral.fit(&cubic, &fit)?, &reference, "rational, the talk's cubic form × (1, α)", &note)?,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_terms_double_the_form() {
        // The committed spec's model is the quadratic form times (1, α): 12 and 11 terms.
        let (num, den) = linear_in_alpha(&QUADRATIC);
        assert_eq!((num.len(), den.len()), (12, 11));
        assert_eq!(num[6], "alpha");
        assert!(!den.contains(&"1".to_string()));
    }
}

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
