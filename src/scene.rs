//! Scenes (`fits/scenes/*.toml`): build only what a scene needs.
//!
//! A scene lists its materials, each with the shading features it uses and parameters that are
//! fixed for the whole material (a number) or confined to a range (`[lo, hi]`):
//!
//! ```toml
//! name = "velvet_horse"             # must equal the file stem
//! description = "..."
//! [[material]]
//! name = "velvet"                   # lowercase identifier, prefixes the emitted names
//! features = ["fuzz"]               # fuzz | skin | gloss_mips | gloss_combine
//! params = { alpha = 0.53, theta_f = 0.4014, density = 0.2 }
//! ```
//!
//! Features, their parameters and what a scene build makes of them:
//! - `fuzz` (alpha ∈ [0.15, 1], theta_f ∈ [0, π/2], density ∈ (0, 0.5]): with alpha and theta_f
//!   fixed, the six P_s coefficients come straight from the integrals (the per-direction
//!   minimax optimum at that point, emitted as `{material}_fuzz_ps(n_dot_u, t_dot_u)`) and R is
//!   a constant (`{MATERIAL}_AVERAGE_PS`); otherwise the general `fuzz_ps` and `fuzz_r` nodes are
//!   reached. With density fixed, Q is a constant (`{MATERIAL}_AVERAGE_PENETRATION`) and G̃'s form
//!   is refitted in μv alone (`{material}_fuzz_g(n_dot_v)`); otherwise `fuzz_q`, `fuzz_g`.
//! - `skin`: the `skin_punctual_lut` and `skin_sh_lut` nodes.
//! - `gloss_mips` (gloss range): `gloss_inverse_table`, and with a gloss range the form of
//!   `gloss_length` refitted on that range (`{material}_gloss_to_normal_length(gloss)`, no end
//!   pins), else the general `gloss_length`.
//! - `gloss_combine`: the `gloss_combine_lut` node.
//!
//! The build graph's nodes are the specs of `fits/` (inputs: the spec text and the generator
//! version, i.e. [`pipeline::input_hash`]) and the scene itself (inputs: the manifest, the
//! generator, and the input hashes of every spec it reads). `shadefit build --scene FILE` builds
//! the nodes the scene reaches whose inputs or files changed since the scene's last build
//! (recorded in `generated/json/scene_NAME.json`: each node's input hash and the SHA-256 of its
//! files), then the scene module `scene_NAME` (WGSL + Rust, one include per scene).

use crate::emit::{self, expr, header_lines, rust, wgsl, Artifact, GENERATOR};
use crate::fit::model::{ModelParts, Term};
use crate::fit::{self, Data, FitOptions, Objective, RationalModel};
use crate::pipeline::{self, input_hash, BuildError, Mode};
use crate::family::fuzz::integrals as fuzz;
use crate::family::gloss::integrals as gloss;
use crate::spec::{is_identifier, line_of, parse_toml, Spec, SpecError};
use nalgebra::{DMatrix, DVector};
use serde::Deserialize;
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum ParamValue {
    Fixed(f64),
    Range([f64; 2]),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    pub features: Vec<String>,
    #[serde(default)]
    pub params: BTreeMap<String, ParamValue>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub material: Vec<MaterialSpec>,
}

/// A validated scene manifest.
#[derive(Debug, Clone)]
pub struct Scene {
    pub path: PathBuf,
    pub text: String,
    pub file: SceneFile,
}

/// Features, their parameters and domains (closed unless noted in the check).
const FEATURES: &[(&str, &[(&str, f64, f64)])] = &[
    ("fuzz", &[("alpha", 0.15, 1.0), ("theta_f", 0.0, std::f64::consts::FRAC_PI_2), ("density", 0.0, 0.5)]),
    ("skin", &[]),
    ("gloss_mips", &[("gloss", 0.0, 1.0)]),
    ("gloss_combine", &[]),
];

