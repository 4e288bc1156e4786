//! A scalar [`Program`] compiled to a flat list of f64 operations on registers, for the inner
//! loops of refits (one objective evaluation visits every point of a grid). The operations are
//! those of [`super::eval_as`] on one lane in the same order (f64's `min`/`max`, clamp as
//! `max(lo).min(hi)`, literals as their f32 values), so a tape's results are bit for bit the
//! program's `eval_f64`; it skips the tree walk and the lanes of a scalar (a vector's lanes are
//! registers of their own), and computes a repeated sub-expression once (the same operation of
//! the same registers is one register: pure operations give the same bits).

use super::Expr;
use super::program::Program;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Lit(f64),
    Var(usize),
    Coef(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Neg(usize),
    Min(usize, usize),
    Max(usize, usize),
    Clamp(usize, usize, usize),
    Positive(usize, usize, usize),
    Less(usize, usize, usize, usize),
    Sqrt(usize),
    Exp2(usize),
    Log2(usize),
    Abs(usize),
    Pow(usize, f64),
}

/// A compiled program: its operations and the registers of its results.
#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    ops: Vec<Op>,
    results: Vec<usize>,
}

/// A register holding `op`: the one already on the tape for the same operation of the same
/// registers (the shading terms repeat their arguments, bindings repeat sub-expressions, and
/// the lanes of a scalar are one register), else a new one.
fn intern(op: Op, ops: &mut Vec<Op>) -> usize {
    if let Some(i) = ops.iter().position(|o| *o == op) {
        return i;
    }
    ops.push(op);
    ops.len() - 1
}

/// The registers of a node's four lanes, as [`super::program::Lanes`] holds them: a scalar in
/// every lane, lane-wise operations on all four (lanes past a vector's length included, as
/// `Lanes` computes them), zeros where a vector or a swizzle leaves a lane empty.
fn emit(e: &Expr, ops: &mut Vec<Op>, lets: &[[usize; 4]]) -> Option<[usize; 4]> {
    let scalar = |op: Op, ops: &mut Vec<Op>| [intern(op, ops); 4];
    let one = |a: &Expr, ops: &mut Vec<Op>, f: &dyn Fn(usize) -> Op| -> Option<[usize; 4]> {
        let a = emit(a, ops, lets)?;
        Some(std::array::from_fn(|k| intern(f(a[k]), ops)))
    };
    let two = |a: &Expr, b: &Expr, ops: &mut Vec<Op>, f: fn(usize, usize) -> Op| -> Option<[usize; 4]> {
        let (a, b) = (emit(a, ops, lets)?, emit(b, ops, lets)?);
        Some(std::array::from_fn(|k| intern(f(a[k], b[k]), ops)))
    };
    Some(match e {
        Expr::Lit(v) => scalar(Op::Lit(*v as f64), ops),
        Expr::Var(i) => scalar(Op::Var(*i), ops),
        Expr::Coef(0, j) => scalar(Op::Coef(*j), ops),
        Expr::Let(k) => *lets.get(*k)?,
        Expr::Add(a, b) => two(a, b, ops, Op::Add)?,
        Expr::Sub(a, b) => two(a, b, ops, Op::Sub)?,
        Expr::Mul(a, b) => two(a, b, ops, Op::Mul)?,
        Expr::Div(a, b) => two(a, b, ops, Op::Div)?,
        Expr::Min(a, b) => two(a, b, ops, Op::Min)?,
        Expr::Max(a, b) => two(a, b, ops, Op::Max)?,
        Expr::Neg(a) => one(a, ops, &Op::Neg)?,
        Expr::Sqrt(a) => one(a, ops, &Op::Sqrt)?,
        Expr::Exp2(a) => one(a, ops, &Op::Exp2)?,
        Expr::Log2(a) => one(a, ops, &Op::Log2)?,
        Expr::Abs(a) => one(a, ops, &Op::Abs)?,
        Expr::Pow(a, p) => one(a, ops, &|r| Op::Pow(r, *p as f64))?,
        Expr::Clamp(x, lo, hi) => {
            let (x, lo, hi) = (emit(x, ops, lets)?, emit(lo, ops, lets)?, emit(hi, ops, lets)?);
            std::array::from_fn(|k| intern(Op::Clamp(x[k], lo[k], hi[k]), ops))
        }
        Expr::Select(c, a, b) => {
            let (c, a, b) = (emit(c, ops, lets)?, emit(a, ops, lets)?, emit(b, ops, lets)?);
            std::array::from_fn(|k| intern(Op::Positive(c[k], a[k], b[k]), ops))
        }
        Expr::Less(x, y, a, b) => {
            let (x, y, a, b) = (emit(x, ops, lets)?, emit(y, ops, lets)?, emit(a, ops, lets)?, emit(b, ops, lets)?);
            std::array::from_fn(|k| intern(Op::Less(x[k], y[k], a[k], b[k]), ops))
        }
        Expr::Vector(items) => {
            let lanes = items.iter().map(|i| emit(i, ops, lets).map(|l| l[0])).collect::<Option<Vec<usize>>>()?;
            let zero = intern(Op::Lit(0.0), ops);
            std::array::from_fn(|k| lanes.get(k).copied().unwrap_or(zero))
        }
        Expr::Splat(_, x) => [emit(x, ops, lets)?[0]; 4],
        Expr::Swizzle(x, lanes) => {
            let x = emit(x, ops, lets)?;
            if let [k] = lanes.as_slice() {
                [x[*k as usize]; 4]
            } else {
                let zero = intern(Op::Lit(0.0), ops);
                std::array::from_fn(|k| lanes.get(k).map_or(zero, |&i| x[i as usize]))
            }
        }
        // Denominator coefficients are not compiled.
        Expr::Coef(..) => return None,
    })
}

