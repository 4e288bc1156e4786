//! `kind = "lobe"`: the user's own BRDF lobe, written as an expression in the language of
//! [`crate::fit::expr::parse`] (its shading terms `d_ggx`, `v_smith_ggx_correlated`,
//! `d_charlie`, `v_neubelt`… by name), integrated by the generic hemispherical operators
//! ([`crate::shading::hemisphere`], through [`crate::shading::written::Written`]) and served as
//! quantities like the built-in lobes':
//!
//! ```text
//! NAME-albedo      [parameters…, n_dot_v]               E(μ) = ∫ f μl dω_l (F = 1)
//! NAME-albedo-avg  [parameters…]                        E_avg = 2 ∫ E(μ) μ dμ
//! NAME-env         [parameters…, n_dot_v, cos_cone=0]   split sum [scale, bias] (Schlick F)
//! ```
//!
//! `shadefit eval` takes them, and `table`, `fit` and `form` specs sample them, from every lobe
//! spec of the `--fits` folder (registered before the command runs, [`register`]). The build
//! of a lobe spec emits the BRDF itself as a shader function (WGSL, Rust and every `[emit]
//! targets`), its inputs clamped to the lobe's domain (n·v and n·l to `[min_cosine, 1]`), and a
//! JSON file with the lobe's directional albedo and E_avg at the corners of its parameter box
//! (an energy check: an energy-conserving lobe has E ≤ 1).
//!
//! ```toml
//! name = "studio_ggx"
//! kind = "lobe"
//! description = "…"
//! source = "Where the lobe comes from"
//!
//! [[parameter]]                     # the lobe's parameters (1 to 4), in order
//! name = "alpha"
//! range = [0.0001, 1.0]
//! doc = "GGX roughness"
//!
//! [constants]                       # optional: named values the expressions use
//! k = 0.5
//!
//! [[let]]                           # optional bindings, in order
//! name = "a2"
//! value = "alpha * alpha"
//!
//! [brdf]                            # f(n_dot_v, n_dot_l, n_dot_h, v_dot_h, parameters…)
//! value = "d_ggx(n_dot_h, alpha) * v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)"
//!                                   # or d = "…" with vis = "…" (f = d·vis) or g = "…"
//!                                   # (f = d·g/(4 n·v n·l), cosines from 1e-9 up in the
//!                                   # division: n·v = 0 is the limit to O(1e-9))
//!
//! [measure]                         # optional: how the half vector is sampled
//! kind = "trowbridge-reitz"         # "cosine" (the default) or GGX's: "trowbridge-reitz"
//! alpha = "alpha"                   # the GGX measure's α over the parameters (> 0)
//!
//! [emit]
//! function = "studio_ggx_brdf"      # default: NAME
//! min_cosine = 1e-4                 # the emitted function's lower clamp of n·v and n·l
//! ```
//!
//! The check refuses a lobe that is negative or not finite anywhere on a sample of its domain
//! (every parameter's ends and interior, n·v from 0 to 1, half vectors over the hemisphere),
//! a GGX measure whose α is not positive and finite there, and an emitted f32 function that
//! is not finite on its clamp box. Numbers in the expressions are f32 literals (as the shader
//! carries them); `pi` is π to f64 in the integrals and its f32 value in the emitted code.

use super::form::{LetSpec, Names, expression_error};
use super::module::{module_built, module_json};
use super::{BuildError, Built, Mode, input_hash, spec_rel_path};
use crate::emit::header_lines;
use crate::emit::lang::{Lang, form_body};
use crate::fit::expr::Expr;
use crate::fit::expr::parse::{self, Scope};
use crate::fit::expr::program::Program;
use crate::fit::expr::tape::Tape;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::shading::hemisphere::{albedo, albedo_avg, split_sum};
use crate::shading::written::{ARGS, Measure, Written};
use crate::spec::{self, CustomSpec, Placement, Spec, SpecError, SpecFile, is_kind, line_of, names, parse_toml};
use serde::Deserialize;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

pub const KIND: &str = "lobe";

