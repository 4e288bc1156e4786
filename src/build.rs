//! The build orchestration behind `shadefit build` and `build --scene`: specs built
//! concurrently on the rayon pool (each also parallelises its own sampling on the same pool),
//! collected in spec order so the outputs do not depend on scheduling; the spec files written
//! before the scene modules (which read their specs' coefficients from generated/json); the
//! runtime index last. `--check` renders everything in memory and compares instead of writing.
//!
//! A build skips a spec whose last build is still current ([`RECORD_PATH`] records its input
//! hash and the SHA-256 of each file it wrote; both must match) and a scene module whose JSON
//! says the same of it and its nodes; `--force` rebuilds them. The input hash covers the spec
//! text (and what its kind reads) and the generator version, not the code: after changing the
//! code, `build --force` (`build --check` re-renders everything and finds what changed).
//!
//! Family spec kinds and scene features come from the registry (`crate::family`); the stages
//! below never name a family.

use crate::emit::targets::{self, Target, TargetError};
use crate::emit::{self, Artifact, Transaction, WriteError};
use crate::family;
use crate::pipeline::{self, BuildError, Built, CustomBuild, Mode};
use crate::scene::{self, Scene, SceneReport};
use crate::spec::{self, Spec, SpecError};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Errors of a build. [`Error::is_input`] tells the user's input (exit 2) from a failed job.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Spec(#[from] SpecError),
    #[error("no spec named '{name}' in {dir} (known: {known})")]
    UnknownSpec { name: String, dir: PathBuf, known: String },
    #[error("building {spec}")]
    Build {
        spec: String,
        #[source]
        source: BuildError,
    },
    /// A merge whose shards passed every check but whose merged build failed (a forged
    /// payload: its checksum recomputed over values the family cannot build from).
    #[error("merging {files}")]
    Merged {
        files: String,
        #[source]
        source: Box<Error>,
    },
    #[error("building scene {scene}")]
    Scene {
        scene: String,
        #[source]
        source: BuildError,
    },
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("translating an emitted WGSL module")]
    Target(#[from] TargetError),
    #[error("{count} generated file(s) differ from what the specs and committed coefficients produce; run `shadefit build`")]
    Stale { count: usize },
    #[error("generated/ holds an interrupted build ({}); the next `shadefit build` restores the files it replaced first", journal.display())]
    Interrupted { journal: PathBuf },
    #[error("{0}")]
    Shard(String),
    #[error("no spec (*.toml) in {}: nothing to build", dir.display())]
    NoSpecs { dir: PathBuf },
    #[error(
        "{} lists module(s) {modules} whose files are in {}, but no spec in {} (nor scene in its scenes/) builds them: \
         this build would drop them from the runtime crate. Build with the fits folder that holds their specs (--fits), \
         or, to retire a module, delete its files from {} first (`shadefit build --check` lists them)",
        index.display(), generated.display(), fits.display(), generated.display()
    )]
    DropsModules { index: PathBuf, modules: String, generated: PathBuf, fits: PathBuf },
}

impl Error {
    /// The error is the user's input (a spec, a manifest, a name), not a failed job.
    pub fn is_input(&self) -> bool {
        use crate::fit::FitError;
        use crate::pipeline::SceneError;
        match self {
            Error::Spec(_) | Error::UnknownSpec { .. } | Error::Shard(_) | Error::NoSpecs { .. } | Error::DropsModules { .. } => true,
            // A spec whose model cannot avoid a pole on its domain or whose basis is degenerate on
            // its samples (e.g. fixed denominator coefficients forcing a pole), or a scene naming a spec that fits/ lacks: the spec or
            // the manifest is what must change.
            Error::Merged { source, .. } => source.is_input(),
            Error::Build { source, .. } | Error::Scene { source, .. } => matches!(
                source,
                BuildError::Fit(FitError::PoleInDomain { .. } | FitError::SingularStart { .. })
                    | BuildError::Scene(SceneError::MissingSpec { .. })
            ),
            _ => false,
        }
    }
}

pub use crate::pipeline::Paths;

/// The builder of a family spec kind, from the registry.
pub fn custom_builder(kind: &str) -> Option<CustomBuild> {
    family::spec_kind(kind).map(|k| k.build)
}

/// Build one spec (any kind) in the given mode; `root` is the generated/ folder.
pub fn build_spec(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    pipeline::build_spec(spec, mode, root, &custom_builder)
}

