//! Model forms: rational functions of named features,
//!
//!   f(x) = offset + factor(x) · P(x) / Q(x),   P = Σ a_j φ_j(x),   Q = lead(x) + Σ b_j ψ_j(x),
//!
//! (`lead` is the constant 1 unless the model names another term, as G̃'s d + c₂μ + c₃μ³ does)
//! over *features*: the inputs, then derived features, each a cos, sin or affine map of one
//! input (e.g. β = 1 − α, γ = cos θ_f, δ = sin θ_f).
//!
//! where every basis function φ_j, ψ_j is a *term*: a sum of monomials sharing one coefficient
//! (`"x^2 + y^2"` ties the coefficients of x² and y²; `"x*y"` is one monomial; `"1"` is the
//! constant). Constraints map the free parameters θ affinely onto the full coefficient vector
//! c = [a; b]:
//! - a fixed coefficient is a constant (`MGH09`'s numerator has no constant term);
//! - a pinned point f(x_k) = v_k is linear in c (P(x_k) = v'_k Q(x_k), v' = (v − offset)/factor),
//!   so it eliminates one numerator coefficient per pin by a K×K solve.
//!
//! So c = M θ + m₀, computed once; the Jacobian in θ is the Jacobian in c times M.

use nalgebra::{DMatrix, DVector};
use std::fmt;

/// A product of powers of features; `exps[i]` is the power of feature i.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Monomial {
    pub exps: Vec<u32>,
}

/// A sum of monomials with one shared coefficient.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Term {
    pub label: String,
    pub monomials: Vec<Monomial>,
}

/// The highest power of one feature in a monomial, as `rational(m,n)`'s highest degree: past it
/// the powers' columns of the fit are numerically dependent on [0, 1] (the Hilbert-like
/// matrix of degree 12 already has condition number ~1e16), and an unbounded power makes the
/// positivity proof's interval powers and the emitted code's products grow without limit.
pub const MAX_DEGREE: u32 = 12;

/// The most coefficients `rational(m,n)` may have, numerator and denominator together: in k
/// features its total-degree form has C(m+k, k) + C(n+k, k) − 1 of them, which grows fast with
/// k (3 features at degree 12: 909). One feature reaches 25 (`rational(12,12)`); 64 takes two
/// features to total degree 6 over 6 and three to 4 over 3. Past it the f32 re-optimisation's
/// coordinate sweeps (each coefficient's neighbours re-evaluated on every row: the cost grows
/// with the square of the count) and the emitted function's size grow without much use; a
/// model file chooses the terms of a larger model.
pub const MAX_TERMS: usize = 64;

/// Why `name` cannot name a feature in a model's terms (`None`: it can). Terms split on `+`,
/// `*` and `^`, trim spaces and read `1` as the constant, so a name holding one of those, an
/// empty name or one with surrounding spaces could never be written in a term.
pub fn check_feature_name(name: &str) -> Option<String> {
    let why = if name.is_empty() {
        "is empty".to_string()
    } else if name.trim() != name {
        "has leading or trailing spaces".to_string()
    } else if name == "1" {
        "is the constant term '1'".to_string()
    } else if let Some(c) = name.chars().find(|c| matches!(c, '+' | '*' | '^')) {
        format!("holds '{c}', an operator of terms (+, *, ^)")
    } else {
        return None;
    };
    Some(format!("cannot name a feature of a model: it {why}"))
}

/// Every feature name writable in terms ([`check_feature_name`]) and none given twice.
pub fn check_features(names: &[String]) -> Result<(), ModelError> {
    for (i, name) in names.iter().enumerate() {
        if let Some(why) = check_feature_name(name) {
            return Err(ModelError::BadFeature { name: name.clone(), why });
        }
        if names[..i].contains(name) {
            return Err(ModelError::BadFeature { name: name.clone(), why: "is given twice".into() });
        }
    }
    Ok(())
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ModelError {
    #[error("term '{term}': {why}")]
    BadTerm { term: String, why: String },
    #[error("feature '{name}' {why}")]
    BadFeature { name: String, why: String },
    #[error("'{0}' is not a model form: expected rational(m,n) or a model spec file")]
    BadForm(String),
    #[error("{form} in {features} features has {count} coefficients, above the {MAX_TERMS} a form takes (a model file chooses its terms)")]
    TooManyTerms { form: String, features: usize, count: u128 },
    #[error("coefficient '{0}' named in a constraint is not a term of the model")]
    UnknownCoefficient(String),
    #[error("pin at {at:?}: {why}")]
    BadPin { at: Vec<f64>, why: String },
    #[error("the model has no free coefficient left after its constraints")]
    NoFreeParameter,
}

impl Term {
    /// Parse `"1"`, `"x"`, `"x^2*y"`, `"x^2 + y^2"` over the given feature names.
    pub fn parse(text: &str, features: &[String]) -> Result<Term, ModelError> {
        let bad = |why: String| ModelError::BadTerm { term: text.to_string(), why };
        let mut monomials = Vec::new();
        for mono in text.split('+') {
            let mono = mono.trim();
            if mono.is_empty() {
                return Err(bad("empty monomial".into()));
            }
            let mut exps = vec![0u32; features.len()];
            if mono != "1" {
                for factor in mono.split('*') {
                    let factor = factor.trim();
                    let (name, power) = match factor.split_once('^') {
                        Some((n, p)) => {
                            let p: u32 = p.trim().parse().map_err(|_| {
                                bad(format!("power '{}' is not a non-negative integer", p.trim()))
                            })?;
                            (n.trim(), p)
                        }
                        None => (factor, 1),
                    };
                    let i = features.iter().position(|f| f == name).ok_or_else(|| {
                        bad(format!("unknown feature '{name}' (features: {})", features.join(", ")))
                    })?;
                    // Checked before the sum, so that no power overflows it.
                    if power > MAX_DEGREE || exps[i] + power > MAX_DEGREE {
                        return Err(bad(format!(
                            "the power of '{name}' is {}, above the highest degree a model takes ({MAX_DEGREE})",
                            u64::from(exps[i]) + u64::from(power)
                        )));
                    }
                    exps[i] += power;
                }
            }
            monomials.push(Monomial { exps });
        }
        Ok(Term { label: text.trim().to_string(), monomials })
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        self.monomials
            .iter()
            .map(|m| m.exps.iter().zip(x).map(|(&e, &xi)| xi.powi(e as i32)).product::<f64>())
            .sum()
    }

    pub fn is_constant(&self) -> bool {
        self.monomials.len() == 1 && self.monomials[0].exps.iter().all(|&e| e == 0)
    }
}

impl fmt::Display for Term {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label)
    }
}

