//! Scenes (`fits/scenes/*.toml`): build only what a scene needs.
//!
//! A scene lists its materials, each with the shading features it uses and parameters that are
//! fixed for the whole material (a number) or confined to a range (`[lo, hi]`):
//!
//! ```toml
//! name = "my_scene"                 # must equal the file stem
//! description = "..."
//! [[material]]
//! name = "cloth"                    # lowercase identifier, prefixes the emitted names
//! features = ["FEATURE"]            # features the families offer
//! params = { a = 0.5, b = [0.2, 0.8] }
//! ```
//!
//! The features are the families' ([`Feature`], listed in each family's `scene.rs` and given to
//! [`Scene::load`] by the caller): each names its parameters and their domains, the general
//! spec nodes a material reaches, and the specialisations the scene module builds instead when
//! parameters are fixed or narrowed (functions refitted at the material's parameters, constants
//! from the integrals, each with a record of its measured error beside the general fit's).
//!
//! The build graph's nodes are the specs of `fits/` (inputs: the spec text and the generator
//! version, i.e. [`pipeline::input_hash`]) and the scene itself (inputs: the manifest, the
//! generator, and the input hashes of every spec it reads). `shadefit build --scene FILE` builds
//! the nodes the scene reaches whose inputs or files changed since the scene's last build
//! (recorded in `generated/json/scene_NAME.json`: each node's input hash and the SHA-256 of its
//! files), then the scene module `scene_NAME` (WGSL + Rust, one include per scene).

use crate::emit::{self, expr, header_lines, rust, wgsl, Artifact, GENERATOR};
use crate::fit::RationalModel;
use crate::pipeline::{self, input_hash, BuildError, Mode, SceneError};
use crate::spec::{is_identifier, line_of, parse_toml, Spec, SpecError};
use nalgebra::DVector;
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

impl MaterialSpec {
    /// The parameter `k` when the material fixes it.
    pub fn fixed(&self, k: &str) -> Option<f64> {
        match self.params.get(k) {
            Some(ParamValue::Fixed(v)) => Some(*v),
            _ => None,
        }
    }

    /// The range `[lo, hi]` the material confines parameter `k` to.
    pub fn range(&self, k: &str) -> Option<(f64, f64)> {
        match self.params.get(k) {
            Some(ParamValue::Range([lo, hi])) => Some((*lo, *hi)),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub name: String,
    #[serde(default)]
    pub description: String,
    pub material: Vec<MaterialSpec>,
}

/// A validated scene manifest, with the features of each material resolved.
#[derive(Debug, Clone)]
pub struct Scene {
    pub path: PathBuf,
    pub text: String,
    pub file: SceneFile,
    /// The features of each material (same order as `file.material` and its `features`).
    pub features: Vec<Vec<&'static Feature>>,
}

/// A scene feature a family offers (`features = [...]` in scene manifests; each family lists
/// its own in its descriptor's `scene_features`). Plain data and function pointers.
#[derive(Debug)]
pub struct Feature {
    pub name: &'static str,
    /// The parameters a material with this feature may fix or confine.
    pub params: &'static [Param],
    /// What the feature needs for one material (already checked against `params`).
    pub reach: fn(&MaterialSpec) -> Reach,
}

/// A parameter of a feature and its domain `[lo, hi]`.
#[derive(Debug, Clone, Copy)]
pub struct Param {
    pub name: &'static str,
    pub lo: f64,
    pub hi: f64,
    /// A fixed value must lie above `lo` (a range may still start at it).
    pub fixed_above_lo: bool,
}

/// What a feature makes of one material: the general spec nodes it reaches and the
/// specialisations the scene module builds for it.
#[derive(Debug, Default)]
pub struct Reach {
    pub nodes: Vec<&'static str>,
    pub special: Vec<&'static Specialisation>,
}

/// A specialisation a feature builds for one material from its parameters: functions
/// refitted at those parameters and constants from the integrals, each with its record.
#[derive(Debug)]
pub struct Specialisation {
    /// The specs it reads (their input hashes enter the scene's; they must be in `fits/`).
    pub inputs: &'static [&'static str],
    /// The scalar functions it emits (name, domain), from the manifest and specs alone: what
    /// the runtime index lists without building the scene.
    pub functions: fn(&MaterialSpec, &[Spec]) -> Vec<IndexedFunction>,
    /// Build it: the functions and constants the scene module emits, in order.
    pub build: fn(&MaterialSpec, &Inputs) -> Result<Pieces, BuildError>,
}

/// A scalar function of a scene module as the runtime index lists it: name and domain.
pub type IndexedFunction = (String, Vec<(f64, f64)>);

/// What a specialisation reads: the scene's specs and the generated/ folder (the committed
/// general fits it compares itself with, through `pipeline::committed`).
pub struct Inputs<'a> {
    pub scene: &'a str,
    pub specs: &'a [Spec],
    pub generated: &'a Path,
}

