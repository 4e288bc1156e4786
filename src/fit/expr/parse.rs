//! The expression language of form specs (`kind = "form"`): text to an [`Expr`] of the IR, so
//! that a user's formula is evaluated, refitted and emitted exactly as a built-in published form.
//!
//! ```text
//! expr    = sum
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = "-" unary | power
//! power   = atom ("^" exponent)?          exponent: a number, optionally negative
//! atom    = number | name | name "(" expr ("," expr)* ")" | "(" expr ")"
//! ```
//!
//! Names are the form's arguments, its constants, its earlier `let` bindings and `pi`.
//! Functions: `min(a, b)`, `max(a, b)`, `clamp(x, lo, hi)`, `saturate(x)`, `mix(a, b, t)`,
//! `sqrt`, `inversesqrt`, `exp2`, `log2`, `exp`, `log`, `abs`, `pow(x, p)` with a number p,
//! and `select(f, t, a < b)` (t where the comparison holds, else f, as WGSL's `select`; the
//! comparison is one of `<`, `>`, `<=`, `>=`).
//!
//! The shading terms of the lobe layer, by name (expanded into the operations above, so that
//! they are integrated, refitted and emitted like any formula; α is the GGX/Charlie roughness,
//! r² for perceptual roughness r):
//! ```text
//! d_ggx(n_dot_h, alpha)                   α²/(π (1 − n·h² + n·h² α²)²)     Trowbridge–Reitz NDF
//! v_smith_ggx_correlated(n_dot_v, n_dot_l, alpha)
//!                                         ½/(n·l √(n·v² (1 − α²) + α²) + n·v √(n·l² (1 − α²) + α²))
//!                                         height-correlated Smith G2/(4 n·v n·l) (Heitz 2014, Eq. 99)
//! v_smith_schlick(n_dot_v, n_dot_l, k)    ¼/((n·v (1 − k) + k)(n·l (1 − k) + k))   separable
//!                                         Schlick–Smith (UE4: k = α/2 for image-based light)
//! d_charlie(n_dot_h, alpha)               (2 + 1/α) max(1 − n·h², 0)^(1/(2α)) / (2π)
//!                                         the Charlie cloth NDF (Estevez & Kulla 2017)
//! v_neubelt(n_dot_v, n_dot_l)             ¼/(n·l + n·v − n·l n·v)   Neubelt & Pettineo 2013
//! f_schlick(f0, f90, v_dot_h)             f0 + (f90 − f0)(1 − v·h)⁵   Schlick 1994
//! ```
//! Their π is the scope's `pi`. `x^n` with a whole n in 2…8 is written as n − 1
//! multiplications (what a shader author writes), any other exponent as `pow`. `exp(x)` is
//! `exp2(x·log2 e)` and `log(x)` is `log2(x)·ln 2`, as shaders compute them. Numbers are f32
//! literals, as the emitted code carries them: a value to be measured in f64 or refitted belongs
//! in the form's constants.

use super::Expr;

/// Longest expression text accepted (characters).
pub const MAX_LEN: usize = 4096;
/// Deepest nesting of parentheses, calls and unary minus accepted.
pub const MAX_DEPTH: usize = 64;

/// A parse error at a 1-based character column of the expression.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    pub column: usize,
    pub message: String,
}

impl std::fmt::Display for ParseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "column {}: {}", self.column, self.message)
    }
}

/// The names an expression may use, each resolved to the IR: the arguments (`Var(i)`), the
/// constants (`Coef(0, j)`) and the bindings defined so far (`Let(k)`).
#[derive(Debug, Clone, Copy)]
pub struct Scope<'a> {
    pub inputs: &'a [String],
    pub constants: &'a [String],
    pub lets: &'a [String],
}

impl Scope<'_> {
    fn resolve(&self, name: &str) -> Option<Expr> {
        // Later bindings shadow nothing: the spec checks names are distinct.
        if let Some(k) = self.lets.iter().position(|n| n == name) {
            return Some(Expr::Let(k));
        }
        if let Some(j) = self.constants.iter().position(|n| n == name) {
            return Some(Expr::Coef(0, j));
        }
        if let Some(i) = self.inputs.iter().position(|n| n == name) {
            return Some(Expr::Var(i));
        }
        (name == "pi").then_some(Expr::Lit(std::f32::consts::PI))
    }

    fn known(&self) -> String {
        let mut all: Vec<&str> = self.inputs.iter().chain(self.constants).chain(self.lets).map(String::as_str).collect();
        all.push("pi");
        all.join(", ")
    }
}

