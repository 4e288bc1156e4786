//! A published form offered for refitting: the form written once as a [`Program`] (its f64 and
//! f32 evaluation and its shader text derive from it), its published constants, the domain its
//! arguments are clamped to, the refit (the same form with new constants, fitted against the
//! integral the form approximates) and the measure of any constants against that integral.
//!
//! Families register their forms in their descriptor; a spec of `kind = "refit"` names the
//! forms it refits, the build runs each form's refit once (`Mode::Fit`) and commits the
//! constants in its JSON, and everything else — the emitted code, `validate`, figures and
//! benchmarks — reads the committed constants (`pipeline::refit`).

use super::expr::program::Program;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A published form, registered by a family.
pub struct PublishedForm {
    /// The name a refit spec's `forms` gives it (unique among every family's forms).
    pub name: &'static str,
    /// The emitted function's name after the spec's prefix: `PREFIX_FUNCTION`.
    pub function: &'static str,
    /// The emitted function's doc line (what it computes, its arguments' convention).
    pub doc: &'static str,
    /// The emitted function's arguments, in the program's input order.
    pub args: &'static [&'static str],
    /// The box the emitted code clamps its arguments to (NaN → the lower end): where the refit
    /// was fitted.
    pub domain: &'static [(f64, f64)],
    /// The form as a program (its constants are the program's `k(j)`), from which its emitted
    /// function derives; `None` for a form the expression IR cannot write yet (its refit is
    /// committed and measured like the others, and the module says it has no function).
    pub program: Option<fn() -> &'static Program>,
    /// The published constants, in the program's order.
    pub published: fn() -> Vec<f64>,
    /// Specs whose committed outputs the refit and the measure read (e.g. a simulated table the
    /// form approximates): their `fits/NAME.toml` texts enter the refit spec's input hash, and
    /// their JSON is read from the generated folder being built.
    pub reads: &'static [&'static str],
    /// The refit: deterministic, from the form, its integral and the committed outputs of
    /// `reads` in the generated folder given; `Err` says what is missing.
    pub refit: fn(&Path) -> Result<Vec<f64>, String>,
    /// The errors of the published constants (first) and of refitted ones (second, as the
    /// emitted code carries them: f32 values) against the integral, one row per grid measured.
    pub measure: fn(&Path, &[f64], &[f64]) -> Result<Vec<FormError>, String>,
    /// A check the refitted constants must pass before they are emitted (e.g. a denominator
    /// proven positive on the clamp box): named figures for the JSON, or why they fail.
    pub check: Option<fn(&[f64]) -> Result<Vec<(String, f64)>, String>>,
}

impl std::fmt::Debug for PublishedForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PublishedForm").field("name", &self.name).field("function", &self.function).finish_non_exhaustive()
    }
}

/// Max and rms |error| over a grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Errors {
    pub max_abs_error: f64,
    pub rms_error: f64,
}

/// A form's errors on one grid: the published constants' and the refit's, side by side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FormError {
    /// The form as its source names it (e.g. "Karis 2014 EnvBRDFApprox").
    pub form: String,
    /// The grid and the integral measured against.
    pub grid: String,
    pub points: usize,
    pub published: Errors,
    pub refit: Errors,
}

/// Round every constant to f32 (what the emitted code carries), back in f64.
pub fn as_emitted(p: &[f64]) -> Vec<f64> {
    p.iter().map(|&v| v as f32 as f64).collect()
}