impl<'a> Inputs<'a> {
    /// The spec `name` (one of the specialisation's `inputs`).
    pub fn spec(&self, name: &str) -> Result<&'a Spec, BuildError> {
        find(self.scene, self.specs, name)
    }
}

/// The pieces of a scene module a specialisation emits.
#[derive(Default)]
pub struct Pieces {
    pub functions: Vec<SceneFunction>,
    pub constants: Vec<SceneConstant>,
}

/// One emitted scalar function of a scene, with its record (`what`, its measured
/// `max_abs_error` and the general fit's at the same parameters).
pub struct SceneFunction {
    pub name: String,
    pub args: Vec<String>,
    pub domain: Vec<(f64, f64)>,
    pub model: RationalModel,
    pub coefficients: DVector<f64>,
    pub record: Value,
}

/// A constant of a scene (a value from the integrals) with its record (`what`, ...).
pub struct SceneConstant {
    pub name: String,
    pub value: f64,
    pub record: Value,
}

/// Max |approx − truth| over a set of points.
pub fn max_err(truth: &[f64], approx: &[f64]) -> f64 {
    truth.iter().zip(approx).map(|(t, a)| (t - a).abs()).fold(0.0, f64::max)
}

impl Scene {
    /// Read and check a manifest; `features` are every feature the families offer.
    pub fn load(path: &Path, features: &[&'static Feature]) -> Result<Scene, SpecError> {
        let text = crate::spec::input::read_input_text(path).map_err(|e| SpecError::unreadable(path, e))?;
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
        let mut resolved = Vec::new();
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
            let mut mine: Vec<&'static Feature> = Vec::new();
            for f in &m.features {
                let Some(feature) = features.iter().copied().find(|x| x.name == f) else {
                    let known: Vec<&str> = features.iter().map(|x| x.name).collect();
                    return Err(err("features", format!("unknown feature '{f}' (known: {})", known.join(", "))));
                };
                mine.push(feature);
            }
            for (k, v) in &m.params {
                let Some(p) = mine.iter().flat_map(|f| f.params.iter()).find(|p| p.name == k) else {
                    return Err(err("params", format!("'{k}' is not a parameter of features [{}]", m.features.join(", "))));
                };
                let (lo, hi) = (p.lo, p.hi);
                let ok = match *v {
                    ParamValue::Fixed(x) => x.is_finite() && x >= lo && x <= hi && !(p.fixed_above_lo && x == lo),
                    ParamValue::Range([a, b]) => a.is_finite() && b.is_finite() && a >= lo && b <= hi && a < b,
                };
                if !ok {
                    let note = if p.fixed_above_lo { format!(" ({k} > {lo} when fixed)") } else { String::new() };
                    return Err(err(
                        "params",
                        format!("'{k}' = {v:?} must be a finite value or increasing range inside [{lo}, {hi}]{note}"),
                    ));
                }
            }
            resolved.push(mine);
        }
        Ok(Scene { path: path.to_path_buf(), text, file, features: resolved })
    }

    /// Every scene in `dir` (`*.toml`, sorted); a missing folder is no scene.
    pub fn load_dir(dir: &Path, features: &[&'static Feature]) -> Result<Vec<Scene>, SpecError> {
        let Ok(rd) = std::fs::read_dir(dir) else { return Ok(vec![]) };
        let mut paths: Vec<PathBuf> =
            rd.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|e| e == "toml")).collect();
        paths.sort();
        paths.iter().map(|p| Scene::load(p, features)).collect()
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

/// A specialisation of one material.
#[derive(Debug, Clone)]
pub struct Special {
    pub material: MaterialSpec,
    pub what: &'static Specialisation,
}

pub fn plan(scene: &Scene) -> Plan {
    let mut nodes = Vec::new();
    let mut special = Vec::new();
    for (m, features) in scene.file.material.iter().zip(&scene.features) {
        for f in features {
            let r = (f.reach)(m);
            nodes.extend(r.nodes);
            special.extend(r.special.into_iter().map(|what| Special { material: m.clone(), what }));
        }
    }
    let mut nodes: Vec<String> = nodes.into_iter().map(String::from).collect();
    nodes.sort();
    nodes.dedup();
    Plan { nodes, special }
}

fn find<'a>(scene: &str, specs: &'a [Spec], name: &str) -> Result<&'a Spec, BuildError> {
    specs
        .iter()
        .find(|s| s.file.name == name)
        .ok_or_else(|| SceneError::MissingSpec { scene: scene.to_string(), spec: name.to_string() }.into())
}

/// The scene node's input hash: manifest, generator, and every spec it reaches or reads.
pub fn scene_hash(scene: &Scene, specs: &[Spec], plan: &Plan) -> Result<String, BuildError> {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(scene.text.as_bytes());
    let mut names: Vec<&str> = plan.nodes.iter().map(String::as_str).collect();
    for s in &plan.special {
        names.extend(s.what.inputs);
    }
    names.sort_unstable();
    names.dedup();
    for n in names {
        h.update(format!("\n{n} {}", input_hash(find(&scene.file.name, specs, n)?)).as_bytes());
    }
    Ok(format!("sha256:{}", pipeline::hex(&h.finalize())))
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
    (name.to_string(), input_hash, artifacts.iter().map(|a| (a.path.display().to_string(), pipeline::sha256_hex(&a.contents))).collect())
}

