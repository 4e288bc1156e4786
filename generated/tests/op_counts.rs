//! Shader cost report: operation counts of every emitted WGSL function, from naga's IR, next
//! to the measured error in its file's header.
//!
//!     cargo test --release -p shadefit-runtime --test op_counts -- --nocapture
//!
//! prints one table of every function of every emitted library (helpers included), one per
//! quantity with several forms (fit, table, texture) to pick from, and checks the counts of a
//! few functions against hand counts of their source. With the `gpu` feature,
//!
//!     cargo test --release -p shadefit-runtime --test op_counts -- --ignored --nocapture
//!
//! also times each function over a 3840×2160 compute dispatch on the adapter wgpu picks (see
//! `timing_over_a_4k_dispatch`).
//!
//! # What is counted
//! Each expression a function evaluates, once (naga's expressions are a DAG: a `let` used
//! twice is computed once), plus the inclusive cost of every function it calls, per call;
//! vector operations count once per component. Columns:
//! - `add`, `mul`, `div`: f32 `+ −`, `×`, `/` (a `dot` of n components is n mul + n−1 add,
//!   `mix` 2 add + 1 mul per component, `normalize` its dot + 1 inverseSqrt + n mul);
//! - `transc`: sin, cos, exp, log, pow, sqrt, inverseSqrt and the like (the special-function
//!   unit on most GPUs), named in the `fns` column;
//! - `tex`: texture fetches (`textureLoad`, `textureSample*`);
//! - `const`: loads from a module-scope `const` array at a computed index (the tables: a real
//!   memory load). Loads at a constant index (the fit coefficients, `NUM[k]`) do not appear:
//!   naga's constant evaluator folds them into immediates while parsing;
//! - `other`: comparisons, select, clamp/min/max/abs, integer and bit operations, float ↔ int
//!   conversions (a bitcast is free and not counted).
//!
//! Both sides of a branch are counted (the only branch in emitted code is `skin_sh_lut`'s
//! band-0 early return, which costs nothing). Counts are of the WGSL as written, with no
//! common-subexpression elimination (`fuzz_ps_coeffs` spells out its monomials in each of its
//! six fields, and a backend shares them) and no fusing of `a*b + c`: they rank forms rather
//! than predict cycles.
//!
//! # Error column
//! `max abs` from the `// measured error:` header line of the function's file (the fit or
//! table against the integral; for skin LUTs the bilinear lookup of the f32 texels, to which
//! the KTX2 texture adds its f16 storage error, shown in `note`). Helpers carry their module's
//! figure in parentheses.

use naga::{BinaryOperator as B, Expression as E, Handle, MathFunction as M, Module, ScalarKind, Statement, TypeInner};
use shadefit_runtime::{compose, lut, wgsl};
use std::collections::{BTreeSet, HashMap};

/// Operation counts of one function (inclusive of its callees).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct Counts {
    add: usize,
    mul: usize,
    div: usize,
    transc: usize,
    tex: usize,
    const_loads: usize,
    other: usize,
    transc_fns: BTreeSet<&'static str>,
}

impl Counts {
    fn plus(&mut self, o: &Counts) {
        self.add += o.add;
        self.mul += o.mul;
        self.div += o.div;
        self.transc += o.transc;
        self.tex += o.tex;
        self.const_loads += o.const_loads;
        self.other += o.other;
        self.transc_fns.extend(o.transc_fns.iter().copied());
    }

    /// Arithmetic total (add + mul + div + transc), for ranking forms.
    fn arith(&self) -> usize {
        self.add + self.mul + self.div + self.transc
    }
}

/// A parsed, validated WGSL source with type information.
struct Source {
    module: Module,
    info: naga::valid::ModuleInfo,
}

