//! Operation counts of WGSL functions from naga's IR.
//!
//! # What is counted
//! Each expression a function evaluates, once (naga's expressions are a DAG: a `let` used
//! twice is computed once), plus the inclusive cost of every function it calls, per call;
//! vector operations count once per component. Columns:
//! - `add`, `mul`, `div`: f32 `+ −`, `×`, `/` (a `dot` of n components is n mul + n−1 add,
//!   `mix` 2 add + 1 mul per component, `normalize` its dot + 1 inverseSqrt + n mul);
//! - `transc`: sin, cos, exp, log, pow, sqrt, inverseSqrt and the like (the special-function
//!   unit on most GPUs), named in `transc_fns`;
//! - `tex`: texture fetches (`textureLoad`, `textureSample*`);
//! - `const_loads`: loads from a module-scope `const` array at a computed index (the tables: a
//!   real memory load). Loads at a constant index (the fit coefficients, `NUM[k]`) do not
//!   appear: naga's constant evaluator folds them into immediates while parsing;
//! - `other`: comparisons, select, clamp/min/max/abs, integer and bit operations, float ↔ int
//!   conversions (a bitcast is free and not counted).
//!
//! Both sides of a branch are counted. A loop's body and continuing block count once, the cost
//! of one iteration (trip counts are data; `loops` says how many loops the counts hold); stores
//! to locals are free (register writes). Counts are of the WGSL as written, with no
//! common-subexpression elimination and no fusing of `a*b + c`: they rank forms rather than
//! predict cycles. [`OpCounts::weighted`] folds them into one number for that ranking.

use naga::{BinaryOperator as B, Expression as E, Handle, MathFunction as M, ScalarKind, Statement, TypeInner};
use serde::Serialize;
use std::collections::{BTreeSet, HashMap};

/// Weight of a divide or a transcendental call in [`OpCounts::weighted`]: they run on the
/// special-function unit at a quarter of the rate of adds and multiplies on most GPUs (a
/// divide is a reciprocal and a multiply).
pub const SFU_WEIGHT: usize = 4;
/// Weight of a texture fetch or a `const`-array load at a computed index: the issue cost of a
/// memory access whose latency other work hides, not its latency.
pub const MEMORY_WEIGHT: usize = 4;

/// Operation counts of one function, inclusive of its callees.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct OpCounts {
    pub add: usize,
    pub mul: usize,
    pub div: usize,
    pub transc: usize,
    pub tex: usize,
    pub const_loads: usize,
    pub other: usize,
    /// Loops in the function and its callees, each counted for one iteration.
    pub loops: usize,
    /// The transcendental functions called (sin, cos, sqrt, ...).
    pub transc_fns: BTreeSet<&'static str>,
}

impl OpCounts {
    /// Add another function's counts (a call, or a second function of the same form).
    pub fn plus(&mut self, o: &OpCounts) {
        self.add += o.add;
        self.mul += o.mul;
        self.div += o.div;
        self.transc += o.transc;
        self.tex += o.tex;
        self.const_loads += o.const_loads;
        self.other += o.other;
        self.loops += o.loops;
        self.transc_fns.extend(o.transc_fns.iter().copied());
    }

    /// Arithmetic total (add + mul + div + transc).
    pub fn arith(&self) -> usize {
        self.add + self.mul + self.div + self.transc
    }

    /// One cost for ranking forms: add, mul and other count 1, divides and transcendentals
    /// [`SFU_WEIGHT`], texture fetches and table loads [`MEMORY_WEIGHT`].
    pub fn weighted(&self) -> usize {
        self.add + self.mul + self.other + SFU_WEIGHT * (self.div + self.transc) + MEMORY_WEIGHT * (self.tex + self.const_loads)
    }
}

/// Why a source could not be counted.
#[derive(Debug, thiserror::Error)]
pub enum OpsError {
    #[error("WGSL does not parse: {0}")]
    Parse(String),
    #[error("WGSL does not validate: {0}")]
    Invalid(String),
    #[error("no function `{0}` in the WGSL source")]
    NoFunction(String),
    #[error("{function}: no cost for {what} (add it to the cost model in src/bench/ops.rs)")]
    Unsupported { function: String, what: String },
}

/// A parsed, validated WGSL source with type information.
pub struct Source {
    module: naga::Module,
    info: naga::valid::ModuleInfo,
}

type Memo = HashMap<Handle<naga::Function>, OpCounts>;

impl Source {
    /// Parse and validate; `#` directive lines (`#define_import_path`, `#import`) are dropped
    /// first, so an emitted library with no imports parses as it is.
    pub fn parse(wgsl_source: &str) -> Result<Source, OpsError> {
        let src = crate::emit::wgsl::strip_directives(wgsl_source);
        let module = naga::front::wgsl::parse_str(&src).map_err(|e| OpsError::Parse(e.emit_to_string(&src)))?;
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .map_err(|e| OpsError::Invalid(e.emit_to_string(&src)))?;
        Ok(Source { module, info })
    }