/// f(x_k) = value, eliminating numerator coefficient `eliminate`.
#[derive(Debug, Clone, PartialEq)]
pub struct Pin {
    pub at: Vec<f64>,
    pub value: f64,
    pub eliminate: usize,
}

/// A feature computed from one input.
#[derive(Debug, Clone, PartialEq)]
pub enum DerivedExpr {
    /// offset + scale · input
    Affine { input: usize, offset: f64, scale: f64 },
    Cos(usize),
    Sin(usize),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    pub name: String,
    pub expr: DerivedExpr,
}

impl Derived {
    /// Parse `cos(x)`, `sin(x)`, `x`, `-x`, `a - x`, `a + x`, `b*x`, `a + b*x`, `a - b*x` over
    /// `inputs`; the numbers a and b may be signed and carry exponents (`-0.5 + x`,
    /// `1e-3 - 2e+1*x`).
    pub fn parse(name: &str, text: &str, inputs: &[String]) -> Result<Derived, ModelError> {
        let bad = |why: &str| ModelError::BadTerm { term: format!("{name} = {text}"), why: why.into() };
        let input = |s: &str| {
            inputs
                .iter()
                .position(|i| i == s.trim())
                .ok_or_else(|| bad(&format!("'{}' is not an input (inputs: {})", s.trim(), inputs.join(", "))))
        };
        let t = text.trim();
        let expr = if let Some(arg) = t.strip_prefix("cos(").and_then(|r| r.strip_suffix(')')) {
            DerivedExpr::Cos(input(arg)?)
        } else if let Some(arg) = t.strip_prefix("sin(").and_then(|r| r.strip_suffix(')')) {
            DerivedExpr::Sin(input(arg)?)
        } else {
            // offset ± [scale *] input, or [scale *] input. The operator is the first + or −
            // after the first character (a leading one is the number's sign) that is not an
            // exponent's sign (`1e-3 + x`, `-0.5 - 2e+1*x`).
            let operator = t.char_indices().skip(1).find(|&(i, c)| (c == '+' || c == '-') && !t[..i].ends_with(['e', 'E'])).map(|(i, _)| i);
            let (offset, sign, rest) = match operator {
                Some(i) => {
                    let off: f64 = t[..i].trim().parse().map_err(|_| bad("offset is not a number"))?;
                    (off, if &t[i..i + 1] == "-" { -1.0 } else { 1.0 }, t[i + 1..].trim())
                }
                None => (0.0, 1.0, t),
            };
            // A bare input may carry a sign of its own (`-x`, `1 + -x`): scale ±1.
            let (scale, var) = match rest.split_once('*') {
                Some((a, v)) => (a.trim().parse::<f64>().map_err(|_| bad("scale is not a number"))?, v),
                None => match rest.strip_prefix('-') {
                    Some(v) => (-1.0, v),
                    None => (1.0, rest.strip_prefix('+').unwrap_or(rest)),
                },
            };
            DerivedExpr::Affine { input: input(var)?, offset, scale: sign * scale }
        };
        Ok(Derived { name: name.to_string(), expr })
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        match self.expr {
            DerivedExpr::Affine { input, offset, scale } => affine(offset, scale, x[input]),
            DerivedExpr::Cos(i) => x[i].cos(),
            DerivedExpr::Sin(i) => x[i].sin(),
        }
    }

    pub fn eval_f32(&self, x: &[f32]) -> f32 {
        match self.expr {
            DerivedExpr::Affine { input, offset, scale } => affine_f32(offset as f32, scale as f32, x[input]),
            DerivedExpr::Cos(i) => x[i].cos(),
            DerivedExpr::Sin(i) => x[i].sin(),
        }
    }

    /// Range over an interval of its input (exact: extrema of cos/sin included).
    pub fn range(&self, r: &[(f64, f64)]) -> (f64, f64) {
        use std::f64::consts::PI;
        let cos_range = |lo: f64, hi: f64| {
            let (a, b) = (lo.cos(), hi.cos());
            let mut out = (a.min(b), a.max(b));
            if ((lo / (2.0 * PI)).ceil() * 2.0 * PI) <= hi {
                out.1 = 1.0;
            }
            if (((lo - PI) / (2.0 * PI)).ceil() * 2.0 * PI + PI) <= hi {
                out.0 = -1.0;
            }
            out
        };
        match self.expr {
            DerivedExpr::Affine { input, offset, scale } => {
                let (a, b) = (affine(offset, scale, r[input].0), affine(offset, scale, r[input].1));
                (a.min(b), a.max(b))
            }
            DerivedExpr::Cos(i) => cos_range(r[i].0, r[i].1),
            DerivedExpr::Sin(i) => cos_range(r[i].0 - PI / 2.0, r[i].1 - PI / 2.0),
        }
    }
}

impl Derived {
    /// The definition over input names, e.g. `1 - alpha`, `cos(theta_f)`.
    pub fn describe(&self, inputs: &[String]) -> String {
        match self.expr {
            DerivedExpr::Affine { input, offset, scale } => format!("{offset} + {scale}*{}", inputs[input]),
            DerivedExpr::Cos(i) => format!("cos({})", inputs[i]),
            DerivedExpr::Sin(i) => format!("sin({})", inputs[i]),
        }
    }
}

/// offset + scale·x, rounded as the emitted code rounds it: the code writes `offset + x` for
/// a scale of 1 and `offset - x` for −1, and these are the same bits as offset + scale·x in
/// IEEE 754 (a product by ±1 is exact, and a − b is a + (−b), signed zeros included).
pub fn affine(offset: f64, scale: f64, x: f64) -> f64 {
    offset + scale * x
}

fn affine_f32(offset: f32, scale: f32, x: f32) -> f32 {
    offset + scale * x
}

/// Everything that defines a model, before its constraints are resolved.
#[derive(Debug, Clone, Default)]
pub struct ModelParts {
    /// Input names (the axes or data columns).
    pub inputs: Vec<String>,
    pub derived: Vec<Derived>,
    pub numerator: Vec<Term>,
    pub denominator: Vec<Term>,
    /// Denominator lead term (None: the constant 1).
    pub lead: Option<Term>,
    pub offset: f64,
    pub factor: Option<Term>,
    pub fixed: Vec<(usize, f64)>,
    pub pins: Vec<Pin>,
    pub clamp: Option<(f64, f64)>,
}

