//! Shader cost against error: several approximation forms per quantity, each built in memory
//! through the pipeline (fit or table → verify → emit WGSL), its emitted WGSL counted by
//! [`super::ops`] and its f32 evaluation measured against the integral on one verification grid
//! per quantity (all forms of a quantity on the same points). Nothing is written.
//!
//! The forms are the families' ([`FormSet`], one per quantity; see each row's `note`), as a
//! rule:
//! - the published constants (from the family's `published` module, measured by
//!   [`crate::validate`]) in the emitted form of the committed spec;
//! - the committed refit (coefficients from generated/json);
//! - a cheaper and, where it pays, a richer rational, fitted here with the committed spec's
//!   objective on the committed spec's sampling grid or a coarser one (said in the note;
//!   quick mode: coarser still);
//! - tables at two resolutions (the committed one where there is one), linear or bilinear,
//!   and whatever else the quantity is served as (coefficient tables, textures).
//!
//! The helpers here ([`Ctx`], [`Integral`], [`fit_row`], [`refit_row`], [`table_row`], …)
//! build those rows. The cost of a form is [`OpCounts::weighted`]; `table_bytes` is the memory
//! its tables take. A form is Pareto-optimal when no other form of its quantity is at most as
//! costly, at most as large and at most as wrong, and better in one of the three.
//!
//! Every integral is evaluated once per quantity and point (a cache shared by the forms, filled
//! in parallel and read in grid order), fits are sequential: the rows are the same at any
//! thread count.

use super::ops::{self, OpCounts};
use super::{BenchError, FamilyBench};
use crate::fit::positivity::{Positivity, prove_denominator_positive};
use crate::fit::{Data, RationalModel};
use crate::pipeline::{self, Built, Denominators, Reference, Verification};
use crate::spec::{Catalog, Sampler, Spec};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;
use std::path::Path;

/// One approximation form of one quantity: its shader cost and its measured error.
#[derive(Debug, Clone, Serialize)]
pub struct FormRow {
    pub quantity: String,
    pub form: String,
    pub ops: OpCounts,
    /// [`OpCounts::weighted`].
    pub cost: usize,
    /// Bytes of the tables the form reads (const arrays: 4 a value; textures: their texel
    /// format); 0 for closed forms, whose coefficients are immediates.
    pub table_bytes: usize,
    /// Max and rms |f32 evaluation − integral| over the quantity's verification grid (RGB
    /// quantities: over the channels too).
    pub max_error: f64,
    pub rms_error: f64,
    pub points: usize,
    /// On the quantity's Pareto front of (cost, table bytes, max error).
    pub pareto: bool,
    pub note: String,
}

/// The forms of one quantity, made by `forms`.
#[derive(Debug, Clone, Copy)]
pub struct FormSet {
    /// The quantity every row of the set is of.
    pub quantity: &'static str,
    /// Place in the section across families (see [`FamilyBench`]).
    pub order: u32,
    pub forms: fn(&Ctx) -> Result<Vec<FormRow>, BenchError>,
}

/// Every family's form sets, by order (see [`of`]).
pub fn all(ctx: &Ctx, families: &[&FamilyBench]) -> Result<Vec<FormRow>, BenchError> {
    let sets: Vec<FormSet> = super::ordered(families, |f| f.forms, |s| s.order).into_iter().copied().collect();
    of(ctx, &sets)
}

/// The rows of `sets` in the order given: each set's forms with their Pareto front, sorted by
/// cost, then table bytes, then max error.
pub fn of(ctx: &Ctx, sets: &[FormSet]) -> Result<Vec<FormRow>, BenchError> {
    let mut rows = Vec::new();
    for set in sets {
        let mut r = (set.forms)(ctx)?;
        mark_pareto(&mut r);
        r.sort_by(|a, b| (a.cost, a.table_bytes).cmp(&(b.cost, b.table_bytes)).then(a.max_error.total_cmp(&b.max_error)));
        rows.extend(r);
    }
    Ok(rows)
}

