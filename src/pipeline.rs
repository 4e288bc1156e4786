//! The build: for every spec, sample the integral, fit (or tabulate), verify, emit.
//!
//! - `Mode::Fit` integrates and fits from scratch (what `shadefit build` does); a fit's f64
//!   coefficients are then rounded to f32 and re-optimised in f32 on the fitting samples
//!   (`fit::f32round`), and the emitted code uses those f32 coefficients;
//! - `Mode::Committed` takes the coefficients or table values from the committed JSON in
//!   generated/json and re-verifies and re-emits them (what `shadefit build --check` compares
//!   byte for byte; it fails if a spec changed since its JSON was written). A fit's f32
//!   coefficients are read back too, and must lie within `f32round::MAX_ULPS` of the rounded f64
//!   ones; what the re-optimisation measured on the fitting samples is carried over.
//!
//! Samples are computed in parallel with rayon and collected in grid order, so outputs are
//! byte-identical at any thread count.
//!
//! This file holds the build of one spec (grids, sampling, the dispatch on its kind,
//! verification); beside it, one job each: `error` (modes and errors), `json` (input hashes,
//! committed JSON read back, JSON text), `fitted` (the `fit` kind), `table` (the `table`
//! kind), `fields` (the `fields` kind), `module` (the provenance of a family's module kinds),
//! `committed` (the one reader of committed fits), `data` (`fit --data --emit`), `index` (the
//! runtime crate's index), `staleness` (differing and orphaned files).

use crate::fit::expr;
use crate::emit::{self, header_lines, rust, wgsl, Artifact, GENERATOR};
use crate::fit::positivity::{prove_denominator_positive, Positivity};
use crate::fit::{self, f32round, Data, FitOptions, FitReport};
use crate::spec::{self, Kind, Spec};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::path::Path;

#[cfg(test)]
pub(crate) mod build_tests;
#[cfg(test)]
mod lobe_tests;
#[cfg(test)]
mod table_tests;
pub mod committed;
pub mod data;
pub mod fields;
pub mod grid;
pub mod module;
pub mod form;
pub mod lobe;
pub mod refit;
mod error;
mod fitted;
mod index;
mod json;
mod staleness;
mod table;

pub use error::*;
pub use fitted::*;
pub use grid::{Grid, GridAxis, Quadrature};
pub use index::*;
pub use json::*;
pub use staleness::*;
pub use table::*;

/// Project paths: specs in `fits/`, outputs in `generated/`.
#[derive(Debug, Clone)]
pub struct Paths {
    pub fits: std::path::PathBuf,
    pub generated: std::path::PathBuf,
}

/// Errors of an emitted function against the integral on the verification grid.
#[derive(Debug, Clone, Serialize)]
pub struct Verification {
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    pub worst_point: Vec<f64>,
    /// The same for the emitted f32 code (f32 coefficients, f32 arithmetic, emitted order).
    pub max_abs_error_f32: f64,
    pub rms_error_f32: f64,
    /// For 1-D quantities with an inverse: max error after mapping back to parameter units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_abs_error_in_parameter: Option<f64>,
}

impl Verification {
    /// The `measured error:` text of a generated file's header.
    pub fn header_line(&self) -> String {
        format!(
            "max abs {}, rms {} over {} points (f32 code: max abs {}, rms {})",
            fmt_err(self.max_abs_error),
            fmt_err(self.rms_error),
            self.points,
            fmt_err(self.max_abs_error_f32),
            fmt_err(self.rms_error_f32)
        )
    }
}

/// Result of building one spec.
#[derive(Debug, Clone)]
pub struct Built {
    pub name: String,
    pub artifacts: Vec<Artifact>,
    pub verification: Verification,
    pub fit: Option<FitReport>,
}

/// Tensor grid over the spec's axes with the given counts, first axis fastest.
pub fn grid(spec: &Spec, counts: &[usize]) -> Vec<Vec<f64>> {
    tensor(&spec.file.axis, counts)
}

/// Tensor grid over some axes with the given counts, first axis fastest.
pub(crate) fn tensor(axes: &[crate::spec::AxisSpec], counts: &[usize]) -> Vec<Vec<f64>> {
    product(axes.iter().zip(counts).map(|(a, &n)| a.points(n)).collect())
}

