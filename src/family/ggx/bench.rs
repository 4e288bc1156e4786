//! The family's benchmark rows.

use super::{lut, published};
use crate::bench::integrals::IntegratorBench;
use crate::bench::FamilyBench;

/// Integrator ladders.
pub static INTEGRATORS: &[IntegratorBench] = &[];

pub static BENCH: FamilyBench =
    FamilyBench { integrators: INTEGRATORS, fits: published::FITS, tables: lut::TABLES, forms: published::FORMS };