/// Mark the rows no other row dominates in (cost, table bytes, max error).
pub fn mark_pareto(rows: &mut [FormRow]) {
    let key: Vec<(usize, usize, f64)> = rows.iter().map(|r| (r.cost, r.table_bytes, r.max_error)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (c, b, e) = key[i];
        r.pareto = !key.iter().any(|&(c2, b2, e2)| c2 <= c && b2 <= b && e2 <= e && (c2 < c || b2 < b || e2 < e));
    }
}

/// Where the specs and the committed coefficients are, the catalog the specs load with, and
/// the grid sizes.
pub struct Ctx<'a> {
    pub fits: &'a Path,
    pub generated: &'a Path,
    /// Coarser verification and fitting grids.
    pub quick: bool,
    pub catalog: &'a Catalog,
}

impl Ctx<'_> {
    /// `full` in a full run, `quick` in a quick one.
    pub fn pick<T>(&self, full: T, quick: T) -> T {
        if self.quick { quick } else { full }
    }

    /// The committed spec `name` in fits/.
    pub fn spec(&self, name: &str) -> Result<Spec, BenchError> {
        Ok(Spec::load(&self.fits.join(format!("{name}.toml")), self.catalog)?)
    }

    /// The committed spec `base` as TOML with `edit` applied and named `name`: a spec in
    /// memory only (its path names no file).
    pub fn variant(&self, base: &Spec, name: &str, edit: impl FnOnce(&mut toml::Table)) -> Result<Spec, BenchError> {
        let mut t: toml::Table = base.text.parse().map_err(|source| BenchError::SpecToml { path: base.path.clone(), source })?;
        t.insert("name".into(), name.into());
        edit(&mut t);
        let text = toml::to_string(&t).map_err(|source| BenchError::VariantToml { spec: name.to_string(), source })?;
        Ok(Spec::parse(&self.fits.join(format!("{name}.toml")), text, self.catalog)?)
    }
}

/// `table[path]` = `value`, where `path` is `key` or `key.index.key…` (arrays by index).
pub fn set(table: &mut toml::Table, path: &str, value: impl Into<toml::Value>) {
    let mut keys = path.split('.');
    let first = keys.next().expect("a non-empty path");
    let mut slot = table.entry(first).or_insert_with(|| toml::Table::new().into());
    for k in keys {
        slot = match (slot, k.parse::<usize>()) {
            (toml::Value::Array(a), Ok(i)) => &mut a[i],
            (toml::Value::Table(t), _) => t.entry(k).or_insert_with(|| toml::Table::new().into()),
            (other, _) => panic!("{path}: {other:?} has no '{k}'"),
        };
    }
    *slot = value.into();
}

/// A TOML array of strings.
pub fn strings(items: &[&str]) -> toml::Value {
    toml::Value::Array(items.iter().map(|s| toml::Value::from(*s)).collect())
}

/// One pin of a 1-D model: f(at) = the integral, eliminating `eliminate`.
pub fn pin(at: f64, eliminate: &str) -> toml::Value {
    let mut t = toml::Table::new();
    t.insert("at".into(), toml::Value::Array(vec![at.into()]));
    t.insert("eliminate".into(), eliminate.into());
    t.into()
}

/// The integral of one quantity, each point evaluated once.
pub struct Integral {
    sampler: Sampler,
    known: HashMap<Vec<u64>, f64>,
}

impl Integral {
    /// The integral of the spec's quantity at the spec's tolerance.
    pub fn of(spec: &Spec) -> Integral {
        Integral { sampler: spec.sampler(), known: HashMap::new() }
    }