/// Tensor product of per-axis point lists, first axis fastest.
pub(crate) fn product(pts: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let total: usize = pts.iter().map(Vec::len).product();
    (0..total)
        .map(|mut k| {
            pts.iter()
                .map(|p| {
                    let i = k % p.len();
                    k /= p.len();
                    p[i]
                })
                .collect()
        })
        .collect()
}

/// The integral at each point, in parallel, in order.
pub fn sample(spec: &Spec, points: &[Vec<f64>]) -> Vec<f64> {
    let sampler = spec.sampler();
    points.par_iter().map(|p| sampler.eval(p).value).collect()
}

/// Records the channel a spec takes (`"channel"`) in its JSON, after `"quantity"`.
pub fn with_channel(json: &mut Value, spec: &Spec) {
    if let Some(c) = spec.channel_name() {
        json["channel"] = c.into();
    }
}

/// What generated files name as their spec: `fits/FILE`, or the origin of a spec made in memory.
pub fn spec_rel_path(spec: &Spec) -> String {
    match &spec.origin {
        Some(o) => o.clone(),
        None => format!("fits/{}", spec.path.file_name().and_then(|s| s.to_str()).unwrap_or("?")),
    }
}

pub fn fmt_err(v: f64) -> String {
    format!("{v:.3e}")
}

/// The builder of a family spec kind.
pub type CustomBuild = fn(&Spec, Mode, &Path) -> Result<Built, BuildError>;

/// Build one spec in the given mode; `root` is the generated/ folder; `custom` finds the builder
/// of a family spec kind by name.
pub fn build_spec(spec: &Spec, mode: Mode, root: &Path, custom: &dyn Fn(&str) -> Option<CustomBuild>) -> Result<Built, BuildError> {
    let mut b = build_any(spec, mode, root, custom)?;
    b.artifacts = texture_files(spec, std::mem::take(&mut b.artifacts))?;
    // A spec's `max_error` bounds the measured error of its emitted f32 code (NaN fails too).
    let measured = b.verification.max_abs_error_f32;
    if let Some(bound) = spec.file.max_error
        && !(measured <= bound)
    {
        return Err(BuildError::ErrorBound { spec: spec.file.name.clone(), measured, bound });
    }
    Ok(b)
}

/// Every texture a spec writes (`data/NAME.ktx2`) in the formats of its `[emit] formats`
/// ([`emit::formats`]; by default the KTX2, DDS and, for float texels, EXR).
fn texture_files(spec: &Spec, artifacts: Vec<Artifact>) -> Result<Vec<Artifact>, BuildError> {
    let bad = |why: String| spec::SpecError::new(&spec.path, spec::line_of(&spec.text, "formats"), "formats", why);
    let listed = spec.file.emit.formats.as_deref().map(emit::formats::parse_list).transpose().map_err(bad)?;
    let mut out = Vec::with_capacity(artifacts.len());
    let mut textures = 0;
    for a in artifacts {
        if !(a.path.starts_with("data") && a.path.extension().is_some_and(|e| e == "ktx2")) {
            out.push(a);
            continue;
        }
        textures += 1;
        let files = emit::formats::files(&a.path, &a.contents, listed.as_deref()).map_err(bad)?;
        out.extend(files.into_iter().map(|(path, contents)| Artifact { path, contents }));
    }
    if listed.is_some() && textures == 0 {
        return Err(bad(emit::formats::NO_TEXTURE.into()).into());
    }
    Ok(out)
}

fn build_any(spec: &Spec, mode: Mode, root: &Path, custom: &dyn Fn(&str) -> Option<CustomBuild>) -> Result<Built, BuildError> {
    match spec.file.kind {
        Kind::Fit => build_fit(spec, mode, root),
        Kind::Table => build_table(spec, mode, root),
        Kind::Fields => fields::build(spec, mode, root),
        Kind::Custom(kind) => match custom(kind) {
            Some(build) => build(spec, mode, root),
            None => Err(BuildError::UnknownKind { spec: spec.file.name.clone(), kind: kind.into() }),
        },
    }
}

fn domain(spec: &Spec) -> Vec<(f64, f64)> {
    spec.file.axis.iter().map(|a| (a.range[0], a.range[1])).collect()
}

fn domain_f32(spec: &Spec) -> Vec<(f32, f32)> {
    domain(spec).iter().map(|&(a, b)| (a as f32, b as f32)).collect()
}

