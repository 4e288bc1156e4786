//! A published form written once: its inputs, its constants, let-bindings and a result, over
//! WGSL's small vectors (1–4 lanes, operations per lane, a scalar broadcast to every lane).
//! From the one [`Program`] derive its evaluation in f64 with f64 constants (the form itself:
//! what `validate` measures and a refit moves), in f32 with the emitted operation order (what
//! the shader computes), its WGSL and Rust text, and through the WGSL its naga operation count.
//!
//! A program refers to its inputs as `Var(i)`, its constants as `Coef(0, j)` and to its
//! bindings as `Let(k)` (earlier ones only). WGSL renders it as written (`let r = x * c0 + c1;`
//! with `vec4<f32>` values); Rust, which has no vector type, one lane at a time
//! (`let r = [x * c0[0] + c1[0], …];`), so both compute the same f32 operations in the same
//! order as [`Program::eval_f32`]. A [`Record`] is a program with several named results, which
//! the emitted code returns as one struct.

use super::{Expr, Float, Spell, Syntax, Value, render_with};

/// A value of a program: `len` lanes (1 for a scalar, which then fills all four).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lanes<T> {
    pub len: u8,
    pub v: [T; 4],
}

impl<T: Float> Lanes<T> {
    fn zip(self, o: Self, f: impl Fn(T, T) -> T) -> Self {
        debug_assert!(self.len == o.len || self.len == 1 || o.len == 1, "lanes {} and {}", self.len, o.len);
        Lanes { len: self.len.max(o.len), v: std::array::from_fn(|k| f(self.v[k], o.v[k])) }
    }
    fn map(self, f: impl Fn(T) -> T) -> Self {
        Lanes { len: self.len, v: self.v.map(f) }
    }
}

