//! Shader cost against error: several approximation forms per quantity, each built in memory
//! through the pipeline (fit or table → verify → emit WGSL), its emitted WGSL counted by
//! [`super::ops`] and its f32 evaluation measured against the integral on one verification grid
//! per quantity (all forms of a quantity on the same points). Nothing is written.
//!
//! Forms per quantity (see each row's `note`):
//! - the published constants (COD: WWII, Ghost of Tsushima Listings 1–5, from
//!   [`crate::validate`]) in the emitted form of the committed spec;
//! - the committed refit (coefficients from generated/json);
//! - a cheaper and, where it pays, a richer rational, fitted here with the committed spec's
//!   objective on the committed spec's sampling grid or a coarser one (said in the note;
//!   quick mode: coarser still);
//! - tables at two resolutions (the committed one where there is one), linear or bilinear;
//!   for P_s a table of the six coefficients over (α, θf); for skin the LUT texture at three
//!   resolutions and the const-array lookup.
//!
//! The cost of a form is [`OpCounts::weighted`]; `table_bytes` is the memory its tables take.
//! A form is Pareto-optimal when no other form of its quantity is at most as costly, at most
//! as large and at most as wrong, and better in one of the three.
//!
//! Every integral is evaluated once per quantity and point (a cache shared by the forms, filled
//! in parallel and read in grid order), fits are sequential: the rows are the same at any
//! thread count.

use super::ops::{self, OpCounts};
use crate::emit::fields as efields;
use crate::emit::wgsl::{self, Body, Function};
use crate::fit::positivity::{prove_denominator_positive, Positivity};
use crate::fit::{Data, RationalModel, Term};
use crate::pipeline::fields::{self as pfields, FieldsReference};
use crate::pipeline::{self, Built, Denominators, Reference, Verification};
use crate::family::fuzz::integrals as fuzz;
use crate::quantity::QuantityDef;
use crate::spec::Spec;
use crate::validate;
use anyhow::{Context, Result};
use nalgebra::DVector;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;
use std::f64::consts::FRAC_PI_2;
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

/// Every form of every quantity, with the specs in `fits/` and the committed coefficients in
/// `generated/` (relative to the working directory, as the CLI's defaults); `quick`: coarser
/// verification and fitting grids.
pub fn shader_forms(quick: bool) -> Result<Vec<FormRow>> {
    shader_forms_at(Path::new("fits"), Path::new("generated"), quick)
}

/// [`shader_forms`] with the spec and generated folders given.
pub fn shader_forms_at(fits: &Path, generated: &Path, quick: bool) -> Result<Vec<FormRow>> {
    let ctx = Ctx { fits, generated, quick };
    let families: [Family; 7] = [gloss_length, gloss_combine, fuzz_q, fuzz_g, fuzz_r, fuzz_ps, skin_punctual];
    let mut rows = Vec::new();
    for family in families {
        let mut r = family(&ctx)?;
        mark_pareto(&mut r);
        r.sort_by(|a, b| (a.cost, a.table_bytes).cmp(&(b.cost, b.table_bytes)).then(a.max_error.total_cmp(&b.max_error)));
        rows.extend(r);
    }
    Ok(rows)
}

/// The forms of one quantity.
type Family = fn(&Ctx) -> Result<Vec<FormRow>>;

/// Mark the rows no other row dominates in (cost, table bytes, max error).
fn mark_pareto(rows: &mut [FormRow]) {
    let key: Vec<(usize, usize, f64)> = rows.iter().map(|r| (r.cost, r.table_bytes, r.max_error)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (c, b, e) = key[i];
        r.pareto = !key.iter().any(|&(c2, b2, e2)| c2 <= c && b2 <= b && e2 <= e && (c2 < c || b2 < b || e2 < e));
    }
}

/// Where the specs and the committed coefficients are, and the grid sizes.
struct Ctx<'a> {
    fits: &'a Path,
    generated: &'a Path,
    quick: bool,
}

impl Ctx<'_> {
    /// `full` in a full run, `quick` in a quick one.
    fn pick<T>(&self, full: T, quick: T) -> T {
        if self.quick { quick } else { full }
    }

    fn spec(&self, name: &str) -> Result<Spec> {
        Ok(Spec::load(&self.fits.join(format!("{name}.toml")), crate::family::catalog())?)
    }

    /// The committed spec `base` as TOML with `edit` applied and named `name`: a spec in
    /// memory only (its path names no file).
    fn variant(&self, base: &Spec, name: &str, edit: impl FnOnce(&mut toml::Table)) -> Result<Spec> {
        let mut t: toml::Table = base.text.parse().with_context(|| format!("{}", base.path.display()))?;
        t.insert("name".into(), name.into());
        edit(&mut t);
        let text = toml::to_string(&t).with_context(|| format!("variant {name}"))?;
        Ok(Spec::parse(&self.fits.join(format!("{name}.toml")), text, crate::family::catalog())?)
    }
}