/// Argument names of the emitted function.
fn args(spec: &Spec) -> Vec<String> {
    spec.file.emit.args.clone().unwrap_or_else(|| spec.file.axis.iter().map(|a| a.name.clone()).collect())
}

/// The integral on a verification grid: the points and the values there.
#[derive(Debug, Clone)]
pub struct Reference {
    pub points: Vec<Vec<f64>>,
    pub values: Vec<f64>,
}

impl Reference {
    /// The spec's verification grid (`verify` points per axis) and the integral on it.
    pub fn of_spec(spec: &Spec) -> Reference {
        let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.verify_count()).collect();
        let points = grid(spec, &counts);
        let values = sample(spec, &points);
        Reference { points, values }
    }
}

fn axes_json(spec: &Spec) -> Value {
    Value::Array(
        spec.file
            .axis
            .iter()
            .map(|a| json!({"name": a.name, "range": a.range, "count": a.count, "verify": a.verify_count()}))
            .collect(),
    )
}

/// The larger of two errors, a NaN being the largest (`f64::max` drops it).
pub fn nan_max(a: f64, b: f64) -> f64 {
    if b > a || b.is_nan() { b } else { a }
}

/// Max abs, rms and worst point of `approx − truth` over `points`; a NaN is the worst point and
/// the max (it then fails every bound).
pub fn measure(points: &[Vec<f64>], truth: &[f64], approx: &[f64]) -> (f64, f64, Vec<f64>) {
    let mut worst = (0, 0.0f64);
    let mut ss = 0.0;
    for (i, (t, a)) in truth.iter().zip(approx).enumerate() {
        let e = (a - t).abs();
        if e > worst.1 || e.is_nan() {
            worst = (i, e);
        }
        ss += e * e;
    }
    (worst.1, (ss / truth.len().max(1) as f64).sqrt(), points.get(worst.0).cloned().unwrap_or_default())
}

/// The spec's quantity's inverse, for a 1-D spec (errors in parameter units).
fn inverse_1d(spec: &Spec, vx: &[Vec<f64>]) -> Option<fn(f64) -> f64> {
    spec.quantity.inverse.filter(|_| vx.first().is_some_and(|x| x.len() == 1))
}

/// Max abs and rms error of the f64 fit and of the emitted f32 code against the integral on the
/// verification points, and through `inverse` in parameter units; a NaN anywhere is the max
/// error (it then fails every bound).
fn verify(inverse: Option<fn(f64) -> f64>, vx: &[Vec<f64>], truth: &[f64], a64: &[f64], a32: &[f32]) -> Verification {
    let a32: Vec<f64> = a32.iter().map(|&v| v as f64).collect();
    let (max_abs_error, rms_error, worst_point) = measure(vx, truth, a64);
    let (max_abs_error_f32, rms_error_f32, _) = measure(vx, truth, &a32);
    let inverse = inverse.map(|inv| {
        vx.iter().zip(a64).map(|(x, &v)| (inv(v) - x[0]).abs()).fold(0.0, nan_max)
    });
    Verification {
        points: truth.len(),
        max_abs_error,
        rms_error,
        worst_point,
        max_abs_error_f32,
        rms_error_f32,
        max_abs_error_in_parameter: inverse,
    }
}

pub use emit::write_all;

#[cfg(test)]
mod tests {
    use super::*;

