//! Quantity families: each module holds an integrand, its conventions and its reference
//! evaluator. This file is the registry the CLI and the spec layer look quantities up in.

pub mod fuzz;
pub mod gloss;
pub mod skin;

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
}

/// A quantity `shadefit eval` serves and specs sample.
#[derive(Debug)]
pub struct QuantityDef {
    pub name: &'static str,
    pub doc: &'static str,
    /// Canonical parameters, in the order `eval` receives them.
    pub params: &'static [ParamSpec],
    /// Alternative parameters: (spec, conversion to the canonical parameter of the same index).
    pub aliases: &'static [(ParamSpec, usize, fn(f64) -> f64)],
    /// Evaluate at canonical parameters (already inside the domain) to an absolute tolerance.
    pub eval: fn(&[f64], f64) -> Estimate,
    /// For 1-D quantities: the inverse map value → parameter, used to report a fit's error in
    /// parameter units (e.g. gloss recovered from a fitted length).
    pub inverse: Option<fn(f64) -> f64>,
    /// Vector-valued quantities (e.g. RGB): channel names and the evaluator of all channels.
    /// Their `eval` returns channel 0; specs do not take them yet.
    pub channels: &'static [&'static str],
    pub eval_channels: Option<fn(&[f64], f64) -> Vec<Estimate>>,
    /// For two-stage fits (`kind = "fields"`): the linear basis in the quantity's trailing
    /// ("inner") parameters whose coefficients become fields over the leading ones.
    pub basis: Option<&'static InnerBasis>,
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

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum QuantityError {
    #[error("unknown quantity '{0}' (known: {1})")]
    Unknown(String, String),
    #[error("{quantity}: unknown parameter '{param}' (expected {expected})")]
    UnknownParam { quantity: String, param: String, expected: String },
    #[error("{quantity}: missing parameter '{param}'")]
    MissingParam { quantity: String, param: String },
    #[error("{quantity}: parameter '{param}' = {value} is outside its domain [{min}, {max}]")]
    OutOfDomain { quantity: String, param: String, value: f64, min: f64, max: f64 },
    #[error("{quantity}: parameter '{param}' = {value} must be a whole number")]
    NotInteger { quantity: String, param: String, value: f64 },
    #[error("{quantity}: parameter '{param}' is given twice (directly or through an alias)")]
    Duplicate { quantity: String, param: String },
}

fn gloss_length(p: &[f64], _tol: f64) -> Estimate {
    // Closed form (see gloss.rs); its error is rounding only: ≤ 4 ulps of a value ≤ 1.
    Estimate { value: gloss::length_from_gloss(p[0]), error: 4.0 * f64::EPSILON, evals: 1 }
}

fn gloss_from_length(p: &[f64], _tol: f64) -> Estimate {
    // Bisection to one ulp of g; the inverse amplifies L's rounding by 1/(dL/dg) ≤ 1e5.
    Estimate { value: gloss::gloss_from_length(p[0]), error: 1e5 * 4.0 * f64::EPSILON, evals: 64 }
}

fn gloss_combine(p: &[f64], _tol: f64) -> Estimate {
    Estimate { value: gloss::combine(p[0], p[1]), error: 1e5 * 8.0 * f64::EPSILON, evals: 130 }
}

fn fuzz_ps(p: &[f64], tol: f64) -> Estimate {
    fuzz::ps(p[0], p[1], p[2], p[3], tol)
}

/// Eq. 1 of the Ghost of Tsushima supplemental: P̃_s = c0 + c1 (u·n) + c2 (u·t) + c3 (u·n)² +
/// c4 (u·n)(u·t) + c5 (u·t)², over the light direction (θu, φu) at fixed (α, θf).
static FUZZ_PS_EQ1: InnerBasis = InnerBasis {
    inner: 2,
    args: &["n_dot_u", "t_dot_u"],
    arg_domain: &[(-1.0, 1.0), (-1.0, 1.0)],
    terms: &["1", "n_dot_u", "t_dot_u", "n_dot_u^2", "n_dot_u*t_dot_u", "t_dot_u^2"],
    to_args: fuzz_ps_args,
    sample: fuzz_ps_sample,
    range: (0.0, 1.0),
};

