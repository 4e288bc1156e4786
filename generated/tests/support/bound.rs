//! Reference evaluation of an emitted WGSL function, with a bound on how far a conforming GPU
//! may be from it.
//!
//! The WGSL is parsed with naga and interpreted on the CPU in f32 with the operations the
//! source spells out (so the result must equal the Rust CPU version bit for bit: same
//! expressions, same order). Alongside each value the interpreter carries its possible
//! deviation Δ = GPU value − CPU value, for a GPU that follows the WGSL / Vulkan accuracy
//! rules, in affine form: Σ cᵢ·εᵢ + r with independent unknowns |εᵢ| ≤ 1 (one per rounding
//! event, so deviations that cancel, like the two weights of a lerp, do cancel) and a
//! remainder |r| ≤ rem for second-order and non-linear effects. The bound is Σ|cᵢ| + rem.
//!
//! - `+ − ×` are correctly rounded (WGSL "Floating Point Accuracy"): equal inputs give equal
//!   results, so Δ stays 0 until one of the rules below makes it non-zero. With deviating
//!   inputs, Δ(a ± b) = Δa ± Δb and Δ(ab) = aΔb + bΔa + ΔaΔb (the last term in `rem`), plus
//!   a new ε of 1 ulp of the result (each side rounds its own exact result by ≤ ½ ulp).
//! - FMA contraction: a GPU may fuse `a*b ± c` (skipping the product's rounding), so a sum
//!   or difference with a product operand gets a new ε of ½ ulp of that product, and the
//!   1 ulp rounding ε of the result.
//! - Constant folding across a product: without the NoContraction decoration (which neither
//!   WGSL nor naga emits) Vulkan lets a driver rewrite more than fusions. NVIDIA's driver
//!   (580.159, on an H200) computes a table index `(x − c)·k`, c and k constants, as
//!   `fma(x, k, −fl(c·k))`: at x = c the index is c·k − fl(c·k), −2.04e-5 for the gloss
//!   inverse table, not 0, and the lerp returns −8.0e-9 for a table that starts at 0. So a
//!   product of a constant k with a sum or difference that has a constant operand c gets a
//!   new ε of ½ ulp of c·k (the folded constant's rounding) plus |k|·½ ulp of the sum when
//!   the CPU's sum was inexact (the rounding the GPU skips).
//! - Division: within 2.5 ulp on the GPU (WGSL and Vulkan, for |divisor| in [2^-126, 2^126])
//!   and 0.5 ulp on the CPU: Δq = (Δa − qΔb)/b to first order (the rest in `rem`), plus a new
//!   ε of 3 ulp of the quotient.
//! - Subnormals may be flushed to zero: an argument or result below f32::MIN_POSITIVE in
//!   magnitude gets a new ε of its own magnitude. A normal CPU value v whose GPU side may be
//!   subnormal (|v| − bound < MIN_POSITIVE) may come back as 0: the deviation is then |v|,
//!   so it gets a new ε of |v| − bound (what the old bound lacks, less than MIN_POSITIVE).
//! - sqrt: 5 ulp of the result (1/inverseSqrt), plus min(Δ/(2√x), √Δ) for an input deviation Δ.
//! - sin/cos: WGSL (and Vulkan's SPIR-V precision table) allow an absolute error of 2^-11
//!   for arguments in [−π, π] (no bound outside: the evaluation panics if either side's
//!   argument may leave that range). The CPU value is Rust's f32 `sin`/`cos` (the platform
//!   libm), whose own error e_cpu = |cpu − sin x| is measured at each point against the f64
//!   function (itself within 2^-50 here). With GPU argument x' = x + Δx, GPU − CPU =
//!   [GPU − sin x'] + [sin x' − sin x] + [sin x − cpu] = 2^-11·ε₁ + cos(x)·Δx + r +
//!   (e_cpu + 2^-50)·ε₂ with |r| ≤ ½Δx² (|sin''| ≤ 1; likewise for cos with −sin(x)·Δx).
//!   So Δ passes through linearly with the slope, ½·rx² goes to `rem`, and one new ε of
//!   2^-11 + e_cpu + 2^-50 is added. The emitted fuzz code takes sin/cos of an exactly
//!   clamped argument (Δx = 0), so the bound of each is just 2^-11 + e_cpu, about 4.9e-4:
//!   this term, amplified by the rational that uses the two values, dominates the bound of
//!   `fuzz_average_ps` and `fuzz_ps_coeffs`.
//! - clamp/min/max: if the two sides cannot straddle a limit, Δ passes through (or is 0 when
//!   both are clamped); otherwise they are 1-Lipschitz: a new ε of the old bound. select
//!   needs an exact condition. Integer operations are exact; bitcasts must see the same value
//!   on both sides (a bitcast of a subnormal, possibly flushed to ±0, is let through: the
//!   emitted code only tests its bits for NaN; so is the bitcast of an inexact value that is
//!   finite on both sides, on which only that NaN test is defined), otherwise the evaluation
//!   panics.
//! - A float→u32 conversion (a table index) whose argument may deviate across an integer
//!   forks the evaluation: each integer the GPU may take is followed, and the bound is the
//!   largest over the paths of |path value − CPU value| + path bound (`simulate_all`).
//!
//! "ulp" is the spacing of f32 at the larger magnitude either side may reach (|v| + bound).
//! For the emitted rationals (a dozen operations and one divide on O(1) values) the bound is
//! a few ulps of the result; for the table lerps about one ulp.


