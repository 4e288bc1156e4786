//! The cone model's helpers as shader code: the spec kind `ggx-occlusion`
//! (`fits/ggx_occlusion.toml`), one WGSL library and one Rust module of exact formulas (no fit):
//!
//! - `F_interreflected_visibility(visibility, albedo)`: A / (1 − ρ + ρA) ([`super::interreflected`]);
//! - `F_cone_of_visibility(visibility)`: cos θc = sqrt(1 − V) ([`super::cone_of_visibility`]);
//! - `F_adjusted_cone_printed(cos_cone, gloss, n_dot_v)` and `F_adjusted_cone_corrected(…)`: the
//!   talk's adjusted cone as printed and in its corrected reading ([`super::cod_adjust_printed`],
//!   [`super::cod_adjust_corrected`]).
//!
//! Inputs are clamped to [0, 1] (NaN → 0). The interreflection denominator is 1 − ρ(1 − A) ≥ A,
//! zero only at A = 0, ρ = 1, where the function returns 0 (its value along A = 0). The error
//! recorded is the f32 code's (the Rust module, same operations as the WGSL) against the f64
//! formulas on a grid of every argument; `Mode::Committed` reads it from the committed JSON.

use super::super::published::emit::module_spec_file;
use crate::emit::lang::Lang;
use crate::pipeline::module::{module_built, module_json};
use crate::emit::header_lines;
use crate::family::SpecKind;
use crate::pipeline::{BuildError, Built, Mode, committed_json_with_hash, fmt_err, input_hash, spec_rel_path};
use crate::fit::expr::Expr;
use crate::fit::expr::program::{Program, build::*};
use crate::spec::{KindDef, Spec, SpecError, SpecFile};
use serde_json::json;
use std::path::Path;

pub const KIND: &str = "ggx-occlusion";

/// The spec kind (registered in the family's descriptor).
pub const OCCLUSION: SpecKind = SpecKind {
    spec: KindDef {
        name: KIND,
        spec_file,
        samples_note: "{name} emits exact formulas of the cone model: it has no samples",
        input_hash,
    },
    build,
    shard: None,
};

/// For `Spec::parse`: the common spec of an occlusion-helpers spec, or `None`.
pub fn spec_file(path: &Path, text: &str) -> Result<Option<SpecFile>, SpecError> {
    let axes = ["alpha", "n_dot_v", "cos_cone"].map(|a| json!({"name": a, "range": [0.0, 1.0], "count": 2})).to_vec();
    module_spec_file(path, text, KIND, axes)
}

/// One helper: name suffix, arguments, its doc, its shader form over the clamped arguments
/// (bound to `x0, x1, …`; the WGSL, the Rust and the f32 evaluation of the recorded error all
/// derive from it), and the f64 formula it is measured against.
struct Helper {
    suffix: &'static str,
    args: &'static [&'static str],
    doc: &'static str,
    result: fn() -> Expr,
    exact: fn(&[f64]) -> f64,
}

impl Helper {
    fn form(&self) -> Program {
        Program { lets: (0..self.args.len()).map(|i| (format!("x{i}"), var(i))).collect(), result: (self.result)() }
    }
}

/// (1 − x)⁴ or x⁴ as the helpers write it: four factors multiplied left to right.
fn fourth(x: impl Fn() -> Expr) -> Expr {
    x() * x() * x() * x()
}

const HELPERS: [Helper; 4] = [
    Helper {
        suffix: "interreflected_visibility",
        args: &["visibility", "albedo"],
        doc: "Visibility after interreflections inside the cavity, A′ = A / (1 − ρ + ρA) (COD: WWII).",
        result: || bind(0) / max(lit(1.0) - bind(1) + bind(1) * bind(0), lit(1e-30)),
        exact: |p| if p[0] == 0.0 { 0.0 } else { super::interreflected(p[0], p[1]) },
    },
    Helper {
        suffix: "cone_of_visibility",
        args: &["visibility"],
        doc: "Cosine of the visibility cone's half-angle, cos θc = sqrt(1 − V) (the Nusselt analog).",
        result: || sqrt(lit(1.0) - bind(0)),
        exact: |p| super::cone_of_visibility(p[0]),
    },
    Helper {
        suffix: "adjusted_cone_printed",
        args: &["cos_cone", "gloss", "n_dot_v"],
        doc: "The talk's adjusted cone as printed: cos θ (1 − g²)(1 − (1 − (n·v)⁴)) = cos θ (1 − g²)(n·v)⁴.",
        result: || bind(0) * (lit(1.0) - bind(1) * bind(1)) * (lit(1.0) - (lit(1.0) - fourth(|| bind(2)))),
        exact: |p| super::cod_adjust_printed(p[0], p[1], p[2]),
    },
    Helper {
        suffix: "adjusted_cone_corrected",
        args: &["cos_cone", "gloss", "n_dot_v"],
        doc: "The adjusted cone in the reading that opens it at grazing views: cos θ (1 − g²)(1 − (1 − n·v)⁴).",
        result: || bind(0) * (lit(1.0) - bind(1) * bind(1)) * (lit(1.0) - fourth(|| lit(1.0) - bind(2))),
        exact: |p| super::cod_adjust_corrected(p[0], p[1], p[2]),
    },
];

