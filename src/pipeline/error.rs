//! The build's modes and errors.

use super::*;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Fit,
    Committed,
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{spec}: the f32 coefficients in generated/json/{spec}.json do not belong to its f64 coefficients: {why}; run `shadefit build`")]
    F32Coefficients { spec: String, why: String },
    #[error(transparent)]
    Fit(#[from] fit::FitError),
    #[error("{spec}: generated/json/{spec}.json is missing or unreadable ({why}); run `shadefit build`")]
    NoCommitted { spec: String, why: String },
    #[error("{spec}: the spec changed since generated/json/{spec}.json was written (hash {committed} ≠ {current}); run `shadefit build`")]
    SpecChanged { spec: String, committed: String, current: String },
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Write(#[from] crate::emit::WriteError),
    #[error("{spec}: the f32 code returns a non-finite value at {at:?}")]
    NonFinite { spec: String, at: Vec<f64> },
    #[error(transparent)]
    Spec(#[from] crate::spec::SpecError),
    /// A spec input a family's builder rejects (e.g. a diffusion profile it cannot integrate).
    #[error("{spec}: {msg}")]
    Input { spec: String, msg: String },
    /// A committed file read as a kind its spec is not.
    #[error("{spec}: not a spec of kind = \"{expected}\"")]
    NotKind { spec: String, expected: &'static str },
    #[error("{spec}: the emitted f32 code's max abs error {measured:e} exceeds the spec's max_error {bound:e}")]
    ErrorBound { spec: String, measured: f64, bound: f64 },
    #[error("{spec}: no builder for kind = \"{kind}\"")]
    UnknownKind { spec: String, kind: String },
    /// A module's translation to another target (`--target`, `[emit] targets`).
    #[error(transparent)]
    Target(#[from] crate::emit::targets::TargetError),
}

/// Errors of a scene's own build (its specialisations), beyond those of the specs it reads.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene reaches or reads a spec that `fits/` does not have.
    #[error("scene {scene} needs fits/{spec}.toml")]
    MissingSpec { scene: String, spec: String },
    /// A linear system of a material's specialisation has no solution.
    #[error("{material}: the {system} is singular")]
    Singular { material: String, system: String },
    /// A specialisation's model could not be formed (e.g. a general fit's form without its pins).
    #[error("{material}: cannot form the model of {function}")]
    Model {
        material: String,
        function: String,
        #[source]
        source: Box<crate::fit::model::ModelError>,
    },
}
