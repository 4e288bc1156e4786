//! The fuzz family's scene feature.
//!
//! `fuzz` (alpha ∈ [0.15, 1], theta_f ∈ [0, π/2], density ∈ (0, 0.5]): with alpha and theta_f
//! fixed, the six P_s coefficients come straight from the integrals (the per-direction minimax
//! optimum at that point, emitted as `{material}_fuzz_ps(n_dot_u, t_dot_u)`) and R is a constant
//! (`{MATERIAL}_AVERAGE_PS`); otherwise the general `fuzz_ps` and `fuzz_r` nodes are reached.
//! With density fixed, Q is a constant (`{MATERIAL}_AVERAGE_PENETRATION`) and G̃'s form is
//! refitted in μv alone (`{material}_fuzz_g(n_dot_v)`); otherwise `fuzz_q`, `fuzz_g`.

use super::integrals as fuzz;
use crate::fit::model::{ModelParts, Term};
use crate::fit::{self, Data, FitOptions, Objective, RationalModel};
use crate::pipeline::committed::{self, Fields};
use crate::pipeline::{self, BuildError, SceneError};
use crate::scene::{max_err, Feature, IndexedFunction, Inputs, MaterialSpec, Param, Pieces, Reach, SceneConstant, SceneFunction, Specialisation};
use crate::spec::Spec;
use nalgebra::{DMatrix, DVector};
use serde_json::json;

/// The family's scene features.
pub const FEATURES: &[Feature] = &[Feature {
    name: "fuzz",
    params: &[
        Param { name: "alpha", lo: 0.15, hi: 1.0, fixed_above_lo: false },
        Param { name: "theta_f", lo: 0.0, hi: std::f64::consts::FRAC_PI_2, fixed_above_lo: false },
        Param { name: "density", lo: 0.0, hi: 0.5, fixed_above_lo: true },
    ],
    reach,
}];

fn reach(m: &MaterialSpec) -> Reach {
    let mut r = Reach::default();
    match (m.fixed("alpha"), m.fixed("theta_f")) {
        (Some(_), Some(_)) => r.special.push(&PS),
        _ => r.nodes.extend(["fuzz_ps", "fuzz_r"]),
    }
    match m.fixed("density") {
        Some(_) => r.special.push(&G),
        None => r.nodes.extend(["fuzz_g", "fuzz_q"]),
    }
    r
}

/// P_s and R at fixed (α, θf).
static PS: Specialisation = Specialisation { inputs: &["fuzz_ps", "fuzz_r"], functions: ps_functions, build: ps_build };

/// G̃ and Q at fixed density.
static G: Specialisation = Specialisation { inputs: &["fuzz_g", "fuzz_q"], functions: g_functions, build: g_build };

fn ps_functions(m: &MaterialSpec, _specs: &[Spec]) -> Vec<IndexedFunction> {
    let d = crate::family::catalog().lookup("fuzz-ps").ok().and_then(|q| q.basis).map_or(vec![], |b| b.arg_domain.to_vec());
    vec![(format!("{}_fuzz_ps", m.name), d)]
}

fn g_functions(m: &MaterialSpec, specs: &[Spec]) -> Vec<IndexedFunction> {
    let r = specs.iter().find(|s| s.file.name == "fuzz_g").map_or([0.001, 1.0], |s| s.file.axis[0].range);
    vec![(format!("{}_fuzz_g", m.name), vec![(r[0], r[1])])]
}

fn model(inputs: &[&str], num: &[&str], den: &[&str], fixed: Vec<(usize, f64)>, clamp: Option<(f64, f64)>) -> RationalModel {
    let f: Vec<String> = inputs.iter().map(|s| s.to_string()).collect();
    let t = |s: &&str| Term::parse(s, &f).expect("scene model terms are valid");
    RationalModel::new(ModelParts {
        inputs: f.clone(),
        numerator: num.iter().map(t).collect(),
        denominator: den.iter().map(t).collect(),
        fixed,
        clamp,
        ..ModelParts::default()
    })
    .expect("scene models are well formed")
}