impl Scene {
    pub fn load(path: &Path) -> Result<Scene, SpecError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SpecError::new(path, 0, "(file)", format!("cannot read: {e}")))?;
        let file: SceneFile = parse_toml(path, &text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(&text, field), field, msg);
        // Line of the n-th `[[material]]` block, for errors inside it.
        let material_line = |i: usize| {
            text.lines().enumerate().filter(|(_, l)| l.trim() == "[[material]]").nth(i).map_or(1, |(n, _)| n + 1)
        };
        if !is_identifier(&file.name) || path.file_stem().and_then(|s| s.to_str()) != Some(file.name.as_str()) {
            return Err(at("name", format!("'{}' must be a lowercase identifier equal to the file name", file.name)));
        }
        if file.material.is_empty() {
            return Err(at("material", "a scene needs at least one [[material]]".into()));
        }
        let mut seen = Vec::new();
        for (i, m) in file.material.iter().enumerate() {
            let line = material_line(i);
            let err = |field: &str, msg: String| SpecError::new(path, line, &format!("material[{i}].{field}"), msg);
            if !is_identifier(&m.name) || seen.contains(&m.name) {
                return Err(err("name", format!("'{}' must be a unique lowercase identifier", m.name)));
            }
            seen.push(m.name.clone());
            if m.features.is_empty() {
                return Err(err("features", "list at least one feature".into()));
            }
            let mut allowed: Vec<(&str, f64, f64)> = Vec::new();
            for f in &m.features {
                let Some((_, params)) = FEATURES.iter().find(|(n, _)| n == f) else {
                    let known: Vec<&str> = FEATURES.iter().map(|(n, _)| *n).collect();
                    return Err(err("features", format!("unknown feature '{f}' (known: {})", known.join(", "))));
                };
                allowed.extend(params.iter().copied());
            }
            for (k, v) in &m.params {
                let Some(&(_, lo, hi)) = allowed.iter().find(|(n, _, _)| n == k) else {
                    return Err(err("params", format!("'{k}' is not a parameter of features [{}]", m.features.join(", "))));
                };
                let ok = match *v {
                    ParamValue::Fixed(x) => x.is_finite() && x >= lo && x <= hi && !(k == "density" && x == 0.0),
                    ParamValue::Range([a, b]) => a.is_finite() && b.is_finite() && a >= lo && b <= hi && a < b,
                };
                if !ok {
                    return Err(err(
                        "params",
                        format!("'{k}' = {v:?} must be a finite value or increasing range inside [{lo}, {hi}] (density > 0 when fixed)"),
                    ));
                }
            }
        }
        Ok(Scene { path: path.to_path_buf(), text, file })
    }

    /// Every scene in `dir` (`*.toml`, sorted); a missing folder is no scene.
    pub fn load_dir(dir: &Path) -> Result<Vec<Scene>, SpecError> {
        let Ok(rd) = std::fs::read_dir(dir) else { return Ok(vec![]) };
        let mut paths: Vec<PathBuf> =
            rd.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|e| e == "toml")).collect();
        paths.sort();
        paths.iter().map(|p| Scene::load(p)).collect()
    }

    pub fn module(&self) -> String {
        format!("scene_{}", self.file.name)
    }
}

/// What a scene needs: spec nodes it reaches and the specialisations it builds itself.
#[derive(Debug, Clone)]
pub struct Plan {
    pub nodes: Vec<String>,
    pub special: Vec<Special>,
}

#[derive(Debug, Clone)]
pub enum Special {
    FuzzPs { material: String, alpha: f64, theta_f: f64 },
    FuzzG { material: String, density: f64 },
    GlossLength { material: String, lo: f64, hi: f64 },
}

fn fixed(m: &MaterialSpec, k: &str) -> Option<f64> {
    match m.params.get(k) {
        Some(ParamValue::Fixed(v)) => Some(*v),
        _ => None,
    }
}

