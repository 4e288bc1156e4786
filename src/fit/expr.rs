//! A small expression tree for emitted functions: built once from a fitted model, rendered
//! to WGSL and Rust, and evaluated in f32 here with the same operation order, so the error
//! shadefit measures is the error of the code it emits (up to FMA contraction on a GPU).

use crate::fit::model::{RationalModel, Term};
use nalgebra::DVector;

#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    Lit(f32),
    /// Index into the argument list (already clamped to the domain).
    Var(usize),
    /// (array, index): 0 = numerator array, 1 = denominator array.
    Coef(u8, usize),
    Add(Box<Expr>, Box<Expr>),
    Mul(Box<Expr>, Box<Expr>),
    Div(Box<Expr>, Box<Expr>),
}

use Expr::*;

fn add(a: Expr, b: Expr) -> Expr {
    Add(Box::new(a), Box::new(b))
}
fn mul(a: Expr, b: Expr) -> Expr {
    Mul(Box::new(a), Box::new(b))
}

/// Monomial as a product of variables (x^3 → x*x*x); constant → None.
fn monomial(exps: &[u32]) -> Option<Expr> {
    let mut out: Option<Expr> = None;
    for (i, &e) in exps.iter().enumerate() {
        for _ in 0..e {
            out = Some(match out {
                None => Var(i),
                Some(p) => mul(p, Var(i)),
            });
        }
    }
    out
}

fn term_expr(t: &Term) -> Option<Expr> {
    let mut out: Option<Expr> = None;
    let mut constant = 0.0f32;
    for m in &t.monomials {
        match monomial(&m.exps) {
            Some(e) => out = Some(match out {
                None => e,
                Some(p) => add(p, e),
            }),
            None => constant += 1.0,
        }
    }
    match (out, constant) {
        (None, c) => Some(Lit(c)),
        (Some(e), c) if c == 0.0 => Some(e),
        (Some(e), c) => Some(add(Lit(c), e)),
    }
}

/// If the terms are the powers start, start+1, … of one feature, return (feature, start).
fn consecutive_powers(terms: &[Term]) -> Option<(usize, u32)> {
    let first = terms.first()?;
    if first.monomials.len() != 1 {
        return None;
    }
    let nz: Vec<usize> = (0..first.monomials[0].exps.len()).collect();
    let var = if first.is_constant() {
        terms.get(1).and_then(|t| t.monomials[0].exps.iter().position(|&e| e > 0)).unwrap_or(0)
    } else {
        first.monomials[0].exps.iter().position(|&e| e > 0)?
    };
    let start = first.monomials[0].exps[var];
    for (k, t) in terms.iter().enumerate() {
        if t.monomials.len() != 1 {
            return None;
        }
        for &i in &nz {
            let want = if i == var { start + k as u32 } else { 0 };
            if t.monomials[0].exps[i] != want {
                return None;
            }
        }
    }
    Some((var, start))
}

/// Σ_j coef(array, j)·term_j, in Horner form for consecutive powers of one feature.
fn linear_combination(terms: &[Term], array: u8) -> Expr {
    if let Some((var, start)) = consecutive_powers(terms) {
        let n = terms.len();
        let mut e = Coef(array, n - 1);
        for j in (0..n - 1).rev() {
            e = add(Coef(array, j), mul(Var(var), e));
        }
        for _ in 0..start {
            e = mul(Var(var), e);
        }
        return e;
    }
    let mut out: Option<Expr> = None;
    for (j, t) in terms.iter().enumerate() {
        let e = match term_expr(t) {
            Some(Lit(c)) if c == 1.0 => Coef(array, j),
            Some(te) => mul(Coef(array, j), te),
            None => continue,
        };
        out = Some(match out {
            None => e,
            Some(p) => add(p, e),
        });
    }
    out.unwrap_or(Lit(0.0))
}

