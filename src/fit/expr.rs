//! A small expression tree for emitted functions: built once from a fitted model (or written
//! as a published form), rendered to WGSL and Rust, and evaluated in f32 here with the same
//! operation order, so the error shadefit measures is the error of the code it emits (up to FMA
//! contraction on a GPU), and in f64 for the form itself.
//!
//! Beyond the rational models' Lit/Var/Coef/Add/Mul/Div, the tree has what published forms
//! are written with: Sub, Neg, Min, Max, Clamp, Select (c > 0 ? a : b), Less (x < y ? a : b),
//! Sqrt, Exp2, Log2, Abs and Pow with a constant exponent, and, inside a [`program::Program`]
//! (a published form with let-bindings), WGSL's small vectors: Vector, Splat, Swizzle and Let.
//! WGSL spells them as its built-ins (`select(b, a, c > 0.0)`, `clamp(x, lo, hi)`, `vec4<f32>(…)`,
//! `.zw`); Rust as f32 methods (`x.max(lo).min(hi)`: NaN → lo, as the evaluator), its vectors
//! as arrays, one expression per lane.

pub mod parse;
pub mod program;
pub mod tape;

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
    Sub(Box<Expr>, Box<Expr>),
    Neg(Box<Expr>),
    Min(Box<Expr>, Box<Expr>),
    Max(Box<Expr>, Box<Expr>),
    /// (x, lo, hi): min(max(x, lo), hi).
    Clamp(Box<Expr>, Box<Expr>, Box<Expr>),
    /// (c, a, b): a where c > 0, else b.
    Select(Box<Expr>, Box<Expr>, Box<Expr>),
    Sqrt(Box<Expr>),
    Exp2(Box<Expr>),
    Log2(Box<Expr>),
    Abs(Box<Expr>),
    /// x^p for a constant p.
    Pow(Box<Expr>, f32),
    /// (x, y, a, b): a where x < y, else b.
    Less(Box<Expr>, Box<Expr>, Box<Expr>, Box<Expr>),
    /// A vector of 2–4 scalar lanes (`vec4<f32>(a, b, c, d)`).
    Vector(Vec<Expr>),
    /// A scalar in every one of n lanes (`vec2<f32>(x)`).
    Splat(u8, Box<Expr>),
    /// Lanes of a vector, by index (`.zw` = [2, 3]; one index is a scalar).
    Swizzle(Box<Expr>, Vec<u8>),
    /// A program's earlier binding, by index.
    Let(usize),
}

macro_rules! expr_op {
    ($tr:ident, $m:ident) => {
        impl std::ops::$tr for Expr {
            type Output = Expr;
            fn $m(self, other: Expr) -> Expr {
                Expr::$tr(Box::new(self), Box::new(other))
            }
        }
    };
}
expr_op!(Add, add);
expr_op!(Sub, sub);
expr_op!(Mul, mul);
expr_op!(Div, div);

impl std::ops::Neg for Expr {
    type Output = Expr;
    fn neg(self) -> Expr {
        Expr::Neg(Box::new(self))
    }
}

/// The language an expression is rendered in (they differ in the built-ins only).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Syntax {
    Wgsl,
    Rust,
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

/// The float types an expression (and a table lookup, `emit::interp`) evaluates in (f32: the
/// emitted code; f64: the form itself).
pub trait Float: Copy + PartialOrd + std::ops::Add<Output = Self> + std::ops::Sub<Output = Self> + std::ops::Mul<Output = Self> + std::ops::Div<Output = Self> + std::ops::Neg<Output = Self> {
    const ZERO: Self;
    const ONE: Self;
    /// A literal of the tree (an f32) in this type.
    fn of_f32(v: f32) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn sqrt(self) -> Self;
    fn exp2(self) -> Self;
    fn log2(self) -> Self;
    fn abs(self) -> Self;
    fn powf(self, p: f32) -> Self;
}

