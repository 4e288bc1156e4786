//! `shadefit bench`: run time against error, for the integrators, the fits, the default tables
//! (side by side with a straightforward numpy/scipy implementation of the same integrals) and
//! the shader forms a user picks from.
//!
//! - [`integrals`]: every integrator, method × tolerance (or resolution) → wall time,
//!   integrand evaluations and max error against a converged reference.
//! - [`fits`]: every fit solver × objective → time, iterations, max and rms error.
//! - [`tables`]: each default table, shadefit against `benches/numpy_tables.py` at equal max
//!   error, with the speed ratio.
//! - [`builds`]: whole spec builds from scratch, on the pool and on one thread (byte-identical
//!   or not), with the op counts of named emitted functions.
//! - [`forms`]: shader cost (op counts from naga's IR, [`ops`]) against max error, several
//!   approximation forms per quantity.
//!
//! The harness names no family: what each section runs comes from the [`FamilyBench`] hooks the
//! caller passes (the CLI passes every registered family's), and the helpers here (timing,
//! ladders, rows, the Pareto front, rendering) are what the families build their rows with.
//!
//! Quick mode (`--quick`, what the test command runs) uses fewer points and settings; both
//! modes print one table per section, or one JSON document with `--json`.

pub mod builds;
pub mod fits;
pub mod forms;
pub mod integrals;
pub mod ops;
pub mod tables;

use crate::pipeline::BuildError;
use crate::spec::{Catalog, Spec, SpecError};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a benchmark run failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A spec in fits/, or a variant of one made for a form, does not load.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// A committed spec's text is not TOML (variants start from it).
    #[error("{path}: not a TOML table")]
    SpecToml {
        path: PathBuf,
        #[source]
        source: toml::de::Error,
    },
    /// A variant of a spec could not be written back as TOML.
    #[error("variant {spec}")]
    VariantToml {
        spec: String,
        #[source]
        source: toml::ser::Error,
    },
    /// Fitting, verifying or emitting a form through the pipeline.
    #[error("building {spec}")]
    Build {
        spec: String,
        #[source]
        source: BuildError,
    },
    /// A build made no WGSL library.
    #[error("{spec}: no WGSL artifact")]
    NoWgsl { spec: String },
    #[error("{spec}: the WGSL artifact is not UTF-8")]
    WgslUtf8 {
        spec: String,
        #[source]
        source: std::str::Utf8Error,
    },
    /// Counting the operations of a form's emitted function.
    #[error("{spec}: counting the operations of `{function}`")]
    Ops {
        spec: String,
        function: String,
        #[source]
        source: ops::OpsError,
    },
    /// A form's emitted WGSL does not parse or validate.
    #[error("{spec}: reading the emitted WGSL")]
    Wgsl {
        spec: String,
        #[source]
        source: ops::OpsError,
    },
    /// The temporary folder the numpy/scipy script exchanges its files through.
    #[error("creating a temporary folder")]
    TempDir {
        #[source]
        source: std::io::Error,
    },
    #[error("writing {path}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("reading {path}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("parsing {path}")]
    Json {
        path: PathBuf,
        #[source]
        source: serde_json::Error,
    },
    /// The numpy/scipy script could not be started.
    #[error("running {} {}", interpreter.display(), script.display())]
    PythonStart {
        interpreter: PathBuf,
        script: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The numpy/scipy script failed.
    #[error("{} exited with {status}", script.display())]
    Python {
        script: PathBuf,
        status: std::process::ExitStatus,
    },
}

impl BenchError {
    /// `building {spec}` of a pipeline error.
    pub fn build(spec: &str) -> impl FnOnce(BuildError) -> BenchError + '_ {
        move |source| BenchError::Build { spec: spec.to_string(), source }
    }

    /// The message with its causes, `: `-separated.
    pub fn chain(&self) -> String {
        let mut s = self.to_string();
        let mut cause = std::error::Error::source(self);
        while let Some(c) = cause {
            let _ = write!(s, ": {c}");
            cause = c.source();
        }
        s
    }
}

/// Quick (CI) or full run.
#[derive(Debug, Clone, Copy)]
pub struct Mode {
    pub quick: bool,
    /// Repeat a timed workload until it has run this long (short workloads are noise otherwise).
    pub min_seconds: f64,
}

impl Mode {
    pub fn new(quick: bool) -> Mode {
        Mode {
            quick,
            min_seconds: if quick { 0.02 } else { 0.2 },
        }
    }
}

/// Seconds per call of `f` (repeated until `min_seconds` have passed) and its last result.
pub fn time_it<T>(min_seconds: f64, mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut runs = 0u32;
    loop {
        let r = f();
        runs += 1;
        let elapsed = start.elapsed().as_secs_f64();
        if elapsed >= min_seconds || runs >= 1_000_000 {
            return (elapsed / runs as f64, r);
        }
    }
}

/// splitmix64 (the one generator, `integrate::rng`): the fixed-seed generator of the Monte
/// Carlo baselines and the sample subsets.
pub use crate::integrate::rng::SplitMix64 as SplitMix;