pub fn plan(scene: &Scene) -> Plan {
    let mut nodes = Vec::new();
    let mut special = Vec::new();
    for m in &scene.file.material {
        for f in &m.features {
            match f.as_str() {
                "fuzz" => {
                    match (fixed(m, "alpha"), fixed(m, "theta_f")) {
                        (Some(alpha), Some(theta_f)) => {
                            special.push(Special::FuzzPs { material: m.name.clone(), alpha, theta_f })
                        }
                        _ => nodes.extend(["fuzz_ps", "fuzz_r"]),
                    }
                    match fixed(m, "density") {
                        Some(density) => special.push(Special::FuzzG { material: m.name.clone(), density }),
                        None => nodes.extend(["fuzz_g", "fuzz_q"]),
                    }
                }
                "skin" => nodes.extend(["skin_punctual_lut", "skin_sh_lut"]),
                "gloss_mips" => {
                    nodes.push("gloss_inverse_table");
                    match m.params.get("gloss") {
                        Some(ParamValue::Range([lo, hi])) => {
                            special.push(Special::GlossLength { material: m.name.clone(), lo: *lo, hi: *hi })
                        }
                        _ => nodes.push("gloss_length"),
                    }
                }
                "gloss_combine" => nodes.push("gloss_combine_lut"),
                _ => {}
            }
        }
    }
    let mut nodes: Vec<String> = nodes.into_iter().map(String::from).collect();
    nodes.sort();
    nodes.dedup();
    Plan { nodes, special }
}

/// The specs a specialisation reads (for the scene's input hash and its comparisons).
fn special_inputs(s: &Special) -> &'static [&'static str] {
    match s {
        Special::FuzzPs { .. } => &["fuzz_ps", "fuzz_r"],
        Special::FuzzG { .. } => &["fuzz_g", "fuzz_q"],
        Special::GlossLength { .. } => &["gloss_length"],
    }
}

fn find<'a>(specs: &'a [Spec], name: &str) -> Result<&'a Spec, BuildError> {
    specs.iter().find(|s| s.file.name == name).ok_or_else(|| BuildError::Scene(format!("the scene needs fits/{name}.toml")))
}

/// The scene node's input hash: manifest, generator, and every spec it reaches or reads.
pub fn scene_hash(scene: &Scene, specs: &[Spec], plan: &Plan) -> Result<String, BuildError> {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(scene.text.as_bytes());
    let mut names: Vec<&str> = plan.nodes.iter().map(String::as_str).collect();
    for s in &plan.special {
        names.extend(special_inputs(s));
    }
    names.sort_unstable();
    names.dedup();
    for n in names {
        h.update(format!("\n{n} {}", input_hash(find(specs, n)?)).as_bytes());
    }
    Ok(format!("sha256:{}", pipeline::hex(&h.finalize())))
}

fn sha(bytes: &[u8]) -> String {
    pipeline::hex(&Sha256::digest(bytes))
}

/// One emitted scalar function of a scene, with its measured error and the general fit's at
/// the same parameters.
struct Emitted {
    name: String,
    args: Vec<String>,
    domain: Vec<(f64, f64)>,
    model: RationalModel,
    coefficients: DVector<f64>,
    record: Value,
}

/// A constant of a scene (value from the integral) with its record.
struct Constant {
    name: String,
    value: f64,
    record: Value,
}

/// Max |approx − truth| over a set of points.
fn max_err(truth: &[f64], approx: &[f64]) -> f64 {
    truth.iter().zip(approx).map(|(t, a)| (t - a).abs()).fold(0.0, f64::max)
}

fn model(inputs: &[&str], num: &[&str], den: &[&str], fixed: Vec<(usize, f64)>, clamp: Option<(f64, f64)>) -> RationalModel {
    let f: Vec<String> = inputs.iter().map(|s| s.to_string()).collect();
    let t = |s: &&str| Term::parse(s, &f).expect("scene model terms are valid");
    RationalModel::new(ModelParts {
        inputs: f.clone(),
        numerator: num.iter().map(t).collect(),
        denominator: den.iter().map(t).collect(),
        fixed,
        clamp,
        ..ModelParts::default()
    })
    .expect("scene models are well formed")
}

