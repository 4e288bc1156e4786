//! The occlusion approximations' refits as registered published forms ([`FORMS`]), refitted by
//! `fits/ggx_occlusion_refits.toml` (`kind = "refit"`), which commits their constants; the
//! validation items and the figures read them from its JSON ([`Refits::committed`]).
//!
//! - Lagarde & de Rousiers 2014, saturate((n·v + V)^(2^(a α + b)) − 1 + V): (a, b) for the least
//!   rms (F0 = 4 %) against the cone model on the validation grid (its minimax is degenerate:
//!   see [`super::refits`]);
//! - Jimenez et al. 2016's cone–cone intersection: the specular cone's k minimax. Its form (a
//!   spherical-lens area through acos) is not written as a program: the module gives no function
//!   for it, only its constants;
//! - Jimenez et al. 2016's multi-bounce cubic max(V, ((aV + b)V + c)V), a, b, c linear in ρ:
//!   minimax against COD: WWII's interreflection model A′ = A/(1 − ρ + ρA) on 65 × 65 points.

use super::validation::{multibounce_errors, so_errors};
use super::{JIMENEZ, JIMENEZ_MULTIBOUNCE, LAGARDE, jimenez_with, lagarde_with};
use crate::fit::expr::Expr;
use crate::fit::expr::program::{Program, build::*};
use crate::fit::expr::tape::Compiled;
use crate::fit::published::{FormError, PublishedForm};
use crate::pipeline::BuildError;
use std::path::Path;
use std::sync::LazyLock;

/// The refit spec (`fits/SPEC.toml`).
pub const SPEC: &str = "ggx_occlusion_refits";
pub const LAGARDE_NAME: &str = "ggx-lagarde-occlusion";
pub const JIMENEZ_NAME: &str = "ggx-jimenez-occlusion";
pub const MULTIBOUNCE_NAME: &str = "ggx-jimenez-multibounce";

/// The committed refits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refits {
    pub lagarde: [f64; 2],
    pub jimenez: f64,
    pub multibounce: [f64; 6],
}

impl Refits {
    /// The refits committed in `generated` (checked against their spec).
    pub fn committed(generated: &Path) -> Result<Refits, BuildError> {
        let refits = crate::family::committed_refits(generated, SPEC)?;
        let c = |form: &str| refits.constants(form);
        let (l, j, m) = (c(LAGARDE_NAME)?, c(JIMENEZ_NAME)?, c(MULTIBOUNCE_NAME)?);
        Ok(Refits { lagarde: [l[0], l[1]], jimenez: j[0], multibounce: std::array::from_fn(|i| m[i]) })
    }
}