/// The functions and their argument counts.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("min", 2),
    ("max", 2),
    ("clamp", 3),
    ("saturate", 1),
    ("mix", 3),
    ("sqrt", 1),
    ("inversesqrt", 1),
    ("exp2", 1),
    ("log2", 1),
    ("exp", 1),
    ("log", 1),
    ("abs", 1),
    ("pow", 2),
    ("select", 3),
    ("d_ggx", 2),
    ("v_smith_ggx_correlated", 3),
    ("v_smith_schlick", 3),
    ("d_charlie", 2),
    ("v_neubelt", 2),
    ("f_schlick", 3),
];

/// Whether `name` is a word of the language (a function or `pi`): no argument, constant or
/// binding may take it.
pub fn is_reserved(name: &str) -> bool {
    name == "pi" || FUNCTIONS.iter().any(|(f, _)| *f == name)
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Op(&'static str),
}

fn tokens(text: &str) -> Result<Vec<(Tok, usize)>, ParseError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let col = i + 1;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit)) {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s: String = chars[start..i].iter().collect();
            let v: f64 = s.parse().map_err(|_| ParseError { column: col, message: format!("'{s}' is not a number") })?;
            out.push((Tok::Num(v), col));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Tok::Name(chars[start..i].iter().collect()), col));
        } else {
            let two: String = chars[i..(i + 2).min(chars.len())].iter().collect();
            let op = match two.as_str() {
                "<=" => Some("<="),
                ">=" => Some(">="),
                _ => None,
            };
            if let Some(op) = op {
                out.push((Tok::Op(op), col));
                i += 2;
                continue;
            }
            let op = match c {
                '+' => "+",
                '-' => "-",
                '*' => "*",
                '/' => "/",
                '^' => "^",
                '(' => "(",
                ')' => ")",
                ',' => ",",
                '<' => "<",
                '>' => ">",
                _ => return Err(ParseError { column: col, message: format!("unexpected character '{c}'") }),
            };
            out.push((Tok::Op(op), col));
            i += 1;
        }
    }
    Ok(out)
}

struct Parser<'a> {
    toks: Vec<(Tok, usize)>,
    at: usize,
    end: usize,
    scope: Scope<'a>,
    depth: usize,
}

fn lit(v: f64, column: usize) -> Result<Expr, ParseError> {
    let f = v as f32;
    if !f.is_finite() {
        return Err(ParseError { column, message: format!("{v} is outside f32's range (numbers are f32 literals)") });
    }
    Ok(Expr::Lit(f))
}

