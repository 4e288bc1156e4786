//! Specs: the TOML files users edit (`fits/*.toml`), model specs for `shadefit fit`, and the
//! CSV data reader. Every error names the file, the line and the field.
//!
//! Schema (see README "Spec files"):
//!
//! ```toml
//! name = "my_fit"                  # output stem; must match the file stem
//! kind = "fit"                     # "fit" (a model fitted to samples), "table" (a LUT),
//!                                  # "fields", or a kind a family defines (`KindDef`)
//! quantity = "some-quantity"       # see `shadefit eval --help`
//! channel = "bias"                 # vector quantities: the channel fitted or tabulated
//! description = "..."
//!
//! [[axis]]                         # one per quantity parameter, in the quantity's order;
//!                                  # trailing parameters with a default may be left out
//! name = "x"
//! range = [0.0, 1.0]
//! count = 256                      # samples (uniform, ends included)
//! verify = 1024                    # verification grid for the measured error (fits/tables)
//!
//! [model]                          # kind = "fit" only
//! numerator = ["1", "x", "x^2", "x^3"]
//! denominator = ["x", "x^2"]       # the constant 1 is implicit
//! clamp = [0.0, 1.0]               # optional: clamp-aware objective
//! fixed = { "1" = 0.0 }            # optional: numerator terms fixed (prefix "den:" for denominator)
//! [[model.pin]]                    # optional: f(at) = value (value defaults to the integral)
//! at = [1.0]
//! eliminate = "x^3"
//!
//! [fit]
//! objective = "minimax"            # or "lsq", or "l4" (Σ r⁴: between the two)
//!
//! [emit]
//! function = "my_function"
//! args = ["x"]                     # optional: argument names (default: the axis names)
//! targets = ["hlsl", "spirv"]      # optional: more outputs than the WGSL module (emit::targets)
//! formats = ["dds", "exr"]         # specs with a texture: its files besides NAME.ktx2
//!                                  # (emit::formats; default dds, and exr for float texels)
//! ```

pub mod data;
pub mod input;
pub mod names;
pub mod table;

pub use names::is_identifier;
pub use table::{AxisMapping, Placement, Preset, TableLayout, TableTextureFormat, preset_spec_file};

use crate::fit::model::{Derived, ModelError, ModelParts, Pin, RationalModel, Term};
use crate::fit::Objective;
use crate::integrate::Estimate;
use crate::quantity::{QuantityDef, QuantityError};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Bad input: names where, and why.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}: field '{field}': {msg}")]
pub struct SpecError {
    pub file: String,
    pub line: usize,
    pub field: String,
    pub msg: String,
}

impl SpecError {
    pub fn new(file: &Path, line: usize, field: &str, msg: impl Into<String>) -> Self {
        SpecError { file: file.display().to_string(), line, field: field.into(), msg: msg.into() }
    }

    /// A file that [`input::read_input`] did not read (line 0, field `(file)`).
    pub fn unreadable(file: &Path, e: input::ReadError) -> Self {
        SpecError::new(file, 0, "(file)", e.to_string())
    }
}

/// 1-based line of the first `key =` or `[key]`/`[[key]]` in a TOML text (1 when absent).
pub fn line_of(text: &str, key: &str) -> usize {
    let last = key.rsplit('.').next().unwrap_or(key);
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let hit = t.starts_with(&format!("{last} "))
            || t.starts_with(&format!("{last}="))
            || t.starts_with(&format!("\"{last}\""))
            || t == format!("[{key}]")
            || t == format!("[[{key}]]");
        if hit {
            return i + 1;
        }
    }
    // A key of an inline table (`derived = { beta = "…", gamma = "…" }`).
    for (i, line) in text.lines().enumerate() {
        let inline = [format!("{{ {last} ="), format!("{{{last} ="), format!(", {last} ="), format!(",{last} =")];
        if inline.iter().any(|k| line.contains(k.as_str())) {
            return i + 1;
        }
    }
    1
}

/// The line of the `at` of the k-th `[[model.pin]]` (its header's line when it has none).
fn pin_line(text: &str, k: usize) -> usize {
    let lines: Vec<&str> = text.lines().collect();
    let Some(start) = lines.iter().enumerate().filter(|(_, l)| l.trim() == "[[model.pin]]").map(|(i, _)| i).nth(k) else {
        return line_of(text, "pin");
    };
    lines[start + 1..]
        .iter()
        .take_while(|l| !l.trim_start().starts_with('['))
        .position(|l| l.trim_start().starts_with("at ") || l.trim_start().starts_with("at="))
        .map_or(start + 1, |i| start + 2 + i)
}

pub fn line_of_offset(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].bytes().filter(|&b| b == b'\n').count() + 1
}

/// Parse TOML into `T`, turning syntax and schema errors into a [`SpecError`].
pub fn parse_toml<T: for<'de> Deserialize<'de>>(path: &Path, text: &str) -> Result<T, SpecError> {
    toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of_offset(text, s.start));
        let msg = e.message().to_string();
        // Schema errors name the field in backticks; syntax errors are named by the key on
        // the offending line.
        let named = (msg.starts_with("unknown field") || msg.starts_with("missing field"))
            .then(|| msg.split('`').nth(1).map(str::to_string))
            .flatten();
        let field = named.unwrap_or_else(|| {
            let l = text.lines().nth(line.saturating_sub(1)).unwrap_or("");
            match l.split_once('=') {
                Some((k, _)) => k.trim().trim_matches('"').to_string(),
                None => l.trim().trim_matches(|c| c == '[' || c == ']').to_string(),
            }
        });
        SpecError::new(path, line, &field, msg)
    })
}

/// Exactly two numbers (`[lo, hi]`): serde's fixed-size arrays would silently drop extra ones.
fn pair<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v = Vec::<f64>::deserialize(d)?;
    <[f64; 2]>::try_from(v.as_slice())
        .map_err(|_| serde::de::Error::invalid_length(v.len(), &"exactly two numbers [lo, hi]"))
}

fn optional_pair<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    pair(d).map(Some)
}

#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PinSpec {
    pub at: Vec<f64>,
    pub value: Option<f64>,
    pub eliminate: String,
}

