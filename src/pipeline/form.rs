//! `kind = "form"`: the user's own formula, measured, refitted and emitted like a built-in
//! published form. A form spec writes one expression per output (a channel of the quantity it
//! approximates, or the one `value` of a scalar quantity) in the expression language of
//! [`crate::fit::expr::parse`], over its arguments (one per `[[axis]]`), its named constants
//! (with their published values) and `let` bindings; its axes are the table kind's
//! (`mapping`, `placement`, `order`), so the grid it is measured on is laid out in the
//! coordinates the formula takes (e.g. perceptual roughness, with `mapping = "perceptual"`).
//!
//! The build integrates the quantity on the grid (to `tolerance`), measures the published
//! constants (max, rms, mean signed error, the worst point in the form's own arguments, per
//! output and over all of them), refits every constant (Nelder–Mead on the max or on the sum of
//! squared errors from the published constants and `starts − 1` deterministic perturbations of
//! them, in parallel; the best start wins, and the published constants stay when no refit beats
//! them once its constants are rounded to f32), and emits `FUNCTION_published` and `FUNCTION`
//! (the refit) as WGSL and Rust (every `[emit] targets` through the WGSL), inputs clamped to the
//! axes' ranges (NaN → the lower end), with `json/NAME.json` holding both constant sets and
//! both measures. `Mode::Committed` re-renders from that JSON. `shadefit measure FILE` does
//! the same without writing anything, and `shadefit validate` measures every form spec.
//!
//! ```toml
//! name = "my_env_brdf"
//! kind = "form"
//! quantity = "…"                   # what the outputs approximate (its channels: scale, bias)
//! source = "Where the constants come from"
//! tolerance = 1e-7                 # of the integrals on the grid
//! order = ["n_dot_v", "alpha"]     # optional: the grid's point order (first fastest)
//!
//! [[axis]]                          # the quantity's parameters in order, as a table's axes
//! name = "alpha"
//! mapping = "perceptual"           # the argument is r, alpha = r²
//! range = [0.0, 1.0]
//! count = 33
//! [[axis]]
//! name = "n_dot_v"
//! placement = "centres"
//! range = [0.0, 1.0]
//! count = 32
//!
//! [constants]                      # name = published value (listed by name)
//! c1 = 1.0
//!
//! [[let]]                          # bindings, in order (each may use the earlier ones)
//! name = "t"
//! value = "1 - n_dot_v"
//!
//! [outputs]                        # one expression per channel (a scalar quantity: value)
//! scale = "…"
//! bias = "…"
//!
//! [refit]                          # optional
//! objective = "minimax"            # or "lsq"
//! starts = 4
//!
//! [emit]
//! function = "my_env_brdf"
//! args = ["roughness", "n_dot_v"]  # one per [[axis]], in [[axis]] order
//! ```

use super::grid::{Grid, GridAxis};
use super::module::{module_built, module_json};
use super::{BuildError, Built, Mode, committed_json_with_hash, fmt_err, input_hash, spec_rel_path};
use crate::emit::header_lines;
use crate::emit::lang::{Lang, form_body};
use crate::fit::expr::Expr;
use crate::fit::expr::parse::{self, Scope};
use crate::fit::expr::program::Program;
use crate::fit::expr::tape::Tape;
use crate::fit::published::as_emitted;
use crate::fit::simplex::nelder_mead;
use crate::integrate::rng::SplitMix64;
use crate::quantity::QuantityDef;
use crate::spec::{self, AxisSpec, Catalog, CustomSpec, Placement, Spec, SpecError, SpecFile, is_kind, line_of, names, parse_toml};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use toml::Spanned;

pub const KIND: &str = "form";

/// The most constants a form may refit (Nelder–Mead's simplex grows with them).
pub const MAX_CONSTANTS: usize = 32;
/// Points of the clamp box's sample on which the emitted code must be finite (beside the grid).
pub const BOX_SAMPLE: usize = 4096;
/// The most refit starts.
pub const MAX_STARTS: usize = 16;

/// What a refit minimises over the grid's points and outputs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RefitObjective {
    /// The largest |error|.
    #[default]
    Minimax,
    /// The sum of squared errors.
    Lsq,
}

fn default_starts() -> usize {
    4
}

fn default_tolerance() -> f64 {
    1e-7
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RefitSection {
    #[serde(default)]
    objective: RefitObjective,
    #[serde(default = "default_starts")]
    starts: usize,
}

impl Default for RefitSection {
    fn default() -> Self {
        RefitSection { objective: RefitObjective::default(), starts: default_starts() }
    }
}

/// A `[[let]]` binding of a form or lobe spec.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LetSpec {
    name: String,
    value: Spanned<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FormEmit {
    function: String,
    args: Option<Vec<String>>,
    #[allow(dead_code)]
    targets: Option<Vec<String>>,
}

/// The spec file of a form spec.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FormFile {
    name: String,
    #[allow(dead_code)]
    kind: String,
    quantity: String,
    #[serde(default)]
    description: String,
    source: String,
    #[serde(default = "default_tolerance")]
    tolerance: f64,
    order: Option<Vec<String>>,
    axis: Vec<AxisSpec>,
    constants: BTreeMap<String, f64>,
    #[serde(default, rename = "let")]
    lets: Vec<LetSpec>,
    outputs: BTreeMap<String, Spanned<String>>,
    #[serde(default)]
    refit: RefitSection,
    emit: FormEmit,
}

