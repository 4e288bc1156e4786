//! Refits of the published forms: the same functional structure with new constants, fitted
//! minimax to the integral the form approximates (its stated G and roughness mapping), on the
//! grids of [`super::grid`].
//!
//! - Karis and Lazarov (min/exp2 forms, not rational): Nelder–Mead (`crate::fit::simplex`) on the largest
//!   |error| over both channels, started from the published constants, restarted from the best
//!   vertex with a shrinking simplex (the objective is a max of kinked functions: a single run
//!   stalls on a ridge).
//! - MaterialX (a rational pair): the rational machinery of `crate::fit` (linearised start,
//!   Lawson minimax, sequential-LP polish, denominator proven positive), each channel on its own.
//! - Kulla–Conty's F_avg: Nelder–Mead on the max error of each branch.
//!
//! Everything is deterministic (no random starts, sequential solvers). Each is a registered
//! [`PublishedForm`] ([`FORMS`]): `fits/ggx_published_refits.toml` (`kind = "refit"`) runs the
//! refits when built and commits the constants in generated/json/ggx_published_refits.json;
//! validate, figures and benchmarks read them from there ([`Refits::committed`]).

use super::forms::{KARIS, KARIS_FORM, KARIS_TAPE, LAZAROV_TAPE, KULLA_CONTY, KULLA_CONTY_FORM, Karis, KullaConty, LAZAROV, LAZAROV_FORM, Lazarov, MATERIALX, MATERIALX_FORM, MaterialX};
use crate::fit::published::{Errors, FormError, PublishedForm, as_emitted};
use crate::pipeline::BuildError;
use std::path::Path;
use super::grid::{self, Grid, Target};
use crate::fit::model::{ModelParts, Term};
use crate::fit::positivity::{Positivity, prove_denominator_positive};
use crate::fit::{Data, FitOptions, Objective, RationalModel};
use crate::fit::simplex::nelder_mead;
use nalgebra::DVector;

/// Karis's form refitted to the grid of `target` (perceptual roughness on its second axis).
pub fn karis(target: Target, start: &Karis) -> Karis {
    let g = grid::standard(target);
    // `p` is the form's constants in `params()` order.
    let (p, _) = nelder_mead(|p| g.max_error(|m, r| KARIS_TAPE.pair([r, m], p)), &start.params());
    Karis::from_params(&p)
}

/// Lazarov's form refitted to the gloss grid.
pub fn lazarov(start: &Lazarov) -> Lazarov {
    let g = grid::standard(Target::Gloss);
    let (p, _) = nelder_mead(|p| g.max_error(|m, gl| LAZAROV_TAPE.pair([gl, m], p)), &start.params());
    Lazarov::from_params(&p)
}

/// MaterialX's rational pair refitted minimax (each channel, with a denominator proven
/// positive on the grid's box: see [`materialx_on`]), clamp to [0, 1] as the source, on every
/// other point of the standard α grid in each direction (32 × 33: the LP polish of the full
/// 64 × 65 takes minutes; the refit is measured on the full grid).
pub fn materialx() -> MaterialX {
    materialx_on(&every_other(grid::standard(Target::Alpha)))
}

/// The grid of every other node of `full` in each direction (the first, third, … of each axis),
/// with the values there.
pub fn every_other(full: &Grid) -> Grid {
    Grid {
        target: full.target,
        mu: full.mu.iter().step_by(2).copied().collect(),
        y: full.y.iter().step_by(2).copied().collect(),
        values: full
            .values
            .iter()
            .enumerate()
            .filter(|(k, _)| (k % full.mu.len()).is_multiple_of(2) && (k / full.mu.len()).is_multiple_of(2))
            .map(|(_, v)| *v)
            .collect(),
    }
}

