//! The sheen family: the Charlie cloth lobe (Estevez & Kulla 2017) with its three visibilities
//! (`shading::charlie`): the exact Smith Λ of the distribution, Estevez–Kulla's fitted Λ curve
//! as glTF's KHR_materials_sheen defines it, and Neubelt–Pettineo/Ashikhmin's V (Filament's
//! cloth, three.js). Its quantities are Λ and the directional albedo E(μ, α) and its average
//! E_avg under each visibility, through the lobe layer's operators; the industry's published
//! sheen curves are measured against them ([`published`]).
//!
//! Roughness: α is the distribution's exponent parameter (D ∝ sin^(1/α)θh); glTF, three.js and
//! Filament take α = r² of a perceptual sheen roughness r (the `roughness` alias).

pub mod published;

use super::Family;
use crate::bench::FamilyBench;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::shading::charlie::{Charlie, LambdaTable, Visibility, lambda_exact};
use crate::shading::hemisphere::{LobeParams, eval_albedo, eval_albedo_avg};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

const ALPHA: ParamSpec = ParamSpec {
    name: "alpha",
    // The exact-Lambda tables meet 1e-13 from 3e-3 (shading::charlie): below it μΛ(μ) needs
    // more than 4096 Chebyshev nodes (D ∝ sin^333 θh there).
    min: 3e-3,
    max: 1.0,
    doc: "Charlie alpha (D ∝ sin^(1/alpha); sheen roughness²)",
    integer: false,
    default: None,
};
const ROUGHNESS: ParamSpec = ParamSpec {
    name: "roughness",
    min: 0.05477225575051661,
    max: 1.0,
    doc: "perceptual sheen roughness (alpha = roughness²)",
    integer: false,
    default: None,
};
const ROUGHNESS_ALIAS: (ParamSpec, usize, fn(f64) -> f64) = (ROUGHNESS, 0, crate::shading::roughness::alpha_from_roughness);
/// Λ grows like 1/μ at grazing: μ = 1e-6 is Λ ~ 1e6.
const MU_LAMBDA: ParamSpec = ParamSpec { name: "n_dot_v", min: 1e-6, max: 1.0, doc: "cosine of the direction", integer: false, default: None };
const N_DOT_V: ParamSpec = ParamSpec { name: "n_dot_v", min: 0.0, max: 1.0, doc: "n·v", integer: false, default: None };
/// Under Estevez–Kulla's curve E grows without bound as n·v → 0 (its Λ(0) = e^L(0) is finite,
/// so G2/(4 μv) ~ 1/(4 μv Λ(0)) ⇒ E ~ 1/μv below μv ≈ 1e-9): the domain starts at 1e-6.
const N_DOT_V_EK: ParamSpec = ParamSpec { name: "n_dot_v", min: 1e-6, max: 1.0, doc: "n·v", integer: false, default: None };

/// The exact Λ of one α, built once per process (a pure function of α: the cache changes no
/// bit of any result). At most [`CACHE_LIMIT`] are kept.
pub fn lambda_table(alpha: f64) -> Arc<LambdaTable> {
    static CACHE: Mutex<BTreeMap<u64, Arc<LambdaTable>>> = Mutex::new(BTreeMap::new());
    if let Some(t) = CACHE.lock().unwrap_or_else(|e| e.into_inner()).get(&alpha.to_bits()) {
        return t.clone();
    }
    let t = Arc::new(LambdaTable::new(alpha));
    let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if cache.len() >= CACHE_LIMIT {
        cache.clear();
    }
    cache.insert(alpha.to_bits(), t.clone());
    t
}

/// Tables of at most 4097 coefficients: 4096 of them are ≤ 128 MiB.
const CACHE_LIMIT: usize = 4096;

/// The lobe with the exact Smith Λ.
pub fn smith(alpha: f64) -> Charlie {
    Charlie::with(alpha, Visibility::Smith(lambda_table(alpha)))
}

struct Smith;
impl LobeParams for Smith {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        smith(p[0])
    }
}

struct EstevezKulla;
impl LobeParams for EstevezKulla {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        Charlie::estevez_kulla(p[0])
    }
}

struct Ashikhmin;
impl LobeParams for Ashikhmin {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        Charlie::new(p[0])
    }
}

fn sheen_lambda(p: &[f64], tol: f64) -> Estimate {
    lambda_exact(p[0], p[1], tol)
}

const fn quantity(name: &'static str, doc: &'static str, params: &'static [ParamSpec], eval: fn(&[f64], f64) -> Estimate) -> QuantityDef {
    QuantityDef { name, doc, params, aliases: &[ROUGHNESS_ALIAS], eval, inverse: None, channels: &[], eval_channels: None, basis: None }
}

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    quantity("sheen-lambda", "exact Smith Lambda(mu) of the Charlie distribution (from its projected area)", &[ALPHA, MU_LAMBDA], sheen_lambda),
    quantity("sheen-albedo", "Charlie E(mu) with height-correlated Smith G2 of the exact Lambda", &[ALPHA, N_DOT_V], eval_albedo::<Smith>),
    quantity("sheen-albedo-ek", "Charlie E(mu) with Estevez-Kulla's Lambda curve (glTF KHR_materials_sheen)", &[ALPHA, N_DOT_V_EK], eval_albedo::<EstevezKulla>),
    quantity("sheen-albedo-ashikhmin", "Charlie E(mu) with V = 1/(4(n·l + n·v - n·l n·v)) (Filament cloth, three.js)", &[ALPHA, N_DOT_V], eval_albedo::<Ashikhmin>),
    quantity("sheen-albedo-avg", "E_avg = 2 int E(mu) mu dmu of sheen-albedo (exact Smith)", &[ALPHA], eval_albedo_avg::<Smith>),
    quantity("sheen-albedo-avg-ek", "E_avg of sheen-albedo-ek (Estevez-Kulla's curve)", &[ALPHA], eval_albedo_avg::<EstevezKulla>),
    quantity("sheen-albedo-avg-ashikhmin", "E_avg of sheen-albedo-ashikhmin", &[ALPHA], eval_albedo_avg::<Ashikhmin>),
];

/// The sheen family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "sheen",
    feature: "sheen",
    doc: "Charlie sheen lobe: exact Smith Lambda, E(mu) and E_avg under three visibilities, published sheen curves audited",
    quantities: QUANTITIES,
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