/// P_s at fixed (α, θf): the coefficients of the quantity's inner basis (Eq. 1) by minimax over
/// the spec's light directions (Lawson's iteration on the linear system), and R as a constant.
fn fuzz_ps(specs: &[Spec], generated: &Path, material: &str, alpha: f64, theta_f: f64) -> Result<(Emitted, Constant), BuildError> {
    let spec = find(specs, "fuzz_ps")?;
    let ib = spec.quantity.basis.expect("fuzz-ps has an inner basis");
    let args: Vec<String> = ib.args.iter().map(|a| a.to_string()).collect();
    let terms: Vec<Term> = ib.terms.iter().map(|t| Term::parse(t, &args).expect("basis terms are valid")).collect();
    let outer = [alpha, theta_f];
    let inner_axes = &spec.file.axis[spec.file.axis.len() - ib.inner..];
    let dirs = |verify: bool| -> Vec<Vec<f64>> {
        let counts: Vec<usize> = inner_axes.iter().map(|a| if verify { a.verify_count() } else { a.count }).collect();
        pipeline::tensor(inner_axes, &counts)
    };
    let basis = |u: &[f64]| -> Vec<f64> {
        let a = (ib.to_args)(&outer, u);
        terms.iter().map(|t| t.eval(&a)).collect()
    };
    let sample = |d: &[Vec<f64>]| -> Vec<f64> { (ib.sample)(&outer, d, spec.file.tolerance).iter().map(|e| e.value).collect() };
    let (lo, hi) = ib.range;
    let fit_dirs = dirs(false);
    let b = DMatrix::from_fn(fit_dirs.len(), terms.len(), |i, k| basis(&fit_dirs[i])[k]);
    let yv = DVector::from_vec(sample(&fit_dirs));
    let mut w = vec![1.0; fit_dirs.len()];
    let mut best: Option<(f64, DVector<f64>)> = None;
    for _ in 0..200 {
        let sw: Vec<f64> = w.iter().map(|v: &f64| v.sqrt()).collect();
        let bw = DMatrix::from_fn(b.nrows(), b.ncols(), |i, k| b[(i, k)] * sw[i]);
        let yw = DVector::from_fn(b.nrows(), |i, _| yv[i] * sw[i]);
        let Ok(c) = bw.svd(true, true).solve(&yw, 1e-14) else { break };
        let r = &b * &c - &yv;
        let m = r.amax();
        if best.as_ref().is_none_or(|(bm, _)| m < *bm) {
            best = Some((m, c.clone()));
        }
        let top = w.iter().zip(r.iter()).map(|(wi, ri)| wi * ri.abs()).fold(0.0, f64::max);
        if !(top > 0.0) {
            break;
        }
        for (wi, ri) in w.iter_mut().zip(r.iter()) {
            *wi = (*wi * ri.abs() / top).max(1e-6);
        }
    }
    let (_, c) = best.ok_or_else(|| BuildError::Scene(format!("{material}: the P_s system at α = {alpha}, θf = {theta_f} is singular")))?;
    // Errors on the verification directions, next to the general fit at the same (α, θf).
    let vd = dirs(true);
    let truth = sample(&vd);
    let eval_at = |coef: &[f64]| -> Vec<f64> {
        vd.iter().map(|u| basis(u).iter().zip(coef).map(|(b, c)| b * c).sum::<f64>().clamp(lo, hi)).collect()
    };
    let ours = eval_at(c.as_slice());
    let general = crate::pipeline::committed::Fields::load(generated, "fuzz_ps", crate::family::catalog()).ok().map(|f| max_err(&truth, &eval_at(&f.eval(&outer))));
    let arg_refs: Vec<&str> = ib.args.to_vec();
    let m = model(&arg_refs, ib.terms, &[], vec![], Some((lo, hi)));
    let ps = Emitted {
        name: format!("{material}_fuzz_ps"),
        args,
        domain: ib.arg_domain.to_vec(),
        record: json!({"what": "P_s coefficients at fixed (alpha, theta_f)", "alpha": alpha, "theta_f": theta_f,
            "coefficients": c.iter().copied().collect::<Vec<f64>>(), "points": vd.len(),
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general}),
        model: m,
        coefficients: c,
    };
    let r = fuzz::r(alpha, theta_f, 1e-10);
    let general_r = crate::pipeline::committed::Refit::load(generated, "fuzz_r", crate::family::catalog())
        .ok()
        .map(|f| (f.eval(&[alpha, theta_f]) - r.value).abs());
    let rc = Constant {
        name: format!("{}_AVERAGE_PS", material.to_uppercase()),
        value: r.value,
        record: json!({"what": "R at fixed (alpha, theta_f)", "value": r.value, "error_estimate": r.error,
            "general_fit_abs_error": general_r}),
    };
    Ok((ps, rc))
}

