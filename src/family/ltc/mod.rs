//! The ltc family: area lights by linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt
//! 2016). An LTC ([`transform`]) is a clamped cosine reshaped by a matrix, whose integral over a
//! polygon light has a closed form; a table of them per (roughness, view) stands in for a
//! lobe. [`fit`] fits that table for any lobe of the lobe layer by deterministic quadrature
//! of the L1 distance between the normalised lobes; [`sphere`] is ltc_2's clipped sphere form
//! factor in closed form; [`reference`] integrates the true lobe over polygon lights, the
//! end-to-end check; [`table`] is the spec kind (`ltc-table`) and [`emit`] its light functions;
//! [`published`] measures ltc_code's shipped GGX tables the same way; [`plot`] draws the
//! committed tables' per-cell maps and lobe slices.

pub mod emit;
pub mod fit;
pub mod plot;
pub mod published;
pub mod reference;
pub mod sphere;
pub mod table;
pub mod transform;

use super::Family;
use crate::bench::FamilyBench;
use crate::bench::builds::BuildBench;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::shading::Lobe;
use fit::{Cell, FIT_NODES, fit_cell};
use transform::Ltc;

const ALPHA: ParamSpec = ParamSpec { name: "alpha", min: 1e-4, max: 1.0, doc: "GGX alpha (roughness²)", integer: false, default: None, limit: None };
const SHEEN_ALPHA: ParamSpec = ParamSpec { name: "alpha", min: 3e-3, max: 1.0, doc: "Charlie alpha (roughness²)", integer: false, default: None, limit: None };
/// cos 1.57: the fit's largest polar angle ([`fit::MAX_THETA`]).
const N_DOT_V: ParamSpec = ParamSpec { name: "n_dot_v", min: 7.963e-4, max: 1.0, doc: "n·v", integer: false, default: None, limit: None };

/// δ of the LTC fitted at one (α, n·v): continuation from α = 1 at normal incidence down to α
/// (8 steps in ln α), then along θ to the view (8 steps), each fitted from the last; value at
/// 2 × [`FIT_NODES`] nodes, error |δ(n) − δ(2n)|.
fn distance_at<L: Lobe>(lobe: &dyn Fn(f64) -> L, alpha: f64, n_dot_v: f64) -> Estimate {
    let mut ltc = Ltc::IDENTITY;
    for k in 0..=8 {
        let a = alpha.powf(k as f64 / 8.0);
        let l = lobe(a);
        ltc = fit_cell(&Cell::new(&l, 0.0, FIT_NODES), ltc, true).0;
    }
    let l = lobe(alpha);
    let theta = n_dot_v.clamp(-1.0, 1.0).acos();
    for k in 1..=8 {
        ltc = fit_cell(&Cell::new(&l, theta * k as f64 / 8.0, FIT_NODES), ltc, false).0;
    }
    let (value, error) = fit::distance_with_error(&l, theta, &ltc, FIT_NODES);
    Estimate { value, error, evals: 0 }
}

fn ggx_distance(p: &[f64], _tol: f64) -> Estimate {
    distance_at(&published::ggx, p[0], p[1])
}

fn sheen_distance(p: &[f64], _tol: f64) -> Estimate {
    distance_at(&crate::shading::charlie::Charlie::new, p[0], p[1])
}

/// The family's quantities: the L1 distance of the best LTC to a lobe (what a table's cells
/// report; a table spec names its lobe by one of them).
pub static QUANTITIES: &[QuantityDef] = &[
    QuantityDef {
        name: "ltc-ggx-distance",
        doc: "L1 distance int |p - D| (in [0, 2]) between GGX's normalised cosine lobe and its LTC fitted by continuation (ltc_code's lobe)",
        params: &[ALPHA, N_DOT_V],
        aliases: &[],
        eval: &ggx_distance,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "ltc-sheen-distance",
        doc: "L1 distance between the Charlie sheen lobe (exact Smith) and its LTC fitted by continuation",
        params: &[SHEEN_ALPHA, N_DOT_V],
        aliases: &[],
        eval: &sheen_distance,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

/// The ltc family's descriptor (registered in `crate::family::FAMILIES`).
pub static FAMILY: Family = Family {
    name: "ltc",
    feature: "ltc",
    doc: "area lights: linearly transformed cosines fitted to a lobe by quadrature, their light functions checked end to end, ltc_code's tables audited",
    quantities: QUANTITIES,
    spec_kinds: &[table::TABLE],
    eval_options: None,
    validate: published::items,
    figures: plot::figures,
    bench: FamilyBench {
        builds: &[
            BuildBench { spec: "ltc_ggx", order: 0, quick: false, functions: &["ltc_ggx_rect", "ltc_ggx_rect_sphere", "ltc_ggx_polygon"] },
            BuildBench { spec: "ltc_sheen", order: 1, quick: false, functions: &[] },
        ],
        ..FamilyBench::NONE
    },
    scene_features: &[],
    commands: &[],
    axis_mappings: &[],
    forms: &[],
};

#[cfg(test)]
mod tests {
    use crate::spec::Spec;

    /// The builds bench row of a small table (8², 12 nodes): the one-thread build gives the
    /// pool's bytes, the row counts its files and the rect light's ops (its polygon's three
    /// loops counted once each); a function the module lacks is an error naming it.
    #[test]
    fn a_build_row_times_both_pools_and_counts_the_light_s_ops() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("ltc_t.toml");
        std::fs::write(&path, super::table::tests::SPEC).unwrap();
        let spec = Spec::load(&path, crate::family::catalog()).unwrap();
        let custom = |k: &str| crate::family::spec_kind(k).map(|s| s.build);
        let r = crate::bench::builds::row(&spec, &["ltc_t_rect"], tmp.path(), &custom).unwrap();
        // WGSL, Rust, JSON, the C and JS arrays, four KTX2 tables and each one's DDS and EXR
        // (the default formats): 17 files.
        assert!(r.identical && r.files == 17 && r.seconds > 0.0 && r.seconds_one_thread > 0.0, "{r:?}");
        assert_eq!(r.ops.len(), 1);
        assert!(r.ops[0].1.weighted() > 0 && r.ops[0].1.loops == 3, "{r:?}");
        let e = crate::bench::builds::row(&spec, &["no_such_function"], tmp.path(), &custom).unwrap_err();
        assert!(format!("{e:?}").contains("no_such_function"), "{e:?}");
    }
}
