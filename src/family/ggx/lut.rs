//! The DFG lookup table: its spec kind (`kind = "ggx-dfg-lut"`, [`spec`]), build ([`build`]),
//! emitted files ([`emit`]), figures ([`plot`]) and benchmark row.

pub mod build;
pub mod emit;
pub mod plot;
pub mod spec;

use crate::bench::tables::{Ladder, Params, Shape, TableBench};
use crate::family::SpecKind;
use crate::plot::PlotError;
use crate::spec::KindDef;
use std::path::{Path, PathBuf};

/// The `ggx-dfg-lut` spec kind: checked and spelled out by [`spec`], built by [`build`].
static DFG_LUT: SpecKind = SpecKind {
    spec: KindDef {
        name: spec::KIND,
        spec_file: spec::spec_file,
        samples_note: "{name} is a DFG LUT: its samples are its texels, \"values\" ([scale, bias]) in generated/json/{name}.json",
        input_hash: crate::pipeline::input_hash,
    },
    build: build::build,
};

/// Spec kinds of the family (the DFG LUT).
pub static KINDS: &[SpecKind] = std::slice::from_ref(&DFG_LUT);

/// Table benchmark rows: the default DFG LUT against numpy (Filament's Hammersley estimator,
/// Gauss–Legendre in the sampling variables).
pub static TABLES: &[TableBench] = &[TableBench {
    spec: "ggx_dfg_lut",
    order: 9,
    samples: (16, 64),
    ladder: Ladder::Tolerances(&[1e-6, 1e-8], &[1e-5, 1e-6, 1e-7, 1e-8, 1e-10]),
    reference_tolerance: 1e-12,
    // (alpha, n_dot_v, cos_cone = 0) → (scale, bias); the script takes (n_dot_v, alpha).
    shape: Shape { params: Params::Pick(&[(1, "n_dot_v"), (0, "alpha")]), channels: 2, fold_last_axis: false },
}];

/// Figures of the LUTs into `out` from the committed outputs in `generated`.
pub fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    plot::figures(out, generated)
}
