//! Command implementations behind `main`: parse nothing, print results. Errors that are the
//! user's input come back as [`InputError`] (exit code 2); everything else is a job failure.

use crate::fit::{self, Data, FitOptions, Objective, RationalModel};
use crate::build;
use crate::family;
use crate::pipeline;
use crate::spec::{self, data::read_csv, ModelSpec, Spec};
use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Bad input: exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

fn input_err(e: impl std::fmt::Display) -> anyhow::Error {
    InputError(e.to_string()).into()
}

pub use crate::build::Paths;

/// The environment variables the library reads, checked before any command runs, so that a
/// bad value is reported as itself rather than at the first spec it would change.
pub fn check_environment() -> Result<()> {
    spec::grid_budget().map(|_| ()).map_err(input_err)
}

/// Registers the lobe specs of `fits` (their quantities join the catalog); a bad one is bad
/// input naming its file, line and field.
pub fn register_lobes(fits: &std::path::Path) -> Result<()> {
    crate::family::register_lobes(fits).map(|_| ()).map_err(input_err)
}

/// `name=value` arguments as a map (each name once, each value a number).
fn parse_params(params: &[String]) -> Result<BTreeMap<String, f64>> {
    let mut named = BTreeMap::new();
    for p in params {
        let (k, v) = p
            .split_once('=')
            .ok_or_else(|| input_err(format!("parameter '{p}' must be name=value")))?;
        let v: f64 = v
            .trim()
            .parse()
            .map_err(|_| input_err(format!("parameter '{}': '{}' is not a number", k.trim(), v.trim())))?;
        if named.insert(k.trim().to_string(), v).is_some() {
            return Err(input_err(format!("parameter '{}' is given twice", k.trim())));
        }
    }
    Ok(named)
}

pub fn eval(name: &str, params: &[String], as_json: bool) -> Result<()> {
    let q = family::catalog().lookup(name).map_err(input_err)?;
    let named = parse_params(params)?;
    let canonical = q.resolve(&named).map_err(input_err)?;
    if let Some(multi) = q.eval_channels {
        let est = multi(&canonical, 1e-12);
        let values: Vec<f64> = est.iter().map(|e| e.value).collect();
        let error = est.iter().map(|e| e.error).fold(0.0, f64::max);
        if as_json {
            let out = json!({
                "quantity": q.name,
                "params": named,
                "value": values,
                "channels": q.channels,
                "error_estimate": error,
            });
            println!("{out}");
        } else {
            let parts: Vec<String> = q.channels.iter().zip(&values).map(|(c, v)| format!("{c} {v:.17e}")).collect();
            println!("{} = {}  (error estimate {error:.1e})", q.name, parts.join(", "));
        }
        return Ok(());
    }
    let est = (q.eval)(&canonical, 1e-12);
    if as_json {
        let out = json!({
            "quantity": q.name,
            "params": named,
            "value": est.value,
            "error_estimate": est.error,
        });
        println!("{out}");
    } else {
        println!("{} = {:.17e}  (error estimate {:.1e})", q.name, est.value, est.error);
    }
    Ok(())
}

fn load_specs(paths: &Paths, only: &[String]) -> Result<Vec<Spec>> {
    build::load_specs(paths, only).map_err(build_err)
}

/// A build error for the CLI edge: the user's input exits 2, a failed job 1.
fn build_err(e: build::Error) -> anyhow::Error {
    if e.is_input() {
        // The whole chain in the message: InputError keeps only its text.
        input_err(format!("{:#}", anyhow::Error::new(e)))
    } else {
        anyhow::Error::new(e)
    }
}

fn progress(len: usize, what: &str) -> ProgressBar {
    // indicatif draws only on a terminal: pipes and CI stay quiet.
    let pb = ProgressBar::new(len as u64);
    pb.set_style(ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}").expect("valid template"));
    pb.set_message(what.to_string());
    pb
}

/// `build --shard K/N`: the shard files of the named specs.
pub fn build_shard(paths: &Paths, only: &[String], shard: &str, out: &Path) -> Result<()> {
    let start = std::time::Instant::now();
    let ks = build::parse_shard(shard).map_err(build_err)?;
    let files = build::shard(paths, only, ks, out).map_err(build_err)?;
    for f in &files {
        println!("{}", f.display());
    }
    println!("{} shard file(s); {:.1} s wall on {} thread(s)", files.len(), start.elapsed().as_secs_f64(), rayon::current_num_threads());
    Ok(())
}

