//! Published tables and approximations, measured against the project's integrals.
//!
//! Each item gives its domain, the points measured, max abs and rms error, the worst point and
//! findings: what the numbers say about the published constants (noise, typos, conventions).

use crate::pipeline::committed::Refit;
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

pub use crate::pipeline::measure;

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
    /// refit is not committed, or was written for another version of its spec).
    pub fn add_refit(&mut self, generated: &Path, name: &str, catalog: &Catalog, points: &[Vec<f64>], truth: &[f64]) -> Option<Vec<f64>> {
        let refit = Refit::load(generated, name, catalog).ok()?;
        let approx: Vec<f64> = points.iter().map(|x| refit.eval(x)).collect();
        let (m, r, _) = measure(points, truth, &approx);
        let objective = refit.spec.file.fit.as_ref().map_or("?".to_string(), |f| format!("{:?}", f.objective).to_lowercase());
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

/// Every item of the given validators (one per family, in registry order).
pub fn all(generated: &Path, validators: &[fn(&Path) -> Vec<Item>]) -> Vec<Item> {
    validators.iter().flat_map(|v| v(generated)).collect()
}
