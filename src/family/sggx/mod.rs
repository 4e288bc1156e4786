//! The sggx family (Ghost of Tsushima, "Anisotropic specular maps and filtering"): a normal and a
//! 2×2 anisotropic GGX matrix as an SGGX matrix S, filtered linearly over a footprint, the normal
//! recovered by power iteration, the block stored as [√Sxx, ½ Sxy/√(Sxx Syy) + ½, √Syy] and
//! decoded by the course's `DecodeSggx`; the NDF distances of linear filtering, SGGX parameter
//! estimation and LEAN mapping to true mixtures (see `integrals.rs`).

pub mod bench;
pub mod emit;
pub mod integrals;
pub mod mip;
pub mod plot;
pub mod published;

use super::Family;
use crate::integrate::{Estimate, Tolerance, adaptive};
use crate::quantity::{ParamSpec, QuantityDef};
use integrals::{Aniso, Lobe, direction, extract, filter, rotation_to, sggx_from};
use std::f64::consts::PI;

const fn p(name: &'static str, min: f64, max: f64, doc: &'static str) -> ParamSpec {
    ParamSpec { name, min, max, doc, integer: false, limit: None, default: None }
}

const fn pd(name: &'static str, min: f64, max: f64, doc: &'static str, default: f64) -> ParamSpec {
    ParamSpec { name, min, max, doc, integer: false, limit: None, default: Some(default) }
}

/// α ∈ [0.001, 1]: the course's α_min to the largest GGX roughness.
const ALPHA_LO: f64 = integrals::ALPHA_MIN;

/// The two texels of `sggx-filter` from its canonical parameters.
fn two_texels(x: &[f64]) -> [(f64, integrals::V3, Aniso); 2] {
    let t = |o: usize, w: f64| (w, direction(x[o], x[o + 1]), Aniso::from_alphas(x[o + 2], x[o + 3], x[o + 4]));
    [t(0, 1.0 - x[10]), t(5, x[10])]
}

fn filter_channels(x: &[f64], _tol: f64) -> Vec<Estimate> {
    let texels = two_texels(x);
    let s = filter(&texels.map(|(w, n, a)| (w, sggx_from(n, a))));
    let e = extract(&s);
    // The power iteration stops at a relative residual r ≤ 1e-14: the normal's error is about
    // r over the relative eigenvalue gap; the block inherits it through M_n′.
    let ev = e.power.iterations as u64;
    let gap = {
        let mut l: Vec<f64> = nalgebra::SymmetricEigen::new(s).eigenvalues.iter().copied().collect();
        l.sort_by(f64::total_cmp);
        (1.0 - l[1] / l[2]).max(1e-300)
    };
    let err = (e.power.residual / gap).max(4.0 * f64::EPSILON);
    [e.n.x, e.n.y, e.n.z, e.aniso.sxx, e.aniso.sxy, e.aniso.syy, e.power.iterations as f64]
        .iter()
        .enumerate()
        .map(|(i, &v)| Estimate { value: v, error: if i == 6 { 0.0 } else { err }, evals: ev })
        .collect()
}

fn filter_first(x: &[f64], tol: f64) -> Estimate {
    filter_channels(x, tol)[0]
}

/// ∫ ⟨ω, m⟩₊ D(m) dm by nested adaptive quadrature in the frame whose pole is ω (so the
/// clamp is the θ range, not a kink): θ ∈ [0, π/2] outside, φ ∈ [0, 2π] inside.
pub fn projected_area_quadrature(lobe: &Lobe, w: integrals::V3, tol: f64) -> Estimate {
    let frame = rotation_to(w);
    let tol1 = Tolerance { abs: tol, rel: tol, max_panels: 4000 };
    let mut evals = 0;
    let mut err = 0.0;
    let outer = adaptive(0.0, PI / 2.0, tol1, |t| {
        let (st, ct) = t.sin_cos();
        let inner = adaptive(0.0, 2.0 * PI, Tolerance { abs: tol / 4.0, ..tol1 }, |p| lobe.d(&(frame * direction(t, p))));
        evals += inner.evals;
        err = f64::max(err, inner.error);
        inner.value * st * ct
    });
    Estimate { value: outer.value, error: outer.error + err * PI / 2.0, evals: evals + outer.evals }
}

fn projected_area(x: &[f64], tol: f64) -> Estimate {
    let s = sggx_from(direction(x[0], x[1]), Aniso::from_alphas(x[2], x[3], x[4]));
    projected_area_quadrature(&Lobe::new(s).expect("α > 0 gives an SPD matrix"), direction(x[5], x[6]), tol.max(1e-13))
}

const TEXEL_PARAMS: [ParamSpec; 5] = [
    p("theta", 0.0, 1.5, "normal's polar angle from z (radians)"),
    p("phi", -PI, PI, "normal's azimuth"),
    p("alpha_t", ALPHA_LO, 1.0, "GGX roughness along the anisotropy axis"),
    p("alpha_b", ALPHA_LO, 1.0, "GGX roughness across it"),
    p("psi", -PI, PI, "axis angle from the normal-mapped tangent"),
];