/// P_s at fixed (α, θf): the coefficients of the quantity's inner basis (Eq. 1) by minimax over
/// the spec's light directions (Lawson's iteration on the linear system), and R as a constant.
fn ps_build(m: &MaterialSpec, inputs: &Inputs) -> Result<Pieces, BuildError> {
    let material = m.name.as_str();
    let alpha = m.fixed("alpha").expect("planned with alpha fixed");
    let theta_f = m.fixed("theta_f").expect("planned with theta_f fixed");
    let spec = inputs.spec("fuzz_ps")?;
    let ib = spec.quantity.basis.expect("fuzz-ps has an inner basis");
    let args: Vec<String> = ib.args.iter().map(|a| a.to_string()).collect();
    let terms: Vec<Term> = ib.terms.iter().map(|t| Term::parse(t, &args).expect("basis terms are valid")).collect();
    let outer = [alpha, theta_f];
    let inner_axes = &spec.file.axis[spec.file.axis.len() - ib.inner..];
    let dirs = |verify: bool| -> Vec<Vec<f64>> {
        let counts: Vec<usize> = inner_axes.iter().map(|a| if verify { a.verify_count() } else { a.count }).collect();
        pipeline::tensor(inner_axes, &counts)
    };
    let basis = |u: &[f64]| -> Vec<f64> {
        let a = (ib.to_args)(&outer, u);
        terms.iter().map(|t| t.eval(&a)).collect()
    };
    let sample = |d: &[Vec<f64>]| -> Vec<f64> { (ib.sample)(&outer, d, spec.file.tolerance).iter().map(|e| e.value).collect() };
    let (lo, hi) = ib.range;
    let fit_dirs = dirs(false);
    let b = DMatrix::from_fn(fit_dirs.len(), terms.len(), |i, k| basis(&fit_dirs[i])[k]);
    let yv = DVector::from_vec(sample(&fit_dirs));
    let mut w = vec![1.0; fit_dirs.len()];
    let mut best: Option<(f64, DVector<f64>)> = None;
    for _ in 0..200 {
        let sw: Vec<f64> = w.iter().map(|v: &f64| v.sqrt()).collect();
        let bw = DMatrix::from_fn(b.nrows(), b.ncols(), |i, k| b[(i, k)] * sw[i]);
        let yw = DVector::from_fn(b.nrows(), |i, _| yv[i] * sw[i]);
        let Ok(c) = bw.svd(true, true).solve(&yw, 1e-14) else { break };
        let r = &b * &c - &yv;
        let m = r.amax();
        if best.as_ref().is_none_or(|(bm, _)| m < *bm) {
            best = Some((m, c.clone()));
        }
        let top = w.iter().zip(r.iter()).map(|(wi, ri)| wi * ri.abs()).fold(0.0, f64::max);
        if !(top > 0.0) {
            break;
        }
        for (wi, ri) in w.iter_mut().zip(r.iter()) {
            *wi = (*wi * ri.abs() / top).max(1e-6);
        }
    }
    let (_, c) = best.ok_or_else(|| SceneError::Singular {
        material: material.to_string(),
        system: format!("P_s system at α = {alpha}, θf = {theta_f}"),
    })?;
    // Errors on the verification directions, next to the general fit at the same (α, θf).
    let vd = dirs(true);
    let truth = sample(&vd);
    let eval_at = |coef: &[f64]| -> Vec<f64> {
        vd.iter().map(|u| basis(u).iter().zip(coef).map(|(b, c)| b * c).sum::<f64>().clamp(lo, hi)).collect()
    };
    let ours = eval_at(c.as_slice());
    let general = Fields::of(spec, inputs.generated).ok().map(|f| max_err(&truth, &eval_at(&f.eval(&outer))));
    let arg_refs: Vec<&str> = ib.args.to_vec();
    let m = model(&arg_refs, ib.terms, &[], vec![], Some((lo, hi)));
    let ps = SceneFunction {
        name: format!("{material}_fuzz_ps"),
        args,
        domain: ib.arg_domain.to_vec(),
        record: json!({"what": "P_s coefficients at fixed (alpha, theta_f)", "alpha": alpha, "theta_f": theta_f,
            "coefficients": c.iter().copied().collect::<Vec<f64>>(), "points": vd.len(),
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general}),
        model: m,
        coefficients: c,
    };
    let r = fuzz::r(alpha, theta_f, 1e-10);
    let r_spec = inputs.spec("fuzz_r")?;
    let general_r = committed::fit_coefficients(r_spec, inputs.generated)
        .ok()
        .map(|cf| (r_spec.model.as_ref().map_or(f64::NAN, |m| m.eval_clamped(&cf, &[alpha, theta_f])) - r.value).abs());
    let rc = SceneConstant {
        name: format!("{}_AVERAGE_PS", material.to_uppercase()),
        value: r.value,
        record: json!({"what": "R at fixed (alpha, theta_f)", "value": r.value, "error_estimate": r.error,
            "general_fit_abs_error": general_r}),
    };
    Ok(Pieces { functions: vec![ps], constants: vec![rc] })
}