/// A form spec, checked: its program, constants, grid and emitted names.
#[derive(Debug, Clone)]
pub struct Form {
    pub name: String,
    pub source: String,
    pub quantity: &'static QuantityDef,
    pub tolerance: f64,
    /// The quantity's channels the outputs approximate, in the quantity's order (empty: a
    /// scalar quantity's one value).
    pub channels: Vec<usize>,
    /// The outputs' names (the channels', or `value`).
    pub outputs: Vec<String>,
    /// The arguments, one per `[[axis]]`, in that order, and the box they are clamped to.
    pub args: Vec<String>,
    pub domain: Vec<(f64, f64)>,
    /// The constants by name, and their published values.
    pub constants: Vec<String>,
    pub published: Vec<f64>,
    /// Inputs: the arguments; constants: `constants`; result: the outputs (a vector of them
    /// when there are several).
    pub program: Program,
    /// The program compiled for the refit's inner loop (the same values bit for bit).
    tape: Tape,
    /// The grid in point order (first fastest), and for each of its axes the argument it gives.
    pub grid: Grid,
    order: Vec<usize>,
    pub objective: RefitObjective,
    pub starts: usize,
    pub function: String,
    /// Axes named by an alias of their parameter (`roughness` for α), converted when sampled.
    convert: spec::Conversions,
}

/// The spec-file column (1-based) of character `column` of the TOML string at `span`.
pub(crate) fn string_position(text: &str, span: std::ops::Range<usize>, column: usize) -> (usize, usize) {
    let line = spec::line_of_offset(text, span.start);
    let line_start = text[..span.start].rfind('\n').map_or(0, |i| i + 1);
    let quote = text[span.start..].chars().next().map_or(0, char::len_utf8);
    (line, text[line_start..span.start].chars().count() + quote + column)
}

/// The names a spec's expressions use (arguments, constants, bindings): each a distinct
/// identifier that neither the expression language nor the emitted module takes.
pub(crate) struct Names<'a> {
    path: &'a Path,
    reserved_by_module: Vec<String>,
    taken: Vec<(String, &'static str)>,
}

impl<'a> Names<'a> {
    pub(crate) fn new(path: &'a Path, reserved_by_module: Vec<String>) -> Self {
        Names { path, reserved_by_module, taken: Vec::new() }
    }

    /// Takes `name` as `is` ("a constant"…), or says why not (`what` names it in the message,
    /// the error is at `line`, `field`); an argument is checked as an emitted argument.
    pub(crate) fn claim(&mut self, name: &str, line: usize, field: &str, what: &str, argument: bool, is: &'static str) -> Result<(), SpecError> {
        let err = |msg: String| SpecError::new(self.path, line, field, msg);
        let why = if argument { names::check_argument(name) } else { names::check_identifier(name) };
        if let Some(why) = why {
            return Err(err(format!("{what} {why}")));
        }
        if parse::is_reserved(name) {
            return Err(err(format!("{what} '{name}' is a word of the expression language (its functions and pi)")));
        }
        if self.reserved_by_module.iter().any(|r| r == name) {
            return Err(err(format!("{what} '{name}' is a name the emitted module defines")));
        }
        if let Some((_, other)) = self.taken.iter().find(|(n, _)| n == name) {
            return Err(err(format!("{what} '{name}' is already {other}")));
        }
        self.taken.push((name.to_string(), is));
        Ok(())
    }

    /// Takes `[constants]` (each finite in f32, as the emitted code carries it): their names and
    /// values, in name order.
    pub(crate) fn constants(&mut self, text: &str, constants: &BTreeMap<String, f64>) -> Result<(Vec<String>, Vec<f64>), SpecError> {
        for (name, &v) in constants {
            self.claim(name, line_of(text, name), name, "constant", false, "a constant")?;
            if !v.is_finite() || !(v as f32).is_finite() {
                return Err(SpecError::new(self.path, line_of(text, name), name, format!("constant '{name}' = {v} must be finite in f32 (the emitted code carries it as f32)")));
            }
        }
        Ok((constants.keys().cloned().collect(), constants.values().copied().collect()))
    }

    /// Takes and parses `[[let]]` bindings in order (each may use the earlier ones): the
    /// bindings and their names.
    pub(crate) fn lets(&mut self, text: &str, lets: &[LetSpec], inputs: &[String], constants: &[String]) -> Result<(Vec<(String, Expr)>, Vec<String>), SpecError> {
        let mut out: Vec<(String, Expr)> = Vec::new();
        let mut let_names: Vec<String> = Vec::new();
        for l in lets {
            let field = format!("let {}", l.name);
            self.claim(&l.name, spec::line_of_offset(text, l.value.span().start), &field, "binding", false, "a binding")?;
            let e = parse::parse(l.value.get_ref(), Scope { inputs, constants, lets: &let_names }).map_err(|e| expression_error(self.path, text, &field, l.value.span(), e))?;
            let_names.push(l.name.clone());
            out.push((l.name.clone(), e));
        }
        Ok((out, let_names))
    }
}

