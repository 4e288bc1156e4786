//! Build of a two-stage fit (`kind = "fields"`): sample the quantity on the outer grid × the
//! inner grid, fit the coefficient fields jointly (`fit::fields`), prove every denominator
//! positive on the outer domain, verify on the verification grids in f64 and in the emitted
//! f32 arithmetic, emit WGSL, Rust and JSON.
//!
//! **f32 coefficients.** The emitted arrays are the f64 coefficients rounded to nearest f32; they
//! are not re-optimised in f32 as `kind = "fit"` coefficients are (`fit::f32round`). The JSON's
//! `f32_rounding` reports, on the fitting samples, the errors of the f64 fields and of the f32
//! code (`reoptimised: false`); committed mode carries it over. Why not: one evaluation of the
//! f64 and f32 errors on the fitting samples (fuzz_ps: 627 264) takes ~0.3 s on two cores, and a
//! coordinate sweep over 6 × 27 coefficients with 14 candidate moves each needs ~2 300 f32
//! evaluations: minutes a sweep (estimated ~15 s even if only the moved field and then the basis
//! sums were re-evaluated), against a budget of a few seconds. Nor is there much to gain: rounding
//! changes the committed fit's max error on those samples by ~5e-6 of its 0.115 (downward, as
//! it happens): the error is the form's, not the coefficients'.

use super::{committed_json, input_hash, json_text, spec_rel_path, tensor, BuildError, Built, Denominators, Mode, Verification};
use crate::fit::expr::{self, model_expr};
use crate::emit::fields::{self as efields, Field, FieldsFunction};
use crate::emit::{header_lines, Artifact, GENERATOR};
use crate::fit::fields::{fit_fields, FieldOptions, PointData};
use crate::fit::model::Term;
use crate::fit::f32round::Errors;
use crate::fit::{Objective, RationalModel};
use crate::quantity::InnerBasis;
use crate::spec::{AxisSpec, Spec};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde_json::{json, Value};

struct Layout<'a> {
    basis: &'static InnerBasis,
    outer: &'a [AxisSpec],
    inner: &'a [AxisSpec],
    terms: Vec<Term>,
    models: Vec<RationalModel>,
}

fn layout(spec: &Spec) -> Layout<'_> {
    let basis = spec.quantity.basis.expect("fields specs are checked to have a basis");
    let n_outer = spec.file.axis.len() - basis.inner;
    let args: Vec<String> = basis.args.iter().map(|s| s.to_string()).collect();
    let terms = basis.terms.iter().map(|t| Term::parse(t, &args).expect("basis terms are valid monomials")).collect();
    let model = spec.model.as_ref().expect("fields specs carry a model");
    let offsets = &spec.file.fields.as_ref().expect("fields specs carry [fields]").offsets;
    let models = offsets
        .iter()
        .map(|&o| {
            let mut m = model.clone();
            m.offset = o;
            m
        })
        .collect();
    Layout { basis, outer: &spec.file.axis[..n_outer], inner: &spec.file.axis[n_outer..], terms, models }
}

/// Samples of the quantity at every outer point (rows: inner points, in order).
fn sample(spec: &Spec, l: &Layout<'_>, outer: &[Vec<f64>], inner: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let tol = spec.file.tolerance;
    outer.par_iter().map(|o| (l.basis.sample)(o, inner, tol).into_iter().map(|e| e.value).collect()).collect()
}

fn design(l: &Layout<'_>, o: &[f64], inner: &[Vec<f64>]) -> DMatrix<f64> {
    let mut b = DMatrix::zeros(inner.len(), l.terms.len());
    for (i, u) in inner.iter().enumerate() {
        let a = (l.basis.to_args)(o, u);
        for (k, t) in l.terms.iter().enumerate() {
            b[(i, k)] = t.eval(&a);
        }
    }
    b
}

/// The quantity on a verification grid: outer points × inner points, one row of values per
/// outer point.
#[derive(Debug, Clone)]
pub struct FieldsReference {
    pub outer: Vec<Vec<f64>>,
    pub inner: Vec<Vec<f64>>,
    pub rows: Vec<Vec<f64>>,
}

impl FieldsReference {
    /// The quantity at every outer point × every inner point (rows in parallel, in order).
    pub fn sample(spec: &Spec, outer: Vec<Vec<f64>>, inner: Vec<Vec<f64>>) -> FieldsReference {
        let rows = sample(spec, &layout(spec), &outer, &inner);
        FieldsReference { outer, inner, rows }
    }

    /// The spec's verification grids (`verify` points per axis).
    pub fn of_spec(spec: &Spec) -> FieldsReference {
        let l = layout(spec);
        let (outer, inner) = (tensor(l.outer, &verify_counts(l.outer)), tensor(l.inner, &verify_counts(l.inner)));
        FieldsReference::sample(spec, outer, inner)
    }
}

