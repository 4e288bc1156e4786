//! The refits of the published forms as shader code: the spec kind `ggx-refits`
//! (`fits/ggx_published_refits.toml`), built from [`refit::COMMITTED`] into
//! `wgsl/NAME.wgsl`, `src/NAME.rs` and `json/NAME.json`.
//!
//! Each function keeps its source's form and argument order, with the refitted constants (f32,
//! round-trip digits):
//!
//! - `F_karis(roughness, n_dot_v)` and `F_karis_separable(roughness, n_dot_v)` → (scale, bias): Karis's
//!   EnvBRDFApprox refitted to the height-correlated integral and to UE4's separable G;
//! - `F_lazarov(gloss, n_dot_v)` → (scale, bias): Lazarov's Black Ops II form;
//! - `F_materialx(n_dot_v, alpha)` → (scale, bias): MaterialX's rational pair, clamped to
//!   [0, 1] as in its source;
//! - `F_fresnel_avg_dielectric(eta)`: Kulla–Conty's two branches.
//!
//! Inputs are clamped to the domain each refit was fitted on (NaN → the lower end): n·v, r, g
//! and α to [0, 1] except MaterialX's n·v, fitted on [1/128, 125/128] (its denominators are
//! proven positive on that box, not beyond), and η to [1/3, 3]. The measured errors (the forms
//! in f64 with the emitted f32 constants, on the grids of `super::grid`, beside the published
//! constants' on the same grid) go to the headers and the JSON; `Mode::Committed` re-renders
//! from the constants and the committed JSON's errors. The input hash covers the spec text and
//! the committed constants, so a new refit makes `build --check` fail until rebuilt.

use super::forms::{KARIS, KARIS_FORM, KULLA_CONTY, KULLA_CONTY_FORM, Karis, KullaConty, LAZAROV, LAZAROV_FORM, Lazarov, MATERIALX, MATERIALX_FORM, MaterialX};
use crate::fit::expr::Syntax;
use crate::fit::expr::program::Program;
use super::grid::{self, Target};
use super::refit::{self, Refits};
use crate::emit::{GENERATOR, f32_literal, header_lines};
use crate::family::SpecKind;
use crate::fit::positivity::{Positivity, prove_denominator_positive};
use crate::pipeline::module::{module_built, module_json};
use crate::pipeline::{BuildError, Built, Mode, committed_json_with_hash, fmt_err, hex, spec_rel_path};
use crate::validate;
use crate::spec::{KindDef, Spec, SpecError, SpecFile};
use nalgebra::DVector;
use serde_json::{Value, json};
use sha2::{Digest, Sha256};
use std::path::Path;

pub const KIND: &str = "ggx-refits";

/// The spec kind (registered in the family's descriptor).
pub const REFITS: SpecKind = SpecKind {
    spec: KindDef {
        name: KIND,
        spec_file,
        samples_note: "{name} emits the committed refits of the published forms: it has no samples of its own (see `shadefit validate`)",
        input_hash,
    },
    build,
    shard: None,
};

/// n·v range of the MaterialX refit's fitting grid (every other texel centre of 64).
pub const MATERIALX_N_DOT_V: (f64, f64) = (1.0 / 128.0, 125.0 / 128.0);
/// The MaterialX refit as the emitted code evaluates it: n·v clamped to [`MATERIALX_N_DOT_V`].
pub fn materialx_refit(m: &MaterialX, n_dot_v: f64, alpha: f64) -> [f64; 2] {
    m.eval(n_dot_v.clamp(MATERIALX_N_DOT_V.0, MATERIALX_N_DOT_V.1), alpha)
}

/// η range of the Fresnel-average grids (both branches).
pub const ETA: (f64, f64) = (1.0 / 3.0, 3.0);

/// For `Spec::parse`: the common spec of a module spec of this family (`ggx-env`, the grid
/// tolerance) of kind `kind`, or `None` when the text is not of that kind.
pub(crate) fn module_spec_file(path: &Path, text: &str, kind: &'static str, axes: Vec<Value>) -> Result<Option<SpecFile>, SpecError> {
    crate::spec::module_spec_file(path, text, kind, "ggx-env", grid::TOL, axes)
}