/// The family's quantities, in `eval --help` order.
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "sggx-filter",
        doc: "two texels (normal + anisotropic GGX) filtered as SGGX matrices: n′, the new 2×2 block, power iterations",
        params: &[
            p("theta1", 0.0, 1.5, "first normal's polar angle"),
            p("phi1", -PI, PI, "first normal's azimuth"),
            p("alpha_t1", ALPHA_LO, 1.0, "first α_t"),
            p("alpha_b1", ALPHA_LO, 1.0, "first α_b"),
            pd("psi1", -PI, PI, "first axis angle", 0.0),
            p("theta2", 0.0, 1.5, "second normal's polar angle"),
            p("phi2", -PI, PI, "second normal's azimuth"),
            p("alpha_t2", ALPHA_LO, 1.0, "second α_t"),
            p("alpha_b2", ALPHA_LO, 1.0, "second α_b"),
            pd("psi2", -PI, PI, "second axis angle", 0.0),
            pd("weight", 0.0, 1.0, "weight of the second texel", 0.5),
        ],
        aliases: &[],
        eval: &filter_first,
        inverse: None,
        channels: &["nx", "ny", "nz", "sxx", "sxy", "syy", "iterations"],
        eval_channels: Some(&filter_channels),
        basis: None,
    },
    QuantityDef {
        name: "sggx-projected-area",
        doc: "∫⟨ω,m⟩₊ D(m) dm of a texel's SGGX NDF by quadrature (closed form √(ωᵀSω); 1 along n)",
        params: &[
            TEXEL_PARAMS[0],
            TEXEL_PARAMS[1],
            TEXEL_PARAMS[2],
            TEXEL_PARAMS[3],
            TEXEL_PARAMS[4],
            p("theta_w", 0.0, PI, "ω's polar angle"),
            p("phi_w", -PI, PI, "ω's azimuth"),
        ],
        aliases: &[],
        eval: &projected_area,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// The sggx family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "sggx",
    feature: "sggx",
    doc: "Ghost of Tsushima SGGX filtering and storage of anisotropic GGX roughness",
    quantities: QUANTITIES,
    spec_kinds: &[emit::DECODE],
    eval_options: None,
    validate: published::items,
    figures: plot::figures,
    bench: bench::BENCH,
    scene_features: &[],
    commands: &[mip::COMMAND],
    axis_mappings: &[],
    forms: &[],
};

#[cfg(test)]
mod tests {
    use super::*;

    /// `sggx-projected-area` of an isotropic α = 1 texel is 1 along every ω: its block is the
    /// identity, so S = M_n I M_nᵀ = I and σ(ω) = √(ωᵀ S ω) = 1 (the module's closed form);
    /// equivalently D = 1/π on the sphere and ∫ ⟨ω, m⟩₊ / π dm = 1. Swept over θ_w ∈ [0, π]
    /// with π itself and points within 1e-9 of it (the quadrature's frame about ω is M_ω, the
    /// rotation onto ω, once unstable there), at `eval`'s tolerance 1e-12. 1e-12: that
    /// tolerance; the integrand is constant, so the rule is exact to the roundings of D.
    #[test]
    fn an_isotropic_unit_texel_has_unit_projected_area_along_every_direction() {
        let mut thetas: Vec<f64> = (0..=32).map(|i| PI * i as f64 / 32.0).collect();
        thetas.extend([PI - 1e-6, PI - 1e-9, PI - 2e-10, 3.1415926, 3.14159265, PI]);
        for (theta, phi) in [(0.0, 0.0), (0.9, 2.0)] {
            for &tw in &thetas {
                for pw in [0.0, 1.3] {
                    let e = projected_area(&[theta, phi, 1.0, 1.0, 0.0, tw, pw], 1e-12);
                    assert!((e.value - 1.0).abs() <= 1e-12, "n ({theta}, {phi}), θ_w {tw}, φ_w {pw}: {}", e.value);
                }
            }
        }
    }

    /// An anisotropic tilted texel against its closed form √(ωᵀ S ω) as ω nears and reaches
    /// −k: 1e-9 relative, the quadrature run at 1e-10 (the nested rule's estimate bounds its
    /// error at that tolerance; a tenth of the margin is left for the estimate's own slack).
    #[test]
    fn the_projected_area_matches_its_closed_form_near_the_south_pole() {
        let s = sggx_from(direction(0.4, 1.0), Aniso::from_alphas(0.5, 0.2, 0.3));
        let lobe = Lobe::new(s).unwrap();
        for tw in [PI - 1e-3, PI - 1e-9, PI] {
            let w = direction(tw, 0.5);
            let q = projected_area_quadrature(&lobe, w, 1e-10).value;
            let exact = lobe.projected_area(&w);
            assert!((q / exact - 1.0).abs() <= 1e-9, "θ_w {tw}: {q} vs {exact}");
        }
    }
}