macro_rules! float_impl {
    ($t:ty) => {
        impl Float for $t {
            const ZERO: $t = 0.0;
            const ONE: $t = 1.0;
            fn of_f32(v: f32) -> $t {
                v as $t
            }
            fn min(self, other: $t) -> $t {
                <$t>::min(self, other)
            }
            fn max(self, other: $t) -> $t {
                <$t>::max(self, other)
            }
            fn sqrt(self) -> $t {
                <$t>::sqrt(self)
            }
            fn exp2(self) -> $t {
                <$t>::exp2(self)
            }
            fn log2(self) -> $t {
                <$t>::log2(self)
            }
            fn abs(self) -> $t {
                <$t>::abs(self)
            }
            fn powf(self, p: f32) -> $t {
                <$t>::powf(self, p as $t)
            }
        }
    };
}
float_impl!(f32);
float_impl!(f64);

/// What a tree evaluates to: a scalar of a [`Float`] type, or a program's lanes
/// ([`program::Lanes`]), with the operations per lane.
pub trait Value<T: Float>: Copy + std::ops::Add<Output = Self> + std::ops::Sub<Output = Self> + std::ops::Mul<Output = Self> + std::ops::Div<Output = Self> + std::ops::Neg<Output = Self> {
    /// A scalar (a literal, variable or coefficient).
    fn of(x: T) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn sqrt(self) -> Self;
    fn exp2(self) -> Self;
    fn log2(self) -> Self;
    fn abs(self) -> Self;
    fn powf(self, p: f32) -> Self;
    /// a where c > 0, else b.
    fn select_positive(c: Self, a: Self, b: Self) -> Self;
    /// a where x < y, else b.
    fn select_less(x: Self, y: Self, a: Self, b: Self) -> Self;
    /// The vector nodes (a scalar tree has none).
    fn vector(lanes: &[Self]) -> Self;
    fn splat(n: u8, x: Self) -> Self;
    fn swizzle(self, lanes: &[u8]) -> Self;
}

/// A scalar tree's value: the float itself.
impl<T: Float> Value<T> for T {
    fn of(x: T) -> T {
        x
    }
    fn min(self, other: T) -> T {
        Float::min(self, other)
    }
    fn max(self, other: T) -> T {
        Float::max(self, other)
    }
    fn sqrt(self) -> T {
        Float::sqrt(self)
    }
    fn exp2(self) -> T {
        Float::exp2(self)
    }
    fn log2(self) -> T {
        Float::log2(self)
    }
    fn abs(self) -> T {
        Float::abs(self)
    }
    fn powf(self, p: f32) -> T {
        Float::powf(self, p)
    }
    fn select_positive(c: T, a: T, b: T) -> T {
        if c > T::ZERO { a } else { b }
    }
    fn select_less(x: T, y: T, a: T, b: T) -> T {
        if x < y { a } else { b }
    }
    fn vector(_: &[T]) -> T {
        unreachable!("a vector node outside a program")
    }
    fn splat(_: u8, _: T) -> T {
        unreachable!("a vector node outside a program")
    }
    fn swizzle(self, _: &[u8]) -> T {
        unreachable!("a vector node outside a program")
    }
}

/// Evaluate in `T` with the emitted operation order (coefficients and variables in `T`).
pub fn eval<T: Float>(e: &Expr, vars: &[T], num: &[T], den: &[T]) -> T {
    eval_as(e, vars, num, den, &[])
}

/// Evaluate to `V` (a scalar, or a program's lanes with its bindings `lets`) with the emitted
/// operation order.
pub fn eval_as<T: Float, V: Value<T>>(e: &Expr, vars: &[V], num: &[T], den: &[T], lets: &[V]) -> V {
    let r = |x: &Expr| eval_as(x, vars, num, den, lets);
    match e {
        Lit(v) => V::of(T::of_f32(*v)),
        Var(i) => vars[*i],
        Coef(0, j) => V::of(num[*j]),
        Coef(_, j) => V::of(den[*j]),
        Add(a, b) => r(a) + r(b),
        Mul(a, b) => r(a) * r(b),
        Div(a, b) => r(a) / r(b),
        Sub(a, b) => r(a) - r(b),
        Neg(a) => -r(a),
        Min(a, b) => r(a).min(r(b)),
        Max(a, b) => r(a).max(r(b)),
        Clamp(x, lo, hi) => r(x).max(r(lo)).min(r(hi)),
        Select(c, a, b) => V::select_positive(r(c), r(a), r(b)),
        Sqrt(a) => r(a).sqrt(),
        Exp2(a) => r(a).exp2(),
        Log2(a) => r(a).log2(),
        Abs(a) => r(a).abs(),
        Pow(a, p) => r(a).powf(*p),
        Less(x, y, a, b) => V::select_less(r(x), r(y), r(a), r(b)),
        Vector(items) => V::vector(&items.iter().map(r).collect::<Vec<V>>()),
        Splat(n, x) => V::splat(*n, r(x)),
        Swizzle(x, lanes) => r(x).swizzle(lanes),
        Let(j) => lets[*j],
    }
}