// Shared by several test binaries, each using a part of it.
#![allow(dead_code)]

use naga::{BinaryOperator as B, Expression as E, Handle, Literal, MathFunction as M, ScalarKind, Statement};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

/// Deviation GPU − CPU of one value: Σ cᵢ·εᵢ (|εᵢ| ≤ 1, ids sorted) + r, |r| ≤ rem.
#[derive(Clone, Debug, Default)]
struct Dev {
    terms: Vec<(u32, f64)>,
    rem: f64,
}

impl Dev {
    fn radius(&self) -> f64 {
        self.terms.iter().map(|t| t.1.abs()).sum::<f64>() + self.rem
    }
    fn is_zero(&self) -> bool {
        self.terms.is_empty() && self.rem == 0.0
    }
    /// k·a + l·b (exact linear combination).
    fn lin(k: f64, a: &Dev, l: f64, b: &Dev) -> Dev {
        let (mut i, mut j) = (0, 0);
        let mut terms = Vec::with_capacity(a.terms.len() + b.terms.len());
        while i < a.terms.len() || j < b.terms.len() {
            let ia = a.terms.get(i).map_or(u32::MAX, |t| t.0);
            let ib = b.terms.get(j).map_or(u32::MAX, |t| t.0);
            let (id, c) = if ia == ib {
                i += 1;
                j += 1;
                (ia, k * a.terms[i - 1].1 + l * b.terms[j - 1].1)
            } else if ia < ib {
                i += 1;
                (ia, k * a.terms[i - 1].1)
            } else {
                j += 1;
                (ib, l * b.terms[j - 1].1)
            };
            if c != 0.0 {
                terms.push((id, c));
            }
        }
        Dev { terms, rem: k.abs() * a.rem + l.abs() * b.rem }
    }
}

#[derive(Clone, Debug)]
enum V {
    /// f32 value on the CPU, the same value on a simulated GPU (see [`Gpu`]), the bound on
    /// their deviation, and how it was made (what a driver may fuse or fold).
    F { v: f32, g: f32, d: Dev, shape: Shape },
    U(u32),
    /// Bits of an f32 that is finite on both sides but may differ between them (`abs`: with
    /// the sign masked off, so below 0x7f800000 on both): only a mask and a comparison with
    /// an infinity/NaN pattern (the emitted NaN test) are defined on it.
    Finite { bits: u32, abs: bool },
    I(i32),
    B(bool),
    Arr(Rc<Vec<V>>),
}

/// What an f32 value is, as far as a driver's rewriting of the expression that uses it goes.
#[derive(Clone, Copy, Debug)]
enum Shape {
    Plain,
    /// A literal or module constant.
    Const,
    /// A product, with its simulated-GPU operands (fusable into an add).
    Prod(f32, f32),
    /// `sa·a + sc·c` (signs ±1) with `c` a constant and `a` not: a product of it with a
    /// constant `k` may be distributed, `sa·a·k + fl(sc·c·k)`. `ga`: `a` on the simulated GPU;
    /// `exact`: the CPU's sum was exact.
    Shifted { ga: f32, sa: f32, c: f32, sc: f32, exact: bool },
}

/// Spacing of f32 numbers at magnitude `m` (subnormal spacing below MIN_POSITIVE).
pub fn ulp(m: f64) -> f64 {
    let m = m.abs().max(f32::MIN_POSITIVE as f64);
    if !m.is_finite() {
        return f64::INFINITY;
    }
    // log2 may round up just below a power of two: a larger ulp is the safe side.
    2f64.powf(m.log2().floor() - 23.0)
}

/// A conforming GPU to simulate next to the bound, to test the bound itself: it may fuse
/// every `a*b ± c` into an FMA, return divisions off by whole ulps, flush subnormals.
#[derive(Clone, Copy, Debug, Default)]
pub struct Gpu {
    pub fuse: bool,
    /// Ulps added to every quotient (|div_ulps| ≤ 2 stays within the 2.5 ulp allowance).
    pub div_ulps: i32,
    pub flush_subnormals: bool,
    /// Added to every sin/cos result, as a fraction of the allowance (2^-11 unless set
    /// otherwise; |trig| < 1: the sum is rounded to f32, so 0.999 stays within it).
    pub trig: f64,
    /// Distribute every product of a constant with a sum that has a constant operand, then
    /// fold and fuse: `(x − c)·k` as `fma(x, k, −fl(c·k))`, what NVIDIA's Vulkan driver does.
    pub distribute: bool,
}

