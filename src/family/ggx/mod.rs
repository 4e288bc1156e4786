//! The GGX split-sum family: the environment BRDF ("DFG") scale and bias, with a visibility
//! cone; the directional albedo E(μ) and its average E_avg; the Fresnel averages; and the
//! industry's published approximations of them measured against the integrals. Conventions
//! (microfacet model, α = roughness², height-correlated Smith G2, Schlick Fc) are in
//! [`integrals`].

pub mod bench;
pub mod compensation;
pub mod integrals;
pub mod lut;
pub mod occlusion;
pub mod published;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::plot::PlotError;
use crate::validate::Item;
use crate::shading::hemisphere::{eval_albedo, eval_albedo_avg, eval_split_sum, eval_split_sum_scale, LobeParams};
use crate::shading::trowbridge_reitz::{Ggx, Shadowing};
use std::path::{Path, PathBuf};

const ALPHA: ParamSpec = ParamSpec {
    name: "alpha",
    // The first row of a 128² LUT at texel centres is α = (1/256)² ≈ 1.5e-5; the integrators
    // are tested down to 1e-6 (integrals.rs).
    min: 1e-6,
    max: 1.0,
    doc: "GGX alpha (perceptual roughness²)",
    integer: false,
    limit: None,
    default: None,
};
/// [`ALPHA`] reaching α = 0, where the split sum is its mirror limit (scale = 1 − (1 − μ)⁵,
/// bias = (1 − μ)⁵, `shading::hemisphere::split_sum`).
const ALPHA_OR_MIRROR: ParamSpec = ParamSpec { limit: Some(0.0), ..ALPHA };
const ROUGHNESS: ParamSpec = ParamSpec {
    name: "roughness",
    min: 1e-3,
    max: 1.0,
    doc: "perceptual roughness (alpha = roughness²)",
    integer: false,
    limit: None,
    default: None,
};
const N_DOT_V: ParamSpec = ParamSpec { name: "n_dot_v", min: 0.0, max: 1.0, doc: "n·v", integer: false, limit: None, default: None };
const COS_CONE: ParamSpec = ParamSpec {
    name: "cos_cone",
    min: 0.0,
    max: 1.0,
    doc: "cosine of the visibility cone's half-angle (0: the hemisphere)",
    integer: false,
    limit: None,
    default: Some(0.0),
};

const N_DOT_L: ParamSpec = ParamSpec { name: "n_dot_l", min: 0.0, max: 1.0, doc: "n·l", integer: false, limit: None, default: None };
const F0: ParamSpec = ParamSpec { name: "f0", min: 0.0, max: 1.0, doc: "Schlick reflectance at normal incidence (1: F = 1)", integer: false, limit: None, default: None };
const SCHEME: ParamSpec = ParamSpec {
    name: "scheme",
    min: 0.0,
    max: 5.0,
    doc: "compensation scheme: 0 single, 1 Kulla-Conty, 2 Turquin, 3 Fdez-Aguera, 4 Cycles, 5 bevy<=0.18",
    integer: true,
    limit: None,
    default: None,
};

const ROUGHNESS_ALIAS: (ParamSpec, usize, fn(f64) -> f64) = (ROUGHNESS, 0, crate::shading::roughness::alpha_from_roughness);
/// [`ROUGHNESS_ALIAS`] reaching r = 0 (α = 0, the mirror limit of [`ALPHA_OR_MIRROR`]).
const ROUGHNESS_OR_MIRROR_ALIAS: (ParamSpec, usize, fn(f64) -> f64) =
    (ParamSpec { limit: Some(0.0), ..ROUGHNESS }, 0, crate::shading::roughness::alpha_from_roughness);

/// The GGX lobe of the quantities: α = p[0], height-correlated Smith G2.
struct HeightCorrelated;

impl LobeParams for HeightCorrelated {
    type Lobe = Ggx;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Ggx {
        Ggx::new(p[0], Shadowing::HeightCorrelated)
    }
}

/// UE4's image-based-lighting lobe: α = p[0], separable Schlick–Smith with k = α/2.
struct Ue4;

impl LobeParams for Ue4 {
    type Lobe = Ggx;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Ggx {
        Ggx::new(p[0], Shadowing::Separable { k: 0.5 * p[0] })
    }
}

fn fresnel_avg_schlick(p: &[f64], _tol: f64) -> Estimate {
    // Closed form; two roundings of a value ≤ 1.
    Estimate { value: integrals::f_avg_schlick(p[0]), error: 4.0 * f64::EPSILON, evals: 0 }
}