/// Evaluate in f32 with the emitted operation order.
pub fn eval_f32(e: &Expr, vars: &[f32], num: &[f32], den: &[f32]) -> f32 {
    eval(e, vars, num, den)
}

/// Evaluate in f64 (the form itself, e.g. a published form against the integral; literals are
/// the tree's f32 values).
pub fn eval_f64(e: &Expr, vars: &[f64], num: &[f64], den: &[f64]) -> f64 {
    eval(e, vars, num, den)
}

/// Render with language-specific names for variables, coefficients and literals. Parentheses
/// follow the tree exactly (a right operand of the same operator is bracketed), so the emitted
/// code evaluates in the order [`eval_f32`] does. The arithmetic reads the same in WGSL and
/// Rust; an expression with built-ins (min, sqrt, …) renders through [`render_in`].
pub fn render(
    e: &Expr,
    var: &dyn Fn(usize) -> String,
    coef: &dyn Fn(u8, usize) -> String,
    lit: &dyn Fn(f32) -> String,
) -> String {
    render_in(Syntax::Wgsl, e, var, coef, lit)
}

/// [`render`] in a language: WGSL's built-in calls or Rust's f32 methods for the built-ins.
pub fn render_in(
    syntax: Syntax,
    e: &Expr,
    var: &dyn Fn(usize) -> String,
    coef: &dyn Fn(u8, usize) -> String,
    lit: &dyn Fn(f32) -> String,
) -> String {
    struct Closures<'a> {
        var: &'a dyn Fn(usize) -> String,
        coef: &'a dyn Fn(u8, usize) -> String,
        lit: &'a dyn Fn(f32) -> String,
    }
    impl Spell for Closures<'_> {
        fn var(&self, i: usize) -> String {
            (self.var)(i)
        }
        fn coef(&self, array: u8, j: usize) -> String {
            (self.coef)(array, j)
        }
        fn lit(&self, v: f32) -> String {
            (self.lit)(v)
        }
    }
    render_with(syntax, e, &Closures { var, coef, lit })
}

/// How the leaves of a tree are spelled in emitted code.
pub trait Spell {
    fn var(&self, i: usize) -> String;
    fn coef(&self, array: u8, j: usize) -> String;
    fn lit(&self, v: f32) -> String;
    /// −coef as one literal, where the coefficients are printed as their values.
    fn negated_coef(&self, _array: u8, _j: usize) -> Option<String> {
        None
    }
    /// A program's binding.
    fn local(&self, j: usize) -> String {
        format!("t{j}")
    }
    /// Whether a quotient's operands are bracketed only where precedence needs it (a sum on
    /// the left; a sum, product or quotient on the right), as a program is written. A rational
    /// model's P/Q keeps its brackets on both sides, as the emitted rationals always had.
    fn tight_quotients(&self) -> bool {
        false
    }
}