/// A model in TOML, shared by fit specs and `shadefit fit --model FILE`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Feature names (fit specs take them from the axes; model files must give them).
    pub features: Option<Vec<String>>,
    pub numerator: Vec<String>,
    #[serde(default)]
    pub denominator: Vec<String>,
    /// Denominator term without a coefficient (default "1").
    pub denominator_lead: Option<String>,
    /// Derived features, name = "cos(x)" | "sin(x)" | "a + b*x" (over the inputs).
    #[serde(default)]
    pub derived: BTreeMap<String, String>,
    #[serde(default)]
    pub offset: f64,
    pub factor: Option<String>,
    #[serde(default, deserialize_with = "optional_pair")]
    pub clamp: Option<[f64; 2]>,
    #[serde(default)]
    pub fixed: BTreeMap<String, f64>,
    #[serde(default)]
    pub pin: Vec<PinSpec>,
}

impl ModelSpec {
    /// Build the model; `pin_value` supplies a pin's value when the spec leaves it out.
    pub fn build(
        &self,
        path: &Path,
        text: &str,
        inputs: Vec<String>,
        pin_value: &dyn Fn(&[f64]) -> Option<f64>,
    ) -> Result<RationalModel, SpecError> {
        let err = |field: &str, e: ModelError| SpecError::new(path, line_of(text, field), field, e.to_string());
        let mut derived = Vec::new();
        for (name, def) in &self.derived {
            if inputs.contains(name) {
                return Err(SpecError::new(path, line_of(text, name), name, "a derived feature cannot shadow an input"));
            }
            derived.push(Derived::parse(name, def, &inputs).map_err(|e| err(name, e))?);
        }
        let parts0 = ModelParts { inputs: inputs.clone(), derived: derived.clone(), ..ModelParts::default() };
        let features = parts0.features();
        if let Err(e) = crate::fit::model::check_features(&features) {
            // A derived feature is its own key; inputs are the model file's features or the axes.
            let field = match &e {
                ModelError::BadFeature { name, .. } if self.derived.contains_key(name) => name.clone(),
                _ if self.features.is_some() => "features".to_string(),
                _ => "axis".to_string(),
            };
            return Err(err(&field, e));
        }
        let parse_all = |field: &str, list: &[String]| -> Result<Vec<Term>, SpecError> {
            list.iter().map(|s| Term::parse(s, &features).map_err(|e| err(field, e))).collect()
        };
        let num = parse_all("numerator", &self.numerator)?;
        let den = parse_all("denominator", &self.denominator)?;
        if num.is_empty() {
            return Err(SpecError::new(path, line_of(text, "numerator"), "numerator", "needs at least one term"));
        }
        // A monomial in two terms of one polynomial makes their coefficients inseparable: the
        // fit is singular (only their sum is determined).
        for (field, terms) in [("numerator", &num), ("denominator", &den)] {
            let lead_one = field == "denominator" && self.denominator_lead.is_none();
            let mut seen: Vec<(&crate::fit::model::Monomial, usize)> = Vec::new();
            for (i, t) in terms.iter().enumerate() {
                for m in &t.monomials {
                    if lead_one && m.exps.iter().all(|&e| e == 0) {
                        return Err(SpecError::new(path, line_of(text, field), field, "the constant 1 is implicit in the denominator: remove the term '1'"));
                    }
                    if let Some(&(_, j)) = seen.iter().find(|(n, _)| *n == m) {
                        let msg = if j == i {
                            format!("term '{}' repeats a monomial", t.label)
                        } else if terms[j].label == t.label {
                            format!("term '{}' is given twice", t.label)
                        } else {
                            format!("terms '{}' and '{}' share a monomial: their coefficients cannot be told apart", terms[j].label, t.label)
                        };
                        return Err(SpecError::new(path, line_of(text, field), field, msg));
                    }
                    seen.push((m, i));
                }
            }
        }
        let factor = match &self.factor {
            Some(f) => Some(Term::parse(f, &features).map_err(|e| err("factor", e))?),
            None => None,
        };
        let mut fixed = Vec::new();
        for (key, &v) in &self.fixed {
            if !v.is_finite() {
                return Err(SpecError::new(path, line_of(text, "fixed"), "fixed", format!("'{key}' is not finite")));
            }
            let idx = if let Some(d) = key.strip_prefix("den:") {
                den.iter().position(|t| t.label == d.trim()).map(|i| num.len() + i)
            } else {
                num.iter().position(|t| t.label == key.trim())
            };
            let idx = idx.ok_or_else(|| err("fixed", ModelError::UnknownCoefficient(key.clone())))?;
            fixed.push((idx, v));
        }
        let mut pins = Vec::new();
        for p in &self.pin {
            if p.at.len() != inputs.len() || p.at.iter().any(|v| !v.is_finite()) {
                return Err(SpecError::new(
                    path,
                    line_of(text, "at"),
                    "pin.at",
                    format!("needs {} finite coordinates ({})", inputs.len(), inputs.join(", ")),
                ));
            }
            let eliminate = num
                .iter()
                .position(|t| t.label == p.eliminate.trim())
                .ok_or_else(|| err("eliminate", ModelError::UnknownCoefficient(p.eliminate.clone())))?;
            let value = match p.value {
                Some(v) if v.is_finite() => v,
                Some(_) => return Err(SpecError::new(path, line_of(text, "value"), "pin.value", "not finite")),
                None => pin_value(&p.at).ok_or_else(|| {
                    SpecError::new(path, line_of(text, "pin"), "pin.value", "missing (no quantity to take it from)")
                })?,
            };
            pins.push(Pin { at: p.at.clone(), value, eliminate });
        }
        let clamp = match self.clamp {
            Some([lo, hi]) if lo < hi => Some((lo, hi)),
            Some(_) => return Err(SpecError::new(path, line_of(text, "clamp"), "clamp", "needs min < max")),
            None => None,
        };
        if !self.offset.is_finite() {
            return Err(SpecError::new(path, line_of(text, "offset"), "offset", "not finite"));
        }
        let lead = match &self.denominator_lead {
            Some(t) => Some(Term::parse(t, &features).map_err(|e| err("denominator_lead", e))?),
            None => None,
        };
        RationalModel::new(ModelParts {
            numerator: num,
            denominator: den,
            lead,
            offset: self.offset,
            factor,
            fixed,
            pins,
            clamp,
            ..parts0
        })
        .map_err(|e| err("model", e))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Fit,
    Table,
    /// Two-stage fit: the quantity's inner basis at every outer grid point, each coefficient
    /// a rational field over the outer axes (see `fit::fields`).
    Fields,
    /// A kind a family defines ([`KindDef`]): its own checker spells the spec out as a common
    /// [`SpecFile`] and its own builder builds it. Never read from TOML directly.
    Custom(&'static str),
}

impl<'de> Deserialize<'de> for Kind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Kind, D::Error> {
        let s = String::deserialize(d)?;
        match s.as_str() {
            "fit" => Ok(Kind::Fit),
            "table" => Ok(Kind::Table),
            "fields" => Ok(Kind::Fields),
            other => Err(serde::de::Error::unknown_variant(other, &["fit", "table", "fields", "or a family kind"])),
        }
    }
}

impl Kind {
    /// The spec's spelling ("fit", "table", "fields" or the family kind's name).
    pub fn name(self) -> &'static str {
        match self {
            Kind::Fit => "fit",
            Kind::Table => "table",
            Kind::Fields => "fields",
            Kind::Custom(name) => name,
        }
    }
}

