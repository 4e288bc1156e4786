//! Whole spec builds timed: each spec a family names is built from scratch (every integral and
//! fit recomputed, nothing written) on the global thread pool and again on a one-thread pool;
//! the row gives both wall times, whether the two builds' artifacts are byte-identical, the
//! measured error of the emitted code, and the op counts of the emitted WGSL functions the
//! family names (from naga's IR, [`super::ops`]).

use super::ops::OpCounts;
use super::{BenchError, FamilyBench, Mode};
use crate::pipeline::{CustomBuild, Mode as BuildMode};
use crate::spec::Spec;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// A spec a family times whole.
#[derive(Debug, Clone, Copy)]
pub struct BuildBench {
    /// The spec's name in fits/ (skipped when absent).
    pub spec: &'static str,
    /// Place in the section across families (see [`FamilyBench`]).
    pub order: u32,
    /// Timed in quick mode too (else in full runs only).
    pub quick: bool,
    /// Emitted WGSL functions whose op counts the row reports.
    pub functions: &'static [&'static str],
}

/// One spec's build, timed.
#[derive(Debug, Clone, Serialize)]
pub struct BuildRow {
    pub spec: String,
    /// Threads of the global pool (the first build).
    pub threads: usize,
    pub seconds: f64,
    pub seconds_one_thread: f64,
    /// The artifacts of both builds, byte for byte the same.
    pub identical: bool,
    pub files: usize,
    /// The build's measured max error of the emitted f32 code.
    pub max_error_f32: f64,
    /// (function, op counts) of the named functions.
    pub ops: Vec<(String, OpCounts)>,
}

/// Every family's build rows of this mode, by order.
pub fn all(mode: &Mode, specs: &[Spec], generated: &Path, custom: &(dyn Fn(&str) -> Option<CustomBuild> + Sync), families: &[&FamilyBench]) -> Result<Vec<BuildRow>, BenchError> {
    super::ordered(families, |f| f.builds, |b| b.order)
        .into_iter()
        .filter(|b| b.quick || !mode.quick)
        .filter_map(|b| specs.iter().find(|s| s.file.name == b.spec).map(|s| row(s, b.functions, generated, custom)))
        .collect()
}

/// Build `spec` twice (global pool, then one thread) and compare; `custom` finds the builder of
/// a family spec kind (as `pipeline::build_spec` takes it).
pub fn row(spec: &Spec, functions: &[&str], generated: &Path, custom: &(dyn Fn(&str) -> Option<CustomBuild> + Sync)) -> Result<BuildRow, BenchError> {
    let name = &spec.file.name;
    let build = || crate::pipeline::build_spec(spec, BuildMode::Fit, generated, custom).map_err(BenchError::build(name));
    let start = Instant::now();
    let built = build()?;
    let seconds = start.elapsed().as_secs_f64();
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a one-thread pool");
    let start = Instant::now();
    let again = one.install(build)?;
    let seconds_one_thread = start.elapsed().as_secs_f64();
    let identical = built.artifacts.len() == again.artifacts.len()
        && built.artifacts.iter().zip(&again.artifacts).all(|(a, b)| a.path == b.path && a.contents == b.contents);
    let ops = if functions.is_empty() {
        Vec::new()
    } else {
        let wgsl = built.artifacts.iter().find(|a| a.path.extension().is_some_and(|x| x == "wgsl")).ok_or_else(|| BenchError::NoWgsl { spec: name.clone() })?;
        let text = std::str::from_utf8(&wgsl.contents).map_err(|source| BenchError::WgslUtf8 { spec: name.clone(), source })?;
        let source = super::forms::parse(name, text)?;
        functions.iter().map(|f| Ok((f.to_string(), super::forms::count_in(name, &source, f)?))).collect::<Result<_, BenchError>>()?
    };
    Ok(BuildRow {
        spec: name.clone(),
        threads: rayon::current_num_threads(),
        seconds,
        seconds_one_thread,
        identical,
        files: built.artifacts.len(),
        max_error_f32: built.verification.max_abs_error_f32,
        ops,
    })
}

/// The section as text.
pub fn render(rows: &[BuildRow]) -> String {
    let mut s = format!(
        "  {:<20} {:>8} {:>10} {:>10} {:>10} {:>6} {:>11}\n",
        "spec", "threads", "time", "1 thread", "identical", "files", "max err f32"
    );
    for r in rows {
        s.push_str(&format!(
            "  {:<20} {:>8} {:>10} {:>10} {:>10} {:>6} {:>11}\n",
            r.spec,
            r.threads,
            super::seconds(r.seconds),
            super::seconds(r.seconds_one_thread),
            if r.identical { "yes" } else { "NO" },
            r.files,
            super::sci(r.max_error_f32)
        ));
        for (f, o) in &r.ops {
            s.push_str(&format!(
                "    {f}: weighted cost {} (add {}, mul {}, div {}, transc {}, tex {}, other {}; loops {}, one iteration each)\n",
                o.weighted(),
                o.add,
                o.mul,
                o.div,
                o.transc,
                o.tex,
                o.other,
                o.loops
            ));
        }
    }
    s
}
