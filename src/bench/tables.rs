//! Default tables: shadefit against a straightforward numpy/scipy implementation of the same
//! integrals (`benches/numpy_tables.py`) at equal max error.
//!
//! For each spec a family compares ([`TableBench`]: a table or the fit behind one, and the
//! samples every fit and table is built from), a seeded subset of its grid is evaluated to a
//! tolerance 1–3 orders below the tightest setting (the reference). shadefit's integrator runs
//! over the subset at a ladder of tolerances (one thread, like the numpy side); the numpy/scipy
//! script runs its own methods over the same points with their own ladders (vectorised
//! Gauss–Legendre, per-point `quad`/`dblquad`, Monte Carlo) and reports seconds per point and
//! max error. The speed ratio at equal error compares the fastest numpy row within
//! [`TARGET_ERROR`] with the fastest shadefit row within the same bound; when no numpy row
//! reaches it, the most accurate numpy row is compared with the fastest shadefit row at least
//! as accurate, and the row says so. Where scipy has the closed form (the script's rows named
//! "closed form …") a second ratio leaves it out: shadefit against the numerical integration a
//! user writes without it. Table times are seconds per point × table size.

use super::{BenchError, FamilyBench, Mode, SplitMix, time_it};
use crate::pipeline;
use crate::spec::Spec;
use serde::Serialize;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Max error at which the ratio is taken: below every table's use (f32 rounding is 6e-8
/// relative) and reachable by the straightforward methods within the time budget.
pub const TARGET_ERROR: f64 = 1e-8;

/// Errors below this are not resolved by the references (their own tolerance is 1e-12 to
/// 1e-14 absolute, and f64 rounding of the sums is ~1e-15): "equal error" saturates here.
const ERROR_FLOOR: f64 = 1e-12;

/// One point of a time-vs-error curve.
#[derive(Debug, Clone, Serialize)]
pub struct CurvePoint {
    pub method: String,
    pub setting: String,
    pub points: usize,
    pub seconds_per_point: f64,
    pub max_error: Option<f64>,
    pub note: String,
}

/// The comparison at equal error.
#[derive(Debug, Clone, Serialize)]
pub struct Ratio {
    pub numpy: CurvePoint,
    pub shadefit: CurvePoint,
    /// numpy seconds per point / shadefit seconds per point.
    pub speedup: f64,
    /// Whether the numpy row reached [`TARGET_ERROR`].
    pub at_target: bool,
}

#[derive(Debug, Clone, Serialize)]
pub struct TableRow {
    pub name: String,
    pub quantity: String,
    pub table_points: usize,
    pub sample_points: usize,
    /// Tolerance the spec builds the table with.
    pub build_tolerance: f64,
    pub shadefit: Vec<CurvePoint>,
    pub numpy: Vec<CurvePoint>,
    pub ratio: Option<Ratio>,
    /// The same against numpy/scipy's numerical integrations only (no closed-form rows).
    pub ratio_integrators: Option<Ratio>,
    pub note: String,
}

/// A spec a family compares with the numpy/scipy script (which knows it by name).
#[derive(Debug, Clone, Copy)]
pub struct TableBench {
    /// The spec's name in fits/ (skipped when absent) and in the script.
    pub spec: &'static str,
    /// Place in the section across families (see [`FamilyBench`]); the sampled subset's seed
    /// is `0x5EED + order`.
    pub order: u32,
    /// Grid points sampled (with the two grid corners), quick and full.
    pub samples: (usize, usize),
    /// shadefit's settings.
    pub ladder: Ladder,
    /// Tolerance of the reference values: below the tightest setting.
    pub reference_tolerance: f64,
    /// How the spec's grid maps to the script's points.
    pub shape: Shape,
}

/// shadefit's settings of one table.
#[derive(Debug, Clone, Copy)]
pub enum Ladder {
    /// A closed form: one setting, the spec's tolerance.
    ClosedForm,
    /// Tolerances, quick and full.
    Tolerances(&'static [f64], &'static [f64]),
}

/// How a spec's grid and values map to the script's points and channels.
#[derive(Debug, Clone, Copy)]
pub struct Shape {
    /// The script's parameters.
    pub params: Params,
    /// Values per script point, all channels of all the grid points behind it.
    pub channels: usize,
    /// One script point per value of the other axes, gathering every value of the last axis
    /// (in axis order: its channels are those of the first value, then the second's, …).
    pub fold_last_axis: bool,
}

