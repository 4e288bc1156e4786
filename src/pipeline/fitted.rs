//! The `fit` kind: a spec's rational model fitted (or read back), rounded to f32 and
//! re-optimised, its denominator proven positive, verified and emitted.

use super::*;

/// Whether a build requires every denominator proven positive on the domain (what the
/// pipeline's own fits must be) or only measures constants it did not fit (the published ones,
/// in `bench`): then a denominator not proven positive is built anyway, with the interval
/// bound the proof reached as its lower bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Denominators {
    Proven,
    Unchecked,
}

/// The lower bound of a denominator on `domain`; an error when it must be proven positive and
/// is not.
pub(crate) fn denominator_bound(
    what: impl FnOnce() -> String,
    model: &fit::RationalModel,
    c: &DVector<f64>,
    domain: &[(f64, f64)],
    check: Denominators,
) -> Result<f64, BuildError> {
    match (prove_denominator_positive(model, c, domain), check) {
        (Positivity::Proven { lower, .. }, _) | (Positivity::NotProven { lower, .. }, Denominators::Unchecked) => Ok(lower),
        (Positivity::NotProven { lower, region, .. }, Denominators::Proven) => {
            Err(fit::FitError::PoleInDomain { what: what(), lower, region }.into())
        }
    }
}

/// Fit the spec's model to samples with the spec's objective.
pub fn fit_samples(spec: &Spec, data: &Data) -> Result<fit::Fit, BuildError> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let fit_section = spec.file.fit.as_ref().expect("fit specs carry [fit]");
    let opts = FitOptions { objective: fit_section.objective, max_rms: fit_section.max_rms, ..FitOptions::default() };
    Ok(fit::fit(model, data, &opts, &spec.file.name)?)
}

pub(super) fn build_fit(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let (coefficients, report, f32s) = match mode {
        Mode::Fit => {
            let counts: Vec<usize> = spec.file.axis.iter().map(|a| a.count).collect();
            let x = grid(spec, &counts);
            let y = sample(spec, &x);
            let data = Data { x, y };
            let f = fit_samples(spec, &data)?;
            let f32s = round_to_f32(spec, &f.coefficients, &data)?;
            (f.coefficients, Some(f.report), f32s)
        }
        Mode::Committed => {
            let (c, f32s) = committed_fit(spec, root)?;
            (c, None, f32s)
        }
    };
    fit_from_coefficients(spec, coefficients, report, Some(f32s), &Reference::of_spec(spec), Denominators::Proven)
}

/// The f32 coefficients of the fit `c` of `spec`'s model to `data`: rounded, then re-optimised
/// on those samples with the spec's objective inside the box the emitted code clamps to.
pub(super) fn round_to_f32(spec: &Spec, c: &DVector<f64>, data: &Data) -> Result<F32Coefficients, BuildError> {
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let fit_section = spec.file.fit.as_ref().expect("fit specs carry [fit]");
    let r = f32round::round_and_reoptimise(
        model,
        c,
        data,
        &domain(spec),
        &f32round::RoundOptions::new(fit_section.objective, fit_section.max_rms),
        &spec.file.name,
    )?;
    let on_grid = RoundingOnGrid {
        fitting_samples: data.len(),
        f64: r.f64,
        rounded_f32: r.rounded,
        reoptimised_f32: r.reoptimised,
        sweeps: r.sweeps,
        evaluations: r.evaluations,
    };
    Ok(F32Coefficients { num: r.num, den: r.den, on_grid })
}

/// The committed f64 and f32 coefficients of a fit spec (generated/json/NAME.json under `root`),
/// checked against the spec's hash and model and against each other, with the committed report
/// of the f32 re-optimisation.
pub fn committed_fit(spec: &Spec, root: &Path) -> Result<(DVector<f64>, F32Coefficients), BuildError> {
    let name = &spec.file.name;
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let v = committed_json(root, spec)?;
    let c = f64_array(&v["model"], name, "coefficients")?;
    if c.len() != model.n_full() {
        return Err(BuildError::NoCommitted { spec: name.clone(), why: "coefficient count differs from the spec".into() });
    }
    let c = DVector::from_vec(c);
    let (num, den) = committed_f32(model, &c, &v["model"], name)?;
    let on_grid: RoundingOnGrid = serde_json::from_value(v["f32_rounding"].clone())
        .map_err(|e| BuildError::NoCommitted { spec: name.clone(), why: format!("'f32_rounding' unreadable ({e})") })?;
    Ok((c, F32Coefficients { num, den, on_grid }))
}

/// The f32 coefficients a fit is emitted with, re-optimised on its fitting samples, and what
/// that measured there.
pub struct F32Coefficients {
    num: Vec<f32>,
    den: Vec<f32>,
    on_grid: RoundingOnGrid,
}

