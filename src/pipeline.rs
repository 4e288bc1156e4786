//! The build: for every spec, sample the integral, fit (or tabulate), verify, emit.
//!
//! - `Mode::Fit` integrates and fits from scratch (what `shadefit build` does); a fit's f64
//!   coefficients are then rounded to f32 and re-optimised in f32 on the fitting samples
//!   (`fit::f32round`), and the emitted code uses those f32 coefficients;
//! - `Mode::Committed` takes the coefficients or table values from the committed JSON in
//!   generated/json and re-verifies and re-emits them (what `shadefit build --check` compares
//!   byte for byte; it fails if a spec changed since its JSON was written). A fit's f32
//!   coefficients are read back too, and must lie within `f32round::MAX_ULPS` of the rounded f64
//!   ones; what the re-optimisation measured on the fitting samples is carried over.
//!
//! Samples are computed in parallel with rayon and collected in grid order, so outputs are
//! byte-identical at any thread count.

use crate::fit::expr;
use crate::emit::{self, header_lines, rust, wgsl, Artifact, GENERATOR};
use crate::fit::positivity::{prove_denominator_positive, Positivity};
use crate::fit::{self, f32round, Data, FitOptions, FitReport};
use crate::spec::{self, Kind, Spec};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::path::Path;

#[cfg(test)]
pub(crate) mod build_tests;
#[cfg(test)]
mod lobe_tests;
pub mod committed;
pub mod data;
pub mod fields;
pub mod module;

/// Project paths: specs in `fits/`, outputs in `generated/`.
#[derive(Debug, Clone)]
pub struct Paths {
    pub fits: std::path::PathBuf,
    pub generated: std::path::PathBuf,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Fit,
    Committed,
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{spec}: the f32 coefficients in generated/json/{spec}.json do not belong to its f64 coefficients: {why}; run `shadefit build`")]
    F32Coefficients { spec: String, why: String },
    #[error(transparent)]
    Fit(#[from] fit::FitError),
    #[error("{spec}: generated/json/{spec}.json is missing or unreadable ({why}); run `shadefit build`")]
    NoCommitted { spec: String, why: String },
    #[error("{spec}: the spec changed since generated/json/{spec}.json was written (hash {committed} ≠ {current}); run `shadefit build`")]
    SpecChanged { spec: String, committed: String, current: String },
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Write(#[from] crate::emit::WriteError),
    #[error("{spec}: the f32 code returns a non-finite value at {at:?}")]
    NonFinite { spec: String, at: Vec<f64> },
    #[error(transparent)]
    Spec(#[from] crate::spec::SpecError),
    /// A spec input a family's builder rejects (e.g. a diffusion profile it cannot integrate).
    #[error("{spec}: {msg}")]
    Input { spec: String, msg: String },
    /// A committed file read as a kind its spec is not.
    #[error("{spec}: not a spec of kind = \"{expected}\"")]
    NotKind { spec: String, expected: &'static str },
    #[error("{spec}: the emitted f32 code's max abs error {measured:e} exceeds the spec's max_error {bound:e}")]
    ErrorBound { spec: String, measured: f64, bound: f64 },
    #[error("{spec}: no builder for kind = \"{kind}\"")]
    UnknownKind { spec: String, kind: String },
    /// A module's translation to another target (`--target`, `[emit] targets`).
    #[error(transparent)]
    Target(#[from] crate::emit::targets::TargetError),
}

/// Errors of a scene's own build (its specialisations), beyond those of the specs it reads.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene reaches or reads a spec that `fits/` does not have.
    #[error("scene {scene} needs fits/{spec}.toml")]
    MissingSpec { scene: String, spec: String },
    /// A linear system of a material's specialisation has no solution.
    #[error("{material}: the {system} is singular")]
    Singular { material: String, system: String },
    /// A specialisation's model could not be formed (e.g. a general fit's form without its pins).
    #[error("{material}: cannot form the model of {function}")]
    Model {
        material: String,
        function: String,
        #[source]
        source: Box<crate::fit::model::ModelError>,
    },
}

/// Errors of an emitted function against the integral on the verification grid.
#[derive(Debug, Clone, Serialize)]
pub struct Verification {
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    pub worst_point: Vec<f64>,
    /// The same for the emitted f32 code (f32 coefficients, f32 arithmetic, emitted order).
    pub max_abs_error_f32: f64,
    pub rms_error_f32: f64,
    /// For 1-D quantities with an inverse: max error after mapping back to parameter units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_abs_error_in_parameter: Option<f64>,
}

impl Verification {
    /// The `measured error:` text of a generated file's header.
    pub fn header_line(&self) -> String {
        format!(
            "max abs {}, rms {} over {} points (f32 code: max abs {}, rms {})",
            fmt_err(self.max_abs_error),
            fmt_err(self.rms_error),
            self.points,
            fmt_err(self.max_abs_error_f32),
            fmt_err(self.rms_error_f32)
        )
    }
}

/// Result of building one spec.
#[derive(Debug, Clone)]
pub struct Built {
    pub name: String,
    pub artifacts: Vec<Artifact>,
    pub verification: Verification,
    pub fit: Option<FitReport>,
}

/// Lowercase hex of a digest.
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

pub fn input_hash(spec: &Spec) -> String {
    let mut h = Sha256::new();
    h.update(GENERATOR.as_bytes());
    h.update(b"\n");
    h.update(spec.text.as_bytes());
    format!("sha256:{}", hex(&h.finalize()))
}

/// Tensor grid over the spec's axes with the given counts, first axis fastest.
pub fn grid(spec: &Spec, counts: &[usize]) -> Vec<Vec<f64>> {
    tensor(&spec.file.axis, counts)
}

/// Tensor grid over some axes with the given counts, first axis fastest.
pub(crate) fn tensor(axes: &[crate::spec::AxisSpec], counts: &[usize]) -> Vec<Vec<f64>> {
    let pts: Vec<Vec<f64>> = axes.iter().zip(counts).map(|(a, &n)| a.points(n)).collect();
    let total: usize = counts.iter().product();
    (0..total)
        .map(|mut k| {
            pts.iter()
                .map(|p| {
                    let i = k % p.len();
                    k /= p.len();
                    p[i]
                })
                .collect()
        })
        .collect()
}

/// The integral at each point, in parallel, in order.
pub fn sample(spec: &Spec, points: &[Vec<f64>]) -> Vec<f64> {
    let sampler = spec.sampler();
    points.par_iter().map(|p| sampler.eval(p).value).collect()
}

/// Records the channel a spec takes (`"channel"`) in its JSON, after `"quantity"`.
pub fn with_channel(json: &mut Value, spec: &Spec) {
    if let Some(c) = spec.channel_name() {
        json["channel"] = c.into();
    }
}

/// What generated files name as their spec: `fits/FILE`, or the origin of a spec made in memory.
pub fn spec_rel_path(spec: &Spec) -> String {
    match &spec.origin {
        Some(o) => o.clone(),
        None => format!("fits/{}", spec.path.file_name().and_then(|s| s.to_str()).unwrap_or("?")),
    }
}

fn committed_json(root: &Path, spec: &Spec) -> Result<Value, BuildError> {
    committed_json_with_hash(root, spec, &input_hash(spec))
}

/// `generated/json/NAME.json` of a spec, if it records `hash` as its input hash (a spec kind
/// whose build reads more than the spec text passes its own hash): `NoCommitted` when it is
/// missing or unreadable, `SpecChanged` when it records another hash.
pub fn committed_json_with_hash(root: &Path, spec: &Spec, hash: &str) -> Result<Value, BuildError> {
    let name = &spec.file.name;
    let path = root.join("json").join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path)
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: e.to_string() })?;
    let v: Value = serde_json::from_str(&text)
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: e.to_string() })?;
    let committed = v["input_hash"].as_str().unwrap_or("").to_string();
    if committed != hash {
        return Err(BuildError::SpecChanged { spec: name.clone(), committed, current: hash.to_string() });
    }
    Ok(v)
}