/// Every spec in `paths.fits`, checking that each name in `only` is one of them and that
/// `[emit] targets` names targets.
pub fn load_specs(paths: &Paths, only: &[String]) -> Result<Vec<Spec>, Error> {
    family::register_lobes(&paths.fits)?;
    let specs = spec::load_dir(&paths.fits, family::catalog())?;
    for s in &specs {
        spec_targets(s)?;
        spec_formats(s)?;
    }
    for name in only {
        if !specs.iter().any(|s| &s.file.name == name) {
            return Err(Error::UnknownSpec {
                name: name.clone(),
                dir: paths.fits.clone(),
                known: specs.iter().map(|s| s.file.name.as_str()).collect::<Vec<_>>().join(", "),
            });
        }
    }
    Ok(specs)
}

/// The targets a spec's `[emit] targets` asks for.
pub fn spec_targets(s: &Spec) -> Result<Vec<Target>, SpecError> {
    targets::parse_list(s.file.emit.targets.as_deref().unwrap_or_default())
        .map_err(|why| SpecError::new(&s.path, spec::line_of(&s.text, "targets"), "targets", why))
}

/// `[emit] formats` checked before anything is built: known names, each once, and a spec
/// that writes a texture (a fit, a two-stage fit or a `form = "const"` table writes none; a
/// family kind without textures refuses the key when it parses).
pub fn spec_formats(s: &Spec) -> Result<(), SpecError> {
    let Some(list) = &s.file.emit.formats else { return Ok(()) };
    let bad = |why: String| SpecError::new(&s.path, spec::line_of(&s.text, "formats"), "formats", why);
    emit::formats::parse_list(list).map_err(bad)?;
    let texture = match s.file.kind {
        spec::Kind::Fit | spec::Kind::Fields => false,
        spec::Kind::Table => s.file.emit.form.unwrap_or_default().has_texture(),
        spec::Kind::Custom(_) => true,
    };
    if !texture {
        return Err(bad(emit::formats::NO_TEXTURE.into()));
    }
    Ok(())
}

/// The files of the other targets for every WGSL module among `artifacts` (`wgsl/NAME.wgsl`):
/// those `module_targets(NAME)` names, translated in parallel and collected in module order.
/// Every WGSL module among them is first checked by naga ([`targets::check`]), with or without
/// other targets: a module naga rejects fails the build before anything is written.
pub fn target_artifacts(artifacts: &[Artifact], module_targets: &(dyn Fn(&str) -> Vec<Target> + Sync)) -> Result<Vec<Artifact>, Error> {
    let wgsl: Vec<(String, &Artifact)> = artifacts
        .iter()
        .filter_map(|a| {
            let rel = a.path.strip_prefix("wgsl").ok()?;
            Some((rel.to_str()?.strip_suffix(".wgsl")?.to_string(), a))
        })
        .collect();
    wgsl.par_iter().map(|(name, a)| targets::check(name, &String::from_utf8_lossy(&a.contents))).collect::<Result<Vec<()>, TargetError>>()?;
    let modules: Vec<(String, &Artifact, Vec<Target>)> = wgsl
        .into_iter()
        .filter_map(|(name, a)| {
            let t = module_targets(&name);
            (!t.iter().all(|t| *t == Target::Wgsl)).then_some((name, a, t))
        })
        .collect();
    let files: Vec<Result<Vec<Artifact>, TargetError>> = modules
        .par_iter()
        .map(|(name, a, t)| targets::translate(name, &String::from_utf8_lossy(&a.contents), t))
        .collect();
    let mut out = Vec::new();
    for f in files {
        out.extend(f?);
    }
    let mut all: Vec<Target> = modules.iter().flat_map(|m| m.2.iter().copied()).collect();
    all.sort();
    all.dedup();
    out.extend(targets::package_files(&all));
    Ok(out)
}

/// Refuses to write `index` over the runtime index in generated/ when it would drop modules whose
/// files are there ([`pipeline::dropped_modules`]): a fits folder without their specs (another
/// `--fits`, or one holding only the `--only` spec) is not a reason to remove them from the crate.
fn keep_modules(paths: &Paths, index: &Artifact) -> Result<(), Error> {
    let dropped = pipeline::dropped_modules(&paths.generated, index);
    if dropped.is_empty() {
        return Ok(());
    }
    Err(Error::DropsModules {
        index: paths.generated.join(pipeline::INDEX_PATH),
        modules: dropped.join(", "),
        generated: paths.generated.clone(),
        fits: paths.fits.clone(),
    })
}

/// The scene manifests in `fits/scenes`.
pub fn load_scenes(paths: &Paths) -> Result<Vec<Scene>, Error> {
    Ok(Scene::load_dir(&paths.fits.join("scenes"), &family::scene_features())?)
}