/// A parse error of the expression at `span` as a spec error at its line and column in the file.
pub(crate) fn expression_error(path: &Path, text: &str, field: &str, span: std::ops::Range<usize>, e: parse::ParseError) -> SpecError {
    let (line, column) = string_position(text, span, e.column);
    SpecError::new(path, line, field, format!("column {column}: {}", e.message))
}

impl Form {
    /// Parse and check a form spec's text.
    pub fn parse(path: &Path, text: &str, catalog: &Catalog) -> Result<Form, SpecError> {
        Form::parse_file(path, text, catalog).map(|(form, _)| form)
    }

    /// [`Form::parse`], with the spec file it read.
    fn parse_file(path: &Path, text: &str, catalog: &Catalog) -> Result<(Form, FormFile), SpecError> {
        let f: FormFile = parse_toml(path, text)?;
        let at = |field: &str, msg: String| SpecError::new(path, line_of(text, field), field, msg);
        let quantity = catalog.lookup(&f.quantity).map_err(|e| at("quantity", e.to_string()))?;

        // Outputs: the quantity's channels, or its one value.
        let (channels, outputs): (Vec<usize>, Vec<String>) = if quantity.channels.is_empty() {
            if f.outputs.len() != 1 || !f.outputs.contains_key("value") {
                return Err(at("outputs", format!("'{}' is a scalar quantity: give its one output as value = \"…\"", quantity.name)));
            }
            (vec![], vec!["value".into()])
        } else {
            if quantity.eval_channels.is_none() {
                return Err(at("quantity", format!("'{}' does not evaluate its channels together", quantity.name)));
            }
            if let Some((bad, v)) = f.outputs.iter().find(|(k, _)| !quantity.channels.contains(&k.as_str())) {
                let line = spec::line_of_offset(text, v.span().start);
                return Err(SpecError::new(path, line, bad, format!("'{bad}' is not a channel of '{}' (channels: {})", quantity.name, quantity.channels.join(", "))));
            }
            let picks: Vec<usize> = (0..quantity.channels.len()).filter(|&c| f.outputs.contains_key(quantity.channels[c])).collect();
            (picks.clone(), picks.iter().map(|&c| quantity.channels[c].to_string()).collect())
        };
        if outputs.is_empty() || outputs.len() > 4 {
            return Err(at("outputs", format!("a form has 1 to 4 outputs, not {}", outputs.len())));
        }

        // Axes: the quantity's parameters in order, laid out as a table's.
        let names_q: Vec<&str> = quantity.params.iter().map(|p| p.name).collect();
        let axis_names: Vec<&str> = f.axis.iter().map(|a| a.name.as_str()).collect();
        let rest_default = quantity.params.get(axis_names.len()..).is_some_and(|r| r.iter().all(|p| p.default.is_some()));
        let convert = spec::conversions(quantity, &axis_names);
        let Some(convert) = convert.filter(|_| !axis_names.is_empty() && axis_names.len() <= names_q.len() && rest_default) else {
            return Err(at("axis", format!("axes must be the quantity's parameters in order: [{}], found [{}]", names_q.join(", "), axis_names.join(", "))));
        };
        for a in &f.axis {
            if !(1..=100_000).contains(&a.count) {
                return Err(at("count", format!("axis '{}' count {} must be in [1, 100000]", a.name, a.count)));
            }
            if a.verify.is_some() {
                return Err(at("verify", format!("axis '{}': a form is measured on its own points; remove verify", a.name)));
            }
        }
        let table = table_shape(&f).map_err(|e| at("axis", e))?;
        let layout = spec::table_layout(path, text, &table, quantity, catalog)?;
        let order = layout.order.clone();
        let grid = Grid {
            axes: order
                .iter()
                .map(|&k| GridAxis { range: f.axis[k].range, count: f.axis[k].count, placement: layout.axes[k].0, mapping: layout.axes[k].1, param: k })
                .collect(),
        };

        // Names: arguments, constants and bindings, each a distinct identifier no emitted
        // code or the language itself uses.
        let args: Vec<String> = f.emit.args.clone().unwrap_or_else(|| f.axis.iter().map(|a| a.name.clone()).collect());
        if args.len() != f.axis.len() {
            return Err(at("args", format!("needs {} names, one per [[axis]], found {}", f.axis.len(), args.len())));
        }
        if let Some(why) = names::check_identifier(&f.emit.function) {
            return Err(at("function", format!("not a valid function name: {why}")));
        }
        if let Some((field, why)) = names::check_emitted(&f.name, &f.emit.function, &[]) {
            return Err(at(field, why));
        }
        let mut names = Names::new(path, vec![f.emit.function.clone(), format!("{}_published", f.emit.function), names::input_helper(&f.name), "input".to_string()]);
        for a in &args {
            names.claim(a, line_of(text, "args"), "args", "argument", true, "an argument")?;
        }
        if f.constants.is_empty() || f.constants.len() > MAX_CONSTANTS {
            return Err(at("constants", format!("a form has 1 to {MAX_CONSTANTS} constants to refit, not {}", f.constants.len())));
        }
        let (constants, published) = names.constants(text, &f.constants)?;
        let expr_err = |field: &str, span: std::ops::Range<usize>, e: parse::ParseError| expression_error(path, text, field, span, e);
        let (lets, let_names) = names.lets(text, &f.lets, &args, &constants)?;
        let mut results = Vec::new();
        for o in &outputs {
            let text_o = &f.outputs[o];
            let e = parse::parse(text_o.get_ref(), Scope { inputs: &args, constants: &constants, lets: &let_names })
                .map_err(|e| expr_err(o, text_o.span(), e))?;
            results.push(e);
        }
        let result = if results.len() == 1 { results.pop().expect("one output") } else { Expr::Vector(results) };
        let program = Program { lets, result };
        let tape = Tape::compile(&program).expect("a parsed form is a scalar program");

        if !(f.tolerance > 0.0 && f.tolerance < 1.0) {
            return Err(at("tolerance", format!("{} must be in (0, 1)", f.tolerance)));
        }
        if !(1..=MAX_STARTS).contains(&f.refit.starts) {
            return Err(at("starts", format!("{} must be in [1, {MAX_STARTS}]", f.refit.starts)));
        }
        let domain: Vec<(f64, f64)> = f.axis.iter().map(|a| (a.range[0], a.range[1])).collect();
        let form = Form {
            name: f.name.clone(),
            source: f.source.clone(),
            quantity,
            tolerance: f.tolerance,
            channels,
            outputs,
            args,
            domain,
            constants,
            published,
            program,
            tape,
            grid,
            order,
            objective: f.refit.objective,
            starts: f.refit.starts,
            function: f.emit.function.clone(),
            convert,
        };
        // The published form must be finite on its grid in f64, and as the emitted f32 code there
        // and on a dense sample of its clamp box.
        let bad_f64 = form.inputs().into_iter().find_map(|x| {
            let v = form.program.eval_f64(&x, &form.published);
            v.iter().position(|v| !v.is_finite()).map(|k| (x, k))
        });
        if let Some((x, k)) = bad_f64.or_else(|| form.non_finite_f32(&form.published)) {
            let o = &form.outputs[k];
            let point: Vec<String> = form.args.iter().zip(&x).map(|(a, v)| format!("{a} = {v}")).collect();
            let line = spec::line_of_offset(text, f.outputs[o].span().start);
            return Err(SpecError::new(path, line, o, format!("output '{o}' is not finite at {} with the published constants", point.join(", "))));
        }
        Ok((form, f))
    }

