//! The COD: WWII multiscattering-diffuse rational refitted as a registered published form
//! ([`FORMS`]): `fits/ms_diffuse_refits.toml` (`kind = "refit"`) refits it least squares to the
//! gloss-0 slice of the committed F0 = 0.04 simulation (`ms_diffuse_slices`, which it reads) and
//! commits its constants; the validation item reads them from its JSON ([`committed`]).

use super::published::{RATIONAL_DEN, RATIONAL_NUM, Slices, gloss_zero, rational, rational_model, refit};
use crate::fit::expr::Expr;
use crate::fit::expr::program::{Program, build::*};
use crate::fit::positivity::{Positivity, prove_denominator_positive};
use crate::fit::published::{Errors, FormError, PublishedForm};
use crate::pipeline::BuildError;
use nalgebra::DVector;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::LazyLock;

/// The refit spec (`fits/SPEC.toml`) and the slices it reads.
pub const SPEC: &str = "ms_diffuse_refits";
pub const SLICES: &str = "ms_diffuse_slices";
pub const RATIONAL_NAME: &str = "ms-diffuse-rational";

/// The committed refit in `generated`: numerator and denominator (constant 1 first).
pub fn committed(generated: &Path) -> Result<([f64; 8], [f64; 8]), BuildError> {
    Ok(halves(&crate::family::committed_refits(generated, SPEC)?.constants(RATIONAL_NAME)?))
}

/// The monomials of [`super::published::TERMS`] over (x, y) = (n·h, l·h): 1, x, y, x², y², xy, x³, y³.
fn monomial(j: usize) -> Expr {
    let (x, y) = (|| var(0), || var(1));
    match j {
        0 => lit(1.0),
        1 => x(),
        2 => y(),
        3 => x() * x(),
        4 => y() * y(),
        5 => x() * y(),
        6 => x() * x() * x(),
        _ => y() * y() * y(),
    }
}

/// R(n·h, l·h) = Σ k_j m_j / Σ k_{8+j} m_j (the BRDF f at ρ = 1, 1/sr).
pub static RATIONAL_FORM: LazyLock<Program> = LazyLock::new(|| {
    let sum = |first: usize| (1..8).fold(k(first) * monomial(0), |acc, j| acc + k(first + j) * monomial(j));
    Program { lets: vec![("p".into(), sum(0)), ("q".into(), sum(8))], result: bind(0) / bind(1) }
});

/// The gloss-0 slice of the committed simulation in `generated`.
fn slice(generated: &Path) -> Result<(Vec<Vec<f64>>, Vec<f64>, Vec<[f64; 2]>), String> {
    let s = Slices::load(generated, SLICES).ok_or_else(|| format!("generated/json/{SLICES}.json is missing or unreadable"))?;
    Ok(gloss_zero(&s))
}

fn halves(c: &[f64]) -> ([f64; 8], [f64; 8]) {
    (std::array::from_fn(|j| c[j]), std::array::from_fn(|j| c[8 + j]))
}

/// Max and rms |π R − π f| on the slice.
fn errors(pts: &[Vec<f64>], truth: &[f64], xy: &[[f64; 2]], c: &[f64]) -> Errors {
    let (num, den) = halves(c);
    let approx: Vec<f64> = xy.iter().map(|p| PI * rational(&num, &den, p[0], p[1])).collect();
    let (max_abs_error, rms_error, _) = crate::validate::measure(pts, truth, &approx);
    Errors { max_abs_error, rms_error }
}

/// The form, as `fits/ms_diffuse_refits.toml` refits it (registered in the family's descriptor).
pub static FORMS: [PublishedForm; 1] = [PublishedForm {
    name: RATIONAL_NAME,
    function: "rational",
    doc: "COD: WWII's 15-coefficient rational R(n·h, l·h), the multiscattering diffuse BRDF at albedo 1 (1/sr), refitted least squares to the gloss-0 slice of the F0 = 0.04 simulation (n·h clamped to the fitted [sin(π/128), 1]).",
    args: &["n_dot_h", "l_dot_h"],
    domain: &[(N_DOT_H_MIN, 1.0), (0.0, 1.0)],
    program: Some(|| &*RATIONAL_FORM),
    published: || RATIONAL_NUM.iter().chain(&RATIONAL_DEN).copied().collect(),
    reads: &[SLICES],
    refit: |g| {
        let (_, truth, xy) = slice(g)?;
        let f: Vec<f64> = truth.iter().map(|v| v / PI).collect();
        let (num, den) = refit(&xy, &f).ok_or("the least-squares fit failed")?;
        Ok(num.iter().chain(&den).copied().collect())
    },
    measure: |g, p, r| {
        let (pts, truth, xy) = slice(g)?;
        Ok(vec![FormError {
            form: "COD: WWII 15-coefficient rational (π·R)".into(),
            grid: format!("the gloss-0 slice of {SLICES} ({} cells), against the simulated π f", pts.len()),
            points: pts.len(),
            published: errors(&pts, &truth, &xy, p),
            refit: errors(&pts, &truth, &xy, r),
        }])
    },
    check: Some(denominator_positive),
}];