/// What a build did: each spec's result and time, each scene module's time, files written.
#[derive(Debug)]
pub struct Summary {
    pub built: Vec<(Built, f64)>,
    pub scenes: Vec<(String, f64)>,
    /// Specs and scene modules skipped as up to date (their files reused as they are).
    pub up_to_date: Vec<String>,
    /// Files rendered in all (written or unchanged).
    pub files: usize,
    pub written: usize,
    /// `--check`: the files that differ (stale or orphaned); empty when up to date.
    pub stale: Vec<String>,
    pub specs: usize,
}

/// `shadefit build [--only A,B] [--check] [--force] [--target T,..]`; `tick(total)` is called
/// once per spec built. Every WGSL module is also written in `extra` targets and its spec's own
/// (`[emit] targets`); with neither, the outputs are the WGSL modules and their siblings only.
/// Without `force` (and without `check`, which renders everything), specs and scene modules
/// whose last build is current are skipped.
pub fn run(paths: &Paths, only: &[String], check: bool, force: bool, extra: &[Target], tick: &(dyn Fn(usize) + Sync)) -> Result<Summary, Error> {
    run_merged(paths, only, check, force, extra, tick, Default::default())
}

/// The build record, in generated/: for each spec, the input hash of its last build and the
/// SHA-256 of every file that build wrote.
pub const RECORD_PATH: &str = "build-record.json";

/// Spec name → (input hash, file → SHA-256).
type Record = BTreeMap<String, (String, BTreeMap<String, String>)>;

/// The record in `generated`, less the specs no longer in `specs` (empty when there is none or it
/// does not parse: then nothing is skipped).
fn read_record(generated: &Path, specs: &[Spec]) -> Record {
    let v: serde_json::Value = match std::fs::read(generated.join(RECORD_PATH)).ok().and_then(|b| serde_json::from_slice(&b).ok()) {
        Some(v) => v,
        None => return Record::new(),
    };
    let Some(entries) = v["specs"].as_object() else { return Record::new() };
    entries
        .iter()
        .filter(|(name, _)| specs.iter().any(|s| &&s.file.name == name))
        .filter_map(|(name, e)| {
            let files = e["files"].as_object()?.iter().map(|(p, h)| Some((p.clone(), h.as_str()?.to_string()))).collect::<Option<_>>()?;
            Some((name.clone(), (e["input_hash"].as_str()?.to_string(), files)))
        })
        .collect()
}

fn render_record(record: &Record) -> Artifact {
    let specs: serde_json::Map<String, serde_json::Value> = record
        .iter()
        .map(|(name, (hash, files))| (name.clone(), serde_json::json!({"input_hash": hash, "files": files})))
        .collect();
    let v = serde_json::json!({
        "description": "What each spec's last `shadefit build` wrote: its input hash and the SHA-256 of each file. \
            `build` skips a spec whose hash and files still match; `build --force` rebuilds it.",
        "generator": emit::GENERATOR,
        "specs": specs,
    });
    let mut text = serde_json::to_string_pretty(&v).expect("JSON values serialise");
    text.push('\n');
    Artifact { path: RECORD_PATH.into(), contents: text.into_bytes() }
}

/// The files of `name`'s last build, read back, when its record holds `hash` and every recorded
/// file is on disk unchanged.
fn reuse(generated: &Path, record: &Record, name: &str, hash: &str) -> Option<Vec<Artifact>> {
    let (_, files) = record.get(name).filter(|(h, _)| h == hash)?;
    pipeline::read_unchanged(generated, files.iter().map(|(p, d)| (p.as_str(), d.as_str())))
}