fn fuzz_ps_args(outer: &[f64], inner: &[f64]) -> Vec<f64> {
    let (st, ct) = outer[1].sin_cos();
    let (su, cu) = inner[0].sin_cos();
    vec![cu, su * inner[1].cos() * st + cu * ct]
}

fn fuzz_ps_sample(outer: &[f64], inner: &[Vec<f64>], tol: f64) -> Vec<Estimate> {
    let dirs: Vec<(f64, f64)> = inner.iter().map(|d| (d[0], d[1])).collect();
    fuzz::ps_directions(outer[0], outer[1], &dirs, tol)
}

fn fuzz_g(p: &[f64], tol: f64) -> Estimate {
    // Canonical order (mu_v, d), the emitted function's (n_dot_v, density).
    fuzz::g(p[1], p[0], tol)
}

fn fuzz_q(p: &[f64], _tol: f64) -> Estimate {
    // 2·E₃(d) from the series / continued fraction: a few ulps (tested against quadrature).
    Estimate { value: fuzz::q_exact(p[0]), error: 8.0 * f64::EPSILON, evals: 1 }
}

fn fuzz_r(p: &[f64], tol: f64) -> Estimate {
    fuzz::r(p[0], p[1], tol)
}

fn skin_channels(r: Result<[Estimate; 3], skin::ProfileError>) -> Vec<Estimate> {
    // The default profile is valid and the arguments are inside the domain, so the only
    // error left would be a bug: report it as NaN with infinite error rather than panic.
    r.map(|e| e.to_vec()).unwrap_or_else(|_| vec![Estimate { value: f64::NAN, error: f64::INFINITY, evals: 0 }; 3])
}

fn skin_tolerance(tol: f64) -> crate::integrate::Tolerance {
    crate::integrate::Tolerance { abs: tol.min(skin::DEFAULT_TOLERANCE.abs), ..skin::DEFAULT_TOLERANCE }
}

fn skin_punctual_rgb(p: &[f64], tol: f64) -> Vec<Estimate> {
    let profile = skin::default_skin_profile();
    skin_channels(skin::punctual(&profile, skin::Kernel::Linear, p[0], p[1], skin_tolerance(tol)))
}

fn skin_punctual(p: &[f64], tol: f64) -> Estimate {
    skin_punctual_rgb(p, tol)[0]
}

fn skin_sh_rgb(p: &[f64], tol: f64) -> Vec<Estimate> {
    let profile = skin::default_skin_profile();
    skin_channels(skin::sh_band(&profile, p[0], p[1] as u32, skin_tolerance(tol)))
}

fn skin_sh(p: &[f64], tol: f64) -> Estimate {
    skin_sh_rgb(p, tol)[0]
}

const CURVATURE: ParamSpec =
    ParamSpec { name: "curvature", min: 0.0, max: 100.0, doc: "curvature (1/mm)", integer: false };

const HALF_PI: f64 = std::f64::consts::FRAC_PI_2;
const ALPHA: ParamSpec = ParamSpec { name: "alpha", min: 0.01, max: 1.0, doc: "SGGX fiber alpha", integer: false };
const THETA_F: ParamSpec = ParamSpec { name: "theta_f", min: 0.0, max: HALF_PI, doc: "fiber polar angle (rad)", integer: false };
const DENSITY: ParamSpec = ParamSpec { name: "d", min: 0.0, max: 50.0, doc: "fuzz density (optical thickness)", integer: false };

const GLOSS: ParamSpec = ParamSpec { name: "gloss", min: 0.0, max: 1.0, doc: "gloss g", integer: false };

