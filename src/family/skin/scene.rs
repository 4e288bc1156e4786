//! The skin family's scene feature.
//!
//! `skin`: the `skin_punctual_lut` and `skin_sh_lut` nodes (no parameters; the LUTs' profile
//! and kernels are their specs').

use crate::scene::{Feature, MaterialSpec, Reach};

/// The family's scene features.
pub const FEATURES: &[Feature] = &[Feature { name: "skin", params: &[], reach }];

fn reach(_: &MaterialSpec) -> Reach {
    Reach { nodes: vec!["skin_punctual_lut", "skin_sh_lut"], special: vec![] }
}