/// [`run`] with the cells `merge` gathered, by spec name, handed to those specs' builders
/// (`Spec::merged`).
fn run_merged(
    paths: &Paths,
    only: &[String],
    check: bool,
    force: bool,
    extra: &[Target],
    tick: &(dyn Fn(usize) + Sync),
    mut merged: std::collections::BTreeMap<String, Vec<u8>>,
) -> Result<Summary, Error> {
    let mut specs = load_specs(paths, only)?;
    if specs.is_empty() {
        return Err(Error::NoSpecs { dir: paths.fits.clone() });
    }
    for s in &mut specs {
        s.merged = merged.remove(&s.file.name).map(std::sync::Arc::new);
    }
    let selected: Vec<&Spec> = specs.iter().filter(|s| only.is_empty() || only.contains(&s.file.name)).collect();
    let mode = if check { Mode::Committed } else { Mode::Fit };
    // One transaction for every file of the build, its lock held from here: a second build
    // waits, and a failure anywhere leaves generated/ as it was. `--check` writes nothing.
    let mut tx = if check { None } else { Some(Transaction::begin(&paths.generated)?) };
    if check && let Some(journal) = emit::interrupted(&paths.generated) {
        return Err(Error::Interrupted { journal });
    }
    // The runtime index lists every spec in the folder and every scene, built now or not; it is
    // known before anything is built, and a build that would drop modules stops here.
    let scenes = load_scenes(paths)?;
    let index = scene::runtime_index(&specs, &scenes);
    if tx.is_some() {
        keep_modules(paths, &index)?;
    }
    let previous = read_record(&paths.generated, &specs);
    let mut record: Record = previous.clone();
    let build_all = |specs: &[&Spec]| -> Result<Vec<(Built, f64)>, Error> {
        let results: Vec<Result<(Built, f64), Error>> = specs
            .par_iter()
            .map(|s| {
                let t = std::time::Instant::now();
                let b = build_spec(s, mode, &paths.generated).map_err(|source| Error::Build { spec: s.file.name.clone(), source })?;
                tick(selected.len());
                Ok((b, t.elapsed().as_secs_f64()))
            })
            .collect();
        results.into_iter().collect()
    };
    // The selected specs to reuse (current, not forced, not handed merged cells); the rest are
    // built.
    let mut reused: Vec<(String, Vec<Artifact>)> = Vec::new();
    let mut needs_build = |s: &Spec, rebuilt: &[String]| -> bool {
        let skip = !check && !force && s.merged.is_none() && family::reads(s).iter().all(|r| !rebuilt.iter().any(|b| b == r));
        match skip.then(|| reuse(&paths.generated, &previous, &s.file.name, &hash_of(s))).flatten() {
            Some(files) => {
                tick(selected.len());
                reused.push((s.file.name.clone(), files));
                false
            }
            None => true,
        }
    };
    // Specs that read other specs' committed outputs (a refit of a form fitted to a committed
    // table) are built after the others are written, so they read this build's outputs; one
    // is rebuilt whenever a spec it reads was.
    let (later, first): (Vec<&Spec>, Vec<&Spec>) = selected.iter().copied().partition(|s| !family::reads(s).is_empty());
    let first: Vec<&Spec> = first.into_iter().filter(|s| needs_build(s, &[])).collect();
    let mut built = build_all(&first)?;
    let mut artifacts: Vec<_> = built.iter().flat_map(|(b, _)| b.artifacts.clone()).collect();
    // The scene modules read their specs' coefficients from generated/json: write this build's
    // first, so a scene never specialises the previous build's fit.
    let mut written = match tx.as_mut() {
        Some(tx) => tx.write(&artifacts)?,
        None => 0,
    };
    let rebuilt: Vec<String> = built.iter().map(|(b, _)| b.name.clone()).collect();
    let later: Vec<&Spec> = later.into_iter().filter(|s| needs_build(s, &rebuilt)).collect();
    let reading = build_all(&later)?;
    let reading_files: Vec<_> = reading.iter().flat_map(|(b, _)| b.artifacts.clone()).collect();
    if let Some(tx) = tx.as_mut() {
        written += tx.write(&reading_files)?;
    }
    artifacts.extend(reading_files);
    built.extend(reading);
    // Summaries list the specs in the order they were selected.
    built.sort_by_key(|(b, _)| selected.iter().position(|s| s.file.name == b.name));
    reused.sort_by_key(|(n, _)| selected.iter().position(|s| &s.file.name == n));
    let mut up_to_date: Vec<String> = reused.iter().map(|(n, _)| n.clone()).collect();
    for (b, _) in &built {
        let spec = specs.iter().find(|s| s.file.name == b.name).expect("built specs are loaded specs");
        let (name, hash, files) = scene::node_record(&b.name, hash_of(spec), &b.artifacts);
        record.insert(name, (hash, files));
    }
    // Every file of a spec: those just built and those reused (the same bytes, so unchanged).
    let spec_files = |name: &str| -> Option<&[Artifact]> {
        built.iter().find(|(b, _)| b.name == name).map(|(b, _)| b.artifacts.as_slice()).or_else(|| reused.iter().find(|(n, _)| n == name).map(|(_, f)| f.as_slice()))
    };
    artifacts.extend(reused.iter().flat_map(|(_, f)| f.iter().cloned()));
    let spec_count = artifacts.len();
    let mut scene_times = Vec::new();
    if only.is_empty() {
        // Every scene module, with the node files of this build recorded for its cache; one
        // whose JSON already records those nodes and its current input hash is reused.
        for sc in &scenes {
            let t = std::time::Instant::now();
            let nodes: Vec<scene::NodeRecord> = scene::plan(sc)
                .nodes
                .iter()
                .filter_map(|n| {
                    let spec = specs.iter().find(|s| &s.file.name == n)?;
                    Some(scene::node_record(n, pipeline::input_hash(spec), spec_files(n)?))
                })
                .collect();
            if !check && !force && let Some(files) = scene::fresh_files(sc, &specs, &paths.generated, &nodes) {
                artifacts.extend(files);
                up_to_date.push(sc.module());
                continue;
            }
            let sb = scene::build_scene(sc, &specs, &paths.generated, &nodes)
                .map_err(|source| Error::Scene { scene: sc.file.name.clone(), source })?;
            artifacts.extend(sb.artifacts);
            scene_times.push((sc.module(), t.elapsed().as_secs_f64()));
        }
    }
    artifacts.push(render_record(&record));
    artifacts.push(index);
    // Other targets of every module (spec or scene), from the WGSL just rendered.
    let module_targets = |module: &str| {
        let mut t: Vec<Target> = extra.to_vec();
        if let Some(s) = specs.iter().find(|s| s.file.name == module) {
            t.extend(spec_targets(s).unwrap_or_default());
        }
        t.sort();
        t.dedup();
        t
    };
    let translated = target_artifacts(&artifacts, &module_targets)?;
    let mut target_dirs: Vec<String> = translated.iter().filter_map(|a| Some(a.path.iter().next()?.to_str()?.to_string())).collect();
    target_dirs.sort();
    target_dirs.dedup();
    artifacts.extend(translated);
    let mut stale = Vec::new();
    if check {
        stale.extend(pipeline::stale(&paths.generated, &artifacts));
        if only.is_empty() {
            // The target folders of this build too, but only those it writes: another build may
            // have asked for other targets.
            let dirs: Vec<&str> = pipeline::OUTPUT_DIRS.iter().copied().chain(target_dirs.iter().map(String::as_str)).collect();
            stale.extend(
                pipeline::orphans_in(&paths.generated, &artifacts, &dirs).into_iter().map(|p| format!("{p} (no spec produces it)")),
            );
        }
    }
    if let Some(mut tx) = tx {
        // The spec files were written above; now the scene modules and the runtime index.
        written += tx.write(&artifacts[spec_count..])?;
        tx.commit()?;
    }
    Ok(Summary { built, scenes: scene_times, up_to_date, files: artifacts.len(), written, stale, specs: selected.len() })
}

