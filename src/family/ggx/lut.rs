//! The DFG lookup table: its spec kind, build, emitted files and figures.

use crate::bench::tables::TableBench;
use crate::family::SpecKind;
use crate::plot::PlotError;
use std::path::{Path, PathBuf};

/// Spec kinds of the family (the DFG LUT).
pub static KINDS: &[SpecKind] = &[];

/// Table benchmark rows.
pub static TABLES: &[TableBench] = &[];

/// Figures of the LUT into `out` from the committed outputs in `generated`.
pub fn figures(_out: &Path, _generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    Ok(Vec::new())
}