impl Shape {
    /// One value per grid point; the script's parameters are the spec's axes.
    pub const SCALAR: Shape = Shape { params: Params::Axes { rename: &[] }, channels: 1, fold_last_axis: false };
}

/// The parameters of a script point.
#[derive(Debug, Clone, Copy)]
pub enum Params {
    /// Every spec axis in order, by its name, save those the script spells otherwise
    /// (spec name, script name).
    Axes { rename: &'static [(&'static str, &'static str)] },
    /// These spec axes (index, script name), in the script's order.
    Pick(&'static [(usize, &'static str)]),
}

struct Table<'a> {
    spec: &'a Spec,
    bench: &'a TableBench,
    /// Points of the numpy view (see [`Shape`]).
    points: Vec<Vec<f64>>,
    /// Spec-grid points behind each numpy point (several when the last axis is folded).
    grid_points: Vec<Vec<Vec<f64>>>,
    table_points: usize,
}

impl Table<'_> {
    /// Values of every numpy point (all channels, flattened point-major) at tolerance `tol`.
    fn eval(&self, tol: f64) -> Vec<f64> {
        let q = self.spec.quantity;
        self.grid_points
            .iter()
            .flat_map(|gs| {
                gs.iter().flat_map(move |g| match q.eval_channels {
                    Some(multi) => multi(g, tol)
                        .into_iter()
                        .map(|e| e.value)
                        .collect::<Vec<_>>(),
                    None => vec![(q.eval)(g, tol).value],
                })
            })
            .collect()
    }

    fn channels(&self) -> usize {
        self.bench.shape.channels
    }

    fn params(&self) -> Vec<String> {
        match self.bench.shape.params {
            Params::Axes { rename } => self
                .spec
                .file
                .axis
                .iter()
                .map(|a| match rename.iter().find(|(from, _)| *from == a.name) {
                    Some((_, to)) => to.to_string(),
                    None => a.name.clone(),
                })
                .collect(),
            Params::Pick(axes) => axes.iter().map(|(_, name)| name.to_string()).collect(),
        }
    }
}

fn table<'a>(spec: &'a Spec, bench: &'a TableBench, n: usize, seed: u64) -> Table<'a> {
    let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
    let grid = pipeline::grid(spec, &counts);
    let shape = bench.shape;
    // The grid is first-axis fastest: a folded point gathers the grid points k, k + m, k + 2m,
    // … (m points per value of the last axis).
    let units: Vec<Vec<Vec<f64>>> = if shape.fold_last_axis {
        let last = counts.last().copied().unwrap_or(1);
        let m = grid.len() / last;
        (0..m)
            .map(|k| (0..last).map(|j| grid[k + j * m].clone()).collect())
            .collect()
    } else {
        grid.into_iter().map(|g| vec![g]).collect()
    };
    let table_points = units.len();
    // The two grid corners, then seeded picks without repetition, in grid order.
    let mut picks = vec![0, table_points - 1];
    let mut rng = SplitMix(seed);
    while picks.len() < n.min(table_points) {
        let i = ((rng.next_f64() * table_points as f64) as usize).min(table_points - 1);
        if !picks.contains(&i) {
            picks.push(i);
        }
    }
    picks.sort_unstable();
    let grid_points: Vec<Vec<Vec<f64>>> = picks.iter().map(|&i| units[i].clone()).collect();
    let points = grid_points
        .iter()
        .map(|gs| match shape.params {
            Params::Axes { .. } => gs[0].clone(),
            Params::Pick(axes) => axes.iter().map(|&(i, _)| gs[0][i]).collect(),
        })
        .collect();
    Table {
        spec,
        bench,
        points,
        grid_points,
        table_points,
    }
}