    /// The form of a loaded spec (checked when the spec was parsed).
    pub fn from_spec(spec: &Spec, catalog: &Catalog) -> Result<Form, SpecError> {
        Form::parse(&spec.path, &spec.text, catalog)
    }

    /// The grid's points as the form's arguments ([[axis]] order), in point order.
    pub fn inputs(&self) -> Vec<Vec<f64>> {
        self.grid
            .points()
            .into_iter()
            .map(|t| {
                let mut x = vec![0.0; self.args.len()];
                for (k, &v) in t.iter().enumerate() {
                    x[self.order[k]] = v;
                }
                x
            })
            .collect()
    }

    /// The first point of the form's grid, or of a sample of its clamp box (at most
    /// [`BOX_SAMPLE`] points, ends included), where the emitted f32 code with constants `c`
    /// (rounded to f32) is not finite, with the output; `None` when it is finite at all of them.
    pub fn non_finite_f32(&self, c: &[f64]) -> Option<(Vec<f64>, usize)> {
        let c32: Vec<f32> = c.iter().map(|&v| v as f32).collect();
        let per_axis = ((BOX_SAMPLE as f64).powf(1.0 / self.args.len() as f64).floor() as usize).max(2);
        let sample = super::product(self.domain.iter().map(|&(lo, hi)| Placement::Nodes.points([lo, hi], per_axis)).collect());
        self.inputs().into_iter().chain(sample).find_map(|x| {
            let x32: Vec<f32> = x.iter().map(|&v| v as f32).collect();
            let v = self.program.eval_f32(&x32, &c32);
            v.iter().position(|v| !v.is_finite()).map(|k| (x, k))
        })
    }

    /// What the grid is, for reports.
    pub fn grid_doc(&self) -> String {
        let axes: Vec<String> = self
            .grid
            .axes
            .iter()
            .map(|a| {
                let arg = &self.args[a.param];
                let mapped = if a.mapping.name == "linear" { String::new() } else { format!(", {}", a.mapping.doc) };
                format!("{arg} ∈ [{}, {}] ({} {}{mapped})", a.range[0], a.range[1], a.count, if a.placement == Placement::Centres { "texel centres" } else { "nodes" })
            })
            .collect();
        format!("{} against {} at tolerance {:.0e}; outputs {}", axes.join(" × "), self.quantity.name, self.tolerance, self.outputs.join(", "))
    }
}

