//! The skin family (pre-integrated subsurface scattering): diffusion profiles, the punctual
//! ring integral and the SH band factors, and the `skin-lut` spec kind that builds them into
//! textures and lookups.

pub mod bench;
pub mod build;
pub mod emit;
pub mod integrals;
pub mod plot;
pub mod profile;
pub mod scene;
pub mod spec;

use crate::spec::Preset;
use super::Family;
use super::{EvalOptions, OptionEval, SpecKind};
use crate::spec::KindDef;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};

fn skin_channels(r: Result<[Estimate; 3], integrals::ProfileError>) -> Vec<Estimate> {
    // The default profile is valid and the arguments are inside the domain, so the only
    // error left would be a bug: report it as NaN with infinite error rather than panic.
    r.map(|e| e.to_vec()).unwrap_or_else(|_| vec![Estimate { value: f64::NAN, error: f64::INFINITY, evals: 0 }; 3])
}

fn skin_tolerance(tol: f64) -> crate::integrate::Tolerance {
    crate::integrate::Tolerance { abs: tol.min(integrals::DEFAULT_TOLERANCE.abs), ..integrals::DEFAULT_TOLERANCE }
}

fn skin_punctual_rgb(p: &[f64], tol: f64) -> Vec<Estimate> {
    let profile = integrals::default_skin_profile();
    skin_channels(integrals::punctual(&profile, integrals::Kernel::Linear, p[0], p[1], skin_tolerance(tol)))
}

fn skin_punctual(p: &[f64], tol: f64) -> Estimate {
    skin_punctual_rgb(p, tol)[0]
}

fn skin_sh_rgb(p: &[f64], tol: f64) -> Vec<Estimate> {
    let profile = integrals::default_skin_profile();
    skin_channels(integrals::sh_band(&profile, p[0], p[1] as u32, skin_tolerance(tol)))
}

fn skin_sh(p: &[f64], tol: f64) -> Estimate {
    skin_sh_rgb(p, tol)[0]
}

const CURVATURE: ParamSpec =
    ParamSpec { name: "curvature", min: 0.0, max: 100.0, doc: "curvature (1/mm)", integer: false, limit: None, default: None };

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "skin-punctual",
        doc: "pre-integrated skin diffusion for a punctual light (linear profile on a ring), RGB",
        params: &[CURVATURE, ParamSpec { name: "n_dot_l", min: -1.0, max: 1.0, doc: "n·l", integer: false, limit: None, default: None }],
        aliases: &[],
        eval: &skin_punctual,
        inverse: None,
        channels: &["red", "green", "blue"],
        basis: None,
        eval_channels: Some(&skin_punctual_rgb),
    },
    QuantityDef {
        name: "skin-sh",
        doc: "per-band factor scaling clamped-cosine SH irradiance by skin scattering (sphere), RGB",
        params: &[CURVATURE, ParamSpec { name: "band", min: 0.0, max: 2.0, doc: "SH band l", integer: true, limit: None, default: None }],
        aliases: &[],
        eval: &skin_sh,
        inverse: None,
        channels: &["red", "green", "blue"],
        basis: None,
        eval_channels: Some(&skin_sh_rgb),
    },
];

/// The `skin-lut` spec kind: checked and spelled out by [`spec`], built by [`build`].
static SKIN_LUT: SpecKind = SpecKind {
    spec: KindDef {
        name: spec::KIND,
        spec_file: crate::spec::preset_spec_file::<spec::SkinLut>,
        samples_note: "{name} is a skin LUT: its samples are its texels, \"values\" in generated/json/{name}.json (RGB, with the axes)",
        input_hash: |s| match spec::SkinLut::from_spec(s) {
            Ok(lut) => build::input_hash(s, &lut),
            // An unreadable profile: the hash of the text alone, which then differs from the
            // recorded one and reports the spec stale.
            Err(_) => crate::pipeline::input_hash(s),
        },
    },
    build: build::build,
    shard: None,
};

/// `eval skin-punctual|skin-sh --profile FILE --kernel linear|radial`: a diffusion profile of
/// your own (a TOML file with a `[profile]` section, or a CSV radial profile) and/or the ring
/// kernel.
fn eval_with_options(q: &QuantityDef, p: &[f64], o: &EvalOptions) -> Result<OptionEval, String> {
    use integrals::Kernel;
    let punctual = q.name == "skin-punctual";
    let kernel = match (punctual, o.kernel) {
        (_, None) | (true, Some("linear")) => Kernel::Linear,
        (true, Some("radial")) => Kernel::Radial,
        (true, Some(other)) => return Err(format!("--kernel '{other}': expected linear or radial")),
        (false, Some(_)) => {
            return Err("--kernel applies to skin-punctual (skin-sh integrates the radial profile over the sphere)".into());
        }
    };
    let loaded = match o.profile {
        Some(path) => profile::load_profile_file(path).map_err(|e| e.to_string())?,
        None => profile::LoadedProfile::deon_luebke(),
    };
    let tol = crate::integrate::Tolerance { abs: 1e-12, ..integrals::DEFAULT_TOLERANCE };
    let est = if punctual {
        integrals::punctual(&loaded.profile, kernel, p[0], p[1], tol)
    } else {
        integrals::sh_band(&loaded.profile, p[0], p[1] as u32, tol)
    };
    let where_ = o.profile.map_or("the default profile".to_string(), |p| p.display().to_string());
    let est = est.map_err(|e| format!("{where_}: {e}"))?;
    let kernel_name = if kernel == Kernel::Linear { "linear" } else { "radial" };
    let mut extra = serde_json::Map::new();
    extra.insert("profile".into(), loaded.provenance());
    extra.insert("kernel".into(), (if punctual { kernel_name } else { "radial (sphere)" }).into());
    Ok(OptionEval {
        values: est.iter().map(|e| e.value).collect(),
        error: est.iter().map(|e| e.error).fold(0.0, f64::max),
        extra,
        note: format!("profile: {where_}"),
    })
}

/// The skin family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "skin",
    feature: "skin",
    doc: "pre-integrated skin scattering: punctual and SH LUTs from a diffusion profile",
    quantities: QUANTITIES,
    spec_kinds: std::slice::from_ref(&SKIN_LUT),
    eval_options: Some((&["skin-punctual", "skin-sh"], eval_with_options)),
    validate: |_| Vec::new(),
    figures: plot::skin_figures,
    bench: bench::BENCH,
    scene_features: scene::FEATURES,
    commands: &[],
    axis_mappings: &[],
    forms: &[],
};