fn verify_counts(axes: &[AxisSpec]) -> Vec<usize> {
    axes.iter().map(|a| a.verify_count()).collect()
}

/// The fitting samples: outer and inner grids, and the samples at each outer point.
pub struct FittingGrid {
    outer: Vec<Vec<f64>>,
    inner: Vec<Vec<f64>>,
    data: Vec<PointData>,
}

/// Errors on the fitting samples of the f64 fields and of the emitted f32 code (the f64
/// coefficients rounded to nearest f32), by the fit's objective. Outer points in parallel,
/// residuals collected in grid order and summed sequentially.
fn fitting_errors(
    l: &Layout<'_>,
    coefficients: &[DVector<f64>],
    func: &FieldsFunction<'_>,
    g: &FittingGrid,
    objective: Objective,
) -> (Errors, Errors) {
    let (lo, hi) = l.basis.range;
    let rows: Vec<(Vec<f64>, Vec<f64>)> = g
        .outer
        .par_iter()
        .zip(&g.data)
        .map(|(o, d)| {
            let c64: Vec<f64> = l.models.iter().zip(coefficients).map(|(m, c)| m.eval_full(c, o)).collect();
            let feats = expr::features_f32(&l.models[0], o, func.domain);
            let c32 = efields::coefficients_f32(func, &feats);
            let mut r64 = Vec::with_capacity(g.inner.len());
            let mut r32 = Vec::with_capacity(g.inner.len());
            for (u, &y) in g.inner.iter().zip(d.y.iter()) {
                let a = (l.basis.to_args)(o, u);
                let v64: f64 = l.terms.iter().zip(&c64).map(|(tm, c)| c * tm.eval(&a)).sum::<f64>().clamp(lo, hi);
                let a_32: Vec<f32> = a.iter().map(|&v| v as f32).collect();
                r64.push(v64 - y);
                r32.push(efields::evaluator_f32(func, &c32, &a_32) as f64 - y);
            }
            (r64, r32)
        })
        .collect();
    (
        Errors::of(rows.iter().flat_map(|r| r.0.iter().copied()), objective),
        Errors::of(rows.iter().flat_map(|r| r.1.iter().copied()), objective),
    )
}

/// The two-stage fit of a fields spec on its sampling grids: the coefficients of every field
/// and the fit's report (JSON, as the generated file records it).
pub fn fit(spec: &Spec) -> Result<(Vec<DVector<f64>>, Value), BuildError> {
    fit_on_grid(spec).map(|(c, r, _)| (c, r))
}

/// [`fit`], also returning the fitting samples.
fn fit_on_grid(spec: &Spec) -> Result<(Vec<DVector<f64>>, Value, FittingGrid), BuildError> {
    let name = &spec.file.name;
    let l = layout(spec);
    let fit_section = spec.file.fit.as_ref().expect("fields specs carry [fit]");
    let counts = |axes: &[AxisSpec]| -> Vec<usize> { axes.iter().map(|a| a.count).collect() };
    let outer = tensor(l.outer, &counts(l.outer));
    let inner = tensor(l.inner, &counts(l.inner));
    let y = sample(spec, &l, &outer, &inner);
    let data: Vec<PointData> = outer
        .iter()
        .zip(y)
        .map(|(o, y)| PointData { design: design(&l, o, &inner), y: DVector::from_vec(y) })
        .collect();
    let opts = FieldOptions { objective: fit_section.objective, max_rms: fit_section.max_rms, ..FieldOptions::default() };
    let f = fit_fields(&l.models, &outer, &data, &opts, name)?;
    let mut conds: Vec<f64> = f.stage1.iter().map(|s| s.condition).collect();
    conds.sort_by(f64::total_cmp);
    // Above 1e8 the stage-1 optimum is not determined by data accurate to 1e-9 (θf ≈ 0).
    let finite: Vec<f64> = conds.iter().copied().filter(|c| *c <= 1e8).collect();
    let report = json!({
        "grid_points": outer.len(),
        "inner_samples": inner.len(),
        "objective": fit_section.objective,
        "max_rms": fit_section.max_rms,
        "max_abs_error": f.max_abs_error,
        "rms_error": f.rms_error,
        "stage1_max_abs_error": f.stage1_max_abs_error,
        "stage1_rms_error": f.stage1_rms_error,
        "stage1_condition": {
            "min": finite.first(),
            "median": finite.get(finite.len() / 2),
            "max_up_to_1e8": finite.last(),
            "points_above_1e8": conds.len() - finite.len(),
            "max": conds.last(),
        },
        "lm_evaluations": f.lm_evaluations,
        "outer_iterations": f.outer_iterations,
    });
    Ok((f.coefficients, report, FittingGrid { outer, inner, data }))
}

