//! The msdiffuse family (Call of Duty: WWII, "Multiscattering Diffuse BRDF"): light walking
//! between Lambertian microfacets of a GGX microsurface (Heitz et al. 2016's random walk), Fresnel
//! (F0 = 0.04) taking the specular share away; its BRDF and directional albedo by Monte Carlo with
//! standard errors, and the talk's published approximations measured against them.

pub mod bench;
pub mod integrals;
pub mod merl;
pub mod plot;
pub mod published;
pub mod refit;
pub mod table;
pub mod walk;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use integrals::{Order, at_cosine, brdf, cell_of, directions, eval_paths, specular_of, surface};
use std::f64::consts::{FRAC_PI_2, PI};

/// The RNG key of `eval` points (tables key theirs by their spec name).
fn eval_key(quantity: &str) -> u64 {
    walk::key_of(quantity)
}

/// π f/ρ at ρ = 1 (Lambert = 1) at (gloss, θh, θd, φd, F0, specular_walks).
fn ms_diffuse(p: &[f64], tol: f64) -> Estimate {
    let s = surface(p[0], p[4], specular_of(p[5]));
    match directions(p[1], p[2], p[3]) {
        Some((l, v)) => brdf(&s, l, v, Order::All, eval_key("ms-diffuse"), cell_of(p), eval_paths(tol), true),
        None => Estimate::exact(0.0),
    }
}

/// π f/ρ at ρ = 1 at (α, n·h, l·h, φd, F0, specular_walks): the slice quantity in the cosines
/// and GGX α a shader has (θh = acos n·h, θd = acos l·h), the input of the family's fits.
fn ms_diffuse_cosines(p: &[f64], tol: f64) -> Estimate {
    let s = walk::Surface { alpha: p[0], rho: 1.0, f0: p[4], specular: specular_of(p[5]) };
    match directions(p[1].clamp(-1.0, 1.0).acos(), p[2].clamp(-1.0, 1.0).acos(), p[3]) {
        Some((l, v)) => brdf(&s, l, v, Order::All, eval_key("ms-diffuse-cosines"), cell_of(p), eval_paths(tol), true),
        None => Estimate::exact(0.0),
    }
}

/// The directional albedo at (gloss, n·v, F0, specular_walks).
fn ms_diffuse_albedo(p: &[f64], tol: f64) -> Estimate {
    let s = surface(p[0], p[2], specular_of(p[3]));
    integrals::albedo(&s, at_cosine(p[1]), eval_key("ms-diffuse-albedo"), cell_of(p), eval_paths(tol), true)
}

const fn p(name: &'static str, min: f64, max: f64, doc: &'static str, default: Option<f64>) -> ParamSpec {
    ParamSpec { name, min, max, doc, integer: false, limit: None, default }
}

const GLOSS: ParamSpec = p("gloss", 0.0, 1.0, "WWII gloss (alpha = sqrt(2/(1 + 2^(18 gloss))))", None);
const F0: ParamSpec = p("f0", 0.0, 1.0, "Schlick F0 of the facets (0: no Fresnel; the talk's 0.04 by default)", Some(integrals::TALK_F0));
const WALKS: ParamSpec = ParamSpec {
    name: "specular_walks",
    min: 0.0,
    max: 1.0,
    doc: "0: the specular share is gone (the talk); 1: it continues the walk",
    integer: true,
    limit: None,
    default: Some(0.0),
};

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "ms-diffuse",
        doc: "multiple-scattering Lambertian-microfacet BRDF times pi/rho (Lambert = 1), Monte Carlo (error = standard error)",
        params: &[
            GLOSS,
            p("theta_h", 0.0, FRAC_PI_2, "half vector's polar angle", None),
            p("theta_d", 0.0, FRAC_PI_2, "light's angle to the half vector", None),
            p("phi_d", 0.0, PI, "difference azimuth (pi/2: BRDF Explorer's slice)", Some(FRAC_PI_2)),
            F0,
            WALKS,
        ],
        aliases: &[],
        eval: &ms_diffuse,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ms-diffuse-cosines",
        doc: "ms-diffuse in a shader's inputs: GGX alpha (not gloss), n.h and l.h; Monte Carlo (error = standard error)",
        params: &[
            p("alpha", 1e-4, 1.0, "GGX alpha (the WWII gloss g maps to sqrt(2/(1 + 2^(18 g))))", None),
            p("n_dot_h", 0.0, 1.0, "cosine of the half vector's polar angle", None),
            p("l_dot_h", 0.0, 1.0, "cosine of the light's angle to the half vector", None),
            p("phi_d", 0.0, PI, "difference azimuth (pi/2: BRDF Explorer's slice)", Some(FRAC_PI_2)),
            F0,
            WALKS,
        ],
        aliases: &[],
        eval: &ms_diffuse_cosines,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ms-diffuse-albedo",
        doc: "directional albedo of the multiple-scattering diffuse BRDF at rho = 1, Monte Carlo (error = standard error)",
        params: &[GLOSS, p("n_dot_v", 0.01, 1.0, "cosine of the view", None), F0, WALKS],
        aliases: &[],
        eval: &ms_diffuse_albedo,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// The msdiffuse family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "msdiffuse",
    feature: "ms",
    doc: "Call of Duty: WWII multiple-scattering diffuse BRDF: Lambertian microfacets on GGX, Heitz 2016's walk",
    quantities: QUANTITIES,
    spec_kinds: &[table::TABLE],
    eval_options: None,
    validate: published::items,
    figures: plot::figures,
    bench: bench::BENCH,
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &refit::FORMS,
};