static REGISTRY: &[QuantityDef] = &[
    QuantityDef {
        name: "skin-punctual",
        doc: "pre-integrated skin diffusion for a punctual light (linear profile on a ring), RGB",
        params: &[CURVATURE, ParamSpec { name: "n_dot_l", min: -1.0, max: 1.0, doc: "n·l", integer: false }],
        aliases: &[],
        eval: skin_punctual,
        inverse: None,
        channels: &["red", "green", "blue"],
        basis: None,
        eval_channels: Some(skin_punctual_rgb),
    },
    QuantityDef {
        name: "skin-sh",
        doc: "per-band factor scaling clamped-cosine SH irradiance by skin scattering (sphere), RGB",
        params: &[CURVATURE, ParamSpec { name: "band", min: 0.0, max: 2.0, doc: "SH band l", integer: true }],
        aliases: &[],
        eval: skin_sh,
        inverse: None,
        channels: &["red", "green", "blue"],
        basis: None,
        eval_channels: Some(skin_sh_rgb),
    },
    QuantityDef {
        name: "fuzz-ps",
        doc: "fraction of light the fuzz layer scatters toward the base layer, P_s(u)",
        params: &[
            ALPHA,
            THETA_F,
            ParamSpec { name: "theta_u", min: 0.0, max: std::f64::consts::PI, doc: "light polar angle (rad)", integer: false },
            ParamSpec {
                name: "phi_u",
                min: -std::f64::consts::PI,
                max: 2.0 * std::f64::consts::PI,
                doc: "light azimuth from the fiber azimuth (rad)",
                integer: false,
            },
        ],
        aliases: &[],
        eval: fuzz_ps,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: Some(&FUZZ_PS_EQ1),
    },
    QuantityDef {
        name: "fuzz-g",
        doc: "hemispherical average G(d, mu_v) of the single-scattering fuzz layer",
        params: &[ParamSpec { name: "mu_v", min: 0.0, max: 1.0, doc: "n·v", integer: false }, DENSITY],
        aliases: &[],
        eval: fuzz_g,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fuzz-q",
        doc: "cosine-weighted average penetration Q(d) = 2 E3(d)",
        params: &[DENSITY],
        aliases: &[],
        eval: fuzz_q,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "fuzz-r",
        doc: "cosine-weighted average of P_s over the hemisphere, R(alpha, theta_f)",
        params: &[ALPHA, THETA_F],
        aliases: &[],
        eval: fuzz_r,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "gloss-length",
        doc: "GGX average (shortened) normal length for a gloss, or for a GGX alpha",
        params: &[GLOSS],
        aliases: &[(
            // α at gloss 1 is sqrt(2/262145) = 0.00276213059566896…; the bound sits just below it
            // and the converted gloss is clamped to 1.
            ParamSpec { name: "alpha", min: 0.0027621305956689, max: 1.0, doc: "GGX alpha", integer: false },
            0,
            gloss::gloss_from_alpha,
        )],
        eval: gloss_length,
        inverse: Some(gloss::gloss_from_length),
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "gloss-from-length",
        doc: "gloss whose GGX average normal length is `length` (clamped to the table ends)",
        params: &[ParamSpec { name: "length", min: 0.0, max: 1.0, doc: "normal length", integer: false }],
        aliases: &[],
        eval: gloss_from_length,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
    QuantityDef {
        name: "gloss-combine",
        doc: "gloss of two combined glosses (Reoriented Normal Mapping of their NDFs)",
        params: &[
            ParamSpec { name: "x", min: 0.0, max: 1.0, doc: "first gloss", integer: false },
            ParamSpec { name: "y", min: 0.0, max: 1.0, doc: "second gloss", integer: false },
        ],
        aliases: &[],
        eval: gloss_combine,
        inverse: None,
        channels: &[],
        eval_channels: None,
        basis: None,
    },
];

pub fn registry() -> &'static [QuantityDef] {
    REGISTRY
}

pub fn lookup(name: &str) -> Result<&'static QuantityDef, QuantityError> {
    REGISTRY.iter().find(|q| q.name == name).ok_or_else(|| {
        QuantityError::Unknown(
            name.to_string(),
            REGISTRY.iter().map(|q| q.name).collect::<Vec<_>>().join(", "),
        )
    })
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
            if !(value >= spec.min && value <= spec.max) {
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
            out[idx] = Some(canonical.clamp(self.params[idx].min, self.params[idx].max));
        }
        out.into_iter()
            .zip(self.params)
            .map(|(v, p)| {
                v.ok_or_else(|| QuantityError::MissingParam {
                    quantity: self.name.into(),
                    param: p.name.into(),
                })
            })
            .collect()
    }

    pub fn param_index(&self, name: &str) -> Option<usize> {
        self.params.iter().position(|p| p.name == name)
    }
}
