//! A lobe registered as quantities through the shading layer's generic evaluators, its tables
//! built by the generic `table` kind, each against the lobe's closed form. The test writes the
//! lobe's BRDF and nothing else: no integrator code.
//!
//! The lobe: f = ρ (3/2π) μv μl (reciprocal; the cosine measure), whose directional albedo is
//! E(μv) = ρ (3/2π) μv ∫ μl² dω_l = ρ μv, so E_avg = 2∫ ρ μ² dμ = 2ρ/3, and in a cone μl ≥ c
//! the split sum adds up to scale + bias = ρ μv (1 − c³).

use super::build_tests::{floats, json_of};
use super::*;
use crate::integrate::Estimate;
use crate::quantity::{ParamSpec, QuantityDef};
use crate::shading::hemisphere::{eval_albedo, eval_albedo_avg, eval_split_sum, eval_split_sum_scale, LobeParams};
use crate::shading::Lobe;
use crate::spec::Catalog;
use std::f64::consts::PI;

struct Linear {
    rho: f64,
}

impl Lobe for Linear {
    type View = f64;
    fn view(&self, mu_v: f64) -> f64 {
        mu_v
    }
    fn eval(&self, mu_v: &f64, _vh: f64, _ch: f64, mu_l: f64) -> f64 {
        self.rho * 1.5 / PI * mu_v * mu_l
    }
}

impl LobeParams for Linear {
    type Lobe = Linear;
    const COUNT: usize = 1;
    fn lobe(p: &[f64]) -> Linear {
        Linear { rho: p[0] }
    }
}

/// The lobe at ρ = 1, with no parameter of its own (the split-sum tables' two axes are the
/// view and the cone: the generic table kind has one or two).
struct UnitLinear;

impl LobeParams for UnitLinear {
    type Lobe = Linear;
    const COUNT: usize = 0;
    fn lobe(_p: &[f64]) -> Linear {
        Linear { rho: 1.0 }
    }
}

const RHO: ParamSpec = ParamSpec { name: "rho", min: 0.0, max: 1.0, doc: "albedo scale", integer: false, limit: None, default: None };
const N_DOT_V: ParamSpec = ParamSpec { name: "n_dot_v", min: 0.0, max: 1.0, doc: "n·v", integer: false, limit: None, default: None };
const COS_CONE: ParamSpec = ParamSpec { name: "cos_cone", min: 0.0, max: 1.0, doc: "cone", integer: false, limit: None, default: Some(0.0) };

static ALBEDO: QuantityDef = QuantityDef {
    name: "linear-albedo",
    doc: "E of the linear lobe",
    params: &[RHO, N_DOT_V],
    aliases: &[],
    eval: &eval_albedo::<Linear>,
    inverse: None,
    channels: &[],
    eval_channels: None,
    basis: None,
};

static AVG: QuantityDef = QuantityDef {
    name: "linear-albedo-avg",
    doc: "E_avg of the linear lobe",
    params: &[RHO],
    aliases: &[],
    eval: &eval_albedo_avg::<Linear>,
    inverse: None,
    channels: &[],
    eval_channels: None,
    basis: None,
};

static SPLIT: QuantityDef = QuantityDef {
    name: "linear-env",
    doc: "[scale, bias] of the linear lobe",
    params: &[N_DOT_V, COS_CONE],
    aliases: &[],
    eval: &eval_split_sum_scale::<UnitLinear>,
    inverse: None,
    channels: &["scale", "bias"],
    eval_channels: Some(&eval_split_sum::<UnitLinear>),
    basis: None,
};

fn table(name: &str, quantity: &str, channel: &str, axes: &[(&str, f64, f64, usize)]) -> Built {
    let mut text = format!("name = \"{name}\"\nkind = \"table\"\nquantity = \"{quantity}\"\n{channel}description = \"t\"\ntolerance = 1e-10\n");
    for (a, lo, hi, n) in axes {
        text.push_str(&format!("\n[[axis]]\nname = \"{a}\"\nrange = [{lo:?}, {hi:?}]\ncount = {n}\nverify = {}\n", 2 * n - 1));
    }
    text.push_str(&format!("\n[emit]\nfunction = \"{name}\"\n"));
    let catalog = Catalog { quantities: vec![&ALBEDO, &AVG, &SPLIT], kinds: vec![], features: vec![], mappings: vec![] };
    let spec = Spec::parse(Path::new(&format!("fits/{name}.toml")), text, &catalog).unwrap();
    build_spec(&spec, Mode::Fit, tempfile::tempdir().unwrap().path(), &|_| None).unwrap()
}

/// The albedo table over (ρ, n·v), the split-sum tables (scale and bias, ρ = 1) over n·v × cone and
/// the E_avg table over ρ, each value against the closed form within the spec's tolerance
/// 1e-10 (each channel's error estimate is ≤ it; the sum of two channels ≤ twice it). The
/// table's grid is the spec's axes, first axis fastest.
#[test]
fn a_lobe_given_by_its_brdf_gets_its_albedo_split_sum_and_average_tables() {
    let tol = 1e-10;
    let b = table("lin_albedo", "linear-albedo", "", &[("rho", 0.0, 1.0, 3), ("n_dot_v", 0.0, 1.0, 5)]);
    let e = floats(&json_of(&b)["values"]);
    assert_eq!(e.len(), 15);
    for (k, v) in e.iter().enumerate() {
        let (rho, mu) = ((k % 3) as f64 / 2.0, (k / 3) as f64 / 4.0);
        assert!((v - rho * mu).abs() <= tol, "E at ρ {rho}, μv {mu}: {v}");
    }
    let axes = [("n_dot_v", 0.0, 1.0, 5), ("cos_cone", 0.0, 0.5, 3)];
    let scale = floats(&json_of(&table("lin_scale", "linear-env", "channel = \"scale\"\n", &axes))["values"]);
    let bias = floats(&json_of(&table("lin_bias", "linear-env", "channel = \"bias\"\n", &axes))["values"]);
    assert_eq!((scale.len(), bias.len()), (15, 15));
    for k in 0..15 {
        let (mu, c) = ((k % 5) as f64 / 4.0, (k / 5) as f64 / 4.0);
        let want = mu * (1.0 - c * c * c);
        assert!((scale[k] + bias[k] - want).abs() <= 2.0 * tol, "scale + bias at μv {mu}, c {c}: {} + {}", scale[k], bias[k]);
        // Schlick's weight splits the albedo into two proper parts.
        assert!(scale[k] >= 0.0 && bias[k] >= 0.0 && (mu == 0.0 || bias[k] > 0.0), "μv {mu}, c {c}");
    }
    let avg = floats(&json_of(&table("lin_avg", "linear-albedo-avg", "", &[("rho", 0.0, 1.0, 5)]))["values"]);
    for (k, v) in avg.iter().enumerate() {
        let rho = k as f64 / 4.0;
        assert!((v - 2.0 * rho / 3.0).abs() <= tol, "E_avg at ρ {rho}: {v}");
    }
    // The evaluators count the work: E at an interior point takes integrand evaluations.
    let one: Estimate = eval_albedo::<Linear>(&[1.0, 0.5], tol);
    assert!(one.evals > 0 && one.error <= tol, "{one:?}");
}
