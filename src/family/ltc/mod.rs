//! The ltc family: area lights by linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt
//! 2016). An LTC ([`transform`]) is a clamped cosine reshaped by a matrix, whose integral over a
//! polygon light has a closed form; a table of them per (roughness, view) stands in for a
//! lobe. [`fit`] fits that table for any lobe of the lobe layer by deterministic quadrature
//! of the L1 distance between the normalised lobes, and [`published`] measures ltc_code's
//! shipped GGX tables the same way.

pub mod fit;
pub mod published;
pub mod reference;
pub mod sphere;
pub mod transform;

use super::Family;
use crate::bench::FamilyBench;

/// The ltc family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "ltc",
    feature: "ltc",
    doc: "area lights: linearly transformed cosines fitted to a lobe by quadrature, ltc_code's tables audited",
    quantities: &[],
    spec_kinds: &[],
    eval_options: None,
    validate: published::items,
    figures: |_, _| Ok(vec![]),
    bench: FamilyBench::NONE,
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &[],
};