/// Which sections to run.
#[derive(Debug, Clone, Copy)]
pub struct Sections {
    pub integrators: bool,
    pub fits: bool,
    pub tables: bool,
    pub builds: bool,
    pub forms: bool,
}

/// The whole benchmark run.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub mode: &'static str,
    pub threads: usize,
    pub seconds: f64,
    pub integrators: Vec<integrals::IntegratorRow>,
    pub fits: Vec<fits::FitRow>,
    pub tables: Vec<tables::TableRow>,
    pub builds: Vec<builds::BuildRow>,
    pub forms: Vec<forms::FormRow>,
}

/// What the sections run on.
pub struct Inputs<'a> {
    /// The specs in fits/ (the fits and tables sections pick theirs by name).
    pub specs: &'a [Spec],
    /// The catalog the specs load with (the forms section loads specs and variants of them).
    pub catalog: &'a Catalog,
    /// The spec folder (fits/) and the committed outputs (generated/).
    pub fits: &'a Path,
    pub generated: &'a Path,
    /// The numpy/scipy side of the tables section; `None`: shadefit's side only.
    pub python: Option<&'a tables::Python>,
    /// The builder of a family spec kind by name (the builds section builds any spec).
    pub custom: &'a (dyn Fn(&str) -> Option<crate::pipeline::CustomBuild> + Sync),
}

/// Run the selected sections over the rows of `families`.
pub fn run(mode: Mode, sections: Sections, inputs: &Inputs, families: &[&FamilyBench]) -> Result<Report, BenchError> {
    let start = Instant::now();
    let integrators = if sections.integrators {
        integrals::all(&mode, families)
    } else {
        Vec::new()
    };
    let fits = if sections.fits {
        fits::all(&mode, inputs.specs, families)
    } else {
        Vec::new()
    };
    let tables = if sections.tables {
        tables::all(&mode, inputs.specs, families, inputs.python)?
    } else {
        Vec::new()
    };
    let builds = if sections.builds {
        builds::all(&mode, inputs.specs, inputs.generated, inputs.custom, families)?
    } else {
        Vec::new()
    };
    let forms = if sections.forms {
        let ctx = forms::Ctx { fits: inputs.fits, generated: inputs.generated, quick: mode.quick, catalog: inputs.catalog };
        forms::all(&ctx, families)?
    } else {
        Vec::new()
    };
    Ok(Report {
        mode: if mode.quick { "quick" } else { "full" },
        threads: rayon::current_num_threads(),
        seconds: start.elapsed().as_secs_f64(),
        integrators,
        fits,
        tables,
        builds,
        forms,
    })
}

fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.2e}")
    }
}

fn opt_sci(v: Option<f64>) -> String {
    v.map_or("-".into(), sci)
}

fn seconds(s: f64) -> String {
    match s {
        s if s >= 1.0 => format!("{s:.2} s"),
        s if s >= 1e-3 => format!("{:.2} ms", s * 1e3),
        s if s >= 1e-6 => format!("{:.2} µs", s * 1e6),
        s => format!("{:.1} ns", s * 1e9),
    }
}