fn f64_array(v: &Value, spec: &str, key: &str) -> Result<Vec<f64>, BuildError> {
    v[key]
        .as_array()
        .and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
        .ok_or_else(|| BuildError::NoCommitted { spec: spec.into(), why: format!("no numeric array '{key}'") })
}

pub fn fmt_err(v: f64) -> String {
    format!("{v:.3e}")
}

/// The builder of a family spec kind.
pub type CustomBuild = fn(&Spec, Mode, &Path) -> Result<Built, BuildError>;

/// Build one spec in the given mode; `root` is the generated/ folder; `custom` finds the builder
/// of a family spec kind by name.
pub fn build_spec(spec: &Spec, mode: Mode, root: &Path, custom: &dyn Fn(&str) -> Option<CustomBuild>) -> Result<Built, BuildError> {
    let b = build_any(spec, mode, root, custom)?;
    // A spec's `max_error` bounds the measured error of its emitted f32 code (NaN fails too).
    let measured = b.verification.max_abs_error_f32;
    if let Some(bound) = spec.file.max_error
        && !(measured <= bound)
    {
        return Err(BuildError::ErrorBound { spec: spec.file.name.clone(), measured, bound });
    }
    Ok(b)
}

fn build_any(spec: &Spec, mode: Mode, root: &Path, custom: &dyn Fn(&str) -> Option<CustomBuild>) -> Result<Built, BuildError> {
    match spec.file.kind {
        Kind::Fit => build_fit(spec, mode, root),
        Kind::Table => build_table(spec, mode, root),
        Kind::Fields => fields::build(spec, mode, root),
        Kind::Custom(kind) => match custom(kind) {
            Some(build) => build(spec, mode, root),
            None => Err(BuildError::UnknownKind { spec: spec.file.name.clone(), kind: kind.into() }),
        },
    }
}

fn domain(spec: &Spec) -> Vec<(f64, f64)> {
    spec.file.axis.iter().map(|a| (a.range[0], a.range[1])).collect()
}

fn domain_f32(spec: &Spec) -> Vec<(f32, f32)> {
    domain(spec).iter().map(|&(a, b)| (a as f32, b as f32)).collect()
}

/// Argument names of the emitted function.
fn args(spec: &Spec) -> Vec<String> {
    spec.file.emit.args.clone().unwrap_or_else(|| spec.file.axis.iter().map(|a| a.name.clone()).collect())
}

/// The integral on a verification grid: the points and the values there.
#[derive(Debug, Clone)]
pub struct Reference {
    pub points: Vec<Vec<f64>>,
    pub values: Vec<f64>,
}

impl Reference {
    /// The spec's verification grid (`verify` points per axis) and the integral on it.
    pub fn of_spec(spec: &Spec) -> Reference {
        let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.verify_count()).collect();
        let points = grid(spec, &counts);
        let values = sample(spec, &points);
        Reference { points, values }
    }
}

/// Whether a build requires every denominator proven positive on the domain (what the
/// pipeline's own fits must be) or only measures constants it did not fit (the published ones,
/// in `bench`): then a denominator not proven positive is built anyway, with the interval
/// bound the proof reached as its lower bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Denominators {
    Proven,
    Unchecked,
}

/// The lower bound of a denominator on `domain`; an error when it must be proven positive and
/// is not.
pub(crate) fn denominator_bound(
    what: impl FnOnce() -> String,
    model: &fit::RationalModel,
    c: &DVector<f64>,
    domain: &[(f64, f64)],
    check: Denominators,
) -> Result<f64, BuildError> {
    match (prove_denominator_positive(model, c, domain), check) {
        (Positivity::Proven { lower, .. }, _) | (Positivity::NotProven { lower, .. }, Denominators::Unchecked) => Ok(lower),
        (Positivity::NotProven { lower, region, .. }, Denominators::Proven) => {
            Err(fit::FitError::PoleInDomain { what: what(), lower, region }.into())
        }
    }
}

/// Fit the spec's model to samples with the spec's objective.
pub fn fit_samples(spec: &Spec, data: &Data) -> Result<fit::Fit, BuildError> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let fit_section = spec.file.fit.as_ref().expect("fit specs carry [fit]");
    let opts = FitOptions { objective: fit_section.objective, max_rms: fit_section.max_rms, ..FitOptions::default() };
    Ok(fit::fit(model, data, &opts, &spec.file.name)?)
}

/// The committed values of a table spec, checked against the spec's hash and grid.
pub fn committed_values(spec: &Spec, root: &Path) -> Result<Vec<f64>, BuildError> {
    let name = &spec.file.name;
    let v = committed_json(root, spec)?;
    let vals = f64_array(&v, name, "values")?;
    if vals.len() != table_points(spec).len() {
        return Err(BuildError::NoCommitted { spec: name.clone(), why: "table size differs from the spec".into() });
    }
    Ok(vals)
}

fn build_fit(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let (coefficients, report, f32s) = match mode {
        Mode::Fit => {
            let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
            let x = grid(spec, &counts);
            let y = sample(spec, &x);
            let data = Data { x, y };
            let f = fit_samples(spec, &data)?;
            let f32s = round_to_f32(spec, &f.coefficients, &data)?;
            (f.coefficients, Some(f.report), f32s)
        }
        Mode::Committed => {
            let (c, f32s) = committed_fit(spec, root)?;
            (c, None, f32s)
        }
    };
    fit_from_coefficients(spec, coefficients, report, Some(f32s), &Reference::of_spec(spec), Denominators::Proven)
}

/// The f32 coefficients of the fit `c` of `spec`'s model to `data`: rounded, then re-optimised
/// on those samples with the spec's objective inside the box the emitted code clamps to.
fn round_to_f32(spec: &Spec, c: &DVector<f64>, data: &Data) -> Result<F32Coefficients, BuildError> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let fit_section = spec.file.fit.as_ref().expect("fit specs carry [fit]");
    let r = f32round::round_and_reoptimise(
        model,
        c,
        data,
        &domain(spec),
        &f32round::RoundOptions::new(fit_section.objective, fit_section.max_rms),
        &spec.file.name,
    )?;
    let on_grid = RoundingOnGrid {
        fitting_samples: data.len(),
        f64: r.f64,
        rounded_f32: r.rounded,
        reoptimised_f32: r.reoptimised,
        sweeps: r.sweeps,
        evaluations: r.evaluations,
    };
    Ok(F32Coefficients { num: r.num, den: r.den, on_grid })
}

