//! The build orchestration behind `shadefit build` and `build --scene`: specs built
//! concurrently on the rayon pool (each also parallelises its own sampling on the same pool),
//! collected in spec order so the outputs do not depend on scheduling; the spec files written
//! before the scene modules (which read their specs' coefficients from generated/json); the
//! runtime index last. `--check` renders everything in memory and compares instead of writing.
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
}

impl Error {
    /// The error is the user's input (a spec, a manifest, a name), not a failed job.
    pub fn is_input(&self) -> bool {
        use crate::fit::FitError;
        use crate::pipeline::SceneError;
        match self {
            Error::Spec(_) | Error::UnknownSpec { .. } => true,
            // A spec whose model cannot avoid a pole on its domain or whose basis is degenerate on
            // its samples (e.g. fixed denominator coefficients forcing a pole), or a scene naming a spec that fits/ lacks: the spec or
            // the manifest is what must change.
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
    let specs = spec::load_dir(&paths.fits, family::catalog())?;
    for s in &specs {
        spec_targets(s)?;
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

/// The files of the other targets for every WGSL module among `artifacts` (`wgsl/NAME.wgsl`):
/// those `module_targets(NAME)` names, translated in parallel and collected in module order.
pub fn target_artifacts(artifacts: &[Artifact], module_targets: &(dyn Fn(&str) -> Vec<Target> + Sync)) -> Result<Vec<Artifact>, Error> {
    let modules: Vec<(String, &Artifact, Vec<Target>)> = artifacts
        .iter()
        .filter_map(|a| {
            let rel = a.path.strip_prefix("wgsl").ok()?;
            let name = rel.to_str()?.strip_suffix(".wgsl")?.to_string();
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
    Ok(out)
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
    /// Files rendered in all (written or unchanged).
    pub files: usize,
    pub written: usize,
    /// `--check`: the files that differ (stale or orphaned); empty when up to date.
    pub stale: Vec<String>,
    pub specs: usize,
}

/// `shadefit build [--only A,B] [--check] [--target T,..]`; `tick(total)` is called once per
/// spec built. Every WGSL module is also written in `extra` targets and its spec's own
/// (`[emit] targets`); with neither, the outputs are the WGSL modules and their siblings only.
pub fn run(paths: &Paths, only: &[String], check: bool, extra: &[Target], tick: &(dyn Fn(usize) + Sync)) -> Result<Summary, Error> {
    let specs = load_specs(paths, only)?;
    let selected: Vec<&Spec> = specs.iter().filter(|s| only.is_empty() || only.contains(&s.file.name)).collect();
    let mode = if check { Mode::Committed } else { Mode::Fit };
    // One transaction for every file of the build, its lock held from here: a second build
    // waits, and a failure anywhere leaves generated/ as it was. `--check` writes nothing.
    let mut tx = if check { None } else { Some(Transaction::begin(&paths.generated)?) };
    if check && let Some(journal) = emit::interrupted(&paths.generated) {
        return Err(Error::Interrupted { journal });
    }
    let results: Vec<Result<(Built, f64), Error>> = selected
        .par_iter()
        .map(|s| {
            let t = std::time::Instant::now();
            let b = build_spec(s, mode, &paths.generated).map_err(|source| Error::Build { spec: s.file.name.clone(), source })?;
            tick(selected.len());
            Ok((b, t.elapsed().as_secs_f64()))
        })
        .collect();
    let built: Vec<(Built, f64)> = results.into_iter().collect::<Result<_, _>>()?;
    let scenes = load_scenes(paths)?;
    let mut artifacts: Vec<_> = built.iter().flat_map(|(b, _)| b.artifacts.clone()).collect();
    // The scene modules read their specs' coefficients from generated/json: write this build's
    // first, so a scene never specialises the previous build's fit.
    let spec_files = artifacts.len();
    let mut written = match tx.as_mut() {
        Some(tx) => tx.write(&artifacts)?,
        None => 0,
    };
    let mut scene_times = Vec::new();
    if only.is_empty() {
        // Every scene module, with the node files of this build recorded for its cache.
        for sc in &scenes {
            let t = std::time::Instant::now();
            let nodes: Vec<scene::NodeRecord> = scene::plan(sc)
                .nodes
                .iter()
                .filter_map(|n| {
                    let (b, _) = built.iter().find(|(b, _)| &b.name == n)?;
                    let spec = specs.iter().find(|s| &s.file.name == n)?;
                    Some(scene::node_record(n, pipeline::input_hash(spec), &b.artifacts))
                })
                .collect();
            let sb = scene::build_scene(sc, &specs, &paths.generated, &nodes)
                .map_err(|source| Error::Scene { scene: sc.file.name.clone(), source })?;
            artifacts.extend(sb.artifacts);
            scene_times.push((sc.module(), t.elapsed().as_secs_f64()));
        }
    }
    artifacts.push(scene::runtime_index(&specs, &scenes));
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
        written += tx.write(&artifacts[spec_files..])?;
        tx.commit()?;
    }
    Ok(Summary { built, scenes: scene_times, files: artifacts.len(), written, stale, specs: selected.len() })
}

/// `shadefit build --scene FILE [--force]`: only the nodes the scene reaches, each only when its
/// inputs or files changed since the scene's last build, then the scene module.
pub fn run_scene(paths: &Paths, file: &Path, force: bool) -> Result<SceneReport, Error> {
    let sc = Scene::load(file, &family::scene_features())?;
    let specs = load_specs(paths, &[])?;
    let mut scenes = load_scenes(paths)?;
    if !scenes.iter().any(|s| s.file.name == sc.file.name) {
        scenes.push(sc.clone());
    }
    let mut tx = Transaction::begin(&paths.generated)?;
    let report = scene::build(&sc, &specs, &scenes, &paths.generated, force, &custom_builder, &mut tx)
        .map_err(|source| Error::Scene { scene: sc.file.name.clone(), source })?;
    tx.commit()?;
    Ok(report)
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
