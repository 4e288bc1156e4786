//! Command implementations behind `main`: parse nothing, print results. Errors that are the
//! user's input come back as [`InputError`] (exit code 2); everything else is a job failure.

use crate::fit::{self, Data, FitOptions, Objective, RationalModel};
use crate::pipeline::{self, Built, Mode};
use crate::quantity;
use crate::scene::{self, Scene};
use crate::spec::{self, data::read_csv, ModelSpec, Spec};
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::collections::BTreeMap;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Bad input: exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

fn input_err(e: impl std::fmt::Display) -> anyhow::Error {
    InputError(e.to_string()).into()
}

/// Project paths: specs in `fits/`, outputs in `generated/`.
pub struct Paths {
    pub fits: PathBuf,
    pub generated: PathBuf,
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
    let q = quantity::lookup(name).map_err(input_err)?;
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
    let specs = spec::load_dir(&paths.fits).map_err(input_err)?;
    for name in only {
        if !specs.iter().any(|s| &s.file.name == name) {
            return Err(input_err(format!(
                "no spec named '{name}' in {} (known: {})",
                paths.fits.display(),
                specs.iter().map(|s| s.file.name.as_str()).collect::<Vec<_>>().join(", ")
            )));
        }
    }
    Ok(specs)
}

fn progress(len: usize, what: &str) -> ProgressBar {
    // indicatif draws only on a terminal: pipes and CI stay quiet.
    let pb = ProgressBar::new(len as u64);
    pb.set_style(ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}").expect("valid template"));
    pb.set_message(what.to_string());
    pb
}