/// The most parameters a lobe takes.
pub const MAX_PARAMS: usize = 4;
/// Points of the clamp box's sample on which the emitted f32 function must be finite.
pub const BOX_SAMPLE: usize = 20_000;
/// With `g`, the cosines below this count as this in f = d·g/(4 n·v n·l) (the limit of
/// g/(n·v n·l) at grazing angles, to O(1e-9)).
pub const G_FLOOR: f32 = 1e-9;
/// Tolerance of the albedo summary in the lobe's JSON.
pub const SUMMARY_TOL: f64 = 1e-7;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamFile {
    name: String,
    range: [f64; 2],
    #[serde(default)]
    doc: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct BrdfFile {
    value: Option<Spanned<String>>,
    d: Option<Spanned<String>>,
    vis: Option<Spanned<String>>,
    g: Option<Spanned<String>>,
}

#[derive(Debug, Default, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
enum MeasureKind {
    #[default]
    Cosine,
    /// GGX's importance measure D·n·h.
    TrowbridgeReitz,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasureFile {
    #[serde(default)]
    kind: MeasureKind,
    alpha: Option<Spanned<String>>,
}

fn default_min_cosine() -> f64 {
    1e-4
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LobeEmit {
    function: Option<String>,
    #[serde(default = "default_min_cosine")]
    min_cosine: f64,
    #[allow(dead_code)]
    targets: Option<Vec<String>>,
}

impl Default for LobeEmit {
    fn default() -> Self {
        LobeEmit { function: None, min_cosine: default_min_cosine(), targets: None }
    }
}

/// The spec file of a lobe spec.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LobeFile {
    name: String,
    #[allow(dead_code)]
    kind: String,
    #[serde(default)]
    description: String,
    #[serde(default)]
    source: String,
    #[serde(rename = "parameter")]
    parameters: Vec<ParamFile>,
    #[serde(default)]
    constants: BTreeMap<String, f64>,
    #[serde(default, rename = "let")]
    lets: Vec<LetSpec>,
    brdf: BrdfFile,
    #[serde(default)]
    measure: MeasureFile,
    #[serde(default)]
    emit: LobeEmit,
}

/// One parameter of a lobe.
#[derive(Debug, Clone, PartialEq)]
pub struct LobeParam {
    pub name: String,
    pub range: (f64, f64),
    pub doc: String,
}

/// A lobe spec, checked.
#[derive(Debug, Clone)]
pub struct LobeDef {
    /// The spec file it was read from.
    pub path: std::path::PathBuf,
    pub name: String,
    pub description: String,
    pub source: String,
    pub params: Vec<LobeParam>,
    /// The constants by name (the user's, then `pi`) and their values.
    pub constants: Vec<String>,
    pub values: Vec<f64>,
    /// Inputs: n_dot_v, n_dot_l, n_dot_h, v_dot_h, then the parameters; result: f.
    pub program: Program,
    tape: Tape,
    /// The GGX measure's α over the parameters (inputs: the parameters), or the cosine measure.
    measure: Option<Tape>,
    pub measure_doc: String,
    pub function: String,
    pub min_cosine: f64,
}

thread_local! {
    /// The tapes' registers, reused between evaluations on each thread.
    static REGS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

fn run(tape: &Tape, inputs: &[f64], consts: &[f64]) -> f64 {
    REGS.with(|regs| {
        let mut out = [0.0];
        tape.eval(inputs, consts, &mut regs.borrow_mut(), &mut out);
        out[0]
    })
}

impl LobeDef {
    /// Parse and check a lobe spec's text.
    pub fn parse(path: &Path, text: &str) -> Result<LobeDef, SpecError> {
        let f: LobeFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        if let Some(why) = names::check_spec_name(&f.name) {
            return Err(at("name", why));
        }
        if f.parameters.is_empty() || f.parameters.len() > MAX_PARAMS {
            return Err(at("parameter", format!("a lobe has 1 to {MAX_PARAMS} [[parameter]]s, not {}", f.parameters.len())));
        }
        let function = f.emit.function.clone().unwrap_or_else(|| f.name.clone());
        if let Some(why) = names::check_identifier(&function) {
            return Err(at("function", format!("not a valid function name: {why}")));
        }
        if let Some((field, why)) = names::check_emitted(&f.name, &function, &[]) {
            return Err(at(field, why));
        }
        if !(f.emit.min_cosine >= 0.0 && f.emit.min_cosine < 1.0) {
            return Err(at("min_cosine", format!("{} must be in [0, 1)", f.emit.min_cosine)));
        }

        // Names: the four cosines, the parameters, constants and bindings, all distinct.
        let mut names = Names::new(path, vec![function.clone(), names::input_helper(&f.name), "input".to_string()]);
        for a in ARGS {
            names.claim(a, 1, "parameter", "argument", true, "an argument of every lobe").expect("the cosines are valid names");
        }
        let mut params = Vec::new();
        for p in &f.parameters {
            let line = text.find(&format!("\"{}\"", p.name)).map_or_else(|| line_of(text, "parameter"), |o| spec::line_of_offset(text, o));
            names.claim(&p.name, line, "parameter", "parameter", true, "a parameter")?;
            let [lo, hi] = p.range;
            if !(lo.is_finite() && hi.is_finite() && lo < hi) || !((lo as f32).is_finite() && (hi as f32).is_finite()) {
                return Err(SpecError::new(path, line, "range", format!("parameter '{}': range [{lo}, {hi}] must be finite (in f32 too) with lo < hi", p.name)));
            }
            params.push(LobeParam { name: p.name.clone(), range: (lo, hi), doc: p.doc.clone() });
        }
        let (mut constants, mut values) = names.constants(text, &f.constants)?;
        constants.push("pi".into());
        values.push(std::f64::consts::PI);

        let inputs: Vec<String> = ARGS.iter().map(|a| a.to_string()).chain(params.iter().map(|p| p.name.clone())).collect();
        let param_names: Vec<String> = params.iter().map(|p| p.name.clone()).collect();
        let expr_err = |field: &str, span: std::ops::Range<usize>, e: parse::ParseError| expression_error(path, text, field, span, e);
        let (lets, let_names) = names.lets(text, &f.lets, &inputs, &constants)?;
        let scope = Scope { inputs: &inputs, constants: &constants, lets: &let_names };
        let term = |field: &str, s: &Spanned<String>| parse::parse(s.get_ref(), scope).map_err(|e| expr_err(field, s.span(), e));
        let b = &f.brdf;
        let (result, brdf_span) = match (&b.value, &b.d, &b.vis, &b.g) {
            (Some(v), None, None, None) => (term("value", v)?, v.span()),
            (None, Some(d), Some(vis), None) => (term("d", d)? * term("vis", vis)?, d.span()),
            (None, Some(d), None, Some(g)) => {
                // g/(n·v n·l) has a finite limit where g vanishes with n·v (or n·l); the
                // division takes the cosines from G_FLOOR up, so that n·v = 0 gives the limit to
                // O(G_FLOOR) rather than 0/0.
                let floor = |i: usize| Expr::Max(Box::new(Expr::Var(i)), Box::new(Expr::Lit(G_FLOOR)));
                let four_nv_nl = Expr::Lit(4.0) * floor(0) * floor(1);
                (term("d", d)? * term("g", g)? / four_nv_nl, d.span())
            }
            _ => return Err(at("brdf", "give the BRDF as value = \"…\", or as d = \"…\" with one of vis = \"…\" (f = d·vis) and g = \"…\" (f = d·g/(4 n·v n·l))".into())),
        };
        let program = Program { lets, result };
        let tape = Tape::compile(&program).expect("a parsed lobe is a scalar program");

        let (measure, measure_doc) = match (f.measure.kind, &f.measure.alpha) {
            (MeasureKind::Cosine, None) => (None, "the cosine-weighted measure".to_string()),
            (MeasureKind::TrowbridgeReitz, Some(a)) => {
                let e = parse::parse(a.get_ref(), Scope { inputs: &param_names, constants: &constants, lets: &[] })
                    .map_err(|e| expr_err("alpha", a.span(), e))?;
                let t = Tape::compile(&Program { lets: vec![], result: e }).expect("a parsed measure is a scalar program");
                (Some(t), format!("GGX's measure D·n·h (Trowbridge–Reitz) at alpha = {}", a.get_ref()))
            }
            (MeasureKind::Cosine, Some(_)) => return Err(at("alpha", "the cosine measure takes no alpha (kind = \"trowbridge-reitz\" does)".into())),
            (MeasureKind::TrowbridgeReitz, None) => return Err(at("measure", "kind = \"trowbridge-reitz\" needs alpha = \"…\", the measure's roughness over the parameters".into())),
        };
        let def = LobeDef {
            path: path.to_path_buf(),
            name: f.name.clone(),
            description: f.description.clone(),
            source: f.source.clone(),
            params,
            constants,
            values,
            program,
            tape,
            measure,
            measure_doc,
            function,
            min_cosine: f.emit.min_cosine,
        };
        def.check_domain().map_err(|(field_kind, msg)| {
            let (field, line) = match (field_kind, &f.measure.alpha) {
                (Bad::Measure, Some(a)) => ("alpha".to_string(), spec::line_of_offset(text, a.span().start)),
                _ => (
                    if b.value.is_some() { "value" } else { "d" }.to_string(),
                    spec::line_of_offset(text, brdf_span.start),
                ),
            };
            SpecError::new(path, line, &field, msg)
        })?;
        Ok(def)
    }

    /// The lobe of a loaded spec (checked when the spec was parsed).
    pub fn from_spec(spec: &Spec) -> Result<LobeDef, SpecError> {
        LobeDef::parse(&spec.path, &spec.text)
    }

    /// f at the cosines `x` = [n·v, n·l, n·h, v·h] and parameters `p`, in f64.
    pub fn brdf(&self, x: [f64; 4], p: &[f64]) -> f64 {
        let mut inputs = [0.0; 4 + MAX_PARAMS];
        inputs[..4].copy_from_slice(&x);
        inputs[4..4 + p.len()].copy_from_slice(p);
        run(&self.tape, &inputs[..4 + p.len()], &self.values)
    }

    /// The measure the lobe is integrated in at parameters `p`.
    pub fn measure(&self, p: &[f64]) -> Measure {
        self.measure.as_ref().map_or(Measure::Cosine, |t| Measure::Ggx(run(t, p, &self.values)))
    }

    /// The lobe at parameters `p` (inside the domain), for the hemispherical operators.
    pub fn lobe<'a>(&'a self, p: &'a [f64]) -> Written<impl Fn([f64; 4]) -> f64 + Sync + 'a> {
        Written::new(move |x| self.brdf(x, p), self.measure(p))
    }

    /// A sample of the parameter box: every parameter at its ends and interior points.
    fn param_sample(&self, per_axis: usize) -> Vec<Vec<f64>> {
        super::product(self.params.iter().map(|p| Placement::Nodes.points([p.range.0, p.range.1], per_axis)).collect())
    }

    /// The first sampled point where the lobe is negative or not finite (or its measure's α
    /// not positive and finite), as a message.
    fn check_domain(&self) -> Result<(), (Bad, String)> {
        let per = ((625f64).powf(1.0 / self.params.len() as f64).floor() as usize).clamp(2, 9);
        let named = |p: &[f64]| self.params.iter().zip(p).map(|(q, v)| format!("{} = {v}", q.name)).collect::<Vec<_>>().join(", ");
        for p in self.param_sample(per) {
            if let Measure::Ggx(a) = self.measure(&p) {
                if !(a > 0.0 && a.is_finite()) {
                    return Err((Bad::Measure, format!("the GGX measure's alpha is {a:e} at {}: it must be positive and finite on the lobe's domain", named(&p))));
                }
            }
            for i in 0..=10 {
                let mu_v = i as f64 / 10.0;
                let sin_v = (1.0 - mu_v * mu_v).sqrt();
                for j in 0..12 {
                    let th = 0.5 * std::f64::consts::PI * (j as f64 + 0.5) / 12.0;
                    let (sh, ch) = th.sin_cos();
                    for k in 0..8 {
                        let phi = std::f64::consts::PI * k as f64 / 7.0;
                        let vh = sin_v * sh * phi.cos() + mu_v * ch;
                        let mu_l = 2.0 * vh * ch - mu_v;
                        if !(mu_l > 0.0 && vh > 0.0) {
                            continue;
                        }
                        let v = self.brdf([mu_v, mu_l, ch, vh], &p);
                        if !(v >= 0.0 && v.is_finite()) {
                            return Err((
                                Bad::Brdf,
                                format!("the BRDF is {v:e} at n_dot_v = {mu_v}, n_dot_l = {mu_l}, n_dot_h = {ch}, v_dot_h = {vh}, {}: a lobe is finite and non-negative on its domain", named(&p)),
                            ));
                        }
                    }
                }
            }
        }
        // The emitted f32 function on its clamp box.
        let domain = self.domain();
        let per_axis = ((BOX_SAMPLE as f64).powf(1.0 / domain.len() as f64).floor() as usize).max(2);
        let c32: Vec<f32> = self.values.iter().map(|&v| v as f32).collect();
        for x in super::product(domain.iter().map(|&(lo, hi)| Placement::Nodes.points([lo, hi], per_axis)).collect()) {
            let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            let v = self.program.eval_f32(&x32, &c32)[0];
            if !v.is_finite() {
                let args: Vec<String> = self.args().iter().zip(&x).map(|(a, v)| format!("{a} = {v}")).collect();
                return Err((Bad::Brdf, format!("the emitted f32 BRDF is {v:e} at {} (its clamp box: raise [emit] min_cosine, or guard the expression)", args.join(", "))));
            }
        }
        Ok(())
    }

    /// The emitted function's arguments: the four cosines, then the parameters.
    pub fn args(&self) -> Vec<String> {
        ARGS.iter().map(|a| a.to_string()).chain(self.params.iter().map(|p| p.name.clone())).collect()
    }

    /// The emitted function's clamp box, one range per argument.
    pub fn domain(&self) -> Vec<(f64, f64)> {
        let c = self.min_cosine;
        [(c, 1.0), (c, 1.0), (0.0, 1.0), (0.0, 1.0)].into_iter().chain(self.params.iter().map(|p| p.range)).collect()
    }

    /// E(μ) at the corners of the parameter box and μ ∈ {0, ½, 1}, and E_avg at each corner
    /// (to [`SUMMARY_TOL`]): (corner, [E(0), E(½), E(1)], E_avg, the largest error estimate).
    pub fn summary(&self) -> Vec<(Vec<f64>, [f64; 3], f64, f64)> {
        self.param_sample(2)
            .into_iter()
            .map(|p| {
                let lobe = self.lobe(&p);
                let e: Vec<Estimate> = [0.0, 0.5, 1.0].iter().map(|&mu| albedo(&lobe, mu, SUMMARY_TOL)).collect();
                let avg = albedo_avg(&lobe, SUMMARY_TOL);
                let err = e.iter().map(|e| e.error).fold(avg.error, f64::max);
                (p.clone(), [e[0].value, e[1].value, e[2].value], avg.value, err)
            })
            .collect()
    }
}

/// Which part of a lobe spec a domain check failed on.
#[derive(Debug, Clone, Copy)]
enum Bad {
    Brdf,
    Measure,
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

const COS_CONE_DOC: &str = "cosine of the visibility cone's half-angle (0: the hemisphere)";

/// The quantities of a registered lobe (see the module doc), for the catalog.
pub fn quantities(def: &'static LobeDef) -> Vec<&'static QuantityDef> {
    let k = def.params.len();
    let lobe_params: Vec<ParamSpec> = def
        .params
        .iter()
        .map(|p| ParamSpec { name: leak(p.name.clone()), min: p.range.0, max: p.range.1, doc: leak(p.doc.clone()), integer: false, default: None, limit: None })
        .collect();
    let n_dot_v = ParamSpec { name: "n_dot_v", min: 0.0, max: 1.0, doc: "cosine of the view angle", integer: false, default: None, limit: None };
    let cos_cone = ParamSpec { name: "cos_cone", min: 0.0, max: 1.0, doc: COS_CONE_DOC, integer: false, default: Some(0.0), limit: None };
    let with = |extra: &[ParamSpec]| -> &'static [ParamSpec] { Box::leak(lobe_params.iter().chain(extra).copied().collect::<Vec<_>>().into_boxed_slice()) };
    let q = |name: String, doc: String, params, eval: crate::quantity::Eval, channels: &'static [&'static str], eval_channels| -> &'static QuantityDef {
        Box::leak(Box::new(QuantityDef { name: leak(name), doc: leak(doc), params, aliases: &[], eval, inverse: None, channels, eval_channels, basis: None }))
    };
    let of = if def.description.is_empty() { def.name.clone() } else { format!("{} ({})", def.name, def.description) };
    let split = move |p: &[f64], tol: f64| split_sum(&def.lobe(&p[..k]), p[k], p.get(k + 1).copied().unwrap_or(0.0), tol).channels();
    vec![
        q(
            format!("{}-albedo", def.name),
            format!("directional albedo E(mu) of the lobe spec {of} (F = 1)"),
            with(&[n_dot_v]),
            Box::leak(Box::new(move |p: &[f64], tol: f64| albedo(&def.lobe(&p[..k]), p[k], tol))),
            &[],
            None,
        ),
        q(
            format!("{}-albedo-avg", def.name),
            format!("E_avg = 2 int E(mu) mu dmu of the lobe spec {of}"),
            with(&[]),
            Box::leak(Box::new(move |p: &[f64], tol: f64| albedo_avg(&def.lobe(&p[..k]), tol))),
            &[],
            None,
        ),
        q(
            format!("{}-env", def.name),
            format!("split-sum [scale, bias] of the lobe spec {of}, lights in a cone"),
            with(&[n_dot_v, cos_cone]),
            Box::leak(Box::new(move |p: &[f64], tol: f64| split(p, tol)[0])),
            &["scale", "bias"],
            Some(Box::leak(Box::new(split))),
        ),
    ]
}

/// Every lobe spec among the `.toml` files directly in `dir` (none when it does not exist),
/// checked, in file-name order; two lobes of one name are refused.
pub fn read_dir(dir: &Path, known: &[&str]) -> Result<Vec<LobeDef>, SpecError> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Ok(vec![]) };
    let mut paths: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|e| e == "toml")).collect();
    paths.sort();
    let mut out: Vec<LobeDef> = Vec::new();
    for path in paths {
        let Ok(text) = std::fs::read_to_string(&path) else { continue };
        if !is_kind(&text, KIND) {
            continue;
        }
        let def = LobeDef::parse(&path, &text)?;
        if out.iter().any(|d| d.name == def.name) {
            return Err(SpecError::new(&path, line_of(&text, "name"), "name", format!("a second lobe named '{}'", def.name)));
        }
        if let Some(q) = ["albedo", "albedo-avg", "env"].iter().map(|s| format!("{}-{s}", def.name)).find(|q| known.contains(&q.as_str())) {
            return Err(SpecError::new(&path, line_of(&text, "name"), "name", format!("the lobe's quantity '{q}' is a built-in quantity's name")));
        }
        out.push(def);
    }
    Ok(out)
}

