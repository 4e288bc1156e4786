//! The fuzz family (Ghost of Tsushima anisotropic asperity scattering, supplemental
//! Appendices A–H): the integrals P_s, G, Q, R of the single-scattering fuzz layer, and the
//! published Listings 1–5 measured against them.

pub mod bench;
pub mod integrals;
pub mod plot;
pub mod published;
pub mod scene;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{InnerBasis, ParamSpec, QuantityDef};

fn fuzz_ps(p: &[f64], tol: f64) -> Estimate {
    integrals::ps(p[0], p[1], p[2], p[3], tol)
}

/// Eq. 1 of the Ghost of Tsushima supplemental: P̃_s = c0 + c1 (u·n) + c2 (u·t) + c3 (u·n)² +
/// c4 (u·n)(u·t) + c5 (u·t)², over the light direction (θu, φu) at fixed (α, θf).
static FUZZ_PS_EQ1: InnerBasis = InnerBasis {
    inner: 2,
    args: &["n_dot_u", "t_dot_u"],
    arg_domain: &[(-1.0, 1.0), (-1.0, 1.0)],
    terms: &["1", "n_dot_u", "t_dot_u", "n_dot_u^2", "n_dot_u*t_dot_u", "t_dot_u^2"],
    to_args: fuzz_ps_args,
    sample: fuzz_ps_sample,
    range: (0.0, 1.0),
};

fn fuzz_ps_args(outer: &[f64], inner: &[f64]) -> Vec<f64> {
    let (st, ct) = outer[1].sin_cos();
    let (su, cu) = inner[0].sin_cos();
    vec![cu, su * inner[1].cos() * st + cu * ct]
}

fn fuzz_ps_sample(outer: &[f64], inner: &[Vec<f64>], tol: f64) -> Vec<Estimate> {
    let dirs: Vec<(f64, f64)> = inner.iter().map(|d| (d[0], d[1])).collect();
    integrals::ps_directions(outer[0], outer[1], &dirs, tol)
}

fn fuzz_g(p: &[f64], tol: f64) -> Estimate {
    // Canonical order (mu_v, d), the emitted function's (n_dot_v, density).
    let (mu_v, d) = (p[0], p[1]);
    if d < f64::MIN_POSITIVE || mu_v < f64::MIN_POSITIVE {
        // Zero and subnormal arguments: the limits, through the integrator's own handling.
        return integrals::g(d, mu_v, tol);
    }
    // The closed form in E₁, E₂: rounding ≲ 1e-15·(1 + |ln d|) (checked against the adaptive
    // quadrature `g` in the unit tests and the integrators bench); 8× that as the estimate.
    Estimate { value: integrals::g_exact(d, mu_v), error: 8e-15 * (1.0 + d.ln().abs()), evals: 1 }
}

fn fuzz_q(p: &[f64], _tol: f64) -> Estimate {
    // 2·E₃(d) from the series / continued fraction: a few ulps (tested against quadrature).
    Estimate { value: integrals::q_exact(p[0]), error: 8.0 * f64::EPSILON, evals: 1 }
}

fn fuzz_r(p: &[f64], tol: f64) -> Estimate {
    integrals::r(p[0], p[1], tol)
}

const HALF_PI: f64 = std::f64::consts::FRAC_PI_2;
const ALPHA: ParamSpec = ParamSpec { name: "alpha", min: 0.01, max: 1.0, doc: "SGGX fiber alpha", integer: false, limit: None, default: None };
const THETA_F: ParamSpec = ParamSpec { name: "theta_f", min: 0.0, max: HALF_PI, doc: "fiber polar angle (rad)", integer: false, limit: None, default: None };
const DENSITY: ParamSpec = ParamSpec { name: "d", min: 0.0, max: 50.0, doc: "fuzz density (optical thickness)", integer: false, limit: None, default: None };

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "fuzz-ps",
        doc: "fraction of light the fuzz layer scatters toward the base layer, P_s(u)",
        params: &[
            ALPHA,
            THETA_F,
            ParamSpec { name: "theta_u", min: 0.0, max: std::f64::consts::PI, doc: "light polar angle (rad)", integer: false, limit: None, default: None },
            ParamSpec {
                name: "phi_u",
                min: -std::f64::consts::PI,
                max: 2.0 * std::f64::consts::PI,
                doc: "light azimuth from the fiber azimuth (rad)",
                integer: false,
                limit: None,
                default: None,
            },
        ],
        aliases: &[],
        eval: &fuzz_ps,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: Some(&FUZZ_PS_EQ1),
    },
    QuantityDef {
        name: "fuzz-g",
        doc: "hemispherical average G(d, mu_v) of the single-scattering fuzz layer",
        params: &[ParamSpec { name: "mu_v", min: 0.0, max: 1.0, doc: "n·v", integer: false, limit: None, default: None }, DENSITY],
        aliases: &[],
        eval: &fuzz_g,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fuzz-q",
        doc: "cosine-weighted average penetration Q(d) = 2 E3(d)",
        params: &[DENSITY],
        aliases: &[],
        eval: &fuzz_q,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fuzz-r",
        doc: "cosine-weighted average of P_s over the hemisphere, R(alpha, theta_f)",
        params: &[ALPHA, THETA_F],
        aliases: &[],
        eval: &fuzz_r,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// The fuzz family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "fuzz",
    feature: "fuzz",
    doc: "Ghost of Tsushima asperity scattering: P_s, G, Q, R and Listings 1–5",
    quantities: QUANTITIES,
    spec_kinds: &[],
    eval_options: None,
    validate: published::items,
    figures: plot::fuzz_figures,
    bench: bench::BENCH,
    scene_features: scene::FEATURES,
    commands: &[],
    axis_mappings: &[],
    forms: &[],
};