/// For `Spec::parse`: the common spec of a refits spec, or `None` when the text is not one.
/// Axes: the standard grid the pair forms are measured on (n·v texel centres of 64, α in [0, 1]).
pub fn spec_file(path: &Path, text: &str) -> Result<Option<SpecFile>, SpecError> {
    let axes = vec![
        json!({"name": "alpha", "range": [0.0, 1.0], "count": 65}),
        json!({"name": "n_dot_v", "range": [1.0 / 128.0, 127.0 / 128.0], "count": 64}),
    ];
    module_spec_file(path, text, KIND, axes)
}

/// The spec text and the committed constants (their shortest round-trip text).
pub fn input_hash(spec: &Spec) -> String {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(spec.text.as_bytes());
    h.update(format!("{:?}", refit::COMMITTED).as_bytes());
    format!("sha256:{}", hex(&h.finalize()))
}

/// Round every constant to f32 (what the emitted code carries), back in f64.
fn f32s(p: &[f64]) -> Vec<f64> {
    p.iter().map(|&v| v as f32 as f64).collect()
}

/// The committed refits as the emitted code carries them.
pub fn emitted() -> Refits {
    let r = &refit::COMMITTED;
    Refits {
        karis_ue4: Karis::from_params(&f32s(&r.karis_ue4.params())),
        karis_hc: Karis::from_params(&f32s(&r.karis_hc.params())),
        lazarov: Lazarov::from_params(&f32s(&r.lazarov.params())),
        materialx: MaterialX::from_params(&f32s(&r.materialx.params())),
        kulla_conty: KullaConty::from_params(&f32s(&r.kulla_conty.params())),
    }
}

/// One form's errors on its grid: the published constants and the emitted refit.
#[derive(Debug, Clone, PartialEq)]
struct Row {
    function: String,
    form: String,
    grid: String,
    published: [f64; 2],
    refit: [f64; 2],
    points: usize,
}

/// Max and rms |error| of a pair form over both channels of its grid (validate's measure).
fn pair_max_rms(g: &grid::Grid, form: impl Fn(f64, f64) -> [f64; 2]) -> [f64; 2] {
    let p = super::pair(g, form);
    let (max, rms, _) = validate::measure(&p.points, &p.truth, &p.approx);
    [max, rms]
}

fn pair_row(function: String, form: &str, target: Target, published: impl Fn(f64, f64) -> [f64; 2], refit: impl Fn(f64, f64) -> [f64; 2]) -> Row {
    let g = grid::standard(target);
    Row {
        function,
        form: form.into(),
        grid: format!("n·v at 64 texel centres × {} ∈ [0, 1] (65), against {}", target.axis_name(), target.integral()),
        published: pair_max_rms(g, published),
        refit: pair_max_rms(g, refit),
        points: 2 * g.values.len(),
    }
}

/// Every row, measured (the grids' integrals: a few seconds).
fn measure(prefix: &str, e: &Refits) -> Vec<Row> {
    let kc = |above: bool, k: &KullaConty| {
        let (eta, f) = grid::fresnel(above);
        let points: Vec<Vec<f64>> = eta.iter().map(|&x| vec![x]).collect();
        let approx: Vec<f64> = eta.iter().map(|&x| k.eval(x)).collect();
        let (max, rms, _) = validate::measure(&points, f, &approx);
        [max, rms]
    };
    let eta_rows = |above: bool| {
        let n = grid::fresnel(above).0.len();
        Row {
            function: format!("{prefix}_fresnel_avg_dielectric"),
            form: if above { "Kulla–Conty F_avg, η ≥ 1 branch" } else { "Kulla–Conty F_avg, η < 1 branch" }.into(),
            grid: format!("{n} values of η in {}, against the exact dielectric Fresnel average", if above { "[1, 3]" } else { "[1/3, 1)" }),
            published: kc(above, &KULLA_CONTY),
            refit: kc(above, &e.kulla_conty),
            points: n,
        }
    };
    vec![
        pair_row(format!("{prefix}_karis"), "Karis 2014 EnvBRDFApprox", Target::Roughness, |m, r| KARIS.eval(r, m), |m, r| e.karis_hc.eval(r, m)),
        pair_row(format!("{prefix}_karis_separable"), "Karis 2014 EnvBRDFApprox", Target::RoughnessUe4, |m, r| KARIS.eval(r, m), |m, r| e.karis_ue4.eval(r, m)),
        pair_row(format!("{prefix}_lazarov"), "Lazarov 2013 (Black Ops II)", Target::Gloss, |m, g| LAZAROV.eval(g, m), |m, g| e.lazarov.eval(g, m)),
        pair_row(format!("{prefix}_materialx"), "MaterialX mx_ggx_dir_albedo_analytic", Target::Alpha, |m, a| MATERIALX.eval(m, a), |m, a| materialx_refit(&e.materialx, m, a)),
        eta_rows(true),
        eta_rows(false),
    ]
}