/// A spec kind of a family's own (`kind = "NAME"`): the checker returns the common spec it
/// enters the pipeline as (axes spelled out), or `None` when the text is not of this kind.
#[derive(Debug)]
pub struct KindDef {
    pub name: &'static str,
    pub spec_file: fn(&Path, &str) -> Result<Option<SpecFile>, SpecError>,
    /// Why `shadefit samples` has nothing to print for specs of this kind ({name}: the spec).
    pub samples_note: &'static str,
    /// The input hash its builder records in `generated/json/NAME.json` (the spec text and
    /// whatever else the build reads, e.g. a data file the spec names).
    pub input_hash: fn(&Spec) -> String,
}

/// What specs may name: every quantity and every family spec kind (built from the family
/// registry by the caller; the spec layer names no family).
#[derive(Debug, Default)]
pub struct Catalog {
    pub quantities: Vec<&'static QuantityDef>,
    pub kinds: Vec<&'static KindDef>,
    /// (quantity, the runtime crate's feature of the family that serves it).
    pub features: Vec<(&'static str, &'static str)>,
    /// Table axis mappings of the families' own, beside [`table::GENERIC_MAPPINGS`].
    pub mappings: Vec<&'static AxisMapping>,
}

impl Catalog {
    pub fn lookup(&self, name: &str) -> Result<&'static QuantityDef, QuantityError> {
        self.quantities.iter().copied().find(|q| q.name == name).ok_or_else(|| {
            QuantityError::Unknown(name.to_string(), self.quantities.iter().map(|q| q.name).collect::<Vec<_>>().join(", "))
        })
    }

    pub fn kind(&self, name: &str) -> Option<&'static KindDef> {
        self.kinds.iter().copied().find(|k| k.name == name)
    }

    /// The table axis mapping named `name`: a generic one or a family's.
    pub fn mapping(&self, name: &str) -> Option<&'static AxisMapping> {
        table::GENERIC_MAPPINGS.iter().chain(&self.mappings).copied().find(|m| m.name == name)
    }

    /// The runtime feature of the family serving quantity `name` ("core" when none is named).
    pub fn feature(&self, name: &str) -> &'static str {
        self.features.iter().find(|f| f.0 == name).map_or("core", |f| f.1)
    }
}

/// What a family spec kind spells out as a common [`SpecFile`] (read as a table, then marked
/// as the kind: the common parser reads only the generic kinds).
pub struct CustomSpec<'a> {
    pub kind: &'static str,
    pub name: &'a str,
    pub quantity: &'a str,
    pub description: &'a str,
    pub tolerance: f64,
    /// Axes as the common schema writes them (name, range, count, verify).
    pub axes: Vec<serde_json::Value>,
    pub function: &'a str,
}

impl CustomSpec<'_> {
    /// The common spec; an error names the file and the `kind` line. `[emit] targets` and
    /// `formats` are taken from the text as they are for every spec (the family's checker
    /// accepts the keys and leaves them to the common one; `build` checks the names).
    pub fn spec_file(self, path: &Path, text: &str) -> Result<SpecFile, SpecError> {
        let toml = toml::from_str::<toml::Value>(text).ok();
        let list = |key: &str| {
            toml.as_ref()?.get("emit")?.get(key)?.as_array()?.iter().map(|t| t.as_str().map(String::from)).collect::<Option<Vec<String>>>()
        };
        let (targets, formats) = (list("targets"), list("formats"));
        let v = serde_json::json!({
            "name": self.name,
            "kind": "table",
            "quantity": self.quantity,
            "description": self.description,
            "tolerance": self.tolerance,
            "axis": self.axes,
            "emit": {"function": self.function, "targets": targets, "formats": formats},
        });
        let mut file: SpecFile =
            serde_json::from_value(v).map_err(|e| SpecError::new(path, line_of(text, "kind"), "kind", e.to_string()))?;
        file.kind = Kind::Custom(self.kind);
        Ok(file)
    }
}

/// The spec file of a family kind that emits one module of functions: name, kind, quantity,
/// description and `[emit] function` (the functions' name prefix).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModuleFile {
    name: String,
    #[allow(dead_code)]
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    emit: ModulePrefix,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModulePrefix {
    /// Prefix of the emitted function names.
    function: String,
    /// Outputs besides the WGSL module (read from the text by [`CustomSpec::spec_file`]).
    #[allow(dead_code)]
    targets: Option<Vec<String>>,
}

/// For family kinds that emit one module of functions: the common spec of a module spec of kind
/// `kind` (see [`ModuleFile`]) serving `quantity`, with `tolerance` and `axes` spelled out, or
/// `None` when the text is not of that kind.
pub fn module_spec_file(
    path: &Path,
    text: &str,
    kind: &'static str,
    quantity: &str,
    tolerance: f64,
    axes: Vec<serde_json::Value>,
) -> Result<Option<SpecFile>, SpecError> {
    if !is_kind(text, kind) {
        return Ok(None);
    }
    let f: ModuleFile = parse_toml(path, text)?;
    if f.quantity != quantity {
        return Err(SpecError::new(path, line_of(text, "quantity"), "quantity", format!("kind = \"{kind}\" serves {quantity}, not '{}'", f.quantity)));
    }
    let common = CustomSpec { kind, name: &f.name, quantity: &f.quantity, description: &f.description, tolerance, axes, function: &f.emit.function };
    common.spec_file(path, text).map(Some)
}

/// For family LUT kinds: every side of a texture `resolution` is in [2, max] (the message
/// names the first that is not).
pub fn check_resolution(resolution: &[usize], max: usize) -> Result<(), String> {
    match resolution.iter().find(|&&n| !(2..=max).contains(&n)) {
        Some(n) => Err(format!("{n} texels: each side must be in [2, {max}]")),
        None => Ok(()),
    }
}

/// For family LUT kinds: a quadrature tolerance inside `[lo, hi]`; `why` says what bounds it.
pub fn check_tolerance(tolerance: f64, [lo, hi]: [f64; 2], why: &str) -> Result<(), String> {
    if tolerance >= lo && tolerance <= hi {
        Ok(())
    } else {
        Err(format!("{tolerance} must be in [{lo:e}, {hi:e}] ({why})"))
    }
}