/// n·h at the slices' last cell centre, cos((31.5/32)·π/2) = sin(π/128): the least n·h the refit
/// was fitted on. Its denominator is positive from there on but not to n·h = 0 (it changes sign
/// near (0, 0.64)), so the emitted code clamps n·h to [N_DOT_H_MIN, 1] (as MaterialX's refit is
/// clamped to the n·v it was fitted on).
pub const N_DOT_H_MIN: f64 = 0.024541228522912264;

/// The emitted quotient is finite on its clamp box only if its denominator is positive there.
fn denominator_positive(c: &[f64]) -> Result<Vec<(String, f64)>, String> {
    let model = rational_model().ok_or("the model does not build")?;
    if c[8] != 1.0 {
        return Err(format!("the denominator's constant is {} (the model's is 1)", c[8]));
    }
    let coefficients: Vec<f64> = c[..8].iter().chain(&c[9..]).copied().collect();
    match prove_denominator_positive(&model, &DVector::from_vec(coefficients), &[(N_DOT_H_MIN, 1.0), (0.0, 1.0)]) {
        Positivity::Proven { lower, .. } => Ok(vec![("denominator_lower_bound".into(), lower)]),
        Positivity::NotProven { lower, .. } => Err(format!("the denominator is not proven positive on [{N_DOT_H_MIN}, 1] × [0, 1] (interval bound {lower:e})")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The program is the form: its f64 evaluation is Σ num_j m_j / Σ den_j m_j over the
    /// monomials 1, x, y, x², y², xy, x³, y³ written out here (the same sums: 1e-12 relative on
    /// values ≤ 10) at the published and the committed constants on an 11 × 11 grid of [0, 1]²;
    /// and the emitted Rust is its f32 evaluation bit for bit at every
    /// input, NaN → the lower end, finite for the special values. The clamp's n·h is the least
    /// of the committed slices' cell centres.
    #[test]
    fn the_program_is_the_form_and_the_emitted_code_is_the_program() {
        use shadefit_runtime::ms_diffuse_refits as g;
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let (num, den) = committed(&generated).expect("the refit is committed");
        let (_, _, xy) = slice(&generated).unwrap();
        assert_eq!(xy.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min), N_DOT_H_MIN);
        let committed: Vec<f64> = num.iter().chain(&den).copied().collect();
        for c in [(FORMS[0].published)(), committed.clone()] {
            let (n, d) = halves(&c);
            let written = |x: f64, y: f64| {
                let m = [1.0, x, y, x * x, y * y, x * y, x * x * x, y * y * y];
                (0..8).map(|j| n[j] * m[j]).sum::<f64>() / (0..8).map(|j| d[j] * m[j]).sum::<f64>()
            };
            for i in 0..=10 {
                for j in 0..=10 {
                    let (x, y) = (i as f64 / 10.0, j as f64 / 10.0);
                    let (got, want) = (RATIONAL_FORM.eval_f64(&[x, y], &c)[0], written(x, y));
                    assert!((got - want).abs() <= 1e-12 * want.abs().max(1.0), "({x}, {y}): {got} vs {want}");
                }
            }
        }
        let c32: Vec<f32> = committed.iter().map(|&v| v as f32).collect();
        let clamp = |v: f32, lo: f64| crate::fit::expr::sanitize(v, lo as f32, 1.0);
        let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, 1e-45, 0.01, 0.25, 0.5, 0.75, 1.0, 2.0];
        for &x in &special {
            for &y in &special {
                let want = RATIONAL_FORM.eval_f32(&[clamp(x, N_DOT_H_MIN), clamp(y, 0.0)], &c32)[0];
                let got = g::ms_refit_rational(x, y);
                assert_eq!(got.to_bits(), want.to_bits(), "({x}, {y})");
                assert!(got.is_finite(), "({x}, {y})");
            }
        }
    }
}