/// The form's axes as a table spec's, for the table kind's layout checks (every axis gets an
/// explicit placement, so that its range is checked against the parameter's domain).
fn table_shape(f: &FormFile) -> Result<SpecFile, String> {
    let axes: Vec<serde_json::Value> = f
        .axis
        .iter()
        .map(|a| {
            serde_json::json!({
                "name": a.name, "range": a.range, "count": a.count,
                "mapping": a.mapping, "placement": a.placement.unwrap_or_default().name(),
            })
        })
        .collect();
    serde_json::from_value(serde_json::json!({
        "name": f.name, "kind": "table", "quantity": f.quantity, "description": f.description,
        "tolerance": f.tolerance, "axis": axes, "order": f.order, "emit": {"function": f.emit.function},
    }))
    .map_err(|e| e.to_string())
}

/// For `Spec::parse`: the common spec of a form spec (checked), or `None` when the text is
/// not one.
pub fn spec_file(path: &Path, text: &str, catalog: &Catalog) -> Result<Option<SpecFile>, SpecError> {
    if !is_kind(text, KIND) {
        return Ok(None);
    }
    let (form, f) = Form::parse_file(path, text, catalog)?;
    // The common spec names the quantity's own parameters (an axis may be named by an alias:
    // the form's checker converted it).
    let axes = f.axis.iter().zip(form.quantity.params).map(|(a, p)| serde_json::json!({"name": p.name, "range": a.range, "count": a.count})).collect();
    let common = CustomSpec { kind: KIND, name: &form.name, quantity: &f.quantity, description: &f.description, tolerance: form.tolerance, axes, function: &form.function };
    common.spec_file(path, text).map(Some)
}

/// Error figures of one set of constants over the grid: every output, or one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    /// Mean of (form − integral).
    pub mean_signed_error: f64,
    /// Where |error| is largest: the arguments by name, and the output.
    pub worst: BTreeMap<String, f64>,
    pub worst_output: String,
}

/// A constant set's errors over every output and per output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    pub all: Stats,
    pub outputs: BTreeMap<String, Stats>,
}

/// The integral on a form's grid: per point, one value per output; with the largest error
/// estimate.
#[derive(Debug, Clone)]
pub struct Truth {
    pub inputs: Vec<Vec<f64>>,
    pub values: Vec<Vec<f64>>,
    pub max_error_estimate: f64,
}

impl Form {
    /// Integrate the quantity at every grid point (in parallel, in point order).
    pub fn truth(&self) -> Truth {
        let sampler = spec::Sampler { quantity: self.quantity, channel: None, tolerance: self.tolerance, convert: self.convert };
        let points = self.grid.points();
        let est = self.grid.sample(&sampler, &self.channels, &points);
        let max_error_estimate = est.iter().flatten().map(|e| e.error).fold(0.0, f64::max);
        Truth { inputs: self.inputs(), values: est.into_iter().map(|p| p.into_iter().map(|e| e.value).collect()).collect(), max_error_estimate }
    }

    /// The errors of constants `c` (the form in f64) against `truth`.
    pub fn errors(&self, truth: &Truth, c: &[f64]) -> Errors {
        let mut regs = Vec::new();
        let approx: Vec<Vec<f64>> = truth
            .inputs
            .iter()
            .map(|x| {
                let mut v = vec![0.0; self.outputs.len()];
                self.tape.eval(x, c, &mut regs, &mut v);
                v
            })
            .collect();
        let stats = |pick: Option<usize>| {
            let (mut points, mut t, mut a) = (Vec::new(), Vec::new(), Vec::new());
            for ((x, tv), av) in truth.inputs.iter().zip(&truth.values).zip(&approx) {
                for k in 0..self.outputs.len() {
                    if pick.is_none_or(|p| p == k) {
                        let mut p = x.clone();
                        p.push(k as f64);
                        points.push(p);
                        t.push(tv[k]);
                        a.push(av[k]);
                    }
                }
            }
            let (max_abs_error, rms_error, worst_point) = super::measure(&points, &t, &a);
            let mean_signed_error = a.iter().zip(&t).map(|(a, t)| a - t).sum::<f64>() / t.len().max(1) as f64;
            let worst = self.args.iter().cloned().zip(worst_point.iter().copied()).collect();
            let worst_output = worst_point.last().map_or(String::new(), |&k| self.outputs[k as usize].clone());
            Stats { points: t.len(), max_abs_error, rms_error, mean_signed_error, worst, worst_output }
        };
        Errors { all: stats(None), outputs: (0..self.outputs.len()).map(|k| (self.outputs[k].clone(), stats(Some(k)))).collect() }
    }

    /// The refit objective of constants `c` (infinite where the form is not finite).
    fn cost(&self, truth: &Truth, c: &[f64]) -> f64 {
        let mut acc = 0.0f64;
        let (mut regs, mut v) = (Vec::with_capacity(64), [0.0f64; 4]);
        for (x, t) in truth.inputs.iter().zip(&truth.values) {
            self.tape.eval(x, c, &mut regs, &mut v);
            for (k, &tk) in t.iter().enumerate() {
                let e = v[k] - tk;
                if !e.is_finite() {
                    return f64::INFINITY;
                }
                acc = match self.objective {
                    RefitObjective::Minimax => acc.max(e.abs()),
                    RefitObjective::Lsq => acc + e * e,
                };
            }
        }
        acc
    }

