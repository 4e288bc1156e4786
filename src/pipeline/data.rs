//! A fit of the user's own data, emitted like a spec's (`shadefit fit --data FILE … --emit DIR`).
//!
//! The CSV's rows are the fitting samples and the verification points both: there is no
//! integral to sample elsewhere. The fit is made into a spec in memory, of kind `fit`, with one
//! axis per `--x` column spanning that column's range, or the `--domain` bounds given for it
//! (which must contain its rows): the box the emitted code clamps its inputs to and the
//! positivity proof covers. It goes through the build's own steps: f32
//! rounding and re-optimisation on the rows, the proof that the denominator is positive on the
//! box (a fit whose denominator is not proven positive is refused), verification in f64 and in
//! the emitted f32 arithmetic, and the WGSL module, Rust module and JSON of a fit spec, plus any
//! other targets. The files name as their spec the command that made them; their input hash
//! covers the command, the model file and the CSV bytes.

use super::{fit_from_coefficients, round_to_f32, BuildError, Built, Denominators, Reference};
use crate::fit::{self, Data, Objective, RationalModel};
use crate::integrate::Estimate;
use crate::quantity::QuantityDef;
use crate::spec::{names, AxisSpec, EmitSection, FitSection, Kind, Spec, SpecFile};
use std::path::Path;

/// The quantity of a spec made from data: the values come from the CSV, nothing is evaluated.
static DATA: QuantityDef = QuantityDef {
    name: "data",
    doc: "values read from a CSV file (shadefit fit --data)",
    params: &[],
    aliases: &[],
    eval: &|_, _| Estimate { value: f64::NAN, error: f64::NAN, evals: 0 },
    inverse: None,
    channels: &[],
    eval_channels: None,
    basis: None,
};

/// What `fit --data … --emit` was asked.
pub struct DataFit<'a> {
    /// The CSV file and its bytes (hashed into the outputs' input hash).
    pub csv: &'a Path,
    pub csv_bytes: &'a [u8],
    /// The `--x` columns (the emitted function's arguments unless `args` names others) and `--y`.
    pub x: &'a [String],
    pub y: &'a str,
    /// `--model` as given, and the text of the model file when it names one.
    pub model_arg: &'a str,
    pub model_text: Option<&'a str>,
    pub objective: Objective,
    /// The module name (`NAME.wgsl`, `NAME.rs`, `NAME.json`) and the function's name.
    pub name: &'a str,
    pub function: &'a str,
    pub args: Option<&'a [String]>,
    /// `--domain`: the box's bounds on the columns it names (the others span their rows).
    pub domain: &'a [(String, [f64; 2])],
}

impl DataFit<'_> {
    /// The command line that makes these files (what they name as their spec).
    pub fn command(&self) -> String {
        let mut c = format!(
            "shadefit fit --data {} --x {} --y {} --model {} --objective {} --emit DIR --name {} --function {}",
            self.csv.file_name().and_then(|s| s.to_str()).unwrap_or("?"),
            self.x.join(","),
            self.y,
            self.model_arg,
            self.objective.name(),
            self.name,
            self.function
        );
        if let Some(a) = self.args {
            c.push_str(&format!(" --args {}", a.join(",")));
        }
        if !self.domain.is_empty() {
            let items: Vec<String> = self.domain.iter().map(|(n, [lo, hi])| format!("{n}={lo:?}:{hi:?}")).collect();
            c.push_str(&format!(" --domain {}", items.join(",")));
        }
        c
    }
}

/// The box of a data fit, per `x` column: the range its rows span, or the `domain` bounds
/// given for it, which must contain every row. The error names `--domain` and the column.
pub fn data_box(x: &[String], data: &Data, domain: &[(String, [f64; 2])]) -> Result<Vec<[f64; 2]>, String> {
    let mut out = Vec::with_capacity(x.len());
    for (j, col) in x.iter().enumerate() {
        let (lo, hi) = data.x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[j]), hi.max(p[j])));
        match domain.iter().find(|(n, _)| n == col) {
            Some((_, [dlo, dhi])) if !(*dlo <= lo && hi <= *dhi) => {
                return Err(format!(
                    "--domain {col}={dlo:?}:{dhi:?}: the data of column '{col}' lies outside it (its rows span [{lo:?}, {hi:?}])"
                ));
            }
            Some((_, b)) => out.push(*b),
            None => out.push([lo, hi]),
        }
    }
    Ok(out)
}