/// `table[path]` = `value`, where `path` is `key` or `key.index.key…` (arrays by index).
fn set(table: &mut toml::Table, path: &str, value: impl Into<toml::Value>) {
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

fn strings(items: &[&str]) -> toml::Value {
    toml::Value::Array(items.iter().map(|s| toml::Value::from(*s)).collect())
}

/// One pin of a 1-D model: f(at) = the integral, eliminating `eliminate`.
fn pin(at: f64, eliminate: &str) -> toml::Value {
    let mut t = toml::Table::new();
    t.insert("at".into(), toml::Value::Array(vec![at.into()]));
    t.insert("eliminate".into(), eliminate.into());
    t.into()
}

/// The integral of one quantity, each point evaluated once.
struct Integral {
    quantity: &'static QuantityDef,
    tolerance: f64,
    known: HashMap<Vec<u64>, f64>,
}

impl Integral {
    fn of(spec: &Spec) -> Integral {
        Integral { quantity: spec.quantity, tolerance: spec.file.tolerance, known: HashMap::new() }
    }

    /// The integral at `points`, the new ones in parallel.
    fn at(&mut self, points: &[Vec<f64>]) -> Vec<f64> {
        let key = |p: &[f64]| p.iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
        let missing: Vec<&Vec<f64>> = points.iter().filter(|p| !self.known.contains_key(&key(p))).collect();
        let (q, tol) = (self.quantity, self.tolerance);
        let values: Vec<f64> = missing.par_iter().map(|p| (q.eval)(p, tol).value).collect();
        for (p, v) in missing.into_iter().zip(values) {
            self.known.insert(key(p), v);
        }
        points.iter().map(|p| self.known[&key(p)]).collect()
    }

    fn reference(&mut self, points: Vec<Vec<f64>>) -> Reference {
        let values = self.at(&points);
        Reference { points, values }
    }

    /// The spec's model fitted to the integral on a grid of `counts` over the spec's axes.
    fn fit(&mut self, spec: &Spec, counts: &[usize]) -> Result<DVector<f64>> {
        let x = pipeline::grid(spec, counts);
        let y = self.at(&x);
        Ok(pipeline::fit_samples(spec, &Data { x, y })?.coefficients)
    }
}

/// The emitted WGSL library of a build.
fn wgsl_of(built: &Built) -> Result<&str> {
    let a = built
        .artifacts
        .iter()
        .find(|a| a.path.starts_with("wgsl"))
        .with_context(|| format!("{}: no WGSL artifact", built.name))?;
    Ok(std::str::from_utf8(&a.contents)?)
}

/// Max and rms error over a number of points.
#[derive(Debug, Clone, Copy)]
struct Measured {
    max: f64,
    rms: f64,
    points: usize,
}

impl From<&Verification> for Measured {
    /// The emitted f32 code's errors.
    fn from(v: &Verification) -> Measured {
        Measured { max: v.max_abs_error_f32, rms: v.rms_error_f32, points: v.points }
    }
}

fn row(quantity: &str, form: &str, ops: OpCounts, table_bytes: usize, m: Measured, note: String) -> FormRow {
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
fn check(form: &str) -> Denominators {
    if form == PUBLISHED { Denominators::Unchecked } else { Denominators::Proven }
}

const PUBLISHED: &str = "published";

/// "; denominator not proven positive …" when the proof fails on the spec's (outer) domain.
fn unproven(model: &RationalModel, c: &DVector<f64>, domain: &[(f64, f64)], what: &str) -> String {
    match prove_denominator_positive(model, c, domain) {
        Positivity::Proven { .. } => String::new(),
        Positivity::NotProven { lower, region, sample } => {
            let centre: Vec<String> = region.iter().map(|(a, b)| format!("{:.3}", 0.5 * (a + b))).collect();
            format!("; {what}denominator not proven positive: interval bound {lower:.1e} near ({}), Q = {sample:.2e} there", centre.join(", "))
        }
    }
}

fn outer_domain(spec: &Spec, n: usize) -> Vec<(f64, f64)> {
    spec.file.axis[..n].iter().map(|a| (a.range[0], a.range[1])).collect()
}

/// A rational form: verified and emitted through the pipeline, its emitted function counted.
fn fit_row(spec: &Spec, coefficients: DVector<f64>, reference: &Reference, form: &str, note: &str) -> Result<FormRow> {
    fit_row_f32(spec, coefficients, None, reference, form, note)
}

/// The committed fit of a spec, with the f32 coefficients its emitted code carries.
fn refit_row(spec: &Spec, generated: &Path, reference: &Reference, note: &str) -> Result<FormRow> {
    let (c, f32s) = pipeline::committed_fit(spec, generated)?;
    fit_row_f32(spec, c, Some(f32s), reference, "refit", note)
}

/// [`fit_row`] with given f32 coefficients (else the f64 ones rounded to nearest).
fn fit_row_f32(
    spec: &Spec,
    coefficients: DVector<f64>,
    f32s: Option<pipeline::F32Coefficients>,
    reference: &Reference,
    form: &str,
    note: &str,
) -> Result<FormRow> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let poles = match check(form) {
        Denominators::Unchecked => unproven(model, &coefficients, &outer_domain(spec, spec.file.axis.len()), ""),
        Denominators::Proven => String::new(),
    };
    let built = pipeline::fit_from_coefficients(spec, coefficients, None, f32s, reference, check(form))?;
    let ops = ops::count(wgsl_of(&built)?, &spec.file.emit.function)?;
    let v = &built.verification;
    let shape = format!("{}/{} terms", model.numerator.len(), model.denominator.len());
    let note = if note.is_empty() { format!("{shape}{poles}") } else { format!("{shape}; {note}{poles}") };
    Ok(row(&spec.file.quantity, form, ops, 0, v.into(), note))
}

/// A table form (values at the spec's table points), verified and emitted through the pipeline.
fn table_row(spec: &Spec, values: Vec<f64>, reference: &Reference, form: &str, note: &str) -> Result<FormRow> {
    let bytes = 4 * values.len();
    let built = pipeline::table_from_values(spec, values, reference)?;
    let ops = ops::count(wgsl_of(&built)?, &spec.file.emit.function)?;
    let v = &built.verification;
    let size: Vec<String> = spec.file.axis.iter().map(|a| a.count.to_string()).collect();
    let kind = if size.len() == 1 { "linear" } else { "bilinear" };
    let shape = format!("{} f32 const array, {kind}", size.join("×"));
    let note = if note.is_empty() { shape } else { format!("{shape}; {note}") };
    Ok(row(&spec.file.quantity, form, ops, bytes, v.into(), note))
}

/// A table spec's values: the integral at its grid points.
fn table_values(integral: &mut Integral, spec: &Spec) -> Vec<f64> {
    integral.at(&pipeline::table_points(spec))
}

/// A table over the axes of a fit or table spec, `count` points on every axis.
fn table_spec(ctx: &Ctx, base: &Spec, name: &str, count: usize) -> Result<Spec> {
    ctx.variant(base, name, |t| {
        t.remove("model");
        t.remove("fit");
        set(t, "kind", "table");
        for i in 0..base.file.axis.len() {
            set(t, &format!("axis.{i}.count"), count as i64);
        }
    })
}

/// g → ‖n_s‖ (COD: WWII).
fn gloss_length(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("gloss_length")?;
    let table = ctx.spec("gloss_table")?;
    let mut integral = Integral::of(&refit);
    // The committed verification grid (16 points per step of the 256-entry table); quick: 4.
    let reference = integral.reference(pipeline::grid(&refit, &[ctx.pick(4081, 1021)]));
    let published_spec = ctx.variant(&refit, "gloss_length_published", |_| {})?;
    let published = crate::family::gloss::published::published_fit_coefficients(crate::family::gloss::published::PUBLISHED_ENDS.1);
    let cheaper = ctx.variant(&refit, "gloss_length_2_1", |t| {
        set(t, "model.numerator", strings(&["1", "gloss", "gloss^2"]));
        set(t, "model.denominator", strings(&["gloss"]));
        set(t, "model.pin", toml::Value::Array(vec![pin(0.0, "1"), pin(1.0, "gloss^2")]));
    })?;
    let richer = ctx.variant(&refit, "gloss_length_4_3", |t| {
        set(t, "model.numerator", strings(&["1", "gloss", "gloss^2", "gloss^3", "gloss^4"]));
        set(t, "model.denominator", strings(&["gloss", "gloss^2", "gloss^3"]));
        set(t, "model.pin", toml::Value::Array(vec![pin(0.0, "1"), pin(1.0, "gloss^4")]));
    })?;
    let small = table_spec(ctx, &table, "gloss_table_64", 64)?;
    let n = refit.file.axis[0].count;
    let fit_note = format!("ends pinned, minimax on {n} samples");
    Ok(vec![
        fit_row(&published_spec, DVector::from_row_slice(&published), &reference, PUBLISHED, "COD: WWII FindFit constants, pinned to the Monte Carlo ends")?,
        refit_row(&refit, ctx.generated, &reference, "fits/gloss_length.toml, committed")?,
        fit_row(&cheaper, integral.fit(&cheaper, &[n])?, &reference, "rational 2/1", &fit_note)?,
        fit_row(&richer, integral.fit(&richer, &[n])?, &reference, "rational 4/3", &fit_note)?,
        table_row(&table, pipeline::committed_values(&table, ctx.generated)?, &reference, "table 256", "fits/gloss_table.toml, committed")?,
        table_row(&small, table_values(&mut integral, &small), &reference, "table 64", "")?,
    ])
}

/// Gloss of two combined normal maps (RNM of two GGX NDFs, COD: WWII).
fn gloss_combine(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("gloss_combine")?;
    let table = ctx.spec("gloss_combine_lut")?;
    let mut integral = Integral::of(&refit);
    // The committed table's grid (253 = 4·63 + 1: its nodes and midpoints; the 22-entry
    // table's too, 252 = 12·21); quick: 127 (the midpoints of both tables).
    let n = ctx.pick(253, 127);
    let reference = integral.reference(pipeline::grid(&refit, &[n, n]));
    let published_spec = ctx.variant(&refit, "gloss_combine_published", |_| {})?;
    let (p, q) = (crate::family::gloss::published::PUBLISHED_COMBINE_P, crate::family::gloss::published::PUBLISHED_COMBINE_Q);
    let published: Vec<f64> = p.iter().chain(&q[1..]).copied().collect();
    let cheaper = ctx.variant(&refit, "gloss_combine_3_2", |t| {
        set(t, "model.numerator", strings(&["1", "x + y", "x*y"]));
        set(t, "model.denominator", strings(&["x + y", "x*y"]));
    })?;
    let small = table_spec(ctx, &table, "gloss_combine_lut_22", 22)?;
    let m = ctx.pick(refit.file.axis[0].count, 33);
    let fit_note = format!("symmetric terms, clamp-aware lsq on {m}×{m}");
    Ok(vec![
        fit_row(&published_spec, DVector::from_vec(published), &reference, PUBLISHED, "COD: WWII rational fit constants")?,
        refit_row(&refit, ctx.generated, &reference, "fits/gloss_combine.toml, committed")?,
        fit_row(&cheaper, integral.fit(&cheaper, &[m, m])?, &reference, "rational, fewer terms", &fit_note)?,
        table_row(&table, pipeline::committed_values(&table, ctx.generated)?, &reference, "table 64²", "fits/gloss_combine_lut.toml, committed")?,
        table_row(&small, table_values(&mut integral, &small), &reference, "table 22²", "")?,
    ])
}

/// Average penetration Q(d) = 2·E₃(d) (Ghost of Tsushima, Eq. 4).
fn fuzz_q(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("fuzz_q")?;
    let mut integral = Integral::of(&refit);
    let reference = integral.reference(pipeline::grid(&refit, &[ctx.pick(refit.file.axis[0].verify_count(), 513)]));
    fuzz_q_forms(ctx, &refit, &mut integral, &reference)
}

fn fuzz_q_forms(ctx: &Ctx, refit: &Spec, integral: &mut Integral, reference: &Reference) -> Result<Vec<FormRow>> {
    let published_spec = ctx.variant(refit, "fuzz_q_published", |_| {})?;
    let [c0, c1] = crate::family::fuzz::published::Q_COEFFS;
    let linear = ctx.variant(refit, "fuzz_q_linear", |t| set(t, "model.numerator", strings(&["1", "d"])))?;
    let rational = ctx.variant(refit, "fuzz_q_2_1", |t| set(t, "model.denominator", strings(&["d"])))?;
    let table = table_spec(ctx, refit, "fuzz_q_table_33", 33)?;
    let n = refit.file.axis[0].count;
    let fit_note = format!("Q(0) = 1 fixed, minimax on {n} samples");
    Ok(vec![
        fit_row(&published_spec, DVector::from_vec(vec![1.0, c0, c1]), reference, PUBLISHED, "Listing 4")?,
        refit_row(refit, ctx.generated, reference, "fits/fuzz_q.toml, committed")?,
        fit_row(&linear, integral.fit(&linear, &[n])?, reference, "linear", &fit_note)?,
        fit_row(&rational, integral.fit(&rational, &[n])?, reference, "rational 2/1", &fit_note)?,
        table_row(&table, table_values(integral, &table), reference, "table 33", "")?,
    ])
}

/// Hemispherical average G(μv, d) of the fuzz layer (Ghost of Tsushima, Eq. 3).
fn fuzz_g(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("fuzz_g")?;
    let mut integral = Integral::of(&refit);
    // The committed verification grid (257², with the nodes and midpoints of the 17² and 33²
    // tables); quick: 129² (the same for both tables).
    let n = ctx.pick(257, 129);
    let reference = integral.reference(pipeline::grid(&refit, &[n, n]));
    let published_spec = ctx.variant(&refit, "fuzz_g_published", |_| {})?;
    let c = crate::family::fuzz::published::G_COEFFS;
    let richer = ctx.variant(&refit, "fuzz_g_4_3", |t| {
        set(t, "model.numerator", strings(&["d", "d*mu_v", "d*mu_v^2", "d*mu_v^3"]));
        set(t, "model.denominator", strings(&["mu_v", "mu_v^2", "mu_v^3"]));
    })?;
    let m = ctx.pick(refit.file.axis[0].count, 33);
    let (t17, t33) = (table_spec(ctx, &refit, "fuzz_g_table_17", 17)?, table_spec(ctx, &refit, "fuzz_g_table_33", 33)?);
    Ok(vec![
        fit_row(&published_spec, DVector::from_vec(vec![1.0, c[0], c[1], c[2], c[3]]), &reference, PUBLISHED, "Listing 3 (μv clamped to ≥ 0.001)")?,
        refit_row(&refit, ctx.generated, &reference, "fits/fuzz_g.toml, committed")?,
        fit_row(&richer, integral.fit(&richer, &[m, m])?, &reference, "rational, more terms", &format!("Σr⁴ on {m}×{m}"))?,
        table_row(&t17, table_values(&mut integral, &t17), &reference, "table 17²", UNIFORM_MU)?,
        table_row(&t33, table_values(&mut integral, &t33), &reference, "table 33²", UNIFORM_MU)?,
    ])
}

const UNIFORM_MU: &str = "uniform grid: the largest errors sit at μv = 0.001, d → 0, where G depends on d/μv";

/// Cosine-weighted average R(α, θf) of P_s (Ghost of Tsushima, Eq. 5).
fn fuzz_r(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("fuzz_r")?;
    let mut integral = Integral::of(&refit);
    // R costs ~20 ms a point: the committed verification grid (25²), quick 13². The cheaper
    // fit and the tables take their samples from that grid's every other and every fourth
    // point (the tables' midpoints stay in the grid).
    let n = ctx.pick(25, 13);
    let reference = integral.reference(pipeline::grid(&refit, &[n, n]));
    let (half, quarter) = ((n - 1) / 2 + 1, (n - 1) / 4 + 1);
    let published_spec = ctx.variant(&refit, "fuzz_r_published", |_| {})?;
    let cheaper = ctx.variant(&refit, "fuzz_r_7_3", |t| {
        set(t, "model.numerator", strings(&["1", "beta", "gamma", "delta", "beta^2", "gamma^2", "beta*gamma"]));
    })?;
    let fine = table_spec(ctx, &refit, &format!("fuzz_r_table_{half}"), half)?;
    let coarse = table_spec(ctx, &refit, &format!("fuzz_r_table_{quarter}"), quarter)?;
    Ok(vec![
        fit_row(&published_spec, DVector::from_row_slice(&crate::family::fuzz::published::R_COEFFS), &reference, PUBLISHED, "Listing 5")?,
        refit_row(&refit, ctx.generated, &reference, "fits/fuzz_r.toml, committed")?,
        fit_row(&cheaper, integral.fit(&cheaper, &[half, half])?, &reference, "rational, fewer terms", &format!("minimax on {half}×{half}"))?,
        table_row(&fine, table_values(&mut integral, &fine), &reference, &format!("table {half}²"), "")?,
        table_row(&coarse, table_values(&mut integral, &coarse), &reference, &format!("table {quarter}²"), "")?,
    ])
}

/// The light directions and (α, θf) grid P_s is measured on: `validate`'s (17 × 17 over
/// α ∈ [0.15, 1], θf ∈ [0.1, π/2], 256 directions); quick: 9 × 9 × 64.
fn ps_reference(ctx: &Ctx, spec: &Spec) -> FieldsReference {
    let n = ctx.pick(17, 9);
    let d = ctx.pick(16, 8);
    let (alphas, thetas) = (fuzz::linspace(0.15, 1.0, n), fuzz::linspace(0.1, FRAC_PI_2, n));
    let outer: Vec<Vec<f64>> = thetas.iter().flat_map(|&t| alphas.iter().map(move |&a| vec![a, t])).collect();
    let inner: Vec<Vec<f64>> = fuzz::fitting_directions(d, d).into_iter().map(|(t, p)| vec![t, p]).collect();
    FieldsReference::sample(spec, outer, inner)
}

/// P_s through the six coefficients of Eq. 1: the coefficient function (once per material
/// when α and θf are) and the evaluator (per light), counted together; also the evaluator's
/// own counts.
fn fields_row(
    spec: &Spec,
    coefficients: &[DVector<f64>],
    reference: &FieldsReference,
    form: &str,
    note: &str,
) -> Result<(FormRow, OpCounts)> {
    let built = pfields::fields_from_coefficients(spec, coefficients, None, None, reference, check(form))?;
    let source = ops::Source::parse(wgsl_of(&built)?)?;
    let mut ops = source.count(&spec.file.emit.function)?;
    let evaluator = source.count(spec.file.emit.evaluator.as_deref().expect("fields specs name an evaluator"))?;
    let model = spec.model.as_ref().expect("fields specs carry a model");
    let offsets = &spec.file.fields.as_ref().expect("fields specs carry [fields]").offsets;
    let domain = outer_domain(spec, model.n_inputs);
    let poles: String = match check(form) {
        Denominators::Unchecked => coefficients
            .iter()
            .zip(offsets)
            .enumerate()
            .map(|(k, (c, &offset))| {
                let mut m = model.clone();
                m.offset = offset;
                unproven(&m, c, &domain, &format!("c{k}'s "))
            })
            .collect(),
        Denominators::Proven => String::new(),
    };
    let note = format!(
        "6 fields of {}/{} terms; coefficients {} + evaluator {} of the cost; {note}{poles}",
        model.numerator.len(),
        model.denominator.len(),
        ops.weighted(),
        evaluator.weighted()
    );
    ops.plus(&evaluator);
    let v = &built.verification;
    Ok((row(&spec.file.quantity, form, ops, 0, v.into(), note), evaluator))
}

/// Fraction P_s the fuzz layer scatters toward the base (Ghost of Tsushima, Eq. 1–2).
fn fuzz_ps(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let refit = ctx.spec("fuzz_ps")?;
    let reference = ps_reference(ctx, &refit);
    // Listing 1 with rows 3 and 4 exchanged (validate's finding), clamped to θf ≥ 0.1 as
    // Listing 2 does.
    let published_spec = ctx.variant(&refit, "fuzz_ps_published", |t| set(t, "axis.1.range", toml::Value::Array(vec![0.1.into(), FRAC_PI_2.into()])))?;
    let published: Vec<DVector<f64>> =
        [0, 1, 2, 4, 3, 5].iter().map(|&k| DVector::from_row_slice(&crate::family::fuzz::published::PS_COEFFS[k])).collect();
    let (committed, _) = pfields::committed(&refit, ctx.generated)?;
    // A cheaper form: the fields of degree 2 in (β, γ, δ), fitted as fits/fuzz_ps.toml is on
    // a coarser grid.
    let (outer, inner) = (ctx.pick(17, 9), ctx.pick(12, 8));
    let cheaper = ctx.variant(&refit, "fuzz_ps_8_7", |t| {
        let x = ["beta", "gamma", "delta", "beta^2", "gamma^2", "beta*gamma", "beta*delta"];
        set(t, "model.numerator", strings(&[&["1"], &x[..]].concat()));
        set(t, "model.denominator", strings(&x));
        for (i, k) in [outer, outer, inner, inner].into_iter().enumerate() {
            set(t, &format!("axis.{i}.count"), k as i64);
        }
    })?;
    let (cheaper_c, _) = pfields::fit(&cheaper)?;
    let (refit_row, evaluator) = fields_row(&refit, &committed, &reference, "refit", "fits/fuzz_ps.toml, committed")?;
    Ok(vec![
        fields_row(&published_spec, &published, &reference, PUBLISHED, "Listings 1–2, rows 3 and 4 exchanged")?.0,
        refit_row,
        fields_row(&cheaper, &cheaper_c, &reference, "rational, fewer terms", &format!("minimax on {outer}²×{inner}²"))?.0,
        ps_table_row(&refit, &committed, &evaluator, &reference, 9)?,
        ps_table_row(&refit, &committed, &evaluator, &reference, 17)?,
    ])
}

/// The six coefficients of the committed refit tabulated on n × n points of (α, θf) (its
/// domain), bilinear, then the refit's evaluator (`evaluator`: its counts).
fn ps_table_row(refit: &Spec, committed: &[DVector<f64>], evaluator: &OpCounts, reference: &FieldsReference, n: usize) -> Result<FormRow> {
    let basis = refit.quantity.basis.expect("fuzz-ps has an inner basis");
    let model = refit.model.as_ref().expect("fields specs carry a model");
    let offsets = &refit.file.fields.as_ref().expect("fields specs carry [fields]").offsets;
    let outer_axes = &refit.file.axis[..2];
    let nodes = pipeline::tensor(outer_axes, &[n, n]);
    let domain: Vec<(f32, f32)> = outer_axes.iter().map(|a| (a.range[0] as f32, a.range[1] as f32)).collect();
    let args: Vec<String> = outer_axes.iter().map(|a| a.name.clone()).collect();
    let tables: Vec<Vec<f32>> = committed
        .iter()
        .zip(offsets)
        .map(|(c, &offset)| {
            let mut m = model.clone();
            m.offset = offset;
            nodes.iter().map(|x| m.eval_full(c, x) as f32).collect()
        })
        .collect();
    // WGSL: one table module per coefficient and a function returning the six.
    let name = format!("fuzz_ps_table_{n}");
    let mut src = String::new();
    let mut calls = Vec::new();
    for (k, values) in tables.iter().enumerate() {
        let module = format!("{name}_c{k}");
        let f = Function { module: &module, name: &module, args: &args, derived: &[], domain: &domain, body: Body::Table { values, counts: &[n, n] } };
        src.push_str(&wgsl::render_module(&[], &f));
        calls.push(format!("{module}({})", args.join(", ")));
    }
    let params: Vec<String> = args.iter().map(|a| format!("{a}: f32")).collect();
    src.push_str(&format!("\nfn {name}({}) -> array<f32, 6> {{\n    return array<f32, 6>({});\n}}\n", params.join(", "), calls.join(", ")));
    let mut ops = ops::count(&src, &name)?;
    let note = format!(
        "6 × {n}² f32 const arrays of the refit's coefficients, bilinear (index arithmetic repeated per table as written); coefficients {} + evaluator {} of the cost",
        ops.weighted(),
        evaluator.weighted()
    );
    ops.plus(evaluator);
    // f32: the six lookups as emitted, then the evaluator as emitted.
    let eval_args: Vec<String> = basis.args.iter().map(|s| s.to_string()).collect();
    let terms: Vec<Term> = basis.terms.iter().map(|t| Term::parse(t, &eval_args).expect("basis terms are valid")).collect();
    let eval_domain: Vec<(f32, f32)> = basis.arg_domain.iter().map(|&(a, b)| (a as f32, b as f32)).collect();
    let evaluator_fn = efields::FieldsFunction {
        module: &name,
        name: &name,
        args: &args,
        derived: &[],
        domain: &domain,
        fields: &[],
        evaluator: "fuzz_ps",
        eval_args: &eval_args,
        eval_domain: &eval_domain,
        terms: &terms,
        range: (basis.range.0 as f32, basis.range.1 as f32),
    };
    let (mut truth, mut approx, mut points) = (Vec::new(), Vec::new(), Vec::new());
    for (o, row) in reference.outer.iter().zip(&reference.rows) {
        let o32: Vec<f32> = o.iter().map(|&v| v as f32).collect();
        let c: Vec<f32> = tables.iter().map(|t| crate::emit::rust::table_eval_f32(t, &[n, n], &domain, &o32)).collect();
        for (u, &y) in reference.inner.iter().zip(row) {
            let a: Vec<f32> = (basis.to_args)(o, u).iter().map(|&v| v as f32).collect();
            approx.push(efields::evaluator_f32(&evaluator_fn, &c, &a) as f64);
            truth.push(y);
            points.push(o.iter().chain(u).copied().collect::<Vec<f64>>());
        }
    }
    let (max, rms, _) = validate::measure(&points, &truth, &approx);
    Ok(row(&refit.file.quantity, &format!("table {n}²"), ops, 4 * 6 * n * n, Measured { max, rms, points: points.len() }, note))
}

/// Pre-integrated skin diffusion D(n·l, κ) for punctual lights (RGB).
fn skin_punctual(ctx: &Ctx) -> Result<Vec<FormRow>> {
    let committed = ctx.spec("skin_punctual_lut")?;
    let mut rows = Vec::new();
    for (w, h) in [(33, 32), (65, 64), (129, 128)] {
        let spec = if (w, h) == (65, 64) {
            committed.clone()
        } else {
            ctx.variant(&committed, &format!("skin_punctual_lut_{w}x{h}"), |t| {
                set(t, "resolution", toml::Value::Array(vec![(w as i64).into(), (h as i64).into()]))
            })?
        };
        let (built, texture) = crate::family::skin::build::build_with_texture_error(&spec)?;
        let source = ops::Source::parse(wgsl_of(&built)?)?;
        let f = &spec.file.emit.function;
        let committed_note = if (w, h) == (65, 64) { ", committed size" } else { "" };
        rows.push(row(
            &spec.file.quantity,
            &format!("texture {w}×{h}"),
            source.count(&format!("{f}_sample"))?,
            8 * w * h,
            (&texture).into(),
            format!(
                "rgba16float texels, linear sampler (error with exact filter weights: 8-bit weights add up to 2⁻⁹ of a texel step){committed_note}; measured on the texel grid with every midpoint"
            ),
        ));
        if (w, h) == (65, 64) {
            let v = &built.verification;
            rows.push(row(
                &spec.file.quantity,
                &format!("const array {w}×{h}"),
                source.count(f)?,
                12 * w * h,
                v.into(),
                "f32 RGB texels, bilinear in the shader; fits/skin_punctual_lut.toml".into(),
            ));
        }
    }
    Ok(rows)
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::OnceLock;

    /// The quick run, shared by the tests that read it.
    fn quick() -> &'static [FormRow] {
        static ROWS: OnceLock<Vec<FormRow>> = OnceLock::new();
        ROWS.get_or_init(|| shader_forms(true).expect("the quick run"))
    }

    fn ctx(quick: bool) -> Ctx<'static> {
        Ctx { fits: Path::new("fits"), generated: Path::new("generated"), quick }
    }

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

    #[test]
    fn every_quantity_has_three_forms_sorted_by_cost_with_a_front() {
        let rows = quick();
        let quantities = ["gloss-length", "gloss-combine", "fuzz-q", "fuzz-g", "fuzz-r", "fuzz-ps", "skin-punctual"];
        for q in quantities {
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
            assert_eq!(text.lines().filter(|l| *l == q).count(), 1, "one block for {q}");
        }
        let marked = text.lines().filter(|l| l.trim_start().starts_with('*')).count();
        assert_eq!(marked, rows.iter().filter(|r| r.pareto).count());
    }

    #[test]
    fn table_error_decreases_with_resolution() {
        // Linear or bilinear interpolation of a smooth function: error O(h²) per step h, so a
        // finer table of the same quantity (more bytes, same domain) must do better. Per
        // quantity and storage kind (texture vs const array), tables sorted by size.
        for q in ["gloss-length", "gloss-combine", "fuzz-q", "fuzz-g", "fuzz-r", "fuzz-ps", "skin-punctual"] {
            for kind in ["table", "texture"] {
                let mut t: Vec<&FormRow> = quick().iter().filter(|r| r.quantity == q && r.form.starts_with(kind)).collect();
                t.sort_by_key(|r| r.table_bytes);
                for w in t.windows(2) {
                    assert!(w[1].max_error < w[0].max_error, "{q}: {} ({:e}) is not better than {} ({:e})", w[1].form, w[1].max_error, w[0].form, w[0].max_error);
                }
            }
        }
        let tables = quick().iter().filter(|r| r.table_bytes > 0).map(|r| &r.quantity).collect::<std::collections::BTreeSet<_>>();
        assert_eq!(tables.len(), 7, "every quantity has a table form");
    }

    #[test]
    fn fuzz_q_forms_agree_with_the_committed_file_and_validate() {
        let c = ctx(false);
        let refit = c.spec("fuzz_q").unwrap();
        let mut integral = Integral::of(&refit);
        // The committed spec's own verification grid.
        let reference = integral.reference(pipeline::grid(&refit, &[refit.file.axis[0].verify_count()]));
        let rows = fuzz_q_forms(&c, &refit, &mut integral, &reference).unwrap();
        let get = |f: &str| rows.iter().find(|r| r.form == f).unwrap_or_else(|| panic!("no {f}"));
        // The refit: what `shadefit build` measured on the same grid with the same f32 code;
        // only the integral is recomputed (2·E₃ to the spec's 1e-12), so they agree to that.
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string("generated/json/fuzz_q.json").unwrap()).unwrap();
        let committed = json["verification"]["max_abs_error_f32"].as_f64().unwrap();
        assert!((get("refit").max_error - committed).abs() <= 1e-12, "{} vs {committed}", get("refit").max_error);
        // The published Listing 4 against validate's f64 evaluation of it on the same points
        // (and Q = 2·E₃ in closed form): the emitted f32 code adds the rounding of
        // 1 + d·(c0 + d·c1), a few ulps of 1 (< 1e-6).
        let truth: Vec<f64> = reference.points.iter().map(|p| fuzz::q_exact(p[0])).collect();
        let f64_form: Vec<f64> = reference.points.iter().map(|p| crate::family::fuzz::published::published_q(p[0])).collect();
        let (max, _, _) = validate::measure(&reference.points, &truth, &f64_form);
        assert!((get("published").max_error - max).abs() < 1e-6, "{} vs {max}", get("published").max_error);
        // The linear form, counted by hand from its emitted source: the input clamp (mask,
        // compare, clamp, select: 4 other), then (N[0] + x0·N[1]) / 1: 1 add, 1 mul, 1 div.
        let o = &get("linear").ops;
        assert_eq!((o.add, o.mul, o.div, o.transc, o.tex, o.const_loads, o.other), (1, 1, 1, 0, 0, 0, 4), "{o:?}");
        assert_eq!(get("linear").table_bytes, 0);
        // The 33-entry table: 33 f32 values.
        assert_eq!(get("table 33").table_bytes, 33 * 4);
    }

    #[test]
    fn the_same_rows_at_any_thread_count() {
        // P_s: parallel sampling of the reference and of the cheaper form's two-stage fit.
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let rows = pool.install(|| fuzz_ps(&ctx(true))).unwrap();
            serde_json::to_string(&rows).unwrap()
        };
        assert_eq!(run(1), run(2));
    }

    /// The full run, printed: `cargo test --release --lib bench::forms -- --ignored --nocapture`.
    #[test]
    #[ignore = "full run (about half a minute on two cores): --ignored --nocapture"]
    fn full_table() {
        let t = std::time::Instant::now();
        let rows = shader_forms(false).unwrap();
        println!("{}\nfull run: {:.1} s", render(&rows), t.elapsed().as_secs_f64());
    }
}