    /// The starts of the refit: the published constants, then perturbations of each by up to
    /// ±25 % (±0.1 for a zero), from a fixed seed.
    fn starts(&self) -> Vec<Vec<f64>> {
        let mut rng = SplitMix64(0x5eed_f0e3);
        let mut out = vec![self.published.clone()];
        for _ in 1..self.starts {
            out.push(self.published.iter().map(|&c| { let u = 2.0 * rng.next_f64() - 1.0; if c == 0.0 { 0.1 * u } else { c * (1.0 + 0.25 * u) } }).collect());
        }
        out
    }

    /// The refitted constants: the best of Nelder–Mead from every start (the first on a tie)
    /// whose emitted code is finite on the grid and the clamp box's sample, or the published
    /// ones when no refit beats them with its constants rounded to f32.
    pub fn refit(&self, truth: &Truth) -> Vec<f64> {
        let runs: Vec<(Vec<f64>, f64)> = self.starts().par_iter().map(|s| nelder_mead(|c| self.cost(truth, c), s)).collect();
        // A start whose emitted code is not finite on the clamp box's sample (a pole between
        // grid points) is dropped.
        let best = runs.into_iter().filter(|r| self.non_finite_f32(&r.0).is_none()).fold(None::<(Vec<f64>, f64)>, |b, r| match b {
            Some(b) if b.1 <= r.1 => Some(b),
            _ => Some(r),
        });
        let published = self.cost(truth, &self.published);
        match best {
            Some((c, _)) if self.cost(truth, &as_emitted(&c)) < published => c,
            _ => self.published.clone(),
        }
    }
}

/// A constant's two values, as the JSON lists them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Constant {
    pub name: String,
    pub published: f64,
    /// As refitted (the emitted code carries it as f32).
    pub refit: f64,
}

/// What a form's JSON commits besides the provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Committed {
    pub constants: Vec<Constant>,
    pub published_errors: Errors,
    /// The refit's errors with its constants rounded to f32, evaluated in f64.
    pub refit_errors: Errors,
    pub max_error_estimate: f64,
}

/// The committed constants and measures of form spec `spec` in `generated` (None when absent or
/// written for another version of the spec).
pub fn committed(generated: &Path, spec: &Spec) -> Option<Committed> {
    let v = committed_json_with_hash(generated, spec, &input_hash(spec)).ok()?;
    serde_json::from_value(v["form"].clone()).ok()
}

/// A form measured and refitted (what the build commits and `measure --refit` prints).
pub fn measure_and_refit(form: &Form, refit: bool) -> (Truth, Committed) {
    let truth = form.truth();
    let refitted = if refit { form.refit(&truth) } else { form.published.clone() };
    let committed = Committed {
        constants: form.constants.iter().zip(&form.published).zip(&refitted).map(|((n, &p), &r)| Constant { name: n.clone(), published: p, refit: r }).collect(),
        published_errors: form.errors(&truth, &form.published),
        refit_errors: form.errors(&truth, &as_emitted(&refitted)),
        max_error_estimate: truth.max_error_estimate,
    };
    (truth, committed)
}

pub fn build(spec: &Spec, mode: Mode, root: &Path, catalog: &Catalog) -> Result<Built, BuildError> {
    let form = Form::from_spec(spec, catalog)?;
    let name = spec.file.name.clone();
    let hash = input_hash(spec);
    let committed = match mode {
        Mode::Fit => measure_and_refit(&form, true).1,
        Mode::Committed => {
            let v = committed_json_with_hash(root, spec, &hash)?;
            let c: Committed = serde_json::from_value(v["form"].clone()).map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: format!("\"form\": {e}") })?;
            if c.constants.iter().map(|k| &k.name).ne(form.constants.iter()) {
                return Err(BuildError::NoCommitted { spec: name.clone(), why: "its constants are not the spec's".into() });
            }
            c
        }
    };
    let refit: Vec<f64> = committed.constants.iter().map(|k| k.refit).collect();
    let (p, r) = (&committed.published_errors.all, &committed.refit_errors.all);
    let err_line = format!(
        "max abs {} refitted ({:.2}x the published {}), rms {} (published {}) over {} values against {} ({}_published: the published constants)",
        fmt_err(r.max_abs_error),
        r.max_abs_error / p.max_abs_error,
        fmt_err(p.max_abs_error),
        fmt_err(r.rms_error),
        fmt_err(p.rms_error),
        r.points,
        form.quantity.name,
        form.function
    );
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let doc_lines = [format!("{}.", spec.file.description), format!("Source: {}.", form.source), format!("Measured on {}.", form.grid_doc())];
    let doc: Vec<&str> = doc_lines.iter().map(String::as_str).collect();
    let args: Vec<&str> = form.args.iter().map(String::as_str).collect();
    let outputs = form.outputs.join(", ");
    let render = |lang: Lang| {
        let c = lang.comment();
        let mut s = lang.preamble(&header, &name, &doc);
        for (function, consts, e, what) in [
            (format!("{}_published", form.function), &form.published, &committed.published_errors.all, "the published constants"),
            (form.function.clone(), &refit, &committed.refit_errors.all, "refitted constants"),
        ] {
            s += &format!(
                "\n{c} ({outputs}) with {what}: max abs {}, rms {}, mean signed {} over {} values; worst at {:?} ({}).\n",
                fmt_err(e.max_abs_error),
                fmt_err(e.rms_error),
                fmt_err(e.mean_signed_error),
                e.points,
                e.worst,
                e.worst_output
            );
            s += &lang.signature(&function, &args, form.outputs.len());
            s += &form_body(lang, &name, &form.program, &as_emitted(consts), &args, &form.domain);
        }
        s
    };
    let (wgsl, rust) = (render(Lang::Wgsl), render(Lang::Rust));
    let mut json = module_json(spec, &hash, KIND);
    json.insert("source".into(), form.source.clone().into());
    json.insert("grid".into(), form.grid_doc().into());
    json.insert("args".into(), serde_json::to_value(&form.args).expect("plain data"));
    json.insert("domain".into(), serde_json::to_value(&form.domain).expect("plain data"));
    json.insert("form".into(), serde_json::to_value(&committed).expect("plain data serialises"));
    Ok(module_built(&name, wgsl, rust, json, r.points, r.max_abs_error, r.rms_error))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::build_tests::{EXP, EXP_PAIR, json_of};
    use crate::pipeline::write_all;

    fn quantities() -> Catalog {
        Catalog { quantities: vec![&EXP, &EXP_PAIR], kinds: vec![], features: vec![], mappings: vec![] }
    }

    static KIND_DEF: crate::spec::KindDef = crate::spec::KindDef {
        name: KIND,
        spec_file: |p, t| spec_file(p, t, &quantities()),
        samples_note: "",
        input_hash: input_hash,
    };

    fn catalog() -> Catalog {
        Catalog { kinds: vec![&KIND_DEF], ..quantities() }
    }

    /// A quadratic for e^−x on [0, 2] with Taylor's constants at 0 (1, −1, ½), on 201 nodes.
    const QUADRATIC: &str = r#"name = "exp_quadratic"