/// The scene JSON's `nodes`: each node's name, input hash and files.
fn node_json(nodes: &[NodeRecord]) -> Vec<Value> {
    nodes.iter().map(|(n, h, files)| json!({"name": n, "input_hash": h, "files": files})).collect()
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
    let inputs = Inputs { scene: &scene.file.name, specs, generated };
    let mut emitted = Vec::new();
    let mut constants = Vec::new();
    for s in &p.special {
        let pieces = (s.what.build)(&s.material, &inputs)?;
        emitted.extend(pieces.functions);
        constants.extend(pieces.constants);
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
    let node_records = node_json(nodes);
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
            wgsl_a.path.display().to_string(): pipeline::sha256_hex(&wgsl_a.contents),
            rust_a.path.display().to_string(): pipeline::sha256_hex(&rust_a.contents),
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
    rec["input_hash"].as_str() == Some(hash) && recorded_files(generated, rec).is_some()
}

/// The files a record (`"files": {path: SHA-256}`) lists, read back when every one is unchanged.
fn recorded_files(generated: &Path, rec: &Value) -> Option<Vec<Artifact>> {
    let files = rec["files"].as_object()?;
    pipeline::read_unchanged(generated, files.iter().map(|(p, h)| Some((p.as_str(), h.as_str()?))).collect::<Option<Vec<_>>>()?)
}

/// The scene module's files as its last build wrote them, read back, when that build is still
/// current: its JSON records the scene's input hash and exactly `nodes` (this build's records of
/// the reached nodes), and its files are unchanged on disk.
pub fn fresh_files(scene: &Scene, specs: &[Spec], generated: &Path, nodes: &[NodeRecord]) -> Option<Vec<Artifact>> {
    let json_rel = Path::new("json").join(format!("{}.json", scene.module()));
    let text = std::fs::read(generated.join(&json_rel)).ok()?;
    let previous: Value = serde_json::from_slice(&text).ok()?;
    let recorded = node_json(nodes);
    if previous["input_hash"].as_str() != Some(scene_hash(scene, specs, &plan(scene)).ok()?.as_str())
        || previous["nodes"].as_array() != Some(&recorded)
    {
        return None;
    }
    let mut out = recorded_files(generated, &previous)?;
    out.push(Artifact { path: json_rel, contents: text });
    Some(out)
}

/// Outcome of `build --scene`.
pub struct SceneReport {
    pub built: Vec<String>,
    pub up_to_date: Vec<String>,
    pub skipped: Vec<String>,
    pub records: Vec<Value>,
    /// Each reached spec node as the scene JSON records it (built now or carried over).
    pub nodes: Vec<NodeRecord>,
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
    targets: &dyn Fn(&str, &str) -> Result<Vec<emit::Artifact>, BuildError>,
    tx: &mut emit::Transaction,
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
        let spec = find(&scene.file.name, specs, name)?;
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
    let mut written = tx.write(&artifacts)?;
    let node_wgsl: Vec<emit::Artifact> = artifacts.drain(..).filter(|a| a.path.starts_with("wgsl")).collect();
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
    // The other targets of every module the scene reaches and of the scene module, rebuilt or
    // not (`targets(module, wgsl)`: none unless asked for), from the WGSL just rendered or the
    // one on disk.
    let mut translated = Vec::new();
    for module in p.nodes.iter().cloned().chain(std::iter::once(scene.module())) {
        let rel = Path::new("wgsl").join(format!("{module}.wgsl"));
        let text = match artifacts.iter().chain(&node_wgsl).find(|a| a.path == rel) {
            Some(a) => String::from_utf8_lossy(&a.contents).into_owned(),
            None => match std::fs::read_to_string(generated.join(&rel)) {
                Ok(t) => t,
                Err(_) => continue,
            },
        };
        translated.extend(targets(&module, &text)?);
    }
    artifacts.extend(translated);
    written += tx.write(&artifacts)?;
    let skipped = specs.iter().map(|s| s.file.name.clone()).filter(|n| !p.nodes.contains(n)).collect();
    Ok(SceneReport { built, up_to_date, skipped, records, nodes, written })
}

/// The runtime index with every scene's functions (read from the scenes' committed JSON-free
/// plan: the function names follow from the manifests).
pub fn runtime_index(specs: &[Spec], scenes: &[Scene]) -> Artifact {
    let list: Vec<pipeline::SceneIndex> = scenes.iter().map(|s| (s.module(), scene_functions(s, specs))).collect();
    pipeline::runtime_index_with_scenes(specs, &list)
}

/// The scalar functions a scene emits (name, domain), from its plan alone.
pub fn scene_functions(scene: &Scene, specs: &[Spec]) -> Vec<IndexedFunction> {
    plan(scene).special.iter().flat_map(|s| (s.what.functions)(&s.material, specs)).collect()
}