/// G̃'s form at fixed density, refitted in μv alone (minimax), and Q = 2·E₃(d) as a constant.
fn fuzz_g(specs: &[Spec], generated: &Path, material: &str, d: f64) -> Result<(Emitted, Constant), BuildError> {
    let spec = find(specs, "fuzz_g")?;
    let ax = &spec.file.axis[0];
    // d(1 + a1 μ + a2 μ²)/(d + b1 μ + b3 μ³) = (1 + a1 μ + a2 μ²)/(1 + (b1/d) μ + (b3/d) μ³).
    let m = model(&["n_dot_v"], &["1", "n_dot_v", "n_dot_v^2"], &["n_dot_v", "n_dot_v^3"], vec![(0, 1.0)], None);
    let x: Vec<Vec<f64>> = ax.points(ax.count * 4 + 1).into_iter().map(|v| vec![v]).collect();
    let y: Vec<f64> = x.iter().map(|p| fuzz::g_exact(d, p[0])).collect();
    let data = Data { x, y };
    let f = fit::fit(&m, &data, &FitOptions { objective: Objective::Minimax, ..FitOptions::default() }, &format!("{material}_fuzz_g"))?;
    let vx: Vec<f64> = ax.points(ax.verify_count() * 4 + 1);
    let truth: Vec<f64> = vx.iter().map(|&mu| fuzz::g_exact(d, mu)).collect();
    let ours: Vec<f64> = vx.iter().map(|&mu| m.eval_clamped(&f.coefficients, &[mu])).collect();
    let general = crate::pipeline::committed::Refit::load(generated, "fuzz_g", crate::family::catalog())
        .ok()
        .map(|f| max_err(&truth, &vx.iter().map(|&mu| f.eval(&[mu, d])).collect::<Vec<_>>()));
    let g = Emitted {
        name: format!("{material}_fuzz_g"),
        args: vec!["n_dot_v".into()],
        domain: vec![(ax.range[0], ax.range[1])],
        record: json!({"what": "G refitted in mu_v at fixed density", "density": d, "points": vx.len(),
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general}),
        model: m,
        coefficients: f.coefficients,
    };
    let q = fuzz::q_exact(d);
    let general_q = crate::pipeline::committed::Refit::load(generated, "fuzz_q", crate::family::catalog()).ok().map(|f| (f.eval(&[d]) - q).abs());
    let qc = Constant {
        name: format!("{}_AVERAGE_PENETRATION", material.to_uppercase()),
        value: q,
        record: json!({"what": "Q = 2 E3(d) at fixed density", "value": q, "general_fit_abs_error": general_q}),
    };
    Ok((g, qc))
}

/// The form of gloss_length refitted (minimax, no end pins) on the material's gloss range.
fn gloss_length(specs: &[Spec], generated: &Path, material: &str, lo: f64, hi: f64) -> Result<Emitted, BuildError> {
    let spec = find(specs, "gloss_length")?;
    let general = spec.model.as_ref().expect("fit specs carry a model");
    let inputs: Vec<String> = general.features[..general.n_inputs].to_vec();
    let m = RationalModel::new(ModelParts {
        inputs,
        derived: general.derived.clone(),
        numerator: general.numerator.clone(),
        denominator: general.denominator.clone(),
        lead: general.lead.clone(),
        offset: general.offset,
        factor: general.factor.clone(),
        fixed: general.fixed.clone(),
        pins: vec![],
        clamp: general.clamp,
    })
    .map_err(|e| BuildError::Scene(format!("{material}: {e}")))?;
    let ax = &spec.file.axis[0];
    let n = ax.count;
    let x: Vec<Vec<f64>> = (0..n).map(|i| vec![lo + (hi - lo) * i as f64 / (n - 1) as f64]).collect();
    let y: Vec<f64> = x.iter().map(|p| gloss::length_from_gloss(p[0])).collect();
    let objective = spec.file.fit.as_ref().map_or(Objective::Minimax, |f| f.objective);
    let f = fit::fit(&m, &Data { x, y }, &FitOptions { objective, ..FitOptions::default() }, &format!("{material}_gloss_to_normal_length"))?;
    let nv = ax.verify_count();
    let vx: Vec<f64> = (0..nv).map(|i| lo + (hi - lo) * i as f64 / (nv - 1) as f64).collect();
    let truth: Vec<f64> = vx.iter().map(|&g| gloss::length_from_gloss(g)).collect();
    let ours: Vec<f64> = vx.iter().map(|&g| m.eval_clamped(&f.coefficients, &[g])).collect();
    let general_err = crate::pipeline::committed::Refit::load(generated, "gloss_length", crate::family::catalog())
        .ok()
        .map(|f| max_err(&truth, &vx.iter().map(|&g| f.eval(&[g])).collect::<Vec<_>>()));
    Ok(Emitted {
        name: format!("{material}_gloss_to_normal_length"),
        args: vec![ax.name.clone()],
        domain: vec![(lo, hi)],
        record: json!({"what": "gloss_length form refitted on the material's gloss range", "range": [lo, hi], "points": nv,
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general_err}),
        model: m,
        coefficients: f.coefficients,
    })
}