/// Verify a fit with the given coefficients against `reference` (in f64 and in the emitted
/// f32 arithmetic) and render its files (see [`Denominators`] for the positivity check). The
/// f32 coefficients are `f32s` (re-optimised, with their report in the JSON) or, without them,
/// the f64 ones rounded to nearest.
pub fn fit_from_coefficients(
    spec: &Spec,
    coefficients: DVector<f64>,
    report: Option<FitReport>,
    f32s: Option<F32Coefficients>,
    reference: &Reference,
    check: Denominators,
) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let model = spec.model.as_ref().expect("fit specs carry a model");
    let objective = spec.file.fit.as_ref().expect("fit specs carry [fit]").objective;
    let dom = domain(spec);
    let lower = denominator_bound(|| name.clone(), model, &coefficients, &dom, check)?;
    let (num, den) = match &f32s {
        Some(f) => (f.num.clone(), f.den.clone()),
        None => expr::f32_arrays(model, &coefficients),
    };
    let f32_rounding = match f32s {
        Some(f) => Some(rounding_report(spec, model, &coefficients, &f, check)?),
        None => None,
    };
    let e = expr::model_expr(model);
    let clamp32 = model.clamp.map(|(a, b)| (a as f32, b as f32));
    let (vx, truth) = (&reference.points, &reference.values);
    let d32 = domain_f32(spec);
    let approx64: Vec<f64> = vx.iter().map(|x| model.eval_clamped(&coefficients, x)).collect();
    let approx32: Vec<f32> = vx
        .iter()
        .map(|x| {
            let xs = expr::features_f32(model, x, &d32);
            let v = expr::eval_f32(&e, &xs, &num, &den);
            match clamp32 {
                Some((lo, hi)) => v.clamp(lo, hi),
                None => v,
            }
        })
        .collect();
    if let Some(i) = approx32.iter().position(|v| !v.is_finite()) {
        return Err(BuildError::NonFinite { spec: name, at: vx[i].clone() });
    }
    let verification = verify(inverse_1d(spec, vx), vx, truth, &approx64, &approx32);
    let hash = input_hash(spec);
    let err_line = verification.header_line();
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let a = args(spec);
    let func = wgsl::Function {
        module: &name,
        name: &spec.file.emit.function,
        args: &a,
        derived: &model.derived,
        domain: &d32,
        body: wgsl::Body::Fit { expr: &e, num: &num, den: &den, clamp: clamp32 },
    };
    let doc = describe_fit(spec, model);
    let labels = model.coefficient_labels();
    let mut json = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": name,
        "kind": "fit",
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function": spec.file.emit.function,
        "axes": axes_json(spec),
        "model": {
            "form": "offset + factor * P / Q, Q = denominator_lead + sum(den)",
            "features": model.features,
            "arguments": a,
            "numerator": model.numerator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator": model.denominator.iter().map(|t| t.label.clone()).collect::<Vec<_>>(),
            "denominator_lead": model.lead.as_ref().map_or("1".to_string(), |t| t.label.clone()),
            "derived": model.derived.iter().map(|d| json!({"name": d.name, "definition": d.describe(&model.features)})).collect::<Vec<_>>(),
            "offset": model.offset,
            "factor": model.factor.as_ref().map(|t| t.label.clone()),
            "clamp": model.clamp.map(|(a, b)| [a, b]),
            "labels": labels,
            "coefficients": coefficients.iter().cloned().collect::<Vec<f64>>(),
            "numerator_f32": num,
            "denominator_f32": den,
            "denominator_lower_bound": lower,
            "objective": objective,
        },
        "verification": verification,
    });
    if let (Some(o), Some(r)) = (json.as_object_mut(), f32_rounding) {
        o.insert("f32_rounding".into(), r);
    }
    with_channel(&mut json, spec);
    let artifacts = vec![
        Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl::render_module(&header, &func).into() },
        Artifact { path: format!("src/{name}.rs").into(), contents: rust::render_module(&header, &func, &doc).into() },
        Artifact { path: format!("json/{name}.json").into(), contents: json_text(&json).into() },
    ];
    Ok(Built { name, artifacts, verification, fit: report })
}