/// The committed coefficients of every field (generated/json/NAME.json under `root`, checked
/// against the spec's hash and model) and the committed JSON they were read from.
pub fn committed(spec: &Spec, root: &std::path::Path) -> Result<(Vec<DVector<f64>>, Value), BuildError> {
    let name = spec.file.name.clone();
    let l = layout(spec);
    let v = committed_json(root, spec)?;
    let fields = v["fields"].as_array().ok_or_else(|| BuildError::NoCommitted { spec: name.clone(), why: "no 'fields' array".into() })?;
    if fields.len() != l.models.len() {
        return Err(BuildError::NoCommitted { spec: name, why: "field count differs from the spec".into() });
    }
    let mut c = Vec::new();
    for (fv, m) in fields.iter().zip(&l.models) {
        let v = super::f64_array(fv, &name, "coefficients")?;
        if v.len() != m.n_full() {
            return Err(BuildError::NoCommitted { spec: name, why: "coefficient count differs from the spec".into() });
        }
        c.push(DVector::from_vec(v));
    }
    Ok((c, v))
}

pub fn build(spec: &Spec, mode: Mode, root: &std::path::Path) -> Result<Built, BuildError> {
    // Fit mode keeps the fitting samples for the f32 rounding report; committed mode carries that
    // report over from the committed JSON (it does not sample the fitting grid). The verification
    // grid is sampled beside the fit (independent work: idle threads of the fit's sequential
    // steps take it up).
    let (fitted, reference) = match mode {
        Mode::Fit => {
            let (f, r) = rayon::join(|| fit_on_grid(spec), || FieldsReference::of_spec(spec));
            let (c, report, g) = f?;
            ((c, Some(report), Rounding::Measure(g)), r)
        }
        Mode::Committed => {
            let (c, v) = committed(spec, root)?;
            ((c, v.get("fit").cloned(), Rounding::Committed(v["f32_rounding"].clone())), FieldsReference::of_spec(spec))
        }
    };
    let (coefficients, report, rounding) = fitted;
    fields_from_coefficients(spec, &coefficients, report, Some(rounding), &reference, Denominators::Proven)
}

/// The `f32_rounding` report of a fields build: measured on the fitting samples, or committed.
pub enum Rounding {
    Measure(FittingGrid),
    Committed(Value),
}