/// The scene node's artifacts (WGSL + Rust module, JSON) and the scalar functions it emits
/// (name, arity, domain) for the runtime index.
pub struct SceneBuild {
    pub artifacts: Vec<Artifact>,
    pub functions: Vec<(String, Vec<(f64, f64)>)>,
    pub records: Vec<Value>,
}

/// A reached spec node as the scene's cache records it: name, input hash, file → SHA-256.
pub type NodeRecord = (String, String, BTreeMap<String, String>);

/// The cache record of a node from the artifacts it was built into.
pub fn node_record(name: &str, input_hash: String, artifacts: &[Artifact]) -> NodeRecord {
    (name.to_string(), input_hash, artifacts.iter().map(|a| (a.path.display().to_string(), sha(&a.contents))).collect())
}

/// Build the scene module; `nodes` are the reached spec nodes, recorded in the scene JSON.
pub fn build_scene(
    scene: &Scene,
    specs: &[Spec],
    generated: &Path,
    nodes: &[NodeRecord],
) -> Result<SceneBuild, BuildError> {
    let p = plan(scene);
    let hash = scene_hash(scene, specs, &p)?;
    let mut emitted = Vec::new();
    let mut constants = Vec::new();
    for s in &p.special {
        match s {
            Special::FuzzPs { material, alpha, theta_f } => {
                let (e, c) = fuzz_ps(specs, generated, material, *alpha, *theta_f)?;
                emitted.push(e);
                constants.push(c);
            }
            Special::FuzzG { material, density } => {
                let (e, c) = fuzz_g(specs, generated, material, *density)?;
                emitted.push(e);
                constants.push(c);
            }
            Special::GlossLength { material, lo, hi } => emitted.push(gloss_length(specs, generated, material, *lo, *hi)?),
        }
    }
    let module = scene.module();
    let rel = format!("fits/scenes/{}.toml", scene.file.name);
    let errs: Vec<String> = emitted
        .iter()
        .map(|e| format!("{} {:.3e}", e.name, e.record["max_abs_error"].as_f64().unwrap_or(f64::NAN)))
        .collect();
    let worst = emitted.iter().filter_map(|e| e.record["max_abs_error"].as_f64()).fold(0.0, f64::max);
    let err_line = if errs.is_empty() {
        "no functions; constants from the integrals only".to_string()
    } else {
        format!("max abs {worst:.3e} over the scene's functions ({})", errs.join(", "))
    };
    let header = header_lines(&rel, &hash, &err_line);
    let mut w = String::new();
    for h in &header {
        w.push_str(&format!("// {h}\n"));
    }
    w.push_str(&format!("#define_import_path shadefit::{module}\n"));
    let mut r = String::new();
    for h in &header {
        r.push_str(&format!("//! {h}\n"));
    }
    r.push_str(&format!("//!\n//! Scene `{}`: {}\n", scene.file.name, scene.file.description));
    for c in &constants {
        w.push_str(&format!("\n// {}\nconst {}: f32 = {}f;\n", c.record["what"].as_str().unwrap_or(""), c.name, emit::f32_literal(c.value as f32)));
        r.push_str(&format!("\n/// {}\npub const {}: f32 = {}_f32;\n", c.record["what"].as_str().unwrap_or(""), c.name, emit::f32_literal(c.value as f32)));
    }
    let mut functions = Vec::new();
    for e in &emitted {
        let sub = format!("{module}_{}", e.name);
        let d32: Vec<(f32, f32)> = e.domain.iter().map(|&(a, b)| (a as f32, b as f32)).collect();
        let ex = expr::model_expr(&e.model);
        let (num, den) = expr::f32_arrays(&e.model, &e.coefficients);
        let func = wgsl::Function {
            module: &sub,
            name: &e.name,
            args: &e.args,
            derived: &e.model.derived,
            domain: &d32,
            body: wgsl::Body::Fit { expr: &ex, num: &num, den: &den, clamp: e.model.clamp.map(|(a, b)| (a as f32, b as f32)) },
        };
        // Each function's own constants and input helper, named after it.
        let part = wgsl::render_module(&[], &func);
        w.push('\n');
        w.push_str(&wgsl::strip_directives(&part));
        w.push('\n');
        let doc = e.record["what"].as_str().unwrap_or("").to_string();
        let rpart = rust::render_module(&[], &func, &doc);
        r.push_str(&format!("\n/// {doc}\npub mod {} {{\n{}}}\npub use {}::{};\n", e.name, indent(&rpart), e.name, e.name));
        functions.push((e.name.clone(), e.domain.clone()));
    }
    let records: Vec<Value> = emitted.iter().map(|e| e.record.clone()).chain(constants.iter().map(|c| c.record.clone())).collect();
    let node_records: Vec<Value> =
        nodes.iter().map(|(n, h, files)| json!({"name": n, "input_hash": h, "files": files})).collect();
    let reached: Vec<&str> = p.nodes.iter().map(String::as_str).collect();
    let all: Vec<&str> = specs.iter().map(|s| s.file.name.as_str()).collect();
    let skipped: Vec<&str> = all.iter().copied().filter(|n| !reached.contains(n)).collect();
    let wgsl_a = Artifact { path: format!("wgsl/{module}.wgsl").into(), contents: w.into() };
    let rust_a = Artifact { path: format!("src/{module}.rs").into(), contents: r.into() };
    let json = json!({
        "generator": GENERATOR,
        "kind": "scene",
        "scene": rel,
        "input_hash": hash,
        "name": scene.file.name,
        "module": module,
        "nodes": node_records,
        "skipped": skipped,
        "specialised": records,
        "files": {
            wgsl_a.path.display().to_string(): sha(&wgsl_a.contents),
            rust_a.path.display().to_string(): sha(&rust_a.contents),
        },
    });
    let mut text = serde_json::to_string_pretty(&json).expect("JSON values serialise");
    text.push('\n');
    let json_a = Artifact { path: format!("json/{module}.json").into(), contents: text.into() };
    Ok(SceneBuild { artifacts: vec![wgsl_a, rust_a, json_a], functions, records })
}