impl Parser<'_> {
    fn column(&self) -> usize {
        self.toks.get(self.at).map_or(self.end, |t| t.1)
    }

    fn err<T>(&self, message: String) -> Result<T, ParseError> {
        Err(ParseError { column: self.column(), message })
    }

    fn peek_op(&self, op: &str) -> bool {
        matches!(self.toks.get(self.at), Some((Tok::Op(o), _)) if *o == op)
    }

    fn expect(&mut self, op: &str) -> Result<(), ParseError> {
        if self.peek_op(op) {
            self.at += 1;
            Ok(())
        } else {
            let found = self.describe();
            self.err(format!("expected '{op}', found {found}"))
        }
    }

    fn describe(&self) -> String {
        match self.toks.get(self.at) {
            None => "the end".into(),
            Some((Tok::Num(v), _)) => format!("the number {v}"),
            Some((Tok::Name(n), _)) => format!("'{n}'"),
            Some((Tok::Op(o), _)) => format!("'{o}'"),
        }
    }

    fn deeper(&mut self) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.err(format!("nested more than {MAX_DEPTH} deep"));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<Expr, ParseError> {
        let mut e = self.product()?;
        loop {
            if self.peek_op("+") {
                self.at += 1;
                e = e + self.product()?;
            } else if self.peek_op("-") {
                self.at += 1;
                e = e - self.product()?;
            } else {
                return Ok(e);
            }
        }
    }

    fn product(&mut self) -> Result<Expr, ParseError> {
        let mut e = self.unary()?;
        loop {
            if self.peek_op("*") {
                self.at += 1;
                e = e * self.unary()?;
            } else if self.peek_op("/") {
                self.at += 1;
                e = e / self.unary()?;
            } else {
                return Ok(e);
            }
        }
    }

    fn unary(&mut self) -> Result<Expr, ParseError> {
        if self.peek_op("-") {
            self.at += 1;
            self.deeper()?;
            let e = -self.unary()?;
            self.depth -= 1;
            return Ok(e);
        }
        self.power()
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.atom()?;
        if !self.peek_op("^") {
            return Ok(base);
        }
        self.at += 1;
        let p = self.exponent()?;
        Ok(power(base, p))
    }

    /// A number, optionally negated (an exponent or pow's second argument).
    fn exponent(&mut self) -> Result<f32, ParseError> {
        let negative = self.peek_op("-");
        if negative {
            self.at += 1;
        }
        match self.toks.get(self.at) {
            Some((Tok::Num(v), col)) => {
                let col = *col;
                self.at += 1;
                let Expr::Lit(p) = lit(*v, col)? else { unreachable!("lit gives a literal") };
                Ok(if negative { -p } else { p })
            }
            _ => {
                let found = self.describe();
                self.err(format!("an exponent must be a number, found {found} (write exp2(y * log2(x)) for a variable one)"))
            }
        }
    }

    fn atom(&mut self) -> Result<Expr, ParseError> {
        let Some((tok, col)) = self.toks.get(self.at).cloned() else {
            return self.err("expected a number, a name or '(', found the end".into());
        };
        match tok {
            Tok::Num(v) => {
                self.at += 1;
                lit(v, col)
            }
            Tok::Op("(") => {
                self.at += 1;
                self.deeper()?;
                let e = self.sum()?;
                self.expect(")")?;
                self.depth -= 1;
                Ok(e)
            }
            Tok::Name(name) => {
                self.at += 1;
                if self.peek_op("(") {
                    return self.call(&name, col);
                }
                if FUNCTIONS.iter().any(|(f, _)| *f == name) {
                    return Err(ParseError { column: col, message: format!("'{name}' is a function: write {name}(…)") });
                }
                self.scope
                    .resolve(&name)
                    .ok_or_else(|| ParseError { column: col, message: format!("unknown name '{name}' (names: {})", self.scope.known()) })
            }
            Tok::Op(_) => {
                let found = self.describe();
                self.err(format!("expected a number, a name or '(', found {found}"))
            }
        }
    }

    fn call(&mut self, name: &str, col: usize) -> Result<Expr, ParseError> {
        let Some(&(_, n)) = FUNCTIONS.iter().find(|(f, _)| *f == name) else {
            let known: Vec<&str> = FUNCTIONS.iter().map(|f| f.0).collect();
            return Err(ParseError { column: col, message: format!("unknown function '{name}' (functions: {})", known.join(", ")) });
        };
        self.expect("(")?;
        self.deeper()?;
        let mut args = Vec::new();
        for k in 0..n {
            if k > 0 {
                self.expect(",")?;
            }
            args.push(match (name, k) {
                ("pow", 1) => Arg::Number(self.exponent()?),
                ("select", 2) => self.comparison()?,
                _ => Arg::Expr(self.sum()?),
            });
        }
        if self.peek_op(",") {
            return self.err(format!("{name} takes {n} argument{}", if n == 1 { "" } else { "s" }));
        }
        self.expect(")")?;
        self.depth -= 1;
        let mut it = args.into_iter();
        let mut next = || it.next().expect("n arguments were parsed");
        let b = Box::new;
        Ok(match name {
            "min" => Expr::Min(b(next().expr()), b(next().expr())),
            "max" => Expr::Max(b(next().expr()), b(next().expr())),
            "clamp" => Expr::Clamp(b(next().expr()), b(next().expr()), b(next().expr())),
            "saturate" => Expr::Clamp(b(next().expr()), b(Expr::Lit(0.0)), b(Expr::Lit(1.0))),
            "mix" => {
                let (a, c, t) = (next().expr(), next().expr(), next().expr());
                a.clone() + (c - a) * t
            }
            "sqrt" => Expr::Sqrt(b(next().expr())),
            "inversesqrt" => Expr::Lit(1.0) / Expr::Sqrt(b(next().expr())),
            "exp2" => Expr::Exp2(b(next().expr())),
            "log2" => Expr::Log2(b(next().expr())),
            "exp" => Expr::Exp2(b(next().expr() * Expr::Lit(std::f32::consts::LOG2_E))),
            "log" => Expr::Log2(b(next().expr())) * Expr::Lit(std::f32::consts::LN_2),
            "abs" => Expr::Abs(b(next().expr())),
            "pow" => {
                let x = next().expr();
                let Arg::Number(p) = next() else { unreachable!("pow's exponent is a number") };
                power(x, p)
            }
            "select" => {
                let (f, t) = (next().expr(), next().expr());
                let Arg::Compare(op, x, y) = next() else { unreachable!("select's condition is a comparison") };
                // a < b ? t : f; the others by swapping the operands or the results.
                match op {
                    "<" => Expr::Less(b(x), b(y), b(t), b(f)),
                    ">" => Expr::Less(b(y), b(x), b(t), b(f)),
                    ">=" => Expr::Less(b(x), b(y), b(f), b(t)),
                    _ => Expr::Less(b(y), b(x), b(f), b(t)),
                }
            }
            term => {
                let pi = self.scope.resolve("pi").expect("pi is always a name");
                shading_term(term, (0..n).map(|_| next().expr()).collect(), pi)
            }
        })
    }

    fn comparison(&mut self) -> Result<Arg, ParseError> {
        let x = self.sum()?;
        for op in ["<=", ">=", "<", ">"] {
            if self.peek_op(op) {
                self.at += 1;
                let y = self.sum()?;
                return Ok(Arg::Compare(op, x, y));
            }
        }
        let found = self.describe();
        self.err(format!("select's third argument is a comparison (a < b, a > b, a <= b or a >= b), found {found}"))
    }
}

