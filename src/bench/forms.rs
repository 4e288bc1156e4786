//! Shader cost against error: several approximation forms per quantity.

use serde::Serialize;

/// One approximation form of one quantity: its shader cost and its measured error.
#[derive(Debug, Clone, Serialize)]
pub struct FormRow {
    pub quantity: String,
    pub form: String,
    pub ops: super::ops::OpCounts,
    pub max_error: f64,
    pub rms_error: f64,
    pub points: usize,
    pub note: String,
}

/// Every form of every quantity (`quick`: a cheaper verification grid).
pub fn shader_forms(_quick: bool) -> anyhow::Result<Vec<FormRow>> {
    anyhow::bail!("shader forms are not measured yet")
}

/// The forms as a table.
pub fn render(_rows: &[FormRow]) -> String {
    String::new()
}
