//! The sheen family: the Charlie cloth lobe (Estevez & Kulla 2017) with its three visibilities
//! (`shading::charlie`): the exact Smith Λ of the distribution, Estevez–Kulla's fitted Λ curve
//! as glTF's KHR_materials_sheen defines it, and Neubelt–Pettineo/Ashikhmin's V (Filament's
//! cloth, three.js). Its quantities are Λ and the directional albedo E(μ, α) and its average
//! E_avg under each visibility, through the lobe layer's operators; the industry's published
//! sheen curves are measured against them ([`published`]).
//!
//! Roughness: α is the distribution's exponent parameter (D ∝ sin^(1/α)θh); glTF, three.js and
//! Filament take α = r² of a perceptual sheen roughness r (the `roughness` alias).

pub mod bench;
pub mod forms;
pub mod grid;
pub mod lut;
pub mod plot;
pub mod published;
pub mod refit;
pub mod velvet;
pub mod viewer;

use super::Family;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::shading::charlie::{Charlie, LambdaTable, Visibility, lambda_exact};
use crate::shading::hemisphere::{LobeParams, eval_albedo, eval_albedo_avg};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

pub(crate) const ALPHA: ParamSpec = ParamSpec {
    name: "alpha",
    // The exact-Lambda tables meet 1e-13 from 3e-3 (shading::charlie): below it μΛ(μ) needs
    // more than 4096 Chebyshev nodes (D ∝ sin^333 θh there).
    min: 3e-3,
    max: 1.0,
    doc: "Charlie alpha (D ∝ sin^(1/alpha); sheen roughness²)",
    integer: false,
    limit: None,
    default: None,
};
/// α of the lobes without the exact Λ (Ashikhmin's V, Estevez–Kulla's curve): their albedo
/// integrals converge from 1e-6 (D ∝ sin^1000000 θh; `the_albedo_converges_at_the_least_alpha`),
/// which reaches the first texel centre of a 255-row grid in α = r² (3.8e-6).
pub(crate) const ALPHA_WIDE: ParamSpec = ParamSpec { min: 1e-6, ..ALPHA };
const fn roughness_of(min: f64) -> (ParamSpec, usize, fn(f64) -> f64) {
    let r = ParamSpec { name: "roughness", min, max: 1.0, doc: "perceptual sheen roughness (alpha = roughness²)", integer: false, limit: None, default: None };
    (r, 0, crate::shading::roughness::alpha_from_roughness)
}
/// √(3e-3) and √(1e-6): the roughness of the least α.
const ROUGHNESS_ALIAS: (ParamSpec, usize, fn(f64) -> f64) = roughness_of(0.05477225575051661);
const ROUGHNESS_ALIAS_WIDE: (ParamSpec, usize, fn(f64) -> f64) = roughness_of(0.001);
/// Λ grows like 1/μ at grazing: μ = 1e-6 is Λ ~ 1e6.
const MU_LAMBDA: ParamSpec = ParamSpec { name: "n_dot_v", min: 1e-6, max: 1.0, doc: "cosine of the direction", integer: false, limit: None, default: None };
const N_DOT_V: ParamSpec = ParamSpec { name: "n_dot_v", min: 0.0, max: 1.0, doc: "n·v", integer: false, limit: None, default: None };
/// Under Estevez–Kulla's curve E grows without bound as n·v → 0 (its Λ(0) = e^L(0) is finite,
/// so G2/(4 μv) ~ 1/(4 μv Λ(0)) ⇒ E ~ 1/μv below μv ≈ 1e-9): the domain starts at 1e-6.
const N_DOT_V_EK: ParamSpec = ParamSpec { name: "n_dot_v", min: 1e-6, max: 1.0, doc: "n·v", integer: false, limit: None, default: None };

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

pub(crate) struct Smith;
impl LobeParams for Smith {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        smith(p[0])
    }
}

pub(crate) struct EstevezKulla;
impl LobeParams for EstevezKulla {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        Charlie::estevez_kulla(p[0])
    }
}

pub(crate) struct Ashikhmin;
impl LobeParams for Ashikhmin {
    type Lobe = Charlie;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Charlie {
        Charlie::new(p[0])
    }
}

pub(crate) struct VelvetLobe;
impl LobeParams for VelvetLobe {
    type Lobe = velvet::Velvet;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> velvet::Velvet {
        velvet::Velvet::new(p[0])
    }
}

/// glTF's albedo scaling of the layer under the sheen (KHR_materials_sheen, "Albedo scaling"):
/// min(1 − c E(n·v), 1 − c E(n·l)), c = max3(sheenColor), E under Estevez–Kulla's curve (the
/// spec's sheen BRDF); its error c·max of the two E's.
fn albedo_scaling(p: &[f64], tol: f64) -> Estimate {
    let (alpha, c) = (p[0], p[3]);
    let (ev, el) = (eval_albedo::<EstevezKulla>(&[alpha, p[1]], tol), eval_albedo::<EstevezKulla>(&[alpha, p[2]], tol));
    Estimate { value: (1.0 - c * ev.value).min(1.0 - c * el.value), error: c * ev.error.max(el.error), evals: ev.evals + el.evals }
}

