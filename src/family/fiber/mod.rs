//! The fiber family (Ghost of Tsushima, "Anisotropic Fuzz | Phase Function"): the
//! normalisation N(k, u·t) of the Schlick phase function taken at sin∠(t, h), the factor
//! W = (1 − k²)/N that normalises it in a shader, and the course's conservative r(k) measured
//! against them.

pub mod bench;
pub mod integrals;
pub mod plot;
pub mod published;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};

fn fiber_phase_norm(p: &[f64], tol: f64) -> Estimate {
    integrals::norm(p[0], p[1], tol)
}

fn fiber_phase_scale(p: &[f64], tol: f64) -> Estimate {
    integrals::scale(p[0], p[1], tol)
}

/// The course's spread parameter: k = −0.99 (1 − spread).
pub fn k_from_spread(spread: f64) -> f64 {
    -0.99 * (1.0 - spread)
}

const K: ParamSpec = ParamSpec { name: "k", min: -0.99, max: 0.0, doc: "Schlick asymmetry k = -0.99 (1 - spread)", integer: false, limit: None, default: None };
const U_DOT_T: ParamSpec = ParamSpec { name: "u_dot_t", min: -1.0, max: 1.0, doc: "cosine of light and fiber", integer: false, limit: None, default: None };
const SPREAD: ParamSpec = ParamSpec { name: "spread", min: 0.0, max: 1.0, doc: "the course's spread", integer: false, limit: None, default: None };

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "fiber-phase-norm",
        doc: "integral N over all views of the Schlick fiber phase function (r = 1/N)",
        params: &[K, U_DOT_T],
        aliases: &[(SPREAD, 0, k_from_spread)],
        eval: &fiber_phase_norm,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fiber-phase-scale",
        doc: "W = (1 - k^2)/N: p_V = W / (4 pi (1 - k x)^2) integrates to 1",
        params: &[K, U_DOT_T],
        aliases: &[(SPREAD, 0, k_from_spread)],
        eval: &fiber_phase_scale,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// The fiber family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "fiber",
    feature: "fiber",
    doc: "Ghost of Tsushima Schlick fiber phase function: its normalisation and the conservative r(k)",
    quantities: QUANTITIES,
    spec_kinds: &[],
    eval_options: None,
    validate: published::items,
    figures: plot::fiber_figures,
    bench: bench::BENCH,
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &[],
};