/// Whether `text` is TOML whose `kind` is `kind` (a family kind's reader declines the others;
/// text that is not TOML is left to the common parser, which reports it).
pub fn is_kind(text: &str, kind: &str) -> bool {
    text.parse::<toml::Table>().is_ok_and(|t| t.get("kind").and_then(|k| k.as_str()) == Some(kind))
}

/// The environment variable that raises (or lowers) [`DEFAULT_GRID_BUDGET`].
pub const GRID_BUDGET_VAR: &str = "SHADEFIT_GRID_BUDGET";
/// Most points a spec's sampling or verification grid may have: 5·10⁷ (each point is at least
/// one integral; the bundled specs' largest grid has about 10⁶).
pub const DEFAULT_GRID_BUDGET: usize = 50_000_000;

/// The values [`GRID_BUDGET_VAR`] may take: from 2 (the smallest grid: one axis of the smallest
/// count) to 10⁹ points (their values alone are 8 GB of f64).
pub const GRID_BUDGET_RANGE: [usize; 2] = [2, 1_000_000_000];

/// The grid budget: [`DEFAULT_GRID_BUDGET`] unless [`GRID_BUDGET_VAR`] is set, then its value,
/// which must be a whole number in [`GRID_BUDGET_RANGE`] (the error names the variable).
pub fn grid_budget() -> Result<usize, String> {
    match std::env::var(GRID_BUDGET_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(DEFAULT_GRID_BUDGET),
        Err(std::env::VarError::NotUnicode(v)) => Err(grid_budget_error(&v.to_string_lossy())),
        Ok(v) => parse_grid_budget(&v),
    }
}

/// A value of [`GRID_BUDGET_VAR`] read as [`grid_budget`] reads it.
pub fn parse_grid_budget(v: &str) -> Result<usize, String> {
    let [lo, hi] = GRID_BUDGET_RANGE;
    v.trim().parse::<usize>().ok().filter(|n| (lo..=hi).contains(n)).ok_or_else(|| grid_budget_error(v))
}

fn grid_budget_error(v: &str) -> String {
    let [lo, hi] = GRID_BUDGET_RANGE;
    format!("{GRID_BUDGET_VAR}='{v}': must be a whole number of grid points in [{lo}, {hi}] (unset: {DEFAULT_GRID_BUDGET})")
}

#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    pub name: String,
    #[serde(deserialize_with = "pair")]
    pub range: [f64; 2],
    pub count: usize,
    /// Verification grid size along this axis (default: 4·count + 1).
    pub verify: Option<usize>,
    /// kind = "table": the axis's argument-to-parameter mapping (default `linear`).
    #[serde(default)]
    pub mapping: Option<String>,
    /// kind = "table": where its points lie (default `nodes`).
    #[serde(default)]
    pub placement: Option<Placement>,
}

impl AxisSpec {
    pub fn points(&self, n: usize) -> Vec<f64> {
        let [a, b] = self.range;
        if n == 1 {
            return vec![a];
        }
        (0..n).map(|i| if i + 1 == n { b } else { a + (b - a) * i as f64 / (n - 1) as f64 }).collect()
    }

    pub fn verify_count(&self) -> usize {
        self.verify.unwrap_or(4 * self.count + 1)
    }
}

#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    pub objective: Objective,
    /// Minimax only: the lowest max error among the iterates with rms ≤ this (on the fitting
    /// samples).
    pub max_rms: Option<f64>,
}

/// kind = "fields": per-coefficient offsets s_k (c_k = s_k + model), one per basis term.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FieldsSection {
    pub offsets: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EmitSection {
    /// Name of the emitted function (WGSL and Rust).
    pub function: String,
    /// Argument names of the emitted function, one per axis (default: the axis names).
    pub args: Option<Vec<String>>,
    /// kind = "fields": name of the emitted evaluator of the inner basis (`function` then
    /// names the function returning the coefficients).
    pub evaluator: Option<String>,
    /// Outputs besides the WGSL module (`emit::targets::Target` names: "wgsl-plain", "hlsl",
    /// "glsl", "glsl-es", "msl", "spirv", "c", "wesl"; `build` checks them); `build --target` adds to them.
    pub targets: Option<Vec<String>>,
    /// Specs that write a texture (`data/NAME.ktx2`): its file formats (`emit::formats`
    /// names: "ktx2", "ktx2-zstd", "dds", "exr", "c", "js"; NAME.ktx2 always; default DDS and,
    /// for float texels, EXR besides).
    pub formats: Option<Vec<String>>,
    /// kind = "table": the WGSL forms of the table (default `const`).
    pub form: Option<TableForm>,
    /// kind = "table" with a texture form: the texel format of `data/NAME.ktx2` (default
    /// `r32float`).
    pub texture_format: Option<TableTextureFormat>,
    /// `texture_format = "r32float"`: the engine requests WebGPU's `float32-filterable` feature,
    /// so the module also gets the linear-sampler helper `FUNCTION_sample` (without it an
    /// R32Float table is read by `textureLoad` only).
    #[serde(default)]
    pub float32_filterable: bool,
}

/// How a `kind = "table"` spec's WGSL holds its table: a `const` array read by `FUNCTION`
/// (`const`), a texture (`data/NAME.ktx2`) read by `FUNCTION_load` and, when the format is
/// filterable, `FUNCTION_sample` (`texture`), or both in one module (`both`).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum TableForm {
    #[default]
    Const,
    Texture,
    Both,
}

impl TableForm {
    pub fn has_const(self) -> bool {
        self != TableForm::Texture
    }

    pub fn has_texture(self) -> bool {
        self != TableForm::Const
    }
}

#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SpecFile {
    pub name: String,
    pub kind: Kind,
    pub quantity: String,
    /// Vector quantities: the channel a fit or table takes (see `shadefit eval --help`).
    pub channel: Option<String>,
    /// kind = "table", vector quantities: several channels, in the order the table holds them.
    pub channels: Option<Vec<String>>,
    /// kind = "table": the axes' names in the table's storage order (first fastest), which is
    /// also the emitted function's argument order (default: the `[[axis]]` order).
    pub order: Option<Vec<String>>,
    #[serde(default)]
    pub description: String,
    /// Integrator absolute tolerance for every sample.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// The largest max abs error of the emitted f32 code on the verification grid the build
    /// accepts; above it the build fails, naming the spec.
    pub max_error: Option<f64>,
    pub axis: Vec<AxisSpec>,
    pub model: Option<ModelSpec>,
    pub fit: Option<FitSection>,
    pub fields: Option<FieldsSection>,
    pub emit: EmitSection,
}

