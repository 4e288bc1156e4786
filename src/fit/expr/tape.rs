//! A scalar [`Program`] compiled to a flat list of f64 operations on registers, for the inner
//! loops of refits (one objective evaluation visits every point of a grid). The operations are
//! those of [`super::eval_as`] on one lane in the same order (f64's `min`/`max`, clamp as
//! `max(lo).min(hi)`, literals as their f32 values), so a tape's results are bit for bit the
//! program's `eval_f64`; it skips the tree walk and the four lanes a program value carries, and
//! computes a repeated sub-expression once (the same operation of the same registers is one
//! register: pure operations give the same bits).

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

fn emit(e: &Expr, ops: &mut Vec<Op>, lets: &[usize]) -> Option<usize> {
    let two = |a: &Expr, b: &Expr, ops: &mut Vec<Op>, f: fn(usize, usize) -> Op| -> Option<Op> {
        let a = emit(a, ops, lets)?;
        let b = emit(b, ops, lets)?;
        Some(f(a, b))
    };
    let op = match e {
        Expr::Lit(v) => Op::Lit(*v as f64),
        Expr::Var(i) => Op::Var(*i),
        Expr::Coef(0, j) => Op::Coef(*j),
        Expr::Let(k) => return lets.get(*k).copied(),
        Expr::Add(a, b) => two(a, b, ops, Op::Add)?,
        Expr::Sub(a, b) => two(a, b, ops, Op::Sub)?,
        Expr::Mul(a, b) => two(a, b, ops, Op::Mul)?,
        Expr::Div(a, b) => two(a, b, ops, Op::Div)?,
        Expr::Min(a, b) => two(a, b, ops, Op::Min)?,
        Expr::Max(a, b) => two(a, b, ops, Op::Max)?,
        Expr::Neg(a) => Op::Neg(emit(a, ops, lets)?),
        Expr::Sqrt(a) => Op::Sqrt(emit(a, ops, lets)?),
        Expr::Exp2(a) => Op::Exp2(emit(a, ops, lets)?),
        Expr::Log2(a) => Op::Log2(emit(a, ops, lets)?),
        Expr::Abs(a) => Op::Abs(emit(a, ops, lets)?),
        Expr::Pow(a, p) => Op::Pow(emit(a, ops, lets)?, *p as f64),
        Expr::Clamp(x, lo, hi) => {
            let (x, lo, hi) = (emit(x, ops, lets)?, emit(lo, ops, lets)?, emit(hi, ops, lets)?);
            Op::Clamp(x, lo, hi)
        }
        Expr::Select(c, a, b) => {
            let (c, a, b) = (emit(c, ops, lets)?, emit(a, ops, lets)?, emit(b, ops, lets)?);
            Op::Positive(c, a, b)
        }
        Expr::Less(x, y, a, b) => {
            let (x, y, a, b) = (emit(x, ops, lets)?, emit(y, ops, lets)?, emit(a, ops, lets)?, emit(b, ops, lets)?);
            Op::Less(x, y, a, b)
        }
        // Vectors (other than a result of scalar lanes) and denominator coefficients are not
        // compiled.
        Expr::Coef(..) | Expr::Vector(_) | Expr::Splat(..) | Expr::Swizzle(..) => return None,
    };
    // An operation already on the tape (the same operation of the same registers) is that
    // register: the shading terms repeat their arguments, bindings repeat sub-expressions.
    if let Some(i) = ops.iter().position(|o| *o == op) {
        return Some(i);
    }
    ops.push(op);
    Some(ops.len() - 1)
}

impl Tape {
    /// The tape of a program whose bindings are scalars and whose result is a scalar or a
    /// vector of scalar lanes; `None` for any other program.
    pub fn compile(p: &Program) -> Option<Tape> {
        let mut ops = Vec::new();
        let mut lets = Vec::new();
        for (_, e) in &p.lets {
            let r = emit(e, &mut ops, &lets)?;
            lets.push(r);
        }
        let results = match &p.result {
            Expr::Vector(items) => items.iter().map(|e| emit(e, &mut ops, &lets)).collect::<Option<Vec<_>>>()?,
            e => vec![emit(e, &mut ops, &lets)?],
        };
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
        let vector = Program { lets: vec![], result: Expr::Splat(2, Box::new(Expr::Var(0))) };
        assert!(Tape::compile(&vector).is_none());
    }
}