    /// The integral at `points`, the new ones in parallel.
    pub fn at(&mut self, points: &[Vec<f64>]) -> Vec<f64> {
        let key = |p: &[f64]| p.iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
        let missing: Vec<&Vec<f64>> = points.iter().filter(|p| !self.known.contains_key(&key(p))).collect();
        let sampler = self.sampler;
        let values: Vec<f64> = missing.par_iter().map(|p| sampler.eval(p).value).collect();
        for (p, v) in missing.into_iter().zip(values) {
            self.known.insert(key(p), v);
        }
        points.iter().map(|p| self.known[&key(p)]).collect()
    }

    /// The verification reference at `points`.
    pub fn reference(&mut self, points: Vec<Vec<f64>>) -> Reference {
        let values = self.at(&points);
        Reference { points, values }
    }

    /// The spec's model fitted to the integral on a grid of `counts` over the spec's axes.
    pub fn fit(&mut self, spec: &Spec, counts: &[usize]) -> Result<DVector<f64>, BenchError> {
        let x = pipeline::grid(spec, counts);
        let y = self.at(&x);
        Ok(pipeline::fit_samples(spec, &Data { x, y }).map_err(BenchError::build(&spec.file.name))?.coefficients)
    }
}

/// The emitted WGSL library of a build.
pub fn wgsl_of(built: &Built) -> Result<&str, BenchError> {
    let a = built
        .artifacts
        .iter()
        .find(|a| a.path.starts_with("wgsl"))
        .ok_or_else(|| BenchError::NoWgsl { spec: built.name.clone() })?;
    std::str::from_utf8(&a.contents).map_err(|source| BenchError::WgslUtf8 { spec: built.name.clone(), source })
}

/// The counts of `function` in a WGSL source of spec `spec`'s.
pub fn count(spec: &str, wgsl: &str, function: &str) -> Result<OpCounts, BenchError> {
    ops::count(wgsl, function).map_err(|source| BenchError::Ops { spec: spec.to_string(), function: function.to_string(), source })
}

/// A parsed WGSL source of spec `spec`'s, for counting several of its functions.
pub fn parse(spec: &str, wgsl: &str) -> Result<ops::Source, BenchError> {
    ops::Source::parse(wgsl).map_err(|source| BenchError::Wgsl { spec: spec.to_string(), source })
}

/// The counts of `function` in a parsed source of spec `spec`'s.
pub fn count_in(spec: &str, source: &ops::Source, function: &str) -> Result<OpCounts, BenchError> {
    source.count(function).map_err(|source| BenchError::Ops { spec: spec.to_string(), function: function.to_string(), source })
}

/// Max and rms error over a number of points.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    pub max: f64,
    pub rms: f64,
    pub points: usize,
}

impl From<&Verification> for Measured {
    /// The emitted f32 code's errors.
    fn from(v: &Verification) -> Measured {
        Measured { max: v.max_abs_error_f32, rms: v.rms_error_f32, points: v.points }
    }
}

/// A row of a form's counts and errors.
pub fn row(quantity: &str, form: &str, ops: OpCounts, table_bytes: usize, m: Measured, note: String) -> FormRow {
    FormRow {
        quantity: quantity.into(),
        form: form.into(),
        cost: ops.weighted(),
        ops,
        table_bytes,
        max_error: m.max,
        rms_error: m.rms,
        points: m.points,
        pareto: false,
        note,
    }
}

/// How a form's denominators are checked: the pipeline's proof for what is fitted here,
/// none for published constants (whose denominators are measured as they are, and reported
/// when the proof does not hold).
pub fn check(form: &str) -> Denominators {
    if form == PUBLISHED { Denominators::Unchecked } else { Denominators::Proven }
}

/// The form name of published constants.
pub const PUBLISHED: &str = "published";

/// "; denominator not proven positive …" when the proof fails on the spec's (outer) domain.
pub fn unproven(model: &RationalModel, c: &DVector<f64>, domain: &[(f64, f64)], what: &str) -> String {
    match prove_denominator_positive(model, c, domain) {
        Positivity::Proven { .. } => String::new(),
        Positivity::NotProven { lower, region, sample } => {
            let centre: Vec<String> = region.iter().map(|(a, b)| format!("{:.3}", 0.5 * (a + b))).collect();
            format!("; {what}denominator not proven positive: interval bound {lower:.1e} near ({}), Q = {sample:.2e} there", centre.join(", "))
        }
    }
}

