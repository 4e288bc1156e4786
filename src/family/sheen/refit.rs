//! The published sheen forms refitted: the same form with new constants, minimax against the
//! integral each approximates on the grid of [`super::grid`] (Nelder–Mead on the largest
//! |error|, `crate::fit::simplex`, from the published constants: deterministic). A form that
//! saturates its result is fitted to the saturated integral min(E, 1) (where E > 1 no
//! saturated form can do better than E − 1, so the published form is measured the same way).
//! Each is a registered [`PublishedForm`] ([`FORMS`]); `fits/sheen_published_refits.toml`
//! (`kind = "refit"`) runs the refits when built and commits the constants; `validate` reads
//! them from there.

use super::forms::*;
use super::grid::{self, Convention, Target, Visibility};
use crate::fit::expr::program::Program;
use crate::fit::expr::tape::Tape;
use crate::fit::published::{Errors, FormError, PublishedForm};
use crate::fit::model::{ModelParts, Term};
use crate::fit::positivity::{Positivity, prove_denominator_positive};
use crate::fit::simplex::nelder_mead;
use crate::fit::{Data, FitOptions, Objective, RationalModel};
use nalgebra::DVector;
use std::sync::LazyLock;

/// The refit spec that commits them (`fits/SPEC.toml`).
pub const SPEC: &str = "sheen_published_refits";

/// A published form on the measurement grid.
pub struct Form {
    /// The form as its source names it.
    pub label: &'static str,
    pub program: &'static LazyLock<Program>,
    pub published: &'static [f64],
    /// The program's inputs at grid point (r, n·v).
    pub inputs: fn(f64, f64) -> [f64; 2],
    /// What is measured of the program's result (G1 from a Λ; the value itself otherwise).
    pub measured: fn(f64) -> f64,
    /// The integral at every grid point, as measured.
    pub truth: fn() -> Vec<f64>,
    /// The integral's description.
    pub against: fn() -> String,
    /// How the refit is solved.
    pub solver: Solver,
}

/// The refit's solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Solver {
    /// Nelder–Mead on the largest |error| from the published constants.
    NelderMead,
    /// MaterialX's rational through `crate::fit` (linearised start, Lawson minimax, LP polish)
    /// with its clamp, kept only with a denominator proven positive on the clamp box.
    Rational,
}

fn roughness_first(r: f64, m: f64) -> [f64; 2] {
    [r, m]
}

fn n_dot_v_first(r: f64, m: f64) -> [f64; 2] {
    [m, r]
}

fn alpha_first(r: f64, m: f64) -> [f64; 2] {
    [r * r, m]
}

fn value(v: f64) -> f64 {
    v
}

fn g1(lambda: f64) -> f64 {
    1.0 / (1.0 + lambda)
}

const ASHIKHMIN_R2: Target = Target::new(Visibility::Ashikhmin, Convention::Squared);
const ASHIKHMIN_R: Target = Target::new(Visibility::Ashikhmin, Convention::Linear);
const EK_R2: Target = Target::new(Visibility::EstevezKulla, Convention::Squared);

fn saturated(t: Target) -> Vec<f64> {
    t.albedo().iter().map(|e| e.min(1.0)).collect()
}

impl Form {
    /// The measured value of the form with constants `c` at every grid point.
    pub fn values(&self, c: &[f64]) -> Vec<f64> {
        self.values_with(&self.tape(), c)
    }

    /// The program compiled (bit for bit its `eval_f64`; the refit's objective evaluates it at
    /// every grid point of every step).
    fn tape(&self) -> Tape {
        Tape::compile(self.program).expect("a published sheen form compiles")
    }

    fn values_with(&self, tape: &Tape, c: &[f64]) -> Vec<f64> {
        let (mut regs, mut out) = (Vec::new(), [0.0]);
        grid::points()
            .iter()
            .map(|p| {
                tape.eval(&(self.inputs)(p[0], p[1]), c, &mut regs, &mut out);
                (self.measured)(out[0])
            })
            .collect()
    }

    fn max_error(&self, tape: &Tape, c: &[f64], truth: &[f64]) -> f64 {
        self.values_with(tape, c).iter().zip(truth).fold(0.0f64, |m, (v, t)| {
            let e = (v - t).abs();
            if e.is_nan() { f64::INFINITY } else { m.max(e) }
        })
    }

    /// The minimax refit from the published constants.
    pub fn refit(&self) -> Vec<f64> {
        let truth = (self.truth)();
        match self.solver {
            Solver::NelderMead => {
                let tape = self.tape();
                nelder_mead(|c| self.max_error(&tape, c, &truth), self.published).0
            }
            Solver::Rational => materialx_rational(&truth).unwrap_or_else(|| self.published.to_vec()),
        }
    }

