//! Quantities: what `shadefit eval` serves and specs sample. Each family declares its own
//! [`QuantityDef`]s (see `src/family/`); the spec layer looks them up in a `spec::Catalog`.

use crate::integrate::Estimate;
use std::collections::BTreeMap;

/// One named parameter of a quantity, with its closed domain.
#[derive(Debug, Clone, Copy)]
pub struct ParamSpec {
    pub name: &'static str,
    pub min: f64,
    pub max: f64,
    pub doc: &'static str,
    /// Only whole numbers are accepted (e.g. an SH band).
    pub integer: bool,
    /// The value `eval` uses when the parameter is not given (None: it must be given). Specs
    /// still name every parameter as an axis.
    pub default: Option<f64>,
    /// A value outside [min, max] where the quantity is defined as its limit (GGX's α = 0, the
    /// mirror), which `eval` and specs accept as well.
    pub limit: Option<f64>,
}

impl ParamSpec {
    /// Whether `v` is a value of the parameter: inside [min, max] or its limit (NaN is not).
    pub fn admits(&self, v: f64) -> bool {
        (v >= self.min && v <= self.max) || self.limit == Some(v)
    }
}

/// A quantity's evaluator at canonical parameters (already inside the domain) to an absolute
/// tolerance: a function, or a closure over a lobe read from a spec (`kind = "lobe"`).
pub type Eval = &'static (dyn Fn(&[f64], f64) -> Estimate + Sync);
/// A vector quantity's evaluator of every channel.
pub type EvalChannels = &'static (dyn Fn(&[f64], f64) -> Vec<Estimate> + Sync);

/// A quantity `shadefit eval` serves and specs sample.
pub struct QuantityDef {
    pub name: &'static str,
    pub doc: &'static str,
    /// Canonical parameters, in the order `eval` receives them.
    pub params: &'static [ParamSpec],
    /// Alternative parameters: (spec, conversion to the canonical parameter of the same index).
    pub aliases: &'static [(ParamSpec, usize, fn(f64) -> f64)],
    /// Evaluate at canonical parameters (already inside the domain) to an absolute tolerance.
    pub eval: Eval,
    /// For 1-D quantities: the inverse map value → parameter, used to report a fit's error in
    /// parameter units (e.g. the parameter recovered from a fitted value).
    pub inverse: Option<fn(f64) -> f64>,
    /// Vector-valued quantities (e.g. RGB): channel names and the evaluator of all channels.
    /// Their `eval` returns channel 0; a fit or table spec takes one (`channel`).
    pub channels: &'static [&'static str],
    pub eval_channels: Option<EvalChannels>,
    /// For two-stage fits (`kind = "fields"`): the linear basis in the quantity's trailing
    /// ("inner") parameters whose coefficients become fields over the leading ones.
    pub basis: Option<&'static InnerBasis>,
}

impl std::fmt::Debug for QuantityDef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("QuantityDef")
            .field("name", &self.name)
            .field("params", &self.params)
            .field("channels", &self.channels)
            .field("basis", &self.basis)
            .finish_non_exhaustive()
    }
}

/// A linear basis f(outer, inner) ≈ Σ_k c_k(outer) b_k(args(outer, inner)): the terms are
/// monomials in `args`, which the emitted evaluator takes as its arguments (clamped to
/// `arg_domain`).
#[derive(Debug)]
pub struct InnerBasis {
    /// How many trailing parameters are inner.
    pub inner: usize,
    /// Argument names of the emitted evaluator, e.g. `n_dot_u`, `t_dot_u`.
    pub args: &'static [&'static str],
    pub arg_domain: &'static [(f64, f64)],
    /// Basis terms (monomials in `args`), in coefficient order.
    pub terms: &'static [&'static str],
    /// (outer, inner) → args.
    pub to_args: fn(&[f64], &[f64]) -> Vec<f64>,
    /// The quantity at one outer point and many inner points, to an absolute tolerance
    /// (batched: per-outer-point set-up is shared).
    pub sample: fn(&[f64], &[Vec<f64>], f64) -> Vec<Estimate>,
    /// Range of the evaluator's output (the quantity's own bounds); the emitted code clamps.
    pub range: (f64, f64),
}

/// A number for a message: its shortest round-trip form, in exponent form below 1e-4 and from
/// 1e6 up (`1e-310`, not 310 decimals).
pub fn short_number(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() >= 1e6 || v.abs() < 1e-4) { format!("{v:e}") } else { format!("{v}") }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum QuantityError {
    #[error("unknown quantity '{0}' (known: {1})")]
    Unknown(String, String),
    #[error("{quantity}: unknown parameter '{param}' (expected {expected})")]
    UnknownParam { quantity: String, param: String, expected: String },
    #[error("{quantity}: missing parameter '{param}'")]
    MissingParam { quantity: String, param: String },
    #[error("{quantity}: parameter '{param}' = {} is outside its domain [{}, {}]", short_number(*value), short_number(*min), short_number(*max))]
    OutOfDomain { quantity: String, param: String, value: f64, min: f64, max: f64 },
    #[error("{quantity}: parameter '{param}' = {} must be a whole number", short_number(*value))]
    NotInteger { quantity: String, param: String, value: f64 },
    #[error("{quantity}: parameter '{param}' is given twice (directly or through an alias)")]
    Duplicate { quantity: String, param: String },
}

impl QuantityDef {
    /// Canonical parameter vector from named values: checks names, domains (NaN is outside
    /// every domain) and applies aliases.
    pub fn resolve(&self, named: &BTreeMap<String, f64>) -> Result<Vec<f64>, QuantityError> {
        let mut out: Vec<Option<f64>> = vec![None; self.params.len()];
        for (key, &value) in named {
            let (spec, idx, conv): (&ParamSpec, usize, Option<fn(f64) -> f64>) =
                if let Some(i) = self.params.iter().position(|p| p.name == key) {
                    (&self.params[i], i, None)
                } else if let Some((s, i, f)) = self.aliases.iter().find(|a| a.0.name == key) {
                    (s, *i, Some(*f))
                } else {
                    let mut names: Vec<&str> = self.params.iter().map(|p| p.name).collect();
                    names.extend(self.aliases.iter().map(|a| a.0.name));
                    return Err(QuantityError::UnknownParam {
                        quantity: self.name.into(),
                        param: key.clone(),
                        expected: names.join(", "),
                    });
                };
            if !spec.admits(value) {
                return Err(QuantityError::OutOfDomain {
                    quantity: self.name.into(),
                    param: key.clone(),
                    value,
                    min: spec.min,
                    max: spec.max,
                });
            }
            if spec.integer && value.fract() != 0.0 {
                return Err(QuantityError::NotInteger { quantity: self.name.into(), param: key.clone(), value });
            }
            if out[idx].is_some() {
                return Err(QuantityError::Duplicate { quantity: self.name.into(), param: key.clone() });
            }
            let canonical = conv.map_or(value, |f| f(value));
            let p = &self.params[idx];
            out[idx] = Some(if p.limit == Some(canonical) { canonical } else { canonical.clamp(p.min, p.max) });
        }
        out.into_iter()
            .zip(self.params)
            .map(|(v, p)| {
                v.or(p.default).ok_or_else(|| QuantityError::MissingParam {
                    quantity: self.name.into(),
                    param: p.name.into(),
                })
            })
            .collect()
    }
}