fn row_json(r: &Row) -> Value {
    json!({
        "function": r.function, "form": r.form, "grid": r.grid, "points": r.points,
        "published": {"max_abs_error": r.published[0], "rms_error": r.published[1]},
        "refit": {"max_abs_error": r.refit[0], "rms_error": r.refit[1]},
    })
}

fn committed_rows(v: &Value, spec: &str) -> Result<Vec<Row>, BuildError> {
    let bad = |why: &str| BuildError::NoCommitted { spec: spec.into(), why: why.into() };
    let rows = v["forms"].as_array().ok_or_else(|| bad("no \"forms\""))?;
    let num = |r: &Value, a: &str, b: &str| r[a][b].as_f64().ok_or_else(|| bad(&format!("no {a}.{b}")));
    rows.iter()
        .map(|r| {
            Ok(Row {
                function: r["function"].as_str().ok_or_else(|| bad("no function"))?.to_string(),
                form: r["form"].as_str().ok_or_else(|| bad("no form"))?.to_string(),
                grid: r["grid"].as_str().ok_or_else(|| bad("no grid"))?.to_string(),
                published: [num(r, "published", "max_abs_error")?, num(r, "published", "rms_error")?],
                refit: [num(r, "refit", "max_abs_error")?, num(r, "refit", "rms_error")?],
                points: r["points"].as_u64().ok_or_else(|| bad("no points"))? as usize,
            })
        })
        .collect()
}