/// The ranges of the spec's first `n` axes.
pub fn outer_domain(spec: &Spec, n: usize) -> Vec<(f64, f64)> {
    spec.file.axis[..n].iter().map(|a| (a.range[0], a.range[1])).collect()
}

/// A rational form: verified and emitted through the pipeline, its emitted function counted.
pub fn fit_row(spec: &Spec, coefficients: DVector<f64>, reference: &Reference, form: &str, note: &str) -> Result<FormRow, BenchError> {
    fit_row_f32(spec, coefficients, None, reference, form, note)
}

/// The committed fit of a spec, with the f32 coefficients its emitted code carries.
pub fn refit_row(spec: &Spec, generated: &Path, reference: &Reference, note: &str) -> Result<FormRow, BenchError> {
    let (c, f32s) = pipeline::committed_fit(spec, generated).map_err(BenchError::build(&spec.file.name))?;
    fit_row_f32(spec, c, Some(f32s), reference, "refit", note)
}

/// [`fit_row`] with given f32 coefficients (else the f64 ones rounded to nearest).
pub fn fit_row_f32(
    spec: &Spec,
    coefficients: DVector<f64>,
    f32s: Option<pipeline::F32Coefficients>,
    reference: &Reference,
    form: &str,
    note: &str,
) -> Result<FormRow, BenchError> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let poles = match check(form) {
        Denominators::Unchecked => unproven(model, &coefficients, &outer_domain(spec, spec.file.axis.len()), ""),
        Denominators::Proven => String::new(),
    };
    let built = pipeline::fit_from_coefficients(spec, coefficients, None, f32s, reference, check(form))
        .map_err(BenchError::build(&spec.file.name))?;
    let ops = count(&spec.file.name, wgsl_of(&built)?, &spec.file.emit.function)?;
    let v = &built.verification;
    let shape = format!("{}/{} terms", model.numerator.len(), model.denominator.len());
    let note = if note.is_empty() { format!("{shape}{poles}") } else { format!("{shape}; {note}{poles}") };
    Ok(row(&spec.quantity_label(), form, ops, 0, v.into(), note))
}

/// A table form (values at the spec's table points), verified and emitted through the pipeline.
pub fn table_row(spec: &Spec, values: Vec<f64>, reference: &Reference, form: &str, note: &str) -> Result<FormRow, BenchError> {
    let bytes = 4 * values.len();
    let built = pipeline::table_from_values(spec, values, reference).map_err(BenchError::build(&spec.file.name))?;
    let ops = count(&spec.file.name, wgsl_of(&built)?, &spec.file.emit.function)?;
    let v = &built.verification;
    let size: Vec<String> = spec.file.axis.iter().map(|a| a.count.to_string()).collect();
    let kind = if size.len() == 1 { "linear" } else { "bilinear" };
    let shape = format!("{} f32 const array, {kind}", size.join("×"));
    let note = if note.is_empty() { shape } else { format!("{shape}; {note}") };
    Ok(row(&spec.quantity_label(), form, ops, bytes, v.into(), note))
}

/// The committed values of a table spec (generated/json).
pub fn committed_values(spec: &Spec, generated: &Path) -> Result<Vec<f64>, BenchError> {
    pipeline::committed_values(spec, generated).map_err(BenchError::build(&spec.file.name))
}

/// A table spec's values: the integral at its grid points.
pub fn table_values(integral: &mut Integral, spec: &Spec) -> Vec<f64> {
    integral.at(&pipeline::table_points(spec))
}