fn indent(s: &str) -> String {
    s.lines().map(|l| if l.is_empty() { "\n".to_string() } else { format!("    {l}\n") }).collect()
}

/// Whether a recorded node (from the scene's JSON) is up to date: same input hash and every
/// recorded file unchanged on disk.
fn recorded_fresh(generated: &Path, rec: &Value, hash: &str) -> bool {
    rec["input_hash"].as_str() == Some(hash)
        && rec["files"].as_object().is_some_and(|files| {
            !files.is_empty()
                && files.iter().all(|(p, h)| std::fs::read(generated.join(p)).is_ok_and(|b| Some(sha(&b).as_str()) == h.as_str()))
        })
}

/// Outcome of `build --scene`.
pub struct SceneReport {
    pub built: Vec<String>,
    pub up_to_date: Vec<String>,
    pub skipped: Vec<String>,
    pub records: Vec<Value>,
    pub written: usize,
}

/// `shadefit build --scene`: build the reached nodes that changed (all with `force`), then the
/// scene module, then the runtime index (all specs and all scenes in `scenes`).
pub fn build(
    scene: &Scene,
    specs: &[Spec],
    scenes: &[Scene],
    generated: &Path,
    force: bool,
    custom: &dyn Fn(&str) -> Option<pipeline::CustomBuild>,
) -> Result<SceneReport, BuildError> {
    let p = plan(scene);
    let json_path = generated.join("json").join(format!("{}.json", scene.module()));
    let previous: Value = std::fs::read_to_string(&json_path).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or(Value::Null);
    let recorded = |name: &str| -> Option<&Value> {
        previous["nodes"].as_array()?.iter().find(|n| n["name"].as_str() == Some(name))
    };
    let mut built = Vec::new();
    let mut up_to_date = Vec::new();
    let mut nodes = Vec::new();
    let mut artifacts = Vec::new();
    for name in &p.nodes {
        let spec = find(specs, name)?;
        let h = input_hash(spec);
        if !force && let Some(rec) = recorded(name).filter(|r| recorded_fresh(generated, r, &h)) {
            up_to_date.push(name.clone());
            // Unchanged files: their recorded hashes carry over.
            let files: BTreeMap<String, String> = rec["files"]
                .as_object()
                .map(|f| f.iter().map(|(p, v)| (p.clone(), v.as_str().unwrap_or("").to_string())).collect())
                .unwrap_or_default();
            nodes.push((name.clone(), h, files));
            continue;
        }
        let b = pipeline::build_spec(spec, Mode::Fit, generated, custom)?;
        built.push(name.clone());
        nodes.push(node_record(name, h, &b.artifacts));
        artifacts.extend(b.artifacts);
    }
    // The specialisations compare themselves with the committed fits of the specs they read
    // (hash-checked): write the rebuilt nodes first, so they read this build's.
    let mut written = emit::write_all(generated, &artifacts)?;
    artifacts.clear();
    let hash = scene_hash(scene, specs, &p)?;
    // The scene JSON records the scene node itself like any other node (input hash, files).
    let scene_fresh = !force && built.is_empty() && recorded_fresh(generated, &previous, &hash);
    let mut records = previous["specialised"].as_array().cloned().unwrap_or_default();
    if scene_fresh {
        up_to_date.push(scene.module());
    } else {
        let sb = build_scene(scene, specs, generated, &nodes)?;
        records = sb.records;
        artifacts.extend(sb.artifacts);
        built.push(scene.module());
    }
    if !built.is_empty() {
        artifacts.push(runtime_index(specs, scenes));
    }
    written += emit::write_all(generated, &artifacts)?;
    let skipped = specs.iter().map(|s| s.file.name.clone()).filter(|n| !p.nodes.contains(n)).collect();
    Ok(SceneReport { built, up_to_date, skipped, records, written })
}

