use crate::plot::PlotError;
use std::path::{Path, PathBuf};
pub fn fiber_figures(_out: &Path, _generated: &Path) -> Result<Vec<PathBuf>, PlotError> { Ok(vec![]) }