impl Source {
    fn new(src: &str) -> Source {
        let module = naga::front::wgsl::parse_str(src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(src)));
        Source { module, info }
    }

    fn function(&self, name: &str) -> Handle<naga::Function> {
        self.module
            .functions
            .iter()
            .find(|(_, f)| f.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no fn {name}"))
            .0
    }

    fn names(&self) -> Vec<String> {
        self.module.functions.iter().filter_map(|(_, f)| f.name.clone()).collect()
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

    /// Inclusive counts of `f` (memoised).
    fn counts(&self, f: Handle<naga::Function>, memo: &mut HashMap<Handle<naga::Function>, Counts>) -> Counts {
        if let Some(c) = memo.get(&f) {
            return c.clone();
        }
        let mut c = Counts::default();
        self.block(f, &self.module.functions[f].body, &mut c, memo);
        memo.insert(f, c.clone());
        c
    }

    fn block(&self, f: Handle<naga::Function>, block: &naga::Block, c: &mut Counts, memo: &mut HashMap<Handle<naga::Function>, Counts>) {
        for s in block.iter() {
            match s {
                Statement::Emit(range) => {
                    for e in range.clone() {
                        self.expr(f, e, c);
                    }
                }
                Statement::Block(b) => self.block(f, b, c, memo),
                Statement::If { accept, reject, .. } => {
                    self.block(f, accept, c, memo);
                    self.block(f, reject, c, memo);
                }
                Statement::Call { function, .. } => {
                    let callee = self.counts(*function, memo);
                    c.plus(&callee);
                }
                Statement::Return { .. } => {}
                other => panic!("op_counts: unsupported statement {other:?} (add it to the cost model)"),
            }
        }
    }

    fn expr(&self, f: Handle<naga::Function>, e: Handle<E>, c: &mut Counts) {
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
                assert!(!matches!(func.expressions[*base], E::Constant(_)), "op_counts: a constant-index load naga did not fold");
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
                    other => panic!("op_counts: no cost for {other:?} (add it to the cost model)"),
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
            other => panic!("op_counts: unsupported expression {other:?} (add it to the cost model)"),
        }
    }
}

/// `max abs` of a `// measured error:` line, and the texture storage error if it names one.
fn header_error(src: &str) -> (Option<f64>, Option<String>) {
    let Some(line) = src.lines().find(|l| l.starts_with("// measured error:")) else { return (None, None) };
    let number_after = |key: &str| {
        line.find(key).and_then(|i| line[i + key.len()..].split([',', ' ', ';', ')']).find(|s| !s.is_empty())?.parse::<f64>().ok())
    };
    let storage = line.find("storage <=").map(|i| {
        let fmt = line[..i].rsplit("; ").next().unwrap_or("").trim();
        format!("texture +{:.1e} ({fmt} storage)", number_after("storage <=").unwrap_or(f64::NAN))
    });
    (number_after("max abs"), storage)
}

/// A string field of the module's JSON provenance (`"key": "value"`), read without a JSON
/// parser: the generator writes one key per line.
fn json_field(module: &str, key: &str) -> Option<String> {
    let path = format!("{}/json/{module}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pat = format!("\"{key}\": \"");
    let i = text.find(&pat)? + pat.len();
    Some(text[i..i + text[i..].find('"')?].to_string())
}

/// One row: a function of an emitted library (or a runtime texture accessor of a table).
struct Row {
    module: String,
    function: String,
    form: String,
    helper: bool,
    quantity: String,
    counts: Counts,
    error: Option<f64>,
    note: String,
}

fn is_helper(module: &str, name: &str) -> bool {
    name == format!("{module}_input") || name.ends_with("_coords") || name.ends_with("_uv") || name.ends_with("_tex_input") || name.ends_with("_tex_load")
}