const N_DOT_L_EK: ParamSpec = ParamSpec { name: "n_dot_l", min: 1e-6, max: 1.0, doc: "n·l", integer: false, limit: None, default: None };
const SHEEN_COLOR: ParamSpec = ParamSpec { name: "sheen_color", min: 0.0, max: 1.0, doc: "max3(sheenColor)", integer: false, limit: None, default: None };

fn sheen_lambda(p: &[f64], tol: f64) -> Estimate {
    lambda_exact(p[0], p[1], tol)
}

const fn quantity(name: &'static str, doc: &'static str, params: &'static [ParamSpec], eval: crate::quantity::Eval) -> QuantityDef {
    let aliases: &'static [(ParamSpec, usize, fn(f64) -> f64)] = if params[0].min < ALPHA.min { &[ROUGHNESS_ALIAS_WIDE] } else { &[ROUGHNESS_ALIAS] };
    QuantityDef { name, doc, params, aliases, eval, inverse: None, channels: &[], eval_channels: None, basis: None }
}

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    quantity("sheen-lambda", "exact Smith Lambda(mu) of the Charlie distribution (from its projected area)", &[ALPHA, MU_LAMBDA], &sheen_lambda),
    quantity("sheen-albedo", "Charlie E(mu) with height-correlated Smith G2 of the exact Lambda", &[ALPHA, N_DOT_V], &eval_albedo::<Smith>),
    quantity("sheen-albedo-ek", "Charlie E(mu) with Estevez-Kulla's Lambda curve (glTF KHR_materials_sheen)", &[ALPHA_WIDE, N_DOT_V_EK], &eval_albedo::<EstevezKulla>),
    quantity("sheen-albedo-ashikhmin", "Charlie E(mu) with V = 1/(4(n·l + n·v - n·l n·v)) (Filament cloth, three.js)", &[ALPHA_WIDE, N_DOT_V], &eval_albedo::<Ashikhmin>),
    quantity("sheen-albedo-velvet", "E(mu) of Ashikhmin's velvet D with Neubelt's V (Filament's cloth before Charlie; the glTF IBL Sampler's D_Ashikhmin)", &[ALPHA, N_DOT_V], &eval_albedo::<VelvetLobe>),
    quantity(
        "sheen-albedo-scaling",
        "glTF's albedo scaling min(1 - c E(n.v), 1 - c E(n.l)) of the layer below the sheen (E: sheen-albedo-ek, c = max3(sheenColor))",
        &[ALPHA_WIDE, N_DOT_V_EK, N_DOT_L_EK, SHEEN_COLOR],
        &albedo_scaling,
    ),
    quantity("sheen-albedo-avg", "E_avg = 2 int E(mu) mu dmu of sheen-albedo (exact Smith)", &[ALPHA], &eval_albedo_avg::<Smith>),
    quantity("sheen-albedo-avg-ek", "E_avg of sheen-albedo-ek (Estevez-Kulla's curve)", &[ALPHA_WIDE], &eval_albedo_avg::<EstevezKulla>),
    quantity("sheen-albedo-avg-ashikhmin", "E_avg of sheen-albedo-ashikhmin", &[ALPHA_WIDE], &eval_albedo_avg::<Ashikhmin>),
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
    figures: plot::figures,
    bench: bench::BENCH,
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &refit::FORMS,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::hemisphere::albedo;

    /// At the least α of the wide domain the albedo under Ashikhmin's V and Estevez–Kulla's
    /// curve at tolerance 1e-8 is the one at 1e-12 within 1e-8 relative to max(E, 1) (E reaches
    /// ~400 at grazing there): the integrator's ξ = sin^k θh variable follows the narrow lobe.
    #[test]
    fn the_albedo_converges_at_the_least_alpha() {
        for alpha in [ALPHA_WIDE.min, 1e-5, 1e-4] {
            for mu in [1e-6, 1e-3, 0.01, 0.05] {
                for (name, lobe) in [("Ashikhmin", Charlie::new(alpha)), ("Estevez–Kulla", Charlie::estevez_kulla(alpha))] {
                    let (coarse, fine) = (albedo(&lobe, mu, 1e-8), albedo(&lobe, mu, 1e-12));
                    assert!((coarse.value - fine.value).abs() <= 1e-8 * fine.value.max(1.0), "α {alpha} μ {mu} {name}: {coarse:?} vs {fine:?}");
                }
            }
        }
    }

    /// The aliases map r to α = r² with the domain of their quantity: r's least value squared is
    /// the least α.
    #[test]
    fn each_roughness_alias_reaches_its_quantitys_least_alpha() {
        for q in QUANTITIES {
            let (r, index, to_alpha) = q.aliases[0];
            assert_eq!(index, 0);
            assert!((to_alpha(r.min) - q.params[0].min).abs() <= 1e-15 * q.params[0].min, "{}: {} vs {}", q.name, to_alpha(r.min), q.params[0].min);
        }
    }
}