impl Tape {
    /// The tape of a program (scalar or vector bindings and result); `None` for a program
    /// with denominator coefficients.
    pub fn compile(p: &Program) -> Option<Tape> {
        let mut ops = Vec::new();
        let mut lets = Vec::new();
        for (_, e) in &p.lets {
            let r = emit(e, &mut ops, &lets)?;
            lets.push(r);
        }
        let lanes = emit(&p.result, &mut ops, &lets)?;
        let results = lanes[..p.width().min(4)].to_vec();
        Some(Tape { ops, results })
    }

    /// Values a result holds.
    pub fn width(&self) -> usize {
        self.results.len()
    }

    /// The results at `inputs` with constants `consts` into `out` (`regs` is scratch space,
    /// reused between calls).
    pub fn eval(&self, inputs: &[f64], consts: &[f64], regs: &mut Vec<f64>, out: &mut [f64]) {
        regs.clear();
        for op in &self.ops {
            let r = |i: usize| regs[i];
            let v = match *op {
                Op::Lit(v) => v,
                Op::Var(i) => inputs[i],
                Op::Coef(j) => consts[j],
                Op::Add(a, b) => r(a) + r(b),
                Op::Sub(a, b) => r(a) - r(b),
                Op::Mul(a, b) => r(a) * r(b),
                Op::Div(a, b) => r(a) / r(b),
                Op::Neg(a) => -r(a),
                Op::Min(a, b) => r(a).min(r(b)),
                Op::Max(a, b) => r(a).max(r(b)),
                Op::Clamp(x, lo, hi) => r(x).max(r(lo)).min(r(hi)),
                Op::Positive(c, a, b) => if r(c) > 0.0 { r(a) } else { r(b) },
                Op::Less(x, y, a, b) => if r(x) < r(y) { r(a) } else { r(b) },
                Op::Sqrt(a) => r(a).sqrt(),
                Op::Exp2(a) => r(a).exp2(),
                Op::Log2(a) => r(a).log2(),
                Op::Abs(a) => r(a).abs(),
                Op::Pow(a, p) => r(a).powf(p),
            };
            regs.push(v);
        }
        for (o, &k) in out.iter_mut().zip(&self.results) {
            *o = regs[k];
        }
    }
}

/// A registered form's program compiled on first use, for its f64 evaluation in inner loops
/// (bit for bit the program's `eval_f64`; the scratch registers are per thread).
pub struct Compiled {
    program: &'static std::sync::LazyLock<Program>,
    tape: std::sync::OnceLock<Tape>,
}

impl Compiled {
    pub const fn of(program: &'static std::sync::LazyLock<Program>) -> Compiled {
        Compiled { program, tape: std::sync::OnceLock::new() }
    }

