//! What every hand-written module kind of a family (helpers emitted as WGSL/Rust with a JSON
//! of provenance and errors) builds its output from.

use super::{compact_json, spec_rel_path, Built, Verification};
use crate::emit::{Artifact, GENERATOR};
use crate::spec::Spec;
use serde_json::{json, Value};

/// The provenance every module JSON of a family's module kind starts with; the caller adds its own keys.
pub fn module_json(spec: &Spec, hash: &str, kind: &str) -> serde_json::Map<String, Value> {
    let v = json!({
        "generator": GENERATOR,
        "spec": spec_rel_path(spec),
        "input_hash": hash,
        "name": spec.file.name,
        "kind": kind,
        "quantity": spec.file.quantity,
        "description": spec.file.description,
        "function_prefix": spec.file.emit.function,
    });
    match v {
        Value::Object(m) => m,
        _ => unreachable!("a JSON object literal"),
    }
}

/// A module's three files (WGSL, Rust, JSON) with its pooled max and rms error over `points`.
pub fn module_built(name: &str, wgsl: String, rust: String, json: serde_json::Map<String, Value>, points: usize, max: f64, rms: f64) -> Built {
    Built {
        name: name.to_string(),
        artifacts: vec![
            Artifact { path: format!("wgsl/{name}.wgsl").into(), contents: wgsl.into_bytes() },
            Artifact { path: format!("src/{name}.rs").into(), contents: rust.into_bytes() },
            Artifact { path: format!("json/{name}.json").into(), contents: (compact_json(&Value::Object(json)) + "\n").into_bytes() },
        ],
        verification: Verification { points, max_abs_error: max, rms_error: rms, worst_point: vec![], max_abs_error_f32: max, rms_error_f32: rms, max_abs_error_in_parameter: None },
        fit: None,
    }
}
