//! Published tables and approximations, measured against the project's integrals.
//!
//! Each item gives its domain, the points measured, max abs and rms error, the worst point and
//! findings: what the numbers say about the published constants (noise, typos, conventions).

pub mod fuzz;
pub mod gloss;

use serde::Serialize;

#[derive(Debug, Clone, Serialize)]
pub struct Item {
    pub name: String,
    pub source: String,
    pub domain: String,
    pub points: usize,
    pub max_abs_error: f64,
    pub rms_error: f64,
    pub worst_point: Vec<f64>,
    /// Extra measures (e.g. error in gloss units), name → value.
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

/// Every item known to the project.
pub fn all(generated: &std::path::Path) -> Vec<Item> {
    let mut items = gloss::items(generated);
    items.extend(fuzz::items(generated));
    items
}