/// The committed f64 and f32 coefficients of a fit spec (generated/json/NAME.json under `root`),
/// checked against the spec's hash and model and against each other, with the committed report
/// of the f32 re-optimisation.
pub fn committed_fit(spec: &Spec, root: &Path) -> Result<(DVector<f64>, F32Coefficients), BuildError> {
    let name = &spec.file.name;
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let v = committed_json(root, spec)?;
    let c = f64_array(&v["model"], name, "coefficients")?;
    if c.len() != model.n_full() {
        return Err(BuildError::NoCommitted { spec: name.clone(), why: "coefficient count differs from the spec".into() });
    }
    let c = DVector::from_vec(c);
    let (num, den) = committed_f32(model, &c, &v["model"], name)?;
    let on_grid: RoundingOnGrid = serde_json::from_value(v["f32_rounding"].clone())
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: format!("'f32_rounding' unreadable ({e})") })?;
    Ok((c, F32Coefficients { num, den, on_grid }))
}

/// The f32 coefficients a fit is emitted with, re-optimised on its fitting samples, and what
/// that measured there.
pub struct F32Coefficients {
    num: Vec<f32>,
    den: Vec<f32>,
    on_grid: RoundingOnGrid,
}

/// Verify a fit with the given coefficients against `reference` (in f64 and in the emitted
/// f32 arithmetic) and render its files (see [`Denominators`] for the positivity check). The
/// f32 coefficients are `f32s` (re-optimised, with their report in the JSON) or, without them,
/// the f64 ones rounded to nearest.
pub fn fit_from_coefficients(
    spec: &Spec,
    coefficients: DVector<f64>,
    report: Option<FitReport>,
    f32s: Option<F32Coefficients>,
    reference: &Reference,
    check: Denominators,
) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let objective = spec.file.fit.as_ref().expect("fit specs carry [fit]").objective;
    let dom = domain(spec);
    let lower = denominator_bound(|| name.clone(), model, &coefficients, &dom, check)?;
    let (num, den) = match &f32s {
        Some(f) => (f.num.clone(), f.den.clone()),
        None => expr::f32_arrays(model, &coefficients),
    };
    let f32_rounding = match f32s {
        Some(f) => Some(rounding_report(spec, model, &coefficients, &f, check)?),
        None => None,
    };
    let e = expr::model_expr(model);
    let clamp32 = model.clamp.map(|(a, b)| (a as f32, b as f32));
    let (vx, truth) = (&reference.points, &reference.values);
    let d32 = domain_f32(spec);
    let approx64: Vec<f64> = vx.iter().map(|x| model.eval_clamped(&coefficients, x)).collect();
    let approx32: Vec<f32> = vx
        .iter()
        .map(|x| {
            let xs = expr::features_f32(model, x, &d32);
            let v = expr::eval_f32(&e, &xs, &num, &den);
            match clamp32 {
                Some((lo, hi)) => v.clamp(lo, hi),
                None => v,
            }
        })
        .collect();
    if let Some(i) = approx32.iter().position(|v| !v.is_finite()) {
        return Err(BuildError::NonFinite { spec: name, at: vx[i].clone() });
    }
    let verification = verify(inverse_1d(spec, vx), vx, truth, &approx64, &approx32);
    let hash = input_hash(spec);
    let err_line = verification.header_line();
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let a = args(spec);
    let func = wgsl::Function {
        module: &name,
        name: &spec.file.emit.function,
        args: &a,
        derived: &model.derived,
        domain: &d32,
        body: wgsl::Body::Fit { expr: &e, num: &num, den: &den, clamp: clamp32 },
    };
    let doc = describe_fit(spec, model);
    let labels = model.coefficient_labels();
    let mut json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "fit",
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function": spec.file.emit.function,
        "axes": axes_json(spec),
        "model": {
            "form": "offset + factor * P / Q, Q = denominator_lead + sum(den)",
            "features": model.features,
            "arguments": a,
            "numerator": model.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator": model.denominator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator_lead": model.lead.as_ref().map_or("1".to_string(), |t| t.label.clone()),
            "derived": model.derived.iter().map(|d| json!({"name": d.name, "definition": d.describe(&model.features)})).collect::<Vec<_>>(),
            "offset": model.offset,
            "factor": model.factor.as_ref().map(|t| t.label.clone()),
            "clamp": model.clamp.map(|(a, b)| [a, b]),
            "labels": labels,
            "coefficients": coefficients.iter().cloned().collect::<Vec<f64>>(),
            "numerator_f32": num,
            "denominator_f32": den,
            "denominator_lower_bound": lower,
            "objective": objective,
        },
        "verification": verification,
    });
    if let (Some(o), Some(r)) = (json.as_object_mut(), f32_rounding) {
        o.insert("f32_rounding".into(), r);
    }
    with_channel(&mut json, spec);
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl::render_module(&header, &func).into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust::render_module(&header, &func, &doc).into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json_text(&json).into() },
    ];
    Ok(Built { name, artifacts, verification, fit: report })
}

/// The `f32_rounding` object of a fit's JSON: the measurements on the fitting samples, the
/// moves from the rounded coefficients and the denominator bound of the f32 coefficients.
fn rounding_report(
    spec: &Spec,
    model: &fit::RationalModel,
    coefficients: &DVector<f64>,
    f: &F32Coefficients,
    check: Denominators,
) -> Result<Value, BuildError> {
    let name = &spec.file.name;
    let lower32 =
        denominator_bound(|| format!("{name} (f32 coefficients)"), model, &f32round::widen(&f.num, &f.den), &domain(spec), check)?;
    let (num0, den0) = f32round::rounded(model, coefficients);
    let moves: Vec<i64> =
        num0.iter().chain(&den0).zip(f.num.iter().chain(&f.den)).map(|(&a, &b)| f32round::ulps_between(a, b)).collect();
    let mut r = serde_json::to_value(&f.on_grid).expect("the rounding report serialises");
    let extra = json!({
        "objective": spec.file.fit.as_ref().expect("fit specs carry [fit]").objective,
        "max_ulps_allowed": f32round::MAX_ULPS,
        "moves_ulps": moves,
        "coefficients_moved": moves.iter().filter(|m| **m != 0).count(),
        "max_move_ulps": moves.iter().map(|m| m.unsigned_abs()).max().unwrap_or(0),
        "denominator_lower_bound": lower32,
    });
    if let (Some(o), Value::Object(x)) = (r.as_object_mut(), extra) {
        o.extend(x);
    }
    Ok(r)
}