/// Max |f32 − f64| of each helper over 65 points per argument in [0, 1], and the point count.
fn measure() -> (Vec<f64>, usize) {
    let axis: Vec<f64> = (0..=64).map(|i| i as f64 / 64.0).collect();
    let mut points = 0;
    let errs = HELPERS
        .iter()
        .map(|h| {
            let (n, form) = (h.args.len(), h.form());
            let total = axis.len().pow(n as u32);
            points += total;
            (0..total)
                .map(|mut k| {
                    let p: Vec<f64> = (0..n).map(|_| {
                        let v = axis[k % axis.len()];
                        k /= axis.len();
                        v
                    }).collect();
                    // The grid is inside [0, 1], so the emitted clamps leave it as it is.
                    let p32: Vec<f32> = p.iter().map(|&v| v as f32).collect();
                    let q: Vec<f64> = p32.iter().map(|&v| v as f64).collect();
                    (form.eval_f32(&p32, &[])[0] as f64 - (h.exact)(&q)).abs()
                })
                .fold(0.0f64, f64::max)
        })
        .collect();
    (errs, points)
}

fn build(spec: &Spec, mode: Mode, root: &Path) -> Result<Built, BuildError> {
    let name = spec.file.name.clone();
    let prefix = spec.file.emit.function.clone();
    let hash = input_hash(spec);
    let (errs, points) = match mode {
        Mode::Fit => measure(),
        Mode::Committed => {
            let v = committed_json_with_hash(root, spec, &hash)?;
            let bad = |why: &str| BuildError::NoCommitted { spec: name.clone(), why: why.into() };
            let errs = v["functions"]
                .as_array()
                .ok_or_else(|| bad("no \"functions\""))?
                .iter()
                .map(|f| f["max_abs_error_f32"].as_f64().ok_or_else(|| bad("no max_abs_error_f32")))
                .collect::<Result<Vec<f64>, _>>()?;
            let points = v["points"].as_u64().ok_or_else(|| bad("no points"))? as usize;
            if errs.len() != HELPERS.len() {
                return Err(bad("one entry per helper expected"));
            }
            (errs, points)
        }
    };
    let max = errs.iter().copied().fold(0.0f64, f64::max);
    let err_line = format!("max abs {} (f32 code against the exact formulas in f64, {points} points over [0, 1] per argument)", fmt_err(max));
    let header = header_lines(&spec_rel_path(spec), &hash, &err_line);
    let doc = [
        "Specular occlusion by a visibility cone (COD: WWII): visibility after interreflections, the",
        "equivalent cone, and the talk's adjusted cone as printed and corrected. Exact formulas;",
        "inputs clamped to [0, 1] (NaN -> 0).",
    ];
    let render = |lang: Lang| {
        let mut s = lang.preamble(&header, &name, &doc);
        for (h, e) in HELPERS.iter().zip(&errs) {
            let c = lang.comment();
            s += &format!("\n{c} {}\n{c} f32 code against the formula: max abs {}.\n", h.doc, fmt_err(*e));
            s += &lang.signature(&format!("{prefix}_{}", h.suffix), h.args, 1);
            s += &h.form().render(lang.syntax(), &|i| lang.clamp(&name, h.args[i], 0.0, 1.0), &[], &|_| unreachable!("no constants"));
            s += "}\n";
        }
        s
    };
    let mut json = module_json(spec, &hash, KIND);
    json.insert("points".into(), points.into());
    json.insert(
        "functions".into(),
        HELPERS.iter().zip(&errs).map(|(h, e)| json!({"function": format!("{prefix}_{}", h.suffix), "args": h.args, "max_abs_error_f32": e})).collect::<Vec<_>>().into(),
    );
    // Exact formulas: the only error is the f32 code's (rms not measured).
    Ok(module_built(&name, render(Lang::Wgsl), render(Lang::Rust), json, points, max, 0.0))
}

#[cfg(test)]
mod tests {
    use shadefit_runtime::ggx_occlusion as g;

    #[test]
    fn emitted_helpers_equal_the_formulas_and_are_finite_everywhere() {
        // Each is a handful of f32 operations on values in [0, 1] (sqrt correctly rounded):
        // within a few ulps of 1, 1e-6 absolute, of the f64 formula at the same f32 inputs;
        // except the interreflection at A → 0, ρ → 1, where the denominator ~A and the value
        // is an exact ratio to relative 2⁻²³ of a result ≤ 1.
        let axis: Vec<f32> = (0..=32).map(|i| i as f32 / 32.0).collect();
        for &a in &axis {
            for &b in &axis {
                let (x, y) = (a as f64, b as f64);
                let want = if x == 0.0 { 0.0 } else { super::super::interreflected(x, y) };
                assert!((g::ggx_cone_interreflected_visibility(a, b) as f64 - want).abs() < 1e-6, "({a}, {b})");
                for &c in &axis {
                    let z = c as f64;
                    assert!((g::ggx_cone_adjusted_cone_printed(a, b, c) as f64 - super::super::cod_adjust_printed(x, y, z)).abs() < 1e-6);
                    assert!((g::ggx_cone_adjusted_cone_corrected(a, b, c) as f64 - super::super::cod_adjust_corrected(x, y, z)).abs() < 1e-6);
                }
            }
            assert!((g::ggx_cone_cone_of_visibility(a) as f64 - super::super::cone_of_visibility(a as f64)).abs() < 1e-6);
        }
        for s in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 2.0, f32::MAX] {
            assert!(g::ggx_cone_interreflected_visibility(s, s).is_finite());
            assert!(g::ggx_cone_cone_of_visibility(s).is_finite());
            assert!(g::ggx_cone_adjusted_cone_printed(s, 0.5, s).is_finite());
            assert!(g::ggx_cone_adjusted_cone_corrected(s, s, s).is_finite());
        }
        // NaN is the lower end; A = 0 with white walls is 0, not 0/0.
        assert_eq!(g::ggx_cone_cone_of_visibility(f32::NAN), 1.0);
        assert_eq!(g::ggx_cone_interreflected_visibility(0.0, 1.0), 0.0);
    }
}