/// The human-readable report: one table per section.
pub fn render(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "shadefit bench ({} mode, {} thread(s) for the parallel parts, {:.1} s)",
        r.mode, r.threads, r.seconds
    );
    if !r.integrators.is_empty() {
        let _ = writeln!(
            s,
            "\n## Integrators (one thread; time and evaluations per point; error against the named reference)\n"
        );
        let mut last = "";
        for row in &r.integrators {
            if row.quantity != last {
                let _ = writeln!(
                    s,
                    "{} ({} points; reference: {})",
                    row.quantity, row.points, row.reference
                );
                let _ = writeln!(
                    s,
                    "  {:<72} {:>12} {:>12} {:>12} {:>10} {:>10}",
                    "method", "setting", "time/point", "evals/point", "max err", "max est"
                );
                last = row.quantity;
            }
            let _ = writeln!(
                s,
                "  {:<72} {:>12} {:>12} {:>12.0} {:>10} {:>10}",
                row.method,
                row.setting,
                seconds(row.seconds_per_point),
                row.evals_per_point,
                sci(row.max_error),
                opt_sci(row.max_estimate)
            );
        }
    }
    if !r.fits.is_empty() {
        let _ = writeln!(
            s,
            "\n## Fits (solver × objective; errors on the fitting samples)\n"
        );
        let _ = writeln!(
            s,
            "  {:<13} {:>7} {:>5} {:<36} {:<8} {:>10} {:>6} {:>7} {:>10} {:>10} {:>9}",
            "spec",
            "samples",
            "free",
            "solver",
            "objective",
            "time",
            "iters",
            "evals",
            "max err",
            "rms err",
            "cond"
        );
        for f in &r.fits {
            let obj = serde_json::to_value(f.objective)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default();
            let _ = writeln!(
                s,
                "  {:<13} {:>7} {:>5} {:<36} {:<8} {:>10} {:>6} {:>7} {:>10} {:>10} {:>9}{}",
                f.spec,
                f.samples,
                f.free_coefficients,
                f.solver,
                obj,
                seconds(f.seconds),
                f.iterations.map_or("-".into(), |v| v.to_string()),
                f.evaluations.map_or("-".into(), |v| v.to_string()),
                opt_sci(f.max_error),
                opt_sci(f.rms_error),
                opt_sci(f.condition_number),
                f.failure
                    .as_ref()
                    .map_or(String::new(), |e| format!("  FAILED: {e}"))
            );
        }
    }
    if !r.tables.is_empty() {
        let _ = writeln!(
            s,
            "\n## Tables against numpy/scipy (one thread each; seconds per point on a seeded subset of the grid; ratio at max error ≤ {:.0e})\n",
            tables::TARGET_ERROR
        );
        for t in &r.tables {
            let _ = writeln!(
                s,
                "{} ({}; {} points, {} sampled; build tolerance {:.0e})",
                t.name, t.quantity, t.table_points, t.sample_points, t.build_tolerance
            );
            let _ = writeln!(
                s,
                "  {:<44} {:<22} {:>12} {:>10} {:>12}",
                "method", "setting", "time/point", "max err", "table time"
            );
            for c in t.shadefit.iter().chain(&t.numpy) {
                let _ = writeln!(
                    s,
                    "  {:<44} {:<22} {:>12} {:>10} {:>12}{}",
                    c.method,
                    c.setting,
                    seconds(c.seconds_per_point),
                    opt_sci(c.max_error),
                    seconds(c.seconds_per_point * t.table_points as f64),
                    if c.note.is_empty() {
                        String::new()
                    } else {
                        format!("  ({})", c.note)
                    }
                );
            }
            s.push_str(&ratio_line("", &t.ratio, &t.note));
            if t.ratio_integrators.is_some() {
                s.push_str(&ratio_line("without closed forms: ", &t.ratio_integrators, &t.note));
            }
        }
    }
    if !r.builds.is_empty() {
        let _ = writeln!(s, "\n## Builds (from scratch, nothing written: the pool, then one thread)\n");
        s.push_str(&builds::render(&r.builds));
    }
    if !r.forms.is_empty() {
        let _ = writeln!(
            s,
            "\n## Shader forms (op counts from naga's IR; max error of the f32 code)\n"
        );
        s.push_str(&forms::render(&r.forms));
    }
    s
}

/// The "=> …" line of a table's comparison at equal error (or why there is none).
fn ratio_line(label: &str, ratio: &Option<tables::Ratio>, note: &str) -> String {
    let Some(q) = ratio else {
        return format!("  => {label}no ratio{}\n", if note.is_empty() { String::new() } else { format!(": {note}") });
    };
    format!(
        "  => {label}shadefit {} ({} err, {}/pt) vs {} {} ({} err, {}/pt): {}× speed-up{}\n",
        q.shadefit.setting,
        opt_sci(q.shadefit.max_error),
        seconds(q.shadefit.seconds_per_point),
        q.numpy.method,
        q.numpy.setting,
        opt_sci(q.numpy.max_error),
        seconds(q.numpy.seconds_per_point),
        if q.speedup < 10.0 { format!("{:.1}", q.speedup) } else { format!("{:.0}", q.speedup) },
        if q.at_target { String::new() } else { format!(" (numpy did not reach {:.0e})", tables::TARGET_ERROR) }
    )
}

/// A family's benchmark rows (the `bench` field of its `Family` descriptor): plain data and
/// function pointers. Each item has an `order`, its place in its section across families: a
/// section runs and reports its items by `order` (ties in the order the families are passed).
#[derive(Debug, Clone, Copy)]
pub struct FamilyBench {
    /// Integrator tables (the integrators section).
    pub integrators: &'static [integrals::IntegratorBench],
    /// Fit specs timed with every solver and objective (the fits section).
    pub fits: &'static [fits::FitBench],
    /// Default tables compared with numpy/scipy (the tables section).
    pub tables: &'static [tables::TableBench],
    /// Specs built whole, timed on the pool and on one thread (the builds section).
    pub builds: &'static [builds::BuildBench],
    /// Shader forms, one set per quantity (the forms section).
    pub forms: &'static [forms::FormSet],
}

impl FamilyBench {
    /// No rows.
    pub const NONE: FamilyBench = FamilyBench { integrators: &[], fits: &[], tables: &[], builds: &[], forms: &[] };
}

/// The items `field` picks from every family, by `order` (stable: ties keep the families' order).
fn ordered<'a, T>(families: &[&'a FamilyBench], field: impl Fn(&'a FamilyBench) -> &'a [T], order: impl Fn(&T) -> u32) -> Vec<&'a T> {
    let mut items: Vec<&T> = families.iter().flat_map(|f| field(f).iter()).collect();
    items.sort_by_key(|t| order(t));
    items
}