/// shadefit's ladder of tolerances (closed forms: none, one setting).
fn ladder(mode: &Mode, ladder: Ladder) -> Option<Vec<f64>> {
    match ladder {
        Ladder::ClosedForm => None,
        Ladder::Tolerances(quick, full) => Some(if mode.quick { quick.to_vec() } else { full.to_vec() }),
    }
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The numpy/scipy script and the interpreter to run it with.
pub struct Python {
    pub interpreter: PathBuf,
    pub script: PathBuf,
    /// Whether a failure of the script fails the run (else each table notes it).
    pub required: bool,
}

/// Every family's tables, by order: shadefit's side, and the script's when `python` is given.
pub fn all(mode: &Mode, specs: &[Spec], families: &[&FamilyBench], python: Option<&Python>) -> Result<Vec<TableRow>, BenchError> {
    let mut tables = Vec::new();
    for bench in super::ordered(families, |f| f.tables, |t| t.order) {
        let Some(spec) = specs.iter().find(|s| s.file.name == bench.spec) else {
            continue;
        };
        let (quick_n, full_n) = bench.samples;
        tables.push(table(
            spec,
            bench,
            if mode.quick { quick_n } else { full_n },
            0x5EED + u64::from(bench.order),
        ));
    }
    let mut rows = Vec::new();
    let mut inputs = Vec::new();
    for t in &tables {
        let quantity = t.spec.file.quantity.clone();
        let truth = t.eval(t.bench.reference_tolerance);
        let mut curve = Vec::new();
        let settings: Vec<(String, f64)> = match ladder(mode, t.bench.ladder) {
            Some(tols) => tols
                .into_iter()
                .map(|tol| (format!("tol {tol:.0e}"), tol))
                .collect(),
            None => vec![("closed form".to_string(), t.spec.file.tolerance)],
        };
        for (setting, tol) in settings {
            let (seconds, values) = time_it(mode.min_seconds, || t.eval(tol));
            curve.push(CurvePoint {
                method: "shadefit".into(),
                setting,
                points: t.points.len(),
                seconds_per_point: seconds / t.points.len() as f64,
                max_error: Some(max_abs_diff(&values, &truth)),
                note: String::new(),
            });
        }
        let c = t.channels();
        inputs.push(json!({
            "name": t.spec.file.name,
            "quantity": quantity,
            "params": t.params(),
            "channels": c,
            "points": t.points,
            "reference": truth.chunks(c).collect::<Vec<_>>(),
            "table_points": t.table_points,
        }));
        rows.push(TableRow {
            name: t.spec.file.name.clone(),
            quantity,
            table_points: t.table_points,
            sample_points: t.points.len(),
            build_tolerance: t.spec.file.tolerance,
            shadefit: curve,
            numpy: Vec::new(),
            ratio: None,
            ratio_integrators: None,
            note: String::new(),
        });
    }
    if let Some(py) = python {
        let input = json!({"quick": mode.quick, "target_error": TARGET_ERROR, "tables": inputs});
        let out = match run_python(py, &input) {
            Ok(v) => v,
            Err(e) if !py.required => {
                for row in &mut rows {
                    row.note = format!("numpy/scipy comparison failed: {}", e.chain());
                }
                return Ok(rows);
            }
            Err(e) => return Err(e),
        };
        for row in &mut rows {
            let Some(t) = out["tables"]
                .as_array()
                .and_then(|ts| ts.iter().find(|t| t["name"] == row.name.as_str()))
            else {
                row.note = "the numpy script returned nothing for this table".into();
                continue;
            };
            row.numpy = t["rows"]
                .as_array()
                .map(|rs| rs.iter().map(curve_point).collect())
                .unwrap_or_default();
            if let Some(n) = t["note"].as_str() {
                row.note = n.to_string();
            }
            row.ratio = ratio(&row.numpy, &row.shadefit);
            let integrations: Vec<CurvePoint> = row
                .numpy
                .iter()
                .filter(|c| !c.method.starts_with("closed form"))
                .cloned()
                .collect();
            if integrations.len() < row.numpy.len() {
                row.ratio_integrators = ratio(&integrations, &row.shadefit);
            }
        }
    } else {
        for row in &mut rows {
            row.note = "numpy/scipy comparison not run (no Python)".into();
        }
    }
    Ok(rows)
}

fn curve_point(v: &Value) -> CurvePoint {
    CurvePoint {
        method: v["method"].as_str().unwrap_or("?").to_string(),
        setting: v["setting"].as_str().unwrap_or("").to_string(),
        points: v["points"].as_u64().unwrap_or(0) as usize,
        seconds_per_point: v["seconds_per_point"].as_f64().unwrap_or(f64::NAN),
        max_error: v["max_error"].as_f64(),
        note: v["note"].as_str().unwrap_or("").to_string(),
    }
}

/// The comparison at equal error (see the module doc).
pub fn ratio(numpy: &[CurvePoint], shadefit: &[CurvePoint]) -> Option<Ratio> {
    let ok = |c: &&CurvePoint| c.max_error.is_some_and(f64::is_finite) && c.seconds_per_point > 0.0;
    let fastest_within = |rows: &[CurvePoint], bound: f64| -> Option<CurvePoint> {
        rows.iter()
            .filter(ok)
            .filter(|c| c.max_error.unwrap() <= bound.max(ERROR_FLOOR))
            .min_by(|a, b| a.seconds_per_point.total_cmp(&b.seconds_per_point))
            .cloned()
    };
    let (np, at_target) = match fastest_within(numpy, TARGET_ERROR) {
        Some(n) => (n, true),
        None => (
            numpy
                .iter()
                .filter(ok)
                .min_by(|a, b| a.max_error.unwrap().total_cmp(&b.max_error.unwrap()))?
                .clone(),
            false,
        ),
    };
    let bound = if at_target {
        TARGET_ERROR
    } else {
        np.max_error.unwrap()
    };
    let sf = fastest_within(shadefit, bound)?;
    Some(Ratio {
        speedup: np.seconds_per_point / sf.seconds_per_point,
        numpy: np,
        shadefit: sf,
        at_target,
    })
}

/// Run the script on `input`; its JSON answer.
fn run_python(py: &Python, input: &Value) -> Result<Value, BenchError> {
    let dir = tempfile::tempdir().map_err(|source| BenchError::TempDir { source })?;
    let inp = dir.path().join("in.json");
    let out = dir.path().join("out.json");
    std::fs::write(&inp, input.to_string()).map_err(|source| BenchError::Write { path: inp.clone(), source })?;
    let status = Command::new(&py.interpreter)
        .arg(&py.script)
        .arg(&inp)
        .arg(&out)
        // One thread, like shadefit's side of the comparison.
        .env("OMP_NUM_THREADS", "1")
        .env("OPENBLAS_NUM_THREADS", "1")
        .env("MKL_NUM_THREADS", "1")
        .status()
        .map_err(|source| BenchError::PythonStart { interpreter: py.interpreter.clone(), script: py.script.clone(), source })?;
    if !status.success() {
        return Err(BenchError::Python { script: py.script.clone(), status });
    }
    let text = std::fs::read_to_string(&out).map_err(|source| BenchError::Read { path: out.clone(), source })?;
    serde_json::from_str(&text).map_err(|source| BenchError::Json { path: out.clone(), source })
}

/// The default interpreter: the test suite's venv when present, else `python3`.
pub fn default_python(root: &Path) -> Python {
    let venv = root.join("tests/python/.venv/bin/python");
    Python {
        interpreter: if venv.exists() {
            venv
        } else {
            PathBuf::from("python3")
        },
        script: root.join("benches/numpy_tables.py"),
        required: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(method: &str, seconds: f64, err: Option<f64>) -> CurvePoint {
        CurvePoint { method: method.into(), setting: String::new(), points: 1, seconds_per_point: seconds, max_error: err, note: String::new() }
    }

    #[test]
    fn ratio_at_the_target_takes_the_fastest_row_within_it_on_each_side() {
        let numpy = [point("gl", 1.0, Some(1e-6)), point("quad", 8.0, Some(1e-9)), point("gl", 4.0, Some(5e-9)), point("bad", 0.1, None)];
        let shadefit = [point("sf", 0.001, Some(1e-5)), point("sf", 0.02, Some(2e-9)), point("sf", 0.05, Some(1e-12))];
        let r = ratio(&numpy, &shadefit).expect("both sides reach 1e-8");
        assert!(r.at_target);
        assert_eq!(r.numpy.seconds_per_point, 4.0, "the fastest numpy row within 1e-8");
        assert_eq!(r.shadefit.seconds_per_point, 0.02, "the fastest shadefit row within 1e-8");
        assert_eq!(r.speedup, 200.0);
    }

    #[test]
    fn ratio_off_target_matches_the_best_numpy_error() {
        let numpy = [point("mc", 1.0, Some(1e-2)), point("mc", 10.0, Some(3e-3))];
        let shadefit = [point("sf", 0.001, Some(5e-3)), point("sf", 0.002, Some(1e-3))];
        let r = ratio(&numpy, &shadefit).expect("shadefit matches 3e-3");
        assert!(!r.at_target);
        assert_eq!((r.numpy.seconds_per_point, r.shadefit.seconds_per_point), (10.0, 0.002));
        // No shadefit row as accurate as numpy's best: no ratio rather than an unequal one.
        assert!(ratio(&numpy, &[point("sf", 0.001, Some(5e-2))]).is_none());
    }
}