/// MaterialX's pair refitted minimax on the grid `g` (n·v, α), each channel on its own (see the
/// body for the fallbacks).
pub fn materialx_on(g: &Grid) -> MaterialX {
    let model = materialx_model();
    let x: Vec<Vec<f64>> = g.points().map(|(m, a)| vec![m, a]).collect();
    let mut r = [[0.0; 4]; 9];
    for ch in 0..2 {
        let y: Vec<f64> = g.values.iter().map(|v| v[ch]).collect();
        let data = Data { x: x.clone(), y };
        let domain = data.bounds();
        // Minimax from the linearised starts, else minimax from the published constants: the
        // first optimum whose denominator is proven positive on the grid's box (the bias's
        // optimum from the linearised starts has a pole inside it: Q changes sign between
        // α = 0 and 1), else the published constants of that channel.
        let published: Vec<f64> = (0..9).map(|k| MATERIALX.r[k][ch]).chain((1..9).map(|k| MATERIALX.r[k][ch + 2])).collect();
        let opts = FitOptions { objective: Objective::Minimax, ..FitOptions::default() };
        let c = crate::fit::solve::fit_proven_positive(&model, &data, &published, &opts, &domain, "materialx refit")
            .unwrap_or_else(|| DVector::from_vec(published));
        let c = &c;
        for k in 0..9 {
            r[k][ch] = c[k];
            r[k][ch + 2] = if k == 0 { 1.0 } else { c[8 + k] };
        }
    }
    MaterialX { r }
}

/// MaterialX's form as a rational model of features (x, y) = (n·v, α): the nine monomials of
/// [`super::forms::materialx_monomials`] over the same eight and the constant 1, clamped to
/// [0, 1]; coefficients are numerator then denominator.
pub fn materialx_model() -> RationalModel {
    let features = vec!["x".to_string(), "y".to_string()];
    let labels = ["1", "x", "y", "x*y", "x^2", "y^2", "x^2*y", "x*y^2", "x^2*y^2"];
    let terms = |l: &[&str]| l.iter().map(|t| Term::parse(t, &features).expect("valid term")).collect::<Vec<_>>();
    RationalModel::new(ModelParts {
        inputs: features.clone(),
        numerator: terms(&labels),
        denominator: terms(&labels[1..]),
        clamp: Some((0.0, 1.0)),
        ..ModelParts::default()
    })
    .expect("the MaterialX form is a valid model")
}

/// Kulla–Conty's two branches refitted minimax on their η ranges.
pub fn kulla_conty(start: &KullaConty) -> KullaConty {
    let (ea, fa) = grid::fresnel(true);
    let (eb, fb) = grid::fresnel(false);
    let max = |e: &[f64], f: &[f64], form: &dyn Fn(f64) -> f64| e.iter().zip(f).fold(0.0f64, |m, (&x, &t)| m.max((form(x) - t).abs()));
    let (above, _) = nelder_mead(|p| max(ea, fa, &|x| (x - 1.0) / (p[0] + p[1] * x)), &start.above);
    let (below, _) = nelder_mead(|p| max(eb, fb, &|x| p[0] + x * (p[1] + x * (p[2] + x * p[3]))), &start.below);
    KullaConty { above: [above[0], above[1]], below: [below[0], below[1], below[2], below[3]] }
}

/// Every refit, as the refit spec commits them.
#[derive(Debug, Clone, PartialEq)]
pub struct Refits {
    pub karis_ue4: Karis,
    pub karis_hc: Karis,
    pub lazarov: Lazarov,
    pub materialx: MaterialX,
    pub kulla_conty: KullaConty,
}

/// The refit spec that commits them (`fits/SPEC.toml`, `kind = "refit"`).
pub const SPEC: &str = "ggx_published_refits";

/// The registered names of the forms, as [`FORMS`] and the spec list them.
pub const KARIS_HC: &str = "ggx-karis";
pub const KARIS_UE4: &str = "ggx-karis-separable";
pub const LAZAROV_NAME: &str = "ggx-lazarov";
pub const MATERIALX_NAME: &str = "ggx-materialx";
pub const KULLA_CONTY_NAME: &str = "ggx-fresnel-avg-dielectric";

impl Refits {
    /// The committed refits of `generated` (generated/json/ggx_published_refits.json, checked
    /// against its spec).
    pub fn committed(generated: &Path) -> Result<Refits, BuildError> {
        let refits = crate::family::committed_refits(generated, SPEC)?;
        let c = |form: &str| refits.constants(form);
        Ok(Refits {
            karis_ue4: Karis::from_params(&c(KARIS_UE4)?),
            karis_hc: Karis::from_params(&c(KARIS_HC)?),
            lazarov: Lazarov::from_params(&c(LAZAROV_NAME)?),
            materialx: MaterialX::from_params(&c(MATERIALX_NAME)?),
            kulla_conty: KullaConty::from_params(&c(KULLA_CONTY_NAME)?),
        })
    }