fn default_tolerance() -> f64 {
    1e-12
}

/// A validated spec with its text (hashed into generated headers).
#[derive(Debug, Clone)]
pub struct Spec {
    pub path: PathBuf,
    pub text: String,
    pub file: SpecFile,
    pub quantity: &'static QuantityDef,
    pub model: Option<RationalModel>,
    /// The channel of a vector quantity the spec takes (`channel`), by index.
    pub channel: Option<usize>,
    /// For a spec made in memory rather than read from fits/ (a fit of the user's own data):
    /// what its generated files name as their spec, e.g. the command that made them.
    pub origin: Option<String>,
    /// The runtime crate's feature that gates the spec's module (its quantity's family's).
    pub feature: &'static str,
    /// The cells of a sharded kind merged from shard files (`shadefit merge`): its builder takes
    /// them in `Mode::Fit` instead of computing them. None when read from fits/.
    pub merged: Option<std::sync::Arc<Vec<u8>>>,
    /// kind = "table": its channels, placements and mappings (None for the other kinds).
    pub table: Option<TableLayout>,
    /// Axes named by an alias of their parameter, and its conversion (see [`axis_param`]).
    pub convert: Conversions,
}

/// How a spec evaluates its quantity at a point of its axes: the channel it takes, and the
/// defaults of the trailing parameters its axes leave out.
#[derive(Debug, Clone, Copy)]
pub struct Sampler {
    pub quantity: &'static QuantityDef,
    pub channel: Option<usize>,
    pub tolerance: f64,
    /// The conversion of each leading axis named by an alias of its parameter (`roughness` for
    /// α): the point's coordinate is the alias's value (see [`axis_param`]).
    pub convert: Conversions,
}

/// The conversions of the axes named by aliases, by axis (the first [`MAX_ALIASED`] axes).
pub type Conversions = [Option<fn(f64) -> f64>; MAX_ALIASED];
/// How many leading axes may be named by an alias.
pub const MAX_ALIASED: usize = 4;

/// The parameter axis `i` named `name` gives: the quantity's parameter `i` itself, or one of its
/// aliases (its domain, and the conversion to the canonical parameter); None when `name` is
/// neither.
pub fn axis_param(quantity: &QuantityDef, i: usize, name: &str) -> Option<(&'static crate::quantity::ParamSpec, Option<fn(f64) -> f64>)> {
    let (params, aliases): (&'static [crate::quantity::ParamSpec], &'static [(crate::quantity::ParamSpec, usize, fn(f64) -> f64)]) = (quantity.params, quantity.aliases);
    let p = params.get(i)?;
    if p.name == name {
        return Some((p, None));
    }
    aliases.iter().find(|(a, k, _)| *k == i && a.name == name && i < MAX_ALIASED).map(|(a, _, f)| (a, Some(*f)))
}

/// The conversions of axes named `axis_names` (in parameter order), or None when one of them is
/// neither its parameter nor an alias of it.
pub fn conversions(quantity: &QuantityDef, axis_names: &[&str]) -> Option<Conversions> {
    let mut convert: Conversions = [None; MAX_ALIASED];
    for (i, n) in axis_names.iter().enumerate() {
        let (_, f) = axis_param(quantity, i, n)?;
        if let Some(slot) = convert.get_mut(i) {
            *slot = f;
        }
    }
    Some(convert)
}

impl Sampler {
    /// The sampler of `quantity` on its own parameters (no alias axes).
    pub fn new(quantity: &'static QuantityDef, channel: Option<usize>, tolerance: f64) -> Sampler {
        Sampler { quantity, channel, tolerance, convert: [None; MAX_ALIASED] }
    }

    /// The integral at `point` (the spec's axes, in order) to the spec's tolerance.
    pub fn eval(&self, point: &[f64]) -> Estimate {
        let q = self.quantity;
        let p = self.complete(point);
        match (self.channel, q.eval_channels) {
            (Some(c), Some(all)) => all(&p, self.tolerance)[c],
            _ => (q.eval)(&p, self.tolerance),
        }
    }

    /// The channels `picks` of a vector quantity at `point` (one evaluation of every channel);
    /// with no picks, [`Sampler::eval`].
    pub fn eval_channels(&self, point: &[f64], picks: &[usize]) -> Vec<Estimate> {
        match (picks, self.quantity.eval_channels) {
            ([_, ..], Some(all)) => {
                let every = all(&self.complete(point), self.tolerance);
                picks.iter().map(|&c| every[c]).collect()
            }
            _ => vec![self.eval(point)],
        }
    }

    /// `point` with the defaults of the trailing parameters it leaves out (Spec::parse admits
    /// only left-out parameters that have a default).
    fn complete(&self, point: &[f64]) -> Vec<f64> {
        let q = self.quantity;
        let converted = point.iter().enumerate().map(|(i, &v)| match self.convert.get(i).copied().flatten() {
            // As `QuantityDef::resolve`: the converted value clamped into the canonical domain
            // (rounding at its ends), the parameter's limit kept.
            Some(f) => {
                let (c, p) = (f(v), &q.params[i]);
                if p.limit == Some(c) { c } else { c.clamp(p.min, p.max) }
            }
            None => v,
        });
        converted.chain(q.params.get(point.len()..).unwrap_or(&[]).iter().map(|p| p.default.unwrap_or(f64::NAN))).collect()
    }
}

impl Spec {
    /// The spec's evaluator of its quantity (see [`Sampler`]).
    pub fn sampler(&self) -> Sampler {
        Sampler { quantity: self.quantity, channel: self.channel, tolerance: self.file.tolerance, convert: self.convert }
    }