/// `merge FILES…`: the merged build of the shards' specs.
pub fn merge(paths: &Paths, files: &[PathBuf]) -> Result<()> {
    let start = std::time::Instant::now();
    let summary = build::merge(paths, files, &|_| {}).map_err(build_err)?;
    for (b, _) in &summary.built {
        println!("{:<22} merged from shards ({} points)", b.name, b.verification.points);
    }
    println!("{} file(s) written, {} unchanged; {:.1} s wall", summary.written, summary.files - summary.written, start.elapsed().as_secs_f64());
    Ok(())
}

pub fn build(paths: &Paths, only: &[String], check: bool, force: bool, targets: &[crate::emit::targets::Target]) -> Result<()> {
    let start = std::time::Instant::now();
    let pb = progress(0, if check { "check" } else { "build" });
    let summary = build::run(paths, only, check, force, targets, &|total| {
        pb.set_length(total as u64);
        pb.inc(1);
    });
    pb.finish_and_clear();
    let summary = summary.map_err(build_err)?;
    if check {
        if summary.stale.is_empty() {
            println!("generated/ is up to date ({} files from {} specs)", summary.files, summary.specs);
            return Ok(());
        }
        for p in &summary.stale {
            println!("stale: {p}");
        }
        return Err(build::Error::Stale { count: summary.stale.len() }.into());
    }
    for (b, t) in &summary.built {
        let v = &b.verification;
        println!(
            "{:<22} max abs {:.3e}  rms {:.3e}  (f32 code: max abs {:.3e})  over {} points  [{t:.1} s]",
            b.name, v.max_abs_error, v.rms_error, v.max_abs_error_f32, v.points
        );
    }
    for (n, t) in &summary.scenes {
        println!("{n:<22} scene module  [{t:.1} s]");
    }
    for n in &summary.up_to_date {
        println!("{n:<22} up to date (skipped; --force rebuilds)");
    }
    println!(
        "{} file(s) written, {} unchanged; {:.1} s wall on {} thread(s)",
        summary.written,
        summary.files - summary.written,
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    Ok(())
}

/// `shadefit build --scene FILE [--force]`: only the nodes the scene reaches, each only when its
/// inputs or files changed since the scene's last build, then the scene module.
pub fn build_scene(paths: &Paths, file: &Path, force: bool, targets: &[crate::emit::targets::Target]) -> Result<()> {
    let start = std::time::Instant::now();
    let r = build::run_scene(paths, file, force, targets).map_err(build_err)?;
    let name = file.file_stem().map_or(String::new(), |s| s.to_string_lossy().into_owned());
    println!("scene {name}: {} up to date, {} built", r.up_to_date.len(), r.built.len());
    println!("  built: {}", if r.built.is_empty() { "-".to_string() } else { r.built.join(", ") });
    println!("  up to date: {}", if r.up_to_date.is_empty() { "-".to_string() } else { r.up_to_date.join(", ") });
    println!("  not reached: {}", r.skipped.join(", "));
    for rec in &r.records {
        let what = rec["what"].as_str().unwrap_or("?");
        let ours = rec.get("max_abs_error").or(rec.get("error_estimate")).and_then(|v| v.as_f64());
        let general = rec.get("general_fit_max_abs_error").or(rec.get("general_fit_abs_error")).and_then(|v| v.as_f64());
        println!(
            "  {what}: error {} (general fit at the same parameters: {})",
            ours.map_or("-".into(), |v| format!("{v:.3e}")),
            general.map_or("-".into(), |v| format!("{v:.3e}"))
        );
    }
    println!("{} file(s) written; {:.2} s wall", r.written, start.elapsed().as_secs_f64());
    Ok(())
}

/// `eval` with `--profile`/`--kernel`, for the quantities whose family takes them.
pub fn eval_with_options(name: &str, params: &[String], as_json: bool, profile: Option<&Path>, kernel: Option<&str>) -> Result<()> {
    let q = family::catalog().lookup(name).map_err(input_err)?;
    let takes: Vec<&str> = family::families().iter().filter_map(|f| f.eval_options).flat_map(|(names, _)| names.iter().copied()).collect();
    let Some((_, with)) = family::of_quantity(q.name).and_then(|f| f.eval_options).filter(|(names, _)| names.contains(&q.name)) else {
        return Err(input_err(format!("--profile and --kernel apply to {}, not '{}'", takes.join(" and "), q.name)));
    };
    let named = parse_params(params)?;
    let p = q.resolve(&named).map_err(input_err)?;
    let e = with(q, &p, &family::EvalOptions { profile, kernel }).map_err(input_err)?;
    if as_json {
        let mut out = json!({
            "quantity": q.name,
            "params": named,
            "value": e.values,
            "channels": q.channels,
            "error_estimate": e.error,
        });
        if let Some(map) = out.as_object_mut() {
            map.extend(e.extra);
        }
        println!("{out}");
    } else {
        let parts: Vec<String> = q.channels.iter().zip(&e.values).map(|(c, v)| format!("{c} {v:.17e}")).collect();
        println!("{} = {}  (error estimate {:.1e}; {})", q.name, parts.join(", "), e.error, e.note);
    }
    Ok(())
}

/// The fitting samples of one spec (its grid and the integral there), as JSON or CSV.
pub fn samples(paths: &Paths, name: &str, as_json: bool) -> Result<()> {
    let specs = load_specs(paths, &[name.to_string()])?;
    let s = specs.iter().find(|s| s.file.name == name).expect("load_specs checked the name");
    if let spec::Kind::Custom(kind) = s.file.kind {
        let note = family::catalog().kind(kind).map_or("{name}: kind = \"{kind}\" has no samples", |k| k.samples_note);
        return Err(input_err(note.replace("{name}", name).replace("{kind}", kind)));
    }
    let counts: Vec<usize> = s.file.axis.iter().map(|a| a.count).collect();
    let x = pipeline::grid(s, &counts);
    let y = pipeline::sample(s, &x);
    let features: Vec<&str> = s.file.axis.iter().map(|a| a.name.as_str()).collect();
    if as_json {
        let model = s.model.as_ref().map(|m| {
            json!({
                "numerator": m.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
                "denominator": m.denominator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
                "clamp": m.clamp.map(|(a, b)| [a, b]),
                "pins": m.pins.iter().map(|p| json!({"at": p.at, "value": p.value, "eliminate": m.numerator[p.eliminate].label})).collect::<Vec<_>>(),
                "fixed": m.fixed.iter().map(|(i, v)| json!({"coefficient": m.coefficient_labels()[*i], "value": v})).collect::<Vec<_>>(),
            })
        });
        let out = json!({
            "name": s.file.name,
            "quantity": s.quantity_label(),
            "features": features,
            "objective": s.file.fit.as_ref().map(|f| f.objective),
            "model": model,
            "x": x,
            "y": y,
        });
        println!("{out}");
    } else {
        println!("{},value", features.join(","));
        for (p, v) in x.iter().zip(&y) {
            let cols: Vec<String> = p.iter().map(|c| format!("{c:?}")).collect();
            println!("{},{v:?}", cols.join(","));
        }
    }
    Ok(())
}

pub fn list(paths: &Paths) -> Result<()> {
    let specs = build::status(paths).map_err(build_err)?;
    println!("{:<22} {:<8} {:<18} {:<28} status", "name", "kind", "quantity", "function");
    for (s, st) in &specs {
        let status = match st {
            build::Status::Current => "up to date",
            build::Status::Changed => "stale (spec changed)",
            build::Status::NotBuilt => "not built",
        };
        println!(
            "{:<22} {:<8} {:<18} {:<28} {status}",
            s.file.name,
            s.file.kind.name(),
            s.quantity_label(),
            s.file.emit.function
        );
    }
    Ok(())
}

/// `fit --data … --emit DIR`: where and what to emit besides printing the fit.
pub struct FitEmit {
    pub dir: PathBuf,
    pub targets: Vec<String>,
    pub name: Option<String>,
    pub function: Option<String>,
    pub args: Option<Vec<String>>,
    /// `--domain` items, `COLUMN=LO:HI` each.
    pub domain: Vec<String>,
}

pub fn fit_data(
    data_path: &Path,
    x_cols: &[String],
    y_col: &str,
    model_arg: &str,
    objective: Objective,
    as_json: bool,
    emit: Option<&FitEmit>,
) -> Result<()> {
    check_columns(data_path, x_cols, y_col)?;
    let model = load_model(model_arg, x_cols)?;
    let (targets, domain) = match emit {
        Some(e) => (
            crate::emit::targets::parse_list(&e.targets).map_err(|why| input_err(format!("--target: {why}")))?,
            parse_domain(&e.domain, x_cols)?,
        ),
        None => (Vec::new(), Vec::new()),
    };
    let data: Data = read_csv(data_path, x_cols, y_col).map_err(input_err)?;
    // The box is checked against the rows before the fit runs (and again where it is made).
    pipeline::data::data_box(x_cols, &data, &domain).map_err(|why| input_err(format!("{}: {why}", data_path.display())))?;
    // Emitted code computes in f32: data it cannot represent is refused before the fit runs.
    if emit.is_some() {
        let columns = x_cols.iter().map(String::as_str).chain([y_col]);
        for (i, row) in data.x.iter().zip(&data.y).enumerate() {
            for (v, col) in row.0.iter().chain([row.1]).zip(columns.clone()) {
                if *v != 0.0 && !(v.abs() >= f32::MIN_POSITIVE as f64 && v.abs() <= f32::MAX as f64) {
                    return Err(input_err(format!(
                        "{}: data row {}, column '{col}': {} is not a normal f32 number, which emitted code computes in; scale the column, or fit without --emit",
                        data_path.display(),
                        i + 1,
                        crate::quantity::short_number(*v)
                    )));
                }
            }
        }
    }
    let opts = FitOptions { objective, ..FitOptions::default() };
    let f = match fit::fit_rescaled(&model, &data, &opts, &data_path.display().to_string()) {
        // Too few rows for the model, or none: the user's input.
        Err(e @ (fit::FitError::NoData { .. } | fit::FitError::Underdetermined { .. })) => return Err(input_err(e)),
        r => r?,
    };
    let nn = model.numerator.len();
    let c = &f.coefficients;
    let mut den = vec![1.0];
    den.extend((nn..model.n_full()).map(|j| c[j]));
    let r = &f.report;
    if !(r.rss.is_finite() && r.max_abs_error.is_finite() && r.rms_error.is_finite()) {
        return Err(input_err(format!(
            "{}: the fit's residuals overflow (rss {:e}): the values are too large to square in f64; scale the data",
            data_path.display(),
            r.rss
        )));
    }
    if as_json {
        let out = json!({
            "model": model_arg,
            "features": model.features,
            "numerator_terms": model.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator_terms": std::iter::once("1".to_string()).chain(model.denominator.iter().map(|t| t.label.clone())).collect::<Vec<_>>(),
            "numerator": (0..nn).map(|j| c[j]).collect::<Vec<_>>(),
            "denominator": den,
            "objective": objective,
            "rss": r.rss,
            "max_abs_error": r.max_abs_error,
            "rms_error": r.rms_error,
            "worst_point": r.worst_point,
            "condition_number": r.condition_number,
            "iterations": r.iterations,
            "samples": r.samples,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("model {model_arg} on {} samples ({:?})", r.samples, objective);
        for (t, j) in model.numerator.iter().zip(0..) {
            println!("  num[{t}] = {:.17e}", c[j]);
        }
        for (t, j) in model.denominator.iter().zip(nn..) {
            println!("  den[{t}] = {:.17e}", c[j]);
        }
        println!(
            "rss {:.10e}  max abs {:.3e}  rms {:.3e}  cond {:.2e}",
            r.rss, r.max_abs_error, r.rms_error, r.condition_number
        );
    }
    if let Some(e) = emit {
        emit_data_fit(e, &targets, &domain, data_path, x_cols, y_col, model_arg, objective, model, data, f, as_json)?;
    }
    Ok(())
}

/// The files of `fit --data … --emit`, rendered in full before any is written, then written
/// as one transaction (all or nothing).
#[allow(clippy::too_many_arguments)]
fn emit_data_fit(
    e: &FitEmit,
    targets: &[crate::emit::targets::Target],
    domain: &[(String, [f64; 2])],
    data_path: &Path,
    x_cols: &[String],
    y_col: &str,
    model_arg: &str,
    objective: Objective,
    model: RationalModel,
    data: Data,
    fitted: fit::Fit,
    as_json: bool,
) -> Result<()> {
    let csv_bytes = spec::input::read_input(data_path).map_err(|err| input_err(format!("{}: {err}", data_path.display())))?;
    let model_text = if model_arg.trim_start().starts_with("rational(") {
        None
    } else {
        Some(spec::input::read_input_text(Path::new(model_arg)).map_err(|err| input_err(format!("{model_arg}: {err}")))?)
    };
    // The default name: the CSV's stem as a module name (lowercase, other characters '_').
    let stem: String = data_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("fit")
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' })
        .collect();
    let stem = if stem.starts_with(|c: char| c.is_ascii_alphabetic()) { stem } else { format!("fit_{stem}") };
    let name = e.name.clone().unwrap_or(stem);
    let function = e.function.clone().unwrap_or_else(|| name.clone());
    let req = pipeline::data::DataFit {
        csv: data_path,
        csv_bytes: &csv_bytes,
        x: x_cols,
        y: y_col,
        model_arg,
        model_text: model_text.as_deref(),
        objective,
        name: &name,
        function: &function,
        args: e.args.as_deref(),
        domain,
    };
    let built = match pipeline::data::fit_and_render(&req, model, data, fitted) {
        Err(err @ pipeline::BuildError::Input { .. }) => return Err(input_err(err)),
        r => r?,
    };
    let mut files = built.artifacts.clone();
    let wanted = targets.to_vec();
    files.extend(build::target_artifacts(&built.artifacts, &|_| wanted.clone())?);
    let written = pipeline::write_all(&e.dir, &files)?;
    let v = &built.verification;
    let line = format!(
        "emitted {} ({} file(s) in {}, {written} written): f32 code max abs {:.3e}, rms {:.3e} over the {} rows",
        name,
        files.len(),
        e.dir.display(),
        v.max_abs_error_f32,
        v.rms_error_f32,
        v.points
    );
    // With --json, stdout holds the JSON object only.
    if as_json { eprintln!("{line}") } else { println!("{line}") }
    Ok(())
}

/// The columns `fit --data` names, before the CSV is read: each `--x` column writable in
/// terms and named once, and `--y` not one of them. Errors name the CSV file and the column.
fn check_columns(csv: &Path, x_cols: &[String], y_col: &str) -> Result<()> {
    // The columns are the model's features: each must be writable in its terms, and once.
    for (i, c) in x_cols.iter().enumerate() {
        if let Some(why) = fit::model::check_feature_name(c) {
            return Err(input_err(format!("{}: --x: column '{c}' {why}", csv.display())));
        }
        if x_cols[..i].contains(c) {
            return Err(input_err(format!("{}: --x: column '{c}' is given twice", csv.display())));
        }
    }
    if x_cols.iter().any(|c| c == y_col) {
        return Err(input_err(format!("{}: --y: column '{y_col}' is also an --x column (a feature cannot be its own target)", csv.display())));
    }
    Ok(())
}

/// `--domain COLUMN=LO:HI,…`: the emitted code's clamp box on the named `--x` columns, each
/// once, with finite bounds LO < HI. Errors name the flag and the item.
fn parse_domain(items: &[String], x_cols: &[String]) -> Result<Vec<(String, [f64; 2])>> {
    let mut out: Vec<(String, [f64; 2])> = Vec::new();
    for item in items {
        let bad = |why: String| input_err(format!("--domain '{item}': {why}"));
        let (name, bounds) = item.split_once('=').ok_or_else(|| bad("expected COLUMN=LO:HI".into()))?;
        let (lo, hi) = bounds.split_once(':').ok_or_else(|| bad("expected COLUMN=LO:HI".into()))?;
        let (name, lo, hi) = (name.trim(), lo.trim(), hi.trim());
        let number = |s: &str| -> Result<f64> {
            let v: f64 = s.parse().map_err(|_| bad(format!("'{s}' is not a number")))?;
            if !v.is_finite() {
                return Err(bad(format!("the bound '{s}' is not finite")));
            }
            Ok(v)
        };
        let (lo, hi) = (number(lo)?, number(hi)?);
        if lo >= hi {
            return Err(bad(format!("the lower bound {lo:?} is not below the upper bound {hi:?}")));
        }
        if !x_cols.iter().any(|c| c == name) {
            return Err(bad(format!("'{name}' is not an --x column (--x: {})", x_cols.join(", "))));
        }
        if out.iter().any(|(n, _)| n == name) {
            return Err(bad(format!("column '{name}' is given twice")));
        }
        out.push((name.to_string(), [lo, hi]));
    }
    Ok(out)
}

/// `rational(m,n)` (of total degree in the x columns) or a model TOML file.
fn load_model(arg: &str, x_cols: &[String]) -> Result<RationalModel> {
    if arg.trim_start().starts_with("rational(") {
        return RationalModel::parse_form_over(arg, x_cols).map_err(input_err);
    }
    let path = Path::new(arg);
    if !path.is_file() {
        return Err(input_err(format!("--model '{arg}' is neither rational(m,n) nor a model spec file")));
    }
    let text = spec::input::read_input_text(path).map_err(|e| input_err(format!("{}: {e}", path.display())))?;
    let ms: ModelSpec = spec::parse_toml(path, &text).map_err(input_err)?;
    let features = ms.features.clone().unwrap_or_else(|| x_cols.to_vec());
    if features.len() != x_cols.len() {
        return Err(input_err(format!(
            "{}: the model has {} features ({}) but --x names {} columns",
            path.display(),
            features.len(),
            features.join(", "),
            x_cols.len()
        )));
    }
    ms.build(path, &text, features, &|_| None).map_err(input_err)
}

/// The families named by `--family` (all when none), in registry order; an unknown name is an
/// input error listing the known ones.
fn selected_families(names: &[String]) -> Result<Vec<&'static family::Family>> {
    let all = family::families();
    if let Some(bad) = names.iter().find(|n| !all.iter().any(|f| f.name == n.as_str())) {
        let known: Vec<&str> = all.iter().map(|f| f.name).collect();
        return Err(input_err(format!("--family: unknown family '{bad}' (known: {})", known.join(", "))));
    }
    Ok(all.iter().filter(|f| names.is_empty() || names.iter().any(|n| n == f.name)).copied().collect())
}

/// `shadefit validate [--family A,B] [--only SPEC,…] [--json] [--no-cache]`: the families' published
/// constants and the form specs of `fits/` measured. With neither option, every family and
/// every form spec; with either, only what they name.
pub fn validate(paths: &Paths, families: &[String], only: &[String], as_json: bool, no_cache: bool) -> Result<()> {
    use crate::validate::cache;
    let everything = families.is_empty() && only.is_empty();
    // Each section (a family's items, a form spec's item) is read from the cache when the
    // executable and the inputs are those it was computed from (`validate::cache`).
    let cached = cache::dir().and_then(|d| Some((cache::base(&paths.fits, &paths.generated)?, d)));
    let (mut hits, mut sections) = (0usize, 0usize);
    let mut section = |name: String, compute: &mut dyn FnMut() -> Result<Vec<crate::validate::Item>>| -> Result<Vec<crate::validate::Item>> {
        sections += 1;
        if let Some((base, dir)) = &cached {
            if !no_cache && let Some(items) = cache::read(dir, base, &name) {
                hits += 1;
                return Ok(items);
            }
            let items = compute()?;
            cache::write(dir, base, &name, &items);
            return Ok(items);
        }
        compute()
    };
    let selected = if everything || !families.is_empty() { selected_families(families)? } else { vec![] };
    // One step per family and per form spec, drawn on a terminal only (indicatif hides itself
    // on a pipe, so `--json` and CI output stay clean).
    let pb = progress(selected.len(), "validate");
    let mut items = Vec::new();
    for f in &selected {
        pb.set_message(format!("validate {}", f.name));
        items.extend(section(format!("family:{}", f.name), &mut || Ok(crate::validate::all(&paths.generated, &[f.validate])))?);
        pb.inc(1);
    }
    let forms: Vec<Spec> = if everything && !paths.fits.is_dir() {
        vec![]
    } else if everything || !only.is_empty() {
        let form_kind = spec::Kind::Custom(pipeline::form::KIND);
        let specs: Vec<Spec> = load_specs(paths, &[])?.into_iter().filter(|s| s.file.kind == form_kind).collect();
        if let Some(bad) = only.iter().find(|n| !specs.iter().any(|s| &s.file.name == *n)) {
            let known: Vec<&str> = specs.iter().map(|s| s.file.name.as_str()).collect();
            return Err(input_err(format!("--only: no form spec '{bad}' in {} (form specs: {})", paths.fits.display(), known.join(", "))));
        }
        specs.into_iter().filter(|s| everything || only.contains(&s.file.name)).collect()
    } else {
        vec![]
    };
    pb.set_length((selected.len() + forms.len()) as u64);
    for s in &forms {
        pb.set_message(format!("validate {}", s.file.name));
        items.extend(section(format!("form:{}", s.file.name), &mut || Ok(vec![crate::validate::form_item(s, &paths.generated, family::catalog()).map_err(input_err)?]))?);
        pb.inc(1);
    }
    pb.finish_and_clear();
    if hits > 0 {
        eprintln!("validate: {hits} of {sections} section(s) from the cache (same executable and inputs; --no-cache recomputes)");
    }
    if as_json {
        println!("{}", serde_json::to_string_pretty(&json!({ "items": items }))?);
        return Ok(());
    }
    for it in &items {
        println!("{}\n  source: {}\n  domain: {}", it.name, it.source, it.domain);
        println!(
            "  {} points: max abs {:.3e}, rms {:.3e}, worst at {:?}",
            it.points, it.max_abs_error, it.rms_error, it.worst_point
        );
        for (k, v) in &it.extra {
            println!("  {k}: {v:.3e}");
        }
        for f in &it.findings {
            println!("  finding: {f}");
        }
        println!();
    }
    Ok(())
}

/// `shadefit measure FILE.toml [--refit] [--json]`: a form spec's published constants (and,
/// with `--refit`, refitted ones) measured against its quantity on its grid; writes nothing.
pub fn measure(path: &Path, refit: bool, as_json: bool) -> Result<()> {
    use pipeline::form::{Form, KIND, measure_and_refit};
    let catalog = family::catalog();
    let spec = Spec::load(path, catalog).map_err(input_err)?;
    if spec.file.kind != spec::Kind::Custom(KIND) {
        return Err(input_err(format!("{}: kind = \"{}\", not a form spec (kind = \"{KIND}\")", path.display(), spec.file.kind.name())));
    }
    let form = Form::from_spec(&spec, catalog).map_err(input_err)?;
    let (_, c) = measure_and_refit(&form, refit);
    if as_json {
        let mut v = json!({
            "name": form.name, "quantity": form.quantity.name, "source": form.source, "grid": form.grid_doc(),
            "max_error_estimate": c.max_error_estimate, "published": c.published_errors,
        });
        if refit {
            v["refit"] = json!({ "constants": c.constants, "errors": c.refit_errors });
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!("{} ({})\n  grid: {}\n  integrals: largest error estimate {:.1e}", form.name, form.source, form.grid_doc(), c.max_error_estimate);
    let show = |what: &str, e: &pipeline::form::Errors| {
        let a = &e.all;
        println!("  {what}: {} values, max abs {:.3e}, rms {:.3e}, mean signed {:.3e}, worst at {:?} ({})", a.points, a.max_abs_error, a.rms_error, a.mean_signed_error, a.worst, a.worst_output);
        for (o, s) in &e.outputs {
            println!("    {o}: max abs {:.3e}, rms {:.3e}, mean signed {:.3e}, worst at {:?}", s.max_abs_error, s.rms_error, s.mean_signed_error, s.worst);
        }
    };
    show("published", &c.published_errors);
    if refit {
        show("refit (f32 constants)", &c.refit_errors);
        for k in &c.constants {
            println!("    {} = {:e} (published {:e})", k.name, k.refit, k.published);
        }
    }
    Ok(())
}

/// Figures (PNG and SVG) of every family with committed outputs.
/// A family's own subcommand (`args[0]` is its name); its bad input is exit 2.
pub fn family_command(args: &[String]) -> Result<()> {
    let name = args.first().map(String::as_str).unwrap_or("");
    let c = family::command(name).ok_or_else(|| input_err(format!("unknown command '{name}'\n{}", family::commands_help())))?;
    match (c.run)(&args[1..]) {
        Ok(out) => {
            println!("{out}");
            Ok(())
        }
        Err(family::CommandError::Input(m)) => Err(input_err(m)),
        Err(family::CommandError::Failed(m)) => Err(anyhow::anyhow!(m)),
    }
}

pub fn plot(paths: &Paths, out: &Path) -> Result<()> {
    use crate::plot::user;
    let mut files = Vec::new();
    // A family whose committed files are not in --generated (a user's own project builds its own
    // specs only) is skipped with a note; any other failure stops the run.
    for f in family::families() {
        match (f.figures)(out, &paths.generated) {
            Ok(v) => files.extend(v),
            Err(e) if e.path().is_some_and(|p| !p.exists()) => {
                eprintln!("note: {}: figures left out from here on ({} is absent: the family's committed files are not in {})", f.name, e.path().expect("a path").display(), paths.generated.display());
            }
            Err(e) => return Err(e.into()),
        }
    }
    // The user's form and lobe specs in --fits.
    for s in load_specs(paths, &[])? {
        match &s.file.kind {
            spec::Kind::Custom(k) if *k == crate::pipeline::form::KIND => {
                let form = crate::pipeline::form::Form::from_spec(&s, family::catalog()).map_err(input_err)?;
                match crate::pipeline::form::committed(&paths.generated, &s) {
                    Some(c) => files.extend(user::form_figures(&form, &c, out)?),
                    None => eprintln!("note: {}: no figures (its refit is not committed in {}: run `shadefit build`)", s.file.name, paths.generated.display()),
                }
            }
            spec::Kind::Custom(k) if *k == crate::pipeline::lobe::KIND => {
                files.extend(user::lobe_figures(&crate::pipeline::lobe::LobeDef::from_spec(&s).map_err(input_err)?, out)?);
            }
            _ => {}
        }
    }
    for f in &files {
        println!("{}", f.display());
    }
    println!("{} file(s) written", files.len());
    Ok(())
}

/// Arguments of `shadefit bench`.
pub struct BenchArgs {
    pub quick: bool,
    pub json: bool,
    pub only: Vec<String>,
    /// Family names (empty: every family).
    pub family: Vec<String>,
    pub python: Option<PathBuf>,
    pub no_python: bool,
}

pub fn bench(paths: &Paths, a: &BenchArgs) -> Result<()> {
    use crate::bench::{self, Mode, Sections, tables};
    const KNOWN: [&str; 5] = ["integrators", "fits", "tables", "builds", "forms"];
    if let Some(bad) = a.only.iter().find(|s| !KNOWN.contains(&s.as_str())) {
        return Err(input_err(format!(
            "--only: unknown section '{bad}' (known: {})",
            KNOWN.join(", ")
        )));
    }
    let on = |s: &str| a.only.is_empty() || a.only.iter().any(|o| o == s);
    let sections = Sections {
        integrators: on("integrators"),
        fits: on("fits"),
        tables: on("tables"),
        builds: on("builds"),
        forms: on("forms"),
    };
    let specs = load_specs(paths, &[])?;
    let root = paths.fits.parent().unwrap_or(Path::new("")).to_path_buf();
    let python = match (&a.python, a.no_python) {
        (_, true) => None,
        (Some(p), false) => Some(tables::Python {
            interpreter: p.clone(),
            script: root.join("benches/numpy_tables.py"),
            required: true,
        }),
        (None, false) => Some(tables::default_python(&root)),
    };
    let inputs = bench::Inputs {
        specs: &specs,
        catalog: family::catalog(),
        fits: &paths.fits,
        generated: &paths.generated,
        python: python.as_ref(),
        custom: &crate::build::custom_builder,
    };
    let families = selected_families(&a.family)?.into_iter().map(|f| &f.bench).collect::<Vec<_>>();
    let report = bench::run(Mode::new(a.quick), sections, &inputs, &families)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", bench::render(&report));
    }
    Ok(())
}
