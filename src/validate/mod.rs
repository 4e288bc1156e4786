//! Published tables and approximations, measured against the project's integrals.
//!
//! Each item gives its domain, the points measured, max abs and rms error, the worst point and
//! findings: what the numbers say about the published constants (noise, typos, conventions).

use crate::spec::Catalog;
use serde::Serialize;
use std::path::Path;

#[derive(Debug, Clone, Serialize)]
pub struct Item {
    pub name: String,
    pub source: String,
    pub domain: String,
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    pub worst_point: Vec<f64>,
    /// Extra measures (e.g. error in parameter units), name → value.
    pub extra: Vec<(String, f64)>,
    pub findings: Vec<String>,
}

/// Max abs, rms and worst point of `approx − truth` over `points`.
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

impl Item {
    /// An item measured from `approx − truth` over `points`, with no extras or findings yet.
    pub fn measured(name: &str, source: &str, domain: &str, points: &[Vec<f64>], truth: &[f64], approx: &[f64]) -> Item {
        let (max_abs_error, rms_error, worst_point) = measure(points, truth, approx);
        Item {
            name: name.into(),
            source: source.into(),
            domain: domain.into(),
            points: points.len(),
            max_abs_error,
            rms_error,
            worst_point,
            extra: vec![],
            findings: vec![],
        }
    }

    /// Measure the committed refit `generated/json/NAME.json` on the same points, through the
    /// model of its spec, and add it side by side. Returns the refit's values (None when the
    /// refit is not committed).
    pub fn add_refit(&mut self, generated: &Path, name: &str, catalog: &Catalog, points: &[Vec<f64>], truth: &[f64]) -> Option<Vec<f64>> {
        let (spec, c) = committed_refit(generated, name, catalog)?;
        let model = spec.model.as_ref()?;
        let approx: Vec<f64> = points.iter().map(|x| model.eval_clamped(&c, x)).collect();
        let (m, r, _) = measure(points, truth, &approx);
        let objective = spec.file.fit.as_ref().map_or("?".to_string(), |f| format!("{:?}", f.objective).to_lowercase());
        self.extra.push(("refit_max_abs_error".into(), m));
        self.extra.push(("refit_rms_error".into(), r));
        self.findings.push(format!(
            "shadefit's refit (fits/{name}.toml, same form, {objective}): max {m:.3e} ({:.2}× the published), rms {r:.3e} ({:.2}×).",
            m / self.max_abs_error,
            r / self.rms_error
        ));
        Some(approx)
    }
}

/// The committed refit NAME: its spec (read from the path its JSON names) and coefficients.
pub fn committed_refit(generated: &Path, name: &str, catalog: &Catalog) -> Option<(crate::spec::Spec, nalgebra::DVector<f64>)> {
    let text = std::fs::read_to_string(generated.join("json").join(format!("{name}.json"))).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    let c: Vec<f64> =
        v["model"]["coefficients"].as_array()?.iter().map(serde_json::Value::as_f64).collect::<Option<_>>()?;
    let spec = crate::spec::Spec::load(&generated.parent()?.join(v["spec"].as_str()?), catalog).ok()?;
    (spec.model.as_ref()?.n_full() == c.len()).then(|| (spec, nalgebra::DVector::from_vec(c)))
}

/// The committed two-stage refit NAME (`kind = "fields"`): the coefficient function
/// outer point → c_k evaluated in f64 through its spec's model and offsets.
pub fn committed_fields(generated: &Path, name: &str, catalog: &Catalog) -> Option<Box<dyn Fn(&[f64]) -> Vec<f64> + Send + Sync>> {
    let text = std::fs::read_to_string(generated.join("json").join(format!("{name}.json"))).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    let spec = crate::spec::Spec::load(&generated.parent()?.join(v["spec"].as_str()?), catalog).ok()?;
    let model = spec.model.clone()?;
    let mut fields = Vec::new();
    for f in v["fields"].as_array()? {
        let c: Vec<f64> = f["coefficients"].as_array()?.iter().map(serde_json::Value::as_f64).collect::<Option<_>>()?;
        if c.len() != model.n_full() {
            return None;
        }
        let mut m = model.clone();
        m.offset = f["offset"].as_f64()?;
        fields.push((m, nalgebra::DVector::from_vec(c)));
    }
    Some(Box::new(move |x: &[f64]| fields.iter().map(|(m, c)| m.eval_full(c, x)).collect()))
}

/// Every item of the given validators (one per family, in registry order).
pub fn all(generated: &Path, validators: &[fn(&Path) -> Vec<Item>]) -> Vec<Item> {
    validators.iter().flat_map(|v| v(generated)).collect()
}