    /// The name of the channel the spec takes, if any.
    pub fn channel_name(&self) -> Option<&'static str> {
        self.channel.map(|c| self.quantity.channels[c])
    }

    /// The quantity as reports name it: `QUANTITY[CHANNEL]` for a channel of a vector quantity,
    /// else the quantity's name.
    pub fn quantity_label(&self) -> String {
        match self.channel {
            Some(c) => format!("{}[{}]", self.quantity.name, self.quantity.channels[c]),
            None => self.file.quantity.clone(),
        }
    }

    pub fn load(path: &Path, catalog: &Catalog) -> Result<Spec, SpecError> {
        let text = input::read_input_text(path).map_err(|e| SpecError::unreadable(path, e))?;
        Spec::parse(path, text, catalog)
    }

    pub fn parse(path: &Path, text: String, catalog: &Catalog) -> Result<Spec, SpecError> {
        let mut custom = None;
        for k in &catalog.kinds {
            if let Some(f) = (k.spec_file)(path, &text)? {
                custom = Some(f);
                break;
            }
        }
        let file: SpecFile = match custom {
            Some(f) => f,
            None => parse_toml(path, &text)?,
        };
        let at = |field: &str, msg: String| SpecError::new(path, line_of(&text, field), field, msg);
        if let Some(why) = names::check_spec_name(&file.name) {
            return Err(at("name", why));
        }
        if path.file_stem().and_then(|s| s.to_str()) != Some(file.name.as_str()) {
            return Err(at("name", format!("'{}' must match the file name", file.name)));
        }
        if let Some(why) = names::check_identifier(&file.emit.function) {
            return Err(at("function", format!("not a valid function name: {why}")));
        }
        let quantity = catalog.lookup(&file.quantity).map_err(|e| at("quantity", e.to_string()))?;
        let n_args = match (file.kind, quantity.basis) {
            (Kind::Fields, Some(b)) => file.axis.len().saturating_sub(b.inner),
            _ => file.axis.len(),
        };
        if let Some(args) = &file.emit.args
            && (args.len() != n_args || args.iter().any(|a| names::check_argument(a).is_some()))
        {
            let why = args.iter().find_map(|a| names::check_argument(a)).unwrap_or_else(|| format!("{} given", args.len()));
            return Err(at("args", format!("needs {n_args} distinct identifiers, one per (outer) axis ({why})")));
        }
        if let Some(args) = &file.emit.args
            && let Some(dup) = args.iter().enumerate().find(|(i, a)| args[..*i].contains(a)).map(|(_, a)| a)
        {
            return Err(at("args", format!("'{dup}' is given twice")));
        }
        // Without `args`, the axis names are the arguments.
        if file.emit.args.is_none()
            && let Some((a, why)) = file.axis.iter().take(n_args).find_map(|a| names::check_argument(&a.name).map(|w| (a, w)))
        {
            return Err(at("args", format!("the axis '{}' would name an argument: {why}; give [emit] args", a.name)));
        }
        let args: Vec<&str> = match &file.emit.args {
            Some(a) => a.iter().map(String::as_str).collect(),
            None => file.axis.iter().take(n_args).map(|a| a.name.as_str()).collect(),
        };
        if let Some((field, why)) = names::check_emitted(&file.name, &file.emit.function, &args) {
            let why = if field == "args" && file.emit.args.is_none() { format!("{why}: an axis name would name it; give [emit] args") } else { why };
            return Err(at(field, why));
        }
        let form = file.emit.form.unwrap_or_default();
        if file.emit.form.is_some() && file.kind != Kind::Table {
            return Err(at("form", format!("applies to kind = \"table\" only, not \"{}\"", file.kind.name())));
        }
        if file.emit.texture_format.is_some() && !form.has_texture() {
            return Err(at("texture_format", "needs form = \"texture\" or \"both\"".into()));
        }
        let width = file.channels.as_ref().map_or(1, Vec::len);
        let format = file.emit.texture_format.unwrap_or(TableTextureFormat::default_for(width));
        if file.emit.float32_filterable && (!form.has_texture() || !format.is_32bit()) {
            let f32name = TableTextureFormat::default_for(width).name();
            let f16name = f32name.replace("32", "16");
            return Err(at("float32_filterable", format!("applies to a texture form with texture_format = \"{f32name}\" only ({f16name} is filterable in core WebGPU)")));
        }
        if form.has_texture() && !format.holds(width) {
            return Err(at("texture_format", format!("{} holds {} channels a texel, the table {width}", format.name(), format.texel_channels())));
        }
        if let Some(b) = file.max_error
            && !(b > 0.0 && b.is_finite())
        {
            return Err(at("max_error", format!("{b} must be positive and finite")));
        }
        if !(file.tolerance > 0.0 && file.tolerance < 1.0) {
            return Err(at("tolerance", format!("{} must be in (0, 1)", file.tolerance)));
        }
        let custom_kind = matches!(file.kind, Kind::Custom(_));
        if file.order.is_some() && file.kind != Kind::Table {
            return Err(at("order", format!("applies to kind = \"table\" only, not \"{}\"", file.kind.name())));
        }
        if file.channels.is_some() && file.kind != Kind::Table {
            return Err(at("channels", format!("applies to kind = \"table\" only, not \"{}\"", file.kind.name())));
        }
        if file.channels.is_some() && file.channel.is_some() {
            return Err(at("channels", "give either channel (one) or channels (several), not both".into()));
        }
        let channel = match (&file.channel, quantity.channels) {
            (None, []) => None,
            (None, _) if custom_kind || file.channels.is_some() => None,
            (None, names) => {
                return Err(at(
                    "quantity",
                    format!(
                        "'{}' has the channels [{}]; a fit or table takes one of them: add channel = \"{}\"",
                        quantity.name,
                        names.join(", "),
                        names[0]
                    ),
                ));
            }
            (Some(c), []) => return Err(at("channel", format!("'{}' is a scalar quantity; remove channel = \"{c}\"", quantity.name))),
            (Some(c), _) if custom_kind => return Err(at("channel", format!("kind = \"{}\" takes every channel; remove channel = \"{c}\"", file.kind.name()))),
            (Some(c), names) => match names.iter().position(|n| n == c) {
                Some(i) if quantity.eval_channels.is_some() => Some(i),
                _ => return Err(at("channel", format!("'{c}' is not a channel of '{}' (channels: {})", quantity.name, names.join(", ")))),
            },
        };
        let names: Vec<&str> = quantity.params.iter().map(|p| p.name).collect();
        let axis_names: Vec<&str> = file.axis.iter().map(|a| a.name.as_str()).collect();
        let left_out_have_defaults = quantity.params.get(axis_names.len()..).is_some_and(|rest| rest.iter().all(|p| p.default.is_some()));
        let own_axes = matches!(file.kind, Kind::Custom(_));
        // A family kind's axes are its quantity's own parameters; the generic kinds' may be aliases.
        let convert = if own_axes { (axis_names[..] == names[..axis_names.len().min(names.len())]).then_some([None; MAX_ALIASED]) } else { conversions(quantity, &axis_names) };
        let Some(convert) = convert.filter(|_| axis_names.len() <= names.len() && left_out_have_defaults) else {
            let optional: Vec<&str> = quantity.params.iter().filter(|p| p.default.is_some()).map(|p| p.name).collect();
            let note = if optional.is_empty() { String::new() } else { format!(" (trailing parameters with a default may be left out: {})", optional.join(", ")) };
            return Err(at(
                "axis",
                format!("axes must be the quantity's parameters in order: [{}], found [{}]{note}", names.join(", "), axis_names.join(", ")),
            ));
        };
        // A family kind spells its axes out from fields its own checker has checked (a fixed
        // parameter is an axis of one point; texel centres may lie outside `eval`'s domain).
        for (i, a) in file.axis.iter().enumerate().filter(|_| !own_axes) {
            let (p, _) = axis_param(quantity, i, &a.name).expect("checked above");
            let [lo, hi] = a.range;
            // An axis samples (and its verification grid interpolates) between its points: a
            // parameter of whole numbers only (an SH band, a scheme) has no values there.
            if p.integer {
                let line = text.lines().position(|l| l.trim_start().starts_with("name") && l.contains(&format!("\"{}\"", a.name))).map_or(1, |i| i + 1);
                return Err(SpecError::new(
                    path,
                    line,
                    "axis",
                    format!("axis '{}': the parameter takes whole numbers only ({}), so it cannot be a sampled axis", a.name, p.doc),
                ));
            }
            if a.mapping.is_some() || a.placement.is_some() {
                if file.kind != Kind::Table {
                    let field = if a.mapping.is_some() { "mapping" } else { "placement" };
                    return Err(at(field, format!("applies to kind = \"table\" only, not \"{}\"", file.kind.name())));
                }
                // A table's mapped range is checked with its mapping (table_layout).
            } else if !(lo.is_finite() && hi.is_finite() && lo < hi && p.admits(lo) && p.admits(hi)) {
                return Err(at(
                    "range",
                    format!("axis '{}' range [{lo}, {hi}] must be finite, increasing and inside [{}, {}]", a.name, p.min, p.max),
                ));
            }
            if a.count < 2 || a.count > 100_000 {
                return Err(at("count", format!("axis '{}' count {} must be in [2, 100000]", a.name, a.count)));
            }
            if a.verify_count() < 2 || a.verify_count() > 1_000_000 {
                return Err(at("verify", format!("axis '{}' verify count must be in [2, 1000000]", a.name)));
            }
        }
        for (field, what, counts) in [
            ("count", "sampling", file.axis.iter().map(|a| a.count).collect::<Vec<_>>()),
            ("verify", "verification", file.axis.iter().map(|a| a.verify_count()).collect()),
        ] {
            let budget = grid_budget().map_err(|why| SpecError::new(path, 0, GRID_BUDGET_VAR, why))?;
            let points = counts.iter().try_fold(1usize, |acc, &n| acc.checked_mul(n));
            if points.is_none_or(|p| p > budget) {
                let shown = points.map_or_else(|| "more than 2^64".to_string(), |p| p.to_string());
                return Err(at(
                    field,
                    format!(
                        "the {what} grid has {shown} points (the product of the axes' {field}s), over the budget of \
                         {budget}; thin the axes, or raise the budget with {GRID_BUDGET_VAR}=<points>"
                    ),
                ));
            }
        }
        let model = match (file.kind, &file.model) {
            (Kind::Fit, Some(m)) => {
                let Some(fit) = &file.fit else {
                    return Err(at("fit", "kind = \"fit\" needs a [fit] section".into()));
                };
                if let Some(cap) = fit.max_rms
                    && !(cap > 0.0 && cap.is_finite() && fit.objective == Objective::Minimax)
                {
                    return Err(at("max_rms", format!("{cap} must be positive and finite, with objective = \"minimax\"")));
                }
                let features: Vec<String> = file.axis.iter().map(|a| a.name.clone()).collect();
                if let Some(f) = &m.features
                    && f != &features
                {
                    return Err(at("features", "a fit spec takes its features from its axes; remove 'features'".into()));
                }
                // A pin is a point of the fit's domain (its axes' box), where the quantity is
                // integrated for its value as any sample is.
                for (k, pin) in m.pin.iter().enumerate() {
                    if let Some((v, a)) = pin.at.iter().zip(&file.axis).find(|(v, a)| !(**v >= a.range[0] && **v <= a.range[1])) {
                        return Err(SpecError::new(
                            path,
                            pin_line(&text, k),
                            "pin.at",
                            format!("{} is outside axis '{}' range [{}, {}]: a pin lies in the fit's domain", crate::quantity::short_number(*v), a.name, a.range[0], a.range[1]),
                        ));
                    }
                }
                let sampler = Sampler { quantity, channel, tolerance: file.tolerance, convert };
                Some(m.build(path, &text, features, &|x: &[f64]| Some(sampler.eval(x).value))?)
            }
            (Kind::Fit, None) => return Err(at("model", "kind = \"fit\" needs a [model] section".into())),
            (Kind::Table, Some(_)) => return Err(at("model", "kind = \"table\" takes no [model]".into())),
            (Kind::Table, None) => None,
            (Kind::Custom(_), _) => None,
            (Kind::Fields, m) => Some(fields_model(path, &text, &file, quantity, m.as_ref())?),
        };
        if file.kind != Kind::Fields && (file.fields.is_some() || file.emit.evaluator.is_some()) {
            return Err(at("fields", "[fields] and emit.evaluator belong to kind = \"fields\"".into()));
        }
        if file.kind == Kind::Table && file.axis.len() > 3 {
            return Err(at("axis", "tables have one, two or three axes".into()));
        }
        let table = match file.kind {
            Kind::Table => Some(table_layout(path, &text, &file, quantity, catalog)?),
            _ => None,
        };
        Ok(Spec { path: path.to_path_buf(), text, file, quantity, model, channel, origin: None, feature: catalog.feature(quantity.name), merged: None, table, convert })
    }
}