/// Every function of every emitted library, then the texture accessor of every table.
fn rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for &module in wgsl::NAMES {
        let text = wgsl::module(module).expect("compiled-in module");
        let src = Source::new(&compose(&[module]).unwrap());
        let (error, storage) = header_error(text);
        let kind = json_field(module, "kind").unwrap_or_default();
        let quantity = json_field(module, "quantity").unwrap_or_default();
        let mut memo = HashMap::new();
        for name in src.names() {
            let counts = src.counts(src.function(&name), &mut memo);
            let helper = is_helper(module, &name);
            let sampled = counts.tex > 0;
            let form = match kind.as_str() {
                "fit" | "fields" => "rational fit",
                "table" => "table, const array",
                "skin-lut" if sampled => "LUT, KTX2 texture",
                "skin-lut" => "LUT, const array",
                _ => "?",
            };
            let note = if sampled { storage.clone().unwrap_or_default() } else { String::new() };
            rows.push(Row { module: module.into(), function: name, form: form.into(), helper, quantity: quantity.clone(), counts, error, note });
        }
    }
    // The hand-written WGSL library of the runtime (no measured error: it is exact algebra).
    let src = Source::new(&compose(&["skin_curvature"]).unwrap());
    let mut memo = HashMap::new();
    for name in src.names() {
        let counts = src.counts(src.function(&name), &mut memo);
        rows.push(Row {
            module: "skin_curvature (runtime)".into(),
            function: name,
            form: "hand-written".into(),
            helper: false,
            quantity: "skin-curvature".into(),
            counts,
            error: None,
            note: "directional curvature for the skin LUTs".into(),
        });
    }
    for t in lut::TABLES {
        let src = Source::new(&t.wgsl(0, 0));
        let mut memo = HashMap::new();
        let (error, _) = header_error(t.emitted_wgsl());
        for name in src.names() {
            let counts = src.counts(src.function(&name), &mut memo);
            rows.push(Row {
                module: format!("{} (lut::Table::wgsl)", t.module),
                helper: is_helper(t.module, &name),
                function: name,
                form: "table, R32Float texture".into(),
                quantity: json_field(t.module, "quantity").unwrap_or_default(),
                counts,
                error,
                note: "same values as the const array".into(),
            });
        }
    }
    rows
}

fn print_table(rows: &[&Row], timing: Option<&HashMap<String, String>>) {
    let time_head = if timing.is_some() { " | lavapipe ms/4K (SOFTWARE)" } else { "" };
    println!("| function | form | add | mul | div | transc | tex | const | other | fns | max abs error | note{time_head} |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---|{}", if timing.is_some() { "---:|" } else { "" });
    for r in rows {
        let c = &r.counts;
        let err = match (r.error, r.helper) {
            (Some(e), false) => format!("{e:.3e}"),
            (Some(e), true) => format!("({e:.3e})"),
            (None, _) => "-".into(),
        };
        let fns: Vec<&str> = c.transc_fns.iter().copied().collect();
        let name = if r.helper { format!("{} (helper)", r.function) } else { r.function.clone() };
        let time = timing.map(|t| format!(" | {}", t.get(&r.function).map(String::as_str).unwrap_or("-"))).unwrap_or_default();
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {err} | {}{time} |",
            r.form,
            c.add,
            c.mul,
            c.div,
            c.transc,
            c.tex,
            c.const_loads,
            c.other,
            fns.join(" "),
            r.note
        );
    }
}