    pub fn errors(&self, c: &[f64]) -> Errors {
        let (max_abs_error, rms_error, _) = crate::validate::measure(grid::points(), &(self.truth)(), &self.values(c));
        Errors { max_abs_error, rms_error }
    }

    fn row(&self, published: &[f64], refit: &[f64]) -> FormError {
        FormError {
            form: self.label.into(),
            grid: format!("{}, against {}", grid::domain(Convention::Squared).replace(", α = r²", ""), (self.against)()),
            points: grid::NR * grid::NV,
            published: self.errors(published),
            refit: self.errors(refit),
        }
    }
}

pub static EK: Form = Form {
    label: "Estevez–Kulla Λ curve, as G1 = 1/(1 + Λ)",
    program: &EK_LAMBDA,
    published: &EK_PUBLISHED,
    inputs: alpha_first,
    measured: g1,
    truth: || grid::g1_exact().to_vec(),
    against: || "G1 of the exact Λ at α = r²".into(),
    solver: Solver::NelderMead,
};

pub static THREEJS_NEW: Form = Form {
    label: "three.js IBLSheenBRDF (r181+)",
    program: &THREEJS_2025,
    published: &THREEJS_2025_PUBLISHED,
    inputs: roughness_first,
    measured: value,
    truth: || saturated(ASHIKHMIN_R2),
    against: || format!("min(1, {})", ASHIKHMIN_R2.describe()),
    solver: Solver::NelderMead,
};

pub static THREEJS_OLD: Form = Form {
    label: "three.js IBLSheenBRDF (2021)",
    program: &THREEJS_2021,
    published: &THREEJS_2021_PUBLISHED,
    inputs: roughness_first,
    measured: value,
    truth: || saturated(ASHIKHMIN_R2),
    against: || format!("min(1, {})", ASHIKHMIN_R2.describe()),
    solver: Solver::NelderMead,
};

pub static MATERIALX_FORM: Form = Form {
    label: "MaterialX mx_imageworks_sheen_dir_albedo_analytic",
    program: &MATERIALX,
    published: &MATERIALX_PUBLISHED,
    inputs: n_dot_v_first,
    measured: value,
    truth: || saturated(ASHIKHMIN_R),
    against: || format!("min(1, {})", ASHIKHMIN_R.describe()),
    solver: Solver::Rational,
};

pub static BABYLON_FORM: Form = Form {
    label: "Babylon.js getBRDFLookupCharlieSheen (Narkowicz)",
    program: &BABYLON,
    published: &BABYLON_PUBLISHED,
    inputs: n_dot_v_first,
    measured: value,
    truth: || EK_R2.albedo().to_vec(),
    against: || EK_R2.describe(),
    solver: Solver::NelderMead,
};

pub static FILAMENT_CHARLIE_FORM: Form = Form {
    label: "Filament prefilteredDFG_Cloth_Charlie (first channel)",
    program: &FILAMENT_CHARLIE,
    published: &FILAMENT_CHARLIE_PUBLISHED,
    inputs: n_dot_v_first,
    measured: value,
    truth: || ASHIKHMIN_R2.albedo().to_vec(),
    against: || ASHIKHMIN_R2.describe(),
    solver: Solver::NelderMead,
};

const VELVET_R2: Target = Target::new(Visibility::Velvet, Convention::Squared);

pub static FILAMENT_ASHIKHMIN_FORM: Form = Form {
    label: "Filament prefilteredDFG_Cloth_Ashikhmin (first channel)",
    program: &FILAMENT_ASHIKHMIN,
    published: &FILAMENT_ASHIKHMIN_PUBLISHED,
    inputs: n_dot_v_first,
    measured: value,
    truth: || VELVET_R2.albedo().to_vec(),
    against: || VELVET_R2.describe(),
    solver: Solver::NelderMead,
};

/// Every refitted form with its registered name, in [`FORMS`] order.
pub static REFITTED: [(&str, &Form); 7] = [
    ("sheen-estevez-kulla-lambda", &EK),
    ("sheen-threejs", &THREEJS_NEW),
    ("sheen-threejs-2021", &THREEJS_OLD),
    ("sheen-materialx", &MATERIALX_FORM),
    ("sheen-babylon", &BABYLON_FORM),
    ("sheen-filament-cloth-charlie", &FILAMENT_CHARLIE_FORM),
    ("sheen-filament-cloth-ashikhmin", &FILAMENT_ASHIKHMIN_FORM),
];

/// The committed constants of form `name` in `generated`.
pub fn committed(generated: &std::path::Path, name: &str) -> Result<Vec<f64>, String> {
    crate::family::committed_refits(generated, SPEC).and_then(|r| r.constants(name)).map_err(|e| e.to_string())
}