/// A table over the axes of a fit or table spec, `count` points on every axis.
pub fn table_spec(ctx: &Ctx, base: &Spec, name: &str, count: usize) -> Result<Spec, BenchError> {
    ctx.variant(base, name, |t| {
        t.remove("model");
        t.remove("fit");
        set(t, "kind", "table");
        for i in 0..base.file.axis.len() {
            set(t, &format!("axis.{i}.count"), count as i64);
        }
    })
}

/// The rows as aligned text, one block per quantity (in the order given), each row's weighted
/// cost, operation counts, table bytes and errors; `*` marks the Pareto-optimal forms.
pub fn render(rows: &[FormRow]) -> String {
    let mut out = format!(
        "Shader cost against error (cost = add + mul + other + {s}·(div + transc) + {m}·(tex + table loads); \
         * = Pareto-optimal in cost, table bytes and max error)\n",
        s = ops::SFU_WEIGHT,
        m = ops::MEMORY_WEIGHT
    );
    let head = ["", "form", "cost", "add", "mul", "div", "transc", "tex", "loads", "other", "bytes", "max error", "rms error", "points", "note"];
    let mut quantities: Vec<&str> = Vec::new();
    for r in rows {
        if !quantities.contains(&r.quantity.as_str()) {
            quantities.push(&r.quantity);
        }
    }
    for q in quantities {
        let cells: Vec<Vec<String>> = rows
            .iter()
            .filter(|r| r.quantity == q)
            .map(|r| {
                let o = &r.ops;
                let transc = if o.transc_fns.is_empty() {
                    o.transc.to_string()
                } else {
                    format!("{} ({})", o.transc, o.transc_fns.iter().copied().collect::<Vec<_>>().join(" "))
                };
                vec![
                    if r.pareto { "*".into() } else { String::new() },
                    r.form.clone(),
                    r.cost.to_string(),
                    o.add.to_string(),
                    o.mul.to_string(),
                    o.div.to_string(),
                    transc,
                    o.tex.to_string(),
                    o.const_loads.to_string(),
                    o.other.to_string(),
                    r.table_bytes.to_string(),
                    format!("{:.3e}", r.max_error),
                    format!("{:.3e}", r.rms_error),
                    r.points.to_string(),
                    r.note.clone(),
                ]
            })
            .collect();
        let widths: Vec<usize> = (0..head.len())
            .map(|i| cells.iter().map(|c| c[i].chars().count()).chain([head[i].chars().count()]).max().unwrap_or(0))
            .collect();
        let line = |c: &[String]| {
            let mut s = String::from("  ");
            for (i, (v, w)) in c.iter().zip(&widths).enumerate() {
                let pad = w - v.chars().count();
                // Text left-aligned (marker, form, note), numbers right-aligned.
                if i <= 1 || i == head.len() - 1 {
                    s.push_str(v);
                    if i != head.len() - 1 {
                        s.push_str(&" ".repeat(pad));
                    }
                } else {
                    s.push_str(&" ".repeat(pad));
                    s.push_str(v);
                }
                if i != head.len() - 1 {
                    s.push_str("  ");
                }
            }
            s.trim_end().to_string() + "\n"
        };
        out.push_str(&format!("\n{q}\n"));
        out.push_str(&line(&head.iter().map(|s| s.to_string()).collect::<Vec<_>>()));
        for c in &cells {
            out.push_str(&line(c));
        }
    }
    out
}

/// Checks of a family's quick forms, for the families' tests.
#[cfg(test)]
pub mod testing {
    use super::*;

    /// The quick run of `sets` (see [`ctx`]).
    pub fn quick(sets: &[FormSet], catalog: &Catalog) -> Vec<FormRow> {
        of(&ctx(true, catalog), sets).expect("the quick run")
    }