/// What rounding to f32 did on the fitting samples (part of `f32_rounding` in the JSON): measured
/// by `build`, carried over from the committed JSON by `build --check` (which does not sample the
/// fitting grid); the rest of `f32_rounding` follows from the coefficients and is recomputed.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RoundingOnGrid {
    fitting_samples: usize,
    /// The f64 fit, the coefficients rounded to nearest f32, and the re-optimised f32 ones
    /// (f32 arithmetic, emitted order).
    f64: f32round::Errors,
    rounded_f32: f32round::Errors,
    reoptimised_f32: f32round::Errors,
    sweeps: usize,
    evaluations: usize,
}

/// The committed f32 arrays: f32 values, as many as the model's terms, fixed coefficients as
/// rounded, every one within [`f32round::MAX_ULPS`] of the rounded f64 coefficient.
fn committed_f32(model: &fit::RationalModel, c: &DVector<f64>, m: &Value, spec: &str) -> Result<(Vec<f32>, Vec<f32>), BuildError> {
    let bad = |why: String| BuildError::F32Coefficients { spec: spec.into(), why };
    let (num0, den0) = f32round::rounded(model, c);
    let labels = model.coefficient_labels();
    let read = |key: &str, want: usize, first: usize| -> Result<Vec<f32>, BuildError> {
        let v = f64_array(m, spec, key)?;
        if v.len() != want {
            return Err(bad(format!("'{key}' has {} values, the model {want}", v.len())));
        }
        v.iter()
            .enumerate()
            .map(|(j, &x)| {
                if (x as f32) as f64 == x {
                    Ok(x as f32)
                } else {
                    Err(bad(format!("{} = {x:e} in '{key}' is not an f32", labels[first + j])))
                }
            })
            .collect()
    };
    let num = read("numerator_f32", num0.len(), 0)?;
    let den = read("denominator_f32", den0.len(), num0.len())?;
    for (i, (&a, &b)) in num0.iter().chain(&den0).zip(num.iter().chain(&den)).enumerate() {
        let d = f32round::ulps_between(a, b);
        if d.unsigned_abs() > f32round::MAX_ULPS as u64 {
            return Err(bad(format!(
                "{} = {b:e} is {d} ulps from the rounded coefficient {a:e} (at most {} allowed)",
                labels[i],
                f32round::MAX_ULPS
            )));
        }
        if d != 0 && model.fixed.iter().any(|f| f.0 == i) {
            return Err(bad(format!("{} is fixed but {b:e} differs from its rounded value {a:e}", labels[i])));
        }
    }
    Ok((num, den))
}

fn describe_fit(spec: &Spec, model: &fit::RationalModel) -> String {
    let num: Vec<String> = model.numerator.iter().map(|t| format!("({t})")).collect();
    let den: Vec<String> = model.denominator.iter().map(|t| format!("({t})")).collect();
    format!(
        "{}: `{}` ≈ {} of quantity `{}`, P = NUM · [{}], Q = {} + DEN · [{}].",
        spec.file.description,
        spec.file.emit.function,
        {
            let mut f = "P/Q".to_string();
            if let Some(t) = &model.factor {
                f = format!("({t})·{f}");
            }
            if model.offset != 0.0 {
                f = format!("{} + {f}", model.offset);
            }
            if model.clamp.is_some() { format!("clamp({f})") } else { f }
        },
        spec.quantity_label(),
        num.join(", "),
        model.lead.as_ref().map_or("1".to_string(), |t| format!("({t})")),
        den.join(", ")
    )
}

fn axes_json(spec: &Spec) -> Value {
    Value::Array(
        spec.file
            .axis
            .iter()
            .map(|a| json!({"name": a.name, "range": a.range, "count": a.count, "verify": a.verify_count()}))
            .collect(),
    )
}

/// The committed texels `values` of a LUT's JSON: an array of `texels` arrays of N numbers
/// (`what` names them in the error, e.g. "[r, g, b]").
pub fn committed_texels<const N: usize>(v: &Value, spec: &str, texels: usize, what: &str) -> Result<Vec<[f64; N]>, BuildError> {
    let bad = |why: String| BuildError::NoCommitted { spec: spec.into(), why };
    let values: Vec<[f64; N]> = v["values"]
        .as_array()
        .and_then(|a| {
            a.iter()
                .map(|t| {
                    let t = t.as_array()?;
                    (t.len() == N).then_some(())?;
                    let mut out = [0.0; N];
                    for (o, x) in out.iter_mut().zip(t) {
                        *o = x.as_f64()?;
                    }
                    Some(out)
                })
                .collect::<Option<Vec<_>>>()
        })
        .ok_or_else(|| bad(format!("no array 'values' of {what} numbers")))?;
    if values.len() != texels {
        return Err(bad("texel count differs from the spec".into()));
    }
    Ok(values)
}

pub fn json_text(v: &Value) -> String {
    let mut s = serde_json::to_string_pretty(v).expect("JSON values serialise");
    s.push('\n');
    s
}

/// JSON text with every array of numbers on one line (a texel list stays one texel
/// per line; everything else as serde_json's pretty printer writes it).
pub fn compact_json(v: &Value) -> String {
    let pretty = json_text(v);
    let lines: Vec<&str> = pretty.lines().collect();
    let is_number = |s: &str| {
        let t = s.trim().trim_end_matches(',');
        !t.is_empty() && t.parse::<f64>().is_ok()
    };
    let mut out = String::with_capacity(pretty.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        if line.ends_with('[') {
            let mut j = i + 1;
            while j < lines.len() && is_number(lines[j]) {
                j += 1;
            }
            if j > i + 1 && j < lines.len() && lines[j].trim_start().starts_with(']') {
                let items: Vec<&str> = lines[i + 1..j].iter().map(|l| l.trim().trim_end_matches(',')).collect();
                out.push_str(line);
                out.push_str(&items.join(", "));
                out.push_str(lines[j].trim_start());
                out.push('\n');
                i = j + 1;
                continue;
            }
        }
        out.push_str(line);
        out.push('\n');
        i += 1;
    }
    out
}

/// The larger of two errors, a NaN being the largest (`f64::max` drops it).
pub fn nan_max(a: f64, b: f64) -> f64 {
    if b > a || b.is_nan() { b } else { a }
}

/// Max abs, rms and worst point of `approx − truth` over `points`; a NaN is the worst point and
/// the max (it then fails every bound).
pub fn measure(points: &[Vec<f64>], truth: &[f64], approx: &[f64]) -> (f64, f64, Vec<f64>) {
    let mut worst = (0, 0.0f64);
    let mut ss = 0.0;
    for (i, (t, a)) in truth.iter().zip(approx).enumerate() {
        let e = (a - t).abs();
        if e > worst.1 || e.is_nan() {
            worst = (i, e);
        }
        ss += e * e;
    }
    (worst.1, (ss / truth.len().max(1) as f64).sqrt(), points.get(worst.0).cloned().unwrap_or_default())
}

/// The spec's quantity's inverse, for a 1-D spec (errors in parameter units).
fn inverse_1d(spec: &Spec, vx: &[Vec<f64>]) -> Option<fn(f64) -> f64> {
    spec.quantity.inverse.filter(|_| vx.first().is_some_and(|x| x.len() == 1))
}