/// The runtime index with every scene's functions (read from the scenes' committed JSON-free
/// plan: the function names follow from the manifests).
pub fn runtime_index(specs: &[Spec], scenes: &[Scene]) -> Artifact {
    let list: Vec<(String, Vec<(String, Vec<(f64, f64)>)>)> = scenes.iter().map(|s| (s.module(), scene_functions(s, specs))).collect();
    pipeline::runtime_index_with_scenes(specs, &list)
}

/// The scalar functions a scene emits (name, domain), from its plan alone.
pub fn scene_functions(scene: &Scene, specs: &[Spec]) -> Vec<(String, Vec<(f64, f64)>)> {
    plan(scene)
        .special
        .iter()
        .map(|s| match s {
            Special::FuzzPs { material, .. } => {
                let d = crate::family::catalog().lookup("fuzz-ps").ok().and_then(|q| q.basis).map_or(vec![], |b| b.arg_domain.to_vec());
                (format!("{material}_fuzz_ps"), d)
            }
            Special::FuzzG { material, .. } => {
                let r = specs.iter().find(|s| s.file.name == "fuzz_g").map_or([0.001, 1.0], |s| s.file.axis[0].range);
                (format!("{material}_fuzz_g"), vec![(r[0], r[1])])
            }
            Special::GlossLength { material, lo, hi } => (format!("{material}_gloss_to_normal_length"), vec![(*lo, *hi)]),
        })
        .collect()
}

/// A scene feature a family offers (see `crate::family::Family::scene_features`).
#[derive(Debug)]
pub struct Feature {
    pub name: &'static str,
}