    /// Every constant rounded to f32, as the emitted code carries them.
    pub fn emitted(&self) -> Refits {
        Refits {
            karis_ue4: Karis::from_params(&as_emitted(&self.karis_ue4.params())),
            karis_hc: Karis::from_params(&as_emitted(&self.karis_hc.params())),
            lazarov: Lazarov::from_params(&as_emitted(&self.lazarov.params())),
            materialx: MaterialX::from_params(&as_emitted(&self.materialx.params())),
            kulla_conty: KullaConty::from_params(&as_emitted(&self.kulla_conty.params())),
        }
    }
}

/// The committed refits of the repository's own generated/ (tests, and the family's emitted
/// module tests).
#[cfg(test)]
pub fn repository() -> Refits {
    Refits::committed(&Path::new(env!("CARGO_MANIFEST_DIR")).join("generated")).expect("the refits are committed")
}

/// Max and rms |error| of a pair form over both channels of its grid (validate's measure).
fn pair_errors(g: &Grid, form: impl Fn(f64, f64) -> [f64; 2]) -> Errors {
    let p = super::pair(g, form);
    let (max_abs_error, rms_error, _) = crate::validate::measure(&p.points, &p.truth, &p.approx);
    Errors { max_abs_error, rms_error }
}

/// A pair form's row on the standard grid of `target`.
fn pair_row(form: &str, target: Target, published: impl Fn(f64, f64) -> [f64; 2], refit: impl Fn(f64, f64) -> [f64; 2]) -> FormError {
    let g = grid::standard(target);
    FormError {
        form: form.into(),
        grid: format!("n·v at 64 texel centres × {} ∈ [0, 1] (65), against {}", target.axis_name(), target.integral()),
        published: pair_errors(g, published),
        refit: pair_errors(g, refit),
        points: 2 * g.values.len(),
    }
}

/// Kulla–Conty's rows: each branch on its own η grid.
fn kulla_conty_rows(published: &KullaConty, refit: &KullaConty) -> Vec<FormError> {
    let errors = |above: bool, k: &KullaConty| {
        let (eta, f) = grid::fresnel(above);
        let points: Vec<Vec<f64>> = eta.iter().map(|&x| vec![x]).collect();
        let approx: Vec<f64> = eta.iter().map(|&x| k.eval(x)).collect();
        let (max_abs_error, rms_error, _) = crate::validate::measure(&points, f, &approx);
        Errors { max_abs_error, rms_error }
    };
    [true, false]
        .into_iter()
        .map(|above| {
            let n = grid::fresnel(above).0.len();
            FormError {
                form: if above { "Kulla–Conty F_avg, η ≥ 1 branch" } else { "Kulla–Conty F_avg, η < 1 branch" }.into(),
                grid: format!("{n} values of η in {}, against the exact dielectric Fresnel average", if above { "[1, 3]" } else { "[1/3, 1)" }),
                published: errors(above, published),
                refit: errors(above, refit),
                points: n,
            }
        })
        .collect()
}

/// The MaterialX refit's denominators (r.z, r.w) proven positive on the clamped domain: the
/// least of the two proven lower bounds. The model's denominators have the constant term 1, as
/// the refit's (and the published form's) do; a form with another constant is refused.
pub fn materialx_denominators_positive(m: &MaterialX) -> Result<f64, String> {
    let model = materialx_model();
    let domain = [MATERIALX_N_DOT_V, (0.0, 1.0)];
    let mut lowest = f64::INFINITY;
    for ch in 2..4 {
        if m.r[0][ch] != 1.0 {
            return Err(format!("channel {ch}: constant term {} (the proof's model has 1)", m.r[0][ch]));
        }
        // The model's coefficients: 9 numerator terms (unused here: r.x), then the 8
        // denominator terms after the constant r[0] = 1.
        let c: Vec<f64> = (0..9).map(|k| m.r[k][ch - 2]).chain((1..9).map(|k| m.r[k][ch])).collect();
        match prove_denominator_positive(&model, &DVector::from_vec(c), &domain) {
            Positivity::Proven { lower, .. } => lowest = lowest.min(lower),
            Positivity::NotProven { lower, .. } => return Err(format!("channel {ch}: interval bound {lower:e}")),
        }
    }
    Ok(lowest)
}