/// Max abs and rms error of the f64 fit and of the emitted f32 code against the integral on the
/// verification points, and through `inverse` in parameter units; a NaN anywhere is the max
/// error (it then fails every bound).
fn verify(inverse: Option<fn(f64) -> f64>, vx: &[Vec<f64>], truth: &[f64], a64: &[f64], a32: &[f32]) -> Verification {
    let a32: Vec<f64> = a32.iter().map(|&v| v as f64).collect();
    let (max_abs_error, rms_error, worst_point) = measure(vx, truth, a64);
    let (max_abs_error_f32, rms_error_f32, _) = measure(vx, truth, &a32);
    let inverse = inverse.map(|inv| {
        vx.iter().zip(a64).map(|(x, &v)| (inv(v) - x[0]).abs()).fold(0.0, nan_max)
    });
    Verification {
        points: truth.len(),
        max_abs_error,
        rms_error,
        worst_point,
        max_abs_error_f32,
        rms_error_f32,
        max_abs_error_in_parameter: inverse,
    }
}

/// The grid points of a table spec (`count` per axis, first axis fastest).
pub fn table_points(spec: &Spec) -> Vec<Vec<f64>> {
    let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
    grid(spec, &counts)
}

fn build_table(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let values: Vec<f64> = match mode {
        Mode::Fit => sample(spec, &table_points(spec)),
        Mode::Committed => committed_values(spec, root)?,
    };
    table_from_values(spec, values, &Reference::of_spec(spec))
}

/// Verify a table with the given values (at [`table_points`]) against `reference`, through
/// the emitted f32 interpolation, and render its files.
pub fn table_from_values(spec: &Spec, values: Vec<f64>, reference: &Reference) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
    let points = table_points(spec);
    assert_eq!(values.len(), points.len(), "{name}: one value per table point");
    let v32: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    let d32 = domain_f32(spec);
    let (vx, truth) = (&reference.points, &reference.values);
    let approx32: Vec<f32> = vx
        .iter()
        .map(|x| {
            let xs: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            rust::table_eval_f32(&v32, &counts, &d32, &xs)
        })
        .collect();
    let approx64: Vec<f64> = approx32.iter().map(|&v| v as f64).collect();
    let verification = verify(inverse_1d(spec, vx), vx, truth, &approx64, &approx32);
    let hash = input_hash(spec);
    let form = spec.file.emit.form.unwrap_or_default();
    let tex_format = spec.file.emit.texture_format.unwrap_or_default();
    let precision = match tex_format {
        spec::TableTextureFormat::R16float => emit::texture::TextureFormat::Rgba16float,
        spec::TableTextureFormat::R32float => emit::texture::TextureFormat::Rgba32float,
    };
    let mut err_line = format!(
        "linear interpolation of the f32 table: max abs {}, rms {} over {} points",
        fmt_err(verification.max_abs_error_f32),
        fmt_err(verification.rms_error_f32),
        verification.points
    );
    if form.has_texture() {
        let storage = v32.iter().map(|&v| (precision.stored(v) - v).abs()).fold(0.0f32, f32::max);
        err_line.push_str(&format!("; {} texture storage <= {}", tex_format.name(), fmt_err(storage as f64)));
    }
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let a = args(spec);
    let func = wgsl::Function {
        module: &name,
        name: &spec.file.emit.function,
        args: &a,
        derived: &[],
        domain: &d32,
        body: wgsl::Body::Table { values: &v32, counts: &counts },
    };
    let doc = format!(
        "{}: `{}` interpolates a {} table of quantity `{}`.",
        spec.file.description,
        spec.file.emit.function,
        counts.iter().map(|c| c.to_string()).collect::<Vec<_>>().join("×"),
        spec.quantity_label()
    );
    let mut json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "table",
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function": spec.file.emit.function,
        "axes": axes_json(spec),
        "layout": "first axis fastest",
        "values": values,
        "verification": verification,
    });
    with_channel(&mut json, spec);
    let mut csv = String::new();
    for h in &header {
        csv.push_str(&format!("# {h}\n"));
    }
    csv.push_str(&format!("{},value\n", a.join(",")));
    for (p, v) in points.iter().zip(&values) {
        let cols: Vec<String> = p.iter().map(|x| format!("{x:?}")).collect();
        csv.push_str(&format!("{},{v:?}\n", cols.join(",")));
    }
    let ktx2_file = format!("data/{name}.ktx2");
    let texture = form.has_texture().then(|| wgsl::TableTexture {
        file: &ktx2_file,
        format: tex_format.name(),
        filterable: tex_format == spec::TableTextureFormat::R16float || spec.file.emit.float32_filterable,
        keep_const: form.has_const(),
    });
    let mut rust_text = rust::render_module(&header, &func, &doc);
    let mut ktx2 = None;
    if let Some(t) = &texture {
        let (w, h) = (counts[0] as u32, counts.get(1).copied().unwrap_or(1) as u32);
        let shadefit = header.join("\n");
        ktx2 = Some(emit::texture::ktx2_texels(w, h, 1, &v32, precision, &[("shadefit", &shadefit)]));
        let upper = name.to_uppercase();
        rust_text.push_str(&format!(
            "\n/// The table as a KTX2 texture ({fmt}, {w}x{h} texels, one level; texel (i, j) the value at\n\
             /// point i of the first axis, j of the second), as written by `shadefit build`; read by the\n\
             /// WGSL function `{f}_load`{sample}.\n\
             pub const {upper}_KTX2: &[u8] = include_bytes!(\"../{file}\");\n\
             /// Texel format of [`{upper}_KTX2`] (WebGPU name).\n\
             pub const {upper}_TEXTURE_FORMAT: &str = \"{fmt}\";\n",
            fmt = t.format,
            f = spec.file.emit.function,
            sample = if t.filterable { format!(" and, through a linear sampler, `{}_sample`", spec.file.emit.function) } else { String::new() },
            file = ktx2_file,
        ));
    }
    let mut artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl::render_table_module(&header, &func, texture.as_ref()).into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust_text.into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json_text(&json).into() },
        Artifact { path: format!("data/{name}.csv").into(), contents: csv.into() },
    ];
    if let Some(bytes) = ktx2 {
        artifacts.push(Artifact { path: ktx2_file.clone().into(), contents: bytes });
    }
    Ok(Built { name, artifacts, verification, fit: None })
}

/// The runtime crate's index of emitted modules (generated/src/emitted.rs), included by the
/// crate's hand-written `lib.rs`.
pub fn runtime_index(specs: &[Spec]) -> Artifact {
    runtime_index_with_scenes(specs, &[])
}

/// Scene modules of the index: (module, [(function, domain)]).
pub type SceneIndex = (String, Vec<(String, Vec<(f64, f64)>)>);