/// A parsed and validated WGSL module whose functions can be evaluated.
pub struct Program {
    module: naga::Module,
    globals: RefCell<HashMap<Handle<E>, V>>,
    next: Cell<u32>,
    gpu: Cell<Gpu>,
    trig_allowance: Cell<f64>,
    forks: RefCell<Forks>,
}

/// The float→u32 conversions of one evaluation whose result may differ between CPU and GPU,
/// in evaluation order, and the results to take for the first of them (`forced`; the CPU's
/// for the rest).
#[derive(Default)]
struct Forks {
    forced: Vec<u32>,
    seen: Vec<Straddle>,
}

/// One such conversion: the result taken, the ones a GPU may give (the CPU's among them),
/// and the simulated GPU's.
struct Straddle {
    chosen: u32,
    candidates: Vec<u32>,
    gpu: u32,
}

/// Values and bounds of one evaluation path, and the conversions it forked at.
type Path = (Vec<(f32, f32, f64)>, Vec<Straddle>);

/// WGSL's absolute error allowance for sin and cos on [−π, π].
pub const WGSL_TRIG_ALLOWANCE: f64 = 1.0 / 2048.0;

/// `x` moved by `n` ulps (toward +inf for n > 0).
fn step_ulps(x: f32, n: i32) -> f32 {
    let mut x = x;
    for _ in 0..n.unsigned_abs() {
        x = if n > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

impl Program {
    pub fn new(wgsl: &str) -> Program {
        let module = naga::front::wgsl::parse_str(wgsl).unwrap_or_else(|e| panic!("{}", e.emit_to_string(wgsl)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(wgsl)));
        Program {
            module,
            globals: RefCell::new(HashMap::new()),
            next: Cell::new(0),
            gpu: Cell::new(Gpu::default()),
            trig_allowance: Cell::new(WGSL_TRIG_ALLOWANCE),
            forks: RefCell::new(Forks::default()),
        }
    }

    /// Replace the sin/cos allowance of [`WGSL_TRIG_ALLOWANCE`] by a tighter one: not what
    /// WGSL promises, only to say how close a GPU came (e.g. 2^-22, about 2 ulp at 1).
    pub fn set_trig_allowance(&self, abs: f64) {
        self.trig_allowance.set(abs);
    }

    pub fn function(&self, name: &str) -> Handle<naga::Function> {
        self.module
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no fn {name}"))
            .0
    }

    /// Whether `h`, or a function it calls, takes a sin or cos.
    pub fn uses_trig(&self, h: Handle<naga::Function>) -> bool {
        let f = &self.module.functions[h];
        f.expressions.iter().any(|(_, e)| matches!(e, E::Math { fun: M::Sin | M::Cos, .. }))
            || f.expressions.iter().any(|(_, e)| matches!(e, E::CallResult(g) if self.uses_trig(*g)))
    }

    /// Evaluate `h` at `args`: the f32 value (CPU semantics) and the bound on |GPU − CPU|.
    pub fn eval(&self, h: Handle<naga::Function>, args: &[f32]) -> (f32, f64) {
        let (v, _, d) = self.simulate(h, args, Gpu::default());
        (v, d)
    }

    /// [`Program::eval`], plus the value on a simulated conforming GPU.
    pub fn simulate(&self, h: Handle<naga::Function>, args: &[f32], gpu: Gpu) -> (f32, f32, f64) {
        match self.simulate_all(h, args, gpu).as_slice() {
            [one] => *one,
            other => panic!("function returned {} values", other.len()),
        }
    }

    /// [`Program::eval`] of a function returning an f32 or an array of f32: each element's
    /// value and bound (the bounds are per element; their deviations may be correlated).
    pub fn eval_all(&self, h: Handle<naga::Function>, args: &[f32]) -> Vec<(f32, f64)> {
        self.simulate_all(h, args, Gpu::default()).into_iter().map(|(v, _, d)| (v, d)).collect()
    }

    /// [`Program::simulate`] of a function returning an f32 or an array of f32.
    ///
    /// Where a float→u32 conversion (a table index) may give the GPU another integer than the
    /// CPU, because its argument deviates across an integer, the evaluation forks: every
    /// combination of the possible integers is evaluated, each path with its own bound, and
    /// the bound of an element is the largest over the paths of |path value − CPU value| +
    /// path bound. (A table lerp is continuous across a texel edge, so the paths agree to
    /// within the slope times the deviation of the index argument.) The simulated GPU's value
    /// is the one of the path its own conversions take.
    pub fn simulate_all(&self, h: Handle<naga::Function>, args: &[f32], gpu: Gpu) -> Vec<(f32, f32, f64)> {
        self.gpu.set(gpu);
        let mut stack = vec![Vec::new()];
        let mut paths: Vec<Path> = Vec::new();
        while let Some(forced) = stack.pop() {
            let (values, seen) = self.path(h, args, &forced);
            for k in forced.len()..seen.len() {
                for &c in seen[k].candidates.iter().filter(|&&c| c != seen[k].chosen) {
                    let mut next: Vec<u32> = seen[..k].iter().map(|s| s.chosen).collect();
                    next.push(c);
                    stack.push(next);
                }
            }
            paths.push((values, seen));
        }
        let cpu = &paths[0].0; // nothing forced: the CPU's integers
        let gpu_path = paths
            .iter()
            .find(|(_, seen)| seen.iter().all(|s| s.chosen == s.gpu))
            .expect("the simulated GPU's path is among the forks");
        (0..cpu.len())
            .map(|k| {
                let bound = paths.iter().map(|(p, _)| (p[k].0 as f64 - cpu[k].0 as f64).abs() + p[k].2).fold(0.0, f64::max);
                (cpu[k].0, gpu_path.0[k].1, bound)
            })
            .collect()
    }

    /// One evaluation with the first straddling conversions' results `forced`.
    fn path(&self, h: Handle<naga::Function>, args: &[f32], forced: &[u32]) -> Path {
        self.next.set(0);
        *self.forks.borrow_mut() = Forks { forced: forced.to_vec(), seen: Vec::new() };
        let a: Vec<V> = args.iter().map(|&x| self.f(x, x, Dev::default(), Shape::Plain)).collect();
        let scalar = |v: &V| match v {
            V::F { v, g, d, .. } => (*v, *g, d.radius()),
            other => panic!("function returned {other:?}"),
        };
        let values = match self.call(h, a) {
            V::Arr(items) => items.iter().map(scalar).collect(),
            v => vec![scalar(&v)],
        };
        (values, std::mem::take(&mut self.forks.borrow_mut().seen))
    }

    /// A float→u32 conversion that gives `cpu` on the CPU and any of `lo..=hi` on a GPU
    /// (`gpu` on the simulated one): the integer this path takes.
    fn straddle(&self, cpu: u32, lo: u32, hi: u32, gpu: u32) -> u32 {
        assert!(hi - lo <= 2, "u32 of a value that may move by more than two integers ({lo}..={hi})");
        assert!((lo..=hi).contains(&gpu), "simulated GPU: u32 gives {gpu}, outside {lo}..={hi}");
        let mut forks = self.forks.borrow_mut();
        let k = forks.seen.len();
        let chosen = forks.forced.get(k).copied().unwrap_or(cpu);
        forks.seen.push(Straddle { chosen, candidates: (lo..=hi).collect(), gpu });
        chosen
    }

    /// A new independent unknown of magnitude `mag` added to `d`.
    fn fresh(&self, mut d: Dev, mag: f64) -> Dev {
        if mag > 0.0 {
            let id = self.next.get();
            self.next.set(id + 1);
            d.terms.push((id, mag)); // ids grow, so the list stays sorted
        }
        d
    }

    /// An f32 value; a subnormal may be flushed to zero on the GPU.
    fn f(&self, v: f32, g: f32, d: Dev, shape: Shape) -> V {
        let d = if v != 0.0 && v.abs() < f32::MIN_POSITIVE {
            self.fresh(d, v.abs() as f64)
        } else if v.is_finite() && v != 0.0 {
            let short = v.abs() as f64 - d.radius();
            if short > 0.0 && short < f32::MIN_POSITIVE as f64 { self.fresh(d, short) } else { d }
        } else {
            d
        };
        let g = if self.gpu.get().flush_subnormals && g.abs() < f32::MIN_POSITIVE { 0.0 * g.signum() } else { g };
        V::F { v, g, d, shape }
    }

    fn exact(&self, v: f32) -> V {
        self.f(v, v, Dev::default(), Shape::Plain)
    }

    fn call(&self, h: Handle<naga::Function>, args: Vec<V>) -> V {
        let func = &self.module.functions[h];
        let mut memo: Vec<Option<V>> = vec![None; func.expressions.len()];
        let mut frame = Frame { p: self, func, args, memo: &mut memo };
        frame.block(&func.body).expect("function returns a value")
    }

    fn global(&self, h: Handle<E>) -> V {
        if let Some(v) = self.globals.borrow().get(&h) {
            return v.clone();
        }
        let v = match &self.module.global_expressions[h] {
            // Built directly (not through `f`): cached values must not depend on the simulated
            // GPU or carry deviation ids of one evaluation.
            E::Literal(Literal::F32(x)) => {
                assert!(*x == 0.0 || x.abs() >= f32::MIN_POSITIVE || !x.is_finite(), "subnormal constant");
                V::F { v: *x, g: *x, d: Dev::default(), shape: Shape::Const }
            }
            E::Literal(l) => self.literal(l),
            E::Compose { components, .. } => V::Arr(Rc::new(components.iter().map(|c| self.global(*c)).collect())),
            E::Constant(c) => self.global(self.module.constants[*c].init),
            other => panic!("unsupported global expression {other:?}"),
        };
        self.globals.borrow_mut().insert(h, v.clone());
        v
    }

    fn literal(&self, l: &Literal) -> V {
        match *l {
            Literal::F32(x) => self.f(x, x, Dev::default(), Shape::Const),
            Literal::AbstractFloat(x) => self.f(x as f32, x as f32, Dev::default(), Shape::Const),
            Literal::U32(x) => V::U(x),
            Literal::I32(x) => V::I(x),
            Literal::AbstractInt(x) => V::I(x as i32),
            Literal::Bool(b) => V::B(b),
            other => panic!("unsupported literal {other:?}"),
        }
    }

    fn binary(&self, op: B, a: V, b: V) -> V {
        match (a, b) {
            (V::F { v: x, g: gx, d: dx, shape: sx }, V::F { v: y, g: gy, d: dy, shape: sy }) => {
                let prod = |s: Shape| match s {
                    Shape::Prod(a, b) => Some((a, b)),
                    _ => None,
                };
                let (px, py) = (prod(sx), prod(sy));
                let fuse = self.gpu.get().fuse;
                let (x64, y64) = (x as f64, y as f64);
                let (rx, ry) = (dx.radius(), dy.radius());
                match op {
                    B::Add | B::Subtract => {
                        let (r, sign) = if op == B::Add { (x + y, 1.0) } else { (x - y, -1.0) };
                        let g = match (px, py) {
                            (Some((a, b)), _) if fuse => a.mul_add(b, sign as f32 * gy),
                            (_, Some((a, b))) if fuse => (sign as f32 * a).mul_add(b, gx),
                            _ => if op == B::Add { gx + gy } else { gx - gy },
                        };
                        let mut d = Dev::lin(1.0, &dx, sign, &dy);
                        let mut inexact = !d.is_zero();
                        for (is_mul, v, rv) in [(px.is_some(), x64, rx), (py.is_some(), y64, ry)] {
                            if is_mul {
                                d = self.fresh(d, 0.5 * ulp(v.abs() + rv)); // fused: unrounded product
                                inexact = true;
                            }
                        }
                        if inexact {
                            let rad = d.radius();
                            d = self.fresh(d, ulp(r.abs() as f64 + rad));
                        }
                        let exact = (r as f64) == x64 + sign * y64;
                        let shape = match (sx, sy) {
                            (Shape::Const, Shape::Const) => Shape::Const,
                            (_, Shape::Const) => Shape::Shifted { ga: gx, sa: 1.0, c: y, sc: sign as f32, exact },
                            (Shape::Const, _) => Shape::Shifted { ga: gy, sa: sign as f32, c: x, sc: 1.0, exact },
                            _ => Shape::Plain,
                        };
                        self.f(r, g, d, shape)
                    }
                    B::Multiply => {
                        let r = x * y;
                        let mut d = Dev::lin(y64, &dx, x64, &dy);
                        d.rem += rx * ry;
                        let mut g = gx * gy;
                        // A shifted value times a constant: the driver may distribute and fold,
                        // (sa·a + sc·c)·k → fma(sa·a, k, fl(sc·c·k)) (Vulkan's default, without
                        // NoContraction, allows it; seen on NVIDIA). Against the CPU's
                        // fl(fl(sa·a + sc·c)·k) that skips the CPU's rounding of the sum,
                        // ≤ |k|·½ ulp of it (0 if exact), and adds the rounding of c·k,
                        // ≤ ½ ulp of it; the one rounding of the result is the ε below.
                        // (the shifted operand's shape and CPU value, the constant k)
                        let shifted = match (sx, sy) {
                            (s @ Shape::Shifted { .. }, Shape::Const) => Some((s, x64, y)),
                            (Shape::Const, s @ Shape::Shifted { .. }) => Some((s, y64, x)),
                            _ => None,
                        };
                        if let Some((Shape::Shifted { ga, sa, c, sc, exact }, value, k)) = shifted {
                            let k64 = k as f64;
                            let sum = if exact { 0.0 } else { k64.abs() * 0.5 * ulp(value) };
                            d = self.fresh(d, sum + 0.5 * ulp(c as f64 * k64));
                            if self.gpu.get().distribute {
                                g = (sa * ga).mul_add(k, sc * c * k);
                            }
                        }
                        if !d.is_zero() {
                            let rad = d.radius();
                            d = self.fresh(d, ulp(r.abs() as f64 + rad));
                        }
                        self.f(r, g, d, Shape::Prod(gx, gy))
                    }
                    B::Divide => {
                        let r = x / y;
                        let den = y64.abs() - ry;
                        assert!(
                            den >= 2f64.powi(-126) && y64.abs() + ry <= 2f64.powi(126),
                            "divisor {y:e} ± {ry:e} outside the range of the WGSL division accuracy"
                        );
                        let q = x64 / y64;
                        // Δq = (Δx − qΔy)/y' = (Δx − qΔy)/y − (Δx − qΔy)Δy/(y y').
                        let num = Dev::lin(1.0, &dx, -q, &dy);
                        let mut d = Dev::lin(1.0 / y64, &num, 0.0, &Dev::default());
                        d.rem += num.radius() * ry / (y64.abs() * den);
                        let rad = d.radius();
                        d = self.fresh(d, 3.0 * ulp(q.abs() + rad));
                        self.f(r, step_ulps(gx / gy, self.gpu.get().div_ulps), d, Shape::Plain)
                    }
                    B::Less | B::LessEqual | B::Greater | B::GreaterEqual | B::Equal | B::NotEqual => {
                        let cmp = |x: f64, y: f64| match op {
                            B::Less => x < y,
                            B::LessEqual => x <= y,
                            B::Greater => x > y,
                            B::GreaterEqual => x >= y,
                            B::Equal => x == y,
                            _ => x != y,
                        };
                        let c = cmp(x64, y64);
                        assert_eq!(cmp(gx as f64, gy as f64), c, "simulated GPU compares {gx} and {gy} differently");
                        assert!(
                            [(-rx, -ry), (-rx, ry), (rx, -ry), (rx, ry)].iter().all(|&(p, q)| cmp(x64 + p, y64 + q) == c),
                            "comparison of {x} and {y} may differ between CPU and GPU"
                        );
                        V::B(c)
                    }
                    other => panic!("unsupported f32 operator {other:?}"),
                }
            }
            (V::Finite { bits, .. }, V::U(0x7fff_ffff)) if op == B::And => V::Finite { bits: bits & 0x7fff_ffff, abs: true },
            (V::Finite { abs: true, .. }, V::U(c)) if c >= 0x7f80_0000 => match op {
                // |bits| ≤ 0x7f7fffff < c on both sides.
                B::Less | B::LessEqual | B::NotEqual => V::B(true),
                B::Greater | B::GreaterEqual | B::Equal => V::B(false),
                other => panic!("unsupported operator {other:?} on the bits of an inexact value"),
            },
            (V::U(x), V::U(y)) => match op {
                B::Add => V::U(x.wrapping_add(y)),
                B::Subtract => V::U(x.wrapping_sub(y)),
                B::Multiply => V::U(x.wrapping_mul(y)),
                B::Divide => V::U(x / y),
                B::Modulo => V::U(x % y),
                B::And => V::U(x & y),
                B::InclusiveOr => V::U(x | y),
                B::ExclusiveOr => V::U(x ^ y),
                B::ShiftLeft => V::U(x << (y & 31)),
                B::ShiftRight => V::U(x >> (y & 31)),
                B::Less => V::B(x < y),
                B::LessEqual => V::B(x <= y),
                B::Greater => V::B(x > y),
                B::GreaterEqual => V::B(x >= y),
                B::Equal => V::B(x == y),
                B::NotEqual => V::B(x != y),
                other => panic!("unsupported u32 operator {other:?}"),
            },
            (V::B(x), V::B(y)) => match op {
                B::LogicalAnd | B::And => V::B(x && y),
                B::LogicalOr | B::InclusiveOr => V::B(x || y),
                B::Equal => V::B(x == y),
                B::NotEqual => V::B(x != y),
                other => panic!("unsupported bool operator {other:?}"),
            },
            // Vectors (a table's channels): component by component, a scalar operand with each.
            (V::Arr(x), V::Arr(y)) if x.len() == y.len() => {
                V::Arr(Rc::new(x.iter().zip(y.iter()).map(|(a, b)| self.binary(op, a.clone(), b.clone())).collect()))
            }
            (V::Arr(x), s @ V::F { .. }) => V::Arr(Rc::new(x.iter().map(|a| self.binary(op, a.clone(), s.clone())).collect())),
            (s @ V::F { .. }, V::Arr(y)) => V::Arr(Rc::new(y.iter().map(|b| self.binary(op, s.clone(), b.clone())).collect())),
            (a, b) => panic!("unsupported operands {a:?} {op:?} {b:?}"),
        }
    }

    /// clamp(x, lo, hi) (Rust semantics on the CPU side: NaN stays NaN; the emitted code
    /// selects NaN away before using the result).
    #[allow(clippy::too_many_arguments)]
    fn clamp(&self, x: f32, gx: f32, dx: Dev, lo: f32, glo: f32, dlo: &Dev, hi: f32, ghi: f32, dhi: &Dev) -> V {
        if x.is_nan() {
            return self.f(x, gx, Dev::default(), Shape::Plain);
        }
        let r = x.max(lo).min(hi);
        let g = gx.max(glo).min(ghi);
        let (rx, rl, rh) = (dx.radius(), dlo.radius(), dhi.radius());
        let (x64, lo64, hi64) = (x as f64, lo as f64, hi as f64);
        let d = if x64 - rx > lo64 + rl && x64 + rx < hi64 - rh {
            dx // inside on both sides
        } else if (x64 + rx < lo64 - rl && rl == 0.0) || (x64 - rx > hi64 + rh && rh == 0.0) {
            Dev::default() // clamped to the same exact limit on both sides
        } else {
            self.fresh(Dev::default(), rx.max(rl).max(rh)) // 1-Lipschitz
        };
        self.f(r, g, d, Shape::Plain)
    }

    /// sin (or cos) of x: see the module docs for the bound.
    fn trig(&self, sin: bool, x: f32, gx: f32, dx: Dev) -> V {
        let rx = dx.radius();
        let pi = std::f64::consts::PI;
        assert!(
            x.is_finite() && (x as f64).abs() + rx <= pi && (gx as f64).abs() <= pi,
            "{}({x:e} ± {rx:e}) outside [-π, π], where WGSL bounds its error",
            if sin { "sin" } else { "cos" }
        );
        let (x64, gx64) = (x as f64, gx as f64);
        let (r, exact, slope, g64) = if sin {
            (x.sin(), x64.sin(), x64.cos(), gx64.sin())
        } else {
            (x.cos(), x64.cos(), -x64.sin(), gx64.cos())
        };
        let mut d = Dev::lin(slope, &dx, 0.0, &Dev::default());
        d.rem += 0.5 * rx * rx;
        let cpu_err = (r as f64 - exact).abs();
        let d = self.fresh(d, self.trig_allowance.get() + cpu_err + 2f64.powi(-50));
        let g = (g64 + self.gpu.get().trig * self.trig_allowance.get()) as f32;
        self.f(r, g, d, Shape::Plain)
    }

    fn math(&self, fun: M, a: V, b: Option<V>, c: Option<V>) -> V {
        let inf = Dev::default();
        match (fun, a, b, c) {
            (
                M::Clamp,
                V::F { v, g, d, .. },
                Some(V::F { v: lo, g: glo, d: dl, .. }),
                Some(V::F { v: hi, g: ghi, d: dh, .. }),
            ) => self.clamp(v, g, d, lo, glo, &dl, hi, ghi, &dh),
            (M::Min, V::F { v, g, d, .. }, Some(V::F { v: w, g: gw, d: dw, .. }), None) => {
                self.clamp(v, g, d, f32::NEG_INFINITY, f32::NEG_INFINITY, &inf, w, gw, &dw)
            }
            (M::Max, V::F { v, g, d, .. }, Some(V::F { v: w, g: gw, d: dw, .. }), None) => {
                self.clamp(v, g, d, w, gw, &dw, f32::INFINITY, f32::INFINITY, &inf)
            }
            (M::Sin | M::Cos, V::F { v, g, d, .. }, None, None) => self.trig(fun == M::Sin, v, g, d),
            (M::Min, V::U(x), Some(V::U(y)), None) => V::U(x.min(y)),
            (M::Max, V::U(x), Some(V::U(y)), None) => V::U(x.max(y)),
            (M::Clamp, V::U(x), Some(V::U(lo)), Some(V::U(hi))) => V::U(x.max(lo).min(hi)),
            (M::Abs, V::F { v, g, d, .. }, None, None) => {
                if v.abs() as f64 > d.radius() {
                    let s = if v < 0.0 { -1.0 } else { 1.0 };
                    self.f(v.abs(), g.abs(), Dev::lin(s, &d, 0.0, &inf), Shape::Plain)
                } else {
                    let r = d.radius();
                    self.f(v.abs(), g.abs(), self.fresh(Dev::default(), r), Shape::Plain)
                }
            }
            (M::Sqrt, V::F { v, g, d, .. }, None, None) => {
                // WGSL: sqrt inherits 1/inverseSqrt's accuracy (2 ulp, then a 2.5-ulp division):
                // a fresh 5 ulp of the result. An input deviation Δ moves √x by at most
                // min(Δ/(2√x), √Δ) (the second near 0, where the slope is unbounded).
                let r = v.sqrt();
                let rx = d.radius();
                let moved = if rx == 0.0 { 0.0 } else { (rx / (2.0 * (v as f64).max(0.0).sqrt())).min(rx.sqrt()) };
                let d = self.fresh(Dev::default(), moved + 5.0 * ulp(r as f64));
                self.f(r, g.max(0.0).sqrt(), d, Shape::Plain)
            }
            (fun, a, b, c) => panic!("unsupported {fun:?}({a:?}, {b:?}, {c:?})"),
        }
    }
}

struct Frame<'p, 'm> {
    p: &'p Program,
    func: &'p naga::Function,
    args: Vec<V>,
    memo: &'m mut Vec<Option<V>>,
}

fn index(v: &V) -> usize {
    match v {
        V::U(u) => *u as usize,
        V::I(i) => *i as usize,
        other => panic!("expected an index, got {other:?}"),
    }
}

impl Frame<'_, '_> {
    fn block(&mut self, block: &naga::Block) -> Option<V> {
        for s in block.iter() {
            match s {
                Statement::Emit(_) => {}
                Statement::Block(b) => {
                    if let Some(v) = self.block(b) {
                        return Some(v);
                    }
                }
                Statement::Call { function, arguments, result } => {
                    let args = arguments.iter().map(|a| self.expr(*a)).collect();
                    let v = self.p.call(*function, args);
                    if let Some(r) = result {
                        self.memo[r.index()] = Some(v);
                    }
                }
                Statement::Return { value: Some(v) } => return Some(self.expr(*v)),
                other => panic!("unsupported statement {other:?}"),
            }
        }
        None
    }

    fn expr(&mut self, h: Handle<E>) -> V {
        if let Some(v) = &self.memo[h.index()] {
            return v.clone();
        }
        let v = self.compute(h);
        self.memo[h.index()] = Some(v.clone());
        v
    }

    fn compute(&mut self, h: Handle<E>) -> V {
        let p = self.p;
        match &self.func.expressions[h] {
            E::Literal(l) => p.literal(l),
            E::Constant(c) => p.global(p.module.constants[*c].init),
            E::FunctionArgument(i) => self.args[*i as usize].clone(),
            E::Compose { components, .. } => V::Arr(Rc::new(components.iter().map(|c| self.expr(*c)).collect())),
            E::Access { base, index: i } => {
                let (b, i) = (self.expr(*base), self.expr(*i));
                match b {
                    V::Arr(a) => a[index(&i)].clone(),
                    other => panic!("indexing {other:?}"),
                }
            }
            E::AccessIndex { base, index: i } => match self.expr(*base) {
                V::Arr(a) => a[*i as usize].clone(),
                other => panic!("indexing {other:?}"),
            },
            E::CallResult(_) => panic!("call result used before the call"),
            E::Unary { op: naga::UnaryOperator::Negate, expr } => match self.expr(*expr) {
                V::F { v, g, d, shape } => {
                    let shape = match shape {
                        Shape::Prod(a, b) => Shape::Prod(-a, b),
                        Shape::Shifted { ga, sa, c, sc, exact } => Shape::Shifted { ga, sa: -sa, c, sc: -sc, exact },
                        other => other,
                    };
                    V::F { v: -v, g: -g, d: Dev::lin(-1.0, &d, 0.0, &Dev::default()), shape }
                }
                V::I(i) => V::I(i.wrapping_neg()),
                other => panic!("negating {other:?}"),
            },
            E::Binary { op, left, right } => {
                let (a, b) = (self.expr(*left), self.expr(*right));
                p.binary(*op, a, b)
            }
            E::Select { condition, accept, reject } => match self.expr(*condition) {
                V::B(c) => {
                    if c {
                        self.expr(*accept)
                    } else {
                        self.expr(*reject)
                    }
                }
                other => panic!("select on {other:?}"),
            },
            E::Math { fun, arg, arg1, arg2, .. } => {
                let a = self.expr(*arg);
                let b = arg1.map(|x| self.expr(x));
                let c = arg2.map(|x| self.expr(x));
                p.math(*fun, a, b, c)
            }
            E::As { expr, kind, convert } => {
                let v = self.expr(*expr);
                match (v, kind, convert) {
                    (V::F { v, g, d, .. }, ScalarKind::Uint, None) => {
                        let r = d.radius();
                        let nan = |x: f32| (x.to_bits() & 0x7fff_ffff) > 0x7f80_0000;
                        assert_eq!(nan(g), nan(v), "simulated GPU bitcast differs in NaN-ness");
                        if r == 0.0 || (v.abs() < f32::MIN_POSITIVE && r <= f32::MIN_POSITIVE as f64) {
                            // Exact unless the value is subnormal and may have been flushed to
                            // ±0; the emitted code only tests the bits for NaN, which neither is.
                            V::U(v.to_bits())
                        } else {
                            // Inexact but finite on both sides (|v| + r below f32::MAX): the
                            // bits differ, their NaN test does not.
                            assert!(
                                v.is_finite() && (v.abs() as f64 + r) < f32::MAX as f64 && g.is_finite(),
                                "bitcast of an inexact value that may not be finite ({v:e} ± {r:e})"
                            );
                            V::Finite { bits: v.to_bits(), abs: false }
                        }
                    }
                    (V::U(u), ScalarKind::Float, None) => p.exact(f32::from_bits(u)),
                    (V::F { v, g, d, .. }, ScalarKind::Uint, Some(4)) => {
                        let i = v as u32; // saturating, like WGSL
                        let r = d.radius();
                        let (lo, hi) = ((v as f64 - r) as f32 as u32, (v as f64 + r) as f32 as u32);
                        if lo == hi {
                            assert_eq!(lo, i, "u32({v} ± {r:e})");
                            assert_eq!(g as u32, i, "simulated GPU: u32({g}) != u32({v})");
                            V::U(i)
                        } else {
                            V::U(p.straddle(i, lo, hi, g as u32))
                        }
                    }
                    (V::U(u), ScalarKind::Float, Some(4)) => p.exact(u as f32),
                    (V::I(i), ScalarKind::Float, Some(4)) => p.exact(i as f32),
                    (V::U(u), ScalarKind::Sint, _) => V::I(u as i32),
                    (V::I(i), ScalarKind::Uint, _) => V::U(i as u32),
                    (v, k, c) => panic!("unsupported conversion of {v:?} to {k:?} ({c:?})"),
                }
            }
            other => panic!("unsupported expression {other:?}"),
        }
    }
}