/// The layout of a kind = "table" spec: its channels (named ones of a vector quantity, each
/// once), and each axis's placement and mapping, whose range of arguments must lie where the
/// mapping is defined and map inside the parameter's domain.
pub(crate) fn table_layout(path: &Path, text: &str, file: &SpecFile, quantity: &QuantityDef, catalog: &Catalog) -> Result<TableLayout, SpecError> {
    let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
    let mut channels = Vec::new();
    if let Some(names) = &file.channels {
        if quantity.channels.is_empty() || quantity.eval_channels.is_none() {
            return Err(at("channels", format!("'{}' is a scalar quantity; remove channels", quantity.name)));
        }
        if !(1..=4).contains(&names.len()) {
            return Err(at("channels", format!("a table holds 1 to 4 channels, not {}", names.len())));
        }
        for (i, c) in names.iter().enumerate() {
            match quantity.channels.iter().position(|n| n == c) {
                Some(_) if names[..i].contains(c) => return Err(at("channels", format!("'{c}' is given twice"))),
                Some(k) => channels.push(k),
                None => return Err(at("channels", format!("'{c}' is not a channel of '{}' (channels: {})", quantity.name, quantity.channels.join(", ")))),
            }
        }
    }
    let mut axes = Vec::new();
    for (i, a) in file.axis.iter().enumerate() {
        // The domain of the parameter or of the alias the axis is named by.
        let p = axis_param(quantity, i, &a.name).map_or(&quantity.params[i], |(p, _)| p);
        let mapping = match &a.mapping {
            None => &table::LINEAR,
            Some(m) => catalog.mapping(m).ok_or_else(|| {
                let known: Vec<&str> = table::GENERIC_MAPPINGS.iter().chain(&catalog.mappings).map(|m| m.name).collect();
                at("mapping", format!("axis '{}': unknown mapping '{m}' (known: {})", a.name, known.join(", ")))
            })?,
        };
        let placement = a.placement.unwrap_or_default();
        if a.mapping.is_some() || a.placement.is_some() {
            let [lo, hi] = a.range;
            // The outermost points sampled: the ends, or at texel centres the first and the last
            // centre of the finer of the table and verification grids (both at centres).
            let (first, last) = match placement {
                Placement::Nodes => (lo, hi),
                Placement::Centres => {
                    let half = (hi - lo) * 0.5 / a.count.max(a.verify_count()) as f64;
                    (lo + half, hi - half)
                }
            };
            let [tlo, thi] = mapping.argument;
            let (plo, phi) = ((mapping.to_parameter)(first), (mapping.to_parameter)(last));
            let inside = |v: f64| p.admits(v);
            if !(lo.is_finite() && hi.is_finite() && lo < hi && first >= tlo && last <= thi && inside(plo) && inside(phi)) {
                return Err(at(
                    "range",
                    format!(
                        "axis '{}' range [{lo}, {hi}] must be finite, increasing, sampled inside [{tlo}, {thi}] (mapping '{}': {}) \
                         and map inside [{}, {}] (its outermost points {first}, {last} map to {plo}, {phi})",
                        a.name, mapping.name, mapping.doc, p.min, p.max
                    ),
                ));
            }
        }
        axes.push((placement, mapping));
    }
    let names: Vec<&str> = file.axis.iter().map(|a| a.name.as_str()).collect();
    let order = match &file.order {
        None => (0..names.len()).collect(),
        Some(o) => {
            let idx: Vec<Option<usize>> = o.iter().map(|n| names.iter().position(|a| a == n)).collect();
            let mut sorted: Vec<usize> = idx.iter().flatten().copied().collect();
            sorted.sort_unstable();
            if idx.iter().any(Option::is_none) || sorted != (0..names.len()).collect::<Vec<_>>() {
                return Err(at("order", format!("needs each axis once: [{}], found [{}]", names.join(", "), o.join(", "))));
            }
            idx.into_iter().flatten().collect()
        }
    };
    Ok(TableLayout { channels, axes, order })
}