fn fresnel_avg_dielectric(p: &[f64], tol: f64) -> Estimate {
    integrals::f_avg_dielectric(p[0], tol)
}

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "ggx-env",
        doc: "split-sum environment BRDF [scale, bias] (F = F0·scale + bias), lights in a cone",
        params: &[ALPHA_OR_MIRROR, N_DOT_V, COS_CONE],
        aliases: &[ROUGHNESS_OR_MIRROR_ALIAS],
        eval: &eval_split_sum_scale::<HeightCorrelated>,
        inverse: None,
        channels: &["scale", "bias"],
        eval_channels: Some(&eval_split_sum::<HeightCorrelated>),
        basis: None,
    },
    QuantityDef {
        name: "ggx-env-ue4",
        doc: "[scale, bias] with UE4's separable Schlick-Smith G (k = alpha/2), hemisphere",
        params: &[ALPHA_OR_MIRROR, N_DOT_V],
        aliases: &[ROUGHNESS_OR_MIRROR_ALIAS],
        eval: &eval_split_sum_scale::<Ue4>,
        inverse: None,
        channels: &["scale", "bias"],
        eval_channels: Some(&eval_split_sum::<Ue4>),
        basis: None,
    },
    QuantityDef {
        name: "ggx-albedo",
        doc: "directional albedo E(mu) of single-scattering GGX (F = 1)",
        params: &[ALPHA, N_DOT_V],
        aliases: &[ROUGHNESS_ALIAS],
        eval: &eval_albedo::<HeightCorrelated>,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ggx-albedo-avg",
        doc: "cosine-weighted average albedo E_avg = 2 int E(mu) mu dmu",
        params: &[ALPHA],
        aliases: &[ROUGHNESS_ALIAS],
        eval: &eval_albedo_avg::<HeightCorrelated>,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fresnel-avg-schlick",
        doc: "cosine-weighted Schlick Fresnel average F0 + (1 - F0)/21 (closed form)",
        params: &[ParamSpec { name: "f0", min: 0.0, max: 1.0, doc: "reflectance at normal incidence", integer: false, limit: None, default: None }],
        aliases: &[],
        eval: &fresnel_avg_schlick,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fresnel-avg-dielectric",
        doc: "cosine-weighted dielectric Fresnel average for relative index eta (numerical)",
        params: &[ParamSpec { name: "eta", min: 0.1, max: 10.0, doc: "relative index of refraction", integer: false, limit: None, default: None }],
        aliases: &[],
        eval: &fresnel_avg_dielectric,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ggx-kc-fms",
        doc: "Kulla-Conty multiple-scattering lobe (1-E(mu_o))(1-E(mu_i))/(pi(1-E_avg)), F = 1",
        params: &[ALPHA, N_DOT_V, N_DOT_L],
        aliases: &[ROUGHNESS_ALIAS],
        eval: &compensation::eval_kc_fms,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ggx-furnace",
        doc: "white-furnace albedo of a compensation scheme (0 single, 1 Kulla-Conty, 2 Turquin, 3 Fdez-Aguera, 4 Cycles, 5 bevy<=0.18)",
        params: &[ALPHA, N_DOT_V, F0, SCHEME],
        aliases: &[ROUGHNESS_ALIAS],
        eval: &compensation::eval_furnace,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

fn items(generated: &Path) -> Vec<Item> {
    let mut items = published::items(generated);
    items.extend(compensation::items(generated));
    items.extend(occlusion::items(generated));
    items
}

fn figures(out: &Path, generated: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut files = lut::figures(out, generated)?;
    files.extend(occlusion::lut::plot::figures(out, generated)?);
    files.extend(occlusion::plot::figures(out, generated)?);
    files.extend(published::figures(out, generated)?);
    files.extend(compensation::figures(out, generated)?);
    Ok(files)
}

/// The GGX split-sum family's descriptor (registered in `crate::family::FAMILIES`).
/// The family's published forms offered for refitting: the split sum's and the Fresnel
/// average's, then specular occlusion's.
static GGX_FORMS: [crate::fit::published::PublishedForm; 8] = {
    let [a, b, c, d, e] = published::refit::FORMS_DEF;
    let [f, g, h] = occlusion::refit::FORMS_DEF;
    [a, b, c, d, e, f, g, h]
};

pub static FAMILY: Family = Family {
    name: "ggx",
    feature: "ggx",
    doc: "GGX split-sum: DFG scale/bias (with a visibility cone), E(mu), E_avg, Fresnel averages, energy compensation",
    quantities: QUANTITIES,
    spec_kinds: &[lut::DFG_LUT, occlusion::emit::OCCLUSION, occlusion::lut::CONE_LUT],
    eval_options: None,
    validate: items,
    figures,
    bench: bench::BENCH,
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &GGX_FORMS,
};