/// G̃'s form at fixed density, refitted in μv alone (minimax), and Q = 2·E₃(d) as a constant.
fn g_build(m: &MaterialSpec, inputs: &Inputs) -> Result<Pieces, BuildError> {
    let material = m.name.as_str();
    let d = m.fixed("density").expect("planned with density fixed");
    let spec = inputs.spec("fuzz_g")?;
    let ax = &spec.file.axis[0];
    // d(1 + a1 μ + a2 μ²)/(d + b1 μ + b3 μ³) = (1 + a1 μ + a2 μ²)/(1 + (b1/d) μ + (b3/d) μ³).
    let m = model(&["n_dot_v"], &["1", "n_dot_v", "n_dot_v^2"], &["n_dot_v", "n_dot_v^3"], vec![(0, 1.0)], None);
    let x: Vec<Vec<f64>> = ax.points(ax.count * 4 + 1).into_iter().map(|v| vec![v]).collect();
    let y: Vec<f64> = x.iter().map(|p| fuzz::g_exact(d, p[0])).collect();
    let data = Data { x, y };
    let f = fit::fit(&m, &data, &FitOptions { objective: Objective::Minimax, ..FitOptions::default() }, &format!("{material}_fuzz_g"))?;
    let vx: Vec<f64> = ax.points(ax.verify_count() * 4 + 1);
    let truth: Vec<f64> = vx.iter().map(|&mu| fuzz::g_exact(d, mu)).collect();
    let ours: Vec<f64> = vx.iter().map(|&mu| m.eval_clamped(&f.coefficients, &[mu])).collect();
    let general = committed::fit_coefficients(spec, inputs.generated).ok().map(|c| {
        let gm = spec.model.as_ref().expect("fit specs carry a model");
        max_err(&truth, &vx.iter().map(|&mu| gm.eval_clamped(&c, &[mu, d])).collect::<Vec<_>>())
    });
    let g = SceneFunction {
        name: format!("{material}_fuzz_g"),
        args: vec!["n_dot_v".into()],
        domain: vec![(ax.range[0], ax.range[1])],
        record: json!({"what": "G refitted in mu_v at fixed density", "density": d, "points": vx.len(),
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general}),
        model: m,
        coefficients: f.coefficients,
    };
    let q = fuzz::q_exact(d);
    let q_spec = inputs.spec("fuzz_q")?;
    let general_q = committed::fit_coefficients(q_spec, inputs.generated)
        .ok()
        .map(|c| (q_spec.model.as_ref().map_or(f64::NAN, |m| m.eval_clamped(&c, &[d])) - q).abs());
    let qc = SceneConstant {
        name: format!("{}_AVERAGE_PENETRATION", material.to_uppercase()),
        value: q,
        record: json!({"what": "Q = 2 E3(d) at fixed density", "value": q, "general_fit_abs_error": general_q}),
    };
    Ok(Pieces { functions: vec![g], constants: vec![qc] })
}

#[cfg(test)]
mod tests {
    use crate::scene::{plan, Feature, Scene};

    fn features() -> Vec<&'static Feature> {
        crate::family::families().iter().flat_map(|f| f.scene_features.iter()).collect()
    }

    fn load(params: &str) -> Result<Scene, crate::spec::SpecError> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.toml");
        std::fs::write(&p, format!("name = \"t\"\n[[material]]\nname = \"m\"\nfeatures = [\"fuzz\"]\nparams = {{ {params} }}\n")).unwrap();
        Scene::load(&p, &features())
    }

    #[test]
    fn fixed_parameters_specialise_ranges_reach_the_general_nodes() {
        let p = plan(&load("alpha = 0.5, theta_f = 0.3, density = 0.2").unwrap());
        assert!(p.nodes.is_empty(), "{:?}", p.nodes);
        let inputs: Vec<&[&str]> = p.special.iter().map(|s| s.what.inputs).collect();
        assert_eq!(inputs, [&["fuzz_ps", "fuzz_r"][..], &["fuzz_g", "fuzz_q"][..]]);
        let p = plan(&load("alpha = [0.3, 0.6], theta_f = 0.3, density = [0.0, 0.3]").unwrap());
        assert_eq!(p.nodes, ["fuzz_g", "fuzz_ps", "fuzz_q", "fuzz_r"]);
        assert!(p.special.is_empty());
    }

    #[test]
    fn a_fixed_density_must_be_positive() {
        let e = load("density = 0.0").unwrap_err().to_string();
        assert!(e.contains("density > 0 when fixed"), "{e}");
        assert!(load("density = 0.5").is_ok());
        assert!(load("density = 0.6").is_err());
        assert!(load("alpha = 0.1").is_err());
    }
}