/// The MaterialX refit's denominators (r.z, r.w) proven positive on the clamped domain: the
/// least of the two proven lower bounds. The model's denominators have the constant term 1, as
/// the refit's (and the published form's) do; a form with another constant is refused.
fn materialx_denominators_positive(m: &MaterialX) -> Result<f64, String> {
    let model = refit::materialx_model();
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

fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let prefix = spec.file.emit.function.clone();
    let hash = input_hash(spec);
    let e = emitted();
    let rows = match mode {
        Mode::Fit => measure(&prefix, &e),
        Mode::Committed => committed_rows(&committed_json_with_hash(root, spec, &hash)?, &name)?,
    };
    let q_lower = materialx_denominators_positive(&e.materialx)
        .map_err(|why| BuildError::NoCommitted { spec: name.clone(), why: format!("the MaterialX refit's denominators are not provably positive on its clamp box ({why})") })?;
    let worst = rows.iter().map(|r| r.refit[0] / r.published[0]).fold(0.0f64, f64::max);
    let largest = rows.iter().map(|r| r.refit[0]).fold(0.0f64, f64::max);
    let err_line = format!(
        "max abs {} (the largest of the forms, each on its own grid; each at most {worst:.2}x its published form's max abs there; per function below; forms in f64 with these f32 constants)",
        fmt_err(largest)
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let wgsl = render(&header, &name, &prefix, &e, &rows, Lang::Wgsl);
    let rust = render(&header, &name, &prefix, &e, &rows, Lang::Rust);
    let max = rows.iter().map(|r| r.refit[0]).fold(0.0f64, f64::max);
    let points: usize = rows.iter().map(|r| r.points).sum();
    let rms = (rows.iter().map(|r| r.refit[1] * r.refit[1] * r.points as f64).sum::<f64>() / points as f64).sqrt();
    let mut json = module_json(spec, &hash, KIND);
    json.insert("source".into(), "family::ggx::published::refit::COMMITTED".into());
    json.insert("materialx_denominator_lower_bound".into(), q_lower.into());
    json.insert("forms".into(), rows.iter().map(row_json).collect::<Vec<_>>().into());
    // The forms' errors pooled (each row is on its own grid and quantity; the per-form figures are in the JSON).
    Ok(module_built(&name, wgsl, rust, json, points, max, rms))
}

/// The two languages a module is written in (shared with the family's other emitted modules).
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Lang {
    Wgsl,
    Rust,
}

impl Lang {
    pub(crate) fn lit(self, v: f64) -> String {
        let s = f32_literal(v as f32);
        match self {
            Lang::Wgsl => format!("{s}f"),
            Lang::Rust => format!("{s}_f32"),
        }
    }

    pub(crate) fn comment(self) -> &'static str {
        match self {
            Lang::Wgsl => "//",
            Lang::Rust => "///",
        }
    }

    /// `fn NAME(args) -> RET {` in the language (args: (name, doc)).
    pub(crate) fn signature(self, name: &str, args: &[&str], vec2: bool) -> String {
        match self {
            Lang::Wgsl => {
                let a: Vec<String> = args.iter().map(|a| format!("{a}: f32")).collect();
                format!("fn {name}({}) -> {} {{\n", a.join(", "), if vec2 { "vec2<f32>" } else { "f32" })
            }
            Lang::Rust => {
                let a: Vec<String> = args.iter().map(|a| format!("{a}: f32")).collect();
                format!("pub fn {name}({}) -> {} {{\n", a.join(", "), if vec2 { "[f32; 2]" } else { "f32" })
            }
        }
    }

    /// The file's opening: header, module doc (`doc` lines), the import path (WGSL) and the
    /// input clamp `MODULE_input` / `input` (NaN → the lower end).
    pub(crate) fn preamble(self, header: &[String], module: &str, doc: &[&str]) -> String {
        let mut s = String::new();
        match self {
            Lang::Wgsl => {
                for line in header {
                    s += &format!("// {line}\n");
                }
                s += &format!("#define_import_path shadefit::{module}\n\n");
                for line in doc {
                    s += &format!("// {line}\n");
                }
                s += &format!(
                    "\n// Clamp an input to [lo, hi]; NaN (any exponent-all-ones pattern with a non-zero\n\
                     // mantissa) maps to lo.\nfn {module}_input(v: f32, lo: f32, hi: f32) -> f32 {{\n    \
                     let nan = (bitcast<u32>(v) & 0x7fffffffu) > 0x7f800000u;\n    \
                     return select(clamp(v, lo, hi), lo, nan);\n}}\n"
                );
            }
            Lang::Rust => {
                for line in header {
                    s += &format!("//! {line}\n");
                }
                s += "//!\n";
                for line in doc {
                    s += &format!("//! {line}\n");
                }
                s += "//! CPU versions of the WGSL functions of the same names.\n\n";
                s += "#[inline]\nfn input(v: f32, lo: f32, hi: f32) -> f32 {\n    if v.is_nan() { lo } else { v.clamp(lo, hi) }\n}\n";
            }
        }
        s
    }

    pub(crate) fn clamp(self, module: &str, v: &str, lo: f64, hi: f64) -> String {
        match self {
            Lang::Wgsl => format!("{module}_input({v}, {}, {})", self.lit(lo), self.lit(hi)),
            Lang::Rust => format!("input({v}, {}, {})", self.lit(lo), self.lit(hi)),
        }
    }
}

/// Doc lines of a function: what it is and its measured errors.
fn doc(lang: Lang, what: &str, rows: &[&Row]) -> String {
    let c = lang.comment();
    let mut s = format!("{c} {what}\n");
    for r in rows {
        s += &format!(
            "{c} {}: max abs {} (published {}, {:.2}x), rms {} (published {}) over {} values; {}.\n",
            r.form,
            fmt_err(r.refit[0]),
            fmt_err(r.published[0]),
            r.refit[0] / r.published[0],
            fmt_err(r.refit[1]),
            fmt_err(r.published[1]),
            r.points,
            r.grid
        );
    }
    s
}