/// n·v range of the MaterialX refit's fitting grid (every other texel centre of 64).
pub const MATERIALX_N_DOT_V: (f64, f64) = (1.0 / 128.0, 125.0 / 128.0);
/// The MaterialX refit as the emitted code evaluates it: n·v clamped to [`MATERIALX_N_DOT_V`].
pub fn materialx_refit(m: &MaterialX, n_dot_v: f64, alpha: f64) -> [f64; 2] {
    m.eval(n_dot_v.clamp(MATERIALX_N_DOT_V.0, MATERIALX_N_DOT_V.1), alpha)
}

/// η range of the Fresnel-average grids (both branches).
pub const ETA: (f64, f64) = (1.0 / 3.0, 3.0);

const UNIT: (f64, f64) = (0.0, 1.0);

/// The split-sum pair's doc ending.
macro_rules! pair_doc {
    ($what:literal) => {
        concat!($what, ": (scale, bias) of the split sum: specular = F0·scale + bias.")
    };
}

/// The published forms of the split sum and of the dielectric Fresnel average, as
/// `fits/ggx_published_refits.toml` refits them (registered in the family's descriptor).
pub static FORMS: [PublishedForm; 5] = FORMS_DEF;

/// [`FORMS`] as a value (the family's descriptor lists every form of the family in one slice).
pub const FORMS_DEF: [PublishedForm; 5] = [
    PublishedForm {
        name: KARIS_HC,
        function: "karis",
        doc: pair_doc!("Karis's EnvBRDFApprox refitted to the height-correlated integral, roughness r (α = r²)"),
        args: &["roughness", "n_dot_v"],
        domain: &[UNIT, UNIT],
        program: Some(|| &*KARIS_FORM),
        published: || KARIS.params(),
        reads: &[],
        refit: |_| Ok(karis(Target::Roughness, &KARIS).params()),
        measure: |_, p, r| Ok({
            let (p, r) = (Karis::from_params(p), Karis::from_params(r));
            vec![pair_row("Karis 2014 EnvBRDFApprox", Target::Roughness, |m, x| p.eval(x, m), |m, x| r.eval(x, m))]
        }),
        check: None,
    },
    PublishedForm {
        name: KARIS_UE4,
        function: "karis_separable",
        doc: pair_doc!("Karis's EnvBRDFApprox refitted to UE4's separable Schlick–Smith G (k = α/2)"),
        args: &["roughness", "n_dot_v"],
        domain: &[UNIT, UNIT],
        program: Some(|| &*KARIS_FORM),
        published: || KARIS.params(),
        reads: &[],
        refit: |_| Ok(karis(Target::RoughnessUe4, &KARIS).params()),
        measure: |_, p, r| Ok({
            let (p, r) = (Karis::from_params(p), Karis::from_params(r));
            vec![pair_row("Karis 2014 EnvBRDFApprox", Target::RoughnessUe4, |m, x| p.eval(x, m), |m, x| r.eval(x, m))]
        }),
        check: None,
    },
    PublishedForm {
        name: LAZAROV_NAME,
        function: "lazarov",
        doc: pair_doc!("Lazarov's Black Ops II form refitted (gloss g: α = sqrt(2/(8192^g + 2)))"),
        args: &["gloss", "n_dot_v"],
        domain: &[UNIT, UNIT],
        program: Some(|| &*LAZAROV_FORM),
        published: || LAZAROV.params(),
        reads: &[],
        refit: |_| Ok(lazarov(&LAZAROV).params()),
        measure: |_, p, r| Ok({
            let (p, r) = (Lazarov::from_params(p), Lazarov::from_params(r));
            vec![pair_row("Lazarov 2013 (Black Ops II)", Target::Gloss, |m, g| p.eval(g, m), |m, g| r.eval(g, m))]
        }),
        check: None,
    },
    PublishedForm {
        name: MATERIALX_NAME,
        function: "materialx",
        doc: pair_doc!("MaterialX's rational pair refitted (n·v clamped to its fitted [1/128, 125/128])"),
        args: &["n_dot_v", "alpha"],
        domain: &[MATERIALX_N_DOT_V, UNIT],
        program: Some(|| &*MATERIALX_FORM),
        published: || MATERIALX.params(),
        reads: &[],
        refit: |_| Ok(materialx().params()),
        measure: |_, p, r| Ok({
            let (p, r) = (MaterialX::from_params(p), MaterialX::from_params(r));
            vec![pair_row("MaterialX mx_ggx_dir_albedo_analytic", Target::Alpha, |m, a| p.eval(m, a), |m, a| materialx_refit(&r, m, a))]
        }),
        check: Some(|c| materialx_denominators_positive(&MaterialX::from_params(c)).map(|lower| vec![("denominator_lower_bound".to_string(), lower)])),
    },
    PublishedForm {
        name: KULLA_CONTY_NAME,
        function: "fresnel_avg_dielectric",
        doc: "Kulla–Conty's dielectric Fresnel average F_avg(η) refitted (η clamped to [1/3, 3]).",
        args: &["eta"],
        domain: &[ETA],
        program: Some(|| &*KULLA_CONTY_FORM),
        published: || KULLA_CONTY.params(),
        reads: &[],
        refit: |_| Ok(kulla_conty(&KULLA_CONTY).params()),
        measure: |_, p, r| Ok(kulla_conty_rows(&KullaConty::from_params(p), &KullaConty::from_params(r))),
        check: None,
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Flipping the sign of any one committed refit constant never lowers that form's max error
    /// on its grid (the refits are minimax: a constant on the wrong side of zero would be a
    /// better start), and raises it for most constants: a lost minus sign in a pasted constant
    /// shows wherever the objective can see it. It leaves the max error unchanged only where
    /// the worst point is out of the constant's reach (Karis's c0 multiplies r, and a worst
    /// point at r = 0 does not move with it). Karis (UE4's G and height-correlated), Lazarov and
    /// Kulla–Conty's branches, every constant; each form's max error through its own `eval`
    /// against the grid's integrals.
    #[test]
    fn a_sign_slip_in_any_committed_constant_raises_its_max_error() {
        let c = &repository();
        let karis = |target: Target, k: &Karis| -> (Vec<f64>, Box<dyn Fn(&[f64]) -> f64>) {
            let g = grid::standard(target);
            (k.params(), Box::new(move |p: &[f64]| g.max_error(|m, r| Karis::from_params(p).eval(r, m))))
        };
        let kc = |above: bool| -> Box<dyn Fn(&[f64]) -> f64> {
            Box::new(move |p: &[f64]| {
                let k = if above { KullaConty { above: [p[0], p[1]], below: c.kulla_conty.below } } else { KullaConty { above: c.kulla_conty.above, below: [p[0], p[1], p[2], p[3]] } };
                let (e, f) = grid::fresnel(above);
                e.iter().zip(f).map(|(&x, &t)| (k.eval(x) - t).abs()).fold(0.0f64, f64::max)
            })
        };
        let g = grid::standard(Target::Gloss);
        let cases: Vec<(&str, Vec<f64>, Box<dyn Fn(&[f64]) -> f64>)> = vec![
            ("karis_ue4", karis(Target::RoughnessUe4, &c.karis_ue4).0, karis(Target::RoughnessUe4, &c.karis_ue4).1),
            ("karis_hc", karis(Target::Roughness, &c.karis_hc).0, karis(Target::Roughness, &c.karis_hc).1),
            ("lazarov", c.lazarov.params(), Box::new(move |p: &[f64]| g.max_error(|m, gl| Lazarov::from_params(p).eval(gl, m)))),
            ("kulla_conty above", c.kulla_conty.above.to_vec(), kc(true)),
            ("kulla_conty below", c.kulla_conty.below.to_vec(), kc(false)),
        ];
        for (name, p, max) in &cases {
            let at = max(p);
            let mut raised = 0;
            for i in 0..p.len() {
                let mut q = p.clone();
                q[i] = -q[i];
                let flipped = max(&q);
                assert!(flipped >= at, "{name} constant {i} ({}): flipped {flipped:e}, committed {at:e}", p[i]);
                raised += usize::from(flipped > at);
            }
            assert!(2 * raised > p.len(), "{name}: {raised} of {} flips raise the max error", p.len());
        }
    }

    /// The model the MaterialX refit solves is MaterialX's form: with the published constants
    /// of a channel (numerator row entries, then the denominator's but its constant 1) it gives
    /// `MaterialX::eval`'s value of that channel, and it is clamped to [0, 1] as the source's
    /// `clamp`: a numerator of constant 2 reads 1, of constant −1 reads 0. 1e-12: the same
    /// sums in another order, on values of the constants' size (≤ 60).
    #[test]
    fn the_materialx_model_is_the_forms_rational_clamped_to_the_unit_interval() {
        let model = materialx_model();
        for ch in 0..2 {
            let c = DVector::from_vec((0..9).map(|k| MATERIALX.r[k][ch]).chain((1..9).map(|k| MATERIALX.r[k][ch + 2])).collect());
            for (m, a) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.7), (0.3, 0.95)] {
                let (got, want) = (model.eval_clamped(&c, &[m, a]), MATERIALX.eval(m, a)[ch]);
                assert!((got - want).abs() < 1e-12, "channel {ch} at ({m}, {a}): {got} vs {want}");
            }
        }
        let constant = |v: f64| DVector::from_vec((0..17).map(|k| if k == 0 { v } else { 0.0 }).collect());
        assert_eq!((model.eval_clamped(&constant(2.0), &[0.5, 0.5]), model.eval_clamped(&constant(-1.0), &[0.5, 0.5])), (1.0, 0.0));
    }

    /// Kulla–Conty's refit from the published constants: each branch's max error on its η
    /// grid, measured through the form (`KullaConty::eval`: (η − 1)/(a₀ + a₁η) for η ≥ 1,
    /// b₀ + b₁η + b₂η² + b₃η³ below), not through the solver's objective, is below the
    /// published constants' (the start): a minimax refit that moved away from its start made
    /// it better, not worse.
    #[test]
    fn the_kulla_conty_refit_lowers_each_branchs_max_error() {
        use super::super::forms::KULLA_CONTY;
        let r = kulla_conty(&KULLA_CONTY);
        let max = |above: bool, k: &KullaConty| {
            let (e, f) = grid::fresnel(above);
            e.iter().zip(f).map(|(&x, &t)| (k.eval(x) - t).abs()).fold(0.0f64, f64::max)
        };
        let (start_a, refit_a) = (max(true, &KULLA_CONTY), max(true, &r));
        let (start_b, refit_b) = (max(false, &KULLA_CONTY), max(false, &r));
        eprintln!("η ≥ 1: {start_a:e} → {refit_a:e}; η < 1: {start_b:e} → {refit_b:e}");
        assert!(refit_a < start_a && refit_b < start_b);
    }

    /// A grid n·v × y with the values `f(n·v, y)` at its points (n·v fastest), of target α.
    fn grid_of(mu: &[f64], y: &[f64], f: impl Fn(f64, f64) -> [f64; 2]) -> Grid {
        let values = y.iter().flat_map(|&y| mu.iter().map(move |&m| (m, y))).map(|(m, y)| f(m, y)).collect();
        Grid { target: Target::Alpha, mu: mu.to_vec(), y: y.to_vec(), values }
    }

    /// Every other node of a 5 × 4 grid whose values are functions of the coordinates: the
    /// axes keep their first, third, … entries, and each kept value is the function at its
    /// own point (a row/column mix-up or an odd-numbered node shows as a wrong value).
    #[test]
    fn every_other_keeps_the_odd_numbered_nodes_with_their_values() {
        let f = |m: f64, y: f64| [m + 10.0 * y, m * y];
        let full = grid_of(&[0.1, 0.2, 0.3, 0.4, 0.5], &[0.0, 0.25, 0.5, 0.75], f);
        let half = every_other(&full);
        assert_eq!(half.mu, [0.1, 0.3, 0.5]);
        assert_eq!(half.y, [0.0, 0.5]);
        assert_eq!(half.target, Target::Alpha);
        assert_eq!(half.values.len(), 6);
        for ((m, y), v) in half.points().zip(&half.values) {
            assert_eq!(*v, f(m, y), "at ({m}, {y})");
        }
    }

    /// Two rationals of MaterialX's form (numerator over the nine monomials, denominator 1 +
    /// the other eight, positive on the box), with values in (0.05, 0.9) there: this channel's
    /// scale and bias.
    const SCALE_NUM: [f64; 9] = [0.1, 0.6, 0.2, -0.1, 0.05, 0.02, 0.03, -0.02, 0.01];
    const SCALE_DEN: [f64; 8] = [0.5, 0.3, 0.1, 0.05, 0.02, -0.03, 0.04, 0.01];
    const BIAS_NUM: [f64; 9] = [0.3, -0.2, 0.1, 0.05, 0.04, -0.02, 0.01, 0.02, -0.01];
    const BIAS_DEN: [f64; 8] = [0.2, 0.4, -0.1, 0.03, 0.05, 0.02, -0.02, 0.01];

    fn rational(num: &[f64; 9], den: &[f64; 8], x: f64, y: f64) -> f64 {
        let m = super::super::forms::materialx_monomials(x, y);
        let p: f64 = (0..9).map(|k| num[k] * m[k]).sum();
        let q: f64 = 1.0 + (0..8).map(|k| den[k] * m[k + 1]).sum::<f64>();
        p / q
    }

    /// The refit of data that are exactly of the form recovers the pair: on the grid and
    /// between its nodes, `MaterialX::eval` of the refit gives both rationals, and the rows
    /// hold numerator then denominator with the denominators' constant 1. The bound 1e-7: the
    /// data are exact, so the minimax optimum is the pair itself; the bound leaves the rounding
    /// of a 17-coefficient solve on 72 points nine decades above f64's 1e-16.
    #[test]
    fn materialx_refit_recovers_a_pair_of_its_own_form() {
        let truth = |m: f64, a: f64| [rational(&SCALE_NUM, &SCALE_DEN, m, a), rational(&BIAS_NUM, &BIAS_DEN, m, a)];
        let mu: Vec<f64> = (0..9).map(|i| 0.1 + 0.1 * i as f64).collect();
        let al: Vec<f64> = (0..8).map(|j| 0.05 + (0.95 / 7.0) * j as f64).collect();
        let g = grid_of(&mu, &al, truth);
        assert!(g.values.iter().flatten().all(|v| (0.05..0.9).contains(v)), "{:?}", g.values);
        let r = materialx_on(&g);
        assert_eq!([r.r[0][2], r.r[0][3]], [1.0, 1.0]);
        let worst = |pts: &[(f64, f64)]| pts.iter().map(|&(m, a)| {
            let (got, want) = (r.eval(m, a), truth(m, a));
            (got[0] - want[0]).abs().max((got[1] - want[1]).abs())
        }).fold(0.0f64, f64::max);
        let on: Vec<(f64, f64)> = g.points().collect();
        let between: Vec<(f64, f64)> = (0..8).flat_map(|i| (0..7).map(move |j| (0.15 + 0.1 * i as f64, 0.1 + 0.13 * j as f64))).collect();
        let (e_on, e_between) = (worst(&on), worst(&between));
        assert!(e_on < 1e-7 && e_between < 1e-7, "{e_on:e} {e_between:e}");
    }

    /// A channel that cannot be fitted (NaN data: both solves fail) keeps MaterialX's
    /// published constants, in their rows; the other channel is still refitted.
    #[test]
    fn an_unfittable_channel_keeps_the_published_constants() {
        let mu: Vec<f64> = (0..9).map(|i| 0.1 + 0.1 * i as f64).collect();
        let al: Vec<f64> = (0..8).map(|j| 0.05 + (0.95 / 7.0) * j as f64).collect();
        let g = grid_of(&mu, &al, |m, a| [rational(&SCALE_NUM, &SCALE_DEN, m, a), f64::NAN]);
        let r = materialx_on(&g);
        for k in 0..9 {
            assert_eq!([r.r[k][1], r.r[k][3]], [MATERIALX.r[k][1], MATERIALX.r[k][3]], "row {k}");
        }
        let e = (r.eval(0.55, 0.5)[0] - rational(&SCALE_NUM, &SCALE_DEN, 0.55, 0.5)).abs();
        assert!(e < 1e-7, "{e:e}");
    }
}