/// The emitted form of a rational model: offset + factor·P/Q (clamp applied by the caller).
pub fn model_expr(model: &RationalModel) -> Expr {
    let p = linear_combination(&model.numerator, 0);
    let lead = model.lead.as_ref().and_then(term_expr).unwrap_or(Lit(1.0));
    let q = if model.denominator.is_empty() { lead } else { add(lead, linear_combination(&model.denominator, 1)) };
    let mut e = Div(Box::new(p), Box::new(q));
    if let Some(f) = &model.factor
        && let Some(fe) = term_expr(f)
    {
        e = mul(fe, e);
    }
    if model.offset != 0.0 {
        e = add(Lit(model.offset as f32), e);
    }
    e
}

/// Coefficient arrays in f32: (numerator, denominator without the implicit 1).
pub fn f32_arrays(model: &RationalModel, c: &DVector<f64>) -> (Vec<f32>, Vec<f32>) {
    let nn = model.numerator.len();
    (
        (0..nn).map(|j| c[j] as f32).collect(),
        (0..model.denominator.len()).map(|j| c[nn + j] as f32).collect(),
    )
}

/// Evaluate in f32 with the emitted operation order.
pub fn eval_f32(e: &Expr, vars: &[f32], num: &[f32], den: &[f32]) -> f32 {
    match e {
        Lit(v) => *v,
        Var(i) => vars[*i],
        Coef(0, j) => num[*j],
        Coef(_, j) => den[*j],
        Add(a, b) => eval_f32(a, vars, num, den) + eval_f32(b, vars, num, den),
        Mul(a, b) => eval_f32(a, vars, num, den) * eval_f32(b, vars, num, den),
        Div(a, b) => eval_f32(a, vars, num, den) / eval_f32(b, vars, num, den),
    }
}

/// Render with language-specific names for variables, coefficients and literals. Parentheses
/// follow the tree exactly (a right operand of the same operator is bracketed), so the emitted
/// code evaluates in the order [`eval_f32`] does.
pub fn render(
    e: &Expr,
    var: &dyn Fn(usize) -> String,
    coef: &dyn Fn(u8, usize) -> String,
    lit: &dyn Fn(f32) -> String,
) -> String {
    let r = |x: &Expr| render(x, var, coef, lit);
    let wrap = |x: &Expr, when: bool| if when { format!("({})", r(x)) } else { r(x) };
    match e {
        Lit(v) => lit(*v),
        Var(i) => var(*i),
        Coef(a, j) => coef(*a, *j),
        Add(a, b) => format!("{} + {}", r(a), wrap(b, matches!(**b, Add(..)))),
        Mul(a, b) => format!(
            "{} * {}",
            wrap(a, matches!(**a, Add(..) | Div(..))),
            wrap(b, matches!(**b, Add(..) | Mul(..) | Div(..)))
        ),
        Div(a, b) => format!("({}) / ({})", r(a), r(b)),
    }
}

/// Sanitised f32 inputs extended with the model's derived features, as emitted code computes them.
pub fn features_f32(model: &RationalModel, x: &[f64], domain: &[(f32, f32)]) -> Vec<f32> {
    let mut v: Vec<f32> = x.iter().zip(domain).map(|(&v, &(lo, hi))| sanitize(v as f32, lo, hi)).collect();
    let derived: Vec<f32> = model.derived.iter().map(|d| d.eval_f32(&v)).collect();
    v.extend(derived);
    v
}