/// `shadefit build --scene FILE [--force]`: only the nodes the scene reaches, each only when its
/// inputs or files changed since the scene's last build, then the scene module.
pub fn run_scene(paths: &Paths, file: &Path, force: bool, extra: &[Target]) -> Result<SceneReport, Error> {
    let sc = Scene::load(file, &family::scene_features())?;
    let specs = load_specs(paths, &[])?;
    let mut scenes = load_scenes(paths)?;
    if !scenes.iter().any(|s| s.file.name == sc.file.name) {
        scenes.push(sc.clone());
    }
    let mut tx = Transaction::begin(&paths.generated)?;
    // The index the scene's build writes lists the same specs and scenes.
    keep_modules(paths, &scene::runtime_index(&specs, &scenes))?;
    // Every module in the `--target` targets and its spec's own, as `build` writes them.
    let translate = |module: &str, text: &str| -> Result<Vec<Artifact>, BuildError> {
        targets::check(module, text)?;
        let mut t: Vec<Target> = extra.to_vec();
        if let Some(s) = specs.iter().find(|s| s.file.name == module) {
            t.extend(spec_targets(s)?);
        }
        t.sort();
        t.dedup();
        if t.iter().all(|t| *t == Target::Wgsl) {
            return Ok(Vec::new());
        }
        Ok(targets::translate(module, text, &t)?)
    };
    let report = scene::build(&sc, &specs, &scenes, &paths.generated, force, &custom_builder, &translate, &mut tx)
        .map_err(|source| Error::Scene { scene: sc.file.name.clone(), source })?;
    // The package files of those targets (the WESL manifest), as `build` writes them.
    let mut all: Vec<Target> = extra.to_vec();
    for s in &specs {
        all.extend(spec_targets(s).unwrap_or_default());
    }
    all.sort();
    all.dedup();
    tx.write(&targets::package_files(&all))?;
    // The nodes rebuilt now, in the build record, so a later `build` skips them.
    if !report.built.is_empty() {
        write_scene_nodes(paths, &specs, &report, &mut tx)?;
    }
    tx.commit()?;
    Ok(report)
}

