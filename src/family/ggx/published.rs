//! The industry's published approximations of the split-sum integrals, measured against them.

use crate::bench::fits::FitBench;
use crate::bench::forms::FormSet;
use crate::plot::PlotError;
use crate::validate::Item;
use std::path::{Path, PathBuf};

/// Published forms measured against the integrals (the committed refits beside them).
pub fn items(_generated: &Path) -> Vec<Item> {
    Vec::new()
}

/// Fit specs timed with every solver (the bench's fits section).
pub static FITS: &[FitBench] = &[];

/// Shader forms per quantity (the bench's forms section).
pub static FORMS: &[FormSet] = &[];

/// Error maps of the published forms.
pub fn figures(_out: &Path, _generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    Ok(Vec::new())
}