/// Verify fields with the given coefficients against `reference` (in f64 and in the emitted
/// f32 arithmetic) and render their files (see [`Denominators`] for the positivity check of
/// every field on the outer domain).
pub fn fields_from_coefficients(
    spec: &Spec,
    coefficients: &[DVector<f64>],
    report: Option<Value>,
    rounding: Option<Rounding>,
    reference: &FieldsReference,
    check: Denominators,
) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let l = layout(spec);
    let dom: Vec<(f64, f64)> = l.outer.iter().map(|a| (a.range[0], a.range[1])).collect();
    let mut lower = Vec::new();
    for (k, (m, c)) in l.models.iter().zip(coefficients).enumerate() {
        lower.push(super::denominator_bound(|| format!("{name} (field {k})"), m, c, &dom, check)?);
    }
    // Emitted form.
    let fields: Vec<Field> = l
        .models
        .iter()
        .zip(coefficients)
        .map(|(m, c)| {
            let (num, den) = expr::f32_arrays(m, c);
            Field { expr: model_expr(m), num, den }
        })
        .collect();
    let d32: Vec<(f32, f32)> = dom.iter().map(|&(a, b)| (a as f32, b as f32)).collect();
    let args: Vec<String> = spec.file.emit.args.clone().unwrap_or_else(|| l.outer.iter().map(|a| a.name.clone()).collect());
    let eval_args: Vec<String> = l.basis.args.iter().map(|s| s.to_string()).collect();
    let eval_domain: Vec<(f32, f32)> = l.basis.arg_domain.iter().map(|&(a, b)| (a as f32, b as f32)).collect();
    let evaluator = spec.file.emit.evaluator.clone().expect("fields specs name an evaluator");
    let func = FieldsFunction {
        module: &name,
        name: &spec.file.emit.function,
        args: &args,
        derived: &l.models[0].derived,
        domain: &d32,
        fields: &fields,
        evaluator: &evaluator,
        eval_args: &eval_args,
        eval_domain: &eval_domain,
        terms: &l.terms,
        range: (l.basis.range.0 as f32, l.basis.range.1 as f32),
    };
    let f32_rounding = rounding.map(|r| match r {
        Rounding::Measure(g) => {
            let objective = spec.file.fit.as_ref().expect("fields specs carry [fit]").objective;
            let (e64, e32) = fitting_errors(&l, coefficients, &func, &g, objective);
            json!({
                "fitting_samples": g.outer.len() * g.inner.len(),
                "objective": objective,
                "f64": e64,
                "rounded_f32": e32,
                "reoptimised": false,
            })
        }
        Rounding::Committed(v) => v,
    });
    // Verification on the reference grids, in f64 and in the emitted f32 arithmetic.
    let (vouter, vinner, truth) = (&reference.outer, &reference.inner, &reference.rows);
    let (lo, hi) = l.basis.range;
    let mut pts = Vec::new();
    let (mut t, mut a64, mut a32) = (Vec::new(), Vec::new(), Vec::new());
    for (o, row) in vouter.iter().zip(truth) {
        let c64: Vec<f64> = l.models.iter().zip(coefficients).map(|(m, c)| m.eval_full(c, o)).collect();
        let feats = expr::features_f32(&l.models[0], o, &d32);
        let c32 = efields::coefficients_f32(&func, &feats);
        for (u, &y) in vinner.iter().zip(row) {
            let a = (l.basis.to_args)(o, u);
            let v64: f64 = l.terms.iter().zip(&c64).map(|(tm, c)| c * tm.eval(&a)).sum::<f64>().clamp(lo, hi);
            let a_32: Vec<f32> = a.iter().map(|&v| v as f32).collect();
            let v32 = efields::evaluator_f32(&func, &c32, &a_32);
            if !v32.is_finite() {
                return Err(BuildError::NonFinite { spec: name, at: o.iter().chain(u).copied().collect() });
            }
            pts.push(o.iter().chain(u).copied().collect::<Vec<f64>>());
            t.push(y);
            a64.push(v64);
            a32.push(v32);
        }
    }
    let verification: Verification = super::verify(super::inverse_1d(spec, &pts), &pts, &t, &a64, &a32);
    let hash = input_hash(spec);
    let err_line = verification.header_line();
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let m0 = &l.models[0];
    let terms_text: Vec<String> = l.basis.terms.iter().map(|s| s.to_string()).collect();
    let doc = format!(
        "{}: `{}` returns c_k = s_k + {}·P_k/Q_k over ({}) with P_k = NUM{{k}} · [{}], Q_k = 1 + DEN{{k}} · [{}]; \
         `{}` evaluates Σ c_k·[{}].",
        spec.file.description,
        spec.file.emit.function,
        m0.factor.as_ref().map_or("1".to_string(), |t| t.label.clone()),
        args.join(", "),
        m0.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>().join(", "),
        m0.denominator.iter().map(|t| t.label.clone()).collect::<Vec<_>>().join(", "),
        evaluator,
        terms_text.join(", "),
    );
    let c64: Vec<(Vec<f64>, Vec<f64>)> = coefficients
        .iter()
        .map(|c| {
            let nn = m0.numerator.len();
            (c.rows(0, nn).iter().copied().collect(), c.rows(nn, c.len() - nn).iter().copied().collect())
        })
        .collect();
    let mut json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "fields",
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function": spec.file.emit.function,
        "evaluator": evaluator,
        "axes": super::axes_json(spec),
        "basis": { "arguments": eval_args, "terms": terms_text, "range": [lo, hi] },
        "model": {
            "form": "c_k = offset_k + factor * P_k / Q_k, Q_k = 1 + sum(den_k)",
            "features": m0.features,
            "arguments": args,
            "numerator": m0.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator": m0.denominator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "derived": m0.derived.iter().map(|d| json!({"name": d.name, "definition": d.describe(&m0.features)})).collect::<Vec<_>>(),
            "factor": m0.factor.as_ref().map(|t| t.label.clone()),
        },
        "fields": l.models.iter().zip(coefficients).zip(&fields).zip(&lower).map(|(((m, c), fl), lo)| json!({
            "offset": m.offset,
            "coefficients": c.iter().copied().collect::<Vec<f64>>(),
            "numerator_f32": fl.num,
            "denominator_f32": fl.den,
            "denominator_lower_bound": lo,
        })).collect::<Vec<_>>(),
        "fit": report,
        "verification": verification,
    });
    if let (Some(o), Some(r)) = (json.as_object_mut(), f32_rounding) {
        o.insert("f32_rounding".into(), r);
    }
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: efields::render_wgsl(&header, &func).into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: efields::render_rust(&header, &func, &doc, &c64).into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json_text(&json).into() },
    ];
    Ok(Built { name, artifacts, verification, fit: None })
}