fn write_scene_nodes(paths: &Paths, specs: &[Spec], report: &SceneReport, tx: &mut Transaction) -> Result<(), Error> {
    let mut record = read_record(&paths.generated, specs);
    for (name, _, files) in report.nodes.iter().filter(|(n, _, _)| report.built.contains(n)) {
        if let Some(spec) = specs.iter().find(|s| &s.file.name == name) {
            record.insert(name.clone(), (hash_of(spec), files.clone()));
        }
    }
    tx.write(&[render_record(&record)])?;
    Ok(())
}

/// Whether a spec's committed outputs were generated from it, by hashes alone.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Status {
    /// `generated/json/NAME.json` records the spec's current input hash.
    Current,
    /// It records another hash: the spec (or a file it reads) changed since.
    Changed,
    /// No readable `generated/json/NAME.json`.
    NotBuilt,
}

/// `shadefit list`: each spec with its [`Status`]. It compares the input hash recorded in the
/// committed JSON with the spec's (no integration, fitting or rendering); `build --check`
/// re-renders every file and compares the bytes.
pub fn status(paths: &Paths) -> Result<Vec<(Spec, Status)>, Error> {
    family::register_lobes(&paths.fits)?;
    let specs = spec::load_dir(&paths.fits, family::catalog())?;
    Ok(specs
        .into_iter()
        .map(|s| {
            let current = match s.file.kind {
                spec::Kind::Custom(kind) => family::catalog().kind(kind).map_or_else(|| pipeline::input_hash(&s), |k| (k.input_hash)(&s)),
                _ => pipeline::input_hash(&s),
            };
            let st = match pipeline::committed_json_with_hash(&paths.generated, &s, &current) {
                Ok(_) => Status::Current,
                Err(BuildError::SpecChanged { .. }) => Status::Changed,
                Err(_) => Status::NotBuilt,
            };
            (s, st)
        })
        .collect())
}

/// First line of a shard file; a JSON header line and the payload follow.
pub const SHARD_MAGIC: &str = "shadefit-shard 1";

/// `K/N` (0 ≤ K < N) of `build --shard`.
pub fn parse_shard(text: &str) -> Result<(u64, u64), Error> {
    let bad = || Error::Shard(format!("--shard '{text}': expected K/N with 0 <= K < N (e.g. 0/8)"));
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let (k, n): (u64, u64) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if n == 0 || k >= n {
        return Err(bad());
    }
    Ok((k, n))
}

/// The cells [lo, hi) of shard k of n over `total` cells (contiguous, in order, sizes within one).
pub fn shard_range(total: u64, k: u64, n: u64) -> std::ops::Range<u64> {
    let at = |i: u64| ((total as u128 * i as u128) / n as u128) as u64;
    at(k)..at(k + 1)
}

/// The input hash a spec's outputs record (its kind's).
fn hash_of(spec: &Spec) -> String {
    match spec.file.kind {
        spec::Kind::Custom(kind) => family::spec_kind(kind).map_or_else(|| pipeline::input_hash(spec), |k| (k.spec.input_hash)(spec)),
        _ => pipeline::input_hash(spec),
    }
}

fn sharding_of(spec: &Spec) -> Option<&'static family::Sharding> {
    match spec.file.kind {
        spec::Kind::Custom(kind) => family::spec_kind(kind)?.shard.as_ref(),
        _ => None,
    }
}

/// `build --shard K/N`: the cells of shard K of N of each named spec (every spec whose kind
/// shards, when none is named) into `out/NAME.K-of-N.shard`. Writes nothing under generated/.
pub fn shard(paths: &Paths, only: &[String], (k, n): (u64, u64), out: &Path) -> Result<Vec<PathBuf>, Error> {
    let specs = load_specs(paths, only)?;
    let selected: Vec<&Spec> = specs.iter().filter(|s| if only.is_empty() { sharding_of(s).is_some() } else { only.contains(&s.file.name) }).collect();
    let mut jobs = Vec::new();
    for s in &selected {
        let sh = sharding_of(s).ok_or_else(|| Error::Shard(format!("{}: kind {:?} does not shard (only family table kinds with independent cells do)", s.file.name, s.file.kind)))?;
        jobs.push((*s, sh));
    }
    let mut files = Vec::new();
    for (s, sh) in jobs {
        let name = s.file.name.clone();
        let total = (sh.cells)(s).map_err(|source| Error::Build { spec: name.clone(), source })?;
        let range = shard_range(total, k, n);
        let payload = (sh.compute)(s, range.clone()).map_err(|source| Error::Build { spec: name.clone(), source })?;
        let header = serde_json::json!({
            "generator": emit::GENERATOR,
            "spec": name,
            "input_hash": hash_of(s),
            "shard": k,
            "of": n,
            "cells": [range.start, range.end],
            "total_cells": total,
            "payload_bytes": payload.len(),
            "payload_sha256": pipeline::sha256_hex(&payload),
        });
        let mut bytes = format!("{SHARD_MAGIC}\n{header}\n").into_bytes();
        bytes.extend_from_slice(&payload);
        std::fs::create_dir_all(out).map_err(|e| Error::Shard(format!("cannot create {}: {e}", out.display())))?;
        let path = out.join(format!("{name}.{k}-of-{n}.shard"));
        std::fs::write(&path, &bytes).map_err(|e| Error::Shard(format!("cannot write {}: {e}", path.display())))?;
        files.push(path);
    }
    Ok(files)
}