    /// The specs in `fits/` and the committed coefficients in `generated/` (relative to the
    /// working directory, as the CLI's defaults), loaded with `catalog`.
    pub fn ctx(quick: bool, catalog: &Catalog) -> Ctx<'_> {
        Ctx { fits: Path::new("fits"), generated: Path::new("generated"), quick, catalog }
    }

    /// Every quantity has at least three forms sorted by cost, finite errors and a Pareto
    /// front; every row is of one of `quantities`; the text has one block per quantity.
    pub fn every_quantity_has_three_forms_sorted_by_cost_with_a_front(rows: &[FormRow], quantities: &[&str]) {
        for &q in quantities {
            let r: Vec<&FormRow> = rows.iter().filter(|r| r.quantity == q).collect();
            assert!(r.len() >= 3, "{q}: {} forms", r.len());
            assert!(r.iter().any(|r| r.pareto), "{q}: no Pareto-optimal form");
            assert!(r.windows(2).all(|w| w[0].cost <= w[1].cost), "{q}: not sorted by cost");
            for f in &r {
                assert!(f.max_error.is_finite() && f.max_error > 0.0 && f.rms_error <= f.max_error, "{q} {}: {f:?}", f.form);
                assert!(f.cost > 0 && f.points > 0, "{q} {}: {f:?}", f.form);
            }
            // The cheapest form is on the front unless an equally cheap one beats it.
            assert!(r[0].pareto || r.iter().any(|o| o.cost == r[0].cost && o.pareto), "{q}");
        }
        assert_eq!(rows.len(), rows.iter().filter(|r| quantities.contains(&r.quantity.as_str())).count());
        let text = render(rows);
        for q in quantities {
            assert_eq!(text.lines().filter(|l| l == q).count(), 1, "one block for {q}");
        }
        let marked = text.lines().filter(|l| l.trim_start().starts_with('*')).count();
        assert_eq!(marked, rows.iter().filter(|r| r.pareto).count());
    }

    /// Linear or bilinear interpolation of a smooth function: error O(h²) per step h, so a
    /// finer table of the same quantity (more bytes, same domain) must do better. Per quantity
    /// and storage kind (texture vs const array), tables sorted by size; every quantity has a
    /// table form.
    pub fn table_error_decreases_with_resolution(rows: &[FormRow], quantities: &[&str]) {
        for &q in quantities {
            for kind in ["table", "texture"] {
                let mut t: Vec<&FormRow> = rows.iter().filter(|r| r.quantity == q && r.form.starts_with(kind)).collect();
                t.sort_by_key(|r| r.table_bytes);
                for w in t.windows(2) {
                    assert!(w[1].max_error < w[0].max_error, "{q}: {} ({:e}) is not better than {} ({:e})", w[1].form, w[1].max_error, w[0].form, w[0].max_error);
                }
            }
        }
        let tables = rows.iter().filter(|r| r.table_bytes > 0).map(|r| &r.quantity).collect::<std::collections::BTreeSet<_>>();
        assert_eq!(tables.len(), quantities.len(), "every quantity has a table form");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthetic(form: &str, cost: usize, bytes: usize, max: f64) -> FormRow {
        row("q", form, OpCounts { add: cost, ..OpCounts::default() }, bytes, Measured { max, rms: max, points: 1 }, String::new())
    }

    #[test]
    fn pareto_front_of_hand_made_rows() {
        let mut rows = vec![
            synthetic("cheap", 10, 0, 1e-2),
            synthetic("dominated", 12, 0, 2e-2), // costlier and worse than "cheap"
            synthetic("accurate", 20, 0, 1e-4),
            synthetic("table", 10, 512, 1e-5),   // as cheap as "cheap", larger, more accurate
            synthetic("tie", 20, 0, 1e-4),       // equal to "accurate": neither dominates
            synthetic("big", 10, 1024, 1e-5),    // "table" is as good and smaller
        ];
        mark_pareto(&mut rows);
        let front: Vec<&str> = rows.iter().filter(|r| r.pareto).map(|r| r.form.as_str()).collect();
        assert_eq!(front, ["cheap", "accurate", "table", "tie"]);
    }
}
