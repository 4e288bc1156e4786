//! The gloss family (Call of Duty: WWII, "Mipmapping normal and gloss", "Rational function
//! fitting", "Combining gloss"): gloss ↔ GGX average normal length, its inverse, the
//! gloss-combine table, and the published constants measured against them.

pub mod bench;
pub mod integrals;
pub mod plot;
pub mod published;
pub mod scene;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};

fn gloss_length(p: &[f64], _tol: f64) -> Estimate {
    // Closed form (see gloss.rs); its error is rounding only: ≤ 4 ulps of a value ≤ 1.
    Estimate { value: integrals::length_from_gloss(p[0]), error: 4.0 * f64::EPSILON, evals: 1 }
}

fn gloss_from_length(p: &[f64], _tol: f64) -> Estimate {
    // Illinois regula falsi to one ulp of g (see integrals.rs); the inverse amplifies L's rounding by 1/(dL/dg) ≤ 1e5.
    Estimate { value: integrals::gloss_from_length(p[0]), error: 1e5 * 4.0 * f64::EPSILON, evals: 64 }
}

fn gloss_combine(p: &[f64], _tol: f64) -> Estimate {
    Estimate { value: integrals::combine(p[0], p[1]), error: 1e5 * 8.0 * f64::EPSILON, evals: 130 }
}

const GLOSS: ParamSpec = ParamSpec { name: "gloss", min: 0.0, max: 1.0, doc: "gloss g", integer: false, limit: None, default: None };

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "gloss-length",
        doc: "GGX average (shortened) normal length for a gloss, or for a GGX alpha",
        params: &[GLOSS],
        aliases: &[(
            // α at gloss 1 is sqrt(2/262145) = 0.00276213059566896…; the bound sits just below it
            // and the converted gloss is clamped to 1.
            ParamSpec { name: "alpha", min: 0.0027621305956689, max: 1.0, doc: "GGX alpha", integer: false, limit: None, default: None },
            0,
            integrals::gloss_from_alpha,
        )],
        eval: &gloss_length,
        inverse: Some(integrals::gloss_from_length),
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "gloss-from-length",
        doc: "gloss whose GGX average normal length is `length` (clamped to the table ends)",
        params: &[ParamSpec { name: "length", min: 0.0, max: 1.0, doc: "normal length", integer: false, limit: None, default: None }],
        aliases: &[],
        eval: &gloss_from_length,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "gloss-combine",
        doc: "gloss of two combined glosses (Reoriented Normal Mapping of their NDFs)",
        params: &[
            ParamSpec { name: "x", min: 0.0, max: 1.0, doc: "first gloss", integer: false, limit: None, default: None },
            ParamSpec { name: "y", min: 0.0, max: 1.0, doc: "second gloss", integer: false, limit: None, default: None },
        ],
        aliases: &[],
        eval: &gloss_combine,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// Table axes over WWII gloss g whose parameter is GGX α = sqrt(2/(1 + 2^(18g)))
/// (`mapping = "gloss"` on a table axis, e.g. the rows of a split-sum table).
pub static GLOSS_MAPPING: crate::spec::AxisMapping = crate::spec::AxisMapping {
    name: "gloss",
    doc: "gloss g, parameter alpha = sqrt(2/(1 + 2^(18 g)))",
    to_parameter: crate::shading::roughness::alpha_from_gloss,
    argument: [0.0, 1.0],
};

/// The gloss family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "gloss",
    feature: "gloss",
    doc: "COD: WWII gloss ↔ GGX average normal length, its inverse and the gloss-combine table",
    quantities: QUANTITIES,
    spec_kinds: &[],
    eval_options: None,
    validate: published::items,
    figures: plot::gloss_figures,
    bench: bench::BENCH,
    scene_features: scene::FEATURES,
    commands: &[],
    axis_mappings: &[&GLOSS_MAPPING],
    forms: &[],
};

#[cfg(test)]
mod tests {
    use super::*;

    /// The mapping the catalog serves as `gloss` is WWII's: α = √(2/2) = 1 at gloss 0 and
    /// √(2/(1 + 2^18)) at gloss 1, for arguments in [0, 1].
    #[test]
    fn the_gloss_axis_mapping_is_wwii_alpha() {
        let m = crate::family::catalog().mapping("gloss").expect("registered");
        assert!(std::ptr::eq(m, &GLOSS_MAPPING));
        assert_eq!((m.to_parameter)(0.0), 1.0);
        // The same expression evaluated in another order: a few ulps of 2.8e-3.
        assert!(((m.to_parameter)(1.0) - (2.0 / (1.0 + 2f64.powi(18))).sqrt()).abs() < 1e-17);
        assert_eq!(m.argument, [0.0, 1.0]);
    }
}