struct ShardFile {
    spec: String,
    hash: String,
    k: u64,
    n: u64,
    cells: [u64; 2],
    total: u64,
    payload: Vec<u8>,
}

fn read_shard(path: &Path) -> Result<ShardFile, Error> {
    let bad = |why: String| Error::Shard(format!("{}: {why}", path.display()));
    let bytes = crate::spec::input::read_input(path).map_err(|e| bad(e.to_string()))?;
    let mut lines = bytes.splitn(3, |&b| b == b'\n');
    if lines.next() != Some(SHARD_MAGIC.as_bytes()) {
        return Err(bad(format!("not a shard file (line 1 is not '{SHARD_MAGIC}')")));
    }
    let header: serde_json::Value = lines.next().and_then(|h| serde_json::from_slice(h).ok()).ok_or_else(|| bad("line 2 is not a JSON header".into()))?;
    let payload = lines.next().unwrap_or_default().to_vec();
    let field = |f: &str| header[f].as_u64().ok_or_else(|| bad(format!("header field '{f}' is missing")));
    let text = |f: &str| header[f].as_str().ok_or_else(|| bad(format!("header field '{f}' is missing")));
    if text("generator")? != emit::GENERATOR {
        return Err(bad(format!("made by {} (this is {}); run its shards again", text("generator")?, emit::GENERATOR)));
    }
    // A checksum of the payload: a corrupted or edited cell is refused, not merged.
    if pipeline::sha256_hex(&payload) != text("payload_sha256")? {
        return Err(bad("the payload does not match its checksum (header field 'payload_sha256'): the file is corrupted or was edited; run its shard again".into()));
    }
    let cells = match header["cells"].as_array().map(Vec::as_slice) {
        Some([a, b]) => [a.as_u64(), b.as_u64()],
        _ => [None, None],
    };
    let sf = ShardFile {
        spec: header["spec"].as_str().ok_or_else(|| bad("header field 'spec' is missing".into()))?.to_string(),
        hash: header["input_hash"].as_str().ok_or_else(|| bad("header field 'input_hash' is missing".into()))?.to_string(),
        k: field("shard")?,
        n: field("of")?,
        cells: match cells {
            [Some(a), Some(b)] => [a, b],
            _ => return Err(bad("header field 'cells' is not [lo, hi]".into())),
        },
        total: field("total_cells")?,
        payload,
    };
    if sf.payload.len() as u64 != field("payload_bytes")? {
        return Err(bad(format!("payload holds {} bytes, the header says {}", sf.payload.len(), field("payload_bytes")?)));
    }
    Ok(sf)
}