macro_rules! lanes_op {
    ($tr:ident, $m:ident, $op:tt) => {
        impl<T: Float> std::ops::$tr for Lanes<T> {
            type Output = Self;
            fn $m(self, o: Self) -> Self {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lanes_op!(Add, add, +);
lanes_op!(Sub, sub, -);
lanes_op!(Mul, mul, *);
lanes_op!(Div, div, /);

impl<T: Float> std::ops::Neg for Lanes<T> {
    type Output = Self;
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl<T: Float> Value<T> for Lanes<T> {
    fn of(x: T) -> Self {
        Lanes { len: 1, v: [x; 4] }
    }
    fn min(self, o: Self) -> Self {
        self.zip(o, T::min)
    }
    fn max(self, o: Self) -> Self {
        self.zip(o, T::max)
    }
    fn sqrt(self) -> Self {
        self.map(T::sqrt)
    }
    fn exp2(self) -> Self {
        self.map(T::exp2)
    }
    fn log2(self) -> Self {
        self.map(T::log2)
    }
    fn abs(self) -> Self {
        self.map(T::abs)
    }
    fn powf(self, p: f32) -> Self {
        self.map(|a| a.powf(p))
    }
    fn select_positive(c: Self, a: Self, b: Self) -> Self {
        let len = c.len.max(a.len).max(b.len);
        Lanes { len, v: std::array::from_fn(|k| if c.v[k] > T::ZERO { a.v[k] } else { b.v[k] }) }
    }
    fn select_less(x: Self, y: Self, a: Self, b: Self) -> Self {
        let len = x.len.max(y.len).max(a.len).max(b.len);
        Lanes { len, v: std::array::from_fn(|k| if x.v[k] < y.v[k] { a.v[k] } else { b.v[k] }) }
    }
    fn vector(lanes: &[Self]) -> Self {
        debug_assert!((2..=4).contains(&lanes.len()) && lanes.iter().all(|l| l.len == 1));
        Lanes { len: lanes.len() as u8, v: std::array::from_fn(|k| lanes.get(k).map_or(T::ZERO, |l| l.v[0])) }
    }
    fn splat(n: u8, x: Self) -> Self {
        Lanes { len: n, v: [x.v[0]; 4] }
    }
    fn swizzle(self, lanes: &[u8]) -> Self {
        if let [k] = lanes {
            return Lanes::of(self.v[*k as usize]);
        }
        Lanes { len: lanes.len() as u8, v: std::array::from_fn(|k| lanes.get(k).map_or(T::ZERO, |&i| self.v[i as usize])) }
    }
}

/// A published form: bindings evaluated in order, then the result.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// (name, value); a value refers to earlier bindings only.
    pub lets: Vec<(String, Expr)>,
    pub result: Expr,
}

impl Program {
    /// The result's lanes at `inputs` with constants `consts`, in `T` with the emitted order.
    pub fn eval<T: Float>(&self, inputs: &[T], consts: &[T]) -> Lanes<T> {
        let (vars, lets) = bindings(&self.lets, inputs, consts);
        super::eval_as(&self.result, &vars, consts, &[], &lets)
    }

    /// The result in f64 (the form itself with f64 constants).
    pub fn eval_f64(&self, inputs: &[f64], consts: &[f64]) -> Vec<f64> {
        let l = self.eval(inputs, consts);
        l.v[..l.len as usize].to_vec()
    }

    /// The result in f32 (what the emitted code computes, FMA contraction aside).
    pub fn eval_f32(&self, inputs: &[f32], consts: &[f32]) -> Vec<f32> {
        let l = self.eval(inputs, consts);
        l.v[..l.len as usize].to_vec()
    }

    /// Lanes of the result.
    pub fn width(&self) -> usize {
        width(&self.result, &let_widths(&self.lets))
    }

    /// The function body (4-space indent, no closing brace): each binding on its line, then
    /// `return …;` (WGSL) or the tail expression (Rust). `input(i)` spells input i (a name,
    /// or the clamp call of the argument); constants print as `constant(consts[j])`, a negated
    /// constant as the literal of its negation.
    pub fn render(&self, syntax: Syntax, input: &dyn Fn(usize) -> String, consts: &[f32], constant: &dyn Fn(f32) -> String) -> String {
        let (mut s, results) = render_parts(&self.lets, &[&self.result], syntax, input, consts, constant);
        match syntax {
            Syntax::Wgsl => s += &format!("    return {};\n", results[0]),
            Syntax::Rust => s += &format!("    {}\n", results[0]),
        }
        s
    }
}

/// A form with several named results, returned as one struct of the emitted language: its
/// fields over bindings they share. WGSL returns the struct's constructor (`return
/// Name(a, …);`), Rust its literal (`Name { a, b: …, … }`, a field named as its binding
/// written once); the evaluators return every field's lanes, field after field.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// (name, value); a value refers to earlier bindings only.
    pub lets: Vec<(String, Expr)>,
    /// The struct's name in the emitted code.
    pub name: String,
    /// (field, value), in the struct's order.
    pub fields: Vec<(String, Expr)>,
}

impl Record {
    /// Each field's lanes at `inputs` with constants `consts`, in `T` with the emitted order.
    pub fn eval<T: Float>(&self, inputs: &[T], consts: &[T]) -> Vec<Lanes<T>> {
        let (vars, lets) = bindings(&self.lets, inputs, consts);
        self.fields.iter().map(|(_, e)| super::eval_as(e, &vars, consts, &[], &lets)).collect()
    }

    /// The fields' lanes in f64, field after field.
    pub fn eval_f64(&self, inputs: &[f64], consts: &[f64]) -> Vec<f64> {
        self.eval(inputs, consts).iter().flat_map(|l| l.v[..l.len as usize].to_vec()).collect()
    }

    /// The fields' lanes in f32 (what the emitted code computes, FMA contraction aside).
    pub fn eval_f32(&self, inputs: &[f32], consts: &[f32]) -> Vec<f32> {
        self.eval(inputs, consts).iter().flat_map(|l| l.v[..l.len as usize].to_vec()).collect()
    }

    /// Lanes of each field.
    pub fn widths(&self) -> Vec<usize> {
        let lets = let_widths(&self.lets);
        self.fields.iter().map(|(_, e)| width(e, &lets)).collect()
    }

    /// The function body as [`Program::render`] writes it, returning the struct.
    pub fn render(&self, syntax: Syntax, input: &dyn Fn(usize) -> String, consts: &[f32], constant: &dyn Fn(f32) -> String) -> String {
        let values: Vec<&Expr> = self.fields.iter().map(|(_, e)| e).collect();
        let (mut s, results) = render_parts(&self.lets, &values, syntax, input, consts, constant);
        match syntax {
            Syntax::Wgsl => s += &format!("    return {}({});\n", self.name, results.join(", ")),
            Syntax::Rust => {
                let fields: Vec<String> = self.fields.iter().zip(&results).map(|((f, _), v)| if f == v { f.clone() } else { format!("{f}: {v}") }).collect();
                s += &format!("    {} {{ {} }}\n", self.name, fields.join(", "));
            }
        }
        s
    }
}

/// The lanes of the inputs (scalars) and of each binding, evaluated in order.
fn bindings<T: Float>(lets: &[(String, Expr)], inputs: &[T], consts: &[T]) -> (Vec<Lanes<T>>, Vec<Lanes<T>>) {
    let vars: Vec<Lanes<T>> = inputs.iter().map(|&x| Lanes::of(x)).collect();
    let mut values: Vec<Lanes<T>> = Vec::with_capacity(lets.len());
    for (_, e) in lets {
        let v = super::eval_as(e, &vars, consts, &[], &values);
        values.push(v);
    }
    (vars, values)
}

/// Lanes of each binding.
fn let_widths(lets: &[(String, Expr)]) -> Vec<usize> {
    let mut w = Vec::new();
    for (_, e) in lets {
        let n = width(e, &w);
        w.push(n);
    }
    w
}

/// Each binding on its line (`    let name = …;\n`), and the text of each result expression.
fn render_parts(lets: &[(String, Expr)], results: &[&Expr], syntax: Syntax, input: &dyn Fn(usize) -> String, consts: &[f32], constant: &dyn Fn(f32) -> String) -> (String, Vec<String>) {
    let widths = let_widths(lets);
    let spell = Bound { syntax, input, consts, constant, names: lets.iter().map(|(k, _)| k.as_str()).collect() };
    let text = |e: &Expr| -> String {
        let lanes = width(e, &widths);
        match syntax {
            Syntax::Wgsl => {
                let one = render_with(syntax, e, &spell);
                // A long sum of three terms or more continues on the next lines, one term each.
                let terms = sum_terms(e);
                if one.len() <= LINE || terms.len() < 3 {
                    return one;
                }
                // As `Add` renders: a right operand that is a sum in brackets.
                let parts: Vec<String> = terms
                    .iter()
                    .enumerate()
                    .map(|(i, t)| {
                        let text = render_with(syntax, t, &spell);
                        if i > 0 && matches!(t, Expr::Add(..) | Expr::Sub(..)) { format!("({text})") } else { text }
                    })
                    .collect();
                parts.join("\n        + ")
            }
            Syntax::Rust if lanes == 1 => tail(render_with(syntax, e, &spell), e),
            Syntax::Rust => {
                let parts: Vec<String> = (0..lanes).map(|k| tail(render_with(syntax, &lane(e, k, &widths), &spell), e)).collect();
                let one = format!("[{}]", parts.join(", "));
                if one.len() <= LINE { one } else { format!("[\n{}    ]", parts.iter().map(|p| format!("        {p},\n")).collect::<String>()) }
            }
        }
    };
    let mut s = String::new();
    for (name, e) in lets {
        s += &format!("    let {name} = {};\n", text(e));
    }
    (s, results.iter().map(|e| text(e)).collect())
}

/// The longest expression kept on one line.
const LINE: usize = 100;

/// The terms of a sum a + b + c (left to right; one term if `e` is not a sum).
fn sum_terms(e: &Expr) -> Vec<&Expr> {
    let mut terms = Vec::new();
    let mut e = e;
    while let Expr::Add(a, b) = e {
        terms.push(&**b);
        e = a;
    }
    terms.push(e);
    terms.reverse();
    terms
}

/// A Rust conditional standing alone (a binding's value or the tail) loses its brackets.
fn tail(text: String, e: &Expr) -> String {
    if matches!(e, Expr::Select(..) | Expr::Less(..)) && text.starts_with('(') && text.ends_with(')') {
        text[1..text.len() - 1].to_string()
    } else {
        text
    }
}

/// Lanes of a node, given the bindings' lanes.
fn width(e: &Expr, lets: &[usize]) -> usize {
    use Expr::*;
    let w = |x: &Expr| width(x, lets);
    match e {
        Lit(_) | Var(_) | Coef(..) => 1,
        Let(j) => lets[*j],
        Vector(items) => items.len(),
        Splat(n, _) => *n as usize,
        Swizzle(_, lanes) => lanes.len(),
        Neg(a) | Sqrt(a) | Exp2(a) | Log2(a) | Abs(a) | Pow(a, _) => w(a),
        Add(a, b) | Sub(a, b) | Mul(a, b) | Div(a, b) | Min(a, b) | Max(a, b) => w(a).max(w(b)),
        Clamp(a, b, c) | Select(a, b, c) => w(a).max(w(b)).max(w(c)),
        Less(a, b, c, d) => w(a).max(w(b)).max(w(c)).max(w(d)),
    }
}

/// Lane `k` of a node as a scalar tree: a vector's k-th component, a swizzle's k-th pick, a
/// binding's `Swizzle(Let, [k])` (Rust's `name[k]`); scalars stand in every lane.
pub fn lane(e: &Expr, k: usize, lets: &[usize]) -> Expr {
    use Expr::*;
    if width(e, lets) == 1 {
        return e.clone();
    }
    let l = |x: &Expr| Box::new(lane(x, k, lets));
    match e {
        Let(j) => Swizzle(Box::new(Let(*j)), vec![k as u8]),
        Vector(items) => lane(&items[k], 0, lets),
        Splat(_, x) => lane(x, 0, lets),
        Swizzle(x, lanes) => lane(x, lanes[k] as usize, lets),
        Neg(a) => Neg(l(a)),
        Sqrt(a) => Sqrt(l(a)),
        Exp2(a) => Exp2(l(a)),
        Log2(a) => Log2(l(a)),
        Abs(a) => Abs(l(a)),
        Pow(a, p) => Pow(l(a), *p),
        Add(a, b) => Add(l(a), l(b)),
        Sub(a, b) => Sub(l(a), l(b)),
        Mul(a, b) => Mul(l(a), l(b)),
        Div(a, b) => Div(l(a), l(b)),
        Min(a, b) => Min(l(a), l(b)),
        Max(a, b) => Max(l(a), l(b)),
        Clamp(a, b, c) => Clamp(l(a), l(b), l(c)),
        Select(a, b, c) => Select(l(a), l(b), l(c)),
        Less(a, b, c, d) => Less(l(a), l(b), l(c), l(d)),
        Lit(_) | Var(_) | Coef(..) => unreachable!("scalar"),
    }
}

/// The leaves of a program with its constants bound: literals in their shortest form.
struct Bound<'a> {
    syntax: Syntax,
    input: &'a dyn Fn(usize) -> String,
    consts: &'a [f32],
    constant: &'a dyn Fn(f32) -> String,
    names: Vec<&'a str>,
}

impl Spell for Bound<'_> {
    fn var(&self, i: usize) -> String {
        (self.input)(i)
    }
    fn coef(&self, _: u8, j: usize) -> String {
        (self.constant)(self.consts[j])
    }
    fn negated_coef(&self, _: u8, j: usize) -> Option<String> {
        Some((self.constant)(-self.consts[j]))
    }
    fn lit(&self, v: f32) -> String {
        short_literal(self.syntax, v)
    }
    fn local(&self, j: usize) -> String {
        self.names[j].to_string()
    }
    fn tight_quotients(&self) -> bool {
        true
    }
}

/// A literal of the form (0, 1, 0.5, 1e-30) in its shorter round-trip spelling, plain or
/// with an exponent: `1f` / `1.0` for 1.
pub fn short_literal(syntax: Syntax, v: f32) -> String {
    let (plain, exp) = (format!("{v}"), format!("{v:e}"));
    let s = if exp.len() < plain.len() { exp } else { plain };
    match syntax {
        Syntax::Wgsl => format!("{s}f"),
        Syntax::Rust if s.contains(['.', 'e']) => s,
        Syntax::Rust => format!("{s}.0"),
    }
}

/// Constructors for writing a form: `var(0) * bind(0) + bind(1)` reads as its WGSL.
pub mod build {
    use super::Expr;

    pub fn var(i: usize) -> Expr {
        Expr::Var(i)
    }
    /// Constant j of the form.
    pub fn k(j: usize) -> Expr {
        Expr::Coef(0, j)
    }
    pub fn lit(v: f32) -> Expr {
        Expr::Lit(v)
    }
    /// Binding j of the program.
    pub fn bind(j: usize) -> Expr {
        Expr::Let(j)
    }
    pub fn min(a: Expr, b: Expr) -> Expr {
        Expr::Min(Box::new(a), Box::new(b))
    }
    pub fn max(a: Expr, b: Expr) -> Expr {
        Expr::Max(Box::new(a), Box::new(b))
    }
    pub fn exp2(a: Expr) -> Expr {
        Expr::Exp2(Box::new(a))
    }
    pub fn sqrt(a: Expr) -> Expr {
        Expr::Sqrt(Box::new(a))
    }
    pub fn clamp(x: Expr, lo: Expr, hi: Expr) -> Expr {
        Expr::Clamp(Box::new(x), Box::new(lo), Box::new(hi))
    }
    /// a where x < y, else b.
    pub fn less(x: Expr, y: Expr, a: Expr, b: Expr) -> Expr {
        Expr::Less(Box::new(x), Box::new(y), Box::new(a), Box::new(b))
    }
    pub fn vector(lanes: Vec<Expr>) -> Expr {
        Expr::Vector(lanes)
    }
    /// Constants `first..first + n` as an n-lane vector.
    pub fn constants(first: usize, n: usize) -> Expr {
        Expr::Vector((first..first + n).map(k).collect())
    }
    pub fn splat(n: u8, x: Expr) -> Expr {
        Expr::Splat(n, Box::new(x))
    }
    /// Lanes by letter: `swz(bind(2), "zw")`.
    pub fn swz(x: Expr, lanes: &str) -> Expr {
        Expr::Swizzle(Box::new(x), lanes.chars().map(|c| "xyzw".find(c).expect("a lane letter") as u8).collect())
    }
}

/// A program with every vector node, for the renderers' tests: over inputs (x0, x1) and
/// constants c0…c3,
/// ```text
/// q = (x0, x1, c0, c1);  w = q·c2 + (0.5, −c3, x0, 1);  s = min(w.x w.y, 2^w.z) / max(w.w, 1e-30)
/// result = clamp((s, w.z − s), 0, 2) + (w.xy < 0.5 ? w.zw : w.yx)
/// ```
#[cfg(test)]
pub(crate) fn every_vector_node() -> Program {
    use build::*;
    let w = |l| swz(bind(1), l);
    Program {
        lets: vec![
            ("q".into(), vector(vec![var(0), var(1), k(0), k(1)])),
            ("w".into(), bind(0) * splat(4, k(2)) + vector(vec![lit(0.5), -k(3), var(0), lit(1.0)])),
            ("s".into(), min(w("x") * w("y"), exp2(w("z"))) / max(w("w"), lit(1e-30))),
        ],
        result: clamp(vector(vec![bind(2), w("z") - bind(2)]), splat(2, lit(0.0)), splat(2, lit(2.0))) + less(w("xy"), splat(2, lit(0.5)), w("zw"), w("yx")),
    }
}

/// The constants and points the renderers' tests run [`every_vector_node`] at: both sides
/// of each select, inside and outside the clamp.
#[cfg(test)]
pub(crate) const EVERY_CONSTS: [f32; 4] = [0.75, -1.5, 1.25, 0.375];
#[cfg(test)]
pub(crate) const EVERY_POINTS: [(f32, f32); 6] = [(0.0, 0.0), (0.9, 0.05), (0.7, 0.6), (1.0, 1.0), (-0.2, 0.31), (1.5, -0.2)];

#[cfg(test)]
mod tests {
    use super::*;

    /// The program's lanes are the formula of [`every_vector_node`] written out by hand, in f32
    /// bit for bit (the same operations in the same order) and in f64.
    #[test]
    fn every_vector_node_evaluates_as_its_formula() {
        fn formula<T: Float>(x0: T, x1: T, c: [T; 4]) -> [T; 2] {
            let v = [x0, x1, c[0], c[1]];
            let add = [T::of_f32(0.5), -c[3], x0, T::ONE];
            let w: [T; 4] = std::array::from_fn(|i| v[i] * c[2] + add[i]);
            let s = (w[0] * w[1]).min(w[2].exp2()) / w[3].max(T::of_f32(1e-30));
            let two = T::of_f32(2.0);
            let pick = |i: usize, a: T, b: T| if w[i] < T::of_f32(0.5) { a } else { b };
            [s.max(T::ZERO).min(two) + pick(0, w[2], w[1]), (w[2] - s).max(T::ZERO).min(two) + pick(1, w[3], w[0])]
        }
        let p = every_vector_node();
        assert_eq!(p.width(), 2);
        let c64 = EVERY_CONSTS.map(|c| c as f64);
        for (x0, x1) in EVERY_POINTS {
            let got = p.eval_f32(&[x0, x1], &EVERY_CONSTS);
            let want = formula(x0, x1, EVERY_CONSTS);
            assert_eq!(got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), want.map(f32::to_bits), "({x0}, {x1})");
            let got = p.eval_f64(&[x0 as f64, x1 as f64], &c64);
            assert_eq!(got, formula(x0 as f64, x1 as f64, c64), "({x0}, {x1}) in f64");
        }
    }

    /// The text of both languages, written out by hand: WGSL as the program is written, Rust
    /// one lane at a time (a long vector a lane a line), a negated constant as its literal.
    #[test]
    fn every_vector_node_renders_as_written() {
        let p = every_vector_node();
        let lit = |v: f32| format!("{v}");
        let wgsl = p.render(Syntax::Wgsl, &|i| format!("x{i}"), &EVERY_CONSTS, &lit);
        assert_eq!(
            wgsl,
            "    let q = vec4<f32>(x0, x1, 0.75, -1.5);\n\
             \x20   let w = q * vec4<f32>(1.25) + vec4<f32>(0.5f, -0.375, x0, 1f);\n\
             \x20   let s = min(w.x * w.y, exp2(w.z)) / max(w.w, 1e-30f);\n\
             \x20   return clamp(vec2<f32>(s, w.z - s), vec2<f32>(0f), vec2<f32>(2f)) + select(w.yx, w.zw, w.xy < vec2<f32>(0.5f));\n"
        );
        let rust = p.render(Syntax::Rust, &|i| format!("x{i}"), &EVERY_CONSTS, &lit);
        assert_eq!(
            rust,
            "    let q = [x0, x1, 0.75, -1.5];\n\
             \x20   let w = [q[0] * 1.25 + 0.5, q[1] * 1.25 + -0.375, q[2] * 1.25 + x0, q[3] * 1.25 + 1.0];\n\
             \x20   let s = (w[0] * w[1]).min(w[2].exp2()) / w[3].max(1e-30);\n\
             \x20   [\n\
             \x20       s.max(0.0).min(2.0) + (if w[0] < 0.5 { w[2] } else { w[1] }),\n\
             \x20       (w[2] - s).max(0.0).min(2.0) + (if w[1] < 0.5 { w[3] } else { w[0] }),\n\
             \x20   ]\n"
        );
    }

    /// A record over shared bindings: its fields evaluate as the formula written out by hand
    /// (bit for bit in f32, field after field), and render as a struct constructor (WGSL) and
    /// literal (Rust, a field named as its binding written once), written out by hand; its
    /// quotients bracket only what precedence needs (a product on the left stays bare, one
    /// on the right is bracketed).
    #[test]
    fn a_record_evaluates_and_renders_as_written() {
        use build::*;
        let r = Record {
            lets: vec![("q".into(), var(0) + k(0)), ("r".into(), lit(1.0) / max(bind(0), lit(1e-30)))],
            name: "Pair".into(),
            fields: vec![("q".into(), bind(0)), ("s".into(), bind(0) * bind(1) / (var(1) * k(1))), ("v".into(), vector(vec![bind(1), -var(0)]))],
        };
        assert_eq!(r.widths(), [1, 1, 2]);
        let c = [0.5f32, 3.0];
        for (x0, x1) in EVERY_POINTS {
            let q = x0 + c[0];
            let rr = 1.0 / q.max(1e-30);
            let want = [q, q * rr / (x1 * c[1]), rr, -x0];
            assert_eq!(r.eval_f32(&[x0, x1], &c).iter().map(|v| v.to_bits()).collect::<Vec<_>>(), want.map(f32::to_bits), "({x0}, {x1})");
        }
        let lit = |v: f32| format!("{v}");
        assert_eq!(
            r.render(Syntax::Wgsl, &|i| format!("x{i}"), &c, &lit),
            "    let q = x0 + 0.5;\n    let r = 1f / max(q, 1e-30f);\n    return Pair(q, q * r / (x1 * 3), vec2<f32>(r, -(x0)));\n"
        );
        assert_eq!(
            r.render(Syntax::Rust, &|i| format!("x{i}"), &c, &lit),
            "    let q = x0 + 0.5;\n    let r = 1.0 / q.max(1e-30);\n    Pair { q, s: q * r / (x1 * 3), v: [r, -(x0)] }\n"
        );
    }

    #[test]
    fn literals_take_their_shorter_spelling() {
        assert_eq!(short_literal(Syntax::Wgsl, 1.0), "1f");
        assert_eq!(short_literal(Syntax::Rust, 1.0), "1.0");
        assert_eq!(short_literal(Syntax::Wgsl, 0.5), "0.5f");
        assert_eq!(short_literal(Syntax::Rust, 1e-30), "1e-30");
        assert_eq!(short_literal(Syntax::Wgsl, 7.8125e-3), "0.0078125f"); // a tie: plain
        assert_eq!(short_literal(Syntax::Wgsl, 1.5e-4), "1.5e-4f");
        assert_eq!(short_literal(Syntax::Rust, -2.0), "-2.0");
    }
}