    /// Orphans are the files directly under the output folders that no artifact is, sorted
    /// within each folder, folders in the order given: not the runtime crate's hand-written
    /// `src/lib.rs`, not a folder (its own code), not a file in a folder not listed, and a
    /// missing folder is skipped. Stale are the artifacts whose file differs or is missing.
    #[test]
    fn orphans_are_the_unproduced_files_of_the_output_folders_and_stale_the_changed_ones() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        for d in ["wgsl", "src/nested", "json", "hlsl"] {
            std::fs::create_dir_all(root.join(d)).unwrap();
        }
        for f in ["wgsl/b.wgsl", "wgsl/a.wgsl", "wgsl/kept.wgsl", "src/lib.rs", "src/x.rs", "src/nested/y.rs", "json/z.json", "hlsl/h.hlsl"] {
            std::fs::write(root.join(f), "old").unwrap();
        }
        let artifact = |p: &str, c: &str| Artifact { path: p.into(), contents: c.as_bytes().to_vec() };
        let artifacts = [artifact("wgsl/kept.wgsl", "old"), artifact("json/z.json", "new"), artifact("data/t.bin", "old")];
        assert_eq!(orphans(root, &artifacts), ["wgsl/a.wgsl", "wgsl/b.wgsl", "src/x.rs"]);
        assert_eq!(orphans_in(root, &artifacts, &["hlsl", "wgsl"]), ["hlsl/h.hlsl", "wgsl/a.wgsl", "wgsl/b.wgsl"]);
        assert_eq!(stale(root, &artifacts), ["json/z.json", "data/t.bin"]);
    }

    /// `x` moved `k` f32 steps away from zero (k < 0: towards it), by its bit pattern: for a
    /// finite non-zero f32 of either sign, consecutive bit patterns are consecutive floats.
    fn away_from_zero(x: f32, k: i32) -> f32 {
        assert!(x != 0.0 && x.is_finite());
        f32::from_bits((x.to_bits() as i64 + k as i64) as u32)
    }

    /// `committed_f32` against the contract in the module docs and ARCHITECTURE.md: a committed
    /// f32 coefficient may lie at most 64 ulps (the re-optimisation's move cap) from the f64
    /// coefficient rounded to nearest; one more is a coefficient the fit cannot have produced.
    #[test]
    fn committed_f32_coefficients_are_held_to_the_move_cap_exactly() {
        assert_eq!(f32round::MAX_ULPS, 64, "the documented cap");
        // P = c0 + c1 x + c2 x², Q = 1 + d1 x: positive and negative coefficients, one below 1.
        let model = fit::RationalModel::rational_1d("x", 2, 1);
        let c = DVector::from_vec(vec![0.3, -1.7, 12.5, -0.25]);
        // Rounded to nearest by the `as` cast (IEEE round-to-nearest-even), not by the code
        // under test.
        let r: Vec<f32> = c.iter().map(|&v| v as f32).collect();
        let check = |i: usize, k: i32| {
            let mut v = r.clone();
            v[i] = away_from_zero(v[i], k);
            let m = json!({
                "numerator_f32": v[..3].iter().map(|&x| x as f64).collect::<Vec<_>>(),
                "denominator_f32": v[3..].iter().map(|&x| x as f64).collect::<Vec<_>>(),
            });
            committed_f32(&model, &c, &m, "t")
        };
        for i in 0..4 {
            for k in [0, 1, -1, 64, -64] {
                let (num, den) = check(i, k).unwrap_or_else(|e| panic!("coefficient {i} moved {k} ulps rejected: {e}"));
                assert_eq!(num.len() + den.len(), 4);
            }
            for k in [65, -65, 512, -512] {
                match check(i, k) {
                    Err(BuildError::F32Coefficients { why, .. }) => assert!(why.contains("ulps"), "{why}"),
                    other => panic!("coefficient {i} moved {k} ulps accepted: {other:?}"),
                }
            }
        }
        // A fixed coefficient (here c1 = −1.7, emitted as its rounded value) may not move at all,
        // while the others still may: an unmoved fixed one is accepted beside a moved free one.
        let fixed = fit::RationalModel::new(fit::model::ModelParts {
            inputs: vec!["x".into()],
            numerator: ["1", "x", "x^2"].iter().map(|t| fit::model::Term::parse(t, &["x".to_string()]).unwrap()).collect(),
            denominator: vec![fit::model::Term::parse("x", &["x".to_string()]).unwrap()],
            fixed: vec![(1, -1.7)],
            ..fit::model::ModelParts::default()
        })
        .unwrap();
        let with = |moves: [i32; 4]| {
            let v: Vec<f64> = r.iter().zip(moves).map(|(&x, k)| away_from_zero(x, k) as f64).collect();
            committed_f32(&fixed, &c, &json!({"numerator_f32": v[..3].to_vec(), "denominator_f32": v[3..].to_vec()}), "t")
        };
        assert!(with([0, 0, 0, 0]).is_ok());
        assert!(with([3, 0, -5, 64]).is_ok(), "free coefficients moved, the fixed one not");
        for k in [1, -1] {
            match with([0, k, 0, 0]) {
                Err(BuildError::F32Coefficients { why, .. }) => assert!(why.contains("fixed"), "{why}"),
                other => panic!("fixed coefficient moved {k} ulp accepted: {other:?}"),
            }
        }
        // A value that is not an f32 at all, and a wrong count, are refused too.
        let m = json!({"numerator_f32": [0.3, r[1] as f64, r[2] as f64], "denominator_f32": [r[3] as f64]});
        assert!(matches!(committed_f32(&model, &c, &m, "t"), Err(BuildError::F32Coefficients { .. })));
        let m = json!({"numerator_f32": [r[0] as f64, r[1] as f64], "denominator_f32": [r[3] as f64]});
        assert!(matches!(committed_f32(&model, &c, &m, "t"), Err(BuildError::F32Coefficients { .. })));
    }

    /// `verify` against errors worked out by hand: max, rms and the worst point of the f64 fit,
    /// the same of the f32 values, and the error mapped back through an inverse (here x ↦ x²,
    /// inverted by the square root).
    #[test]
    fn verification_is_measured_from_the_errors() {
        let vx = vec![vec![0.2], vec![0.5], vec![0.8]];
        let truth: Vec<f64> = vx.iter().map(|x| x[0] * x[0]).collect();
        // f64 errors +0.01, −0.03, +0.02; f32 errors −0.04, 0, +0.005 (up to f32 rounding).
        let a64 = [truth[0] + 0.01, truth[1] - 0.03, truth[2] + 0.02];
        let a32 = [(truth[0] - 0.04) as f32, truth[1] as f32, (truth[2] + 0.005) as f32];
        let v = verify(Some(f64::sqrt), &vx, &truth, &a64, &a32);
        assert_eq!(v.points, 3);
        // Three squared errors summed: exact to a few ulps of 1e-3.
        assert!((v.max_abs_error - 0.03).abs() < 1e-12, "{}", v.max_abs_error);
        assert!((v.rms_error - (14e-4f64 / 3.0).sqrt()).abs() < 1e-12, "{}", v.rms_error);
        assert_eq!(v.worst_point, vec![0.5]);
        // The f32 values carry their rounding, below 1e-7 for values below 1.
        assert!((v.max_abs_error_f32 - 0.04).abs() < 1e-7, "{}", v.max_abs_error_f32);
        assert!((v.rms_error_f32 - ((16e-4f64 + 25e-6) / 3.0).sqrt()).abs() < 1e-7, "{}", v.rms_error_f32);
        // In parameter units, by hand: |√(x² + e) − x| at each point, the largest at x = 0.5
        // (√0.22 − 0.5); the same square roots, so equal to rounding.
        let p = v.max_abs_error_in_parameter.expect("an inverse was given");
        let expected = [(0.05f64.sqrt() - 0.2).abs(), (0.22f64.sqrt() - 0.5).abs(), (0.66f64.sqrt() - 0.8).abs()].into_iter().fold(0.0, f64::max);
        assert!((p - expected).abs() < 1e-12 && p > 1e-2, "{p} vs {expected}");
        // An exact fit has no error in either unit; no inverse, no parameter error.
        let exact = verify(Some(f64::sqrt), &vx, &truth, &truth, &truth.iter().map(|&t| t as f32).collect::<Vec<_>>());
        assert_eq!((exact.max_abs_error, exact.rms_error), (0.0, 0.0));
        assert!(exact.max_abs_error_in_parameter.unwrap() < 1e-15);
        assert_eq!(verify(None, &vx, &truth, &a64, &a32).max_abs_error_in_parameter, None);
    }

    /// A NaN from the f64 fit or the f32 code is the max error, so a spec's `max_error` bound
    /// fails on it (`f64::max` would have dropped it).
    #[test]
    fn a_nan_is_the_max_error() {
        let vx = vec![vec![0.2], vec![0.5], vec![0.8]];
        let truth = [0.9, 0.8, 0.7];
        let v = verify(Some(f64::sqrt), &vx, &truth, &[0.9, f64::NAN, 0.7], &[0.9, 0.8, f32::NAN]);
        assert!(v.max_abs_error.is_nan() && v.max_abs_error_f32.is_nan(), "{v:?}");
        assert_eq!(v.worst_point, vec![0.5]);
        assert!(v.max_abs_error_in_parameter.unwrap().is_nan());
        let v = verify(None, &vx, &truth, &truth, &[f32::NAN, 0.8, 0.7]);
        assert!(v.max_abs_error_f32.is_nan() && v.max_abs_error == 0.0, "{v:?}");
    }

    /// `tensor` is the full grid, first axis fastest, each axis at its own points.
    #[test]
    fn the_grid_runs_first_axis_fastest() {
        let axis = |name: &str, range: [f64; 2]| spec::AxisSpec { name: name.into(), range, count: 2, verify: None, mapping: None, placement: None };
        let two = [axis("x", [0.0, 1.0]), axis("y", [-2.0, 2.0])];
        let want = vec![vec![0.0, -2.0], vec![0.5, -2.0], vec![1.0, -2.0], vec![0.0, 2.0], vec![0.5, 2.0], vec![1.0, 2.0]];
        assert_eq!(tensor(&two, &[3, 2]), want);
    }

    /// The `measured error:` line names each measure with its value (3 significant digits).
    #[test]
    fn the_header_line_carries_every_measure() {
        let v = Verification {
            points: 4081,
            max_abs_error: 1.2345e-3,
            rms_error: 6.789e-5,
            worst_point: vec![0.5],
            max_abs_error_f32: 1.2351e-3,
            rms_error_f32: 6.8e-5,
            max_abs_error_in_parameter: None,
        };
        assert_eq!(v.header_line(), "max abs 1.234e-3, rms 6.789e-5 over 4081 points (f32 code: max abs 1.235e-3, rms 6.800e-5)");
    }

    /// Compact JSON is the same JSON (parsed back equal) with number arrays on one line.
    #[test]
    fn compact_json_is_the_same_json() {
        let v = json!({"name": "t", "values": [0.5, -1.25e-7, 3.0], "texels": [[1.0, 2.0], [3.0, 4.0]], "empty": [], "nested": {"n": [1, 2]}});
        let text = compact_json(&v);
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), v);
        assert!(text.contains("\"values\": [0.5, -1.25e-7, 3.0]"), "{text}");
        assert!(text.contains("[1.0, 2.0]") && text.contains("[3.0, 4.0]"), "{text}");
        assert!(text.ends_with("}\n"));
        // A number array at the top level too: its `[` is the first line.
        assert_eq!(compact_json(&json!([0.5, 2.0, -3.0])), "[0.5, 2.0, -3.0]\n");
    }

    /// Arrays that are not all numbers are left as serde_json's pretty printer writes them:
    /// numbers before a string, an array or an object in the same array are not gathered.
    #[test]
    fn arrays_not_all_numbers_stay_pretty() {
        let v = json!({"mixed": [1.0, "x", 2.0], "ragged": [0.5, [1.0, 2.0]], "records": [3, {"k": 4}], "words": ["a", "b"]});
        let text = compact_json(&v);
        // Only the inner all-number array [1.0, 2.0] is gathered onto one line.
        assert_eq!(text, json_text(&v).replace("[\n      1.0,\n      2.0\n    ]", "[1.0, 2.0]"), "{text}");
        assert_eq!(serde_json::from_str::<Value>(&text).unwrap(), v);
    }

    /// Max abs, rms and worst point worked out by hand; errors of either sign count.
    #[test]
    fn measure_is_max_rms_and_worst_point() {
        let points = vec![vec![0.0, 1.0], vec![1.0, 1.0], vec![2.0, 1.0]];
        let (max, rms, worst) = measure(&points, &[1.0, 2.0, 3.0], &[1.5, 1.0, 3.25]);
        assert_eq!(max, 1.0);
        // (0.25 + 1 + 0.0625) / 3, each term exact in binary.
        assert_eq!(rms, (1.3125f64 / 3.0).sqrt());
        assert_eq!(worst, vec![1.0, 1.0]);
        assert_eq!(measure(&points, &[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]), (0.0, 0.0, vec![0.0, 1.0]));
    }

    /// A NaN approximation is the worst point, and the max stays NaN past later finite errors.
    #[test]
    fn a_nan_is_worst() {
        let points = vec![vec![0.0], vec![1.0], vec![2.0]];
        let (max, rms, worst) = measure(&points, &[1.0, 2.0, 3.0], &[1.0, f64::NAN, 7.0]);
        assert!(max.is_nan() && rms.is_nan());
        assert_eq!(worst, vec![1.0]);
    }
}