impl ModelParts {
    /// Feature names terms are parsed against: inputs, then derived features.
    pub fn features(&self) -> Vec<String> {
        self.inputs.iter().cloned().chain(self.derived.iter().map(|d| d.name.clone())).collect()
    }
}

/// A rational model with its constraints resolved into an affine parameter map.
#[derive(Debug, Clone)]
pub struct RationalModel {
    /// All features: inputs, then derived.
    pub features: Vec<String>,
    pub n_inputs: usize,
    pub derived: Vec<Derived>,
    pub numerator: Vec<Term>,
    /// Denominator terms with coefficients; the lead term (default 1) has none.
    pub denominator: Vec<Term>,
    pub lead: Option<Term>,
    pub offset: f64,
    pub factor: Option<Term>,
    pub fixed: Vec<(usize, f64)>,
    pub pins: Vec<Pin>,
    /// Clamp applied to the model output (clamp-aware objective).
    pub clamp: Option<(f64, f64)>,
    /// c = m · θ + m0.
    map: DMatrix<f64>,
    map0: DVector<f64>,
    free: Vec<usize>,
}

impl RationalModel {
    /// Plain 1-D rational(m, n) in feature `x`: numerator 1..x^m, denominator 1 + x..x^n.
    /// The feature must pass [`check_feature_name`] and m, n ≤ [`MAX_DEGREE`] (as
    /// [`RationalModel::parse_form`] checks).
    pub fn rational_1d(feature: &str, m: u32, n: u32) -> RationalModel {
        RationalModel::rational_total(&[feature.to_string()], m, n)
    }

    /// rational(m, n) of total degree in `features`: the numerator every monomial of total
    /// degree ≤ m (the constant first), the denominator 1 + every monomial of total degree
    /// 1..=n, each in [`total_degree_monomials`]'s order (in one feature: 1, x, …, x^m over
    /// 1 + x, …, x^n). The features must pass [`check_features`], m, n ≤ [`MAX_DEGREE`] and the
    /// coefficients number at most [`MAX_TERMS`] (as [`RationalModel::parse_form`] checks).
    pub fn rational_total(features: &[String], m: u32, n: u32) -> RationalModel {
        let terms = |lo, hi| -> Vec<Term> {
            total_degree_monomials(features.len(), lo, hi)
                .iter()
                .map(|e| Term::parse(&monomial_label(features, e), features).expect("valid term"))
                .collect()
        };
        let (numerator, denominator) = (terms(0, m), terms(1, n));
        RationalModel::new(ModelParts { inputs: features.to_vec(), numerator, denominator, ..ModelParts::default() })
            .expect("an unconstrained rational model is always valid")
    }

    /// Parse `rational(m,n)` (feature name given).
    pub fn parse_form(form: &str, feature: &str) -> Result<RationalModel, ModelError> {
        RationalModel::parse_form_over(form, &[feature.to_string()])
    }

    /// Parse `rational(m,n)` over one feature or several (degrees are total degrees, see
    /// [`RationalModel::rational_total`]).
    pub fn parse_form_over(form: &str, features: &[String]) -> Result<RationalModel, ModelError> {
        let f = form.trim();
        let inner = f
            .strip_prefix("rational(")
            .and_then(|s| s.strip_suffix(')'))
            .ok_or_else(|| ModelError::BadForm(form.to_string()))?;
        let (m, n) = inner.split_once(',').ok_or_else(|| ModelError::BadForm(form.to_string()))?;
        let m: u32 = m.trim().parse().map_err(|_| ModelError::BadForm(form.to_string()))?;
        let n: u32 = n.trim().parse().map_err(|_| ModelError::BadForm(form.to_string()))?;
        if m > MAX_DEGREE || n > MAX_DEGREE {
            return Err(ModelError::BadForm(format!("{form} (degrees above {MAX_DEGREE} are not supported)")));
        }
        check_features(features)?;
        let count = monomials_up_to(features.len(), m) + monomials_up_to(features.len(), n) - 1;
        if count > MAX_TERMS as u128 {
            return Err(ModelError::TooManyTerms { form: f.to_string(), features: features.len(), count });
        }
        Ok(RationalModel::rational_total(features, m, n))
    }

    pub fn new(parts: ModelParts) -> Result<RationalModel, ModelError> {
        let features = parts.features();
        let ModelParts { inputs, derived, numerator, denominator, lead, offset, factor, fixed, pins, clamp } = parts;
        let lead_is_one = lead.as_ref().is_none_or(|t| t.is_constant() && t.monomials.len() == 1);
        if lead_is_one && let Some(t) = denominator.iter().find(|t| t.is_constant()) {
            return Err(ModelError::BadTerm {
                term: t.label.clone(),
                why: "the denominator's constant term is fixed to 1; list only its other terms".into(),
            });
        }
        let nn = numerator.len();
        let nfull = nn + denominator.len();
        let eliminated: Vec<usize> = pins.iter().map(|p| p.eliminate).collect();
        let free: Vec<usize> = (0..nfull)
            .filter(|i| !fixed.iter().any(|f| f.0 == *i) && !eliminated.contains(i))
            .collect();
        if free.is_empty() {
            return Err(ModelError::NoFreeParameter);
        }
        let mut model = RationalModel {
            features,
            n_inputs: inputs.len(),
            derived,
            numerator,
            denominator,
            lead: if lead_is_one { None } else { lead },
            offset,
            factor,
            fixed,
            pins,
            clamp,
            map: DMatrix::zeros(nfull, free.len()),
            map0: DVector::zeros(nfull),
            free,
        };
        for p in &model.pins {
            if model.fixed.iter().any(|f| f.0 == p.eliminate) || p.eliminate >= nn {
                return Err(ModelError::BadPin {
                    at: p.at.clone(),
                    why: "must eliminate a numerator coefficient that is not fixed".into(),
                });
            }
            let fac = model.factor.as_ref().map_or(1.0, |t| t.eval(&model.extend(&p.at)));
            if fac == 0.0 || !fac.is_finite() {
                return Err(ModelError::BadPin { at: p.at.clone(), why: "the factor is zero or not finite there".into() });
            }
        }
        let theta0 = DVector::zeros(model.free.len());
        let base = model.full_from_free_uncached(&theta0)?;
        for j in 0..model.free.len() {
            let mut e = theta0.clone();
            e[j] = 1.0;
            let col = model.full_from_free_uncached(&e)? - &base;
            model.map.set_column(j, &col);
        }
        model.map0 = base;
        Ok(model)
    }