/// Render through a [`Spell`]. Vectors render as WGSL's; Rust has no vector type, so a
/// program hands the Rust renderer one lane at a time ([`program::lane`]), where a lane of a
/// binding is `name[k]`.
pub fn render_with(syntax: Syntax, e: &Expr, spell: &dyn Spell) -> String {
    let r = |x: &Expr| render_with(syntax, x, spell);
    let wrap = |x: &Expr, when: bool| if when { format!("({})", r(x)) } else { r(x) };
    let sum = |x: &Expr| matches!(x, Add(..) | Sub(..));
    // A call: `f(a, …)` in WGSL, `a.f(…)` in Rust, whose receiver is bracketed unless it is a
    // name or a call itself (a literal too: `-1.5_f32.abs()` would negate the call).
    let call = |wgsl: &str, rust: &str, args: &[&Expr], extra: Option<String>| -> String {
        let mut parts: Vec<String> = args.iter().map(|a| r(a)).collect();
        parts.extend(extra);
        match syntax {
            Syntax::Wgsl => format!("{wgsl}({})", parts.join(", ")),
            Syntax::Rust => {
                let recv = if is_atom(args[0]) || is_call(args[0]) { parts[0].clone() } else { format!("({})", parts[0]) };
                format!("{recv}.{rust}({})", parts[1..].join(", "))
            }
        }
    };
    // A quotient's operand is bracketed unless it is a program's name or a call, or, where
    // the spelling asks for tight quotients, where precedence needs it ([`Spell::tight_quotients`]).
    let quotient = |x: &Expr, right: bool| {
        let needed = if spell.tight_quotients() { sum(x) || (right && matches!(x, Mul(..) | Div(..))) } else { !matches!(x, Let(..) | Swizzle(..)) && !is_call(x) };
        wrap(x, needed)
    };
    let condition = |c: &Expr| wrap(c, !matches!(c, Var(..) | Coef(..) | Lit(..)) && !is_atom(c) && !is_call(c));
    match e {
        Lit(v) => spell.lit(*v),
        Var(i) => spell.var(*i),
        Coef(a, j) => spell.coef(*a, *j),
        Add(a, b) => format!("{} + {}", r(a), wrap(b, sum(b))),
        Sub(a, b) => format!("{} - {}", r(a), wrap(b, sum(b))),
        Neg(a) => match **a {
            Coef(arr, j) => spell.negated_coef(arr, j).unwrap_or_else(|| format!("-({})", r(a))),
            _ => format!("-({})", r(a)),
        },
        Mul(a, b) => format!(
            "{} * {}",
            wrap(a, matches!(**a, Add(..) | Sub(..) | Div(..))),
            wrap(b, matches!(**b, Add(..) | Sub(..) | Mul(..) | Div(..)))
        ),
        Div(a, b) => format!("{} / {}", quotient(a, false), quotient(b, true)),
        Min(a, b) => call("min", "min", &[a, b], None),
        Max(a, b) => call("max", "max", &[a, b], None),
        Clamp(x, lo, hi) => match syntax {
            Syntax::Wgsl => call("clamp", "", &[x, lo, hi], None),
            Syntax::Rust => {
                let inner = Max(x.clone(), lo.clone());
                call("min", "min", &[&inner, hi], None)
            }
        },
        Select(c, a, b) => match syntax {
            Syntax::Wgsl => format!("select({}, {}, {} > 0.0)", r(b), r(a), condition(c)),
            Syntax::Rust => format!("(if {} > 0.0 {{ {} }} else {{ {} }})", condition(c), r(a), r(b)),
        },
        Less(x, y, a, b) => match syntax {
            Syntax::Wgsl => format!("select({}, {}, {} < {})", r(b), r(a), condition(x), condition(y)),
            Syntax::Rust => format!("(if {} < {} {{ {} }} else {{ {} }})", condition(x), condition(y), r(a), r(b)),
        },
        Sqrt(a) => call("sqrt", "sqrt", &[a], None),
        Exp2(a) => call("exp2", "exp2", &[a], None),
        Log2(a) => call("log2", "log2", &[a], None),
        Abs(a) => call("abs", "abs", &[a], None),
        Pow(a, p) => call("pow", "powf", &[a], Some(spell.lit(*p))),
        Vector(items) => {
            let parts: Vec<String> = items.iter().map(r).collect();
            match syntax {
                Syntax::Wgsl => format!("vec{}<f32>({})", items.len(), parts.join(", ")),
                Syntax::Rust => format!("[{}]", parts.join(", ")),
            }
        }
        Splat(n, x) => match syntax {
            Syntax::Wgsl => format!("vec{n}<f32>({})", r(x)),
            Syntax::Rust => format!("[{}; {n}]", r(x)),
        },
        Swizzle(x, lanes) => {
            let base = wrap(x, !is_atom(x));
            match syntax {
                Syntax::Wgsl => format!("{base}.{}", lanes.iter().map(|&k| ['x', 'y', 'z', 'w'][k as usize]).collect::<String>()),
                Syntax::Rust => {
                    let idx: Vec<String> = lanes.iter().map(|k| format!("{base}[{k}]")).collect();
                    if idx.len() == 1 { idx[0].clone() } else { format!("[{}]", idx.join(", ")) }
                }
            }
        }
        Let(j) => spell.local(*j),
    }
}