/// The runtime index: every spec's module (feature per family) and every scene's module
/// (feature `scenes`), their WGSL, and the scalar functions for GPU verification.
pub fn runtime_index_with_scenes(specs: &[Spec], scenes: &[SceneIndex]) -> Artifact {
    let mut s = String::new();
    s.push_str(&format!(
        "// @generated by {GENERATOR}: do not edit; regenerate with `shadefit build`.\n\
         // Index of the emitted modules, one feature per family; included by lib.rs.\n\n"
    ));
    for spec in specs {
        let fam = family(spec);
        s.push_str(&format!(
            "#[cfg(feature = \"{fam}\")]\n#[path = \"{n}.rs\"]\npub mod {n};\n",
            n = spec.file.name
        ));
    }
    for (m, _) in scenes {
        s.push_str(&format!("#[cfg(feature = \"scenes\")]\n#[path = \"{m}.rs\"]\npub mod {m};\n"));
    }
    s.push_str("\n/// WGSL libraries by module name (each starts with `#define_import_path shadefit::NAME`).\npub mod wgsl {\n");
    for spec in specs {
        let fam = family(spec);
        s.push_str(&format!(
            "    #[cfg(feature = \"{fam}\")]\n    pub const {}: &str = include_str!(\"../wgsl/{}.wgsl\");\n",
            spec.file.name.to_uppercase(),
            spec.file.name
        ));
    }
    for (m, _) in scenes {
        s.push_str(&format!(
            "    #[cfg(feature = \"scenes\")]\n    pub const {}: &str = include_str!(\"../wgsl/{m}.wgsl\");\n",
            m.to_uppercase()
        ));
    }
    s.push_str("\n    /// The WGSL library of a module, if its feature is enabled.\n    pub fn module(name: &str) -> Option<&'static str> {\n        match name {\n");
    for spec in specs {
        let fam = family(spec);
        s.push_str(&format!(
            "            #[cfg(feature = \"{fam}\")]\n            \"{}\" => Some({}),\n",
            spec.file.name,
            spec.file.name.to_uppercase()
        ));
    }
    for (m, _) in scenes {
        s.push_str(&format!("            #[cfg(feature = \"scenes\")]\n            \"{m}\" => Some({}),\n", m.to_uppercase()));
    }
    s.push_str("            _ => None,\n        }\n    }\n\n    /// Names of the modules compiled in.\n    pub const NAMES: &[&str] = &[\n");
    for spec in specs {
        s.push_str(&format!("        #[cfg(feature = \"{}\")]\n        \"{}\",\n", family(spec), spec.file.name));
    }
    for (m, _) in scenes {
        s.push_str(&format!("        #[cfg(feature = \"scenes\")]\n        \"{m}\",\n"));
    }
    s.push_str("    ];\n}\n");
    s.push_str("\n/// Every emitted function with its domain and CPU version (for GPU verification).\npub const FUNCTIONS: &[EmittedFunction] = &[\n");
    // Family spec kinds (e.g. RGB LUT lookups) and coefficient fields (see emit::fields) return
    // arrays: not scalar functions of this list; a table emitted as a texture only
    // (`form = "texture"`) has no WGSL function of that name (its `_load` takes a texture).
    let listed = |s: &&Spec| {
        !matches!(s.file.kind, Kind::Custom(_) | Kind::Fields) && s.file.emit.form.is_none_or(|f| f.has_const())
    };
    for spec in specs.iter().filter(listed) {
        let arity = spec.file.axis.len();
        let domain: Vec<String> = spec
            .file
            .axis
            .iter()
            .map(|a| format!("[{}, {}]", emit::f32_literal(a.range[0] as f32), emit::f32_literal(a.range[1] as f32)))
            .collect();
        let cpu = match arity {
            1 => "Cpu::One",
            2 => "Cpu::Two",
            _ => "Cpu::Three",
        };
        s.push_str(&format!(
            "    #[cfg(feature = \"{fam}\")]\n    EmittedFunction {{ module: \"{m}\", name: \"{f}\", domain: &[{d}], cpu: {cpu}({m}::{f}) }},\n",
            fam = family(spec),
            m = spec.file.name,
            f = spec.file.emit.function,
            d = domain.join(", ")
        ));
    }
    for (m, fns) in scenes {
        for (f, dom) in fns {
            let cpu = if dom.len() == 1 { "Cpu::One" } else { "Cpu::Two" };
            let d: Vec<String> = dom
                .iter()
                .map(|(a, b)| format!("[{}, {}]", emit::f32_literal(*a as f32), emit::f32_literal(*b as f32)))
                .collect();
            s.push_str(&format!(
                "    #[cfg(feature = \"scenes\")]\n    EmittedFunction {{ module: \"{m}\", name: \"{f}\", domain: &[{}], cpu: {cpu}({m}::{f}) }},\n",
                d.join(", ")
            ));
        }
    }
    s.push_str("];\n");
    Artifact { path: "src/emitted.rs".into(), contents: s.into() }
}

/// The runtime feature of a spec's module: its family's (`Family::feature`, through the catalog).
pub fn family(spec: &Spec) -> &str {
    spec.feature
}

/// Compare artifacts with the files under `root`: the paths that differ or are missing.
pub fn stale(root: &Path, artifacts: &[Artifact]) -> Vec<String> {
    artifacts
        .iter()
        .filter(|a| std::fs::read(root.join(&a.path)).map_or(true, |old| old != a.contents))
        .map(|a| a.path.display().to_string())
        .collect()
}

/// Hand-written files of the runtime crate under generated/src (never reported as orphans).
pub const HAND_WRITTEN: &[&str] = &["src/lib.rs"];

/// The folders under generated/ every build writes (other targets add theirs).
pub const OUTPUT_DIRS: &[&str] = &["wgsl", "src", "json", "data"];

/// Files under generated/{wgsl,src,json,data} that no spec produces (directories below
/// generated/src, and the files in [`HAND_WRITTEN`], are the runtime crate's own code).
pub fn orphans(root: &Path, artifacts: &[Artifact]) -> Vec<String> {
    orphans_in(root, artifacts, OUTPUT_DIRS)
}

/// Files directly under the folders `dirs` of generated/ that no artifact is (see [`orphans`]).
pub fn orphans_in(root: &Path, artifacts: &[Artifact], dirs: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    for &dir in dirs {
        let Ok(rd) = std::fs::read_dir(root.join(dir)) else { continue };
        let mut names: Vec<_> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        names.sort();
        for p in names {
            let rel = p.strip_prefix(root).unwrap_or(&p).to_path_buf();
            let hand_written = HAND_WRITTEN.iter().any(|h| rel == Path::new(h));
            if p.is_file() && !hand_written && !artifacts.iter().any(|a| a.path == rel) {
                out.push(rel.display().to_string());
            }
        }
    }
    out
}

pub use emit::write_all;

/// Cell payloads merged from shard files (`shadefit merge`), by spec name: a spec kind that
/// shards takes its payload here in `Mode::Fit` instead of computing its cells.
static MERGED: std::sync::Mutex<std::collections::BTreeMap<String, Vec<u8>>> = std::sync::Mutex::new(std::collections::BTreeMap::new());