enum Arg {
    Expr(Expr),
    Number(f32),
    Compare(&'static str, Expr, Expr),
}

impl Arg {
    fn expr(self) -> Expr {
        match self {
            Arg::Expr(e) => e,
            _ => unreachable!("only pow's and select's last arguments are not expressions"),
        }
    }
}

/// The shading terms (see the module doc) written in the IR's operations; `pi` is the scope's.
fn shading_term(name: &str, args: Vec<Expr>, pi: Expr) -> Expr {
    let one = || Expr::Lit(1.0);
    let lit = Expr::Lit;
    let a = |k: usize| args[k].clone();
    match name {
        "d_ggx" => {
            let a2 = a(1) * a(1);
            // 1 − n·h²(1 − α²) as (1 − n·h²) + n·h² α²: in f32, α² − 1 rounds to −1 for α
            // below ~2.4e-4 and the peak's denominator to 0.
            let c2 = a(0) * a(0);
            let q = (one() - c2.clone()) + c2 * a2.clone();
            a2 / (pi * (q.clone() * q))
        }
        "v_smith_ggx_correlated" => {
            let a2 = a(2) * a(2);
            let root = |x: Expr| Expr::Sqrt(Box::new(x.clone() * x * (one() - a2.clone()) + a2.clone()));
            lit(0.5) / (a(1) * root(a(0)) + a(0) * root(a(1)))
        }
        "v_smith_schlick" => {
            let g = |x: Expr| x * (one() - a(2)) + a(2);
            lit(0.25) / (g(a(0)) * g(a(1)))
        }
        "d_charlie" => {
            let s2 = Expr::Max(Box::new(one() - a(0) * a(0)), Box::new(lit(0.0)));
            let power = Expr::Exp2(Box::new(Expr::Log2(Box::new(s2)) * (lit(0.5) / a(1))));
            (lit(2.0) + one() / a(1)) * power / (lit(2.0) * pi)
        }
        "v_neubelt" => lit(0.25) / (a(1) + a(0) - a(1) * a(0)),
        "f_schlick" => {
            let m = one() - a(2);
            a(0) + (a(1) - a(0)) * (m.clone() * m.clone() * m.clone() * m.clone() * m)
        }
        _ => unreachable!("every function is listed"),
    }
}

/// x^p: a whole p in 2…8 as multiplications, 1 as x, anything else as `pow`.
fn power(x: Expr, p: f32) -> Expr {
    if p == 1.0 {
        return x;
    }
    if p.fract() == 0.0 && (2.0..=8.0).contains(&p) {
        let mut e = x.clone();
        for _ in 1..p as usize {
            e = e * x.clone();
        }
        return e;
    }
    Expr::Pow(Box::new(x), p)
}

/// Parse `text` with the names of `scope`.
pub fn parse(text: &str, scope: Scope<'_>) -> Result<Expr, ParseError> {
    let len = text.chars().count();
    if len > MAX_LEN {
        return Err(ParseError { column: MAX_LEN + 1, message: format!("longer than {MAX_LEN} characters") });
    }
    let toks = tokens(text)?;
    if toks.is_empty() {
        return Err(ParseError { column: 1, message: "empty expression".into() });
    }
    let mut p = Parser { toks, at: 0, end: len + 1, scope, depth: 0 };
    let e = p.sum()?;
    if p.at < p.toks.len() {
        let found = p.describe();
        return p.err(format!("unexpected {found} after a complete expression"));
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::expr::eval_f64;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    /// Evaluate `text` over inputs (x, y) = (0.3, 2.0) and constants (c = 1.5).
    fn at(text: &str) -> f64 {
        let (inputs, constants) = (names(&["x", "y"]), names(&["c"]));
        let e = parse(text, Scope { inputs: &inputs, constants: &constants, lets: &[] }).unwrap_or_else(|e| panic!("{text}: {e}"));
        eval_f64(&e, &[0.3, 2.0], &[1.5], &[])
    }

    fn err(text: &str) -> ParseError {
        let (inputs, constants) = (names(&["x", "y"]), names(&["c"]));
        parse(text, Scope { inputs: &inputs, constants: &constants, lets: &[] }).expect_err(text)
    }

    /// Precedence and associativity as in WGSL and mathematics, each checked against the same
    /// arithmetic written in Rust (the literals are f32, so those enter as f32 values): − binds
    /// looser than ^, * and / before + and −, both left to right.
    #[test]
    fn precedence_and_functions_follow_the_usual_rules() {
        let (x, y, c) = (0.3f64, 2.0f64, 1.5f64);
        let f = |v: f64| v as f32 as f64;
        assert_eq!(at("x + y * c"), x + y * c);
        assert_eq!(at("x - y - c"), (x - y) - c);
        assert_eq!(at("x / y / c"), (x / y) / c);
        assert_eq!(at("-x^2"), -(x * x));
        assert_eq!(at("(x + y)^3"), (x + y) * (x + y) * (x + y));
        assert_eq!(at("y^0.5"), y.powf(0.5));
        assert_eq!(at("y^-1.5"), y.powf(-1.5));
        assert_eq!(at("pow(y, 2)"), y * y);
        assert_eq!(at("1 - 0.55 * x"), 1.0 - f(0.55) * x);
        assert_eq!(at("min(x, y) + max(x, y)"), x + y);
        assert_eq!(at("clamp(y, 0, 1)"), 1.0);
        assert_eq!(at("saturate(-y)"), 0.0);
        assert_eq!(at("mix(x, y, 0.25)"), x + (y - x) * 0.25);
        assert_eq!(at("sqrt(y) * inversesqrt(y)"), y.sqrt() * (1.0 / y.sqrt()));
        assert_eq!(at("exp2(x) + log2(y)"), x.exp2() + y.log2());
        assert_eq!(at("exp(x)"), (x * f(std::f64::consts::LOG2_E)).exp2());
        assert_eq!(at("log(y)"), y.log2() * f(std::f64::consts::LN_2));
        assert_eq!(at("abs(x - y)"), (x - y).abs());
        assert_eq!(at("pi"), f(std::f64::consts::PI));
        assert_eq!(at(".5e1 + 2E-1"), 5.0 + f(0.2));
        for (cond, holds) in [("x < y", true), ("x > y", false), ("x <= x", true), ("x >= y", false), ("y >= y", true), ("y <= x", false)] {
            assert_eq!(at(&format!("select(10, 20, {cond})")), if holds { 20.0 } else { 10.0 }, "{cond}");
        }
    }

    /// Bindings and constants resolve to their IR nodes; a binding is found before a constant of
    /// the same name would be (the spec refuses such a pair).
    #[test]
    fn names_resolve_to_inputs_constants_and_bindings() {
        let (inputs, constants, lets) = (names(&["x"]), names(&["k"]), names(&["t"]));
        let e = parse("t * k + x", Scope { inputs: &inputs, constants: &constants, lets: &lets }).unwrap();
        assert_eq!(e, Expr::Let(0) * Expr::Coef(0, 0) + Expr::Var(0));
    }

    /// Every malformed expression is refused at the column of its fault, saying what was
    /// expected; nothing panics, and nesting or length past the limits is refused.
    #[test]
    fn bad_expressions_are_refused_at_their_column() {
        let cases: &[(&str, usize, &str)] = &[
            ("x +", 4, "found the end"),
            ("x + * y", 5, "expected a number"),
            ("x y", 3, "unexpected 'y'"),
            ("(x + y", 7, "expected ')'"),
            ("x + zz", 5, "unknown name 'zz' (names: x, y, c, pi)"),
            ("foo(x)", 1, "unknown function 'foo'"),
            ("min(x)", 6, "expected ','"),
            ("min(x, y, c)", 9, "min takes 2 arguments"),
            ("sqrt", 1, "'sqrt' is a function"),
            ("x ^ y", 5, "an exponent must be a number"),
            ("pow(x, y)", 8, "an exponent must be a number"),
            ("select(x, y, c)", 15, "select's third argument is a comparison"),
            ("x # y", 3, "unexpected character '#'"),
            ("1e39", 1, "outside f32's range"),
            ("1.2.3", 1, "not a number"),
            ("", 1, "empty expression"),
            ("   ", 1, "empty expression"),
        ];
        for &(text, column, message) in cases {
            let e = err(text);
            assert_eq!(e.column, column, "{text}: {e}");
            assert!(e.message.contains(message), "{text}: {e}");
        }
        let deep = format!("{}x{}", "(".repeat(MAX_DEPTH + 1), ")".repeat(MAX_DEPTH + 1));
        assert!(err(&deep).message.contains("nested more than"));
        assert!(err(&"-".repeat(MAX_DEPTH + 1)).message.contains("nested more than"));
        assert!(err(&"x+".repeat(MAX_LEN)).message.contains("longer than"));
    }

    /// The shading terms are the shading layer's closed forms: with inputs (n·v, n·l, n·h, v·h,
    /// α) and `pi` bound to π in f64 (a lobe's scope), each agrees with the f64 function of
    /// the layer (or the formula as published) to ~10 roundings of values ≤ 1e6 (1e-12
    /// relative); the literals ½ and ¼ are exact in f32.
    #[test]
    fn the_shading_terms_are_the_shading_layers_functions() {
        use crate::shading::{charlie, trowbridge_reitz};
        let (inputs, constants) = (names(&["nv", "nl", "nh", "vh", "a"]), names(&["pi"]));
        let term = |text: &str, x: [f64; 5]| {
            let e = parse(text, Scope { inputs: &inputs, constants: &constants, lets: &[] }).unwrap();
            eval_f64(&e, &x, &[std::f64::consts::PI], &[])
        };
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-300);
        for &[nv, nl, nh, vh, a] in &[[0.3, 0.7, 0.9, 0.6, 0.2], [1.0, 0.05, 0.999, 0.1, 0.01], [0.0, 0.5, 0.4, 0.8, 1.0]] {
            let x = [nv, nl, nh, vh, a];
            assert!(close(term("d_ggx(nh, a)", x), trowbridge_reitz::d(a, nh)), "d_ggx at {x:?}");
            // G2/(4 n·v n·l) = 1/(4 n·v n·l (1 + Λv + Λl)), Λ of GGX (Heitz 2014, Eq. 72).
            let g2 = 1.0 / (1.0 + trowbridge_reitz::lambda(a, nv) + trowbridge_reitz::lambda(a, nl));
            if nv > 0.0 {
                assert!(close(term("v_smith_ggx_correlated(nv, nl, a)", x), g2 / (4.0 * nv * nl)), "V at {x:?}");
            }
            let k = 0.5 * a;
            assert!(close(term("v_smith_schlick(nv, nl, a / 2)", x), 0.25 / ((nv * (1.0 - k) + k) * (nl * (1.0 - k) + k))));
            let sh = (1.0 - nh * nh).sqrt();
            assert!(close(term("d_charlie(nh, a)", x), charlie::d_charlie(a, sh)), "d_charlie at {x:?}");
            assert!(close(term("v_neubelt(nv, nl)", x), 0.25 / (nl + nv - nl * nv)));
            assert!(close(term("f_schlick(a, 1, vh)", x), a + (1.0 - a) * (1.0 - vh).powi(5)));
        }
        assert_eq!(term("d_charlie(nh, a)", [0.5, 0.5, 1.0, 1.0, 0.3]), 0.0, "Charlie's D vanishes at n·h = 1");
        assert!(err("d_ggx(x)").message.contains("expected ','"), "{}", err("d_ggx(x)").message);
    }
}
