//! The gloss family's scene features.
//!
//! - `gloss_mips` (gloss range): `gloss_inverse_table`, and with a gloss range the form of
//!   `gloss_length` refitted on that range (`{material}_gloss_to_normal_length(gloss)`, no end
//!   pins), else the general `gloss_length`.
//! - `gloss_combine`: the `gloss_combine_lut` node.

use super::integrals as gloss;
use crate::fit::model::ModelParts;
use crate::fit::{self, Data, FitOptions, Objective, RationalModel};
use crate::pipeline::committed;
use crate::pipeline::{BuildError, SceneError};
use crate::scene::{max_err, Feature, IndexedFunction, Inputs, MaterialSpec, Param, Pieces, Reach, SceneFunction, Specialisation};
use crate::spec::Spec;
use serde_json::json;

/// The family's scene features.
pub const FEATURES: &[Feature] = &[
    Feature { name: "gloss_mips", params: &[Param { name: "gloss", lo: 0.0, hi: 1.0, fixed_above_lo: false }], reach: mips },
    Feature { name: "gloss_combine", params: &[], reach: combine },
];

fn mips(m: &MaterialSpec) -> Reach {
    let mut r = Reach { nodes: vec!["gloss_inverse_table"], special: vec![] };
    match m.range("gloss") {
        Some(_) => r.special.push(&LENGTH),
        None => r.nodes.push("gloss_length"),
    }
    r
}

fn combine(_: &MaterialSpec) -> Reach {
    Reach { nodes: vec!["gloss_combine_lut"], special: vec![] }
}

/// gloss_length's form on the material's gloss range.
static LENGTH: Specialisation = Specialisation { inputs: &["gloss_length"], functions: length_functions, build: length_build };

fn length_functions(m: &MaterialSpec, _specs: &[Spec]) -> Vec<IndexedFunction> {
    let (lo, hi) = m.range("gloss").expect("planned with a gloss range");
    vec![(format!("{}_gloss_to_normal_length", m.name), vec![(lo, hi)])]
}

/// The form of gloss_length refitted (minimax, no end pins) on the material's gloss range.
fn length_build(mat: &MaterialSpec, inputs: &Inputs) -> Result<Pieces, BuildError> {
    let material = mat.name.as_str();
    let (lo, hi) = mat.range("gloss").expect("planned with a gloss range");
    let function = format!("{material}_gloss_to_normal_length");
    let spec = inputs.spec("gloss_length")?;
    let general = spec.model.as_ref().expect("fit specs carry a model");
    let model_inputs: Vec<String> = general.features[..general.n_inputs].to_vec();
    let m = RationalModel::new(ModelParts {
        inputs: model_inputs,
        derived: general.derived.clone(),
        numerator: general.numerator.clone(),
        denominator: general.denominator.clone(),
        lead: general.lead.clone(),
        offset: general.offset,
        factor: general.factor.clone(),
        fixed: general.fixed.clone(),
        pins: vec![],
        clamp: general.clamp,
    })
    .map_err(|source| SceneError::Model { material: material.to_string(), function: function.clone(), source: Box::new(source) })?;
    let ax = &spec.file.axis[0];
    let n = ax.count;
    let x: Vec<Vec<f64>> = (0..n).map(|i| vec![lo + (hi - lo) * i as f64 / (n - 1) as f64]).collect();
    let y: Vec<f64> = x.iter().map(|p| gloss::length_from_gloss(p[0])).collect();
    let objective = spec.file.fit.as_ref().map_or(Objective::Minimax, |f| f.objective);
    let f = fit::fit(&m, &Data { x, y }, &FitOptions { objective, ..FitOptions::default() }, &function)?;
    let nv = ax.verify_count();
    let vx: Vec<f64> = (0..nv).map(|i| lo + (hi - lo) * i as f64 / (nv - 1) as f64).collect();
    let truth: Vec<f64> = vx.iter().map(|&g| gloss::length_from_gloss(g)).collect();
    let ours: Vec<f64> = vx.iter().map(|&g| m.eval_clamped(&f.coefficients, &[g])).collect();
    let general_err = committed::fit_coefficients(spec, inputs.generated)
        .ok()
        .map(|c| max_err(&truth, &vx.iter().map(|&g| general.eval_clamped(&c, &[g])).collect::<Vec<_>>()));
    let length = SceneFunction {
        name: function,
        args: vec![ax.name.clone()],
        domain: vec![(lo, hi)],
        record: json!({"what": "gloss_length form refitted on the material's gloss range", "range": [lo, hi], "points": nv,
            "max_abs_error": max_err(&truth, &ours), "general_fit_max_abs_error": general_err}),
        model: m,
        coefficients: f.coefficients,
    };
    Ok(Pieces { functions: vec![length], constants: vec![] })
}

#[cfg(test)]
mod tests {
    use crate::scene::{plan, scene_functions, Feature, Scene};

    fn features() -> Vec<&'static Feature> {
        crate::family::families().iter().flat_map(|f| f.scene_features.iter()).collect()
    }

    fn load(features_line: &str, params: &str) -> Result<Scene, crate::spec::SpecError> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.toml");
        std::fs::write(&p, format!("name = \"t\"\n[[material]]\nname = \"m\"\nfeatures = {features_line}\nparams = {{ {params} }}\n"))
            .unwrap();
        Scene::load(&p, &features())
    }

    #[test]
    fn a_gloss_range_refits_the_length_a_fixed_gloss_does_not() {
        let s = load("[\"gloss_mips\", \"gloss_combine\"]", "gloss = [0.3, 0.9]").unwrap();
        let p = plan(&s);
        assert_eq!(p.nodes, ["gloss_combine_lut", "gloss_inverse_table"]);
        assert_eq!(scene_functions(&s, &[]), [("m_gloss_to_normal_length".to_string(), vec![(0.3, 0.9)])]);
        let p = plan(&load("[\"gloss_mips\"]", "gloss = 0.5").unwrap());
        assert_eq!(p.nodes, ["gloss_inverse_table", "gloss_length"]);
        assert!(p.special.is_empty());
    }

    #[test]
    fn parameters_belong_to_the_material_features() {
        let e = load("[\"gloss_combine\"]", "gloss = 0.5").unwrap_err().to_string();
        assert!(e.contains("not a parameter"), "{e}");
        let e = load("[\"glossy\"]", "").unwrap_err().to_string();
        assert!(e.contains("unknown feature 'glossy'") && e.contains("gloss_mips"), "{e}");
    }
}