    fn full_from_free_uncached(&self, theta: &DVector<f64>) -> Result<DVector<f64>, ModelError> {
        let nn = self.numerator.len();
        let mut c = DVector::zeros(nn + self.denominator.len());
        for (j, &i) in self.free.iter().enumerate() {
            c[i] = theta[j];
        }
        for &(i, v) in &self.fixed {
            c[i] = v;
        }
        let k = self.pins.len();
        if k == 0 {
            return Ok(c);
        }
        let mut a = DMatrix::zeros(k, k);
        let mut rhs = DVector::zeros(k);
        for (r, pin) in self.pins.iter().enumerate() {
            let at = self.extend(&pin.at);
            let fac = self.factor.as_ref().map_or(1.0, |t| t.eval(&at));
            let v = (pin.value - self.offset) / fac;
            let q = self.lead_at(&at)
                + self.denominator.iter().enumerate().map(|(j, t)| c[nn + j] * t.eval(&at)).sum::<f64>();
            let mut s = v * q;
            for (j, t) in self.numerator.iter().enumerate() {
                if let Some(col) = self.pins.iter().position(|p| p.eliminate == j) {
                    a[(r, col)] = t.eval(&at);
                } else {
                    s -= c[j] * t.eval(&at);
                }
            }
            rhs[r] = s;
        }
        let sol = a.lu().solve(&rhs).ok_or_else(|| ModelError::BadPin {
            at: self.pins[0].at.clone(),
            why: "the pins do not determine the eliminated coefficients (singular system)".into(),
        })?;
        for (col, pin) in self.pins.iter().enumerate() {
            c[pin.eliminate] = sol[col];
        }
        Ok(c)
    }

    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    pub fn n_full(&self) -> usize {
        self.numerator.len() + self.denominator.len()
    }

    /// Full coefficients [a; b] from free parameters θ.
    pub fn full(&self, theta: &DVector<f64>) -> DVector<f64> {
        &self.map * theta + &self.map0
    }

    pub fn map(&self) -> &DMatrix<f64> {
        &self.map
    }

    pub fn map0(&self) -> &DVector<f64> {
        &self.map0
    }

    /// Labels of the full coefficients, e.g. `num[x^2]`, `den[x]`.
    pub fn coefficient_labels(&self) -> Vec<String> {
        self.numerator
            .iter()
            .map(|t| format!("num[{t}]"))
            .chain(self.denominator.iter().map(|t| format!("den[{t}]")))
            .collect()
    }

    /// Inputs followed by the derived features.
    pub fn extend(&self, x: &[f64]) -> Vec<f64> {
        let mut v = x[..self.n_inputs].to_vec();
        v.extend(self.derived.iter().map(|d| d.eval(x)));
        v
    }

    /// The denominator's lead term at extended features.
    pub fn lead_at(&self, xe: &[f64]) -> f64 {
        self.lead.as_ref().map_or(1.0, |t| t.eval(xe))
    }

    /// Basis values of one point (inputs only; derived features are computed here).
    pub fn basis(&self, x: &[f64]) -> Basis {
        let xe = self.extend(x);
        Basis {
            phi: self.numerator.iter().map(|t| t.eval(&xe)).collect(),
            psi: self.denominator.iter().map(|t| t.eval(&xe)).collect(),
            lead: self.lead_at(&xe),
            factor: self.factor.as_ref().map_or(1.0, |t| t.eval(&xe)),
        }
    }

    /// Unclamped value at a point, from full coefficients.
    pub fn eval_full(&self, c: &DVector<f64>, x: &[f64]) -> f64 {
        self.basis(x).value(c, self.offset)
    }

    /// Value with the model's clamp applied.
    pub fn eval_clamped(&self, c: &DVector<f64>, x: &[f64]) -> f64 {
        let v = self.eval_full(c, x);
        match self.clamp {
            Some((lo, hi)) => v.clamp(lo, hi),
            None => v,
        }
    }

    /// Denominator Q at a point.
    pub fn denominator_at(&self, c: &DVector<f64>, x: &[f64]) -> f64 {
        self.basis(x).pq(c).1
    }
}

/// The exponents of every monomial in `k` features of total degree `lo..=hi`: by degree, and
/// within one degree the first feature's power highest first, then the second's, … (in (a, b)
/// at degree 2: a², a·b, b²).
pub fn total_degree_monomials(k: usize, lo: u32, hi: u32) -> Vec<Vec<u32>> {
    // Every exponent vector of k entries summing to d, in that order, appended to `out`.
    fn of_degree(k: usize, d: u32, prefix: &mut Vec<u32>, out: &mut Vec<Vec<u32>>) {
        if k == 0 {
            if d == 0 {
                out.push(prefix.clone());
            }
            return;
        }
        for e in (0..=d).rev() {
            prefix.push(e);
            of_degree(k - 1, d - e, prefix, out);
            prefix.pop();
        }
    }
    let mut out = Vec::new();
    for d in lo..=hi {
        of_degree(k, d, &mut Vec::with_capacity(k), &mut out);
    }
    out
}

/// The number of monomials in `k` features of total degree ≤ `d`, C(d + k, k) (saturating at
/// `u128::MAX`).
fn monomials_up_to(k: usize, d: u32) -> u128 {
    // C(d + i, i) = C(d + i − 1, i − 1)·(d + i)/i, exact at each step.
    let mut c: u128 = 1;
    for i in 1..=k as u128 {
        c = match c.checked_mul(u128::from(d) + i) {
            Some(v) => v / i,
            None => return u128::MAX,
        };
    }
    c
}

/// A monomial written as a term: `1`, `a`, `a^2*b`.
fn monomial_label(features: &[String], exps: &[u32]) -> String {
    let factors: Vec<String> = features
        .iter()
        .zip(exps)
        .filter(|&(_, &e)| e > 0)
        .map(|(f, &e)| if e == 1 { f.clone() } else { format!("{f}^{e}") })
        .collect();
    if factors.is_empty() { "1".to_string() } else { factors.join("*") }
}

/// Precomputed basis values at one sample.
#[derive(Debug, Clone)]
pub struct Basis {
    pub phi: Vec<f64>,
    pub psi: Vec<f64>,
    pub lead: f64,
    pub factor: f64,
}

impl Basis {
    pub fn pq(&self, c: &DVector<f64>) -> (f64, f64) {
        let nn = self.phi.len();
        let p: f64 = self.phi.iter().enumerate().map(|(j, v)| c[j] * v).sum();
        let q: f64 = self.lead + self.psi.iter().enumerate().map(|(j, v)| c[nn + j] * v).sum::<f64>();
        (p, q)
    }