/// The `f32_rounding` object of a fit's JSON: the measurements on the fitting samples, the
/// moves from the rounded coefficients and the denominator bound of the f32 coefficients.
pub(super) fn rounding_report(
    spec: &Spec,
    model: &fit::RationalModel,
    coefficients: &DVector<f64>,
    f: &F32Coefficients,
    check: Denominators,
) -> Result<Value, BuildError> {
    let name = &spec.file.name;
    let lower32 =
        denominator_bound(|| format!("{name} (f32 coefficients)"), model, &f32round::widen(&f.num, &f.den), &domain(spec), check)?;
    let (num0, den0) = f32round::rounded(model, coefficients);
    let moves: Vec<i64> =
        num0.iter().chain(&den0).zip(f.num.iter().chain(&f.den)).map(|(&a, &b)| f32round::ulps_between(a, b)).collect();
    let mut r = serde_json::to_value(&f.on_grid).expect("the rounding report serialises");
    let extra = json!({
        "objective": spec.file.fit.as_ref().expect("fit specs carry [fit]").objective,
        "max_ulps_allowed": f32round::MAX_ULPS,
        "moves_ulps": moves,
        "coefficients_moved": moves.iter().filter(|m| **m != 0).count(),
        "max_move_ulps": moves.iter().map(|m| m.unsigned_abs()).max().unwrap_or(0),
        "denominator_lower_bound": lower32,
    });
    if let (Some(o), Value::Object(x)) = (r.as_object_mut(), extra) {
        o.extend(x);
    }
    Ok(r)
}

/// What rounding to f32 did on the fitting samples (part of `f32_rounding` in the JSON): measured
/// by `build`, carried over from the committed JSON by `build --check` (which does not sample the
/// fitting grid); the rest of `f32_rounding` follows from the coefficients and is recomputed.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct RoundingOnGrid {
    fitting_samples: usize,
    /// The f64 fit, the coefficients rounded to nearest f32, and the re-optimised f32 ones
    /// (f32 arithmetic, emitted order).
    f64: f32round::Errors,
    rounded_f32: f32round::Errors,
    reoptimised_f32: f32round::Errors,
    sweeps: usize,
    evaluations: usize,
}


/// The committed f32 arrays: f32 values, as many as the model's terms, fixed coefficients as
/// rounded, every one within [`f32round::MAX_ULPS`] of the rounded f64 coefficient.
pub(super) fn committed_f32(model: &fit::RationalModel, c: &DVector<f64>, m: &Value, spec: &str) -> Result<(Vec<f32>, Vec<f32>), BuildError> {
    let bad = |why: String| BuildError::F32Coefficients { spec: spec.into(), why };
    let (num0, den0) = f32round::rounded(model, c);
    let labels = model.coefficient_labels();
    let read = |key: &str, want: usize, first: usize| -> Result<Vec<f32>, BuildError> {
        let v = f64_array(m, spec, key)?;
        if v.len() != want {
            return Err(bad(format!("'{key}' has {} values, the model {want}", v.len())));
        }
        v.iter()
            .enumerate()
            .map(|(j, &x)| {
                if (x as f32) as f64 == x {
                    Ok(x as f32)
                } else {
                    Err(bad(format!("{} = {x:e} in '{key}' is not an f32", labels[first + j])))
                }
            })
            .collect()
    };
    let num = read("numerator_f32", num0.len(), 0)?;
    let den = read("denominator_f32", den0.len(), num0.len())?;
    for (i, (&a, &b)) in num0.iter().chain(&den0).zip(num.iter().chain(&den)).enumerate() {
        let d = f32round::ulps_between(a, b);
        if d.unsigned_abs() > f32round::MAX_ULPS as u64 {
            return Err(bad(format!(
                "{} = {b:e} is {d} ulps from the rounded coefficient {a:e} (at most {} allowed)",
                labels[i],
                f32round::MAX_ULPS
            )));
        }
        if d != 0 && model.fixed.iter().any(|f| f.0 == i) {
            return Err(bad(format!("{} is fixed but {b:e} differs from its rounded value {a:e}", labels[i])));
        }
    }
    Ok((num, den))
}

pub(super) fn describe_fit(spec: &Spec, model: &fit::RationalModel) -> String {
    let num: Vec<String> = model.numerator.iter().map(|t| format!("({t})")).collect();
    let den: Vec<String> = model.denominator.iter().map(|t| format!("({t})")).collect();
    format!(
        "{}: `{}` ≈ {} of quantity `{}`, P = NUM · [{}], Q = {} + DEN · [{}].",
        spec.file.description,
        spec.file.emit.function,
        {
            let mut f = "P/Q".to_string();
            if let Some(t) = &model.factor {
                f = format!("({t})·{f}");
            }
            if model.offset != 0.0 {
                f = format!("{} + {f}", model.offset);
            }
            if model.clamp.is_some() { format!("clamp({f})") } else { f }
        },
        spec.quantity_label(),
        num.join(", "),
        model.lead.as_ref().map_or("1".to_string(), |t| format!("({t})")),
        den.join(", ")
    )
}