/// `merge FILES…`: the shard files of one or more specs combined (every shard of each present
/// once, made from the current spec) and built exactly as a single-machine `build --only` of
/// those specs would, into generated/.
pub fn merge(paths: &Paths, files: &[PathBuf], tick: &(dyn Fn(usize) + Sync)) -> Result<Summary, Error> {
    if files.is_empty() {
        return Err(Error::Shard("merge: no shard files given".into()));
    }
    let mut by_spec: std::collections::BTreeMap<String, Vec<(ShardFile, PathBuf)>> = Default::default();
    for f in files {
        let sf = read_shard(f)?;
        by_spec.entry(sf.spec.clone()).or_default().push((sf, f.clone()));
    }
    let names: Vec<String> = by_spec.keys().cloned().collect();
    let specs = load_specs(paths, &names)?;
    let mut merged = std::collections::BTreeMap::new();
    for (name, mut parts) in by_spec {
        let spec = specs.iter().find(|s| s.file.name == name).expect("load_specs checked the names");
        let sh = sharding_of(spec).ok_or_else(|| Error::Shard(format!("{name}: its kind does not shard")))?;
        let hash = hash_of(spec);
        parts.sort_by_key(|(p, _)| p.k);
        let n = parts[0].0.n;
        let total = (sh.cells)(spec).map_err(|source| Error::Build { spec: name.clone(), source })?;
        let mut payload = Vec::new();
        for (i, (p, path)) in parts.iter().enumerate() {
            let at = |why: String| Error::Shard(format!("{}: {why}", path.display()));
            if p.hash != hash {
                return Err(at(format!("made from another version of fits/{name}.toml (input hash {}, the spec's is {hash}); run its shards again", p.hash)));
            }
            if p.n != n || p.total != total {
                return Err(at(format!("shard {}/{} of {} cells does not belong with {}-way shards of {total} cells", p.k, p.n, p.total, n)));
            }
            if p.k != i as u64 {
                let why = if p.k < i as u64 { format!("shard {} is given twice", p.k) } else { format!("shard {i} is missing") };
                return Err(at(format!("{why}; each of 0..{n} must be given once")));
            }
            let r = shard_range(total, p.k, n);
            if p.cells != [r.start, r.end] {
                return Err(at(format!("cells {:?} are not shard {}/{n}'s {:?}", p.cells, p.k, r)));
            }
            payload.extend_from_slice(&p.payload);
        }
        if parts.len() as u64 != n {
            return Err(Error::Shard(format!("{name}: {} of {n} shards given", parts.len())));
        }
        merged.insert(name, payload);
    }
    let given = files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(", ");
    run_merged(paths, &names, false, true, &[], tick, merged).map_err(|e| Error::Merged { files: given, source: Box::new(e) })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A WGSL module naga rejects fails `target_artifacts` even when no other target is asked
    /// for (the build's backstop before its transaction commits), and names the module; the
    /// same module made valid passes.
    #[test]
    fn every_emitted_wgsl_module_is_checked_by_naga() {
        let module = |body: &str| Artifact {
            path: PathBuf::from("wgsl/m.wgsl"),
            contents: format!("// header\n#define_import_path shadefit::m\n\nfn m_f(min: f32) -> f32 {{\n    return {body};\n}}\n").into_bytes(),
        };
        let err = target_artifacts(&[module("min(min, 1f)")], &|_| vec![Target::Wgsl]).unwrap_err();
        let err = format!("{err}: {}", std::error::Error::source(&err).map(|e| e.to_string()).unwrap_or_default());
        assert!(err.contains("m: naga rejects the emitted WGSL module"), "{err}");
        assert!(target_artifacts(&[module("max(min, 1f)")], &|_| vec![Target::Wgsl]).unwrap().is_empty());
    }

    /// Every module of the runtime index is gated on its family's feature (its quantity up to the
    /// first '-'), and the runtime crate's manifest declares every feature the index names: a
    /// `cfg(feature)` on an undeclared name compiles its module out with only a warning. Over the
    /// committed specs (fits/) and generated/Cargo.toml's `[features]`. Here, not in `pipeline`:
    /// the catalog of the committed specs is `family`'s, and `pipeline` does not import `family`.
    #[test]
    fn the_runtime_index_gates_modules_on_features_the_runtime_crate_declares() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        family::register_lobes(&root.join("fits")).unwrap();
        let specs = spec::load_dir(&root.join("fits"), family::catalog()).unwrap();
        assert!(specs.len() > 20, "{} specs", specs.len());
        let text = String::from_utf8(pipeline::runtime_index(&specs).contents).unwrap();
        let manifest: toml::Table = std::fs::read_to_string(root.join("generated/Cargo.toml")).unwrap().parse().unwrap();
        let declared = manifest["features"].as_table().unwrap();
        let named: std::collections::BTreeSet<&str> = text.split("feature = \"").skip(1).map(|r| r.split('"').next().unwrap()).collect();
        for f in &named {
            assert!(declared.contains_key(*f), "the index names feature '{f}', which generated/Cargo.toml does not declare");
        }
        for s in &specs {
            // A family's quantities are named FAMILY-…; a lobe spec's module is the lobes feature's.
            let fam = if s.file.kind == spec::Kind::Custom(pipeline::lobe::KIND) {
                "lobes"
            } else {
                s.file.quantity.split_once('-').map_or(s.file.quantity.as_str(), |(f, _)| f)
            };
            let gate = format!("#[cfg(feature = \"{fam}\")]\n#[path = \"{}.rs\"]", s.file.name);
            assert!(text.contains(&gate), "{}: no '{gate}'", s.file.name);
        }
    }
}
