//! The one reader of committed fits outside the build itself: the fits (`kind = "fit"`) and
//! coefficient fields (`kind = "fields"`) in generated/json that validation, figures and scenes
//! measure beside their own numbers.
//!
//! Every read goes through the build's own committed readers ([`super::committed_fit`],
//! [`super::fields::committed`]), which check the JSON against its spec's input hash and model:
//! a JSON written for another version of its spec is an error here, never a silently different
//! fit. Callers that only report a committed fit when there is one take `.ok()`.

use super::{committed_fit, fields, BuildError};
use crate::fit::RationalModel;
use crate::spec::{Catalog, Kind, Spec};
use nalgebra::DVector;
use std::path::{Path, PathBuf};

/// Where the spec NAME of the outputs in `generated` lives: `fits/NAME.toml` beside
/// `generated/` (the path its committed JSON names).
pub fn spec_path(generated: &Path, name: &str) -> PathBuf {
    generated.parent().unwrap_or(Path::new("")).join("fits").join(format!("{name}.toml"))
}

/// The spec NAME of the outputs in `generated` (see [`spec_path`]).
pub fn load_spec(generated: &Path, name: &str, catalog: &Catalog) -> Result<Spec, BuildError> {
    Ok(Spec::load(&spec_path(generated, name), catalog)?)
}

fn expect_kind(spec: &Spec, kind: Kind, expected: &'static str) -> Result<(), BuildError> {
    if spec.file.kind == kind {
        Ok(())
    } else {
        Err(BuildError::NotKind { spec: spec.file.name.clone(), expected })
    }
}

/// The committed f64 coefficients of the fit spec `spec` (generated/json/NAME.json under
/// `generated`), checked against the spec's hash and model.
pub fn fit_coefficients(spec: &Spec, generated: &Path) -> Result<DVector<f64>, BuildError> {
    expect_kind(spec, Kind::Fit, "fit")?;
    Ok(committed_fit(spec, generated)?.0)
}

/// A committed fit with its spec, evaluated through the spec's model.
#[derive(Debug, Clone)]
pub struct Refit {
    pub spec: Spec,
    pub coefficients: DVector<f64>,
}

impl Refit {
    /// The committed fit NAME: `fits/NAME.toml` and generated/json/NAME.json.
    pub fn load(generated: &Path, name: &str, catalog: &Catalog) -> Result<Refit, BuildError> {
        let spec = load_spec(generated, name, catalog)?;
        let coefficients = fit_coefficients(&spec, generated)?;
        Ok(Refit { spec, coefficients })
    }

    pub fn model(&self) -> &RationalModel {
        self.spec.model.as_ref().expect("fit specs carry a model")
    }

    /// The fit at `x` (the spec's axes, in order), with the model's clamp.
    pub fn eval(&self, x: &[f64]) -> f64 {
        self.model().eval_clamped(&self.coefficients, x)
    }
}

/// A committed two-stage fit: the coefficient functions outer point → c_k, in f64, through
/// the spec's model and per-coefficient offsets.
#[derive(Debug, Clone)]
pub struct Fields {
    fields: Vec<(RationalModel, DVector<f64>)>,
}

impl Fields {
    /// The committed fields of the spec `spec` (generated/json/NAME.json under `generated`).
    pub fn of(spec: &Spec, generated: &Path) -> Result<Fields, BuildError> {
        expect_kind(spec, Kind::Fields, "fields")?;
        let (coefficients, _) = fields::committed(spec, generated)?;
        let model = spec.model.as_ref().expect("fields specs carry a model");
        let offsets = &spec.file.fields.as_ref().expect("fields specs carry [fields]").offsets;
        let fields = offsets
            .iter()
            .zip(coefficients)
            .map(|(&offset, c)| {
                let mut m = model.clone();
                m.offset = offset;
                (m, c)
            })
            .collect();
        Ok(Fields { fields })
    }

    /// The committed fields NAME: `fits/NAME.toml` and generated/json/NAME.json.
    pub fn load(generated: &Path, name: &str, catalog: &Catalog) -> Result<Fields, BuildError> {
        Fields::of(&load_spec(generated, name, catalog)?, generated)
    }

    /// c_0 … c_k at an outer point (the spec's outer axes, in order).
    pub fn eval(&self, outer: &[f64]) -> Vec<f64> {
        self.fields.iter().map(|(m, c)| m.eval_full(c, outer)).collect()
    }
}