/// Every constant of a form finite, and `positive` (indices) strictly positive: what keeps
/// each form finite on its clamp box (a denominator 1 + b x^c or k₁ + e^x, a power's exponent,
/// a Gaussian's width).
fn finite_with_positive(c: &[f64], positive: &[usize]) -> Result<Vec<(String, f64)>, String> {
    if let Some(v) = c.iter().find(|v| !v.is_finite()) {
        return Err(format!("a constant is {v}"));
    }
    match positive.iter().find(|&&i| c[i] <= 0.0) {
        Some(&i) => Err(format!("constant {i} is {} (the form is finite only where it is positive)", c[i])),
        None => Ok(vec![]),
    }
}

/// MaterialX's form as a rational model of (x, y) = (n·v, roughness): numerator over
/// 1, x, y, xy, x², y², denominator 1 + the other five, clamped to [0, 1] (the program's order).
fn materialx_model() -> RationalModel {
    let features = vec!["x".to_string(), "y".to_string()];
    let labels = ["1", "x", "y", "x*y", "x^2", "y^2"];
    let terms = |l: &[&str]| l.iter().map(|t| Term::parse(t, &features).expect("valid term")).collect::<Vec<_>>();
    RationalModel::new(ModelParts { inputs: features.clone(), numerator: terms(&labels), denominator: terms(&labels[1..]), clamp: Some((0.0, 1.0)), ..ModelParts::default() })
        .expect("the MaterialX form is a valid model")
}

const MATERIALX_BOX: [(f64, f64); 2] = [UNIT, R];

/// The minimax rational from the linearised start, else from the published constants: the first
/// whose denominator is proven positive on the clamp box.
fn materialx_rational(truth: &[f64]) -> Option<Vec<f64>> {
    let model = materialx_model();
    let data = Data { x: grid::points().iter().map(|p| vec![p[1], p[0]]).collect(), y: truth.to_vec() };
    let opts = FitOptions { objective: Objective::Minimax, ..FitOptions::default() };
    crate::fit::solve::fit_proven_positive(&model, &data, &MATERIALX_PUBLISHED, &opts, &MATERIALX_BOX, "materialx sheen refit").map(|c| c.as_slice().to_vec())
}

/// MaterialX's denominator proven positive on the clamp box (interval arithmetic).
fn materialx_denominator(c: &[f64]) -> Result<Vec<(String, f64)>, String> {
    finite_with_positive(c, &[])?;
    match prove_denominator_positive(&materialx_model(), &DVector::from_vec(c.to_vec()), &MATERIALX_BOX) {
        Positivity::Proven { lower, .. } => Ok(vec![("denominator_lower_bound".into(), lower)]),
        Positivity::NotProven { lower, .. } => Err(format!("the denominator is not proven positive on [0, 1] × [0.1, 1] (interval bound {lower:e})")),
    }
}

const UNIT: (f64, f64) = (0.0, 1.0);
const R: (f64, f64) = (grid::R_MIN, 1.0);
const A: (f64, f64) = (grid::R_MIN * grid::R_MIN, 1.0);

macro_rules! form {
    ($i:expr, $function:expr, $doc:expr, $args:expr, $domain:expr, $check:expr) => {
        PublishedForm {
            name: REFITTED[$i].0,
            function: $function,
            doc: $doc,
            args: $args,
            domain: $domain,
            program: Some(|| &**REFITTED[$i].1.program),
            published: || REFITTED[$i].1.published.to_vec(),
            reads: &[],
            refit: |_| Ok(REFITTED[$i].1.refit()),
            measure: |_, p, r| Ok(vec![REFITTED[$i].1.row(p, r)]),
            check: Some($check),
        }
    };
}