/// The refits of the repository's own generated/.
#[cfg(test)]
pub fn repository() -> Refits {
    Refits::committed(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")).expect("the occlusion refits are committed")
}

/// [`LAGARDE_FORM`] and [`MULTIBOUNCE_FORM`] compiled (the refits' objectives evaluate them at
/// every point of every step).
pub static LAGARDE_TAPE: Compiled = Compiled::of(&LAGARDE_FORM);
pub static MULTIBOUNCE_TAPE: Compiled = Compiled::of(&MULTIBOUNCE_FORM);

/// Lagarde's form over (n·v, V, α): saturate(exp2(2^(a α + b) · log2(max(n·v + V, 1e-30))) − 1 + V),
/// the power written as exp2 · log2 as a shader's pow is, its base kept off 0 (where log2 is
/// undefined in WGSL). The floor never shows: n·v + V < 1e-30 means V < 1e-30, and then the
/// power (≤ 1 for a base ≤ 1) minus 1 plus V is at most ~1e-30, which the saturate takes to 0
/// or leaves below 1e-30, as the exact 0^e − 1 + V would give.
pub static LAGARDE_FORM: LazyLock<Program> = LazyLock::new(|| {
    let base = max(var(0) + var(1), lit(1e-30));
    let power = exp2(exp2(k(0) * var(2) + k(1)) * Expr::Log2(Box::new(base)));
    Program { lets: vec![], result: clamp(power - lit(1.0) + var(1), lit(0.0), lit(1.0)) }
});

/// Jimenez's multi-bounce cubic over (V, ρ): a = k₀ρ + k₁, b = k₂ρ + k₃, c = k₄ρ + k₅, then
/// max(V, ((aV + b)V + c)V) (their Eq. 10, in [`super::jimenez_multibounce`]'s order).
pub static MULTIBOUNCE_FORM: LazyLock<Program> = LazyLock::new(|| Program {
    lets: vec![
        ("a".into(), k(0) * var(1) + k(1)),
        ("b".into(), k(2) * var(1) + k(3)),
        ("c".into(), k(4) * var(1) + k(5)),
    ],
    result: max(var(0), ((bind(0) * var(0) + bind(1)) * var(0) + bind(2)) * var(0)),
});

const UNIT: (f64, f64) = (0.0, 1.0);

/// The occlusion forms, as `fits/ggx_occlusion_refits.toml` refits them (registered in the
/// family's descriptor).
pub static FORMS: [PublishedForm; 3] = FORMS_DEF;

/// [`FORMS`] as a value (the family's descriptor lists every form of the family in one slice).
pub const FORMS_DEF: [PublishedForm; 3] = [
    PublishedForm {
        name: LAGARDE_NAME,
        function: "lagarde",
        doc: "Lagarde & de Rousiers 2014's specular occlusion refitted to the cone model (least rms, F0 = 4 %): SO at n·v, visibility V and GGX α.",
        args: &["n_dot_v", "visibility", "alpha"],
        domain: &[UNIT, UNIT, UNIT],
        program: Some(|| &*LAGARDE_FORM),
        published: || LAGARDE.to_vec(),
        reads: &[],
        refit: |_| Ok(super::validation::lagarde_refit().to_vec()),
        measure: |_, p, r| Ok({
            let (p, r) = ([p[0], p[1]], [r[0], r[1]]);
            vec![so_row("Lagarde & de Rousiers 2014", |rr, mu, v| lagarde_with(p, mu, v, rr * rr), |rr, mu, v| lagarde_with(r, mu, v, rr * rr))]
        }),
        check: None,
    },
    PublishedForm {
        name: JIMENEZ_NAME,
        function: "jimenez",
        doc: "Jimenez et al. 2016's cone–cone specular occlusion with the specular cone cos α_s = 2^(k r²) refitted (minimax, F0 = 4 %).",
        args: &["n_dot_v", "visibility", "roughness"],
        domain: &[UNIT, UNIT, UNIT],
        program: None,
        published: || vec![JIMENEZ],
        reads: &[],
        refit: |_| Ok(vec![super::validation::jimenez_refit()]),
        measure: |_, p, r| Ok({
            let (p, r) = (p[0], r[0]);
            vec![so_row("Jimenez et al. 2016 cone–cone", |rr, mu, v| jimenez_with(p, mu, v, rr), |rr, mu, v| jimenez_with(r, mu, v, rr))]
        }),
        check: None,
    },
    PublishedForm {
        name: MULTIBOUNCE_NAME,
        function: "multibounce",
        doc: "Jimenez et al. 2016's multi-bounce AO cubic refitted minimax to COD: WWII's interreflection model A/(1 − ρ + ρA).",
        args: &["visibility", "albedo"],
        domain: &[UNIT, UNIT],
        program: Some(|| &*MULTIBOUNCE_FORM),
        published: || JIMENEZ_MULTIBOUNCE.to_vec(),
        reads: &[],
        refit: |_| Ok(super::validation::multibounce_refit().to_vec()),
        measure: |_, p, r| Ok({
            let (pm, pr, _) = multibounce_errors(p);
            let (rm, rr, _) = multibounce_errors(r);
            vec![FormError {
                form: "Jimenez et al. 2016 multi-bounce".into(),
                grid: "V × ρ on [0, 1]² (65 × 65 uniform points), against A/(1 − ρ + ρA)".into(),
                points: 65 * 65,
                published: crate::fit::published::Errors { max_abs_error: pm, rms_error: pr },
                refit: crate::fit::published::Errors { max_abs_error: rm, rms_error: rr },
            }]
        }),
        check: None,
    },
];

/// A specular-occlusion form's row on the validation grid (F0 = 4 %).
fn so_row(form: &str, published: impl Fn(f64, f64, f64) -> f64 + Sync, refit: impl Fn(f64, f64, f64) -> f64 + Sync) -> FormError {
    let (points, published) = so_errors(published);
    let (_, refit) = so_errors(refit);
    FormError {
        form: form.into(),
        grid: "perceptual roughness r ∈ [0.05, 1] (20) × n·v at 32 texel centres × V ∈ [1/32, 1] (32), F0 = 4 %, against the cone model".into(),
        points,
        published,
        refit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The programs are the forms as their sources write them: in f64, Lagarde's equals
    /// saturate((n·v + V)^(2^(aα + b)) − 1 + V) with `powf` (against exp2·log2: a few ulps of
    /// values ≤ 2, 1e-14) and the multi-bounce cubic Jimenez et al.'s Eq. 10 written out (the
    /// same operations: exactly), on an 11³ / 11² grid, with the published and the committed
    /// constants.
    #[test]
    fn the_programs_are_the_forms() {
        let lagarde_with = |[a, b]: [f64; 2], mu: f64, v: f64, alpha: f64| ((mu + v).powf((a * alpha + b).exp2()) - 1.0 + v).clamp(0.0, 1.0);
        let jimenez_multibounce = |p: &[f64], v: f64, albedo: f64| {
            let (a, b, c) = (p[0] * albedo + p[1], p[2] * albedo + p[3], p[4] * albedo + p[5]);
            v.max(((a * v + b) * v + c) * v)
        };
        let r = repository();
        for c in [LAGARDE, r.lagarde] {
            for i in 0..=10 {
                for j in 0..=10 {
                    for l in 0..=10 {
                        let (mu, v, a) = (i as f64 / 10.0, j as f64 / 10.0, l as f64 / 10.0);
                        let got = LAGARDE_FORM.eval_f64(&[mu, v, a], &c)[0];
                        assert!((got - lagarde_with(c, mu, v, a)).abs() < 1e-14, "({mu}, {v}, {a}): {got}");
                    }
                }
            }
        }
        for c in [JIMENEZ_MULTIBOUNCE, r.multibounce] {
            for i in 0..=10 {
                for j in 0..=10 {
                    let (v, rho) = (i as f64 / 10.0, j as f64 / 10.0);
                    assert_eq!(MULTIBOUNCE_FORM.eval_f64(&[v, rho], &c)[0], jimenez_multibounce(&c, v, rho));
                }
            }
        }
    }

    /// The emitted Rust of the refits is their programs' f32 evaluation bit for bit (inputs
    /// clamped to [0, 1], NaN → 0), finite for every special input.
    #[test]
    fn emitted_rust_is_the_programs_f32_evaluation() {
        use shadefit_runtime::ggx_occlusion_refits as g;
        let r = repository();
        let c32 = |c: &[f64]| c.iter().map(|&v| v as f32).collect::<Vec<f32>>();
        let clamp = |v: f32| crate::fit::expr::sanitize(v, 0.0, 1.0);
        let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, 1e-45, 0.25, 0.5, 1.0, 2.0];
        for &x in &special {
            for &y in &special {
                for &z in &special {
                    let want = LAGARDE_FORM.eval_f32(&[clamp(x), clamp(y), clamp(z)], &c32(&r.lagarde))[0];
                    let got = g::ggx_so_refit_lagarde(x, y, z);
                    assert_eq!(got.to_bits(), want.to_bits(), "({x}, {y}, {z})");
                    assert!(got.is_finite());
                }
                let want = MULTIBOUNCE_FORM.eval_f32(&[clamp(x), clamp(y)], &c32(&r.multibounce))[0];
                let got = g::ggx_so_refit_multibounce(x, y);
                assert_eq!(got.to_bits(), want.to_bits(), "({x}, {y})");
                assert!(got.is_finite());
            }
        }
    }
}