    /// The first `N` results at `inputs` with constants `consts`.
    pub fn eval<const N: usize>(&self, inputs: &[f64], consts: &[f64]) -> [f64; N] {
        thread_local! {
            static REGS: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut out = [0.0; N];
        let tape = self.tape.get_or_init(|| Tape::compile(self.program).expect("a registered form compiles"));
        REGS.with(|r| tape.eval(inputs, consts, &mut r.borrow_mut(), &mut out));
        out
    }

    /// [A, B] of a pair form.
    pub fn pair(&self, inputs: [f64; 2], consts: &[f64]) -> [f64; 2] {
        self.eval(&inputs, consts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::expr::parse::{Scope, parse};

    /// A tape gives the program's own f64 values bit for bit (every operation it compiles, on
    /// inputs where the branches go both ways, NaN included), and refuses vector programs it
    /// does not compile.
    #[test]
    fn a_tape_is_the_program_bit_for_bit() {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let (inputs, constants, lets) = (names(&["x", "y"]), names(&["c", "d"]), names(&["t"]));
        let scope = |n: usize| Scope { inputs: &inputs, constants: &constants, lets: &lets[..n] };
        let t = parse("x * c - y / d + -x", scope(0)).unwrap();
        let outputs = [
            "min(t, y) + max(t, x) + clamp(t, 0.1, 0.9) + saturate(y - x)",
            "select(sqrt(abs(t)), exp2(y) + log2(abs(x) + 1), t < y) + select(1, 2, x >= 0.5)",
            "pow(abs(t) + 0.5, 1.7) + t^3 - mix(x, y, 0.3) + exp(x) * log(y + 2) + inversesqrt(abs(t) + 1)",
        ];
        let program = Program { lets: vec![("t".into(), t)], result: Expr::Vector(outputs.iter().map(|o| parse(o, scope(1)).unwrap()).collect()) };
        let tape = Tape::compile(&program).expect("a scalar program compiles");
        assert_eq!(tape.width(), 3);
        let (mut regs, mut out) = (Vec::new(), vec![0.0; 3]);
        let consts = [1.25, -0.75];
        for x in [-1.5, -0.2, 0.0, 0.3, 0.5, 0.99, 2.0, f64::NAN] {
            for y in [-0.4, 0.0, 0.7, 3.0] {
                tape.eval(&[x, y], &consts, &mut regs, &mut out);
                let want = program.eval_f64(&[x, y], &consts);
                for k in 0..3 {
                    assert!(out[k].to_bits() == want[k].to_bits(), "output {k} at ({x}, {y}): {} vs {}", out[k], want[k]);
                }
            }
        }
        let denominator = Program { lets: vec![], result: Expr::Coef(1, 0) };
        assert!(Tape::compile(&denominator).is_none());
    }

    /// A vector program (vector bindings, splats, swizzles of one and of several lanes, a
    /// vector result) compiles to the program's own lanes bit for bit (the published pair
    /// forms are checked the same way in their family).
    #[test]
    fn a_vector_program_compiles_to_its_lanes_bit_for_bit() {
        let v = |e: Expr| Box::new(e);
        let edge = Program {
            lets: vec![("a".into(), Expr::Vector(vec![Expr::Var(0), Expr::Lit(0.5), Expr::Mul(v(Expr::Var(1)), v(Expr::Coef(0, 0)))]))],
            result: Expr::Add(
                v(Expr::Swizzle(v(Expr::Let(0)), vec![2, 0])),
                v(Expr::Mul(v(Expr::Splat(2, v(Expr::Swizzle(v(Expr::Let(0)), vec![1])))), v(Expr::Swizzle(v(Expr::Let(0)), vec![3, 1])))),
            ),
        };
        assert_eq!(same_bits(&edge, &[-1.5]), 2);
    }
}

/// Compiles `program` and checks its tape against the program's `eval_f64` bit for bit with
/// constants `consts` on a grid of two inputs through 0, 1 and a NaN; the tape's width.
#[cfg(test)]
pub fn same_bits(program: &Program, consts: &[f64]) -> usize {
    let tape = Tape::compile(program).expect("the program compiles");
    assert_eq!(tape.width(), program.width());
    let (mut regs, mut out) = (Vec::new(), vec![0.0; tape.width()]);
    for x in [0.0, 1.0 / 3.0, 0.5, 1.0, -0.25, f64::NAN] {
        for y in [0.0, 0.01, 0.7, 1.0] {
            tape.eval(&[x, y], consts, &mut regs, &mut out);
            let want = program.eval_f64(&[x, y], consts);
            assert_eq!(out.iter().map(|o| o.to_bits()).collect::<Vec<_>>(), want.iter().map(|w| w.to_bits()).collect::<Vec<_>>(), "at ({x}, {y})");
        }
    }
    tape.width()
}