/// Whether a node renders as a call (needs no brackets as an operand or a receiver).
fn is_call(e: &Expr) -> bool {
    matches!(e, Min(..) | Max(..) | Clamp(..) | Select(..) | Less(..) | Sqrt(..) | Exp2(..) | Log2(..) | Abs(..) | Pow(..) | Vector(..) | Splat(..))
}

/// Whether a node renders as a name (a variable, coefficient, binding or lane of one).
fn is_atom(e: &Expr) -> bool {
    matches!(e, Var(..) | Coef(..) | Let(..)) || matches!(e, Swizzle(x, _) if is_atom(x))
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

/// A tree with every node of the published forms' vocabulary over two variables, for the
/// renderers' tests: clamp(min(x0², 2^(−9.28 x1))·x0 − |x0 − 0.5|, 0, 1)
/// + select(x1 − 0.3, sqrt(x1), log2(1 + x0)) + max(−x1, pow(x0 + 0.25, 1.5)).
#[cfg(test)]
pub(crate) fn every_node() -> Expr {
    let b = Box::new;
    let x0 = || b(Var(0));
    let x1 = || b(Var(1));
    let first = Clamp(
        b(Sub(
            b(Mul(b(Min(b(Mul(x0(), x0())), b(Exp2(b(Mul(b(Lit(-9.28)), x1())))))), x0())),
            b(Abs(b(Sub(x0(), b(Lit(0.5)))))),
        )),
        b(Lit(0.0)),
        b(Lit(1.0)),
    );
    let second = Select(b(Sub(x1(), b(Lit(0.3)))), b(Sqrt(x1())), b(Log2(b(Add(b(Lit(1.0)), x0())))));
    let third = Max(b(Neg(x1())), b(Pow(b(Add(x0(), b(Lit(0.25)))), 1.5)));
    Add(b(Add(b(first), b(second))), b(third))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published forms' nodes evaluate as written out by hand (the formula of
    /// [`every_node`] in f32 and in f64, both branches of the select, the clamp's both ends
    /// and its inside): the same operations in the same order, so exactly in f32; in f64 the
    /// literals are the f32 ones.
    #[test]
    fn every_node_evaluates_as_its_formula() {
        let e = every_node();
        let f32_formula = |x0: f32, x1: f32| {
            let first = ((x0 * x0).min((-9.28f32 * x1).exp2()) * x0 - (x0 - 0.5).abs()).max(0.0).min(1.0);
            let second = if x1 - 0.3 > 0.0 { x1.sqrt() } else { (1.0 + x0).log2() };
            first + second + (-x1).max((x0 + 0.25).powf(1.5))
        };
        let f64_formula = |x0: f64, x1: f64| {
            let first = ((x0 * x0).min((-9.28f32 as f64 * x1).exp2()) * x0 - (x0 - 0.5).abs()).max(0.0).min(1.0);
            let second = if x1 - 0.3f32 as f64 > 0.0 { x1.sqrt() } else { (1.0 + x0).log2() };
            first + second + (-x1).max((x0 + 0.25).powf(1.5))
        };
        for (x0, x1) in [(0.0f32, 0.0f32), (0.9, 0.05), (0.7, 0.6), (1.0, 1.0), (0.2, 0.31), (1.5, -0.2), (3.0, 0.1)] {
            assert_eq!(eval_f32(&e, &[x0, x1], &[], &[]).to_bits(), f32_formula(x0, x1).to_bits(), "({x0}, {x1})");
            let (a, b) = (x0 as f64, x1 as f64);
            assert_eq!(eval_f64(&e, &[a, b], &[], &[]).to_bits(), f64_formula(a, b).to_bits(), "({x0}, {x1}) in f64");
        }
    }

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