fn print_report(timing: Option<&HashMap<String, String>>) {
    let rows = rows();
    println!("\nShader cost of every emitted WGSL function (naga IR; inclusive of callees; see tests/op_counts.rs)\n");
    let mut by_module: Vec<&Row> = rows.iter().collect();
    by_module.sort_by(|a, b| (a.module.as_str(), a.helper).cmp(&(b.module.as_str(), b.helper)));
    print_table(&by_module, timing);

    // Quantities with several non-helper forms: the table a user picks from.
    let mut quantities: Vec<&str> = rows.iter().map(|r| r.quantity.as_str()).collect();
    quantities.sort_unstable();
    quantities.dedup();
    for q in quantities {
        let mut forms: Vec<&Row> = rows.iter().filter(|r| r.quantity == q && !r.helper).collect();
        let mut kinds: Vec<&str> = forms.iter().map(|r| r.form.as_str()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        if kinds.len() < 2 {
            continue; // one form (the P̃_s pair is two parts of one form)
        }
        forms.sort_by_key(|r| (r.counts.arith(), r.counts.tex, r.counts.const_loads));
        println!("\nForms of `{q}` (cheapest arithmetic first):\n");
        print_table(&forms, timing);
    }
}

#[test]
fn cost_report() {
    print_report(None);
}

/// Hand counts of the source, so the walker is checked against something it did not compute.
#[test]
fn counts_match_hand_counts() {
    let rows = rows();
    let get = |f: &str| &rows.iter().find(|r| r.function == f).unwrap_or_else(|| panic!("no row {f}")).counts;
    #[cfg(feature = "gloss")]
    {
        // gloss_to_normal_length_lut: the input clamp (mask, compare, clamp, select: 4 other);
        // t0 = (x0 − 0)·255 (1 add, 1 mul); i0 = min(u32(t0), 254) (2 other); f0 = t0 − f32(i0)
        // (1 add, 1 other); T[i0]·(1 − f0) + T[i0 + 1]·f0 (2 add, 2 mul, 1 integer add, two
        // loads at computed indices).
        let c = get("gloss_to_normal_length_lut");
        assert_eq!((c.add, c.mul, c.div, c.transc, c.tex), (4, 3, 0, 0, 0), "{c:?}");
        assert_eq!((c.const_loads, c.other), (2, 8), "{c:?}");
        // The texture accessor: the same arithmetic, two fetches instead of the loads, each
        // with its texel address (i % width, i / width: 2 other).
        let t = get("gloss_to_normal_length_lut_tex");
        assert_eq!((t.add, t.mul, t.tex, t.const_loads, t.other), (4, 3, 2, 0, 12), "{t:?}");
    }
    #[cfg(feature = "fuzz")]
    {
        // fuzz_average_penetration: one input clamp (4 other); (N[0] + x0·(N[1] + x0·N[2])) / 1:
        // 2 add, 2 mul, 1 div (the N[k] are immediates).
        let c = get("fuzz_average_penetration");
        assert_eq!((c.add, c.mul, c.div, c.transc, c.const_loads, c.other), (2, 2, 1, 0, 0, 4), "{c:?}");
        // fuzz_average_ps: one sin, one cos.
        let r = get("fuzz_average_ps");
        assert_eq!((r.transc, r.transc_fns.iter().copied().collect::<Vec<_>>()), (2, vec!["cos", "sin"]), "{r:?}");
    }
    #[cfg(feature = "skin")]
    {
        // skin_punctual_lut_sample: one texture fetch, no table loads.
        let c = get("skin_punctual_lut_sample");
        assert_eq!((c.tex, c.const_loads), (1, 0), "{c:?}");
        // skin_punctual_lut: four loads of a vec3 texel (counted once each), then two vec3
        // lerps a·(1 − f0) + b·f0 and one across rows (9 mul, 3 add each).
        let c = get("skin_punctual_lut");
        assert_eq!(c.const_loads, 4);
        assert!(c.mul >= 18 && c.add >= 9, "{c:?}");
    }
    assert!(rows.iter().all(|r| r.error.is_some() || r.form == "hand-written"), "every emitted file has a measured error");
}

/// Times each function over a 3840×2160 dispatch (one invocation per pixel, 8×8 workgroups)
/// on the adapter wgpu picks from the environment, and prints the report with a column of
/// milliseconds per dispatch (the best of five, after a warm-up dispatch), and the time of a
/// baseline kernel that only computes the arguments and writes them, before and after.
///
/// Arguments come from the pixel position (values do not change the cost: the emitted code
/// has no data-dependent branches); vector and array results are summed into the one f32
/// written per pixel (a few adds in the driver, also in the baseline). On a software adapter
/// (lavapipe) the numbers are CPU time of LLVM-compiled SIMD code on this machine's cores,
/// shared with whatever else runs: a trend, not a GPU cost. Functions indexing a `const` array
/// at a computed index are not timed there (lavapipe copies the whole array per access, see
/// tests/gpu.rs); their texture forms are.
#[cfg(feature = "gpu")]
#[test]
#[ignore = "timing: run with --ignored --nocapture"]
fn timing_over_a_4k_dispatch() {
    let g = match pollster::block_on(shadefit_runtime::gpu::headless("op_counts timing")) {
        Ok(g) => g,
        Err(e) => {
            println!("timing SKIPPED: {e}");
            return;
        }
    };
    let info = g.adapter.get_info();
    let software = info.device_type == wgpu::DeviceType::Cpu;
    println!("adapter: {}{}", shadefit_runtime::gpu::describe(&info), if software { " -- SOFTWARE RENDERING: CPU time, trend only" } else { "" });
    let mut times = HashMap::new();
    let baseline = || timing::run(&g, "baseline", &timing::kernel("", "", "", "c0 + c1 + c2"), timing::Bind::None);
    let before = baseline();
    for r in rows().iter().filter(|r| !r.helper) {
        if software && r.counts.const_loads > 0 {
            times.insert(r.function.clone(), "- (const array)".into());
            continue;
        }
        let ms = timing::time_row(&g, r);
        times.insert(r.function.clone(), format!("{ms:.1}"));
    }
    let after = baseline();
    println!("baseline kernel (arguments and write only): {before:.1} ms before, {after:.1} ms after the functions, per 3840x2160 dispatch");
    print_report(Some(&times));
}

#[cfg(feature = "gpu")]
mod timing {
    use super::{Row, Source};
    use shadefit_runtime::{compose, gpu, lut, skin};

    pub const W: u32 = 3840;
    pub const H: u32 = 2160;

    /// What a kernel binds besides its output buffer (binding 1).
    pub enum Bind {
        None,
        /// A table's R32Float texture at binding 2 (declared by `lut::Table::wgsl`).
        Table(&'static lut::Table),
        /// A skin LUT's KTX2 texture and a linear sampler, at 2 and 3.
        Ktx2(&'static [u8]),
    }

    /// `library`, extra declarations, and an entry point that runs the statement `call` and
    /// writes `reduce` (an f32 expression of c0, c1, c2 and what `call` defines).
    pub fn kernel(library: &str, decls: &str, call: &str, reduce: &str) -> String {
        format!(
            "{library}\n{decls}\n@group(0) @binding(1) var<storage, read_write> shadefit_out: array<f32>;\n\n\
             @compute @workgroup_size(8, 8)\n\
             fn shadefit_main(@builtin(global_invocation_id) id: vec3<u32>) {{\n    \
                 let c0 = f32(id.x) / {w}.0;\n    \
                 let c1 = f32(id.y) / {h}.0;\n    \
                 let c2 = fract(c0 * 7.0 + c1 * 3.0);\n    \
                 {call}\n    \
                 shadefit_out[id.y * {W}u + id.x] = {reduce};\n}}\n",
            w = W - 1,
            h = H - 1,
        )
    }

    /// Milliseconds for the row's function.
    pub fn time_row(g: &gpu::Gpu, r: &Row) -> f64 {
        let module = r.module.split(' ').next().unwrap();
        let (library, bind, decls) = if let Some(t) = lut::TABLES.iter().find(|t| r.module.starts_with(&format!("{} (lut", t.module))) {
            (t.wgsl(0, 2), Bind::Table(t), String::new())
        } else {
            let ktx2 = match module {
                #[cfg(feature = "skin")]
                "skin_punctual_lut" => Some(shadefit_runtime::skin_punctual_lut::SKIN_PUNCTUAL_LUT_KTX2),
                #[cfg(feature = "skin")]
                "skin_sh_lut" => Some(shadefit_runtime::skin_sh_lut::SKIN_SH_LUT_KTX2),
                _ => None,
            };
            let decls = "@group(0) @binding(2) var shadefit_tex: texture_2d<f32>;\n@group(0) @binding(3) var shadefit_smp: sampler;\n";
            match ktx2 {
                Some(k) if r.counts.tex > 0 => (compose(&[module]).unwrap(), Bind::Ktx2(k), decls.to_string()),
                _ => (compose(&[module]).unwrap(), Bind::None, String::new()),
            }
        };
        let src = Source::new(&library);
        let f = &src.module.functions[src.function(&r.function)];
        let floats = ["c0", "c1", "c2", "1.0 - c0"];
        let mut k = 0;
        let args: Vec<String> = f
            .arguments
            .iter()
            .map(|a| {
                let ty = &src.module.types[a.ty].inner;
                match ty {
                    naga::TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Float => {
                        k += 1;
                        floats[(k - 1) % floats.len()].to_string()
                    }
                    naga::TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Uint => "1u + (id.x & 1u)".into(),
                    naga::TypeInner::Vector { size: naga::VectorSize::Tri, .. } => "vec3<f32>(c0, c1, c2)".into(),
                    naga::TypeInner::Array { .. } => "array<f32, 6>(c0, c1, c2, 0.1, 0.2, 0.3)".into(),
                    naga::TypeInner::Image { .. } => "shadefit_tex".into(),
                    naga::TypeInner::Sampler { .. } => "shadefit_smp".into(),
                    other => panic!("{}: no timing argument for {other:?}", r.function),
                }
            })
            .collect();
        let result = f.result.as_ref().map(|res| &src.module.types[res.ty].inner);
        let reduce = match result {
            Some(naga::TypeInner::Scalar(_)) => "r".to_string(),
            Some(naga::TypeInner::Vector { size, .. }) => (0..*size as usize).map(|i| format!("r[{i}]")).collect::<Vec<_>>().join(" + "),
            Some(naga::TypeInner::Array { size: naga::ArraySize::Constant(n), .. }) => {
                (0..n.get() as usize).map(|i| format!("r[{i}]")).collect::<Vec<_>>().join(" + ")
            }
            other => panic!("{}: no reduction of {other:?}", r.function),
        };
        let call = format!("let r = {}({});", r.function, args.join(", "));
        run(g, &r.function, &kernel(&library, &decls, &call, &reduce), bind)
    }

    /// Compile, warm up, then the best of five timed dispatches (submit to completion), in ms.
    pub fn run(g: &gpu::Gpu, label: &str, shader: &str, bind: Bind) -> f64 {
        let device = &g.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(shader.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: None,
            module: &module,
            entry_point: Some("shadefit_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let out = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("out"),
            size: W as u64 * H as u64 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let table;
        let ktx;
        let view;
        let sampler;
        let mut entries = vec![wgpu::BindGroupEntry { binding: 1, resource: out.as_entire_binding() }];
        match bind {
            Bind::None => {}
            Bind::Table(t) => {
                table = t.create_texture(device, &g.queue);
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&table.view) });
            }
            Bind::Ktx2(bytes) => {
                ktx = skin::create_lut_texture(device, &g.queue, label, bytes).expect("KTX2");
                view = ktx.create_view(&Default::default());
                sampler = skin::lut_sampler(device);
                entries.push(wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view) });
                entries.push(wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) });
            }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let dispatch = || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(W / 8, H / 8, 1);
            }
            let t0 = std::time::Instant::now();
            g.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
            t0.elapsed().as_secs_f64() * 1e3
        };
        dispatch();
        (0..5).map(|_| dispatch()).fold(f64::INFINITY, f64::min)
    }
}