pub fn build(paths: &Paths, only: &[String], check: bool) -> Result<()> {
    let specs = load_specs(paths, only)?;
    let selected: Vec<&Spec> =
        specs.iter().filter(|s| only.is_empty() || only.contains(&s.file.name)).collect();
    let mode = if check { Mode::Committed } else { Mode::Fit };
    let pb = progress(selected.len(), if check { "check" } else { "build" });
    let mut scene_names: Vec<String> = Vec::new();
    let start = std::time::Instant::now();
    // Specs are independent: build them concurrently (each also parallelises its own sampling on
    // the same rayon pool), collected in spec order, so the outputs do not depend on scheduling.
    let results: Vec<Result<(Built, f64)>> = selected
        .par_iter()
        .map(|s| {
            let t = std::time::Instant::now();
            let b = pipeline::build_spec(s, mode, &paths.generated).with_context(|| format!("building {}", s.file.name))?;
            pb.inc(1);
            Ok((b, t.elapsed().as_secs_f64()))
        })
        .collect();
    pb.finish_and_clear();
    let mut built: Vec<Built> = Vec::new();
    let mut seconds: Vec<f64> = Vec::new();
    for r in results {
        let (b, t) = r?;
        built.push(b);
        seconds.push(t);
    }
    let scenes = Scene::load_dir(&paths.fits.join("scenes")).map_err(input_err)?;
    let mut artifacts: Vec<_> = built.iter().flat_map(|b| b.artifacts.clone()).collect();
    // The scene modules read their specs' coefficients from generated/json: write this build's
    // first, so a scene never specialises the previous build's fit.
    let spec_files = artifacts.len();
    let mut written = if check { 0 } else { pipeline::write_all(&paths.generated, &artifacts)? };
    if only.is_empty() {
        // Every scene module, with the node files of this build recorded for its cache.
        for sc in &scenes {
            let t = std::time::Instant::now();
            let nodes: Vec<scene::NodeRecord> = scene::plan(sc)
                .nodes
                .iter()
                .filter_map(|n| {
                    let b = built.iter().find(|b| &b.name == n)?;
                    let spec = specs.iter().find(|s| &s.file.name == n)?;
                    Some(scene::node_record(n, pipeline::input_hash(spec), &b.artifacts))
                })
                .collect();
            let sb = scene::build_scene(sc, &specs, &paths.generated, &nodes).with_context(|| format!("building scene {}", sc.file.name))?;
            artifacts.extend(sb.artifacts);
            seconds.push(t.elapsed().as_secs_f64());
            scene_names.push(sc.module());
        }
    }
    artifacts.push(scene::runtime_index(&specs, &scenes));
    if check {
        let mut bad = pipeline::stale(&paths.generated, &artifacts);
        if only.is_empty() {
            bad.extend(pipeline::orphans(&paths.generated, &artifacts).into_iter().map(|p| format!("{p} (no spec produces it)")));
        }
        if bad.is_empty() {
            println!("generated/ is up to date ({} files from {} specs)", artifacts.len(), selected.len());
            return Ok(());
        }
        for p in &bad {
            println!("stale: {p}");
        }
        anyhow::bail!("{} generated file(s) differ from what the specs and committed coefficients produce; run `shadefit build`", bad.len());
    }
    // The spec files were written above; now the scene modules and the runtime index.
    written += pipeline::write_all(&paths.generated, &artifacts[spec_files..])?;
    for (b, t) in built.iter().zip(&seconds) {
        let v = &b.verification;
        println!(
            "{:<22} max abs {:.3e}  rms {:.3e}  (f32 code: max abs {:.3e})  over {} points  [{t:.1} s]",
            b.name, v.max_abs_error, v.rms_error, v.max_abs_error_f32, v.points
        );
    }
    for (n, t) in scene_names.iter().zip(&seconds[built.len()..]) {
        println!("{n:<22} scene module  [{t:.1} s]");
    }
    println!(
        "{written} file(s) written, {} unchanged; {:.1} s wall on {} thread(s)",
        artifacts.len() - written,
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    Ok(())
}

/// `shadefit build --scene FILE [--force]`: only the nodes the scene reaches, each only when its
/// inputs or files changed since the scene's last build, then the scene module.
pub fn build_scene(paths: &Paths, file: &Path, force: bool) -> Result<()> {
    let start = std::time::Instant::now();
    let sc = Scene::load(file).map_err(input_err)?;
    let specs = load_specs(paths, &[])?;
    let mut scenes = Scene::load_dir(&paths.fits.join("scenes")).map_err(input_err)?;
    if !scenes.iter().any(|s| s.file.name == sc.file.name) {
        scenes.push(sc.clone());
    }
    let r = scene::build(&sc, &specs, &scenes, &paths.generated, force).with_context(|| format!("building scene {}", sc.file.name))?;
    println!("scene {}: {} up to date, {} built", sc.file.name, r.up_to_date.len(), r.built.len());
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

/// A skin quantity with a diffusion profile of your own (`--profile`: a TOML file with a
/// `[profile]` section, or a CSV radial profile) and/or the ring kernel (`--kernel`).
pub fn eval_skin(name: &str, params: &[String], as_json: bool, profile: Option<&Path>, kernel: Option<&str>) -> Result<()> {
    use crate::quantity::skin::{self, Kernel};
    let q = quantity::lookup(name).map_err(input_err)?;
    if !matches!(q.name, "skin-punctual" | "skin-sh") {
        return Err(input_err(format!("--profile and --kernel apply to skin-punctual and skin-sh, not '{}'", q.name)));
    }
    let kernel = match (q.name, kernel) {
        (_, None) | ("skin-punctual", Some("linear")) => Kernel::Linear,
        ("skin-punctual", Some("radial")) => Kernel::Radial,
        ("skin-punctual", Some(other)) => return Err(input_err(format!("--kernel '{other}': expected linear or radial"))),
        (_, Some(_)) => return Err(input_err("--kernel applies to skin-punctual (skin-sh integrates the radial profile over the sphere)")),
    };
    let named = parse_params(params)?;
    let p = q.resolve(&named).map_err(input_err)?;
    let loaded = match profile {
        Some(path) => spec::profile::load_profile_file(path).map_err(input_err)?,
        None => spec::profile::LoadedProfile::deon_luebke(),
    };
    let tol = crate::integrate::Tolerance { abs: 1e-12, ..skin::DEFAULT_TOLERANCE };
    let est = match q.name {
        "skin-punctual" => skin::punctual(&loaded.profile, kernel, p[0], p[1], tol),
        _ => skin::sh_band(&loaded.profile, p[0], p[1] as u32, tol),
    };
    let where_ = profile.map_or("the default profile".to_string(), |p| p.display().to_string());
    let est = est.map_err(|e| input_err(format!("{where_}: {e}")))?;
    let values: Vec<f64> = est.iter().map(|e| e.value).collect();
    let error = est.iter().map(|e| e.error).fold(0.0, f64::max);
    let kernel_name = if kernel == Kernel::Linear { "linear" } else { "radial" };
    if as_json {
        let out = json!({
            "quantity": q.name,
            "params": named,
            "value": values,
            "channels": q.channels,
            "error_estimate": error,
            "profile": loaded.provenance(),
            "kernel": if q.name == "skin-punctual" { kernel_name } else { "radial (sphere)" },
        });
        println!("{out}");
    } else {
        let parts: Vec<String> = q.channels.iter().zip(&values).map(|(c, v)| format!("{c} {v:.17e}")).collect();
        println!("{} = {}  (error estimate {error:.1e}; profile: {where_})", q.name, parts.join(", "));
    }
    Ok(())
}

/// The fitting samples of one spec (its grid and the integral there), as JSON or CSV.
pub fn samples(paths: &Paths, name: &str, as_json: bool) -> Result<()> {
    let specs = load_specs(paths, &[name.to_string()])?;
    let s = specs.iter().find(|s| s.file.name == name).expect("load_specs checked the name");
    if s.file.kind == spec::Kind::SkinLut {
        return Err(input_err(format!(
            "{name} is a skin LUT: its samples are its texels, \"values\" in generated/json/{name}.json (RGB, with the axes)"
        )));
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
            "quantity": s.file.quantity,
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
    let specs = spec::load_dir(&paths.fits).map_err(input_err)?;
    println!("{:<22} {:<8} {:<18} {:<28} status", "name", "kind", "quantity", "function");
    for s in &specs {
        let status = match pipeline::build_spec(s, Mode::Committed, &paths.generated) {
            Ok(b) if pipeline::stale(&paths.generated, &b.artifacts).is_empty() => "up to date".to_string(),
            Ok(_) => "stale".to_string(),
            Err(e) => format!("stale ({})", short(&e.to_string())),
        };
        println!(
            "{:<22} {:<8} {:<18} {:<28} {status}",
            s.file.name,
            s.file.kind.name(),
            s.file.quantity,
            s.file.emit.function
        );
    }
    Ok(())
}

fn short(s: &str) -> String {
    s.split(';').next().unwrap_or(s).chars().take(60).collect()
}

pub fn fit_data(
    data_path: &Path,
    x_cols: &[String],
    y_col: &str,
    model_arg: &str,
    objective: Objective,
    as_json: bool,
) -> Result<()> {
    let model = load_model(model_arg, x_cols)?;
    let data: Data = read_csv(data_path, x_cols, y_col).map_err(input_err)?;
    let opts = FitOptions { objective, ..FitOptions::default() };
    let f = fit::fit(&model, &data, &opts, &data_path.display().to_string())?;
    let nn = model.numerator.len();
    let c = &f.coefficients;
    let mut den = vec![1.0];
    den.extend((nn..model.n_full()).map(|j| c[j]));
    let r = &f.report;
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
    Ok(())
}

/// `rational(m,n)` (one feature, named by the x column) or a model TOML file.
fn load_model(arg: &str, x_cols: &[String]) -> Result<RationalModel> {
    if arg.trim_start().starts_with("rational(") {
        if x_cols.len() != 1 {
            return Err(input_err(format!("{arg} is one-dimensional but --x names {} columns", x_cols.len())));
        }
        return RationalModel::parse_form(arg, &x_cols[0]).map_err(input_err);
    }
    let path = Path::new(arg);
    if !path.is_file() {
        return Err(input_err(format!("--model '{arg}' is neither rational(m,n) nor a model spec file")));
    }
    let text = std::fs::read_to_string(path).map_err(|e| input_err(format!("{}: {e}", path.display())))?;
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

pub fn validate(paths: &Paths, as_json: bool) -> Result<()> {
    let items = crate::validate::all(&paths.generated);
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

/// Figures (PNG and SVG) of every family with committed outputs.
pub fn plot(paths: &Paths, out: &Path) -> Result<()> {
    let mut files = crate::plot::gloss_figures(out, &paths.generated)?;
    files.extend(crate::plot::fuzz_figures(out, &paths.generated)?);
    files.extend(crate::plot::skin_figures(out, &paths.generated)?);
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
    pub python: Option<PathBuf>,
    pub no_python: bool,
}

pub fn bench(paths: &Paths, a: &BenchArgs) -> Result<()> {
    use crate::bench::{self, Mode, Sections, tables};
    const KNOWN: [&str; 4] = ["integrators", "fits", "tables", "forms"];
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
    let report = bench::run(Mode::new(a.quick), sections, &specs, paths, python.as_ref())?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", bench::render(&report));
    }
    Ok(())
}