/// Clamp to [lo, hi] with NaN mapped to lo, in f32 (what emitted code does with inputs).
pub fn sanitize(x: f32, lo: f32, hi: f32) -> f32 {
    if x.is_nan() { lo } else { x.clamp(lo, hi) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rendering_keeps_the_tree_order() {
        // C * (x * y) and 1 + ((a + b) + c) must not be flattened into left-to-right chains.
        let e = mul(Coef(0, 0), mul(Var(0), Var(1)));
        let s = render(&e, &|i| format!("x{i}"), &|_, j| format!("c{j}"), &|v| format!("{v}"));
        assert_eq!(s, "c0 * (x0 * x1)");
        let e = add(Lit(1.0), add(add(Var(0), Var(1)), Var(2)));
        let s = render(&e, &|i| format!("x{i}"), &|_, j| format!("c{j}"), &|v| format!("{v}"));
        assert_eq!(s, "1 + (x0 + x1 + x2)");
    }

    /// The emitted tree evaluates the model for every shape of term: a constant, a lone
    /// variable, a power, a cross term, tied terms with and without a constant (1 + x, x + y²),
    /// a sum of constants (1 + 1, whose coefficient counts twice), a lead term, a factor and an
    /// offset; against the model's own f64 evaluation (`eval_full`, which sums basis values, not
    /// the tree) at points across the unit square.
    #[test]
    fn the_emitted_tree_evaluates_the_model_for_every_term_shape() {
        use crate::fit::model::ModelParts;
        let f = vec!["x".to_string(), "y".to_string()];
        let t = |s: &str| Term::parse(s, &f).unwrap();
        let m = RationalModel::new(ModelParts {
            inputs: f.clone(),
            numerator: vec![t("1"), t("x"), t("1 + x"), t("x + y^2"), t("x*y"), t("1 + 1")],
            denominator: vec![t("y"), t("1 + x*y"), t("x^2")],
            lead: Some(t("1 + y")),
            offset: 0.25,
            factor: Some(t("1 + x^2")),
            ..ModelParts::default()
        })
        .unwrap();
        let c = DVector::from_vec(vec![0.5, -1.25, 0.75, 2.0, -0.5, 0.125, 0.3, 0.2, -0.1]);
        let (num, den) = f32_arrays(&m, &c);
        let e = model_expr(&m);
        for (x, y) in [(0.0, 0.0), (0.3, 0.8), (1.0, 0.5), (0.7, 1.0)] {
            let want = m.eval_full(&c, &[x, y]);
            let got = eval_f32(&e, &[x as f32, y as f32], &num, &den) as f64;
            // f32 rounding of ~20 operations on values ≤ 10 (Q ≥ 1 here): 1e-5.
            assert!((got - want).abs() < 1e-5, "({x}, {y}): tree {got}, model {want}");
        }
    }

    /// Consecutive powers of any one feature, from a constant or not, take Horner form; other
    /// term lists stay a sum of products, with no product by a literal 1 for a constant term.
    /// The expected renderings are written out by hand.
    #[test]
    fn consecutive_powers_of_either_feature_render_in_horner_form() {
        let f = vec!["x".to_string(), "y".to_string()];
        let terms = |ts: &[&str]| -> Vec<Term> { ts.iter().map(|s| Term::parse(s, &f).unwrap()).collect() };
        let show = |ts: &[&str]| render(&linear_combination(&terms(ts), 0), &|i| f[i].clone(), &|_, j| format!("c{j}"), &|v| format!("{v}"));
        assert_eq!(show(&["1", "x", "x^2"]), "c0 + x * (c1 + x * c2)");
        assert_eq!(show(&["1", "y", "y^2"]), "c0 + y * (c1 + y * c2)");
        assert_eq!(show(&["y", "y^2", "y^3"]), "y * (c0 + y * (c1 + y * c2))");
        assert_eq!(show(&["x^2", "x^3"]), "x * (x * (c0 + x * c1))");
        // Not consecutive, or not one feature: no Horner form, but a sum of coefficient times
        // monomial, a constant term its coefficient alone.
        assert_eq!(consecutive_powers(&terms(&["1", "y^2"])), None);
        assert_eq!(consecutive_powers(&terms(&["1", "y", "x^2"])), None);
        assert_eq!(consecutive_powers(&terms(&["y", "x*y"])), None);
        assert_eq!(show(&["1", "y^2"]), "c0 + c1 * (y * y)");
        assert_eq!(show(&["1", "y", "x^2"]), "c0 + c1 * y + c2 * (x * x)");
        assert_eq!(show(&["y", "x*y"]), "c0 * y + c1 * (x * y)");
    }

    #[test]
    fn horner_form_matches_direct_sum() {
        let m = RationalModel::rational_1d("x", 3, 2);
        let e = model_expr(&m);
        let num = [0.5f32, -1.0, 2.0, 0.25];
        let den = [0.3f32, 0.1];
        let x = 0.7f32;
        let p = 0.5 - x + 2.0 * x * x + 0.25 * x * x * x;
        let q = 1.0 + 0.3 * x + 0.1 * x * x;
        // Horner vs power sum in f32 differ by a few ulps of values ~1.
        assert!((eval_f32(&e, &[x], &num, &den) - p / q).abs() < 1e-6);
    }
}