/// For `Spec::parse`: the common spec of a lobe spec (checked), or `None` when the text is not
/// one. Its quantity is the lobe's albedo, its axes the summary's.
pub fn spec_file(path: &Path, text: &str) -> Result<Option<SpecFile>, SpecError> {
    if !is_kind(text, KIND) {
        return Ok(None);
    }
    let def = LobeDef::parse(path, text)?;
    let axes = def
        .params
        .iter()
        .map(|p| serde_json::json!({"name": p.name, "range": [p.range.0, p.range.1], "count": 2}))
        .chain([serde_json::json!({"name": "n_dot_v", "range": [0.0, 1.0], "count": 3})])
        .collect();
    let quantity = format!("{}-albedo", def.name);
    let common = CustomSpec { kind: KIND, name: &def.name, quantity: &quantity, description: &def.description, tolerance: SUMMARY_TOL, axes, function: &def.function };
    common.spec_file(path, text).map(Some)
}

/// The lobe's module: its BRDF as a shader function, and the albedo summary.
pub fn build(spec: &Spec, _mode: Mode, _root: &Path) -> Result<Built, BuildError> {
    let def = LobeDef::from_spec(spec)?;
    let name = spec.file.name.clone();
    let hash = input_hash(spec);
    let summary = def.summary();
    let max_e = summary.iter().flat_map(|s| s.1).fold(0.0f64, f64::max);
    let err_line = format!(
        "the lobe itself (no approximation); largest sampled directional albedo {max_e:.6} (an energy-conserving lobe has E <= 1)"
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let params: Vec<String> = def.params.iter().map(|p| format!("{} ∈ [{}, {}]", p.name, p.range.0, p.range.1)).collect();
    let doc_lines = [
        format!("{}.", if spec.file.description.is_empty() { &def.name } else { &spec.file.description }),
        format!("Source: {}.", if def.source.is_empty() { "the lobe spec" } else { &def.source }),
        format!("BRDF f(n·v, n·l, n·h, v·h, {}); integrated in {}.", params.join(", "), def.measure_doc),
        format!("Its tables: the quantities {0}-albedo, {0}-albedo-avg and {0}-env.", def.name),
    ];
    let doc: Vec<&str> = doc_lines.iter().map(String::as_str).collect();
    let args = def.args();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let domain = def.domain();
    let consts: Vec<f64> = def.values.clone();
    let render = |lang: Lang| {
        let mut s = lang.preamble(&header, &name, &doc);
        s += &format!("\n{} The BRDF (no cosine factor), inputs clamped to the lobe's domain.\n", lang.comment());
        s += &lang.signature(&def.function, &args, 1);
        s += &form_body(lang, &name, &def.program, &consts, &args, &domain);
        s
    };
    let (wgsl, rust) = (render(Lang::Wgsl), render(Lang::Rust));
    let mut json = module_json(spec, &hash, KIND);
    json.insert("source".into(), def.source.clone().into());
    json.insert("args".into(), serde_json::to_value(def.args()).expect("plain data"));
    json.insert("domain".into(), serde_json::to_value(&domain).expect("plain data"));
    json.insert("measure".into(), def.measure_doc.clone().into());
    json.insert(
        "albedo_summary".into(),
        serde_json::Value::Array(
            summary
                .iter()
                .map(|(p, e, avg, err)| {
                    let at: serde_json::Map<String, serde_json::Value> = def.params.iter().zip(p).map(|(q, v)| (q.name.clone(), (*v).into())).collect();
                    serde_json::json!({"at": at, "albedo_at_n_dot_v_0_half_1": e, "albedo_avg": avg, "error_estimate": err})
                })
                .collect(),
        ),
    );
    Ok(module_built(&name, wgsl, rust, json, summary.len(), 0.0, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GGX: &str = r#"name = "my_ggx"
kind = "lobe"

[[parameter]]
name = "alpha"
range = [0.01, 1.0]

[brdf]
d = "d_ggx(n_dot_h, alpha)"
vis = "v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)"

[measure]
kind = "trowbridge-reitz"
alpha = "alpha"
"#;

    fn parse(text: &str) -> Result<LobeDef, SpecError> {
        LobeDef::parse(Path::new("fits/my_ggx.toml"), text)
    }

    /// f = d·vis and f = d·g/(4 n·v n·l) with g = 4 n·v n·l vis are the same BRDF (to the
    /// few roundings of the extra product and quotient, 1e-14 relative).
    #[test]
    fn d_with_g_is_d_with_vis_over_four_cosines() {
        let a = parse(GGX).unwrap();
        let b = parse(&GGX.replace("vis = \"v_smith", "g = \"4 * n_dot_v * n_dot_l * v_smith")).unwrap();
        for x in [[0.3, 0.7, 0.9, 0.6], [0.9, 0.2, 0.8, 0.5]] {
            let (u, v) = (a.brdf(x, &[0.2]), b.brdf(x, &[0.2]));
            assert!((u - v).abs() <= 1e-14 * u, "{x:?}: {u} vs {v}");
        }
        assert_eq!(a.measure(&[0.2]), Measure::Ggx(0.2));
        assert_eq!(a.args(), ["n_dot_v", "n_dot_l", "n_dot_h", "v_dot_h", "alpha"]);
    }

    /// Mistakes name the file, the line and the field (and the column in the file for an
    /// expression).
    #[test]
    fn a_bad_lobe_spec_is_named_by_file_line_field_and_column() {
        let e = parse(&GGX.replace("d_ggx(n_dot_h, alpha)", "d_ggx(n_dot_h, alpah)")).unwrap_err();
        assert_eq!((e.file.as_str(), e.line, e.field.as_str()), ("fits/my_ggx.toml", 9, "d"));
        assert!(e.msg.starts_with("column 21: unknown name 'alpah'"), "{}", e.msg);
        let e = parse(&GGX.replace("alpha = \"alpha\"", "alpha = \"0.25 - alpha\"")).unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (14, "alpha"));
        assert!(e.msg.contains("the GGX measure's alpha is -"), "{}", e.msg);
        let e = parse(&GGX.replace("name = \"alpha\"", "name = \"n_dot_v\"")).unwrap_err();
        assert!(e.msg.contains("'n_dot_v' is already an argument of every lobe"), "{}", e.msg);
        let e = parse(&GGX.replace("[measure]\nkind = \"trowbridge-reitz\"\n", "[measure]\n")).unwrap_err();
        assert!(e.msg.contains("the cosine measure takes no alpha"), "{}", e.msg);
        let e = parse(&GGX.replace("range = [0.01, 1.0]", "range = [1.0, 0.01]")).unwrap_err();
        assert_eq!(e.field, "range");
    }
}