kind = "form"
quantity = "exp-decay"
description = "A quadratic for e^-x"
source = "Taylor at 0"

[[axis]]
name = "x"
range = [0.0, 2.0]
count = 201

[constants]
c0 = 1.0
c1 = -1.0
c2 = 0.5

[[let]]
name = "xx"
value = "x * x"

[outputs]
value = "c0 + c1 * x + c2 * xx"

[refit]
starts = 2

[emit]
function = "exp_quadratic"
"#;

    fn parse(text: &str) -> Result<Spec, SpecError> {
        let name = text.split('"').nth(1).unwrap();
        Spec::parse(Path::new(&format!("fits/{name}.toml")), text.to_string(), &catalog())
    }

    /// Every fault of a form spec is refused naming the file, its line and field, and for an
    /// expression the column in the file: bad syntax, unknown names, a constant without a value
    /// (so an unknown name), a NaN constant, names the language or the module reserve, outputs
    /// that are not the quantity's channels, a form that is not finite on its grid.
    #[test]
    fn a_form_spec_is_checked_naming_file_line_field_and_column() {
        parse(QUADRATIC).expect("the quadratic is a valid form");
        let err = |from: &str, to: &str| {
            assert!(QUADRATIC.contains(from), "{from}");
            parse(&QUADRATIC.replacen(from, to, 1)).expect_err(to).to_string()
        };
        // `value = "c0 + c1 * x + c2 * xx"` is line 22; its string opens at column 9, so
        // character k of the expression is column 9 + k.
        let cases: &[(&str, &str, &[&str])] = &[
            ("c2 * xx\"", "c2 * xx +\"", &["fits/exp_quadratic.toml:22", "value", "column 33", "found the end"]),
            ("c1 * x", "c1 * y", &[":22", "column 20: unknown name 'y' (names: x, c0, c1, c2, xx, pi)"]),
            ("c2 = 0.5\n", "", &[":21", "column 24: unknown name 'c2'"]),
            ("c2 = 0.5", "c2 = nan", &[":15", "c2", "must be finite"]),
            ("c2 = 0.5", "c2 = 1e39", &[":15", "must be finite in f32"]),
            ("c2 = 0.5", "inversesqrt = 0.5", &["'inversesqrt' is a word of the expression language"]),
            ("c2 = 0.5", "min = 0.5", &["'min' is a WGSL built-in that emitted code calls"]),
            ("name = \"xx\"", "name = \"x\"", &["binding 'x' is already an argument"]),
            ("name = \"xx\"", "name = \"smooth\"", &["'smooth' is a WGSL keyword"]),
            ("name = \"xx\"", "name = \"exp_quadratic_input\"", &["a name the emitted module defines"]),
            ("value = \"x * x\"", "value = \"x * xx\"", &[":19", "let xx", "column 14: unknown name 'xx'"]),
            ("value = \"c0", "scale = \"c0", &["'exp-decay' is a scalar quantity"]),
            ("quantity = \"exp-decay\"", "quantity = \"exp-pair\"", &["'value' is not a channel of 'exp-pair' (channels: slow, fast)"]),
            ("c0 + c1 * x + c2 * xx", "c0 / (x - 1)", &[":22", "output 'value' is not finite at x = 1"]),
            ("range = [0.0, 2.0]", "range = [0.0, 3.0]", &["range", "inside [0, 2]"]),
            ("count = 201", "count = 0", &["count 0 must be in [1, 100000]"]),
            ("starts = 2", "starts = 99", &["starts", "must be in [1, 16]"]),
            ("source = \"Taylor at 0\"\n", "", &["missing field `source`"]),
        ];
        for (from, to, want) in cases {
            let e = err(from, to);
            for w in *want {
                assert!(e.contains(w), "{to}: {e}\n(wanted {w})");
            }
        }
    }

    /// Fit mode refits the quadratic minimax: its error equioscillates as Chebyshev's theorem
    /// says the best quadratic's does (four alternating extrema of equal size, to the 1 % the
    /// restarted Nelder–Mead reaches on this kinked objective), below Taylor's error (e^−2 − 1
    /// + 2 − 2 at x = 2: 0.135); the published errors are Taylor's, measured here from the
    /// closed form; Committed mode re-renders every file byte for byte.
    #[test]
    fn fit_refits_minimax_and_committed_mode_reproduces_the_files() {
        let spec = parse(QUADRATIC).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let generated = tmp.path().join("generated");
        let cat = catalog();
        let fit = build(&spec, Mode::Fit, &generated, &cat).unwrap();
        let v = json_of(&fit);
        let c: Committed = serde_json::from_value(v["form"].clone()).unwrap();
        let xs: Vec<f64> = (0..=200).map(|i| if i == 200 { 2.0 } else { 2.0 * i as f64 / 200.0 }).collect();
        let taylor: Vec<f64> = xs.iter().map(|&x| 1.0 - x + 0.5 * x * x - (-x).exp()).collect();
        let max_taylor = taylor.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        assert!((c.published_errors.all.max_abs_error - max_taylor).abs() < 1e-15, "{:?}", c.published_errors.all);
        assert_eq!(c.published_errors.all.worst["x"], 2.0);
        let k: Vec<f64> = c.constants.iter().map(|k| k.refit as f32 as f64).collect();
        let e: Vec<f64> = xs.iter().map(|&x| k[0] + k[1] * x + k[2] * x * x - (-x).exp()).collect();
        let max = e.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!((c.refit_errors.all.max_abs_error - max).abs() < 1e-15);
        assert!(max < 0.2 * max_taylor, "refit {max:e}, Taylor {max_taylor:e}");
        // The extrema: the ends and every interior local extremum of |e|.
        let extrema: Vec<f64> = (0..e.len())
            .filter(|&i| i == 0 || i + 1 == e.len() || (e[i].abs() >= e[i - 1].abs() && e[i].abs() >= e[i + 1].abs()))
            .map(|i| e[i])
            .collect();
        assert_eq!(extrema.len(), 4, "{extrema:?}");
        for w in extrema.windows(2) {
            assert!(w[0] * w[1] < 0.0, "alternating: {extrema:?}");
        }
        assert!(extrema.iter().all(|v| v.abs() > 0.99 * max), "equal: {extrema:?}");
        let wgsl = String::from_utf8(fit.artifacts[0].contents.clone()).unwrap();
        assert!(wgsl.contains("fn exp_quadratic_published(x: f32) -> f32 {") && wgsl.contains("fn exp_quadratic(x: f32) -> f32 {"), "{wgsl}");
        assert!(wgsl.contains("let xx = exp_quadratic_input(x, 0e0f, 2e0f) * exp_quadratic_input(x, 0e0f, 2e0f);"), "{wgsl}");
        write_all(&generated, &fit.artifacts).unwrap();
        let again = build(&spec, Mode::Committed, &generated, &cat).unwrap();
        for (a, b) in fit.artifacts.iter().zip(&again.artifacts) {
            assert_eq!(a.contents, b.contents, "{}", a.path.display());
        }
    }

    /// A form of two outputs is one vector function; each output is measured against its own
    /// channel (here exactly: e^−x and e^−2x written out, so every error is the f64 rounding of
    /// exp2 against exp, under 1e-15).
    #[test]
    fn outputs_are_measured_against_their_channels() {
        let text = QUADRATIC
            .replace("exp-decay", "exp-pair")
            .replace("value = \"c0 + c1 * x + c2 * xx\"", "fast = \"exp2(c2 * x)\"\nslow = \"exp2(c1 * x)\"")
            .replace("c1 = -1.0", &format!("c1 = {}", -std::f64::consts::LOG2_E))
            .replace("c2 = 0.5", &format!("c2 = {}", -2.0 * std::f64::consts::LOG2_E));
        let spec = parse(&text).unwrap();
        let form = Form::from_spec(&spec, &catalog()).unwrap();
        assert_eq!(form.outputs, ["slow", "fast"]);
        assert_eq!(form.channels, [0, 1]);
        let (_, c) = measure_and_refit(&form, false);
        assert!(c.published_errors.outputs["slow"].max_abs_error < 1e-15 && c.published_errors.outputs["fast"].max_abs_error < 1e-15, "{:?}", c.published_errors);
        assert_eq!(c.published_errors.all.points, 2 * 201);
        let wgsl = String::from_utf8(build(&spec, Mode::Fit, Path::new("unused"), &catalog()).unwrap().artifacts[0].contents.clone()).unwrap();
        assert!(wgsl.contains("-> vec2<f32> {"), "{wgsl}");
    }
}