/// The published sheen forms, as `fits/sheen_published_refits.toml` refits them (registered in
/// the family's descriptor).
pub static FORMS: [PublishedForm; 7] = [
    form!(
        0,
        "lambda",
        "Estevez–Kulla's Λ(μ) curve refitted minimax in G1 = 1/(1 + Λ) to the exact Λ of the Charlie distribution (α clamped to [0.01, 1]).",
        &["alpha", "mu"],
        &[A, UNIT],
        |c| finite_with_positive(c, &[1, 2, 6, 7])
    ),
    form!(
        1,
        "threejs",
        "three.js's IBLSheenBRDF (r181+) refitted minimax to min(1, E) of its D_Charlie(r²)·V_Neubelt (r clamped to [0.1, 1]).",
        &["roughness", "n_dot_v"],
        &[R, UNIT],
        |c| {
            finite_with_positive(c, &[])?;
            // r_inv = 1/(r + k₈) is finite on the clamp box when k₈ > −0.1.
            if c[8] + grid::R_MIN > 0.0 { Ok(vec![("least_r_plus_offset".into(), c[8] + grid::R_MIN)]) } else { Err(format!("r + {} vanishes on [0.1, 1]", c[8])) }
        }
    ),
    form!(
        2,
        "threejs_legacy",
        "three.js's 2021 IBLSheenBRDF refitted minimax to min(1, E) of its D_Charlie(r²)·V_Neubelt (r clamped to [0.1, 1]).",
        &["roughness", "n_dot_v"],
        &[R, UNIT],
        |c| finite_with_positive(c, &[])
    ),
    form!(
        3,
        "materialx",
        "MaterialX's sheen directional albedo refitted minimax to min(1, E) of its Charlie D (α = roughness)·Ashikhmin V (roughness clamped to [0.1, 1]).",
        &["n_dot_v", "roughness"],
        &[UNIT, R],
        materialx_denominator
    ),
    form!(
        4,
        "babylon",
        "Babylon's (unused) Narkowicz sheen albedo fit refitted minimax to E under Estevez–Kulla's visibility at α = r² (r clamped to [0.1, 1]).",
        &["n_dot_v", "roughness"],
        &[UNIT, R],
        |c| finite_with_positive(c, &[1])
    ),
    form!(
        5,
        "filament_cloth_charlie",
        "Filament's (unused) prefilteredDFG_Cloth_Charlie, first channel, refitted minimax to E of Charlie D·Ashikhmin V at α = r² (r clamped to [0.1, 1]).",
        &["n_dot_v", "roughness"],
        &[UNIT, R],
        // (k₂ + 1 − n·v)⁶⁴: a power of a positive base only (WGSL's pow is undefined below 0).
        |c| finite_with_positive(c, &[2])
    ),
    form!(
        6,
        "filament_cloth_ashikhmin",
        "Filament's (unused) prefilteredDFG_Cloth_Ashikhmin, first channel, refitted minimax to E of Ashikhmin's velvet D·Neubelt's V at α = r² (r clamped to [0.1, 1]).",
        &["n_dot_v", "roughness"],
        &[UNIT, R],
        // 2^(−(s − k₁)²/(2 k₂)): a Gaussian of positive width.
        |c| finite_with_positive(c, &[2])
    ),
];

#[cfg(test)]
mod tests {
    use super::*;
    use shadefit_runtime::sheen_published_refits as g;
    use std::path::Path;

    /// The emitted Rust of every refitted form is its program's f32 evaluation bit for bit at
    /// the committed constants, on inputs clamped to its box as the emitted code clamps them
    /// (NaN → the lower end), and finite for every special value and across the box.
    #[test]
    fn the_emitted_refits_are_their_programs_and_finite() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        let functions: [fn(f32, f32) -> f32; 7] = [
            g::sheen_refit_lambda,
            g::sheen_refit_threejs,
            g::sheen_refit_threejs_legacy,
            g::sheen_refit_materialx,
            g::sheen_refit_babylon,
            g::sheen_refit_filament_cloth_charlie,
            g::sheen_refit_filament_cloth_ashikhmin,
        ];
        let special = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 0.0, 1e-45, 1e-3, 0.1, 0.25, 0.4999, 0.5, 0.75, 0.9999, 1.0, 2.0, f32::MAX];
        for ((name, form), f) in REFITTED.iter().zip(functions) {
            let c: Vec<f32> = committed(&generated, name).expect("the refit is committed").iter().map(|&v| v as f32).collect();
            let form_name: &str = &name;
            let spec = FORMS.iter().find(|p| p.name == form_name).expect("registered");
            let clamp = |v: f32, (lo, hi): (f64, f64)| crate::fit::expr::sanitize(v, lo as f32, hi as f32);
            for &x in &special {
                for &y in &special {
                    let want = form.program.eval_f32(&[clamp(x, spec.domain[0]), clamp(y, spec.domain[1])], &c)[0];
                    let got = f(x, y);
                    assert_eq!(got.to_bits(), want.to_bits(), "{name} ({x}, {y})");
                    assert!(got.is_finite(), "{name} ({x}, {y}): {got}");
                }
            }
            for i in 0..=64 {
                for j in 0..=64 {
                    let v = f(i as f32 / 64.0, j as f32 / 64.0);
                    assert!(v.is_finite(), "{name} at ({i}/64, {j}/64): {v}");
                }
            }
        }
    }

    /// Each committed refit beats its published form by the margin on the grid it was
    /// fitted on (max error ≤ 0.8× the published), measured here through the form.
    #[test]
    fn every_refit_beats_its_published_form() {
        let generated = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
        for (name, form) in &REFITTED {
            let c = crate::fit::published::as_emitted(&committed(&generated, name).unwrap());
            let (p, r) = (form.errors(form.published), form.errors(&c));
            assert!(r.max_abs_error <= 0.8 * p.max_abs_error, "{name}: refit {} vs published {}", r.max_abs_error, p.max_abs_error);
        }
    }
}