    /// The functions of the source, in order.
    pub fn function_names(&self) -> Vec<String> {
        self.module.functions.iter().filter_map(|(_, f)| f.name.clone()).collect()
    }

    /// Inclusive counts of one function.
    pub fn count(&self, function: &str) -> Result<OpCounts, OpsError> {
        self.counts(self.handle(function)?, &mut Memo::new())
    }

    /// Inclusive counts of every function, in order (callees counted once and reused).
    pub fn count_all(&self) -> Result<Vec<(String, OpCounts)>, OpsError> {
        let mut memo = Memo::new();
        self.function_names().into_iter().map(|n| Ok((n.clone(), self.counts(self.handle(&n)?, &mut memo)?))).collect()
    }

    fn handle(&self, name: &str) -> Result<Handle<naga::Function>, OpsError> {
        self.module
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(name))
            .map(|(h, _)| h)
            .ok_or_else(|| OpsError::NoFunction(name.into()))
    }

    fn unsupported(&self, f: Handle<naga::Function>, what: String) -> OpsError {
        OpsError::Unsupported { function: self.module.functions[f].name.clone().unwrap_or_default(), what }
    }

    /// Components of an expression's type (1 for scalars).
    fn width(&self, f: Handle<naga::Function>, e: Handle<E>) -> usize {
        match self.info[f][e].ty.inner_with(&self.module.types) {
            TypeInner::Vector { size, .. } => *size as usize,
            TypeInner::Matrix { columns, rows, .. } => *columns as usize * *rows as usize,
            _ => 1,
        }
    }

    fn is_float(&self, f: Handle<naga::Function>, e: Handle<E>) -> bool {
        self.info[f][e].ty.inner_with(&self.module.types).scalar_kind() == Some(ScalarKind::Float)
    }

    fn counts(&self, f: Handle<naga::Function>, memo: &mut Memo) -> Result<OpCounts, OpsError> {
        if let Some(c) = memo.get(&f) {
            return Ok(c.clone());
        }
        let mut c = OpCounts::default();
        self.block(f, &self.module.functions[f].body, &mut c, memo)?;
        memo.insert(f, c.clone());
        Ok(c)
    }

    fn block(&self, f: Handle<naga::Function>, block: &naga::Block, c: &mut OpCounts, memo: &mut Memo) -> Result<(), OpsError> {
        for s in block.iter() {
            match s {
                Statement::Emit(range) => {
                    for e in range.clone() {
                        self.expr(f, e, c)?;
                    }
                }
                Statement::Block(b) => self.block(f, b, c, memo)?,
                Statement::If { accept, reject, .. } => {
                    self.block(f, accept, c, memo)?;
                    self.block(f, reject, c, memo)?;
                }
                Statement::Call { function, .. } => {
                    let callee = self.counts(*function, memo)?;
                    c.plus(&callee);
                }
                Statement::Loop { body, continuing, .. } => {
                    c.loops += 1;
                    self.block(f, body, c, memo)?;
                    self.block(f, continuing, c, memo)?;
                }
                Statement::Return { .. } | Statement::Store { .. } | Statement::Break | Statement::Continue => {}
                other => return Err(self.unsupported(f, format!("statement {other:?}"))),
            }
        }
        Ok(())
    }

    fn expr(&self, f: Handle<naga::Function>, e: Handle<E>, c: &mut OpCounts) -> Result<(), OpsError> {
        let func = &self.module.functions[f];
        let w = self.width(f, e);
        match &func.expressions[e] {
            E::Binary { op, left, .. } => {
                let float = self.is_float(f, *left);
                match op {
                    B::Add | B::Subtract if float => c.add += w,
                    B::Multiply if float => c.mul += w,
                    B::Divide if float => c.div += w,
                    _ => c.other += w,
                }
            }
            E::Unary { .. } => {} // negation folds into the consumer on GPUs
            E::Access { base, .. } => {
                if matches!(func.expressions[*base], E::Constant(_)) {
                    c.const_loads += 1;
                }
            }
            E::AccessIndex { base, .. } => {
                if matches!(func.expressions[*base], E::Constant(_)) {
                    return Err(self.unsupported(f, "a constant-index load naga did not fold".into()));
                }
            }
            E::Select { .. } => c.other += w,
            E::As { convert: Some(_), .. } => c.other += w,
            E::As { convert: None, .. } => {} // bitcast
            E::ImageSample { .. } | E::ImageLoad { .. } => c.tex += 1,
            E::Math { fun, arg, .. } => {
                let n = self.width(f, *arg);
                let mut transc = |name: &'static str, k: usize| {
                    c.transc += k;
                    c.transc_fns.insert(name);
                };
                match fun {
                    M::Sin => transc("sin", w),
                    M::Cos => transc("cos", w),
                    M::Tan => transc("tan", w),
                    M::Exp => transc("exp", w),
                    M::Exp2 => transc("exp2", w),
                    M::Log => transc("log", w),
                    M::Log2 => transc("log2", w),
                    M::Pow => transc("pow", w),
                    M::Sqrt => transc("sqrt", w),
                    M::InverseSqrt => transc("inverseSqrt", w),
                    M::Atan => transc("atan", w),
                    M::Acos => transc("acos", w),
                    M::Asin => transc("asin", w),
                    M::Atan2 => transc("atan2", w),
                    M::Length => {
                        transc("sqrt", 1);
                        c.mul += n;
                        c.add += n - 1;
                    }
                    M::Normalize => {
                        transc("inverseSqrt", 1);
                        c.mul += 2 * n;
                        c.add += n - 1;
                    }
                    M::Dot => {
                        c.mul += n;
                        c.add += n - 1;
                    }
                    M::Cross => {
                        c.mul += 6;
                        c.add += 3;
                    }
                    M::Mix => {
                        c.add += 2 * w;
                        c.mul += w;
                    }
                    M::Fma => {
                        c.add += w;
                        c.mul += w;
                    }
                    M::Clamp | M::Min | M::Max | M::Abs | M::Saturate | M::Floor | M::Ceil | M::Fract | M::Round | M::Trunc | M::Sign => {
                        c.other += w
                    }
                    other => return Err(self.unsupported(f, format!("{other:?}"))),
                }
            }
            // Free: names, constants, construction, swizzles, call results.
            E::Literal(_)
            | E::Constant(_)
            | E::Override(_)
            | E::ZeroValue(_)
            | E::Compose { .. }
            | E::Splat { .. }
            | E::Swizzle { .. }
            | E::FunctionArgument(_)
            | E::GlobalVariable(_)
            | E::LocalVariable(_)
            | E::Load { .. }
            | E::CallResult(_) => {}
            other => return Err(self.unsupported(f, format!("expression {other:?}"))),
        }
        Ok(())
    }
}