/// The model shared by the coefficient fields of a kind = "fields" spec (features: the outer
/// axes), with its [fields], [fit] and [emit] sections checked.
fn fields_model(
    path: &Path,
    text: &str,
    file: &SpecFile,
    quantity: &QuantityDef,
    model: Option<&ModelSpec>,
) -> Result<RationalModel, SpecError> {
    let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
    let basis = quantity
        .basis
        .ok_or_else(|| at("quantity", format!("'{}' has no inner basis for kind = \"fields\"", quantity.name)))?;
    let m = model.ok_or_else(|| at("model", "kind = \"fields\" needs a [model] section".into()))?;
    let fit = file.fit.as_ref().ok_or_else(|| at("fit", "kind = \"fields\" needs a [fit] section".into()))?;
    if let Some(cap) = fit.max_rms
        && !(cap > 0.0 && cap.is_finite() && fit.objective == Objective::Minimax)
    {
        return Err(at("max_rms", format!("{cap} must be positive and finite, with objective = \"minimax\"")));
    }
    let fields = file.fields.as_ref().ok_or_else(|| at("fields", "kind = \"fields\" needs a [fields] section".into()))?;
    if fields.offsets.len() != basis.terms.len() || fields.offsets.iter().any(|v| !v.is_finite()) {
        return Err(at(
            "offsets",
            format!("needs {} finite values, one per basis term [{}]", basis.terms.len(), basis.terms.join(", ")),
        ));
    }
    match &file.emit.evaluator {
        Some(e) if names::check_identifier(e).is_none() && *e != file.emit.function => {}
        _ => return Err(at("evaluator", "kind = \"fields\" needs emit.evaluator, a function name other than emit.function".into())),
    }
    if m.offset != 0.0 {
        return Err(at("offset", "kind = \"fields\" takes per-coefficient offsets in [fields]".into()));
    }
    if !m.pin.is_empty() {
        return Err(at("pin", "kind = \"fields\" takes no pins".into()));
    }
    let n_outer = file.axis.len() - basis.inner;
    let features: Vec<String> = file.axis[..n_outer].iter().map(|a| a.name.clone()).collect();
    if let Some(f) = &m.features
        && f != &features
    {
        return Err(at("features", "the fields take their features from the outer axes; remove 'features'".into()));
    }
    m.build(path, text, features, &|_| None)
}

/// All specs in a folder (`*.toml`, sorted by name; `scenes/` is not read).
pub fn load_dir(dir: &Path, catalog: &Catalog) -> Result<Vec<Spec>, SpecError> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| SpecError::new(dir, 0, "(folder)", format!("cannot read: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml") && p.is_file())
        .collect();
    paths.sort();
    paths.iter().map(|p| Spec::load(p, catalog)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid budget's variable takes whole numbers in its range only; anything else is an
    /// error naming the variable, the value and the range (the process's environment is not
    /// touched: tests run in parallel).
    #[test]
    fn the_grid_budget_takes_whole_numbers_in_its_range() {
        assert_eq!(parse_grid_budget("2"), Ok(2));
        assert_eq!(parse_grid_budget(" 1000000000 "), Ok(1_000_000_000));
        for bad in ["abc", "-1", "1e30", "0", "1", "1000000001", "", "2.5", "99999999999999999999999"] {
            let e = parse_grid_budget(bad).unwrap_err();
            assert!(e.starts_with(&format!("{GRID_BUDGET_VAR}='{bad}': ")) && e.contains("[2, 1000000000]"), "{bad}: {e}");
        }
    }
}