/// Hand the merged payload of spec `name` to its next build.
pub fn set_merged(name: &str, payload: Vec<u8>) {
    MERGED.lock().unwrap_or_else(|e| e.into_inner()).insert(name.to_string(), payload);
}

/// The merged payload of spec `name`, if `merge` gave one (taken: a later build computes).
pub fn take_merged(name: &str) -> Option<Vec<u8>> {
    MERGED.lock().unwrap_or_else(|e| e.into_inner()).remove(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Orphans are the files directly under the output folders that no artifact is, sorted
    /// within each folder, folders in the order given: not the runtime crate's hand-written
    /// `src/lib.rs`, not a folder (its own code), not a file in a folder not listed, and a
    /// missing folder is skipped. Stale are the artifacts whose file differs or is missing.
    #[test]
    fn orphans_are_the_unproduced_files_of_the_output_folders_and_stale_the_changed_ones() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        for d in ["wgsl", "src/nested", "json", "hlsl"] {
            std::fs::create_dir_all(root.join(d)).unwrap();
        }
        for f in ["wgsl/b.wgsl", "wgsl/a.wgsl", "wgsl/kept.wgsl", "src/lib.rs", "src/x.rs", "src/nested/y.rs", "json/z.json", "hlsl/h.hlsl"] {
            std::fs::write(root.join(f), "old").unwrap();
        }
        let artifact = |p: &str, c: &str| Artifact { path: p.into(), contents: c.as_bytes().to_vec() };
        let artifacts = [artifact("wgsl/kept.wgsl", "old"), artifact("json/z.json", "new"), artifact("data/t.bin", "old")];
        assert_eq!(orphans(root, &artifacts), ["wgsl/a.wgsl", "wgsl/b.wgsl", "src/x.rs"]);
        assert_eq!(orphans_in(root, &artifacts, &["hlsl", "wgsl"]), ["hlsl/h.hlsl", "wgsl/a.wgsl", "wgsl/b.wgsl"]);
        assert_eq!(stale(root, &artifacts), ["json/z.json", "data/t.bin"]);
    }

    /// `x` moved `k` f32 steps away from zero (k < 0: towards it), by its bit pattern: for a
    /// finite non-zero f32 of either sign, consecutive bit patterns are consecutive floats.
    fn away_from_zero(x: f32, k: i32) -> f32 {
        assert!(x != 0.0 && x.is_finite());
        f32::from_bits((x.to_bits() as i64 + k as i64) as u32)
    }

    /// `committed_f32` against the contract in the module docs and ARCHITECTURE.md: a committed
    /// f32 coefficient may lie at most 64 ulps (the re-optimisation's move cap) from the f64
    /// coefficient rounded to nearest; one more is a coefficient the fit cannot have produced.
    #[test]
    fn committed_f32_coefficients_are_held_to_the_move_cap_exactly() {
        assert_eq!(f32round::MAX_ULPS, 64, "the documented cap");
        // P = c0 + c1 x + c2 x², Q = 1 + d1 x: positive and negative coefficients, one below 1.
        let model = fit::RationalModel::rational_1d("x", 2, 1);
        let c = DVector::from_vec(vec![0.3, -1.7, 12.5, -0.25]);
        // Rounded to nearest by the `as` cast (IEEE round-to-nearest-even), not by the code
        // under test.
        let r: Vec<f32> = c.iter().map(|&v| v as f32).collect();
        let check = |i: usize, k: i32| {
            let mut v = r.clone();
            v[i] = away_from_zero(v[i], k);
            let m = json!({
                "numerator_f32": v[..3].iter().map(|&x| x as f64).collect::<Vec<_>>(),
                "denominator_f32": v[3..].iter().map(|&x| x as f64).collect::<Vec<_>>(),
            });
            committed_f32(&model, &c, &m, "t")
        };
        for i in 0..4 {
            for k in [0, 1, -1, 64, -64] {
                let (num, den) = check(i, k).unwrap_or_else(|e| panic!("coefficient {i} moved {k} ulps rejected: {e}"));
                assert_eq!(num.len() + den.len(), 4);
            }
            for k in [65, -65, 512, -512] {
                match check(i, k) {
                    Err(BuildError::F32Coefficients { why, .. }) => assert!(why.contains("ulps"), "{why}"),
                    other => panic!("coefficient {i} moved {k} ulps accepted: {other:?}"),
                }
            }
        }
        // A fixed coefficient (here c1 = −1.7, emitted as its rounded value) may not move at all,
        // while the others still may: an unmoved fixed one is accepted beside a moved free one.
        let fixed = fit::RationalModel::new(fit::model::ModelParts {
            inputs: vec!["x".into()],
            numerator: ["1", "x", "x^2"].iter().map(|t| fit::model::Term::parse(t, &["x".to_string()]).unwrap()).collect(),
            denominator: vec![fit::model::Term::parse("x", &["x".to_string()]).unwrap()],
            fixed: vec![(1, -1.7)],
            ..fit::model::ModelParts::default()
        })
        .unwrap();
        let with = |moves: [i32; 4]| {
            let v: Vec<f64> = r.iter().zip(moves).map(|(&x, k)| away_from_zero(x, k) as f64).collect();
            committed_f32(&fixed, &c, &json!({"numerator_f32": v[..3].to_vec(), "denominator_f32": v[3..].to_vec()}), "t")
        };
        assert!(with([0, 0, 0, 0]).is_ok());
        assert!(with([3, 0, -5, 64]).is_ok(), "free coefficients moved, the fixed one not");
        for k in [1, -1] {
            match with([0, k, 0, 0]) {
                Err(BuildError::F32Coefficients { why, .. }) => assert!(why.contains("fixed"), "{why}"),
                other => panic!("fixed coefficient moved {k} ulp accepted: {other:?}"),
            }
        }
        // A value that is not an f32 at all, and a wrong count, are refused too.
        let m = json!({"numerator_f32": [0.3, r[1] as f64, r[2] as f64], "denominator_f32": [r[3] as f64]});
        assert!(matches!(committed_f32(&model, &c, &m, "t"), Err(BuildError::F32Coefficients { .. })));
        let m = json!({"numerator_f32": [r[0] as f64, r[1] as f64], "denominator_f32": [r[3] as f64]});
        assert!(matches!(committed_f32(&model, &c, &m, "t"), Err(BuildError::F32Coefficients { .. })));
    }

    /// `verify` against errors worked out by hand: max, rms and the worst point of the f64 fit,
    /// the same of the f32 values, and the error mapped back through an inverse (here x ↦ x²,
    /// inverted by the square root).
    #[test]
    fn verification_is_measured_from_the_errors() {
        let vx = vec![vec![0.2], vec![0.5], vec![0.8]];
        let truth: Vec<f64> = vx.iter().map(|x| x[0] * x[0]).collect();
        // f64 errors +0.01, −0.03, +0.02; f32 errors −0.04, 0, +0.005 (up to f32 rounding).
        let a64 = [truth[0] + 0.01, truth[1] - 0.03, truth[2] + 0.02];
        let a32 = [(truth[0] - 0.04) as f32, truth[1] as f32, (truth[2] + 0.005) as f32];
        let v = verify(Some(f64::sqrt), &vx, &truth, &a64, &a32);
        assert_eq!(v.points, 3);
        // Three squared errors summed: exact to a few ulps of 1e-3.
        assert!((v.max_abs_error - 0.03).abs() < 1e-12, "{}", v.max_abs_error);
        assert!((v.rms_error - (14e-4f64 / 3.0).sqrt()).abs() < 1e-12, "{}", v.rms_error);
        assert_eq!(v.worst_point, vec![0.5]);
        // The f32 values carry their rounding, below 1e-7 for values below 1.
        assert!((v.max_abs_error_f32 - 0.04).abs() < 1e-7, "{}", v.max_abs_error_f32);
        assert!((v.rms_error_f32 - ((16e-4f64 + 25e-6) / 3.0).sqrt()).abs() < 1e-7, "{}", v.rms_error_f32);
        // In parameter units, by hand: |√(x² + e) − x| at each point, the largest at x = 0.5
        // (√0.22 − 0.5); the same square roots, so equal to rounding.
        let p = v.max_abs_error_in_parameter.expect("an inverse was given");
        let expected = [(0.05f64.sqrt() - 0.2).abs(), (0.22f64.sqrt() - 0.5).abs(), (0.66f64.sqrt() - 0.8).abs()].into_iter().fold(0.0, f64::max);
        assert!((p - expected).abs() < 1e-12 && p > 1e-2, "{p} vs {expected}");
        // An exact fit has no error in either unit; no inverse, no parameter error.
        let exact = verify(Some(f64::sqrt), &vx, &truth, &truth, &truth.iter().map(|&t| t as f32).collect::<Vec<_>>());
        assert_eq!((exact.max_abs_error, exact.rms_error), (0.0, 0.0));
        assert!(exact.max_abs_error_in_parameter.unwrap() < 1e-15);
        assert_eq!(verify(None, &vx, &truth, &a64, &a32).max_abs_error_in_parameter, None);
    }

    /// A NaN from the f64 fit or the f32 code is the max error, so a spec's `max_error` bound
    /// fails on it (`f64::max` would have dropped it).
    #[test]
    fn a_nan_is_the_max_error() {
        let vx = vec![vec![0.2], vec![0.5], vec![0.8]];
        let truth = [0.9, 0.8, 0.7];
        let v = verify(Some(f64::sqrt), &vx, &truth, &[0.9, f64::NAN, 0.7], &[0.9, 0.8, f32::NAN]);
        assert!(v.max_abs_error.is_nan() && v.max_abs_error_f32.is_nan(), "{v:?}");
        assert_eq!(v.worst_point, vec![0.5]);
        assert!(v.max_abs_error_in_parameter.unwrap().is_nan());
        let v = verify(None, &vx, &truth, &truth, &[f32::NAN, 0.8, 0.7]);
        assert!(v.max_abs_error_f32.is_nan() && v.max_abs_error == 0.0, "{v:?}");
    }

    /// `tensor` is the full grid, first axis fastest, each axis at its own points.
    #[test]
    fn the_grid_runs_first_axis_fastest() {
        let axis = |name: &str, range: [f64; 2]| spec::AxisSpec { name: name.into(), range, count: 2, verify: None };
        let two = [axis("x", [0.0, 1.0]), axis("y", [-2.0, 2.0])];
        let want = vec![vec![0.0, -2.0], vec![0.5, -2.0], vec![1.0, -2.0], vec![0.0, 2.0], vec![0.5, 2.0], vec![1.0, 2.0]];
        assert_eq!(tensor(&two, &[3, 2]), want);
    }

    /// The `measured error:` line names each measure with its value (3 significant digits).
    #[test]
    fn the_header_line_carries_every_measure() {
        let v = Verification {
            points: 4081,
            max_abs_error: 1.2345e-3,
            rms_error: 6.789e-5,
            worst_point: vec![0.5],
            max_abs_error_f32: 1.2351e-3,
            rms_error_f32: 6.8e-5,
            max_abs_error_in_parameter: None,
        };
        assert_eq!(v.header_line(), "max abs 1.234e-3, rms 6.789e-5 over 4081 points (f32 code: max abs 1.235e-3, rms 6.800e-5)");
    }

    /// Compact JSON is the same JSON (parsed back equal) with number arrays on one line.
    #[test]
    fn compact_json_is_the_same_json() {
        let v = json!({"name": "t", "values": [0.5, -1.25e-7, 3.0], "texels": [[1.0, 2.0], [3.0, 4.0]], "empty": [], "nested": {"n": [1, 2]}});
        let text = compact_json(&v);
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), v);
        assert!(text.contains("\"values\": [0.5, -1.25e-7, 3.0]"), "{text}");
        assert!(text.contains("[1.0, 2.0]") && text.contains("[3.0, 4.0]"), "{text}");
        assert!(text.ends_with("}\n"));
        // A number array at the top level too: its `[` is the first line.
        assert_eq!(compact_json(&json!([0.5, 2.0, -3.0])), "[0.5, 2.0, -3.0]\n");
    }

    /// Arrays that are not all numbers are left as serde_json's pretty printer writes them:
    /// numbers before a string, an array or an object in the same array are not gathered.
    #[test]
    fn arrays_not_all_numbers_stay_pretty() {
        let v = json!({"mixed": [1.0, "x", 2.0], "ragged": [0.5, [1.0, 2.0]], "records": [3, {"k": 4}], "words": ["a", "b"]});
        let text = compact_json(&v);
        // Only the inner all-number array [1.0, 2.0] is gathered onto one line.
        assert_eq!(text, json_text(&v).replace("[\n      1.0,\n      2.0\n    ]", "[1.0, 2.0]"), "{text}");
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), v);
    }

    /// Max abs, rms and worst point worked out by hand; errors of either sign count.
    #[test]
    fn measure_is_max_rms_and_worst_point() {
        let points = vec![vec![0.0, 1.0], vec![1.0, 1.0], vec![2.0, 1.0]];
        let (max, rms, worst) = measure(&points, &[1.0, 2.0, 3.0], &[1.5, 1.0, 3.25]);
        assert_eq!(max, 1.0);
        // (0.25 + 1 + 0.0625) / 3, each term exact in binary.
        assert_eq!(rms, (1.3125f64 / 3.0).sqrt());
        assert_eq!(worst, vec![1.0, 1.0]);
        assert_eq!(measure(&points, &[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]), (0.0, 0.0, vec![0.0, 1.0]));
    }

    /// A NaN approximation is the worst point, and the max stays NaN past later finite errors.
    #[test]
    fn a_nan_is_worst() {
        let points = vec![vec![0.0], vec![1.0], vec![2.0]];
        let (max, rms, worst) = measure(&points, &[1.0, 2.0, 3.0], &[1.0, f64::NAN, 7.0]);
        assert!(max.is_nan() && rms.is_nan());
        assert_eq!(worst, vec![1.0]);
    }
}