/// The spec a data fit stands for. Errors name the option at fault.
fn spec_of(req: &DataFit, model: RationalModel, data: &Data) -> Result<Spec, BuildError> {
    let input = |msg: String| BuildError::Input { spec: req.csv.display().to_string(), msg };
    if let Some(why) = names::check_spec_name(req.name) {
        return Err(input(format!("--name '{}': {why}", req.name)));
    }
    if let Some(why) = names::check_identifier(req.function) {
        return Err(input(format!("--function '{}': not a valid function name: {why}", req.function)));
    }
    let args: Vec<String> = req.args.map(<[String]>::to_vec).unwrap_or_else(|| req.x.to_vec());
    if args.len() != req.x.len() {
        return Err(input(format!("--args names {} arguments for {} --x columns", args.len(), req.x.len())));
    }
    for (i, a) in args.iter().enumerate() {
        if let Some(why) = names::check_argument(a) {
            let opt = if req.args.is_some() { "--args" } else { "--x (the arguments' names; give --args)" };
            return Err(input(format!("{opt} '{a}': {why}")));
        }
        if args[..i].contains(a) {
            return Err(input(format!("argument '{a}' is named twice")));
        }
    }
    let arg_names: Vec<&str> = args.iter().map(String::as_str).collect();
    if let Some((field, why)) = names::check_emitted(req.name, req.function, &arg_names) {
        let opt = if field == "function" { "--function" } else if req.args.is_some() { "--args" } else { "--x (the arguments' names; give --args)" };
        return Err(input(format!("{opt}: {why}")));
    }
    let bounds = data_box(req.x, data, req.domain).map_err(input)?;
    let mut axis = Vec::new();
    for (j, (col, &[lo, hi])) in req.x.iter().zip(&bounds).enumerate() {
        if !(lo < hi) {
            return Err(input(format!("column '{col}' takes one value only: the fit's box needs a range")));
        }
        let mut distinct: Vec<f64> = data.x.iter().map(|p| p[j]).collect();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        axis.push(AxisSpec { name: col.clone(), range: [lo, hi], count: distinct.len(), verify: Some(data.len()), mapping: None, placement: None });
    }
    let origin = req.command();
    let mut text = format!("{origin}\n");
    if let Some(m) = req.model_text {
        text.push_str("--- model file\n");
        text.push_str(m);
        text.push('\n');
    }
    text.push_str("--- data\n");
    text.push_str(&String::from_utf8_lossy(req.csv_bytes));
    let file = SpecFile {
        name: req.name.to_string(),
        kind: Kind::Fit,
        quantity: format!("data: column {} of {}", req.y, req.csv.file_name().and_then(|s| s.to_str()).unwrap_or("?")),
        channel: None,
        channels: None,
        order: None,
        description: format!("Fit of column {} of {} over {}", req.y, req.csv.display(), req.x.join(", ")),
        tolerance: 1e-12,
        max_error: None,
        axis,
        model: None,
        fit: Some(FitSection { objective: req.objective, max_rms: None }),
        fields: None,
        emit: EmitSection {
            function: req.function.to_string(),
            args: req.args.map(<[String]>::to_vec),
            evaluator: None,
            targets: None,
            formats: None,
            form: None,
            texture_format: None,
            float32_filterable: false,
        },
    };
    Ok(Spec { path: req.csv.to_path_buf(), text, file, quantity: &DATA, model: Some(model), channel: None, convert: [None; crate::spec::MAX_ALIASED], origin: Some(origin), feature: "core", merged: None, table: None })
}

/// Fit `data` (read from `req.csv`) with `model` and render the files of a fit spec: the fit
/// as the CLI's `fit --data` makes it (rescaled where the data is huge or tiny), its f32
/// coefficients re-optimised on the rows, every denominator proven positive on the data's box.
pub fn fit_and_render(req: &DataFit, model: RationalModel, data: Data, fitted: fit::Fit) -> Result<Built, BuildError> {
    let spec = spec_of(req, model, &data)?;
    let f32s = round_to_f32(&spec, &fitted.coefficients, &data)?;
    let reference = Reference { points: data.x, values: data.y };
    fit_from_coefficients(&spec, fitted.coefficients, Some(fitted.report), Some(f32s), &reference, Denominators::Proven)
}