impl Lang {
    pub(crate) fn syntax(self) -> Syntax {
        match self {
            Lang::Wgsl => Syntax::Wgsl,
            Lang::Rust => Syntax::Rust,
        }
    }
}

/// A form's body with its constants: the inputs clamped to `domain` (WGSL: the clamp call at
/// each use, Rust: the arguments rebound once, since Rust spells a vector lane by lane).
fn form_body(lang: Lang, module: &str, form: &Program, consts: &[f64], args: &[&str], domain: &[(f64, f64)]) -> String {
    let c32: Vec<f32> = consts.iter().map(|&v| v as f32).collect();
    let lit = |v: f32| lang.lit(v as f64);
    let input = |i: usize| match lang {
        Lang::Wgsl => lang.clamp(module, args[i], domain[i].0, domain[i].1),
        Lang::Rust => args[i].to_string(),
    };
    let rebound: String = match lang {
        Lang::Wgsl => String::new(),
        Lang::Rust => args.iter().zip(domain).map(|(a, d)| format!("    let {a} = {};\n", lang.clamp(module, a, d.0, d.1))).collect(),
    };
    rebound + &form.render(lang.syntax(), &input, &c32, &lit) + "}\n"
}

fn render(header: &[String], module: &str, prefix: &str, e: &Refits, rows: &[Row], lang: Lang) -> String {
    let mut s = String::new();
    let by = |f: &str| rows.iter().filter(|r| r.function == f).collect::<Vec<_>>();
    s += &lang.preamble(
        header,
        module,
        &["The published forms of the GGX split sum and the Fresnel average with shadefit's refitted", "constants (same form; minimax against the integrals each form approximates)."],
    );
    let f = |n: &str| format!("{prefix}_{n}");
    let pair = "(scale, bias) of the split sum: specular = F0·scale + bias.";
    let unit = (0.0, 1.0);
    let items: [(String, String, &[&str], &Program, Vec<f64>, Vec<(f64, f64)>); 5] = [
        (f("karis"), format!("Karis's EnvBRDFApprox refitted to the height-correlated integral, roughness r (α = r²): {pair}"), &["roughness", "n_dot_v"], &KARIS_FORM, e.karis_hc.params(), vec![unit, unit]),
        (f("karis_separable"), format!("Karis's EnvBRDFApprox refitted to UE4's separable Schlick–Smith G (k = α/2): {pair}"), &["roughness", "n_dot_v"], &KARIS_FORM, e.karis_ue4.params(), vec![unit, unit]),
        (f("lazarov"), format!("Lazarov's Black Ops II form refitted (gloss g: α = sqrt(2/(8192^g + 2))): {pair}"), &["gloss", "n_dot_v"], &LAZAROV_FORM, e.lazarov.params(), vec![unit, unit]),
        (f("materialx"), format!("MaterialX's rational pair refitted (n·v clamped to its fitted [1/128, 125/128]): {pair}"), &["n_dot_v", "alpha"], &MATERIALX_FORM, e.materialx.params(), vec![MATERIALX_N_DOT_V, unit]),
        (f("fresnel_avg_dielectric"), "Kulla–Conty's dielectric Fresnel average F_avg(η) refitted (η clamped to [1/3, 3]).".to_string(), &["eta"], &KULLA_CONTY_FORM, e.kulla_conty.params(), vec![ETA]),
    ];
    for (name, what, args, form, consts, domain) in items {
        s += "\n";
        s += &doc(lang, &what, &by(&name));
        s += &lang.signature(&name, args, form.width() == 2);
        s += &form_body(lang, module, form, &consts, args, &domain);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadefit_runtime::ggx_published_refits as g;

    /// A 33 × 33 grid of [0, 1]² and the special f32 values.
    fn grid() -> Vec<(f32, f32)> {
        (0..=32).flat_map(|i| (0..=32).map(move |j| (i as f32 / 32.0, j as f32 / 32.0))).collect()
    }

    const SPECIAL: [f32; 9] = [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -1.0, -0.0, 1e-45, 2.0];

    /// The proven lower bound of the emitted MaterialX refit's denominators (r.z and r.w of the
    /// form, constant term 1) on its clamp box n·v ∈ [1/128, 125/128] × α ∈ [0, 1] is a lower
    /// bound: positive and never above their least value on a 257 × 257 grid of the box, each
    /// evaluated as Σ_k r[k][ch]·monomial_k (the form's monomials, not the proof's model). The same with r.w's x and x² terms set to −1.9
    /// and 1 (1 − 1.9x + x² ≈ 0.0975 at x = 0.95, α = 0, where the α terms add 12.45α + 69.15α²):
    /// the bound follows the coefficients down. With x's −3 (1 − 3x + x² = −0.25 at x = ½) and
    /// with a constant term other than the model's 1, the form is refused, naming the channel.
    #[test]
    fn the_materialx_denominator_bound_is_below_the_sampled_minimum() {
        let least = |m: &MaterialX| {
            let (lo, hi) = MATERIALX_N_DOT_V;
            let mut least = f64::INFINITY;
            for i in 0..=256 {
                for j in 0..=256 {
                    let t = super::super::forms::materialx_monomials(lo + (hi - lo) * i as f64 / 256.0, j as f64 / 256.0);
                    for ch in 2..4 {
                        least = least.min((0..9).map(|k| m.r[k][ch] * t[k]).sum::<f64>());
                    }
                }
            }
            least
        };
        let m = emitted().materialx;
        let lower = materialx_denominators_positive(&m).expect("proven positive");
        assert!(lower > 0.0 && lower <= least(&m), "bound {lower}, sampled least {}", least(&m));
        let mut low = m;
        (low.r[1][3], low.r[4][3]) = (-1.9, 1.0);
        let lower = materialx_denominators_positive(&low).expect("proven positive");
        assert!(least(&low) < 0.1 && lower > 0.0 && lower <= least(&low), "bound {lower}, sampled least {}", least(&low));
        let mut negative = low;
        negative.r[1][3] = -3.0;
        let err = materialx_denominators_positive(&negative).expect_err("r.w < 0 at x = ½");
        assert!(err.starts_with("channel 3: interval bound "), "{err}");
        let mut constant = m;
        constant.r[0][2] = 2.0;
        let err = materialx_denominators_positive(&constant).expect_err("constant term 2");
        assert!(err.starts_with("channel 2: constant term 2 "), "{err}");
    }

    #[test]
    fn emitted_rust_equals_the_committed_forms_in_f64() {
        let e = emitted();
        let mut worst = [0.0f64; 4];
        for (u, v) in grid() {
            let (x, y) = (u as f64, v as f64);
            let pairs = [
                (g::ggx_refit_karis(u, v), e.karis_hc.eval(x, y)),
                (g::ggx_refit_karis_separable(u, v), e.karis_ue4.eval(x, y)),
                (g::ggx_refit_lazarov(u, v), e.lazarov.eval(x, y)),
                (g::ggx_refit_materialx(u, v), materialx_refit(&e.materialx, x, y)),
            ];
            for (k, (a, b)) in pairs.iter().enumerate() {
                worst[k] = worst[k].max((a[0] as f64 - b[0]).abs()).max((a[1] as f64 - b[1]).abs());
            }
        }
        // Karis and Lazarov: a handful of f32 operations on values ≤ 2 and one exp2 (≤ 2 ulp):
        // well under 1e-6. MaterialX: sums of nine terms up to ~300 in magnitude (|R|·monomial)
        // in f32, so ~9 · 300 · 2⁻²⁴ ≈ 2e-4 in each of r.xy and r.zw, divided by r.zw ≥ 1 on
        // the box (its proven lower bound is in the JSON): ≤ 5e-4.
        assert!(worst[0] < 1e-6 && worst[1] < 1e-6 && worst[2] < 1e-6, "{worst:?}");
        assert!(worst[3] < 5e-4, "{worst:?}");
        for i in 0..=64 {
            let eta = 1.0 / 3.0 + (3.0 - 1.0 / 3.0) * i as f64 / 64.0;
            // A rational of degree 1 or a cubic on values ≤ 3: a few ulps of 1.
            assert!((g::ggx_refit_fresnel_avg_dielectric(eta as f32) as f64 - e.kulla_conty.eval(eta as f32 as f64)).abs() < 1e-6);
        }
    }

    /// The emitted Rust of every refit computes its form's f32 evaluation (`Program::eval_f32`
    /// of the clamped inputs with the emitted f32 constants) bit for bit, on the grid and at
    /// the special values: the renderer keeps the form's operations and their order.
    #[test]
    fn emitted_rust_is_the_forms_f32_evaluation_bit_for_bit() {
        let e = emitted();
        let c32 = |p: Vec<f64>| p.iter().map(|&v| v as f32).collect::<Vec<f32>>();
        let clamp = |v: f32, (lo, hi): (f64, f64)| crate::fit::expr::sanitize(v, lo as f32, hi as f32);
        let unit = (0.0, 1.0);
        let all = grid().into_iter().chain(SPECIAL.iter().flat_map(|&s| [(s, 0.5), (0.5, s), (s, s)]));
        for (u, v) in all {
            let bits = |p: [f32; 2]| p.map(f32::to_bits).to_vec();
            let form = |f: &Program, c: Vec<f64>, d: [(f64, f64); 2]| f.eval_f32(&[clamp(u, d[0]), clamp(v, d[1])], &c32(c)).iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
            assert_eq!(bits(g::ggx_refit_karis(u, v)), form(&KARIS_FORM, e.karis_hc.params(), [unit, unit]), "karis ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_karis_separable(u, v)), form(&KARIS_FORM, e.karis_ue4.params(), [unit, unit]), "karis separable ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_lazarov(u, v)), form(&LAZAROV_FORM, e.lazarov.params(), [unit, unit]), "lazarov ({u}, {v})");
            assert_eq!(bits(g::ggx_refit_materialx(u, v)), form(&MATERIALX_FORM, e.materialx.params(), [MATERIALX_N_DOT_V, unit]), "materialx ({u}, {v})");
            let kc = KULLA_CONTY_FORM.eval_f32(&[clamp(u, ETA)], &c32(e.kulla_conty.params()));
            assert_eq!(g::ggx_refit_fresnel_avg_dielectric(u).to_bits(), kc[0].to_bits(), "kulla-conty {u}");
        }
    }

    #[test]
    fn emitted_rust_is_finite_for_every_input_and_nan_is_the_lower_end() {
        let all = grid().into_iter().chain(SPECIAL.iter().flat_map(|&s| [(s, 0.5), (0.5, s), (s, s)]));
        for (u, v) in all {
            for p in [g::ggx_refit_karis(u, v), g::ggx_refit_karis_separable(u, v), g::ggx_refit_lazarov(u, v), g::ggx_refit_materialx(u, v)] {
                assert!(p.iter().all(|c| c.is_finite()), "({u}, {v}): {p:?}");
            }
            assert!(g::ggx_refit_fresnel_avg_dielectric(u).is_finite());
        }
        assert_eq!(g::ggx_refit_karis(f32::NAN, 0.5), g::ggx_refit_karis(0.0, 0.5));
        assert_eq!(g::ggx_refit_materialx(f32::NAN, 0.5), g::ggx_refit_materialx((MATERIALX_N_DOT_V.0) as f32, 0.5));
        assert_eq!(g::ggx_refit_fresnel_avg_dielectric(f32::NAN), g::ggx_refit_fresnel_avg_dielectric((1.0f64 / 3.0) as f32));
    }

    #[test]
    fn every_refit_beats_its_published_form_and_the_json_says_so() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/generated/json/ggx_published_refits.json")).unwrap();
        let v: Value = serde_json::from_str(&text).unwrap();
        let rows = committed_rows(&v, "ggx_published_refits").unwrap();
        assert_eq!(rows.len(), 6);
        for r in &rows {
            // The aim: at most 0.8× the published max error, on the same grid.
            assert!(r.refit[0] <= 0.8 * r.published[0], "{}: {:?} vs {:?}", r.form, r.refit, r.published);
        }
        // Re-measured here (the grids' integrals), they are what the JSON records.
        let fresh = measure("ggx_refit", &emitted());
        for (a, b) in fresh.iter().zip(&rows) {
            assert_eq!((a.published, a.refit, a.points), (b.published, b.refit, b.points), "{}", a.form);
        }
    }
}