/// Inclusive operation counts of `function` in a WGSL source (directive lines dropped).
pub fn count(wgsl_source: &str, function: &str) -> Result<OpCounts, OpsError> {
    Source::parse(wgsl_source)?.count(function)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_a_hand_written_function() {
        // Hand count: a*b + c (1 mul, 1 add); / d (1 div); sqrt (1 transc); clamp (1 other);
        // the vec3 product v*s (3 mul) and dot(v, v) (3 mul, 2 add); T[i] at a computed index
        // (1 const load) and the integer i + 1u (1 other) for a second load; the call of g
        // (x*x: 1 mul) twice; f32(i) (1 other).
        let src = "#define_import_path shadefit::t\n\
            const T: array<f32, 4> = array<f32, 4>(1.0, 2.0, 3.0, 4.0);\n\
            fn g(x: f32) -> f32 { return x * x; }\n\
            fn f(a: f32, b: f32, c: f32, d: f32, i: u32, v: vec3<f32>) -> f32 {\n\
                let s = sqrt((a * b + c) / d);\n\
                let w = v * s;\n\
                let k = clamp(s, 0.0, 1.0) + dot(w, w);\n\
                return k + T[i] + T[i + 1u] + g(a) + g(b) + f32(i);\n\
            }\n";
        let c = count(src, "f").unwrap();
        // adds: a*b + c, clamp(..) + dot, k + T[i], + T[i+1], + g(a), + g(b), + f32(i) = 7,
        // plus the dot's 2.
        assert_eq!((c.add, c.mul, c.div, c.transc, c.tex, c.const_loads, c.other), (9, 1 + 3 + 3 + 2, 1, 1, 0, 2, 3), "{c:?}");
        assert_eq!(c.transc_fns.iter().copied().collect::<Vec<_>>(), vec!["sqrt"]);
        // add + mul + other + 4·(div + transc) + 4·loads
        assert_eq!(c.weighted(), 9 + 9 + 3 + 4 * 2 + 4 * 2);
        assert!(matches!(count(src, "h"), Err(OpsError::NoFunction(_))));
        assert!(matches!(count("fn f( {", "f"), Err(OpsError::Parse(_))));
    }

    /// A loop counts one iteration: its body (the add, the mul and the store to a local, which
    /// is free) and its continuing block (i++: 1 other), and the loop guard (i < n: 1 other).
    #[test]
    fn a_loop_counts_one_iteration() {
        let src = "fn f(n: u32, x: f32) -> f32 {\n\
                var s = 0f;\n\
                for (var i = 0u; i < n; i++) { s += x * x; }\n\
                return s;\n\
            }\n";
        let c = count(src, "f").unwrap();
        assert_eq!((c.add, c.mul, c.loops), (1, 1, 1), "{c:?}");
        assert_eq!(c.other, 2, "{c:?}");
    }
}