    pub fn value(&self, c: &DVector<f64>, offset: f64) -> f64 {
        let (p, q) = self.pq(c);
        offset + self.factor * p / q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names that terms could never write are refused as features, naming why, and so is a
    /// name given twice; ordinary column names (upper case, digits, spaces inside) pass and
    /// parse back as their own monomial.
    #[test]
    fn features_must_be_writable_in_terms() {
        for (bad, why) in [("", "is empty"), (" x", "spaces"), ("1", "constant"), ("x^2", "'^'"), ("a*b", "'*'"), ("a + b", "'+'")] {
            let e = check_feature_name(bad).unwrap_or_else(|| panic!("{bad:?} passed"));
            assert!(e.contains(why), "{bad:?}: {e}");
            assert!(RationalModel::parse_form("rational(1,1)", bad).is_err(), "{bad:?}");
        }
        for good in ["x", "X", "2", "n dot v", "alpha_t"] {
            assert_eq!(check_feature_name(good), None, "{good:?}");
            let t = Term::parse(&format!("{good}^2"), &[good.to_string()]).unwrap();
            assert_eq!(t.monomials, vec![Monomial { exps: vec![2] }], "{good:?}");
        }
        let twice = check_features(&["a".into(), "b".into(), "a".into()]).unwrap_err().to_string();
        assert_eq!(twice, "feature 'a' is given twice");
    }

    /// A feature's power in a monomial is at most MAX_DEGREE, written at once or as a product
    /// (so no sum of powers overflows); MAX_DEGREE itself parses.
    #[test]
    fn powers_above_the_highest_degree_are_refused() {
        let f = vec!["x".to_string(), "y".to_string()];
        assert_eq!(Term::parse("x^12*y^12", &f).unwrap().monomials[0].exps, vec![12, 12]);
        for bad in ["x^13", "x^99999", "x^4294967295", "x^12*x", "x^7*y*x^6", "x^4294967295*x^4294967295"] {
            let e = Term::parse(bad, &f).unwrap_err().to_string();
            assert!(e.contains("above the highest degree a model takes (12)"), "{bad}: {e}");
        }
    }

    /// offset + scale·x, on values exact in binary (so the expected sums are exact in f64 and
    /// f32 alike); and for scales ±1, the bits of the emitted forms `offset + x` and
    /// `offset - x` on values whose sums round, signed zeros included.
    #[test]
    fn affine_is_offset_plus_scale_times_x() {
        for (o, s, x, want) in [(0.5, 1.0, 0.25, 0.75), (0.5, -1.0, 0.25, 0.25), (0.5, 2.0, 0.25, 1.0), (-1.0, -0.5, 3.0, -2.5)] {
            assert_eq!(affine(o, s, x), want, "{o} + {s}·{x}");
            assert_eq!(affine_f32(o as f32, s as f32, x as f32), want as f32, "{o} + {s}·{x} (f32)");
        }
        for (o, x) in [(1.0, 0.1), (0.3, 1e-17), (-0.0, 0.0), (0.0, 0.0), (-0.0, -0.0), (1e300, -1e300), (0.7, 2f64.powi(-1074))] {
            assert_eq!(affine(o, 1.0, x).to_bits(), (o + x).to_bits(), "{o} + {x}");
            assert_eq!(affine(o, -1.0, x).to_bits(), (o - x).to_bits(), "{o} - {x}");
            let (of, xf) = (o as f32, x as f32);
            assert_eq!(affine_f32(of, 1.0, xf).to_bits(), (of + xf).to_bits(), "{of} + {xf} (f32)");
            assert_eq!(affine_f32(of, -1.0, xf).to_bits(), (of - xf).to_bits(), "{of} - {xf} (f32)");
        }
    }

    /// A derived feature's definition as the fit reports print it (`describe`) parses back to
    /// the same feature, and its f32 evaluation (the emitted arithmetic) is its value. Values
    /// by hand at α = 0.25, θ = π/3: 1 − α = 0.75, 0.5 + 3α = 1.25, 2α = 0.5, α, cos θ = ½,
    /// sin θ = √3/2.
    #[test]
    fn derived_features_describe_themselves_and_evaluate_in_f32() {
        let inputs = vec!["alpha".to_string(), "theta".to_string()];
        let x = [0.25, std::f64::consts::PI / 3.0];
        let xf = x.map(|v| v as f32);
        let cases = [
            ("1 - alpha", 0.75),
            ("0.5 + 3*alpha", 1.25),
            ("2*alpha", 0.5),
            ("alpha", 0.25),
            ("cos(theta)", 0.5),
            ("sin(theta)", 3f64.sqrt() / 2.0),
        ];
        for (text, want) in cases {
            let d = Derived::parse("d", text, &inputs).unwrap();
            let described = d.describe(&inputs);
            assert_eq!(Derived::parse("d", &described, &inputs), Ok(d.clone()), "{text} described as {described:?}");
            // f64: exact for the affine maps (binary values), libm's cos/sin of the f64 π/3
            // within a few ulps of 1.
            assert!((d.eval(&x) - want).abs() <= 4.0 * f64::EPSILON, "{text}: {}", d.eval(&x));
            // f32: θ rounded to f32 moves cos/sin by ≤ ½ ulp of π/3 (slope ≤ 1), plus the f32
            // functions' own ulp or two; the affine maps are exact on these values.
            let got = d.eval_f32(&xf) as f64;
            assert!((got - want).abs() <= 3.0 * f32::EPSILON as f64, "{text}: f32 {got}, want {want}");
        }
    }

    /// `rational(m,n)` (the CLI's `fit --model`): numerator terms 1, x, …, x^m and
    /// denominator terms x, …, x^n (its constant fixed to 1), labelled as the reports list
    /// the coefficients; degrees up to 12 in either place, 13 refused, malformed forms refused.
    #[test]
    fn rational_forms_parse_to_their_degrees() {
        let m = RationalModel::parse_form(" rational(2, 1) ", "x").unwrap();
        assert_eq!(m.coefficient_labels(), ["num[1]", "num[x]", "num[x^2]", "den[x]"]);
        // (1 + 2x + 3x²)/(1 + 4x) at x = 0.5: 2.75 / 3, the coefficients in label order.
        let full = DVector::from_vec(vec![1.0, 2.0, 3.0, 4.0]);
        // A handful of roundings of values below 3.
        assert!((m.eval_full(&full, &[0.5]) - 2.75 / 3.0).abs() <= 1e-15);
        assert_eq!(RationalModel::parse_form("rational(12,12)", "x").unwrap().coefficient_labels().len(), 13 + 12);
        for form in ["rational(13,0)", "rational(0,13)", "rational(13,13)", "rational(2)", "rational(a,1)", "poly(2,1)", "rational(2,1"] {
            assert!(matches!(RationalModel::parse_form(form, "x"), Err(ModelError::BadForm(_))), "{form}");
        }
    }

    /// `rational(2,2)` in two features (total degree): the numerator is the C(4, 2) = 6
    /// monomials of degree ≤ 2, the denominator 1 and the 5 of degree 1..2, listed here by
    /// hand; each term is its one monomial. The value at (a, b) = (2, 3) with coefficients
    /// 1..11 is the polynomials summed by hand: (1 + 2·2 + 3·3 + 4·4 + 5·6 + 6·9) /
    /// (1 + 7·2 + 8·3 + 9·4 + 10·6 + 11·9) = 114/234, exact in binary up to the one division.
    #[test]
    fn total_degree_forms_in_two_features() {
        let ab = vec!["a".to_string(), "b".to_string()];
        let m = RationalModel::parse_form_over("rational(2,2)", &ab).unwrap();
        let labels = |ts: &[Term]| ts.iter().map(|t| t.label.clone()).collect::<Vec<_>>();
        assert_eq!(labels(&m.numerator), ["1", "a", "b", "a^2", "a*b", "b^2"]);
        assert_eq!(labels(&m.denominator), ["a", "b", "a^2", "a*b", "b^2"]);
        let exps = |ts: &[Term]| ts.iter().map(|t| t.monomials.iter().map(|m| m.exps.clone()).collect::<Vec<_>>()).collect::<Vec<_>>();
        let want = [vec![0, 0], vec![1, 0], vec![0, 1], vec![2, 0], vec![1, 1], vec![0, 2]];
        assert_eq!(exps(&m.numerator), want.iter().map(|e| vec![e.clone()]).collect::<Vec<_>>());
        assert_eq!(exps(&m.denominator), want[1..].iter().map(|e| vec![e.clone()]).collect::<Vec<_>>());
        assert_eq!((m.n_inputs, m.n_free()), (2, 11));
        let c = DVector::from_iterator(11, (1..=11).map(f64::from));
        assert_eq!(m.eval_full(&c, &[2.0, 3.0]), 114.0 / 234.0);
        // In three features the counts are C(m + 3, 3): 4 and 10 at degrees 1 and 2.
        let abc = vec!["a".to_string(), "b".to_string(), "c".to_string()];
        let m = RationalModel::parse_form_over("rational(1,2)", &abc).unwrap();
        assert_eq!(labels(&m.numerator), ["1", "a", "b", "c"]);
        assert_eq!(labels(&m.denominator), ["a", "b", "c", "a^2", "a*b", "a*c", "b^2", "b*c", "c^2"]);
    }

    /// One feature is the 1-D form exactly (the same terms in the same order); the cap on
    /// coefficients is C(m+k, k) + C(n+k, k) − 1 ≤ 64: two features at (6,6) have 28 + 27 = 55,
    /// at (7,6) 36 + 27 = 63, at (7,7) 36 + 35 = 71 (refused); 65 features at (1,0) have 66;
    /// the degree cap and the feature checks come first.
    #[test]
    fn total_degree_forms_keep_the_one_feature_form_and_cap_the_terms() {
        for (m, n) in [(0, 0), (2, 1), (3, 3), (12, 12)] {
            let a = RationalModel::parse_form_over(&format!("rational({m},{n})"), &["x".to_string()]).unwrap();
            let power = |p: u32| if p == 0 { "1".to_string() } else if p == 1 { "x".to_string() } else { format!("x^{p}") };
            let want: Vec<String> = (0..=m).map(|p| format!("num[{}]", power(p))).chain((1..=n).map(|p| format!("den[{}]", power(p)))).collect();
            assert_eq!(a.coefficient_labels(), want, "rational({m},{n})");
            assert_eq!(a.numerator, RationalModel::parse_form(&format!("rational({m},{n})"), "x").unwrap().numerator);
        }
        let ab = vec!["a".to_string(), "b".to_string()];
        assert_eq!(RationalModel::parse_form_over("rational(6,6)", &ab).unwrap().n_full(), 55);
        assert_eq!(RationalModel::parse_form_over("rational(7,6)", &ab).unwrap().n_full(), 63);
        let e = RationalModel::parse_form_over("rational(7,7)", &ab).unwrap_err();
        assert_eq!(e, ModelError::TooManyTerms { form: "rational(7,7)".into(), features: 2, count: 71 });
        let many: Vec<String> = (0..65).map(|i| format!("x{i}")).collect();
        assert!(matches!(RationalModel::parse_form_over("rational(1,0)", &many), Err(ModelError::TooManyTerms { count: 66, .. })));
        assert_eq!(RationalModel::parse_form_over("rational(1,0)", &many[..63]).unwrap().n_full(), 64);
        // The counts: C(4, 2) = 6, C(15, 3) = 455, C(1, 1) = 1; C(10012, 12) ≈ 2e39 is past
        // u128 (3.4e38) and saturates rather than wrapping.
        assert_eq!((monomials_up_to(2, 2), monomials_up_to(3, 12), monomials_up_to(1, 0)), (6, 455, 1));
        assert_eq!(monomials_up_to(10_000, 12), u128::MAX);
        assert!(matches!(RationalModel::parse_form_over("rational(13,1)", &ab), Err(ModelError::BadForm(_))));
        let twice = RationalModel::parse_form_over("rational(1,1)", &["a".into(), "a".into()]).unwrap_err();
        assert_eq!(twice.to_string(), "feature 'a' is given twice");
    }

    #[test]
    fn term_parsing_ties_monomials() {
        let feats = vec!["x".to_string(), "y".to_string()];
        let t = Term::parse("x^2 + y^2", &feats).unwrap();
        assert_eq!(t.eval(&[2.0, 3.0]), 13.0);
        let t = Term::parse("x*y^2", &feats).unwrap();
        assert_eq!(t.eval(&[2.0, 3.0]), 18.0);
        assert!(Term::parse("z", &feats).is_err());
        assert!(Term::parse("x^-1", &feats).is_err());
    }

    #[test]
    fn pins_hold_for_any_free_parameters() {
        let feats = vec!["x".to_string()];
        let num: Vec<Term> =
            ["1", "x", "x^2", "x^3"].iter().map(|s| Term::parse(s, &feats).unwrap()).collect();
        let den: Vec<Term> = ["x", "x^2"].iter().map(|s| Term::parse(s, &feats).unwrap()).collect();
        let pins = vec![
            Pin { at: vec![0.0], value: 0.5, eliminate: 0 },
            Pin { at: vec![1.0], value: 0.9, eliminate: 3 },
        ];
        let m = RationalModel::new(ModelParts {
            inputs: feats,
            numerator: num,
            denominator: den,
            pins,
            ..ModelParts::default()
        })
        .unwrap();
        assert_eq!(m.n_free(), 4);
        let theta = DVector::from_vec(vec![0.3, -1.2, 0.7, 2.5]);
        let c = m.full(&theta);
        // The map is exact up to rounding of a 2×2 solve on O(1) numbers.
        assert!((m.eval_full(&c, &[0.0]) - 0.5).abs() < 1e-14);
        assert!((m.eval_full(&c, &[1.0]) - 0.9).abs() < 1e-14);

        // With an offset, a factor and a lead term, at pins where the factor is 1.5 and 3
        // and the lead 1.25 and 5: the model is offset + factor·N/(lead + D).
        let feats = vec!["x".to_string()];
        let terms = |ts: &[&str]| ts.iter().map(|s| Term::parse(s, &feats).unwrap()).collect::<Vec<_>>();
        let m = RationalModel::new(ModelParts {
            inputs: feats.clone(),
            numerator: terms(&["1", "x", "x^2"]),
            denominator: terms(&["x"]),
            lead: Some(Term::parse("1 + x^2", &feats).unwrap()),
            offset: 0.25,
            factor: Some(Term::parse("1 + x", &feats).unwrap()),
            pins: vec![Pin { at: vec![0.5], value: 0.8, eliminate: 0 }, Pin { at: vec![2.0], value: -1.5, eliminate: 2 }],
            ..ModelParts::default()
        })
        .unwrap();
        assert_eq!(m.n_free(), 2);
        for theta in [[0.3, -1.2], [4.0, 0.01]] {
            let c = m.full(&DVector::from_vec(theta.to_vec()));
            for (x, v) in [(0.5, 0.8), (2.0, -1.5)] {
                let (n, q) = (c[0] + c[1] * x + c[2] * x * x, 1.0 + x * x + c[3] * x);
                // Rounding of a 2×2 solve on O(1) numbers, then of this evaluation.
                assert!((0.25 + (1.0 + x) * n / q - v).abs() < 1e-13, "pin at {x}: θ = {theta:?}");
            }
        }
    }

    /// `range` is the exact range of every kind of derived feature: it holds every value at
    /// 100001 points of the interval, and its ends are reached within the sampling's error
    /// (spacing ≤ 1.5e-4, so cos/sin at the nearest sample lie within (7.5e-5)²/2 ≈ 2.8e-9 of
    /// an interior extremum; affine ends are sampled exactly). Intervals inside one period, across one
    /// or both extrema, over several periods, and negative; and intervals in periods other than
    /// the first, where the extremum's position is the period index k ≠ 0 times 2π (plus π for
    /// cos's −1): cos −1 at −3π in [−10, −9], 1 at 2π in [6, 6.5], neither in [4, 5], [10.5,
    /// 11.5] or [20, 21]; sin −1 at 3π/2 in [4, 5] and 7π/2 in [10.5, 11.5], 1 at 13π/2 in
    /// [20, 21].
    #[test]
    fn derived_ranges_are_tight_against_dense_sampling() {
        let inputs = vec!["x".to_string()];
        let features = ["cos(x)", "sin(x)", "1 - 2*x", "0.5 + 3*x", "x"];
        let intervals = [
            (0.5, 5.5),
            (0.1, 1.5),
            (-0.5, 4.0),
            (2.0, 9.0),
            (-7.0, -6.0),
            (1.0, 1.0 + 1e-3),
            (-3.0, 12.0),
            (4.0, 5.0),
            (-10.0, -9.0),
            (6.0, 6.5),
            (10.5, 11.5),
            (20.0, 21.0),
        ];
        for text in features {
            let d = Derived::parse("d", text, &inputs).unwrap();
            for &(lo, hi) in &intervals {
                let (r0, r1) = d.range(&[(lo, hi)]);
                let v: Vec<f64> = (0..=100_000).map(|k| d.eval(&[lo + (hi - lo) * k as f64 / 100_000.0])).collect();
                let (v0, v1) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
                assert!(v0 >= r0 - 1e-12 && v1 <= r1 + 1e-12, "{text} on [{lo}, {hi}]: samples [{v0}, {v1}] outside [{r0}, {r1}]");
                assert!(v0 - r0 < 1e-8 && r1 - v1 < 1e-8, "{text} on [{lo}, {hi}]: range [{r0}, {r1}] wider than samples [{v0}, {v1}]");
            }
        }
    }

    #[test]
    fn derived_features_parse_and_bound() {
        let inputs = vec!["alpha".to_string(), "theta_f".to_string()];
        let b = Derived::parse("beta", "1 - alpha", &inputs).unwrap();
        assert_eq!(b.eval(&[0.25, 0.0]), 0.75);
        let g = Derived::parse("gamma", "cos(theta_f)", &inputs).unwrap();
        let r = g.range(&[(0.0, 1.0), (-0.5, 4.0)]);
        // cos over [-0.5, 4] reaches 1 at 0 and -1 at π.
        assert_eq!(r, (-1.0, 1.0));
        let d = Derived::parse("delta", "sin(theta_f)", &inputs).unwrap();
        let r = d.range(&[(0.0, 1.0), (0.1, 1.5)]);
        assert!((r.0 - 0.1f64.sin()).abs() < 1e-15 && (r.1 - 1.5f64.sin()).abs() < 1e-15);
        let e = Derived::parse("e", "2 + 3*alpha", &inputs).unwrap();
        assert_eq!(e.eval(&[1.0, 0.0]), 5.0);
        assert!(Derived::parse("z", "cos(phi)", &inputs).is_err());
    }

    /// Signed numbers parse in every place a number stands: a negative offset, a negative
    /// scale with no offset, exponents with either sign; and each such feature's description
    /// parses back to it. Values written out by hand.
    #[test]
    fn signed_and_exponent_numbers_parse_in_affine_features() {
        let inputs = vec!["alpha".to_string()];
        let affine = |input, offset, scale| DerivedExpr::Affine { input, offset, scale };
        for (text, want) in [
            ("-0.5 + alpha", affine(0, -0.5, 1.0)),
            ("-2*alpha", affine(0, 0.0, -2.0)),
            ("-2 * alpha", affine(0, 0.0, -2.0)),
            ("1e-3 + alpha", affine(0, 1e-3, 1.0)),
            ("1e-3*alpha", affine(0, 0.0, 1e-3)),
            ("2.5E-1 - 3e+0*alpha", affine(0, 0.25, -3.0)),
            ("-1 - alpha", affine(0, -1.0, -1.0)),
            ("1 + -4*alpha", affine(0, 1.0, -4.0)),
            ("-alpha", affine(0, 0.0, -1.0)),
            ("+alpha", affine(0, 0.0, 1.0)),
            ("1 + -alpha", affine(0, 1.0, -1.0)),
            ("0.5 - -alpha", affine(0, 0.5, 1.0)),
        ] {
            let d = Derived::parse("d", text, &inputs).unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_eq!(d.expr, want, "{text}");
            let described = d.describe(&inputs);
            assert_eq!(Derived::parse("d", &described, &inputs), Ok(d.clone()), "{text} described as {described:?}");
        }
        for bad in ["--alpha", "-beta", "1e + alpha", "alpha - 1"] {
            assert!(Derived::parse("d", bad, &inputs).is_err(), "{bad} parsed");
        }
    }

    /// `RationalModel::new` refuses each model it cannot resolve, with the error its docs
    /// name, and accepts the neighbours of each refused one:
    /// - a constant denominator term beside the implicit lead 1 (also when the lead is
    ///   written as `"1"`); beside a lead that is not 1 (`"1 + x^2"`, or `"x"`, one monomial
    ///   that is not constant) the constant term is a coefficient like any other, and that
    ///   lead is kept;
    /// - no free coefficient left, by fixing or by pinning;
    /// - a pin that eliminates a fixed coefficient or a denominator one, a pin where the
    ///   factor is 0 or overflows, and two pins at one point (a singular system).
    #[test]
    fn the_constructor_refuses_what_it_cannot_resolve() {
        let feats = vec!["x".to_string()];
        let term = |t: &str| Term::parse(t, &feats).unwrap();
        let terms = |ts: &[&str]| ts.iter().map(|t| term(t)).collect::<Vec<_>>();
        let parts = |num: &[&str], den: &[&str]| ModelParts {
            inputs: feats.clone(),
            numerator: terms(num),
            denominator: terms(den),
            ..ModelParts::default()
        };
        let pin = |at: f64, eliminate| Pin { at: vec![at], value: 0.5, eliminate };
        assert!(term("1").is_constant());
        assert!(!term("x").is_constant());
        assert!(!term("1 + x").is_constant());

        // The denominator's constant.
        for lead in [None, Some(term("1"))] {
            let err = RationalModel::new(ModelParts { lead: lead.clone(), ..parts(&["1"], &["1", "x"]) }).unwrap_err();
            assert!(matches!(&err, ModelError::BadTerm { term, .. } if term == "1"), "lead {lead:?}: {err}");
        }
        let one = RationalModel::new(ModelParts { lead: Some(term("1")), ..parts(&["1"], &["x"]) }).unwrap();
        assert_eq!((one.lead.clone(), one.lead_at(&[3.0])), (None, 1.0), "a lead of 1 is the implicit one");
        for lead in ["1 + x^2", "x"] {
            let m = RationalModel::new(ModelParts { lead: Some(term(lead)), ..parts(&["1"], &["1", "x"]) })
                .unwrap_or_else(|e| panic!("lead {lead}: {e}"));
            assert_eq!(m.lead.as_ref().map(|t| t.label.as_str()), Some(lead));
            // (1 + x²) or x, plus 1·b0 + x·b1, at x = 3 with b = (2, 0.5): 10 + 3.5, 3 + 3.5.
            let c = DVector::from_vec(vec![7.0, 2.0, 0.5]);
            let want_q = if lead == "x" { 6.5 } else { 13.5 };
            assert_eq!(m.denominator_at(&c, &[3.0]), want_q, "lead {lead}");
        }

        // No free coefficient.
        let all_fixed = RationalModel::new(ModelParts { fixed: vec![(0, 1.0), (1, 2.0)], ..parts(&["1"], &["x"]) });
        assert_eq!(all_fixed.unwrap_err(), ModelError::NoFreeParameter);
        let fixed_and_pinned = ModelParts { fixed: vec![(1, 2.0)], pins: vec![pin(0.5, 0)], ..parts(&["1", "x"], &[]) };
        assert_eq!(RationalModel::new(fixed_and_pinned).unwrap_err(), ModelError::NoFreeParameter);
        let one_left = ModelParts { fixed: vec![(1, 2.0)], pins: vec![pin(0.5, 0)], ..parts(&["1", "x"], &["x"]) };
        assert_eq!(RationalModel::new(one_left).unwrap().n_free(), 1);

        // Pins that cannot be resolved.
        let bad_pin = |p: ModelParts, why: &str| {
            let err = RationalModel::new(p).unwrap_err();
            assert!(matches!(&err, ModelError::BadPin { why: w, .. } if w.contains(why)), "{err} (want '{why}')");
        };
        bad_pin(ModelParts { fixed: vec![(0, 1.0)], pins: vec![pin(0.5, 0)], ..parts(&["1", "x"], &["x"]) }, "not fixed");
        bad_pin(ModelParts { pins: vec![pin(0.5, 2)], ..parts(&["1", "x"], &["x"]) }, "numerator coefficient");
        let with_factor = |at: f64| ModelParts { factor: Some(term("x^2")), pins: vec![pin(at, 0)], ..parts(&["1", "x"], &[]) };
        bad_pin(with_factor(0.0), "factor is zero");
        bad_pin(with_factor(1e200), "not finite");
        assert!(RationalModel::new(with_factor(2.0)).is_ok());
        bad_pin(ModelParts { pins: vec![pin(0.5, 0), pin(0.5, 1)], ..parts(&["1", "x", "x^2"], &[]) }, "singular");
        // The same pins at two points determine both coefficients: c0 + c1·x + c2·x² = 0.5 at
        // x = 0.5 and 2 for every c2.
        let two = RationalModel::new(ModelParts { pins: vec![pin(0.5, 0), pin(2.0, 1)], ..parts(&["1", "x", "x^2"], &[]) }).unwrap();
        for c2 in [0.0, 3.0] {
            let c = two.full(&DVector::from_vec(vec![c2]));
            for x in [0.5, 2.0] {
                // Rounding of a 2×2 solve on numbers below 12.
                assert!((two.eval_full(&c, &[x]) - 0.5).abs() <= 1e-14, "c2 = {c2}, x = {x}");
            }
        }
    }
}
