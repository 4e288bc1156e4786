//! Multiple-scattering energy compensation built from E(μ) and E_avg, and the white-furnace
//! validator of each scheme.

use crate::plot::PlotError;
use crate::validate::Item;
use std::path::{Path, PathBuf};

/// The furnace validator's findings.
pub fn items(_generated: &Path) -> Vec<Item> {
    Vec::new()
}

/// Furnace maps and E(μ) curves.
pub fn figures(_out: &Path, _generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    Ok(Vec::new())
}
